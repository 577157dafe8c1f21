"""The LAMMPS engine: the scene's deck driven through LAMMPS's Python interface.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (``units lj``).

The deck's setup and physics commands are issued one by one; then the run proceeds in
segments of one sample interval. After each segment the particles are gathered from LAMMPS
memory (no text dump) and fed to the analyses, so profiles accumulate while the run goes.
Every ``run.checkpoint_interval`` a restart file and the analysis state are written; an
interrupted run continues from there with ``resume=True``. Under MPI (``np > 1``) the same
driver runs on every rank (``mpirun … python -m demstudy.engines.lammps``); rank 0 analyses
and writes.
"""

from __future__ import annotations

import json
import os
import pickle
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from .._lammps import mpirun_executable, open_lammps
from ..analysis.profiles import ProfileAnalysis
from ..analysis.steady import energy_trend, is_steady
from ..decks import Deck, build_deck
from ..decks.contact import contact_setup
from ..decks.output import WALL_FORCES, sample_steps, segment_steps, steps
from ..decks.servo import ServoController, has_servo
from ..decks.system import DATA_FILE
from ..io.frames import Frame
from ..io.results import Results, write_results
from ..scene import Scene, scene_to_toml, validate_scene
from .base import EngineError, RunOptions

CHECKPOINT_RESTART = "checkpoint.restart"
CHECKPOINT_STATE = "checkpoint.pkl"
WORKER_FLAG = "DEMSTUDY_LAMMPS_WORKER"


def profile_analysis(scene: Scene, walls: tuple[float, float] | None = None) -> ProfileAnalysis:
    """Profiles along the scene's axis over the region particles can occupy (``walls``: the
    current lower and upper wall positions when walls move)."""
    m = scene.measure
    axis = "xyz".index(m.axis)
    period = scene.box.size[axis] if m.axis in scene.periodic else 0.0
    if m.axis == "y" and walls is not None:
        lo, hi = walls
    elif m.axis == "y" and not scene.y_periodic:
        lo = scene.wall_position("lower")
        hi = scene.wall_position("upper") if scene.wall("upper") else scene.box.size[1]
    else:
        lo, hi = 0.0, scene.box.size[axis]
    shift = scene.shear.rate * period if scene.shear is not None and m.axis == "y" else 0.0
    return ProfileAnalysis(axis=m.axis, bin_width=m.bin_width, lo=lo, hi=hi,
                           dim=scene.dimension, inertia_factor=scene.inertia_k, period=period,
                           image_velocity_shift=shift)


class LammpsSession:
    """One LAMMPS instance; errors come back as ``EngineError`` naming the deck line."""

    def __init__(self, workdir: Path, screen: bool = False):
        self.workdir = workdir
        self.lmp = open_lammps(screen=screen, log=workdir / "log.lammps")
        self.rank = int(self.lmp.extract_setting("world_rank"))
        self.nprocs = int(self.lmp.extract_setting("world_size"))

    def command(self, cmd: str) -> None:
        try:
            self.lmp.command(cmd)
        except Exception as exc:  # LAMMPS raises a bare Exception with its error message
            message = str(exc).strip() or type(exc).__name__
            raise EngineError(f"LAMMPS error: {message}\n  deck line: {cmd}") from None

    def gather(self, name: str, count: int, integer: bool = False) -> np.ndarray:
        data = self.lmp.gather_atoms(name, 0 if integer else 1, count)
        if data is None:
            raise EngineError(f"LAMMPS could not gather per-atom {name!r}")
        arr = np.ctypeslib.as_array(data)
        return arr.reshape(-1, count) if count > 1 else arr.copy()

    def fix_vector(self, fix_id: str, length: int) -> np.ndarray:
        """Global vector of a fix (e.g. ``fix ave/time``), identical on every rank."""
        lam = sys.modules[type(self.lmp).__module__.split(".")[0]]
        if length == 1:  # a fix averaging one value has a global scalar, not a vector
            return np.array([self.lmp.extract_fix(fix_id, lam.LMP_STYLE_GLOBAL,
                                                  lam.LMP_TYPE_SCALAR)], dtype=float)
        return np.array([
            self.lmp.extract_fix(fix_id, lam.LMP_STYLE_GLOBAL, lam.LMP_TYPE_VECTOR, i)
            for i in range(length)
        ], dtype=float)

    def close(self) -> None:
        self.lmp.close()


