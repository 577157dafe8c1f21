"""Gutt (1989), the theory part: Chapters 1 and 2 solved with demstudy.theory.gutt_spin and
gutt_walls (no runs). Figures in the thesis's forms (demstudy.plots.gutt_theory, shared with
analysis/gutt_theory_figures.py) and one check per statement of the digest's §1.6/§1.8 and
§2.5 (:mod:`.theory_checks`).

Units: Ch. 1 in arbitrary units as the thesis (d = 1); Ch. 2 in dimensionless particle units
d = 1, m = 1, no gravity, the wall speed u_w = 1 sets the time scale.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from ...plots import gutt_theory as gt
from ...theory import wall_couette_sweep
from ..base import Analysis, Case, Figure
from . import theory_checks as tc


def cases(quick: bool) -> list[Case]:
    """The theory needs no runs."""
    return []


def figures(out: Path) -> list[Figure]:
    spin = gt.SPIN
    a = gt.spin_couette_ratio(spin, 1.1 * gt.spin_couette_threshold(spin))[0]
    made = [Figure(gt.fig_1_3(out), "Fig 1.3: uniform cooling with spin (S1), cases a-c; "
                                    "arbitrary units, assumed constants"),
            Figure(gt.fig_1_5(out), "Fig 1.5: v and W between vibrating plates (S2), cases "
                                    "a-c; arbitrary units, assumed constants")]
    path, _ = gt.couette_figure(out, "1.7", "case 1: W_wall = 0, v_wall = 0.5", 0.5, 0.0)
    made.append(Figure(path, "Fig 1.7: Couette with spin (S3), case 1 (W_wall = 0)"))
    path, _ = gt.couette_figure(out, "1.8", "case 2: v_wall = 0.005, W_wall = 2a·0.5/d", 0.005,
                                2 * a * 0.5 / spin.d)
    made.append(Figure(path, "Fig 1.8: Couette with spin (S3), case 2 (v_wall very small)"))
    path, _ = gt.fig_2_4_to_2_9(out)
    made.append(Figure(path, "Figs 2.4-2.9: three-slip Couette against wall roughness ⟨k_τ²⟩, "
                             "curves a, b, c (e_w = .96, .92, .84); thesis constants"))
    path, _ = gt.fig_2_10(out)
    made.append(Figure(path, "Fig 2.10: profiles v/u_w, u/u_w, s/d at ⟨k_τ²⟩ = .0625, .125, "
                             ".25 (e_w = .84)"))
    path, _ = gt.fig_2_11(out)
    made.append(Figure(path, "Fig 2.11: v/u_w profiles with q = .5, t_w = 1 or e_w = .96"))
    return made


def checks() -> list:
    sweeps = {f"{label} (e_w = {e_w})": wall_couette_sweep(gt.K2, gt.WALL, e_w=e_w)
              for label, e_w in gt.CURVES}
    return [tc.cooling_ratio(), tc.cooling_decay(), *tc.plates(), *tc.couette_spin(),
            tc.spin_raises(), tc.sigma_ratio_trend(sweeps), tc.slip_trend(sweeps),
            tc.v_wall_trend(sweeps), tc.stresses_trend(sweeps), tc.regimes(gt.WALL),
            tc.variants(gt.WALL), tc.v_wall_fraction(sweeps), tc.slip_insensitive(sweeps)]


SECTION = (
    "Chapters 1 and 2 solved with demstudy.theory (docs/theory-gutt.md): Ch. 1 in arbitrary "
    "units with assumed constants (the thesis prints none; GuttSpinConstants() = the digest's "
    "derived proportionalities at e = 0.6, β = 0.5; the IVP and analytic checks repeat over "
    "three more sets), Ch. 2 with the fig 2.4 caption's constants (γ = .16, q = .25, r = 1, "
    "t = 1, q_w = 1, r_w = 1, t_w = .5, h = 10 d, Δh = 3.25 d), particle units d = 1 and the "
    "wall speed u_w = 1. The thesis states only trends (its figures are lost in the OCR), so "
    "every check tests a trend or an identity with a stated tolerance.")


def analyse(runs: Mapping[str, Path], out: Path, quick: bool) -> Analysis:
    out.mkdir(parents=True, exist_ok=True)
    return Analysis(checks=checks(), figures=figures(out),
                    sections=[("Theory (Chapters 1 and 2)", SECTION)])
