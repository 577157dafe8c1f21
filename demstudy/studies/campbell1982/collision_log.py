"""The Campbell study's collision-log helpers, shared by the chute and Couette parts: which
part of a production the log spans, and the share of collisions in the approach quadrant.

Dimensionless particle units: d = 1, m = 1 (g = 1 in the chutes; the wall speed U_T in the
Couette cells). θ is the text's angle: the line of centres from the flow direction, 0-180°.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np


def log_window_of(path: Path, res: Any) -> tuple[float, float, float, float]:
    """:func:`log_window` of a file read without its log (its times alone, from the file)."""
    import h5py

    with h5py.File(path, "r") as f:
        times = f["collisions/time"][...] if "collisions/time" in f else np.zeros(0)
    return log_window(times, res)


def log_window(times: np.ndarray, res: Any) -> tuple[float, float, float, float]:
    """(first, last logged collision time, start, end of the production) of a run whose log
    holds ``times``: the engine keeps the production's first 2·10⁵ collisions
    (demstudy.engines.backend.LOG_CAPACITY, wall collisions included), so a long run's
    collision statistics cover only its start. NaN for the window without a log."""
    t = np.asarray(times, float)
    end = float(np.asarray(res.timeseries["time"], float)[-1]) if res.timeseries else math.nan
    start = float(res.attrs.get("equilibration_end", 0.0))
    if t.size == 0:
        return math.nan, math.nan, start, end
    return float(t.min()), float(t.max()), start, end


def logged_fraction(window: tuple[float, float, float, float]) -> float:
    """The share of the production its collision log spans."""
    _t0, t1, start, end = window
    return (t1 - start) / (end - start) if end > start else math.nan


def approach_share(p: np.ndarray, err: np.ndarray, theta: np.ndarray) -> tuple[float, float]:
    """Share of collisions with θ (text convention) in the approach quadrant 90°-180°."""
    width = math.pi / theta.size
    sel = theta > math.pi / 2
    return float(np.sum(p[sel]) * width), float(np.sqrt(np.sum(err[sel] ** 2)) * width)
