"""Campbell (1982) chutes: the figures, in the thesis's forms (Fig 2.4 kinetic-energy history,
Fig 3.1/3.2 profiles against y/H, stresses against y/H, Fig 3.14 the 20° plug), plus the
flat-base scan, the t_c comparison and the series (depth, ε_p, ε_w, width, soft discs).

Dimensionless particle units: d = 1, m = 1, g = 1 (times √(d/g), speeds √(gd), energies m g d,
2D stresses m g/d); H = 2 × the mass-mean centre height (Campbell's depth). Every figure says so
in its footer.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..base import pm
from .chute_measure import SURFACE_NU, ChuteRun

FOOTER = ("Campbell's chute, hard discs (event-driven, t_c = 1e-5 unless stated) unless "
          "marked LAMMPS; units d = m = g = 1 (t in √(d/g), u in √(gd), energy in m g d, "
          "stress in m g/d); H = 2 × mass-mean centre height; error bars: block errors (1σ).")
NU_SQUARE = math.pi / 4          # ν_s: square packing, layers slide (L1093)
NU_SHEARABLE = math.pi / (math.sqrt(3) + 2 * math.pi / 3)   # ν_m = 0.821 (L1093)


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _finish(fig, path: Path, note: str = "") -> Path:
    import textwrap

    text = "\n".join(textwrap.wrap(FOOTER + (" " + note if note else ""), 170))
    fig.text(0.5, 0.005, text, ha="center", va="bottom", fontsize=7)
    lines = text.count("\n") + 1
    fig.tight_layout(rect=(0, 0.02 + 0.018 * lines, 1, 1))
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    _plt().close(fig)
    return path


#: the study's reference run, black in every figure it is in
REFERENCE = "chute-30-bumpy"


#: beyond tab10's ten: dark, saturated colours unlike any of tab10's (tab20's light halves of
#: the same hues would sit beside their dark partners in one panel)
EXTRA_COLOURS = ("navy", "maroon", "darkgoldenrod", "teal", "indigo", "lime", "deeppink")


def run_colours(runs: Sequence[ChuteRun]) -> dict[str, Any]:
    """One colour per run of a figure, the same in each of its panels: the reference run
    black, the others tab10's colours in the order they first appear, then
    ``EXTRA_COLOURS`` (no two runs of a figure share one up to 17 others)."""
    names = list(dict.fromkeys(r.name for r in runs))
    others = [n for n in names if n != REFERENCE]
    palette = [*_plt().get_cmap("tab10").colors, *EXTRA_COLOURS]
    return {n: ("k" if n == REFERENCE else palette[others.index(n) % len(palette)])
            for n in names}


def _bed(run: ChuteRun) -> np.ndarray:
    """Strips of the bed and its saltating surface (ν above a trace)."""
    return np.nan_to_num(run.profiles["nu"]) >= 0.2 * SURFACE_NU


def profile_panels(axes: Sequence, runs: Sequence[ChuteRun], labels: Sequence[str],
                   what: Sequence[str] = ("u", "nu", "T", "T_rot"), fit: bool = False,
                   colours: Mapping[str, Any] | None = None) -> None:
    """Campbell's profile forms against y/H (vertical): u/u_max, ν, T, T_rot; ``fit``: overlay
    the thesis's velocity-profile fit F(y/H) (COL007, digest §1.2) on u/u_max."""
    titles = {"u": ("u / u_max", "mean velocity"), "nu": ("ν", "solid fraction"),
              "T": ("T [g d]", "translational temperature (⟨u'²⟩+⟨v'²⟩)/2"),
              "T_rot": ("T_rot [g d]", "rotational temperature β⟨w'²⟩")}
    colours = colours or run_colours(runs)
    for ax, key in zip(axes, what, strict=True):
        for run, label in zip(runs, labels, strict=True):
            p, sel = run.profiles, _bed(run)
            value, err = p[key][sel], p[f"{key}_err"][sel]
            if key == "u":
                value, err = value / run.u_max, err / abs(run.u_max)
            ax.errorbar(value, p["y"][sel] / run.depth, xerr=err, fmt="o-", ms=3, lw=1,
                        capsize=2, color=colours[run.name], label=label)
        if key == "u" and fit:
            from ...scene.initial import CAMPBELL_CHUTE_FIT

            z = np.linspace(0.0, 1.0, 101)
            ax.plot(np.polyval(CAMPBELL_CHUTE_FIT[::-1], z), z, "k--", lw=1.2,
                    label="Campbell's profile fit F(y/H) (COL007)")
        if key == "nu":
            ax.axvline(NU_SQUARE, color="k", ls=":", lw=1, label="π/4 (square packing)")
        if key in ("T", "T_rot") and any(np.nanmax(r.profiles[key]) > 0 for r in runs):
            ax.set_xscale("log")
        ax.set(xlabel=titles[key][0], ylabel="y / H", title=titles[key][1])
        ax.title.set_fontsize(9)


