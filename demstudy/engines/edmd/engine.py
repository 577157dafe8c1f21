"""``--engine edmd``: run a scene with the event-driven core, write the common results file.

Dimensionless particle units: d = 1, m = 1 (mass ∝ d^dim), time in the scene's unit.

Layout mirrors the LAMMPS driver (demstudy/engines/lammps/driver.py) so the two engines'
results are directly comparable: samples every ``run.sample_interval`` from t = 0 (the
initial state) with equilibration and production in whole sample intervals; profiles
(``ProfileAnalysis``) over the production samples; frames when asked. Extra timeseries:
``collisions`` (cumulative count), ``dissipated_energy`` (cumulative) and ``pressure``: the
kinetic part 2 E_kin/(dim V) at the sample plus the collisional part ΔW/(dim V Δt) over the
interval that ends at the sample (NaN at t = 0); W = Σ r_ij·J_i. Checkpoints (``--resume``)
restore the synchronised core state, so a resumed run is bit-identical to an uninterrupted one.
"""

from __future__ import annotations

import dataclasses
import math
import pickle
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ... import UNITS_NOTE, __version__
from ...analysis.base import bin_edges
from ...analysis.profiles import ProfileAnalysis
from ...analysis.stress import collisional_stress, momentum_snapshot, stress_results
from ...analysis.suite import profile_analysis, profile_bounds
from ...decks.base import UnsupportedByEngine
from ...decks.servo import ServoController, has_servo
from ...io.frames import Frame
from ...io.results import Results, write_results
from ...scene import Scene, scene_to_toml
from ...scene.initial import build_initial_state
from ..base import EngineError, RunOptions, RunStopped, frames_on_resume, work_folder
from ..child import in_worker, launch_child
from ..common import (
    StopRequest,
    keep_frame,
    load_checkpoint,
    pickle_atomically,
    run_attrs,
)
from .core import (
    DEFAULT_TC,
    EventDriven,
    advance_watched,
    from_initial_state,
    scene_parameters,
    with_bumps,
    y_range,
)

CHECKPOINT = "checkpoint.pkl"
ENGINE_VERSION = (f"demstudy-edmd {__version__} (gravity, flat and bumpy walls, servo, "
                  "Lees-Edwards, Walton, e(v), TC, events with wall collisions, synchronised "
                  "every 10^7 events)")
#: collision-log records kept per run (sampled every ``log_every`` collisions)
LOG_CAPACITY = 200_000


def check_supported(scene: Scene) -> dict:
    """Refuse what the event-driven engine cannot do (``scene_parameters``: regular bumps under
    gravity, servo-controlled or no-slip bumpy walls, Campbell's e(v) without gravity; here:
    periodic boxes too small for the cell lists, the stress along an axis other than y);
    return the core's options for the scene."""
    params = scene_parameters(scene)
    d_max = 1.0 + scene.particles.diameter_spread / 2
    short = [a for i, a in enumerate("xyz"[:scene.dimension])
             if a in scene.periodic and scene.box.size[i] < 3 * d_max]
    if short:
        raise UnsupportedByEngine("edmd", "box.size", list(scene.box.size),
                                  f"every periodic box length must be at least 3 largest "
                                  f"diameters ({3 * d_max:g}) for the cell lists")
    if "stress" in scene.measure.statistics and scene.measure.axis != "y":
        raise UnsupportedByEngine("edmd", "measure.axis", scene.measure.axis,
                                  "the collisional stress is binned along y only: use "
                                  "measure.axis = 'y' with 'stress' in measure.statistics")
    return params


class _StopInInterval(Exception):
    """A stop request (Ctrl-C, wall-clock limit) honoured between two event chunks."""


