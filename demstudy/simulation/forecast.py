"""Wall-time forecast of a run, from this machine's measured speed (docs/forecast.md).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise a wall speed
or the shear rate sets the time unit τ); durations in τ, wall time in seconds.

* Soft-contact (time-stepped) engines: atoms (particles + wall bumps) × steps (duration / dt)
  ÷ the machine's atom-steps per second for the engine, contact model and dimension.
* Event-driven engines: events ÷ the machine's events per second for the dimension; the
  events come from the pilot's measured events per particle per τ (× N × duration), or, with
  no pilot, from the Enskog collision frequency at T = (reference speed)² with
  ``EVENTS_PER_COLLISION`` events (collisions and cell crossings) per pair collision; a run
  counted in collisions (``run.unit = 'collisions'``) knows its pair collisions exactly.

Machine rates are measured once by a short benchmark run of the engine (through the same
simulation loop, so its per-sample overhead is in the rate) and cached in
``machine-rates.json`` of demstudy's cache folder ($XDG_CACHE_HOME/demstudy, default
~/.cache/demstudy) with the CPU model; a different CPU, ``demstudy forecast --measure`` or
``measure_rate(..., remeasure=True)`` measures again. The forecast covers the simulation
loop (the results file's ``wall_seconds``), not the engine's start-up nor the pilot.
"""

from __future__ import annotations

import json
import math
import os
import platform
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..contact.pilot import PilotResult, cache_dir
from ..scene import Scene, validate_scene

__all__ = ["EVENTS_PER_COLLISION", "UNCERTAINTY", "Forecast", "cpu_model", "forecast_run",
           "load_rates", "measure_rate", "rate_key", "rates_path"]

#: the forecast's stated relative uncertainty (the goal: within ±30 % of the actual time)
UNCERTAINTY = 0.3
#: event-driven events per pair collision without a pilot (collisions + cell crossings)
EVENTS_PER_COLLISION = 3.0
RATES_FILE = "machine-rates.json"


@dataclass(frozen=True)
class Forecast:
    """A wall-time forecast: ``seconds`` ± ``uncertainty`` (relative), and what it is
    computed from (``basis``)."""

    seconds: float
    basis: str
    uncertainty: float = UNCERTAINTY

    def line(self) -> str:
        return (f"forecast: {_duration(self.seconds)} (±{self.uncertainty:.0%}) from "
                f"{self.basis}").replace("%", " %")

    def attrs(self) -> dict[str, Any]:
        return {"forecast_seconds": self.seconds, "forecast_basis": self.basis,
                "forecast_uncertainty": self.uncertainty}


def _duration(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.3g} s"
    if seconds < 7200:
        return f"{seconds / 60:.3g} min"
    return f"{seconds / 3600:.3g} h"


# -- machine rates --------------------------------------------------------------------------
def cpu_model() -> str:
    """The CPU's model name (/proc/cpuinfo on Linux) and its logical core count."""
    name = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                name = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{name} ({os.cpu_count()} logical cores)"


def rates_path() -> Path:
    return cache_dir() / RATES_FILE


def rate_key(engine: str, dim: int, model: str | None = None) -> str:
    """Cache key of a rate: "lammps-hooke-2d" (soft contacts), "edmd-3d" (event-driven)."""
    return f"{engine}-{model}-{dim}d" if model else f"{engine}-{dim}d"


def load_rates() -> dict[str, dict]:
    """The cached rates measured on this CPU (empty when none, or measured on another)."""
    try:
        data = json.loads(rates_path().read_text())
    except (OSError, ValueError):
        return {}
    return data.get("rates", {}) if data.get("cpu") == cpu_model() else {}


def _store_rate(key: str, entry: dict) -> None:
    rates = load_rates()
    rates[key] = entry
    path = rates_path()
    path.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps({"units": "atom-steps or events per wall-clock second",
                       "cpu": cpu_model(), "rates": rates}, indent=1)
    with tempfile.NamedTemporaryFile("w", dir=path.parent, delete=False, suffix=".tmp") as f:
        f.write(text)
    os.replace(f.name, path)


def measure_rate(engine: str, dim: int, model: str | None = None, *,
                 remeasure: bool = False) -> float:
    """This machine's atom-steps (soft) or events (event-driven) per second for ``engine``,
    ``dim`` and contact ``model``: cached, or measured now by a benchmark run of a few
    seconds (``remeasure``: measure again)."""
    key = rate_key(engine, dim, model)
    cached = load_rates().get(key)
    if cached is not None and not remeasure:
        return float(cached["rate"])
    rate, what = _benchmark(engine, dim, model)
    _store_rate(key, {"rate": rate, "what": what,
                      "measured": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())})
    return rate


