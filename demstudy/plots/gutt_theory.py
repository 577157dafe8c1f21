"""Gutt's (1989) continuum-theory figures in the thesis's forms, drawn from
demstudy.theory.gutt_spin (Ch. 1) and demstudy.theory.gutt_walls (Ch. 2). The thesis's images
are missing from the OCR, so these are the figures in its forms (captions, digest §6), not
copies. Used by analysis/gutt_theory_figures.py (docs/theory-gutt.md) and the gutt1989 study's
theory part; each function writes one PNG into ``out`` and returns its path (and the solutions
it drew where the callers need their numbers).

Units: Ch. 1 figures (1.3, 1.5, 1.7, 1.8) in arbitrary units as in the thesis, d = 1, with the
assumed constants GuttSpinConstants() (the thesis prints none). Ch. 2 figures (2.4-2.11):
the fig 2.4 caption's constants, dimensionless particle units d = 1 and the wall speed
u_w = 1 (no gravity).
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..theory import (  # noqa: E402
    GuttSpinConstants,
    GuttWallConstants,
    spin_cooling,
    spin_couette,
    spin_couette_ratio,
    spin_couette_threshold,
    spin_plates,
    spin_plates_analytic,
    wall_couette,
    wall_couette_sweep,
    wall_simple_shear_roughness,
)
from .common import save_with_note  # noqa: E402

__all__ = ["CURVES", "K2", "SPIN", "WALL", "couette_figure", "fig_1_3", "fig_1_5",
           "fig_2_10", "fig_2_11", "fig_2_4_to_2_9"]

SPIN = GuttSpinConstants()
WALL = GuttWallConstants()
CH1_NOTE = ("arbitrary units (d = 1); constants GuttSpinConstants() defaults, all assumed: "
            "e = 0.6, β = 0.5 via the digest's derived proportionalities")
CH2_NOTE = ("γ = .16, q = .25, r = 1, t = 1, q_w = 1, r_w = 1, t_w = .5, h = 10 d, Δh = 3.25 d "
            "(fig 2.4 caption); units d = 1, u_w = 1")


def save(fig, out: Path, name: str, note: str) -> Path:
    """Write ``fig`` as out/name with the constants' note at the bottom; close it."""
    return save_with_note(fig, out / name, note, bottom=0.03, fontsize=7.5)


# -- Ch. 1 ---------------------------------------------------------------------------------------
def fig_1_3(out: Path) -> Path:
    """Uniform cooling: (a) W(0) = 2a v(0)/d, (b) W(0) = 0, (c) small v(0)."""
    t = np.concatenate([[0.0], np.geomspace(1e-3, 1e3, 400)])
    a = spin_cooling(SPIN, 1.0, 0.0, t[:2]).a
    cases = [("(a) W(0) = 2a v(0)/d", 1.0, 2 * a / SPIN.d), ("(b) W(0) = 0", 1.0, 0.0),
             ("(c) v(0) = 0.001 (seed)", 1e-3, 2 * a / SPIN.d)]
    fig, axes = plt.subplots(2, 3, figsize=(13, 6.5), sharex=True)
    for (title, v0, w0), top, bottom in zip(cases, axes[0], axes[1], strict=True):
        sol = spin_cooling(SPIN, v0, w0, t)
        top.plot(t[1:], sol.v[1:], "C0-", label="v")
        top.plot(t[1:], sol.W[1:], "C3--", label="W")
        top.set(xscale="log", yscale="log", ylabel="v, W [arb. units]", title=title,
                ylim=(1e-4, 10))
        top.legend(loc="lower left", fontsize=8)
        bottom.plot(t[1:], sol.ratio[1:], "k-", label="d W/(2v)")
        bottom.axhline(a, color="C2", ls=":", label=f"a = {a:.3f} (1.25)")
        bottom.set(xscale="log", xlabel="t [arb. units]", ylabel="d W/(2 v)",
                   ylim=(0, 2.5 * a))
        bottom.legend(loc="upper right", fontsize=8)
    fig.suptitle("Fig 1.3: time evolution of v and W in a uniform system (S1)")
    return save(fig, out, "fig1_3.png", CH1_NOTE)


