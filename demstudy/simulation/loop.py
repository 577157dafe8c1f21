"""The one simulation loop: schedule, sampling, servo, stop requests, checkpoints, results.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise a wall speed
or the shear rate sets the time unit τ); with ``run.unit = 'collisions'`` the schedule counts
pair collisions per particle instead of time, with ``run.unit = 'steps'`` the lattice engine's
whole steps (``Backend.advance_steps``).

:class:`Simulation` runs a scene in any engine backend (:mod:`demstudy.engines.backend`):
samples every ``run.sample_interval`` from t = 0 (the initial state), equilibration and
production in whole sample intervals (time-stepped engines: in whole steps); at each sample
the timeseries (the engine's observables, the walls' mean forces over the interval that
ended, the Lees–Edwards tilt, the servo's state), and in production the profiles and the
streaming statistics of ``measure.statistics``, the frames when kept, the interaction stress
and the collision log. Campbell's servo is updated every servo interval (time-stepped
engines: at sample ends; event-driven ones: at exact times or collision counts). A stop
request (Ctrl-C or ``--wall-limit``) is honoured at the end of a sample, or between two
event chunks inside one, after a checkpoint; ``--resume`` continues from it. With MPI every
rank runs this loop with identical bookkeeping; rank 0 alone analyses and writes.
"""

from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from .. import UNITS_NOTE, __version__
from ..analysis.base import bin_edges
from ..analysis.registry import STATISTICS, Context
from ..analysis.stress import CollisionalSums, ContactStress, momentum_snapshot
from ..analysis.suite import profile_bounds
from ..analysis.walls import frame_walls, with_walls
from ..contact.health import warning_text
from ..effects.servo import ServoController, has_servo, servo_samples, servo_settings
from ..engines.backend import LOG_CAPACITY, BackendBase, Needs, frame_mass
from ..errors import RESUME_ADVICE, EngineError, RunAborted, RunStopped
from ..io.frames import Frame
from ..io.results import write_results
from ..scene import Scene, scene_to_toml
from .checkpoint import (
    CHECKPOINT,
    load_checkpoint,
    pickle_atomically,
    refuse_foreign_checkpoint,
    resume_note,
)
from .isolation import in_worker
from .options import RunOptions, check_run, frames_on_resume, work_folder
from .progress import PROGRESS, Progress, scene_digest, write_progress
from .results import run_results
from .schedule import Schedule, StopInInterval, StopRequest
from .state import RunState
from .tracks import MarkedTracks

__all__ = ["Simulation"]

# 2: RunState.health. RunState.tracks (marked grains' paths), RunState.marks (the run's
# pace at each checkpoint) and RunState.resumes came later without a new version: a
# checkpoint pickled before them unpickles with the class defaults (None, (), 0); only
# lattice scenes with marked grains have tracks (none were checkpointed before them), and a
# run resumed without marks has no pace until its next checkpoint
LOOP_VERSION = f"demstudy {__version__} (simulation loop 2)"
FRAME_ARRAYS = ("position", "velocity", "angular_velocity", "radius", "box_lo", "box_hi")


