"""Velocity distributions per bin along y: Campbell's X1...X5, Malik's C/sigma, moments.

Dimensionless particle units: d = 1, m = 1. Axes: x flow, y wall-normal (the bin axis),
z spanwise (3D). A particle belongs to the bin (Campbell's "strip") of its *centre*; bin
statistics are number-weighted over all samples of the run (equal weight per particle and
frame, Campbell's area weighting for equal discs).

Components (``attrs["components"]``): the translational velocities ``u, v[, w]``, the spins
``omega_z`` (2D) or ``omega_x, omega_y, omega_z`` (3D), and ``sqrtj_omega_*`` = sqrt(j) omega
with j = I/m = K r^2 (the rotational velocity whose square is Campbell's beta omega^2 in units
of R = 1: it enters X5 so that every degree of freedom has the dimension of a velocity^2).

Moments (one pass, exact): per bin and component, the pooled mean, variance
<c'^2>, skewness <c'^3>/<c'^2>^(3/2) and kurtosis <c'^4>/<c'^2>^2 of c' = c - <c>, with <c>
the run mean of the bin (population moments, 1/N). Power sums are taken about a per-bin
shift (the first frame's bin mean) to limit cancellation. A Maxwellian gives skewness 0 and
kurtosis 3 for every component; a uniform distribution gives kurtosis 9/5.

Histograms need the bin means and variances of the whole run, so they use **two passes**:
the first pass (``reference=None``) gives the moments above; the second pass
(``reference=first.results``) histograms the frames against those stored per-bin means and
variances (:func:`velocity_distributions` does both for a re-iterable frame source). No
running moments are used. With M the reference mean and S the variance of the bin:

* Campbell (thesis §4, "VDF"; 50 bins of 0.1 on [0, 5], P = count / (N_bin * 0.1) with
  N_bin all samples of the bin, those beyond X = 5 included):
  X1 = |u - M_u| / sqrt(S_u), X2 = |v - M_v| / sqrt(S_v), X3 = |omega_z - M| / sqrt(S),
  X4 = [sum_a (c_a - M_a)^2 / sum_a S_a]^(1/2) over the dim translational components,
  X5 = the same over the translational and the sqrt(j) omega components (dim + n_rot).
  Maxwellian references, folded onto X >= 0 (the digest's NOTE: the factor 2 is needed for
  a normalised density on [0, inf)): a chi distribution with k degrees of freedom,
  P_k(X) = 2 a^(k/2) / Gamma(k/2) X^(k-1) exp(-a X^2), a = k/2, i.e. k = 1, 1, 1, 2, 3 and
  a = 1/2, 1/2, 1/2, 1, 3/2 in 2D (Campbell's values) and k = 1, 1, 1, 3, 6 in 3D. X4 and X5
  follow P_k only if the components share one variance (equipartition), as Campbell assumes.
  ``X_reference`` is P_k averaged over each histogram bin (exact, from the chi CDF), the
  quantity to compare histograms with; ``X_reference_centre`` is P_k at the bin centres.
* Malik (2008, §4.6): per component (translational and spin, not the sqrt(j) ones) the signed
  x = (c - M)/sqrt(S), 100 bins of 0.1 on [-5, 5]; ``malik_pdf`` = count / (N_bin * 0.1)
  (normalised density) and ``malik_P`` = malik_pdf / P0 with P0 the mean of the two bins
  adjacent to x = 0 (Malik's "P(0) = 1" scaling; his estimator of P(0) is not stated).
  References: ``gaussian`` = exp(-x^2/2) at the bin centres, ``gaussian_binned`` = the
  normal density averaged over each bin and scaled by the same P0 rule.

Malik's cell convention (``z_cells`` > 1, 3D): fluctuations are taken relative to the means of
cells that split each y-bin into ``z_cells`` slabs along z (Malik 2008 §4.1: "cellwise",
bins in y and z; his number of z cells is not stated). Moments and references are computed
per cell; the reported ``variance``, ``skewness``, ``kurtosis`` and histograms pool the cells
of a y-bin (count-weighted central moments about the cell means), ``mean`` is the bin's mean,
and ``cell_mean`` / ``cell_variance`` (n_bins · z_cells, n_comp) are kept for the second pass.
``z_cells = 1`` is Campbell's strip convention.

Wall-relative strips (``wall_relative=True``, the suite's default when the walls move: servo
walls; :mod:`demstudy.analysis.walls`): a particle belongs to strip k when its centre lies
in y_lower(t) + [k, k + 1) H(t)/n, the n strips between the frame's walls
(``frame.extra["walls"]``), moving and stretching with them (Campbell's ST = HGT/FND); n is
round(H_0 / bin_width) with H_0 the first frame's gap, and ``edges`` / ``y`` are the grid
between the run means of the wall positions.

Errors (``*_err``): delete-one-block jackknife over time blocks of the per-frame sums
(:class:`~demstudy.analysis.blocking.BlockAccumulator`); memory is flat in the number of
frames. The bin mean includes any mean-velocity gradient across the bin, which widens the
distributions (see :mod:`demstudy.analysis.profiles` for the size of the effect).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy.special import erf, gammainc, gammaln

from demstudy import UNITS_NOTE
from demstudy.analysis.base import AnalysisBase, default_y_edges, z_slab
from demstudy.analysis.blocking import BlockAccumulator, jackknife
from demstudy.analysis.walls import FIXED, WallStrips
from demstudy.io.frames import Frame

__all__ = ["VelocityDistribution", "folded_maxwellian", "velocity_distributions"]

X_NAMES = ("X1", "X2", "X3", "X4", "X5")


def folded_maxwellian(x: ArrayLike, k: int) -> np.ndarray:
    """Chi density with k degrees of freedom in Campbell's scaling (<X^2> = 1), X >= 0:
    2 a^(k/2) / Gamma(k/2) X^(k-1) exp(-a X^2), a = k/2 (k = 1: 2 sqrt(a/pi) exp(-a X^2))."""
    x = np.asarray(x, float)
    a = k / 2
    log = np.log(2.0) + a * np.log(a) - gammaln(a) - a * x**2
    with np.errstate(divide="ignore"):
        return np.exp(log) * x ** (k - 1)


def _chi_cdf(x: np.ndarray, k: int) -> np.ndarray:
    return gammainc(k / 2, k / 2 * np.asarray(x, float) ** 2)


class VelocityDistribution(AnalysisBase):
    """Per-bin velocity moments and (second pass) Campbell / Malik velocity histograms.

    Parameters
    ----------
    dim: 2 (discs) or 3 (spheres).
    edges: bin edges along y; None means ``n_bins`` equal bins over the first frame's box.
    n_bins: number of bins when ``edges`` is None.
    inertia_factor: K = 4 I / (m d^2) (j = K r^2); None means a solid disc (1/2) or sphere
        (2/5).
    reference: None (first pass: moments only) or the ``results`` of a first pass over the
        same frames with the same edges (second pass: histograms too).
    period: y period (> 0: centres are wrapped into ``[edges[0], edges[0] + period)``).
    image_velocity_shift: x velocity of the periodic image at y + period (Lees-Edwards:
        shear rate × period), added per period a centre is wrapped upwards.
    x_bins, x_width: Campbell's histogram (50 bins of 0.1); Malik's uses 2 x_bins on
        [-x_bins x_width, x_bins x_width].
    max_blocks: bound on the stored time blocks.
    wall_relative: strips between each frame's walls (``frame.extra["walls"]``) that move and
        stretch with them (Campbell's ST = HGT/FND; y not periodic); ``edges`` and
        ``n_bins`` are then not used, ``bin_width`` sets the number of strips.
    bin_width: the strip width asked for with ``wall_relative``.
    """

    #: class default: an instance pickled into a checkpoint before wall-relative strips
    #: existed unpickles without ``walls`` and resumes with its fixed strips
    walls = None

    def __init__(
        self,
        dim: int = 2,
        edges: ArrayLike | None = None,
        n_bins: int = 1,
        inertia_factor: float | None = None,
        reference: Mapping[str, Any] | None = None,
        period: float = 0.0,
        image_velocity_shift: float = 0.0,
        x_bins: int = 50,
        x_width: float = 0.1,
        z_cells: int = 1,
        max_blocks: int = 64,
        wall_relative: bool = False,
        bin_width: float = 1.0,
        verbose: bool = False,
    ) -> None:
        super().__init__(verbose=verbose)
        if dim not in (2, 3):
            raise ValueError(f"dim must be 2 or 3, got {dim!r}")
        if wall_relative and period:
            raise ValueError(f"wall_relative = True: strips between the walls need a y "
                             f"without a period (period = {period!r})")
        self.walls = WallStrips(bin_width, "VelocityDistribution") if wall_relative else None
        if int(z_cells) < 1 or (dim == 2 and int(z_cells) != 1):
            raise ValueError(f"z_cells = {z_cells!r}: a positive number of cells along z (3D "
                             "only; 1 is Campbell's strip convention)")
        self.z_cells = int(z_cells)
        self.dim = dim
        self.n_rot = 1 if dim == 2 else 3
        self.inertia_factor = float(
            inertia_factor if inertia_factor is not None else (0.5 if dim == 2 else 0.4)
        )
        self._edges = None if edges is None else np.asarray(edges, float)
        if self._edges is not None and (self._edges.ndim != 1 or self._edges.size < 2
                                        or np.any(np.diff(self._edges) <= 0)):
            raise ValueError("edges must be increasing with at least 2 entries")
        self._n_bins = int(n_bins)
        self.period = float(period)
        self.image_velocity_shift = float(image_velocity_shift)
        if self.image_velocity_shift and not self.period:
            raise ValueError("image_velocity_shift needs a periodic y (period > 0)")
        self.nx, self.dx = int(x_bins), float(x_width)
        self.max_blocks = int(max_blocks)
        rot = ["omega_z"] if dim == 2 else ["omega_x", "omega_y", "omega_z"]
        self.components = ["u", "v", "w"][:dim] + rot + [f"sqrtj_{c}" for c in rot]
        self.n_comp = len(self.components)
        self.n_malik = dim + self.n_rot  # translational and spin components
        # Campbell's X: component indices for X1..X3 and the sets for X4, X5
        self._x3 = dim + self.n_rot - 1  # omega_z
        self._trans = list(range(dim))
        self._total = self._trans + list(range(dim + self.n_rot, self.n_comp))
        self.dof = (1, 1, 1, dim, dim + self.n_rot)
        self.reference = None
        if reference is not None:
            self.reference = {
                "mean": np.asarray(reference.get("cell_mean", reference["mean"]), float),
                "variance": np.asarray(reference.get("cell_variance", reference["variance"]),
                                       float),
                "edges": np.asarray(reference["edges"], float),
            }
            if self.reference["mean"].shape[1] != self.n_comp:
                raise ValueError("reference has other components (dim mismatch?)")

    # -- layout ------------------------------------------------------------------------
    def _layout(self) -> None:
        c = self.n_comp
        self._c_n = 0
        self._c_pow = [slice(1 + k * c, 1 + (k + 1) * c) for k in range(4)]
        stop = 1 + 4 * c
        self._c_x = slice(stop, stop + (5 * self.nx if self.reference else 0))
        self._c_m = slice(self._c_x.stop,
                          self._c_x.stop + (self.n_malik * 2 * self.nx if self.reference else 0))
        self.n_values = self._c_m.stop

    def _prepare(self) -> None:
        frame = self.first_frame
        assert frame is not None
        if frame.dim != self.dim:
            raise ValueError(f"frame is {frame.dim}D, analysis is {self.dim}D")
        if self.walls is not None:  # the first frame's strips; the grid is set at the end
            n_bins = self.walls.start(frame)
            lower, width = self.walls.strips(frame, record=False)
            self.edges = lower + width * np.arange(n_bins + 1)
        else:
            if self._edges is None:
                self._edges = default_y_edges(frame, self.period, self._n_bins)
            self.edges = self._edges
        self.n_bins = self.edges.size - 1
        self.n_cells = self.n_bins * self.z_cells
        if self.reference is not None:
            ref_edges = self.reference["edges"]
            # wall-relative strips: their number must agree (the grid is the mean walls')
            same = ref_edges.shape == self.edges.shape and (
                self.walls is not None or np.allclose(ref_edges, self.edges, rtol=0, atol=1e-12))
            if not same:
                raise ValueError("the reference was computed on other bin edges")
            if self.reference["mean"].shape[0] != self.n_cells:
                raise ValueError("the reference was computed with other z cells")
            var = self.reference["variance"]
            self._ref_mean = self.reference["mean"]
            with np.errstate(divide="ignore", invalid="ignore"):
                self._ref_inv_sd = np.where(var > 0, 1.0 / np.sqrt(var), np.nan)
                self._ref_inv_var4 = 1.0 / var[:, self._trans].sum(1)
                self._ref_inv_var5 = 1.0 / var[:, self._total].sum(1)
        self._layout()
        self._acc = BlockAccumulator(self.n_cells * self.n_values, self.max_blocks)
        bins, comps = self._assign(frame, record=False)
        counts = np.bincount(bins, minlength=self.n_cells).astype(float)
        sums = np.zeros((self.n_cells, self.n_comp))
        np.add.at(sums, bins, comps)
        with np.errstate(invalid="ignore"):
            self._shift = np.where(counts[:, None] > 0, sums / counts[:, None], 0.0)

    def _assign(self, frame: Frame, record: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Cell index (y-bin · z_cells + z-cell) and component matrix of the particles whose
        centre lies in a bin (``record``: count the frame's walls into the run means)."""
        pos = np.asarray(frame.position, float)
        vel = np.array(frame.velocity, float)
        omega = np.asarray(frame.angular_velocity, float)
        omega = omega[:, None] if omega.ndim == 1 else omega
        radius = np.asarray(frame.radius, float)
        y = pos[:, 1]
        if self.period:
            turns = np.floor((y - self.edges[0]) / self.period)
            y = y - turns * self.period
            if self.image_velocity_shift:
                vel[:, 0] -= turns * self.image_velocity_shift
        if self.walls is None:
            bins = np.searchsorted(self.edges, y, side="right") - 1
        else:
            bins = self.walls.bin_of(frame, y, record)
        keep = (bins >= 0) & (bins < self.n_bins)
        if self.z_cells > 1:  # Malik's cells: y-bin × z-slab
            bins = bins * self.z_cells + z_slab(frame, pos[:, 2], self.z_cells)
        sqrt_j = np.sqrt(self.inertia_factor) * radius
        comps = np.concatenate([vel, omega, sqrt_j[:, None] * omega], axis=1)
        return bins[keep], comps[keep]

    def _single_frame(self, frame: Frame) -> None:
        bins, comps = self._assign(frame)
        nb, nv = self.n_cells, self.n_values
        sample = np.zeros((nb, nv))
        sample[:, 0] = np.bincount(bins, minlength=nb)
        dev = comps - self._shift[bins]
        power = np.ones_like(dev)
        for k in range(4):
            power *= dev
            for c in range(self.n_comp):
                sample[:, self._c_pow[k].start + c] = np.bincount(
                    bins, weights=power[:, c], minlength=nb)
        if self.reference is not None:
            self._histograms(bins, comps, sample)
        self._acc.add(sample.reshape(-1))

    def _histograms(self, bins: np.ndarray, comps: np.ndarray, sample: np.ndarray) -> None:
        nx, dx = self.nx, self.dx
        dev = comps - self._ref_mean[bins]
        scaled = dev * self._ref_inv_sd[bins]
        x4 = np.sqrt((dev[:, self._trans] ** 2).sum(1) * self._ref_inv_var4[bins])
        x5 = np.sqrt((dev[:, self._total] ** 2).sum(1) * self._ref_inv_var5[bins])
        xs = np.stack([np.abs(scaled[:, 0]), np.abs(scaled[:, 1]), np.abs(scaled[:, self._x3]),
                       x4, x5], axis=1)
        self._bincount_into(sample[:, self._c_x], bins, xs / dx, nx)
        signed = scaled[:, : self.n_malik] / dx + nx
        self._bincount_into(sample[:, self._c_m], bins, signed, 2 * nx)

    @staticmethod
    def _bincount_into(out: np.ndarray, bins: np.ndarray, values: np.ndarray, width: int) -> None:
        """Histogram columns of ``values`` (already in bin units) per bin into ``out``."""
        nb, ncol = out.shape[0], values.shape[1]
        with np.errstate(invalid="ignore"):
            k = np.floor(values)
            ok = np.isfinite(k) & (k >= 0) & (k < width)
        col = np.broadcast_to(np.arange(ncol), values.shape)
        flat = (bins[:, None] * ncol + col) * width + np.where(ok, k, 0).astype(np.int64)
        out += np.bincount(flat[ok], minlength=nb * ncol * width).reshape(nb, ncol * width)

    # -- estimates ---------------------------------------------------------------------
    def _estimate(self, mean: np.ndarray) -> dict[str, np.ndarray]:
        s = mean.reshape(self.n_cells, self.n_values)
        n = s[:, 0]
        nb, zc = self.n_bins, self.z_cells
        with np.errstate(invalid="ignore", divide="ignore"):
            m1, m2, m3, m4 = (s[:, sl] / n[:, None] for sl in self._c_pow)
            mu2 = m2 - m1**2
            mu3 = m3 - 3 * m1 * m2 + 2 * m1**3
            mu4 = m4 - 4 * m1 * m3 + 6 * m1**2 * m2 - 3 * m1**4
            cell_mean = self._shift + m1

            def pool(values: np.ndarray) -> np.ndarray:  # count-weighted over a bin's cells
                w = np.nan_to_num(values * n[:, None]).reshape(nb, zc, -1).sum(1)
                return w / n.reshape(nb, zc).sum(1)[:, None]

            var = pool(mu2)
            out = {
                "count": n.reshape(nb, zc).sum(1),
                "mean": pool(cell_mean),
                "variance": var,
                "skewness": pool(mu3) / var**1.5,
                "kurtosis": pool(mu4) / var**2,
            }
            if zc > 1:
                out.update({"cell_mean": cell_mean, "cell_variance": mu2})
            if self.reference is not None:
                total = s.reshape(nb, zc, self.n_values).sum(1)
                norm = out["count"][:, None, None] * self.dx
                x = total[:, self._c_x].reshape(nb, 5, self.nx) / norm
                pdf = total[:, self._c_m].reshape(nb, self.n_malik, 2 * self.nx) / norm
                p0 = 0.5 * (pdf[:, :, self.nx - 1] + pdf[:, :, self.nx])
                out.update({"X": x, "malik_pdf": pdf, "malik_P": pdf / p0[:, :, None]})
        return out

    def _conclude(self) -> None:
        if self.walls is not None:  # report on the grid between the mean walls
            self.edges = self.walls.edges()
        est, err = jackknife(self._acc, self._estimate)
        self.results = {"edges": self.edges, "y": 0.5 * (self.edges[1:] + self.edges[:-1])}
        for key in est:
            self.results[key] = est[key]
            self.results[f"{key}_err"] = err[key]
        self.attrs = {
            "dim": self.dim,
            "components": ",".join(self.components),
            "inertia_factor": self.inertia_factor,
            "binning": "strip of the particle centre, number-weighted, pooled over the run",
            **({"bins": FIXED, "wall_relative": False} if self.walls is None
               else self.walls.attrs()),
            "z_cells": self.z_cells,
            "fluctuations": ("relative to the strip (bin) mean: Campbell" if self.z_cells == 1
                             else f"relative to the means of {self.z_cells} z-cells per bin: "
                                  "Malik's cell convention"),
            "passes": 2 if self.reference is not None else 1,
            "samples": self.n_frames,
            "block_length": self._acc.block_length,
            "n_blocks": self._acc.n_blocks,
            "units": UNITS_NOTE,
        }
        if self.reference is None:
            return
        nx, dx = self.nx, self.dx
        x_edges = dx * np.arange(nx + 1)
        x_mid = 0.5 * (x_edges[1:] + x_edges[:-1])
        self.results["X_edges"] = x_edges
        self.results["X_centres"] = x_mid
        self.results["X_reference"] = np.stack(
            [np.diff(_chi_cdf(x_edges, k)) / dx for k in self.dof])
        self.results["X_reference_centre"] = np.stack(
            [folded_maxwellian(x_mid, k) for k in self.dof])
        c_edges = dx * np.arange(-nx, nx + 1)
        c_mid = 0.5 * (c_edges[1:] + c_edges[:-1])
        binned = np.diff(0.5 * (1 + erf(c_edges / np.sqrt(2)))) / dx
        self.results["malik_edges"] = c_edges
        self.results["malik_centres"] = c_mid
        self.results["gaussian"] = np.exp(-0.5 * c_mid**2)
        self.results["gaussian_binned"] = binned / (0.5 * (binned[nx - 1] + binned[nx]))
        self.attrs.update({
            "X_names": ",".join(X_NAMES),
            "X_degrees_of_freedom": ",".join(str(k) for k in self.dof),
            "X_a": ",".join(f"{k / 2:g}" for k in self.dof),
            "malik_components": ",".join(self.components[: self.n_malik]),
            "malik_P0": "mean of the two histogram bins adjacent to 0",
        })


def velocity_distributions(
    frames: Callable[[], Iterable[Frame]] | Iterable[Frame], **options: Any
) -> VelocityDistribution:
    """Both passes: moments, then histograms against the first pass's bin means/variances.

    ``frames`` is a callable returning a fresh iterable of frames (e.g.
    ``lambda: read_dump_fast(path, 2)``) or a re-iterable sequence (a list). ``options`` go
    to :class:`VelocityDistribution`.
    """
    if not callable(frames) and iter(frames) is frames:
        raise TypeError("velocity_distributions reads the frames twice: pass a list or a "
                        "callable returning a fresh iterator, not an iterator")
    source = frames if callable(frames) else (lambda: frames)
    first = VelocityDistribution(**options).run(source())
    options = {**options, "edges": first.edges, "reference": first.results}
    return VelocityDistribution(**options).run(source())
