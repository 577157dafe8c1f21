"""The analyses a scene asks for, configured from the scene, run over any frame source.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts. Each statistic is one
AnalysisBase class; this module only chooses their parameters from the scene (bins along the
profile axis, periodic lengths, Lees–Edwards image shifts) so that results files from every
engine and every frame source (in-memory capture, dumps, stored frames) are comparable.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np

from ..errors import StatisticUnavailable
from ..io.frames import Frame
from ..scene import Scene
from .base import bin_edges
from .profiles import ProfileAnalysis
from .walls import walls_move


def periodic_lengths(scene: Scene) -> list[float]:
    """The box lengths along the periodic axes."""
    return [scene.box.size[i] for i, a in enumerate("xyz"[:scene.dimension])
            if a in scene.periodic]


def profile_bounds(scene: Scene) -> tuple[float, float, float]:
    """(lo, hi, period) of the profile axis: between the walls, or the periodic box."""
    axis = "xyz".index(scene.measure.axis)
    period = scene.box.size[axis] if scene.measure.axis in scene.periodic else 0.0
    if scene.measure.axis == "y" and not scene.y_periodic:
        lo = scene.wall_position("lower")
        hi = scene.wall_position("upper") if scene.wall("upper") else scene.box.size[1]
        return lo, hi, period
    return 0.0, scene.box.size[axis], period


def image_shift(scene: Scene, period: float) -> float:
    """x velocity of the periodic image above (Lees–Edwards: γ̇ L_y), 0 otherwise."""
    return scene.shear.rate * period if scene.shear is not None and scene.measure.axis == "y" \
        else 0.0


def wall_relative_bins(scene: Scene, asked: bool | None = None) -> bool:
    """Whether the y bins follow the walls (:mod:`.walls`): ``asked``, or by default when
    the scene's walls move (servo walls) and the profile axis is y."""
    if asked is None:
        return walls_move(scene) and scene.measure.axis == "y"
    relative = bool(asked)
    if relative and (scene.measure.axis != "y" or not walls_move(scene)):
        raise StatisticUnavailable(
            f"wall_relative = True: strips that follow the walls need walls that move (a "
            f"[walls.servo]) and measure.axis = 'y' (this scene: axis "
            f"{scene.measure.axis!r}, {'servo walls' if walls_move(scene) else 'fixed walls'})")
    return relative


def profile_analysis(scene: Scene, walls: tuple[float, float] | None = None,
                     z_cells: int = 1, wall_relative: bool | None = None) -> ProfileAnalysis:
    """Profiles along the scene's axis (``z_cells`` > 1 adds the temperatures in Malik's cell
    convention). Walls that move: strips between each frame's walls (``wall_relative``, the
    default, Campbell's ST = HGT/FND), or fixed strips between ``walls`` (the wall positions
    when production started; None: the scene's)."""
    lo, hi, period = profile_bounds(scene)
    relative = wall_relative_bins(scene, wall_relative)
    if walls is not None and scene.measure.axis == "y" and not relative:
        lo, hi = walls
    return ProfileAnalysis(axis=scene.measure.axis, bin_width=scene.measure.bin_width, lo=lo,
                           hi=hi, dim=scene.dimension, inertia_factor=scene.inertia_k,
                           period=period, image_velocity_shift=image_shift(scene, period),
                           z_cells=z_cells, wall_relative=relative)


def _need_results(results: Any, name: str) -> Any:
    if results is None:
        raise StatisticUnavailable(f"{name}: needs a results file (RUN.h5), not a dump")
    return results


def _collision_log(results: Any, name: str) -> tuple[Any, dict]:
    """The results file and its ``/collisions`` log, or a clear error."""
    res = _need_results(results, name)
    log = res.groups.get("collisions")
    if not log:
        raise StatisticUnavailable(f"{name}: the results file has no /collisions log "
                                   "(event-driven runs write it when the scene's "
                                   "measure.statistics names angles or freepath)")
    return res, log


def collision_angle_analysis(scene: Scene, results: Any, n_chunks: int = 64) -> Any:
    """P(theta) per profile bin from the ``/collisions`` log of a results file (production
    only), with the Savage–Jeffrey overlay when the file's profiles use the same bins."""
    from .collisions import CollisionAngles, collision_chunks

    res, log = _collision_log(results, "angles")
    lo, hi, _period = profile_bounds(scene)
    edges = res.profiles.get("edges")
    if edges is None:
        edges = bin_edges(lo, hi, scene.measure.bin_width)
    start = float(res.attrs.get("equilibration_end", 0.0))
    ana = CollisionAngles(edges, dim=scene.dimension)
    ana.run(collision_chunks(log, n_chunks, start))
    if res.profiles and scene.measure.axis == "y":
        ana.overlay(res.profiles)
    return ana


