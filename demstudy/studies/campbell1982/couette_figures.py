"""The Couette part's figures, in the thesis's forms (digest §4): profiles u/U_T and ν against
y/H; S(ν); f_s, f_N against ν (log); the temperature partition ×(H/U_T)² against ν; the
velocity distributions X1-X5 with the folded Maxwellians; P(θ) with Savage-Jeffrey; the
structure distributions; the shear-rate series.

Dimensionless particle units: d = 1, m = 1; no gravity: the upper wall's speed U_T sets the
time scale. Campbell's length unit R = d/2 is used where the thesis prints in it (said on the
axis).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..base import Figure  # noqa: E402
from .couette_measure import RunSummary  # noqa: E402

FOOTER = ("Dimensionless particle units: d = 1, m = 1, no gravity: the upper wall speed U_T "
          "sets the time scale; Campbell's R = d/2. Event-driven hard discs (edmd) unless "
          "marked; 10 × 4 discs, ε_w/ε_p = 0.8/0.6 unless marked. Errors: block jackknife.")
COLOURS = plt.get_cmap("tab10").colors
WHICH_S = {"S_text": "S text", "S_listing": "S listing", "S_text_C": "S′"}


def _save(fig: plt.Figure, out: Path, name: str, caption: str, bottom: float = 0.05) -> Figure:
    fig.text(0.01, 0.005, FOOTER, fontsize=6.5, wrap=True, va="bottom")
    fig.tight_layout(rect=(0, bottom, 1, 1))
    path = out / name
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Figure(path, caption)


def profiles(runs: Sequence[tuple[str, RunSummary]], out: Path, name: str,
             title: str) -> Figure:
    """u/U_T, ν and the temperature QFL/3 = (⟨u'²⟩ + ⟨v'²⟩ + β⟨ω'²⟩)(H/U_T)²/3 (Campbell's
    print, R = 1) against y/H (y/H vertical, Campbell's Figs 3.15-3.16); the legend sits
    below the axes, off the data."""
    fig, (a, b, t) = plt.subplots(1, 3, figsize=(11, 5.4), sharey=True)
    for k, (label, r) in enumerate(runs):
        c = COLOURS[k % 10]
        yh = r.arrays["y_over_h"]
        a.errorbar(r.arrays["u_over_ut"], yh, xerr=2 * r.arrays["u_err"], fmt="o-", ms=3,
                   color=c, label=label)
        b.errorbar(r.arrays["nu"], yh, xerr=2 * r.arrays["nu_err"], fmt="o-", ms=3, color=c)
        if "Tw_err" in r.arrays:
            qfl = (r.arrays["Tu"] + r.arrays["Tv"] + r.arrays["Tw"]) / 3
            err = np.sqrt(r.arrays["Tu_err"] ** 2 + r.arrays["Tv_err"] ** 2
                          + r.arrays["Tw_err"] ** 2) / 3
            t.errorbar(qfl, yh, xerr=2 * err, fmt="o-", ms=3, color=c)
    a.plot([0, 1], [0, 1], "k:", lw=0.8, label="no slip, uniform shear")
    a.set_xlabel("u / U_T")
    a.set_ylabel("y / H (H: wall gap; servo cells: strips follow the walls)")
    b.set_xlabel("solid fraction ν")
    t.set_xlabel("T (H/U_T)² = QFL/3, lengths in R")
    t.set_xlim(left=0)
    a.set_ylim(0, 1)
    a.set_xlim(0, 1)
    fig.legend(*a.get_legend_handles_labels(), loc="lower center", ncol=4, fontsize=7.5,
               bbox_to_anchor=(0.5, 0.05))
    fig.suptitle(title + " (±2σ)", fontsize=10)
    fig.text(0.01, 0.005, FOOTER, fontsize=6.5, wrap=True, va="bottom")
    fig.tight_layout(rect=(0, 0.17, 1, 1))
    path = out / name
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Figure(path, title)


def s_of_nu(points: dict[str, list[RunSummary]], out: Path) -> Figure:
    """S(ν), both S definitions and the corrected S' (Fig 3.40)."""
    fig, (a, b) = plt.subplots(1, 2, figsize=(9, 5.6))
    for k, (label, rs) in enumerate(points.items()):
        nu = [r.v("nu") for r in rs]
        for ax, key, mk in ((a, "S_text", "o"), (a, "S_listing", "s"), (b, "S_text_C", "o")):
            ax.errorbar(nu, [r.v(key) for r in rs], yerr=[2 * r.e(key) for r in rs],
                        xerr=[2 * r.e("nu") for r in rs], fmt=mk, color=COLOURS[k],
                        mfc="none" if key == "S_listing" else COLOURS[k],
                        label=f"{label}: {WHICH_S[key]}")
    a.set_ylabel("S = 2R (du/dy)/√⟨u'²⟩ (text) or /√(⟨u'²⟩+⟨v'²⟩) (listing)")
    b.set_ylabel("S′ = S (π/ν)^½ (length scale C)")
    for ax in (a, b):
        ax.set_xlabel("solid fraction ν (centre strips)")
        ax.set_ylim(bottom=0)
    handles, labels = a.get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=7,
               bbox_to_anchor=(0.5, 0.05))
    fig.suptitle("S(ν), Campbell Fig 3.40 (centre strips, ±2σ; right: S′ of the same runs)",
                 fontsize=10)
    return _save(fig, out, "couette-S-nu.png", "S(ν) (Fig 3.40): text and listing S, and "
                 "S′ with the mean spacing as length scale", bottom=0.25)


