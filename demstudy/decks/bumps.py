"""Bumpy walls: rows (2D) or square grids (3D) of heavy particles that move with their wall.

Dimensionless particle units: d = 1, m = 1. Each bumpy wall owns an atom type and a group
(type 2 for the first bumpy wall, 3 for the second), so each collides with its own wall rule
and moves with its own wall. Bumps are 1e6 times heavier than a particle of their size, so the
pair contact sees m_eff = m to 1 part in 1e6, and ``fix move`` prescribes their motion.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..scene import Scene
from ..scene.schema import Wall

MASS_FACTOR = 1e6


@dataclass(frozen=True)
class BumpRow:
    side: str
    atom_type: int
    centres: np.ndarray  # (n, dim)
    diameter: float

    @property
    def group(self) -> str:
        return bump_group(self.side)


def bump_group(side: str) -> str:
    """LAMMPS group (and ID prefix) of one wall's bumps."""
    return f"bumps_{side}"


def bumpy_walls(scene: Scene) -> list[Wall]:
    return [w for w in scene.walls if w.kind == "bumpy"]


def bump_type(scene: Scene, side: str) -> int:
    sides = [w.side for w in bumpy_walls(scene)]
    return 2 + sides.index(side)


def bump_rows(scene: Scene) -> list[BumpRow]:
    """Every bumpy wall's bumps: centres on the wall plane, spacing rounded so that a whole
    number fits the periodic length; ``random`` bumps stand up to a quarter diameter proud."""
    rows = []
    rng = np.random.default_rng(scene.run.seed + 7)
    for wall in bumpy_walls(scene):
        b = wall.bumps
        y0 = scene.wall_position(wall.side)
        nx = max(1, round(scene.box.size[0] / b.spacing))
        xs = (np.arange(nx) + 0.5) * scene.box.size[0] / nx
        if scene.dimension == 3:
            nz = max(1, round(scene.box.size[2] / b.spacing))
            zs = (np.arange(nz) + 0.5) * scene.box.size[2] / nz
            gx, gz = np.meshgrid(xs, zs, indexing="ij")
            pts = np.stack([gx.ravel(), np.full(gx.size, y0), gz.ravel()], axis=1)
        else:
            pts = np.stack([xs, np.full(nx, y0)], axis=1)
        if b.pattern == "random":
            sign = 1.0 if wall.side == "lower" else -1.0
            pts[:, 1] += sign * rng.uniform(0.0, 0.25 * b.diameter, len(pts))
        rows.append(BumpRow(wall.side, bump_type(scene, wall.side), pts, b.diameter))
    return rows


def bump_padding(scene: Scene) -> float:
    """How far bumps reach beyond their wall plane (the data file's box must hold them)."""
    return max((w.bumps.diameter * 0.5 + 1e-3 for w in bumpy_walls(scene)), default=0.0)


def n_atom_types(scene: Scene) -> int:
    return 1 + len(bumpy_walls(scene))
