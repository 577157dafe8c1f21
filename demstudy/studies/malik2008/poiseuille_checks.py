"""The checks of the Poiseuille part: one per statement of the digest (§3.5 validation, §2.3
β = 0 most dissipative, §4.4 Kn and the transitional regime, §4.6 VDFs, §4.7 g(r), §4.8 Λ,
§6 dense core and plug, Fig 4.5 S-wave), each with the measured value ± its statistical error
(block jackknife of the analyses), a verdict and its reason.

Thresholds where the thesis gives only words (its statements are qualitative; the digest
quotes no numbers): "considerable" slip = at least 20 % of the centre velocity; "nearly
uniform" = every interior bin within 20 % of the mean φ; a "Gaussian core" = P within 10 % of
exp(-x²/2) for |x| ≤ 1 (beyond 2σ); "extremely low" Kn = below 0.01. They are stated in each
check. Dimensionless particle units: d = 1, m = 1, g = 1 (gravity acts).
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Sequence

import numpy as np

from ...engines.edmd.tc_share import WARN_SHARE
from ..base import (
    NO_THESIS_VALUE,
    NOT_REPRODUCED,
    NOT_RUN,
    PARTLY,
    REPRODUCED,
    Check,
    not_run,
    pm,
    twin_comparison,
    twin_evidence,
    within,
)
from .poiseuille_cases import BETAS, RESTITUTIONS, Flow
from .poiseuille_data import (
    CENTRE_BIN,
    FlowData,
    carnahan_starling,
    contact_value,
    vdf_bins,
    wall_distance,
    wall_gradient,
)
from .tc import STUDY_TC

Runs = dict[tuple[float, float, float], FlowData]
REF = (0.01, 0.99, 0.8)  # Fig 2.11's parameters (φ, β, e), rerun with Ch. 3's N = 2744


def _ratio(a: float, ea: float, b: float, eb: float) -> tuple[float, float]:
    r = a / b
    return r, abs(r) * math.hypot(ea / a if a else 0.0, eb / b if b else 0.0)


def _mean(v: np.ndarray, e: np.ndarray) -> tuple[float, float]:
    ok = np.isfinite(v) & np.isfinite(e)
    return float(np.mean(v[ok])), float(math.sqrt(np.sum(e[ok] ** 2)) / max(ok.sum(), 1))


def _tag(d: FlowData) -> str:
    twin = "" if d.flow.tc is None else f", t_c = {d.flow.tc:g}"
    return f"β = {d.flow.beta:g}, e = {d.flow.e:g}{twin}"


def _unsteady(ds: FlowData | Sequence[FlowData]) -> list[FlowData]:
    return [d for d in (ds if isinstance(ds, (list, tuple)) else [ds])
            if not d.run_info()["steady"]]


def _steady_note(ds: FlowData | Sequence[FlowData]) -> str:
    """Every run of ``ds`` (the runs a row uses) that did not reach its plateau, by name with
    its kinetic-energy trend (the fitted change over the production over its mean; |trend| ≥
    ``demstudy.analysis.steady.STEADY_LIMIT`` counts as unsteady): their values are of a
    transient."""
    bad = _unsteady(ds)
    if not bad:
        return ""
    runs = ", ".join(f"{_tag(d)} (trend {d.run_info()['trend']:.2g})" for d in bad)
    their = "their" if len(bad) > 1 else "its"
    return (f" The run{'s' * (len(bad) > 1)} {runs} {'are' if len(bad) > 1 else 'is'} not "
            f"in steady state: a transient's values ({their} fluctuations, taken about each "
            "bin's run mean, include the mean flow's drift), a weaker test either way.")


def _with_steady_note(reason: str, ds: FlowData | Sequence[FlowData]) -> str:
    """``reason`` as a finished sentence followed by :func:`_steady_note`'s (when a run of
    ``ds`` is unsteady), so that no caller has to end its sentence for it."""
    note, reason = _steady_note(ds).strip(), reason.strip()
    if not note or not reason:
        return reason or note
    reason = reason.rstrip(";:,").rstrip()
    return f"{reason}{'' if reason.endswith('.') else '.'} {note}"


def _cap(verdict: str, ds: FlowData | Sequence[FlowData]) -> str:
    """"partly" for an agreement found in runs that did not reach their plateau (a weaker
    test); a disagreement stays "not reproduced", its reason naming the unsteady runs (one
    possible cause) by ``_steady_note``."""
    return PARTLY if verdict == REPRODUCED and _unsteady(ds) else verdict


def tc_caveats(checks: list[Check], data: Runs,
               evidence: tuple[dict[str, str], dict[str, str]] | None = None) -> None:
    """The studies' one TC rule (:func:`..base.tc_caveats`: a row resting on a run whose TC
    model made more than WARN_SHARE of its pair collisions elastic names the share, and an
    agreement becomes "partly" unless a twin with a small share agrees) on this part's rows.
    A statement about a φ ("φ = 0.5: …") that names no runs rests on every run of that φ,
    except the plateau statements, which are about the runs' length. ``evidence``: (runs a
    small-share twin reproduced → evidence, runs whose twin says something else → what), as
    :func:`tc_twin_evidence` gives them."""
    from ..base import tc_caveats as rule

    for phi in sorted({p for p, _b, _e in data}):
        names = tuple(d.flow.name for (p, _b, _e), d in sorted(data.items()) if p == phi)
        pattern = re.compile(rf"^φ = {re.escape(f'{phi:g}')}[:,]")
        for c in checks:
            if (not c.runs and pattern.match(c.statement)
                    and "plateau of the kinetic energy" not in c.statement):
                c.runs = names
    shares = {d.flow.name: (d.run_info()["tc_fraction"], d.run_info()["tc"])
              for d in data.values()}
    unchanged, told = evidence or ({}, {})
    rule(checks, shares, unchanged, told, unit="√(d/g)")


#: what a TC twin must reproduce of its flow (key → name in the report): a twin that agrees
#: exempts every row resting on the flow (the studies' TC rule), so the comparison spans the
#: kinds of quantity the rows use: profiles, the VDF's shape, Λ and g at contact
TWIN_VALUES = {"u_centre": "u_x centre", "u_wall": "u_x wall", "phi_centre": "φ centre",
               "phi_wall": "φ wall", "T_centre": "T centre", "T_mean": "mean T",
               "theta_wall": "θ wall", "kurtosis_centre": "kurtosis of C_x centre",
               "lambda_mean": "mean Λ", "g_contact": "g(d+) centre"}


def twin_values(d: FlowData) -> dict[str, tuple[float, float]]:
    """The values of run ``d`` a TC twin is compared on (:data:`TWIN_VALUES`; those a run
    lacks, e.g. g(r) without frames, are left out). θ is taken at the walls, where the rows
    read it: the dense plug's centre hardly spins (θ ~ 10⁻⁵ T), and a relative change of a
    vanishing quantity says nothing (the own row quotes it)."""
    out = {"u_centre": d.centre_value("ux"), "u_wall": d.wall_value("ux"),
           "phi_centre": d.centre_value("phi"), "phi_wall": d.wall_value("phi"),
           "T_centre": d.centre_value("T"), "T_mean": d.mean_temperature(),
           "theta_wall": d.wall_value("theta")}
    vdf = d.stat("vdf")
    if "kurtosis" in vdf:
        k = CENTRE_BIN - 1
        out["kurtosis_centre"] = (float(vdf["kurtosis"][k, 0]),
                                  float(vdf["kurtosis_err"][k, 0]))
    if "lambda" in d.stat("lambda"):
        out["lambda_mean"] = lambda_mean(d)
    if d.gr:
        out["g_contact"] = contact_value(d.gr, CENTRE_BIN - 1)
    return out


def _twin_of(data: Runs, twin: FlowData) -> FlowData | None:
    return data.get((twin.flow.phi, twin.flow.beta, twin.flow.e))


def tc_twin_evidence(data: Runs, twins: Sequence[FlowData]
                     ) -> tuple[dict[str, str], dict[str, str]]:
    """What the TC twins (the same flow at a smaller t_c) say, for :func:`tc_caveats`
    (:func:`..base.twin_evidence` on :data:`TWIN_VALUES`; the full comparison in the twin's
    own row, :func:`tc_twin_rows`)."""
    pairs = []
    for twin in twins:
        base = _twin_of(data, twin)
        if base is not None:
            info = twin.run_info()
            pairs.append((base.flow.name, twin_values(base), twin_values(twin),
                          info["tc_fraction"], info["tc"]))
    return twin_evidence(pairs, TWIN_VALUES, unit="√(d/g)")


def tc_twin_rows(data: Runs, twins: Sequence[FlowData], wanted: Sequence) -> list[Check]:
    """demstudy's own rows: each flow of ``wanted`` (Flows with a t_c) against its run at the
    study's t_c (``tc.STUDY_TC``). Reproduced: the same values within 2σ + 10 % and a small
    share at the smaller t_c; partly: the same values, but the twin's share is large too (no
    run free of the model); not reproduced: the values depend on t_c."""
    out = []
    for flow in wanted:
        ref = f"TC model, φ = {flow.phi:g} (demstudy; not in the thesis)"
        statement = (f"the φ = {flow.phi:g} flow (β = {flow.beta:g}, e = {flow.e:g}) does not "
                     f"depend on the event-driven engine's t_c ({STUDY_TC:g} against "
                     f"{flow.tc:g} √(d/g)), and the TC-elastic share is small at the smaller "
                     "t_c")
        thesis = "— (the thesis's collisions all dissipate: no TC model)"
        twin = next((t for t in twins if t.flow == flow), None)
        base = data.get((flow.phi, flow.beta, flow.e))
        if twin is None or base is None:
            out.append(not_run(ref, statement, thesis,
                               [f.name for f, d in ((flow, twin), (base_flow(flow), base))
                                if d is None], own=True))
            continue
        same, text, off = twin_comparison(twin_values(base), twin_values(twin), TWIN_VALUES)
        b, t = base.run_info(), twin.run_info()
        small = t["tc_fraction"] < WARN_SHARE
        theta = (base.centre_value("theta"), twin.centre_value("theta"))
        mean_t = base.mean_temperature()[0]
        measured = (f"t_c {b['tc']:g}: TC share {100 * b['tc_fraction']:.1f} %; t_c "
                    f"{t['tc']:g}: TC share {100 * t['tc_fraction']:.1f} %, " + text
                    + f"; not compared: θ centre {pm(*theta[0])} → {pm(*theta[1])} "
                    f"({theta[1][0] / mean_t:.1g} of the mean T)")
        verdict = _cap(REPRODUCED if same and small else PARTLY if same else NOT_REPRODUCED,
                       [base, twin])
        reason = ("every value within 2σ + 10 %" if same else
                  "a value differs by more than 2σ + 10 % (" + ", ".join(off)
                  + "): the flow depends on t_c")
        if not small:
            reason += ("; the smaller t_c does not bring the share below 5 %: the elastic "
                       "collisions are plausibly the dense core's rapid re-collisions, which a "
                       "smaller t_c brings closer in time rather than removes (not measured)")
        reason += ("; both runs start from the same state (the scene's seed), so the "
                   "comparison isolates t_c; it covers only what the rows use: profiles, the "
                   "centre's kurtosis, Λ and g at contact, not the correlations or the VDF "
                   "tails")
        reason = _with_steady_note(reason + ".", [base, twin])
        out.append(Check(ref, statement, thesis, measured, verdict, reason, own=True))
    return out


def base_flow(flow: Flow) -> Flow:
    """The flow at the study's t_c (``tc.STUDY_TC``) of TC twin ``flow``."""
    return dataclasses.replace(flow, tc=None)


