"""Wall-time forecast of a run, from this machine's measured speed (docs/forecast.md).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise a wall speed
or the shear rate sets the time unit τ); durations in τ, wall time in seconds.

The wall time is a sum of measured costs (seconds per unit) times counts of the run:

* soft-contact (time-stepped) engines: ``step`` × steps + ``atom_step`` × atoms × steps +
  ``contact_step`` × atoms × steps × ν (contacts grow with the solid fraction ν; 0.5 for a
  bed under gravity) + ``atom_sample`` × atoms × samples (gathering and binning) +
  ``sample`` × samples (a segment's fixed cost) +
  ``shear_atom_step`` × atoms × steps under Lees–Edwards shear + ``history_atom_step`` ×
  atoms × steps with tangential springs + ``wall_step`` × steps × walls, atoms = particles
  + wall bumps, steps = duration / dt;
* event-driven engines: ``collision`` × collisions (pair and wall) + ``crossing`` × cell
  crossings + ``large_event`` × events × log2(N/1000) above N = 1000 (caches) +
  ``atom_sample`` × N × samples + ``sample`` × samples + ``run`` (the loop's fixed cost:
  its first sample and event queue, ~0.1 s). The two kinds of events
  cost differently (a rough pair collision ~1 µs, a cell crossing ~0.3 µs) and their ratio
  varies from 0.2 (dense) to 30 crossings per collision (dilute, or a fast mean flow). Their
  rates per particle per τ (:mod:`.forecast_events`) come from a finished run of the same
  scene family in the results file's folder, else the pilot's last window, else Enskog's
  collision frequency and the thermal cell crossings at the flow's typical temperature
  (:func:`typical_temperature`); a run counted in collisions (``run.unit = 'collisions'``)
  knows its pair collisions.
* every engine, measured for the scene at plan time (:mod:`.forecast_sampling`):
  ``analysis_sample`` × production samples (its streaming statistics other than the
  profiles, e.g. g(r), and copying kept frames) + ``checkpoint_byte`` × the bytes its
  checkpoints write (the frames kept so far go into every checkpoint).

A forecast from a pilot that stopped on its wall-time cap while the event rate still grew
(a flow accelerating under gravity) is a lower bound (``Forecast.kind``), and says so.

The costs of each engine, contact model and dimension are measured once by a few short
benchmark runs through the same simulation loop (a least-squares fit with non-negative
costs, ``scipy.optimize.nnls``) and cached in ``machine-rates.json`` of demstudy's cache
folder ($XDG_CACHE_HOME/demstudy, default ~/.cache/demstudy) with the CPU model; another
CPU, ``demstudy forecast --measure`` or ``measure_costs(..., remeasure=True)`` measures
again; a run that measures says so on stderr first, a ``--dry-run`` never runs these
benchmarks (``measure=False``; it still times the scene's own analyses on one synthetic
frame and the checkpoint write speed on a temporary file, :func:`scene_costs`). Parallel
workers update the file under a lock (``demstudy.cache.locked``). The forecast covers the
simulation loop (the results file's ``wall_seconds``), not the engine's start-up nor the
pilot.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import platform
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..cache import cache_dir, locked
from ..contact.pilot import PilotResult
from ..io.results import write_atomically
from ..scene import Scene, validate_scene
from .forecast_events import estimated_rates, pilot_rates, reference_rates
from .forecast_sampling import (
    analysis_seconds,
    checkpoint_bytes,
    checkpoint_seconds_per_byte,
    production_samples,
)

__all__ = ["ACCURACY", "Forecast", "cpu_model", "event_counts",
           "forecast_run", "load_rates", "measure_costs", "predict", "rate_key", "rates_path",
           "soft_counts"]

#: the forecast's measured accuracy, printed with every estimate (a lower bound prints why
#: instead): the factor (×) within which it met the actual loop time, and how often. The goal
#: is ±30 %; measured in docs/benchmarks.md ("Wall-time forecast vs actual",
#: benchmarks/bench_forecast.py, 2 vCPUs shared at load 3.9–4.9, 2026-12-02 08:28–08:36 UTC,
#: two sessions of 10 estimated cases × 2 repeats, analysis-heavy and dilute runs included):
#: 19 of 40 within ±30 %, all 40 within ×2.5. On a loaded machine the same run's wall time
#: varies ×1.5–2 between repeats and the measured costs with the load (docs/forecast.md).
#: Re-measured tables update this one place (and docs/forecast.md quotes it).
ACCURACY = {"factor": 2.5, "met": "40 of 40 runs"}
#: event-driven: above this N an event costs ``large_event`` more per doubling of N (the
#: event queue and the cells outgrow the CPU's caches)
LARGE_N = 1000
RATES_FILE = "machine-rates.json"
#: set to "0" to forbid benchmarking inside a run (the test suite does: its timings would
#: measure a loaded machine); forecasts then come from the cache or are skipped
MEASURE_ENV = "DEMSTUDY_MEASURE_RATES"


class NoForecast(ValueError):
    """The run's cost cannot be known before it starts (the reason is the message)."""


