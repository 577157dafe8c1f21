"""The accuracy-versus-cost (Pareto) figure of a cost study: error against wall time,
log–log, one marker per soft run, the Pareto front, the reference's cost (vertical line) and
the tolerance (horizontal line). Dimensionless particle units: d = 1, m = 1, g = 1 when
gravity acts; wall times in seconds of this machine."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

MARKERS = {"hooke": "o", "hertz": "s"}


def pareto_front(points: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """The non-dominated points (no other point is both cheaper and more accurate), by cost."""
    front, best = [], math.inf
    for cost, err in sorted(points):
        if err < best:
            front.append((cost, err))
            best = err
    return front


def _minor_label(value: float, _pos) -> str:
    mantissa = value / 10 ** math.floor(math.log10(value) + 1e-9)
    return f"{value:g}" if round(mantissa) in (2, 5) and abs(mantissa - round(mantissa)) < 1e-6 \
        else ""


def pareto_figure(study, path: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm
    from matplotlib.ticker import FuncFormatter

    soft = [r for r in study.rows if r["engine"] != "edmd" and math.isfinite(r["error"])]
    positive = [r["error"] for r in soft if r["error"] > 0]
    # runs within their noise floor (error 0 by the rule) are drawn at a floor, hollow
    shown_zero = (min(positive) if positive else study.tolerance) / 3
    fig, ax = plt.subplots(figsize=(7.0, 5.6), layout="constrained")
    ks = [r["kstar"] for r in soft] or [1.0]
    norm = LogNorm(min(ks), max(ks) * (1.0001 if min(ks) == max(ks) else 1))
    cmap = plt.get_cmap("viridis")
    for r in soft:
        err = r["error"] if r["error"] > 0 else shown_zero
        colour = cmap(norm(r["kstar"]))
        if math.isfinite(r["floor"]):  # the noise floor: how far the error itself is known
            ax.errorbar(r["wall_seconds"], err, yerr=[[min(r["floor"], 0.9 * err)],
                                                      [r["floor"]]],
                        color=colour, alpha=0.5, lw=1, capsize=2, zorder=2)
        ax.scatter(r["wall_seconds"], err, marker=MARKERS.get(r["model"], "^"),
                   s=25 + 0.6 * r["steps_per_contact"], edgecolors=colour,
                   facecolors=colour if r["error"] > 0 else "none", linewidths=1.5, zorder=3)
    front = pareto_front([(r["wall_seconds"], r["error"] if r["error"] > 0 else shown_zero)
                          for r in soft])
    if front:
        ax.plot(*np.array(front).T, "-", color="0.4", lw=1, drawstyle="steps-post",
                label="Pareto front", zorder=2)
    ref = study.reference
    ax.axvline(ref["wall_seconds"], color="C3", ls="--",
               label=f"event-driven reference ({ref['wall_seconds']:.3g} s)")
    ax.axhline(study.tolerance, color="C1", ls=":", label=f"tolerance {study.tolerance:g}")
    for model, marker in MARKERS.items():
        if any(r["model"] == model for r in soft):
            ax.scatter([], [], marker=marker, color="0.3", label=f"{model} (size: steps/contact)")
    ax.scatter([], [], marker="o", facecolors="none", edgecolors="0.3",
               label="within noise floor (drawn at floor)")
    ax.errorbar([], [], yerr=[], color="0.5", capsize=2, label="error bar: noise floor")
    ax.set_xscale("log")
    ax.set_yscale("log")
    reps = sorted({int(r.get("replicas", 1)) for r in study.rows if r["engine"] != "edmd"})
    ax.set_xlabel("wall time of the run (s, this machine)" if reps in ([], [1]) else
                  f"wall time, sum over the {'/'.join(map(str, reps))} replicas of a run "
                  "(s, this machine)")
    ax.set_ylabel("error: worst profile rel. L2 beyond noise (-)")
    ax.set_title(f"accuracy vs cost: {Path(study.folder).name}", fontsize=10)
    sm = plt.cm.ScalarMappable(norm=norm, cmap=cmap)
    fig.colorbar(sm, ax=ax, label=study.scale_label, pad=0.01)
    for axis in (ax.xaxis, ax.yaxis):  # minor labels at 2 and 5 only: all of them collide
        axis.set_minor_formatter(FuncFormatter(_minor_label))
    fig.legend(*ax.get_legend_handles_labels(), fontsize=8, loc="outside lower center",
               ncol=2, frameon=False)
    ax.grid(True, which="both", alpha=0.2)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
