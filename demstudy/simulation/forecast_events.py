"""The events an event-driven run will process, per particle per time unit, split by kind:
collisions (pair and wall) and cell crossings, whose costs differ (docs/forecast.md).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise a wall speed
or the shear rate sets the time unit τ); rates in events per particle per τ.

Where the rates come from, best first:

1. a finished run of the same scene family in the results file's folder
   (:func:`reference_rates`): the flow's own rates over a whole run, transient included;
2. the pilot: what it counted over its whole run, then its last window's rates
   (:func:`pilot_rates`); in a flow that gravity accelerates along a
   periodic axis (a channel, a chute), or when the pilot stopped on its wall-time cap while
   its event rate still rose, the pilot has seen only the flow's start and the forecast
   from it is a lower bound (``lower_bound`` says why);
3. Enskog's collision frequency and the thermal speed's cell crossings at the flow's typical
   temperature (:func:`estimated_rates`).

Why cell crossings matter: in a dilute flow they are most of the events (94–98 % in
Malik's φ = 0.01 Poiseuille runs, 14–39 per collision), and a mean flow crosses cells at |u|/w
per particle without colliding more.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from ..scene import Scene

__all__ = ["EventRates", "cell_widths", "crossing_rate", "drive", "estimated_rates",
           "family_distance", "mean_flow_speed", "pilot_rates", "reference_rates",
           "same_family", "similar_fraction"]

#: a run whose pilot's event rate grew by more than this fraction over its last windows has
#: not reached its steady rate (as ``pilot.SETTLED``)
STILL_RISING = 0.25
#: a finished run is of the same family when its solid fraction is within this fraction
FAMILY_PHI = 0.1


@dataclass(frozen=True)
class EventRates:
    """Collisions (pair + wall) and cell crossings per particle per τ, where they come from
    (``source``), and why a forecast from them is only a lower bound ('' when it is not)."""

    collision: float
    crossing: float
    source: str
    lower_bound: str = ""
    #: what was counted from t = 0 to ``seen`` τ (the pilot's whole run): collisions and
    #: crossings per particle; the rates hold after it
    seen: float = 0.0
    seen_collisions: float = 0.0
    seen_crossings: float = 0.0

    def counts(self, n: int, duration: float) -> tuple[float, float]:
        """Collisions and crossings of ``n`` particles over ``duration`` τ from t = 0: what
        was seen up to ``seen`` (scaled down for a shorter run), the rates after it."""
        if self.seen <= 0:
            return self.collision * n * duration, self.crossing * n * duration
        if duration <= self.seen:
            part = duration / self.seen
            return self.seen_collisions * n * part, self.seen_crossings * n * part
        rest = duration - self.seen
        return ((self.seen_collisions + self.collision * rest) * n,
                (self.seen_crossings + self.crossing * rest) * n)


def cell_widths(scene: Scene) -> list[float]:
    """The event-driven engine's cell widths per axis (native/src/edmd/edmd.cpp,
    ``setup_grid``): at least the largest diameter, at least 3 cells per periodic axis, at
    most ~8 cells per particle (the axis with the most cells coarsened first by 1.1)."""
    dmax = 1.0 + scene.particles.diameter_spread / 2
    lengths = list(scene.box.size[:scene.dimension])
    periodic = [a != 1 or scene.y_periodic for a in range(scene.dimension)]
    cells = [max(1.0, math.floor(length / dmax)) for length in lengths]
    least = [3.0 if p else 1.0 for p in periodic]
    cap = max(8 * scene.n_particles, 64)
    for _ in range(100000):
        most = max((a for a in range(len(cells)) if cells[a] > least[a]),
                   key=lambda a: cells[a], default=None)
        if math.prod(cells) <= cap or most is None:
            break
        cells[most] = max(least[most], math.floor(cells[most] / 1.1))
    return [length / c for length, c in zip(lengths, cells, strict=True)]


def crossing_rate(scene: Scene, temperature: float, mean_speed: float = 0.0) -> float:
    """Cell crossings per particle per τ of a Maxwellian gas at ``temperature`` (mean |v_a|
    = √(2T/π) per axis) moving at ``mean_speed`` along x: Σ_a mean |v_a| / w_a."""
    thermal = math.sqrt(2 * temperature / math.pi)
    widths = cell_widths(scene)
    return sum((math.hypot(thermal, mean_speed) if a == 0 else thermal) / w
               for a, w in enumerate(widths))


def mean_flow_speed(scene: Scene) -> float:
    """The mean |u_x| of an imposed linear profile: γ̇ L_y / 4 under Lees–Edwards shear,
    |ΔU| / 4 between walls moving apart (0 otherwise: a flow gravity drives is unknown)."""
    if scene.shear is not None:
        return abs(scene.shear.rate) * scene.box.size[1] / 4
    if len(scene.walls) == 2:
        speeds = [w.velocity for w in scene.walls]
        return abs(max(speeds) - min(speeds)) / 4
    return 0.0


def estimated_rates(scene: Scene, temperature: float) -> EventRates:
    """Enskog's pair collisions (ω/2 per particle: each involves two) plus the cell
    crossings at ``temperature`` and the imposed mean flow (:func:`mean_flow_speed`)."""
    from ..theory import collision_frequency

    omega = float(collision_frequency(min(scene.solid_fraction, 0.6), temperature,
                                      scene.dimension))
    crossings = crossing_rate(scene, temperature, mean_flow_speed(scene))
    return EventRates(omega / 2, crossings,
                      f"Enskog ω = {omega:.3g} and {crossings:.3g} cell crossings per "
                      f"particle per τ at T = {temperature:.3g}")


def pilot_rates(pilot, accelerating: bool = False,
                duration: float | None = None) -> EventRates | None:
    """The rates of the pilot's last window (None for a pilot without window counts: an
    older cache entry). A lower bound when the flow is ``accelerating`` (gravity along a
    periodic axis: it speeds up over 10²–10³ τ, a pilot of seconds sees its start; measured
    in Malik's runs: 3–12× the pilot's events per particle per τ once the flow is steady)
    or when the pilot stopped on its wall-time cap while its event rate still grew; never
    when the pilot covered the whole run (``duration``, in τ): it then saw every event."""
    if not (pilot is not None and pilot.usable and pilot.window_time > 0):
        return None
    per = pilot.n_particles * pilot.window_time
    collisions = pilot.window_collisions / per
    crossings = pilot.window_crossings / per
    why = ""
    rising = pilot.rate_growth > 1 + STILL_RISING
    whole_run = duration is not None and pilot.simulated_time >= duration * (1 - 1e-9)
    if whole_run:
        pass  # the pilot was the run: its counts are the run's
    elif accelerating:
        why = (f"gravity accelerates the flow along a periodic axis and the pilot saw its "
               f"first {pilot.simulated_time:.3g} τ (event rate ×{pilot.rate_growth:.3g} "
               "over its windows): a steady flow has more events; a finished run of the "
               "scene's family next to the results file scales instead")
    elif "cap" in pilot.stopped_by and rising:
        why = (f"the pilot stopped on its wall-time cap at t = {pilot.simulated_time:.3g} τ "
               f"while its event rate still grew (×{pilot.rate_growth:.3g} over its "
               "windows)")
    n = pilot.n_particles
    seen = pilot.total_collisions / n, (pilot.events - pilot.total_collisions) / n
    if pilot.total_collisions <= 0:  # without the pilot's totals: its last window's rates
        return EventRates(collisions, crossings,
                          f"the pilot's last window: {collisions:.3g} collisions and "
                          f"{crossings:.3g} cell crossings per particle per τ", why)
    return EventRates(collisions, crossings,
                      f"the pilot's first {pilot.simulated_time:.3g} τ ({seen[0]:.3g} "
                      f"collisions and {seen[1]:.3g} crossings per particle), then its last "
                      f"window's {collisions:.3g} and {crossings:.3g} per particle per τ",
                      why, pilot.simulated_time, *seen)


# -- finished runs of the same scene family -------------------------------------------------
def drive(s: Scene) -> tuple:
    """What drives a run's flow, and so sets its speed and event rates: the dimension, the
    walls (side, kind: a bumpy wall adds collisions, and speed), gravity (vector, magnitude
    included), the shear rate and whether y is periodic. Runs with the same drive differ in
    N, lengths, φ, e and β only (:func:`same_family`; the study forecast's calibration)."""
    g = s.gravity_vector
    return (s.dimension, tuple((w.side, w.kind, round(w.velocity, 6)) for w in s.walls),
            None if g is None else tuple(round(x, 6) for x in g),
            None if s.shear is None else round(s.shear.rate, 6), s.y_periodic)


def similar_fraction(scene: Scene, other: Scene) -> bool:
    """Solid fractions within ``FAMILY_PHI`` of each other."""
    return abs(other.solid_fraction / scene.solid_fraction - 1) <= FAMILY_PHI


def same_family(scene: Scene, other: Scene) -> bool:
    """Whether a finished run of ``other`` tells the event rates of ``scene``: the same
    :func:`drive`, the same wall gap (box size along y) and a solid fraction within
    ``FAMILY_PHI``; N, the periodic lengths, e and β may differ."""
    return (drive(scene) == drive(other)
            and round(scene.box.size[1], 6) == round(other.box.size[1], 6)
            and similar_fraction(scene, other))


def family_distance(scene: Scene, other: Scene) -> float:
    """How far a finished run of the family is: N and the run's length (by ratio: a short
    run's rates are more of its start-up's), then e and β (the collision rate of a channel
    grows as e → 1: ×1.8 from e = 0.8 to 0.99 at φ = 0.01)."""
    def beta(s: Scene) -> float:
        return float(getattr(s.contact.tangential, "beta", -1.0))

    def length(s: Scene) -> float:
        return s.run.equilibration + s.run.production
    return (abs(math.log(other.n_particles / scene.n_particles))
            + abs(math.log(length(other) / length(scene)))
            + abs(other.contact.restitution - scene.contact.restitution)
            + abs(beta(other) - beta(scene)) / 4)


def reference_rates(scene: Scene, folder: Path, engine: str = "edmd",
                    exclude: Path | None = None) -> EventRates | None:
    """The event rates of the finished ``engine`` run of ``scene``'s family in ``folder``
    (results files' root attributes) closest in N, e and β (:func:`family_distance`), the cell
    crossings scaled by the cells' widths (Σ 1/w, :func:`cell_widths`); None when there is
    none."""
    import h5py

    from ..scene import parse_scene_text, validate_scene

    best = None
    for path in sorted(Path(folder).glob("*.h5")):
        if exclude is not None and path.resolve() == Path(exclude).resolve():
            continue
        try:
            with h5py.File(path, "r") as f:
                a = dict(f.attrs)
        except OSError:
            continue
        if a.get("engine") != engine or "events" not in a or "scene_toml" not in a:
            continue
        try:
            other = validate_scene(parse_scene_text(str(a["scene_toml"])), path.name)
        except Exception:  # noqa: BLE001 - a file of an older format is no reference
            continue
        if other.run.unit != "time" or not same_family(scene, other):
            continue
        distance = family_distance(scene, other)
        if best is None or distance < best[0]:
            best = (distance, path, other, a)
    if best is None:
        return None
    _d, path, other, a = best
    per = other.n_particles * (other.run.equilibration + other.run.production)
    collisions = (float(a["pair_collisions"]) + float(a.get("wall_collisions", 0))) / per
    widths = sum(1 / w for w in cell_widths(scene)) / sum(1 / w for w in cell_widths(other))
    crossings = (float(a["events"]) - collisions * per) / per * widths
    return EventRates(collisions, crossings,
                      f"the finished run {path.name} (N = {other.n_particles}): "
                      f"{collisions:.3g} collisions and {crossings:.3g} cell crossings per "
                      "particle per τ")
