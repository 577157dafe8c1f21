"""The ``health`` figure of soft-contact runs: overlaps and contacts per production sample
against the limits of the hard-particle verdict. Dimensionless particle units: d = 1, m = 1,
g = 1 with gravity; overlaps in d, time in the scene's unit τ.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure

from .common import LINESTYLES, Run, finish, new_figure

__all__ = ["draw_health"]


def _limit(ax, value: float | None, label: str, ls: str = ":") -> None:
    if value is not None:
        ax.axhline(value, color="0.3", ls=ls, lw=1.2, label=f"{label} = {value:g}")


def draw_health(runs: Sequence[Run]) -> Figure:
    """Largest and mean overlap (left) and coordination and multi-contact fraction (right)
    per production sample, one colour per run, with the flagging limits dotted; the legend
    of each run names its verdict."""
    fig, axes = new_figure(1, 2, width=5.2, height=4.0)
    over, coord = axes[0]
    limits: dict = {}
    labels = [run.label for run in runs]
    if len(set(labels)) < len(labels):  # same scene and engine: tell them by file
        labels = [f"{run.path.name} ({run.attrs.get('engine', '?')})" for run in runs]
    for r, (run, label) in enumerate(zip(runs, labels, strict=True)):
        data, attrs = run.group("health")
        limits = attrs.get("limits", limits)
        t = np.asarray(data["time"], float)
        verdict = "healthy" if attrs.get("healthy") else \
            f"flagged: {', '.join(p.split()[0] for p in attrs.get('problems', []))}"
        name, colour = run.path.name, f"C{r}"
        over.plot(t, data["max_overlap"], color=colour, ls=LINESTYLES[0],
                  label=f"{label}: largest ({verdict})", gid=f"{name}:max_overlap")
        over.plot(t, data["mean_overlap"], color=colour, ls=LINESTYLES[1],
                  label=f"{label}: mean", gid=f"{name}:mean_overlap")
        coord.plot(t, data["coordination"], color=colour, ls=LINESTYLES[0],
                   label=f"{label}: coordination Z", gid=f"{name}:coordination")
        coord.plot(t, data["multi_contact_fraction"], color=colour, ls=LINESTYLES[1],
                   label=f"{label}: fraction in ≥ 2 contacts",
                   gid=f"{name}:multi_contact_fraction")
    _limit(over, limits.get("max_overlap"), "limit: largest overlap")
    _limit(over, limits.get("mean_overlap"), "limit: mean overlap", ls="-.")
    _limit(coord, limits.get("multi_contact_fraction"), "limit: fraction in ≥ 2 contacts")
    over.set_yscale("log")
    over.set_ylabel("overlap δ (d)")
    over.set_title("overlaps of the touching contacts", fontsize=9)
    coord.set_ylabel("contacts per particle, fraction (1)")
    coord.set_title("coordination and multiple contacts", fontsize=9)
    for ax in (over, coord):
        ax.set_xlabel("t (τ)")
        ax.grid(alpha=0.3)
    handles = over.get_legend_handles_labels()
    more = coord.get_legend_handles_labels()
    fig.legend(handles[0] + more[0], handles[1] + more[1], fontsize=7, loc="lower center",
               ncol=2, bbox_to_anchor=(0.5, 0.06))
    return finish(fig, runs, "soft-contact health at the production samples (grey: the "
                             "limits of the hard-particle verdict)", bottom=0.3)