def fig_1_5(out: Path) -> Path:
    """Vibrating plates: (a) W_wall = 2a v_wall/d, (b) W_wall = 0, (c) v_wall very small."""
    lam = 1 / math.sqrt(-spin_plates_analytic(SPIN, 1.0, 1.0).curvature)
    h = 8 * lam
    exact = spin_plates_analytic(SPIN, h, 1.0)
    w_a = float(exact.W[-1])
    cases = [("(a) W_wall = 2a v_wall/d", 1.0, w_a), ("(b) W_wall = 0", 1.0, 0.0),
             ("(c) v_wall = 0.01", 0.01, w_a)]
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2))
    for (title, vw, ww), ax in zip(cases, axes, strict=True):
        sol = spin_plates(SPIN, h, vw, ww)
        ax.plot(sol.y / lam, sol.v, "C0-", label="v")
        ax.plot(sol.y / lam, sol.W, "C3--", label="W")
        if title.startswith("(a)"):
            ax.plot(exact.y[::8] / lam, exact.v[::8], "C0o", ms=3, label="v, cosh (1.26)")
        ax.set(xlabel="x/λ (x = 0 mid-channel)", ylabel="v, W [arb. units]", title=title,
               yscale="log", ylim=(1e-3, 5))
        ax.legend(loc="upper center", fontsize=8)
    fig.suptitle(f"Fig 1.5: v and W between vibrating plates (S2), h = 8λ, "
                 f"λ = {lam:.3f} d, a = {exact.a:.3f}")
    return save(fig, out, "fig1_5.png", CH1_NOTE)


