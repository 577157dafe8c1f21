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

from ... import __version__
from ...analysis.profiles import ProfileAnalysis
from ...analysis.suite import profile_analysis
from ...decks.base import UnsupportedByEngine
from ...io.frames import Frame
from ...io.results import Results, write_results
from ...scene import Scene, scene_to_toml
from ...scene.initial import build_initial_state
from ..base import EngineError, RunOptions, RunStopped
from ..child import in_worker, launch_child
from ..common import StopRequest, keep_frame, pickle_atomically, run_attrs
from .core import DEFAULT_TC, EventDriven, from_initial_state, scene_parameters

CHECKPOINT = "checkpoint.pkl"
ENGINE_VERSION = f"demstudy-edmd {__version__} (milestone 1: periodic box, e, beta, K, TC)"


def check_supported(scene: Scene) -> dict:
    """Refuse every scene feature outside milestone 1; return e, β, K."""
    if scene.walls:
        raise UnsupportedByEngine("edmd", "walls", [w.side for w in scene.walls],
                                  "walls are not implemented yet (fully periodic boxes only)")
    if scene.gravity is not None:
        raise UnsupportedByEngine("edmd", "gravity", scene.gravity.magnitude,
                                  "gravity (parabolic flights) is not implemented yet")
    if scene.shear is not None:
        raise UnsupportedByEngine("edmd", "shear", scene.shear.rate,
                                  "Lees–Edwards shear is not implemented yet")
    if scene.run.unit != "time":
        raise UnsupportedByEngine("edmd", "run.unit", scene.run.unit,
                                  "run lengths in collisions are not implemented; use 'time'")
    missing = [a for a in "xyz"[:scene.dimension] if a not in scene.periodic]
    if missing:
        raise UnsupportedByEngine("edmd", "box.periodic", list(scene.periodic),
                                  "every axis must be periodic")
    d_max = 1.0 + scene.particles.diameter_spread / 2
    if min(scene.box.size) < 3 * d_max:
        raise UnsupportedByEngine("edmd", "box.size", list(scene.box.size),
                                  f"every box length must be at least 3 largest diameters "
                                  f"({3 * d_max:g}) for the cell lists")
    return scene_parameters(scene)


@dataclass
class EdmdRunState:
    """Everything needed to continue a run besides the core's own state."""

    samples: int = 0  # sample intervals done
    timeseries: dict[str, list] = field(default_factory=dict)
    frames: dict[str, list] = field(default_factory=dict)
    profiles: ProfileAnalysis | None = None
    wall_seconds: float = 0.0
    last_virial: float = 0.0
    keep_frames: bool = False  # fixed when the run starts, kept on resume

    def record(self, key: str, value) -> None:
        self.timeseries.setdefault(key, []).append(value)