@dataclass
class EdmdRunState:
    """Everything needed to continue a run besides the core's own state."""

    samples: int = 0  # sample intervals done
    timeseries: dict[str, list] = field(default_factory=dict)
    frames: dict[str, list] = field(default_factory=dict)
    profiles: ProfileAnalysis | None = None
    wall_seconds: float = 0.0
    last_virial: float = 0.0
    last_time: float = 0.0
    last_impulse: dict[str, np.ndarray] = field(default_factory=dict)
    keep_frames: bool = False  # fixed when the run starts, kept on resume
    servo: ServoController | None = None
    next_servo: int = 0  # collision count of the next servo update (interval_unit collisions)
    next_servo_time: float = 0.0  # time of the next servo update (interval_unit time)
    servo_impulse: dict[str, np.ndarray] = field(default_factory=dict)
    servo_time: float = 0.0
    last_stress: np.ndarray | None = None
    stress_chunks: list = field(default_factory=list)  # per production interval
    stress_durations: list = field(default_factory=list)
    log: dict[str, list] = field(default_factory=dict)
    logged: int = 0
    stress_edges: np.ndarray | None = None  # servo runs: bins fixed when production starts
    # particle y and momenta where production starts and ends (the momentum balance's
    # unsteady term)
    momentum_start: dict | None = None
    momentum_end: dict | None = None

    def record(self, key: str, value) -> None:
        self.timeseries.setdefault(key, []).append(value)


class EdmdEngine:
    """``run(scene, options)``: event-driven hard discs/spheres (see the module docstring).

    ``options.extra``: ``tc`` (TC-model time, default ``DEFAULT_TC``; 0 switches it off),
    ``log_every`` (log every k-th collision; default 1 when the scene measures "angles",
    otherwise no log). ``options.isolate`` runs it in a child process; ``options.np`` > 1
    and ``options.dump`` are refused (a serial engine; no LAMMPS dump)."""

    name = "edmd"

    def run(self, scene: Scene, options: RunOptions) -> Path:
        params = check_supported(scene)
        if options.np > 1:
            raise UnsupportedByEngine("edmd", "--np", options.np, "the engine is serial")
        if options.dump is not None:
            raise UnsupportedByEngine("edmd", "--dump", str(options.dump),
                                      "the LAMMPS dump is not written by this engine; use "
                                      "--keep-frames")
        if options.isolate and not in_worker():
            return launch_child(self.name, scene, options)  # a crash in C++ stays there
        tc = float(options.extra.get("tc", DEFAULT_TC))
        return _Run(scene, options, params, tc).run()


