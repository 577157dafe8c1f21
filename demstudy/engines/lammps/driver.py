"""The run loop: segments of one sample interval, in-memory sampling, servo, checkpoints.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (``units lj``).

Every rank runs this loop with identical bookkeeping (so commands issued between segments are
the same everywhere); rank 0 alone accumulates profiles, keeps frames and writes files.
A stop request (Ctrl-C, or the wall-clock limit) is honoured at the end of a segment, after
all bookkeeping, when every rank agrees (MPI_Allreduce), so the checkpoint is consistent.
"""

from __future__ import annotations

import dataclasses
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ... import UNITS_NOTE, __version__
from ...analysis.base import bin_edges
from ...analysis.profiles import ProfileAnalysis
from ...analysis.stress import ContactStress, branch_sums, momentum_snapshot, stress_results
from ...analysis.suite import profile_analysis, profile_bounds
from ...decks import Deck
from ...decks.output import (
    STRESS_COLUMNS,
    STRESS_IDS,
    STRESS_PAIRS,
    WALL_FORCES,
    sample_steps,
    steps,
)
from ...decks.servo import ServoController, has_servo
from ...decks.system import DATA_FILE
from ...decks.walls import wall_fix_id, wall_force_sources
from ...io.frames import Frame
from ...io.results import Results, write_results
from ...scene import Scene, scene_to_toml
from ..base import EngineError, RunOptions, RunStopped, frames_on_resume
from ..common import (
    StopRequest,
    keep_frame,
    load_checkpoint,
    pickle_atomically,
    run_attrs,
)
from .session import LammpsSession, quoted

CHECKPOINT_STATE = "checkpoint.pkl"
# the restart file of a checkpoint is named by its step and the state pickle names it: the
# pickle's atomic rename commits the pair, so a cut-off checkpoint leaves the previous pair
CHECKPOINT_RESTARTS = "checkpoint-*.restart"
CHECKPOINT_VERSION = f"demstudy {__version__} (lammps checkpoint 2)"


@dataclass
class RunState:
    """Everything needed to continue a run: counters, timeseries, accumulators."""

    step: int = 0
    timeseries: dict[str, list] = field(default_factory=dict)
    frames: dict[str, list] = field(default_factory=dict)
    profiles: ProfileAnalysis | None = None
    stress: ContactStress | None = None  # contact stress (measure.statistics "stress")
    wall_seconds: float = 0.0
    servo: ServoController | None = None
    dump_size: int = 0
    keep_frames: bool = False  # fixed when the run starts, kept on resume
    # wall forces (on the particles) summed over segments since the last sample / servo update
    force_sums: dict[str, np.ndarray] = field(default_factory=dict)
    force_counts: dict[str, int] = field(default_factory=dict)
    # particle y and momenta where production starts and ends (the momentum balance's
    # unsteady term)
    momentum_start: dict | None = None
    momentum_end: dict | None = None

    def record(self, key: str, value) -> None:
        self.timeseries.setdefault(key, []).append(value)

    def add_forces(self, forces: np.ndarray) -> None:
        for key in ("sample", "servo"):
            self.force_sums[key] = self.force_sums.get(key, 0.0) + forces
            self.force_counts[key] = self.force_counts.get(key, 0) + 1

    def take_forces(self, key: str) -> np.ndarray | None:
        """Mean wall forces since the last call for ``key`` (None before any segment)."""
        count = self.force_counts.pop(key, 0)
        total = self.force_sums.pop(key, None)
        return None if not count else total / count


