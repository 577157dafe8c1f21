"""Pair correlation g(r), Campbell's structure distributions, velocity correlations C_αα(r),
C_αβ(r) and Malik's Λ(y).

Dimensionless particle units: d = 1, m = 1, g = 1 with gravity (r in particle diameters).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

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
from .profiles import _edges, panels_with_legend_row


def _artefact(ax, r_edges: np.ndarray, flags: np.ndarray | None) -> None:
    """Shade the shells beyond half the shortest periodic length (several images counted)."""
    if flags is not None and np.any(flags):
        ax.axvspan(float(r_edges[:-1][np.asarray(flags, bool)][0]), float(r_edges[-1]),
                   color="0.85", zorder=0, label="beyond L_min/2 (image artefact)")


def _gr_variants(run: Run) -> list[tuple[str, dict, dict]]:
    """The stored g(r) groups: ``statistics/gr`` and any in-bin variant (``statistics/gr*``
    holding ``g``), each (name, data, attrs)."""
    groups = run.results.groups
    names = sorted(k for k in groups if k.startswith("statistics/gr") and "g" in groups[k])
    return [(k.split("/", 1)[1], groups[k], run.results.group_attrs.get(k, {})) for k in names]


def draw_gr(runs: Sequence[Run], bins: Sequence[int] | None = None) -> Figure:
    """g(r) against r/d: the whole-box g(r) (one row of ``g``) and, when stored with y-bins
    (``attrs in_bin``, or a ``statistics/gr*`` in-bin variant), g(r) in chosen bins (Malik's
    in-bin reading); grey: shells beyond half the shortest periodic length."""
    variants = {}
    for run in runs:
        for name, data, attrs in _gr_variants(run):
            in_bin = bool(attrs.get("in_bin", False)) or np.asarray(data["g"]).shape[0] > 1
            variants.setdefault("in-bin g(r)" if in_bin else "g(r)", []).append(
                (run, name, data, in_bin))
    panels = sorted(variants, key=len)
    fig, axes = new_figure(1, len(panels), width=5.0, height=4.0)
    entries: dict[str, Any] = {}
    for ax, panel in zip(axes[0], panels, strict=True):
        for run, name, data, in_bin in variants[panel]:
            r = runs.index(run)  # the run's colour in every panel
            g = np.atleast_2d(np.asarray(data["g"], float))
            g_err = data.get("g_err")
            g_err = None if g_err is None else np.atleast_2d(np.asarray(g_err, float))
            rr = np.asarray(data["r"], float)
            prefix = f"{run.label}, " if len(runs) > 1 else ""
            if in_bin:
                y = np.asarray(data["y"], float)
                valid = np.asarray(data.get("mean_count", np.ones(g.shape[0])), float) > 1
                rows = pick_bins(valid, bins)
                labels = [f"{prefix}{bin_label(y, b)}" for b in rows]
            else:
                rows, labels = [0], [f"{prefix}whole box".rstrip(", ")]
            for i, (b, label) in enumerate(zip(rows, labels, strict=True)):
                ax.errorbar(rr, g[b], yerr=None if g_err is None else g_err[b],
                            ls=LINESTYLES[i % len(LINESTYLES)], color=run_colour(r, i), lw=1.2,
                            elinewidth=0.6, label=label, gid=f"{run.path.name}:{name}:{b}")
            if not any(p.get_label().startswith("beyond") for p in ax.patches):
                _artefact(ax, np.asarray(data["r_edges"], float), data.get("image_artefact"))
        ax.axhline(1.0, color="0.5", lw=0.8)
        ax.set_title(panel, fontsize=9)
        ax.set_xlabel("r (particle diameters)")
        ax.set_ylabel("g(r)")
        ax.grid(alpha=0.3)
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            entries.setdefault(label, handle)
    # below the panels: g(r) fills them (peaks at contact, tails at 1)
    return finish(fig, runs, "pair correlation function; error bars: block averages",
                  legend=(list(entries.values()), list(entries)), max_cols=2)


def draw_vcorr(runs: Sequence[Run], bins: Sequence[int] | None = None) -> Figure:
    """Malik's C_αα(r) per component (x, y[, z]) in chosen y-bins: the normalised correlation
    of the velocity fluctuations about the run-mean bin velocities (C → 1 as r → 0+); below,
    when stored, the off-diagonal C_αβ(r) (xy[, xz, yz]; symmetrised over the pair order,
    normalised by √(⟨u'_α²⟩⟨u'_β²⟩)), which can be negative: C_xy carries the shear stress."""
    dim = max(int(run.group("vcorr")[0]["C"].shape[1]) for run in runs)
    off = any("C_offdiag" in run.group("vcorr")[0] for run in runs)
    # off-diagonal values are usually much smaller than C_αα(0+) = 1: a y scale per row
    fig, axes = new_figure(2 if off else 1, dim, width=4.5, height=4.0, sharey="row")
    for r, run in enumerate(runs):
        data, attrs = run.group("vcorr")
        rr, y = np.asarray(data["r"], float), np.asarray(data["y"], float)
        c = np.asarray(data["C"], float)
        chosen = pick_bins(np.asarray(data.get("count", np.ones(c.shape[0])), float) > 0, bins)
        prefix = f"{run.label}, " if len(runs) > 1 else ""
        c_err = data.get("C_err")
        panels = [(axes[0, a], "xyz"[a] * 2, c[:, a],
                   None if c_err is None else np.asarray(c_err, float)[:, a], f"C:{{b}}:{a}")
                  for a in range(c.shape[1])]
        if "C_offdiag" in data:
            c_off = np.asarray(data["C_offdiag"], float)
            off_err = data.get("C_offdiag_err")
            names = str(attrs.get("offdiag_components", "xy,xz,yz")).split(",")
            panels += [(axes[1, p], names[p], c_off[:, p],
                        None if off_err is None else np.asarray(off_err, float)[:, p],
                        f"C_offdiag:{{b}}:{p}") for p in range(c_off.shape[1])]
        for ax, comp, values, errors, gid in panels:
            for i, b in enumerate(chosen):
                ax.errorbar(rr, values[b], yerr=None if errors is None else errors[b],
                            ls=LINESTYLES[i % len(LINESTYLES)], marker=MARKERS[i % len(MARKERS)],
                            ms=2.5, lw=1, elinewidth=0.6, capsize=0, color=run_colour(r, i),
                            mfc="none" if r else None, label=f"{prefix}{bin_label(y, b)}",
                            gid=f"{run.path.name}:{gid.format(b=b)}")
            if not ax.get_title():  # first run drawn in this panel
                _artefact(ax, np.asarray(data["r_edges"], float), data.get("image_artefact"))
                ax.set_title(f"C_{comp}(r)", fontsize=9)
                ax.axhline(0.0, color="0.5", lw=0.8)
                ax.set_xlabel("r (particle diameters)")
                ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel("C_αα(r)")
    if off:
        axes[1, 0].set_ylabel("C_αβ(r), symmetrised")
        for ax in axes[1]:
            ax.set_visible(bool(ax.get_title()))  # 2D: one off-diagonal panel of two
    # below the panels: the correlations are largest at contact, in the corner a legend
    # would take
    return finish(fig, runs, "spatial velocity correlations (fluctuations about the "
                             "run-mean bin velocity); error bars: block averages",
                  legend=axes[0, 0].get_legend_handles_labels(), max_cols=3)


def draw_lambda(runs: Sequence[Run]) -> Figure:
    """Malik's Λ(y) = ⟨cos² Ψ⟩ (horizontal) against y (vertical) with error bars, the pooled
    estimate dotted, and the uncorrelated value 1/3 (vertical line)."""
    fig, axes = new_figure(1, 1, width=5.0, height=5.0)
    ax = axes[0, 0]
    for r, run in enumerate(runs):
        data, _attrs = run.group("lambda")
        y, lam = np.asarray(data["y"], float), np.asarray(data["lambda"], float)
        mask = np.asarray(data.get("count", np.ones_like(y)), float) > 0
        err = data.get("lambda_err")
        ax.errorbar(lam[mask], y[mask], xerr=None if err is None else np.asarray(err)[mask],
                    marker="o", ms=3, capsize=2, color=f"C{r}", label=f"{run.label}: Λ",
                    gid=f"{run.path.name}:lambda")
        if "lambda_pooled" in data:
            ax.plot(np.asarray(data["lambda_pooled"])[mask], y[mask], ls=":", color=f"C{r}",
                    label=f"{run.label}: pooled Σcos²Ψ/ΣN", gid=f"{run.path.name}:lambda_pooled")
    ax.axvline(1 / 3, color="brown", lw=1.2, label="uncorrelated 1/3")
    ax.set_xlabel("Λ = ⟨cos² Ψ⟩ (translational vs spin fluctuation)")
    ax.set_ylabel("y (particle diameters)")
    ax.set_xlim(0, 1)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper right")
    return finish(fig, runs, "orientational correlation Λ(y)")


def _bin_overlap(edges: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Length of each bin [e_b, e_b+1) inside [lo, hi]."""
    return np.clip(np.minimum(edges[1:], hi) - np.maximum(edges[:-1], lo), 0.0, None)


