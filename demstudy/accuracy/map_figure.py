"""The engine-map figure: two panels (2D discs, 3D spheres), solid fraction across,
restitution up, colour log10(soft cost / event-driven cost) on a diverging scale centred at 0
(blue: soft contacts cheaper, red: event-driven cheaper), the crossover contour (ratio 1)
where the grid holds one, crosses where the event-driven engine was impractical.

Dimensionless particle units: d = 1, m = 1, shear rate γ̇ = 1; costs per particle per strain
unit, in wall seconds of the machine named in the footer."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np


def _panel_grid(points: list[dict]):
    fracs = sorted({p["fraction"] for p in points})
    rests = sorted({p["restitution"] for p in points})
    value = np.full((len(rests), len(fracs)), np.nan)
    error = np.full_like(value, np.nan)
    stalled = []
    for p in points:
        i, j = rests.index(p["restitution"]), fracs.index(p["fraction"])
        if p.get("log10_ratio") is not None:
            value[i, j] = p["log10_ratio"]
            error[i, j] = p.get("log10_ratio_err") or np.nan
        else:
            stalled.append((j, i))
    return fracs, rests, value, error, stalled


def _boundary(ax, stalled: list[tuple[int, int]], shape: tuple[int, int]) -> bool:
    """The edges between cells the event-driven engine ran and cells where it was
    impractical: beyond them soft contacts are the only choice. True if any was drawn."""
    cells, drawn = set(stalled), False
    for j, i in stalled:
        for dj, di in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            nj, ni = j + dj, i + di
            if 0 <= nj < shape[1] and 0 <= ni < shape[0] and (nj, ni) not in cells:
                if dj:  # vertical edge
                    ax.plot([j + dj / 2] * 2, [i - 0.5, i + 0.5], color="k", lw=2.5)
                else:
                    ax.plot([j - 0.5, j + 0.5], [i + di / 2] * 2, color="k", lw=2.5)
                drawn = True
    return drawn


def map_figure(data: dict, path: Path) -> Path:
    """Write the figure of a map summary (``map_output.summary``) to ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import TwoSlopeNorm
    from matplotlib.lines import Line2D

    from .map_output import loaded_note

    dims = sorted({p["dim"] for p in data["points"]})
    values = [p["log10_ratio"] for p in data["points"] if p.get("log10_ratio") is not None]
    reach = max([abs(v) for v in values] + [0.5]) * 1.05
    norm = TwoSlopeNorm(0.0, -reach, reach)
    fig, axes = plt.subplots(1, len(dims), figsize=(4.6 * len(dims) + 1.4, 4.6), squeeze=False,
                             layout="constrained")
    mesh, crossing, boundary = None, False, False
    for ax, dim in zip(axes[0], dims, strict=True):
        fracs, rests, value, error, stalled = _panel_grid([p for p in data["points"]
                                                           if p["dim"] == dim])
        mesh = ax.pcolormesh(np.arange(len(fracs) + 1) - 0.5, np.arange(len(rests) + 1) - 0.5,
                             np.ma.masked_invalid(value), cmap="RdBu_r", norm=norm)
        for (i, j), v in np.ndenumerate(value):
            if math.isfinite(v):
                # the standard error of log10(ratio) as a relative error of the ratio
                spread = (f"\n±{100 * math.log(10) * error[i, j]:.0f} %"
                          if math.isfinite(error[i, j]) else "")
                ax.text(j, i, f"{10 ** v:.3g}{spread}", ha="center", va="center",
                        fontsize=8, color="white" if abs(v) > 0.6 * reach else "black")
        filled = np.isfinite(value)
        if filled.sum() >= 4 and np.nanmin(value) < 0 < np.nanmax(value):
            crossing = True
            ax.contour(np.arange(len(fracs)), np.arange(len(rests)),
                       np.where(filled, value, np.nanmax(value)), levels=[0.0], colors="k",
                       linewidths=2, linestyles="--")
        boundary |= _boundary(ax, stalled, value.shape)
        if stalled:
            ax.scatter(*zip(*stalled, strict=True), marker="X", s=160, c="k")
        ax.set_xticks(range(len(fracs)), [f"{f:g}" for f in fracs])
        ax.set_yticks(range(len(rests)), [f"{e:g}" for e in rests])
        ax.set_xlabel("solid fraction " + ("ν (discs)" if dim == 2 else "φ (spheres)"))
        ax.set_ylabel("restitution e")
        ax.set_title(f"{dim}D Lees–Edwards shear, β = 0.5")
    bar = fig.colorbar(mesh, ax=axes[0].tolist(), shrink=0.9)
    bar.set_label("log$_{10}$(soft cost / event-driven cost)\n"
                  "< 0: soft cheaper (blue),  > 0: event-driven cheaper (red)")
    settings, machine = data["settings"], data["machine"]
    handles = [Line2D([], [], color="k", lw=2, ls="--", label="crossover (ratio 1)"
                      + ("" if crossing else ": none where event-driven runs")),
               Line2D([], [], marker="X", ms=10, ls="", color="k",
                      label="event-driven impractical")]
    if boundary:
        handles.append(Line2D([], [], color="k", lw=2.5,
                              label="edge of the event-driven engine's reach"))
    fig.legend(handles=handles, loc="outside upper center", ncols=len(handles), frameon=False)
    fig.supxlabel(f"numbers: cost ratio per particle per strain unit (1/γ̇) ± standard error "
                  f"of {settings.get('repeats', 1)} repeats; soft at "
             f"t$_c$ = {settings['ratio']:g} τ$_{{flight}}$, {settings['steps_per_contact']:g} "
             f"steps/contact (Hooke)\n{machine.get('cpu', '?')}, {machine.get('date', '')[:10]}"
             f"; {loaded_note(machine)}. Units: d = m = 1, γ̇ = 1",
             fontsize=7)
    fig.savefig(path, dpi=130, bbox_inches="tight")
    plt.close(fig)
    return path
