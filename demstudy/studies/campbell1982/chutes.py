"""Campbell (1982) chutes part of ``demstudy study campbell1982``: 2D chutes of 10 × 4 rough
discs (and the depth, restitution and width series), hard discs in the event-driven engine (the
reference), the 30° chute also with soft discs in LAMMPS; analysed in the thesis's forms.

Dimensionless particle units: d = 1, m = 1, g = 1 (lengths d = 2R, times √(d/g), speeds √(gd),
energies m g d, 2D stresses m g/d). Campbell's unit of length was R: his lengths are twice
ours, his speeds √2 times ours.

Cases: :mod:`.chute_cases` (which base for which statement, and why); the measures:
:mod:`.chute_measure`; checks: :mod:`.chute_checks`; figures: :mod:`.chute_figures`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..base import Analysis, Case, Figure, pm, tc_caveats
from . import chute_figures as figs
from .chute_cases import cases as _cases
from .chute_checks import all_checks, tc_quoted, tc_unchanged
from .chute_measure import ChuteRun, summarise_all

__all__ = ["analyse", "cases"]


def cases(quick: bool) -> list[Case]:
    """The chute runs (:func:`.chute_cases.cases`)."""
    return _cases(quick)


def _pick(runs: Mapping[str, ChuteRun], names: list[str]) -> list[ChuteRun]:
    return [runs[n] for n in names if n in runs]


def _figures(runs: Mapping[str, ChuteRun], out: Path) -> list[Figure]:
    made: list[Figure] = []

    def add(path: Path | None, caption: str) -> None:
        if path is not None:
            made.append(Figure(path, caption))

    angle = _pick(runs, ["chute-20-flat", "chute-30-bumpy", "chute-40-flat", "chute-30-flat"])
    add(figs.energy_history({r.name: r for r in angle}, "chute-30-bumpy",
                            out / "chute_energy_history.png"),
        "Fig 2.4 form: kinetic energy per disc against time; the 30° bumpy chute with its "
        "mean and Campbell's ±20 % band; the angle series (log scale).")
    main = _pick(runs, ["chute-20-flat", "chute-30-bumpy", "chute-40-flat"])
    add(figs.profiles_figure(main, [f"{r.name} ({r.base} base)" for r in main],
                             out / "chute_profiles.png",
                             "Fig 3.1/3.2 form: profiles against y/H (10 × 4, ε_p 0.6, ε_w 0.8)"),
        "Fig 3.1/3.2 form: u/u_max, ν, T and the rotational T against y/H at 20° (flat base), "
        "30° (bumpy base) and 40° (flat base, accelerating: the window's mean).")
    add(figs.stress_figure(_pick(runs, ["chute-30-bumpy", "chute-20-flat", "chute-40-flat"]),
                           out / "chute_stresses.png"),
        "Stresses against y/H three ways: momentum balance from the free surface (band: 2σ), "
        "kinetic + collisional (stress statistic), the base's wall stress.")
    add(figs.plug_figure(_pick(runs, ["chute-20-flat", "chute-20-bumpy"]),
                         out / "chute_plug_20.png"),
        "Fig 3.14 form: the 20° bed, ν and u/u_max against y/H (π/4 and ν_m marked), and its "
        "energy: it stops.")
    add(figs.angles_figure(_pick(runs, ["chute-40-flat", "chute-40-bumpy", "chute-30-bumpy"]),
                           out / "chute_angles.png"),
        "Fig 3.33 form: the collision-angle distribution P(θ) of the 40° chutes (C9) and the "
        "steady 30° bumpy chute, ±2σ; the approach quadrant shaded.")
    flat = _pick(runs, ["chute-24-flat", "chute-26-flat", "chute-30-flat"])
    add(figs.flat_scan_figure(flat, runs.get("chute-30-bumpy"), out / "chute_flat_base.png"),
        "Why the bumpy base: on Campbell's flat sticking base the force ratio stays ≈ 0.5 in "
        "the dense phase; the 30° bed accelerates; the bumps give tan 30°.")
    tc = _pick(runs, ["chute-30-bumpy-tc1e-4", "chute-30-bumpy", "chute-30-bumpy-tc1e-6"])
    add(figs.tc_figure(tc if len(tc) > 1 else [], out / "chute_tc.png"),
        "The 30° bumpy chute at t_c = 1e-4, 1e-5 (default), 1e-6: profiles, energy and the "
        "share of pair collisions the TC model made elastic.")
    series = [
        ("depth, variable ε", _pick(runs, [f"chute-30-bumpy-{n}x4-var" for n in (5, 10, 13)]
                                    + ["chute-30-bumpy-5x4"])),
        ("ε_p and ε_w", _pick(runs, ["chute-30-bumpy-ep0.1", "chute-30-bumpy",
                                     "chute-30-bumpy-ep0.8", "chute-30-bumpy-ew0.6",
                                     "chute-30-bumpy-ew1"])),
        ("width, soft discs", _pick(runs, ["chute-30-bumpy", "chute-30-bumpy-10x8",
                                           "chute-30-bumpy-lammps"])),
        ("seeds (bump heights)", _pick(runs, ["chute-30-bumpy", "chute-30-bumpy-seed2",
                                              "chute-30-bumpy-seed3"])),
    ]
    add(figs.series_figure([(t, rs, [_short(r) for r in rs]) for t, rs in series
                            if len(rs) > 1], out / "chute_series.png"),
        "The series against y/H: depth (variable ε), ε_p and ε_w, width and soft discs, seeds "
        "(bumpy base). The shallow 40° beds (C7, C8) accelerate into a dilute spray: no "
        "profile to show.")
    return made


def _short(r: ChuteRun) -> str:
    law = "var ε" if r.law != "constant" else f"ε_p {r.e_p:g}"
    steady = "steady" if r.steady else "unsteady"
    engine = ", LAMMPS" if r.engine == "lammps" else ""
    seed = "" if r.seed == 12345 else f", seed {r.seed}"
    return f"{r.rows}×{r.columns}, {law}, ε_w {r.e_w:g}{engine}{seed} ({steady})"


def _table(runs: Mapping[str, ChuteRun]) -> str:
    head = ("| run | α | base | discs | ε_p / ε_w | engine | window | KE/N | trend | ±20 % | "
            "ratio | tan α | u_max | slip | H | ν max | TC share | wall s |\n"
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    rows = []
    for r in runs.values():
        law = "var" if r.law != "constant" else f"{r.e_p:g}"
        rows.append(
            f"| {r.name} | {r.angle:g}° | {r.base} | {r.rows}×{r.columns} | {law} / {r.e_w:g} | "
            f"{r.engine}{'' if r.tc is None else f' t_c {r.tc:g}'} | {r.start:.0f}-{r.t[-1]:.0f} | "
            f"{pm(r.energy_mean, r.energy_err)} | {pm(r.trend, r.trend_err)} | "
            f"{100 * r.within:.0f} % | "
            f"{pm(r.ratio, r.ratio_err)} | {r.tan_alpha:.3f} | {pm(r.u_max, r.u_max_err)} | "
            f"{pm(r.slip, r.slip_err)} | {r.depth:.2f} | {np.nanmax(r.profiles['nu']):.2f} | "
            f"{'—' if not np.isfinite(r.tc_share) else f'{100 * r.tc_share:.1f} %'} | "
            f"{r.wall_seconds:.0f} |")
    return head + "\n" + "\n".join(rows)


HOW = """\
Dimensionless particle units: d = 1, m = 1, g = 1 (times √(d/g), speeds √(gd), energies m g d,
2D stresses m g/d); Campbell used R = d/2. Hard discs in the event-driven engine unless the run
says LAMMPS. Campbell's definitions: H = 2 × the mass-mean centre height above the base plane;
u_max the fastest strip of the bed (ν ≥ 0.05); slip = u of the strip 0 < y < 1 over u_max;
kinetic energy per disc = translation + rotation with the mean flow. **Convergence**: Campbell's
criterion (§2.5), the fitted change of the energy over the production window below 20 % of its
mean (`demstudy.analysis.steady`) within 2σ (σ from the scatter of 8 block means about the
line: the energy of 40 discs wanders by ±30 % over hundreds of √(d/g) even when the momentum
balance holds), with the share of samples inside ±20 % reported; **and** the steady momentum
balance, base force ratio |F_x/F_y| = tan α within 2σ + 0.01. Errors: block jackknife over the
production window (1σ in the table). "Little effect" / "insignificant": within 2σ + 10 % with
the block errors ("reproduced"), or only with σ raised to √2 × the spread of three seeds of the
30° bumpy chute ("partly"; seeds change the initial state and the random bump heights, and one
seed settles into a slow dense state, so this tolerance is wide).

