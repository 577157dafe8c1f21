"""The comparison figure: per field the overlaid profiles with error bars (top) and
Δ = other − reference with σ_Δ (bottom: a zero line and the ±σ_Δ band). Dimensionless
particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise a wall speed or the shear
rate sets the time scale τ)."""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..errors import NotComparable
from .core import Comparison, FieldComparison

__all__ = ["DEFAULT_FIGURE_FIELDS", "plot_comparison"]

#: drawn when no fields are asked for (those the comparisons hold)
DEFAULT_FIGURE_FIELDS = ("solid_fraction", "velocity[x]", "temperature",
                         "rotational_temperature", "stress/xy", "stress/yy")
PER_ROW = 4
FOOTER = ("units: d = 1, m = 1, g = 1 when gravity acts (otherwise the wall speed or shear "
          "rate sets the time unit τ)")


def _pick(comparisons: Sequence[Comparison], fields: Sequence[str] | None) -> list[str]:
    held = list(dict.fromkeys(n for c in comparisons for n in c.fields))
    if fields is None:
        chosen = [n for n in DEFAULT_FIGURE_FIELDS if n in held]
        return chosen or held[:PER_ROW]
    chosen = []
    for want in fields:
        match = [n for n in held if n == want or n.split("[")[0] == want
                 or n.split("/")[0] == want]
        if not match:
            raise NotComparable(f"unknown field {want!r} for the figure (compared: "
                             f"{', '.join(held)})")
        chosen += [n for n in match if n not in chosen]
    return chosen


def _pretty(units: str) -> str:
    return units.replace("^2", "²").replace("^3", "³")


def _short(f: FieldComparison) -> str:
    if f.n_compared == 0:
        return "nothing compared"
    if f.resolved:
        return f"differs: L2 {f.rel_l2_debiased:.2g}, max|z| {f.max_z:.1f}"
    shared = "  (> 2× floor)" if f.rel_l2 > 2 * f.rel_l2_floor else ""
    return f"agrees: L2 ≲ {max(f.rel_l2_floor, f.rel_l2):.2g}{shared}"


def plot_comparison(comparisons: Sequence[Comparison] | Comparison, out: str | os.PathLike,
                    fields: Sequence[str] | None = None, axis: str = "y") -> Path:
    """Draw the comparisons (one reference, one colour per other run) to ``out``; ``fields``:
    labels or dataset names (default: solid fraction, u_x, T, rotational T, stress xy, yy
    where compared). Returns the path written."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from ..plots.common import save

    comps = [comparisons] if isinstance(comparisons, Comparison) else list(comparisons)
    if not comps:
        raise NotComparable("no comparisons to draw")
    names = _pick(comps, fields)
    n_rows = math.ceil(len(names) / PER_ROW)
    n_cols = min(len(names), PER_ROW)
    fig = Figure(figsize=(3.7 * n_cols, 4.3 * n_rows + 1.0), layout="constrained")
    FigureCanvasAgg(fig)
    outer = fig.add_gridspec(n_rows, n_cols)
    handles = {}
    for k, name in enumerate(names):
        # the difference right under its profiles, sharing the y axis of the bins
        inner = outer[k // PER_ROW, k % PER_ROW].subgridspec(2, 1, height_ratios=[2, 1],
                                                             hspace=0.04)
        top = fig.add_subplot(inner[0])
        bottom = fig.add_subplot(inner[1], sharex=top)
        verdicts = []
        first = next(c.fields[name] for c in comps if name in c.fields)
        grids: list[np.ndarray] = []  # the reference once per bin grid (rebinned: again)
        for i, c in enumerate(comps):
            f = c.fields.get(name)
            if f is None:
                continue
            color = f"C{i}"
            use = f.compared if f.compared is not None else np.isfinite(f.delta)
            if not any(g.shape == f.y.shape and np.allclose(g, f.y) for g in grids):
                shown = use  # the compared bins: empty ones (0 ± 0 in both) left out
                h = top.errorbar(f.y[shown], f.reference[shown], yerr=f.reference_err[shown],
                                 color="k", marker="o", ms=3, capsize=2, lw=1,
                                 ls="-" if not f.rebinned else ":")
                handles.setdefault(f"reference: {c.reference}" + (", rebinned" if f.rebinned
                                                                  else ""), h)
                grids.append(f.y)
            h = top.errorbar(f.y[use], f.other[use], yerr=f.other_err[use], color=color,
                             marker="s", ms=3, capsize=2, lw=1, ls="--", mfc="none")
            handles.setdefault(f"({i + 1}) {c.other}", h)
            bottom.fill_between(f.y, -np.where(use, f.delta_err, np.nan),
                                np.where(use, f.delta_err, np.nan), color=color, alpha=0.15,
                                lw=0, step="mid")
            bottom.errorbar(f.y[use], f.delta[use], yerr=f.delta_err[use], color=color,
                            marker="s", ms=3, capsize=2, lw=0, elinewidth=1)
            verdicts.append(f"({i + 1}) {_short(f)}")
        bottom.axhline(0.0, color="k", lw=0.8)
        units = _pretty(first.units)
        top.set_ylabel(f"{name}\n[{units}]" if units not in ("", "1") else name, fontsize=8)
        bottom.set_ylabel("Δ" + (f"\n[{units}]" if units not in ("", "1") else ""), fontsize=8)
        bottom.set_xlabel(f"{axis} (d)")
        top.set_title("\n".join(verdicts), fontsize=7, loc="left")
        for ax in (top, bottom):
            ax.grid(alpha=0.3)
            ax.tick_params(labelsize=7)
            ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 4))
        top.tick_params(labelbottom=False)
    rebinned = " (rebinned to a common grid)" if any(c.rebinned for c in comps) else ""
    fig.suptitle(f"compared with {comps[0].reference}{rebinned}: profiles (top), other − "
                 "reference with the ±σ_Δ band (bottom)\n" + FOOTER, fontsize=9)
    fig.legend(list(handles.values()), list(handles), loc="outside lower center",
               ncol=min(len(handles), 3), fontsize=8, frameon=False)
    return save(fig, Path(out))
