"""Campbell (1982) chutes: one check per statement of the thesis (digest §1.4 C1-C8, §3.9, §4,
§6 H10-H13), each with demstudy's measured value ± error, the verdict and its reason.

Dimensionless particle units: d = 1, m = 1, g = 1 (u in √(gd), energies m g d, 2D stresses
m g/d). A check whose runs are missing says "not run".
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence

import numpy as np

from ..base import (
    NOT_REPRODUCED,
    NOT_RUN,
    PARTLY,
    REPRODUCED,
    TWIN_TOLERANCE,
    Check,
    not_run,
    pm,
    within,
)
from .chute_measure import ChuteRun, basal_layer, centre_plug
from .collision_log import logged_fraction

NU_SQUARE = math.pi / 4
#: ν_m: the densest shearable packing, layers following contours (L1093)
NU_SHEARABLE = math.pi / (math.sqrt(3) + 2 * math.pi / 3)
#: "little effect", "insignificant changes": a difference within 2σ + 10 % (of the reference)
#: how far two runs of the 40-disc flow may differ and count as the same flow (2σ + 10 %,
#: the C6, width and t_c rows), the same as the studies' TC-twin tolerance
SAME = TWIN_TOLERANCE
#: wall slip: Campbell's initial-profile fit gives F(0) = 0.20; its own precision (a fit to a
#: profile the thesis does not show) taken as ±0.05
SLIP_THESIS, SLIP_TOL = 0.20, 0.05
BUMPY_NOTE = ("bumpy base (random bumps of diameter d, spacing 1.2 d): Campbell's flat "
              "sticking base has no steady dense flow above ≈ 25° (row 'flat base')")


def needs(*names: str, own: bool = False):
    """Decorator: the check gets the ChuteRuns named; NOT_RUN when one is missing (``own``:
    demstudy's own check, as the check's own row is)."""
    def wrap(fn: Callable[..., Check]):
        def check(runs: Mapping[str, ChuteRun]) -> Check:
            if any(n not in runs for n in names):
                ref, statement, thesis = fn.__doc__.split(" | ")[:3]
                return not_run(ref.strip(), statement.strip(), thesis.strip(),
                               [n for n in names if n not in runs], own)
            return fn(*(runs[n] for n in names))
        check.__doc__ = fn.__doc__
        return check
    return wrap


def convergence(r: ChuteRun) -> str:
    """The convergence numbers of one run, in words."""
    return (f"trend {pm(r.trend, r.trend_err)}, {100 * r.within:.0f} % of samples within ±20 %, "
            f"KE/N {pm(r.energy_mean, r.energy_err)}, base ratio {pm(r.ratio, r.ratio_err)} "
            f"(tan α {r.tan_alpha:.3f})")


def steady_verdict(r: ChuteRun) -> str:
    if r.steady:
        return REPRODUCED
    return PARTLY if (r.converged or r.balanced) else NOT_REPRODUCED


def why_not_steady(r: ChuteRun) -> str:
    if r.steady:
        return ""
    parts = []
    if not r.converged:
        parts.append(f"The energy drifts (trend {pm(r.trend, r.trend_err)}: |trend| ≥ 0.2 "
                     "beyond 2σ)")
    if not r.balanced:
        parts.append(f"The base ratio {pm(r.ratio, r.ratio_err)} ≠ tan α = {r.tan_alpha:.3f}: "
                     "the bed " + ("accelerates" if r.ratio < r.tan_alpha else "decelerates"))
    return ". ".join(parts)


@needs("chute-30-bumpy")
def c1_converged(r: ChuteRun) -> Check:
    """C1; Fig 2.4; §2.5 L574-586, L186 | the 30° chute (10 × 4, ε_p 0.6, ε_w 0.8) converges: \