class RatesNotMeasured(LookupError):
    """The machine's costs are not cached and measuring them now is forbidden."""

#: the cost model's version: cached costs of another version are measured again
COST_MODEL = 5  # 5: collisions and cell crossings apart


@dataclass(frozen=True)
class Forecast:
    """A wall-time forecast: ``seconds``, what it is computed from (``basis``) and its
    measured accuracy (``factor``: the actual time was within seconds/factor … seconds ×
    factor in the benchmark runs of :data:`ACCURACY`)."""

    seconds: float
    basis: str
    factor: float = ACCURACY["factor"]
    #: why the run will take longer than ``seconds`` ('' : an estimate within ``factor``)
    lower_bound: str = ""
    #: the runs ``factor`` was measured on
    accuracy_met: str = ACCURACY["met"]

    @property
    def kind(self) -> str:
        return "lower bound" if self.lower_bound else "estimate"

    def line(self) -> str:
        if self.lower_bound:
            return (f"forecast: probably more than {_duration(self.seconds)} (likely low: "
                    f"{self.lower_bound}; such forecasts met ×0.7–2.3 of the actual time "
                    f"in the benchmark's 12 short runs, ×1.0–68 in Malik's study runs, "
                    f"docs/forecast.md) from {self.basis}")
        return (f"forecast: {_duration(self.seconds)} (measured accuracy: within "
                f"×{self.factor:g} in {self.accuracy_met}) from {self.basis}")

    def attrs(self) -> dict[str, Any]:
        return {"forecast_seconds": self.seconds, "forecast_basis": self.basis,
                "forecast_factor": self.factor, "forecast_kind": self.kind,
                "forecast_lower_bound": self.lower_bound}


def _duration(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.3g} s"
    if seconds < 7200:
        return f"{seconds / 60:.3g} min"
    return f"{seconds / 3600:.3g} h"


# -- machine costs --------------------------------------------------------------------------
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


def _load() -> float | None:
    """The 1-minute load average (None where the OS has none): a run's costs scale with the
    share of a core it gets on a shared machine (docs/forecast.md, "Accuracy and limits")."""
    try:
        return round(os.getloadavg()[0], 2)
    except OSError:
        return None


def _load_note(key: str) -> str:
    """The load when ``key``'s costs were measured and now, for the basis."""
    then, now = load_rates().get(key, {}).get("load"), _load()
    if then is None or now is None:
        return ""
    return f" (measured at load {then:.2g}, now {now:.2g}, on {os.cpu_count()} cores)"


def rates_path() -> Path:
    return cache_dir() / RATES_FILE


