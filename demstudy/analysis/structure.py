"""Campbell's (1982) structure distributions: the normal and the parallel pair distribution.

Dimensionless particle units: d = 1, m = 1 (Campbell's R = ½; his ST ≈ 2R = one diameter).

Test particles are those whose centre lies within ``half_width`` (Campbell: one strip, ST)
of the mid-plane y_mid (the channel centre, or the box centre with a periodic y). Around each
test particle, partners (every other particle, with the periodic images along x and z) are
counted

* **normal**: against |Δy|, in slices [r, r + dr) of the whole periodic cross-section — the
  density of particles at a distance |Δy| from a test particle, whatever their Δx;
* **parallel**: against the in-plane distance (|Δx| in 2D, √(Δx² + Δz²) in 3D) for partners
  with |Δy| < ``half_width``, in slices [r, r + dr).

Both are normalised by the number of test particles and the size of the sampling region, so
they are number densities (particles per unit area in 2D, per volume in 3D) whose dilute,
uncorrelated limit is the mean number density n = ν/(π R²) (2D) or ν/(π d³/6) (3D) — Campbell's
normalisation (thesis L1416–1424). Region sizes: normal slice 2 dr × W (× D); parallel slice
2 dr × 2 half_width in 2D and 2π r dr × 2 half_width in 3D. The normal distribution between walls
is not corrected for the walls (it falls where a slice leaves the channel, as in the thesis).
The listing's variant (range [0, INT(WL)], ±1 periodic images) is the same estimator on another
range. Errors: jackknife over time blocks. Periodic-image artefact: partners farther than W/2
along x are images of nearer ones; ``r_max`` must stay below W/2 (checked).

Geometry: a :class:`~demstudy.analysis.box.Box` with x (and z) periodic and y always bounded
(Campbell's distributions never look across y, whatever the boundary) wraps the centres; the
parallel partners come from its :class:`~demstudy.analysis.box.NeighbourQuery` and their
separations from :meth:`~demstudy.analysis.box.Box.minimum_image`.
"""

from __future__ import annotations

import numpy as np

from ..io.frames import Frame
from .base import AnalysisBase
from .blocking import BlockAccumulator, jackknife
from .box import Box, NeighbourQuery
from .walls import WallStrips

__all__ = ["StructureDistributions"]


