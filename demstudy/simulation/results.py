"""The results file of a run: root attributes, profiles, timeseries, stress, collision log
and every statistic the scene names.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..analysis.registry import STATISTICS, Context
from ..analysis.steady import energy_trend, is_steady
from ..analysis.stress import CollisionalSums, ContactStress, collisional_stress, stress_results
from ..contact.health import health_results
from ..io.results import Results, frames_of
from ..scene import Scene, scene_to_toml
from .state import RunState

__all__ = ["run_attrs", "run_results"]


def run_attrs(scene: Scene, engine: str, version: str, wall_seconds: float,
              equilibration_end: float, timeseries: dict[str, np.ndarray]) -> dict[str, Any]:
    """Root attributes every results file carries, with Campbell's steadiness verdict over the
    production samples (those after ``equilibration_end``): on the kinetic energy, in
    y-periodic boxes its peculiar part (the Lees–Edwards mean flow's share is fixed by the
    shear and would hide any change of the fluctuations, e.g. 15 times their energy at
    L = 40, ν = 0.3)."""
    t = timeseries["time"]
    production = t > equilibration_end + 1e-9 * max(1.0, abs(equilibration_end))
    energy = timeseries.get("peculiar_kinetic_energy", timeseries["kinetic_energy"])
    trend = energy_trend(t[production], np.asarray(energy)[production])
    return {
        "engine": engine,
        "engine_version": version,
        "scene_toml": scene_to_toml(scene),
        "scene_name": scene.meta.name,
        "seed": scene.run.seed,
        "run_unit": scene.run.unit,
        "wall_seconds": wall_seconds,
        "equilibration_end": equilibration_end,
        "kinetic_energy_trend": trend,
        "steady": is_steady(trend),
    }


# -- results --------------------------------------------------------------------------
def run_results(sim: Any, state: RunState, extra: dict[str, Any]) -> Results:
    """The results of a finished run of ``sim`` (a Simulation): what the loop accumulated,
    the stress, the collision log, the streaming statistics, and those computed now from the
    kept frames, the log or the results themselves; ``extra``: the engine's attributes."""
    scene, backend = sim.scene, sim.backend
    profiles = state.profiles.finish()
    timeseries = {k: np.asarray(v) for k, v in state.timeseries.items()}
    frames = {k: np.asarray(v) for k, v in state.frames.items()} or None
    equilibration_end = float(timeseries["time"][sim.schedule.n_eq])
    attrs = run_attrs(scene, backend.name, backend.version, state.wall_seconds,
                      equilibration_end, timeseries)
    attrs["resumes"] = state.resumes
    attrs.update(extra)
    results = Results(attrs, timeseries, profiles.results, profiles.attrs, frames)
    if sim.measure_stress:
        results.groups["stress"], results.group_attrs["stress"] = _stress(
            sim, state, results, equilibration_end)
    if state.health:  # soft contacts: how far from the hard-particle limit
        results.groups["health"], results.group_attrs["health"] = health_results(
            scene, backend.contact, state.health, profiles.results)
    if state.log:
        results.groups["collisions"] = {k: np.concatenate(v) for k, v in state.log.items()}
        results.group_attrs["collisions"] = {
            "log_every": sim.log_every, "capacity": sim.log_capacity,
            "units": "d = 1, m = 1 (g = 1 with gravity); kind 0 pair, 1 lower wall, "
                     "2 upper wall; normal from i to j (or to the wall); branch r_j - r_i "
                     "(contact point - r_i for walls); impulse on i; velocity v_i - v_j "
                     "and spin_velocity (contact-point relative velocity) before"}
    if state.tracks is not None:  # marked grains' paths
        results.groups["tracks"], results.group_attrs["tracks"] = state.tracks.results()
    for name, analysis in state.streams.items():
        analysis.finish()
        results.groups[f"statistics/{name}"] = analysis.results
        results.group_attrs[f"statistics/{name}"] = analysis.attrs
    ctx = Context(scene, results=results,
                  frames=(lambda: frames_of(results, scene.dimension)) if frames else None)
    failed = []
    for name in sim.after:
        try:  # a finished run's results are written whatever one statistic does
            data, group_attrs = STATISTICS[name].compute(ctx)
        except Exception as exc:  # noqa: BLE001 - recorded and reported after the write
            failed.append(f"{name}: {type(exc).__name__}: {exc}")
            continue
        results.groups[f"statistics/{name}"] = data
        results.group_attrs[f"statistics/{name}"] = group_attrs
    if failed:
        results.attrs["statistics_failed"] = "\n".join(failed)
    return results


def _stress(sim: Any, state: RunState, results: Results, start: float) -> tuple[dict, dict]:
    """The ``/stress`` group: kinetic (profiles), walls, momentum balance, and the engine's
    interaction stress (collisional: increments over the production intervals; contact:
    samples)."""
    parts: dict[str, Any] = {}
    stress, edges = state.stress, state.stress_edges
    if isinstance(stress, CollisionalSums) and stress.chunks:
        # the bins' cross-section: the (mean production) periodic width × depth
        size = list(sim.scene.box.size)
        if "width" in results.timeseries:
            size[0] = float(np.mean(results.timeseries["width"][sim.schedule.n_eq:]))
        section = float(np.prod([size[i] for i in range(sim.scene.dimension) if i != 1]))
        parts["collisional"] = collisional_stress(np.asarray(stress.chunks),
                                                  np.asarray(stress.durations), edges,
                                                  section)
    elif isinstance(stress, ContactStress):
        parts["contact"] = stress.finish()
    data, attrs = stress_results(sim.scene, results.profiles, results.timeseries, start,
                                 momentum=(state.momentum_start, state.momentum_end),
                                 **parts)
    if sim.backend.capabilities.stress == "contact":
        attrs["contact_samples"] = stress.samples if isinstance(stress, ContactStress) else 0
    if results.profile_attrs.get("wall_relative") and edges is not None:
        # walls that move: the engine's bins stay where production started (same count as
        # the profiles' wall-relative strips, which the kinetic part and `edges` follow)
        attrs["interaction_bins"] = (f"fixed strips between the walls where production "
                                     f"started, [{edges[0]:.6g}, {edges[-1]:.6g}]; kinetic: "
                                     "the profiles' wall-relative strips")
    return data, attrs