def bagnold(points: dict[str, list[RunSummary]], out: Path,
            chute: dict[str, dict] | None = None, compared_up_to: float = np.inf) -> Figure:
    """f_s, f_N against ν, log axis (Figs 3.21-3.24), with the chute's strips (``chute``:
    run name → :func:`.chute_measure.local_bagnold`) as black triangles, open beyond
    ``compared_up_to`` (the cells' ν range the row compares them in)."""
    fig, axes = plt.subplots(1, 2, figsize=(9, 5.6), sharey=True)
    for ax, key in zip(axes, ("f_s", "f_N"), strict=False):
        cells = sorted((r for r in points.get("fixed gap, no-slip", [])
                        if r.v("nu") <= compared_up_to), key=lambda r: r.v("nu"))
        if chute and len(cells) > 1:  # the curve the chute strips are compared with
            ax.plot([r.v("nu") for r in cells], [r.v(key) for r in cells], "--", color="0.5",
                    lw=1, zorder=0, label="the cells' curve the strips are compared with")
        for name, strips in (chute or {}).items():
            if len(strips.get("nu", ())):
                val, err = strips[key], 2 * strips[f"{key}_err"]
                compared = strips["nu"] <= compared_up_to
                for sel, fill, what in ((compared, "k", "compared"),
                                        (~compared, "none", "beyond the cells' ν")):
                    if sel.any():
                        ax.errorbar(strips["nu"][sel], val[sel],
                                    yerr=[np.minimum(err, 0.95 * val)[sel], err[sel]],
                                    fmt="^", color="k", mfc=fill, ms=5,
                                    label=f"{name}: strips, {what} (thesis f)")
        for k, (label, rs) in enumerate(points.items()):
            nu = [r.v("nu") for r in rs]
            for suffix, mk, fill in (("", "o", True), ("_listing", "s", False)):
                val = np.array([r.v(key + suffix) for r in rs])
                err = np.array([2 * r.e(key + suffix) for r in rs])
                # a log axis cannot show a bar below zero: the lower bar stops at 5 %
                ax.errorbar(nu, val, yerr=[np.minimum(err, 0.95 * val), err], fmt=mk,
                            color=COLOURS[k], mfc=COLOURS[k] if fill else "none",
                            label=f"{label}{'' if fill else ' (÷π, listing)'}")
        ax.set_yscale("log")
        ax.set_xlabel("solid fraction ν (cells: centre strips; chute: each strip)")
        ax.set_title(f"{key}: τ = ρ_p {key} R² (du/dy)²", fontsize=9)
    axes[0].set_ylabel("f (thesis definition; open: listing FNU = f/π)")
    fig.legend(*axes[0].get_legend_handles_labels(), loc="lower center", ncol=3,
               fontsize=7, bbox_to_anchor=(0.5, 0.05))
    fig.suptitle("Bagnold coefficients f_s(ν), f_N(ν), Campbell Figs 3.21-3.24 (±2σ; lower "
                 "bars stop at 5 % of the value)\ntriangles: the 30° chute's strips (τ from its "
                 "momentum balance; f is dimensionless in either flow's units)", fontsize=9.5)
    return _save(fig, out, "couette-f-nu.png", "f_s(ν) and f_N(ν) on a log axis, with and "
                 "without the π factor (cubic-spline du/dy; fixed gap: the engine's "
                 "collisional + kinetic strip stress; servo: the walls' stress)", bottom=0.22)