def couette_figure(out: Path, number: str, case: str, v_wall: float, w_wall: float
                   ) -> tuple[Path, dict]:
    """Figs 1.7/1.8: S3 at 1.1 × the threshold σ0/p0, h = 10 d; also the numbers."""
    thr = spin_couette_threshold(SPIN)
    ratio = 1.1 * thr
    a, k = spin_couette_ratio(SPIN, ratio)
    h = 10.0
    sol = spin_couette(SPIN, ratio, h, v_wall, w_wall, n=401)
    fig, (ax1, ax2, ax3) = plt.subplots(1, 3, figsize=(13, 4.2))
    ax1.plot(sol.y, sol.v, "C0-", label="v")
    ax1.plot(sol.y, sol.W, "C3--", label="W")
    ax1.plot(sol.y, 2 * a * sol.v / SPIN.d, "C3:", lw=1, label="2a v/d, a from (1.32)")
    ax1.set(xlabel="y [d]", ylabel="v, W [arb. units]", title="(a) thermal velocities")
    ax1.legend(loc="lower center", fontsize=8)
    ax2.plot(sol.y, sol.u, "C0-")
    ax2.set(xlabel="y [d]", ylabel="u_x [arb. units]",
            title=f"(b) mean flow velocity, u(h/2) = {sol.u_wall:.3g}")
    ax3.plot(sol.y, sol.omega_z, "C0-")
    ax3.set(xlabel="y [d]", ylabel="ω_z [arb. units / d]", title="(c) mean spin ω_z = −u'/2")
    fig.suptitle(f"Fig {number}: Couette with spin (S3), {case}; σ0/p0 = 1.1 × threshold "
                 f"= {ratio:.4f}, h = 10 d")
    path = save(fig, out, f"fig{number.replace('.', '_')}.png", CH1_NOTE)
    return path, {"ratio": ratio, "a": a, "k": k, "u_wall": sol.u_wall,
                  "centre_ratio": float(sol.ratio[len(sol.y) // 2]), "solution": sol}


# -- Ch. 2 ---------------------------------------------------------------------------------------
CURVES = [("a", 0.96), ("b", 0.92), ("c", 0.84)]
K2 = np.concatenate([np.geomspace(1e-4, 0.02, 30), np.linspace(0.021, 0.5, 120)])


def fig_2_4_to_2_9(out: Path) -> tuple[Path, dict]:
    """Figs 2.4-2.9 against ⟨k_τ²⟩ for the curves a, b, c; also the sweeps."""
    panels = [("sigma_ratio", "2.4", "σ0/p0"), ("slip_ratio", "2.5", "u_s/u_w"),
              ("flux_ratio", "2.6", "Q_a/Q_g"), ("v_wall_ratio", "2.7", "v(h/2)/u_w"),
              ("stress_norm", "2.8", "σ0 / (ρ_p d² (2u_w/h)²)"),
              ("pressure_norm", "2.9", "p0 / (ρ_p d² (2u_w/h)²)")]
    fig, axes = plt.subplots(2, 3, figsize=(13, 7.5))
    sweeps = {}
    for label, e_w in CURVES:
        sweeps[label] = wall_couette_sweep(K2, WALL, e_w=e_w)
    for (key, number, name), ax in zip(panels, axes.flat, strict=True):
        for (label, e_w), colour in zip(CURVES, ("C0", "C1", "C3"), strict=True):
            ax.plot(K2, getattr(sweeps[label], key), color=colour,
                    label=f"{label}: e_w = {e_w}")
        ax.set(xlabel="⟨k_τ²⟩", ylabel=name, title=f"fig {number}")
        if key == "flux_ratio":
            ax.axhline(1, color="grey", lw=0.8, ls=":")
            ax.set(yscale="log")
    axes.flat[0].legend(loc="lower right", fontsize=8)
    axes.flat[3].legend(loc="lower right", fontsize=8)
    fig.suptitle("Figs 2.4-2.9: gravity-free Couette with three-slip walls against wall "
                 "roughness (fixed wall speed)")
    return save(fig, out, "fig2_4-2_9.png", CH2_NOTE + "; ρ = ρ_p as the thesis's L775 formula"
                ), sweeps


def profile_panels(axes, constants: GuttWallConstants, only_v: bool = False) -> list:
    sols = []
    for number, k2 in (("1", 0.0625), ("2", 0.125), ("3", 0.25)):
        sol = wall_couette(constants, n=201, k2=k2)
        sols.append(sol)
        label = f"{number}: ⟨k_τ²⟩ = {k2}, Q_a/Q_g = {sol.flux_ratio:.2f}"
        axes[0].plot(sol.y, sol.v / constants.u_w, label=label)
        if not only_v:
            axes[1].plot(sol.y, sol.u / constants.u_w, label=label)
            axes[2].plot(sol.y, sol.s / constants.d, label=label)
    return sols


def fig_2_10(out: Path) -> tuple[Path, list]:
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.4))
    sols = profile_panels(axes, WALL)
    axes[0].set(xlabel="y [d]", ylabel="v/u_w", title="(a) thermal velocity", ylim=(0, None))
    axes[1].set(xlabel="y [d]", ylabel="u/u_w", title="(b) mean velocity (u_w = u_s + u(h/2))")
    axes[2].set(xlabel="y [d]", ylabel="s/d", title="(c) mean surface spacing", ylim=(0, None))
    axes[0].legend(loc="lower center", fontsize=8)
    fig.suptitle("Fig 2.10: profiles across the channel, e_w = 0.84")
    return save(fig, out, "fig2_10.png", CH2_NOTE), sols


def fig_2_11(out: Path) -> tuple[Path, list]:
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.4), sharey=True)
    changes = [("(a) q = 0.5", {"q": 0.5}), ("(b) t_w = 1.0", {"t_w": 1.0}),
               ("(c) e_w = 0.96", {"e_w": 0.96})]
    variants = []
    for (title, change), ax in zip(changes, axes, strict=True):
        constants = GuttWallConstants(**change)
        sols = profile_panels([ax], constants, only_v=True)
        base = profile_panels([ax], WALL, only_v=True)
        for line, colour in zip(ax.lines[3:], ("C0", "C1", "C2"), strict=True):
            line.set(ls=":", lw=1, color=colour, label="_nolegend_")
        star = wall_simple_shear_roughness(constants)
        ax.set(xlabel="y [d]", title=f"{title}; simple shear at ⟨k_τ²⟩ = {star:.3g}",
               ylim=(0, 0.45))
        ax.legend(loc="upper center", fontsize=7.5, title="dotted: fig 2.10 (a)",
                  title_fontsize=7.5)
        variants.append((title, sols, base))
    axes[0].set(ylabel="v/u_w")
    fig.suptitle("Fig 2.11: v/u_w profiles as fig 2.10 (a) with one constant changed")
    return save(fig, out, "fig2_11.png", CH2_NOTE), variants
