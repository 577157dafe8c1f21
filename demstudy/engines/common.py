"""Bookkeeping every engine shares: stored frames, stop requests, checkpoints, result attrs.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.
"""

from __future__ import annotations

import pickle
import signal
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np

from ..analysis.steady import energy_trend, is_steady
from ..io.frames import Frame
from ..io.results import write_atomically
from ..scene import Scene, scene_to_toml

FRAME_ARRAYS = ("position", "velocity", "angular_velocity", "radius", "box_lo", "box_hi")


def keep_frame(frames: dict[str, list], frame: Frame) -> None:
    """Append one frame to the ``/frames`` lists (copies: engines reuse their buffers)."""
    for key in FRAME_ARRAYS:
        frames.setdefault(key, []).append(np.array(getattr(frame, key)))
    frames.setdefault("time", []).append(frame.time)
    frames.setdefault("tilt", []).append(frame.tilt)


def pickle_atomically(path: Path, obj: Any) -> None:
    """Pickle ``obj`` to ``path`` atomically (temporary file, fsync, rename): a checkpoint is
    whole or absent, also when the disk is full."""
    write_atomically(path, pickle.dumps(obj))


def load_checkpoint(path: Path, scene: Scene, keys: set[str], version: str,
                    engine: str) -> dict:
    """The pickled checkpoint dict at ``path`` for ``--resume``, refused (``EngineError``
    naming the file) when missing, unreadable, without the ``keys`` the engine needs (besides
    ``scene``), written by another ``version`` (a checkpoint continues only with the code that
    wrote it) or for a scene other than ``scene`` (naming the keys that differ)."""
    from .base import EngineError  # noqa: PLC0415

    if not path.exists():
        raise EngineError(f"--resume: no checkpoint in {path.parent}")
    try:
        with open(path, "rb") as fh:
            saved = pickle.load(fh)
    except Exception as exc:  # truncated, corrupt or written by other code
        raise EngineError(f"--resume: {path} is not readable ({type(exc).__name__}: {exc}); "
                          "remove it to start afresh") from exc
    if not isinstance(saved, dict):
        raise EngineError(f"--resume: {path} is not a checkpoint of the {engine} engine")
    written = saved.get("version", "an earlier version")
    if written != version:
        raise EngineError(f"--resume: {path} was written by {written}, this is {version}: a "
                          "checkpoint continues only with the code that wrote it (remove it "
                          "to start afresh)")
    if not keys | {"scene"} <= saved.keys():
        raise EngineError(f"--resume: {path} is not a checkpoint of the {engine} engine")
    if saved["scene"] != scene_to_toml(scene):
        raise EngineError("--resume: the checkpoint belongs to a different scene ("
                          f"{scene_difference(saved['scene'], scene)})")
    return saved


def scene_difference(saved_toml: str, scene: Scene, most: int = 3) -> str:
    """The scene a checkpoint was run with against ``scene``: the first ``most`` dotted keys
    whose values differ, e.g. "run.production: 4.0 in the checkpoint, 1.0 now"."""
    import tomllib  # noqa: PLC0415

    def flat(data: dict, prefix: str = "") -> dict:
        out = {}
        for key, value in data.items():
            if isinstance(value, dict):
                out.update(flat(value, f"{prefix}{key}."))
            else:
                out[f"{prefix}{key}"] = value
        return out

    old, new = flat(tomllib.loads(saved_toml)), flat(tomllib.loads(scene_to_toml(scene)))
    missing = object()
    diffs = [f"{k}: {old.get(k, 'unset')!r} in the checkpoint, {new.get(k, 'unset')!r} now"
             for k in sorted(old.keys() | new.keys())
             if old.get(k, missing) != new.get(k, missing)]
    more = f" and {len(diffs) - most} more" if len(diffs) > most else ""
    return "; ".join(diffs[:most]) + more


def run_attrs(scene: Scene, engine: str, version: str, wall_seconds: float,
              equilibration_end: float, timeseries: dict[str, np.ndarray]) -> dict[str, Any]:
    """Root attributes every results file carries, with Campbell's steadiness verdict over the
    production samples (those after ``equilibration_end``)."""
    t = timeseries["time"]
    production = t > equilibration_end + 1e-9 * max(1.0, abs(equilibration_end))
    trend = energy_trend(t[production], timeseries["kinetic_energy"][production])
    return {
        "engine": engine,
        "engine_version": version,
        "scene_toml": scene_to_toml(scene),
        "scene_name": scene.meta.name,
        "seed": scene.run.seed,
        "wall_seconds": wall_seconds,
        "equilibration_end": equilibration_end,
        "kinetic_energy_trend": trend,
        "steady": is_steady(trend),
    }


class StopRequest:
    """Ctrl-C (SIGINT, main thread only) or a wall-clock limit asks the run loop to stop at
    the end of its current segment; ``with StopRequest(limit) as stop: … stop.reason``."""

    def __init__(self, wall_limit: float | None):
        self.wall_limit = wall_limit
        self.reason: str | None = None
        self.started = time.perf_counter()
        self._previous = None

    def request(self, _signum=None, _frame=None) -> None:
        self.reason = self.reason or "interrupted"

    def check(self) -> bool:
        """True once a stop was asked for (checks the wall-clock limit too)."""
        elapsed = time.perf_counter() - self.started
        if self.wall_limit is not None and elapsed > self.wall_limit:
            self.reason = self.reason or "wall-clock limit"
        return self.reason is not None

    def __enter__(self) -> StopRequest:
        if threading.current_thread() is threading.main_thread():
            self._previous = signal.signal(signal.SIGINT, self.request)
        return self

    def __exit__(self, *exc) -> None:
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)
