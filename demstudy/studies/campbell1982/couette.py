"""Campbell (1982), the Couette part: the 2D shear cell of rough discs (cases K1-K7 of the
digest), run with hard discs in the event-driven engine (the reference) and, where LAMMPS
can express the scene (rough walls, the servo), with soft discs as a cross-check.

Dimensionless particle units: d = 1, m = 1; no gravity: the upper wall's speed U_T sets the
time scale (times in d/U_T, 2D stresses in m U_T²/d²). Campbell's unit of length was R = d/2;
his temperatures are printed ×(H/U_T)² with R = 1.

Runs (:mod:`.couette_cases`): K1/K2 servo cells (rough / no-slip walls, three normal
stresses), K3 the shear-rate series, the fixed-gap ν = 0.35 … 0.75 series (K4, K5), K6 the
elastic ν = 0.45 cell, candidate causes (wall rule, system size, t_c) and the LAMMPS cell.
Measurements: :mod:`.couette_measure`; checks: :mod:`.couette_checks`; figures:
:mod:`.couette_figures`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..base import Analysis, Case, pm, tc_caveats, twin_evidence
from . import couette_checks as ck
from . import couette_figures as figs
from .couette_cases import FIXED_NU, SERVO_FACTORS, SHEAR_RATES, all_cases, nu_tag
from .couette_measure import RunSummary, summarise

K1 = [f"couette-k1-rough-servo-s{f:g}" for f in SERVO_FACTORS]
K2 = [f"couette-k2-noslip-servo-s{f:g}" for f in SERVO_FACTORS]
K3 = [f"couette-k3-noslip-rate{12 * g:g}" if g != 1 / 12 else "couette-k2-noslip-servo-s1"
      for g in SHEAR_RATES]
FIXED = [f"couette-fixed-nu{nu_tag(n)}" for n in FIXED_NU]
PARTITION_NU = (0.45, 0.55, 0.65, 0.75)
PARTITION = [f"couette-fixed-nu{nu_tag(n)}" for n in PARTITION_NU]
K6 = ["couette-k6-nu45-elastic", "couette-fixed-nu35"]
LAMMPS = "couette-k1-rough-servo-s1-lammps"
#: the candidate-cause cells of the fixed-gap series (larger lattices, rough walls)
LARGER = "couette-cause-20x8-nu75"
CAUSE_FIXED = ["couette-cause-20x8-nu55", "couette-cause-20x8-nu75"]
CAUSE_ROUGH = ["couette-cause-rough-nu55", "couette-cause-rough-nu75"]

#: TC twins: a cell → the same cell at t_c = 1e-6 (the cause runs): the ν = 0.65 cell (6.0 %
#: of its pair collisions elastic at the default 1e-5) and the rough servo cell (13.0 %); the
#: ν = 0.75 cell's 4.3 % is below the warning level, so its twin is only a cause run
TC_TWINS = {"couette-fixed-nu65": "couette-cause-tc1e-06-nu65",
            "couette-fixed-nu75": "couette-cause-tc1e-06-nu75",
            K1[1]: "couette-cause-tc1e-06-rough-servo-s1"}
#: what a twin must reproduce (values key → name in the report): an agreeing twin exempts
#: every row resting on its cell, so the comparison spans the kinds of quantity they use
TWIN_VALUES = {"nu": "ν", "S_text": "S", "f_s": "f_s", "f_N": "f_N", "chi": "χ",
               "T_mean": "T(H/U_T)²", "rot_share": "rotational share",
               "kurtosis_u": "kurtosis of u", "approach_share": "approach share",
               "layering": "layering"}


def _tc_share(r: RunSummary) -> tuple[float, float]:
    return r.attrs.get("tc_elastic_fraction", math.nan), r.attrs.get("tc", math.nan)


def tc_twins(s: Mapping[str, RunSummary]) -> tuple[dict[str, str], dict[str, str]]:
    """What the TC twins say about their cells, for :func:`..base.tc_caveats`
    (:func:`..base.twin_evidence`; their values side by side: the causes section). A smaller
    t_c need not lower the share: the ν = 0.65 cell makes 6.0 % elastic at 1e-5 and 6.6 % at
    1e-6 (re-collisions within clusters, which come closer in time as t_c falls), so a twin
    can show the results converged in t_c without being a reference free of the model."""
    return twin_evidence([(base, s[base].values, s[twin].values, *_tc_share(s[twin]))
                          for base, twin in TC_TWINS.items() if base in s and twin in s],
                         TWIN_VALUES, unit="d/U_T")


#: the chute runs this part reads: Figs 3.21-3.24 put the steady chute's strips on f(ν)
CHUTE_F = ("chute-30-bumpy",)


def reads(quick: bool) -> tuple[str, ...]:
    """Other parts' runs the Couette analysis uses (module demstudy.studies.parts)."""
    return CHUTE_F


