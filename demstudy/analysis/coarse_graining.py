"""Gaussian coarse-grained profiles along one axis (the MercuryCG convention).

Dimensionless particle units: d = 1, m = 1; uniform material density, so a particle of
radius r has mass m_i = V_i / V_1 (V_1 = pi/4 in 2D, pi/6 in 3D). Axes: x flow, y wall-normal
(the default profile axis), z spanwise (3D).

Kernel (Weinhart et al., MercuryCG): a particle at coordinate y_i contributes to the field at
y with phi(y - y_i) = exp(-(y - y_i)^2 / (2 w^2)) / c_w for |y - y_i| <= 3 w and 0 beyond, with
c_w = sqrt(2 pi) w erf(3 / sqrt(2)) so that phi integrates to 1 over the cut-off domain.
Particles are points at their centres (no volume smearing); the fields are averaged over the
other directions (divided by the frame's cross-section A):

* number density n(y) = sum_i phi / A, solid fraction nu(y) = sum_i V_i phi / A,
  mass density rho(y) = nu / V_1,
* momentum density p_a(y) = sum_i m_i v_ia phi / A and velocity V = <p> / <rho> (NaN where
  no particle is within reach),
* kinetic stress sigma_ab(y) = <sum_i m_i v_ia v_ib phi / A> - <rho> V_a V_b, i.e.
  sum_i m_i v'_ia v'_ib phi with v' = v_i - V(y) relative to the run-mean field velocity at
  the CG point (MercuryCG's definition, time-averaged),
* temperature T(y) = tr(sigma) / (dim n): per degree of freedom, m <v'^2> / dim for d = 1.

<...> are averages over frames (the time-averaged fields, like the binned profiles). A
velocity gradient V' leaks into sigma through the kernel width: for uniform density sigma_aa
gains rho V_a'^2 s^2 with s^2 = w^2 (1 - 6 phi_N(3) / erf(3/sqrt 2)) = 0.97334 w^2 the
variance of the truncated Gaussian (phi_N the standard normal density). Near a wall
(distance < 3 w) the kernel mass beyond the wall is lost, so nu falls there (MercuryCG's
boundary effect; no boundary correction is applied).

Periodic axis: minimum image (3 w < period / 2 is required); with ``image_velocity_shift``
(Lees-Edwards: shear rate * period) the image at y + P has x velocity v_x + shift. Errors:
delete-one-block jackknife over time blocks (memory flat in the number of frames).
"""

from __future__ import annotations

from math import erf, sqrt

import numpy as np
from numpy.typing import ArrayLike

from demstudy import UNITS_NOTE
from demstudy.analysis.base import AnalysisBase
from demstudy.analysis.blocking import BlockAccumulator, jackknife
from demstudy.io.frames import Frame

__all__ = ["CoarseGrainedProfiles", "gaussian_kernel"]

AXES = {"x": 0, "y": 1, "z": 2}
CUTOFF = 3.0
#: variance of the Gaussian truncated at 3 w, in units of w^2
TRUNCATED_VARIANCE = 1.0 - 2 * CUTOFF * np.exp(-0.5 * CUTOFF**2) / np.sqrt(2 * np.pi) / erf(
    CUTOFF / sqrt(2.0))


def gaussian_kernel(s: ArrayLike, width: float) -> np.ndarray:
    """MercuryCG 1D Gaussian of standard deviation ``width``, cut off at 3 width and
    normalised on [-3 width, 3 width]."""
    s = np.asarray(s, float)
    norm = sqrt(2 * np.pi) * width * erf(CUTOFF / sqrt(2.0))
    return np.where(np.abs(s) <= CUTOFF * width, np.exp(-0.5 * (s / width) ** 2) / norm, 0.0)