**Which base.** Campbell's flat base with sticking contacts does not give a steady dense 30°
flow: its basal discs roll and a dense bed passes at most ≈ 0.5 of its weight as shear, so a
dense steady flow exists only up to ≈ 25° (rows chute-24/26/30-flat: the dense-phase ratio at
t = 25-200 against tan α, and docs/studies/campbell1982-chute30.md); at 30° the bed accelerates
for ~1000 √(d/g) into a levitated state over a hot dilute basal layer. Random bumps of
diameter d at spacing 1.2 d let the base push back with normal impulses: the 30° bed is steady
there. So every statement about a *steady* chute is tested on the bumpy base; the 40° and 20°
statements as the thesis ran them (flat base) and on the bumps beside it; ε_p = 0.8 and the
constant-ε 5 × 4 bed on the bumps, where the reference 10 × 4 at ε_p = 0.6 is steady (on the
flat base every 30° bed accelerates, which would make their non-convergence trivially true).
Campbell's variable ε acts on pair collisions only (the scene's `[contact.law] model =
"campbell-exp"`; the thesis applied it to the wall too).
"""


def _tc_text(runs: Mapping[str, ChuteRun]) -> str:
    tc = _pick(runs, ["chute-30-bumpy-tc1e-4", "chute-30-bumpy", "chute-30-bumpy-tc1e-6"])
    lines = [f"* t_c = {r.tc:g}: {100 * r.tc_share:.1f} % of pair collisions TC-elastic, "
             f"u_max {pm(r.u_max, r.u_max_err)}, KE/N {pm(r.energy_mean, r.energy_err)}, "
             f"H {r.depth:.2f}, ratio {pm(r.ratio, r.ratio_err)}" for r in tc]
    rest = _pick(runs, ["chute-20-flat", "chute-20-bumpy"])
    lines += [f"* {r.name} (comes to rest): {100 * r.tc_share:.0f} % TC-elastic over the run"
              for r in rest]
    text = "\n".join(lines)
    seed3 = runs.get("chute-30-bumpy-seed3")
    if len(tc) == 3:
        shares = " → ".join(f"{100 * r.tc_share:.0f} %" for r in tc)
        text += f"""