def _chute_strips(paths: Mapping[str, Path]) -> tuple[dict[str, dict],
                                                      dict[str, tuple[float, float]]]:
    """The chutes' strip-by-strip f (:func:`.chute_measure.local_bagnold`) and their TC
    shares (the row on them carries the TC rule too)."""
    from .chute_measure import local_bagnold
    from .chute_measure import summarise as chute_summary

    strips, shares = {}, {}
    for name, path in paths.items():
        try:
            run = chute_summary(name, path)
        except (OSError, KeyError, ValueError) as exc:  # a damaged file: the row says not run
            print(f"warning: {name}: {path} not read for f(ν) ({exc})")
            continue
        strips[name] = local_bagnold(run)
        shares[name] = (run.tc_share, math.nan if run.tc is None else run.tc)
    return strips, shares


def cases(quick: bool) -> list[Case]:
    """Every Couette case; ``quick`` marks the subset in ``--quick`` (the runner picks it)."""
    return [c for c in all_cases() if c.quick or not quick]


def analyse(runs: Mapping[str, Path], out: Path, quick: bool) -> Analysis:
    out.mkdir(parents=True, exist_ok=True)
    chute, chute_shares = _chute_strips({n: Path(runs[n]) for n in CHUTE_F if n in runs})
    summaries = {name: summarise(name, Path(path)) for name, path in sorted(runs.items())
                 if name not in CHUTE_F}
    ana = Analysis()
    ana.checks = checks(summaries, chute)
    unchanged, told = tc_twins(summaries)
    units = {**{n: "d/U_T" for n in summaries}, **{n: "√(d/g)" for n in chute_shares}}
    tc_caveats(ana.checks, {**{n: _tc_share(r) for n, r in summaries.items()},
                            **chute_shares}, unchanged, told, unit=units)
    ana.figures = figures(summaries, out, chute)
    ana.sections = sections(summaries, quick)
    return ana


def checks(s: dict[str, RunSummary], chute: Mapping[str, dict] | None = None) -> list:
    fixed_here = [n for n in FIXED if n in s]
    fixed_nu = [FIXED_NU[FIXED.index(n)] for n in fixed_here]
    # the trends use every fixed-gap run present (at least two), else they are not run
    trend_names = fixed_here if len(fixed_here) >= 2 else FIXED
    trend_nu = fixed_nu if len(fixed_here) >= 2 else list(FIXED_NU)
    part_here = [n for n in PARTITION if n in s]
    part_names = part_here if len(part_here) >= 2 else PARTITION
    part_nu = [PARTITION_NU[PARTITION.index(n)] for n in part_names]
    history = [n for n in FIXED + K2 + K1 if n in s] or FIXED
    out = [
        ck.energy_history(s, history, [_short(n) for n in history]),
        ck.servo_density(s, "K1", K1, SERVO_FACTORS, "Fig 3.15", "rough"),
        ck.servo_density(s, "K2", K2, SERVO_FACTORS, "Fig 3.16", "no-slip"),
        ck.wall_slip(s, K1[1], K2[1]),
        *ck.shear_rate_independence(s, K3, SHEAR_RATES),
        ck.s_order_one(s, trend_names, trend_nu),
        ck.s_trend(s, trend_names, trend_nu, LARGER),
        *ck.bagnold_steep(s, trend_names, trend_nu, LARGER),
        ck.chute_on_curve(s, trend_names, chute or {}),
        ck.chi_check(s, trend_names, trend_nu),
        ck.rotational_share(s, part_names, part_nu),
        ck.vdf_maxwellian(s, trend_names, trend_nu),
        ck.angles_approach(s, trend_names, trend_nu),
        ck.angles_savage_jeffrey(s, K6, ["ν=0.45, ε=1", "ν=0.35, 0.8/0.6"]),
        ck.elastic_lower_s(s, K6[0], "couette-fixed-nu45"),
        ck.layering(s, trend_names, trend_nu),
        ck.plug(s, FIXED[-1], FIXED_NU[-1], LARGER),
        ck.lammps_cross_check(s, K1[1], LAMMPS),
    ]
    return out