class CoarseGrainedProfiles(AnalysisBase):
    """Gaussian coarse-grained nu, rho, velocity, kinetic stress and temperature along ``axis``.

    Parameters
    ----------
    width: w, the kernel's standard deviation (cut off at 3 w).
    points: evaluation points (uniformly spaced); None means ``n_points`` points at the
        centres of equal cells on [lo, hi] (or on the period).
    n_points: number of points when ``points`` is None (default: spacing about w / 2).
    axis, lo, hi, dim, period, image_velocity_shift, max_blocks: as in
        :class:`~demstudy.analysis.profiles.ProfileAnalysis`. With a period the points must
        be the cell centres of the period (the default).
    """

    def __init__(self, width: float = 0.5, points: ArrayLike | None = None,
                 n_points: int | None = None, axis: str | int = "y",
                 lo: float | None = None, hi: float | None = None, dim: int = 2,
                 period: float = 0.0, image_velocity_shift: float = 0.0,
                 max_blocks: int = 64, verbose: bool = False) -> None:
        super().__init__(verbose=verbose)
        if dim not in (2, 3):
            raise ValueError(f"dim must be 2 or 3, got {dim!r}")
        self.axis = AXES.get(axis, -1) if isinstance(axis, str) else int(axis)
        if not 0 <= self.axis < dim:
            raise ValueError(f"axis {axis!r} does not exist in {dim}D")
        if not width > 0:
            raise ValueError(f"width must be positive, got {width!r}")
        if period and CUTOFF * width > period / 2:
            raise ValueError("the kernel reach 3 w must be at most half the period")
        if image_velocity_shift and (not period or self.axis == 0):
            raise ValueError("image_velocity_shift needs a periodic axis other than x")
        self.width, self.dim, self.period = float(width), dim, float(period)
        self.image_velocity_shift = float(image_velocity_shift)
        self.max_blocks = int(max_blocks)
        self._points = None if points is None else np.asarray(points, float)
        if self._points is not None:
            d = np.diff(self._points)
            if self._points.ndim != 1 or self._points.size < 2 or not (
                    np.all(d > 0) and np.allclose(d, d[0], rtol=1e-9)):
                raise ValueError("points must be uniformly spaced and increasing")
        self._n_points, self._lo, self._hi = n_points, lo, hi
        self._pairs = [(a, b) for a in range(dim) for b in range(a, dim)]
        self._unit_volume = np.pi / 4 if dim == 2 else np.pi / 6

    def _prepare(self) -> None:
        frame = self.first_frame
        if frame.dim != self.dim:
            raise ValueError(f"frame is {frame.dim}D, analysis is {self.dim}D")
        if self._points is None:
            lo = float(frame.box_lo[self.axis]) if self._lo is None else float(self._lo)
            if self._hi is not None:
                hi = float(self._hi)
            else:
                hi = lo + self.period if self.period else float(frame.box_hi[self.axis])
            n = self._n_points or max(2, int(round((hi - lo) / (0.5 * self.width))))
            self.points = lo + (hi - lo) * (np.arange(n) + 0.5) / n
        else:
            self.points = self._points
        self.spacing = float(self.points[1] - self.points[0])
        if self.period and not np.isclose(self.spacing * self.points.size, self.period):
            raise ValueError("with a period the points must be the cell centres of the period")
        self._reach = int(np.ceil(CUTOFF * self.width / self.spacing)) + 1
        # per point: n | V | V v_a | V v_a v_b
        self._nv = 2 + self.dim + len(self._pairs)
        self._acc = BlockAccumulator(self.points.size * self._nv, self.max_blocks)

    def _single_frame(self, frame: Frame) -> None:
        pos = np.asarray(frame.position, float)
        vel = np.asarray(frame.velocity, float)
        radius = np.asarray(frame.radius, float)
        if pos.shape != (radius.size, self.dim) or vel.shape != pos.shape:
            raise ValueError("position / velocity / radius shapes do not match")
        g = self.points.size
        y = pos[:, self.axis]
        j0 = np.floor((y - self.points[0]) / self.spacing).astype(np.int64)
        offsets = np.arange(-self._reach + 1, self._reach + 1)
        j = j0[:, None] + offsets[None, :]  # (N, M) candidate points
        wraps = np.floor_divide(j, g) if self.period else np.zeros_like(j)
        jw = j - wraps * g
        s = self.points[0] + j * self.spacing - y[:, None]  # to the unwrapped point
        ok = (jw >= 0) & (jw < g) & (np.abs(s) <= CUTOFF * self.width)
        phi = np.where(ok, gaussian_kernel(s, self.width), 0.0)
        idx = np.where(ok, jw, 0).ravel()
        volume = (np.pi * radius**2 if self.dim == 2 else 4 / 3 * np.pi * radius**3)
        # the point jw = j - wraps * g sees the particle's image at y - wraps * P, whose x
        # velocity is v_x - wraps * shift
        v = np.broadcast_to(vel[:, None, :], (*j.shape, self.dim)).copy()
        v[..., 0] -= wraps * self.image_velocity_shift
        w_n = phi.ravel()
        w_v = (phi * volume[:, None]).ravel()
        vf = v.reshape(-1, self.dim)
        cols = [w_n, w_v] + [w_v * vf[:, a] for a in range(self.dim)]
        cols += [w_v * vf[:, a] * vf[:, b] for a, b in self._pairs]
        section = float(np.prod(np.delete(frame.lengths, self.axis)))
        sample = np.stack([np.bincount(idx, weights=c, minlength=g) for c in cols], axis=1)
        self._acc.add(sample / section)

    def _estimate(self, mean: np.ndarray) -> dict[str, np.ndarray]:
        s = mean.reshape(self.points.size, self._nv)
        dim, v1 = self.dim, self._unit_volume
        n, nu = s[:, 0], s[:, 1]
        rho = nu / v1
        vel = s[:, 2 : 2 + dim] / nu[:, None]
        stress = np.empty((s.shape[0], dim, dim))
        for k, (a, b) in enumerate(self._pairs):
            stress[:, a, b] = stress[:, b, a] = (s[:, 2 + dim + k] - nu * vel[:, a] * vel[:, b]
                                                 ) / v1
        return {
            "number_density": n,
            "solid_fraction": nu,
            "density": rho,
            "momentum_density": s[:, 2 : 2 + dim] / v1,
            "velocity": vel,
            "kinetic_stress": stress,
            "temperature": np.trace(stress, axis1=1, axis2=2) / (dim * n),
        }

    def _conclude(self) -> None:
        est, err = jackknife(self._acc, self._estimate)
        self.results = {"y": self.points}
        for key in est:
            self.results[key], self.results[f"{key}_err"] = est[key], err[key]
        self.attrs = {
            "axis": "xyz"[self.axis],
            "method": "gaussian",
            "width": self.width,
            "cutoff": CUTOFF * self.width,
            "kernel": "exp(-s^2/2w^2), cut off at 3w, normalised on the cut-off domain",
            "spacing": self.spacing,
            "dim": self.dim,
            "period": self.period,
            "image_velocity_shift": self.image_velocity_shift,
            "truncated_variance": TRUNCATED_VARIANCE * self.width**2,
            "samples": self.n_frames,
            "block_length": self._acc.block_length,
            "n_blocks": self._acc.n_blocks,
            "units": UNITS_NOTE,
        }
