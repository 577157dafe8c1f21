"""Soft-contact health: how far a soft-contact run is from the hard-particle limit.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise a wall speed or
the shear rate sets the time unit τ); overlaps are in d, times in τ.

A soft-contact backend measures, at each production sample (never every step), the contacts
touching at that instant (:func:`contact_sample`); the loop keeps the samples and
:func:`health_results` turns them into the results file's ``health`` group: overlaps,
coordination, the contact time t_c of the contact model against the shear time 1/γ̇ and the
free-flight time between collisions, the steps per contact realised, and a verdict against
:data:`LIMITS` (the one place the thresholds live). The hard-particle limit assumes brief
(t_c ≪ τ_flight, t_c γ̇ ≪ 1), binary (few particles in two contacts at once), shallow
(overlap ≪ d) and resolved (enough steps per contact) collisions.

The collision rate is not counted (contacts begin and end between samples): it follows from
Little's law, contacts per particle at an instant = collision rate per particle × contact
duration, so ω = Z / t_c. That is exact for binary collisions lasting t_c and overestimates ω
when contacts endure (dense flows: then ``persistent_fraction``, the share of contacts already
present at the previous sample, is large, and is flagged).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..scene import Scene
from . import mapping
from .stiffness import ContactSetup

__all__ = ["LIMITS", "SAMPLE_KEYS", "assess", "contact_sample", "health_results",
           "impact_speeds", "shear_rate_of", "warning_text"]

#: Thresholds of the verdict (dimensionless; each flags a run when exceeded, or for
#: ``min_steps_per_contact`` when not reached). Documented in docs/contact.md.
LIMITS: dict[str, float] = {
    "max_overlap": 0.05,  # largest overlap, in d: contacts too soft for hard spheres
    "mean_overlap": 0.01,  # mean overlap of the touching contacts, in d
    "tc_flight": 0.1,  # t_c / τ_flight: collisions not instantaneous against free flights
    "tc_shear": 0.1,  # t_c γ̇: the flow deforms during a contact
    "multi_contact_fraction": 0.1,  # particles in ≥ 2 contacts at once: not binary collisions
    # contacts found again one sample later, beyond the share max(0, 1 − Δt/t_c) expected of
    # binary collisions lasting t_c: enduring contacts
    "persistent_fraction": 0.5,
    "min_steps_per_contact": 10.0,  # steps resolving the shortest contact (fewest realised)
}

#: Per-sample values a backend's ``health_sample()`` returns (all floats; NaN when no contact).
SAMPLE_KEYS = ("max_overlap", "mean_overlap", "contacts", "pair_contacts", "wall_contacts",
               "coordination", "multi_contact_fraction", "persistent_fraction",
               "min_impact_speed", "median_impact_speed", "max_impact_speed")


# -- per-sample measurement (pure numpy: engines pass their contact lists) ---------------------
def impact_speeds(vn: np.ndarray, overlap: np.ndarray, kn: float, m_eff: np.ndarray,
                  r_eff: np.ndarray, model: str) -> np.ndarray:
    """Normal impact speed of each contact reconstructed from its overlap δ and normal
    relative speed v_n now, by energy conservation of the elastic contact: Hooke
    v₀² = v_n² + k δ²/m_eff, Hertz v₀² = v_n² + (4/5) k √R δ^{5/2}/m_eff (damping makes it
    a lower bound by a few % for e ≳ 0.8)."""
    if model == "hertz":
        stored = 0.8 * kn * np.sqrt(r_eff) * overlap**2.5 / m_eff
    else:
        stored = kn * overlap**2 / m_eff
    return np.sqrt(vn**2 + stored)


def contact_sample(n_mobile: int, pair_i: np.ndarray, pair_j: np.ndarray,
                   pair_overlap: np.ndarray, wall_i: np.ndarray, wall_overlap: np.ndarray,
                   speeds: np.ndarray, previous: np.ndarray | None) -> tuple[dict, np.ndarray]:
    """One sample's health values (:data:`SAMPLE_KEYS`) from every contact touching now.

    ``pair_i``, ``pair_j``: 0-based indices of the touching mobile pairs' particles (below
    ``n_mobile``); ``wall_i``: the mobile particle of each wall or wall-bump contact; overlaps
    in d;
    ``speeds``: reconstructed impact speeds (:func:`impact_speeds`) of the mobile pairs;
    ``previous``: the pair keys of the previous sample (None: unknown). Returns the values and
    this sample's pair keys."""
    counts = np.zeros(n_mobile, dtype=np.int64)
    for side in (pair_i, pair_j, wall_i):
        counts += np.bincount(side, minlength=n_mobile)
    overlaps = np.concatenate([pair_overlap, wall_overlap])
    lo, hi = np.minimum(pair_i, pair_j), np.maximum(pair_i, pair_j)
    keys = np.unique(lo.astype(np.int64) * (1 << 31) + hi)
    persistent = math.nan
    if previous is not None and keys.size:
        persistent = np.intersect1d(keys, previous, assume_unique=True).size / keys.size
    nan = math.nan
    values = {
        "max_overlap": float(overlaps.max()) if overlaps.size else 0.0,
        "mean_overlap": float(overlaps.mean()) if overlaps.size else nan,
        "contacts": float(overlaps.size),
        "pair_contacts": float(pair_overlap.size),
        "wall_contacts": float(wall_overlap.size),
        "coordination": float(counts.mean()) if n_mobile else nan,
        "multi_contact_fraction": float(np.mean(counts >= 2)) if n_mobile else nan,
        "persistent_fraction": persistent,
        "min_impact_speed": float(speeds.min()) if speeds.size else nan,
        "median_impact_speed": float(np.median(speeds)) if speeds.size else nan,
        "max_impact_speed": float(speeds.max()) if speeds.size else nan,
    }
    return values, keys


