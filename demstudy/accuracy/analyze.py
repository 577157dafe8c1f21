"""Errors of the soft runs against the reference, the convergence law, the choice at a
tolerance and the engine recommendation.

Error rule (one number per run): for each headline field f (``HEADLINE_FIELDS``: ν, u_x, T,
rotational T and the stress components, those the theses plot; fields whose reference is
zero within its errors, such as u_y, have no relative error and are left out) the compare
module gives the relative L2 difference rel_l2_f, its noise floor rel_l2_floor_f (what the
statistical errors alone produce) and the debiased difference
sqrt(max(rel_l2_f² − rel_l2_floor_f², 0)); the run's error is the worst field's debiased
difference. The table of every field is ``demstudy compare``'s. A run meets a tolerance X
when that error ≤ X AND its noise floor (the largest over the counted fields) ≤ X: with a
floor above X the run cannot tell whether it meets X. When the noise floor of the chosen run
(or, with none chosen, of the quietest run) exceeds X, the runs are too short to tell, and
the recommendation says so (lengthen the runs).
Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class RunError:
    error: float        # worst field's rel_l2 beyond its noise floor
    field: str          # that field
    rel_l2: float       # its rel_l2
    floor: float        # the largest noise floor of all fields
    resolved: list[str]  # fields whose difference is resolved (compare's family test)


#: the fields whose error counts (when present in both runs)
HEADLINE_FIELDS = ("solid_fraction", "velocity[x]", "temperature", "rotational_temperature",
                   "stress/xx", "stress/yy", "stress/zz", "stress/xy")


def run_error(comparison) -> RunError:
    """The error rule of the module doc, from one ``Comparison``."""
    worst, name, raw = -1.0, "—", math.nan
    counted = {f: fc for f, fc in comparison.fields.items()
               if f in HEADLINE_FIELDS and not fc.reference_is_zero}
    for field, fc in counted.items():
        excess = fc.rel_l2_debiased
        if excess > worst:
            worst, name, raw = excess, field, fc.rel_l2
    floor = max((fc.rel_l2_floor for fc in counted.values()), default=math.nan)
    resolved = [f for f, fc in comparison.fields.items() if fc.resolved]
    return RunError(worst if worst >= 0 else math.nan, name, raw, floor, resolved)


@dataclass(frozen=True)
class ConvergenceFit:
    """error = a x^(−p) + floor, with one-sigma errors (``floor`` fixed at 0 with < 4
    points: three parameters need a residual to have errors)."""

    a: float
    p: float
    floor: float
    a_err: float
    p_err: float
    floor_err: float
    n: int

    @property
    def resolved(self) -> bool:
        """Whether the data resolve a decay: an exponent at least twice its error (a flat
        ladder, every run within the noise, fits any exponent: 3e-5 ± 1e8)."""
        return bool(np.isfinite(self.p) and np.isfinite(self.p_err) and self.p > 0
                    and self.p_err < 0.5 * self.p)

    def law(self, variable: str = "k*") -> str:
        floor = f" + {self.floor:.2g} ± {self.floor_err:.1g}" if self.n >= 4 else ""
        law = (f"error = {self.a:.3g} {variable}^-({self.p:.3g} ± {self.p_err:.2g})"
               f"{floor} ({self.n} runs)")
        if not self.resolved:
            law += ": no decay resolved (the errors are flat within their noise)"
        return law


def fit_convergence(x, error, rel_sigma: float = 0.1) -> ConvergenceFit:
    """Fit error = a x^(−p) + floor (scipy ``curve_fit``) with relative weights (each point
    ``rel_sigma`` of its own value, so that every decade counts alike); parameter errors from
    the covariance scaled by the residuals. Needs ≥ 3 positive-x points."""
    from scipy.optimize import curve_fit

    x, y = np.asarray(x, float), np.asarray(error, float)
    ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    x, y = x[ok], y[ok]
    if x.size < 3:
        raise ValueError(f"the convergence fit needs at least 3 runs with an error > 0, "
                         f"got {x.size}")
    scale = float(np.exp(np.mean(np.log(x))))  # fit in x/scale: a of order y
    sigma = rel_sigma * y
    p0_slope = -np.polyfit(np.log(x), np.log(y), 1)[0]
    p0 = [float(np.max(y)) * (x.min() / scale) ** p0_slope, max(p0_slope, 0.1)]
    if x.size >= 4:
        def model(xs, a, p, floor):
            return a * (xs / scale) ** (-p) + floor
        popt, pcov = curve_fit(model, x, y, p0=[*p0, float(y.min()) / 2], sigma=sigma,
                               bounds=([0, 0, 0], [np.inf, 20, np.inf]), maxfev=20000)
    else:
        def model(xs, a, p):
            return a * (xs / scale) ** (-p)
        popt, pcov = curve_fit(model, x, y, p0=p0, sigma=sigma, maxfev=20000)
        popt, pcov = np.append(popt, 0.0), np.pad(pcov, ((0, 1), (0, 1)))
    errs = np.sqrt(np.clip(np.diag(pcov), 0, None))
    a, p, floor = popt
    # a refers to x/scale: a' = a scale^p, its error by the same factor (p's share ignored)
    return ConvergenceFit(float(a * scale**p), float(p), float(floor),
                          float(errs[0] * scale**p), float(errs[1]), float(errs[2]),
                          int(x.size))


def meets(row: dict, tolerance: float) -> bool:
    """Whether a run meets ``tolerance`` (module doc): its ``error`` and its noise ``floor``
    both ≤ ``tolerance`` (a missing or NaN one: not met)."""
    error, floor = float(row.get("error", np.nan)), float(row.get("floor", np.nan))
    return bool(np.isfinite(error) and np.isfinite(floor) and error <= tolerance
                and floor <= tolerance)


def pick_cheapest(rows: list[dict], tolerance: float) -> dict | None:
    """The cheapest row (``wall_seconds``) that :func:`meets` ``tolerance`` (error and noise
    floor ≤ tolerance, module doc); None when none does."""
    if not tolerance > 0:
        raise ValueError(f"tolerance must be > 0, not {tolerance}")
    meeting = [r for r in rows if meets(r, tolerance)]
    return min(meeting, key=lambda r: r["wall_seconds"], default=None)


def recommend(choice: dict | None, reference_seconds: float, tolerance: float,
              worst_floor: float) -> str:
    """The engine to use at ``tolerance`` for this scene, with the soft/hard cost ratio."""
    caveat = (f" (caution: the noise floor {worst_floor:.2g} exceeds the tolerance; "
              "longer runs are needed to confirm)" if worst_floor > tolerance else "")
    if choice is None:
        return (f"event-driven (edmd): no soft run met the tolerance {tolerance:g}; the "
                f"reference took {reference_seconds:.3g} s{caveat}")
    ratio = choice["wall_seconds"] / reference_seconds
    engine = (f"soft contacts ({choice.get('engine', 'lammps')})" if ratio < 1
              else "event-driven (edmd)")
    return (f"{engine} at tolerance {tolerance:g}: cheapest soft run {choice['name']} "
            f"({choice['wall_seconds']:.3g} s, error {choice['error']:.3g}) costs "
            f"{ratio:.3g} x the event-driven reference ({reference_seconds:.3g} s){caveat}")