def partition(rs: Sequence[RunSummary], nus: Sequence[float], out: Path) -> Figure:
    """⟨u'²⟩, ⟨v'²⟩, β⟨ω'²⟩ ×(H/U_T)² (R = 1) and the rotational share against ν."""
    fig, (a, b) = plt.subplots(1, 2, figsize=(9, 4.2))
    for k, (key, label) in enumerate((("Tu", "⟨u'²⟩"), ("Tv", "⟨v'²⟩"), ("Tw", "β⟨ω'²⟩"),
                                      ("T_mean", "total/3 (QFL/3)"))):
        a.errorbar(nus, [r.v(key) for r in rs], yerr=[2 * r.e(key) for r in rs], fmt="o-",
                   color=COLOURS[k], label=label)
    b.errorbar(nus, [r.v("rot_share") for r in rs], yerr=[2 * r.e("rot_share") for r in rs],
               fmt="o-", color=COLOURS[2])
    a.set_ylabel("⟨q'²⟩ (H/U_T)², lengths in R (Campbell's print)")
    b.set_ylabel("β⟨ω'²⟩ / (⟨u'²⟩+⟨v'²⟩+β⟨ω'²⟩)")
    for ax in (a, b):
        ax.set_xlabel("nominal solid fraction ν (fixed gap)")
        ax.set_ylim(bottom=0)
    a.legend(fontsize=7, loc="upper right")
    fig.suptitle("Partition of the fluctuation energy, Campbell Figs 3.18-3.19", fontsize=10)
    return _save(fig, out, "couette-temperature.png", "Temperature partition ×(H/U_T)² "
                 "against ν (Figs 3.18-3.19) and the rotational share")


def vdfs(runs: Sequence[tuple[str, RunSummary]], out: Path) -> Figure:
    """X1-X5 histograms (centre strips) with the folded Maxwellians (Figs 3.25-3.29)."""
    fig, axes = plt.subplots(1, 5, figsize=(13, 3.6), sharey=True)
    names = ("X1 (u)", "X2 (v)", "X3 (ω)", "X4 (u, v)", "X5 (u, v, βω)")
    for j, ax in enumerate(axes):
        for k, (label, r) in enumerate(runs):
            x = r.arrays["vdf_x"]
            ax.errorbar(x, r.arrays["vdf"][j], yerr=2 * r.arrays["vdf_err"][j], fmt=".",
                        ms=3, color=COLOURS[k], label=label)
            if k == 0:
                ax.plot(x, r.arrays["vdf_ref"][j], "k-", lw=1, label="folded Maxwellian")
        ax.set_title(names[j], fontsize=9)
        ax.set_xlabel("X")
        ax.set_xlim(0, 4)
    axes[0].set_ylabel("P(X)")
    axes[-1].legend(fontsize=7, loc="upper right")
    fig.suptitle("Velocity distributions in the centre strips, Campbell Figs 3.25-3.29",
                 fontsize=10)
    return _save(fig, out, "couette-vdf.png", "Velocity distributions X1-X5 against the "
                 "folded Maxwellians (a = ½, ½, ½, 1, 3/2)")