the kinetic energy fluctuates within about 20 % of its mean with no trend | converged \
(Fig 3.1 'typical')"""
    ref, statement, thesis = c1_converged.__doc__.split(" | ")
    reason = (BUMPY_NOTE + ". " + why_not_steady(r)).strip(". ")
    if r.steady:
        reason += (f". The ±20 % band holds {100 * r.within:.0f} % of the samples: 40 discs "
                   "fluctuate more than that even when steady (no trend, ratio = tan α)")
    return Check(ref, statement, thesis, f"bumpy base: {convergence(r)}", steady_verdict(r),
                 reason)


def c1_flat(runs: Mapping[str, ChuteRun]) -> Check:
    ref = "C1 on Campbell's base; digest §1.2 (WALLCL F.1), H10"
    statement = "the 30° chute converges on Campbell's flat base with sticking contacts"
    thesis = "converged"
    names = [f"chute-{a}-flat" for a in (24, 26, 30)]
    if "chute-30-flat" not in runs:
        return not_run(ref, statement, thesis, ["chute-30-flat"])
    flat = [runs[n] for n in names if n in runs]
    text = "; ".join(f"{r.angle:g}°: dense phase (t = 25-200) ratio "
                     f"{pm(r.ratio_dense, r.ratio_dense_err)} vs tan α {r.tan_alpha:.3f}, "
                     f"production ratio {pm(r.ratio, r.ratio_err)}, trend {r.trend:+.2f}, "
                     f"KE/N {pm(r.energy_mean, r.energy_err)}" for r in flat)
    r30 = runs["chute-30-flat"]
    dense_ok = within(r30.ratio_dense, r30.ratio_dense_err, r30.tan_alpha, 2, 0.01)
    if dense_ok and r30.steady:
        return Check(ref, statement, thesis, text, REPRODUCED, "flat base")
    return Check(ref, statement, thesis, text, NOT_REPRODUCED,
                 "on a flat sticking base the basal discs roll; a dense bed passes at most ≈ 0.5 "
                 "of its weight as shear (dense-phase ratio below tan 30°), so it accelerates "
                 "until a dilute hot basal layer carries it (the production window: fast, "
                 "levitated). Steady dense flow exists only up to ≈ 25° "
                 "(docs/studies/campbell1982-chute30.md). Campbell's run was plausibly an early "
                 "transient that passes his energy criterion. Hence the bumpy base elsewhere")


def c1_slip(runs: Mapping[str, ChuteRun]) -> Check:
    check = _c1_slip(runs)
    others = [runs[n] for n in SEED_RUNS[1:] if n in runs]
    if others and check.verdict != NOT_RUN:
        check.reason += ("; other seeds: " + ", ".join(f"{pm(r.slip, r.slip_err)}"
                                                      for r in others))
        if not all(within(r.slip, r.slip_err, fit_at_first_strip(r), 2, SLIP_TOL)
                   for r in others):
            check.verdict = PARTLY
            check.reason += " (outside the tolerance: the slip depends on the bump heights)"
    return check


def fit_at_first_strip(r: ChuteRun) -> float:
    """Campbell's profile fit F(y/H) at the first strip's centre height (y ≈ d/2): the
    measured slip is that strip's u/u_max, F(0) = 0.20 is at the base plane, where no disc
    centre can be."""
    from ...scene.initial import CAMPBELL_CHUTE_FIT

    return float(np.polynomial.polynomial.polyval(0.5 / r.depth, CAMPBELL_CHUTE_FIT))


@needs("chute-30-bumpy")
def _c1_slip(r: ChuteRun) -> Check:
    """C1; §1.2 COL007 (L4800-4828), L625 | wall slip: the thesis's velocity-profile fit F(y/H) \
has u(0)/u_max = 0.20 | 0.20"""
    ref, statement, thesis = _c1_slip.__doc__.split(" | ")
    at_centres = fit_at_first_strip(r)
    ok = within(r.slip, r.slip_err, at_centres, 2, SLIP_TOL)
    return Check(ref, statement, thesis,
                 f"bumpy base: u(0 < y < 1)/u_max = {pm(r.slip, r.slip_err)} "
                 f"(u_max {pm(r.u_max, r.u_max_err)} √(gd)); the fit at the strip's centre "
                 f"height F(0.5/H = {0.5 / r.depth:.3f}) = {at_centres:.2f} (F(0) = "
                 f"{SLIP_THESIS:.2f} at the base plane)",
                 REPRODUCED if ok else NOT_REPRODUCED,
                 f"bumpy base; compared at the same height, tolerance ±{SLIP_TOL} + 2σ (a fit "
                 "to a profile the thesis does not show)" + ("" if ok else
                                                             ": the measured slip is outside "
                                                             "it; a flat base slips more "
                                                             "(37-55 %), the bumps' geometry "
                                                             "sets the slip"))


#: the velocity-profile fit: tolerance of a polynomial fitted to a profile the thesis does not
#: show (which run it came from is not stated)
FIT_TOL = 0.1


@needs("chute-30-bumpy")
def c1_profile(r: ChuteRun) -> Check:
    """C1; §1.2 COL007 (L4800-4828), Fig 3.1 | the velocity profile: Campbell's initial state is \
'a least squares fit to a velocity profile', F(y/H) (20 % slip, F(0.5) = 0.78) | F(y/H)"""
    from ...scene.initial import CAMPBELL_CHUTE_FIT

    ref, statement, thesis = c1_profile.__doc__.split(" | ")
    p = r.profiles
    bed = (np.nan_to_num(p["nu"]) >= 0.3) & (p["y"] / r.depth <= 1.0)
    z = p["y"][bed] / r.depth
    dev = p["u"][bed] / r.u_max - np.polyval(CAMPBELL_CHUTE_FIT[::-1], z)
    err = p["u_err"][bed] / r.u_max
    ok = bool(np.all(np.abs(dev) <= 2 * err + FIT_TOL))
    return Check(ref, statement, thesis,
                 f"bumpy base, strips with ν ≥ 0.3: u/u_max − F(y/H) from {dev.min():+.3f} to "
                 f"{dev.max():+.3f} (rms {np.sqrt(np.mean(dev ** 2)):.3f}; 1σ of u/u_max ≤ "
                 f"{err.max():.3f})", REPRODUCED if ok else PARTLY,
                 f"bumpy base; tolerance ±{FIT_TOL} + 2σ (the fitted run is not named)"
                 + ("" if ok else ": some strips lie outside"))


