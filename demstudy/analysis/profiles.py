"""Volume-weighted (= mass-weighted) profiles across one axis with blocking/jackknife errors.

Dimensionless particle units: diameter d = 1, mass m = 1; uniform material density, so a
particle of radius r has mass m_i = V_i / V_1 (V_1 = pi/4 in 2D, pi/6 in 3D, the volume of
the unit particle) and mass weighting is volume weighting.
Axes: x flow, y wall-normal (the default profile axis), z spanwise (3D only).

Each frame every particle i is split exactly over the bins b by its overlap volume V_ib
(circular segments / spherical caps, :mod:`demstudy.analysis.volumes`), and the bin sums of
V, V v_a, V v_a v_b, V w_a, V j w_a, V j |w|^2, V j and V/V_i (j = I_i/m_i = K r_i^2) are fed to
a :class:`~demstudy.analysis.blocking.BlockAccumulator`, so memory is flat in the number of
frames. Averages <q> = sum_frames sum_i V_ib q_i / sum_frames sum_i V_ib are mass-weighted run
averages; fluctuations are relative to the bin's run-mean velocity <v> / spin <w>. With
<m>_b = mass per particle in the bin (fractional particle counts V_ib/V_i):

* velocity = <v>, spin = <w> (n_rot = 1 component in 2D, 3 in 3D),
* temperature_components_a = <m>_b <(v_a - <v_a>)^2>, temperature = their sum / dim: the
  per-degree-of-freedom particle temperature sum_i m_i v_i'^2 / (dim N_b); for equal
  particles of d = 1 simply <v_a'^2> (divide by mean_mass for the mass-weighted <v'^2>),
* kinetic_shear = <(u - <u>)(v - <v>)> (x, y components whatever the profile axis; the
  kinetic shear stress is -(phi / V_1) * kinetic_shear),
* rotational_temperature = <m>_b <(I/m)(w - <w>)^2> / n_rot = sum_i I_i w_i'^2 / (n_rot N_b),
  I = K m r^2 = K m d^2 / 4 with the reduced inertia K = 4 I / (m d^2),
* solid_fraction = per-frame sum_i V_ib / (width * cross-section of the frame's box),
  averaged over frames (the cross-section may change between frames),
* number_density = solid_fraction / (mean particle volume in the bin), mean_mass = <m>_b.

Standard errors (``*_err``) come from delete-one-block jackknife over time blocks. Empty bins
give NaN. A velocity gradient leaks into the temperature through the spread of the positions
that feed one bin: for u = g y and uniform density the extra <u'^2> is g^2 (w^2/12 + r^2/4)
for discs and g^2 (w^2/12 + r^2/5) for spheres (bin width w; r^2/4 and r^2/5 are the
variances of a particle's chord-length profile across a bin edge), 0.15 g^2 for w = d = 1
discs: keep w and the gradient small where this matters.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from demstudy import UNITS_NOTE
from demstudy.analysis.base import AnalysisBase
from demstudy.analysis.blocking import BlockAccumulator, jackknife
from demstudy.analysis.volumes import bin_profile_sums, profile_nvalues
from demstudy.io.frames import Frame

__all__ = ["ProfileAnalysis"]

AXES = {"x": 0, "y": 1, "z": 2}


class ProfileAnalysis(AnalysisBase):
    """Bin profiles of solid fraction, velocity, temperatures and spin along ``axis``.

    Parameters
    ----------
    axis: "x", "y" or "z" (or 0, 1, 2); bins are perpendicular to it.
    bin_width: requested width; the grid uses ``round((hi - lo)/bin_width)`` equal bins.
    lo, hi: grid range; None takes the first frame's box along the axis (or ``lo + period``).
    dim: 2 (discs) or 3 (spheres).
    inertia_factor: K = 4 I / (m d^2); None means a solid disc (1/2) or sphere (2/5).
    period: box length when the axis is periodic (0 = not periodic: the parts of particles
        outside the grid are dropped).
    max_blocks: bound on the stored time blocks (memory; see BlockAccumulator).
    edges: explicit uniformly spaced bin edges (overrides lo, hi, bin_width).
    image_velocity_shift: x velocity of the periodic image at ``+period`` relative to the
        particle (Lees-Edwards: shear rate * period); parts of a particle straddling the
        periodic boundary then enter the other end of the grid with that velocity offset.
    """

    def __init__(
        self,
        axis: str | int = "y",
        bin_width: float = 1.0,
        lo: float | None = None,
        hi: float | None = None,
        dim: int = 2,
        inertia_factor: float | None = None,
        period: float = 0.0,
        max_blocks: int = 64,
        edges: ArrayLike | None = None,
        image_velocity_shift: float = 0.0,
        verbose: bool = False,
    ) -> None:
        super().__init__(verbose=verbose)
        if dim not in (2, 3):
            raise ValueError(f"dim must be 2 or 3, got {dim!r}")
        self.axis = AXES.get(axis, -1) if isinstance(axis, str) else int(axis)
        if not 0 <= self.axis < dim:
            raise ValueError(f"axis {axis!r} does not exist in {dim}D")
        if not bin_width > 0:
            raise ValueError(f"bin_width must be positive, got {bin_width!r}")
        if period < 0:
            raise ValueError(f"period must be >= 0, got {period!r}")
        if image_velocity_shift and not period:
            raise ValueError("image_velocity_shift needs a periodic axis (period > 0)")
        if image_velocity_shift and self.axis == 0:
            raise ValueError("image_velocity_shift shifts x velocities: the axis cannot be x")
        self.dim = dim
        self.inertia_factor = float(
            inertia_factor if inertia_factor is not None else (0.5 if dim == 2 else 0.4)
        )
        self.period = float(period)
        self.max_blocks = int(max_blocks)
        self.image_velocity_shift = float(image_velocity_shift)
        self._bin_width, self._lo, self._hi = float(bin_width), lo, hi
        self._edges = None if edges is None else self._check_edges(edges)
        self.n_rot = 1 if dim == 2 else 3
        self._pairs = [(a, b) for a in range(dim) for b in range(a, dim)]
        # value columns (see volumes.bin_profile_sums): v | v_a v_b | w | j w | j w^2 | j | 1/V
        n_pairs = len(self._pairs)
        self._c_v = slice(0, dim)
        self._c_vv = slice(dim, dim + n_pairs)
        self._c_w = slice(self._c_vv.stop, self._c_vv.stop + self.n_rot)
        self._c_jw = slice(self._c_w.stop, self._c_w.stop + self.n_rot)
        self._c_jww = self._c_jw.stop
        self._c_j = self._c_jww + 1
        self._c_inv = self._c_j + 1
        self.n_values = profile_nvalues(dim)
        assert self.n_values == self._c_inv + 1
        self._unit_volume = np.pi / 4 if dim == 2 else np.pi / 6

    @staticmethod
    def _check_edges(edges: ArrayLike) -> np.ndarray:
        e = np.asarray(edges, dtype=np.float64)
        if e.ndim != 1 or e.size < 2 or not np.all(np.isfinite(e)):
            raise ValueError("edges must be a finite 1D array with at least 2 entries")
        d = np.diff(e)
        if not (np.all(d > 0) and np.allclose(d, d[0], rtol=1e-9, atol=0.0)):
            raise ValueError("edges must be increasing and uniformly spaced")
        return e

    # -- AnalysisBase hooks ------------------------------------------------------------
    def _prepare(self) -> None:
        frame = self.first_frame
        assert frame is not None
        if self._edges is not None:
            lo, hi, nbins = float(self._edges[0]), float(self._edges[-1]), self._edges.size - 1
        else:
            box_lo = float(np.asarray(frame.box_lo, float)[self.axis])
            box_hi = float(np.asarray(frame.box_hi, float)[self.axis])
            lo = box_lo if self._lo is None else float(self._lo)
            if self._hi is not None:
                hi = float(self._hi)
            else:
                hi = lo + self.period if self.period > 0 else box_hi
            if not hi > lo:
                raise ValueError(f"empty profile range [{lo}, {hi}]")
            nbins = max(1, int(round((hi - lo) / self._bin_width)))
        if self.period > 0 and hi - lo > self.period * (1 + 1e-9):
            raise ValueError(f"profile range {hi - lo} exceeds the period {self.period}")
        self.lo, self.hi, self.n_bins = lo, hi, nbins
        self.bin_width = (hi - lo) / nbins
        self.edges = lo + self.bin_width * np.arange(nbins + 1)
        self._acc = BlockAccumulator(nbins * (self.n_values + 2), self.max_blocks)
        self._sample = np.zeros(nbins * (self.n_values + 2))

    def _single_frame(self, frame: Frame) -> None:
        pos, vel, omega, radius = self._frame_arrays(frame)
        coord, period = pos[:, self.axis], self.period
        if self.image_velocity_shift:
            coord, radius, vel, omega = self._lees_edwards_images(coord, radius, vel, omega)
            period = 0.0
        nb = self.n_bins
        self._sample[:] = 0.0
        vol = self._sample[nb : 2 * nb]
        sums = self._sample[2 * nb :].reshape(nb, self.n_values)
        bin_profile_sums(
            coord,
            radius,
            vel,
            omega,
            self.inertia_factor,
            self.lo,
            self.bin_width,
            nb,
            self.dim,
            period,
            out_volume=vol,
            out_sums=sums,
        )
        section = float(np.prod(np.delete(frame.lengths, self.axis)))
        if not section > 0:
            raise ValueError(f"non-positive box cross-section {section} at t = {frame.time}")
        np.multiply(vol, 1.0 / (self.bin_width * section), out=self._sample[:nb])
        self._acc.add(self._sample)

    def _frame_arrays(self, frame: Frame) -> tuple[np.ndarray, ...]:
        pos = np.asarray(frame.position, dtype=np.float64)
        n = pos.shape[0]
        if pos.ndim != 2 or pos.shape[1] != self.dim:
            raise ValueError(f"position must have shape (N, {self.dim}), got {pos.shape}")
        vel = np.asarray(frame.velocity, dtype=np.float64)
        omega = np.asarray(frame.angular_velocity, dtype=np.float64)
        omega = omega[:, None] if omega.ndim == 1 else omega  # (N,) accepted in 2D
        radius = np.asarray(frame.radius, dtype=np.float64)
        if vel.shape != (n, self.dim):
            raise ValueError(f"velocity must have shape ({n}, {self.dim}), got {vel.shape}")
        if omega.shape != (n, self.n_rot):
            raise ValueError(f"angular_velocity must have {self.n_rot} components per particle")
        if radius.shape != (n,):
            raise ValueError(f"radius must have shape ({n},), got {radius.shape}")
        return pos, vel, omega, radius

    def _lees_edwards_images(
        self, coord: np.ndarray, radius: np.ndarray, vel: np.ndarray, omega: np.ndarray
    ) -> tuple[np.ndarray, ...]:
        """Explicit periodic images of boundary straddlers, with shifted x velocities."""
        lo, p = self.lo, self.period
        c = lo + np.mod(coord - lo, p)
        below, above = c - radius < lo, c + radius > lo + p
        img_v = [vel, vel[below].copy(), vel[above].copy()]
        img_v[1][:, 0] += self.image_velocity_shift  # image at c + P
        img_v[2][:, 0] -= self.image_velocity_shift  # image at c - P
        return (
            np.concatenate([c, c[below] + p, c[above] - p]),
            np.concatenate([radius, radius[below], radius[above]]),
            np.concatenate(img_v),
            np.concatenate([omega, omega[below], omega[above]]),
        )

    def _estimate(self, mean: np.ndarray) -> dict[str, np.ndarray]:
        nb, dim = self.n_bins, self.dim
        vol = mean[nb : 2 * nb]
        q = mean[2 * nb :].reshape(nb, self.n_values) / vol[:, None]
        v = q[:, self._c_v]
        cov = np.empty((nb, dim, dim))
        for k, (a, b) in enumerate(self._pairs):
            cov[:, a, b] = cov[:, b, a] = q[:, self._c_vv.start + k] - v[:, a] * v[:, b]
        mean_volume = 1.0 / q[:, self._c_inv]  # mass-weighted count -> volume per particle
        mean_mass = mean_volume / self._unit_volume
        comps = mean_mass[:, None] * np.stack([cov[:, a, a] for a in range(dim)], axis=1)
        w = q[:, self._c_w]
        jw = q[:, self._c_jw]
        t_rot = q[:, self._c_jww] - 2.0 * (w * jw).sum(1) + (w * w).sum(1) * q[:, self._c_j]
        return {
            "solid_fraction": mean[:nb],
            "number_density": mean[:nb] / mean_volume,
            "mean_mass": mean_mass,
            "velocity": v,
            "temperature": comps.sum(1) / dim,
            "temperature_components": comps,
            "kinetic_shear": cov[:, 0, 1],
            "spin": w,
            "rotational_temperature": mean_mass * t_rot / self.n_rot,
        }

    def _conclude(self) -> None:
        est, err = jackknife(self._acc, self._estimate)
        self.results = {"y": 0.5 * (self.edges[1:] + self.edges[:-1]), "edges": self.edges}
        for key in est:
            self.results[key] = est[key]
            self.results[f"{key}_err"] = err[key]
        axis_name = "xyz"[self.axis]
        self.attrs = {
            "axis": axis_name,
            "bin_width": self.bin_width,
            "samples": self.n_frames,
            "dim": self.dim,
            "lo": self.lo,
            "hi": self.hi,
            "n_bins": self.n_bins,
            "period": self.period,
            "inertia_factor": self.inertia_factor,
            "image_velocity_shift": self.image_velocity_shift,
            "block_length": self._acc.block_length,
            "n_blocks": self._acc.n_blocks,
            "units": UNITS_NOTE,
        }