class EdmdEngine:
    """``run(scene, options)``: event-driven hard discs/spheres (see the module docstring).

    ``options.extra["tc"]``: TC-model time (default ``DEFAULT_TC``; 0 switches it off).
    ``options.isolate`` runs it in a child process; ``options.np`` > 1 and ``options.dump``
    are refused (a serial engine; no LAMMPS dump)."""

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
        self.workdir = self.out.with_suffix(".edmd")
        run = scene.run
        self.dt = run.sample_interval
        self.n_eq = round(run.equilibration / self.dt)
        self.n_total = self.n_eq + max(1, round(run.production / self.dt))
        ckpt = options.checkpoint_interval or run.checkpoint_interval
        self.n_ckpt = max(1, round(ckpt / self.dt)) if ckpt else 0
        keep = options.keep_frames
        self.keep_frames = scene.measure.keep_frames if keep is None else keep
        self.volume = math.prod(scene.box.size)

    # -- state ----------------------------------------------------------------------------
    def _start(self) -> tuple[EventDriven, EdmdRunState]:
        initial = build_initial_state(self.scene)
        self.radius = initial.diameter / 2
        self.mass = initial.mass
        core = from_initial_state(initial, self.scene.box.size, tc=self.tc, **self.params)
        if not self.options.resume:
            return core, EdmdRunState(profiles=profile_analysis(self.scene),
                                      keep_frames=self.keep_frames)
        path = self.workdir / CHECKPOINT
        if not path.exists():
            raise EngineError(f"--resume: no checkpoint in {self.workdir}")
        with open(path, "rb") as fh:
            saved = pickle.load(fh)
        if saved["scene"] != scene_to_toml(self.scene) or saved["tc"] != self.tc:
            raise EngineError("--resume: the checkpoint belongs to a different scene")
        core.set_state(saved["core"])
        self.keep_frames = saved["run"].keep_frames  # frames for the whole run or not at all
        return core, saved["run"]

    def _checkpoint(self, core: EventDriven, state: EdmdRunState, started: float) -> None:
        self.workdir.mkdir(parents=True, exist_ok=True)
        snapshot = dataclasses.replace(
            state, wall_seconds=state.wall_seconds + time.perf_counter() - started)
        pickle_atomically(self.workdir / CHECKPOINT,
                          {"scene": scene_to_toml(self.scene), "tc": self.tc,
                           "core": core.get_state(), "run": snapshot})

    # -- sampling -------------------------------------------------------------------------
    def _sample(self, core: EventDriven, state: EdmdRunState, production: bool) -> None:
        dim, t = self.scene.dimension, core.time
        velocity = core.velocities()
        kinetic = core.kinetic_energy
        state.record("time", t)
        state.record("momentum", np.sum(self.mass[:, None] * velocity, axis=0))
        state.record("kinetic_energy", kinetic)
        state.record("rotational_energy", core.rotational_energy)
        state.record("collisions", core.collisions)
        state.record("dissipated_energy", core.dissipated)
        virial = core.virial
        if state.samples == 0:
            pressure = float("nan")
        else:
            pressure = (2 * kinetic / dim + (virial - state.last_virial) / (dim * self.dt)) \
                / self.volume
        state.last_virial = virial
        state.record("pressure", pressure)
        if not production:
            return
        frame = Frame(time=t, box_lo=np.zeros(dim), box_hi=np.asarray(self.scene.box.size, float),
                      position=core.positions(), velocity=velocity,
                      angular_velocity=core.angular_velocities(), radius=self.radius)
        state.profiles.feed(frame)
        if self.keep_frames:
            keep_frame(state.frames, frame)

    # -- main loop ------------------------------------------------------------------------
    def _request_stop(self) -> None:
        self.stop.request()

    def run(self) -> Path:
        core, state = self._start()
        started = time.perf_counter()
        self.stop = StopRequest(self.options.wall_limit)
        with self.stop:
            if state.samples == 0 and not state.timeseries:
                self._sample(core, state, production=False)
            self._loop(core, state, started)
        state.wall_seconds += time.perf_counter() - started
        return self._write(core, state)

    def _loop(self, core: EventDriven, state: EdmdRunState, started: float) -> None:
        bar = tqdm(total=self.n_total * self.dt, initial=state.samples * self.dt, unit="τ",
                   disable=not self.options.progress,
                   bar_format="{l_bar}{bar}| {n:.1f}/{total:.1f} τ [{elapsed}<{remaining}]",
                   desc=f"edmd {self.scene.meta.name}")
        with bar:
            while state.samples < self.n_total:
                state.samples += 1
                core.advance_to(state.samples * self.dt)
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
        notes = [f"TC model (Luding & McNamara): a collision within t_c = {self.tc:g} of "
                 "either partner's previous collision is elastic (e = 1, no tangential "
                 f"impulse); {core.elastic_tc_collisions} such collisions"]
        attrs = run_attrs(scene, "edmd", ENGINE_VERSION, state.wall_seconds,
                          self.n_eq * self.dt, timeseries)
        attrs.update(tc=self.tc, events=core.events, cell_crossings=core.cell_crossings,
                     approximations="\n".join(notes))
        path = write_results(self.out, Results(attrs, timeseries, analysis.results,
                                               analysis.attrs, frames))
        (self.workdir / CHECKPOINT).unlink(missing_ok=True)
        if self.workdir.exists() and not any(self.workdir.iterdir()):
            self.workdir.rmdir()
        return path
