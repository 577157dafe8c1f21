"""Soft-contact cases of the stability suite: each runs in every soft-contact engine through
the one simulation loop (``run_scene``), so it measures what a user's run would do.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise the wall speed
or shear rate sets the time unit τ); k_n in m/τ² (Hooke), overlaps and distances in d.
Every run here gives its stiffness (or hardness) explicitly or takes the automatic estimate
without the event-driven pilot (``plan = False``): the cases test the contact and time-step
settings, not the pilot.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from ..contact.health import LIMITS
from ..contact.stiffness import DEFAULT_OVERLAP, contact_setup
from ..errors import EngineError, UnsupportedByEngine
from ..io.results import Results, read_results
from ..scene import SceneError, load_scene, validate_scene
from ..simulation import RunOptions, run_scene
from .registry import SOFT, Outcome, case

#: restitution tolerance of a resolved binary collision (the calibration tables measure
#: |Δe| ≲ 0.004 at 50 steps per contact; docs/contact.md)
E_TOLERANCE = 0.01
#: the seed flows' typical impact speed the fast-impact case multiplies by 100
TYPICAL_SPEED = 1.0


def soft_run(spec: dict[str, Any], engine: str, folder: Path, name: str,
             keep_frames: bool = True) -> Results:
    """Run the scene ``spec`` (a scene dict) in ``engine``, isolated in a child process."""
    scene = validate_scene(spec, name)
    out = folder / f"{name}.h5"
    return read_results(run_scene(scene, engine, RunOptions(
        out=out, progress=False, keep_frames=keep_frames, plan=False, isolate=True)))


def particle_file(folder: Path, rows: list[list[float]]) -> str:
    path = folder / "particles.txt"
    path.write_text("".join(" ".join(f"{v:.17g}" for v in row) + "\n" for row in rows))
    return str(path)


def walled_box(size: list[float], e: float, rows: list[list[float]], folder: Path,
               soft: dict, production: float, sample: float) -> dict:
    """A 3D box periodic along x and z between flat smooth walls at y = 0 and y = size[1]."""
    return {"dimension": 3, "box": {"size": size, "periodic": ["x", "z"]},
            "particles": {"count": len(rows)}, "contact": {"restitution": e},
            "walls": [{"side": "lower", "position": 0.0, "restitution": e},
                      {"side": "upper", "position": size[1], "restitution": e}],
            "initial": {"placement": "file", "path": particle_file(folder, rows)},
            "run": {"equilibration": 0.0, "production": production,
                    "sample_interval": sample},
            "soft": soft}


def all_there(res: Results, n: int) -> str | None:
    """Why the run lost or broke particles (None: all n there, all finite)."""
    pos = np.asarray(res.frames["position"])
    if pos.shape[1] != n:
        return f"{n - pos.shape[1]} of {n} particles lost"
    if not (np.isfinite(pos).all() and np.isfinite(res.frames["velocity"]).all()):
        return "NaN or inf in positions or velocities"
    return None


# -- very stiff contacts ---------------------------------------------------------------------
@case("stiff-contacts", SOFT,
      "k_n = 1e5, 1e7, 1e9 with the automatic time step: pair and wall impacts restitute to "
      "e = 0.8; no particle lost",
      f"max |e_measured - e| < {E_TOLERANCE:g}")
def stiff_contacts(engine: str, quick: bool, folder: Path) -> Outcome:
    e, worst, parts = 0.8, 0.0, []
    for kn in (1e5, 1e7, 1e9):
        # a head-on pair closing at 1 and a sphere hitting the lower wall at 1, 3D
        rows = [[3.0, 5.0, 5.0, 0.5, 0.0, 0.0], [4.02, 5.0, 5.0, -0.5, 0.0, 0.0],
                [7.0, 0.6, 5.0, 0.0, -1.0, 0.0]]
        tc = math.pi / math.sqrt(2 * kn)  # pair t_c ≤ this (Hooke, m_eff = 1/2)
        spec = walled_box([10.0, 10.0, 10.0], e, rows, folder,
                          {"model": "hooke", "stiffness": kn}, 0.15 + 10 * tc, 0.05)
        res = soft_run(spec, engine, folder, f"kn{kn:g}")
        lost = all_there(res, 3)
        if lost:
            return Outcome("-", False, f"k_n = {kn:g}: {lost}")
        v = np.asarray(res.frames["velocity"])[-1]
        e_pair = (v[1, 0] - v[0, 0]) / 1.0
        e_wall = v[2, 1] / 1.0
        worst = max(worst, abs(e_pair - e), abs(e_wall - e))
        parts.append(f"k_n {kn:g}: dt {res.attrs['timestep']:.3g}, e_pair {e_pair:.4f}, "
                     f"e_wall {e_wall:.4f}")
    return Outcome(f"max |Δe| {worst:.2g}", worst < E_TOLERANCE, "; ".join(parts))


# -- elastic energy drift --------------------------------------------------------------------
@case("elastic-drift", SOFT,
      "27 elastic smooth spheres (e = 1, mu = 0), phi = 0.2, T = 1, Hooke at 50 steps per "
      "contact: total energy over 1e6 steps (--quick 1e5)",
      "max |E - E0|/E0 < 1e-3 at contact-free samples")
def elastic_drift(engine: str, quick: bool, folder: Path) -> Outcome:
    n, phi = 27, 0.2
    length = (n * math.pi / 6 / phi) ** (1 / 3)
    spec = {"dimension": 3, "box": {"size": [length] * 3}, "particles": {"count": n},
            "contact": {"restitution": 1.0},
            "initial": {"placement": "random", "velocity": {"temperature": 1.0}},
            "run": {"equilibration": 0.0, "production": 1.0, "sample_interval": 0.05,
                    "seed": 3},
            "soft": {"model": "hooke", "hardness": {"overlap": DEFAULT_OVERLAP,
                                                    "impact_speed": 3.0}}}
    steps = 100_000 if quick else 1_000_000
    dt = contact_setup(validate_scene(spec)).timestep
    spec["run"]["production"] = steps * dt
    res = soft_run(spec, engine, folder, "drift", keep_frames=False)
    ts, health = res.timeseries, res.groups["health"]
    energy = np.asarray(ts["kinetic_energy"]) + np.asarray(ts["rotational_energy"])
    # at a sample without any contact all energy is kinetic: the total energy, exactly
    free = np.isin(ts["time"], np.asarray(health["time"])[np.asarray(health["contacts"]) == 0])
    free[0] = True  # the start: no contact (random placement without overlaps)
    drift = np.abs(energy[free] - energy[0]) / energy[0]
    # measured in LAMMPS: 1.4e-4 after 1e5 steps, 4.3e-4 after 1e6, growing about as √steps
    # (a random walk of the small errors each contact's entry and exit between two steps
    # makes); the limit leaves room for 1e6 steps without accepting a systematic drift
    figure = float(drift.max())
    note = (f"{steps:.0e} steps of dt = {dt:.3g} (t = {steps * dt:.4g}), "
            f"{int(free.sum())} contact-free samples of {len(free)}; final |ΔE|/E0 = "
            f"{drift[-1]:.2g}")
    return Outcome(f"|ΔE|/E0 {figure:.2g} over {steps:.0e} steps", figure < 1e-3, note)


# -- impacts at 100 × the typical speed -------------------------------------------------------
def _min_pair_distance(pos: np.ndarray, i: int, j: int, width: float) -> np.ndarray:
    d = pos[:, i] - pos[:, j]
    d[:, 0] -= width * np.round(d[:, 0] / width)
    return np.linalg.norm(d, axis=1)


@case("fast-impacts", SOFT,
      "head-on and oblique (30 deg) pair and wall impacts at 100 x the typical speed 1, "
      "Hooke and Hertz made for overlap 0.005 d at speed 1: no tunnelling",
      "centres never cross: pairs stay > 0 apart and recede, wall centres stay inside")
def fast_impacts(engine: str, quick: bool, folder: Path) -> Outcome:
    v = 100 * TYPICAL_SPEED
    s, c = v * math.sin(math.radians(30)), v * math.cos(math.radians(30))
    pairs = [[3.0, 5.0, 2.5, v / 2, 0.0, 0.0], [4.2, 5.0, 2.5, -v / 2, 0.0, 0.0],  # head-on
             # oblique: the line of centres 30° from the approach (impact parameter d/2)
             [10.0, 5.0, 7.5, v / 2, 0.0, 0.0], [11.2, 5.5, 7.5, -v / 2, 0.0, 0.0]]
    walls = [[18.0, 0.7, 2.5, 0.0, -v, 0.0],  # head-on onto the lower wall
             [24.0, 0.7, 7.5, s, -c, 0.0]]  # 30° from the wall normal
    figures, notes, refused, ok = [], [], [], True
    undetected = False  # a failure other than a loss the engine stopped on and named
    for model in ("hooke", "hertz"):
        soft = {"model": model, "hardness": {"overlap": DEFAULT_OVERLAP,
                                             "impact_speed": TYPICAL_SPEED}}
        setup = contact_setup(validate_scene(walled_box([30.0, 10.0, 10.0], 0.8, pairs,
                                                        folder, soft, 1.0, 1.0)))
        duration = 0.004 + 3 * setup.pair.contact_time
        for what, rows in (("pairs", pairs), ("walls", walls)):
            spec = walled_box([30.0, 10.0, 10.0], 0.8, rows, folder, soft, duration,
                              setup.timestep)
            try:
                res = soft_run(spec, engine, folder, f"{model}-{what}")
            except UnsupportedByEngine as exc:  # e.g. an engine without Hertz contacts
                refused.append(f"{model} {what}: {exc}")
                continue
            except EngineError as exc:
                ok = False
                # LAMMPS: "Lost atoms" with its cause; LIGGGHTS: "crossed the lower wall"
                text = str(exc).lower()
                lost = "lost" in text or "crossed the" in text
                undetected |= not (lost and model == "hooke")
                figures.append(f"{model} {what}: " + ("lost (stopped, named)" if lost
                                                      else "failed"))
                notes.append(f"{model} {what}: the run stopped: "
                             f"{str(exc).splitlines()[0][-160:]}")
                continue
            broken = all_there(res, len(rows))
            if broken:
                ok, undetected = False, True
                figures.append(f"{model} {what}: {broken}")
                continue
            pos, vel = np.asarray(res.frames["position"]), np.asarray(res.frames["velocity"])
            if what == "pairs":
                closest = math.inf
                for i, j in ((0, 1), (2, 3)):
                    dist = _min_pair_distance(pos, i, j, 30.0)
                    closest = min(closest, float(dist.min()))
                    # receding along the line of centres at the end (an oblique pair may
                    # pass each other in x without any overlap: that is no tunnelling)
                    sep = pos[-1, j] - pos[-1, i]
                    sep[0] -= 30.0 * np.round(sep[0] / 30.0)
                    held = bool(dist.min() > 0.0 and sep @ (vel[-1, j] - vel[-1, i]) > 0)
                    ok &= held
                    undetected |= not held
                figures.append(f"{model} pairs {closest:.2g} d")
            else:
                lowest = float(pos[..., 1].min())  # the lower wall stays at y = 0
                held = bool(lowest > 0.0 and (vel[-1, :, 1] > 0).all())
                ok &= held
                undetected |= not held
                figures.append(f"{model} walls {lowest:.2g} d")
            notes.append(f"{model} {what}: dt {setup.timestep:.3g}, max overlap "
                         f"{res.group_attrs['health']['max_overlap']:.3g} d")
    if not figures:  # the engine refused every run: the row is "refused"
        raise UnsupportedByEngine(engine, "fast-impacts", "all runs", "; ".join(refused))
    # a Hooke contact made for an overlap of 0.005 d at speed 1 overlaps ≈ v √(m_eff/k_n):
    # 0.5 d for a pair, 0.71 d at a wall (m_eff = m) at 100 x, so the centre passes the wall
    # plane; what matters is that the engine stops and names it, never silently
    explained = "" if ok or undetected else (
        "a Hooke wall contact sized for speed 1 overlaps ~0.71 d at 100 x (v sqrt(m/k_n)): "
        "the centre crosses the wall plane and the engine stops with its lost-atom error "
        "naming the cause (too soft for the impact speeds); pairs and Hertz contacts hold")
    return Outcome("; ".join(figures), ok, "closest centre distance (pairs) and lowest "
                   "centre above the wall (walls); " + "; ".join(notes + refused), explained)


# -- a time step too large for the contact ----------------------------------------------------
@case("timestep-too-large", SOFT,
      "a time step too large for the contact: steps_per_contact = 5 in the scene, and Hertz "
      "contacts made for speed 1 at 10 steps hit at 30",
      f"refused at validation; realised steps < {LIMITS['min_steps_per_contact']:g} "
      "flagged by the health verdict")
def timestep_too_large(engine: str, quick: bool, folder: Path) -> Outcome:
    rows = [[3.0, 5.0, 5.0, 15.0, 0.0, 0.0], [4.2, 5.0, 5.0, -15.0, 0.0, 0.0]]
    soft = {"model": "hertz", "hardness": {"overlap": DEFAULT_OVERLAP, "impact_speed": 1.0},
            "steps_per_contact": 10}
    spec = walled_box([10.0, 10.0, 10.0], 0.9, rows, folder, soft, 1.0, 1.0)
    try:  # (a) a scene asking for under-resolved contacts directly
        validate_scene({**spec, "soft": {**soft, "steps_per_contact": 5}}, "coarse")
        refused, why = False, "steps_per_contact = 5 was accepted"
    except SceneError as exc:
        refused = "steps_per_contact" in str(exc)
        why = "refused: " + str(exc).splitlines()[-1].strip().lstrip("- ")
    # (b) the steps the time step leaves to contacts faster than designed (Hertz t_c ∝ v^-1/5)
    setup = contact_setup(validate_scene(spec))
    spec["run"].update(production=0.2 / 30 + 3 * setup.pair.contact_time,
                       sample_interval=setup.timestep)
    try:
        health = soft_run(spec, engine, folder, "hertz",
                          keep_frames=False).group_attrs["health"]
    except UnsupportedByEngine as exc:  # a Hooke-only engine: t_c is speed-independent
        return Outcome(f"refused: {'yes' if refused else 'no'}; Hertz refused", refused,
                       f"(a) {why}; (b) {exc}")
    steps = float(health["min_steps_per_contact"])
    flagged = any(p.startswith("min_steps_per_contact") for p in health["problems"])
    measured = f"refused: {'yes' if refused else 'no'}; realised steps {steps:.3g}"
    note = (f"(a) {why}; (b) health verdict: "
            + ("; ".join(health["problems"]) or "healthy (not flagged)"))
    return Outcome(measured, refused and flagged and steps < 10, note)


# -- dense shear near jamming -----------------------------------------------------------------
def packed_start(dim: int, fraction: float, cells: tuple[int, ...], seed: int,
                 folder: Path) -> tuple[list[float], str]:
    """A periodic box and a particle file at ``fraction``: a hexagonal lattice of discs
    (cells = columns, rows; rows even) or an fcc lattice of spheres (cells = (m,): 4 m³),
    each centre jittered by up to a quarter of its gap, velocities u_x = γ̇ (y − L_y/2) with
    γ̇ = 1 plus a thermal part of T = 0.1. Random placement stops at ν = 0.8 / φ = 0.6."""
    rng = np.random.default_rng(seed)
    if dim == 2:
        nx, ny = cells
        a = math.sqrt(math.pi / (2 * math.sqrt(3) * fraction))  # hexagonal spacing
        i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
        pos = np.column_stack([(i + 0.5 * (j % 2) + 0.25).ravel() * a,
                               (j + 0.5).ravel() * a * math.sqrt(3) / 2])
        size = [nx * a, ny * a * math.sqrt(3) / 2]
    else:
        (m,) = cells
        a = (4 * math.pi / 6 / fraction) ** (1 / 3)  # cubic cell of 4 spheres
        basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]]) + 0.25
        grid = np.stack(np.meshgrid(*[np.arange(m)] * 3, indexing="ij"), -1).reshape(-1, 3)
        pos = ((grid[:, None, :] + basis[None]) * a).reshape(-1, 3)
        size = [m * a] * 3
        a /= math.sqrt(2)  # the nearest-neighbour distance
    pos += rng.uniform(-1, 1, pos.shape) * (a - 1.0) / 4
    vel = rng.normal(scale=math.sqrt(0.1), size=pos.shape)
    vel -= vel.mean(axis=0)
    vel[:, 0] += pos[:, 1] - size[1] / 2
    rows = np.column_stack([pos, vel]).tolist()
    return [round(s, 12) for s in size], particle_file(folder, rows)


def thermal_energy(res: Results, height: float, window: float) -> float:
    """Mean kinetic energy per particle about the shear profile u = γ̇ (y − L_y/2) x̂ (γ̇ = 1)
    over the frames in 0 < t <= window: the heat, without the mean flow that dominates E_kin."""
    t = np.asarray(res.frames["time"])
    x = np.asarray(res.frames["position"])[(t > 0) & (t <= window + 1e-9)]
    v = np.array(res.frames["velocity"])[(t > 0) & (t <= window + 1e-9)]
    v[..., 0] -= x[..., 1] - np.asarray(res.frames["box_lo"])[0][1] - height / 2
    return float(np.mean(0.5 * np.sum(v**2, axis=-1)))


#: the elastic regime's signature (docs/stability.md, finding 2): 10 x k_n leaves the mean
#: overlap above 10^-1/4 of its value (a collisional flow: k_n^-1/2, 0.32), and heats the flow
#: instead of leaving its temperature alone (a collisional flow's T does not depend on k_n)
ELASTIC_OVERLAP_RATIO = 10 ** -0.25
ELASTIC_HEAT_RATIO = 1.5


def _dense_shear(engine: str, quick: bool, folder: Path, dim: int, fraction: float,
                 cells: tuple[int, ...]) -> Outcome:
    """The automatic stiffness (the estimate: overlap 0.005 d at 5 γ̇ d) and 10 × it; the
    pilot's choice is reported, not run (near jamming it asks for dt ~ 1e-8).

    Outside the limits, the row is "explained" when the runs show the elastic regime of
    shear-jammed rough contacts (docs/stability.md, finding 2): overlaps that do not shrink
    as k_n^-1/2 and heat that grows with k_n, with enduring contacts flagged by the health
    verdict. The uncapped tangential spring that stands for β sticks without limit in an
    enduring contact; above the jamming fraction of infinitely rough particles the flow is
    then a sheared solid whose stress grows with k_n, which hard β collisions cannot show."""
    from ..contact.pilot import run_pilot

    size, path = packed_start(dim, fraction, cells, 7, folder)
    spec = {"dimension": dim, "box": {"size": size},
            "particles": {"count": len(Path(path).read_text().splitlines())},
            "contact": {"restitution": 0.7, "tangential": {"model": "beta", "beta": 0.0}},
            "shear": {"rate": 1.0},
            "initial": {"placement": "file", "path": path},
            "run": {"equilibration": 0.0, "production": 2.0 if quick else 10.0,
                    "sample_interval": 0.2, "seed": 7}}
    scene = validate_scene(spec)
    overlaps, means, kinetic, heat, notes, ok = [], [], [], [], [], True
    persistent = True
    duration = spec["run"]["production"]
    window = 1.0 if quick else 2.0  # the hard run's window
    kn = contact_setup(scene).kn
    for factor in (1, 10):
        if factor > 1:
            spec["soft"] = {"stiffness": factor * kn}
        res = soft_run(spec, engine, folder, f"shear{dim}d-k{factor}")
        lost = all_there(res, scene.n_particles)
        if lost or not np.isfinite(res.timeseries["kinetic_energy"]).all():
            return Outcome("-", False, f"k_n = {factor * kn:.3g}: {lost or 'NaN energy'}")
        health = res.group_attrs["health"]
        overlaps.append(float(health["max_overlap"]))
        means.append(float(health["mean_overlap"]))
        t = np.asarray(res.timeseries["time"])
        early = (t > 0) & (t <= window + 1e-9)
        kinetic.append(float(np.mean(res.timeseries["kinetic_energy"][early])))
        heat.append(thermal_energy(res, size[1], window))
        flagged = any(p.startswith("max_overlap") for p in health["problems"])
        persistent &= any(p.startswith("persistent_fraction") for p in health["problems"])
        # the automatic k_n may be too soft, but then the verdict must say so; 10 × it must
        # keep the overlaps within the limit
        ok &= (flagged if overlaps[-1] > LIMITS["max_overlap"] else not flagged)
        ok &= factor == 1 or overlaps[-1] <= LIMITS["max_overlap"]
        notes.append(f"k_n = {factor * kn:.3g} ({'automatic estimate' if factor == 1 else '10 x'}"
                     f", dt {res.attrs['timestep']:.3g}): max overlap {overlaps[-1]:.3g} d, "
                     f"mean {means[-1]:.3g} d, coordination {health['coordination']:.3g}, "
                     f"heat (E_kin per particle about the shear profile, t <= {window:g}) "
                     f"{heat[-1]:.3g}; verdict: "
                     + ("; ".join(p.split(":")[0] for p in health["problems"]) or "healthy"))
    # the same start with hard particles: a soft run must not heat beyond it
    # (rough hard spheres near jamming are slow: 2 strain units of 256 take ~35 s)
    spec.pop("soft", None)
    spec["run"]["production"] = window
    hard = read_results(run_scene(validate_scene(spec), "edmd", RunOptions(
        out=folder / f"shear{dim}d-edmd.h5", progress=False, plan=False, isolate=True,
        keep_frames=True)))
    ratio = kinetic[0] / float(np.mean(hard.timeseries["kinetic_energy"][1:]))
    heat_ratio = heat[0] / thermal_energy(hard, size[1], window)
    ok &= abs(ratio - 1.0) < HEAT_TOLERANCE
    notes.append(f"mean E_kin (mean flow included) over t <= {window:g}: {ratio:.3g} x the "
                 f"event-driven run's from the same start; heat {heat_ratio:.3g} x")
    pilot = contact_setup(scene, pilot=run_pilot(scene))
    notes.append(f"the event-driven pilot would choose k_n = {pilot.kn:.3g}, dt = "
                 f"{pilot.timestep:.3g} (its free-flight time near jamming is tiny)")
    head = (f"N = {scene.n_particles} at {scene.solid_fraction:.3f}, "
            f"{duration:g} strain units, nothing lost, no NaN; ")
    elastic = (means[1] / means[0] > ELASTIC_OVERLAP_RATIO
               and heat[1] / heat[0] > ELASTIC_HEAT_RATIO and persistent)
    why = ""
    if not ok and elastic:
        why = (f"elastic regime of shear-jammed rough contacts (docs/stability.md, finding 2): "
               f"10 x k_n leaves the mean overlap at {means[1] / means[0]:.2f} of its value "
               f"(> {ELASTIC_OVERLAP_RATIO:.2f}; collisional: 0.32) and multiplies the heat by "
               f"{heat[1] / heat[0]:.2f} (> {ELASTIC_HEAT_RATIO:g}); contacts persist")
    return Outcome(f"max overlap {overlaps[0]:.3g} d (auto k_n), {overlaps[1]:.3g} d (10 x); "
                   f"E_kin {ratio:.2f} x hard (heat {heat_ratio:.2g} x)",
                   bool(ok), head + "; ".join(notes), why)


#: largest relative difference of the mean kinetic energy from the event-driven run's
HEAT_TOLERANCE = 0.25
DENSE_LIMIT = (f"max overlap <= {LIMITS['max_overlap']:g} d (health limit) at 10 x the "
               "automatic k_n, above it only if the health verdict flags it; mean E_kin "
               f"within {HEAT_TOLERANCE:.0%} of the event-driven run's")


@case("dense-shear-2d", SOFT,
      "Lees-Edwards shear of rough discs (beta = 0) at nu = 0.82, e = 0.7, automatic k_n "
      "and 10 x it: no particle lost, no NaN, overlaps, no heating", DENSE_LIMIT)
def dense_shear_2d(engine: str, quick: bool, folder: Path) -> Outcome:
    return _dense_shear(engine, quick, folder, 2, 0.82, (14, 16))


@case("dense-shear-3d", SOFT,
      "Lees-Edwards shear of rough spheres (beta = 0) at phi = 0.62, e = 0.7, automatic "
      "k_n and 10 x it: no particle lost, no NaN, overlaps, no heating", DENSE_LIMIT)
def dense_shear_3d(engine: str, quick: bool, folder: Path) -> Outcome:
    return _dense_shear(engine, quick, folder, 3, 0.62, (4,))


# -- servo walls at 10 × the seed's normal stress ---------------------------------------------
SERVO_SEED = "campbell1982/couette-rough"


@case("servo-10x", SOFT,
      f"servo walls of {SERVO_SEED} at 10 x its normal stress: the gap settles, no "
      "particle crosses a wall",
      "gap: mean of the last two quarters within 5 %, spread < 5 %; centres between walls")
def servo_10x(engine: str, quick: bool, folder: Path) -> Outcome:
    base = load_scene(SERVO_SEED)
    sigma = 10 * base.walls[0].servo.normal_stress
    sets = [f"walls.{k}.servo.normal_stress={sigma}" for k in (0, 1)]
    sets += ["run.equilibration=300", f"run.production={300 if quick else 600}"]
    scene = load_scene(SERVO_SEED, sets)
    res = read_results(run_scene(scene, engine, RunOptions(
        out=folder / "servo.h5", progress=False, keep_frames=True, plan=False, isolate=True)))
    lost = all_there(res, scene.n_particles)
    if lost:
        return Outcome("-", False, lost)
    ts = res.timeseries
    t, gap = np.asarray(ts["time"]), np.asarray(ts["gap"])
    start = scene.run.equilibration
    span = t[-1] - start
    q3 = gap[(t >= start + span / 2) & (t < start + 3 * span / 4)]
    q4 = gap[t >= start + 3 * span / 4]
    change = abs(q4.mean() - q3.mean()) / q4.mean()
    spread = float(np.std(gap[t >= start + span / 2]) / q4.mean())
    y = np.asarray(res.frames["position"])[..., 1]
    n_frames = len(y)
    lower = np.asarray(ts["wall_position_lower"])[-n_frames:]
    upper = np.asarray(ts["wall_position_upper"])[-n_frames:]
    inside = float(min((y.min(axis=1) - lower).min(), (upper - y.max(axis=1)).min()))
    ok = change < 0.05 and spread < 0.05 and inside > 0.0
    note = (f"sigma_n = {sigma:.4g}; gap {q4.mean():.3g} d (started 12), last-quarter change "
            f"{change:.2%}, spread {spread:.2%}; closest centre {inside:.3g} d from a wall; "
            f"max overlap {res.group_attrs['health']['max_overlap']:.3g} d")
    return Outcome(f"gap change {change:.1%}, spread {spread:.1%}", ok, note)


# -- very soft contacts -----------------------------------------------------------------------
@case("very-soft", SOFT,
      "a gas of spheres with k_n = 100 (overlaps ~ 0.1 d): the run's health figures flag it",
      f"max_overlap >= {LIMITS['max_overlap']:g} d and the health verdict says so")
def very_soft(engine: str, quick: bool, folder: Path) -> Outcome:
    length = (100 * math.pi / 6 / 0.3) ** (1 / 3)
    spec = {"dimension": 3, "box": {"size": [length] * 3}, "particles": {"count": 100},
            "contact": {"restitution": 0.9},
            "initial": {"velocity": {"temperature": 1.0}},
            "run": {"equilibration": 0.0, "production": 2.0, "sample_interval": 0.05,
                    "seed": 5},
            "soft": {"model": "hooke", "stiffness": 100.0}}
    health = soft_run(spec, engine, folder, "soft", keep_frames=False).group_attrs["health"]
    overlap = float(health["max_overlap"])
    flagged = not health["healthy"] and any(p.startswith("max_overlap")
                                            for p in health["problems"])
    note = "health verdict: " + ("; ".join(health["problems"]) or "healthy (not flagged)")
    return Outcome(f"max overlap {overlap:.3g} d, flagged: {'yes' if flagged else 'no'}",
                   flagged and overlap >= LIMITS["max_overlap"], note)