@dataclass
class RunState:
    """Everything needed to continue a run: counters, timeseries, analysis accumulators."""

    step: int = 0
    timeseries: dict[str, list] = field(default_factory=dict)
    frames: dict[str, list] = field(default_factory=dict)
    profiles: ProfileAnalysis | None = None
    wall_seconds: float = 0.0
    servo: ServoController | None = None
    # wall forces (on the particles) summed over segments since the last sample / servo update
    force_sums: dict[str, np.ndarray] = field(default_factory=dict)
    force_counts: dict[str, int] = field(default_factory=dict)

    def add_forces(self, forces: np.ndarray) -> None:
        for key in ("sample", "servo"):
            self.force_sums[key] = self.force_sums.get(key, 0.0) + forces
            self.force_counts[key] = self.force_counts.get(key, 0) + 1

    def take_forces(self, key: str) -> np.ndarray | None:
        """Mean wall forces since the last call for ``key`` (None before any segment)."""
        count = self.force_counts.pop(key, 0)
        total = self.force_sums.pop(key, None)
        return None if not count else total / count

    def record(self, key: str, value) -> None:
        self.timeseries.setdefault(key, []).append(value)


class LammpsEngine:
    name = "lammps"

    def run(self, scene: Scene, options: RunOptions) -> Path:
        if (options.np > 1 or options.isolate) and os.environ.get(WORKER_FLAG) != "1":
            return _launch_child(scene, options)
        setup = contact_setup(scene)  # raises UnsupportedByEngine before LAMMPS starts
        deck = build_deck(scene, setup=setup)  # so does every effect LAMMPS cannot express
        out = Path(options.out).resolve()
        workdir = out.with_suffix(".lammps")
        workdir.mkdir(parents=True, exist_ok=True)
        for name, content in deck.files.items():
            (workdir / name).write_text(content)
        (workdir / "deck.in").write_text(deck.render(scene.meta.name))
        return _Driver(scene, deck, setup.timestep, workdir, out, options).run()