def structure_references(run: Run) -> dict[str, float]:
    """Campbell's dilute-limit densities of a run from its ``/profiles``: ``n_mean``, the mean
    number density between the profile bounds (Σ n_b w_b / Σ w_b over the bins, empty bins
    counting 0: N/V, Campbell's n = ν/(πR²) with the run's mean ν), ``nu_mean`` the mean solid
    fraction, and ``n_test`` the number density of the test region (bins within
    ``half_width`` of the structure's mid-plane, overlap-weighted; profiles along y only).
    Empty without ``/profiles``."""
    prof = run.results.profiles
    if not prof or "number_density" not in prof or "y" not in prof:
        return {}
    edges = _edges(prof)
    widths = np.diff(edges)
    n = np.asarray(prof["number_density"], float)
    n = np.where(np.isfinite(n), n, 0.0)  # an empty bin holds no particle
    out = {"n_mean": float(np.sum(n * widths) / np.sum(widths))}
    if "solid_fraction" in prof:
        out["nu_mean"] = float(np.sum(np.asarray(prof["solid_fraction"], float) * widths)
                               / np.sum(widths))
    _data, attrs = run.group("structure")
    if run.results.profile_attrs.get("axis", "y") == "y" and "half_width" in attrs:
        # the mid-plane the analysis used (files written before it was stored: the middle
        # of the profile range)
        y_mid = float(attrs.get("y_mid", 0.5 * (edges[0] + edges[-1])))
        h = float(attrs["half_width"])
        overlap = _bin_overlap(edges, y_mid - h, y_mid + h)
        if overlap.sum() > 0:
            out["n_test"] = float(np.sum(n * overlap) / overlap.sum())
    return out


