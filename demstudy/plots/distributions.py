"""Velocity distributions (Campbell's P(X), Malik's C/σ), collision-angle distributions and
free-path / free-time distributions.

Dimensionless particle units: d = 1, m = 1, g = 1 with gravity. Line2D ``gid``s name the
data ("<file>:<dataset>:<bin>:<panel>") so that tests can read them back.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import NullLocator

from .common import (
    LINESTYLES,
    MARKERS,
    Run,
    bin_label,
    finish,
    new_figure,
    pick_bins,
    run_colour,
)

X_TITLES = {
    "X1": "X1 = |u′| / √⟨u′²⟩",
    "X2": "X2 = |v′| / √⟨v′²⟩",
    "X3": "X3 = |ω_z′| / √⟨ω_z′²⟩",
    "X4": "X4: translational",
    "X5": "X5: translational + rotational",
}
MALIK_TITLES = {"u": "C_x", "v": "C_y", "w": "C_z", "omega_x": "Ω_x", "omega_y": "Ω_y",
                "omega_z": "Ω_z"}


def _split(attrs: dict, key: str, default: str) -> list[str]:
    return [s for s in str(attrs.get(key, default)).split(",") if s]


def draw_vdf(runs: Sequence[Run], bins: Sequence[int] | None = None) -> Figure:
    """Top row: Campbell's P(X) for X1…X5 (histogram of 0.1-wide bins, normalised on
    [0, ∞)) with the folded Maxwellians (chi densities, averaged over each histogram bin;
    a = ½, ½, ½, 1, 3/2 in 2D). Bottom row: Malik's P(C/σ) per translational and spin
    component, scaled to P(0) = 1, log scale, with the Gaussian exp(−x²/2)."""
    comps = [_split(run.group("vdf")[1], "malik_components", "u,v,omega_z") for run in runs]
    n_malik = max(len(c) for c in comps)
    n_cols = max(5, n_malik)
    fig, axes = new_figure(2, n_cols, width=3.2, height=3.2)
    for ax in axes[0, 5:]:
        ax.set_visible(False)
    for ax in axes[1, n_malik:]:
        ax.set_visible(False)
    for r, run in enumerate(runs):
        data, attrs = run.group("vdf")
        y, count = np.asarray(data["y"], float), np.asarray(data["count"], float)
        chosen = pick_bins(count > 0, bins)
        prefix = f"{run.label}, " if len(runs) > 1 else ""
        names = _split(attrs, "X_names", "X1,X2,X3,X4,X5")
        dof = _split(attrs, "X_degrees_of_freedom", "1,1,1,2,3")
        a_vals = _split(attrs, "X_a", "0.5,0.5,0.5,1,1.5")
        xc = np.asarray(data["X_centres"], float)
        for k, name in enumerate(names[:5]):
            ax = axes[0, k]
            err = data.get("X_err")
            for i, b in enumerate(chosen):
                ax.errorbar(xc, data["X"][b, k], yerr=None if err is None else err[b, k],
                            ls=LINESTYLES[i % len(LINESTYLES)], lw=1,
                            marker=MARKERS[i % len(MARKERS)], ms=2, elinewidth=0.6,
                            color=run_colour(r, i), label=f"{prefix}{bin_label(y, b)}",
                            gid=f"{run.path.name}:X:{b}:{name}")
            if r == 0:
                ax.plot(xc, data["X_reference"][k], "k--", lw=1,
                        label=f"folded Maxwellian (k = {dof[k]}, a = {a_vals[k]})",
                        gid=f"{run.path.name}:X_reference:-:{name}")
            ax.set_title(X_TITLES.get(name, name), fontsize=9)
            ax.set_xlabel(name)
            ax.set_ylabel("P(X)")
            ax.grid(alpha=0.3)
        cc = np.asarray(data["malik_centres"], float)
        for c, comp in enumerate(comps[r]):
            ax = axes[1, c]
            err = data.get("malik_P_err")
            for i, b in enumerate(chosen):
                ax.errorbar(cc, data["malik_P"][b, c], ls="none",
                            yerr=None if err is None else err[b, c], elinewidth=0.6,
                            marker=MARKERS[i % len(MARKERS)], ms=3, mfc="none" if r else None,
                            color=run_colour(r, i), label=f"{prefix}{bin_label(y, b)}",
                            gid=f"{run.path.name}:malik_P:{b}:{comp}")
            ax.set_yscale("log")
            if r == 0:
                ax.plot(cc, data["gaussian"], "k--", lw=1, label="Gaussian exp(−x²/2)",
                        gid=f"{run.path.name}:gaussian:-:{comp}")
            title = MALIK_TITLES.get(comp, comp)
            ax.set_title(f"{title} / σ (P(0) = 1)", fontsize=9)
            ax.set_xlabel(f"{title}/σ")
            ax.set_ylabel("P")
            ax.set_ylim(1e-4, 3)
            ax.yaxis.set_minor_locator(NullLocator())  # decades only: cheaper to draw
            ax.grid(alpha=0.3)
    # one legend below the panels (the distributions fill them): the bins, then each
    # reference curve once
    entries: dict[str, object] = {}
    for ax in (axes[0, 0], axes[0, 4], axes[1, 0]):
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            entries.setdefault(label, handle)
    references = ("folded Maxwellian", "Gaussian")  # after the runs' bins
    entries = dict(sorted(entries.items(), key=lambda kv: kv[0].startswith(references)))
    return finish(fig, runs, "velocity distributions: Campbell's P(X) (top), "
                             "Malik's C/σ (bottom), fluctuations about the bin means; error "
                             "bars: block averages",
                  legend=(list(entries.values()), list(entries)))


def draw_angles(runs: Sequence[Run], bins: Sequence[int] | None = None) -> Figure:
    """P(θ) (per radian, normalised on [0, π)) of pair collisions in chosen y-bins, in the
    thesis-text convention (θ from the flow direction) and Campbell's listing convention
    (θ = π/2 − θ_text), with Savage–Jeffrey's (1/π) erfc(S cos θ sin θ/√2) for the length R
    (dashed) and the mean spacing C (dotted), and the isotropic 1/π."""
    fig, axes = new_figure(1, 2, width=5.0, height=4.2)
    axes = axes[0]
    titles = {"text": "thesis text: θ = atan2(n_y, n_x) mod π",
              "listing": "Campbell's listing: θ = (π/2 − θ_text) mod π"}
    for r, run in enumerate(runs):
        data, _attrs = run.group("angles")
        y = np.asarray(data["y"], float)
        deg = np.degrees(np.asarray(data["theta"], float))
        chosen = pick_bins(np.asarray(data["pair_collisions"]) > 0, bins)
        prefix = f"{run.label}, " if len(runs) > 1 else ""
        for ax, conv in zip(axes, ("text", "listing"), strict=True):
            if f"p_{conv}" not in data:
                continue
            for i, b in enumerate(chosen):
                s = data.get(f"s_{conv}")
                s_text = "" if s is None or not np.isfinite(s[b]) else f", S = {float(s[b]):.2f}"
                err = data.get(f"p_{conv}_err")
                ax.errorbar(deg, data[f"p_{conv}"][b], yerr=None if err is None else err[b],
                            ls="-", marker=MARKERS[i % len(MARKERS)], ms=2, capsize=1,
                            color=run_colour(r, i),
                            label=f"{prefix}{bin_label(y, b)}{s_text}",
                            gid=f"{run.path.name}:p_{conv}:{b}")
                for key, style, what in (("R", "--", "R"), ("C", ":", "C")):
                    sj = data.get(f"sj_{conv}_{key}")
                    if sj is not None and np.any(np.isfinite(sj[b])):
                        ax.plot(deg, sj[b], ls=style, color=run_colour(r, i), lw=1,
                                label=f"Savage–Jeffrey ({what})" if i == 0 and r == 0 else None,
                                gid=f"{run.path.name}:sj_{conv}_{key}:{b}")
            ax.axhline(1 / np.pi, color="0.5", lw=0.8, label="isotropic 1/π" if r == 0 else None)
            ax.set_title(titles[conv], fontsize=9)
            ax.set_xlabel("θ (degrees)")
            ax.set_ylabel("P(θ) (per radian)")
            ax.set_xlim(0, 180)
            ax.set_xticks(np.arange(0, 181, 30))
            ax.grid(alpha=0.3)
    # below the panels: the distributions fill the whole θ range, so no corner is free
    return finish(fig, runs, "collision-angle distributions (pair collisions, contact point "
                             "binned in y); dashed/dotted: Savage–Jeffrey with R / C",
                  legend=axes[0].get_legend_handles_labels(), max_cols=3)


def _fmt(data: dict, key: str, b: int) -> str:
    """``value ± err`` of a per-bin dataset (3 significant digits), "?" when absent."""
    if key not in data:
        return "?"
    err = data.get(f"{key}_err")
    text = f"{float(data[key][b]):.3g}"
    return text if err is None else f"{text} ± {float(err[b]):.2g}"


def draw_freepath(runs: Sequence[Run], bins: Sequence[int] | None = None) -> Figure:
    """P(λ) and P(τ) per chosen y-bin (flights binned by their starting centre) on log y axes
    with error bars, and dashed the exponential (1/⟨x⟩) exp(−x/⟨x⟩) of the bin's measured
    mean: a dilute hard-sphere gas is close to it but not exactly on it (moment ratio 2.10,
    not 2), so departures show correlations or a speed-dependent collision rate. The
    legend gives ⟨λ⟩, Kn and Enskog's λ (⟨τ⟩ and Enskog's τ) where stored."""
    fig, axes = new_figure(1, 2, width=5.0, height=4.2)
    axes = axes[0]
    panels = (("lambda", "mean_free_path", "lambda_enskog", "λ", "free path λ (d)"),
              ("tau", "mean_free_time", "tau_enskog", "τ", "free time τ (particle units)"))
    widths = []
    for r, run in enumerate(runs):
        data, attrs = run.group("freepath")
        y = np.asarray(data["y"], float)
        occupied = np.asarray(data.get("flights", data["mean_free_path"]), float) > 0
        chosen = pick_bins(occupied & np.isfinite(data["mean_free_path"]), bins)
        prefix = f"{run.label}, " if len(runs) > 1 else ""
        if "knudsen_width" in attrs:
            widths.append(f"{float(attrs['knudsen_width']):.3g} "
                          f"({attrs.get('knudsen_width_is', 'Kn length')})")
        for ax, (x_key, mean_key, enskog_key, sym, xlabel) in zip(axes, panels, strict=True):
            x = np.asarray(data[x_key], float)
            for i, b in enumerate(chosen):
                label = f"{prefix}{bin_label(y, b)}: ⟨{sym}⟩ = {_fmt(data, mean_key, b)}"
                if x_key == "lambda":
                    label += f", Kn = {_fmt(data, 'knudsen', b)}"
                if enskog_key in data:
                    label += f", Enskog {sym}_E = {float(data[enskog_key][b]):.3g}"
                err = data.get(f"p_{x_key}_err")
                ax.errorbar(x, data[f"p_{x_key}"][b], yerr=None if err is None else err[b],
                            ls="-", marker=MARKERS[i % len(MARKERS)], ms=2, capsize=1,
                            color=run_colour(r, i), label=label,
                            gid=f"{run.path.name}:p_{x_key}:{b}")
                # the reference uses the bin's own measured mean: it tests the shape only
                mean = float(data[mean_key][b])
                ax.plot(x, np.exp(-x / mean) / mean, ls="--", lw=0.8, color=run_colour(r, i),
                        label="exponential (1/⟨x⟩) e^(−x/⟨x⟩)" if i == 0 and r == 0 else None,
                        gid=f"{run.path.name}:exp_{x_key}:{b}")
            ax.set_yscale("log")
            ax.set_xlabel(xlabel)
            ax.set_ylabel(f"P({sym}) (per unit {'length' if x_key == 'lambda' else 'time'})")
            ax.grid(alpha=0.3, which="both")
    title = ("free paths λ and free times τ per y-bin (centre to centre relative to the local "
             "mean flow, starting centre's bin)")
    if widths:
        title += "\nKn = ⟨λ⟩/W, W = " + ", ".join(dict.fromkeys(widths))
    # below the panels (the distributions reach every corner): the λ panel's entries, then
    # the τ panel's
    entries: dict[str, object] = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            entries.setdefault(label, handle)
    return finish(fig, runs, title, legend=(list(entries.values()), list(entries)),
                  max_cols=2, legend_size=6)