def rate_key(engine: str, dim: int, model: str | None = None) -> str:
    """Cache key of a cost set: "lammps-hooke-2d" (soft contacts), "edmd-3d" (event-driven)."""
    return f"{engine}-{model}-{dim}d" if model else f"{engine}-{dim}d"


def load_rates() -> dict[str, dict]:
    """The cached costs measured on this CPU (empty when none, or measured on another)."""
    try:
        data = json.loads(rates_path().read_text())
    except (OSError, ValueError):
        return {}
    return data.get("rates", {}) if data.get("cpu") == cpu_model() else {}


def _store_rate(key: str, entry: dict) -> None:
    """Add ``entry`` under ``key``: read, modify and write under the file's lock (parallel
    workers measuring other keys keep theirs), the write atomic (readers need no lock)."""
    path = rates_path()
    with locked(path):
        rates = load_rates()
        rates[key] = entry
        text = json.dumps({"units": "wall-clock seconds per unit of each count "
                                    "(docs/forecast.md)",
                           "cpu": cpu_model(), "rates": rates}, indent=1)
        write_atomically(path, text.encode())


def measure_costs(engine: str, dim: int, model: str | None = None, *,
                  remeasure: bool = False, measure: bool = True) -> dict[str, float]:
    """This machine's costs (seconds per count, :func:`soft_counts` / :func:`event_counts`)
    for ``engine``, ``dim`` and contact ``model``: cached, or measured now by benchmark runs
    (~10 s in all, announced on stderr; ``remeasure``: measure again). ``measure`` False (a
    dry run) or ``DEMSTUDY_MEASURE_RATES=0``: never measure, ``RatesNotMeasured`` instead."""
    key = rate_key(engine, dim, model)
    cached = load_rates().get(key)
    if cached is not None and cached.get("model") == COST_MODEL and not remeasure:
        return {k: float(v) for k, v in cached["costs"].items()}
    if not remeasure and (not measure or os.environ.get(MEASURE_ENV, "1") == "0"):
        raise RatesNotMeasured(f"this machine's {key} costs are not measured yet: run "
                               "`demstudy forecast`")
    print(f"measuring this machine's speed once for the forecasts (~10 s; cached in "
          f"{rates_path()})", file=sys.stderr, flush=True)
    costs, what = _benchmark(engine, dim, model)
    _store_rate(key, {"model": COST_MODEL, "costs": costs, "what": what,
                      "measured": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
                      "load": _load()})
    return costs


#: benchmark cases: (N, ν, duration, sample interval, sheared, rough) with times in soft
#: time steps (soft) or τ (event-driven); each count dominates one case
SOFT_CASES = ((1000, 0.1, 30000, 3000, False, False), (1000, 0.45, 30000, 3000, False, False),
              (20, 0.3, 80000, 8000, False, False), (1000, 0.1, 4000, 2, False, False),
              (1000, 0.1, 30000, 3000, True, False), (1000, 0.1, 30000, 3000, False, True),
              (20, 0.3, 80000, 8000, "wall", True), (20, 0.3, 4000, 4, False, False))
EVENT_CASES = ((1000, 0.4, 60.0, 2.0, True, True), (1000, 0.4, 4.0, 0.005, True, True),
               (20, 0.4, 40.0, 0.01, True, True),
               # dilute: cell crossings are most of the events (as in a fast or dilute flow),
               # short and long apart (the loop's fixed cost per run: ~0.1 s measured)
               (1000, 0.01, 100.0, 10.0, False, False), (1000, 0.01, 1000.0, 100.0, False, False),
               (1000, 0.1, 200.0, 20.0, False, False),
               # many particles: events cost more once the event queue and the cells leave
               # the CPU's caches (measured 0.6 µs per cell crossing at N = 24 400, 0.3 at
               # N = 2 744)
               (20000, 0.1, 10.0, 5.0, False, False), (20000, 0.3, 4.0, 2.0, True, True))