class Driver:
    def __init__(self, scene: Scene, deck: Deck, dt: float, workdir: Path, out: Path,
                 options: RunOptions):
        self.scene, self.deck, self.dt, self.workdir, self.out = scene, deck, dt, workdir, out
        self.options = options
        run = scene.run
        self.n_sample = sample_steps(scene, dt)
        # equilibration and production in whole sample intervals
        self.n_eq = self.n_sample * round(steps(run.equilibration, dt) / self.n_sample)
        n_prod = self.n_sample * max(1, round(steps(run.production, dt) / self.n_sample))
        self.n_total = self.n_eq + n_prod
        ckpt = options.checkpoint_interval or run.checkpoint_interval
        self.n_ckpt = self.n_sample * max(1, round(ckpt / dt / self.n_sample)) if ckpt else 0
        keep = options.keep_frames
        self.keep_frames = scene.measure.keep_frames if keep is None else keep
        self.dump = Path(options.dump).resolve() if options.dump else None
        self.sources = wall_force_sources(scene)
        self.measure_stress = "stress" in scene.measure.statistics
        self._mobile: np.ndarray | None = None
        self._all: tuple[np.ndarray, np.ndarray] | None = None  # (x, radius) of every atom

    # -- set-up -------------------------------------------------------------------------
    def _issue_deck(self, session: LammpsSession, resume: bool) -> None:
        for cmd in self.deck.commands("setup"):
            if cmd.startswith("read_data"):
                cmd = (f"read_restart {quoted(self._restart)}" if resume
                       else f"read_data {quoted(self.workdir / DATA_FILE)}")
            elif resume and cmd.startswith("set "):
                continue  # masses are in the restart file
            session.command(cmd)
        for cmd in self.deck.commands("physics"):
            session.command(cmd)
        session.command("thermo 0")

    def _load_state(self) -> RunState:
        if self.options.resume:
            saved = self._load_checkpoint()
            state = saved["run"]
            dump = str(self.dump) if self.dump else None
            if saved.get("dump") != dump:
                raise EngineError(f"--resume: the run started with --dump {saved.get('dump')}, "
                                  f"this call has {dump}: the dump continues only in its file")
            self.keep_frames = frames_on_resume(self.options.keep_frames, state.keep_frames)
            self._saved_forces = saved.get("forces")
            return state
        if has_servo(self.scene):
            # bins are laid between the walls where they stand when production starts
            return RunState(servo=ServoController(self.scene, self.dt),
                            keep_frames=self.keep_frames)
        return RunState(profiles=profile_analysis(self.scene), keep_frames=self.keep_frames)

    def _reanchor(self, session: LammpsSession, state: RunState) -> None:
        """Re-issue the time-anchored variables before LAMMPS initialises again.

        At every initialisation (``run … pre yes``, ``write_restart``, ``read_restart``) fix
        deform takes the current box as its start, so the Lees–Edwards tilt and the servo's
        width change must count from that moment; the servo's walls are re-anchored too."""
        t = state.step * self.dt
        if self.scene.shear is not None:
            session.command(f"variable lees_edwards_t0 equal {t:.17g}")
        if state.servo is not None:
            state.servo.advance(t)
            state.servo.apply(session.command)

    # -- sampling -----------------------------------------------------------------------
    def _frame(self, session: LammpsSession, t: float) -> Frame:
        dim = self.scene.dimension
        if self._mobile is None:  # atom types never change: gather them once
            self._mobile = session.gather("type", 1, integer=True) == 1
        mobile = self._mobile
        x_all, r_all = session.gather("x", 3), session.gather("radius", 1)
        self._all = (x_all, r_all)
        x = x_all[mobile, :dim]
        v = session.gather("v", 3)[mobile, :dim]
        omega = session.gather("omega", 3)[mobile]
        radius = r_all[mobile]
        boxlo, boxhi, xy, *_ = session.lmp.extract_box()
        return Frame(time=t, box_lo=np.array(boxlo[:dim]), box_hi=np.array(boxhi[:dim]),
                     position=x, velocity=v,
                     angular_velocity=omega[:, 2:3] if dim == 2 else omega,
                     radius=radius, tilt=float(xy))

    def _wall_forces(self, forces: np.ndarray) -> np.ndarray:
        """(n_walls, 3) force of each wall on the particles from the per-source vectors."""
        walls = [w.side for w in self.scene.walls]
        total = np.zeros((len(walls), 3))
        for (side, _compute, sign), row in zip(self.sources, forces, strict=True):
            total[walls.index(side)] += sign * row
        return total

    def _sample(self, session: LammpsSession, state: RunState, production: bool) -> None:
        t = state.step * self.dt
        frame = self._frame(session, t)  # collective: every rank gathers
        if production and self.dump is not None:  # collective too
            session.command(
                f"write_dump mobile custom {quoted(self.dump)} id type radius x y z vx vy vz "
                "omegax omegay omegaz modify sort id append yes format float %.17g"
            )
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
            state.record("width", float(frame.lengths[0]))
        if self.scene.gravity is not None and state.step in (self.n_eq, self.n_total):
            snap = momentum_snapshot(t, frame.position[:, 1], mass[:, None] * frame.velocity)
            if state.step == self.n_eq:
                state.momentum_start = snap
            else:
                state.momentum_end = snap
        if production and self.measure_stress:  # collective (sum over ranks)
            self._sample_stress(session, state, frame)
        if not production or session.rank != 0:
            return
        if state.profiles is None:
            lower, upper = state.servo.walls["lower"], state.servo.walls["upper"]
            state.profiles = profile_analysis(self.scene, (lower.y, upper.y))
        state.profiles.feed(frame)
        if self.keep_frames:
            keep_frame(state.frames, frame)

    def _sample_stress(self, session: LammpsSession, state: RunState, frame: Frame) -> None:
        """Contact stress of this sample: every rank bins the contacts it holds (pairs from
        ``compute pair/local``, wall contacts from the wall fixes' per-atom arrays), the
        per-bin sums are added over the ranks, rank 0 accumulates them."""
        if state.stress is None:  # bins of the profiles, laid when production starts
            lo, hi, _ = profile_bounds(self.scene)
            if state.servo is not None:
                lo, hi = state.servo.walls["lower"].y, state.servo.walls["upper"].y
            period = self.scene.box.size[1] if self.scene.y_periodic else 0.0
            state.stress = ContactStress(bin_edges(lo, hi, self.scene.measure.bin_width),
                                         self.scene.dimension, period)
        sums = session.sum_ranks(self._contact_sums(session, state.stress))
        if session.rank == 0:
            section = float(np.prod(np.delete(frame.lengths, 1)))
            state.stress.add_sums(sums, section)

    def _contact_sums(self, session: LammpsSession, stress: ContactStress) -> np.ndarray:
        """Per-bin sums of f_i (x) (r_i - r_j) over this rank's contacts (branch to a bump's
        or a wall's contact point for wall contacts)."""
        dim = self.scene.dimension
        x_all, r_all = self._all
        mobile = self._mobile
        rows = session.local_array(STRESS_PAIRS, STRESS_COLUMNS)
        ids = session.local_array(STRESS_IDS, 2).astype(np.int64) - 1
        if ids.shape[0] != rows.shape[0]:
            raise EngineError(f"{STRESS_PAIRS} and {STRESS_IDS} disagree on the contacts")
        force = rows[:, 0:3] + rows[:, 3:6]  # on i: normal + tangential
        sep = rows[:, 6:9]  # x_i - x_j (minimum image)
        i, j = ids[:, 0], ids[:, 1]
        dist = np.linalg.norm(sep, axis=1)
        both = mobile[i] & mobile[j]
        ends = [(x_all[i[both], 1], force[both], sep[both])]
        for a, b, sign in ((i, j, 1.0), (j, i, -1.0)):  # mobile a, bump b
            sel = mobile[a] & ~mobile[b] & (dist > 0)
            reach = r_all[a[sel]] - 0.5 * (r_all[a[sel]] + r_all[b[sel]] - dist[sel])
            unit = sign * sep[sel] / dist[sel, None]
            ends.append((x_all[a[sel], 1], sign * force[sel], unit * reach[:, None]))
        local_x = None
        for wall in self.scene.walls:
            contacts = session.fix_atom_array(wall_fix_id(wall.side))
            if contacts.size == 0:
                continue
            if local_x is None:
                local_x = session.local_positions()
            on = contacts[:, 0] != 0
            ends.append((local_x[on, 1], contacts[on, 1:4], local_x[on] - contacts[on, 4:7]))
        y = np.concatenate([e[0] for e in ends])
        f = np.concatenate([e[1] for e in ends])[:, :dim]
        br = np.concatenate([e[2] for e in ends])[:, :dim]
        return branch_sums(y, y - br[:, 1], f[:, :, None] * br[:, None, :], stress.edges,
                           stress.period)

    def _load_checkpoint(self) -> dict:
        """The state pickle of this output's checkpoint (and ``self._restart``, the restart
        file it names), refused when missing, unreadable or written by another version."""
        saved = load_checkpoint(self.workdir / CHECKPOINT_STATE, self.scene, {"run", "restart"},
                                CHECKPOINT_VERSION, "LAMMPS")
        self._restart = self.workdir / saved["restart"]
        if not self._restart.exists():
            raise EngineError(f"--resume: {self._restart}, the restart file of the checkpoint, "
                              "is missing")
        return saved

    def _checkpoint(self, session: LammpsSession, state: RunState, started: float,
                    resetup: bool) -> dict[str, np.ndarray]:
        """Write the checkpoint; return the per-atom forces and torques of this step (velocity
        Verlet's, from half-step velocities), which restart files do not hold. ``resetup``:
        LAMMPS sets up again here anyway (a servo update), so they are not carried over."""
        forces = ({} if resetup else
                  {name: session.gather(name, 3).copy() for name in ("f", "torque")})
        restart = self.workdir / f"checkpoint-{state.step}.restart"
        session.command(f"write_restart {quoted(restart)}")
        if session.rank != 0:
            return forces
        if self.dump is not None and self.dump.exists():
            state.dump_size = self.dump.stat().st_size
        snapshot = dataclasses.replace(
            state, wall_seconds=state.wall_seconds + time.perf_counter() - started)
        pickle_atomically(self.workdir / CHECKPOINT_STATE,
                          {"scene": scene_to_toml(self.scene), "units": UNITS_NOTE,
                           "version": CHECKPOINT_VERSION, "restart": restart.name,
                           "dump": str(self.dump) if self.dump else None,
                           "forces": forces, "run": snapshot})
        for old in self.workdir.glob(CHECKPOINT_RESTARTS):  # committed: the older pairs go
            if old != restart:
                old.unlink(missing_ok=True)
        return forces

    def _set_up_again(self, session: LammpsSession, state: RunState,
                      forces: dict[str, np.ndarray] | None) -> None:
        """LAMMPS after ``write_restart`` or ``read_restart``: re-anchor the variables, set up
        (``run 0``) and put back the forces and torques of the checkpoint's step. The set-up
        would otherwise have recomputed them from full-step velocities, changing every
        velocity-dependent (damping) force for one step; with them restored, a checkpoint
        leaves the run as it was and a resumed run continues as the uninterrupted one."""
        self._reanchor(session, state)
        session.command("run 0 post no")
        for name, value in (forces or {}).items():
            session.scatter(name, value)

    # -- main loop ----------------------------------------------------------------------
    def _request_stop(self) -> None:
        self.stop.request()

    def run(self) -> Path:
        state = self._load_state()
        session = LammpsSession(self.workdir)
        started = time.perf_counter()
        self.stop = StopRequest(self.options.wall_limit)
        try:
            with self.stop:
                self._start(session, state)
                self._loop(session, state, started)
        except KeyboardInterrupt:  # no handler (not the main thread): keep the last checkpoint
            raise EngineError("interrupted: run again with --resume to continue from the last "
                              "checkpoint (if any)") from None
        finally:
            version = session.lmp.version()
            session.close()
        if session.rank != 0:
            return self.out
        state.wall_seconds += time.perf_counter() - started
        return self._write(state, version)

    def _start(self, session: LammpsSession, state: RunState) -> None:
        self._issue_deck(session, resume=self.options.resume)
        if self.options.resume:
            step = session.lmp.extract_global("ntimestep")
            if step != state.step:  # a safety net: the pickle names its own restart file
                raise EngineError(f"--resume: {self._restart} holds step {step}, the "
                                  f"checkpoint's state step {state.step}; remove "
                                  f"{self.workdir} to start afresh")
            if self.dump is not None and session.rank == 0 and self.dump.exists():
                os.truncate(self.dump, state.dump_size)  # drop frames after the checkpoint
            self._set_up_again(session, state, self._saved_forces)
        else:
            if self.dump is not None and session.rank == 0:
                self.dump.unlink(missing_ok=True)
            session.command("run 0 post no")
        if state.step == 0:
            self._sample(session, state, production=False)  # the initial state

    def _loop(self, session: LammpsSession, state: RunState, started: float) -> None:
        servo = state.servo
        # counted in steps (exact), shown in time units; sparse updates when not on a terminal
        bar = tqdm(total=self.n_total, initial=state.step, unit_scale=self.dt, unit="τ",
                   disable=not self.options.progress or session.rank != 0,
                   mininterval=0.5 if sys.stderr.isatty() else 30.0,
                   bar_format="{l_bar}{bar}| {n:.1f}/{total:.1f} τ [{elapsed}<{remaining}]",
                   desc=f"lammps {self.scene.meta.name}")
        initialise = False
        with bar:
            while state.step < self.n_total:
                if initialise:
                    self._reanchor(session, state)
                session.command(f"run {self.n_sample} pre {'yes' if initialise else 'no'} "
                                "post no")
                initialise = False
                state.step += self.n_sample
                if self.sources:
                    forces = session.fix_vector(WALL_FORCES, 3 * len(self.sources))
                    state.add_forces(self._wall_forces(forces.reshape(-1, 3)))
                if servo is not None and state.step % servo.n_steps == 0:
                    mean = state.take_forces("servo")
                    normal = {w.side: mean[i, 1] for i, w in enumerate(self.scene.walls)}
                    servo.update(state.step * self.dt, normal, session.box_lengths()[0])
                    initialise = True  # new wall motion: re-anchor, LAMMPS sets up again
                self._sample(session, state, production=state.step > self.n_eq)
                bar.update(self.n_sample)
                stop = session.any_rank(self.stop.check())
                checkpoint = self.n_ckpt and state.step % self.n_ckpt == 0
                if (stop or checkpoint) and state.step < self.n_total:
                    forces = self._checkpoint(session, state, started, resetup=initialise)
                    if not initialise:  # write_restart re-initialised LAMMPS
                        self._set_up_again(session, state, forces)
                if stop and state.step < self.n_total:
                    raise RunStopped(
                        f"stopped ({self.stop.reason or 'on another rank'}) at t = "
                        f"{state.step * self.dt:.6g} after a checkpoint: run the same command "
                        "again with --resume to continue")

    def _write(self, state: RunState, version: int) -> Path:
        analysis = state.profiles.finish()
        timeseries = {k: np.asarray(v) for k, v in state.timeseries.items()}
        frames = {k: np.asarray(v) for k, v in state.frames.items()} or None
        attrs = run_attrs(self.scene, "lammps", f"LAMMPS {version}", state.wall_seconds,
                          self.n_eq * self.dt, timeseries)
        attrs.update(timestep=self.dt, deck=self.deck.render(self.scene.meta.name),
                     approximations="\n".join(self.deck.notes))
        results = Results(attrs, timeseries, analysis.results, analysis.attrs, frames)
        if self.measure_stress:
            contact = state.stress.finish() if state.stress is not None else None
            data, group_attrs = stress_results(
                self.scene, analysis.results, timeseries, self.n_eq * self.dt, contact=contact,
                momentum=(state.momentum_start, state.momentum_end))
            group_attrs["contact_samples"] = state.stress.samples if state.stress else 0
            results.groups["stress"], results.group_attrs["stress"] = data, group_attrs
        path = write_results(self.out, results)
        (self.workdir / CHECKPOINT_STATE).unlink(missing_ok=True)
        for old in self.workdir.glob(CHECKPOINT_RESTARTS):
            old.unlink(missing_ok=True)
        return path