# -- time scales ----------------------------------------------------------------------------
def shear_rate_of(scene: Scene, profiles: Mapping[str, Any] | None) -> tuple[float | None, str]:
    """γ̇ and where it came from: the scene's Lees–Edwards rate, the walls' speed difference
    over the gap (Couette), or the slope of a straight-line fit to the measured u_x(y) profile
    (occupied bins); None when no shear is found."""
    if scene.shear is not None:
        return float(scene.shear.rate), "scene shear rate"
    walls = {w.side: w for w in scene.walls}
    if len(walls) == 2 and all(w.servo is None for w in walls.values()):
        du = abs(walls["upper"].velocity - walls["lower"].velocity)
        gap = scene.wall_position("upper") - scene.wall_position("lower")
        if du > 0 and gap > 0:
            return du / gap, "wall speed difference / gap (Couette)"
    if profiles and "velocity" in profiles and "y" in profiles:
        y = np.asarray(profiles["y"], float)
        u = np.asarray(profiles["velocity"], float)[:, 0]
        occupied = np.isfinite(u)
        if "solid_fraction" in profiles:
            occupied &= np.asarray(profiles["solid_fraction"], float) > 0
        if occupied.sum() >= 3:
            slope = abs(float(np.polyfit(y[occupied], u[occupied], 1)[0]))
            scale = float(np.ptp(u[occupied])) or 1.0
            if slope > 1e-6 * scale:
                return slope, "straight-line fit to the measured u_x(y) profile"
    return None, "no shear"


def _enskog_flight_time(scene: Scene, profiles: Mapping[str, Any] | None) -> float | None:
    """1/ω̄ of Enskog theory, ω̄ the particle-weighted mean over the profile bins of the local
    collision frequency at the bin's ν and T (ν capped below close packing)."""
    from ..theory.kinetic import collision_frequency  # noqa: PLC0415 - theory is lazy

    if not profiles or "solid_fraction" not in profiles or "temperature" not in profiles:
        return None
    nu = np.asarray(profiles["solid_fraction"], float)
    temp = np.asarray(profiles["temperature"], float)
    ok = np.isfinite(nu) & np.isfinite(temp) & (nu > 0) & (temp > 0)
    if not ok.any():
        return None
    cap = 0.6 if scene.dimension == 3 else 0.8
    omega = collision_frequency(np.minimum(nu[ok], cap), temp[ok], scene.dimension)
    mean = float(np.sum(nu[ok] * omega) / np.sum(nu[ok]))
    return 1.0 / mean if mean > 0 else None