def snapshots(runs: Sequence[tuple[str, RunSummary]], out: Path) -> Figure:
    """Fig 2.3: the discs of each cell in its last frame (x periodic: discs across the edge
    drawn on both sides), the walls as thick lines, lengths in d."""
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle

    sizes = [r.arrays["snapshot_box"][1] - r.arrays["snapshot_box"][0] for _, r in runs]
    widths = [float(sz[0]) for sz in sizes]
    height = max(float(sz[1]) for sz in sizes)
    fig, axes = plt.subplots(1, len(runs), figsize=(1.5 + 0.42 * sum(widths),
                                                    0.36 * height + 1.2),
                             gridspec_kw={"width_ratios": widths}, squeeze=False)
    for ax, (label, r) in zip(axes[0], runs, strict=True):
        (x0, y0), (x1, y1) = r.arrays["snapshot_box"]
        pos, rad = r.arrays["snapshot"], r.arrays["snapshot_radius"]
        circles = []
        for (x, y), a in zip(pos, rad, strict=True):
            for shift in (-(x1 - x0), 0.0, x1 - x0):  # periodic images across x
                if x0 - a < x + shift < x1 + a:
                    circles.append(Circle((x + shift, y), a))
        ax.add_collection(PatchCollection(circles, facecolor="0.8", edgecolor="k", lw=0.6))
        for y in (y0, y1):
            ax.axhline(y, color="k", lw=2.5)
        ax.set(xlim=(x0, x1), ylim=(y0 - 0.3, y1 + 0.3), aspect="equal",
               xlabel="x [d]", title=f"{label}\n(centre strips {r.v('nu'):.2f})")
        ax.title.set_fontsize(9)
    axes[0][0].set_ylabel("y [d] (walls: thick lines)")
    fig.suptitle("Snapshots at the end of the run, Campbell Fig 2.3", fontsize=10)
    return _save(fig, out, "couette-snapshots.png", "Fig 2.3 form: the cells' discs in "
                 "their last frame (the upper wall moves to the right)", bottom=0.04)


#: how much of the settling the energy history shows before averaging starts (strain units)
SETTLING_SHOWN = 100.0


def energy_history(groups: Sequence[tuple[str, Sequence[tuple[str, RunSummary]]]],
                   out: Path) -> Figure:
    """Fig 2.4: kinetic energy per disc over its production mean against the strain from the
    start of averaging (the last 100 strain units of the settling before it: the cells settle
    for different lengths), one panel per group, with Campbell's ±20 % band."""
    fig, axes = plt.subplots(1, len(groups), figsize=(4.6 * len(groups), 5.2), sharey=True,
                             squeeze=False)
    tops = []
    for ax, (title, runs) in zip(axes[0], groups, strict=True):
        ax.axhspan(0.8, 1.2, color="0.92", zorder=0)
        longest = 0.0
        for k, (label, r) in enumerate(runs):
            strain = r.arrays["ke_strain"] - float(r.arrays["ke_start"])
            show = strain >= -SETTLING_SHOWN
            ax.plot(strain[show], r.arrays["ke"][show] / r.v("ke_mean"), lw=0.6,
                    color=COLOURS[k % 10],
                    label=f"{label} ({100 * r.v('ke_within'):.0f} % in band)")
            longest = max(longest, float(strain[-1]))
        ax.axvline(0.0, color="k", ls="--", lw=0.8)
        tops += [float(np.nanmax(r.arrays["ke"][r.arrays["ke_strain"] - float(
            r.arrays["ke_start"]) >= -SETTLING_SHOWN] / r.v("ke_mean"))) for _l, r in runs]
        ax.set(xlabel="strain γ̇(t − t_avg) from the start of averaging", title=title,
               xlim=(-SETTLING_SHOWN, longest))
        ax.title.set_fontsize(9)
        # below the axes: the rough cells' energy swings through the whole panel
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.2),
                  ncol=2 if len(runs) > 3 else 1)
    axes[0][0].set_ylabel("kinetic energy per disc / production mean")
    axes[0][0].set_ylim(0, max(2.0, 1.05 * max(tops, default=2.0)))  # shared: no spike cut
    fig.suptitle("Kinetic-energy history, Campbell Fig 2.4 (band: ±20 %; dashed: averaging "
                 "starts, t_avg)", fontsize=10)
    return _save(fig, out, "couette-energy.png", "Fig 2.4 form: total kinetic energy per "
                 "disc (translation + rotation, mean flow included) over its production mean "
                 "against the strain, with Campbell's ±20 % band", bottom=0.05)


