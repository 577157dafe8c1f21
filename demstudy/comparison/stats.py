"""The significance test shared by ``demstudy.testing`` and ``demstudy compare``: per-value
z-scores judged with Student's t and a Šidák-corrected family level.

Each difference is divided by its combined standard error √(σ_a² + σ_b²). The errors are
estimates, so the ratio follows Student's t with the Welch–Satterthwaite degrees of freedom,
not the normal distribution: with 20 blocks a 3σ-normal test would fail several times too
often. A single run's errors are its finest blocks' jackknife scaled by a fitted statistical
inefficiency, so they rest on at most ``effective_samples`` independent samples, not on
``n_blocks``: dof = max(1, min(n_blocks, effective_samples) − 1) per run. A replica mean
(``n_blocks`` = R replicas, no ``effective_samples``) has R − 1. A family of n values
fails with the probability of one two-sided ``sigma``-σ normal event (0.27 % at 3σ) when both
runs sample the same state: each value is held to 1 − (1 − p)^(1/n) (Šidák).
Units: whatever the compared quantities carry (dimensionless particle units in demstudy).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.special import erfc
from scipy.stats import t as student_t

__all__ = ["block_dof", "dof_note", "sidak_level", "z_test"]


def sidak_level(sigma: float, n: int) -> float:
    """The p-value each of ``n`` tests is held to so that the family fails with the
    probability of a two-sided ``sigma``-σ normal event."""
    family = math.erfc(sigma / math.sqrt(2.0))
    return -math.expm1(math.log1p(-family) / max(1, n))


def block_dof(attrs: dict[str, Any]) -> float:
    """Degrees of freedom of a run's errors (module doc): max(1, min(n_blocks,
    effective_samples) − 1); n_blocks − 1 without ``effective_samples`` (a replica mean:
    R − 1); infinite (errors taken as exact) without ``n_blocks``."""
    n = attrs.get("n_blocks")
    if not n:
        return math.inf
    samples = float(attrs.get("effective_samples", math.inf))
    if not math.isfinite(samples) or samples <= 0:
        samples = math.inf
    return float(max(1.0, min(float(n), samples) - 1.0))


def dof_note(attrs: dict[str, Any], dof: float) -> str:
    """Where ``dof`` (from :func:`block_dof`) came from, for a comparison's notes."""
    if not math.isfinite(dof):
        return "∞ (no n_blocks: errors taken as exact)"
    samples = attrs.get("effective_samples")
    basis = f"{int(attrs['n_blocks'])} blocks"
    if samples is not None and math.isfinite(float(samples)):
        basis += f", {float(samples):.3g} effective samples"
    return f"{dof:.3g} ({basis})"


def z_test(diff: Any, err_a: Any, err_b: Any, dof_a: float, dof_b: float
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(z, degrees of freedom, two-sided p) of differences ``diff`` with the two runs' errors
    (arrays or scalars, broadcast). Both errors zero: z = 0 and p = 1 for no difference, z = ±∞
    and p = 0 otherwise; both dof infinite: the normal distribution."""
    diff, sa, sb = np.broadcast_arrays(*(np.asarray(v, float) for v in (diff, err_a, err_b)))
    var = sa * sa + sb * sb
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.where(var > 0, diff / np.sqrt(var), np.where(diff == 0, 0.0,
                                                             np.copysign(np.inf, diff)))
        parts = (sa**4 / dof_a if math.isfinite(dof_a) else 0.0) + \
                (sb**4 / dof_b if math.isfinite(dof_b) else 0.0)
        dof = np.where(parts > 0, var * var / np.where(parts > 0, parts, 1.0), np.inf)
        normal = erfc(np.abs(z) / math.sqrt(2.0))
        p = np.where(np.isinf(dof), normal, 2.0 * student_t.sf(np.abs(z),
                                                                np.where(np.isinf(dof), 1.0,
                                                                         dof)))
    p = np.where(var > 0, p, np.where(diff == 0, 1.0, 0.0))
    return z, dof, p
