"""The soft-contact cross-check of the Poiseuille part: LAMMPS's soft spheres against the
event-driven hard spheres in one of Malik's flows (``poiseuille_cases.SOFT``: φ = 0.01,
β = 0.99, e = 0.8), profile by profile with both runs' statistical errors
(:func:`demstudy.comparison.compare_pair`), and what each cost.

Tolerance: a field agrees when its difference is within the errors, or its debiased relative
L2 difference is at most ``TOLERANCE`` (3 %: what the cost study measured for this stiffness
and step, k* = 10⁶ at 10 steps per contact, 2.4 % in the φ = 0.1 Poiseuille flow,
docs/accuracy-cost.md); up to ``LOOSE`` (10 %) it is "partly". A field whose noise floor
(what the errors alone give) exceeds ``LOOSE`` cannot show a difference of that size: the
row is then "partly", too noisy to judge.

Dimensionless particle units: d = 1, m = 1, g = 1 (gravity acts).
"""

from __future__ import annotations

from ...comparison.core import compare_pair
from ..base import NOT_REPRODUCED, NOT_RUN, PARTLY, REPRODUCED, Check
from .poiseuille_cases import SOFT, SOFT_SECTIONS
from .poiseuille_data import FlowData

FIELDS = ("solid_fraction", "velocity[x]", "temperature", "rotational_temperature", "spin[z]")
TOLERANCE, LOOSE = 0.03, 0.10


def _cost(d: FlowData) -> tuple[float, float]:
    """(wall seconds, simulated time) of a run (NaN when unknown)."""
    t = d.res.timeseries.get("time")
    return d.run_info()["wall_seconds"], float(t[-1]) if t is not None and t.size else 0.0


def soft_check(hard: FlowData | None, soft: FlowData | None) -> Check:
    """The row of the soft cross-check (``hard``: the event-driven run of ``SOFT``'s flow)."""
    run = SOFT_SECTIONS["run"]
    ref = (f"soft-contact cross-check (LAMMPS, hooke, the scene's k_n, "
           f"{SOFT_SECTIONS['soft']['steps_per_contact']} steps per contact)")
    statement = (f"soft spheres give the hard spheres' flow (φ = {SOFT.phi:g}, β = "
                 f"{SOFT.beta:g}, e = {SOFT.e:g}): φ, U_x, T, θ and ω_z across the channel")
    thesis = "— (the hard-sphere limit; the thesis is event-driven)"
    if hard is None or soft is None:
        absent = [n for n, d in ((SOFT.name.replace("lammps", "edmd"), hard),
                                 (SOFT.name, soft)) if d is None]
        return Check(ref, statement, thesis, "not run", NOT_RUN,
                     "run missing: " + ", ".join(absent))
    comp = compare_pair(hard.res, soft.res, fields=list(FIELDS))
    rows, worst = [], 0.0
    for name, f in comp.fields.items():
        off = f.rel_l2_debiased if f.resolved else 0.0
        worst = max(worst, off)
        rows.append(f"{name}: rel. L2 {f.rel_l2:.3g} (noise floor {f.rel_l2_floor:.3g}, "
                    f"debiased {f.rel_l2_debiased:.3g}, max |z| {f.max_z:.1f})")
    (hs, ht), (ss, st) = (_cost(d) for d in (hard, soft))
    cost = (f"; cost (one core): soft {ss:.0f} s for {st:.0f} √(d/g), hard {hs:.0f} s for "
            f"{ht:.0f} √(d/g): ×{(ss / st) / (hs / ht):.0f} per unit of simulated time"
            if all(v > 0 for v in (hs, ht, ss, st)) else "")
    measured = "; ".join(rows) + cost
    resolved = [n for n, f in comp.fields.items() if f.resolved]
    noisy = [n for n, f in comp.fields.items() if not f.resolved and f.rel_l2_floor > LOOSE]
    if worst <= TOLERANCE and noisy:
        return Check(ref, statement, thesis, measured, PARTLY,
                     f"no difference resolved, but the noise floor of {', '.join(noisy)} "
                     f"exceeds {100 * LOOSE:.0f} %: too noisy to judge (longer runs)")
    if worst <= TOLERANCE:
        reason = ("" if not resolved else
                  f"{', '.join(resolved)} resolved beyond the errors, within "
                  f"{100 * TOLERANCE:.0f} % (the cost study's accuracy at this setting)")
        return Check(ref, statement, thesis, measured, REPRODUCED, reason)
    verdict = PARTLY if worst <= LOOSE else NOT_REPRODUCED
    return Check(ref, statement, thesis, measured, verdict,
                 f"{', '.join(resolved)} differ beyond the errors by up to "
                 f"{100 * worst:.1f} % (debiased rel. L2); soft run "
                 f"{run['equilibration']:.0f} + {run['production']:.0f} √(d/g)")
