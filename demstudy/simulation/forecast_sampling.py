"""What a run's sampling costs beyond the engine's gathering: the scene's own on-the-fly
analyses and kept frames per production sample, and its checkpoints, timed on this machine
for this scene at plan time (docs/forecast.md).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise a wall speed
or the shear rate sets the time unit τ); wall time in seconds.

Why measured per scene: the machine's benchmark runs feed only the profiles (every run's),
while g(r) costs ~0.3 s per frame of 24 400 particles and Campbell's structure ~0.15 s, and
a run that keeps its frames pickles all of them into every checkpoint. Both are timed on
synthetic frames of the scene's N in its box (uniform positions, Maxwellian velocities):
the analyses' work depends on N, the bins and the density, not on the flow's details.
"""

from __future__ import annotations

import math
import tempfile
import time
from pathlib import Path

import numpy as np

from ..scene import Scene

__all__ = ["analysis_seconds", "checkpoint_bytes", "checkpoint_seconds_per_byte", "frame_bytes",
           "production_samples", "synthetic_frame"]

def frame_bytes(dim: int) -> int:
    """Bytes a kept frame holds per particle: position, velocity (dim each), angular
    velocity (1 in 2D, 3 in 3D) and radius, float64 (``loop.FRAME_ARRAYS``)."""
    return 8 * (2 * dim + (1 if dim == 2 else 3) + 1)


#: the engine's own checkpoint state per particle (measured: 145 bytes for edmd in 3D) and a
#: full collision log's entry (time, i, j, kind, position, normal, velocity, impulse, …)
ENGINE_BYTES_PER_PARTICLE = 160
LOG_BYTES_PER_ENTRY = 140
#: synthetic frames timed per analysis after a first, untimed one (set-up): the median
TIMED_FRAMES = 1


def synthetic_frame(scene: Scene, seed: int = 0):
    """A frame of the scene's N particles spread uniformly in its box (half a diameter off
    the walls), Maxwellian velocities at T = 1: what the analyses are timed on."""
    from ..io.frames import Frame

    rng = np.random.default_rng(seed)
    dim, n = scene.dimension, scene.n_particles
    size = np.asarray(scene.box.size[:dim], float)
    position = rng.random((n, dim)) * np.maximum(size - 1.0, 1e-9) + 0.5
    return Frame(0.0, np.zeros(dim), size, position, rng.normal(size=(n, dim)),
                 rng.normal(size=(n, 1 if dim == 2 else 3)), np.full(n, 0.5),
                 periodic_y=scene.y_periodic)


def analysis_seconds(scene: Scene, keep_frames: bool) -> tuple[float, list[str]]:
    """Seconds per production sample of the scene's streaming statistics other than the
    profiles (the benchmark's ``atom_sample`` covers those) and of keeping the frame, timed
    on :func:`synthetic_frame`; and what was timed."""
    from ..analysis.registry import STATISTICS
    from ..scene import scene_to_toml

    names = [s for s in scene.measure.statistics
             if STATISTICS[s].source == "stream" and s != "profiles"]
    if not names and not keep_frames:
        return 0.0, []
    key = (scene_to_toml(scene), keep_frames)
    if key not in _TIMED:  # a plan forecasts twice (before and after its pilot)
        _TIMED[key] = _time_analyses(scene, names, keep_frames)
    return _TIMED[key]


_TIMED: dict[tuple[str, bool], tuple[float, list[str]]] = {}


def _time_analyses(scene: Scene, names: list[str], keep_frames: bool
                   ) -> tuple[float, list[str]]:
    from ..analysis.registry import STATISTICS, Context

    frame = synthetic_frame(scene)
    total, parts = 0.0, []
    for name in names:
        try:
            analysis = STATISTICS[name].build(Context(scene))
            seconds = _median_feed(lambda a=analysis: a.feed(frame))
        except Exception:  # noqa: BLE001 - the run itself reports an unusable statistic
            continue
        total += seconds
        parts.append(f"{name} {seconds * 1e3:.3g} ms")
    if keep_frames:
        keys = ("position", "velocity", "angular_velocity", "radius", "box_lo", "box_hi")
        seconds = _median_feed(lambda: [np.array(getattr(frame, k)) for k in keys])
        total += seconds
        parts.append(f"frame copy {seconds * 1e3:.3g} ms")
    return total, parts


def _median_feed(call) -> float:
    """The median time of ``TIMED_FRAMES`` calls after a first one (set-up, caches)."""
    call()
    times = []
    for _ in range(TIMED_FRAMES):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def checkpoint_bytes(scene: Scene, keep_frames: bool, interval: float | None,
                     log_every: int = 0, log_capacity: int = 0) -> tuple[int, float]:
    """The checkpoints of a run (every ``interval`` τ, none at its end) and the bytes they
    write in all: each pickles the engine's state, the frames kept so far (production only)
    and the collision log kept so far."""
    run = scene.run
    if not interval or run.unit != "time":
        return 0, 0.0
    total_samples = max(1, round((run.equilibration + run.production) / run.sample_interval))
    n_eq = round(run.equilibration / run.sample_interval)
    every = max(1, round(interval / run.sample_interval))
    n = scene.n_particles
    frame = frame_bytes(scene.dimension) * n if keep_frames else 0
    count, written = 0, 0.0
    for sample in range(every, total_samples, every):
        frames = max(0, sample - n_eq)
        logged = min(log_capacity, frames * n) if log_every else 0  # ≳ 1 per particle
        written += ENGINE_BYTES_PER_PARTICLE * n + frames * frame + logged * LOG_BYTES_PER_ENTRY
        count += 1
    return count, written


_IO_RATE: dict[str, float] = {}


def checkpoint_seconds_per_byte(folder: Path | None = None) -> float:
    """This machine's seconds per checkpoint byte (pickle, SHA-256, write, fsync: as
    ``checkpoint.pickle_atomically``), timed once per process on 16 MB in ``folder``."""
    key = str(folder)
    if key not in _IO_RATE:
        from .checkpoint import pickle_atomically

        payload = {"frames": [np.random.default_rng(0).random(2**18) for _ in range(8)]}
        size = sum(a.nbytes for a in payload["frames"])
        target = folder if folder is not None and folder.is_dir() else None
        with tempfile.TemporaryDirectory(prefix="demstudy-io-", dir=target) as tmp:
            start = time.perf_counter()
            pickle_atomically(Path(tmp) / "probe.pkl", payload)
            _IO_RATE[key] = (time.perf_counter() - start) / size
    return _IO_RATE[key]


def production_samples(scene: Scene) -> int:
    """Production samples of a run counted in time or collisions."""
    run = scene.run
    return max(1, round(run.production / run.sample_interval)) if math.isfinite(
        run.production) else 0
