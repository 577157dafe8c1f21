"""Exact particle/bin overlap volumes (typed wrappers around the native module).

Dimensionless particle units: diameter d = 1, mass m = 1. "Volume" is the area of a disc
(``dim = 2``) or the volume of a sphere (``dim = 3``). Bins are strips (2D) or slabs (3D)
perpendicular to one axis: bin b covers ``lo + b*width <= y < lo + (b+1)*width``.

The closed forms are the circular-segment area and the spherical-cap volume; a particle
whose centre is at ``c`` along the axis has the cumulative volume below ``c + s``

    2D: r^2 (pi/2 + asin(s/r)) + s sqrt(r^2 - s^2),      3D: pi h^2 (3r - h) / 3,  h = r + s,

and its overlap with a bin is the difference of this at the two bin edges. The compiled
module ``demstudy._native`` is required (there is no pure-Python fallback).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from demstudy import _native

__all__ = [
    "bin_overlaps",
    "bin_profile_sums",
    "disc_strip_area",
    "particle_volume",
    "profile_nvalues",
    "sphere_slab_volume",
]

F64 = NDArray[np.float64]


def _check_dim(dim: int) -> int:
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 (discs) or 3 (spheres), got {dim!r}")
    return int(dim)


def _strip(c: ArrayLike, r: ArrayLike, lo: float, hi: float, dim: int) -> float | F64:
    if np.ndim(c) == 0 and np.ndim(r) == 0:
        if r < 0 or not math.isfinite(r):
            raise ValueError(f"radius must be finite and >= 0, got {r!r}")
        fn = _native.disc_strip_area if dim == 2 else _native.sphere_slab_volume
        return float(fn(float(c), float(r), float(lo), float(hi)))
    cb, rb = np.broadcast_arrays(np.asarray(c, np.float64), np.asarray(r, np.float64))
    if np.any(rb < 0) or not np.all(np.isfinite(rb)):
        raise ValueError("radius must be finite and >= 0")
    cc = np.ascontiguousarray(cb.ravel())
    rc = np.ascontiguousarray(rb.ravel())
    out = np.empty(cc.size)
    _native.strip_overlaps(cc, rc, float(lo), float(hi), dim, out)
    return out.reshape(cb.shape)


def disc_strip_area(c: ArrayLike, r: ArrayLike, lo: float, hi: float) -> float | F64:
    """Area of the disc (centre ``c`` along the axis, radius ``r``) inside ``lo <= y <= hi``.

    Scalars give a float; arrays broadcast and give an array. Zero when ``hi <= lo``.
    """
    return _strip(c, r, lo, hi, 2)


def sphere_slab_volume(c: ArrayLike, r: ArrayLike, lo: float, hi: float) -> float | F64:
    """Volume of the sphere (centre ``c`` along the axis, radius ``r``) inside ``lo <= y <= hi``.

    Scalars give a float; arrays broadcast and give an array. Zero when ``hi <= lo``.
    """
    return _strip(c, r, lo, hi, 3)


def particle_volume(radius: ArrayLike, dim: int) -> float | F64:
    """Particle volume: pi r^2 for discs (``dim = 2``), 4/3 pi r^3 for spheres (``dim = 3``)."""
    _check_dim(dim)
    r = np.asarray(radius, np.float64)
    v = np.pi * r**2 if dim == 2 else (4.0 / 3.0) * np.pi * r**3
    return float(v) if v.ndim == 0 else v


def _as_f64(name: str, a: ArrayLike, ndim: int) -> F64:
    arr = np.ascontiguousarray(a, dtype=np.float64)
    if arr.ndim != ndim:
        raise ValueError(f"{name} must be {ndim}-dimensional, got shape {arr.shape}")
    return arr


def _check_out(name: str, out: np.ndarray, shape: tuple[int, ...]) -> None:
    if not isinstance(out, np.ndarray) or out.dtype != np.float64:
        raise ValueError(f"{name} must be a float64 numpy array")
    if out.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {out.shape}")
    if not (out.flags.c_contiguous and out.flags.writeable):
        raise ValueError(f"{name} must be C-contiguous and writeable")


def bin_overlaps(
    coord: ArrayLike,
    radius: ArrayLike,
    values: ArrayLike | None,
    lo: float,
    width: float,
    nbins: int,
    dim: int,
    period: float = 0.0,
    out_volume: F64 | None = None,
    out_sums: F64 | None = None,
) -> tuple[F64, F64]:
    """Accumulate exact particle/bin overlaps: ``V[b] += V_ib``, ``S[b, :] += V_ib values[i, :]``.

    Parameters
    ----------
    coord, radius: (N,) particle centres along the binning axis and radii.
    values: (N, F) per-particle quantities to weight by overlap volume (None: F = 0).
    lo, width, nbins: the uniform grid ``lo + b*width``, b = 0..nbins.
    dim: 2 (discs; "volume" is area) or 3 (spheres).
    period: > 0 when the axis is periodic with this period (a particle straddling the
        periodic boundary contributes to the bins at both ends); the bins must then lie
        within one period. 0: parts outside ``[lo, lo + nbins*width]`` are dropped.
    out_volume, out_sums: (nbins,), (nbins, F) float64 C-contiguous accumulators, added to in
        place; allocated as zeros when None.

    Returns ``(out_volume, out_sums)``. Raises ValueError on bad shapes, dtypes or values.
    """
    dim = _check_dim(dim)
    c, r = _check_particles(coord, radius)
    n = c.shape[0]
    v = np.zeros((n, 0)) if values is None else _as_f64("values", values, 2)
    if v.shape[0] != n:
        raise ValueError(f"values must have shape ({n}, F), got {v.shape}")
    nbins = _check_grid(lo, width, nbins, period)
    out_volume, out_sums = _outputs(out_volume, out_sums, nbins, v.shape[1])
    _native.accumulate_bins(
        c, r, v, float(lo), float(width), nbins, dim, float(period), out_volume, out_sums
    )
    return out_volume, out_sums


def _check_particles(coord: ArrayLike, radius: ArrayLike) -> tuple[F64, F64]:
    c = _as_f64("coord", coord, 1)
    r = _as_f64("radius", radius, 1)
    if r.shape != c.shape:
        raise ValueError(f"radius must have shape {c.shape}, got {r.shape}")
    if not (np.isfinite(c).all() and np.isfinite(r).all()):
        raise ValueError("coord and radius must be finite")
    if r.size and r.min() < 0:
        raise ValueError("radius must be >= 0")
    return c, r


def _check_grid(lo: float, width: float, nbins: int, period: float) -> int:
    nbins = int(nbins)
    if nbins <= 0:
        raise ValueError(f"nbins must be positive, got {nbins}")
    if not (math.isfinite(width) and width > 0):
        raise ValueError(f"width must be finite and positive, got {width!r}")
    if not math.isfinite(lo):
        raise ValueError(f"lo must be finite, got {lo!r}")
    if not (math.isfinite(period) and period >= 0):
        raise ValueError(f"period must be finite and >= 0 (0 = not periodic), got {period!r}")
    if period > 0 and nbins * width > period * (1 + 1e-9):
        raise ValueError(f"bins span {nbins * width} > period {period}: they would double count")
    return nbins


def _outputs(
    out_volume: F64 | None, out_sums: F64 | None, nbins: int, nvalues: int
) -> tuple[F64, F64]:
    out_volume = np.zeros(nbins) if out_volume is None else out_volume
    out_sums = np.zeros((nbins, nvalues)) if out_sums is None else out_sums
    _check_out("out_volume", out_volume, (nbins,))
    _check_out("out_sums", out_sums, (nbins, nvalues))
    return out_volume, out_sums


def profile_nvalues(dim: int) -> int:
    """Number of value columns of :func:`bin_profile_sums`: 10 in 2D, 18 in 3D."""
    return int(_native.profile_nvalues(_check_dim(dim)))


def bin_profile_sums(
    coord: ArrayLike,
    radius: ArrayLike,
    velocity: ArrayLike,
    angular_velocity: ArrayLike,
    inertia_factor: float,
    lo: float,
    width: float,
    nbins: int,
    dim: int,
    period: float = 0.0,
    out_volume: F64 | None = None,
    out_sums: F64 | None = None,
) -> tuple[F64, F64]:
    """:func:`bin_overlaps` with the profile value columns built in the native loop.

    ``velocity`` is (N, dim), ``angular_velocity`` (N, n_rot) with n_rot = 1 in 2D, 3 in 3D.
    The columns of ``out_sums`` (F = :func:`profile_nvalues`) are the overlap-weighted sums of
    ``v_a`` (dim) | ``v_a v_b`` for a <= b, row-major (dim(dim+1)/2) | ``w_a`` (n_rot) |
    ``j w_a`` (n_rot) | ``j |w|^2`` | ``j`` | ``1/V``, with ``j = inertia_factor * r^2 = I/m``
    and V the particle volume (the last column sums to the fractional particle count).
    """
    dim = _check_dim(dim)
    c, r = _check_particles(coord, radius)
    n, nrot = c.shape[0], 1 if dim == 2 else 3
    v = _as_f64("velocity", velocity, 2)
    w = np.ascontiguousarray(angular_velocity, dtype=np.float64)
    w = w[:, None] if w.ndim == 1 else w  # (N,) accepted in 2D
    if v.shape != (n, dim):
        raise ValueError(f"velocity must have shape ({n}, {dim}), got {v.shape}")
    if w.shape != (n, nrot):
        raise ValueError(f"angular_velocity must have shape ({n}, {nrot}), got {w.shape}")
    if not math.isfinite(inertia_factor):
        raise ValueError(f"inertia_factor must be finite, got {inertia_factor!r}")
    nbins = _check_grid(lo, width, nbins, period)
    out_volume, out_sums = _outputs(out_volume, out_sums, nbins, profile_nvalues(dim))
    _native.accumulate_profile(
        c,
        r,
        v,
        w,
        float(inertia_factor),
        float(lo),
        float(width),
        nbins,
        dim,
        float(period),
        out_volume,
        out_sums,
    )
    return out_volume, out_sums
