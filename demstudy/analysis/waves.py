"""Density waves: coarse-grained solid fraction on planes, power spectra, pattern class.

Dimensionless particle units: d = 1, m = 1. Axes: x flow (periodic), y wall-normal (walls,
or periodic), z spanwise (3D, periodic). Follows Malik (2008, §4.10-4.11) and Liss et al.
(2002).

Field. The box (or ``ranges``) is cut into n_x x n_y (x n_z) cells of about ``cell_size``;
every frame the solid fraction of a cell of plane (a, b) is sum V_i / (h_a h_b L_c) over the
particles whose *centre* lies in the column of cells (Malik: "average over the particles in a
cell"), i.e. averaged over the third axis c (3D). Planes: "xy" in 2D; "xy", "xz", "yz" in 3D.
Between walls, pass the range the centres can reach (walls +- d/2, as ``demstudy analyze``
does) so that a homogeneous gas gives a flat field. Lees-Edwards (``periodic_y`` and
``frame.tilt`` != 0): the grid is sheared with the box, x' = x - tilt (y - y_lo) / L_y, the
frame in which the density is periodic in x and y.

Spectrum. X = fft2(nu) on the n_a x n_b mesh and Malik's P = 2 |X|^2 / (n_a n_b)^2, averaged
over frames (the mean spectrum, so that travelling waves do not average out). k are integer
harmonics (waves per box length). A *mode family* F = (|k_a|, |k_b|) collects the +-k_a, +-k_b
modes; its power P_F = sum of P over them and its **amplitude** A_F = sqrt(P_F): a single
wave A cos(2 pi (k_a a / L_a + k_b b / L_b)) on the mesh has A_F = A times the cell-average
factor sinc(pi k_a / n_a) sinc(pi k_b / n_b), sinc(t) = sin(t)/t (Nyquist modes excepted).

Dominant modes. The noise floor f is the median of P over all modes but (0, 0) (a white
spectrum, e.g. the shot noise 2 var(nu_cell) / (n_a n_b) of an ideal gas, is flat at f); a
family F != (0, 0) with m_F members is *dominant* if P_F > ``peak_ratio`` * m_F * f and
P_F - m_F f > ``z`` * (its block-jackknife error, when there are >= 2 blocks).

Classification (xy plane: x flow, y across the channel). With the mirror y -> y_lo + y_hi - y
about the centreline the field splits into a symmetric ("varicose") and an antisymmetric
("sinuous") part; within a family the two powers add up to P_F exactly. Over the dominant
families with k_x >= 1 (x-varying) let s = their symmetric and a = their antisymmetric power:

* "none": no dominant family (homogeneous, or only noise);
* "plug": every dominant family has k_x = 0 (density varies across y only; Malik's (0,1));
* "s-wave": a >= 2/3 (a + s): dense on one side of the centreline faces dilute on the other,
  the antisymmetric mode (birth of (1,1): one hump; (2,1): two humps);
* "slug": s >= 2/3 (a + s): dense regions symmetric about the centreline that vary along x,
  Malik's (0,1) + (1,0) (a pure (k,0) band also counts as a slug; Malik's "(3,0) for three
  humps" of an S-wave is not followed);
* "mixed": otherwise (Malik's wavy slug / sandwich).

In 3D ``z_structure`` is True when a dominant family of the xz or yz plane has k_z >= 1
(Malik's "3D wave" shows peaks in all planes). The parity rule needs a channel (walls along y);
in a y-periodic box the "centreline" is the grid centre, and the class is only indicative.

Steadiness. ``series_<plane>`` holds the per-frame amplitudes of the low families
(|k_a|, |k_b| <= ``k_series``, listed in ``series_modes_<plane>``) in a decimating buffer of at
most ``max_series`` points: when full, neighbouring points are averaged pairwise, so memory is
flat in the number of frames (``series_frames`` = frames per point).

Errors: delete-one-block jackknife over time blocks (BlockAccumulator), memory flat in the
number of frames.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from demstudy import UNITS_NOTE
from demstudy.analysis.base import AnalysisBase
from demstudy.analysis.blocking import BlockAccumulator, jackknife
from demstudy.io.frames import Frame

__all__ = ["DensityWaves", "classify_pattern"]

_AX = {"x": 0, "y": 1, "z": 2}


class _Series:
    """Bounded time series: at most ``max_points`` points, pairwise averaged when full."""

    def __init__(self, n_values: int, max_points: int) -> None:
        self.max = max(2, int(max_points) // 2 * 2)
        self.per = 1
        self.n = 0
        self._t = np.zeros(self.max)
        self._v = np.zeros((self.max, n_values))
        self._pt, self._pv, self._pc = 0.0, np.zeros(n_values), 0

    def add(self, t: float, v: np.ndarray) -> None:
        self._pt += t
        self._pv += v
        self._pc += 1
        if self._pc < self.per:
            return
        self._t[self.n], self._v[self.n] = self._pt / self._pc, self._pv / self._pc
        self.n += 1
        self._pt, self._pv, self._pc = 0.0, np.zeros_like(self._pv), 0
        if self.n == self.max:
            h = self.max // 2
            self._t[:h] = 0.5 * (self._t[0::2] + self._t[1::2])
            self._v[:h] = 0.5 * (self._v[0::2] + self._v[1::2])
            self.n, self.per = h, 2 * self.per

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        t, v = self._t[: self.n], self._v[: self.n]
        frames = np.full(self.n, self.per)
        if self._pc:
            t = np.append(t, self._pt / self._pc)
            v = np.vstack([v, self._pv / self._pc])
            frames = np.append(frames, self._pc)
        return t, v, frames


def classify_pattern(dominant: ArrayLike, symmetric: ArrayLike,
                     antisymmetric: ArrayLike) -> str:
    """The xy pattern from the dominant families (rows (k_x, k_y)) and their symmetric and
    antisymmetric powers (see the module docstring for the rule)."""
    dom = np.asarray(dominant, int).reshape(-1, 2)
    if dom.shape[0] == 0:
        return "none"
    moving = dom[:, 0] >= 1
    if not moving.any():
        return "plug"
    s = float(np.sum(np.asarray(symmetric, float)[moving]))
    a = float(np.sum(np.asarray(antisymmetric, float)[moving]))
    if a >= 2.0 / 3.0 * (a + s):
        return "s-wave"
    if s >= 2.0 / 3.0 * (a + s):
        return "slug"
    return "mixed"


class DensityWaves(AnalysisBase):
    """Plane-averaged solid-fraction fields, mean power spectra, dominant modes and pattern.

    Parameters
    ----------
    dim: 2 (discs) or 3 (spheres).
    planes: subset of "xy", "xz", "yz" (default: "xy" in 2D, all three in 3D).
    cell_size: target cell edge; n = max(2, round(length / cell_size)) cells per axis.
    cells: explicit cells per axis (length dim), overrides ``cell_size``.
    ranges: per axis (lo, hi) or None (the first frame's box); centres outside are dropped
        along bounded axes and wrapped along periodic ones.
    periodic_y: y is periodic (x and z always are).
    peak_ratio, z: dominance thresholds (see the module docstring).
    n_leading: number of leading families reported per plane.
    k_series, max_series: families and length of the bounded amplitude time series.
    max_blocks: bound on the stored time blocks.
    """

    def __init__(self, dim: int = 3, planes: tuple[str, ...] | None = None,
                 cell_size: float = 2.0, cells: ArrayLike | None = None,
                 ranges: list[tuple[float, float] | None] | None = None,
                 periodic_y: bool = False, peak_ratio: float = 20.0, z: float = 3.0,
                 n_leading: int = 5, k_series: int = 3, max_series: int = 1024,
                 max_blocks: int = 64, verbose: bool = False) -> None:
        super().__init__(verbose=verbose)
        if dim not in (2, 3):
            raise ValueError(f"dim must be 2 or 3, got {dim!r}")
        self.dim = dim
        self.planes = tuple(planes) if planes is not None else (
            ("xy",) if dim == 2 else ("xy", "xz", "yz"))
        for p in self.planes:
            if p not in ("xy", "xz", "yz") or (dim == 2 and p != "xy"):
                raise ValueError(f"plane {p!r} does not exist in {dim}D")
        if not cell_size > 0:
            raise ValueError("cell_size must be positive")
        self.cell_size = float(cell_size)
        self._cells = None if cells is None else np.asarray(cells, int)
        if self._cells is not None and (self._cells.shape != (dim,) or np.any(self._cells < 2)):
            raise ValueError(f"cells must give >= 2 cells for each of the {dim} axes")
        self._ranges = ranges
        self.periodic = np.array([True, bool(periodic_y), True][:dim])
        self.peak_ratio, self.z = float(peak_ratio), float(z)
        self.n_leading, self.k_series = int(n_leading), int(k_series)
        self.max_series, self.max_blocks = int(max_series), int(max_blocks)

    # -- set-up ------------------------------------------------------------------------
    def _prepare(self) -> None:
        frame = self.first_frame
        if frame.dim != self.dim:
            raise ValueError(f"frame is {frame.dim}D, analysis is {self.dim}D")
        box_lo, box_hi = np.asarray(frame.box_lo, float), np.asarray(frame.box_hi, float)
        rng = self._ranges or [None] * self.dim
        self.lo = np.array([box_lo[i] if r is None else r[0] for i, r in enumerate(rng)], float)
        self.hi = np.array([box_hi[i] if r is None else r[1] for i, r in enumerate(rng)], float)
        if np.any(self.hi <= self.lo):
            raise ValueError("empty grid range")
        self.length = self.hi - self.lo
        self.n = self._cells if self._cells is not None else np.maximum(
            2, np.round(self.length / self.cell_size).astype(int))
        self.h = self.length / self.n
        self._geo: dict[str, dict[str, Any]] = {}
        for p in self.planes:
            a, b = _AX[p[0]], _AX[p[1]]
            na, nb = int(self.n[a]), int(self.n[b])
            ka = np.minimum(np.arange(na), na - np.arange(na))
            kb = np.minimum(np.arange(nb), nb - np.arange(nb))
            fb = nb // 2 + 1
            fam = (ka[:, None] * fb + kb[None, :]).ravel()
            n_fam = (na // 2 + 1) * fb
            members = np.bincount(fam, minlength=n_fam)
            low = [(i, j) for i in range(min(self.k_series, na // 2) + 1)
                   for j in range(min(self.k_series, nb // 2) + 1) if (i, j) != (0, 0)]
            third = 3 - a - b if self.dim == 3 else None
            depth = self.length[third] if third is not None else 1.0
            self._geo[p] = {
                "a": a, "b": b, "na": na, "nb": nb, "fb": fb, "fam": fam, "n_fam": n_fam,
                "members": members, "cell_volume": self.h[a] * self.h[b] * depth,
                "low": np.array(low, int).reshape(-1, 2),
                "low_idx": np.array([i * fb + j for i, j in low], int),
                "acc": BlockAccumulator(na * nb * 2 + 2 * n_fam, self.max_blocks),
                "series": _Series(len(low), self.max_series),
            }

    def _single_frame(self, frame: Frame) -> None:
        pos = np.array(frame.position, float)
        radius = np.asarray(frame.radius, float)
        if pos.shape != (radius.size, self.dim):
            raise ValueError(f"position must have shape (N, {self.dim})")
        if self.periodic[1] and frame.tilt:
            ly = float(frame.lengths[1])
            turns = np.floor((pos[:, 1] - self.lo[1]) / ly)
            pos[:, 1] -= turns * ly
            pos[:, 0] -= turns * float(frame.tilt)
            pos[:, 0] -= float(frame.tilt) * (pos[:, 1] - self.lo[1]) / ly  # sheared grid
        rel = (pos - self.lo) / self.h
        idx = np.floor(rel).astype(np.int64)
        for ax in range(self.dim):
            if self.periodic[ax]:
                idx[:, ax] = np.mod(idx[:, ax], self.n[ax])
        inside = np.all((idx >= 0) & (idx < self.n), axis=1)
        unit = np.pi * radius**2 if self.dim == 2 else 4.0 / 3.0 * np.pi * radius**3
        vol, idx = unit[inside], idx[inside]
        for g in self._geo.values():
            na, nb = g["na"], g["nb"]
            flat = idx[:, g["a"]] * nb + idx[:, g["b"]]
            field = np.bincount(flat, weights=vol, minlength=na * nb).reshape(na, nb)
            field /= g["cell_volume"]
            power = self._power(field)
            mirror = field[:, ::-1]
            fam_s = self._families(g, self._power(0.5 * (field + mirror)))
            fam_a = self._families(g, self._power(0.5 * (field - mirror)))
            g["acc"].add(np.concatenate([field.ravel(), power.ravel(), fam_s, fam_a]))
            g["series"].add(float(frame.time), np.sqrt(fam_s + fam_a)[g["low_idx"]])

    @staticmethod
    def _power(field: np.ndarray) -> np.ndarray:
        return 2.0 * np.abs(np.fft.fft2(field)) ** 2 / field.size**2

    @staticmethod
    def _families(g: dict[str, Any], power: np.ndarray) -> np.ndarray:
        return np.bincount(g["fam"], weights=power.ravel(), minlength=g["n_fam"])

    # -- results -----------------------------------------------------------------------
    def _estimator(self, g: dict[str, Any]):
        na, nb, nf = g["na"], g["nb"], g["n_fam"]

        def est(mean: np.ndarray) -> dict[str, np.ndarray]:
            power = mean[na * nb : 2 * na * nb]
            sym, anti = mean[2 * na * nb : 2 * na * nb + nf], mean[2 * na * nb + nf :]
            return {"field": mean[: na * nb].reshape(na, nb),
                    "spectrum": power.reshape(na, nb),
                    "family_power": self._families(g, power), "symmetric": sym,
                    "antisymmetric": anti}

        return est

    def _conclude(self) -> None:
        self.results, z_structure = {}, False
        self.attrs = {"dim": self.dim, "planes": ",".join(self.planes)}
        for p, g in self._geo.items():
            est, err = jackknife(g["acc"], self._estimator(g))
            fb = g["fb"]
            power = est["spectrum"].ravel()
            floor = float(np.median(power[1:])) if power.size > 1 else 0.0
            fam_p, fam_e = est["family_power"], err["family_power"]
            excess = fam_p - g["members"] * floor
            with np.errstate(invalid="ignore"):
                significant = np.where(np.isfinite(fam_e), excess > self.z * fam_e, True)
            dom = (fam_p > self.peak_ratio * g["members"] * floor) & significant
            dom[0] = False
            order = np.argsort(-np.where(np.arange(fam_p.size) == 0, -np.inf, fam_p))
            dom_idx = order[dom[order]]
            lead = order[: min(self.n_leading, fam_p.size - 1)]

            def kk(ids: np.ndarray, fb: int = fb) -> np.ndarray:
                return np.stack([ids // fb, ids % fb], axis=1).astype(int).reshape(-1, 2)

            shape = (g["na"] // 2 + 1, fb)
            t, series, frames = g["series"].arrays()
            self.results.update({
                f"field_{p}": est["field"], f"field_{p}_err": err["field"],
                f"spectrum_{p}": est["spectrum"], f"spectrum_{p}_err": err["spectrum"],
                f"k_{p[0]}_{p}": np.fft.fftfreq(g["na"], 1.0 / g["na"]).astype(int),
                f"k_{p[1]}_{p}": np.fft.fftfreq(g["nb"], 1.0 / g["nb"]).astype(int),
                f"family_power_{p}": fam_p.reshape(shape),
                f"family_power_{p}_err": fam_e.reshape(shape),
                f"amplitude_{p}": np.sqrt(fam_p).reshape(shape),
                f"antisymmetric_fraction_{p}": (est["antisymmetric"] / fam_p).reshape(shape),
                f"dominant_{p}": kk(dom_idx),
                f"leading_{p}": kk(lead),
                f"leading_amplitude_{p}": np.sqrt(fam_p[lead]),
                f"leading_amplitude_{p}_err": 0.5 * fam_e[lead] / np.sqrt(fam_p[lead]),
                f"series_{p}": series, f"series_modes_{p}": g["low"],
            })
            self.results["series_time"], self.results["series_frames"] = t, frames
            self.attrs[f"noise_floor_{p}"] = floor
            self.attrs[f"cells_{p}"] = f"{g['na']}x{g['nb']}"
            if p == "xy":
                self.attrs["pattern"] = classify_pattern(
                    kk(dom_idx), est["symmetric"][dom_idx], est["antisymmetric"][dom_idx])
            elif np.any(kk(dom_idx)[:, 1] >= 1):  # xz, yz: the second axis is z
                z_structure = True
        if self.dim == 3:
            self.attrs["z_structure"] = z_structure
        acc = self._geo[self.planes[0]]["acc"]
        self.attrs.update({
            "lo": self.lo, "hi": self.hi, "cells": self.n, "peak_ratio": self.peak_ratio,
            "z": self.z, "spectrum": "P = 2 |fft2(nu)|^2 / (n_a n_b)^2, mean over frames",
            "amplitude": "sqrt(sum of P over the +-k modes of a family)",
            "classification": "none / plug / s-wave / slug / mixed (see demstudy.analysis.waves)",
            "samples": self.n_frames, "block_length": acc.block_length,
            "n_blocks": acc.n_blocks, "units": UNITS_NOTE,
        })
