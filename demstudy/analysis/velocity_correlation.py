"""Spatial velocity correlations C_ab(r) and Malik's orientational correlation Lambda(y).

Dimensionless particle units: d = 1, m = 1 (r in particle diameters). Axes: x flow (periodic),
y wall-normal (the bin axis; periodic or bounded by walls), z spanwise (3D, periodic).
Particles belong to the y-bin of their *centre*; particles outside every bin are ignored.

Fluctuations. Malik (2008, §4.1) takes fluctuations relative to the mean of the particle's
cell, without saying whether the mean is instantaneous or time-averaged. Both readings exist:

* ``reference=None`` (single pass): the *instantaneous* mean of the bin in that frame,
  u'_i = c_i - (1/N_b) sum_{j in b} c_j;
* ``reference=BinMeans(...).results`` (second pass, the default of the two-pass helpers
  :func:`velocity_correlations` and :func:`orientational_correlation`, and of
  ``demstudy analyze``): the *run-mean* of the bin from a first pass over the same frames,
  u'_i = c_i - U(b_i) (number-weighted, like :mod:`demstudy.analysis.vdf`). The first-pass
  mean is treated as exact (its error is not propagated).

Geometry: each frame's :class:`~demstudy.analysis.box.Box` (x, z periodic; y periodic over
``[edges[0], edges[0] + period)`` when ``period`` > 0) wraps the centres and velocities and
its :class:`~demstudy.analysis.box.NeighbourQuery` finds the pairs. Lees-Edwards (y periodic,
``frame.tilt`` != 0): a centre moved across y by k periods gets x -= k tilt and
u -= k ``image_velocity_shift`` (= shear rate * L_y). A partner seen through the y boundary is
the explicit image shifted by +-tilt along x; its *fluctuation* is that of the particle itself,
because the image velocity and the image's local mean velocity differ by the same shear
rate * L_y.

VelocityCorrelation (Malik §4.9, eq. 4.1, on fluctuations). For particle i in bin b and each
partner j != i at distance r_ij in shell k = [k dr, (k+1) dr) (partners anywhere, or with
``in_bin=True`` only partners in the same bin, Malik's binwise convention), per frame and bin
the sums S_a(b, k) = sum u'_ia u'_ja, P(b, k) = number of ordered pairs, Q_a(b) = sum_i u'_ia^2
and N(b) are block-averaged, and

    covariance_a(r_k) = <S_a> / <P>          (mean product over the pairs in the shell),
    temperature_components_a = <Q_a> / <N>   (= m <u'_a^2>, m = 1: the temperature component),
    C_a(r_k) = covariance_a / temperature_components_a,

so C_a -> 1 as r -> 0+ for a velocity field that is smooth on the particle scale and C = 0 for
independent velocities; covariance(0+) is the temperature component. ``C_malik`` is Malik's
literal (4.1), sum_i sum_{j>i} u'_ia u'_ja delta(r - r_ij) / sum_i u'_ia^2 with the delta
binned as 1/dr, i.e. <S_a> / (2 dr <Q_a>) (exactly Malik's for ``in_bin=True``; it mixes
C with the pair density: C_malik = C * pairs_per_particle / (2 dr)). ``distance="planar"``
(only with ``in_bin``) uses the separation in the periodic x(z) plane, Malik's reading for
g(r).

Off-diagonal components C_ac (a != c: xy in 2D; xy, xz, yz in 3D), from the same pairs: with
the ordered sums S_ac(b, k) = sum u'_ia u'_jc (i in bin b supplies component a, j component c),

    covariance_offdiag_ac(r_k) = (<S_ac> + <S_ca>) / (2 <P>)   (symmetrised over the pair order),
    C_offdiag_ac = covariance_offdiag_ac / sqrt(T_a T_c),      T = temperature_components (bin b),
    C_offdiag_antisym_ac = (<S_ac> - <S_ca>) / (2 <P> sqrt(T_a T_c)).

Normalising by sqrt(T_a T_c) makes C_ac a correlation coefficient that reduces to C_aa for
a = c: u'_c = s u'_a in every particle gives C_ac = sign(s) C_aa exactly, independent
components give 0. C_xy is the shear-stress-like one (the pair analogue of <u'v'>). When every
ordered pair comes with its reverse in the same bin (one bin over a whole periodic box, or
``in_bin=True``), S_ac = S_ca and the antisymmetric part is exactly 0; otherwise its
expectation is 0 for statistically homogeneous fluctuations (<u'_a(x) u'_c(x + r)> =
<u'_c(x) u'_a(x - r)> and each shell holds r and -r), and it is nonzero where the statistics
vary across bins (e.g. a temperature gradient). Hence the symmetrised C_ac as the result, the
antisymmetric part kept as a diagnostic.

OrientationalCorrelation (Malik §4.8): per particle cos^2 Psi = (C.W)^2 / (|C|^2 |W|^2) of the
translational fluctuation C and the spin fluctuation W (particles with C = 0 or W = 0 are
skipped), and

    lambda(y) = < (1/N_b) sum_{i in b} cos^2 Psi_i >_frames   (Malik: time average of the
                 per-frame bin averages, over the frames in which the bin holds particles),
    lambda_pooled(y) = sum_frames sum_i cos^2 Psi_i / sum_frames N_b.

Uncorrelated isotropic 3D vectors give 1/3, parallel ones 1, perpendicular ones 0. **3D
only**: in 2D the spin is the scalar omega_z along z, perpendicular to every in-plane
velocity, so cos Psi = 0 identically and Lambda carries no information; 2D is refused.

Errors: delete-one-block jackknife over time blocks
(:class:`~demstudy.analysis.blocking.BlockAccumulator`); memory is flat in the number of
frames (the pair search is chunked so that memory is bounded by ``chunk`` particles' pairs).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from demstudy import UNITS_NOTE
from demstudy.analysis.base import AnalysisBase, default_y_edges, z_slab
from demstudy.analysis.blocking import BlockAccumulator, jackknife
from demstudy.analysis.box import Box, NeighbourQuery
from demstudy.io.frames import Frame

__all__ = [
    "BinMeans",
    "OrientationalCorrelation",
    "VelocityCorrelation",
    "orientational_correlation",
    "velocity_correlations",
]


def _check_edges(edges: ArrayLike | None) -> np.ndarray | None:
    if edges is None:
        return None
    e = np.asarray(edges, float)
    if e.ndim != 1 or e.size < 2 or np.any(np.diff(e) <= 0):
        raise ValueError("edges must be increasing with at least 2 entries")
    return e


class _Binned(AnalysisBase):
    """Common set-up: y-bins of the particle centres, periodic wrapping with LE shifts."""

    def __init__(self, dim: int, edges: ArrayLike | None, n_bins: int, period: float,
                 image_velocity_shift: float, max_blocks: int, verbose: bool,
                 z_cells: int = 1) -> None:
        super().__init__(verbose=verbose)
        if dim not in (2, 3):
            raise ValueError(f"dim must be 2 or 3, got {dim!r}")
        if int(z_cells) < 1 or (dim == 2 and int(z_cells) != 1):
            raise ValueError(f"z_cells = {z_cells!r}: a positive number of cells along z (3D "
                             "only; 1 = the bin mean)")
        self.z_cells = int(z_cells)
        if period < 0:
            raise ValueError(f"period must be >= 0, got {period!r}")
        if image_velocity_shift and not period:
            raise ValueError("image_velocity_shift needs a periodic y (period > 0)")
        self.dim, self.n_rot = dim, (1 if dim == 2 else 3)
        self._edges = _check_edges(edges)
        self._n_bins = int(n_bins)
        self.period = float(period)
        self.image_velocity_shift = float(image_velocity_shift)
        self.max_blocks = int(max_blocks)

    def _set_edges(self, frame: Frame) -> None:
        if frame.dim != self.dim:
            raise ValueError(f"frame is {frame.dim}D, analysis is {self.dim}D")
        if self._edges is None:
            self._edges = default_y_edges(frame, self.period, self._n_bins)
        self.edges = self._edges
        self.n_bins = self.edges.size - 1

    def _box(self, frame: Frame) -> Box:
        """The frame's box with y periodic over ``[edges[0], edges[0] + period)`` when
        ``period`` > 0 (images offset by the tilt, moving with ``image_velocity_shift``)."""
        lo, lengths = np.array(frame.box_lo, float), frame.lengths
        if self.period:
            lo[1], lengths[1] = self.edges[0], self.period
        periodic = tuple(a != 1 or bool(self.period) for a in range(self.dim))
        return Box(lo, lengths, periodic, tilt=float(frame.tilt) if self.period else 0.0,
                   shear_velocity=self.image_velocity_shift)

    def _assign(self, frame: Frame) -> dict[str, Any]:
        """The frame's box, wrapped positions, LE-shifted velocities, spins and bin index of
        every particle (bin -1: outside the bins)."""
        pos, vel = np.asarray(frame.position, float), np.asarray(frame.velocity, float)
        omega = np.asarray(frame.angular_velocity, float)
        omega = omega[:, None] if omega.ndim == 1 else omega
        if vel.shape != pos.shape or omega.shape != (pos.shape[0], self.n_rot):
            raise ValueError("velocity / angular_velocity do not match the positions")
        box = self._box(frame)
        pos, vel, _ = box.wrap(pos, vel)
        bins = np.searchsorted(self.edges, pos[:, 1], side="right") - 1
        bins[(bins < 0) | (bins >= self.n_bins)] = -1
        cells = bins
        if self.z_cells > 1:  # Malik's cells: y-bin × z-slab
            cells = np.where(bins >= 0, bins * self.z_cells + z_slab(frame, pos[:, 2],
                                                                     self.z_cells), -1)
        return {"box": box, "pos": pos, "vel": vel, "omega": omega, "bins": bins,
                "cells": cells}

    def _bin_mean(self, bins: np.ndarray, values: np.ndarray,
                  size: int | None = None) -> np.ndarray:
        """Per-bin (or per-cell, ``size`` of them) mean of ``values`` (rows with index -1
        ignored; empty ones give 0)."""
        size = self.n_bins if size is None else size
        keep = bins >= 0
        n = np.bincount(bins[keep], minlength=size).astype(float)
        out = np.zeros((size, values.shape[1]))
        for c in range(values.shape[1]):
            out[:, c] = np.bincount(bins[keep], weights=values[keep, c], minlength=size)
        return out / np.maximum(n, 1.0)[:, None]

    def _reference_means(self, reference: Mapping[str, Any] | None) -> None:
        self._ref = None
        if reference is None:
            return
        ref_edges = np.asarray(reference["edges"], float)
        if ref_edges.shape != self.edges.shape or not np.allclose(ref_edges, self.edges,
                                                                  rtol=0, atol=1e-12):
            raise ValueError("the reference was computed on other bin edges")
        self._ref = {k: np.nan_to_num(np.asarray(reference.get(f"cell_{k}", reference[k]),
                                                 float))
                     for k in ("velocity", "spin")}
        if self._ref["velocity"].shape[0] != self.n_bins * self.z_cells:
            raise ValueError("the reference was computed with other z cells")

    def _fluctuations(self, a: dict[str, np.ndarray], spin: bool = False) -> tuple[np.ndarray, ...]:
        cells, size = a["cells"], self.n_bins * self.z_cells
        b = np.maximum(cells, 0)
        if self._ref is None:
            u = a["vel"] - self._bin_mean(cells, a["vel"], size)[b]
            w = a["omega"] - self._bin_mean(cells, a["omega"], size)[b] if spin else None
        else:
            u = a["vel"] - self._ref["velocity"][b]
            w = a["omega"] - self._ref["spin"][b] if spin else None
        return u, w

    def _common_attrs(self) -> dict[str, Any]:
        return {
            "dim": self.dim,
            "period": self.period,
            "image_velocity_shift": self.image_velocity_shift,
            "binning": "bin of the particle centre along y",
            "z_cells": self.z_cells,
            "fluctuations": "relative to the bin mean" if self.z_cells == 1 else
            f"relative to the means of {self.z_cells} z-cells per bin (Malik's cells)",
            "samples": self.n_frames,
            "block_length": self._acc.block_length,
            "n_blocks": self._acc.n_blocks,
            "units": UNITS_NOTE,
        }


class BinMeans(_Binned):
    """First pass: number-weighted run-mean velocity and spin of each y-bin (centre binning).

    Parameters: ``dim``, ``edges`` (or ``n_bins`` equal bins over the first frame's box, or
    over ``period``), ``period`` (y period, 0 = walls), ``image_velocity_shift`` (LE: shear
    rate * period), ``max_blocks``. Results: ``edges``, ``y``, ``count`` (mean particles per
    frame), ``velocity`` (n_bins, dim), ``spin`` (n_bins, n_rot), each with ``_err``.
    """

    def __init__(self, dim: int = 2, edges: ArrayLike | None = None, n_bins: int = 1,
                 period: float = 0.0, image_velocity_shift: float = 0.0, max_blocks: int = 64,
                 verbose: bool = False, z_cells: int = 1) -> None:
        super().__init__(dim, edges, n_bins, period, image_velocity_shift, max_blocks, verbose,
                         z_cells)

    def _prepare(self) -> None:
        self._set_edges(self.first_frame)
        self._nv = 1 + self.dim + self.n_rot
        self._n_cells = self.n_bins * self.z_cells
        self._acc = BlockAccumulator(self._n_cells * self._nv, self.max_blocks)

    def _single_frame(self, frame: Frame) -> None:
        a = self._assign(frame)
        keep = a["cells"] >= 0
        cells = a["cells"][keep]
        values = np.concatenate([np.ones((cells.size, 1)), a["vel"][keep], a["omega"][keep]], 1)
        sample = np.zeros((self._n_cells, self._nv))
        for c in range(self._nv):
            sample[:, c] = np.bincount(cells, weights=values[:, c], minlength=self._n_cells)
        self._acc.add(sample)

    def _estimate(self, mean: np.ndarray) -> dict[str, np.ndarray]:
        cells = mean.reshape(self._n_cells, self._nv)
        s = cells.reshape(self.n_bins, self.z_cells, self._nv).sum(1)
        n = s[:, :1]
        out = {"count": s[:, 0], "velocity": s[:, 1 : 1 + self.dim] / n,
               "spin": s[:, 1 + self.dim :] / n}
        if self.z_cells > 1:  # Malik's cell means, the second pass's reference
            nc = cells[:, :1]
            out.update({"cell_velocity": cells[:, 1 : 1 + self.dim] / nc,
                        "cell_spin": cells[:, 1 + self.dim :] / nc})
        return out

    def _conclude(self) -> None:
        est, err = jackknife(self._acc, self._estimate)
        self.results = {"edges": self.edges, "y": 0.5 * (self.edges[1:] + self.edges[:-1])}
        for key in est:
            self.results[key], self.results[f"{key}_err"] = est[key], err[key]
        self.attrs = {**self._common_attrs(), "weighting": "number (one per particle)"}


class VelocityCorrelation(_Binned):
    """Spatial correlations C_aa(r) and C_ab(r) (a != b, ``C_offdiag``) of velocity
    fluctuations per y-bin (see the module doc).

    Parameters
    ----------
    dim: 2 (discs) or 3 (spheres).
    edges: y-bin edges; None means ``n_bins`` equal bins over the first frame's box (or
        ``[lo, lo + period)``).
    r_max, dr: shells ``[0, dr), [dr, 2 dr), ...`` up to ``r_max``.
    reference: None (instantaneous bin means, one pass) or ``BinMeans(...).results`` of the
        same frames and edges (run-mean bin velocity, second pass).
    in_bin: partners only in the particle's own bin (Malik's binwise reading); otherwise
        partners anywhere (each with the fluctuation of its own bin).
    distance: "full" (dim-D distance) or "planar" (x(z) separation; needs ``in_bin``).
    period: y period (> 0: y periodic, Lees-Edwards images from ``frame.tilt``).
    image_velocity_shift: Lees-Edwards shear rate * period (used to unwrap velocities).
    chunk: particles per pair query (bounds the memory of one query).
    max_blocks: bound on the stored time blocks.
    """

    def __init__(self, dim: int = 2, edges: ArrayLike | None = None, n_bins: int = 1,
                 r_max: float = 5.0, dr: float = 0.1,
                 reference: Mapping[str, Any] | None = None, in_bin: bool = False,
                 distance: str = "full", period: float = 0.0,
                 image_velocity_shift: float = 0.0, chunk: int = 4096, max_blocks: int = 64,
                 verbose: bool = False, z_cells: int = 1) -> None:
        super().__init__(dim, edges, n_bins, period, image_velocity_shift, max_blocks, verbose,
                         z_cells)
        if not (r_max > 0 and dr > 0):
            raise ValueError("r_max and dr must be positive")
        if distance not in ("full", "planar"):
            raise ValueError(f"distance must be 'full' or 'planar', got {distance!r}")
        if distance == "planar" and not in_bin:
            raise ValueError("distance='planar' needs in_bin=True (pairs inside one bin)")
        self.n_r = max(1, int(round(r_max / dr)))
        self.dr = float(dr)
        self.r_edges = self.dr * np.arange(self.n_r + 1)
        self.in_bin, self.distance = bool(in_bin), distance
        self.chunk = max(1, int(chunk))
        self._reference = reference

    def _prepare(self) -> None:
        frame = self.first_frame
        self._set_edges(frame)
        self._reference_means(self._reference)
        self.r_image_limit = self._box(frame).image_limit
        # ordered off-diagonal (a, b), a != b: the pair (a, b) then its reverse (b, a)
        pairs = [(a, b) for a in range(self.dim) for b in range(a + 1, self.dim)]
        self._off = [ab for a, b in pairs for ab in ((a, b), (b, a))]
        # per bin: N | Q_a (dim) | P (n_r) | S_aa (dim x n_r) | S_ab (len(_off) x n_r)
        self._nv = 1 + self.dim + self.n_r * (1 + self.dim + len(self._off))
        self._acc = BlockAccumulator(self.n_bins * self._nv, self.max_blocks)

    def _single_frame(self, frame: Frame) -> None:
        a = self._assign(frame)
        u, _ = self._fluctuations(a)
        keep = a["bins"] >= 0
        pos, u, bins = a["pos"][keep], u[keep], a["bins"][keep]
        nb, nr, dim = self.n_bins, self.n_r, self.dim
        sample = np.zeros((nb, self._nv))
        sample[:, 0] = np.bincount(bins, minlength=nb)
        for c in range(dim):
            sample[:, 1 + c] = np.bincount(bins, weights=u[:, c] ** 2, minlength=nb)
        whole_period = self.period and nb == 1 and np.isclose(self.edges[-1] - self.edges[0],
                                                              self.period)
        if self.in_bin and not whole_period:
            groups = [np.flatnonzero(bins == b) for b in range(nb)]
        else:
            groups = [np.arange(len(bins))]
        # partners across y only when y is periodic and pairs may leave a bin
        box = a["box"] if whole_period or not self.in_bin else a["box"].with_bounded_y()
        plane = [0, 2] if dim == 3 else [0]
        if self.distance == "planar":
            box, pos = box.project(plane), pos[:, plane]
        for sel in groups:
            if sel.size < 2:
                continue
            i, j, r = NeighbourQuery(box, pos[sel]).pairs(self.r_edges[-1], chunk=self.chunk)
            i, j = sel[i], sel[j]
            k = np.minimum((r / self.dr).astype(np.int64), nr - 1)
            idx = bins[i] * nr + k
            sample[:, 1 + dim : 1 + dim + nr] += np.bincount(
                idx, minlength=nb * nr).reshape(nb, nr)
            for c, (ca, cb) in enumerate([(c, c) for c in range(dim)] + self._off):
                col = 1 + dim + nr * (1 + c)
                sample[:, col : col + nr] += np.bincount(
                    idx, weights=u[i, ca] * u[j, cb], minlength=nb * nr).reshape(nb, nr)
        self._acc.add(sample)

    def _estimate(self, mean: np.ndarray) -> dict[str, np.ndarray]:
        nb, nr, dim = self.n_bins, self.n_r, self.dim
        s = mean.reshape(nb, self._nv)
        n, q = s[:, 0], s[:, 1 : 1 + dim]
        p = s[:, 1 + dim : 1 + dim + nr]
        sums = s[:, 1 + dim + nr : 1 + dim + nr * (1 + dim)].reshape(nb, dim, nr)
        cov = sums / p[:, None, :]
        temp = q / n[:, None]
        # ordered off-diagonal covariances in pairs: [:, 0::2] is (a, b), [:, 1::2] is (b, a)
        off = s[:, 1 + dim + nr * (1 + dim) :].reshape(nb, len(self._off), nr) / p[:, None, :]
        sym, anti = 0.5 * (off[:, 0::2] + off[:, 1::2]), 0.5 * (off[:, 0::2] - off[:, 1::2])
        norm = np.sqrt(np.stack([temp[:, a] * temp[:, b] for a, b in self._off[0::2]],
                                axis=1))[:, :, None]
        return {
            "C": cov / temp[:, :, None],
            "covariance": cov,
            "C_offdiag": sym / norm,
            "C_offdiag_antisym": anti / norm,
            "covariance_offdiag": sym,
            "temperature_components": temp,
            "C_malik": sums / (2 * self.dr * q[:, :, None]),
            "pairs_per_particle": p / n[:, None],
            "count": n,
        }

    def _conclude(self) -> None:
        est, err = jackknife(self._acc, self._estimate)
        self.results = {
            "r": 0.5 * (self.r_edges[1:] + self.r_edges[:-1]),
            "r_edges": self.r_edges,
            "edges": self.edges,
            "y": 0.5 * (self.edges[1:] + self.edges[:-1]),
            "image_artefact": self.r_edges[1:] > self.r_image_limit + 1e-12,
        }
        for key in est:
            self.results[key], self.results[f"{key}_err"] = est[key], err[key]
        self.attrs = {
            **self._common_attrs(),
            "components": ",".join("xyz"[: self.dim]),
            "offdiag_components": ",".join("xyz"[a] + "xyz"[b] for a, b in self._off[0::2]),
            "shape": "C, covariance, C_malik: (n_bins, dim, n_r); C_offdiag, "
                     "C_offdiag_antisym, covariance_offdiag: (n_bins, dim (dim - 1) / 2, n_r)",
            "in_bin": self.in_bin,
            "distance": self.distance,
            "dr": self.dr,
            "r_max": float(self.r_edges[-1]),
            "r_image_limit": self.r_image_limit,
            "mean": "instantaneous bin mean" if self._ref is None
            else "run-mean bin velocity (first pass)",
            "normalisation": "C = <sum_pairs u'_i u'_j>/<pairs> / (<sum_i u'_i^2>/<N>); "
                             "C_offdiag_ab = (<u'_ia u'_jb> + <u'_ib u'_ja>)/2 / sqrt(T_a T_b)",
        }


class OrientationalCorrelation(_Binned):
    """Malik's Lambda(y) = <cos^2 Psi> between translational and spin fluctuations (3D only).

    Parameters: ``edges`` / ``n_bins``, ``reference`` (None: instantaneous bin means of
    velocity and spin; or ``BinMeans(...).results``: run means), ``period``,
    ``image_velocity_shift``, ``max_blocks``; see the module docstring for the definitions.
    """

    def __init__(self, dim: int = 3, edges: ArrayLike | None = None, n_bins: int = 1,
                 reference: Mapping[str, Any] | None = None, period: float = 0.0,
                 image_velocity_shift: float = 0.0, max_blocks: int = 64,
                 verbose: bool = False, z_cells: int = 1) -> None:
        if dim != 3:
            raise ValueError("Lambda needs 3D: in 2D the spin omega_z is perpendicular to "
                             "every in-plane velocity, so cos(Psi) = 0 identically")
        super().__init__(dim, edges, n_bins, period, image_velocity_shift, max_blocks, verbose,
                         z_cells)
        self._reference = reference

    def _prepare(self) -> None:
        self._set_edges(self.first_frame)
        self._reference_means(self._reference)
        self._acc = BlockAccumulator(self.n_bins * 4, self.max_blocks)

    def _single_frame(self, frame: Frame) -> None:
        a = self._assign(frame)
        c, w = self._fluctuations(a, spin=True)
        c2, w2 = (c * c).sum(1), (w * w).sum(1)
        ok = (a["bins"] >= 0) & (c2 > 0) & (w2 > 0)
        bins = a["bins"][ok]
        cos2 = (c[ok] * w[ok]).sum(1) ** 2 / (c2[ok] * w2[ok])
        nb = self.n_bins
        n = np.bincount(bins, minlength=nb).astype(float)
        total = np.bincount(bins, weights=cos2, minlength=nb)
        has = n > 0
        sample = np.stack([n, total, np.where(has, total / np.maximum(n, 1), 0.0),
                           has.astype(float)], axis=1)
        self._acc.add(sample)

    def _estimate(self, mean: np.ndarray) -> dict[str, np.ndarray]:
        s = mean.reshape(self.n_bins, 4)
        return {"lambda": s[:, 2] / s[:, 3], "lambda_pooled": s[:, 1] / s[:, 0],
                "count": s[:, 0]}

    def _conclude(self) -> None:
        est, err = jackknife(self._acc, self._estimate)
        self.results = {"edges": self.edges, "y": 0.5 * (self.edges[1:] + self.edges[:-1])}
        for key in est:
            self.results[key], self.results[f"{key}_err"] = est[key], err[key]
        self.attrs = {
            **self._common_attrs(),
            "uncorrelated_value": 1.0 / 3.0,
            "mean": "instantaneous bin means" if self._ref is None
            else "run-mean bin velocity and spin (first pass)",
            "definition": "lambda = <(1/N_b) sum_i (C.W)^2/(C^2 W^2)>_frames",
        }


def _two_pass(cls: type, frames: Callable[[], Iterable[Frame]] | Iterable[Frame],
              options: dict[str, Any]) -> AnalysisBase:
    if not callable(frames) and iter(frames) is frames:
        raise TypeError("two passes read the frames twice: pass a list or a callable "
                        "returning a fresh iterator, not an iterator")
    source = frames if callable(frames) else (lambda: frames)
    keys = ("dim", "edges", "n_bins", "period", "image_velocity_shift", "max_blocks", "z_cells")
    first = BinMeans(**{k: options[k] for k in keys if k in options}).run(source())
    options = {**options, "edges": first.edges, "reference": first.results}
    return cls(**options).run(source())


def velocity_correlations(frames: Callable[[], Iterable[Frame]] | Iterable[Frame],
                          **options: Any) -> VelocityCorrelation:
    """Two passes: run-mean bin velocities (:class:`BinMeans`), then C_aa(r), C_ab(r) of the
    fluctuations about them. ``frames``: a list or a callable returning fresh iterables."""
    return _two_pass(VelocityCorrelation, frames, options)


def orientational_correlation(frames: Callable[[], Iterable[Frame]] | Iterable[Frame],
                              **options: Any) -> OrientationalCorrelation:
    """Two passes: run-mean bin velocities and spins, then Lambda(y) about them."""
    options.setdefault("dim", 3)
    return _two_pass(OrientationalCorrelation, frames, options)