def _short(name: str) -> str:
    """A cell's name in a row: 'ν = 0.35' for the fixed-gap cells, 'K1 σ_n×0.5' for servo."""
    if name in FIXED:
        return f"ν = {FIXED_NU[FIXED.index(name)]:g}"
    key, _wall, _servo, factor = name.removeprefix("couette-").split("-")[:4]
    return f"{key.upper()} σ_n×{factor.removeprefix('s')}"


def _present(s: dict[str, RunSummary], names: list[str], labels: list[str]):
    return [(lab, s[n]) for n, lab in zip(names, labels, strict=False) if n in s]


def figures(s: dict[str, RunSummary], out: Path, chute: Mapping[str, dict] | None = None
            ) -> list:
    made = []
    history = [(title, [(_short(n), s[n]) for n in names if n in s and "ke" in s[n].arrays])
               for title, names in (("fixed gap, no-slip walls", FIXED),
                                    ("servo, no-slip walls (K2)", K2),
                                    ("servo, rough walls (K1)", K1))]
    history = [g for g in history if g[1]]
    if history:
        made.append(figs.energy_history(history, out))
    # Campbell's snapshots are at ν = 0.56, 0.63, 0.76: the fixed-gap cells nearest them
    shots = [(lab, s[n]) for n, lab in ((FIXED[2], "10 × 4, ν = 0.55"),
                                        (FIXED[3], "10 × 4, ν = 0.65"),
                                        (FIXED[4], "10 × 4, ν = 0.75"),
                                        (LARGER, "20 × 8, ν = 0.75"))
             if n in s and "snapshot" in s[n].arrays]
    if shots:
        made.append(figs.snapshots(shots, out))
    k1 = _present(s, K1, [f"rough, σ_n×{f:g}" for f in SERVO_FACTORS])
    if LAMMPS in s:
        k1.append(("rough, σ_n×1, LAMMPS (soft)", s[LAMMPS]))
    if k1:
        made.append(figs.profiles(k1, out, "couette-profiles-k1.png",
                                  "Servo cells with rough walls at three normal stresses "
                                  "(K1, Fig 3.15)"))
    k2 = _present(s, K2, [f"no-slip, σ_n×{f:g}" for f in SERVO_FACTORS])
    if k2:
        made.append(figs.profiles(k2, out, "couette-profiles-k2.png",
                                  "Servo cells with no-slip walls at three normal stresses "
                                  "(K2, Fig 3.16)"))
    fixed = _present(s, FIXED, [f"ν = {n:g}" for n in FIXED_NU])
    if fixed:
        made.append(figs.profiles(fixed, out, "couette-profiles-fixed.png",
                                  "Fixed-gap cells, no-slip walls, ν = 0.35 … 0.75"))
    groups = {"fixed gap, no-slip": [r for _, r in fixed],
              "servo, rough (K1)": [s[n] for n in K1 if n in s],
              "servo, no-slip (K2)": [s[n] for n in K2 if n in s],
              "fixed gap, 20 × 8 (cause)": [s[n] for n in CAUSE_FIXED if n in s],
              "fixed gap, rough walls (cause)": [s[n] for n in CAUSE_ROUGH if n in s]}
    groups = {k: v for k, v in groups.items() if v}
    if groups:
        made.append(figs.s_of_nu(groups, out))
        fixed_cells = [s[n] for n in FIXED if n in s and s[n].v("nu") < ck.LAYERED_NU]
        made.append(figs.bagnold(groups, out, chute or {},
                                 max((r.v("nu") for r in fixed_cells), default=np.inf)))
    part = [(n, s[name]) for n, name in zip(PARTITION_NU, PARTITION, strict=False) if name in s]
    if len(part) >= 2:
        made.append(figs.partition([r for _, r in part], [n for n, _ in part], out))
    with_vdf = [(lab, r) for lab, r in fixed if "vdf" in r.arrays]
    if with_vdf:
        made.append(figs.vdfs(with_vdf, out))
    ang = _present(s, K6, ["ν = 0.45, ε = 1 (K6)", "ν = 0.35, 0.8/0.6 (K6)"]) + _present(
        s, FIXED[2:], [f"ν = {n:g}" for n in FIXED_NU[2:]])
    ang = [(lab, r) for lab, r in ang if "p_text" in r.arrays]
    if ang:
        made.append(figs.angles(ang, out))
    st = [(lab, r) for lab, r in fixed if "st_r" in r.arrays]
    if st:
        made.append(figs.structure(st, out))
    if all(n in s for n in K3):
        made.append(figs.shear_rates([s[n] for n in K3], SHEAR_RATES, out))
    return made