def draw_structure(runs: Sequence[Run]) -> Figure:
    """Campbell's (1982) structure distributions, in his figures' form: left the normal
    distribution (number density of partners at a distance |Δy| from a test particle, over
    the whole periodic cross-section), right the parallel one (against |Δx| in 2D,
    √(Δx² + Δz²) in 3D, for partners with |Δy| < h), test particles within h of the
    mid-plane, with error bars; dashed in the run's colour the dilute, uncorrelated limit
    n̄ = the run's mean number density (Campbell's normalisation, n = ν/(πR²) in 2D), dotted
    the number density of the test region (the limit the estimator tends to when the density
    varies across the channel). Top axis: Campbell's unit R = d/2."""
    refs = [structure_references(run) for run in runs]
    empty = [ref.get("n_test") == 0.0
             or not np.any(np.asarray(run.group("structure")[0]["normal"], float))
             for run, ref in zip(runs, refs, strict=True)]
    fig, axes, legend_row = panels_with_legend_row(2, len(runs) + sum(empty), width=5.2,
                                                   height=4.4, sharey="row")
    dims, widths = set(), set()
    # legend below the panels, one row per run: the data, n̄, the test region's n
    columns: list[list[tuple[Any, str]]] = [[], [], []]
    blank = (Line2D([], [], alpha=0), "")
    for r, run in enumerate(runs):
        data, attrs = run.group("structure")
        name, colour = run.path.name, f"C{r}"
        dims.add(int(attrs.get("dim", 2)))
        widths.add(f"{float(attrs.get('half_width', 1.0)):.3g}")
        ref = refs[r]
        rr = np.asarray(data["r"], float)
        label = run.label + (f", ν̄ = {ref['nu_mean']:.3g}" if "nu_mean" in ref else "")
        if empty[r]:  # e.g. an open-top chute: the box's mid-plane lies above the flow
            label += "\nNO PARTICLES AT THE MID-PLANE: the distributions are empty"
        labels = (label,
                  f"n̄ = {ref.get('n_mean', 0):.3g}: mean number density (dilute limit, "
                  "Campbell)", f"n = {ref.get('n_test', 0):.3g} in the test region")
        row: list[tuple[Any, str]] = []
        for ax, key in zip(axes, ("normal", "parallel"), strict=True):
            err = data.get(f"{key}_err")
            row = [(ax.errorbar(rr, np.asarray(data[key], float), yerr=err,
                                marker=MARKERS[r % len(MARKERS)], ms=3, lw=1, capsize=1.5,
                                color=colour, label=labels[0], gid=f"{name}:{key}"),
                    labels[0])]
            for ref_key, style, text in (("n_mean", "--", labels[1]),
                                         ("n_test", ":", labels[2])):
                if ref_key in ref:
                    row.append((ax.axhline(ref[ref_key], color=colour, ls=style, lw=1.2,
                                           label=text, gid=f"{name}:{ref_key}:{key}"), text))
                else:
                    row.append(blank)
        for column, entry in zip(columns, row, strict=True):
            column.append(entry)
    inplane = {frozenset({2}): "|Δx|", frozenset({3}): "√(Δx² + Δz²)"}.get(
        frozenset(dims), "|Δx| (2D), √(Δx² + Δz²) (3D)")
    unit = {frozenset({2}): "d⁻²", frozenset({3}): "d⁻³"}.get(frozenset(dims),
                                                               "d⁻² in 2D, d⁻³ in 3D")
    h = widths.pop() if len(widths) == 1 else "(see the files)"
    titles = ("normal: partners at |Δy| (whole cross-section)",
              f"parallel: partners at {inplane}, |Δy| < h")
    xlabels = ("|Δy| (d)", f"{inplane} (d)")
    for ax, title, xlabel in zip(axes, titles, xlabels, strict=True):
        ax.set_title(title, fontsize=9)
        ax.set_xlabel(xlabel)
        ax.set_xlim(left=0)
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
        top = ax.secondary_xaxis("top", functions=(lambda x: 2 * x, lambda x: 0.5 * x))
        top.set_xlabel("in Campbell's R = d/2", fontsize=8)
        top.tick_params(labelsize=7)
    axes[0].set_ylabel(f"number density of partners ({unit})")
    entries = [e for column in columns for e in column]  # the legend fills column by column
    legend_row.legend(*zip(*entries, strict=True), fontsize=7, ncol=3, loc="center",
                      frameon=False)
    return finish(fig, runs, "Campbell's structure distributions about test particles within "
                             f"h = {h} d of the mid-plane")
