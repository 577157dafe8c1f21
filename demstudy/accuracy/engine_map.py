"""Which engine should I use? The engine map: over solid fraction and restitution, 2D discs
and 3D spheres in unbounded Lees–Edwards shear (β = 0.5 rough particles, the presets
``shear/lees-edwards-2d`` and ``-3d`` in small boxes), the cost per particle per strain unit of
the event-driven engine against soft contacts (LAMMPS) stiff enough for a target accuracy
(docs/accuracy-cost.md, "Which engine? The engine map").

Dimensionless particle units: d = 1, m = 1, the shear rate γ̇ = 1 sets the time scale (times
in strain units 1/γ̇); costs in seconds of wall time of the machine that ran the map, per
particle per strain unit (intensive: small boxes and short runs suffice).

Method, per grid point (``map_point``):

1. **Event-driven cost**: an edmd run (TC model at its default t_c) with a wall-clock limit
   ``timeout``: an equilibration of ``relaxations`` (3) relaxation times of the temperature,
   3/((1 − e²) ω_E), then a production of ``production`` (400) collisions per particle,
   400/ω_E, both in strain units between ``min_strain`` (2) and ``max_strain`` (200); ω_E is
   Enskog's collision rate at T = (γ̇ d)², a budget only (the preset's initial state, a
   jittered lattice, collapses into a burst of collisions at first: a run counted in
   collisions would measure that burst in dense boxes). Its cost is the production share of
   the wall time (wall × production collisions / all collisions: an event-driven run's time
   goes with its collisions) over N × production strain. A run that stops at the limit or
   fails (an event budget exhausted), or whose TC model made more than ``TC_IMPRACTICAL``
   (10 %) of the production's collisions elastic (inelastic collapse held off by the TC
   model: not the hard-particle limit, and smaller t_c costs ever more) marks the point
   "event-driven impractical", with the reason; no soft run is made there.
2. **The stiffness for the accuracy**: the collision rate ω per particle of the production
   (2 pair collisions per particle per strain) gives the mean free-flight time
   τ_flight = 1/ω; the soft contacts' time is t_c = R τ_flight (``R``, default
   ``R_DEFAULT`` = 0.05, stands for "profile errors within 2 %": the accuracy ladders set
   it) and the Hooke k_n follows exactly from ``mapping.hooke_contact`` (``kn_for_contact``);
   k* = k_n/(ρ d³ γ̇²). Soft runs take ``STEPS_PER_CONTACT`` = 50 steps per contact.
3. **Soft cost**: a LAMMPS run at that k_n started at the event-driven temperature, of
   ``soft_steps`` (20 000) time steps (at most ``max_strain``), cost = wall / (N × simulated
   strain). The cost per step is what matters: where those steps cover less than
   ``soft_strain`` (2) strain units the row says the cost is extrapolated from a shorter run
   (``soft_extrapolated``).

Each point is measured ``repeats`` (3) times with other seeds; the ratio soft cost /
event-driven cost (geometric mean, with its standard error) classifies the point
(``classify``).
"""

from __future__ import annotations

import math
import os
import shutil
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..contact import mapping
from ..contact.stiffness import TARGET_CONTACT_RATIO
from ..errors import BadOption

#: t_c / τ_flight that keeps profile errors within the target (2 %), from the accuracy
#: ladders (docs/accuracy-cost.md: 2.4 % at 0.018, 8.6 % at 0.05 in Malik's Poiseuille);
#: the same as the automatic settings' target (``contact.stiffness.TARGET_CONTACT_RATIO``)
R_DEFAULT = TARGET_CONTACT_RATIO
#: soft time steps per contact time: 10 suffice with the time-step-compensated contacts
#: (docs/accuracy-cost.md: 10 and 50 agree within the noise in every ladder)
STEPS_PER_CONTACT = 10.0
#: the grid of the map (issue 12, item 7)
FRACTIONS = {2: (0.1, 0.3, 0.5, 0.65, 0.75), 3: (0.1, 0.3, 0.45, 0.55, 0.6)}
RESTITUTIONS = (0.5, 0.7, 0.9, 0.99)
#: above this share of collisions made elastic by the TC model (within t_c of a partner's
#: previous collision: dense, collapsing flows) the event-driven run is not the hard-particle
#: limit and a converged one (smaller t_c) costs ever more: "event-driven impractical"
TC_IMPRACTICAL = 0.1
#: particles per box: a few hundred (costs per particle are intensive)
PARTICLES = {2: 300, 3: 350}
PRESETS = {2: "shear/lees-edwards-2d", 3: "shear/lees-edwards-3d"}
SOFT_CHEAPER, EVENT_CHEAPER, IMPRACTICAL = ("soft cheaper", "event-driven cheaper",
                                            "event-driven impractical")