class _Driver:
    def __init__(self, scene: Scene, deck: Deck, dt: float, workdir: Path, out: Path,
                 options: RunOptions):
        self.scene, self.deck, self.dt, self.workdir, self.out = scene, deck, dt, workdir, out
        self.options = options
        run = scene.run
        self.n_sample = sample_steps(scene, dt)
        # equilibration rounded to whole sample intervals so samples fall on dump steps
        self.n_eq = self.n_sample * round(steps(run.equilibration, dt) / self.n_sample)
        n_prod = self.n_sample * max(1, round(steps(run.production, dt) / self.n_sample))
        self.n_total = self.n_eq + n_prod
        ckpt = options.checkpoint_interval or run.checkpoint_interval
        self.n_ckpt = self.n_sample * max(1, round(ckpt / dt / self.n_sample)) if ckpt else 0
        keep = options.keep_frames
        self.keep_frames = scene.measure.keep_frames if keep is None else keep
        self.dump = Path(options.dump).resolve() if options.dump else None

    # -- set-up -------------------------------------------------------------------------
    def _issue_deck(self, session: LammpsSession, resume: bool) -> None:
        for cmd in self.deck.commands("setup"):
            if resume and cmd.startswith("read_data"):
                cmd = f"read_restart {self.workdir / CHECKPOINT_RESTART}"
            elif resume and cmd.startswith("set "):
                continue  # masses are in the restart file
            elif cmd.startswith("read_data"):
                cmd = f"read_data {self.workdir / DATA_FILE}"
            session.command(cmd)
        for cmd in self.deck.commands("physics"):
            session.command(cmd)
        session.command("thermo 0")

    def _load_state(self) -> RunState:
        if self.options.resume:
            path = self.workdir / CHECKPOINT_STATE
            if not path.exists() or not (self.workdir / CHECKPOINT_RESTART).exists():
                raise EngineError(f"--resume: no checkpoint in {self.workdir}")
            with open(path, "rb") as fh:
                state = pickle.load(fh)
            if state["scene"] != scene_to_toml(self.scene):
                raise EngineError("--resume: the checkpoint belongs to a different scene")
            return state["run"]
        if has_servo(self.scene):
            # bins are laid between the walls where they stand when production starts
            return RunState(servo=ServoController(self.scene, self.dt))
        return RunState(profiles=profile_analysis(self.scene))

    # -- sampling -----------------------------------------------------------------------
    def _frame(self, session: LammpsSession, t: float) -> Frame:
        dim = self.scene.dimension
        types = session.gather("type", 1, integer=True)
        mobile = types == 1
        x = session.gather("x", 3)[mobile, :dim]
        v = session.gather("v", 3)[mobile, :dim]
        omega = session.gather("omega", 3)[mobile]
        radius = session.gather("radius", 1)[mobile]
        lmp = session.lmp
        boxlo, boxhi, xy, _yz, _xz, _periodic, _change = lmp.extract_box()
        return Frame(time=t, box_lo=np.array(boxlo[:dim]), box_hi=np.array(boxhi[:dim]),
                     position=x, velocity=v,
                     angular_velocity=omega[:, 2:3] if dim == 2 else omega,
                     radius=radius, tilt=float(xy))

    def _sample(self, session: LammpsSession, state: RunState, production: bool) -> None:
        t = state.step * self.dt
        frame = self._frame(session, t)
        if session.rank != 0:
            return
        dim, K = self.scene.dimension, self.scene.inertia_k
        mass = (2 * frame.radius) ** dim
        inertia = K * mass * frame.radius**2
        state.record("time", t)
        state.record("momentum", np.sum(mass[:, None] * frame.velocity, axis=0))
        state.record("kinetic_energy", 0.5 * float(np.sum(mass[:, None] * frame.velocity**2)))
        state.record("rotational_energy",
                     0.5 * float(np.sum(inertia[:, None] * frame.angular_velocity**2)))
        forces = state.take_forces("sample")
        for i, wall in enumerate(self.scene.walls):
            # force of the particles on the wall, averaged over the interval that just ended
            force = -forces[i, :dim] if forces is not None else np.full(dim, np.nan)
            state.record(f"wall_force_{wall.side}", force)
        if self.scene.shear is not None:
            state.record("tilt", frame.tilt)  # Lees–Edwards offset of the upper image
        if state.servo is not None:
            state.servo.advance(t)
            for key, value in state.servo.state().items():
                state.record(key, value)
        if production:
            if state.profiles is None:
                lower, upper = state.servo.walls["lower"], state.servo.walls["upper"]
                state.profiles = profile_analysis(self.scene, (lower.y, upper.y))
            state.profiles.feed(frame)
            if self.keep_frames:
                for key in ("position", "velocity", "angular_velocity", "radius"):
                    state.frames.setdefault(key, []).append(getattr(frame, key).copy())
                state.frames.setdefault("time", []).append(t)
            if self.dump is not None:
                session.command(
                    f"write_dump mobile custom {self.dump} id type radius x y z vx vy vz "
                    "omegax omegay omegaz modify sort id append yes format float %.17g"
                )

    def _rebase_shear(self, session: LammpsSession, state: RunState) -> None:
        """Re-anchor the Lees–Edwards tilt variable after LAMMPS re-initialised fix deform.

        Every init (``write_restart``, ``run … pre yes``) makes fix deform take the current
        tilt as its start, so the tilt increment must count from that moment again."""
        if self.scene.shear is not None:
            session.command(f"variable lees_edwards_t0 equal {state.step * self.dt:.17g}")

    def _checkpoint(self, session: LammpsSession, state: RunState, started: float) -> None:
        restart = self.workdir / CHECKPOINT_RESTART
        session.command(f"write_restart {restart}.new")
        self._rebase_shear(session, state)  # write_restart re-initialises LAMMPS
        if session.rank != 0:
            return
        os.replace(f"{restart}.new", restart)
        snapshot = RunState(state.step, state.timeseries, state.frames, state.profiles,
                            state.wall_seconds + time.perf_counter() - started, state.servo)
        tmp = self.workdir / (CHECKPOINT_STATE + ".new")
        with open(tmp, "wb") as fh:
            pickle.dump({"scene": scene_to_toml(self.scene), "run": snapshot}, fh)
        os.replace(tmp, self.workdir / CHECKPOINT_STATE)

    # -- main loop ----------------------------------------------------------------------
    def run(self) -> Path:
        state = self._load_state()
        session = LammpsSession(self.workdir)
        started = time.perf_counter()
        try:
            self._issue_deck(session, resume=self.options.resume)
            if state.servo is not None and state.step > 0:
                state.servo.apply(session.command)  # variables are not in restart files
            session.command("run 0 post no")
            if state.step == 0:
                if self.dump is not None and self.dump.exists() and session.rank == 0:
                    self.dump.unlink()
                self._sample(session, state, production=self.n_eq == 0)
            self._loop(session, state, started)
        except KeyboardInterrupt:
            self._checkpoint(session, state, started)
            raise EngineError(
                f"interrupted at t = {state.step * self.dt:.6g}; a checkpoint was written: run "
                "the same command again with --resume to continue"
            ) from None
        finally:
            version = session.lmp.version()
            session.close()
        if session.rank != 0:
            return self.out
        state.wall_seconds += time.perf_counter() - started
        return self._write(state, version)

    def _loop(self, session: LammpsSession, state: RunState, started: float) -> None:
        servo = state.servo
        n_servo = servo.n_steps if servo is not None else self.n_sample
        segment = segment_steps(self.scene, self.dt)
        bar = tqdm(total=self.n_total * self.dt, initial=state.step * self.dt, unit="τ",
                   disable=not self.options.progress or session.rank != 0,
                   bar_format="{l_bar}{bar}| {n:.1f}/{total:.1f} τ [{elapsed}<{remaining}]",
                   desc=f"lammps {self.scene.meta.name}")
        pre = "no"
        with bar:
            while state.step < self.n_total:
                n = min(segment, self.n_total - state.step)
                if pre == "yes":
                    self._rebase_shear(session, state)
                session.command(f"run {n} pre {pre} post no")
                pre = "no"
                state.step += n
                walls = self.scene.walls
                if walls:
                    forces = session.fix_vector(WALL_FORCES, 3 * len(walls))
                    state.add_forces(forces.reshape(len(walls), 3))
                if servo is not None and state.step % n_servo == 0:
                    mean = state.take_forces("servo")
                    normal = {w.side: mean[i, 1] for i, w in enumerate(walls)}
                    servo.update(state.step * self.dt, normal, session.command)
                    pre = "yes"  # variables and fixes changed: LAMMPS must set up again
                if state.step % self.n_sample == 0:
                    self._sample(session, state, production=state.step > self.n_eq)
                bar.update(n * self.dt)
                if self.n_ckpt and state.step % self.n_ckpt == 0 and state.step < self.n_total:
                    self._checkpoint(session, state, started)

    def _write(self, state: RunState, version: int) -> Path:
        analysis = state.profiles.finish()
        profiles, profile_attrs = analysis.results, analysis.attrs
        scene = self.scene
        timeseries = {k: np.asarray(v) for k, v in state.timeseries.items()}
        frames = None
        if state.frames:
            frames = {k: np.asarray(v) for k, v in state.frames.items()}
        prod = timeseries["time"] >= self.n_eq * self.dt
        trend = energy_trend(timeseries["time"][prod], timeseries["kinetic_energy"][prod])
        attrs = {
            "engine": "lammps",
            "kinetic_energy_trend": trend,
            "steady": is_steady(trend),
            "engine_version": f"LAMMPS {version}",
            "scene_toml": scene_to_toml(scene),
            "scene_name": scene.meta.name,
            "seed": scene.run.seed,
            "wall_seconds": state.wall_seconds,
            "timestep": self.dt,
            "equilibration_end": self.n_eq * self.dt,
            "deck": self.deck.render(scene.meta.name),
            "approximations": "\n".join(self.deck.notes),
        }
        path = write_results(self.out, Results(attrs, timeseries, profiles, profile_attrs, frames))
        for name in (CHECKPOINT_RESTART, CHECKPOINT_STATE):
            (self.workdir / name).unlink(missing_ok=True)
        return path


