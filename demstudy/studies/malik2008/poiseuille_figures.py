"""The Poiseuille part's figures, in the thesis's forms (digest §4, §7): profiles of φ, U_x*,
ω_z*, T*, θ*, Kn against y (Figs 3.3/3.5/3.7, 4.2/4.4/4.6, 4.16), the kinetic-energy trace
against collisions per particle (Figs 3.2d, 4.15b), six-panel VDFs P(C/σ) with P(0) = 1 and
the Gaussian exp(-x²/2) (Figs 3.12-3.17, 4.7-4.9, 4.18), the in-bin g(r) (Figs 3.18-3.20,
4.10, 4.17), C_xx, C_yy, C_zz (Figs 4.12-4.14, 4.19), Λ(y) with Λ horizontal, y vertical, the
molecular 1/3 line and an inset of Λ(0) and mean Λ against e (Figs 3.21, 4.11, 4.20), and
the wall values against e (Fig 3.10).

Dimensionless particle units: d = 1, m = 1, g = 1 (gravity acts): u* = u/√(gd), ω* = ω/√(g/d),
T* = T/(gd), θ* = θ/(gd), y and r in d (every footer says so).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
from matplotlib.lines import Line2D
from matplotlib.ticker import MaxNLocator

from ...plots.common import LINESTYLES, MARKERS, Run, finish, new_figure, run_colour, save
from .poiseuille_data import FlowData, wall_distance

PROFILE_PANELS = (("phi", "φ"), ("ux", "U_x* = U_x/√(gd)"), ("omz", "ω_z* = ω_z/√(g/d)"),
                  ("T", "T* = T/(gd)"), ("theta", "θ* = θ/(gd)"), ("Kn", "Kn = λ/W"))
VDF_COMPONENTS = ("C_x", "C_y", "C_z", "Ω_x", "Ω_y", "Ω_z")
Series = tuple[str, FlowData, int]  # (label, run, 0-based bin)


def _runs(datas: Sequence[FlowData]) -> list[Run]:
    return [Run.of(d.res) for d in dict.fromkeys(datas)]


def _legend(labels: Sequence[str], colours: Sequence, styles: Sequence[str] | None = None,
            markers: Sequence[str] | None = None) -> tuple[list, list[str]]:
    handles = [Line2D([], [], color=c, ls=(styles[i] if styles else "-"),
                      marker=(markers[i] if markers else None), ms=4)
               for i, c in enumerate(colours)]
    return handles, list(labels)


def profiles_figure(datas: Sequence[FlowData], labels: Sequence[str], title: str,
                    out: Path, across: bool = False) -> Path:
    """Six panels against y (Malik's Figs 3.3, 4.2): φ, U_x*, ω_z*, T*, θ*, Kn; ``across``:
    against y/W, for channels of different widths W side by side."""
    fig, axes = new_figure(2, 3, width=3.6, height=2.9)
    colours = [run_colour(i) for i in range(len(datas))]
    for ax, (key, name) in zip(axes.flat, PROFILE_PANELS, strict=True):
        for i, d in enumerate(datas):
            v, e = d.series(key)
            width = float(d.res.scene.box.size[1]) if across else 1.0
            ax.errorbar(d.y / width, v, yerr=e, color=colours[i],
                        marker=MARKERS[i % len(MARKERS)], ms=3, lw=1, capsize=2)
        if across:
            ax.set_xlabel("y/W (wall-normal; walls at 0 and 1)")
            ax.set_xlim(0, 1)
        else:
            ax.set_xlabel("y/d (wall-normal; walls at 0 and 50)")
            ax.set_xlim(0, 50)
        ax.set_ylabel(name)
        if key == "omz":
            ax.axhline(0, color="0.6", lw=0.6)
        if key == "Kn":
            ax.axhline(0.1, color="0.4", lw=0.8, ls="--")
            # at mid-channel, where the near-wall Kn (largest) does not reach the label
            ax.text(0.5, 0.1, "Kn = 0.1 (transitional above)", fontsize=6, va="bottom",
                    ha="center", transform=ax.get_yaxis_transform())
    finish(fig, _runs(datas), title, legend=_legend(labels, colours, markers=[
        MARKERS[i % len(MARKERS)] for i in range(len(datas))]))
    return save(fig, out)


def trace_figure(datas: Sequence[FlowData], title: str, out: Path) -> Path:
    """Kinetic energy per particle (translational, mean flow included) against collisions
    per particle (2 N_pp/N), the start of production marked (Malik's Figs 3.2d, 4.15b): one
    panel per β, one colour per e."""
    betas = sorted({d.flow.beta for d in datas})
    es = sorted({d.flow.e for d in datas})
    fig, axes = new_figure(1, len(betas), width=4.2, height=3.6, sharey=True)
    for ax, beta in zip(axes.flat, betas, strict=True):
        for d in (d for d in datas if d.flow.beta == beta):
            colour = run_colour(es.index(d.flow.e))
            ts, n = d.res.timeseries, d.res.scene.particles.count
            c = np.maximum(2.0 * ts["collisions"] / n, 1e-2)
            ax.plot(c, ts["kinetic_energy"] / n, color=colour, lw=1)
            t0 = float(d.res.attrs.get("equilibration_end", 0.0))
            k = min(int(np.searchsorted(ts["time"], t0)), c.size - 1)
            ax.plot(c[k], ts["kinetic_energy"][k] / n, "|", color=colour, ms=14, mew=2)
        ax.set_xscale("log")
        ax.set_title(f"φ = {datas[0].flow.phi:g}, β = {beta:g}", fontsize=9)
        ax.set_xlabel("collisions per particle (2 N_pp/N)")
    axes[0, 0].set_ylabel("kinetic energy per particle E/N (m g d)")
    finish(fig, _runs(datas), title + " (| = start of averaging)",
           legend=_legend([f"e = {e:g}" for e in es],
                          [run_colour(i) for i in range(len(es))]))
    return save(fig, out)


#: the VDF panels' line styles: no dashes, which mark the Gaussian (Malik's black dashed line)
VDF_STYLES = ("-", "-.", ":", (0, (4, 1, 1, 1, 1, 1)))
#: the panels' upper limit of P/P(0): a curve beyond it is a core the P(0) = 1 scaling fails on
VDF_TOP = 3.0


def vdf_figure(series: Sequence[Series], title: str, out: Path) -> Path:
    """Six panels P(x) against x = C/σ (P(0) = 1, log scale) with the Gaussian exp(-x²/2);
    shaded: ± the block-jackknife error; histogram bins with errors > 50 % are left out. A
    curve that leaves the panel (P/P(0) > VDF_TOP: a spike the P(0) = 1 scaling cannot
    normalise, e.g. a plug's bin whose σ is its drift) or has no resolved bin is named in
    the panel, not left to look like missing data."""
    fig, axes = new_figure(2, 3, width=3.4, height=2.9)
    colours = _series_colours(series)
    for c, ax in enumerate(axes.flat):
        notes = []
        for i, (label, d, b) in enumerate(series):
            vdf = d.stat("vdf")
            if "malik_P" not in vdf:
                continue
            x, p, e = vdf["malik_centres"], vdf["malik_P"][b, c], vdf["malik_P_err"][b, c]
            # histogram bins resolved within their error only (the far tails are noise)
            ok = (p > 0) & np.isfinite(e) & (e < 0.5 * p)
            if not ok.any():
                notes.append(f"{label.split(' (')[0]}: no resolved bin")
                continue
            ax.plot(x[ok], p[ok], color=colours[i], ls=VDF_STYLES[i % 4], lw=1.3)
            ax.fill_between(x[ok], np.maximum(p[ok] - e[ok], 1e-5), p[ok] + e[ok],
                            color=colours[i], alpha=0.25, lw=0)
            if p[ok].max() > VDF_TOP:
                notes.append(f"{label.split(' (')[0]}: off scale (peak {p[ok].max():.0f})")
        x = np.linspace(-5, 5, 201)
        ax.plot(x, np.exp(-0.5 * x**2), "k--", lw=1)
        ax.set_yscale("log")
        ax.set_ylim(1e-4, VDF_TOP)
        ax.set_xlim(-5, 5)
        ax.set_xlabel(f"{VDF_COMPONENTS[c]}/σ")
        ax.set_ylabel(f"P({VDF_COMPONENTS[c]}/σ), P(0) = 1")
        if notes:  # the empty floor between the Gaussian's flanks
            ax.text(0.5, 0.04, "\n".join(notes), transform=ax.transAxes, ha="center",
                    va="bottom", fontsize=7, color="0.25")
    labels = [s[0] for s in series] + ["Gaussian exp(-x²/2)"]
    handles, labels = _legend(labels, colours + ["k"],
                              [VDF_STYLES[i % 4] for i in range(len(series))] + ["--"])
    finish(fig, _runs([s[1] for s in series]), title, legend=(handles, labels))
    return save(fig, out)


def _series_colours(series: Sequence[Series]) -> list:
    """One colour per run; the bins of one run in shades of it."""
    runs = list(dict.fromkeys(id(s[1]) for s in series))
    seen: dict[int, int] = {}
    out = []
    for _label, d, _b in series:
        r = runs.index(id(d))
        out.append(run_colour(r, seen.get(r, 0)))
        seen[r] = seen.get(r, 0) + 1
    return out


def gr_figure(series: Sequence[Series], title: str, out: Path) -> Path:
    """In-bin g(r) against r/d (both particles in the bin; 3D distance, slab-corrected)."""
    fig, axes = new_figure(1, 1, width=6.5, height=3.8)
    ax = axes[0, 0]
    colours = _series_colours(series)
    for i, (_label, d, b) in enumerate(series):
        if not d.gr:
            continue
        r, g, e = d.gr["r"], d.gr["g"][b], d.gr["g_err"][b]
        ok = r >= 1.0
        ax.errorbar(r[ok], g[ok], yerr=e[ok], color=colours[i], ls=LINESTYLES[i % 4], lw=1.4,
                    elinewidth=0.5)
    ax.axhline(1.0, color="0.6", lw=0.6)
    ax.set_xlabel("r/d (pairs inside the bin, 3D distance)")
    ax.set_ylabel("g(r) (ideal gas = 1)")
    finish(fig, _runs([s[1] for s in series]), title,
           legend=_legend([s[0] for s in series], colours,
                          [LINESTYLES[i % 4] for i in range(len(series))]))
    return save(fig, out)


def vcorr_figure(series: Sequence[Series], title: str, out: Path) -> Path:
    """C_xx, C_yy, C_zz against r/d, normalised by the self term (C(0+) = 1 for a smooth
    field, 0 for independent velocities)."""
    fig, axes = new_figure(1, 3, width=3.4, height=3.2)
    colours = _series_colours(series)
    for c, ax in enumerate(axes.flat):
        for i, (_label, d, b) in enumerate(series):
            vc = d.stat("vcorr")
            if "C" not in vc:
                continue
            r, v, e = vc["r"], vc["C"][b, c], vc["C_err"][b, c]
            ok = np.isfinite(v) & (r >= 0.95)
            ax.errorbar(r[ok], v[ok], yerr=e[ok], color=colours[i], ls=LINESTYLES[i % 4],
                        lw=1.4, elinewidth=0.5)
        ax.axhline(0, color="0.6", lw=0.6)
        ax.set_xlabel("r/d")
        ax.set_ylabel(f"C_{'xyz'[c] * 2}(r) (self term = 1)")
    finish(fig, _runs([s[1] for s in series]), title,
           legend=_legend([s[0] for s in series], colours,
                          [LINESTYLES[i % 4] for i in range(len(series))]))
    return save(fig, out)


def lambda_figure(panels: Sequence[tuple[str, Sequence[FlowData]]], title: str,
                  out: Path) -> Path:
    """Λ(y) horizontal, y vertical, one panel per β with its runs over e, the molecular
    value 1/3; below each, the thesis's inset as its own panel (so that it covers no data):
    Λ at the centre (bin 13) and the bin mean against e."""
    fig, axes = new_figure(2, len(panels), width=3.6, height=3.0,
                           gridspec_kw={"height_ratios": [2.2, 1]})
    every = [d for _t, datas in panels for d in datas]
    # one colour per e (each panel is one β, so a run is its panel and its colour)
    es = sorted({d.flow.e for d in every})
    colours = {id(d): run_colour(es.index(d.flow.e)) for d in every}
    for k, (name, datas) in enumerate(panels):
        ax = axes[0, k]
        for d in datas:
            lam = d.stat("lambda")
            if "lambda" not in lam:
                continue
            ax.errorbar(lam["lambda"], lam["y"], xerr=lam["lambda_err"], color=colours[id(d)],
                        marker="o", ms=3, lw=1, elinewidth=0.6)
        ax.axvline(1 / 3, color="saddlebrown", lw=0.9, alpha=0.7, zorder=0)  # under the data
        ax.xaxis.set_major_locator(MaxNLocator(4))
        ax.set_xlabel("Λ = <cos²Ψ> (brown: molecular 1/3)")
        ax.set_ylabel("y/d")
        ax.set_ylim(0, 50)
        ax.set_title(name, fontsize=9)
        _lambda_inset(axes[1, k], datas)
    finish(fig, _runs(every), title,
           legend=_legend([f"e = {e:g} (panels: β)" for e in es],
                          [run_colour(i) for i in range(len(es))]))
    return save(fig, out)


def _lambda_inset(ax, datas: Sequence[FlowData]) -> None:
    """Λ at the centre (bin 13) and the mean over the bins against e, with errors."""
    from .poiseuille_checks import lambda_mean

    good = sorted((d for d in datas if "lambda" in d.stat("lambda")), key=lambda d: d.flow.e)
    e = [d.flow.e for d in good]
    centre = [(d.stat("lambda")["lambda"][12], d.stat("lambda")["lambda_err"][12])
              for d in good]
    mean = [lambda_mean(d) for d in good]
    if good:
        ax.errorbar(e, [c[0] for c in centre], yerr=[c[1] for c in centre], fmt="ko-", ms=3,
                    lw=0.8, capsize=2, label="Λ(centre, bin 13)")
        ax.errorbar(e, [m[0] for m in mean], yerr=[m[1] for m in mean], fmt="s--",
                    color="0.5", ms=3, lw=0.8, capsize=2, label="mean Λ over y")
        ax.legend(fontsize=6, frameon=False)
    ax.axhline(1 / 3, color="saddlebrown", lw=0.8)
    ax.set_xlabel("e")
    ax.set_ylabel("Λ")


#: Fig 3.10's panels: the wall values (FlowData.wall_value)
WALL_PANELS = (("ux", "U_x,w* (slip)"), ("omz", "ω_z,w* (rotational slip)"), ("T", "T_w*"),
               ("theta", "θ_w*"))
#: Fig 3.11's panels: the wall gradients (poiseuille_checks.wall_slope): the change per d from
#: the wall into the flow of each wall value (ω_z: rolling along the wall > 0)
GRADIENT_PANELS = (("ux", "dU_x*/dy, inward [1/d]"), ("omz", "dω_z*/dy, inward [1/d]"),
                   ("T", "dT*/dy, inward [1/d]"), ("theta", "dθ*/dy, inward [1/d]"))


def wall_figure(by_beta: Sequence[tuple[str, Sequence[FlowData]]], title: str,
                out: Path, value: Callable[[FlowData, str], tuple[float, float]] | None = None,
                panels: Sequence[tuple[str, str]] = WALL_PANELS) -> Path:
    """Fig 3.10: against e, one curve per β: translational slip U_x,w, rotational slip
    ω_z,w (> 0: rolling along the walls), T_w and θ_w (the mean of bins 1 and 25); with
    ``value`` = ``wall_slope`` and ``GRADIENT_PANELS``, Fig 3.11's wall gradients."""
    value = value or FlowData.wall_value
    fig, axes = new_figure(1, 4, width=3.0, height=3.0)
    colours = [run_colour(i) for i in range(len(by_beta))]
    for ax, (key, name) in zip(axes.flat, panels, strict=True):
        for i, (_label, datas) in enumerate(by_beta):
            e = [d.flow.e for d in datas]
            vals = np.array([value(d, key) for d in datas])
            if vals.size:
                ax.errorbar(e, vals[:, 0], yerr=vals[:, 1], color=colours[i],
                            marker=MARKERS[i], ms=4, lw=1, capsize=2)
        ax.set_xlabel("e")
        ax.set_ylabel(name)
    every = [d for _l, ds in by_beta for d in ds]
    finish(fig, _runs(every), title,
           legend=_legend([b[0] for b in by_beta], colours, markers=list(MARKERS[:3])))
    return save(fig, out)


def freepath_figure(by_beta: Sequence[tuple[str, Sequence[FlowData]]], title: str,
                    out: Path, b: int) -> Path:
    """Fig 3.9: the free-path distribution P(l) in bin ``b`` (0-based; free paths relative
    to the local mean flow, the collision log's) for several e, one panel per β, log scale;
    dashed: the exponential exp(-l/λ)/λ with the run's own mean free path λ."""
    fig, axes = new_figure(1, len(by_beta), width=3.6, height=3.2)
    es = sorted({d.flow.e for _l, ds in by_beta for d in ds})
    colours = {e: run_colour(i) for i, e in enumerate(es)}
    for ax, (label, datas) in zip(axes.flat, by_beta, strict=True):
        for d in datas:
            fp = d.stat("freepath")
            if "p_lambda" not in fp:
                continue
            x, p, e = fp["lambda"], fp["p_lambda"][b], fp["p_lambda_err"][b]
            ok = (p > 0) & np.isfinite(e) & (e < 0.5 * p)
            ax.errorbar(x[ok], p[ok], yerr=e[ok], color=colours[d.flow.e], lw=1, ms=2,
                        marker="o", elinewidth=0.5)
            lam = float(fp["mean_free_path"][b])
            span = x[x <= x[ok].max()] if ok.any() else x
            ax.plot(span, np.exp(-span / lam) / lam, color=colours[d.flow.e], ls="--", lw=0.8)
        if datas:  # the walls end flights longer than the bin's distance to them
            ax.axvline(wall_distance(datas[0].y, b), color="0.5", ls=":", lw=1)
        ax.set_yscale("log")
        ax.set_xlabel("free path l [d]")
        ax.set_ylabel("P(l) [1/d]")
        ax.set_title(label, fontsize=9)
    labels = [f"e = {e:g}" for e in es] + ["exp(-l/λ)/λ, the run's λ",
                                           "distance from the bin to a wall"]
    handles, labels = _legend(labels, [colours[e] for e in es] + ["0.3", "0.5"],
                              ["-"] * len(es) + ["--", ":"])
    finish(fig, _runs([d for _l, ds in by_beta for d in ds]), title, legend=(handles, labels))
    return save(fig, out)