def _benchmark_scene(dim: int, n: int, phi: float, duration: float, interval: float,
                     model: str | None, sheared: bool | str = True,
                     rough: bool = True) -> Scene:
    """A gas of ``n`` smooth or rough (β = 0.5) particles (solid fraction ``phi``, T0 = 1),
    sheared or not (Lees–Edwards, γ̇ = 1); soft contacts at δ/d = 0.005 for impacts at 3."""
    phi = min(phi, 0.3) if dim == 3 else phi
    volume = n * (math.pi / 4 if dim == 2 else math.pi / 6) / phi
    length = max(volume ** (1 / dim), 3.2)
    data: dict[str, Any] = {
        "dimension": dim, "box": {"size": [length] * dim}, "particles": {"count": n},
        "contact": {"restitution": 0.9, "tangential": {"model": "beta", "beta": 0.5}
                    if rough else {"model": "smooth"}},
        "initial": {"placement": "random", "velocity": {"temperature": 1.0}},
        "run": {"equilibration": 0.0, "production": duration, "sample_interval": interval,
                "seed": 1},
    }
    if sheared == "wall":  # a chute's fixed costs per step: a rough wall fix and gravity
        data["walls"] = [{"side": "lower", "restitution": 0.9,
                          "tangential": {"model": "beta", "beta": 0.5}}]
        data["gravity"] = {"angle": 20.0}
    elif sheared:
        data["shear"] = {"rate": 1.0}
        data["initial"]["velocity"]["profile"] = "linear"
    if model is not None:
        data["soft"] = {"model": model, "hardness": {"overlap": 0.005, "impact_speed": 3.0}}
    return validate_scene(data, "forecast benchmark")


def _benchmark(engine: str, dim: int, model: str | None) -> tuple[dict[str, float], str]:
    """Run the benchmark cases and fit the costs (non-negative least squares, relative
    residuals: every case weighs the same)."""
    if engine == "lgd":  # lattice runs: node-updates and samples (its own benchmark)
        from ..engines.lgd.forecast import benchmark

        return benchmark()
    import numpy as np
    from scipy.optimize import nnls

    from ..contact.stiffness import contact_setup
    from ..engines import get_backend
    from ..io.results import read_results
    from . import RunOptions, run_scene

    backend = get_backend(engine)
    soft = backend.capabilities.soft_contact
    rows, seconds, what = [], [], []
    for n, phi, duration, interval, sheared, rough in SOFT_CASES if soft else EVENT_CASES:
        scene = _benchmark_scene(dim, n, phi, 1.0, 1.0, model, sheared, rough)
        if soft and not _expresses(backend, scene):
            continue  # LIGGGHTS and Lees–Edwards: its shear cost is never needed
        dt = contact_setup(scene).timestep if soft else 1.0
        scene = _benchmark_scene(dim, n, phi, duration * dt, interval * dt, model, sheared,
                                 rough)
        with tempfile.TemporaryDirectory(prefix="demstudy-benchmark-") as tmp:
            options = RunOptions(out=Path(tmp) / "bench.h5", progress=False, isolate=True,
                                 plan=False)  # no forecast of the benchmark itself
            attrs = read_results(run_scene(scene, backend, options)).attrs
        collisions = int(attrs.get("pair_collisions", 0)) + int(attrs.get("wall_collisions", 0))
        counts = soft_counts(scene, dt) if soft else event_counts(
            scene, collisions, int(attrs.get("events", 0)) - collisions)
        rows.append(counts)
        seconds.append(float(attrs["wall_seconds"]))
        what.append(f"N {n}, ν {scene.solid_fraction:.2g}"
                    f"{', ' + str(sheared).replace('True', 'sheared') if sheared else ''}"
                    f"{', rough' if rough else ''}: {float(attrs['wall_seconds']):.3g} s")
    if not rows:
        raise RatesNotMeasured(f"the {engine} engine runs none of the benchmark cases "
                               f"({model} contacts)")
    names = list(rows[0])
    a = np.array([[r[k] for k in names] for r in rows], float)
    b = np.array(seconds)
    coef, _ = nnls(a / b[:, None], np.ones(len(b)))
    return dict(zip(names, map(float, coef), strict=True)), "; ".join(what)


