"""The soft-contact cross-checks of the Poiseuille part: LAMMPS's and LIGGGHTS's soft spheres
against the event-driven hard spheres in one of Malik's flows (``poiseuille_cases.SOFT_FLOWS``:
φ = 0.01, β = 0.99, e = 0.8), profile by profile with both runs' statistical errors
(:func:`demstudy.comparison.compare_pair`), and what each cost; one row per soft engine.

Tolerance: the soft run reproduces the hard one when every field's debiased relative L2
difference (the difference with the noise taken out, resolved or not) is at most
``TOLERANCE`` (3 %: what the cost study measured for this stiffness and step, k* = 10⁶ at
10 steps per contact, 2.4 % in the φ = 0.1 Poiseuille flow, docs/accuracy-cost.md) and its
noise floor (what the errors alone give) is at most ``TOLERANCE`` too, so that a 3 % shift
would show. Differences up to ``LOOSE`` (10 %), or floors above 3 %, give "partly" with the
fields named; a difference beyond the errors larger than ``LOOSE`` "not reproduced".

Dimensionless particle units: d = 1, m = 1, g = 1 (gravity acts).
"""

from __future__ import annotations

import dataclasses
import math

from ...comparison.core import compare_pair
from ..base import NOT_REPRODUCED, NOT_RUN, PARTLY, REPRODUCED, Check
from .poiseuille_cases import SOFT, SOFT_SECTIONS, Flow
from .poiseuille_data import FlowData

FIELDS = ("solid_fraction", "velocity[x]", "temperature", "rotational_temperature", "spin[z]")
TOLERANCE, LOOSE = 0.03, 0.10


def _cost(d: FlowData) -> tuple[float, float]:
    """(wall seconds, simulated time) of a run (0 when unknown; a soft run has no collision
    count, so not ``run_info``)."""
    t = d.res.timeseries.get("time")
    wall = float(d.res.attrs.get("wall_seconds", 0.0))
    return (wall if math.isfinite(wall) else 0.0), (float(t[-1]) if t is not None and t.size
                                                    else 0.0)


#: each soft engine's contact model as its deck writes it
MODELS = {"lammps": ("LAMMPS", "hooke"), "liggghts": ("LIGGGHTS", "hooke/stiffness")}


def _header(flow: Flow) -> tuple[str, str, str]:
    engine, model = MODELS[flow.engine]
    ref = (f"soft-contact cross-check ({engine}, {model}, the scene's k_n, "
           f"{SOFT_SECTIONS['soft']['steps_per_contact']} steps per contact)")
    statement = (f"soft spheres give the hard spheres' flow (φ = {flow.phi:g}, β = "
                 f"{flow.beta:g}, e = {flow.e:g}): φ, U_x, T, θ and ω_z across the channel")
    return ref, statement, "— (the hard-sphere limit; the thesis is event-driven)"


def soft_unreadable(why: str, flow: Flow = SOFT) -> Check:
    """The row when the soft run (or its comparison) cannot be read: "not run", why."""
    return Check(*_header(flow), "not run", NOT_RUN, f"{flow.name}: {why}", own=True)


def soft_check(hard: FlowData | None, soft: FlowData | None, flow: Flow = SOFT) -> Check:
    """The row of the soft cross-check of ``flow`` (a soft engine's; ``hard``: the
    event-driven run of the same flow); raises ``NotComparable`` (a ValueError) when the
    runs' profiles do not compare."""
    run = SOFT_SECTIONS["run"]
    ref, statement, thesis = _header(flow)
    if hard is None or soft is None:
        absent = [n for n, d in ((dataclasses.replace(flow, engine="edmd").name, hard),
                                 (flow.name, soft)) if d is None]
        return Check(ref, statement, thesis, "not run", NOT_RUN,
                     "run missing: " + ", ".join(absent), own=True)
    comp = compare_pair(hard.res, soft.res, fields=list(FIELDS))
    rows = [f"{name}: rel. L2 {f.rel_l2:.3g} (noise floor {f.rel_l2_floor:.3g}, debiased "
            f"{f.rel_l2_debiased:.3g}, max |z| {f.max_z:.1f}"
            f"{', resolved' if f.resolved else ''})" for name, f in comp.fields.items()]
    (hs, ht), (ss, st) = (_cost(d) for d in (hard, soft))
    cost = (f"; cost (one core): soft {ss:.0f} s for {st:.0f} √(d/g), hard {hs:.0f} s for "
            f"{ht:.0f} √(d/g): ×{(ss / st) / (hs / ht):.0f} per unit of simulated time (the "
            "runs' own wall times, not timed side by side: docs/accuracy-cost.md compares "
            "costs interleaved)"
            if all(v > 0 for v in (hs, ht, ss, st)) else "")
    measured = "; ".join(rows) + cost
    fields = comp.fields.values()
    unknown = [f.name for f in fields if f.n_compared == 0
               or not (math.isfinite(f.rel_l2_floor) and math.isfinite(f.rel_l2_debiased))]
    apart = [f for f in fields if f.name not in unknown and f.rel_l2_debiased > TOLERANCE]
    far = [f for f in apart if f.resolved and f.rel_l2_debiased > LOOSE]
    noisy = [f.name for f in fields if f.name not in unknown and f.rel_l2_floor > TOLERANCE]
    length = f"soft run {run['equilibration']:.0f} + {run['production']:.0f} √(d/g)"
    if not (unknown or apart or noisy):
        return Check(ref, statement, thesis, measured, REPRODUCED,
                     f"every field within {100 * TOLERANCE:.0f} % (debiased), noise floors "
                     f"≤ {100 * TOLERANCE:.0f} %: the cost study's accuracy at this setting",
                     own=True)
    reasons = []
    if apart:
        reasons.append("; ".join(f"{f.name} differs by {100 * f.rel_l2_debiased:.1f} % "
                                 f"(debiased{', beyond the errors' if f.resolved else ''})"
                                 for f in apart))
    if noisy:
        reasons.append(f"the noise floor of {', '.join(noisy)} exceeds "
                       f"{100 * TOLERANCE:.0f} %: a difference of that size would not show")
    if unknown:
        reasons.append(f"not compared: {', '.join(unknown)}")
    apart_names = {f.name for f in apart}
    small = [f for f in fields if f.name not in unknown and f.name not in apart_names
             and f.resolved]
    if small:  # real, but within the tolerance: named, so the reader sees where soft differs
        reasons.append("resolved but within the tolerance: " + ", ".join(
            f"{f.name} {100 * f.rel_l2_debiased:.1f} % (max |z| {f.max_z:.1f})"
            for f in small))
    return Check(ref, statement, thesis, measured, NOT_REPRODUCED if far else PARTLY,
                 "; ".join(reasons) + f"; {length}", own=True)
