"""Wall-relative strips: bins along y that move and stretch with walls that move.

Dimensionless particle units: d = 1, m = 1 (g = 1 when gravity acts).

Where the walls move during production (Campbell's stress servo, ``[walls.servo]``), strips
fixed in the lab smear the wall layers: a strip behind a wall is empty part of the time.
Campbell referred his strips to the walls instead: with n strips over the gap, the strip
width at each sample is ST = HGT/FND, the current gap over the number of strips (listing
L3689-3690, L3950), so strip k covers

    y_lower(t) + k H(t)/n  <=  y  <  y_lower(t) + (k + 1) H(t)/n,   H(t) = y_upper(t) − y_lower(t).

Equivalently every frame is mapped by the affine map y' = lo + (y − y_lower(t)) (hi − lo)/H(t)
onto the mean gap's grid [lo, hi] (lo, hi: the run means of the wall positions), and the
results are reported on that grid. The number of strips n = round(H_0 / bin_width) is
fixed by the first frame's gap H_0, the first production frame, so that the run and a
re-analysis of its stored frames agree (Campbell: FND = INT(HGT/ST), fixed when averaging
starts). Particle/strip overlaps are computed with the true radii in the frame's physical
strips, which is the affine map applied to the whole particle (volume ratios are kept).

Each frame carries its wall positions in ``frame.extra["walls"]`` = (y_lower, y_upper): the
simulation loop puts them there from the engine's walls, and frames read back from a results
file get them from the stored frames (``/frames/walls``) or, for older files, from the
servo's ``/timeseries/wall_position_lower`` / ``_upper`` at the frame's time.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np

from ..io.frames import WALLS, Frame

__all__ = ["CONVENTION", "FIXED", "WALLS", "WallStrips", "first_walls", "frame_walls",
           "walls_move", "with_walls"]

#: the attribute text of wall-relative bins
CONVENTION = ("wall-relative strips (Campbell's ST = HGT/FND): n strips between the frame's "
              "walls, moving and stretching with them; reported on the grid between the run "
              "means of the wall positions")
#: the attribute text of fixed bins
FIXED = "fixed strips in the lab frame"


def walls_move(scene: Any) -> bool:
    """The scene's walls move along y during the run (a ``[walls.servo]``; the only way a
    scene's wall positions change)."""
    return any(w.servo is not None for w in scene.walls) and not scene.y_periodic


def frame_walls(frame: Frame) -> tuple[float, float] | None:
    """(y_lower, y_upper) of the walls at the frame, None when the frame does not say."""
    walls = frame.extra.get(WALLS)
    if walls is None:
        return None
    lower, upper = (float(w) for w in walls)
    return lower, upper


def first_walls(frames: Callable[[], Iterable[Frame]] | None) -> tuple[float, float] | None:
    """The wall positions at the first of ``frames`` (a callable giving a fresh iterable):
    where fixed strips stand when the walls move (``wall_relative = False``)."""
    first = next(iter(frames()), None) if frames is not None else None
    return frame_walls(first) if first is not None else None


def strips_for(scene: Any, frames: Callable[[], Iterable[Frame]] | None,
               asked: bool | None, source: str = "these results") -> bool | None:
    """The ``wall_relative`` choice for re-analysing ``frames``: ``asked``, except that by
    default (None) frames carrying no wall positions (older or hand-made files) give fixed
    strips at the scene's walls, with a warning, instead of an error."""
    if asked is None and frames is not None and walls_move(scene) \
            and first_walls(frames) is None:
        warnings.warn(f"{source}: the frames carry no wall positions, so the y bins are "
                      "fixed strips at the scene's walls, not wall-relative ones",
                      stacklevel=3)
        return False
    return asked


def with_walls(frame: Frame, lower: float, upper: float) -> Frame:
    """``frame`` with its wall positions recorded (in place; returned for chaining)."""
    frame.extra[WALLS] = (float(lower), float(upper))
    return frame


class WallStrips:
    """n strips between each frame's walls; keeps the run means of the wall positions.

    :meth:`start` (first frame) fixes n from that frame's gap and ``bin_width`` (or takes
    ``n_bins`` when given);
    :meth:`strips` gives a frame's (y_lower, strip width) and, with ``record``, adds its walls
    to the means; :meth:`edges` is the grid between the mean walls.
    """

    def __init__(self, bin_width: float, owner: str, n_bins: int | None = None) -> None:
        if not bin_width > 0:
            raise ValueError(f"{owner}: bin_width must be positive, got {bin_width!r}")
        if n_bins is not None and not (isinstance(n_bins, int | np.integer) and n_bins >= 1):
            raise ValueError(f"{owner}: strips = {n_bins!r}: the number of wall-relative "
                             "strips must be an integer >= 1 (None: from the first gap)")
        self.bin_width, self.owner = float(bin_width), owner
        self._asked = None if n_bins is None else int(n_bins)
        self.n_bins = 0
        self._sums = np.zeros(2)
        self._gap_range = [np.inf, -np.inf]
        self.frames = 0

    def walls(self, frame: Frame) -> tuple[float, float]:
        walls = frame_walls(frame)
        if walls is None:
            raise ValueError(
                f"{self.owner}: wall_relative = True needs each frame's wall positions in "
                f"frame.extra[{WALLS!r}] = (y_lower, y_upper); the frame at t = {frame.time:g} "
                "has none (frames from the simulation loop and from results files of runs "
                "with moving walls carry them; use wall_relative = False for fixed strips)")
        if not walls[1] > walls[0]:
            raise ValueError(f"{self.owner}: frame.extra[{WALLS!r}] = {walls} at t = "
                             f"{frame.time:g}: the upper wall must lie above the lower one")
        return walls

    def start(self, frame: Frame) -> int:
        lower, upper = self.walls(frame)
        self.n_bins = self._asked or max(1, round((upper - lower) / self.bin_width))
        return self.n_bins

    def strips(self, frame: Frame, record: bool = True) -> tuple[float, float]:
        """(y_lower(t), H(t)/n) of ``frame``."""
        lower, upper = self.walls(frame)
        if record:
            self._sums += (lower, upper)
            self.frames += 1
            gap = upper - lower
            self._gap_range = [min(self._gap_range[0], gap), max(self._gap_range[1], gap)]
        return lower, (upper - lower) / self.n_bins

    def bin_of(self, frame: Frame, y: np.ndarray, record: bool = True) -> np.ndarray:
        """The strip of each y (−1 below the lower wall, n at or above the upper one)."""
        lower, width = self.strips(frame, record)
        return np.floor((np.asarray(y, float) - lower) / width).astype(np.intp).clip(-1,
                                                                                     self.n_bins)

    def mean_walls(self) -> tuple[float, float]:
        if not self.frames:
            raise ValueError(f"{self.owner}: no frame recorded")
        lower, upper = self._sums / self.frames
        return float(lower), float(upper)

    def edges(self) -> np.ndarray:
        lower, upper = self.mean_walls()
        return lower + (upper - lower) / self.n_bins * np.arange(self.n_bins + 1)

    def attrs(self) -> dict[str, Any]:
        lower, upper = self.mean_walls()
        return {"bins": CONVENTION, "wall_relative": True, "wall_lower_mean": lower,
                "wall_upper_mean": upper, "gap_mean": upper - lower,
                "gap_min": self._gap_range[0], "gap_max": self._gap_range[1]}