def _share(r: RunSummary) -> str:
    """The run's TC-elastic share, "—" for an engine without the TC model (soft contacts)."""
    share = r.attrs.get("tc_elastic_fraction", math.nan)
    return "—" if not math.isfinite(share) else f"{100 * share:.2f} %"


def _row(name: str, r: RunSummary) -> str:
    return (f"| {name} | {r.attrs['engine']} | {pm(*r.values['nu_cell'])} | "
            f"{pm(*r.values['nu'])} | {pm(*r.values.get('S_text', (float('nan'), 0)))} | "
            f"{pm(*r.values.get('f_s', (float('nan'), 0)))} | "
            f"{pm(*r.values.get('f_N', (float('nan'), 0)))} | "
            f"{pm(*r.values.get('chi', (float('nan'), 0)))} | {pm(*r.values['T_mean'])} | "
            f"{pm(*r.values['rot_share'])} | "
            f"{pm(*r.values.get('layering', (float('nan'), 0)))} | "
            f"{_share(r)} |")


HEADER = ("| run | engine | ν cell | ν centre | S (text) | f_s | f_N | χ | T(H/U_T)² | "
          "rot. share | layering | TC share |\n|---|---|---|---|---|---|---|---|---|---|---|---|")


def sections(s: dict[str, RunSummary], quick: bool) -> list[tuple[str, str]]:
    if not s:
        return [("Couette cells", "No Couette run is present: every check says not run.")]
    table = "\n".join([HEADER] + [_row(n, r) for n, r in s.items()])
    text = ("Centre values: strips at least 2 d from both walls; errors: block jackknife of "
            "the strips, or the strips' scatter/√n when larger; T(H/U_T)² is Campbell's "
            "QFL/3 = (⟨u'²⟩+⟨v'²⟩+β⟨ω'²⟩)/3 ×(H/U_T)² with R = 1; f with the thesis's π "
            "(ρ_p = 4/π per d²); layering: (max − min)/mean of the normal structure "
            "distribution over 0.5 < |Δy| < 2; TC share: pair collisions the TC model made "
            "elastic. Dimensionless particle units (d = 1, m = 1, U_T = 1).\n\n" + table)
    out = [("Couette cells: the numbers", text)]
    out.append(("Couette cells: candidate causes", causes(s)))
    out.append(("Couette cells: the servo in practice", servo_notes(s)))
    return out