def free_path_mean_flow(scene: Scene, profiles: Any,
                        along_y: bool) -> tuple[Callable[[np.ndarray], np.ndarray] | None, str]:
    """The local mean flow u(y) -> (M, dim) the free paths are measured against, and where it
    comes from. Lees–Edwards: the streaming profile γ̇ y x̂ + c, defined for y beyond the box
    (the images), c the offset (and drift) fitted to the run's ``/profiles/velocity``
    (number-weighted mean of u − γ̇ y x̂ over the bins) or, without profiles, −γ̇ L_y/2 x̂
    (the linear start's). Otherwise the run's own ``/profiles/velocity`` (bins along y),
    interpolated linearly between bin centres and constant beyond the outer ones (y taken
    modulo the period in a y-periodic box). None without either: the lab frame."""
    dim = scene.dimension
    usable = along_y and bool(profiles) and "velocity" in profiles and "y" in profiles
    if usable:
        y_b = np.asarray(profiles["y"], float)
        u_b = np.asarray(profiles["velocity"], float)[:, :dim]
        n_b = np.asarray(profiles.get("number_density", np.ones(y_b.size)), float)
        ok = np.all(np.isfinite(u_b), axis=1) & np.isfinite(n_b) & (n_b > 0)
        usable = bool(ok.any())
    if scene.shear is not None and scene.y_periodic:
        rate, ly = float(scene.shear.rate), float(scene.box.size[1])
        offset = np.zeros(dim)
        offset[0] = -rate * ly / 2
        source = "Lees–Edwards streaming profile γ̇ (y − L_y/2) x̂ (no /profiles/velocity)"
        if usable:
            slid = u_b[ok].copy()
            slid[:, 0] -= rate * y_b[ok]
            offset = np.average(slid, axis=0, weights=n_b[ok])
            source = ("Lees–Edwards streaming profile γ̇ y x̂ + c, c fitted to "
                      "/profiles/velocity")

        def streaming(y: np.ndarray) -> np.ndarray:
            out = np.tile(offset, (np.size(y), 1))
            out[:, 0] += rate * np.asarray(y, float)
            return out
        return streaming, source
    if not usable:
        return None, "none (no /profiles/velocity along y): lab frame"
    period = float(scene.box.size[1]) if scene.y_periodic else 0.0
    y_ok, u_ok = y_b[ok], u_b[ok]

    def profile(y: np.ndarray) -> np.ndarray:
        y = np.asarray(y, float)
        if period:
            y = np.mod(y, period)
        return np.column_stack([np.interp(y, y_ok, u_ok[:, a]) for a in range(dim)])
    return profile, "/profiles/velocity, linear between bin centres"


def free_path_analysis(scene: Scene, results: Any, n_chunks: int = 64) -> Any:
    """Free paths and times per profile bin from the ``/collisions`` log (every collision
    needed: ``log_every`` = 1), radii from the scene's initial state, Kn with the wall gap
    (or the periodic height; an open top: Campbell's flow depth from the profiles), Enskog
    references when the file's profiles use the same bins."""
    from ..scene.initial import build_initial_state  # only this statistic needs the radii
    from .collisions import FreePath, flight_chunks, free_flights
    from .derived import campbell_depth

    res, log = _collision_log(results, "freepath")
    every = int(res.group_attrs.get("collisions", {}).get("log_every", 1))
    if every != 1:
        raise StatisticUnavailable(f"freepath: the log keeps every {every}th collision; "
                                   "free paths need every collision (run with log_every = 1)")
    dim = scene.dimension
    radius = build_initial_state(scene).diameter / 2
    periods = [scene.box.size[a] if "xyz"[a] in scene.periodic else 0.0 for a in range(dim)]
    ts = res.timeseries
    offset = x_period = None
    if scene.shear is not None and scene.y_periodic:
        shear, ly = scene.shear.rate, scene.box.size[1]
        t_s = np.asarray(ts.get("time", [0.0]), float)
        if "tilt" not in ts or len(ts["tilt"]) != t_s.size:
            raise StatisticUnavailable("freepath: a Lees–Edwards run needs /timeseries/tilt "
                                       "(the image offset, one per time sample); this file "
                                       "has none")
        tilt = np.asarray(ts["tilt"], float)

        def offset(t: np.ndarray) -> np.ndarray:  # exactly linear from the last sample
            k = np.clip(np.searchsorted(t_s, t, side="right") - 1, 0, t_s.size - 1)
            return tilt[k] + shear * ly * (t - t_s[k])
    if "width" in ts:  # servo: the x period follows the gap
        def x_period(t: np.ndarray) -> np.ndarray:
            return np.interp(t, np.asarray(ts["time"], float), np.asarray(ts["width"], float))
    start = float(res.attrs.get("equilibration_end", 0.0))
    along_y = scene.measure.axis == "y"
    flow, flow_source = free_path_mean_flow(scene, res.profiles, along_y)
    flights = free_flights(log, radius, periods, scene.gravity_vector, offset, x_period, start,
                           mean_flow=flow)
    lo, hi, _period = profile_bounds(scene)
    if not along_y:  # flights are binned along y whatever the profile axis
        lo, hi = 0.0, scene.box.size[1]
    edges = res.profiles.get("edges") if along_y else None
    if edges is None:
        edges = bin_edges(lo, hi, scene.measure.bin_width)
    width = hi - lo
    if scene.has_open_top and res.profiles:
        width = campbell_depth(res.profiles, scene.wall_position("lower"))
    lam, tau = flights["length"], flights["tau"]
    if lam.size == 0:
        raise StatisticUnavailable("freepath: no particle collides twice in the logged window")
    ana = FreePath(edges, lambda_max=8 * float(lam.mean()), tau_max=8 * float(tau.mean()),
                   width=width, dim=dim)
    ana.run(flight_chunks(flights, n_chunks))
    span = flights["t1"] - flights["t0"]
    shortest = min(p for p in periods if p > 0)  # x is always periodic
    omega = flights["collisions"] / (radius.size * span)
    ana.attrs.update({
        "window_start": flights["t0"], "window_end": flights["t1"],
        "collisions_logged": flights["collisions"], "particles": radius.size,
        "measured_collision_frequency": omega,
        "mean_free_time_over_window": float(tau.mean()) / span,
        "y_wrapped_flights": int(flights["y_wrapped"].sum()),
        "mean_flow": flow_source,
        "gravity": "arc length of the parabola" if scene.gravity else "none: chord",
        "knudsen_width_is": "flow depth (campbell_depth)" if scene.has_open_top and res.profiles
                            else "wall gap" if not scene.y_periodic else "periodic height",
        "shortest_period": shortest,
        # nearest images (about the displacement the mean flow and gravity predict): a flight
        # whose free path exceeds half a period along an axis is aliased; the share of an
        # exponential P(lambda) beyond half the shortest period bounds it
        "alias_fraction_bound": math.exp(-0.5 * shortest / float(lam.mean())),
    })
    if res.profiles and along_y:
        section = math.prod(s for a, s in enumerate(scene.box.size[:dim]) if a != 1)
        if x_period is not None:
            section *= float(np.mean(ts["width"])) / scene.box.size[0]
        ana.overlay(res.profiles, section)
    return ana


