"""Figures of the density-wave part in the thesis's forms (digest §7, Figs 5.1-5.27): per run
(a) positions, (b)-(d) density contours xy/xz/yz with velocity vectors, (e)-(g) power spectra
as bars over the integer harmonics, (h) kinetic energy against collisions per particle, (i)
the amplitudes of the leading modes; and the phase diagram over (L/W, W/d) (Fig 5.25).

Dimensionless particle units: d = 1, m = 1, g = 1 (gravity acts): lengths in d, speeds in
√(gd), energies in m g d; time in collisions per particle c/p = 2 N_pair / N.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import MaxNLocator

from ..base import UNITS_NOTE
from .waves_boxes import Box
from .waves_measure import PLANES, RunWaves

#: the thesis's snapshot times in collisions per particle (digest §1.8)
THESIS_SNAPSHOTS = (4000, 8000, 10000, 11000, 14000)
FOOTER = (f"{UNITS_NOTE} Time: collisions per particle c/p = 2 N_pair/N. Hard spheres, "
          "event-driven engine (edmd); e_w = β_w = 0.99, β = 0.1.")
#: marker and colour per class in the phase diagram
STYLE = {"plug": ("s", "tab:blue"), "s-wave": ("^", "tab:orange"), "slug": ("o", "tab:red"),
         "mixed": ("D", "tab:purple"), "none": ("v", "tab:gray")}
K_MAX = 4


def _footer(fig: Figure, extra: str = "") -> None:
    fig.text(0.005, 0.004, FOOTER + (" " + extra if extra else ""), fontsize=6.5,
             ha="left", va="bottom", wrap=True)


def _positions(ax, run: RunWaves) -> None:
    pos = run.snapshot.position
    rng = np.random.default_rng(0)
    pick = rng.choice(pos.shape[0], min(pos.shape[0], 15000), replace=False)
    p = pos[pick]
    size = 4.0 if p.shape[0] < 5000 else 1.0
    ax.scatter(p[:, 0], p[:, 2], p[:, 1], s=size, c=p[:, 1], cmap="viridis",
               depthshade=False)
    ax.set_box_aspect(tuple(run.size[[0, 2, 1]]))
    ax.set_xlabel("x (d)", fontsize=7, labelpad=-2)
    ax.set_ylabel("z (d)", fontsize=7, labelpad=-2)
    ax.set_zlabel("y (d)", fontsize=7, labelpad=-2)
    ax.tick_params(labelsize=6, pad=0)
    shown = "" if pick.size == pos.shape[0] else f" ({pick.size} of {pos.shape[0]} shown)"
    ax.set_title(f"(a) positions at {run.snapshot.cpp:.0f} c/p{shown}\n"
                 "(colour: y; gravity along +x)", fontsize=7.5)


def _contour(fig: Figure, ax, run: RunWaves, plane: str, letter: str) -> None:
    ca, cb, nu, ua, ub = run.snapshot.planes[plane]
    cs = ax.contourf(ca, cb, nu.T, levels=12, cmap="viridis")
    ratio = float(np.ptp(cb) + cb[1] - cb[0]) / float(np.ptp(ca) + ca[1] - ca[0])
    fig.colorbar(cs, ax=ax, label="solid fraction ν", shrink=float(np.clip(1.3 * ratio, 0.4,
                                                                            0.85)))
    step_a, step_b = max(1, ca.size // 18), max(1, cb.size // 18)
    ax.quiver(ca[::step_a], cb[::step_b], np.nan_to_num(ua[::step_a, ::step_b].T),
              np.nan_to_num(ub[::step_a, ::step_b].T), color="white", width=0.004)
    ax.set_aspect("equal")
    # a flat plane (H = 10 against L = 150) has room for few ticks along its short side
    ax.yaxis.set_major_locator(MaxNLocator(2 if ratio < 0.2 else 5))
    ax.set_xlabel(f"{plane[0]} (d)")
    ax.set_ylabel(f"{plane[1]} (d)")
    ax.set_title(f"({letter}) ν, {plane} plane at {run.snapshot.cpp:.0f} c/p; arrows: "
                 f"(u_{plane[0]}, u_{plane[1]}) − box mean", fontsize=7.5)


def _spectrum(ax, run: RunWaves, plane: str, letter: str) -> None:
    power = np.asarray(run.modes.results[f"family_power_{plane}"], float)
    na, nb = min(K_MAX, power.shape[0] - 1), min(K_MAX, power.shape[1] - 1)
    ka, kb = np.meshgrid(np.arange(na + 1), np.arange(nb + 1), indexing="ij")
    top = power[: na + 1, : nb + 1].copy()
    top[0, 0] = 0.0  # the mean density, not a wave
    dom = set(run.modes.dominant(plane))
    colours = [("tab:red" if (i, j) in dom else "tab:blue") for i, j in
               zip(ka.ravel(), kb.ravel(), strict=True)]
    ax.bar3d(ka.ravel() - 0.3, kb.ravel() - 0.3, 0 * top.ravel(), 0.6, 0.6, top.ravel(),
             color=colours, shade=True)
    # ±2σ whiskers (jackknife over the production's blocks) above each bar's centre
    err = np.asarray(run.modes.results.get(f"family_power_{plane}_err",
                                           np.zeros_like(power)), float)[: na + 1, : nb + 1]
    for (i, j), p, e in zip(zip(ka.ravel(), kb.ravel(), strict=True), top.ravel(),
                            np.nan_to_num(err).ravel(), strict=True):
        if p > 0 and e > 0:
            ax.plot([i, i], [j, j], [max(p - 2 * e, 0.0), p + 2 * e], color="k", lw=0.9,
                    zorder=10)
    ax.set_xlabel(f"k_{plane[0]}", fontsize=7, labelpad=-2)
    ax.set_ylabel(f"k_{plane[1]}", fontsize=7, labelpad=-2)
    ax.set_zlabel("P_F", fontsize=7, labelpad=0)
    ax.tick_params(labelsize=6, pad=0)
    ax.set_xticks(range(na + 1))
    ax.set_yticks(range(nb + 1))
    spread = ("±2σ whiskers" if run.stationary else
              "±2σ whiskers (modes drift: a transient's spread)")
    ax.set_title(f"({letter}) power {plane}: P = 2|X|²/(N1N2)², ± modes summed,\nmean over "
                 f"the production; red: dominant;\n{spread}", fontsize=7.5)


def _energy(ax, run: RunWaves) -> None:
    ax.plot(run.cpp, run.ke, color="tab:blue", lw=0.8, label="translational KE per particle")
    ax.axvspan(run.eq_cpp, run.end_cpp, color="tab:green", alpha=0.12,
               label="production (analysed)")
    for t in THESIS_SNAPSHOTS:
        ax.axvline(t, color="gray", ls=":", lw=0.7)
    ax.plot([], [], color="gray", ls=":", lw=0.7, label="thesis snapshot times")
    ax.set_xlabel("collisions per particle")
    ax.xaxis.set_major_locator(MaxNLocator(5))
    ax.set_ylabel("KE / N (m g d)")
    ax.set_xlim(0, max(run.end_cpp, THESIS_SNAPSHOTS[-1]) * 1.02)
    ax.set_ylim(0, float(np.nanmax(run.ke)) * 1.35)
    ax.legend(fontsize=6, loc="upper right")
    ax.set_title("(h) kinetic energy trace", fontsize=7.5)


def _series(ax, run: RunWaves) -> None:
    res = run.modes.results
    series = np.asarray(res["series_xy"], float).reshape(run.series_cpp.size, -1)
    modes = [tuple(m) for m in np.asarray(res["series_modes_xy"], int).reshape(-1, 2)]
    lead = run.modes.leading("xy", 4)
    colours = ["tab:blue", "tab:orange", "tab:green", "tab:red"]
    for colour, k in zip(colours, lead, strict=False):
        if k in modes:
            ax.plot(run.series_cpp, series[:, modes.index(k)], color=colour, lw=0.8,
                    label=f"xy {k}")
    half = run.halves[1].results["series_time"]
    if np.size(half):
        ax.axvline(float(np.interp(half[0], run.time, run.cpp)), color="k", ls="--", lw=0.7,
                   label="halves compared")
    ax.set_xlabel("collisions per particle")
    ax.xaxis.set_major_locator(MaxNLocator(5))
    ax.set_ylabel("amplitude √P_F")
    ax.set_ylim(0, float(np.nanmax(series)) * 1.45 if series.size else 1.0)
    ax.legend(fontsize=6, loc="upper right", ncol=3)
    state = "stationary" if run.stationary else "drifting"
    ax.set_title(f"(i) leading xy modes (k_x, k_y): {state}", fontsize=7.5)


def run_figure(run: RunWaves, box: Box, out: Path) -> Path:
    """The 3 × 3 panels of one run (module docstring), saved to ``out``."""
    fig = Figure(figsize=(15, 13))
    axes = {}
    for i in range(9):
        three_d = i in (0, 4, 5, 6)
        axes[i] = fig.add_subplot(3, 3, i + 1, projection="3d" if three_d else None)
    _positions(axes[0], run)
    for i, (plane, letter) in enumerate(zip(PLANES, "bcd", strict=True)):
        _contour(fig, axes[i + 1], run, plane, letter)
    for i, (plane, letter) in enumerate(zip(PLANES, "efg", strict=True)):
        _spectrum(axes[i + 4], run, plane, letter)
    _energy(axes[7], run)
    _series(axes[8], run)
    fig.suptitle(f"Malik (2008) Fig {box.fig}: N = {box.n}, L × W × H = {box.length} × "
                 f"{box.width} × {box.height} d (L/W = {box.aspect:.2g}, φ = {box.phi:.3f}), "
                 f"e = {run.restitution:g}: class {run.modes.pattern}", fontsize=11)
    _footer(fig)
    fig.subplots_adjust(left=0.04, right=0.98, top=0.93, bottom=0.05, wspace=0.3, hspace=0.35)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=90)
    return out


def phase_figure(found: Sequence[tuple[Box, str]], missing: Sequence[Box],
                 thesis: Sequence[tuple[Box, str, str]], out: Path,
                 transient: Sequence[str] = ()) -> Path:
    """Fig 5.25's form: classes over (L/W, W/d) at e = 0.7, H = W; filled: demstudy, open
    rings: the thesis where known (``thesis``: box, class, source), ×: not run; a box in
    ``transient`` (names: its modes not stationary over the production) is drawn pale with
    a dashed edge: the class of a flow still changing, not a steady structure."""
    fig = Figure(figsize=(7.5, 5.4))
    ax = fig.add_subplot(1, 1, 1)
    for box, cls in found:
        marker, colour = STYLE.get(cls.split(" ")[0], ("*", "k"))
        changing = box.name in transient
        ax.scatter(box.aspect, box.width, marker=marker, color=colour, s=90, zorder=3,
                   alpha=0.45 if changing else 1.0, edgecolors="k" if changing else "none",
                   linestyles="--", linewidths=0.8 if changing else 0)
        if "+ z" in cls:
            ax.annotate("+z", (box.aspect, box.width), textcoords="offset points",
                        xytext=(7, -10), fontsize=7)
    for box in missing:
        ax.scatter(box.aspect, box.width, marker="x", color="0.6", s=50, zorder=2)
    for box, cls, _source in thesis:
        marker, colour = STYLE.get(cls, ("*", "k"))
        ax.scatter(box.aspect, box.width, marker=marker, facecolors="none", edgecolors=colour,
                   s=330, linewidths=1.6,
                   zorder=4)
    handles = [Line2D([], [], marker=m, color=c, ls="", markersize=8, label=f"demstudy: {k}")
               for k, (m, c) in STYLE.items()]
    handles += [Line2D([], [], marker="o", markerfacecolor="none", markeredgecolor="k",
                       ls="", markersize=13, label="thesis, digest §1.8 (solid ring)"),
                Line2D([], [], marker="o", color="0.5", alpha=0.45, markeredgecolor="k",
                       ls="", markersize=8, label="pale: modes not stationary\n(a transient's "
                                                  "class)"),
                Line2D([], [], marker="x", color="0.6", ls="", label="not run")]
    ax.legend(handles=handles, fontsize=7, loc="center left", bbox_to_anchor=(1.02, 0.5))
    ax.set_xlabel("aspect ratio L/W")
    ax.set_ylabel("channel width W/d")
    ax.set_xlim(0, 5.6)
    ax.set_ylim(5, 60)
    ax.set_xticks([0.6, 1.4, 3, 5])
    ax.set_yticks([15, 30, 50])
    ax.grid(alpha=0.3)
    ax.set_title("Fig 5.25's form: structures over the thesis's span\n"
                 "φ ≈ 0.15, e = 0.7, β = 0.1, H = W", fontsize=9)
    _footer(fig)
    fig.subplots_adjust(left=0.1, right=0.62, top=0.92, bottom=0.2)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    return out