def angles(runs: Sequence[tuple[str, RunSummary]], out: Path) -> Figure:
    """P(θ) (text convention) with Savage-Jeffrey for S and S' (Figs 3.32-3.34)."""
    n = len(runs)
    fig, axes = plt.subplots(1, n, figsize=(max(3.3 * n, 8.0), 4.2), sharey=True,
                             squeeze=False)
    for k, (ax, (label, r)) in enumerate(zip(axes[0], runs, strict=True)):
        deg = np.degrees(r.arrays["theta"])
        first = k == 0
        ax.errorbar(deg, r.arrays["p_text"], yerr=2 * r.arrays["p_text_err"], fmt=".",
                    color=COLOURS[0], label="measured (text θ), ±2σ" if first else None)
        ax.plot(deg, r.arrays["sj_text_R"], "-", color=COLOURS[1],
                label="Savage-Jeffrey with S" if first else None)
        ax.plot(deg, r.arrays["sj_text_C"], "--", color=COLOURS[2],
                label="Savage-Jeffrey with S′ = S(π/ν)^½" if first else None)
        ax.axhline(1 / np.pi, color="grey", lw=0.6, label="isotropic 1/π" if first else None)
        ax.set_title(f"{label}\nS = {r.v('S_text'):.2f}, S′ = {r.v('S_text_C'):.2f}",
                     fontsize=8.5)
        ax.set_xlabel("θ from the flow direction (deg)")
        ax.set_xticks([0, 45, 90, 135, 180])
    axes[0][0].set_ylabel("P(θ) per radian (centre strips)")
    fig.legend(loc="upper center", ncol=4, fontsize=7.5, bbox_to_anchor=(0.5, 0.93))
    fig.suptitle("Collision angles with Savage-Jeffrey, Campbell Figs 3.32-3.34 (the "
                 "listing's θ' = 90° − θ)", fontsize=10)
    fig.text(0.01, 0.005, FOOTER, fontsize=6.5, wrap=True, va="bottom")
    fig.tight_layout(rect=(0, 0.06, 1, 0.86))
    path = out / "couette-angles.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Figure(path, "P(θ) in the centre strips with Savage-Jeffrey for S and the "
                  "corrected S′")


def structure(runs: Sequence[tuple[str, RunSummary]], out: Path) -> Figure:
    """Normal and parallel distributions (Figs 3.35-3.39), normalised by n = ν/(πR²)."""
    fig, (a, b) = plt.subplots(1, 2, figsize=(9, 4.2), sharey=True)
    for k, (label, r) in enumerate(runs):
        n0 = r.v("nu") / (np.pi * 0.25)
        for ax, key in ((a, "normal"), (b, "parallel")):
            ax.errorbar(r.arrays["st_r"], r.arrays[f"st_{key}"] / n0,
                        yerr=2 * r.arrays[f"st_{key}_err"] / n0, fmt="-", color=COLOURS[k],
                        label=label)
    a.set_xlabel("|Δy| (d)")
    b.set_xlabel("|Δx|, partners with |Δy| < 1 (d)")
    a.set_ylabel("density / (ν/(π R²))")
    a.set_title("normal distribution", fontsize=9)
    b.set_title("parallel distribution", fontsize=9)
    a.legend(fontsize=7, loc="upper right")
    fig.suptitle("Structure distributions around mid-gap test particles, Campbell Figs "
                 "3.35-3.39", fontsize=10)
    return _save(fig, out, "couette-structure.png", "Normal and parallel structure "
                 "distributions, normalised by the mean number density")


def shear_rates(rs: Sequence[RunSummary], rates: Sequence[float], out: Path) -> Figure:
    """ν and T(H/U_T)² against Campbell's R/H (Fig 3.17)."""
    fig, (a, b) = plt.subplots(1, 2, figsize=(8, 4.0))
    rh = [g / 2 for g in rates]
    a.errorbar(rh, [r.v("nu_cell") for r in rs], yerr=[2 * r.e("nu_cell") for r in rs],
               fmt="o-")
    b.errorbar(rh, [r.v("T_mean") for r in rs], yerr=[2 * r.e("T_mean") for r in rs],
               fmt="o-")
    a.set_ylabel("cell solid fraction ν")
    b.set_ylabel("T (H/U_T)² = QFL/3, lengths in R")
    for ax in (a, b):
        ax.set_xscale("log")
        ax.set_xticks(rh, [f"1/{round(1 / x):d}" for x in rh])
        ax.minorticks_off()
        ax.set_xlim(min(rh) / 1.5, max(rh) * 1.5)
        ax.set_xlabel("R/H: Campbell's shear rate (his units)")
    fig.suptitle("Shear-rate scaling at σ_n = 0.567 (R/H)², no-slip walls, Fig 3.17",
                 fontsize=10)
    return _save(fig, out, "couette-shear-rate.png", "ν and T(H/U_T)² against the shear "
                 "rate R/H at σ_n = 0.567 (R/H)² (Fig 3.17)")