def legend_below(fig, axes) -> None:
    handles, labels = [], []
    for ax in np.ravel(axes):
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    fig.legend(handles, labels, loc="lower center", ncol=min(3, len(labels)), fontsize=8,
               bbox_to_anchor=(0.5, 0.06), frameon=False)


def energy_history(runs: dict[str, ChuteRun], main: str, path: Path) -> Path | None:
    """Fig 2.4: kinetic energy per disc against time; the main run with its production mean
    and Campbell's ±20 % band; every angle run on a log scale beside it."""
    if not runs:
        return None
    plt = _plt()
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 5.2))
    colours = run_colours(list(runs.values()))
    if main in runs:
        r = runs[main]
        ax1.plot(r.t, r.energy, color=colours[r.name], lw=0.7, label=r.label)
        prod = r.t > r.start
        m = float(r.energy[prod].mean())
        ax1.axhline(m, color="k", lw=1, label=f"production mean {m:.1f}")
        ax1.axhspan(0.8 * m, 1.2 * m, color="0.8", alpha=0.5,
                    label=f"±20 % (Campbell's band); {100 * r.within:.0f} % of samples inside")
        ax1.axvspan(0, r.start, color="C1", alpha=0.08, label="equilibration (not averaged)")
        ax1.set(xlabel="t [√(d/g)]", ylabel="kinetic energy per disc [m g d]",
                title=f"Fig 2.4 form: {r.name}, trend {pm(r.trend, r.trend_err)} "
                      "(converged: |trend| < 0.2 within 2σ)",
                ylim=(0, 2.2 * m))
        ax1.legend(fontsize=8, loc="upper right")
    for r in runs.values():
        ax2.plot(r.t, r.energy, color=colours[r.name], lw=0.8,
                 label=f"{r.name}: trend {r.trend:+.2f}")
    ax2.set(yscale="log", xlabel="t [√(d/g)]", ylabel="kinetic energy per disc [m g d]",
            title="the angle series (log scale)")
    ax2.legend(fontsize=7, loc="lower right")
    return _finish(fig, path, "Kinetic energy = translational + rotational, mean flow included.")


def profiles_figure(runs: Sequence[ChuteRun], labels: Sequence[str], path: Path,
                    title: str) -> Path | None:
    """Fig 3.1/3.2: u/u_max, ν, T and T_rot against y/H, one colour per run."""
    if not runs:
        return None
    plt = _plt()
    fig, axes = plt.subplots(1, 4, figsize=(15, 5.8), sharey=True)
    profile_panels(axes, runs, labels, fit=True)
    fig.suptitle(title, fontsize=10)
    legend_below(fig, axes)
    fig.tight_layout()
    return _finish_legend(fig, path, len(labels) + 1)


def _finish_legend(fig, path: Path, entries: int, note: str = "") -> Path:
    """_finish with room for a legend row block under the panels."""
    import textwrap

    rows = math.ceil(entries / 3)
    text = "\n".join(textwrap.wrap(FOOTER + (" " + note if note else ""), 170))
    fig.text(0.5, 0.005, text, ha="center", va="bottom", fontsize=7)
    lines = text.count("\n") + 1
    bottom = 0.02 + 0.018 * lines
    for lg in fig.legends:
        lg.set_bbox_to_anchor((0.5, bottom))
    fig.tight_layout(rect=(0, bottom + 0.035 * rows, 1, 0.97))
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    _plt().close(fig)
    return path