# ------------------------------------------------------------------ steady state
def steady_checks(data: Runs) -> list[Check]:
    out = []
    for phi in (0.01, 0.1, 0.5):
        ds = [d for (p, _b, _e), d in sorted(data.items()) if p == phi]
        ref, statement = "digest §1.8 [L583], [L652]", f"φ = {phi:g}: statistics taken in the " \
                                                 "steady state (plateau of the kinetic energy)"
        if not ds:
            out.append(not_run(ref, statement, "plateau reached", f"the φ = {phi:g} runs"))
            continue
        steady = [d for d in ds if d.run_info()["steady"]]
        bad = ", ".join(_tag(d) for d in ds if d not in steady)
        out.append(Check(ref, statement, "plateau reached before averaging",
                         f"{len(steady)} of {len(ds)} runs on a plateau (demstudy's trend "
                         "test of the kinetic energy over production)",
                         REPRODUCED if len(steady) == len(ds) else PARTLY,
                         "" if not bad else f"not steady: {bad} (runs too short for the CPU "
                                            "budget; see the runs table)"))
    return out


# ------------------------------------------------------------------ §3.5 validation
def validation_checks(data: Runs, box: FlowData | None = None) -> list[Check]:
    """§3.5's qualitative results of the code validation (Fig 2.11): on the validation box
    ``box`` (N = 1000 in a 37.4 d cube, the figure's system) when it ran, else on Ch. 3's
    2744 in 50³ at the same φ, β, e (REF); the other φ = 0.01 runs say whether each holds
    beyond this one flow."""
    main = data.get(REF)
    d = box if box is not None else main
    items = (("slip", "considerable wall slip", _slip),
             ("gradient", "larger velocity gradient near the walls", _gradient),
             ("spin", "ω_z < 0 in the lower half and > 0 in the upper half", _spin_sign),
             ("density", "density slightly higher at the centre but nearly uniform (no "
                         "clusters)", _density),
             ("temps", "T and θ larger near the walls", _temperatures))
    out = []
    for _key, statement, fn in items:
        ref = "digest §3.5 [L595]-[L613], Fig 2.11; Figs 3.3-3.7"
        full = f"φ = 0.01, β = 0.99, e = 0.8: {statement}"
        if d is None:
            out.append(not_run(ref, full, statement, "the φ = 0.01, β = 0.99, e = 0.8 run"))
            continue
        measured, verdict, reason = fn(d)
        if box is not None:
            measured = (f"N = 1000 in {box.flow.side:.1f}³ (Fig 2.11's N; the cube's side "
                        "from φ = 0.01, not given in the thesis): " + measured)
        others = [x for (p, _b, _e), x in data.items() if p == 0.01 and x is not d]
        if others:
            holds = sum(fn(x)[1] == REPRODUCED for x in others)
            ch3 = ("" if box is None or main is None else
                   f"; Ch. 3's N = 2744 in 50³: {'holds' if fn(main)[1] == REPRODUCED else 'not'}")
            measured += (f"{ch3}; holds in {holds} of {len(others)} "
                         f"{'' if box is not None else 'other '}φ = 0.01 runs of Ch. 3")
        out.append(Check(ref, full, statement, measured, _cap(verdict, d),
                         _with_steady_note(reason, d), runs=(d.flow.name,)))
    return out


def _slip(d: FlowData) -> tuple[str, str, str]:
    uw, ew = d.wall_value("ux")
    uc, ec = d.centre_value("ux")
    s, es = _ratio(uw, ew, uc, ec)
    ok = s - 2 * es >= 0.2
    return (f"U_x,w* = {pm(uw, ew)}, U_x,c* = {pm(uc, ec)}, U_w/U_c = {pm(s, es)}",
            REPRODUCED if ok else NOT_REPRODUCED,
            "" if ok else "slip below 20 % of the centre velocity (the threshold read for "
                          "'considerable')")


def _gradient(d: FlowData) -> tuple[str, str, str]:
    u, e = d.series("ux")
    dy = float(d.y[1] - d.y[0])
    gw, ew = wall_gradient(u, e, d.y)
    gi = 0.5 * ((u[6] - u[5]) + (u[-7] - u[-6])) / dy  # bins 6-7 and 19-20: y ≈ W/4, 3W/4
    ei = 0.5 * math.sqrt(e[5] ** 2 + e[6] ** 2 + e[-6] ** 2 + e[-7] ** 2) / dy
    ok = gw - gi > 2 * math.hypot(ew, ei)
    y_in = 0.5 * float(d.y[5] + d.y[6])
    return (f"dU_x*/dy at the walls (bins 1-2) {pm(gw, ew)}, at y ≈ {y_in:.0f} (bins 6-7) "
            f"{pm(gi, ei)} (per d)", REPRODUCED if ok else NOT_REPRODUCED,
            "" if ok else "the wall gradient is not larger beyond 2σ")


def _spin_sign(d: FlowData) -> tuple[str, str, str]:
    w, e = d.series("omz")
    lo, elo = _mean(w[:12], e[:12])
    hi, ehi = _mean(w[13:], e[13:])
    wrong = int(np.sum(w[:12] > 2 * e[:12]) + np.sum(w[13:] < -2 * e[13:]))
    ok = lo < -2 * elo and hi > 2 * ehi and wrong == 0
    return (f"mean ω_z* lower half {pm(lo, elo)}, upper half {pm(hi, ehi)}; bins of the "
            f"wrong sign (2σ): {wrong}", REPRODUCED if ok else NOT_REPRODUCED,
            "" if ok else "sign pattern not found within 2σ")


def _density(d: FlowData) -> tuple[str, str, str]:
    f, e = d.series("phi")
    fc, ec = _mean(f[11:14], e[11:14])
    near = [1, 2, 22, 23]  # bins 2-3 and 23-24: bins 1 and 25 lose the wall's excluded volume
    fw, ew = _mean(f[near], e[near])
    interior = f[1:-1]
    spread = float(np.max(np.abs(interior / np.mean(interior) - 1)))
    higher, uniform = fc - fw > 2 * math.hypot(ec, ew), spread < 0.2
    verdict = REPRODUCED if higher and uniform else PARTLY if (higher or uniform) \
        else NOT_REPRODUCED
    reason = "" if verdict == REPRODUCED else (
        ("centre not denser than the walls beyond 2σ; " if not higher else "")
        + ("interior φ varies by more than 20 % " if not uniform else ""))
    return (f"φ centre (bins 12-14) {pm(fc, ec, 2)}, near walls (bins 2-3, 23-24) "
            f"{pm(fw, ew, 2)}; interior bins within {100 * spread:.0f} % of their mean",
            verdict, reason)


def _temperatures(d: FlowData) -> tuple[str, str, str]:
    parts, ok = [], True
    for key, name in (("T", "T*"), ("theta", "θ*")):
        w, ew = d.wall_value(key)
        c, ec = d.centre_value(key)
        parts.append(f"{name} wall {pm(w, ew)} vs centre {pm(c, ec)}")
        ok &= w - c > 2 * math.hypot(ew, ec)
    return ("; ".join(parts), REPRODUCED if ok else NOT_REPRODUCED,
            "" if ok else "a wall value is not above the centre's beyond 2σ")


# ------------------------------------------------------------------ β = 0 most dissipative
def dissipation_checks(data: Runs) -> list[Check]:
    """β = 0 coldest at each e, on the mass-weighted mean T of the channel (the system's
    temperature, as the thesis monitors the system's kinetic energy): an unweighted mean of
    the bins lets the hot, dilute wall layers of a φ = 0.1 plug flow outweigh its cold,
    dense core (β = 0, e = 0.99: 92.6 unweighted against 36.7 weighted)."""
    out = []
    for phi in (0.01, 0.1):
        ref = "[L664], [L873]; digest §2.3"
        statement = (f"φ = {phi:g}: β = 0 is the most dissipative case (lowest T at "
                     "each e)")
        rows, held, tested, used, untested = [], 0, 0, [], []
        for e in RESTITUTIONS[phi]:
            runs = {b: r for b in BETAS if (r := data.get((phi, b, e))) is not None}
            if 0.0 not in runs or len(runs) < 2:  # β = 0 and at least one other
                untested.append(f"{e:g}")
                continue
            means = {b: r.mean_temperature() for b, r in runs.items()}
            used += runs.values()
            t0, e0 = means[0.0]
            others = [means[b] for b in runs if b != 0.0]
            ok = all(t - t0 > 2 * math.hypot(et, e0) for t, et in others)
            held += ok
            tested += 1
            rows.append(f"e = {e:g}: " + ", ".join(f"β = {b:g}: {pm(*means[b])}"
                                                   for b in runs))
        if not tested:
            out.append(not_run(ref, statement, "lowest T for β = 0",
                                f"β = 0 and another β at one e (φ = {phi:g})"))
            continue
        verdict = REPRODUCED if held == tested else PARTLY if held else NOT_REPRODUCED
        if untested and verdict == REPRODUCED:  # the e not run could still break it
            verdict = PARTLY
        missing = (f"; not tested at e = {', '.join(untested)} (β = 0 and another β not both "
                   "run)" if untested else "")
        out.append(Check(ref, statement, "lowest T for β = 0",
                         f"mass-weighted mean T* (the system's temperature): "
                         f"{'; '.join(rows)}; holds at {held} of {tested} e",
                         _cap(verdict, used),
                         _with_steady_note(
                             (("" if held == tested else "β = 0 is not the coldest beyond 2σ "
                                                         "at every e tested")
                              + missing).strip().removeprefix("; "), used)))
    return out


