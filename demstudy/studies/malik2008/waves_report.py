"""The density-wave part's checks, figures and report sections (see waves.py): per run the
structure class against what the thesis reports (where the digest says), the steady state
(energy balance, KE plateau, stationary Fourier modes), and the phase diagrams (Figs
5.25-5.27). A run missing gives "not run" checks with a forecast, never an error.

Dimensionless particle units: d = 1, m = 1, g = 1 (gravity acts): times in √(d/g); time in
the thesis is collisions per particle, here c/p = 2 N_pair / N.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from ...engines.edmd.tc_share import WARN_SHARE
from ...errors import BadInputFile
from ..base import (
    NO_THESIS_VALUE,
    NOT_REPRODUCED,
    NOT_RUN,
    PARTLY,
    REPRODUCED,
    TWIN_TOLERANCE,
    Analysis,
    Check,
    Figure,
    pm,
)
from .tc import STUDY_TC
from .waves import TC_TWIN_TC, on_thesis_span, twin_boxes, twin_name
from .waves_boxes import BOXES, QUICK, RESTITUTION, THESIS, Box
from .waves_figures import phase_figure, run_figure
from .waves_measure import (
    COARSE,
    DRIFT_SIGMAS,
    PLATEAU_TOL,
    SNAPSHOTS,
    WINDOW,
    RunWaves,
    measure,
)

#: CPU seconds per particle per √(d/g), measured on this machine (N = 600 box, steady
#: state, one core): the forecast of a run missing when no run of this analysis gives one
COST_PER_PARTICLE_TIME = 2.0e-5
#: CPU seconds per pair collision (cell crossings included), the slowest of the W = 15 and
#: W = 30 boxes measured on 2026-12-02 (4.3-5.6e-6, one core)
COST_PER_COLLISION = 6.0e-6
STEADY_REF = "[L1088], [L1149]-[L1159] (digest §1.8)"


def _boxes(quick: bool) -> list[Box]:
    return [b for b in BOXES if not quick or (b.tag in QUICK and b.restitution == RESTITUTION)]


def _duration(box: Box, quick: bool) -> tuple[float, str]:
    """The case's run length (equilibration + production) and its unit ("time" in √(d/g)
    or "collisions": pair collisions per particle)."""
    from .waves import cases

    case = next(c for c in cases(quick) if c.name == box.name)
    run = case.load(quick).run
    return float(run.equilibration + run.production), run.unit


def _forecast(box: Box, quick: bool, costs: Mapping[str, float]) -> str:
    """The wall time of a missing run: per pair collision as in the largest box run here
    (``costs["collisions"]``, that box's N under "n"), per particle per √(d/g) the slowest
    measured (``costs["time"]``)."""
    length, unit = _duration(box, quick)
    n = costs.get("n", float("nan"))
    where = f"as in the largest box run here, N = {n:.0f}" if math.isfinite(n) else \
        "a default"
    if unit == "collisions":
        cost = costs["collisions"]
        seconds, how = cost * box.n * length, (f"{cost:.1e} s per pair collision, {where}, "
                                               f"× N × {length:.0f} pair collisions per "
                                               "particle")
    else:
        cost = costs["time"]
        seconds, how = cost * box.n * length, (f"{cost:.1e} s per particle per √(d/g), "
                                               f"the slowest measured here, × N × "
                                               f"{length:.0f} √(d/g)")
    text = f"{seconds / 60:.0f} min" if seconds < 7200 else f"{seconds / 3600:.1f} h"
    return (f"forecast ≈ {text} on one core ({how}; `demstudy study malik2008 --only "
            f"{box.name} --dry-run` gives the engine's own)")


def _modes_text(run: RunWaves) -> str:
    parts = []
    for plane in ("xy", "xz", "yz"):
        dom = run.modes.dominant(plane)
        parts.append(f"{plane} {', '.join(str(k) for k in dom) if dom else 'none'}")
    lead = run.modes.leading("xy", 1)
    amp = run.modes.amplitude("xy", lead[0]) if lead else (float("nan"), float("nan"))
    moving = [k for k in run.modes.dominant("xy") if k[0] >= 1]
    ratio = ""
    if moving and (0, 1) in run.modes.dominant("xy"):
        a_x, e_x = run.modes.amplitude("xy", moving[0])
        a_y, e_y = run.modes.amplitude("xy", (0, 1))
        ratio = (f"; x-modulation A{moving[0]}/A(0, 1) = "
                 f"{pm(a_x / a_y, a_x / a_y * float(np.hypot(e_x / a_x, e_y / a_y)))}")
    return (f"dominant families: {'; '.join(parts)}; leading xy {lead[0] if lead else '-'} "
            f"amplitude {pm(*amp)}{ratio}")


def _stationary_text(run: RunWaves) -> str:
    worst = run.max_drift
    drift = (f"largest drift {worst.sigmas:.1f}σ ({worst.plane} {worst.k}: "
             f"{pm(*worst.first)} → {pm(*worst.second)})" if worst else "no modes")
    halves = " / ".join(h.pattern for h in run.halves)
    changes = "".join(f"; {c:.0f} c/p: {run.windows[c].pattern}" for c in run.window_changes)
    return (f"modes {'stationary' if run.stationary else 'NOT stationary'} over "
            f"{run.eq_cpp:.0f}-{run.end_cpp:.0f} c/p (halves: {halves}; {drift}{changes})")


def _windows_text(run: RunWaves) -> str:
    """The classes at the thesis's snapshot times, under both readings of its c/p."""
    if not run.windows:
        return ""
    ours = [f"{c:.0f} {run.windows[c].pattern}" for c in SNAPSHOTS if c in run.windows]
    doubled = [f"{2 * c:.0f} {run.windows[2 * c].pattern}" for c in SNAPSHOTS
               if 2 * c in run.windows]
    parts = []
    if ours:
        parts.append("at the thesis's snapshot times read as our c/p: " + ", ".join(ours))
    if doubled:
        parts.append("read as N_pair/N (our c/p × 2): " + ", ".join(doubled))
    return "; ".join(parts) + f" (frames within ±{WINDOW:.0f} c/p)"


def at_thesis_time(run: RunWaves, cls: str, time: float) -> list[str]:
    """The readings of the thesis's c/p under which ``run`` has class ``cls`` at its time
    ``time`` (c/p)."""
    out = []
    for label, ours in (("c/p = 2 N_pair/N", time), ("c/p = N_pair/N", 2.0 * time)):
        modes = run.windows.get(ours)
        if modes is not None and modes.cls == cls:
            out.append(f"{label} ({ours:.0f} of ours)")
    return out


def first_seen_text(run: RunWaves, cls: str, time: float) -> str:
    """When both readings of the thesis's c/p show ``cls`` at its ``time``, the snapshot time
    (thesis's clock) at which each reading first shows it: the thesis says the structure
    forms at ``time`` (earlier snapshots show other classes), so the reading whose first
    ``cls`` is nearer to it fits better."""
    firsts = []
    for label, factor in (("2 N_pair/N", 1.0), ("N_pair/N", 2.0)):
        seen = [t for t in SNAPSHOTS if factor * t in run.windows
                and run.windows[factor * t].cls == cls]
        if not seen:
            return ""
        firsts.append((abs(seen[0] - time), label, seen[0]))
    text = "; ".join(f"read as {label} the first {cls} is at the thesis's {t:.0f} c/p"
                     for _gap, label, t in firsts)
    (gap_a, a, _ta), (gap_b, b, _tb) = firsts
    if gap_a == gap_b:
        return f" ({text}: the snapshots cannot tell the readings apart)"
    near = a if gap_a < gap_b else b
    return f" ({text}, against its ≈ {time:.0f}: the {near} reading fits better)"


def sequence_text(run: RunWaves, sequence: tuple[str, ...]) -> str:
    """The classes over the snapshot windows (our c/p, in time order; repeats merged) against
    the thesis's ``sequence``: the same order when ours, without the classes the thesis does
    not name ("mixed", "none"), is the thesis's from some class on."""
    if not sequence or not run.windows:
        return ""
    ours: list[str] = []
    for c in sorted(run.windows):
        cls = run.windows[c].cls
        if not ours or ours[-1] != cls:
            ours.append(cls)
    named = [c for c in ours if c in sequence]
    ranks = [sequence.index(c) for c in named]
    ordered = bool(named) and ranks == sorted(ranks)
    first = min(run.windows)
    unseen = [c for c in sequence[sequence.index(named[0]):] if c not in named] if named \
        else []
    if not ordered:
        verdict = "another order"
    else:
        verdict = ("the same order" if named[-1] == sequence[-1] else
                   f"the same order, but it stops at the {named[-1]}")
        if named[0] != sequence[0]:
            verdict += (f" from the {named[0]} on (no window before {first:.0f} c/p: whether "
                        f"the {' and '.join(sequence[:sequence.index(named[0])])} came first "
                        "is not measured)")
        if unseen:
            verdict += f" ({', '.join(unseen)} not caught at the windows)"
    return (f"; the thesis's sequence {' → '.join(sequence)}, ours over the snapshot windows "
            f"{' → '.join(ours)}: {verdict}")


def class_check(box: Box, run: RunWaves | None, missing: str = "") -> Check:
    """The structure class of ``box`` against the thesis's (digest) where known."""
    ref = (f"Fig {box.fig} (N = {box.n}, L/W = {box.aspect:.2g}, W/d = {box.width}, "
           f"H/d = {box.height}, e = {box.restitution:g}); digest §4.11")
    thesis = THESIS.get(box.fig)
    thesis_text = thesis.text if thesis else "not in the digest"
    statement = "steady density structure (plug, S-wave, slug, ...) of this box"
    if run is None:
        return Check(ref, statement, thesis_text, "not run", NOT_RUN, missing)
    windows = _windows_text(run)
    measured = (f"{run.modes.pattern}; {_modes_text(run)}; {_stationary_text(run)}"
                + (f"; {windows}" if windows else ""))
    found = run.modes.cls
    compared = [t for t in (thesis.time, 2.0 * thesis.time) if t in run.windows] \
        if thesis and thesis.time is not None else []
    if compared:
        # the thesis's class is a snapshot: compare at its time, under the readings measured
        readings = at_thesis_time(run, thesis.cls, thesis.time)
        order = sequence_text(run, thesis.sequence)
        if readings:
            return Check(ref, statement, thesis_text, measured, REPRODUCED,
                         f"{thesis.cls} at t = {thesis.time:.0f} c/p with " +
                         " and ".join(readings) + (first_seen_text(run, thesis.cls,
                                                                   thesis.time)
                                                   if len(readings) == 2 else "") + order)
        which = ("under either reading of the thesis's c/p" if len(compared) == 2 else
                 f"at {compared[0]:.0f} of our c/p (the only reading whose window has frames)")
        return Check(ref, statement, thesis_text, measured, NOT_REPRODUCED,
                     f"no {thesis.cls} at t = {thesis.time:.0f} c/p {which} (classes above); "
                     f"the whole production is {run.modes.pattern}" + order)
    if thesis:
        if found != thesis.cls:
            return Check(ref, statement, thesis_text, measured, NOT_REPRODUCED,
                         f"demstudy finds {found}, the thesis {thesis.cls}; run to "
                         f"{run.end_cpp:.0f} c/p" + ("" if run.stationary else
                                                     ", modes still drifting"))
        if not run.stationary:
            return Check(ref, statement, thesis_text, measured, PARTLY,
                         "same class, but the modes are not stationary")
        return Check(ref, statement, thesis_text, measured, REPRODUCED)
    why = "thesis class not in the digest"
    if not run.stationary:
        why += "; the modes are not stationary (class of a transient)"
    return Check(ref, statement, thesis_text, measured, NO_THESIS_VALUE, why)


def tc_row(tag: str) -> str:
    """The name of the TC twin's row of box ``tag`` (the report's first column up to the
    parenthesis); the rows that cite the twin name it by this."""
    return f"TC model, {tag}"


#: the twins' KE tolerance in words (the studies' one tolerance for a TC twin)
TOLERANCE_TEXT = f"{100 * TWIN_TOLERANCE:.0f} %"


def tc_evidence(own_twin: Check | None = None, agreed: Sequence[str] = (), tag: str = "",
                disagreed: Mapping[str, str] | None = None,
                twin_shares: Mapping[str, float] | None = None) -> tuple[bool, str]:
    """What the TC twins say about a box, for the studies' one TC rule
    (:func:`..base.tc_caveats`): (whether its own twin exempts it, the evidence in words).
    ``own_twin``: the TC row of this box's own twin at a smaller t_c; "reproduced" (same
    class and KE within 2σ + ``TWIN_TOLERANCE``, small share) exempts it, "partly"/"not
    reproduced" are named. ``agreed`` and ``disagreed``: the tags of other boxes whose twins
    agreed, and those whose did not (tag → the twin row's verdict), named when the box has no
    twin of its own (none decides for this box). ``tag``: this box's tag, naming its twin's row;
    without it the row is read off the twin's reference. ``twin_shares``: tag → the twin's
    own TC share, which says why a "partly" twin row is one (its share, or its KE/N)."""
    if not tag and own_twin is not None:
        tag = own_twin.ref.split(" (")[0].removeprefix(tc_row(""))
    row = f"row \"{tc_row(tag)}\""
    shares = twin_shares or {}

    def kept(t: str) -> str:
        share = shares.get(t, math.nan)
        return (f"kept the class and the KE/N, but its own share ({100 * share:.1f} %) is above "
                f"{100 * WARN_SHARE:g} %" if share > WARN_SHARE else
                "kept the class but not the KE/N")
    if own_twin is not None and own_twin.verdict == REPRODUCED:
        return True, (f"its twin at t_c = {TC_TWIN_TC:g} √(d/g) gives the same class and KE/N "
                      f"within 2σ + {TOLERANCE_TEXT} ({row}): the share does not change the "
                      "structure "
                      "here")
    if own_twin is not None and own_twin.verdict in (PARTLY, NOT_REPRODUCED):
        found = ("changes the class, so the structure depends on the engine's TC model"
                 if own_twin.verdict == NOT_REPRODUCED else
                 kept(tag) + ", so an effect of the TC model is not ruled out")
        return False, f"its twin at t_c = {TC_TWIN_TC:g} √(d/g) {found} ({row})"
    said = []
    if agreed:
        said.append(f"the TC twin{'s' * (len(agreed) > 1)} of {', '.join(agreed)} at "
                    f"t_c = {TC_TWIN_TC:g} kept {'their' if len(agreed) > 1 else 'its'} "
                    "class")
    changed = [t for t, v in (disagreed or {}).items() if v == NOT_REPRODUCED]
    if changed:
        said.append(f"the TC twin{'s' * (len(changed) > 1)} of {', '.join(changed)} changed "
                    "the class")
    said += [f"the TC twin of {t} {kept(t)}" for t, v in (disagreed or {}).items()
             if v == PARTLY]
    return False, ("" if not said else
                   f"{'; '.join(said)}: rows \"TC model\"; this box's share is not tested")


def tc_caveat(check: Check, run: RunWaves, own_twin: Check | None = None,
              agreed: Sequence[str] = (), tag: str = "",
              disagreed: Mapping[str, str] | None = None, label: str = "",
              twin_shares: Mapping[str, float] | None = None) -> Check:
    """``check`` of a box run under the studies' one TC rule (:func:`..base.tc_caveats`):
    above WARN_SHARE the share in the reason and an agreement "partly" (a mismatch stays,
    the TC model one possible cause) unless the box's own twin exempts it; the twins'
    evidence (:func:`tc_evidence`) quoted."""
    from ..base import tc_caveats as rule

    name = label or tag or "this box"  # label: the box with its e where it is not 0.7
    exempt, text = tc_evidence(own_twin, agreed, tag, disagreed, twin_shares)
    check.runs = (name,)
    rule([check], {name: (run.tc_fraction, STUDY_TC)}, {name: text} if exempt else {},
         {name: text} if text and not exempt else {}, unit="√(d/g)")
    return check


def tc_dependence(box: Box, base: RunWaves | None, twin: RunWaves | None,
                  why: str = "") -> Check:
    """The TC twin of ``box`` against the box at the study's t_c (demstudy's own check; the
    thesis has no TC model): the class of the whole production and at every snapshot window
    both sampled, the KE of each half, and the share at the smaller t_c. ``why``: the cause
    when a run is missing (unreadable, failed)."""
    tc = TC_TWIN_TC
    ref = f"{tc_row(box.tag)} (demstudy; not in the thesis)"
    statement = (f"the structure of {box.tag} (N = {box.n}) does not depend on the "
                 f"event-driven engine's t_c ({STUDY_TC:g} against {tc:g} √(d/g)), and the "
                 "TC-elastic share is small at the smaller t_c")
    thesis = "— (the thesis's collisions all dissipate: no TC model)"
    if base is None or twin is None:
        absent = [n for n, r in ((box.name, base), (twin_name(box), twin)) if r is None]
        return Check(ref, statement, thesis, "not run", NOT_RUN,
                     "run missing: " + ", ".join(absent) + (f" ({why})" if why else ""),
                     own=True)
    ran = [(t, r) for t, r in ((STUDY_TC, base), (tc, twin))
           if math.isfinite(r.tc) and not math.isclose(r.tc, t)]
    if ran:
        return Check(ref, statement, thesis, "not run", NOT_RUN, "; ".join(
            f"{r.path.name} ran at t_c = {r.tc:g}, not {t:g}" for t, r in ran), own=True)
    common = sorted(set(base.windows) & set(twin.windows))
    differ = [c for c in common
              if base.windows[c].cls != twin.windows[c].cls]
    texts = []
    for t, r in ((STUDY_TC, base), (tc, twin)):
        windows = ", ".join(f"{c:.0f} {r.windows[c].pattern}" for c in common)
        (m1, e1), (m2, e2) = r.ke_halves
        texts.append(f"t_c {t:g}: TC share {_share(r)}, class {r.modes.pattern}; at "
                     f"{windows or 'no common window'}; dissipation/input {pm(*r.balance)}; "
                     f"KE/N halves {pm(m1, e1)} → {pm(m2, e2)} m g d; {r.rate:.0f} c/p per "
                     "√(d/g)")
    halves = zip(base.ke_halves, twin.ke_halves, strict=True)
    # the halves apart beyond 2σ + TWIN_TOLERANCE (10 %: the studies' one tolerance for a TC
    # twin; the share and the clock change with t_c, so a few per cent of KE are allowed; the
    # reason states the largest difference either way)
    gaps = [(abs(a - b), float(np.hypot(ea, eb)), abs(a)) for (a, ea), (b, eb) in halves]
    ke_apart = [i for i, (d, err, ref_) in enumerate(gaps) if d > 2.0 * err + TWIN_TOLERANCE * ref_]
    d, err, ref_ = max(gaps, key=lambda g: g[0] / g[2] if g[2] > 0 else 0.0)
    ke_gap = (f"KE/N halves differ by at most {100 * d / ref_:.1f} % "
              f"({d / err:.1f}σ)" if ref_ > 0 and err > 0 else "")
    # the most significant gap, when another half's and resolved (beyond 2σ): the tolerance's
    # 10 % may cover it, but the reader should see that t_c changed the KE measurably
    sd, serr, sref = max(gaps, key=lambda g: g[0] / g[1] if g[1] > 0 else 0.0)
    if ke_gap and serr > 0 and sref > 0 and sd > 2.0 * serr and (sd, serr) != (d, err):
        ke_gap += f"; the other half {100 * sd / sref:.1f} % ({sd / serr:.1f}σ, resolved)"
    same = base.modes.cls == twin.modes.cls and not differ
    if not same:
        reasons = ["the class differs: " + (f"{base.modes.pattern} against "
                                            f"{twin.modes.pattern}" if not differ else
                                            "at " + ", ".join(f"{c:.0f}" for c in differ)
                                            + " c/p")]
    else:
        reasons = ["same class over the production" + (
            f" and at the {len(common)} common snapshot windows" if common else
            " (no snapshot window in both runs)")]
        if base.modes.pattern != twin.modes.pattern:
            reasons[0] += f" ({base.modes.pattern} against {twin.modes.pattern})"
        patterns = [c for c in common if base.windows[c].pattern != twin.windows[c].pattern]
        if patterns:  # same class, another z-modulation ("+ z") or mixture at some windows
            reasons[0] += (", the pattern differs at " + ", ".join(f"{c:.0f}" for c in
                                                                patterns) + " c/p")
    if not ke_apart and ke_gap:
        reasons.append(ke_gap + f" (within 2σ + {TOLERANCE_TEXT})")
    if ke_apart:
        reasons.append("the KE/N of the " + " and ".join(("first", "second")[i]
                                                        for i in ke_apart)
                       + f" half differs by more than 2σ + {TOLERANCE_TEXT}: the TC model "
                       "changes the dissipation")
    clock = twin.rate / base.rate if base.rate > 0 else float("nan")
    if math.isfinite(clock) and not 0.8 < clock < 1.25:
        # equal c/p is then not equal time: the dense clumps collide at another rate
        reasons.append(f"the collision clock runs ×{clock:.2f} at t_c = {tc:g} (the clumps "
                       "collide " + ("more" if clock > 1 else "less") + " often): the windows "
                       "compare at equal c/p, not at equal time")
    small = twin.tc_fraction < WARN_SHARE
    reasons.append(f"share at {tc:g}: {_share(twin)} " + (
        "< 5 %" if small else "≥ 5 % (the engine's warning level)"
        if math.isfinite(twin.tc_fraction) else "(unknown: not in the results file)"))
    verdict = (REPRODUCED if same and small and not ke_apart
               else PARTLY if same else NOT_REPRODUCED)
    return Check(ref, statement, thesis, "; ".join(texts), verdict, "; ".join(reasons),
                 own=True)


def _share(run: RunWaves) -> str:
    """The TC-elastic share in per cent: one decimal, two where one would round onto the
    warning level (4.96 % is below 5 %, "5.0 %" would not say so)."""
    if not math.isfinite(run.tc_fraction):
        return "unknown"
    share = 100 * run.tc_fraction
    near = round(share, 1) == round(100 * WARN_SHARE, 1)
    return f"{share:.2f} %" if near else f"{share:.1f} %"


def steady_check(box: Box, run: RunWaves) -> Check:
    """Energy balance, KE plateau and stationary modes in the production of ``run``."""
    ratio, err = run.balance
    (m1, e1), (m2, e2) = run.ke_halves
    measured = (f"dissipation / gravity power = {pm(ratio, err)}; KE/N halves {pm(m1, e1)} → "
                f"{pm(m2, e2)} m g d; {_stationary_text(run)}; {run.rate:.1f} c/p per √(d/g)")
    statement = (f"N = {box.n} ({box.tag}, e = {box.restitution:g}): steady state, gravity's "
                 "input balances dissipation and the KE levels off; a plateau alone is not "
                 "enough, the Fourier modes must be stationary")
    thesis = "balance = 1; KE plateau; stationary modes"
    if not run.balanced:
        return Check(STEADY_REF, statement, thesis, measured, NOT_REPRODUCED,
                     _unbalanced_reason(run, on_thesis_span(box)))
    if not run.plateau:
        change = 100 * (m2 - m1) / m1
        return Check(STEADY_REF, statement, thesis, measured, PARTLY,
                     f"energy balance holds, but the KE/N {'rises' if change > 0 else 'falls'} "
                     f"by {abs(change):.1f} % from the first half of the production to the "
                     f"second (beyond 2σ and {100 * PLATEAU_TOL:g} %): gravity's input and the "
                     "dissipation balance on average while the flow's energy still "
                     f"{'grows' if change > 0 else 'decays'} slowly, so a longer production "
                     "is needed to call it a plateau")
    if not run.stationary:
        return Check(STEADY_REF, statement, thesis, measured, PARTLY,
                     f"energy balanced and KE on a plateau, but a mode drifts by > "
                     f"{DRIFT_SIGMAS:g}σ or the class changes between the halves or at a "
                     "snapshot window: the structure has not settled (the thesis's warning, "
                     "N = 50094)")
    return Check(STEADY_REF, statement, thesis, measured, REPRODUCED)


#: a clock speed-up worth explaining: c/p per √(d/g) at the production's end over its start
CLOCK_SPEED_UP = 2.0


def _unbalanced_reason(run: RunWaves, thesis_span: bool) -> str:
    """Why input and dissipation differ: which way, and, when dense clumps speed up the
    thesis's clock (c/p) over the production, how flat the KE looks against c/p while it
    still rises in time (the thesis's plateau at 11000 c/p for N = 50094 may be this).
    ``thesis_span``: the run is as long as the thesis's, so its structures are transients."""
    ratio, _ = run.balance
    if not math.isfinite(ratio):
        return ("the energy balance is unknown (too few production samples): the steady "
                "state cannot be judged")
    if thesis_span:
        return _unbalanced_reason(run, False) + (
            "; this run spans the thesis's own c/p, so the thesis's snapshots (≤ 14000 c/p) "
            "show a flow not yet steady in time")
    if not ratio < 1.0:
        return ("input and dissipation do not balance within 2σ: the dissipation exceeds "
                "gravity's input, the flow decelerates from an overshoot (longer runs needed)")
    text = ("input and dissipation do not balance within 2σ: gravity's input exceeds the "
            "dissipation, the flow still accelerates (the production starts before the "
            "steady state)")
    clock = run.clock()
    if not math.isfinite(clock.span):
        return text + "; runs longer in time are needed"
    if not clock.speed_up > CLOCK_SPEED_UP:
        return text + (f"; the production ({run.eq_cpp:.0f}-{run.end_cpp:.0f} c/p) spans "
                       f"{clock.span:.0f} √(d/g), over which the KE/N still rises "
                       f"{clock.ke_per_10t:.1f} % per 10 √(d/g): runs longer in time are "
                       "needed")
    return text + (
        f". Against c/p, the thesis's clock, the KE looks flatter than in time: the dense "
        f"clumps speed the clock up from {clock.start:.0f} to {clock.end:.0f} c/p per "
        f"√(d/g) over the production (×{clock.speed_up:.1f}), so over its last fifth the "
        f"KE/N rises {clock.ke_per_kcpp:.1f} % per 1000 c/p but {clock.ke_per_10t:.1f} % "
        f"per 10 √(d/g); the span {run.eq_cpp:.0f}-{run.end_cpp:.0f} c/p is only "
        f"{clock.span:.0f} √(d/g) here. A plateau in c/p is not a steady state (the "
        "thesis's own warning for N = 50094): runs longer in time are needed")


def _series_check(ref: str, statement: str, boxes: Sequence[Box],
                  measured: Mapping[str, RunWaves]) -> Check:
    """Figs 5.26/5.27: classes along a series; the digest gives none of the thesis's."""
    found = [f"{b.tag} e = {b.restitution:g}: {measured[b.name].modes.pattern}"
             + ("" if measured[b.name].stationary else " (transient)")
             for b in boxes if b.name in measured]
    if not found:
        return Check(ref, statement, "not in the digest", "not run", NOT_RUN,
                     "none of the series' runs made: " + ", ".join(b.name for b in boxes))
    missing = [b.tag + (f" e = {b.restitution:g}" if b.restitution != RESTITUTION else "")
               for b in boxes if b.name not in measured]
    return Check(ref, statement, "not in the digest", "; ".join(found), NO_THESIS_VALUE,
                 "thesis classes not in the digest" +
                 (f"; not run: {', '.join(missing)}" if missing else ""))


def _peak_range(run: RunWaves) -> tuple[float, float]:
    """The range of the peak over the two grids, ± 2σ + 0.03 (the colour bar's reading)."""
    fine, coarse = run.peak, run.peak_coarse
    err = 2 * max(fine[1], coarse[1]) + 0.03
    return min(fine[0], coarse[0]) - err, max(fine[0], coarse[0]) + err


def peak_check(measured: Mapping[str, RunWaves]) -> Check:
    """The densest cells of the structures against the thesis's colour bars (≈ 0.58), box by
    box: the thesis's cells are not stated, so each box's peak is given on two grids (≈ 2 d
    and ≈ 5 d) and 0.58 "lies within" when it falls in their range ± 2σ + 0.03. At most
    "partly" (the cells and the snapshot times differ); "not reproduced" when no box's range
    holds it."""
    ref = "Ch. 5 colour bars (digest §3.4, §6)"
    statement = "dense plugs and slugs reach a local solid fraction of about 0.58"
    if not measured:
        return Check(ref, statement, "≈ 0.58", "not run", NOT_RUN, "no run made")
    tag = {n: n.removeprefix("waves-phi0.15-").removesuffix("-edmd") for n in measured}
    within = [n for n, r in measured.items() if _peak_range(r)[0] <= 0.58 <= _peak_range(r)[1]]
    text = ("densest cell column of the xy plane (depth-averaged), mean over the production "
            f"frames, on 2 d / {COARSE:g} d cells: " + "; ".join(
                f"{tag[n]} {pm(*r.peak)} / {pm(*r.peak_coarse)}"
                + (" (0.58 within)" if n in within else "") for n, r in measured.items())
            + f"; 0.58 within {len(within)} of {len(measured)} boxes")
    cells = ("the thesis's cells (N1 × N2 × N3) are not stated and the peak depends on them "
             f"(2 d against {COARSE:g} d columns above)")
    name, run = max(measured.items(), key=lambda item: item[1].peak_coarse[0])
    packed = (f"; the densest, {tag[name]}, has {100 * run.close_packed:.1f} % of its "
              "particles touching 12 neighbours (a close-packed, FCC/HCP-like core; random "
              "close packing is 0.64): its clump compacts beyond the thesis's, possibly helped "
              "by the engine's TC model (elastic pair collisions within t_c = 10⁻⁵, absent "
              "from the thesis) and sampled far later (production from "
              f"{run.eq_cpp:.0f} c/p, the thesis's snapshots ≤ 14000)"
              if run.close_packed > 0.01 and name not in within else "")
    if within:
        return Check(ref, statement, "≈ 0.58", text, PARTLY,
                     "0.58 lies within the two grids' range (± 2σ of the larger error + "
                     f"0.03, the colour bar's reading) in {len(within)} of {len(measured)} "
                     "boxes, but " + cells
                     + packed)
    return Check(ref, statement, "≈ 0.58", text, NOT_REPRODUCED,
                 "0.58 lies outside the two grids' range (± 2σ + 0.03) in every box; " + cells
                 + packed)


def _run_table(measured: Mapping[str, RunWaves]) -> str:
    head = ("| case | N | c/p analysed | c/p per √(d/g) | class | dominant xy | stationary | "
            "max drift | dissipation/input | peak φ (2 d / 5 d cells) | close-packed | "
            "TC-elastic share | engine wall time (s) |\n"
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n")
    rows = []
    for name, run in measured.items():
        worst = run.max_drift
        drift = f"{worst.sigmas:.1f}σ {worst.plane} {worst.k}" if worst else "-"
        rows.append(
            f"| {name} | {run.n} | {run.eq_cpp:.0f}-{run.end_cpp:.0f} | {run.rate:.1f} | "
            f"{run.modes.pattern} | {', '.join(str(k) for k in run.modes.dominant('xy'))} | "
            f"{'yes' if run.stationary else 'no'} | {drift} | {pm(*run.balance)} | "
            f"{pm(*run.peak)} / {pm(*run.peak_coarse)} | {100 * run.close_packed:.1f} % | "
            f"{_share(run)} | {run.wall_seconds:.0f} |")
    return head + "\n".join(rows)


METHOD = """\
**Model.** Malik's Ch. 5 model: φ ≈ 0.15, pair restitution e = 0.7 (0.9 and 0.99 for the
restitution series), constant tangential restitution β = 0.1, walls at y = 0 and W with
e_w = β_w = 0.99 (L1084-1086), solid spheres' inertia K = 2/5 (I = K m d²/4; assumed, the
thesis does not state it), periodic along x (the flow) and z, gravity along x. Hard
spheres in the event-driven engine (the thesis's method).

**Time.** The thesis measures time in collisions per particle (c/p) without defining it
(digest §1.6, §9.15); here c/p = 2 N_pair / N, each pair collision counted for both
partners, wall collisions apart (had the thesis counted N_pair / N, its 14000 c/p would be
our 28000). Once
the energy plateaus (≈ 100 √(d/g)) the W = 15 boxes make 10 (N = 600, a plug) to 43
(N = 4800, L/W = 5, a slug) c/p per √(d/g) (measured, the table's column): the W = 15
scenes' equilibration of 1000 √(d/g) therefore covers ≈ 1-6 × 10^4 c/p, beyond the thesis's
snapshots (4000-14000 c/p), and their production of 3000 √(d/g) ≈ 3-13 × 10^4 c/p more
(frames are kept in the production only: the structure at the thesis's snapshot times is
not sampled, only the KE trace). The W = 30 and W = 50 boxes run over the thesis's own span
instead, counted in collisions: 2000 c/p of equilibration, then production to 30000 c/p
with a frame every 400 c/p, so that their structures are seen at the thesis's snapshot times
(4000-14000 c/p, or up to 28000 had it counted N_pair / N) and the first half of the
production (≈ 2000-16000 c/p) is the thesis's window. {length}

**Modes.** demstudy.analysis.waves.DensityWaves over the production frames: cells of ≈ 2 d,
each plane (xy, xz, yz) the depth average over the third axis, Malik's P = 2 X conj(X) /
(N1 N2)², integer harmonics, the ± modes summed into families (|k_a|, |k_b|), mean over the
frames with jackknife errors. A family is dominant when its power exceeds 20 × the median
(noise floor) per member and 3 errors. Class (xy plane): no dominant family → none; only
k_x = 0 families → plug ((0,1)); x-varying families mostly antisymmetric about the
centreline → s-wave ((1,1), (2,1)); mostly symmetric → slug ((0,1) + (1,0)); otherwise mixed
(wavy slug, sandwich); "+ z" when the xz or yz plane has a dominant family varying along z.
The yz plane's families are written (k_y, k_z) throughout (the thesis switches, digest §9.13).

**Stationarity.** The analysis is repeated on each half of the production: the class must
be the same and the amplitudes of the two leading xy families, the leading xz family and the
leading z-varying yz family must agree within 2σ; the kinetic energy of the halves must
agree within 2σ, and the dissipation rate must equal gravity's power within 2σ (block
jackknife errors). The engine's TC model (Luding & McNamara, t_c = 10⁻⁵ √(d/g)) makes a
small fraction of pair collisions elastic (column): a deviation from the thesis's model,
which has none.

**Snapshot times.** The thesis's classes are snapshots (t = 4000, 8000, 10000, 11000, 14000
c/p, digest §1.8). The frames within ±800 c/p of each of these times, read as our c/p and as
N_pair / N (our c/p × 2), are classified on their own (3 frames at least); a statement the
thesis ties to a time (N = 50094: a slug at 14000 c/p) is compared there, under either
reading, and the report names the reading that agrees.

**TC model.** The engine makes a pair collision elastic (e = 1, no tangential impulse) when either
partner collided less than t_c earlier (Luding & McNamara's TC model against inelastic collapse; the
thesis has none). At the study's t_c = 10⁻⁵ √(d/g) this made {shares} of the W = 30/50 boxes' pair
collisions elastic, so {twins} are run again at t_c = 10⁻⁶ (the engine's default for spheres since
2026-12-03; the study's runs stay at 10⁻⁵, where its records were made) over the same span (cases
waves-phi0.15-<box>-tc1e-06-edmd): each "TC model" row compares the class over the production and at
each snapshot window, the KE of each half (within 2σ + 10 %, the studies' tolerance for a twin) and
the share. A box whose own twin agrees keeps its verdicts; in the others, with a share above 5 %, an
agreement with the thesis counts as "partly" (a weaker test) and a mismatch stays "not reproduced"
with the share named as one possible cause.

**Peak density.** The densest cell column of the xy plane in each production frame (mean
over the frames), on the 2 d grid and on ≈ 5 d columns, since the thesis's cells are not
stated; and in the last frame the fraction of particles with 12 neighbours closer than
1.05 d (a touching FCC/HCP-like shell: a close-packed core).
"""


def analyse_waves(runs: Mapping[str, Path], out: Path, quick: bool) -> Analysis:
    """Checks, figures and sections of the density-wave part (module docstring)."""
    ana = Analysis()
    boxes = _boxes(quick)
    measured: dict[str, RunWaves] = {}
    failed: dict[str, str] = {}
    for box in boxes:
        path = runs.get(box.name)
        if path is None:
            continue
        try:
            measured[box.name] = measure(Path(path))
        except (OSError, KeyError, ValueError, BadInputFile) as exc:
            failed[box.name] = f"results file unreadable for the mode analysis: {exc}"
    timed = [r for r in measured.values() if np.isfinite(r.wall_seconds) and r.time[-1] > 0]
    # a missing long run's cost per collision from the largest box measured (its cache
    # misses and event queue are the nearest to a large missing box's; small boxes cost more
    # per collision in per-frame analysis: their worst overstated a large run's time ×2-3)
    largest = max((r for r in timed if r.cpp[-1] > 0), key=lambda r: r.n, default=None)
    costs = {"time": max([r.wall_seconds / (r.n * r.time[-1]) for r in timed],
                         default=COST_PER_PARTICLE_TIME),
             "collisions": (2.0 * largest.wall_seconds / (largest.n * largest.cpp[-1])
                            if largest else COST_PER_COLLISION),
             "n": float(largest.n) if largest else float("nan")}
    table = dict(measured)
    tc_rows: dict[str, Check] = {}
    for box in [] if quick else twin_boxes():
        twin = _measure_twin(box, runs, failed)
        tc_rows[box.name] = tc_dependence(box, measured.get(box.name), twin,
                                          failed.get(twin_name(box))
                                          or failed.get(box.name, ""))
        if twin is not None:
            table[twin_name(box)] = twin
    twin_shares = {b.tag: table[twin_name(b)].tc_fraction for b in twin_boxes()
                   if twin_name(b) in table}
    agreed = [b.tag for b in twin_boxes()
              if b.name in tc_rows and tc_rows[b.name].verdict == REPRODUCED]
    disagreed = {b.tag: tc_rows[b.name].verdict for b in twin_boxes() if b.name in tc_rows
                 and tc_rows[b.name].verdict in (PARTLY, NOT_REPRODUCED)}
    for box in boxes:
        run = measured.get(box.name)
        if run is None:
            ana.checks.append(class_check(box, None, failed.get(box.name) or
                                          "run missing; " + _forecast(box, quick, costs)))
            continue
        label = box.tag + ("" if box.restitution == RESTITUTION
                           else f", e = {box.restitution:g}")
        shape = class_check(box, run)
        twin = table.get(twin_name(box)) if box.name in tc_rows else None
        thesis = THESIS.get(box.fig)
        if twin is not None and thesis is not None and thesis.time is not None:
            # the twin with the smaller share: when its structure forms, by the same readings
            seen = first_seen_text(twin, thesis.cls, thesis.time).strip(" ()")
            if seen:
                shape.reason = (shape.reason.rstrip(".") + f". Its TC twin at t_c = "
                                f"{TC_TWIN_TC:g} √(d/g) ({100 * twin.tc_fraction:.1f} % "
                                f"elastic): {seen}")
        for check in (shape, steady_check(box, run)):
            ana.checks.append(tc_caveat(check, run, tc_rows.get(box.name),
                                        [t for t in agreed if t != box.tag], box.tag,
                                        {t: v for t, v in disagreed.items()
                                         if t != box.tag}, label, twin_shares))
        path = run_figure(run, box, out / f"{box.name.removesuffix('-edmd')}.png")
        ana.figures.append(Figure(path, f"Fig {box.fig}'s form: N = {box.n} in {box.tag}, "
                                        f"e = {box.restitution:g}: positions, density "
                                        "contours with velocity vectors, power spectra, KE "
                                        "and mode amplitudes against collisions per "
                                        "particle (class " + run.modes.pattern + ")"))
    diagram = [b for b in boxes if b.restitution == RESTITUTION and b.height == b.width]
    ana.checks += tc_rows.values()
    ana.checks.append(peak_check(measured))
    ana.checks += _phase_checks(boxes, diagram, measured)
    thesis = [(b, THESIS[b.fig].cls, "digest") for b in diagram if b.fig in THESIS]
    path = phase_figure([(b, measured[b.name].modes.pattern) for b in diagram
                         if b.name in measured],
                        [b for b in diagram if b.name not in measured], thesis,
                        out / "waves-phase-diagram.png",
                        [b.name for b in diagram
                         if b.name in measured and not measured[b.name].stationary])
    ana.figures.append(Figure(path, "Fig 5.25's form: the structure class of each box over "
                                    "(L/W, W/d), demstudy (filled) and the thesis where the "
                                    "digest gives it (rings); pale: modes not stationary over the "
                                    "production (a transient's class); × not run"))
    ana.sections.append(("Density waves (Malik Ch. 5): method", method_text(measured)))
    if table:
        ana.sections.append(("Density waves: the runs", _run_table(table)))
    return ana


def method_text(measured: Mapping[str, RunWaves]) -> str:
    """METHOD with the numbers that come from the runs: the W = 30/50 boxes' collision
    rates (what the shipped scenes' lengths in time would cost in c/p) and TC shares."""
    wide = [(b, measured[b.name]) for b in BOXES if b.width >= 30 and b.name in measured]
    rates = [r.rate for _b, r in wide if math.isfinite(r.rate) and r.rate > 0]
    shares = [100 * r.tc_fraction for _b, r in wide if math.isfinite(r.tc_fraction)]
    if rates:
        lo, hi = min(rates), max(rates)
        length = (f"The shipped scenes' lengths (2000-3000 + 4000-5000 √(d/g), ≈ 7000 "
                  f"√(d/g)) would be {7000 * lo:.1e}-{7000 * hi:.1e} c/p at these boxes' "
                  f"measured {lo:.0f}-{hi:.0f} c/p per √(d/g): ×{7000 * lo / 30000:.0f}-"
                  f"{7000 * hi / 30000:.0f} the cost of the 30000 c/p run here.")
    else:
        length = ("The shipped scenes' lengths (≈ 7000 √(d/g)) are many times the thesis's "
                  "span in c/p at these boxes' collision rates.")
    share = f"{min(shares):.1f}-{max(shares):.1f} %" if shares else "a share (see the table)"
    twins = ", ".join(b.tag for b in twin_boxes())
    return METHOD.format(length=length, shares=share, twins=twins)


def _measure_twin(box: Box, runs: Mapping[str, Path],
                  failed: dict[str, str]) -> RunWaves | None:
    path = runs.get(twin_name(box))
    if path is None:
        return None
    try:
        return measure(Path(path))
    except (OSError, KeyError, ValueError, BadInputFile) as exc:
        failed[twin_name(box)] = f"results file unreadable for the mode analysis: {exc}"
        return None


def _phase_checks(boxes: Sequence[Box], diagram: Sequence[Box],
                  measured: Mapping[str, RunWaves]) -> list[Check]:
    checks = []
    if diagram:
        found = [f"{b.tag}: {measured[b.name].modes.pattern}"
                 + ("" if measured[b.name].stationary else " (transient)") for b in diagram
                 if b.name in measured]
        transient = sum(1 for b in diagram if b.name in measured
                        and not measured[b.name].stationary)
        ref = "Fig 5.25 [L1465] (digest §7)"
        statement = "phase diagram of the steady structures over (L/W, W/d), e = 0.7, H = W"
        if found:
            checks.append(Check(ref, statement, "classes not in the digest, except N = 50094 "
                                "(L/W = 1.4, W/d = 50): slug", "; ".join(found),
                                NO_THESIS_VALUE,
                                f"{len(found)} of {len(diagram)} boxes run, {transient} of "
                                "them with modes not stationary over the thesis's span "
                                "(transient: the class of a flow still changing, not a steady "
                                "structure); the thesis's classes are not in the digest (the "
                                "one it gives, N = 50094, is judged in that box's own row)"))
        else:
            checks.append(Check(ref, statement, "not in the digest", "not run", NOT_RUN,
                                "no box of the diagram run"))
    tall = [b for b in boxes if b.length == 150 and b.width == 50
            and b.restitution == RESTITUTION]
    if tall:
        checks.append(_series_check("Fig 5.26 [L1475]", "structures against H/W (L/W = 3, "
                                    "W/d = 50; H/d = 10, 50, 150)", tall, measured))
    e_series = [b for b in boxes if b.tag == "L150W50H50"]
    if e_series:
        checks.append(_series_check("Fig 5.27 [L1479]; Figs 5.13, 5.23, 5.24",
                                    "structures against e (L/W = 3, W/d = H/d = 50; e = "
                                    "0.7, 0.9, 0.99)", e_series, measured))
    return checks