def _expresses(backend: Any, scene: Scene) -> bool:
    """Whether a soft-contact ``backend`` runs the benchmark ``scene`` (LIGGGHTS refuses
    Lees–Edwards shear and Hertz contacts)."""
    from ..errors import UnsupportedByEngine

    try:
        backend.check(scene, None)
    except UnsupportedByEngine:
        return False
    return True


def runs_model(engine: str, model: str | None, dim: int = 2) -> bool:
    """Whether ``engine`` runs ``model`` contacts at all (a benchmark gas): costs are
    measured only for those."""
    from ..engines import get_backend

    backend = get_backend(engine)
    if not backend.capabilities.soft_contact:
        return True
    return _expresses(backend, _benchmark_scene(dim, 20, 0.3, 1.0, 1.0, model, False, False))


# -- forecasts ------------------------------------------------------------------------------
def _atoms(scene: Scene) -> int:
    from ..effects.bumps import bump_rows

    return scene.n_particles + sum(len(row.centres) for row in bump_rows(scene))


def _contact_density(scene: Scene) -> float:
    """ν for the contact cost: the solid fraction, or 0.5 (a bed) under gravity, where the
    box's own fraction (an open top) says little."""
    return 0.5 if scene.gravity is not None else min(scene.solid_fraction, 0.6)


def _samples(scene: Scene) -> int:
    run = scene.run
    return max(1, round((run.equilibration + run.production) / run.sample_interval))


def soft_counts(scene: Scene, timestep: float) -> dict[str, float]:
    """The counts a time-stepped run's costs multiply (see the module docstring)."""
    atoms = _atoms(scene)
    steps = math.ceil((scene.run.equilibration + scene.run.production) / timestep - 1e-9)
    return {"step": steps, "atom_step": atoms * steps,
            "contact_step": atoms * steps * _contact_density(scene),
            "atom_sample": atoms * _samples(scene),
            "sample": _samples(scene),  # a segment's fixed cost: run command, observables
            # Lees–Edwards: the deforming box and its fast particles rebuild neighbour lists
            "shear_atom_step": atoms * steps if scene.shear is not None else 0,
            # tangential springs: contact histories (fix neigh/history)
            "history_atom_step": atoms * steps if _history(scene) else 0,
            # a wall fix's fixed cost per step (and gravity's, which comes with walls)
            "wall_step": steps * len(scene.walls)}


def _history(scene: Scene) -> bool:
    """Whether the soft contacts carry tangential histories (anything but smooth)."""
    rules = [scene.contact.tangential, *(w.tangential for w in scene.walls)]
    return any(r.model != "smooth" and getattr(r, "beta", 0.0) != -1.0 for r in rules)


def event_counts(scene: Scene, collisions: float, crossings: float) -> dict[str, float]:
    """The counts an event-driven run's costs multiply (see the module docstring):
    ``collisions`` pair and wall collisions, ``crossings`` the other events (cell
    crossings)."""
    samples = _samples(scene)
    large = max(0.0, math.log2(scene.n_particles / LARGE_N))
    return {"collision": collisions, "crossing": crossings,
            "large_event": (collisions + crossings) * large,
            "atom_sample": scene.n_particles * samples, "sample": samples, "run": 1}


def predict(costs: dict[str, float], counts: dict[str, float]) -> float:
    """Σ cost × count (seconds); a count without a measured cost is an error."""
    missing = set(counts) - set(costs)
    if missing:
        raise ValueError(f"no measured cost for {sorted(missing)} (have {sorted(costs)}): "
                         "run `demstudy forecast --measure`")
    return float(sum(costs[k] * v for k, v in counts.items()))


