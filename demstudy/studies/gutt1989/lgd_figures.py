"""Figures of the LGD part of the Gutt (1989) study in the forms of his Ch. 3 captions (digest
§6): positions (a dot per grain), row profiles (v̄x red, v̄y green, thermal velocity blue),
wall shear and pressure per wall particle against time (curves 1-4), velocity histograms
against the 2D Maxwellian (|vx| red, |vy| green, speed blue, theory black), block-averaged
velocity arrows, the hourglass discharge against time.

Dimensionless particle units: d = 1 (lattice spacing), m = 1; g = 1 where gravity acts,
otherwise the scene's speed unit (wall speed or initial gas speed) sets the time scale.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ...plots.common import save_with_note  # noqa: E402
from ..base import Figure  # noqa: E402
from .lgd_measure import ROW, LgdRun  # noqa: E402

NOTE = ("LGD (--engine lgd); d = 1 (lattice spacing), m = 1;\ng = 1 with gravity, otherwise "
        "the scene's speed unit (wall or initial speed) = 1")


def _save(fig, out: Path, name: str, caption: str) -> Figure:
    return Figure(save_with_note(fig, out / name, NOTE, bottom=0.06, dpi=100), caption)


def _legend_room(ax) -> None:
    """Room above the data for a one-row legend (legends stay off the curves)."""
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo, hi + 0.3 * (hi - lo))
    ax.legend(fontsize=7, loc="upper center", ncol=3)


def _positions(ax, run: LgdRun, frame: int, walls: np.ndarray | None, title: str) -> None:
    p = run.position[frame]
    ax.scatter(p[:, 0], p[:, 1], s=0.15, c="k", lw=0, rasterized=True)
    if walls is not None:
        ax.scatter(walls[:, 0], walls[:, 1], s=0.3, c="C3", lw=0, rasterized=True)
    ax.set_xlim(0, run.nxt)
    ax.set_ylim(-1, (run.nyt - 1) * ROW + 1)
    ax.set_aspect("equal")
    ax.set_xlabel("x (d)")
    ax.set_ylabel("y (d)")
    ax.set_title(f"{title}, step {run.frame_steps[frame]}", fontsize=9)


def positions(runs: Sequence[tuple[LgdRun, int, np.ndarray | None, str]], out: Path,
              name: str, caption: str, cols: int = 2) -> Figure:
    """A panel of grain positions per (run, frame index, wall nodes, title); walls red."""
    rows = -(-len(runs) // cols)
    first = runs[0][0]
    aspect = (first.nyt - 1) * ROW / first.nxt  # panels as tall as the lattice, plus labels
    fig, axes = plt.subplots(rows, cols, figsize=(5.2 * cols, (5.2 * aspect + 1.2) * rows),
                             squeeze=False)
    for ax, (run, frame, walls, title) in zip(axes.flat, runs, strict=False):
        _positions(ax, run, frame, walls, title)
    for ax in list(axes.flat)[len(runs):]:
        ax.axis("off")
    return _save(fig, out, name, caption)


def profiles(panels: Sequence[tuple[dict, str]], out: Path, name: str, caption: str,
             speed_label: str = "velocity (speed unit)") -> Figure:
    """Row profiles: v̄x red, v̄y green, thermal velocity blue, against y; error bars."""
    cols = min(3, len(panels))
    rows = -(-len(panels) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.6 * cols, 3.6 * rows), squeeze=False)
    for ax in list(axes.flat)[len(panels):]:
        ax.axis("off")
    for ax, (p, title) in zip(axes.flat, panels, strict=False):
        for key, colour, label in (("vx", "r", "v̄x"), ("vy", "g", "v̄y"),
                                   ("thermal", "b", "thermal")):
            ok = np.isfinite(p[key])
            ax.errorbar(p["y"][ok], p[key][ok], yerr=p.get(key + "_err", None)[ok]
                        if key + "_err" in p else None, fmt="-", color=colour, lw=0.9,
                        elinewidth=0.5, label=label)
        ax.axhline(0, color="0.7", lw=0.5)
        ax.set_xlabel("y (d)")
        ax.set_ylabel(speed_label)
        ax.set_title(title, fontsize=9)
        _legend_room(ax)
    return _save(fig, out, name, caption)


def wall_stress(panels: Sequence[tuple[LgdRun, str]], out: Path, name: str, caption: str,
                scale: Sequence[float] | None = None, ylabel: str = "per wall particle",
                xlabel: str = "time (d/U)", reference: float | None = None,
                reference_label: str = "") -> Figure:
    """Curves 1-4: bottom shear, bottom pressure, top shear, top pressure per wall particle
    per unit time against time (the thesis's fig 3.22 / 3.36)."""
    fig, axes = plt.subplots(1, len(panels), figsize=(4.6 * len(panels), 3.5), squeeze=False)
    for k, (ax, (run, title)) in enumerate(zip(axes[0], panels, strict=False)):
        ts, f = run.ts, (scale[k] if scale else 1.0)
        t = ts["time"]
        for series, sign, label in (("wall_shear_lower", 1, "1 bottom shear"),
                                    ("wall_normal_lower", -1, "2 bottom pressure"),
                                    ("wall_shear_upper", 1, "3 top shear"),
                                    ("wall_normal_upper", 1, "4 top pressure")):
            ax.plot(t, sign * ts[series] * f, lw=0.9, label=label)
        if reference is not None:
            ax.axhline(reference, color="k", ls="--", lw=1, label=reference_label)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.set_title(title, fontsize=9)
        lo, hi = ax.get_ylim()
        ax.set_ylim(lo, hi + 0.35 * (hi - lo))
        ax.legend(fontsize=7, loc="upper center", ncol=2)
    return _save(fig, out, name, caption)


def histograms(panels: Sequence[tuple[np.ndarray, str]], out: Path, name: str,
               caption: str) -> Figure:
    """|vx| red, |vy| green, speed blue against the 2D Maxwellian with the run's own ⟨v²⟩
    (black): histograms of magnitudes are 2 f_x (digest §3.15); counts with √n bars."""
    fig, axes = plt.subplots(1, len(panels), figsize=(4.6 * len(panels), 3.6), squeeze=False)
    for ax, (vel, title) in zip(axes[0], panels, strict=False):
        v = vel - vel.mean(axis=0)
        n = len(v)
        m2 = float((v ** 2).sum(1).mean())
        edges = np.linspace(0, 3 * np.sqrt(m2), 31)
        mid, w = 0.5 * (edges[1:] + edges[:-1]), edges[1] - edges[0]
        for data, colour, label in ((np.abs(v[:, 0]), "r", "|vx|"), (np.abs(v[:, 1]), "g", "|vy|"),
                                    (np.hypot(v[:, 0], v[:, 1]), "b", "speed")):
            h, _ = np.histogram(data, edges)
            ax.errorbar(mid, h, yerr=np.sqrt(h), fmt="o-", ms=2, lw=0.8, color=colour,
                        label=label)
        fx = 2 * n / np.sqrt(np.pi * m2) * np.exp(-mid ** 2 / m2) * w
        fs = 2 * n * mid / m2 * np.exp(-mid ** 2 / m2) * w
        ax.plot(mid, fx, "k-", lw=1, label="Maxwellian")
        ax.plot(mid, fs, "k--", lw=1, label="Maxwellian speed")
        ax.set_xlabel("velocity (initial speed = 1)")
        ax.set_ylabel("grains per bin")
        ax.set_title(title, fontsize=9)
        ax.legend(fontsize=7)
    return _save(fig, out, name, caption)


def arrows(blocks: dict, run: LgdRun, out: Path, name: str, caption: str,
           background: bool = False, centre: tuple[float, float] | None = None,
           figsize: tuple[float, float] = (6.4, 5.6)) -> Figure:
    """Block-averaged velocity arrows (+ the thermal velocity as background colour)."""
    fig, ax = plt.subplots(figsize=figsize)
    gx, gy = np.meshgrid(blocks["x"], blocks["y"])
    ok = blocks["n"] > 0
    if background:
        th = np.where(ok, blocks["thermal"], np.nan)
        mesh = ax.pcolormesh(blocks["x"], blocks["y"], th, shading="nearest", cmap="viridis")
        fig.colorbar(mesh, ax=ax, label="thermal velocity (√(g d))", shrink=0.8)
    # on a stretched channel (background) the arrows keep the velocity's own direction on
    # screen ("uv"); on an equal-aspect map that is the same as the data's direction
    ax.quiver(gx[ok], gy[ok], blocks["vx"][ok], blocks["vy"][ok], angles="uv",
              color="w" if background else "k", width=0.002)
    if centre is not None:
        ax.plot(*centre, "r+", ms=10)
    ax.set_xlim(0, run.nxt)
    ax.set_ylim(0, (run.nyt - 1) * ROW)
    ax.set_aspect("equal" if not background else "auto")
    ax.set_xlabel("x (d)")
    ax.set_ylabel("y (d)")
    return _save(fig, out, name, caption)


def explosion_front(front: dict, out: Path, name: str, caption: str) -> Figure:
    fig, ax = plt.subplots(figsize=(5.2, 3.4))
    ax.plot(np.degrees(front["theta"]), front["front"], "o-", ms=2)
    ax.axhline(front["mean"], color="0.5", lw=0.8, label=f"mean {front['mean']:.1f} d")
    for a in range(-180, 181, 60):
        ax.axvline(a, color="C3", lw=0.4, ls=":")
    ax.set_xlabel("angle from +x (degrees; dotted: lattice directions)")
    ax.set_ylabel("front radius (d)")
    ax.legend(fontsize=7)
    return _save(fig, out, name, caption)


def discharge(run: LgdRun, fit: dict, out: Path, name: str, caption: str) -> Figure:
    fig, ax = plt.subplots(figsize=(5.2, 3.6))
    t, c = run.ts["time"], run.ts["discharged"]
    ax.plot(t, c, "b.-", ms=3, label="grains past x = nxt/2")
    if np.isfinite(fit.get("rate", np.nan)):
        tt = np.linspace(fit["t0"], fit["t1"], 20)
        ax.plot(tt, fit["intercept"] + fit["rate"] * tt, "k--",
                label=f"linear fit: {fit['rate']:.1f} ± {fit['rate_err']:.1f} grains per √(d/g)")
    ax.set_xlabel("time (√(d/g))")
    ax.set_ylabel("grains discharged")
    ax.legend(fontsize=7)
    return _save(fig, out, name, caption)


def _wrapped(path: np.ndarray, period: float) -> np.ndarray:
    """A path (samples, 2) with x unwrapped, wrapped into [0, period) with NaN where it
    crosses the periodic boundary (so that no line spans the box)."""
    p = path.copy()
    if period > 0:
        p[:, 0] = np.mod(p[:, 0], period)
        jump = np.flatnonzero(np.abs(np.diff(p[:, 0])) > period / 2) + 1
        p = np.insert(p, jump, np.nan, axis=0)
    return p


def _lattice_axes(ax, run: LgdRun, title: str) -> None:
    ax.set_xlim(0, run.nxt)
    ax.set_ylim(-1, (run.nyt - 1) * ROW + 1)
    ax.set_aspect("equal")
    ax.set_xlabel("x (d)")
    ax.set_ylabel("y (d)")
    ax.set_title(title, fontsize=9)


def obstacle_paths(panels: Sequence[tuple[LgdRun, np.ndarray, np.ndarray, str]], out: Path,
                   name: str, caption: str) -> Figure:
    """Per (run, obstacle nodes, wall nodes, title): the walls (red) and each marker's path
    in its own colour, start ○, end ●."""
    first = panels[0][0]
    aspect = (first.nyt - 1) * ROW / first.nxt
    rows = -(-len(panels) // 2)
    fig, axes = plt.subplots(rows, 2, figsize=(10.4, (5.2 * aspect + 1.2) * rows),
                             squeeze=False)
    for ax in list(axes.flat)[len(panels):]:
        ax.axis("off")
    for ax, (run, _nodes, walls, title) in zip(axes.flat, panels, strict=False):
        tracks = run.extra["tracks"]
        ax.scatter(walls[:, 0], walls[:, 1], s=0.3, c="C3", lw=0, rasterized=True)
        period = float(tracks["period_x"])
        for k in range(tracks["position"].shape[1]):
            colour = plt.cm.tab10(k % 10)
            path = tracks["position"][:, k]
            ax.plot(*_wrapped(path, period).T, "-", color=colour, lw=0.8)
            ok = path[np.isfinite(path).all(axis=1)]
            ax.plot(ok[0, 0] % period, ok[0, 1], "o", mfc="none", color=colour, ms=3)
            ax.plot(ok[-1, 0] % period, ok[-1, 1], "o", color=colour, ms=3)
        steps = int(run.ts["steps"][-1])
        _lattice_axes(ax, run, f"{title}: marker paths, steps 0-{steps}")
    return _save(fig, out, name, caption)


def incline_paths(run: LgdRun, tracks: dict, arcs: Sequence[dict], out: Path, name: str,
                  caption: str) -> Figure:
    """The last kept frame's positions (grey), walls (red), the marker's path (blue) with
    its parabolic flights (orange)."""
    from .lgd_measure import initial_state

    aspect = (run.nyt - 1) * ROW / run.nxt
    fig, ax = plt.subplots(figsize=(10.4, 10.4 * aspect + 1.4))
    p = run.position[-1]
    ax.scatter(p[:, 0], p[:, 1], s=0.15, c="0.6", lw=0, rasterized=True)
    walls = initial_state(run)["walls"]
    ax.scatter(walls[:, 0], walls[:, 1], s=0.3, c="C3", lw=0, rasterized=True)
    period = float(tracks["period_x"])
    path = tracks["position"][:, 0]
    ax.plot(*_wrapped(path, period).T, "-", color="C0", lw=0.7, label="marker path")
    for i, arc in enumerate(arcs):
        seg = path[arc["start"]:arc["end"] + 1]
        ax.plot(*_wrapped(seg, period).T, "-", color="C1", lw=2.0,
                label="parabolic free flights" if i == 0 else None)
    ax.plot(path[0, 0] % period, path[0, 1], "o", mfc="none", color="C0", ms=5)
    _lattice_axes(ax, run, f"incline: positions at step {run.frame_steps[-1]}, marker path "
                           f"over steps 0-{int(run.ts['steps'][-1])}")
    ax.legend(fontsize=7, loc="lower right")
    return _save(fig, out, name, caption)