@needs("chute-30-bumpy", own=True)
def c1_stresses(r: ChuteRun) -> Check:
    """§4 stresses (L1195-1213, L2852-2856) | the momentum-balance stresses (integrated from \
the free surface, with the unsteady term), the wall stress and the kinetic + collisional \
stress agree at the base | (method)"""
    ref, statement, thesis = c1_stresses.__doc__.split(" | ")
    s = r.stress
    if not s:
        return Check(ref, statement, thesis, "no stress group", NOT_RUN, "run without 'stress'",
                     own=True)
    base_ok = all(within(s[f"wall_{c}"], math.hypot(s[f"wall_{c}_err"],
                                                     s[f"base_balance_{c}_err"]),
                         s[f"base_balance_{c}"], 2, 0.01 * abs(s["wall_tau_yy"]))
                  for c in ("tau_xy", "tau_yy"))
    # the stress statistic against the balance in the bed's strips above the base's strip
    bed = (np.nan_to_num(r.profiles["nu"]) >= 0.3) & (np.arange(r.profiles["y"].size) >= 1)
    tol = 0.05 * abs(s["wall_tau_yy"])
    agree, total = 0, 0
    for c in ("tau_xy", "tau_yy"):
        d = np.abs(s[f"stat_{c}"] - s[f"balance_{c}"])[bed]
        e = np.hypot(s[f"stat_{c}_err"], s[f"balance_{c}_err"])[bed]
        agree += int(np.sum(d <= 2 * e + tol))
        total += int(d.size)
    k0 = 0
    measured = (f"at y = 0: wall τ_yy {pm(s['wall_tau_yy'], s['wall_tau_yy_err'])}, "
                f"τ_xy {pm(s['wall_tau_xy'], s['wall_tau_xy_err'])}; balance "
                f"{pm(s['base_balance_tau_yy'], s['base_balance_tau_yy_err'])}, "
                f"{pm(s['base_balance_tau_xy'], s['base_balance_tau_xy_err'])}; "
                f"{s['stat_parts']} in the base strip 0 < y < 1: τ_yy "
                f"{pm(s['stat_tau_yy'][k0], s['stat_tau_yy_err'][k0])}; in the bed above it "
                f"(ν ≥ 0.3) {agree} of {total} strip values agree with the balance "
                f"(2σ + 5 % of the base τ_yy)")
    verdict = REPRODUCED if base_ok and agree == total else PARTLY if base_ok else NOT_REPRODUCED
    reason = ("bumpy base. Wall and balance agree at the base (momentum conservation); the "
              "collisional stress of the base strip misses the discs' impulses on the bumps "
              "(booked as wall collisions, not pair collisions), so it is compared above "
              "that strip")
    if agree < total:
        reason += f"; {total - agree} strip values differ beyond 2σ + 5 %"
    if not base_ok:
        reason += "; the wall stress differs from the balance at the base"
    # the three routes agreeing is demstudy's method check (Campbell's §4 computes them)
    return Check(ref, statement, thesis, measured, verdict, reason, own=True)


def c2_plug(runs: Mapping[str, ChuteRun]) -> Check:
    ref, statement = "C2; Fig 3.14, L1107, L203, H12", "at 20° a central plug forms with ν > π/4"
    thesis = "ν > π/4 = 0.785 in the centre"
    if "chute-20-flat" not in runs:
        return not_run(ref, statement, thesis, ["chute-20-flat"])
    parts, plug = [], []
    for name in ("chute-20-flat", "chute-20-bumpy"):
        if name in runs:
            r = runs[name]
            nu, err = centre_plug(r)
            parts.append(f"{r.base} base: ν max at 0.25 < y/H < 0.75 = {pm(nu, err)}")
            plug.append((nu, err))
    nu, err = plug[0]
    if nu - 2 * err > NU_SQUARE:
        verdict, reason = REPRODUCED, "Campbell's flat base: ν > π/4 beyond 2σ"
        if stopped(runs["chute-20-flat"]):
            ordered = ", denser than ν_m = 0.821 (the densest shearable)" if nu > 0.821 else ""
            verdict = PARTLY
            reason += (", but in a bed that comes to rest (next row): the dense centre is the "
                       f"resting packing{ordered}, not a plug riding on a shearing flow")
    elif nu > NU_SQUARE:
        verdict, reason = PARTLY, "Campbell's flat base: ν > π/4, but by less than 2σ"
    else:
        verdict, reason = NOT_REPRODUCED, "Campbell's flat base: the centre stays below π/4"
    if len(plug) > 1:
        reason += f"; the bumps: {'above' if plug[1][0] > NU_SQUARE else 'below'} π/4"
    return Check(ref, statement, thesis, "; ".join(parts), verdict, reason)


