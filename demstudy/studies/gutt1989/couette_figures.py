"""Figures of the Couette part of the Gutt (1989) study: the runs on Gutt's figs 2.4, 2.5, 2.7
(against the measured ⟨k_τ²⟩) and on fig 2.10's profiles, with his Ch. 2 solution overlaid.

Dimensionless particle units: d = 1, m = 1; no gravity: the wall speed u_w = 1 sets the time
scale. y' = y − h/2 from the channel's centre.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from ...plots.common import save_with_note  # noqa: E402
from ...plots.gutt_theory import K2, WALL  # noqa: E402
from ...theory import wall_couette_sweep  # noqa: E402
from ..base import Figure  # noqa: E402
from .couette_measure import CouetteRun, theory  # noqa: E402

E_COLOURS = {0.96: "C0", 0.92: "C1", 0.84: "C3"}
NOTE = ("d = 1, m = 1, u_w = 1 (no gravity); theory: Gutt's Ch. 2 solution, thesis constants "
        "(γ = .16, q = .25, r = t = 1, t_w = .5, q_w = r_w = 1, h = 10 d, Δh = 3.25 d) unless "
        "marked fitted (t, q, γ from the run's bulk, r and the wall constants the thesis's)")


def _save(fig, out: Path, name: str, caption: str) -> Figure:
    return Figure(save_with_note(fig, out / name, NOTE, wrap=True), caption)


def against_roughness(runs: Sequence[CouetteRun], out: Path) -> Figure:
    """σ0/p0, u_s/u_w and v(h/2)/u_w against ⟨k_τ²⟩: theory curves a, b, c and the runs."""
    panels = (("R", "sigma_ratio", "σ0/p0", "fig 2.4"),
              ("slip", "slip_ratio", "u_s/u_w", "fig 2.5"),
              ("v_wall", "v_wall_ratio", "v(h/2)/u_w", "fig 2.7"))
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.8))
    sweeps = {e: wall_couette_sweep(K2, WALL, e_w=e) for e in E_COLOURS}
    for (key, attr, label, number), ax in zip(panels, axes, strict=True):
        for e, colour in E_COLOURS.items():
            ax.plot(K2, getattr(sweeps[e], attr), color=colour, lw=1.2,
                    label=f"theory, e_w = {e}")
        for r in runs:
            colour = E_COLOURS.get(r.e_w, "k")
            marker = "o" if r.dim == 3 else "s"
            ax.errorbar(r.v("k2"), r.v(key), xerr=r.e("k2"), yerr=r.e(key), fmt=marker,
                        color=colour, ms=5, mfc="none" if r.dim == 2 else colour, capsize=2)
            fit = theory(r, fitted=True, n=2)
            if fit is not None:
                value = {"R": fit.sigma_ratio, "slip": fit.u_s / r.u_w,
                         "v_wall": fit.v_wall / r.u_w}[key]
                ax.plot(r.v("k2"), value, "x", color=colour, ms=6)
        ax.set(xlabel="⟨k_τ²⟩ (measured for the runs)", ylabel=label,
               title=f"{number}: {label}", xlim=(-0.01, 0.5))
    handles = [plt.Line2D([], [], color=c, label=f"theory, e_w = {e}")
               for e, c in E_COLOURS.items()]
    handles += [plt.Line2D([], [], marker="o", ls="", color="grey", label="3D spheres"),
                plt.Line2D([], [], marker="s", ls="", color="grey", mfc="none",
                           label="2D discs"),
                plt.Line2D([], [], marker="x", ls="", color="grey",
                           label="theory with fitted t, q, γ")]
    axes[2].legend(handles=handles, loc="lower right", fontsize=7.5)
    fig.suptitle("Event-driven Couette runs between bumpy frictionless walls on Gutt's figs "
                 "2.4, 2.5, 2.7 (colour: e_w)")
    return _save(fig, out, "couette-vs-roughness.png",
                 "σ0/p0, slip u_s/u_w and wall thermal velocity v(h/2)/u_w against the "
                 "measured wall roughness ⟨k_τ²⟩: Gutt's theory (lines, curves a-c) and the "
                 "2D/3D runs (symbols; × the theory with t, q, γ fitted to the run's bulk)")


def profiles(runs: Sequence[CouetteRun], out: Path, dim: int) -> Figure:
    """v/u_w, u/u_w and φ/φ_cp across the channel with the theory at each run's ⟨k_τ²⟩."""
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.8))
    for i, r in enumerate(runs):
        colour = f"C{i}"
        y = r.arrays["y"]
        label = f"⟨k_τ²⟩ = {r.v('k2'):.3f} ({r.name.split('-')[2]})"
        for ax, key in zip(axes, ("v", "u", "phi"), strict=True):
            ax.errorbar(y, r.arrays[key], yerr=r.arrays[f"{key}_err"], fmt="o", ms=3,
                        color=colour, label=label if key == "phi" else None)
        for fitted, style in ((False, "-"), (True, "--")):
            sol = theory(r, fitted=fitted)
            if sol is None:
                continue
            axes[0].plot(sol.y, sol.v / r.u_w, style, color=colour, lw=1)
            axes[1].plot(sol.y, sol.u / r.u_w, style, color=colour, lw=1)
            axes[2].plot(sol.y, 1 - 3 * sol.s / sol.constants.d, style, color=colour, lw=1)
    axes[0].set(xlabel="y' = y − h/2 [d]", ylabel="v/u_w", title="(a) thermal velocity",
                ylim=(0, None))
    axes[1].set(xlabel="y' [d]", ylabel="u/u_w", title="(b) mean velocity (walls at ±1)")
    axes[2].set(xlabel="y' [d]", ylabel="φ/φ_cp (theory: 1 − 3s/d)",
                title="(c) solid fraction", ylim=(-0.45, 1.1))
    axes[2].legend(loc="lower center", fontsize=7.5,
                   title="runs (dots); theory: thesis (—), fitted (--)", title_fontsize=7.5)
    kind = "3D spheres" if dim == 3 else "2D discs"
    fig.suptitle(f"Profiles across the channel, {kind}, e_w = 0.84 (as Gutt's fig 2.10)")
    return _save(fig, out, f"couette-profiles-{dim}d.png",
                 f"Profiles of the {kind} runs at e_w = 0.84 with Gutt's solution at each "
                 "run's measured roughness (thesis constants solid, fitted t, q, γ dashed)")