def _benchmark_scene(engine: str, dim: int, model: str | None) -> Scene:
    """A sheared gas of 1000 rough particles (Lees–Edwards, γ̇ = 1, ν = 0.4 in 2D, 0.25 in 3D)
    sampled every ~900 soft steps (~27 000 steps, a few seconds) or every τ (event-driven, 100 τ:
    ~1.5 million events)."""
    n, phi = 1000, 0.4 if dim == 2 else 0.25
    volume = n * (math.pi / 4 if dim == 2 else math.pi / 6) / phi
    length = volume ** (1 / dim)
    data: dict[str, Any] = {
        "dimension": dim, "box": {"size": [length] * dim}, "particles": {"count": n},
        "contact": {"restitution": 0.9, "tangential": {"model": "beta", "beta": 0.5}},
        "shear": {"rate": 1.0},
        "initial": {"placement": "random", "velocity": {"profile": "linear",
                                                          "temperature": 1.0}},
        "run": {"equilibration": 0.0, "production": 100.0, "sample_interval": 1.0, "seed": 1},
    }
    if model is not None:  # ~3000 steps at k* = 1e4-ish stiffness
        data["soft"] = {"model": model, "hardness": {"overlap": 0.005, "impact_speed": 3.0}}
        data["run"].update(production=3.0, sample_interval=0.1)
    return validate_scene(data, "forecast benchmark")


def _benchmark(engine: str, dim: int, model: str | None) -> tuple[float, str]:
    from ..engines import get_backend
    from ..io.results import read_results
    from . import RunOptions, run_scene

    scene = _benchmark_scene(engine, dim, model)
    backend = get_backend(engine)
    with tempfile.TemporaryDirectory(prefix="demstudy-benchmark-") as tmp:
        options = RunOptions(out=Path(tmp) / "bench.h5", progress=False, isolate=True,
                             plan=False)  # no forecast of the benchmark itself
        attrs = read_results(run_scene(scene, backend, options)).attrs
    seconds = float(attrs["wall_seconds"])
    if backend.capabilities.time_step:
        steps = round(scene.run.production / float(attrs["timestep"]))
        work = scene.n_particles * steps
        return work / seconds, f"{scene.n_particles} atoms × {steps} steps in {seconds:.3g} s"
    events = int(attrs["events"])
    return events / seconds, f"{events} events in {seconds:.3g} s"


# -- forecasts ------------------------------------------------------------------------------
def _atoms(scene: Scene) -> int:
    from ..effects.bumps import bump_rows

    return scene.n_particles + sum(len(row.centres) for row in bump_rows(scene))


def soft_forecast(scene: Scene, timestep: float, rate: float, key: str = "") -> Forecast:
    """Time-stepped run: atoms × steps ÷ ``rate`` (atom-steps per second)."""
    atoms = _atoms(scene)
    steps = math.ceil((scene.run.equilibration + scene.run.production) / timestep - 1e-9)
    return Forecast(atoms * steps / rate, f"{atoms} atoms × {steps} steps (dt = "
                    f"{timestep:.4g}) at {rate:.3g} atom-steps/s ({key or 'given rate'})")


def event_forecast(scene: Scene, rate: float, pilot: PilotResult | None = None,
                   key: str = "") -> Forecast:
    """Event-driven run: events ÷ ``rate`` (events per second); the events from the pilot,
    the collision count of ``run.unit = 'collisions'``, or Enskog."""
    n, duration = scene.n_particles, scene.run.equilibration + scene.run.production
    per_collision = EVENTS_PER_COLLISION
    if pilot is not None and pilot.usable and pilot.pair_collisions > 0:
        per_collision = pilot.events / pilot.pair_collisions
    if scene.run.unit == "collisions":
        events = duration * n * per_collision
        source = f"{duration * n:.4g} pair collisions × {per_collision:.3g} events each"
    elif pilot is not None and pilot.usable and pilot.simulated_time > 0:
        per = pilot.events / (pilot.n_particles * pilot.simulated_time)
        events = per * n * duration
        source = (f"the pilot's {per:.3g} events per particle per τ × {n} × {duration:g} τ")
    else:
        from ..contact.stiffness import reference_speed
        from ..theory import collision_frequency

        temperature = reference_speed(scene) ** 2
        omega = float(collision_frequency(min(scene.solid_fraction, 0.6), temperature,
                                          scene.dimension))
        events = omega * n * duration / 2 * per_collision
        source = (f"Enskog ω = {omega:.3g} at T = {temperature:.3g} × {n} × {duration:g} τ "
                  f"/ 2 × {per_collision:g} events per collision")
    return Forecast(events / rate, f"{source} at {rate:.3g} events/s "
                    f"({key or 'given rate'})")


def forecast_run(scene: Scene, backend: Any, timestep: float | None = None,
                 pilot: PilotResult | None = None, rate: float | None = None) -> Forecast:
    """The forecast of ``scene`` in ``backend`` (a backend class): time-stepped engines need
    the ``timestep``; ``rate`` (atom-steps or events per second) overrides the machine's
    measured one (measured now if not cached)."""
    model = scene.soft.model if backend.capabilities.time_step else None
    key = rate_key(backend.name, scene.dimension, model)
    if rate is None:
        rate = measure_rate(backend.name, scene.dimension, model)
    if backend.capabilities.time_step:
        if timestep is None:
            raise ValueError("a time-stepped engine's forecast needs its time step")
        return soft_forecast(scene, timestep, rate, key)
    return event_forecast(scene, rate, pilot, key)
