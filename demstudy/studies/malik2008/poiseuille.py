"""Malik (2008), Ch. 3-4: gravity-driven granular Poiseuille flow of rough inelastic spheres
between flat walls (e_w = β_w = 1), φ ≈ 0.01 (β ∈ {-0.99, 0, 0.99} × e ∈ {0.8 … 0.99}),
φ ≈ 0.1 (e ∈ {0.7 … 0.99}) and φ ≈ 0.5 (e = β = 0.9), with the thesis's N and boxes, in the
event-driven engine (cases: :mod:`.poiseuille_cases`). The analysis checks the statements of
the digest (../shared/reference/malik2008.md §3.5, §2.3, §4) and draws the thesis's figures.

Dimensionless particle units: d = 1, m = 1, g = 1 (gravity acts): speeds in √(gd), spins in
√(g/d), temperatures in g d, times in √(d/g) (Malik's u*, ω*, T*, θ* are these numbers).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np

from ...analysis.steady import STEADY_LIMIT
from ...errors import BadInputFile
from ...io.results import read_results
from ..base import NOT_RUN, UNITS_NOTE, Analysis, Check, Figure
from . import poiseuille_checks as pc
from .poiseuille_cases import (
    BETAS,
    QUICK,
    RESTITUTIONS,
    SOFT_FLOWS,
    TC_TWINS,
    VALIDATION,
    Flow,
    cases,
    flows,
)
from .poiseuille_data import (
    BINS,
    BINS_DENSE,
    CENTRE_BIN,
    FlowData,
    collisions_text,
    flow_gr,
    load_flow,
    vdf_bins,
)
from .poiseuille_figures import (
    GRADIENT_PANELS,
    freepath_figure,
    gr_figure,
    lambda_figure,
    profiles_figure,
    trace_figure,
    vcorr_figure,
    vdf_figure,
    wall_figure,
)
from .poiseuille_soft import soft_check, soft_unreadable
from .poiseuille_waves import frame_mode_ratios

__all__ = ["analyse", "cases", "derive"]

Runs = dict[tuple[float, float, float], FlowData]  # (φ, β, e) -> run

#: the checks, in the report's order: each takes the runs and returns its Check(s)
CHECKS: tuple[Callable[[Runs], list[Check]], ...] = (
    pc.steady_checks, pc.validation_checks, pc.dissipation_checks, pc.knudsen_checks,
    pc.freepath_checks,
    pc.vdf_checks, pc.vdf_elastic_limit_checks, pc.wall_value_checks, pc.wall_dissipation_checks,
    pc.contact_checks, pc.gr_shell_checks, pc.sparse_wall_checks, pc.lambda_checks,
    pc.vcorr_checks, pc.dense_checks, pc.wave_checks)


#: a steady run (|trend| < STEADY_LIMIT) whose kinetic energy still changes by this fraction
#: over the production has a slow drift the criterion lets pass
SLOW_DRIFT = 0.05


def _drifting(data: Mapping) -> str:
    """The steady runs whose kinetic energy still drifts by SLOW_DRIFT-STEADY_LIMIT."""
    slow = [d.flow.name for d in data.values()
            if d.run_info()["steady"] and abs(d.run_info()["trend"]) >= SLOW_DRIFT]
    return "here: " + ", ".join(slow) if slow else "none here"


def _known_flows(quick: bool) -> dict[str, Flow]:
    """The event-driven flows of the (quick) study by case name, the TC twins and the
    validation box included."""
    return {f.name: f for f in (QUICK if quick else (*flows(), *TC_TWINS, VALIDATION))}


def load_runs(runs: Mapping[str, Path], quick: bool) -> Runs:
    """The part's runs present in ``runs``, read (in-bin g(r) computed from their frames);
    the TC twins apart (:func:`load_extra`)."""
    known = _known_flows(quick)
    out: Runs = {}
    for name, path in runs.items():
        flow = known.get(name)
        if (flow is not None and flow.engine == "edmd" and flow.tc is None
                and flow.n is None and Path(path).is_file()):
            out[(flow.phi, flow.beta, flow.e)] = load_flow(flow, Path(path))
    return out


def load_extra(runs: Mapping[str, Path], quick: bool, which: tuple[Flow, ...]) -> list[FlowData]:
    """The runs of ``which`` (flows outside the thesis's (φ, β, e) grid: the TC twins, the
    validation box) present in ``runs`` (full study), read."""
    if quick:
        return []
    return [load_flow(f, Path(runs[f.name])) for f in which
            if f.name in runs and Path(runs[f.name]).is_file()]


def soft_row(data: Runs, runs: Mapping[str, Path], flow: Flow) -> Check:
    """The row of soft cross-check ``flow`` (full study only): its run read without g(r)
    and compared with the hard run; an unreadable file or profiles that do not compare give
    "not run" with the cause, never an exception."""
    hard = data.get((flow.phi, flow.beta, flow.e))
    path = runs.get(flow.name)
    if path is None or not Path(path).is_file():
        return soft_check(hard, None, flow)
    try:
        return soft_check(hard, load_flow(flow, Path(path), with_gr=False), flow)
    except (OSError, KeyError, ValueError, BadInputFile) as exc:  # NotComparable: ValueError
        return soft_unreadable(f"unreadable or not comparable: {exc}", flow)


def _percent(fraction: float) -> str:
    return "n/a" if fraction != fraction else f"{100 * fraction:.2g} %"


def derive(name: str, path: Path) -> dict[str, tuple[dict, dict]]:
    """What a study record (demstudy.studies.records) keeps of run ``name`` in place of its
    frames: the in-bin g(r) and the xy density modes of the S-wave check."""
    flow = {**_known_flows(True), **_known_flows(False)}.get(name)
    if flow is None or flow.engine != "edmd":
        return {}
    res = read_results(path, skip=("frames", "collisions"))
    out: dict[str, tuple[dict, dict]] = {}
    gr = flow_gr(flow, Path(path), res.profiles["edges"])
    if gr:
        out["gr"] = (gr, {"description": "in-bin g(r) (Malik §4.7) from the run's frames"})
    ratios = frame_mode_ratios(Path(path))
    out["mode_ratios"] = ({k: np.array(v) for k, v in ratios.items()}, {
        "description": "R = <|X(k)|^2>/N over the frames (mean, standard error) of the xy "
                       "count modes 11 = (1, ±1), 10 = (1, 0), 01 = (0, 1); shot noise = 1"})
    return out


def analyse(runs: Mapping[str, Path], out: Path, quick: bool) -> Analysis:
    """Checks, figures and report sections of the Poiseuille part (cases missing from
    ``runs`` give "not run" checks)."""
    data = load_runs(runs, quick)
    twins = load_extra(runs, quick, TC_TWINS)
    box = next(iter(load_extra(runs, quick, (VALIDATION,))), None)
    checks = [c for check in CHECKS for c in
              (check(data, box) if check is pc.validation_checks else check(data))]
    pc.tc_caveats(checks, data, pc.tc_twin_evidence(data, twins))
    pc.common_motion_caveats(checks, data)
    if not quick:
        checks += [soft_row(data, runs, flow) for flow in SOFT_FLOWS]
        checks += pc.tc_twin_rows(data, twins, TC_TWINS)
    for c in checks:  # a statement without runs says so, never crashes
        if c.verdict == NOT_RUN and not c.reason:
            c.reason = "its runs are not in this run of the study"
    figures = make_figures(data, Path(out), quick)
    if box is not None:
        shown = [box, *([data[pc.REF]] if pc.REF in data else [])]
        path = profiles_figure(shown, ["N = 1000 in 37.4³, φ = 0.0100 (Fig 2.11's N)",
                                       "N = 2744 in 50³, φ = 0.0115 (Ch. 3)"][: len(shown)],
                               "Malik Fig 2.11: the validation flow, nominal φ = 0.01, "
                               "β = 0.99, e = 0.8", Path(out) / "poiseuille-validation.png",
                               across=True)
        figures.insert(0, Figure(path, "Fig 2.11's form: U_x*, ω_z*, φ, T*, θ* and Kn "
                                       "against y/W for the validation box (N = 1000, φ = "
                                       "0.0100) beside Ch. 3's N = 2744 flow (φ = 0.0115) at "
                                       "the same β, e."))
    return Analysis(checks, figures, sections(data, runs, quick,
                                              [*twins, *([box] if box else [])]))


def _label(d: FlowData) -> str:
    return f"φ = {d.flow.phi:g}, β = {d.flow.beta:g}, e = {d.flow.e:g}"


def _of(data: Runs, phi: float, beta: float | None = None) -> list[FlowData]:
    """The runs at ``phi`` (and ``beta``), ordered by e."""
    found = [d for (p, b, _e), d in data.items() if p == phi and (beta is None or b == beta)]
    return sorted(found, key=lambda d: (d.flow.beta, d.flow.e))


def make_figures(data: Runs, out: Path, quick: bool) -> list[Figure]:
    """Every figure whose runs exist (module doc of :mod:`.poiseuille_figures`)."""
    figs: list[Figure] = []
    if not data:
        return figs
    tag = " (quick: short runs)" if quick else ""
    for phi in (0.01, 0.1, 0.5):
        at_phi = _of(data, phi)
        if at_phi:
            figs.append(Figure(
                trace_figure(at_phi, f"Malik Figs 3.2d/4.1c/4.15b: kinetic energy vs collisions, "
                             f"φ = {phi:g}{tag}", out / f"poiseuille-trace-phi{phi:g}.png"),
                f"Kinetic energy per particle against collisions per particle, φ = {phi:g}; "
                "the bar marks the start of averaging (Figs 3.2d, 4.1c, 4.15b)."))
        figs += _phi_figures(data, phi, out, tag)
    return figs


def _phi_figures(data: Runs, phi: float, out: Path, tag: str) -> list[Figure]:
    figs: list[Figure] = []
    at_phi = _of(data, phi)
    if not at_phi:
        return figs
    fig_no = {0.01: ("3.3/3.5/3.7", "3.12-3.17", "3.18-3.20", "3.21"),
              0.1: ("4.2/4.4/4.6", "4.7-4.9", "4.10", "4.11"),
              0.5: ("4.16", "4.18", "4.17", "4.20")}[phi]
    betas = [b for b in BETAS if _of(data, phi, b)] or sorted({d.flow.beta for d in at_phi})
    groups = [(b, _of(data, phi, b)) for b in betas]
    # profiles: one figure per β with its e (φ = 0.1 with one e: every β together)
    if all(len(ds) == 1 for _b, ds in groups) and len(groups) > 1:
        groups_p = [(None, at_phi)]
    else:
        groups_p = [(b, ds) for b, ds in groups if ds]
    for b, ds in groups_p:
        name = f"phi{phi:g}" + (f"-b{b:g}" if b is not None else "")
        path = profiles_figure(ds, [_label(d) for d in ds],
                               f"Malik Figs {fig_no[0]}: profiles, φ = {phi:g}"
                               + (f", β = {b:g}" if b is not None else "") + tag,
                               out / f"poiseuille-profiles-{name}.png")
        figs.append(Figure(path, f"φ, U_x*, ω_z*, T*, θ*, Kn against y, {name} (25 bins of "
                                 "2 d; Figs " + fig_no[0] + ")."))
    bins = BINS_DENSE if phi == 0.5 else BINS
    for b, ds in groups:
        ref = min(ds, key=lambda d: abs(d.flow.e - (0.9 if phi == 0.5 else
                                                    RESTITUTIONS[phi][0])))
        name = f"phi{phi:g}-b{b:g}"
        series = [(f"bin {k} (e = {ref.flow.e:g})", ref, k - 1) for k in vdf_bins(phi)]
        figs.append(Figure(vdf_figure(series, f"Malik Figs {fig_no[1]}: VDFs, φ = {phi:g}, "
                                              f"β = {b:g}, e = {ref.flow.e:g}{tag}",
                                      out / f"poiseuille-vdf-bins-{name}.png"),
                           f"Six VDF panels, bins {vdf_bins(phi)}, {name}, e = "
                           f"{ref.flow.e:g}."))
        gseries = [(f"bin {k} (e = {ref.flow.e:g})", ref, k - 1) for k in bins]
        figs.append(Figure(gr_figure(gseries, f"Malik Figs {fig_no[2]}: g(r) in bins, "
                                              f"φ = {phi:g}, β = {b:g}{tag}",
                                     out / f"poiseuille-gr-bins-{name}.png"),
                           f"In-bin g(r), bins {bins}, {name}, e = {ref.flow.e:g}."))
        vseries = [(f"bin {k} (e = {ref.flow.e:g})", ref, k - 1) for k in bins]
        figs.append(Figure(vcorr_figure(vseries, f"Malik Figs 4.12/4.13/4.19: velocity "
                                                 f"correlations, φ = {phi:g}, β = {b:g}{tag}",
                                        out / f"poiseuille-vcorr-bins-{name}.png"),
                           f"C_xx, C_yy, C_zz in bins {bins}, {name}, e = {ref.flow.e:g}."))
        if len(ds) > 1:
            figs += _over_e(ds, name, phi, b, fig_no, out, tag)
    if any(len(ds) > 1 for _b, ds in groups) or phi != 0.01:
        figs.append(Figure(lambda_figure([(f"β = {b:g}", ds) for b, ds in groups],
                                         f"Malik Fig {fig_no[3]}: Λ(y), φ = {phi:g}{tag}",
                                         out / f"poiseuille-lambda-phi{phi:g}.png"),
                           f"Λ(y) (horizontal) against y, φ = {phi:g}, one panel per β, "
                           "the molecular 1/3 line; inset: Λ(centre) and mean Λ against e."))
    if phi == 0.01 and any(len(ds) > 1 for _b, ds in groups):
        by_beta = [(f"β = {b:g}", ds) for b, ds in groups]
        figs.append(Figure(wall_figure(by_beta,
                                       f"Malik Fig 3.10: wall values vs e, φ = {phi:g}{tag}",
                                       out / f"poiseuille-walls-phi{phi:g}.png"),
                           "Translational and rotational slip, T and θ at the walls (mean "
                           "of bins 1 and 25) against e, one curve per β (Fig 3.10)."))
        figs.append(Figure(wall_figure(by_beta, f"Malik Fig 3.11: wall gradients vs e, "
                                                f"φ = {phi:g}{tag}",
                                       out / f"poiseuille-wall-gradients-phi{phi:g}.png",
                                       value=pc.wall_slope, panels=GRADIENT_PANELS),
                           "Wall gradients of U_x, ω_z, T and θ (bins 1-2 and 24-25, per d) "
                           "against e, one curve per β (Fig 3.11); inward: the change from "
                           "the wall into the flow of each wall value (ω_z: rolling along "
                           "the wall > 0)."))
        figs.append(Figure(freepath_figure(by_beta[::-1], f"Malik Fig 3.9: free-path "
                                                          f"distribution in bin 13, "
                                                          f"φ = {phi:g}{tag}",
                                           out / f"poiseuille-freepath-phi{phi:g}.png",
                                           CENTRE_BIN - 1),
                           "P(l) of the free paths (relative to the local mean flow) in bin "
                           "13, several e, one panel per β (β = 0.99, 0, -0.99 as in Fig "
                           "3.9); dashed: exp(-l/λ)/λ with each run's λ."))
    return figs


def _over_e(ds: list[FlowData], name: str, phi: float, b: float,
            fig_no: tuple[str, ...], out: Path, tag: str) -> list[Figure]:
    """The centre bin for several e: VDF, g(r), velocity correlations."""
    series = [(f"e = {d.flow.e:g}", d, CENTRE_BIN - 1) for d in ds]
    return [
        Figure(vdf_figure(series, f"Malik Figs {fig_no[1]}: VDFs in bin 13, φ = {phi:g}, "
                                  f"β = {b:g}{tag}", out / f"poiseuille-vdf-e-{name}.png"),
               f"Six VDF panels in bin 13 for several e, {name}."),
        Figure(gr_figure(series, f"Malik Figs {fig_no[2]}: g(r) in bin 13, φ = {phi:g}, "
                                 f"β = {b:g}{tag}", out / f"poiseuille-gr-e-{name}.png"),
               f"In-bin g(r), bin 13, several e, {name}."),
        Figure(vcorr_figure(series, f"Malik Fig 4.14: velocity correlations in bin 13, "
                                    f"φ = {phi:g}, β = {b:g}{tag}",
                            out / f"poiseuille-vcorr-e-{name}.png"),
               f"C_xx, C_yy, C_zz in bin 13, several e, {name}."),
    ]


def sections(data: Runs, runs: Mapping[str, Path], quick: bool,
             extra: Sequence[FlowData] = ()) -> list[tuple[str, str]]:
    """The report's text: what ran (the flows, then ``extra``: the TC twins and the
    validation box), for how long against the thesis, what did not run."""
    known = [*_known_flows(quick), *([] if quick else [f.name for f in SOFT_FLOWS])]
    made = sorted(n for n in known if n in runs)
    missing = sorted(n for n in known if n not in runs)
    lines = [UNITS_NOTE, "",
             "Event-driven hard spheres (the reference engine), the thesis's N and boxes "
             "(2744 in 50³, 24400 in 50³, 19600 in 20 × 50 × 20), 25 bins of 2 d across W = "
             "50; beside them Fig 2.11's validation box (N = 1000 in a 37.4 d cube at φ = "
             "0.01, 25 bins of W/25) and the φ = 0.5 flow's TC twin at t_c = 10⁻⁶; K = 2/5, "
             "e_w = β_w = 1, g along +x. Collisions per particle = 2 N_pp/N "
             "(wall collisions not counted). Fluctuations (T, θ, VDFs, Λ, C_aa) are taken "
             "relative to the run mean of each 2 d bin (Malik's number of z cells is not "
             "stated; the flows are homogeneous in z). Kn uses the free paths of the first "
             "2·10⁵ logged collisions of production (the collision log's capacity; window in "
             "the table): about one √(d/g) at φ = 0.1 and 0.5, so its error is that "
             "window's scatter and misses slower drifts. Steady: the straight line fitted "
             "to the kinetic energy over the production changes by less than "
             f"{100 * STEADY_LIMIT:.0f} % of its mean over the window (|trend| < "
             f"{STEADY_LIMIT:g}, Campbell's criterion made quantitative, "
             f"demstudy.analysis.steady); a run with |trend| of {SLOW_DRIFT:g}-"
             f"{STEADY_LIMIT:g} has a slow drift "
             f"that this criterion lets pass ({_drifting(data)}).", "",
             "| run | steady (plateau) | averaged over (√(d/g)) | collisions/particle "
             "averaged | Kn from t = (√(d/g)) | TC-elastic share | CPU s |",
             "|---|---|---|---|---|---|---|"]
    for d in [data[key] for key in sorted(data)] + list(extra):
        info = d.run_info()
        fp = d.res.group_attrs.get("statistics/freepath", {})
        window = f"{fp.get('window_start', float('nan')):.0f}-" \
                 f"{fp.get('window_end', float('nan')):.0f}"
        lines.append(f"| {d.flow.name} | {'yes' if info['steady'] else 'NO'} "
                     f"(trend {info['trend']:.2g}) | {info['production']:.0f} | "
                     f"{info['collisions_per_particle']:.3g} | {window} | "
                     f"{_percent(info['tc_fraction'])} | {info['wall_seconds']:.0f} |")
    lines += ["", "TC-elastic share: the pair collisions the engine's TC model (Luding & "
              "McNamara, t_c = 10⁻⁵ √(d/g) unless stated) made elastic, absent from the "
              "thesis's model; above 5 % an agreement in the rows resting on that run (a "
              "statement about a φ rests on all its runs) counts as \"partly\", unless a "
              "twin at a smaller t_c with a share below 5 % gives the same values, and a "
              "mismatch names the share as one possible cause.", "",
              f"The thesis averaged Λ over 7·10⁴ (φ = 0.01, 0.1) and 8·10⁴ (φ = 0.5) "
              f"collisions per particle; demstudy averaged over "
              f"{collisions_text(list(data.values()))} (table).", "",
              f"Made: {len(made)} of {len(known)} runs. Not run: "
              + (", ".join(missing) if missing else "none") + ".", "",
              "Soft cross-checks (LAMMPS and LIGGGHTS, the scene's stiffness, constant β by "
              "the tangential spring): the φ = 0.01, β = 0.99, e = 0.8 flow at 10 steps per "
              "contact over 200 + 400 √(d/g) (cases " + ", ".join(f.name for f in SOFT_FLOWS)
              + "; the scene's 2500 √(d/g) at 50 steps per contact is forecast at 3.7 h on "
              "one core in LAMMPS); φ = 0.1 and 0.5 are left to the "
              "event-driven engine (the cost study forecasts Malik's φ = 0.1 box at 65 h in "
              "LAMMPS, docs/accuracy-cost.md)."]
    return [("Poiseuille flows (Malik Ch. 3-4): runs", "\n".join(lines)),
            ("Poiseuille flows: correlations and VDFs in numbers", pc.numbers_text(data))]
