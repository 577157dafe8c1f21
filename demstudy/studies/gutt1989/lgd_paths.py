"""Marked-grain paths of the LGD part of the Gutt (1989) study (figs 3.29b-3.32b, 3.34b): the
``lgd-obstacle-<shape>-paths`` and ``lgd-incline-paths`` runs sample every few steps and store
the marked grains' paths (``/tracks``, x unwrapped across the periodic x).

Dimensionless particle units: d = 1 (lattice spacing), m = 1, g = 1: times in √(d/g), speeds
in √(g d).

Proxies (the thesis shows pictures):

* obstacles, "the grains flow around the obstacle": no path enters the obstacle (a point of a
  path segment more than ``INSIDE_MARGIN`` inside the convex hull of the obstacle's wall-node
  centres; every obstacle is convex), and markers pass it (their x beyond its downstream end);
* incline, "a marker grain saltates along parabolic arcs": free flights are runs of at least
  ``FLIGHT_SAMPLES`` sample intervals in which the velocity changes by g·Δt alone (within
  ``FLIGHT_TOL``: no contact) and the grain moves at least ``FLIGHT_MIN_MOVE``; a flight is a
  parabolic arc when its height along −g fits a quadratic in time within ``ARC_RMS`` with a
  curvature giving g within ``ARC_G_TOL``; saltation: at least ``SALTATIONS`` such flights,
  separated by contacts.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
from scipy.spatial import ConvexHull

from ..base import NOT_REPRODUCED, PARTLY, REPRODUCED, Analysis, Check, not_run
from . import lgd_figures as figs
from . import lgd_measure as m

INSIDE_MARGIN = 0.5  # d: a grain centre this deep inside the obstacle's node hull is inside
FLIGHT_SAMPLES, FLIGHT_TOL, FLIGHT_MIN_MOVE = 4, 0.01, 1.5  # intervals, √(gd), d
ARC_RMS, ARC_G_TOL, SALTATIONS = 0.1, 0.1, 3  # d, relative, flights
OBSTACLE_REF = "L1093-L1107, figs 3.29-3.32"
INCLINE_REF = "L1109-L1115, figs 3.33-3.34"
SHAPES = ("circle", "square", "triangle-up", "triangle-down")


# --- measurements ---------------------------------------------------------------------------

def obstacle_nodes(run: m.LgdRun) -> np.ndarray:
    """The obstacle's wall-node centres: wall nodes off the wall rows, upstream of the
    restrictor (as in :func:`lgd_flows.obstacles`)."""
    ini = m.initial_state(run)
    w = ini["walls"][(ini["wall_rows"] > 0) & (ini["wall_rows"] < run.nyt - 1)]
    return w[(w[:, 0] > 40) & (w[:, 0] < 150)]


def path_crossings(paths: np.ndarray, nodes: np.ndarray, period: float,
                   margin: float = INSIDE_MARGIN, step: float = 0.25) -> np.ndarray:
    """Per marker, the number of path segments (between consecutive samples) with a point
    more than ``margin`` inside the convex hull of ``nodes``; ``paths`` (samples, markers, 2)
    with x unwrapped (wrapped here with ``period``; 0: none), NaN samples skipped."""
    hull = ConvexHull(nodes)
    normals, offsets = hull.equations[:, :2], hull.equations[:, 2]
    out = np.zeros(paths.shape[1], dtype=int)
    for k in range(paths.shape[1]):
        p = paths[:, k]
        p = p[np.isfinite(p).all(axis=1)]
        for a, b in zip(p[:-1], p[1:], strict=True):
            n = max(2, int(np.ceil(np.linalg.norm(b - a) / step)) + 1)
            pts = a + np.linspace(0.0, 1.0, n)[:, None] * (b - a)
            if period > 0:
                pts[:, 0] = np.mod(pts[:, 0], period)
            depth = -(pts @ normals.T + offsets).max(axis=1)  # > 0 inside
            out[k] += bool((depth > margin).any())
    return out


def flights(time: np.ndarray, pos: np.ndarray, vel: np.ndarray, g: np.ndarray) -> list[dict]:
    """The free flights of one marker (module doc): per flight the sample range, the
    distance moved, the speed at its start, the turn of the velocity, the rms distance of
    the height (along −g) from a quadratic in time and the g that quadratic gives."""
    dt = np.diff(time)
    free = np.linalg.norm(np.diff(vel, axis=0) - g * dt[:, None], axis=1) < FLIGHT_TOL
    edges = np.flatnonzero(np.diff(np.concatenate([[0], free.astype(int), [0]])))
    out = []
    for a, b in zip(edges[::2], edges[1::2], strict=True):  # intervals a..b-1: samples a..b
        if b - a < FLIGHT_SAMPLES:
            continue
        t, p = time[a:b + 1] - time[a], pos[a:b + 1]
        move = float(np.linalg.norm(p[-1] - p[0]))
        if move < FLIGHT_MIN_MOVE:
            continue
        height = -p @ g / np.linalg.norm(g)
        basis = np.column_stack([np.ones_like(t), t, t * t])
        coef, *_ = np.linalg.lstsq(basis, height, rcond=None)
        v0, v1 = vel[a], vel[b]
        cos = float(v0 @ v1 / max(np.linalg.norm(v0) * np.linalg.norm(v1), 1e-300))
        out.append({"start": int(a), "end": int(b), "move": move,
                    "speed": float(np.linalg.norm(v0)),
                    "turn": float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))),
                    "rms": float(np.sqrt(np.mean((basis @ coef - height) ** 2))),
                    "g": float(-2.0 * coef[2])})
    return out


def is_arc(flight: dict, g: float = 1.0) -> bool:
    return flight["rms"] <= ARC_RMS and abs(flight["g"] - g) <= ARC_G_TOL * g


# --- checks and figures -----------------------------------------------------------------------

def obstacle_paths(runs: Mapping[str, m.LgdRun], out: Path, an: Analysis) -> None:
    statement = ("marker paths at 1536 steps (figs 3.29b-3.32b): the grains flow around the "
                 "obstacle (as the experiment's streamlines, figs 3.29c-3.32c)")
    panels, parts, ok_all = [], [], True
    for shape in SHAPES:
        run = runs.get(f"lgd-obstacle-{shape}-paths")
        tracks = run.extra.get("tracks") if run is not None else None
        if tracks is None:
            an.checks.append(not_run(OBSTACLE_REF, statement, "pictures",
                                     f"lgd-obstacle-{shape}-paths"))
            return
        nodes = obstacle_nodes(run)
        paths = tracks["position"]
        crossed = path_crossings(paths, nodes, float(tracks["period_x"]))
        passed = np.nanmax(paths[:, :, 0], axis=0) > nodes[:, 0].max() + 1.0
        y0 = paths[0, :, 1]
        ahead = (y0 > nodes[:, 1].min()) & (y0 < nodes[:, 1].max())  # started in its shadow
        ok = crossed.sum() == 0 and passed[ahead].any()
        ok_all &= bool(ok)
        parts.append(f"{shape}: {int(passed.sum())} of {len(passed)} markers passed the "
                     f"obstacle ({int(passed[ahead].sum())} of the {int(ahead.sum())} starting "
                     f"in front of it), {int(crossed.sum())} path segments inside it")
        panels.append((run, nodes, m.initial_state(run)["walls"], shape))
    an.checks.append(Check(
        OBSTACLE_REF, statement, "pictures",
        "; ".join(parts) + f" (paths sampled every 2 steps; inside: > {INSIDE_MARGIN} d "
        "within the hull of the obstacle's wall nodes)",
        REPRODUCED if ok_all else PARTLY,
        "" if ok_all else "some obstacle has a path through it or no marker from in front "
                          "of it went past (held in the stagnant cap)"))
    an.figures.append(figs.obstacle_paths(
        panels, out, "lgd_obstacle_paths.png",
        "Obstacles (figs 3.29b-3.32b): marker paths over 1536 steps, one colour per marker "
        "(start ○, end ●), obstacle and walls red; gravity +x; 9 markers at x = 20 "
        "(assumed, the thesis's kale-seed markers)"))


def incline_paths(run: m.LgdRun | None, out: Path, an: Analysis) -> None:
    statement = "a marker grain saltates along parabolic arcs (fig 3.34b)"
    tracks = run.extra.get("tracks") if run is not None else None
    if tracks is None:
        an.checks.append(not_run(INCLINE_REF, statement, "qualitative", "lgd-incline-paths"))
        return
    g = np.array([run.attrs["lgd_igx"], run.attrs["lgd_igy"]], float)
    g /= np.linalg.norm(g)  # g = 1 along the scene's gravity
    k = 0  # the scene's one marker
    fl = flights(tracks["time"], tracks["position"][:, k], tracks["velocity"][:, k], g)
    arcs = [f for f in fl if is_arc(f)]
    ok = len(arcs) >= SALTATIONS
    if arcs:
        moves, speeds = [f["move"] for f in arcs], [f["speed"] for f in arcs]
        gs, turns = [f["g"] for f in arcs], [f["turn"] for f in arcs]
        measured = (f"{len(fl)} free flights (≥ {FLIGHT_SAMPLES} sample intervals of 2 steps "
                    f"without contact), {len(arcs)} of them parabolic arcs: height along g a "
                    f"quadratic in time within rms ≤ {max(f['rms'] for f in arcs):.3f} d, its "
                    f"curvature giving g = {min(gs):.3f}-{max(gs):.3f} (median "
                    f"{np.median(gs):.3f}); flights {min(moves):.1f}-{max(moves):.1f} d long "
                    f"(median {np.median(moves):.1f}) at {np.median(speeds):.1f} √(gd) "
                    f"(median), the velocity turning {np.median(turns):.1f}° (median)")
    else:
        measured = f"{len(fl)} free flights, none a parabolic arc"
    an.checks.append(Check(
        INCLINE_REF, statement, "qualitative", measured,
        REPRODUCED if ok else (PARTLY if arcs else NOT_REPRODUCED),
        ("the arcs are flat: fast (≈ 13 √(gd)) and a few d long, so they turn by a few "
         "degrees; marker position assumed (the block's top front corner; a marker at its "
         "bottom front stays pinned to the slope)") if ok else
        "fewer than three parabolic flights: no saltation"))
    an.figures.append(figs.incline_paths(
        run, tracks, arcs, out, "lgd_incline_paths.png",
        "Incline (fig 3.34b): positions at 6144 steps (grey), the marker's path (blue, start "
        "○) with its parabolic free flights (orange); walls red; gravity normal to the "
        "diagonal wall"))
