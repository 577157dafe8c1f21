"""Profiles and stress tensors of one run moved to another bin grid (``demstudy compare`` of
runs with different bins). Dimensionless particle units: d = 1, m = 1 (uniform material
density: a particle's mass is its volume over V_1, V_1 = π/4 in 2D, π/6 in 3D).

A source bin i contributes to a target bin j in proportion to the length of their overlap
A_ji (whole bins when the grids nest; a bin split between two target bins is assumed uniform
inside). Each field is combined with the weight its definition carries
(:mod:`demstudy.analysis.profiles`): volume for the solid fraction, number density and
stresses, mass for the mean velocity, spin and kinetic shear, particle number for the mean
mass and the temperatures. Temperatures and kinetic stresses are fluctuations about the bin's
mean velocity, so a wider bin also holds the spread of the narrower bins' means: the target
gets Σ_i A_ji ρ_i (u_i − U_j)² (ρ the mass density, U_j the target's mean velocity), which
makes rebinned and natively coarse profiles the same up to the volume splitting at the
edges. Errors combine in quadrature as independent bins; the spread term carries the error
of the finer bins' mean velocities (linearised), and its bias from their noise,
Σ_i A_ji ρ_i σ_i² (1 − A_ji ρ_i / Σ A ρ), is taken off.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ..errors import NotComparable

__all__ = ["RULES", "common_grid", "overlap", "rebin_profiles", "rebin_stress", "splits_bins"]

UNIT_VOLUME = {2: math.pi / 4, 3: math.pi / 6}

#: how each profile is combined (names not listed cannot be rebinned and are left out)
RULES = {"solid_fraction": "volume", "number_density": "volume", "mean_mass": "number",
         "velocity": "mass", "spin": "mass", "kinetic_shear": "covariance",
         "temperature": "temperature", "temperature_components": "temperature",
         "rotational_temperature": "rotational"}


def common_grid(a: np.ndarray, b: np.ndarray, tol: float = 1e-9) -> np.ndarray | None:
    """The bins two runs are compared on: ``None`` when their edges coincide; otherwise the
    coarser grid's bins that lie inside the range both runs cover. ``NotComparable`` when the
    ranges do not overlap by a whole bin of the coarser grid."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    if a.shape == b.shape and np.allclose(a, b, rtol=tol, atol=tol):
        return None
    lo, hi = max(a[0], b[0]), min(a[-1], b[-1])
    coarse = a if np.mean(np.diff(a)) >= np.mean(np.diff(b)) else b
    slack = tol * max(1.0, abs(hi - lo))
    inside = coarse[(coarse >= lo - slack) & (coarse <= hi + slack)]
    if inside.size < 2:
        raise NotComparable(f"the bins do not overlap by a whole bin: [{a[0]:g}, {a[-1]:g}] in "
                         f"{a.size - 1} bins and [{b[0]:g}, {b[-1]:g}] in {b.size - 1} bins")
    return inside