DEFAULT_OUT = Path("results") / "engine-map"
#: ``--quick``: two points of very short runs (end-to-end check, seconds)
QUICK = {"fractions": (0.3,), "restitutions": (0.7, 0.9),
         "settings": {"production": 40.0, "min_strain": 1.0, "max_strain": 5.0,
                      "soft_strain": 0.2, "soft_steps": 1000, "repeats": 1}}


@dataclass(frozen=True)
class MapSettings:
    """How each point is measured (module doc). Collisions are pair collisions per
    particle (the scenes' ``run.unit = 'collisions'``); ``timeout`` in wall seconds."""

    ratio: float = R_DEFAULT
    steps_per_contact: float = STEPS_PER_CONTACT
    production: float = 400.0
    min_strain: float = 2.0
    max_strain: float = 200.0
    timeout: float = 20.0
    soft_strain: float = 2.0
    soft_steps: int = 20_000
    relaxations: float = 3.0
    repeats: int = 3
    particles: dict[int, int] = field(default_factory=lambda: dict(PARTICLES))

    def check(self) -> None:
        """Bad values raise ``BadOption`` naming the option (CLI exit 2)."""
        for name, value in (("--ratio", self.ratio), ("--timeout", self.timeout),
                            ("production", self.production), ("min_strain", self.min_strain),
                            ("soft_strain", self.soft_strain)):
            if not (math.isfinite(value) and value > 0):
                raise BadOption(name, value, "a number > 0 is allowed")
        if not self.max_strain >= self.min_strain:
            raise BadOption("max_strain", self.max_strain, f">= min_strain {self.min_strain}")
        if self.steps_per_contact < 10:
            raise BadOption("steps_per_contact", self.steps_per_contact, "at least 10")
        if self.repeats < 1:
            raise BadOption("repeats", self.repeats, "at least 1")
        if self.soft_steps < 100:
            raise BadOption("soft_steps", self.soft_steps, "at least 100 time steps")


# ------------------------------------------------------------------ the stiffness criterion
def kn_for_contact(contact_time: float, e: float, m_eff: float = 0.5) -> float:
    """Hooke k_n whose damped contact time (LAMMPS ``hooke`` + ``coeff_restitution``) is
    ``contact_time``: inverts ``mapping.hooke_contact`` exactly,
    t_c = π / (√(k_n/m_eff) √(1 − ζ²)), ζ the damping ratio of restitution e."""
    if not contact_time > 0:
        raise ValueError(f"contact_time must be > 0, not {contact_time}")
    zeta = mapping.damping_ratio(e)
    return m_eff * (math.pi / contact_time) ** 2 / (1.0 - zeta * zeta)


def soft_stiffness(tau_flight: float, e: float, ratio: float = R_DEFAULT,
                   dim: int = 2, shear_rate: float = 1.0) -> tuple[float, float]:
    """(k_n, k*) of the criterion t_c = ``ratio`` × τ_flight for equal particles (pair
    contact, m_eff = m/2); k* = k_n/(ρ d³ γ̇²) (``mapping.mass_scale``)."""
    kn = kn_for_contact(ratio * tau_flight, e)
    return kn, kn / (mapping.mass_scale(1.0, dim) * shear_rate**2)


def classify(soft_cost: float, event_cost: float, impractical: bool = False) -> str:
    """The cheaper engine at a point: ``IMPRACTICAL`` when the event-driven run stalled,
    else whichever cost per particle per strain is smaller (ties go to the event-driven
    engine, the exact one)."""
    if impractical:
        return IMPRACTICAL
    if not (soft_cost > 0 and event_cost > 0):
        raise ValueError(f"costs must be > 0: soft {soft_cost}, event-driven {event_cost}")
    return SOFT_CHEAPER if soft_cost < event_cost else EVENT_CHEAPER