class Simulation:
    """Run ``scene`` in ``backend`` (a backend class) with ``options``; :meth:`run` returns
    the results file's path (on MPI ranks other than 0, the path it is written to)."""

    def __init__(self, scene: Scene, backend: type[BackendBase], options: RunOptions):
        self.scene, self.options = scene, options
        self.out = Path(options.out).resolve()
        self.workdir = work_folder(self.out, backend.name)
        check_run(backend, scene, options)
        self.backend = backend(scene, options, self.workdir)
        self.schedule = Schedule.of(scene, options, self.backend.time_step)
        statistics = scene.measure.statistics
        self.streams = [s for s in statistics if STATISTICS[s].source == "stream"
                        and s != "profiles"]
        # computed at the end: from the kept frames or log, then from the results so far (the
        # stress is the loop's own: the engine's interaction sums, accumulated on the way)
        self.measure_stress = "stress" in statistics
        self.after = sorted((s for s in statistics if STATISTICS[s].source != "stream"
                             and s != "stress"), key=lambda s: STATISTICS[s].source == "results")
        frames_needed = any(STATISTICS[s].source == "frames" for s in statistics)
        keep = options.keep_frames
        self.keep_frames = frames_needed or (scene.measure.keep_frames if keep is None else keep)
        log_every = int(options.extra.get("log_every", 0))
        if any(STATISTICS[s].log_every for s in statistics):
            log_every = log_every or 1
        self.log_every, self.log_capacity = log_every, LOG_CAPACITY
        self.servo_by_time = has_servo(scene) and (
            self.backend.capabilities.time_step or servo_settings(scene).interval_unit == "time")
        # the first Ctrl-C's notice comes from the process the user sees (an engine's child
        # leaves it to its parent)
        self.stop = StopRequest(options.wall_limit, None if in_worker() else backend.name)

    # -- set-up ---------------------------------------------------------------------------
    def _needs(self) -> Needs:
        bins = None
        if self.measure_stress:
            lo, hi, _period = profile_bounds(self.scene)
            bins = (lo, hi, len(bin_edges(lo, hi, self.scene.measure.bin_width)) - 1)
        return Needs(stress_bins=bins, log_every=self.log_every, log_capacity=self.log_capacity)

    def _start(self) -> RunState:
        backend, path = self.backend, self.workdir / CHECKPOINT
        if self.options.resume:
            saved = load_checkpoint(path, self.scene, {"run", "backend"}, self._version(),
                                    backend.name)
            state = saved["run"]
            state.resumes += 1
            self.keep_frames = frames_on_resume(self.options.keep_frames, state.keep_frames)
            backend.setup(self._needs(), saved["backend"], state.servo)
            return state
        refuse_foreign_checkpoint(path, self.out)
        servo = ServoController(self.scene) if has_servo(self.scene) else None
        state = RunState(keep_frames=self.keep_frames, servo=servo)
        needs = self._needs()
        backend.setup(needs, None, servo)
        if servo is None:  # servo: bins between the walls where production starts
            state.profiles = STATISTICS["profiles"].build(Context(self.scene))
            if needs.stress_bins is not None:
                lo, hi, _n = needs.stress_bins
                self._lay_stress_bins(state, bin_edges(lo, hi, self.scene.measure.bin_width))
        else:
            settings = servo_settings(self.scene)
            if self.servo_by_time:
                state.next_servo_time = settings.interval_time
            else:
                state.next_servo = self._servo_interval(settings)
            state.servo_impulse = backend.wall_impulse()
        return state

    def _version(self) -> str:
        return f"{LOOP_VERSION}; {self.backend.version}"

    # -- servo ----------------------------------------------------------------------------
    def _servo_interval(self, settings) -> int:
        """Pair collisions between two updates (Campbell: interval_collisions × N)."""
        return max(1, round(settings.interval_collisions * self.backend.n_particles))

    def _servo_update(self, state: RunState) -> None:
        """Campbell's servo step: the walls' mean normal forces on the particles since the
        previous update set their new normal velocities (:class:`ServoController`); the
        engine then moves its walls (and rescales the periodic width when asked)."""
        backend, servo = self.backend, state.servo
        t = backend.time
        impulses = backend.wall_impulse()
        span = max(t - state.servo_time, 1e-300)
        force = {side: float(impulses[side][1] - state.servo_impulse[side][1]) / span
                 for side in impulses}
        servo.update(t, force, backend.width())
        backend.move_walls(servo)
        state.servo_impulse, state.servo_time = impulses, t
        settings = servo_settings(self.scene)
        if backend.capabilities.time_step:  # at sample ends (``_sample_servo``)
            return
        if self.servo_by_time:
            state.next_servo_time += settings.interval_time
        else:
            state.next_servo += self._servo_interval(settings)

    # -- advancing ------------------------------------------------------------------------
    def _advance_interval(self, state: RunState) -> None:
        """Advance to sample ``state.samples``: a time, or a collision count with
        ``run.unit = 'collisions'``; event-driven servo updates happen on the way."""
        backend, sched = self.backend, self.schedule
        if sched.by_steps:  # whole lattice steps: no servo (lattice walls have none)
            if backend.advance_steps(round(state.samples * sched.interval), self.stop.check):
                return
            if self.stop.reason is not None:
                raise StopInInterval
            raise EngineError(f"the {backend.name} engine stopped at step {backend.steps} "
                              "before the sample's step count")
        if sched.by_collisions:
            t_end, target = 1e300, round(state.samples * sched.interval * backend.n_particles)
        else:
            t_end, target = state.samples * sched.interval, 0
        servo = state.servo is not None and not backend.capabilities.time_step
        by_time, by_count = servo and self.servo_by_time, servo and not self.servo_by_time
        while True:
            stops = [c for c in (target, state.next_servo if by_count else 0) if c > 0]
            t_stop = min(t_end, state.next_servo_time) if by_time else t_end
            reached = backend.advance(t_stop, min(stops, default=0), self.stop.check)
            if reached and target and backend.collisions < target and backend.time >= t_end:
                raise EngineError(f"run.unit = 'collisions': no events are left after "
                                  f"{backend.collisions} pair collisions (the particles no "
                                  f"longer meet), so the count {target} cannot be reached")
            if reached and by_time and backend.time >= state.next_servo_time:
                self._servo_update(state)
                if backend.time >= t_end:
                    return
                continue
            if reached:
                return
            if by_count and backend.collisions >= state.next_servo:
                self._servo_update(state)
                continue
            if target and backend.collisions >= target:
                return
            if self.stop.reason is not None:
                raise StopInInterval
            raise EngineError(f"the collision count {target} was not reached: the engine's "
                              f"event budget ran out at t = {backend.time:.6g}, so a run "
                              "counted in pair collisions cannot go on")

    def _sample_servo(self, state: RunState) -> None:
        """Time-stepped engines update the servo at the end of every m-th sample interval."""
        if state.samples % servo_samples(self.scene) == 0:
            self._servo_update(state)

    # -- sampling -------------------------------------------------------------------------
    def _sample(self, state: RunState, production: bool) -> None:
        backend, scene, dim = self.backend, self.scene, self.scene.dimension
        root = backend.rank == 0
        t = backend.time
        state.record("time", t)
        for key, value in backend.observe(production).items():
            state.record(key, value)
        span = t - state.last_time
        impulses = backend.wall_impulse()
        for side, impulse in impulses.items():
            # force of the particles on the wall, averaged over the interval that just ended
            previous = state.last_impulse.get(side, impulse)
            force = -(impulse - previous)[:dim] / span if span > 0 else np.full(dim, np.nan)
            state.record(f"wall_force_{side}", force)
        state.last_impulse = impulses
        if scene.shear is not None:
            state.record("tilt", backend.tilt())  # Lees–Edwards offset of the upper image
        if state.servo is not None:
            state.servo.advance(t)
            for side, y in (backend.wall_positions() or {}).items():
                state.servo.walls[side].y = y  # the engine's positions are the truth
            for key, value in state.servo.state().items():
                state.record(key, value)
            state.record("width", backend.width())
        rebinned = production and not state.in_production and self._begin_production(state)
        if state.stress is not None and (production or isinstance(state.stress,
                                                                  CollisionalSums)):
            sums = backend.stress_sums()  # collective on MPI ranks
            if root:  # cumulative sums count from the bins' first sample
                state.stress.add(sums, span if production and not rebinned else None,
                                 self._section() if production else 0.0)
        if self.log_every:
            self._keep_log(state, backend.take_collision_log(), production)
        self._keep_marked(state, t)
        state.last_time = t
        snapshot = scene.gravity is not None and state.samples in (self.schedule.n_eq,
                                                                   self.schedule.n_total)
        if not (production or snapshot):
            return
        frame = backend.frame()  # collective on MPI ranks
        if snapshot:
            snap = momentum_snapshot(t, frame.position[:, 1],
                                     frame_mass(frame)[:, None] * frame.velocity)
            if state.samples == self.schedule.n_eq:
                state.momentum_start = snap
            else:
                state.momentum_end = snap
        if production:
            self._production_frame(state, frame)
            self._health(state, t)

    def _keep_marked(self, state: RunState, t: float) -> None:
        """The marked grains at every sample, equilibration included (their paths)."""
        record = self.backend.marked()
        if record is None or self.backend.rank != 0:
            return
        if state.tracks is None:
            state.tracks = MarkedTracks.start(record)
        state.tracks.add(t, record)

    def _health(self, state: RunState, t: float) -> None:
        """The contact health of a soft-contact engine (those with ``health_sample``; a
        collective call on MPI ranks), kept per production sample."""
        sample = getattr(self.backend, "health_sample", None)
        if sample is None:
            return
        values = sample()
        if self.backend.rank == 0:
            state.health.setdefault("time", []).append(t)
            for key, value in values.items():
                state.health.setdefault(key, []).append(value)

    def _begin_production(self, state: RunState) -> bool:
        """Production starts: lay what is binned from now on; True when the interaction
        stress got new bins here (servo walls: between the walls where they stand now; the
        profiles and the other binned statistics follow the walls frame by frame)."""
        state.in_production = True
        walls = None
        if state.servo is not None:
            walls = (state.servo.walls["lower"].y, state.servo.walls["upper"].y)
            if self.backend.rank == 0:
                state.profiles = STATISTICS["profiles"].build(Context(self.scene, walls=walls))
        if self.backend.rank == 0:
            state.streams = {name: STATISTICS[name].build(Context(self.scene, walls=walls))
                             for name in self.streams}
        if walls is None or not self.measure_stress:
            return False
        edges = bin_edges(*walls, self.scene.measure.bin_width)
        self.backend.set_stress_bins(*walls, len(edges) - 1)
        self._lay_stress_bins(state, edges)
        return True

    def _production_frame(self, state: RunState, frame: Frame) -> None:
        if self.backend.rank != 0:
            return
        if state.servo is not None:  # walls that move: where they are at this frame
            walls = state.servo.walls  # (the engine's positions, set in ``_sample``)
            with_walls(frame, walls["lower"].y, walls["upper"].y)
        state.profiles.feed(frame)
        for analysis in state.streams.values():
            analysis.feed(frame)
        if self.keep_frames:
            for key in FRAME_ARRAYS:  # copies: engines reuse their buffers
                state.frames.setdefault(key, []).append(np.array(getattr(frame, key)))
            state.frames.setdefault("time", []).append(frame.time)
            state.frames.setdefault("tilt", []).append(frame.tilt)
            walls = frame_walls(frame)
            if walls is not None:
                state.frames.setdefault("walls", []).append(walls)

    def _lay_stress_bins(self, state: RunState, edges: np.ndarray) -> None:
        """Accumulate the interaction stress in ``edges`` from now on."""
        state.stress_edges = edges
        if self.backend.capabilities.stress == "collisional":
            state.stress = CollisionalSums()
        else:
            period = self.scene.box.size[1] if self.scene.y_periodic else 0.0
            state.stress = ContactStress(edges, self.scene.dimension, period)

    def _section(self) -> float:
        """The bins' cross-section now: periodic width (× depth in 3D)."""
        size = list(self.scene.box.size)
        size[0] = self.backend.width()
        return float(np.prod([size[i] for i in range(self.scene.dimension) if i != 1]))

    def _keep_log(self, state: RunState, log: dict | None, production: bool) -> None:
        if production and log and state.logged < self.log_capacity:
            keep = min(len(log["time"]), self.log_capacity - state.logged)
            for key, value in log.items():
                state.log.setdefault(key, []).append(value[:keep])
            state.logged += keep

    # -- checkpoints ----------------------------------------------------------------------
    def _checkpoint(self, state: RunState, started: float) -> None:
        saved = self.backend.get_state()  # collective on MPI ranks
        if self.backend.rank != 0:
            return
        self.workdir.mkdir(parents=True, exist_ok=True)
        wall = state.wall_seconds + time.perf_counter() - started
        done = self.schedule.done(self.backend, state.samples)  # a stop may land mid-interval
        state.marks = (*state.marks, (done, wall))
        snapshot = dataclasses.replace(state, wall_seconds=wall)
        scene_toml = scene_to_toml(self.scene)
        # the progress file describes the checkpoint written next; without it, none
        (self.workdir / PROGRESS).unlink(missing_ok=True)
        digest = pickle_atomically(
            self.workdir / CHECKPOINT,
            {"scene": scene_toml, "version": self._version(), "engine": self.backend.name,
             "out": str(self.out), "units": UNITS_NOTE, "backend": saved, "run": snapshot})
        self.backend.cleanup(saved)  # committed: the engine's older files go
        write_progress(self.workdir, Progress(done, self.schedule.n_total, self.backend.time,
                                              state.marks), digest, scene_digest(scene_toml))

    # -- main loop ------------------------------------------------------------------------
    def run(self) -> Path:
        backend = self.backend
        try:
            # Ctrl-C from here on is a stop request, never a traceback: taken between two
            # event chunks or at the next sample (after a checkpoint); during the set-up the
            # run stops after its first chunk; during the final write it is ignored
            with self.stop:
                state = self._start()
                started = time.perf_counter()
                if state.samples == 0 and not state.timeseries:
                    self._sample(state, production=False)  # the initial state
                self._loop(state, started)
                state.wall_seconds += time.perf_counter() - started
                extra = backend.result_attrs()
                if self.options.forecast is not None:  # next to wall_seconds: forecast vs actual
                    extra.update(self.options.forecast.attrs())
        except KeyboardInterrupt:  # a second Ctrl-C (or no handler: not the main thread)
            raise RunAborted(f"aborted by Ctrl-C at t = {backend.time:.6g}: "
                             f"{resume_note(self.workdir)}") from None
        finally:
            backend.close()
        path = self._write(state, extra) if backend.rank == 0 else self.out
        # MPI: no rank exits before rank 0 has written the results file (mpirun ends the
        # other ranks once one has exited: rank 0 was killed while writing, silently)
        backend.agree(False)
        return path

    def _loop(self, state: RunState, started: float) -> None:
        sched, backend = self.schedule, self.backend
        unit = "coll/N" if sched.by_collisions else "steps" if sched.by_steps else "τ"
        bar = tqdm(total=sched.n_total * sched.interval, initial=state.samples * sched.interval,
                   unit=unit, disable=not self.options.progress or backend.rank != 0,
                   mininterval=0.5 if sys.stderr.isatty() else 30.0,
                   bar_format="{l_bar}{bar}| {n:.1f}/{total:.1f} " + unit +
                   " [{elapsed}<{remaining}]", desc=f"{backend.name} {self.scene.meta.name}")
        with bar:
            while state.samples < sched.n_total:
                state.samples += 1
                try:
                    self._advance_interval(state)
                except StopInInterval:
                    # a stop asked for between two event chunks: the engine is synchronised
                    # there, and the resumed run redoes this interval from that point (its
                    # chunks start where this one ended, so it continues bit-identically)
                    state.samples -= 1
                    # the collisions logged on the way are the checkpoint's, not the engine's
                    self._keep_log(state, backend.take_collision_log(),
                                   state.samples + 1 > sched.n_eq)
                    self._checkpoint(state, started)
                    raise RunStopped(
                        f"stopped ({self.stop.reason}) at t = {backend.time:.6g}, inside a "
                        f"sample interval, after a checkpoint{RESUME_ADVICE}") from None
                if state.servo is not None and backend.capabilities.time_step:
                    self._sample_servo(state)
                self._sample(state, production=state.samples > sched.n_eq)
                bar.update(sched.interval)
                stop = backend.agree(self.stop.check())
                checkpoint = sched.n_ckpt and state.samples % sched.n_ckpt == 0
                if (stop or checkpoint) and state.samples < sched.n_total:
                    self._checkpoint(state, started)
                if stop and state.samples < sched.n_total:
                    raise RunStopped(
                        f"stopped ({self.stop.reason or 'on another rank'}) at t = "
                        f"{backend.time:.6g} after a checkpoint{RESUME_ADVICE}")

    # -- results ------------------------------------------------------------------------------
    def _write(self, state: RunState, extra: dict[str, Any]) -> Path:
        results = run_results(self, state, extra)
        path = write_results(self.out, results)
        (self.workdir / CHECKPOINT).unlink(missing_ok=True)
        (self.workdir / PROGRESS).unlink(missing_ok=True)
        self.backend.cleanup(None)
        if self.workdir.exists() and not any(self.workdir.iterdir()):
            self.workdir.rmdir()
        warning = warning_text(results.group_attrs.get("health", {}))
        if warning:  # the results stand, but not for the hard-particle limit
            print(warning, file=sys.stderr)
        for line in self.backend.end_notes(results.attrs):
            print(line, file=sys.stderr)
        failed = results.attrs.get("statistics_failed")
        if failed:  # the run's results are safe; say what is missing from them
            raise EngineError(f"the run finished and its results are in {path}, but these "
                              f"statistics could not be computed from them:\n{failed}")
        return path
