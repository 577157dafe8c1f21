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

Malik's cell convention (``z_cells`` > 1, 3D, profile axis x or y; Malik 2008 §4.1: the
fluctuating velocities of the temperatures are taken "cellwise", about the means of cells that
split each bin into slabs along z; his number of z cells is not stated). Each particle's volume
is split over the bins exactly as above and goes to the z-slab of its centre (:func:`z_slab`,
the cells of :mod:`demstudy.analysis.vdf`), so summing the cells of a bin gives back the bin's
sums and every field above is unchanged. The cell mean is, as in the vdf, the run mean of the
cell (time-averaged, exact from the accumulated sums, one pass). Added fields, per bin, pooled
over its cells with the volume (mass) weights (C = cell, <.>_C its run mean):

* cell_temperature_components_a = sum_C sum_i V_iC (v_a - <v_a>_C)^2 / (V_1 N_b), i.e.
  <m>_b <(v_a - <v_a>_C)^2>_b, cell_temperature = their sum / dim,
* cell_rotational_temperature = sum_C sum_i V_iC j_i |w - <w>_C|^2 / (n_rot V_1 N_b),

with N_b the bin's fractional particle count. A mean velocity varying along z inside a bin
leaks into ``temperature`` (u = a z: + a^2 L_z^2 / 12 in T_xx) but into the cell temperature
only through the cell's own width (+ a^2 (L_z / z_cells)^2 / 12). ``z_cells = 1`` (the
default) is Campbell's strip convention and adds nothing. ``kinetic_shear`` stays a bin
(strip) quantity.