# ------------------------------------------------------------------ one grid point
def point_scene(dim: int, fraction: float, e: float, particles: int):
    """The preset of ``dim`` in a cubic (square) box holding ~``particles`` at ``fraction``."""
    from ..scene import load_scene

    if dim not in PRESETS:
        raise BadOption("--dim", dim, "2 or 3")
    import numpy as np

    from ..scene.initial import _close_packed

    grain = math.pi / 4 if dim == 2 else math.pi / 6
    # rounded up: the preset's random placement stops at φ = 0.6 (spheres), never exceeded
    side = math.ceil(1000 * (particles * grain / fraction) ** (1 / dim)) / 1000
    # dense: grow the box until the placement's close-packed lattice (contact distance d)
    # holds the particles (a box between two lattice sizes holds fewer sites than it needs)
    while len(_close_packed(1.0 + 1e-6, np.full(dim, side), np.ones(dim, bool))) < round(
            fraction * side**dim / grain):
        side = round(side + 0.05, 3)
    return load_scene(PRESETS[dim], [
        # half a particle less: the rounded count never exceeds the fraction asked for
        f"box.size=[{', '.join([str(side)] * dim)}]",
        f"particles.solid_fraction={fraction - 0.5 * grain / side**dim}",
        f"contact.restitution={e}", 'measure.statistics=["profiles"]'])


def point_name(dim: int, fraction: float, e: float) -> str:
    return f"{dim}d-frac{fraction:g}-e{e:g}"


def _event_driven(scene, settings: MapSettings, folder: Path) -> dict[str, Any]:
    """Step 1 of the module doc: cost, collision rate, temperature, or why impractical."""
    import numpy as np

    from ..api import run
    from ..errors import EngineError, RunStopped
    from ..theory.kinetic import collision_frequency

    e = scene.contact.restitution
    # run lengths in strain from Enskog's collision rate at T = (γ̇ d)² (a budget only)
    guess = float(collision_frequency(scene.solid_fraction, 1.0, scene.dimension))
    equil, prod = (float(np.clip(x, settings.min_strain, settings.max_strain)) for x in
                   (settings.relaxations / ((1 - e * e) * guess), settings.production / guess))
    scene = scene.model_copy(update={"run": scene.run.model_copy(update={
        "unit": "time", "equilibration": equil, "production": prod,
        "sample_interval": prod / 5})})
    out = folder / "edmd.h5"
    try:
        res = run(scene, engine="edmd", out=out, wall_limit=settings.timeout, progress=False)
    except RunStopped:
        return {"impractical": f"time-out: more than {settings.timeout:g} s for "
                               f"{equil + prod:.3g} strain units"}
    except EngineError as exc:
        return {"impractical": f"failed: {str(exc).splitlines()[0][:200]}"}
    finally:
        shutil.rmtree(out.with_suffix(".edmd"), ignore_errors=True)
    ts = res.timeseries
    t, c = np.asarray(ts["time"], float), np.asarray(ts["collisions"], float)
    start = float(res.attrs["equilibration_end"])
    i0 = int(np.searchsorted(t, start - 1e-12))
    strain, pairs = t[-1] - t[i0], c[-1] - c[i0]
    n = scene.n_particles
    # the production's share of the wall time: an event-driven run's time goes with its
    # collisions (the equilibration's include the initial state's burst)
    wall = float(res.attrs["wall_seconds"]) * float(pairs) / max(float(c[-1]), 1.0)
    omega = 2.0 * float(pairs) / (n * float(strain))
    prof = res.profiles
    weights = np.asarray(prof["solid_fraction"], float)
    temp = float(np.nansum(np.asarray(prof["temperature"], float) * weights)
                 / np.nansum(weights))
    elastic = np.asarray(ts.get("elastic_tc_collisions", np.zeros_like(c)), float)
    tc_share = float(elastic[-1] - elastic[i0]) / max(float(pairs), 1.0)
    row = {"event_cost": wall / (n * float(strain)), "event_wall_seconds": wall,
           "event_strain": float(strain), "event_equilibration": equil,
           "collision_rate": omega, "tau_flight": 1.0 / omega,
           "temperature": temp, "events": int(res.attrs.get("events", 0)),
           "elastic_tc_collisions": int(res.attrs.get("elastic_tc_collisions", 0)),
           "tc_share": tc_share, "impractical": ""}
    if tc_share > TC_IMPRACTICAL:
        row["impractical"] = (f"TC-dominated: the TC model made {100 * tc_share:.0f} % of the "
                              f"production's collisions elastic (collapse; "
                              f"{omega:.3g} collisions per particle per strain)")
    return row