class StructureDistributions(AnalysisBase):
    """Campbell's normal and parallel distributions (see the module docstring).

    dim: 2 or 3; r_max, dr: the slices; half_width: the test region and the parallel
    distribution's slab half-width (Campbell: ST ≈ 1 diameter); y_mid: the mid-plane (None:
    the middle of the frame's y range); max_blocks: bound on the stored time blocks;
    wall_relative: the mid-plane is that of each frame's walls (``frame.extra["walls"]``,
    walls that move: Campbell's |n − HGT/2| < ST with the current gap), ``y_mid`` unused.
    """

    # class defaults: instances pickled into checkpoints before these attributes existed
    # unpickle without them and resume with fixed strips (what they were built with)
    walls = None
    _y_mid_sum: float | None = None

    def __init__(self, dim: int = 2, r_max: float = 4.0, dr: float = 0.08,
                 half_width: float = 1.0, y_mid: float | None = None, max_blocks: int = 64,
                 wall_relative: bool = False, verbose: bool = False) -> None:
        super().__init__(verbose=verbose)
        if dim not in (2, 3):
            raise ValueError(f"dim must be 2 or 3, got {dim!r}")
        if not (r_max > 0 and dr > 0 and half_width > 0):
            raise ValueError("r_max, dr and half_width must be positive")
        self.dim, self.dr, self.half_width, self.y_mid = dim, float(dr), float(half_width), y_mid
        self.n_r = max(1, int(round(r_max / dr)))
        self.r_max = self.n_r * self.dr
        self.max_blocks = max_blocks
        self.walls = WallStrips(half_width, "StructureDistributions") if wall_relative else None
        self._y_mid_sum = 0.0

    def _prepare(self) -> None:
        limit = Box.from_frame(self.first_frame, periodic_y=False).image_limit
        if self.r_max > limit:
            raise ValueError(f"r_max = {self.r_max:g} exceeds half the periodic length "
                             f"{limit:g}: partners would be counted twice")
        self._acc = BlockAccumulator(2 * self.n_r + 1, self.max_blocks)

    def _single_frame(self, frame: Frame) -> None:
        box = Box.from_frame(frame, periodic_y=False)  # never across y (see the module doc)
        pos = box.wrap(frame.position).position
        lo, hi = box.lo, box.hi
        if self.walls is not None:  # the mid-plane of the frame's walls
            y_mid = 0.5 * sum(self.walls.walls(frame))
        else:
            y_mid = 0.5 * (lo[1] + hi[1]) if self.y_mid is None else self.y_mid
        if self._y_mid_sum is None:  # restored from a checkpoint pickled before the sum
            # existed: its frames used this same fixed mid-plane (walls were not followed)
            self._y_mid_sum = float(y_mid) * self.n_frames
        self._y_mid_sum += float(y_mid)
        test = np.flatnonzero(np.abs(pos[:, 1] - y_mid) < self.half_width)
        normal = np.zeros(self.n_r)
        # normal: every partner within r_max along y, whatever its x (z): a sorted sweep
        order = np.argsort(pos[:, 1], kind="stable")
        ys = pos[order, 1]
        for t in test:
            a, b = np.searchsorted(ys, [pos[t, 1] - self.r_max, pos[t, 1] + self.r_max])
            dy = np.abs(ys[a:b] - pos[t, 1])
            k = (dy / self.dr).astype(np.intp)
            normal += np.bincount(k[k < self.n_r], minlength=self.n_r)
            normal[0] -= 1  # the test particle itself (dy = 0)
        # parallel: partners within r_max in the plane and half_width across it
        reach = float(np.hypot(self.r_max, self.half_width))
        i, j, _ = NeighbourQuery(box, pos).pairs(reach, of=test)
        d = box.minimum_image(pos[j] - pos[i])
        inplane = np.abs(d[:, 0]) if self.dim == 2 else np.hypot(d[:, 0], d[:, 2])
        near = np.abs(d[:, 1]) < self.half_width
        parallel = np.bincount(np.minimum((inplane[near] / self.dr).astype(np.intp), self.n_r),
                               minlength=self.n_r + 1)[: self.n_r].astype(float)
        self._cross = float(np.prod([box.lengths[a] for a in range(self.dim) if a != 1]))
        self._acc.add(np.concatenate([normal, parallel, [float(test.size)]]))

    def _estimate(self, mean: np.ndarray) -> dict[str, np.ndarray]:
        n = self.n_r
        tests = max(mean[-1], 1e-300)
        r = self.dr * np.arange(n)
        normal_area = 2 * self.dr * self._cross
        if self.dim == 2:
            parallel_area = np.full(n, 2 * self.dr * 2 * self.half_width)
        else:  # annuli in the x-z plane, slab 2 half_width thick
            parallel_area = np.pi * ((r + self.dr) ** 2 - r**2) * 2 * self.half_width
        return {"normal": mean[:n] / tests / normal_area,
                "parallel": mean[n: 2 * n] / tests / parallel_area}

    def _conclude(self) -> None:
        est, err = jackknife(self._acc, self._estimate)
        r = self.dr * (np.arange(self.n_r) + 0.5)
        self.results = {"r": r, "normal": est["normal"], "normal_err": err["normal"],
                        "parallel": est["parallel"], "parallel_err": err["parallel"]}
        self.attrs = {"frames": self.n_frames, "dim": self.dim, "dr": self.dr,
                      "half_width": self.half_width,
                      "y_mid": self._y_mid_sum / self.n_frames,  # mean over the frames
                      "mid_plane": "between each frame's walls (they move)" if self.walls
                                   else "fixed",
                      "units": "number density (per area in 2D, per volume in 3D), d = 1",
                      "convention": "Campbell (1982): test particles within half_width of "
                                    "the mid-plane; normal vs |dy| over the whole section, "
                                    "parallel vs in-plane distance for |dy| < half_width"}