# ------------------------------------------------------------------ Kn
def knudsen_checks(data: Runs) -> list[Check]:
    out = []
    ds = [d for (p, _b, _e), d in sorted(data.items()) if p == 0.01]
    ref = "[L702]-[L712], [L770]; Fig 3.8"
    statement = ("φ = 0.01: Kn = λ/W > 0.1 across the channel, the transitional regime "
                 "(free paths relative to the local mean flow)")
    if not ds:
        out.append(not_run(ref, statement, "Kn > 0.1", "the φ = 0.01 runs"))
    else:
        lows, lab_lows, rows = [], [], []
        for d in ds:
            k, e = d.series("Kn")
            i = int(np.nanargmin(k))
            lows.append(k[i] - 2 * e[i] > 0.1)
            kl, el = d.series("Kn_lab")
            j = int(np.nanargmin(kl)) if np.any(np.isfinite(kl)) else 0
            lab_lows.append(bool(kl[j] - 2 * el[j] > 0.1))
            rows.append(f"{_tag(d)}: min {pm(k[i], e[i])}, centre {pm(*d.centre_value('Kn'))}"
                        f" (lab displacements: min {pm(kl[j], el[j])})")
        held = sum(lows)
        lab = ("" if all(lab_lows) else
               f"; with the lab-frame displacements of the thesis's formula Kn > 0.1 "
               f"everywhere in {sum(lab_lows)} of {len(ds)} runs")
        out.append(Check(ref, statement, "Kn > 0.1 (transitional)",
                         f"{'; '.join(rows)}; Kn > 0.1 everywhere in {held} of {len(ds)} runs "
                         "(both readings of the free path)" if held == sum(lab_lows) == len(ds)
                         else f"{'; '.join(rows)}; Kn > 0.1 everywhere in {held} of {len(ds)} "
                         "runs",
                         REPRODUCED if held == len(ds) else PARTLY if held else NOT_REPRODUCED,
                         ("" if held == len(ds) else "some bins have Kn ≤ 0.1 within 2σ")
                         + lab))
    out.append(_plug_knudsen(data))
    return out


def _plug_knudsen(data: Runs) -> Check:
    ref, statement = "[L875]; Fig 4.4f", ("φ = 0.1, e = 0.7: Kn 'extremely low' in the β = 0 "
                                          "plug (read: centre Kn < 0.01, lowest of the three β)")
    runs = {b: data.get((0.1, b, 0.7)) for b in BETAS}
    if runs[0.0] is None:
        return not_run(ref, statement, "Kn ≪ 0.1 in the plug", "the φ = 0.1, e = 0.7 runs")
    def holds(key: str) -> tuple[bool, dict[float, tuple[float, float]]]:
        kn = {b: r.centre_value(key) for b, r in runs.items() if r is not None}
        k0, e0 = kn[0.0]
        lowest = all(k0 < k for b, (k, _e) in kn.items() if b != 0.0)
        return k0 + 2 * e0 < 0.01 and lowest, kn

    ok, kn = holds("Kn")
    ok_lab, kn_lab = holds("Kn_lab")
    measured = ("free paths relative to the local mean flow: "
                + ", ".join(f"β = {b:g}: {pm(k, e)}" for b, (k, e) in kn.items())
                + "; lab-frame displacements (the thesis's formula): "
                + ", ".join(f"β = {b:g}: {pm(k, e)}" for b, (k, e) in kn_lab.items()))
    # a lab displacement is never shorter than the relative one on average (the mean flow
    # adds to it), so the lab reading holding implies the relative one
    if ok and ok_lab:
        verdict, reason = REPRODUCED, ""
    elif ok:
        # the thesis's formula is the lab displacement, its plot may not be
        verdict = PARTLY
        reason = ("holds only with free paths relative to the local mean flow: the lab "
                  "displacements of the thesis's formula carry the plug's own motion")
    else:
        verdict, reason = NOT_REPRODUCED, ("centre Kn not below 0.01 or not the lowest, with "
                                           "either reading of the free path")
    used = list(runs.values())  # every β run enters (the lowest Kn among them)
    return Check(ref, statement, "Kn extremely low", measured, _cap(verdict, used),
                 _with_steady_note(reason, used))


# ------------------------------------------------------------------ VDFs
#: a core deviation above this (1000 %) is no shape but a spike narrower than the histogram
#: bins (a bin of the dense plug moving as a solid, σ set by a few fast particles)
SPIKE = 10.0


#: kurtosis below which a spike-cored VDF is read as a drifting mean (light tails), not as a
#: few fast particles (heavy tails)
PLATYKURTIC = 2.5

#: |skewness| above which a component's VDF counts as asymmetric
SKEWED = 0.3
COMPONENTS = ("C_x", "C_y", "C_z")