def stress_figure(runs: Sequence[ChuteRun], path: Path) -> Path | None:
    """Stresses against y/H three ways: momentum balance (line with band), kinetic +
    collisional from the stress statistic (points), the base's wall stress (star at y = 0)."""
    runs = [r for r in runs if r.stress]
    if not runs:
        return None
    plt = _plt()
    fig, axes = plt.subplots(2, len(runs), figsize=(4.6 * len(runs), 8.6), squeeze=False)
    for j, r in enumerate(runs):
        s, y = r.stress, r.profiles["y"] / r.depth
        bed = _bed(r)
        for i, comp in enumerate(("tau_yy", "tau_xy")):
            ax = axes[i, j]
            bal, bal_e = s[f"balance_{comp}"], s[f"balance_{comp}_err"]
            ok = bed & np.isfinite(bal)
            # continued to the base plane y = 0 (the half strip below the first centre)
            yb = np.concatenate([[0.0], y[ok]])
            bal_line = np.concatenate([[s[f"base_balance_{comp}"]], bal[ok]])
            ax.plot(bal_line, yb, "-", color="C0", lw=1.5, label="momentum balance (from the "
                    "free surface, with the unsteady term)")
            ax.fill_betweenx(y[ok], bal[ok] - 2 * bal_e[ok], bal[ok] + 2 * bal_e[ok],
                             color="C0", alpha=0.2, lw=0)
            ax.errorbar(s[f"stat_{comp}"][bed], y[bed], xerr=s[f"stat_{comp}_err"][bed],
                        fmt="o", ms=3, color="C1", capsize=2,
                        label=f"{s['stat_parts']} (stress statistic)")
            ax.errorbar([s[f"wall_{comp}"]], [0.0], xerr=[s[f"wall_{comp}_err"]], fmt="*",
                        ms=12, color="C3", label="base wall stress (y = 0)")
            name = "τ_yy (normal)" if comp == "tau_yy" else "τ_xy (shear)"
            ax.set(xlabel=f"{name} [m g/d]", ylabel="y / H",
                   title=f"{r.name}: {name}")
            ax.title.set_fontsize(9)
    legend_below(fig, axes)
    return _finish_legend(fig, path, 4, "Strip 0 < y < 1 of a bumpy base holds the bumps, "
                          "whose load path (bump to base) is not in the collisional sum.")


def plug_figure(runs: Sequence[ChuteRun], path: Path) -> Path | None:
    """Fig 3.14: the 20° bed: ν and u/u_max against y/H with π/4 and ν_m."""
    if not runs:
        return None
    plt = _plt()
    fig, axes = plt.subplots(1, 3, figsize=(14, 5.6))
    labels = [f"{r.name} ({r.base} base)" for r in runs]
    profile_panels(axes[:2], runs, labels, what=("nu", "u"))
    axes[0].axvline(NU_SHEARABLE, color="k", ls="--", lw=1, label="ν_m = 0.821 (max. shearable)")
    colours = run_colours(runs)
    for i, r in enumerate(runs):
        axes[2].plot(r.t, r.energy, color=colours[r.name], lw=0.8, label=labels[i])
    axes[2].set(yscale="log", xlabel="t [√(d/g)]", ylabel="kinetic energy per disc [m g d]",
                title="energy history")
    axes[2].title.set_fontsize(9)
    legend_below(fig, axes)
    return _finish_legend(fig, path, 5, "The profiles average the production window.")


def angles_figure(runs: Sequence[ChuteRun], path: Path) -> Path | None:
    """Fig 3.33: P(θ) of the pair collisions (text θ, from the flow direction) with ±2σ, the
    isotropic 1/π and the approach quadrant 90°-180° shaded; one panel per run."""
    runs = [r for r in runs if r.angles]
    if not runs:
        return None
    plt = _plt()
    fig, axes = plt.subplots(1, len(runs), figsize=(max(4.2 * len(runs), 8.0), 4.4),
                             sharey=True, squeeze=False)
    colours = run_colours(runs)
    for ax, r in zip(axes[0], runs, strict=True):
        a = r.angles
        deg = np.degrees(a["theta"])
        ax.axvspan(90, 180, color="0.93", zorder=0)
        ax.axhline(1 / math.pi, color="grey", lw=0.8, ls=":", zorder=1)
        ax.errorbar(deg, a["p"], yerr=2 * a["p_err"], fmt=".", ms=4, color=colours[r.name],
                    elinewidth=0.8, zorder=2)
        share, err = a["approach"]
        t0, t1 = a["window"][:2]
        ax.set_title(f"{r.name} ({r.angle:g}°, {r.base} base)\nt = {t0:.0f}-{t1:.0f} √(d/g); "
                     f"share in 90°-180°: {share:.3f} ± {err:.3f}", fontsize=9)
        ax.set(xlabel="θ from the flow direction [deg]", xlim=(0, 180),
               xticks=[0, 45, 90, 135, 180])
    axes[0][0].set_ylabel("P(θ) per radian, ±2σ")
    top = max(float(np.max(r.angles["p"] + 2 * r.angles["p_err"])) for r in runs)
    axes[0][0].set_ylim(0, 1.12 * top)
    fig.suptitle("Collision angles in the chute, Campbell Fig 3.33 (shaded: the approach "
                 "quadrant; dotted: isotropic 1/π)", fontsize=10)
    return _finish(fig, path, "Here the bars are ±2σ. The pair collisions of the logged "
                   "window (the production's first 2·10⁵ collisions, the base's included); "
                   "the 40° beds accelerate (a transient's distribution).")