def stress_from_results(scene: Scene, results: Any) -> tuple[dict, dict]:
    """The ``/stress`` datasets from a results file: kinetic (its profiles), wall stresses
    and momentum balance (its time series), plus the contact / collisional tensors the
    engine stored in ``/stress`` (carried over)."""
    from .stress import stress_results

    res = _need_results(results, "stress")
    if not res.profiles:
        raise StatisticUnavailable("stress: the results file has no /profiles")
    stored = res.groups.get("stress", {})
    parts = {k: (stored[k], stored[f"{k}_err"]) for k in ("contact", "collisional")
             if k in stored and f"{k}_err" in stored}
    return stress_results(scene, res.profiles, res.timeseries,
                          float(res.attrs.get("equilibration_end", 0.0)),
                          contact=parts.get("contact"), collisional=parts.get("collisional"))


def correlation_analysis(scene: Scene, frames: Callable[[], Iterable[Frame]] | None, name: str,
                         z_cells: int = 1) -> Any:
    """vcorr / lambda (two passes over ``frames``: run-mean bin (``z_cells`` > 1: cell)
    velocities first) and, not yet run (``frames`` None), waves in bins of
    ``measure.bin_width`` along y and cgprofiles along ``measure.axis`` with w = bin_width / 2
    at points spaced bin_width / 2."""
    from .coarse_graining import CoarseGrainedProfiles
    from .velocity_correlation import orientational_correlation, velocity_correlations
    from .waves import DensityWaves

    lo, hi, period = profile_bounds(scene)
    dim, shift = scene.dimension, image_shift(scene, period)
    if name == "cgprofiles":  # along measure.axis, like the profiles
        n_bins = len(bin_edges(lo, hi, scene.measure.bin_width)) - 1
        return CoarseGrainedProfiles(width=0.5 * scene.measure.bin_width,
                                     axis=scene.measure.axis, lo=lo, hi=hi, dim=dim,
                                     period=period, image_velocity_shift=shift,
                                     n_points=2 * n_bins)
    if scene.measure.axis != "y":  # the other statistics bin along y
        lo, hi = 0.0, scene.box.size[1]
    y_period = scene.box.size[1] if scene.y_periodic else 0.0
    edges = bin_edges(lo, hi, scene.measure.bin_width)
    y_bins = {"dim": dim, "edges": edges, "period": y_period,
              "image_velocity_shift": scene.shear.rate * y_period if scene.shear else 0.0}
    if name == "vcorr":
        periodic = periodic_lengths(scene)
        r_max = min(5.0, 0.5 * min(periodic) - 0.05) if periodic else 5.0
        return velocity_correlations(frames, r_max=r_max, dr=0.1, z_cells=z_cells, **y_bins)
    if name == "lambda":
        return orientational_correlation(frames, z_cells=z_cells, **y_bins)
    if name == "waves":
        ranges: list[tuple[float, float] | None] = [None] * dim
        if not scene.y_periodic:  # where the centres can be: walls -/+ d/2
            ranges[1] = (lo + 0.5, hi - 0.5)
        return DensityWaves(dim=dim, ranges=ranges, periodic_y=scene.y_periodic)
    raise ValueError(f"unknown statistic {name!r}")
