"""One snapshot of the particles, the common currency between engines, readers and analyses.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.
Axes: x is the flow direction, y the wall-normal (profile) direction, z the spanwise
direction (3D only). ``dim`` is 2 for discs and 3 for spheres.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from demstudy.analysis.box import Box


#: key of the wall positions (y_lower, y_upper) in ``Frame.extra`` (walls that move)
WALLS = "walls"


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
    extra: additions: ``extra[WALLS]`` = (y_lower, y_upper), where walls that move (servo)
        stand at this frame (set by the simulation loop and by ``frames_of``;
        :mod:`demstudy.analysis.walls`); otherwise engine-specific.
    periodic_y: y is periodic (Lees-Edwards and homogeneous boxes); False: bounded (walls).
        x and z are always periodic. Engines and readers leave the default; the analyses
        take the periodicity from their own arguments (``periodic_y``, ``period``), which
        override this field (see :meth:`demstudy.analysis.box.Box.from_frame`).
    shear_velocity: x velocity of the upper periodic image relative to the original,
        shear rate * L_y (Lees-Edwards; 0 without shear or when unknown).
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
    periodic_y: bool = False
    shear_velocity: float = 0.0

    @property
    def dim(self) -> int:
        return int(self.position.shape[1])

    @property
    def n(self) -> int:
        return int(self.position.shape[0])

    @property
    def lengths(self) -> np.ndarray:
        return np.asarray(self.box_hi, float) - np.asarray(self.box_lo, float)

    @property
    def box(self) -> Box:
        """The :class:`~demstudy.analysis.box.Box` of this frame (x, z periodic; y periodic
        when ``periodic_y``, with the tilt and ``shear_velocity`` of its images). A tilt
        without ``periodic_y`` is refused: the frame is sheared but does not say so."""
        from demstudy.analysis.box import Box  # noqa: PLC0415 (analysis imports io)

        if self.tilt and not self.periodic_y:
            raise ValueError("a Lees-Edwards tilt with periodic_y=False: set periodic_y (and "
                             "shear_velocity), or build Box.from_frame(frame, periodic_y=...)")
        return Box.from_frame(self)