def expected_events(scene: Scene, pilot: PilotResult | None = None,
                    references: Path | None = None, out: Path | None = None,
                    engine: str = "edmd") -> tuple[float, float, str, str]:
    """An event-driven run's collisions and cell crossings, where the rates come from
    (:mod:`.forecast_events`: a finished run of the scene's family in the folder
    ``references`` other than ``out``, the pilot's last window, or Enskog), and why the
    count is only a lower bound ('' when it is not)."""
    n, duration = scene.n_particles, scene.run.equilibration + scene.run.production
    rates = None
    if references is not None and Path(references).is_dir():
        rates = reference_rates(scene, Path(references), engine, exclude=out)
    if rates is None:
        rates = pilot_rates(pilot, accelerates(scene),
                            scene.run.equilibration + scene.run.production)
    if rates is None:
        rates = estimated_rates(scene, typical_temperature(scene))
        if accelerates(scene):
            rates = dataclasses.replace(rates, lower_bound=(
                "gravity drives the flow along a periodic axis and nothing measured how "
                "fast it gets: Enskog at the typical temperature counts its start"))
    if scene.run.unit == "collisions":  # duration: pair collisions per particle
        collisions = duration * n
        crossings = collisions * rates.crossing / max(rates.collision, 1e-300)
        return collisions, crossings, (f"{collisions:.4g} pair collisions × "
                                       f"{rates.crossing / max(rates.collision, 1e-300):.3g} "
                                       f"cell crossings each ({rates.source})"), \
            rates.lower_bound
    collisions, crossings = rates.counts(n, duration)
    return collisions, crossings, f"{rates.source}; × {n} × {duration:g} τ", rates.lower_bound


def accelerates(scene: Scene) -> bool:
    """Gravity has a component along a periodic axis: the flow speeds up from rest (a
    channel or a chute), its event rate unknown before it is steady."""
    if scene.gravity is None:
        return False
    periodic = [a != 1 or scene.y_periodic for a in range(scene.dimension)]
    return any(p and abs(g) > 1e-9 for p, g in zip(periodic, scene.gravity_vector,
                                                     strict=False))


def typical_temperature(scene: Scene) -> float:
    """The granular temperature a flow keeps, for the Enskog collision rate (an estimate
    within a factor of a few, i.e. within ~2 on the rate ∝ √T): the largest of the initial
    temperature, (γ̇ d)² under shear, (ΔU d / gap)² between moving walls, and g d under
    gravity; never below 1e-6."""
    temps = [scene.initial.velocity.temperature]
    if scene.shear is not None:
        temps.append(scene.shear.rate**2)
    if len(scene.walls) == 2:
        gap = scene.box.size[1]
        speeds = [w.velocity for w in scene.walls]
        temps.append(((max(speeds) - min(speeds)) / gap) ** 2)
    if scene.gravity is not None:
        temps.append(scene.gravity.magnitude)
    return max(max(temps), 1e-6)