def servo_notes(s: dict[str, RunSummary]) -> str:
    """How the servo walls behaved: gap, width/gap (Campbell holds it at its start value,
    0.4), the lower wall's wander during production."""
    rows = []
    for name, r in s.items():
        if "wall_wander" not in r.values:
            continue
        ratio = r.v("width") / r.v("gap")
        rows.append(f"| {name} | {pm(*r.values['gap'])} | {pm(*r.values['width'])} | "
                    f"{ratio:.3f} | {r.v('wall_wander'):.2f} |")
    if not rows:
        return "No servo run in this run of the study."
    return "\n".join([
        "Campbell keeps width/gap at its start value (0.4, L867-869). The event-driven engine "
        "rescales the width affinely at each servo update but never so far that touching "
        "discs would overlap (edmd scale_width), so a dense cell that compresses keeps its "
        "width: width/gap then exceeds 0.4. The lower wall wanders by the amount in the last "
        "column during production; the profiles of servo cells are therefore taken in "
        "wall-relative strips, Campbell's ST = HGT/FND (demstudy.analysis.walls; here with "
        "the strips of the mean gap, module couette_measure).", "",
        "| run | gap H | width | width/H | lower-wall wander (max−min) |",
        "|---|---|---|---|---|", *rows])


def causes(s: dict[str, RunSummary]) -> str:
    """Where demstudy's dense cells differ (no steep f rise, no plug), the candidate causes
    side by side with the baseline fixed-gap runs."""
    rows = []
    for nu in (0.55, 0.65, 0.75):
        tag = nu_tag(nu)
        base = f"couette-fixed-nu{tag}"
        for name, what in ((base, "baseline: no-slip, 10 × 4, t_c = 1e-5"),
                           (f"couette-cause-rough-nu{tag}", "rough walls"),
                           (f"couette-cause-10x8-nu{tag}", "10 × 8 discs"
                            + (", t_c = 1e-4" if nu > 0.7 else "")),
                           (f"couette-cause-20x8-nu{tag}", "20 × 8 discs"
                            + (", t_c = 1e-4" if nu > 0.7 else "")),
                           (f"couette-cause-tc0.0001-nu{tag}", "t_c = 1e-4"),
                           (f"couette-cause-tc1e-06-nu{tag}", "t_c = 1e-6")):
            if name in s:
                r = s[name]
                rows.append(f"| ν = {nu:g} | {what} | {pm(*r.values['nu'])} | "
                            f"{pm(*r.values['S_text'])} | {pm(*r.values['f_s'])} | "
                            f"{pm(*r.values['T_mean'])} | {pm(*r.values['layering'])} | "
                            f"{_share(r)} |")
    for name, what in ((K1[1], "baseline: rough walls, servo σ_n×1, t_c = 1e-5"),
                       ("couette-cause-tc0.0001-rough-servo-s1", "rough servo, t_c = 1e-4"),
                       ("couette-cause-tc1e-06-rough-servo-s1", "rough servo, t_c = 1e-6")):
        if name in s:
            r = s[name]
            rows.append(f"| servo | {what} | {pm(*r.values['nu'])} (cell "
                        f"{pm(*r.values['nu_cell'])}) | {pm(*r.values['S_text'])} | "
                        f"{pm(*r.values['f_s'])} | {pm(*r.values['T_mean'])} | "
                        f"{pm(*r.values['layering'])} | "
                        f"{_share(r)} |")
    servo = [(n, s[n]) for n in K2 if n in s]
    if not rows and not servo:
        return "The cause runs are not in this run of the study (full study only)."
    head = ("| ν | variant | ν centre | S | f_s | T(H/U_T)² | layering | TC share |\n"
            "|---|---|---|---|---|---|---|---|")
    text = [head, *rows, "",
            "Servo against fixed gap: the servo cells (K2) at the same walls reach "
            + ", ".join(f"ν = {pm(*r.values['nu'])} with f_s = {pm(*r.values['f_s'])}"
                        for _, r in servo) + "."]
    return "\n".join(text)
