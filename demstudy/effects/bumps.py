"""Bumpy walls: the geometry of the bumps, the same in every engine.

Dimensionless particle units: d = 1, m = 1. A bumpy wall carries a row (2D) or square grid
(3D) of fixed particles centred on its plane, moving with the wall along x; ``random`` bumps
stand up to a quarter diameter proud of the plane (seeded from ``run.seed``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..scene import Scene
from ..scene.schema import Wall

__all__ = ["BumpRow", "bump_padding", "bump_rows", "bumpy_walls"]


@dataclass(frozen=True)
class BumpRow:
    side: str
    centres: np.ndarray  # (n, dim)
    diameter: float


def bumpy_walls(scene: Scene) -> list[Wall]:
    return [w for w in scene.walls if w.kind == "bumpy"]


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
        rows.append(BumpRow(wall.side, pts, b.diameter))
    return rows


def bump_padding(scene: Scene) -> float:
    """How far bumps reach beyond their wall plane."""
    return max((w.bumps.diameter * 0.5 + 1e-3 for w in bumpy_walls(scene)), default=0.0)