def _contact_times(scene: Scene, setup: ContactSetup,
                   speeds: np.ndarray) -> tuple[float, float, float, float]:
    """(pair t_c, wall t_c, shortest pair t_c, longest pair t_c) of the run's own contacts
    (``setup``: its k_n, which a pilot may have chosen): Hooke's are speed-independent;
    Hertz's at the median, largest and smallest measured impact speeds."""
    e = scene.contact.restitution
    wall_e = [w.restitution for w in scene.walls] or [e]
    if scene.soft.model != "hertz":
        tc = mapping.hooke_contact(setup.kn, e, 0.5).contact_time
        tw = mapping.hooke_contact(setup.kn, wall_e[0], 1.0).contact_time
        return tc, tw, tc, tc
    ok = speeds[np.isfinite(speeds) & (speeds > 0)]
    typical = float(np.median(ok)) if ok.size else 1.0

    def tc_at(v: float, m_eff: float = 0.5, r_eff: float = 0.25, rest: float = e) -> float:
        return mapping.hertz_contact(setup.kn, rest, m_eff, r_eff, v).contact_time

    fast = float(ok.max()) if ok.size else typical
    slow = float(ok.min()) if ok.size else typical
    return tc_at(typical), tc_at(typical, 1.0, 0.5, wall_e[0]), tc_at(fast), tc_at(slow)


# -- verdict and results --------------------------------------------------------------------
def assess(values: Mapping[str, Any], limits: Mapping[str, float] = LIMITS) -> list[str]:
    """The problems of a run's health attributes against ``limits`` (empty: healthy)."""
    problems = []

    def over(key: str, what: str) -> None:
        v = values.get(key)
        if v is not None and np.isfinite(v) and v > limits[key]:
            problems.append(f"{key} {v:.3g} > {limits[key]:g}: {what}")

    over("max_overlap", "largest overlap (in d) too large: contacts too soft for the "
                        "hard-particle limit")
    over("mean_overlap", "mean overlap (in d) too large: contacts too soft")
    over("tc_flight", "contact time not short against the free flight between collisions")
    over("tc_shear", "contact time not short against the shear time 1/γ̇")
    over("multi_contact_fraction", "many particles in two or more contacts at once: "
                                   "collisions are not binary")
    excess = values.get("persistent_fraction", math.nan) - values.get("persistent_expected",
                                                                         0.0)
    if np.isfinite(excess) and excess > limits["persistent_fraction"]:
        problems.append(f"persistent_fraction {values['persistent_fraction']:.3g} > "
                        f"{values.get('persistent_expected', 0.0):.3g} + "
                        f"{limits['persistent_fraction']:g} (binary collisions of duration t_c "
                        "+ limit): contacts outlive a sample interval: enduring contacts, "
                        "not collisions")
    steps = values.get("min_steps_per_contact")
    if steps is not None and steps < limits["min_steps_per_contact"]:
        problems.append(f"min_steps_per_contact {steps:.3g} < "
                        f"{limits['min_steps_per_contact']:g}: contacts under-resolved in time")
    return problems