def forecast_run(scene: Scene, backend: Any, timestep: float | None = None,
                 pilot: PilotResult | None = None,
                 costs: dict[str, float] | None = None, *, measure: bool = True,
                 options: Any = None) -> Forecast:
    """The forecast of ``scene`` in ``backend`` (a backend class): time-stepped engines need
    the ``timestep``; ``costs`` (seconds per count) override the machine's measured ones
    (measured now if not cached, unless ``measure`` is False: ``RatesNotMeasured``).
    ``options`` (``RunOptions``): the kept frames, the checkpoints and the results file,
    whose folder may hold a finished run of the same scene family."""
    if backend.name == "lgd":
        return _lattice_forecast(scene, costs, measure)
    model = scene.soft.model if backend.capabilities.soft_contact else None
    key = rate_key(backend.name, scene.dimension, model)
    where = key if costs is None else "given costs"
    if costs is None:
        costs = measure_costs(backend.name, scene.dimension, model, measure=measure)
    lower_bound = ""
    if backend.capabilities.soft_contact:
        if timestep is None:
            raise ValueError("a time-stepped engine's forecast needs its time step")
        counts = soft_counts(scene, timestep)
        basis = (f"{_atoms(scene)} atoms × {counts['step']} steps (dt = {timestep:.4g}), "
                 f"{_samples(scene)} samples, ν = {_contact_density(scene):.3g}")
    else:
        out = Path(options.out) if options is not None and options.out else None
        collisions, crossings, source, lower_bound = expected_events(
            scene, pilot, out.parent if out is not None else None, out, backend.name)
        counts = event_counts(scene, collisions, crossings)
        basis = (f"{collisions:.4g} collisions and {crossings:.4g} cell crossings ({source}), "
                 f"{_samples(scene)} samples")
    extra_costs, extra_counts, extra_basis = scene_costs(scene, options)
    seconds = predict(costs, counts) + predict(extra_costs, extra_counts)
    if where == key:
        where += _load_note(key)
    return Forecast(seconds, f"{basis}{extra_basis}; costs of {where}",
                    lower_bound=lower_bound)


def _lattice_forecast(scene: Scene, costs: dict[str, float] | None,
                      measure: bool) -> Forecast:
    """A lattice run's forecast (:mod:`demstudy.engines.lgd.forecast`): its node-updates and
    samples at this machine's measured costs; ``NoForecast`` for a run counted in time."""
    from ..engines.lgd import forecast as lattice

    count = lattice.counts(scene)
    if count is None:
        raise NoForecast("a lattice run counted in time takes as many steps as its peak "
                         "speed dictates (unknown in advance): count it in steps "
                         "(run.unit = \"steps\") for a forecast")
    key = rate_key("lgd", scene.dimension)
    where = key if costs is None else "given costs"
    if costs is None:
        costs = measure_costs("lgd", scene.dimension, measure=measure)
        where += _load_note(key)
    return Forecast(lattice.seconds(costs, count),
                    f"{lattice.forecast_basis(scene)}; costs of {where}",
                    factor=lattice.ACCURACY["factor"], accuracy_met=lattice.ACCURACY["met"])


def scene_costs(scene: Scene, options: Any = None
                ) -> tuple[dict[str, float], dict[str, float], str]:
    """The costs measured for ``scene`` itself now (:mod:`.forecast_sampling`): its
    streaming analyses and kept frames per production sample, its checkpoints' bytes."""
    from ..analysis.registry import STATISTICS
    from ..engines.backend import LOG_CAPACITY

    statistics = scene.measure.statistics
    frames_needed = any(STATISTICS[s].source == "frames" for s in statistics)
    keep = getattr(options, "keep_frames", None)
    keep_frames = frames_needed or (scene.measure.keep_frames if keep is None else keep)
    interval = getattr(options, "checkpoint_interval", None) or scene.run.checkpoint_interval
    log_every = int(any(STATISTICS[s].log_every for s in statistics))
    costs, counts, parts = {}, {}, []
    per_sample, timed = analysis_seconds(scene, keep_frames)
    if per_sample > 0:
        costs["analysis_sample"] = per_sample
        counts["analysis_sample"] = production_samples(scene)
        parts.append(f"analyses {per_sample * 1e3:.3g} ms per sample ({', '.join(timed)})")
    n_checkpoints, written = checkpoint_bytes(scene, keep_frames, interval, log_every,
                                              LOG_CAPACITY)
    if n_checkpoints:
        out = getattr(options, "out", None)
        costs["checkpoint_byte"] = checkpoint_seconds_per_byte(
            Path(out).resolve().parent if out else None)
        counts["checkpoint_byte"] = written
        parts.append(f"{n_checkpoints} checkpoints of {written / 1e6:.3g} MB in all")
    return costs, counts, "".join(f", {p}" for p in parts)