def c2_converged(runs: Mapping[str, ChuteRun]) -> Check:
    ref = "C2; L1107, L203"
    statement = "the 20° chute converges to a steady flow around the plug"
    thesis = "converged"
    if "chute-20-flat" not in runs:
        return not_run(ref, statement, thesis, ["chute-20-flat"])
    parts = []
    for name in ("chute-20-flat", "chute-20-bumpy"):
        if name in runs:
            r = runs[name]
            end = float(np.mean(r.energy[-max(1, r.energy.size // 20):]))
            parts.append(f"{r.base} base: {convergence(r)}, KE/N at the end {end:.3g}, "
                         f"TC share {100 * r.tc_share:.0f} %")
    r = runs["chute-20-flat"]
    if stopped(r):
        return Check(ref, statement, thesis, "; ".join(parts), NOT_REPRODUCED,
                     f"flat base: the bed decelerates and comes to rest by t ≈ {rest_time(r):.0f} "
                     "√(d/g) (energy < 1 % of the initial for good; on the bumps sooner): "
                     "steady only as a static packing (base ratio = tan α by static friction), "
                     "not a flow. A resting hard-disc bed is held by the TC model's elastic "
                     "micro-bounces (share → 100 %). Campbell's 'converged' 20° run was "
                     "plausibly a slow deceleration judged by its energy history")
    if r.steady:
        return Check(ref, statement, thesis, "; ".join(parts), REPRODUCED, "flat base")
    return Check(ref, statement, thesis, "; ".join(parts), steady_verdict(r),
                 "flat base. " + why_not_steady(r))


def stopped(r: ChuteRun) -> bool:
    """The bed came to rest: the last 5 % of the samples hold < 1 % of the initial energy."""
    end = float(np.mean(r.energy[-max(1, r.energy.size // 20):]))
    return end < 0.01 * float(r.energy[0])


def rest_time(r: ChuteRun) -> float:
    """The time after which the energy stays below 1 % of the initial (NaN: never)."""
    above = np.flatnonzero(r.energy >= 0.01 * float(r.energy[0]))
    if above.size == 0:
        return float(r.t[0])
    return float(r.t[above[-1] + 1]) if above[-1] + 1 < r.t.size else float("nan")


def c3_accelerates(runs: Mapping[str, ChuteRun]) -> Check:
    ref, statement = "C3; L1051, H10", "the 40° chute (10 × 4) does not converge: it accelerates"
    thesis = "non-converged, accelerating"
    if "chute-40-flat" not in runs:
        return not_run(ref, statement, thesis, ["chute-40-flat"])
    rs = [runs[n] for n in ("chute-40-flat", "chute-40-bumpy") if n in runs]
    text = "; ".join(f"{r.base} base: {convergence(r)}" for r in rs)
    accel = [r.trend > 0.2 and not r.balanced for r in rs]
    verdict = REPRODUCED if all(accel) else PARTLY if accel[0] else NOT_REPRODUCED
    return Check(ref, statement, thesis, text, verdict,
                 "Campbell's flat base" + (" and the bumps" if len(rs) > 1 else "")
                 + ": the energy grows and the base passes less than tan 40° of the weight"
                 if verdict == REPRODUCED else "; ".join(why_not_steady(r) or "steady"
                                                          for r in rs))


def c3_basal_layer(runs: Mapping[str, ChuteRun]) -> Check:
    ref = "C3; L1051, H10"
    statement = "the accelerating 40° bed rides on a low-density basal (lubricating) layer"
    thesis = "low-density basal layer"
    if "chute-40-flat" not in runs:
        return not_run(ref, statement, thesis, ["chute-40-flat"])
    parts, ok, met = [], [], []
    for name in ("chute-40-flat", "chute-40-bumpy", "chute-30-bumpy"):
        if name in runs:
            r = runs[name]
            nu, err, top = basal_layer(r)
            parts.append(f"{name}: ν(1 < y < 2) {pm(nu, err)}, bed's ν max {top:.2f}")
            if name.startswith("chute-40"):
                ok.append(nu + 2 * err < 0.5 * top)
                met.append(f"{r.base} base {'met' if ok[-1] else 'not met beyond 2σ'} "
                           f"({nu:.2f} vs {0.5 * top:.2f})")
    verdict = REPRODUCED if all(ok) else PARTLY if any(ok) else NOT_REPRODUCED
    return Check(ref, statement, thesis, "; ".join(parts), verdict,
                 "criterion: the strip 1 < y < 2 below half the bed's densest, by 2σ (the "
                 "steady 30° bumpy bed for contrast): " + ", ".join(met))


def c9_angles(runs: Mapping[str, ChuteRun]) -> Check:
    """C9: the 40° chute's collision-angle distribution (Fig 3.33), read as the Couette cells'
    (Fig 3.32): anisotropic, the approach quadrant preferred. The digest gives no values."""
    ref = "C9; Fig 3.33, L224"
    statement = ("the 40° chute (10 × 4, ε_p 0.6, ε_w 0.8): the collision angles prefer the "
                 "approach quadrant (θ from the flow direction in 90°-180°: du/dy > 0 across "
                 "the bed), as in the Couette cells")
    thesis = "anisotropic, approach quadrant preferred (figure; no values in the digest)"
    names = ("chute-40-flat", "chute-40-bumpy", "chute-30-bumpy")
    have = [n for n in names if n in runs and runs[n].angles]
    if not any(n.startswith("chute-40") for n in have):
        return not_run(ref, statement, thesis, "chute-40-flat with its collision log")
    parts, ok = [], []
    for name in have:
        a = runs[name].angles
        share, err = a["approach"]
        t0, t1, start, end = a["window"]
        first, second = a["halves"]
        parts.append(f"{name}: share in 90°-180° {pm(share, err)} ({a['collisions']:.3g} "
                     f"pair collisions logged over t = {t0:.0f}-{t1:.0f} of the production "
                     f"{start:.0f}-{end:.0f} √(d/g); halves of that window {first:.3f}, "
                     f"{second:.3f})")
        if name.startswith("chute-40"):
            ok.append(share - 0.5 > 2 * err)
    verdict = REPRODUCED if all(ok) else PARTLY if any(ok) else NOT_REPRODUCED
    short = [n for n in have if logged_fraction(runs[n].angles["window"]) < 0.99]
    reason = ("criterion: share − ½ beyond 2σ (isotropic collisions give ½); the 40° beds "
              "accelerate (row C3), so this is the distribution of a transient, as the "
              "thesis's own 40° bed was; the steady 30° bumpy bed beside it"
              + ("" if not short else "; the log of " + ", ".join(short) + " covers only the "
                 "start of the production (the engine keeps its first 2·10⁵ collisions, the "
                 "base's included)"))
    return Check(ref, statement, thesis, "; ".join(parts), verdict, reason)


def _series_steady(runs: Mapping[str, ChuteRun], names: Sequence[str], ref: str,
                   statement: str, thesis: str, base: str) -> Check:
    present = [runs[n] for n in names if n in runs]
    if len(present) < len(names):
        return not_run(ref, statement, thesis, [n for n in names if n not in runs])
    text = "; ".join(f"{r.rows}×{r.columns}, {r.angle:g}°: {convergence(r)}" for r in present)
    steady = [r.steady for r in present]
    verdict = REPRODUCED if all(steady) else PARTLY if any(steady) else NOT_REPRODUCED
    reasons = [f"{r.name}: {why_not_steady(r)}" for r in present if not r.steady]
    loud = [r for r in present if r.steady and r.within < 0.5]
    if loud and verdict == REPRODUCED:
        verdict = PARTLY
    reasons += [f"{r.name}: no trend beyond 2σ and ratio = tan α, but only "
                f"{100 * r.within:.0f} % of the samples inside ±20 % (the energy wanders "
                "by a factor of several)" for r in loud]
    return Check(ref, statement, thesis, text, verdict, "; ".join([base, *reasons]))


def c4_depths(runs: Mapping[str, ChuteRun]) -> Check:
    return _series_steady(
        runs, [f"chute-30-bumpy-{n}x4-var" for n in (5, 10, 13)], "C4; L1059-1077, L197",
        "with the variable restitution ε = ½[1 + exp(−3δv/√(gR))] the 5×4, 10×4 and 13×4 beds "
        "at 30° converge", "converged",
        BUMPY_NOTE + "; the law on pair collisions only (demstudy's contact.law; the thesis "
        "applied it to the wall too, ε_w = 0.8 here)")


def _unsteady(runs: Mapping[str, ChuteRun], name: str, ref: str, statement: str, thesis: str,
              base: str) -> Check:
    if name not in runs:
        return not_run(ref, statement, thesis, [name])
    r = runs[name]
    verdict = REPRODUCED if not r.steady else NOT_REPRODUCED
    reason = base + (". " + why_not_steady(r) if not r.steady else
                     ": on the bumpy base this bed is steady (no trend, ratio = tan α)")
    return Check(ref, statement, thesis, convergence(r), verdict, reason)


def c4_shallow_constant(runs: Mapping[str, ChuteRun]) -> Check:
    check = _unsteady(runs, "chute-30-bumpy-5x4", "C4; L1073-1077, H10",
                      "the 5 × 4 bed at 30° with constant ε accelerates (too few collisions)",
                      "accelerated", "bumpy base, ε_p 0.6 (10 × 4 converges there)")
    if check.verdict == NOT_REPRODUCED:
        check.reason += ("; on Campbell's flat base every 30° bed accelerates (row 'flat "
                         "base'), 10 × 4 too: his observation fits the base, not the depth")
    return check


def c5_ep08(runs: Mapping[str, ChuteRun]) -> Check:
    return _unsteady(runs, "chute-30-bumpy-ep0.8", "C5; L1083-1085, H10",
                     "ε_p = 0.8 at 30° (10 × 4) never properly converged",
                     "never properly converged", "bumpy base (ε_p 0.6 converges there)")


@needs("chute-30-bumpy-ep0.1")
def c5_ep01(r: ChuteRun) -> Check:
    """C5; Fig 3.11, L1081-1087 | ε_p = 0.1 at 30° (10 × 4) gives a converged flow (the ε_p \
series of Fig 3.11) | converged"""
    ref, statement, thesis = c5_ep01.__doc__.split(" | ")
    return Check(ref, statement, thesis, convergence(r), steady_verdict(r),
                 (BUMPY_NOTE + ". " + why_not_steady(r)).strip(". "))


#: the reference 30° bumpy chute and its other seeds (initial state and bump heights)
SEED_RUNS = ("chute-30-bumpy", "chute-30-bumpy-seed2", "chute-30-bumpy-seed3")
COMPARED = (("u_max", "u_max", "u_max_err"), ("KE/N", "energy_mean", "energy_err"),
            ("H", "depth", None))


def seed_spread(runs: Mapping[str, ChuteRun]) -> dict[str, float]:
    """Standard deviation of u_max, KE/N and H over the seeds of the 30° bumpy chute (0 with
    fewer than two seeds): how much two realisations of the same 40-disc flow differ."""
    present = [runs[n] for n in SEED_RUNS if n in runs]
    if len(present) < 2:
        return {key: 0.0 for _, key, _ in COMPARED}
    return {key: float(np.std([getattr(r, key) for r in present], ddof=1))
            for _, key, _ in COMPARED}


def _same(a: ChuteRun, b: ChuteRun, spread: Mapping[str, float]) -> tuple[int, str]:
    """How closely b matches a in u_max, KE/N and H, and the text: 2 = every difference within
    2σ of the two runs' block errors + 10 %; 1 = within that only with σ raised to √2 × the
    seed-to-seed spread (another realisation of the same flow differs that much); 0 = not."""
    out, level = [], 2
    for what, key, err_key in COMPARED:
        x, y = getattr(a, key), getattr(b, key)
        xe = getattr(a, err_key) if err_key else 0.0
        ye = getattr(b, err_key) if err_key else 0.0
        block = math.hypot(xe, ye)
        seeds = max(block, math.sqrt(2) * spread.get(key, 0.0))
        if not within(y, block, x, 2, SAME * abs(x)):
            level = min(level, 1 if within(y, seeds, x, 2, SAME * abs(x)) else 0)
        out.append(f"{what} {pm(y, ye)} ({100 * (y - x) / x:+.0f} %)")
    return level, ", ".join(out)


VERDICT_OF_LEVEL = {2: REPRODUCED, 1: PARTLY, 0: NOT_REPRODUCED}
LEVEL_TEXT = {2: "within 2σ + 10 %",
              1: "beyond the block errors and 10 %, within the seed-to-seed spread only (the "
                 "40-disc flow on 4 random bumps has realisations differing by ×2 in u_max)",
              0: "beyond the seed-to-seed spread"}


def _spread_text(spread: Mapping[str, float]) -> str:
    if not any(spread.values()):
        return "no seed spread (seed runs missing)"
    return ("seed spread (sd of 3 seeds): " + ", ".join(
        f"{what} {spread[key]:.2g}" for what, key, _ in COMPARED))


def _little_effect(runs: Mapping[str, ChuteRun], ref: str, statement: str, thesis: str,
                   names: Sequence[str], base: str) -> Check:
    if "chute-30-bumpy" not in runs or any(n not in runs for n in names):
        return not_run(ref, statement, thesis,
                       [n for n in ("chute-30-bumpy", *names) if n not in runs])
    a, spread = runs["chute-30-bumpy"], seed_spread(runs)
    texts, oks = [f"reference {a.label}: u_max {pm(a.u_max, a.u_max_err)}, KE/N "
                  f"{pm(a.energy_mean, a.energy_err)}, H {a.depth:.2f}"], []
    for n in names:
        level, text = _same(a, runs[n], spread)
        oks.append(level)
        texts.append(f"{runs[n].label}: {text}" + ("" if runs[n].steady else " (unsteady)"))
    level = min(oks)
    return Check(ref, statement, thesis, "; ".join(texts), VERDICT_OF_LEVEL[level],
                 base + f"; 'little' = within 2σ or {100 * SAME:.0f} % in u_max, KE/N and H: "
                 + LEVEL_TEXT[level] + "; " + _spread_text(spread))


def c6_wall_restitution(runs: Mapping[str, ChuteRun]) -> Check:
    return _little_effect(runs, "C6; Fig 3.12, L1087",
                          "varying ε_w (ε_p 0.6, 30°, 10 × 4) has little effect",
                          "little effect", ["chute-30-bumpy-ew0.6", "chute-30-bumpy-ew1"],
                          "bumpy base, ε_w on plane and bumps")


def width_doubling(runs: Mapping[str, ChuteRun]) -> Check:
    return _little_effect(runs, "L621-623", "doubling the width (10 × 8) gives insignificant "
                          "changes", "insignificant changes", ["chute-30-bumpy-10x8"],
                          "bumpy base, 30°")


def c7_c8(runs: Mapping[str, ChuteRun], name: str, ref: str, statement: str) -> Check:
    if name not in runs:
        return not_run(ref, statement, "converged profile", [name])
    r = runs[name]
    return Check(ref, statement, "converged profile (compared with experiments)",
                 convergence(r), steady_verdict(r),
                 ("bumpy base. " + why_not_steady(r)).strip(". ")
                 + ("" if r.steady else ". The bumps pass less than tan 40° of the weight; "
                                        "denser bumps (spacing 1.0 d, tried outside the "
                                        "study: 5 × 4 and 10 × 4, 400 √(d/g)) pass 0.64-0.66 "
                                        "and accelerate too, as does Campbell's flat base "
                                        "(row C3)"))


#: 3D dense granular flows (inclined planes, GDR MiDi 2004, Eur. Phys. J. E 14, 341): solid
#: fractions from ≈ 0.5 (the thinnest flows) to ≈ 0.6
DENSE_3D = (0.5, 0.6)


def nu_3d(nu: float) -> float:
    """Campbell's 2-D → 3-D solid fraction at equal mean spacing (L990-999): C_2D = (π/ν)^½ R
    and C_3D = ((4/3)π/ν_3D)^⅓ R give ν_3D = (4/(3√π)) ν^{3/2}."""
    return 4.0 / (3.0 * math.sqrt(math.pi)) * nu**1.5


def c8_conversion(runs: Mapping[str, ChuteRun]) -> Check:
    """C8's 2-D → 3-D conversion (Fig 3.6, L990-999), which Campbell himself thought gives
    "probably too small" solid fractions: the steady bed's densest strips converted, against
    3D dense flows' ν."""
    ref = "C8; Fig 3.6, L990-999"
    statement = ("the equivalent 3-D solid fraction ν_3D = (4/(3√π)) ν^{3/2} (equal mean "
                 "spacing) of a dense 2-D bed is probably too small")
    thesis = "probably too small (no value)"
    if "chute-30-bumpy" not in runs:
        return not_run(ref, statement, thesis, ["chute-30-bumpy"])
    r = runs["chute-30-bumpy"]
    top = float(np.nanmax(r.profiles["nu"]))
    limits = [("ν_s = π/4 (square, layers slide)", NU_SQUARE),
              ("ν_m = 0.821 (densest shearable)", NU_SHEARABLE)]
    parts = [f"the steady 30° bed's densest strip ν = {top:.3f} → ν_3D = {nu_3d(top):.3f}"]
    parts += [f"{what} → {nu_3d(v):.3f}" for what, v in limits]
    low = nu_3d(top) < DENSE_3D[0]
    return Check(ref, statement, thesis, "; ".join(parts),
                 REPRODUCED if low else NOT_REPRODUCED,
                 f"3D dense granular flows run at ν ≈ {DENSE_3D[0]:g}-{DENSE_3D[1]:g} (inclined "
                 "planes, GDR MiDi 2004): the converted bed "
                 + ("falls below that" if low else "reaches it")
                 + "; only beds at the 2-D packing limits (π/4, 0.821) would map into it; "
                 "the conversion keeps the mean spacing, not the contact network that makes a "
                 "3-D bed dense")


def tc_independence(runs: Mapping[str, ChuteRun]) -> Check:
    ref = "TC model (demstudy; not in the thesis)"
    statement = ("the 30° bumpy chute does not depend on the event-driven engine's t_c, and "
                 "the TC-elastic share is small at the default 1e-5")
    thesis = "— (Campbell's collisions are binary, no TC model)"
    names = ["chute-30-bumpy-tc1e-4", "chute-30-bumpy", "chute-30-bumpy-tc1e-6"]
    if any(n not in runs for n in names):
        return not_run(ref, statement, thesis, [n for n in names if n not in runs], own=True)
    a = runs["chute-30-bumpy"]
    texts = [f"t_c {r.tc:g}: TC share {100 * r.tc_share:.1f} %, u_max {pm(r.u_max, r.u_max_err)}"
             f", KE/N {pm(r.energy_mean, r.energy_err)}, H {r.depth:.2f}, ratio "
             f"{pm(r.ratio, r.ratio_err)}" for r in (runs[n] for n in names)]
    spread = seed_spread(runs)
    level = min(_same(a, runs[n], spread)[0] for n in names if n != "chute-30-bumpy")
    small = a.tc_share < 0.05
    verdict = REPRODUCED if level == 2 and small else PARTLY if level or small \
        else NOT_REPRODUCED
    reason = ("the flow against t_c: " + LEVEL_TEXT[level]) + (
        f"; share at the default {100 * a.tc_share:.1f} % " +
        ("< 5 %" if small else "≥ 5 % (the engine's warning level)")) + "; " + \
        _spread_text(spread)
    return Check(ref, statement, thesis, "; ".join(texts), verdict, reason, own=True)


def soft_cross_check(runs: Mapping[str, ChuteRun], engine: str = "lammps") -> Check:
    label = {"lammps": "LAMMPS", "liggghts": "LIGGGHTS"}.get(engine, engine)
    ref = f"soft-contact cross-check ({label}, k_n = 1e6)"
    statement = f"soft discs ({label}) give the hard discs' 30° bumpy flow"
    thesis = "— (the hard-disc limit)"
    name = f"chute-30-bumpy-{engine}"
    if name not in runs or "chute-30-bumpy" not in runs:
        return not_run(ref, statement, thesis, [name], own=True)
    a, b = runs["chute-30-bumpy"], runs[name]
    spread = seed_spread(runs)
    level, text = _same(a, b, spread)
    ok = level == 2
    slip_ok = within(b.slip, math.hypot(a.slip_err, b.slip_err), a.slip, 2, 0.05)
    text += (f", slip {pm(b.slip, b.slip_err)} (hard {pm(a.slip, a.slip_err)}), base ratio "
             f"{pm(b.ratio, b.ratio_err)}; trend {b.trend:+.2f}")
    verdict = REPRODUCED if ok and slip_ok and b.steady else PARTLY if (ok or b.steady) \
        else NOT_REPRODUCED
    # every condition that failed, by name (the same rule for each soft engine)
    failed = ([] if ok else [f"u_max, KE/N, H: {LEVEL_TEXT[level]}"]) + (
        [] if slip_ok else ["the slip differs beyond 2σ + 0.05"]) + (
        [] if b.converged else [f"the soft run's kinetic energy still drifts (trend "
                                f"{pm(b.trend, b.trend_err)})"]) + (
        [] if b.balanced else [f"its base is not balanced (force ratio "
                               f"{pm(b.ratio, b.ratio_err)} against tan 30° = 0.577)"])
    return Check(ref, statement, thesis, text, verdict,
                 f"bumpy base; {label} run 800 + 600 √(d/g) (hard: 800 + 1600)"
                 + ("" if verdict == REPRODUCED else ": " + "; ".join(failed))
                 + "; " + _spread_text(spread), own=True)


def all_checks(runs: Mapping[str, ChuteRun], quick: bool) -> list[Check]:
    """Every chute check, in the catalogue's order, each naming the runs it rests on
    (``Check.runs``: the TC model's caveat reaches the rows through them; the t_c row
    itself has none)."""
    bumpy30 = "chute-30-bumpy"
    at20, at40 = ("chute-20-flat", "chute-20-bumpy"), ("chute-40-flat", "chute-40-bumpy")
    c7, c8 = "chute-40-bumpy-5x4", "chute-40-bumpy-4x4-var"
    rest_on = [
        (c1_converged(runs), (bumpy30,)),
        (c1_flat(runs), tuple(f"chute-{a}-flat" for a in (24, 26, 30))),
        (c1_slip(runs), SEED_RUNS), (c1_profile(runs), (bumpy30,)),
        # the stress routes test a momentum balance, which TC-elastic collisions keep too
        (c1_stresses(runs), ()),
        (c2_plug(runs), at20), (c2_converged(runs), at20), (c3_accelerates(runs), at40),
        (c3_basal_layer(runs), at40),
        (c9_angles(runs), at40),
        (c4_depths(runs), tuple(f"chute-30-bumpy-{n}x4-var" for n in (5, 10, 13))),
        (c4_shallow_constant(runs), ("chute-30-bumpy-5x4",)),
        (c5_ep08(runs), ("chute-30-bumpy-ep0.8",)), (c5_ep01(runs), ("chute-30-bumpy-ep0.1",)),
        (c6_wall_restitution(runs), (bumpy30, "chute-30-bumpy-ew0.6", "chute-30-bumpy-ew1")),
        (c7_c8(runs, c7, "C7; Fig 3.3, L190, L974",
               "the 5 × 4 bed at 40° gives a steady profile (compared with Augenstein & "
               "Hogg)"), (c7,)),
        (c7_c8(runs, c8, "C8; Fig 3.6, L193, L1039",
               "the 4 × 4 bed at 40° with the variable ε gives a steady mass-flow profile "
               "(compared with Ridgway & Rupp)"), (c8,)),
        (c8_conversion(runs), (bumpy30,)),
        (width_doubling(runs), (bumpy30, "chute-30-bumpy-10x8")),
        # the t_c row is about the TC model; the soft engines have none, so agreeing with
        # them is evidence on the TC model's effect, not a test it weakens
        (tc_independence(runs), ()),
        (soft_cross_check(runs, "lammps"), ()),
        (soft_cross_check(runs, "liggghts"), ())]
    for check, names in rest_on:
        check.runs = tuple(n for n in names if n in runs)
    return [check for check, _names in rest_on]


def tc_quoted(runs: Mapping[str, ChuteRun]) -> dict[str, str]:
    """What the 30° bumpy chute's t_c twins found when none of them exempts it (their own
    shares are large): quoted in the rows resting on it (``base.tc_caveats``)."""
    from ...engines.edmd.tc_share import WARN_SHARE

    names = ["chute-30-bumpy-tc1e-4", "chute-30-bumpy-tc1e-6"]
    if "chute-30-bumpy" not in runs or any(n not in runs for n in names):
        return {}
    a, spread = runs["chute-30-bumpy"], seed_spread(runs)
    twins = [runs[n] for n in names]
    if any(r.tc_share < WARN_SHARE for r in twins):
        return {}  # a small-share twin decides (tc_unchanged), or its row says it differs
    same = all(_same(a, r, spread)[0] == 2 for r in twins)
    listed = " and ".join(f"{r.tc:g} ({100 * r.tc_share:.1f} %)" for r in twins)
    return {"chute-30-bumpy": f"the twins of chute-30-bumpy at t_c = {listed} √(d/g) give "
                              + ("the same u_max, KE/N and H within 2σ + 10 %"
                                 if same else "other u_max, KE/N or H")
                              + ", but neither has a share below 5 % (row 'TC model')"}


def tc_unchanged(runs: Mapping[str, ChuteRun]) -> dict[str, str]:
    """The runs shown not to depend on the TC model (case name → the evidence): the 30° bumpy
    chute when a twin at another t_c whose own share is below the warning level gives the
    same flow within 2σ + 10 % (:func:`tc_independence`); twins that are themselves above it
    show no reference free of the model, so they exempt nothing."""
    from ...engines.edmd.tc_share import WARN_SHARE

    names = ["chute-30-bumpy-tc1e-4", "chute-30-bumpy-tc1e-6"]
    if "chute-30-bumpy" not in runs:
        return {}
    a, spread = runs["chute-30-bumpy"], seed_spread(runs)
    clean = [runs[n] for n in names if n in runs and runs[n].tc_share < WARN_SHARE
             and _same(a, runs[n], spread)[0] == 2]
    if not clean:
        return {}
    twins = ", ".join(f"t_c = {r.tc:g} ({100 * r.tc_share:.1f} % elastic)" for r in clean)
    return {"chute-30-bumpy": f"its twin at {twins} gives the same u_max, KE/N and H within "
                              "2σ + 10 % (row 'TC model')"}