Wall-relative strips (``wall_relative=True``; the suite's default when the walls move, i.e.
servo walls; :mod:`demstudy.analysis.walls`). Campbell's convention ST = HGT/FND: the n strips
of each frame lie between that frame's walls (``frame.extra["walls"]``) and stretch with the
gap, strip k covering y_lower(t) + [k, k + 1) H(t)/n. Overlaps stay volume-exact: each
particle (its true radius) is split over the frame's physical strips, and the solid fraction
divides by the frame's strip volume H(t)/n × cross-section. This is the same as mapping the
whole frame (centres and particle shapes) by y' = lo + (y − y_lower(t)) (hi − lo)/H(t) onto
the mean gap's grid [lo, hi] (the run means of the wall positions; an affine map keeps
volume ratios), on which the results are reported. n = round(H_0/bin_width) with H_0 the
first frame's gap (Campbell: FND = INT(HGT/ST) fixed when averaging starts, L3689-3690).
Campbell divided the run's summed overlaps by the mean strip width (ν_i = π Σ A/(ST WL N_s)
with ST = AVHGT/LAV, L4095) where this divides each frame by its own strip volume, a
difference of order (δH/H)^2.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from demstudy import UNITS_NOTE
from demstudy.analysis.base import AnalysisBase, z_slab
from demstudy.analysis.blocking import BlockAccumulator, error_figures, jackknife_report
from demstudy.analysis.box import wrap_periodic
from demstudy.analysis.volumes import bin_profile_sums, profile_nvalues
from demstudy.analysis.walls import FIXED, WallStrips
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
    z_cells: Malik's cells: > 1 adds the temperatures about the means of ``z_cells`` z-slabs
        of each bin (3D, axis x or y); 1 is Campbell's strip convention.
    wall_relative: bin in strips between each frame's walls (``frame.extra["walls"]``), which
        move and stretch with them (Campbell's ST = HGT/FND; axis y, not periodic); ``lo``,
        ``hi`` and ``edges`` are then not used: the first frame's gap sets the number of
        strips, the run means of the walls the reported grid.
    strips: with ``wall_relative``, the number of strips (None: round(first gap/bin_width)).
    """

    #: class default: an instance pickled into a checkpoint before wall-relative strips
    #: existed unpickles without ``walls`` and resumes with its fixed strips
    walls = None

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
        z_cells: int = 1,
        wall_relative: bool = False,
        strips: int | None = None,
        verbose: bool = False,
    ) -> None:
        super().__init__(verbose=verbose)
        if dim not in (2, 3):
            raise ValueError(f"dim must be 2 or 3, got {dim!r}")
        self.axis = AXES.get(axis, -1) if isinstance(axis, str) else int(axis)
        if not 0 <= self.axis < dim:
            raise ValueError(f"axis {axis!r} does not exist in {dim}D")
        if wall_relative and (self.axis != 1 or period):
            raise ValueError(f"wall_relative = True: strips between the walls need the profile "
                             f"axis y without a period (this analysis: axis {'xyz'[self.axis]}, "
                             f"period {period!r})")
        self.walls = WallStrips(bin_width, "ProfileAnalysis", strips) if wall_relative \
            else None
        if not bin_width > 0:
            raise ValueError(f"bin_width must be positive, got {bin_width!r}")
        if period < 0:
            raise ValueError(f"period must be >= 0, got {period!r}")
        if image_velocity_shift and not period:
            raise ValueError("image_velocity_shift needs a periodic axis (period > 0)")
        if image_velocity_shift and self.axis == 0:
            raise ValueError("image_velocity_shift shifts x velocities: the axis cannot be x")
        if not (isinstance(z_cells, int | np.integer) and z_cells >= 1) or (
            z_cells > 1 and (dim != 3 or self.axis == 2)
        ):
            raise ValueError(
                f"z_cells = {z_cells!r}: Malik's cells split each bin into z_cells slabs along "
                "z, so z_cells must be an integer >= 1, and > 1 only in 3D with the profile "
                f"axis x or y (this analysis: {dim}D, axis {'xyz'[self.axis]}); 1 is "
                "Campbell's strip convention"
            )
        self.z_cells = int(z_cells)
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
        if self.walls is not None:  # the first frame's strips; the grid is set at the end
            nbins = self.walls.start(frame)
            lo, width = self.walls.strips(frame, record=False)
            hi = lo + nbins * width
        elif self._edges is not None:
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
        # sample layout: solid fraction | volume | sums, per cell = z-slab * nbins + bin (each
        # slab's bins contiguous, so the kernel writes a slab's cells in place)
        self.n_cells = nbins * self.z_cells
        self._acc = BlockAccumulator(self.n_cells * (self.n_values + 2), self.max_blocks)
        self._sample = np.zeros(self.n_cells * (self.n_values + 2))

    def _single_frame(self, frame: Frame) -> None:
        pos, vel, omega, radius = self._frame_arrays(frame)
        coord, period, zc = pos[:, self.axis], self.period, self.z_cells
        extra = [omega] if zc == 1 else [omega, z_slab(frame, pos[:, 2], zc)]
        if self.image_velocity_shift:
            coord, radius, vel, *extra = self._lees_edwards_images(coord, radius, vel, *extra)
            period = 0.0
        nb, nc = self.n_bins, self.n_cells
        # the frame's strips: fixed, or between its walls (Campbell's ST = HGT/FND)
        lo, width = (self.lo, self.bin_width) if self.walls is None else \
            self.walls.strips(frame)
        self._sample[:] = 0.0
        vol = self._sample[nc : 2 * nc]
        sums = self._sample[2 * nc :].reshape(nc, self.n_values)
        if zc == 1:
            self._kernel(coord, radius, vel, extra[0], period, vol, sums, lo, width)
        else:  # one kernel call per z-slab on the particles centred in it (sorted once)
            slab = extra[1].astype(np.int16 if zc < 2**15 else np.intp)  # int16: radix sort
            order = np.argsort(slab, kind="stable")
            ends = np.cumsum(np.bincount(slab, minlength=zc))
            coord, radius, vel, omega = (
                np.take(a, order, 0) for a in (coord, radius, vel, extra[0])
            )
            for s in range(zc):
                p, c = slice(ends[s - 1] if s else 0, ends[s]), slice(s * nb, (s + 1) * nb)
                self._kernel(coord[p], radius[p], vel[p], omega[p], period, vol[c], sums[c],
                             lo, width)
        section = float(np.prod(np.delete(frame.lengths, self.axis)))
        if not section > 0:
            raise ValueError(f"non-positive box cross-section {section} at t = {frame.time}")
        np.multiply(vol, 1.0 / (width * section), out=self._sample[:nc])
        self._acc.add(self._sample)

    def _kernel(
        self,
        coord: np.ndarray,
        radius: np.ndarray,
        vel: np.ndarray,
        omega: np.ndarray,
        period: float,
        vol: np.ndarray,
        sums: np.ndarray,
        lo: float,
        width: float,
    ) -> None:
        bin_profile_sums(
            coord,
            radius,
            vel,
            omega,
            self.inertia_factor,
            lo,
            width,
            self.n_bins,
            self.dim,
            period,
            out_volume=vol,
            out_sums=sums,
        )

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
        self, coord: np.ndarray, radius: np.ndarray, vel: np.ndarray, *rest: np.ndarray
    ) -> tuple[np.ndarray, ...]:
        """Centres put into the period with the image rule (a centre moved by k periods moves
        its x velocity by −k × the image velocity: engines leave centres slightly outside),
        then explicit periodic images of boundary straddlers with shifted x velocities (the
        ``rest`` per-particle arrays, spin and z-slab, are copied unchanged)."""
        lo, p = self.lo, self.period
        c, turns = wrap_periodic(coord, lo, p)
        moved = np.flatnonzero(turns)
        if moved.size:
            vel = vel.copy()
            vel[moved, 0] -= turns[moved] * self.image_velocity_shift
        below, above = c - radius < lo, c + radius > lo + p
        img_v = [vel, vel[below].copy(), vel[above].copy()]
        img_v[1][:, 0] += self.image_velocity_shift  # image at c + P
        img_v[2][:, 0] -= self.image_velocity_shift  # image at c - P
        return (
            np.concatenate([c, c[below] + p, c[above] - p]),
            np.concatenate([radius, radius[below], radius[above]]),
            np.concatenate(img_v),
            *(np.concatenate([a, a[below], a[above]]) for a in rest),
        )

    def _estimate(self, mean: np.ndarray) -> dict[str, np.ndarray]:
        if self.z_cells == 1:
            return self._bin_estimate(mean)
        nb, nc, zc, nv = self.n_bins, self.n_cells, self.z_cells, self.n_values
        vol = mean[nc : 2 * nc].reshape(zc, nb)
        sums = mean[2 * nc :].reshape(zc, nb, nv)
        # a bin's sums are the sums of its cells: the strip fields come out unchanged
        strip = np.concatenate([mean[:nc].reshape(zc, nb).sum(0), vol.sum(0), sums.sum(0).ravel()])
        out = self._bin_estimate(strip)
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = np.where(vol > 0, 1.0 / vol, 0.0)  # empty cells hold no fluctuation
            s_v, s_w = sums[..., self._c_v], sums[..., self._c_w]
            diag = [self._c_vv.start + self._pairs.index((a, a)) for a in range(self.dim)]
            dev2 = sums[..., diag] - s_v**2 * inv[..., None]  # sum V (v_a - <v_a>_C)^2
            rot = (
                sums[..., self._c_jww]
                - 2.0 * (s_w * sums[..., self._c_jw]).sum(-1) * inv
                + (s_w**2).sum(-1) * sums[..., self._c_j] * inv**2
            )
            norm = self._unit_volume * sums[..., self._c_inv].sum(0)  # V_1 N_b
            comps = dev2.sum(0) / norm[:, None]
            out.update(
                {
                    "cell_temperature": comps.sum(1) / self.dim,
                    "cell_temperature_components": comps,
                    "cell_rotational_temperature": rot.sum(0) / (self.n_rot * norm),
                }
            )
        return out

    def _bin_estimate(self, mean: np.ndarray) -> dict[str, np.ndarray]:
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
        temperature = comps.sum(1) / dim
        filled = vol > 0
        return {
            "solid_fraction": mean[:nb],
            "number_density": mean[:nb] / mean_volume,
            "mean_mass": mean_mass,
            "velocity": v,
            "temperature": temperature,
            "mean_temperature": np.sum(mean[:nb][filled] * temperature[filled]) /
                                np.sum(mean[:nb][filled]),  # mass-weighted over the bins
            "temperature_components": comps,
            "kinetic_shear": cov[:, 0, 1],
            "spin": w,
            "rotational_temperature": mean_mass * t_rot / self.n_rot,
        }

    def _conclude(self) -> None:
        if self.walls is not None:  # report on the grid between the mean walls
            self.edges = self.walls.edges()
            self.lo, self.hi = float(self.edges[0]), float(self.edges[-1])
            self.bin_width = (self.hi - self.lo) / self.n_bins
        est, err, report = jackknife_report(self._acc, self._estimate)
        self.results = {"y": 0.5 * (self.edges[1:] + self.edges[:-1]), "edges": self.edges}
        for key in est:
            self.results[key] = est[key]
            self.results[f"{key}_err"] = err[key]
        axis_name = "xyz"[self.axis]
        fluctuations = "temperature*: relative to the run mean of the bin (strip), Campbell"
        if self.z_cells > 1:
            fluctuations += (
                f"; cell_temperature*: relative to the run means of {self.z_cells} z-cells "
                "per bin, Malik's cell convention"
            )
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
            "z_cells": self.z_cells,
            "fluctuations": fluctuations,
            **({"bins": FIXED, "wall_relative": False} if self.walls is None
               else self.walls.attrs()),
            "block_length": self._acc.block_length,
            "n_blocks": self._acc.n_blocks,
            "units": UNITS_NOTE,
            **error_figures(report),
        }
