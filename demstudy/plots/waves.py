"""Density waves: power spectrum of the dominant plane (log colour), its coarse-grained
solid-fraction contour and the amplitude time series of the low mode families.

Dimensionless particle units: d = 1, m = 1, g = 1 with gravity; k are integer harmonics
(waves per box length along each axis of the plane).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib import colormaps
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure

from .common import Run, finish, new_figure

_AX = {"x": 0, "y": 1, "z": 2}


def dominant_plane(data: dict, attrs: dict) -> str:
    """The plane whose strongest dominant family has the most power; the first plane (xy)
    when no plane has a dominant family."""
    planes = [p for p in str(attrs.get("planes", "xy")).split(",") if f"spectrum_{p}" in data]
    best, power = planes[0], -np.inf
    for p in planes:
        dom = np.asarray(data.get(f"dominant_{p}", np.zeros((0, 2))), int).reshape(-1, 2)
        if dom.shape[0]:
            value = float(np.asarray(data[f"family_power_{p}"])[dom[0, 0], dom[0, 1]])
            if value > power:
                best, power = p, value
    return best


def spectrum_image(data: dict, plane: str) -> tuple[np.ndarray, np.ndarray, np.ma.MaskedArray]:
    """(k_a, k_b, P) with zero frequency centred (fftshift), P[k_b, k_a] for pcolormesh, the
    (0, 0) mode and non-positive powers masked."""
    ka = np.fft.fftshift(np.asarray(data[f"k_{plane[0]}_{plane}"]))
    kb = np.fft.fftshift(np.asarray(data[f"k_{plane[1]}_{plane}"]))
    power = np.fft.fftshift(np.asarray(data[f"spectrum_{plane}"], float)).T
    mask = (power <= 0) | ~np.isfinite(power) | ((kb[:, None] == 0) & (ka[None, :] == 0))
    return ka, kb, np.ma.masked_array(power, mask)


def _cell_centres(attrs: dict, plane: str, shape: tuple[int, ...]
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Cell centres along the two axes of ``plane`` from the grid range (attrs lo, hi)."""
    lo, hi = attrs.get("lo"), attrs.get("hi")
    out = []
    for axis, n in zip(plane, shape, strict=True):
        i = _AX[axis]
        if lo is None or hi is None or np.size(lo) <= i:
            out.append(np.arange(n) + 0.5)
        else:
            a, b = float(np.ravel(lo)[i]), float(np.ravel(hi)[i])
            out.append(a + (np.arange(n) + 0.5) * (b - a) / n)
    return out[0], out[1]


def draw_waves(runs: Sequence[Run]) -> Figure:
    """One row per results file: the mean power spectrum P(k_a, k_b) of the dominant plane
    on a log colour scale, the mean solid-fraction field of that plane (contours), and the
    amplitudes √P_F of the families with |k| ≤ 3 against time."""
    fig, axes = new_figure(len(runs), 3, width=4.6, height=3.8)
    for row, run in zip(axes, runs, strict=True):
        data, attrs = run.group("waves")
        p = dominant_plane(data, attrs)
        a, b = p[0], p[1]
        dom = np.asarray(data.get(f"dominant_{p}", np.zeros((0, 2))), int).reshape(-1, 2)
        dom_text = ", ".join(f"({i},{j})" for i, j in dom[:4]) or "none"
        ka, kb, power = spectrum_image(data, p)
        ax = row[0]
        norm = LogNorm(vmin=float(power.min()), vmax=float(power.max())) if power.count() \
            else None
        mesh = ax.pcolormesh(np.append(ka - 0.5, ka[-1] + 0.5), np.append(kb - 0.5, kb[-1] + 0.5),
                             power, norm=norm, cmap="magma", shading="flat",
                             gid=f"{run.path.name}:spectrum_{p}")
        fig.colorbar(mesh, ax=ax, label="P = 2|X|²/(n_a n_b)²")
        ax.set_xlabel(f"k_{a}")
        ax.set_ylabel(f"k_{b}")
        ax.set_title(f"{run.label}\nplane {p}: spectrum (log), dominant: {dom_text}", fontsize=8)
        ax = row[1]
        field = np.asarray(data[f"field_{p}"], float)
        ca, cb = _cell_centres(attrs, p, field.shape)
        cs = ax.contourf(ca, cb, field.T, levels=12, cmap="viridis")
        cs.set_gid(f"{run.path.name}:field_{p}")
        fig.colorbar(cs, ax=ax, label="solid fraction ν")
        ax.set_aspect("equal")
        ax.set_xlabel(f"{a} (particle diameters)")
        ax.set_ylabel(f"{b} (particle diameters)")
        ax.set_title(f"coarse-grained ν, plane {p} (pattern: {attrs.get('pattern', '?')})",
                     fontsize=8)
        ax = row[2]
        t = np.asarray(data["series_time"], float)
        series = np.asarray(data[f"series_{p}"], float).reshape(t.size, -1)
        modes = np.asarray(data[f"series_modes_{p}"], int).reshape(-1, 2)
        cmap = colormaps["tab20"]
        strongest = set(np.argsort(-np.nanmean(series, axis=0))[:6]) if t.size else set()
        for j, (i, k) in enumerate(modes):
            ax.plot(t, series[:, j], marker="." if t.size < 30 else None, lw=0.8,
                    color=cmap(j % cmap.N),
                    label=f"({i},{k})" if j in strongest else None,
                    gid=f"{run.path.name}:series_{p}:{j}")
        ax.set_xlabel("time")
        ax.set_ylabel("amplitude √P_F")
        ax.set_title(f"mode amplitudes (k_{a}, k_{b}), |k| ≤ 3", fontsize=8)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6, ncol=2, loc="upper right", title="strongest", title_fontsize=6)
    return finish(fig, runs, "density waves (Malik): power spectrum, density field, "
                             "mode amplitudes")