**The flowing 30° bed.** At the default t_c = 1e-5 the share is {100 * tc[1].tc_share:.0f} %
(the engine warns above 5 %) and it changes with t_c ({shares} for 1e-4 → 1e-6): the dense bed
is close to inelastic collapse, and a smaller t_c lets clusters of rapid collisions run further
before the model steps in. The flow is judged in check 'TC model' (u_max, KE/N, H within 2σ +
10 %, or only within the seed spread)""" + ("" if seed3 is None else f"""; another seed of the
same chute (seed 3) settles into a slow dense state, u_max {seed3.u_max:.1f}, with
{100 * seed3.tc_share:.0f} % TC-elastic collisions""") + "."
    return text + """

**The resting 20° bed.** The TC model (Luding & McNamara) makes a pair collision elastic when
either partner collided less than t_c earlier; it stands in for the lasting contacts hard discs
do not have. A *resting* bed is necessarily all-TC: hard discs carry a static load only through
collisions, and a disc resting under gravity on others with restitution < 1 would bounce
infinitely often in finite time (inelastic collapse). With the TC model each such disc bounces
elastically on its neighbours every ~t_c at a height ~g t_c² (kinetic energy ~(g t_c)², nothing
left to dissipate), so once the bed stops every collision is TC-elastic (the 20° shares above
include the flowing start) and the cost is ~1/t_c events per disc and √(d/g) (the 20° runs'
wall seconds in the table). The resting packing (ν, the dense centre) is held by these
micro-bounces, which carry the static load but no flow; it is expected not to depend on t_c
(not rerun at other t_c)."""


def analyse(runs: Mapping[str, Path], out: Path, quick: bool) -> Analysis:
    """Figures into ``out``, one check per statement, the runs' table (module doc)."""
    found = summarise_all(dict(runs))
    out.mkdir(parents=True, exist_ok=True)
    checks = all_checks(found, quick)
    shares = {n: (r.tc_share, math.nan if r.tc is None else r.tc) for n, r in found.items()}
    tc_caveats(checks, shares, tc_unchanged(found), tc_quoted(found), unit="√(d/g)")
    sections = [("Chutes: how they were measured, and which base", HOW)]
    if found:
        sections.append(("Chutes: every run", _table(found)))
        sections.append(("Chutes: the TC model's t_c", _tc_text(found)))
    return Analysis(checks=checks, figures=_figures(found, out), sections=sections)
