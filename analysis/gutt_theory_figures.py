"""Gutt's (1989) continuum-theory figures redrawn from demstudy.theory.gutt_spin (Ch. 1) and
demstudy.theory.gutt_walls (Ch. 2); the thesis's images are missing from the OCR, so these are
the figures in the thesis's forms (captions, digest §6), not copies. Text: docs/theory-gutt.md.
The drawing is demstudy.plots.gutt_theory, shared with the gutt1989 study's theory part.

Ch. 1 figures (1.3, 1.5, 1.7, 1.8) are in arbitrary units as in the thesis, with d = 1 and the
assumed constants GuttSpinConstants() (the thesis prints none). Ch. 2 figures (2.4-2.11) use the
fig 2.4 caption's constants, particle units d = 1 and the wall speed u_w = 1.

Writes docs/figures/theory/gutt/*.png and prints the numbers quoted in docs/theory-gutt.md.

    python analysis/gutt_theory_figures.py      # about 10 s (4 s of CPU)
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from demstudy.plots.gutt_theory import (
    CURVES,
    K2,
    SPIN,
    couette_figure,
    fig_1_3,
    fig_1_5,
    fig_2_4_to_2_9,
    fig_2_10,
    fig_2_11,
)
from demstudy.theory import (
    GuttWallConstants,
    spin_cooling_analytic,
    spin_couette_analytic,
    spin_couette_ratio,
    spin_couette_threshold,
    spin_plates_analytic,
    wall_simple_shear_roughness,
)

OUT = Path(__file__).resolve().parents[1] / "docs" / "figures" / "theory" / "gutt"


def main() -> None:
    paths = [fig_1_3(OUT), fig_1_5(OUT)]
    a = spin_couette_ratio(SPIN, 1.1 * spin_couette_threshold(SPIN))[0]
    path, one = couette_figure(OUT, "1.7", "case 1: W_wall = 0, v_wall = 0.5", 0.5, 0.0)
    paths.append(path)
    path, two = couette_figure(OUT, "1.8", "case 2: v_wall = 0.005, W_wall = 2a·0.5/d", 0.005,
                               2 * a * 0.5 / SPIN.d)
    paths.append(path)
    path, sweeps = fig_2_4_to_2_9(OUT)
    paths.append(path)
    path, profiles = fig_2_10(OUT)
    paths.append(path)
    path, variants = fig_2_11(OUT)
    paths.append(path)
    for path in paths:
        print(f"wrote {path}")
    one = {k: v for k, v in one.items() if k != "solution"}
    two = {k: v for k, v in two.items() if k != "solution"}
    # numbers for docs/theory-gutt.md
    print(f"Ch1 constants: {SPIN}")
    print(f"S1 a = {spin_cooling_analytic(SPIN, 1.0, np.zeros(1)).a:.4f}, "
          f"S2 a = {spin_plates_analytic(SPIN, 1, 1).a:.4f}, "
          f"lambda = {1 / math.sqrt(-spin_plates_analytic(SPIN, 1, 1).curvature):.4f}")
    print(f"S3 threshold = {spin_couette_threshold(SPIN):.4f}; case 1 {one}; case 2 {two}")
    for lam in (2.0, 5.0, 20.0):
        s4 = spin_couette_analytic(SPIN, lam, 4.0, 1.0, 1.3)
        print(f"S4 lambda = {lam}: sigma0/p0 spin {s4.sigma_ratio_spin:.4f} no spin "
              f"{s4.sigma_ratio_no_spin:.4f}, a2 = {s4.a2:.4f}")
    for label, sw in sweeps.items():
        peak = int(np.argmax(sw.v_wall_ratio))
        i05 = int(np.argmin(abs(K2 - 0.5)))
        print(f"curve {label}: R(k2=1e-4) = {sw.sigma_ratio[0]:.4f}, R(0.5) = "
              f"{sw.sigma_ratio[i05]:.4f}; v/u_w max {sw.v_wall_ratio[peak]:.4f} at k2 = "
              f"{K2[peak]:.3f}, at 0.5 {sw.v_wall_ratio[i05]:.4f}; u_s/u_w(0.5) = "
              f"{sw.slip_ratio[i05]:.4f}; stress(0.5) = {sw.stress_norm[i05]:.3f}, "
              f"pressure(0.5) = {sw.pressure_norm[i05]:.3f}; simple shear k2* = "
              f"{wall_simple_shear_roughness(GuttWallConstants(e_w=dict(CURVES)[label])):.4f}")
    for sol in profiles:
        print(f"fig 2.10 k2 = {sol.constants.k2}: R = {sol.sigma_ratio:.4f}, omega2 = "
              f"{sol.omega2:.3e}, Q_a/Q_g = {sol.flux_ratio:.4f}, u_s = {sol.u_s:.4f}, "
              f"v(h/2) = {sol.v_wall:.4f}, v(0) = {2 * sol.v0:.4f}, s(0) = {sol.s[100]:.4f}, "
              f"s(h/2) = {sol.s[-1]:.4f}")
    for title, sols, _base in variants:
        print(title, [f"k2 {s.constants.k2}: v(h/2) {s.v_wall:.4f}, u_s {s.u_s:.4f}, "
                      f"Q_a/Q_g {s.flux_ratio:.3f}" for s in sols])


if __name__ == "__main__":
    main()