# ------------------------------------------------------------------ child process / MPI
def _launch_child(scene: Scene, options: RunOptions) -> Path:
    """Run this driver in a child process (on ``options.np`` MPI ranks when np > 1).

    A crash inside LAMMPS (a segfault, an MPI abort) then ends the child, not the caller, and
    is reported as an ``EngineError``; the checkpoint written so far remains usable.
    """
    build_deck(scene)  # refuse unsupported scenes before launching anything
    payload = {
        "scene": scene.model_dump(mode="json"),
        "out": str(Path(options.out).resolve()),
        "dump": str(Path(options.dump).resolve()) if options.dump else None,
        "resume": options.resume,
        "progress": options.progress,
        "keep_frames": options.keep_frames,
        "checkpoint_interval": options.checkpoint_interval,
        "np": options.np,
    }
    out = Path(payload["out"])
    out.parent.mkdir(parents=True, exist_ok=True)
    job = out.with_name(f".{out.name}.job.json")
    job.write_text(json.dumps(payload))
    env = dict(os.environ, **{WORKER_FLAG: "1"})
    cmd = [sys.executable, "-m", "demstudy.engines.lammps", str(job)]
    if options.np > 1:
        cmd = [mpirun_executable(), "-np", str(options.np), *cmd]
    proc = subprocess.Popen(cmd, env=env, stdin=subprocess.DEVNULL)
    try:
        returncode = proc.wait()
    except KeyboardInterrupt:
        # the child got the same SIGINT: let it finish its segment and write a checkpoint
        try:
            proc.wait(timeout=300)
        except (subprocess.TimeoutExpired, KeyboardInterrupt):
            proc.kill()
        raise EngineError("interrupted: run the same command again with --resume to continue "
                          "from the last checkpoint") from None
    finally:
        job.unlink(missing_ok=True)
    if returncode != 0:
        how = (f"was killed by signal {-returncode}" if returncode < 0
               else f"failed (exit {returncode})")
        where = out.with_suffix(".lammps") / "log.lammps"
        raise EngineError(f"the LAMMPS run on {options.np} rank(s) {how}; see the messages "
                          f"above and {where}")
    return out


def _worker(job: str) -> int:
    payload = json.loads(Path(job).read_text())
    scene = validate_scene(payload["scene"], source=job)
    options = RunOptions(out=Path(payload["out"]), np=payload["np"],
                         dump=Path(payload["dump"]) if payload["dump"] else None,
                         resume=payload["resume"], progress=payload["progress"],
                         keep_frames=payload["keep_frames"],
                         checkpoint_interval=payload["checkpoint_interval"])
    try:
        LammpsEngine().run(scene, options)
    except EngineError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(_worker(sys.argv[1]))
