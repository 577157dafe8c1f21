"""One snapshot of the particles, the common currency between engines, readers and analyses.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.
Axes: x is the flow direction, y the wall-normal (profile) direction, z the spanwise
direction (3D only). ``dim`` is 2 for discs and 3 for spheres.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Frame:
    """Particle state at one time.

    Attributes
    ----------
    time: simulation time.
    box_lo, box_hi: (dim,) box bounds; for an open boundary these are the current extent.
    position: (N, dim) centres, wrapped into the periodic box.
    velocity: (N, dim).
    angular_velocity: (N, n_rot) with n_rot = 1 in 2D (the z component) and 3 in 3D.
    radius: (N,).
    tilt: Lees-Edwards shift of the upper periodic image along x (0 without shear).
    """

    time: float
    box_lo: np.ndarray
    box_hi: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray
    radius: np.ndarray
    tilt: float = 0.0
    extra: dict = field(default_factory=dict)

    @property
    def dim(self) -> int:
        return int(self.position.shape[1])

    @property
    def n(self) -> int:
        return int(self.position.shape[0])

    @property
    def lengths(self) -> np.ndarray:
        return np.asarray(self.box_hi, float) - np.asarray(self.box_lo, float)
