"""The contacts touching now, found from the gathered particles, for the contact health of
a LIGGGHTS run (:mod:`demstudy.contact.health`).

Dimensionless particle units: d = 1, m = 1 (m = d^dim), g = 1 when gravity acts.

LIGGGHTS's contacts are exactly the overlapping pairs (a Hooke contact acts while
r_i + r_j − |x_i − x_j| > 0), so they are found from the positions LIGGGHTS gives every
sample (a k-d tree, periodic along x and z, and y when y is periodic) rather than from a
local compute: pairs of mobile particles, mobile particles on a flat wall plane, and mobile
particles on a bump (which count as wall contacts, as in the LAMMPS backend).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ...contact.health import contact_sample, impact_speeds
from ...scene import Scene

__all__ = ["health_values"]


def _touching(x: np.ndarray, radius: np.ndarray, period: np.ndarray) -> np.ndarray:
    """Index pairs (i < j) of overlapping spheres; ``period`` 0 along a bounded axis."""
    lo = x.min(axis=0)
    shifted = x - lo
    box = np.where(period > 0, period, shifted.max(axis=0) * 3 + 4 * radius.max() + 1.0)
    shifted = np.where(period > 0, np.mod(x, np.where(period > 0, period, 1.0)), shifted)
    shifted = np.minimum(shifted, np.nextafter(box, 0))  # the tree wants [0, box)
    tree = cKDTree(shifted, boxsize=box)
    pairs = tree.query_pairs(2 * radius.max(), output_type="ndarray")
    return pairs.reshape(-1, 2)


def health_values(scene: Scene, x: np.ndarray, v: np.ndarray, radius: np.ndarray,
                  mobile: np.ndarray, kn: float, previous: np.ndarray | None
                  ) -> tuple[dict, np.ndarray]:
    """One sample's health values and pair keys (``contact_sample``) from every atom's
    position, velocity and radius (``mobile``: the particles, the rest bumps)."""
    dim = scene.dimension
    x, v = x[:, :dim], v[:, :dim]
    period = np.array(scene.box.size[:dim], dtype=float)
    if not scene.y_periodic:
        period[1] = 0.0
    pairs = _touching(x, radius, period)
    i, j = pairs[:, 0], pairs[:, 1]
    sep = x[i] - x[j]
    wrap = period > 0
    sep[:, wrap] -= period[wrap] * np.round(sep[:, wrap] / period[wrap])
    dist = np.linalg.norm(sep, axis=1)
    overlap = radius[i] + radius[j] - dist
    on = overlap > 0
    i, j, sep, dist, overlap = i[on], j[on], sep[on], dist[on], overlap[on]
    index = np.cumsum(mobile) - 1  # atom -> mobile particle
    both = mobile[i] & mobile[j]
    one = mobile[i] != mobile[j]
    wall_i = [np.where(mobile[i[one]], i[one], j[one])]
    wall_overlap = [overlap[one]]
    for wall in scene.walls:  # flat planes
        y0 = scene.wall_position(wall.side)
        gap = x[:, 1] - y0 if wall.side == "lower" else y0 - x[:, 1]
        touch = mobile & (radius - gap > 0)
        wall_i.append(np.flatnonzero(touch))
        wall_overlap.append((radius - gap)[touch])
    i, j, sep, dist, pair_overlap = i[both], j[both], sep[both], dist[both], overlap[both]
    vn = np.einsum("ij,ij->i", v[i] - v[j], sep) / np.maximum(dist, 1e-300)
    mass = (2 * radius) ** dim
    speeds = impact_speeds(vn, pair_overlap, kn, mass[i] * mass[j] / (mass[i] + mass[j]),
                           radius[i] * radius[j] / (radius[i] + radius[j]), "hooke")
    return contact_sample(int(mobile.sum()), index[i], index[j], pair_overlap,
                          index[np.concatenate(wall_i)], np.concatenate(wall_overlap),
                          speeds, previous)
