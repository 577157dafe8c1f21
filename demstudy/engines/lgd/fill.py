"""Seeded random fills of a lattice rectangle (``[[lattice.fill]]``, an extension of Gutt's
(1989) initial-data format: the listing has no random fill; docs/lgd-engine.md).

Units: the listing's integers (user coordinates ix, iy; velocities in 1/256 "cm/s"); nothing
here is in demstudy's particle units (d = 1 = lattice spacing, m = 1, g = 1 with gravity).

A fill puts ``count`` grains (md 1) or wall particles (md −1), at rest or at one velocity,
with offset 0, on nodes of the user rectangle [x1, x2] × [y1, y2] that are empty when it is
applied. The nodes are drawn without replacement by numpy's ``Generator`` seeded with
``SeedSequence([seed, k])`` (k = the fill's place in the list, so two fills with one seed
draw independently) from the rectangle's empty nodes listed row by row (iy, then ix). The
result is md ±1 lines in that row order, so Gutt's file format represents it exactly (the
problem-file writer writes them), and a file written once keeps the layout even if a later
numpy draws differently (numpy does not promise one stream across versions, NEP 19).
"""

from __future__ import annotations

import numpy as np

from .lattice import EMPTY, Lattice
from .problem import MdLine, storage_column

__all__ = ["fill_count", "fill_lines"]


def fill_count(x1: int, y1: int, x2: int, y2: int, density: float | None,
               count: int | None) -> int:
    """Grains a fill places: ``count``, or round(density × nodes of the rectangle)."""
    if count is not None:
        return count
    nodes = (x2 - x1 + 1) * (y2 - y1 + 1)
    return int(np.floor(float(density) * nodes + 0.5))


def fill_lines(lat: Lattice, *, x1: int, y1: int, x2: int, y2: int, count: int, md: int,
               vx: int, vy: int, seed: int, index: int, where: str = "lattice.fill"
               ) -> list[MdLine]:
    """md ±1 lines of ``count`` nodes drawn from the empty nodes of the rectangle in ``lat``
    (module docstring). ValueError naming the fill when fewer nodes are empty."""
    nyt, nxt = lat.mlp.shape
    iy, ix = np.meshgrid(np.arange(y1, y2 + 1), np.arange(x1, x2 + 1), indexing="ij")
    iy, ix = iy.ravel(), ix.ravel()  # row by row: the order the draw indexes
    free = lat.mlp[iy - 1, storage_column(ix, iy, nxt)] == EMPTY
    n_free = int(np.count_nonzero(free))
    if count > n_free:
        raise ValueError(f"{where}: count = {count} grains but the rectangle x {x1}..{x2}, "
                         f"y {y1}..{y2} has {n_free} empty nodes when the fill applies "
                         f"(after the md lines and earlier fills); allowed: 1..{n_free}")
    rng = np.random.default_rng(np.random.SeedSequence([seed, index]))
    chosen = np.sort(rng.choice(n_free, size=count, replace=False))
    fx, fy = ix[free][chosen], iy[free][chosen]
    return [MdLine(md, int(x), int(y), 0, 0, vx, vy) for x, y in zip(fx, fy, strict=True)]