class _Run:
    def __init__(self, scene: Scene, options: RunOptions, params: dict, tc: float):
        self.scene, self.options, self.params, self.tc = scene, options, params, tc
        self.out = Path(options.out).resolve()
        self.workdir = work_folder(self.out, "edmd")
        run = scene.run
        self.dt = run.sample_interval  # time, or collisions per particle
        self.by_collisions = run.unit == "collisions"
        self.n_eq = round(run.equilibration / self.dt)
        self.n_total = self.n_eq + max(1, round(run.production / self.dt))
        ckpt = options.checkpoint_interval or run.checkpoint_interval
        self.n_ckpt = max(1, round(ckpt / self.dt)) if ckpt else 0
        keep = options.keep_frames
        self.keep_frames = scene.measure.keep_frames if keep is None else keep
        self.volume = math.prod(scene.box.size)
        statistics = scene.measure.statistics
        default_log = 1 if "angles" in statistics else 0
        self.log_every = int(options.extra.get("log_every", default_log))
        self.stress = scene.measure.axis == "y"

    # -- state ----------------------------------------------------------------------------
    def _core_options(self, initial) -> dict:
        options = dict(self.params)
        if not self.scene.y_periodic:
            options["y_range"] = y_range(self.scene, initial.position)
        if self.stress:
            lo, hi, _period = profile_bounds(self.scene)
            self.stress_edges = bin_edges(lo, hi, self.scene.measure.bin_width)
            n_bins = len(self.stress_edges) - 1
            options["stress_bins"] = (lo, (hi - lo) / n_bins, n_bins)
        if self.log_every > 0:
            options.update(log_every=self.log_every, log_capacity=LOG_CAPACITY)
        return options

    def _start(self) -> tuple[EventDriven, EdmdRunState]:
        if not self.options.resume:
            self._refuse_foreign_checkpoint()
        initial = build_initial_state(self.scene)
        self.radius = initial.diameter / 2
        self.mass = initial.mass
        self.n = len(self.mass)  # mobile particles; bumps follow them in the core
        options = self._core_options(initial)
        everything, fixed = with_bumps(self.scene, initial)
        if fixed.any():
            options["fixed"] = fixed
        core = from_initial_state(everything, self.scene.box.size, tc=self.tc, **options)
        if not self.options.resume:
            servo = ServoController(self.scene, None) if has_servo(self.scene) else None
            state = EdmdRunState(keep_frames=self.keep_frames, servo=servo)
            if servo is None:
                state.profiles = profile_analysis(self.scene)
            else:
                if self._servo_by_time:
                    state.next_servo_time = self._servo_settings().interval_time
                else:
                    state.next_servo = self._servo_interval()
                state.servo_impulse = self._impulses(core)
            return core, state
        saved = load_checkpoint(self.workdir / CHECKPOINT, self.scene, {"tc", "core", "run"},
                                ENGINE_VERSION, "edmd")
        if saved["tc"] != self.tc:
            if "tc" in self.options.extra:  # asked for explicitly: refuse to change it
                raise EngineError(f"--resume: the checkpoint was run with --tc "
                                  f"{saved['tc']:g}, this call has {self.tc:g}")
            self.tc = float(saved["tc"])  # not given: continue with the run's own t_c
            core = from_initial_state(everything, self.scene.box.size, tc=self.tc, **options)
        core.set_state(saved["core"])
        self.keep_frames = frames_on_resume(self.options.keep_frames, saved["run"].keep_frames)
        if saved["run"].stress_edges is not None:
            self.stress_edges = saved["run"].stress_edges
        return core, saved["run"]

    def _refuse_foreign_checkpoint(self) -> None:
        """Outputs that differ only in their suffix share a work folder: a fresh run must not
        delete the checkpoint another output's interrupted run left there."""
        path = self.workdir / CHECKPOINT
        if not path.exists():
            return
        try:
            with open(path, "rb") as fh:
                other = pickle.load(fh).get("out")
        except Exception:  # unreadable: a fresh run replaces it
            return
        if other is not None and other != str(self.out):
            raise EngineError(f"{self.workdir} holds the checkpoint of the interrupted run "
                              f"writing {other}: resume that run first, or remove the folder")

    def _checkpoint(self, core: EventDriven, state: EdmdRunState, started: float) -> None:
        self.workdir.mkdir(parents=True, exist_ok=True)
        snapshot = dataclasses.replace(
            state, wall_seconds=state.wall_seconds + time.perf_counter() - started)
        pickle_atomically(self.workdir / CHECKPOINT,
                          {"scene": scene_to_toml(self.scene), "tc": self.tc,
                           "version": ENGINE_VERSION, "out": str(self.out),
                           "units": UNITS_NOTE, "core": core.get_state(), "run": snapshot})

    def _impulses(self, core: EventDriven) -> dict[str, np.ndarray]:
        return {w.side: core.wall_impulse(0 if w.side == "lower" else 1)
                for w in self.scene.walls}

    # -- servo ----------------------------------------------------------------------------
    def _servo_settings(self):
        return next(w.servo for w in self.scene.walls if w.servo is not None)

    @property
    def _servo_by_time(self) -> bool:
        return has_servo(self.scene) and self._servo_settings().interval_unit == "time"

    def _servo_interval(self) -> int:
        return max(1, round(self._servo_settings().interval_collisions * self.n))

    def _servo_update(self, core: EventDriven, state: EdmdRunState) -> None:
        """Campbell's servo step after every interval_collisions × N pair collisions: the
        walls' mean forces over the interval set their new normal velocities (the rule of
        ``ServoController``); the periodic width is rescaled (positions affinely) to keep
        width/gap, and the upper wall's speed follows the gap when the shear rate is held."""
        servo, t = state.servo, core.time
        impulses = self._impulses(core)
        span = max(t - state.servo_time, 1e-300)
        force = {side: float(impulses[side][1] - state.servo_impulse[side][1]) / span
                 for side in impulses}
        servo.update(t, force, float(core.box[0]))
        for side, wall in servo.walls.items():
            k = 0 if side == "lower" else 1
            wall.y = core.wall_position(k)  # the core's position is the truth
            core.set_wall(k, wall.y, wall.vy, wall.vx)
        if servo.scale_width:
            core.scale_width(servo.shape * servo.gap / float(core.box[0]))
        state.servo_impulse, state.servo_time = impulses, t
        if self._servo_by_time:
            state.next_servo_time += self._servo_settings().interval_time
        else:
            state.next_servo += self._servo_interval()

    @staticmethod
    def _tilt(core: EventDriven) -> float:
        """The image offset flipped into [−L_x/2, L_x/2), the convention of the results file
        (LAMMPS's ``flip yes``)."""
        lx = float(core.box[0])
        return (core.shear_offset + lx / 2) % lx - lx / 2

    # -- sampling -------------------------------------------------------------------------
    def _advance_interval(self, core: EventDriven, state: EdmdRunState) -> None:
        """Advance to the next sample: a time, or a collision count with run.unit =
        'collisions'; servo updates happen on the way."""
        if self.by_collisions:
            t_end, target = 1e300, round(state.samples * self.dt * self.n)
            guard = 1000 * max(1, target - core.collisions) + 10_000_000
        else:
            t_end, target, guard = state.samples * self.dt, 0, 0
        by_time = state.servo is not None and self._servo_by_time
        by_count = state.servo is not None and not by_time
        while True:
            stops = [c for c in (target, state.next_servo if by_count else 0) if c > 0]
            t_stop = min(t_end, state.next_servo_time) if by_time else t_end
            reached = advance_watched(core, t_stop, tc=self.tc, max_events=guard,
                                      stop_collisions=min(stops, default=0),
                                      stop_requested=self.stop.check)
            if reached and target and core.collisions < target and core.time >= t_end:
                raise EngineError(f"run.unit = 'collisions': no events are left after "
                                  f"{core.collisions} pair collisions (the particles no longer "
                                  f"meet), so the count {target} cannot be reached")
            if reached and by_time and core.time >= state.next_servo_time:
                self._servo_update(core, state)
                if core.time >= t_end:
                    return
                continue
            if reached:
                return
            if by_count and core.collisions >= state.next_servo:
                self._servo_update(core, state)
                continue
            if target and core.collisions >= target:
                return
            if self.stop.reason is not None:
                raise _StopInInterval
            raise EngineError(f"the collision count {target} was not reached within {guard} "
                              f"events (pair and wall collisions, cell crossings, stale "
                              f"predictions) after t = {core.time:.6g}: a run counted in pair "
                              f"collisions cannot go on")

    def _sample(self, core: EventDriven, state: EdmdRunState, production: bool) -> None:
        dim, t = self.scene.dimension, core.time
        n = self.n
        velocity = core.velocities()[:n]
        kinetic = core.kinetic_energy
        state.record("time", t)
        state.record("momentum", np.sum(self.mass[:, None] * velocity, axis=0))
        state.record("kinetic_energy", kinetic)
        state.record("rotational_energy", core.rotational_energy)
        state.record("collisions", core.collisions)
        state.record("wall_collisions", core.wall_collisions)
        state.record("dissipated_energy", core.dissipated)
        if self.scene.gravity is not None:
            state.record("gravity_work", core.gravity_work)
        span = t - state.last_time
        impulses = self._impulses(core)
        for side, impulse in impulses.items():
            # force of the particles on the wall, averaged over the interval that just ended
            previous = state.last_impulse.get(side, impulse)
            force = -(impulse - previous)[:dim] / span if span > 0 else np.full(dim, np.nan)
            state.record(f"wall_force_{side}", force)
            state.record(f"wall_work_{side}", core.wall_work(0 if side == "lower" else 1))
        state.last_impulse = impulses
        if self.scene.shear is not None:
            state.record("tilt", self._tilt(core))
        if state.servo is not None:
            for side, wall in state.servo.walls.items():  # the core's positions are the truth
                wall.y = core.wall_position(0 if side == "lower" else 1)
            state.servo.t_last = t
            for key, value in state.servo.state().items():
                state.record(key, value)
            state.record("width", float(core.box[0]))
        if self.scene.y_periodic:
            virial = core.virial
            pressure = float("nan") if state.samples == 0 or span <= 0 else \
                (2 * kinetic / dim + (virial - state.last_virial) / (dim * span)) / self.volume
            state.last_virial = virial
            state.record("pressure", pressure)
        if self.stress:
            sums = core.stress_sums[:, :dim, :dim].transpose(0, 2, 1)  # P_ab = Σ J_a r_b
            if production and state.last_stress is not None:
                state.stress_chunks.append(sums - state.last_stress)
                state.stress_durations.append(span)
            state.last_stress = sums
        log = core.take_log() if self.log_every > 0 else {}
        if production and log and state.logged < LOG_CAPACITY:
            keep = min(len(log["time"]), LOG_CAPACITY - state.logged)
            for key, value in log.items():
                state.log.setdefault(key, []).append(value[:keep])
            state.logged += keep
        state.last_time = t
        snapshot = self.scene.gravity is not None and state.samples in (self.n_eq, self.n_total)
        if not (production or snapshot):
            return
        position = core.positions()[:n]
        if snapshot:
            snap = momentum_snapshot(t, position[:, 1], self.mass[:, None] * velocity)
            if state.samples == self.n_eq:
                state.momentum_start = snap
            else:
                state.momentum_end = snap
        if not production:
            return
        lo, hi = np.zeros(dim), np.asarray(core.box, float)
        if not self.scene.y_periodic:
            lo[1] = core.wall_position(0) if self.scene.wall("lower") else 0.0
            hi[1] = core.wall_position(1) if self.scene.wall("upper") else hi[1]
        frame = Frame(time=t, box_lo=lo, box_hi=hi, position=position,
                      velocity=velocity, angular_velocity=core.angular_velocities()[:n],
                      radius=self.radius, tilt=self._tilt(core))
        if state.profiles is None:  # servo: bins between the walls where production starts
            state.profiles = profile_analysis(self.scene, (float(lo[1]), float(hi[1])))
            if self.stress:  # the collisional stress in the same bins, from now on
                self.stress_edges = bin_edges(lo[1], hi[1], self.scene.measure.bin_width)
                n_bins = len(self.stress_edges) - 1
                core.set_stress_bins(float(lo[1]), float((hi[1] - lo[1]) / n_bins), n_bins)
                state.stress_edges = self.stress_edges
                state.stress_chunks, state.stress_durations = [], []
                state.last_stress = core.stress_sums[:, :dim, :dim].transpose(0, 2, 1)
        state.profiles.feed(frame)
        if self.keep_frames:
            keep_frame(state.frames, frame)

    # -- main loop ------------------------------------------------------------------------
    def _request_stop(self) -> None:
        self.stop.request()

    def run(self) -> Path:
        self.stop = StopRequest(self.options.wall_limit)
        # Ctrl-C from here on is a stop request, never a traceback: taken between two event
        # chunks or at the next sample (after a checkpoint); during the set-up the run stops
        # after its first chunk, during the final write it is ignored (the results are written)
        with self.stop:
            core, state = self._start()
            started = time.perf_counter()
            if state.samples == 0 and not state.timeseries:
                self._sample(core, state, production=False)
            self._loop(core, state, started)
            state.wall_seconds += time.perf_counter() - started
            return self._write(core, state)

    def _loop(self, core: EventDriven, state: EdmdRunState, started: float) -> None:
        unit = "coll/N" if self.by_collisions else "τ"
        bar = tqdm(total=self.n_total * self.dt, initial=state.samples * self.dt, unit=unit,
                   disable=not self.options.progress,
                   bar_format="{l_bar}{bar}| {n:.1f}/{total:.1f} " + unit +
                   " [{elapsed}<{remaining}]",
                   desc=f"edmd {self.scene.meta.name}")
        with bar:
            while state.samples < self.n_total:
                state.samples += 1
                try:
                    self._advance_interval(core, state)
                except _StopInInterval:
                    # a stop asked for between two event chunks: the core is synchronised
                    # there, and the resumed run redoes this interval from that point (its
                    # chunks start where this one ended, so it continues bit-identically)
                    state.samples -= 1
                    self._checkpoint(core, state, started)
                    raise RunStopped(
                        f"stopped ({self.stop.reason}) at t = {core.time:.6g}, inside a sample "
                        "interval, after a checkpoint: run the same command again with "
                        "--resume to continue") from None
                self._sample(core, state, production=state.samples > self.n_eq)
                bar.update(self.dt)
                checkpoint = self.n_ckpt and state.samples % self.n_ckpt == 0
                stop = self.stop.check()
                if (stop or checkpoint) and state.samples < self.n_total:
                    self._checkpoint(core, state, started)
                if stop and state.samples < self.n_total:
                    raise RunStopped(
                        f"stopped ({self.stop.reason}) at t = {core.time:.6g} after a "
                        "checkpoint: run the same command again with --resume to continue")

    def _write(self, core: EventDriven, state: EdmdRunState) -> Path:
        analysis = state.profiles.finish()
        scene = self.scene
        timeseries = {k: np.asarray(v) for k, v in state.timeseries.items()}
        frames = {k: np.asarray(v) for k, v in state.frames.items()} or None
        notes = [f"TC model (Luding & McNamara): a pair collision within t_c = {self.tc:g} "
                 "of either partner's previous collision is elastic (e = 1, no tangential "
                 f"impulse); {core.elastic_tc_collisions} such collisions"]
        if scene.gravity is not None and scene.walls:
            notes.append("particles pressed onto a wall by gravity leave it at least at "
                         "½ t_c |g_n| (a hop of period t_c: resting contact); "
                         f"{core.resting_bounces} such bounces")
        if state.servo is not None and state.servo.scale_width:
            notes.append("servo width scaling: x positions are rescaled affinely at each "
                         "servo update")
        equilibration_end = float(timeseries["time"][self.n_eq])
        attrs = run_attrs(scene, "edmd", ENGINE_VERSION, state.wall_seconds,
                          equilibration_end, timeseries)
        attrs.update(tc=self.tc, events=core.events, cell_crossings=core.cell_crossings,
                     wall_collisions=core.wall_collisions, approximations="\n".join(notes),
                     run_unit=scene.run.unit)
        groups, group_attrs = {}, {}
        collisional = None
        if self.stress and state.stress_chunks:
            section = self._cross_section(timeseries)
            collisional = collisional_stress(np.asarray(state.stress_chunks),
                                             np.asarray(state.stress_durations),
                                             self.stress_edges, section)
        if self.stress:
            stress, stress_attrs = stress_results(
                scene, analysis.results, timeseries, start=equilibration_end,
                collisional=collisional, momentum=(state.momentum_start, state.momentum_end))
            groups["stress"], group_attrs["stress"] = stress, stress_attrs
        if state.log:
            groups["collisions"] = {k: np.concatenate(v) for k, v in state.log.items()}
            group_attrs["collisions"] = {
                "log_every": self.log_every, "capacity": LOG_CAPACITY,
                "units": "d = 1, m = 1 (g = 1 with gravity); kind 0 pair, 1 lower wall, "
                         "2 upper wall; normal from i to j (or to the wall); branch r_j - r_i "
                         "(contact point - r_i for walls); impulse on i; velocity v_i - v_j "
                         "and spin_velocity (contact-point relative velocity) before"}
        path = write_results(self.out, Results(attrs, timeseries, analysis.results,
                                               analysis.attrs, frames, groups, group_attrs))
        (self.workdir / CHECKPOINT).unlink(missing_ok=True)
        if self.workdir.exists() and not any(self.workdir.iterdir()):
            self.workdir.rmdir()
        return path

    def _cross_section(self, timeseries: dict[str, np.ndarray]) -> float:
        """Bin cross-section: the (mean production) periodic width × depth."""
        size = list(self.scene.box.size)
        if "width" in timeseries:
            size[0] = float(np.mean(timeseries["width"][self.n_eq:]))
        return float(np.prod([size[i] for i in range(self.scene.dimension) if i != 1]))
