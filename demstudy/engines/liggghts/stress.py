"""The contact stress of a LIGGGHTS run: per-bin sums of f_i ⊗ (r_i − r_j) over the contacts
of one step, as the LAMMPS backend sums them (:func:`demstudy.analysis.stress.branch_sums`).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.

Pairs come from ``compute pair/gran/local pos id force`` (columns x_i, x_j, id_i, id_j, a
periodic flag, the force on i). Its positions are the stored ones, not the periodic image
the contact is with, so the branch is folded to the minimum image here. LIGGGHTS 3.8's
library interface does not say how many rows a local compute has: ``compute reduce`` sums
and averages the id_i column, whose ratio is the count. Wall contacts come from each wall
fix's ``store_force`` per-atom array (the branch runs from the centre to the plane).
"""

from __future__ import annotations

import numpy as np

from ...analysis.stress import branch_sums
from ...scene import Scene
from .library import Liggghts

__all__ = ["STRESS_COMMANDS", "contact_stress_sums"]

PAIRS, PAIR_COUNT_SUM, PAIR_COUNT_AVE = "stress_pairs", "stress_n_sum", "stress_n_ave"
COLUMNS = 12  # x_i (3), x_j (3), id_i, id_j, periodic flag, f on i (3)
STRESS_COMMANDS = [
    f"compute {PAIRS} all pair/gran/local pos id force",
    f"compute {PAIR_COUNT_SUM} all reduce sum c_{PAIRS}[7]",
    f"compute {PAIR_COUNT_AVE} all reduce ave c_{PAIRS}[7]",
]


def _pair_count(lmp: Liggghts) -> int:
    total, mean = lmp.compute_scalar(PAIR_COUNT_SUM), lmp.compute_scalar(PAIR_COUNT_AVE)
    return 0 if mean == 0.0 else round(total / mean)


def contact_stress_sums(lmp: Liggghts, scene: Scene, x: np.ndarray, radius: np.ndarray,
                        types: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """(n_bins, dim, dim) sums of f_i ⊗ branch over this step's contacts; ``x``, ``radius``,
    ``types``: every atom by ID (bumps have types > 1)."""
    dim = scene.dimension
    rows = lmp.local_rows(PAIRS, _pair_count(lmp), COLUMNS)
    i, j = rows[:, 6].astype(np.int64) - 1, rows[:, 7].astype(np.int64) - 1
    force = rows[:, 9:12]
    sep = x[i] - x[j]
    period = np.array(scene.box.size + ([0.0] if dim == 2 else []), dtype=float)[:3]
    if not scene.y_periodic:
        period[1] = 0.0
    wrap = period > 0
    sep[:, wrap] -= period[wrap] * np.round(sep[:, wrap] / period[wrap])
    dist = np.linalg.norm(sep, axis=1)
    mobile = types == 1
    both = mobile[i] & mobile[j]
    ends = [(x[i[both], 1], force[both], sep[both])]
    for a, b, sign in ((i, j, 1.0), (j, i, -1.0)):  # mobile a on bump b: centre to contact
        sel = mobile[a] & ~mobile[b] & (dist > 0)
        reach = radius[a[sel]] - 0.5 * (radius[a[sel]] + radius[b[sel]] - dist[sel])
        unit = sign * sep[sel] / dist[sel, None]
        ends.append((x[a[sel], 1], sign * force[sel], unit * reach[:, None]))
    if scene.walls:
        ids = lmp.local_ids() - 1
        for wall in scene.walls:
            wall_force = np.zeros((len(x), 3))
            wall_force[ids] = lmp.fix_atom_rows(f"force_wall_{wall.side}", 3)
            on = np.flatnonzero(np.any(wall_force != 0.0, axis=1))
            branch = np.zeros((on.size, 3))
            branch[:, 1] = x[on, 1] - scene.wall_position(wall.side)
            ends.append((x[on, 1], wall_force[on], branch))
    y = np.concatenate([e[0] for e in ends])
    f = np.concatenate([e[1] for e in ends])[:, :dim]
    br = np.concatenate([e[2] for e in ends])[:, :dim]
    y_period = scene.box.size[1] if scene.y_periodic else 0.0
    return branch_sums(y, y - br[:, 1], f[:, :, None] * br[:, None, :], edges, y_period)