def overlap(src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """A[j, i]: length of source bin i inside target bin j."""
    lo = np.maximum(dst[:-1, None], src[None, :-1])
    hi = np.minimum(dst[1:, None], src[None, 1:])
    return np.clip(hi - lo, 0.0, None)


class _Mover:
    """Weighted bin means of one run's fields onto the target bins (see the module doc)."""

    def __init__(self, prof: dict[str, np.ndarray], dst: np.ndarray, dim: int):
        self.a = overlap(np.asarray(prof["edges"], float), dst)
        phi = np.nan_to_num(np.asarray(prof["solid_fraction"], float))
        n = prof.get("number_density")
        n = phi / UNIT_VOLUME[dim] if n is None else np.nan_to_num(np.asarray(n, float))
        mean_mass = np.nan_to_num(np.asarray(prof.get("mean_mass", np.ones_like(n)), float))
        self.weights = {"volume": np.ones_like(phi), "number": n, "mass": n * mean_mass}
        self.prof = prof
        u = np.asarray(prof["velocity"], float).reshape(len(phi), -1)
        self.u = u
        self.u_err = np.asarray(prof.get("velocity_err", np.zeros_like(u)), float).reshape(
            u.shape)
        self.u_mean = self.mean(u, np.zeros_like(u), "mass")[0]

    def mean(self, q: np.ndarray, err: np.ndarray, weight: str,
             extra: tuple[np.ndarray, np.ndarray] | None = None
             ) -> tuple[np.ndarray, np.ndarray]:
        """Σ_i A_ji w_i q_i (+ extra_j) over Σ_i A_ji w_i, and its error in quadrature;
        ``extra``: (value, variance) of a spread term."""
        w = self.a * self.weights[weight][None, :]
        total = w.sum(1)
        shape = q.shape
        q2 = np.where(w.sum(0)[:, None] > 0, q.reshape(shape[0], -1), 0.0)
        e2 = np.where(w.sum(0)[:, None] > 0, err.reshape(shape[0], -1), 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            coef = w / total[:, None]
            val = coef @ q2
            var = (coef**2) @ (e2**2)
            if extra is not None:
                val = val + extra[0].reshape(val.shape) / total[:, None]
                var = var + extra[1].reshape(var.shape) / total[:, None] ** 2
            out_err = np.sqrt(var)
        val[total <= 0] = np.nan
        out_err[total <= 0] = np.nan
        return val.reshape((len(total), *shape[1:])), out_err.reshape((len(total), *shape[1:]))

    def spread(self, q: np.ndarray, q_err: np.ndarray, q_mean: np.ndarray, a: int, b: int
               ) -> tuple[np.ndarray, np.ndarray]:
        """(value, variance) of Σ_i A_ji ρ_i (q_ia − Q_ja)(q_ib − Q_jb), the bins' mean-flow
        spread in target j: debiased, with the linearised error of the q_i (the derivative
        through Q_j vanishes: Σ_i A_ji ρ_i (q_i − Q_j) = 0)."""
        w = self.a * self.weights["mass"][None, :]
        da = np.nan_to_num(q[None, :, a] - q_mean[:, None, a])
        db = np.nan_to_num(q[None, :, b] - q_mean[:, None, b])
        ea, eb = (np.nan_to_num(q_err[None, :, k]) for k in (a, b))
        val = (w * da * db).sum(1)
        if a == b:
            with np.errstate(divide="ignore", invalid="ignore"):
                share = np.nan_to_num(w / w.sum(1)[:, None])
            val = val - (w * ea**2 * (1.0 - share)).sum(1)
            var = ((2.0 * w * da * ea) ** 2).sum(1)
        else:
            var = (w**2 * ((db * ea) ** 2 + (da * eb) ** 2)).sum(1)
        return val, var


def _add(*terms: tuple[np.ndarray, np.ndarray], scale: float = 1.0
         ) -> tuple[np.ndarray, np.ndarray]:
    """scale × the sum of spread terms (value, variance), taken as independent."""
    return scale * sum(t[0] for t in terms), scale**2 * sum(t[1] for t in terms)


def rebin_profiles(prof: dict[str, np.ndarray], dst: np.ndarray, dim: int,
                   inertia_factor: float) -> tuple[dict[str, np.ndarray], list[str]]:
    """The profiles (with ``_err``) on the target edges ``dst``, and the names that could not
    be rebinned (no rule, e.g. Malik's cell temperatures)."""
    mv = _Mover(prof, dst, dim)
    u, u_err, u_mean = mv.u, mv.u_err, mv.u_mean
    out: dict[str, np.ndarray] = {"edges": dst, "y": 0.5 * (dst[1:] + dst[:-1])}
    left: list[str] = []
    rules: dict[str, Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]] = {
        "volume": lambda q, e: mv.mean(q, e, "volume"),
        "number": lambda q, e: mv.mean(q, e, "number"),
        "mass": lambda q, e: mv.mean(q, e, "mass"),
    }
    for name, value in prof.items():
        if name in ("edges", "y") or name.endswith("_err") or f"{name}_err" not in prof:
            continue
        q, e = np.asarray(value, float), np.asarray(prof[f"{name}_err"], float)
        rule = RULES.get(name)
        if q.ndim == 0 or rule is None:
            left.append(name)
            continue
        if rule in rules:
            val, err = rules[rule](q, e)
        elif rule == "temperature":  # + the mean-flow spread per component (over dim: T)
            comps = [mv.spread(u, u_err, u_mean, k, k) for k in range(u.shape[1])]
            extra = (np.stack([c[0] for c in comps], 1), np.stack([c[1] for c in comps], 1)) \
                if q.ndim == 2 else _add(*comps, scale=1.0 / dim)
            val, err = mv.mean(q, e, "number", extra)
        elif rule == "rotational":  # I (ω_i − Ω)² per rotational degree of freedom
            if "spin" not in prof:
                left.append(name)
                continue
            w = np.asarray(prof["spin"], float).reshape(len(u), -1)
            w_err = np.asarray(prof.get("spin_err", np.zeros_like(w)), float).reshape(w.shape)
            w_mean = mv.mean(w, np.zeros_like(w), "mass")[0]
            j = inertia_factor / 4.0  # I/m of a particle of d = 1
            extra = _add(*(mv.spread(w, w_err, w_mean, k, k) for k in range(w.shape[1])),
                         scale=j / w.shape[1])
            val, err = mv.mean(q, e, "number", extra)
        else:  # covariance of u and v about the target's mean
            val, err = mv.mean(q, e, "mass", mv.spread(u, u_err, u_mean, 0, 1))
        out[name], out[f"{name}_err"] = val, err
    return out, left


def rebin_stress(stress: dict[str, np.ndarray], prof: dict[str, np.ndarray],
                 dst: np.ndarray, dim: int) -> dict[str, np.ndarray]:
    """The stress group's ``total`` and ``kinetic`` tensors (with errors; the others are
    dropped) on the target edges: volume means, plus the mean-flow spread ρ (u_a − U_a)
    (u_b − U_b) that a wider bin's kinetic stress holds. ``prof``: the same run's profiles,
    on the stress group's bins."""
    mv = _Mover({**prof, "edges": stress["edges"]}, dst, dim)
    out: dict[str, np.ndarray] = {"edges": dst, "y": 0.5 * (dst[1:] + dst[:-1])}
    for name in ("total", "kinetic"):
        if name not in stress or f"{name}_err" not in stress:
            continue
        q, e = np.asarray(stress[name], float), np.asarray(stress[f"{name}_err"], float)
        k, n_out = q.shape[1], len(dst) - 1
        val, var = np.zeros((n_out, k, k)), np.zeros((n_out, k, k))
        for a in range(min(k, mv.u.shape[1])):
            for b in range(min(k, mv.u.shape[1])):
                val[:, a, b], var[:, a, b] = mv.spread(mv.u, mv.u_err, mv.u_mean, a, b)
        extra = (val, var)
        out[name], out[f"{name}_err"] = mv.mean(q, e, "volume", extra)
    return out


def splits_bins(src: np.ndarray, dst: np.ndarray) -> bool:
    """Whether a source bin inside the target range is shared between target bins (grids
    that do not nest: the uniform-inside assumption is used)."""
    a = overlap(np.asarray(src, float), np.asarray(dst, float))
    width = np.diff(np.asarray(src, float))
    covered = a.sum(0)
    partly = (covered > 1e-9 * width) & (covered < width * (1 - 1e-9))
    return bool(np.any(partly) or np.any((a > 1e-9 * width[None, :]).sum(0) > 1))
