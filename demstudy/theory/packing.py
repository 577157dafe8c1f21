"""Campbell's limiting packings of discs and his 2D -> 3D solid-fraction conversion.

* NU_HEXAGONAL = pi / (2 sqrt 3) = 0.9069: hexagonal packing, the maximum (unshearable).
* NU_SHEARABLE = pi / (sqrt 3 + 2 pi / 3) = 0.8210 (quoted ".822"): the densest shearable
  state, layers following each other's contours.
* NU_SQUARE = pi / 4 = 0.7854: square / parallelogram packing, layers slide freely.
* PHI_CUBIC = pi / 6 = 0.5236: simple cubic spheres.

Conversion (thesis L990-999), equal mean spacing in 2D and 3D: C_2D = R sqrt(pi/nu),
C_3D = R (4 pi / (3 nu_3D))^(1/3) give nu_3D = 4 / (3 sqrt(pi)) nu^(3/2) (Campbell:
"probably too small").
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "NU_HEXAGONAL",
    "NU_SHEARABLE",
    "NU_SQUARE",
    "PHI_CUBIC",
    "mean_spacing",
    "nu_2d_from_3d",
    "nu_3d_from_2d",
]

NU_HEXAGONAL = math.pi / (2 * math.sqrt(3))
NU_SHEARABLE = math.pi / (math.sqrt(3) + 2 * math.pi / 3)
NU_SQUARE = math.pi / 4
PHI_CUBIC = math.pi / 6

_K = 4 / (3 * math.sqrt(math.pi))


def nu_3d_from_2d(nu: ArrayLike) -> np.ndarray:
    """nu_3D = 4 / (3 sqrt pi) nu^(3/2)."""
    return _K * np.asarray(nu, float) ** 1.5


def nu_2d_from_3d(phi: ArrayLike) -> np.ndarray:
    """Inverse of :func:`nu_3d_from_2d`."""
    return (np.asarray(phi, float) / _K) ** (2 / 3)


def mean_spacing(nu: ArrayLike, dim: int, radius: float = 1.0) -> np.ndarray:
    """Campbell's mean spacing: R sqrt(pi/nu) (2D), R (4 pi / (3 nu))^(1/3) (3D)."""
    nu = np.asarray(nu, float)
    if dim == 2:
        return radius * np.sqrt(np.pi / nu)
    if dim == 3:
        return radius * np.cbrt(4 * np.pi / (3 * nu))
    raise ValueError(f"dim must be 2 or 3, got {dim!r}")
