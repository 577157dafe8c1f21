"""Paths of marked grains: what the loop keeps of them at every sample (``/tracks``).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (the engine's time unit
otherwise). An engine whose scene has marked grains hands the loop, at every sample, a record
(:meth:`demstudy.engines.backend.BackendBase.marked`): the markers' numbers, positions and
velocities, and the periodic length along x (0: not periodic). The markers are those of the
first record (the initial state); a marker missing from a later record gets NaN there.

x is unwrapped across the periodic boundary, so that a path is continuous: between two samples
each marker is taken to have moved by the nearest periodic image of its displacement. That is
exact as long as no marker moves more than half the period between two samples (an LGD grain
moves at most one lattice spacing per step, so a sample interval below nxt/2 steps suffices).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["MarkedTracks"]


@dataclass
class MarkedTracks:
    """The marked grains' samples so far (pickled into checkpoints with the loop's state)."""

    mark: np.ndarray  # (k,) marker numbers, ascending
    period: float  # periodic length along x (0: none)
    time: list[float] = field(default_factory=list)
    position: list[np.ndarray] = field(default_factory=list)  # (k, dim) each, x unwrapped
    velocity: list[np.ndarray] = field(default_factory=list)  # (k, dim) each

    @classmethod
    def start(cls, record: dict[str, Any]) -> MarkedTracks:
        return cls(mark=np.sort(np.asarray(record["mark"], dtype=np.int64)),
                   period=float(record.get("period", 0.0)))

    def add(self, time: float, record: dict[str, Any]) -> None:
        """Append the sample ``record`` (mark (n,), position (n, dim), velocity (n, dim))
        taken at ``time``."""
        mark = np.asarray(record["mark"], dtype=np.int64)
        pos = np.asarray(record["position"], dtype=float)
        vel = np.asarray(record["velocity"], dtype=float)
        dim = pos.shape[1]
        where = {int(m): i for i, m in enumerate(mark)}
        rows = np.array([where.get(int(m), -1) for m in self.mark], dtype=np.int64)
        found = rows >= 0
        p = np.full((len(self.mark), dim), np.nan)
        v = np.full((len(self.mark), dim), np.nan)
        p[found], v[found] = pos[rows[found]], vel[rows[found]]
        if self.period > 0 and self.position:
            # the nearest image of each displacement: continuous paths across the boundary
            last = self._last_x()
            known = found & np.isfinite(last)
            step = p[known, 0] - last[known]
            p[known, 0] = last[known] + step - self.period * np.round(step / self.period)
        self.time.append(float(time))
        self.position.append(p)
        self.velocity.append(v)

    def _last_x(self) -> np.ndarray:
        """Each marker's latest known (unwrapped) x; NaN if never seen."""
        out = np.full(len(self.mark), np.nan)
        for p in reversed(self.position):
            todo = np.isnan(out)
            if not todo.any():
                break
            out[todo] = p[todo, 0]
        return out

    def results(self) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        """The ``/tracks`` group: datasets and attributes."""
        data = {"mark": self.mark, "time": np.asarray(self.time),
                "position": np.asarray(self.position), "velocity": np.asarray(self.velocity)}
        attrs = {"period_x": self.period,
                 "units": "d = 1, m = 1 (g = 1 with gravity); the engine's time unit",
                 "layout": "position, velocity: (samples, markers, dim); marker j is mark[j]; "
                           "NaN where a marker is absent from a sample",
                 "unwrapped": "x is unwrapped across the periodic x boundary (nearest image of "
                              "each displacement between samples): paths are continuous; "
                              "wrap with x mod period_x to get box coordinates"}
        return data, attrs