def flat_scan_figure(flat: Sequence[ChuteRun], bumpy: ChuteRun | None, path: Path) -> Path | None:
    """Why the bumpy base: the flat base's force ratio against α and the energy histories."""
    if not flat:
        return None
    plt = _plt()
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 5.2))
    flat = sorted(flat, key=lambda r: r.angle)
    colours = run_colours(flat)
    for r in flat:
        ax1.plot(r.t, r.energy, color=colours[r.name], lw=0.8, label=f"flat base, {r.angle:g}°")
    if bumpy is not None:
        ax1.plot(bumpy.t, bumpy.energy, color="k", lw=0.8, label="bumpy base, 30°")
    ax1.set(yscale="log", xlabel="t [√(d/g)]", ylabel="kinetic energy per disc [m g d]",
            title="flat sticking base: energy per angle")
    ax1.legend(fontsize=8, loc="lower right")
    a = np.array([r.angle for r in flat])
    ax2.errorbar(a - 0.15, [r.ratio_dense for r in flat], [r.ratio_dense_err for r in flat],
                 fmt="o", color="C0", capsize=2, label="flat, dense phase t = 25-200")
    ax2.errorbar(a + 0.15, [r.ratio for r in flat], [r.ratio_err for r in flat], fmt="s",
                 color="C1", capsize=2, label="flat, production window")
    if bumpy is not None:
        ax2.errorbar([bumpy.angle + 0.4], [bumpy.ratio], [bumpy.ratio_err], fmt="^", color="k",
                     capsize=2, label="bumpy base, production window")
    grid = np.linspace(a.min() - 2, a.max() + 2, 50)
    ax2.plot(grid, np.tan(np.radians(grid)), "k-", lw=1, label="tan α (steady flow)")
    ax2.set(xlabel="α [°]", ylabel="base force ratio |F_x/F_y|",
            title="base shear-to-normal force ratio")
    ax2.legend(fontsize=8, loc="upper left")
    return _finish(fig, path)


def tc_figure(runs: Sequence[ChuteRun], path: Path) -> Path | None:
    """The 30° bumpy chute at three t_c: profiles, energy and the TC share."""
    if not runs:
        return None
    plt = _plt()
    runs = sorted(runs, key=lambda r: -(r.tc or 0))
    fig, axes = plt.subplots(1, 4, figsize=(15, 5.4))
    labels = [f"t_c = {r.tc:g}" for r in runs]
    profile_panels(axes[:2], runs, labels, what=("u", "nu"))
    colours = run_colours(runs)
    for i, r in enumerate(runs):
        axes[2].plot(r.t, r.energy, color=colours[r.name], lw=0.7, label=labels[i])
    axes[2].axvline(runs[0].start, color="k", ls=":", lw=1)
    axes[2].set(xlabel="t [√(d/g)]  (dotted: end of equilibration)",
                ylabel="kinetic energy per disc [m g d]", title="energy history")
    tcs = [r.tc for r in runs]
    axes[3].plot(tcs, [100 * r.tc_share for r in runs], "ko-")
    axes[3].set(xscale="log", xlabel="t_c [√(d/g)]", ylabel="TC-elastic pair collisions [%]",
                title="share made elastic by the TC model")
    for ax in axes[2:]:
        ax.title.set_fontsize(9)
    legend_below(fig, axes)
    return _finish_legend(fig, path, len(runs) + 1)


def series_figure(series: Sequence[tuple[str, Sequence[ChuteRun], Sequence[str]]],
                  path: Path) -> Path | None:
    """u/u_max and ν against y/H for each series (columns), one colour per run."""
    series = [s for s in series if s[1]]
    if not series:
        return None
    plt = _plt()
    fig, axes = plt.subplots(2, len(series), figsize=(4.2 * len(series), 9), squeeze=False)
    colours = run_colours([r for _title, runs, _labels in series for r in runs])
    for j, (title, runs, labels) in enumerate(series):
        profile_panels([axes[0, j], axes[1, j]], runs, labels, what=("u", "nu"),
                       colours=colours)
        axes[0, j].set_title(f"{title}: u/u_max", fontsize=9)
        axes[1, j].set_title(f"{title}: ν", fontsize=9)
        axes[0, j].legend(fontsize=7, loc="upper left")
    return _finish(fig, path, "Bumpy base (random bumps, diameter d, spacing 1.2 d). Dotted: "
                   "ν = π/4. (steady): no energy trend beyond 2σ and base ratio = tan α.")