def _soft(scene, kn: float, temperature: float, settings: MapSettings,
          folder: Path) -> dict[str, Any]:
    """Step 3 of the module doc: the soft cost per particle per strain at ``kn``."""
    from ..api import run
    from ..scene.schema import Soft

    tc = mapping.hooke_contact(kn, scene.contact.restitution, 0.5).contact_time
    dt = tc / settings.steps_per_contact
    # a fixed number of steps (the cost per step is what matters): the same timing
    # precision at every point; shorter than ``soft_strain`` is an extrapolation
    strain = min(settings.soft_steps * dt, settings.max_strain)
    velocity = scene.initial.velocity.model_copy(update={"temperature": max(temperature, 1e-3)})
    scene = scene.model_copy(update={
        "soft": Soft(model="hooke", stiffness=kn, steps_per_contact=settings.steps_per_contact),
        "initial": scene.initial.model_copy(update={"velocity": velocity}),
        "run": scene.run.model_copy(update={"unit": "time", "equilibration": 0.0,
                                            "production": strain,
                                            "sample_interval": strain / 4})})
    res = run(scene, engine="lammps", out=folder / "soft.h5", np=1, progress=False)
    shutil.rmtree((folder / "soft.h5").with_suffix(".lammps"), ignore_errors=True)
    wall = float(res.attrs["wall_seconds"])
    return {"soft_cost": wall / (scene.n_particles * strain), "soft_wall_seconds": wall,
            "soft_strain": strain, "soft_steps": round(strain / dt), "dt": dt, "tc": tc,
            "soft_extrapolated": strain < settings.soft_strain * (1 - 1e-9)}


def _measure(scene, settings: MapSettings, folder: Path) -> dict[str, Any]:
    """One measurement of a point (steps 1-3 of the module doc)."""
    e, dim = scene.contact.restitution, scene.dimension
    row = _event_driven(scene, settings, folder)
    if not row["impractical"]:
        row["kn"], row["kstar"] = soft_stiffness(row["tau_flight"], e, settings.ratio, dim,
                                                 scene.shear.rate)
        row |= _soft(scene, row["kn"], row["temperature"], settings, folder)
    for name in ("edmd.h5", "soft.h5"):
        (folder / name).unlink(missing_ok=True)
    return row


def map_point(dim: int, fraction: float, e: float, settings: MapSettings,
              folder: str | os.PathLike) -> dict[str, Any]:
    """Measure one grid point (module doc) ``settings.repeats`` times (seeds 1, 2, …) in
    ``folder`` (scratch; its results files are removed) and return its row: the medians of
    the measured numbers, the cost ratio as the geometric mean of the repeats' ratios with
    its standard error in log10 (``log10_ratio_err``). An impractical repeat ends the point
    as impractical (a stall is not noise)."""
    import numpy as np

    folder = Path(folder) / point_name(dim, fraction, e)
    folder.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    base = point_scene(dim, fraction, e, settings.particles[dim])
    row: dict[str, Any] = {"dim": dim, "fraction": fraction, "restitution": e,
                           "particles": base.n_particles, "box": base.box.size[0],
                           "fraction_actual": base.solid_fraction,
                           "ratio_R": settings.ratio, "impractical": ""}
    repeats: list[dict] = []
    for seed in range(1, settings.repeats + 1):
        scene = base.model_copy(update={"run": base.run.model_copy(update={"seed": seed})})
        repeats.append(_measure(scene, settings, folder))
        if repeats[-1]["impractical"]:
            row |= repeats[-1]
            break
    row["repeats"] = len(repeats)
    if not row["impractical"]:
        for key, value in repeats[0].items():
            row[key] = (float(np.median([r[key] for r in repeats]))
                        if isinstance(value, float) else value)
        logs = np.log10([r["soft_cost"] / r["event_cost"] for r in repeats])
        row["log10_ratio"] = float(logs.mean())
        row["log10_ratio_err"] = (float(logs.std(ddof=1) / math.sqrt(len(logs)))
                                  if len(logs) > 1 else math.nan)
        row["cost_ratio"] = 10 ** row["log10_ratio"]
        # soft cost goes as 1/t_c, so as 1/R: soft contacts would break even at this R
        row["break_even_R"] = settings.ratio * row["cost_ratio"]
        row["cheaper"] = classify(row["cost_ratio"], 1.0)
    else:
        row["cheaper"] = classify(math.nan, math.nan, impractical=True)
    row["seconds"] = time.perf_counter() - started
    return row