def health_results(scene: Scene, setup: ContactSetup, samples: Mapping[str, list],
                   profiles: Mapping[str, Any] | None = None) -> tuple[dict, dict]:
    """The ``health`` group of a soft-contact run: per-sample arrays (``samples``: lists per
    :data:`SAMPLE_KEYS` plus ``time``, production samples only) and the scalar attributes
    (names in docs/results-format.md), with the verdict ``healthy``/``problems``.
    ``setup``: the contacts the run used (the backend's ``contact``: k_n and dt as the pilot
    chose them, not as a fresh ``contact_setup(scene)`` would guess)."""
    timestep = setup.timestep
    data = {k: np.asarray(v, dtype=float) for k, v in samples.items()}
    count = data["contacts"]
    with np.errstate(invalid="ignore"):
        mean_overlap = (float(np.nansum(data["mean_overlap"] * count) / count.sum())
                        if count.sum() else 0.0)
    tc, tc_wall, tc_fast, tc_slow = _contact_times(
        scene, setup, np.concatenate([data["min_impact_speed"], data["median_impact_speed"],
                               data["max_impact_speed"]]))
    n_mobile = max(1, scene.n_particles)  # bumps are not particles
    z_pair = float(np.mean(2 * data["pair_contacts"])) / n_mobile
    z_wall = float(np.mean(data["wall_contacts"])) / n_mobile
    omega = z_pair / tc + z_wall / tc_wall  # Little's law (module docstring)
    flight = max(0.0, 1.0 / omega - tc) if omega > 0 else math.inf
    rate, rate_source = shear_rate_of(scene, profiles)
    with np.errstate(all="ignore"):
        values: dict[str, Any] = {
            "max_overlap": _nanmax(data["max_overlap"]),
            "mean_overlap": mean_overlap,
            "contact_time": tc,
            "contact_time_wall": tc_wall,
            "timestep": timestep,
            "steps_per_contact": tc / timestep,
            "min_steps_per_contact": min([tc_fast] + [tc_wall] * bool(scene.walls)) / timestep,
            "max_steps_per_contact": tc_slow / timestep,
            "shear_rate": rate,
            "shear_rate_source": rate_source,
            "shear_time": 1.0 / rate if rate else None,
            "tc_shear": tc * rate if rate else None,
            "collision_rate": omega,
            "flight_time": flight,
            "tc_flight": (tc / flight if flight > 0 else math.inf) if omega > 0 else 0.0,
            "flight_time_method": "Little's law: collision rate per particle ω = Z_pair/t_c + "
                                  "Z_wall/t_c,wall from the contacts touching at the samples; "
                                  "τ_flight = 1/ω − t_c",
            "flight_time_enskog": _enskog_flight_time(scene, profiles),
            "coordination": float(np.nanmean(data["coordination"])),
            "multi_contact_fraction": float(np.nanmean(data["multi_contact_fraction"])),
            "persistent_fraction": _nanmean(data["persistent_fraction"]),
            "persistent_expected": max(0.0, 1.0 - _interval(data["time"]) / tc),
            "max_impact_speed": _nanmax(data["max_impact_speed"]),
            "median_impact_speed": _nanmedian(data["median_impact_speed"]),
            "impact_speed_method": "per touching pair: √(v_n² + stored elastic energy × 2/m_eff)"
                                   " (a lower bound: damping)",
            "model": scene.soft.model,
            "samples": len(data["time"]),
        }
    problems = assess(values)
    values.update(healthy=not problems, problems=problems, limits=dict(LIMITS),
                  units="d = 1, m = 1 (g = 1 with gravity); overlaps in d, times in τ")
    return data, values


def _interval(time: np.ndarray) -> float:
    """The sampling interval (inf with fewer than two samples: nothing can persist)."""
    return float(np.median(np.diff(time))) if time.size > 1 else math.inf


def _nanmean(a: np.ndarray) -> float:
    return float(np.nanmean(a)) if np.isfinite(a).any() else math.nan


def _nanmax(a: np.ndarray) -> float:
    return float(np.nanmax(a)) if np.isfinite(a).any() else math.nan


def _nanmedian(a: np.ndarray) -> float:
    return float(np.nanmedian(a)) if np.isfinite(a).any() else math.nan


def warning_text(attrs: Mapping[str, Any]) -> str | None:
    """The end-of-run warning of an unhealthy run (None when healthy)."""
    if attrs.get("healthy", True):
        return None
    lines = "\n  ".join(attrs["problems"])
    return ("warning: the soft contacts violate the hard-particle assumptions "
            f"(results group 'health'):\n  {lines}")