def vdf_shape(d: FlowData, b: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(core deviations, kurtosis, its error, skewness) of C_x, C_y, C_z in bin ``b``
    (0-based): per component the largest departure of P(C/σ) from the binned Gaussian for
    |x| ≤ 1 beyond 2σ (relative), the kurtosis (3 for a Gaussian) and the skewness."""
    v = d.stat("vdf")
    x, p, e, g = v["malik_centres"], v["malik_P"][b, :3], v["malik_P_err"][b, :3], \
        v["gaussian_binned"]
    core = np.abs(x) <= 1.0
    dev = np.clip(np.abs(p[:, core] - g[core]) - 2 * np.nan_to_num(e[:, core]), 0, None) / g[core]
    return (np.nanmax(dev, axis=1), v["kurtosis"][b, :3], v["kurtosis_err"][b, :3],
            v["skewness"][b, :3])


def _core_above(d: FlowData, b: int, c: int) -> bool:
    """Whether component ``c``'s σ-scaled VDF in bin ``b`` lies above the Gaussian over
    0.5 ≤ |x| ≤ 1 on average (a flat-topped core) rather than below (a peaked one)."""
    v = d.stat("vdf")
    x, g = v["malik_centres"], v["gaussian_binned"]
    ring = (np.abs(x) >= 0.5) & (np.abs(x) <= 1.0)
    return bool(np.nanmean(v["malik_P"][b, c][ring] / g[ring]) > 1.0)


def _core_text(dev: np.ndarray) -> str:
    if np.all(dev <= SPIKE):
        return "core dev " + "/".join(f"{100 * x:.0f}" for x in dev) + " %"
    return f"core a spike (dev > {100 * SPIKE:.0f} %)"


def tails_core_deviation(kurtosis: float) -> float:
    """How far below exp(-x²/2) at |x| = 1 a Student t of this kurtosis lies once scaled
    by its σ and P(0) = 1 (ν = 4 + 6/(κ - 3)); 0 for κ ≤ 3. Heavy tails explain a core
    deviation of about this size and no more."""
    if not kurtosis > 3.0:
        return 0.0
    from scipy import stats

    nu = 4.0 + 6.0 / (kurtosis - 3.0)
    scale = math.sqrt(nu / (nu - 2.0))
    ratio = stats.t.pdf(scale, nu) / stats.t.pdf(0.0, nu)
    return float(1.0 - ratio / math.exp(-0.5))


#: the share of a core deviation heavy tails must predict to be named its cause
TAILS_SHARE = 0.7

#: a spread of temperatures describes a peaked core when one Gaussian's χ² per degree of
#: freedom on the histogram (|x| < MIXTURE_RANGE) is at least this and a two-temperature
#: mixture's below it (the bins' errors taken as independent, so a yardstick, not a p-value)
MIXTURE_FIT = 2.0
MIXTURE_RANGE = 4.0


def two_temperatures(edges: np.ndarray, pdf: np.ndarray, err: np.ndarray
                     ) -> tuple[float, float, float, float, float] | None:
    """Fit q N(0, T₁) + (1 − q) N(0, T₂), with q T₁ + (1 − q) T₂ = 1 (the bin's own σ² = 1),
    to a σ-scaled velocity histogram (density per bin of ``edges``, its errors ``err``; bins
    with |x| < ``MIXTURE_RANGE`` and an error): (q, T₁, T₂, χ²/dof, χ²/dof of one Gaussian)
    with T₁ ≤ T₂, None when too few bins. The model is the histogram bins' average of the
    mixture (erf differences), as ``gaussian_binned`` is of one Gaussian."""
    from scipy import optimize, special

    width = np.diff(edges)
    centres = 0.5 * (edges[1:] + edges[:-1])
    use = np.isfinite(pdf) & np.isfinite(err) & (err > 0) & (np.abs(centres) < MIXTURE_RANGE)
    if use.sum() < 6:
        return None

    def binned(variance: float) -> np.ndarray:
        cdf = 0.5 * (1 + special.erf(edges / math.sqrt(2 * variance)))
        return np.diff(cdf) / width

    def chi2(params: np.ndarray) -> float:
        q, t1 = params
        if not (0 < q < 1 and 0 < t1 < 1 / q):
            return 1e30
        model = q * binned(t1) + (1 - q) * binned((1 - q * t1) / (1 - q))
        return float(np.sum(((model - pdf)[use] / err[use]) ** 2))

    best = min((optimize.minimize(chi2, [q, t1], method="Nelder-Mead")
                for q in (0.1, 0.3, 0.5, 0.7, 0.9) for t1 in (0.2, 0.5, 0.8)),
               key=lambda fit: fit.fun)
    q, t1 = (float(v) for v in best.x)
    t2 = (1 - q * t1) / (1 - q)
    if t1 > t2:  # name the colder population first
        q, t1, t2 = 1 - q, t2, t1
    one = float(np.sum(((binned(1.0) - pdf)[use] / err[use]) ** 2))
    dof = int(use.sum())
    return q, t1, t2, float(best.fun) / (dof - 2), one / dof


def _slow_deficit(v: dict, b: int, c: int) -> str:
    """The σ-scaled density at C = 0 (the two histogram bins beside it, as Malik's P(0))
    against a unit Gaussian's, when it lies below by more than 2σ: a flat top that is a real
    shortage of slow particles, not the P(0) = 1 scaling of a noisy centre."""
    if "malik_pdf_err" not in v or "malik_edges" not in v:
        return ""
    pdf, err, edges = v["malik_pdf"][b, c], v["malik_pdf_err"][b, c], v["malik_edges"]
    nx = len(pdf) // 2
    # the two bins' errors added as fully correlated (an upper bound: they share the run's
    # fluctuations of the bin's σ and count)
    p0, p0_err = 0.5 * (pdf[nx - 1] + pdf[nx]), 0.5 * (err[nx - 1] + err[nx])
    width = float(edges[nx + 1] - edges[nx])  # a unit Gaussian over the bin (0, width)
    gauss = 0.5 * math.erf(width / math.sqrt(2)) / width
    if not p0 + 2 * p0_err < gauss:
        return ""
    return (f" (fewer slow particles than a Gaussian: density at C = 0 {pm(p0, p0_err)} per σ "
            f"against {gauss:.3f})")


def _vdf_cause(d: FlowData, k: int, c: int, dev: float, kur: float, ker: float,
               skew: float) -> tuple[str, str]:
    """(cause, entry) of a core deviating by ``dev`` (> 10 %): component ``c`` of bin ``k``."""
    entry = f"{_tag(d)} bin {k} {COMPONENTS[c]}"
    if abs(skew) > SKEWED:
        return ("skewed-x" if c == 0 else "skewed"), entry
    if kur - 3 > 2 * ker and tails_core_deviation(kur) >= TAILS_SHARE * dev:
        return "tails", f"{entry} (κ {kur:.2f}: {100 * tails_core_deviation(kur):.0f} % of " \
                        f"{100 * dev:.0f} %)"
    v = d.stat("vdf")
    if _core_above(d, k - 1, c):  # no mixture of centred Gaussians is flat-topped
        return "other", f"{entry} flat-topped{_slow_deficit(v, k - 1, c)}"
    fit = (two_temperatures(v["malik_edges"], v["malik_pdf"][k - 1, c],
                            v["malik_pdf_err"][k - 1, c])
           if "malik_pdf_err" in v and "malik_edges" in v else None)
    if fit is not None and fit[3] < MIXTURE_FIT <= fit[4]:  # one Gaussian fails, two fit
        q, t1, t2, chi, one = fit
        return "mixture", (f"{entry} (as {100 * q:.0f} % at {t1:.2f} T, the rest at "
                           f"{t2:.2f} T: χ²/dof {chi:.1f} against {one:.0f} for one Gaussian)")
    return "other", f"{entry} peaked" + (
        f" (χ²/dof {fit[4]:.1f} for one Gaussian, {fit[3]:.1f} for two temperatures)"
        if fit is not None else "")


#: the words for each cause of a core deviation, in the reason's order
VDF_CAUSES = {
    "skewed-x": "Streamwise C_x skewed (|skewness| > {s}): the VDF is asymmetric, its peak "
                "displaced from the mean by slow particles from the walls, which the P(0) = 1 "
                "scaling turns into a core deviation",
    "skewed": "Skewed (|skewness| > {s}) across the flow: an asymmetric VDF, the P(0) = 1 "
              "scaling turning it into a core deviation",
    "tails": "Symmetric with heavy tails: σ-scaled, heavy tails narrow the core (a Student t of "
             "the same kurtosis lies this far below exp(-x²/2) at |x| = 1), so a Gaussian "
             "core and non-Gaussian tails cannot both hold to 10 %; the thesis judged by eye",
    "mixture": "Peaked, and consistent with a spread of temperatures: one Gaussian fails "
               "(χ²/dof ≥ {m:g} on the histogram) where q N(0, T₁) + (1 − q) N(0, T₂) with "
               "the bin's own variance fits (< {m:g}); the bin's particles are not one local "
               "Maxwellian but a superposition of temperatures, whose σ-scaled shape is a "
               "peaked core (two populations, a temperature gradient across the bin and a "
               "drift of T over an unsteady run look alike here; heavy tails are the same "
               "thing, named above when a Student t predicts the deviation)",
    "other": "Neither skewed, heavy-tailed enough nor a spread of temperatures (flat-topped: above "
             "exp(-x²/2) towards |x| = 1, which no mixture of centred Gaussians is; peaked: "
             "below), not explained here",
}


def vdf_checks(data: Runs) -> list[Check]:
    """A Gaussian core (P within 10 % of exp(-x²/2) for |x| ≤ 1, beyond 2σ) and non-Gaussian
    tails (kurtosis ≠ 3 beyond 2σ), per component. In the thesis's scaling (x = C/σ, P(0) =
    1) the two pull against each other: heavy tails narrow the σ-scaled core (a Student t of
    kurtosis 4 lies 14 % below exp(-x²/2) at |x| = 1). Each deviating core (run, bin,
    component) is given one cause: its skewness, tails heavy enough to predict most of the
    deviation (TAILS_SHARE), a peaked core that one Gaussian fails and a spread of
    temperatures fits (:func:`two_temperatures`, MIXTURE_FIT), or none found."""
    out = []
    for phi in (0.01, 0.1, 0.5):
        bins = vdf_bins(phi)
        ds = [d for (p, _b, e), d in sorted(data.items())
              if p == phi and e == (0.9 if phi == 0.5 else RESTITUTIONS[phi][0])]
        ref = {0.01: "digest §4.6, Figs 3.12-3.17", 0.1: "digest §4.6, Figs 4.7-4.9",
               0.5: "digest §4.6, Fig 4.18"}[phi]
        statement = (f"φ = {phi:g}, bins {', '.join(map(str, bins))}: VDFs with a Gaussian "
                     "core and non-Gaussian tails (visual in the thesis)")
        ds = [d for d in ds if "malik_P" in d.stat("vdf")]
        if not ds:
            out.append(not_run(ref, statement, "Gaussian core, tails", f"φ = {phi:g} runs"))
            continue
        rows, cores, tails, spikes, drifts = [], True, False, [], []
        causes: dict[str, list[str]] = {key: [] for key in VDF_CAUSES}
        for d in ds:
            for k in bins:
                dev, kur, ker, skew = vdf_shape(d, k - 1)
                cores &= bool(np.all(dev <= 0.1))
                tails |= bool(np.any(np.abs(kur - 3) > 2 * ker))
                if np.any(dev > SPIKE):
                    # light tails (κ below a Gaussian's 3, toward a uniform's 1.8): the bin's
                    # velocity drifts over the run, not a few fast particles
                    where = f"{_tag(d)} bin {k}"
                    spiking = kur[dev > SPIKE]  # the components whose core is a spike
                    if np.nanmin(spiking) < PLATYKURTIC:
                        drifts.append(f"{where} (kurtosis down to {np.nanmin(spiking):.1f}"
                                      + ("" if d.run_info()["steady"] else ", unsteady run")
                                      + ")")
                    else:
                        spikes.append(where)
                else:
                    for c in range(3):
                        if dev[c] > 0.1:
                            cause, entry = _vdf_cause(d, k, c, float(dev[c]), float(kur[c]),
                                                      float(ker[c]), float(skew[c]))
                            causes[cause].append(entry)
                rows.append(f"{_tag(d)} bin {k}: {_core_text(dev)}, kurtosis "
                            + "/".join(pm(a, b, 1) for a, b in zip(kur, ker, strict=True))
                            + ", skewness " + "/".join(f"{x:.2f}" for x in skew))
        verdict = REPRODUCED if cores and tails else PARTLY if (cores or tails) \
            else NOT_REPRODUCED
        named = [f"{VDF_CAUSES[key].format(s=SKEWED, m=MIXTURE_FIT)}: {', '.join(entries)}"
                 for key, entries in causes.items() if entries]
        reason = "" if verdict == REPRODUCED else (
            ("The core departs from the Gaussian by > 10 % beyond 2σ in some bins. "
             + ". ".join(named) + ". " if named else "")
            + (f"In {', '.join(spikes)} the σ-scaled VDF is a spike narrower than the "
               "histogram's bins (the P(0) = 1 scaling fails): the bin moves nearly as a "
               "solid and a few fast particles set σ. " if spikes else "")
            + (f"In {', '.join(drifts)} the σ-scaled VDF is no Gaussian core (the P(0) = 1 "
               "scaling fails) and its tails are light (a uniform distribution's kurtosis "
               "is 1.8): the fluctuations about the bin's run mean are dominated by a slow "
               "change of the bin's mean velocity over the run (a drift, or a plug moving "
               "as a block), not by thermal motion. " if drifts else "")
            + ("Kurtosis consistent with 3 (Gaussian tails). " if not tails else ""))
        reason = reason.strip()
        verdict = _cap(verdict, ds)
        reason = _with_steady_note(reason, ds)
        out.append(Check(ref, statement, "Gaussian core; tails deviate",
                         "; ".join(rows) + " (per C_x/C_y/C_z: core dev = the largest "
                         "relative departure of P(C/σ) from exp(-x²/2) over |x| ≤ 1 beyond "
                         "2σ; kurtosis, 3 for a Gaussian; skewness)", verdict,
                         reason.strip()))
    return out


def vdf_elastic_limit_checks(data: Runs) -> list[Check]:
    """[L1491] (summary): the VDFs approach the Gaussian as e → 1 (the digest notes that
    [L897], [L909] read otherwise). Measured on the centre bin's excess kurtosis |κ - 3|,
    the mean over C_x, C_y, C_z, at the smallest and the largest e run for each (φ, β):
    "holds" when it falls beyond 2σ."""
    ref = "[L1491] (summary); digest item 10"
    out = []
    for phi in (0.01, 0.1):
        statement = (f"φ = {phi:g}: the VDFs approach the Gaussian as e → 1 (centre bin "
                     f"{CENTRE_BIN}: excess kurtosis |κ - 3| falls with e)")
        rows, held, tested, used = [], 0, 0, []
        for beta in BETAS:
            runs = sorted(((e, d) for (p, b, e), d in data.items()
                           if p == phi and b == beta and "kurtosis" in d.stat("vdf")),
                          key=lambda item: item[0])
            if len(runs) < 2:
                continue
            (e_lo, d_lo), (e_hi, d_hi) = runs[0], runs[-1]
            excess = {}
            for e, d in ((e_lo, d_lo), (e_hi, d_hi)):
                v = d.stat("vdf")
                ku, ke = v["kurtosis"][CENTRE_BIN - 1, :3], v["kurtosis_err"][CENTRE_BIN - 1, :3]
                excess[e] = (float(np.mean(np.abs(ku - 3.0))),
                             float(np.sqrt(np.sum(ke ** 2))) / 3.0)
            (a, ea), (b, eb) = excess[e_lo], excess[e_hi]
            ok = a - b > 2.0 * math.hypot(ea, eb)
            held += ok
            tested += 1
            used += [d_lo, d_hi]
            rows.append(f"β = {beta:g}: e = {e_lo:g} {pm(a, ea)} → e = {e_hi:g} {pm(b, eb)}"
                        + ("" if ok else " (not beyond 2σ)"))
        if not tested:
            out.append(not_run(ref, statement, "VDF → Gaussian as e → 1",
                                f"two e at one β (φ = {phi:g})"))
            continue
        verdict = REPRODUCED if held == tested else PARTLY if held else NOT_REPRODUCED
        reason = "" if held == tested else (
            f"|κ - 3| does not fall beyond 2σ at {tested - held} of {tested} β")
        verdict = _cap(verdict, used)
        reason = _with_steady_note(reason, used)
        out.append(Check(ref, statement, "VDF → Gaussian as e → 1",
                         "mean |κ - 3| of C_x/C_y/C_z: " + "; ".join(rows)
                         + f"; holds at {held} of {tested} β", verdict, reason.strip()))
    return out


#: the energy budget (gravity's work = dissipation + energy gained − walls' work) closes when
#: its residual is below this fraction of gravity's work (the engine's round-off is ~1e-9)
BUDGET_TOL = 1e-6


def wall_dissipation_checks(data: Runs) -> list[Check]:
    """[L726]: "dissipation of energy at the walls due to wall-particle collisions is large"
    for β = 0. The thesis's Ch. 3-4 walls (e_w = β_w = 1) conserve each colliding particle's
    energy exactly (digest §1.2, §2.3): its walls cannot dissipate. The check reads each β = 0
    run's walls and its energy budget (gravity's work against the dissipation, which all
    comes from pair collisions when the walls are elastic)."""
    ref = "[L726]; digest §1.2, item 7"
    statement = "β = 0: the walls dissipate much energy (wall-particle collisions)"
    runs = [d for (p, b, e), d in sorted(data.items()) if b == 0.0]
    if not runs:
        return [not_run(ref, statement, "large wall dissipation", "a β = 0 run")]
    elastic, budgets = [], []
    for d in runs:
        walls = d.res.scene.walls
        elastic.append(all(w.restitution == 1.0 and w.tangential.model == "beta"
                           and w.tangential.beta == 1.0 for w in walls))
        ts = d.res.timeseries
        wall_work = float(ts["wall_work_lower"][-1] + ts["wall_work_upper"][-1]) \
            if "wall_work_lower" in ts else 0.0
        # the budget from t = 0: gravity's work = dissipation + the energy the flow gained
        # (kinetic and rotational) + what the walls took; its residual is the round-off
        gained = sum(float(ts[k][-1] - ts[k][0]) for k in ("kinetic_energy",
                                                          "rotational_energy") if k in ts)
        work = float(ts["gravity_work"][-1])
        if not work > 0:
            budgets.append(f"{_tag(d)}: no work of gravity recorded")
            continue
        residual = (work - float(ts["dissipated_energy"][-1]) - gained + wall_work) / work
        closes = (f"the budget closes to {abs(residual):.0e}" if abs(residual) < BUDGET_TOL
                  else f"the budget does NOT close: residual {residual:+.2e} of gravity's work")
        budgets.append(f"{_tag(d)}: dissipation/gravity's work "
                       f"{ts['dissipated_energy'][-1] / work:.4f}, energy gained since t = 0 "
                       f"{gained / work:.4f}, walls' work {wall_work:g}; {closes}")
    phis = sorted({p for (p, b, _e) in data if b == 0.0})
    measured = (f"walls e_w = β_w = 1 in {sum(elastic)} of {len(runs)} β = 0 runs "
                f"(φ = {', '.join(f'{p:g}' for p in phis)}): a wall collision then conserves "
                "the particle's energy exactly (tests/test_edmd_walls.py: the energy budget "
                "with such walls closes to round-off), so all of the dissipation is in "
                "pair collisions (gravity's work over the whole run, t = 0 to its end): "
                + "; ".join(budgets[:3])
                + (f"; … ({len(budgets)} runs)" if len(budgets) > 3 else ""))
    if not all(elastic):
        return [Check(ref, statement, "large wall dissipation", measured, PARTLY,
                      "some β = 0 runs have dissipative walls: the wall share is not "
                      "separated in the results file")]
    return [Check(ref, statement, "large wall dissipation", measured, NOT_REPRODUCED,
                  "the thesis's own walls (e_w = β_w = 1, Ch. 3-4) dissipate nothing: the "
                  "statement contradicts its model (digest item 7). What is large at β = 0 "
                  "is the pair collisions' loss (β = 0 removes the tangential relative "
                  "velocity at each collision), and the walls' momentum sink (wall slip) is "
                  "what the thesis may have meant")]


# ------------------------------------------------------------------ g(r) contact
def contact_checks(data: Runs) -> list[Check]:
    out = []
    for phi in (0.01, 0.1, 0.5):
        ds = [d for (p, _b, _e), d in sorted(data.items()) if p == phi and d.gr]
        ref = {0.01: "digest §4.7, Figs 3.18-3.20", 0.1: "digest §4.7, Fig 4.10",
               0.5: "digest §4.7, Fig 4.17"}[phi]
        statement = (f"φ = {phi:g}, bin 13: g(r) contact value vs Enskog's χ "
                     "(Carnahan-Starling at the bin's φ)")
        if not ds:
            out.append(not_run(ref, statement, "χ(φ) (CS)", f"φ = {phi:g} runs", own=True))
            continue
        rows, held, ratios, far_high, frozen = [], 0, [], [], []
        for d in ds:
            g, eg = contact_value(d.gr, CENTRE_BIN - 1)
            f = d.centre_value("phi")[0]
            chi = carnahan_starling(f)
            ok = within(g, eg, chi, 2.0, 0.1 * chi)  # CS/Enskog: ~10 % (dense, inelastic)
            held += ok
            ratios.append((g / chi, eg / chi))
            far, efar = _far_g(d.gr)
            if not ok and far - 2 * efar > 1.02:
                far_high.append(f"{_tag(d)} {pm(far, efar)}")
            if f > FREEZING and not ok:
                frozen.append(_tag(d))
            rows.append(f"{_tag(d)}: g(d+) {pm(g, eg)} vs χ_CS({f:.3g}) = {chi:.3g}, "
                        f"g(4-5 d) {pm(far, efar)}")
        r = np.array(ratios)
        w = 1.0 / np.maximum(r[:, 1], 1e-12) ** 2
        mean = float(np.sum(w * r[:, 0]) / np.sum(w))
        # runs that disagree beyond their errors: the error grows by √(χ²/dof)
        chi2 = float(np.sum(w * (r[:, 0] - mean) ** 2)) / max(len(r) - 1, 1)
        pooled = (mean, float(math.sqrt(max(chi2, 1.0) / np.sum(w))))
        spread = (f" (runs {r[:, 0].min():.3g}-{r[:, 0].max():.3g})" if len(r) > 1 else "")
        verdict = REPRODUCED if held == len(ds) else PARTLY if held else NOT_REPRODUCED
        causes = []
        if far_high:
            causes.append("g stays above 1 at 4-5 d in " + ", ".join(far_high) + ": density "
                          "correlations over several d (inelastic clustering, or the bin's "
                          "density gradient) accompany the high contact value")
        if frozen:
            causes.append(f"the bin's φ lies above freezing ({FREEZING}) in "
                          + ", ".join(frozen) + ": Carnahan-Starling is the fluid branch, "
                          "outside its range there")
        if not causes and verdict != REPRODUCED:
            causes.append("pair correlations beyond molecular chaos (inelastic clustering) "
                          "or ordering")
        out.append(Check(ref, statement, "contact value ≈ χ_CS(φ) (no value in the thesis)",
                         "; ".join(rows) + f"; agree (2σ + 10 %) in {held} of {len(ds)}; "
                         f"pooled g(d+)/χ_CS = {pm(*pooled)}{spread}",
                         _cap(verdict, ds),
                         _with_steady_note(
                             "" if verdict == REPRODUCED else
                             "the contact value departs from Enskog-CS: " + "; ".join(causes)
                             + ".", ds),
                         own=True))  # the thesis shows g(r) but states no contact value
    return out


def _shell_centres(gr: dict[str, np.ndarray]) -> np.ndarray:
    """The centres of g(r)'s shells (r/d)."""
    return 0.5 * (gr["r_edges"][1:] + gr["r_edges"][:-1])


def shell_peaks(gr: dict[str, np.ndarray], b: int) -> list[float]:
    """The local maxima of bin ``b``'s g(r) beyond 1.5 d (the shells after contact) that
    stand out of the noise: prominence above 3 × the median error."""
    from scipy.signal import find_peaks

    r = _shell_centres(gr)
    g, e = gr["g"][b], gr["g_err"][b]
    found, _ = find_peaks(g, prominence=3.0 * float(np.median(e[r > 1.0])))
    return [float(r[i]) for i in found if r[i] > 1.5]


def gr_shell_checks(data: Runs) -> list[Check]:
    """[L951] after Fig 4.10 (φ = 0.1, bin 13, several e; β = 0 in the main panel): g(r)
    peaks at r/d = 2 and 3, read as the second and third shells after the contact peak (the
    digest finds the numbers odd for a contact at r = d). Each shell "seen" when a peak of
    the centre bin lies within 0.2 d of it."""
    ref, statement = "[L951], Fig 4.10", ("φ = 0.1, bin 13: g(r) peaks at r/d = 2 and 3 "
                                          "(the shells after contact)")
    ds = [d for (p, _b, _e), d in sorted(data.items()) if p == 0.1 and d.gr]
    if not ds:
        return [not_run(ref, statement, "peaks at 2 d, 3 d", "the φ = 0.1 runs")]
    rows, both, lacking, counts = [], [], [], [0, 0]
    for d in ds:
        peaks = shell_peaks(d.gr, CENTRE_BIN - 1)
        seen = [any(abs(r - shell) < 0.2 for r in peaks) for shell in (2.0, 3.0)]
        counts = [c + s for c, s in zip(counts, seen, strict=True)]
        phi = d.centre_value("phi")[0]
        rows.append(f"{_tag(d)} (bin φ {phi:.2f}): " + (", ".join(f"{r:.2f}" for r in peaks)
                                                        or "none"))
        (both if all(seen) else lacking).append((d, phi))
    main = [d for d in ds if d.flow.beta == 0.0]
    main_both = [d for d, _ in both if d.flow.beta == 0.0]
    verdict = (REPRODUCED if main and len(main_both) == len(main) else
               PARTLY if both else NOT_REPRODUCED)
    reason = "" if verdict == REPRODUCED else (
        ("not every β = 0 run (the figure's main panel) shows both; " if main else
         "no β = 0 run (the figure's main panel); ")
        + f"the 2 d shell stands out of the noise in {counts[0]} of {len(ds)} runs, the 3 d "
        f"shell in {counts[1]}; missing one in "
        + ", ".join(f"{_tag(d)} (bin φ {p:.2f})" for d, p in lacking)
        + ": the outer shells of a fluid at φ ≲ 0.3 are weak (g within ≈ 10 % of 1), so "
        "longer runs or wider bins would be needed to resolve them")
    # the digest's erratum 4: the thesis's r may be in radii (then its peaks are at d, the
    # contact, and 1.5 d); this row reads diameters and says so
    reason = (reason + ("; " if reason else "") + "r read in diameters; the digest (erratum "
              "4) notes the thesis's r may be in radii, which would put its peaks at d (the "
              "contact peak, present in every run) and 1.5 d")
    return [Check(ref, statement, "peaks at r/d = 2, 3",
                  "centre-bin g(r) peaks beyond 1.5 d (r/d): " + "; ".join(rows)
                  + f"; both shells in {len(both)} of {len(ds)} runs",
                  _cap(verdict, ds),
                  _with_steady_note(reason, ds))]


#: a wall bin is "sparse" below this fraction of a uniform gas's φ there
SPARSE = 0.5


def sparse_wall_checks(data: Runs) -> list[Check]:
    """[L945], [L972]: at φ = 0.1 the bins by the walls hold few particles (their g(r) and
    velocity correlations are 'negligible' for that reason). Sparse: the wall bins' φ (bins
    1 and 25, Malik's wall value) below SPARSE × the channel's mean φ."""
    ref, statement = "[L945], [L972]", ("φ = 0.1: the bins by the walls hold few particles "
                                        "(their g(r) and correlations not reported)")
    ds = [d for (p, _b, _e), d in sorted(data.items()) if p == 0.1]
    if not ds:
        return [not_run(ref, statement, "sparse near-wall bins", "the φ = 0.1 runs")]
    rows, sparse, ratios = [], [], {}
    for d in ds:
        f, _ef = d.series("phi")
        wall, ewall = d.wall_value("phi")
        ratio = wall / float(np.nanmean(f)) / uniform_wall_share(f.size, float(d.y[1] - d.y[0]))
        ratios[id(d)] = ratio
        rows.append(f"{_tag(d)}: {pm(wall, ewall)} ({100 * ratio:.0f} % of a uniform gas's)")
        if ratio < SPARSE:
            sparse.append(d)
    verdict = REPRODUCED if len(sparse) == len(ds) else PARTLY if sparse else NOT_REPRODUCED
    dense = [d for d in ds if d not in sparse]
    low = min((ratios[id(d)] for d in dense), default=0.0)
    high = max((ratios[id(d)] for d in dense), default=0.0)
    share = f"{100 * low:.0f}" + (f"-{100 * high:.0f}" if round(100 * high) > round(100 * low)
                                   else "")
    reason = ("" if not dense else
              "not sparse in " + ", ".join(_tag(d) for d in dense) + ": there the wall bins "
              f"keep {share} % of a uniform gas's φ, a weaker contrast between the walls and "
              "the centre.")
    return [Check(ref, statement, "sparse near-wall bins",
                  "wall bins' φ (bins 1, 25) against a uniform gas's there (the centres stay "
                  "d/2 off the wall): " + "; ".join(rows)
                  + f"; below {100 * SPARSE:.0f} % in {len(sparse)} of {len(ds)}",
                  _cap(verdict, ds),
                  _with_steady_note(reason, ds))]


def uniform_wall_share(n_bins: int, width: float) -> float:
    """A uniform gas's solid fraction in a wall bin over the channel's mean φ: the centres
    stay d/2 off the wall, so a bin of ``width`` d (≥ 1) at the wall holds (width - 1/2)/width
    of an inner bin's (sphere volume counted where it lies)."""
    wall = (width - 0.5) / width
    return wall / ((n_bins - 2 + 2 * wall) / n_bins)


#: hard-sphere freezing: the fluid branch (Carnahan-Starling) ends here
FREEZING = 0.494


def _far_g(gr: dict[str, np.ndarray]) -> tuple[float, float]:
    """The centre bin's g over 4-5 d and its error (1 when the bin holds no correlations
    beyond a few d)."""
    r = _shell_centres(gr)
    sel = (r >= 4.0) & (r < 5.0)
    if not sel.any():
        return float("nan"), float("nan")
    return _mean(gr["g"][CENTRE_BIN - 1][sel], gr["g_err"][CENTRE_BIN - 1][sel])


# ------------------------------------------------------------------ Λ
def lambda_mean(d: FlowData) -> tuple[float, float]:
    lam = d.stat("lambda")
    ok = lam["count"] > 0
    return _mean(lam["lambda"][ok], lam["lambda_err"][ok])


#: β at or below which a sphere counts as nearly smooth: its spin barely couples to its
#: translation, so Λ stays at 1/3 (the control, not the statement's "rough" spheres)
SMOOTH_BETA = -0.9


def lambda_checks(data: Runs) -> list[Check]:
    """Λ ≠ 1/3 for rough spheres (β > SMOOTH_BETA, judged on every such run); the nearly
    smooth β = -0.99 runs are the control, expected at 1/3 (Brilliantov et al. 2007: the
    correlation comes from the roughness coupling spin and translation). Trends with e are
    fitted over steady runs only."""
    out = []
    for phi in (0.01, 0.1, 0.5):
        ds = [d for (p, _b, _e), d in sorted(data.items()) if p == phi
              and "lambda" in d.stat("lambda")]
        ref = {0.01: "digest §4.8 [L819]-[L837], Fig 3.21", 0.1: "digest §4.8, Fig 4.11",
               0.5: "digest §4.8, Fig 4.20"}[phi]
        statement = (f"φ = {phi:g}: orientational correlation Λ(y) departs from the "
                     "molecular value 1/3 for rough spheres; its variation with β and e "
                     "(insets)")
        if not ds:
            out.append(not_run(ref, statement, "Λ ≠ 1/3", f"φ = {phi:g} runs"))
            continue
        rough = [d for d in ds if d.flow.beta > SMOOTH_BETA]
        smooth = [d for d in ds if d.flow.beta <= SMOOTH_BETA]
        means = {id(d): lambda_mean(d) for d in ds}

        def off(runs: list[FlowData], means=means) -> list[float]:
            return [abs(means[id(d)][0] - 1 / 3) for d in runs]

        rows, departs = [], []
        for d in ds:
            m, em = means[id(d)]
            lam = d.stat("lambda")
            c, ec = lam["lambda"][CENTRE_BIN - 1], lam["lambda_err"][CENTRE_BIN - 1]
            if abs(m - 1 / 3) > 2 * em:
                departs.append(d)
            rows.append(f"{_tag(d)}: mean {pm(m, em)}, centre {pm(c, ec)}")
        # a rough run's departure counts beyond what anisotropy alone gives the control
        floor = max(off([d for d in smooth if d.run_info()["steady"]]), default=0.0)
        beyond = [d for d in rough if off([d])[0] - floor > 2 * means[id(d)][1]]
        steady = [d for d in ds if d.run_info()["steady"]]
        trend = _lambda_trend(steady)
        dropped = len(ds) - len(steady)
        thesis = ("Λ ≠ 1/3 for rough inelastic spheres (Brilliantov et al. 2007; direction of "
                  "the trends: digest silent)")
        measured = ("; ".join(rows) + (f". Trend (steady runs): {trend}" if trend else "")
                    + (f" ({dropped} unsteady run(s) left out of the trends)" if dropped
                       else ""))
        control = [d for d in smooth if d not in departs]
        rough_off = off([d for d in rough if d in departs])
        control_text = (f" Nearly smooth control (β ≤ {SMOOTH_BETA:g}, spin barely coupled): "
                        f"Λ̄ at 1/3 within 2σ in {len(control)} of {len(smooth)} runs"
                        + (", as expected." if len(control) == len(smooth) else
                           f"; the others off 1/3 by up to {max(off(smooth)):.2g}"
                           + (" (unsteady runs among them)" if any(
                               not d.run_info()["steady"] for d in smooth if d in departs)
                              else "")
                           + (f" (rough runs: from {min(rough_off):.2g})" if rough_off
                              else "") + ": anisotropic translational and rotational "
                           "fluctuations move Λ off 1/3 even without a spin-translation "
                           "correlation, so a departure alone does not prove the roughness "
                           "coupling; and the walls (e_w = β_w = 1, perfectly rough) couple "
                           "spin and translation in every wall collision even here: a "
                           "spin-free control would need β = β_w = -1.")
                        if smooth else "")
        if not rough:
            out.append(Check(ref, statement, thesis, measured, NOT_RUN,
                             f"no rough (β > {SMOOTH_BETA:g}) run at φ = {phi:g}"
                             + control_text))
            continue
        verdict = REPRODUCED if len(beyond) == len(rough) else PARTLY \
            if beyond else NOT_REPRODUCED
        near = ", ".join(_tag(d) for d in rough if d not in departs)
        within_floor = ", ".join(_tag(d) for d in rough if d in departs and d not in beyond)
        out.append(Check(ref, statement, thesis, measured,
                         _cap(verdict, rough),
                         _with_steady_note(
                          ("" if verdict == REPRODUCED else
                           (f"Λ̄ consistent with 1/3 (2σ) for {near}. " if near else "")
                           + (f"Off 1/3, but not by 2σ more than the steady smooth control "
                              f"({floor:.2g}), for {within_floor}: anisotropy, not roughness, "
                              "may explain it." if within_floor else ""))
                          + control_text, rough)))
    return out


def _lambda_trend(ds: list[FlowData]) -> str:
    """The sign of dΛ̄/de per β (least squares over e) in words."""
    parts = []
    for b in sorted({d.flow.beta for d in ds}):
        sub = sorted((d for d in ds if d.flow.beta == b), key=lambda d: d.flow.e)
        if len(sub) < 2:
            continue
        e = np.array([d.flow.e for d in sub])
        m = np.array([lambda_mean(d)[0] for d in sub])
        slope = float(np.polyfit(e, m, 1)[0])
        grows = slope * (m.mean() - 1 / 3) < 0  # |Λ̄ - 1/3| larger at smaller e
        parts.append(f"β = {b:g}: |Λ̄ - 1/3| {'grows' if grows else 'shrinks'} as e falls "
                     f"(dΛ̄/de = {slope:.2g})")
    return "; ".join(parts)


# ------------------------------------------------------------------ φ = 0.5 and waves
def dense_checks(data: Runs) -> list[Check]:
    d = data.get((0.5, 0.9, 0.9))
    ref, statement = "[L996]-[L1050], Figs 4.15-4.16; §6", \
        "φ = 0.5: a liquid-like dense core (0.494 < φ < 0.64) flowing as a plug"
    if d is None:
        return [not_run(ref, statement, "liquid-like core, plug", "the φ = 0.5 run")]
    f, ef = d.series("phi")
    core = slice(9, 16)  # bins 10-16
    fc, efc = _mean(f[core], ef[core])
    u, eu = d.series("ux")
    shear_core = abs(float(np.polyfit(d.y[core], u[core], 1)[0]))
    shear_wall = abs(wall_gradient(u, eu, d.y)[0])
    liquid = FREEZING < fc < 0.64
    plug = shear_core < 0.2 * shear_wall
    verdict = REPRODUCED if liquid and plug else PARTLY if (liquid or plug) else NOT_REPRODUCED
    reason = "" if verdict == REPRODUCED else (
        ("core φ outside the liquid range; " if not liquid else "")
        + ("core shear not < 20 % of the wall's" if not plug else ""))
    structure, glassy = _second_shell(d)
    if liquid and fc > MELTING:
        reason += (f" The thesis's φ range holds, but the core lies above hard-sphere melting "
                   f"(φ = {MELTING}), where no equilibrium fluid exists"
                   + ("; its centre bin's g(r) has the sharp peak at 2 d of collinear "
                      "touching triples and no crystal's peak at √2 d (above): an amorphous, "
                      "glass-like packing rather than a liquid" if glassy else "") + ".")
    return [Check(ref, statement, "liquid-like core and plug",
                  f"core φ (bins 10-16) {pm(fc, efc, 2)}; |dU_x/dy| core {shear_core:.3g}, "
                  f"at the walls {shear_wall:.3g} per √(d/g)" + structure,
                  _cap(verdict, d), _with_steady_note(reason, d))]


#: hard-sphere melting: the densest equilibrium fluid coexists with the crystal up to here
MELTING = 0.545


def _second_shell(d: FlowData) -> tuple[str, bool]:
    """The centre bin's g(r) second shell: its largest value near √3 d (1.65-1.9 d) and just
    below 2 d (1.9-2.0 d), and whether the 2 d one is a peak standing above the √3 d one by
    more than 10 % (collinear touching triples: dense amorphous packings; a liquid's second
    shell is one smooth peak near 2 d)."""
    gr = d.gr
    if "g" not in gr:
        return "", False
    r = _shell_centres(gr)
    g = gr["g"][CENTRE_BIN - 1]
    near_root3 = (r > 1.65) & (r < 1.9)
    near_two = (r >= 1.9) & (r < 2.0)
    beyond = (r >= 2.0) & (r < 2.1)
    if not (near_root3.any() and near_two.any() and beyond.any()):
        return "", False
    g3, g2, g_after = (float(np.max(g[near_root3])), float(np.max(g[near_two])),
                       float(np.max(g[beyond])))
    root2 = (r > 1.35) & (r < 1.48)  # FCC/HCP's second neighbours
    g_root2 = float(np.max(g[root2])) if root2.any() else float("nan")
    glassy = g2 > 1.1 * g3 and g2 > 1.2 * g_after and not g_root2 > 1.0
    return (f"; centre-bin g(r): {float(np.max(g)):.3g} in the first shell (d to 1.05 d), "
            f"{g_root2:.3g} at most near √2 d (no crystal's peak when < 1), second shell max "
            f"{g3:.3g} at 1.65-1.9 d and {g2:.3g} at 1.9-2 d, then {g_after:.3g} at 2-2.1 d"), \
        glassy


def wave_checks(data: Runs) -> list[Check]:
    """Figs 4.1, 4.3, 4.5 (φ = 0.1, e = 0.7): the density structure for each β, from the
    modes of the xy density (``poiseuille_waves``): the thesis names the β = 0 plug [L875]
    and the β = 0.99 S-wave (Fig 4.5); of β = -0.99 it shows snapshots only."""
    return [_s_wave(data), _beta_structure(data, 0.0), _beta_structure(data, -0.99)]


#: the (0, 1) mode is also the mean density profile across the walls: strong in every
#: wall-bounded flow, so the structures are told apart by the x-modulated modes
PROFILE_MODE = ("the (0, 1) mode is also the mean density profile across the walls, strong in "
                "every wall-bounded flow: the structures differ in the x-modulated modes")


def _s_wave(data: Runs) -> Check:
    d = data.get((0.1, 0.99, 0.7))
    ref, statement = "Fig 4.5 [L925]", "φ = 0.1, β = 0.99, e = 0.7: an S-shaped density wave"
    if d is None:
        return not_run(ref, statement, "S-wave seen", "the φ = 0.1, β = 0.99, e = 0.7 run")
    from .poiseuille_waves import mode_ratios, s_wave_text

    r = mode_ratios(d)
    (ratio, err), (slug, slug_err), text = r["11"], r["10"], s_wave_text(r)
    above_noise = ratio - 2 * err > 1.0
    # an S-wave, not a slug: the antisymmetric (1, ±1) mode beats the symmetric (1, 0)
    over_slug = ratio - slug > 2 * math.hypot(err, slug_err)
    seen = above_noise and over_slug
    reason = ("" if seen else
              "the antisymmetric (1,1) mode is not above the noise of independent particles"
              if not above_noise else
              "the (1,1) mode does not exceed the slug's (1,0) beyond 2σ: a slug or a mixed "
              "wave rather than an S-wave")
    reason = f"{reason}; {PROFILE_MODE}" if reason else PROFILE_MODE[0].upper() + PROFILE_MODE[1:]
    return Check(ref, statement, "S-wave (mode (1,1) of the xy density)", text,
                 _cap(REPRODUCED if seen else NOT_REPRODUCED, d),
                 _with_steady_note(reason + ".", d),
                 runs=(d.flow.name,))


def _x_share(modes: dict[str, tuple[float, float]]) -> float:
    """The stronger x-modulated mode, (1, 0) or (1, ±1), in % of the (0, 1) mode's power."""
    return 100 * max(modes["11"][0], modes["10"][0]) / modes["01"][0]


def _beta_structure(data: Runs, beta: float) -> Check:
    """The β = 0 plug [L875] (Fig 4.3), or the β = -0.99 structure (Fig 4.1: no class in
    the thesis's text)."""
    from .poiseuille_waves import mode_ratios, s_wave_text, structure_class

    plug = beta == 0.0
    ref = "[L875], Fig 4.3" if plug else "Fig 4.1 [L861]"
    statement = (f"φ = 0.1, β = {beta:g}, e = 0.7: " + ("a plug (dense centre, no modulation "
                 "along the flow)" if plug else "the density structure (snapshots)"))
    thesis = "plug" if plug else "snapshots only (no class stated)"
    d = data.get((0.1, beta, 0.7))
    if d is None:
        return not_run(ref, statement, thesis, f"the φ = 0.1, β = {beta:g}, e = 0.7 run")
    r = mode_ratios(d)
    kind, why = structure_class(r)
    measured = f"{kind}: {why}; {s_wave_text(r)}"
    if not plug:
        return Check(ref, statement, thesis, measured, NO_THESIS_VALUE,
                     _with_steady_note(
                         "the thesis shows this run's snapshots without naming its structure; "
                         + PROFILE_MODE + ".", d), runs=(d.flow.name,))
    if kind == "plug":
        return Check(ref, statement, thesis, measured, _cap(REPRODUCED, d),
                     _with_steady_note("", d), runs=(d.flow.name,))
    other = data.get((0.1, 0.99, 0.7))
    than = ""
    if other is not None:
        o = mode_ratios(other)
        than = (f" ({_x_share(r):.2g} % of (0, 1)'s power here against {_x_share(o):.2g} % "
                "in the β = 0.99 run the thesis calls an S-wave)")
    return Check(ref, statement, thesis, measured, NOT_REPRODUCED,
                 _with_steady_note(
                     f"not a plug: the density is modulated along the flow ({kind}){than}; "
                     "the thesis's plug is read off snapshots (one time), ours is the mean "
                     "over the production's frames; " + PROFILE_MODE + ".", d),
                 runs=(d.flow.name,))


# ------------------------------------------------------------------ free paths (Fig 3.9)
def tail_length(fp: dict[str, np.ndarray], b: int, below: float = math.inf
                ) -> tuple[float, float]:
    """(ℓ, λ) in bin ``b`` (0-based): the decay length of P(l)'s tail, a weighted
    straight-line fit to log P over λ < l < min(4λ, ``below``) (resolved histogram bins
    only; ``below``: where the walls start to cut the flights off), and the mean free path
    λ."""
    x, p, e = fp["lambda"], fp["p_lambda"][b], fp["p_lambda_err"][b]
    lam = float(fp["mean_free_path"][b])
    ok = (p > 0) & np.isfinite(e) & (e < 0.5 * p) & (x > lam) & (x < min(4 * lam, below))
    if ok.sum() < 3:
        return math.nan, lam
    slope = np.polyfit(x[ok], np.log(p[ok]), 1, w=p[ok] / e[ok])[0]
    return (-1.0 / slope if slope < 0 else math.nan), lam


#: the tail fit stops at this fraction of the distance from the bin to the nearer wall
WALL_REACH = 0.8


def freepath_checks(data: Runs) -> list[Check]:
    """Fig 3.9: the free-path distribution P(l), whose tails the thesis shows on a log scale
    without stating values: the tail's decay length against the mean free path in bin 13,
    fitted below the distance to the walls (which cut the longest flights off)."""
    ref, statement = "Fig 3.9 [L718]", ("φ = 0.01: the free-path distribution P(l) for "
                                        "several e (tails on a log scale)")
    ds = [d for (p, _b, _e), d in sorted(data.items()) if p == 0.01
          and "p_lambda" in d.stat("freepath")]
    if not ds:
        return [not_run(ref, statement, "figure only", "the φ = 0.01 runs")]
    parts, ratios, widths = [], [], []
    y = ds[0].y
    reach = wall_distance(y, CENTRE_BIN - 1)
    for d in ds:
        ell, lam = tail_length(d.stat("freepath"), CENTRE_BIN - 1, WALL_REACH * reach)
        ratios.append(ell / lam)
        widths.append((WALL_REACH * reach - lam) / ell)
        parts.append(f"{_tag(d)}: ℓ = {ell:.3g} d, λ = {lam:.3g} d (ℓ/λ {ell / lam:.2f})")
    lo, hi = np.nanmin(ratios), np.nanmax(ratios)
    return [Check(ref, statement, "figure only (no values in the text)",
                  f"bin 13, exp(-l/ℓ) fitted over λ < l < {WALL_REACH * reach:.0f} d: "
                  + "; ".join(parts), NO_THESIS_VALUE,
                  _with_steady_note(
                  f"ℓ/λ = {lo:.2f}-{hi:.2f} over the fit window (about "
                  f"{np.nanmean(widths):.1f} decay lengths wide; no error is given: a "
                  "yardstick): the distribution falls off "
                  "about as the exponential of a dilute gas with the run's own mean free "
                  f"path. The walls, {reach:.0f} d from bin 13, end the longest flights: "
                  "beyond that distance the figure's P(l) leaves the exponential, and the "
                  "mean λ counts those shortened flights too. The thesis states no value to "
                  "compare with.", ds),
                  runs=tuple(d.flow.name for d in ds))]


# ------------------------------------------------------------------ wall values (Figs 3.10-3.11)
WALL_KEYS = (("ux", "U_x*"), ("omz", "ω_z*"), ("T", "T*"), ("theta", "θ*"))


def wall_slope(d: FlowData, key: str) -> tuple[float, float]:
    """The wall gradient of profile ``key`` (bins 1-2 and 24-25, per d): the change per d
    going from each wall into the flow of the quantity as its wall value reads it
    (:meth:`FlowData.wall_value`: ω_z with the lower wall's sign flipped, so that rolling
    along either wall is positive), the mean of the two walls."""
    v, e = d.series(key)
    value, err = wall_gradient(v, e, d.y)  # symmetric profiles: inward from both walls
    if key == "omz":  # antisymmetric, read with the lower wall's sign flipped
        dy = float(d.y[1] - d.y[0])
        value = 0.5 * (-(v[1] - v[0]) + (v[-2] - v[-1])) / dy
    return float(value), err


def wall_value_checks(data: Runs) -> list[Check]:
    """Figs 3.10 and 3.11 (φ = 0.01): the wall values (Malik's mean of bins 1 and 25) and the
    wall gradients against e, one curve per β: figures only in the thesis (digest §4.5);
    the rows give the values at the smallest and largest e of each β."""
    ds = [d for (p, _b, _e), d in sorted(data.items()) if p == 0.01]
    rows = [("Fig 3.10 [L722]", "φ = 0.01: translational and rotational slip, T and θ at the "
             "walls against e, one curve per β", FlowData.wall_value),
            ("Fig 3.11 [L732] (digest item 8)", "φ = 0.01: wall gradients of U_x, ω_z, T, θ "
             "against e, one curve per β", wall_slope)]
    out = []
    for ref, statement, value in rows:
        if not ds:
            out.append(not_run(ref, statement, "figures only", "the φ = 0.01 runs"))
            continue
        parts = []
        for beta in sorted({d.flow.beta for d in ds}):
            by_e = sorted((d for d in ds if d.flow.beta == beta), key=lambda d: d.flow.e)
            ends = [by_e[0], by_e[-1]] if len(by_e) > 1 else by_e
            slope = value is wall_slope
            cells = [f"{f'd{name}/dy' if slope else name} "
                     + " → ".join(pm(*value(d, key)) for d in ends) for key, name in WALL_KEYS]
            span = " → ".join(f"{d.flow.e:g}" for d in ends)
            parts.append(f"β = {beta:g}, e = {span}: " + ", ".join(cells))
        out.append(Check(ref, statement, "figures only (no values in the text)",
                         "; ".join(parts) + " (ω_z at the walls: positive when the spheres "
                         "roll along them; gradients: the change per d from the wall into the "
                         "flow of that wall value)",
                         NO_THESIS_VALUE,
                         _with_steady_note(
                         "the thesis plots these against e without stating values; its text's "
                         "one claim about the walls (much wall dissipation for β = 0) has its "
                         "own row.", ds), runs=tuple(d.flow.name for d in ds)))
    return out


# ------------------------------------------------------------------ velocity correlations
#: the far range of C_aa(r): its mean over 4 d ≤ r < 5 d (the largest shells measured) is the
#: share of the bin's fluctuation about its run mean that moves together across the bin
FAR = (4.0, 5.0)


def correlation_at(vc: dict[str, np.ndarray], b: int, a: int, lo: float,
                   hi: float | None = None) -> tuple[float, float]:
    """C_aa of bin ``b`` (0-based), component ``a``, at the shell starting at ``lo`` (or the
    mean over lo ≤ r < hi, errors combined as independent: a yardstick)."""
    edges = vc["r_edges"]
    if hi is None:
        k = int(np.searchsorted(edges, lo - 1e-9))
        return float(vc["C"][b, a, k]), float(vc["C_err"][b, a, k])
    centres = 0.5 * (edges[1:] + edges[:-1])
    sel = (centres >= lo) & (centres < hi)
    v, e = vc["C"][b, a, sel], vc["C_err"][b, a, sel]
    return _mean(v, e)


def _correlation_text(d: FlowData, bins: Sequence[int]) -> str:
    vc, parts = d.stat("vcorr"), []
    for k in bins:
        near = "/".join(pm(*correlation_at(vc, k - 1, a, 1.0), 1) for a in range(3))
        far = "/".join(pm(*correlation_at(vc, k - 1, a, *FAR), 1) for a in range(3))
        parts.append(f"bin {k}: C_xx/C_yy/C_zz at r = 1 d {near}, at {FAR[0]:g}-{FAR[1]:g} d "
                     f"{far}")
    return f"{_tag(d)}: " + "; ".join(parts)


COMMON_MOTION = (
    "No value in the thesis's text (figures only). C_aa(r) about the bin's run mean (the "
    "formula's ⟨c⟩, digest §4.1, §4.9) does not decay where it stays near its r = 1 d value "
    "out to 5 d: that share of the bin's ⟨C_a²⟩ is motion common to the whole bin, the "
    "dense centre moving as a block whose speed varies over the run (a plug or wave, or a "
    "drift), not thermal motion; the bin's T, VDF and Λ, taken about the same run mean, "
    "include it (about the instantaneous bin mean T_aa would be about (1 − far value) of "
    "it)")


#: a centre bin whose far C_xx reaches this moves mostly as a block
BLOCK = 0.5


def _far_xx(d: FlowData) -> float | None:
    """Bin 13's C_xx over the far range ``FAR`` (None without velocity correlations)."""
    vc = d.stat("vcorr")
    return correlation_at(vc, CENTRE_BIN - 1, 0, *FAR)[0] if "C" in vc else None


def _common_motion(ds: Sequence[FlowData]) -> str:
    """COMMON_MOTION and, in the centre bin, which runs are dominated by common motion (far
    C_xx ≥ BLOCK) and which are uncorrelated as a molecular gas (|C_aa| < 0.05 at every r)."""
    block, free = [], []
    for d in ds:
        far = _far_xx(d)
        if far is None:
            continue
        if far >= BLOCK:
            block.append(f"{_tag(d)} ({far:.2f})")
        elif np.nanmax(np.abs(d.stat("vcorr")["C"][CENTRE_BIN - 1])) < 0.05:
            free.append(_tag(d))
    text = COMMON_MOTION
    if block:
        text += f". Bin 13's far C_xx ≥ {BLOCK:g} (mostly common motion): {', '.join(block)}"
    if free:
        text += f". Uncorrelated (|C_aa| < 0.05 at every r) in bin 13: {', '.join(free)}"
    return text


def common_motion_caveats(checks: list[Check], data: Runs) -> None:
    """The VDF, Λ and Gaussian-limit rows of φ = 0.1 and 0.5 name the runs whose centre bin
    moves as a block (far C_xx ≥ BLOCK, rows 'Fig 4.14' and 'Fig 4.19'): their fluctuations
    about the bin's run mean include that motion, which a temperature, a VDF's width and
    Λ count as thermal."""
    for phi in (0.1, 0.5):
        block = [_tag(d) for (p, _b, _e), d in sorted(data.items())
                 if p == phi and (_far_xx(d) or 0.0) >= BLOCK]
        if not block:
            continue
        note = (f" In bin 13 of {', '.join(block)} the fluctuations about the bin's run mean "
                f"are mostly motion common to the whole bin (far C_xx ≥ {BLOCK:g}: the "
                "velocity-correlation rows), which the VDFs and Λ count as thermal.")
        pattern = re.compile(rf"^φ = {re.escape(f'{phi:g}')}[:,]")
        for c in checks:
            if (c.verdict != NOT_RUN and pattern.match(c.statement)
                    and any(k in c.statement for k in ("VDF", "Λ", "Gaussian"))):
                c.reason = (c.reason + note).strip()


def vcorr_checks(data: Runs) -> list[Check]:
    """Figs 4.12-4.14 and 4.19: the spatial velocity correlations C_aa(r) (digest §4.9) that
    the thesis plots without stating values: measured near contact and at the far range,
    with what a far value that does not decay means."""
    by_phi = {phi: [d for (p, _b, _e), d in sorted(data.items()) if p == phi]
              for phi in (0.1, 0.5)}
    rows = [  # ref, statement, thesis, runs, bins, what a missing run is called
        ("Figs 4.12-4.13 [L978], [L988]",
         "φ = 0.1, β = ∓0.99, e = 0.7, bins 1, 4, 13: velocity correlations C_xx, C_yy, C_zz "
         "against r", "figures only (no values in the text)",
         [data[k] for k in ((0.1, -0.99, 0.7), (0.1, 0.99, 0.7)) if k in data], (1, 4, 13),
         "the φ = 0.1, e = 0.7 runs"),
        ("Fig 4.14 [L992]", "φ = 0.1, bin 13, several e: C_xx, C_yy, C_zz for each β",
         "figures only (no values in the text)", by_phi[0.1], (CENTRE_BIN,), "the φ = 0.1 runs"),
        ("Fig 4.19 [L1036], [L1048]",
         "φ = 0.5, bins 1, 3, 13: C_xx, C_yy, C_zz against r (compared with Orpe & Kudrolli's "
         "experiments in the thesis)",
         "figures only; Orpe & Kudrolli's values not in the digest", by_phi[0.5], (1, 3, 13),
         "the φ = 0.5 run")]
    out = []
    for ref, statement, thesis, ds, bins, needs in rows:
        if not ds:
            out.append(not_run(ref, statement, "figures only", needs))
            continue
        out.append(Check(ref, statement, thesis,
                         "; ".join(_correlation_text(d, bins) for d in ds), NO_THESIS_VALUE,
                         _with_steady_note(_common_motion(ds) + ".", ds),
                         runs=tuple(d.flow.name for d in ds)))
    return out


# ------------------------------------------------------------------ numbers for the report
def numbers_text(data: Runs) -> str:
    """Velocity correlations, Λ and VDF moments in bin 13, per run (markdown table)."""
    if not data:
        return "No runs."
    lines = ["Bin 13 (the centre). C_aa at the first shell beyond contact (r ∈ [1.0, 1.1)) "
             "and at r ∈ [3.0, 3.1) (normalised by the self term; 0 for independent "
             "velocities); kurtosis of C_x (3 for a Gaussian).", "",
             "| run | C_xx(1) | C_yy(1) | C_zz(1) | C_xx(3) | kurtosis C_x | Λ̄ |",
             "|---|---|---|---|---|---|---|"]
    for key in sorted(data):
        d = data[key]
        vc, cells = d.stat("vcorr"), []
        if "C" in vc:
            b = CENTRE_BIN - 1
            cells = [pm(*correlation_at(vc, b, a, 1.0), 1) for a in range(3)]
            cells.append(pm(*correlation_at(vc, b, 0, 3.0), 1))
        else:
            cells = ["n/a"] * 4
        kur = d.stat("vdf")
        ku = pm(kur["kurtosis"][CENTRE_BIN - 1, 0], kur["kurtosis_err"][CENTRE_BIN - 1, 0]) \
            if "kurtosis" in kur else "n/a"
        lam = pm(*lambda_mean(d)) if "lambda" in d.stat("lambda") else "n/a"
        lines.append(f"| {d.flow.name} | " + " | ".join(cells) + f" | {ku} | {lam} |")
    return "\n".join(lines)