# ------------------------------------------------------------------ the whole map
@dataclass
class EngineMap:
    """The map: one row per grid point (``map_point``), the settings and the machine."""

    rows: list[dict]
    settings: MapSettings
    machine: dict
    folder: Path
    written: list[Path] = field(default_factory=list)


def grid(dims: Sequence[int], fractions: Sequence[float] | None = None,
         restitutions: Sequence[float] = RESTITUTIONS) -> list[tuple[int, float, float]]:
    """(dim, fraction, e) of every point; ``fractions`` None: ``FRACTIONS[dim]``."""
    points = []
    for dim in dims:
        if dim not in FRACTIONS:
            raise BadOption("--dim", dim, "2 and/or 3")
        for frac in fractions or FRACTIONS[dim]:
            if not 0 < frac < (0.9 if dim == 2 else 0.7):
                raise BadOption("--fractions", frac, f"solid fractions in (0, "
                                f"{0.9 if dim == 2 else 0.7}) for {dim}D shear")
            for e in restitutions:
                if not 0 < e < 1:
                    raise BadOption("--restitutions", e, "restitutions in (0, 1)")
                points.append((int(dim), float(frac), float(e)))
    return points


def engine_map(dims: Sequence[int] = (2, 3), fractions: Sequence[float] | None = None,
               restitutions: Sequence[float] = RESTITUTIONS,
               settings: MapSettings | None = None, out: str | os.PathLike | None = None,
               workers: int | None = None, figure: bool = True,
               progress: Callable[[str], Any] = print) -> EngineMap:
    """Measure every grid point (``workers`` processes, default: the cores) and write
    ``engine_map.csv``, ``engine_map.json`` (atomically) and ``engine_map.png`` into ``out``
    (default ``results/engine-map/``)."""
    from .execute import _start_method, _worker_start

    settings = settings or MapSettings()
    settings.check()
    workers = workers or os.cpu_count() or 1
    if workers < 1:
        raise BadOption("--workers", workers, "at least 1")
    points = grid(dims, fractions, restitutions)
    folder = Path(out or DEFAULT_OUT)
    scratch = folder / "runs"
    from .map_output import machine_note, write_map

    machine = machine_note()
    rows: list[dict] = []

    def done(row: dict) -> None:
        rows.append(row)
        what = (f"ratio {row['cost_ratio']:.3g}" if "cost_ratio" in row
                else row["impractical"])
        progress(f"  {point_name(row['dim'], row['fraction'], row['restitution'])}: "
                 f"{row['cheaper']} ({what}; {row['seconds']:.1f} s)")

    progress(f"engine map: {len(points)} point(s), {workers} worker(s), R = {settings.ratio:g}")
    if workers == 1:
        for p in points:
            done(map_point(*p, settings, scratch))
    else:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor, as_completed

        context = multiprocessing.get_context(_start_method())
        with ProcessPoolExecutor(workers, mp_context=context, initializer=_worker_start) as pool:
            for future in as_completed([pool.submit(map_point, *p, settings, scratch)
                                        for p in points]):
                done(future.result())
    shutil.rmtree(scratch, ignore_errors=True)
    machine |= machine_note(end=True)
    rows.sort(key=lambda r: (r["dim"], r["fraction"], r["restitution"]))
    result = EngineMap(rows, settings, machine, folder)
    result.written = write_map(result, figure=figure)
    return result
