"""The forecast of a whole cost ladder before any run starts (``demstudy cost`` prints it
first; ``--dry-run`` prints it and stops).

Each run's forecast is ``demstudy.simulation.plan_run(..., dry_run=True)`` (this machine's
measured speed, docs/forecast.md): one per setting (replicas and the reference's t_c ladder
share it: the forecast does not depend on the seed or t_c). Runs whose results file is
already there are listed as reused, not forecast; a stopped run (its checkpoint in the work
folder: the sweep continues it) counts what is left of it at its own pace
(``demstudy.simulation.progress``). The ladder's wall time on W workers is
the reference phase and then the soft phase, each scheduled longest first onto the least
busy worker (as ``execute`` starts them). The machine's speed is measured here, once, in the
parent process (``measure_machine``), so that pool workers find it cached and never
benchmark a machine loaded by the other workers.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts; wall times in seconds.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

from .execute import Task
from .plan import RunSpec

__all__ = ["PHASES", "LadderForecast", "ladder_forecast", "makespan", "measure_machine"]

#: a ladder's phases in the order they run ("tc-ladder?": the reference's t_c ladder when
#: it is not known yet whether it will run: forecast, not counted in the totals)
MAYBE = "tc-ladder?"
PHASES = ("reference", "tc-ladder", MAYBE, "soft")


def measure_machine(dim: int, models: Sequence[str],
                    engines: Sequence[str] = ("lammps",)) -> str | None:
    """Measure (or find cached) this machine's costs for the ladder's engines: each soft
    engine with each contact model and the event-driven engine, in ``dim`` dimensions.
    Returns why not (None when all are known): measuring forbidden
    (``DEMSTUDY_MEASURE_RATES=0``) or failed."""
    from ..simulation.forecast import RatesNotMeasured, measure_costs, runs_model
    from ..simulation.plan import FORECAST_ENGINES

    try:
        for engine in (e for e in engines if e in FORECAST_ENGINES):  # others: no benchmark
            for model in models:
                if runs_model(engine, model, dim):  # LIGGGHTS: no Hertz
                    measure_costs(engine, dim, model)
        measure_costs("edmd", dim)
    except RatesNotMeasured as exc:
        return str(exc)
    except Exception as exc:  # noqa: BLE001 - a forecast never stops a ladder
        return f"benchmark failed: {type(exc).__name__}: {exc}"
    return None


def makespan(seconds: Sequence[float], workers: int) -> float:
    """Wall time of ``seconds`` worth of runs on ``workers``, longest first onto the least
    busy worker (LPT, as ``execute`` orders them)."""
    loads = [0.0] * max(1, min(workers, len(seconds)))
    for s in sorted(seconds, reverse=True):
        heapq.heapreplace(loads, loads[0] + s)
    return max(loads, default=0.0)


@dataclass
class LadderForecast:
    """Per run: (name, phase, seconds or NaN, line), phase one of ``PHASES`` or "reused";
    the totals of what would run."""

    runs: list[tuple[str, str, float, str]] = field(default_factory=list)
    workers: int | None = None  # None: a Dask cluster
    unmeasured: str | None = None  # why there is no forecast

    def seconds(self, phase: str) -> list[float]:
        return [s for _, p, s, _ in self.runs if p == phase]

    @property
    def total(self) -> float:
        """Sum of the forecasts of the runs to make (a conditional t_c ladder excluded)."""
        return math.fsum(s for p in PHASES if p != MAYBE for s in self.seconds(p))

    @property
    def wall(self) -> float:
        """The ladder's forecast wall time on ``workers``: its phases one after the other."""
        w = self.workers or 1
        return math.fsum(makespan(self.seconds(p), w) for p in PHASES if p != MAYBE)

    def lines(self) -> list[str]:
        out = ["forecast of the ladder (this machine's measured speed):"]
        for name, phase, _, line in self.runs:
            tag = " (only if the reference's TC model acts)" if phase == MAYBE else ""
            out.append(f"  {name:28s} {line}{tag}")
        todo = [r for r in self.runs if r[1] not in ("reused", MAYBE)]
        maybe = len(self.seconds(MAYBE))
        if self.unmeasured:
            out.append(f"  no forecast: {self.unmeasured}")
        elif todo:
            where = (f"about {_duration(self.wall)} on {self.workers} worker(s)"
                     if self.workers else "on the Dask cluster's workers")
            out.append(f"  in all: {_duration(self.total)} of runs, {where}")
            extra = math.fsum(self.seconds(MAYBE))
            if extra > 0:
                out.append(f"  plus up to {_duration(extra)} of runs if the reference's t_c "
                           "is laddered")
        reused = len(self.runs) - len(todo) - maybe
        out.append(f"  {len(todo)} run(s) to make"
                   + (f" (+{maybe} if the reference's t_c is laddered)" if maybe else "")
                   + f", {reused} reused")
        return out


def _duration(seconds: float) -> str:
    from ..simulation.forecast import _duration as duration

    return duration(seconds) if math.isfinite(seconds) else "unknown"


def _key(spec: RunSpec) -> RunSpec:
    """Runs with one forecast: replicas (seed) and the reference's t_c ladder alike."""
    return replace(spec, replica=None, tc=None if not spec.soft else spec.tc)


def ladder_forecast(phases: dict[str, tuple[list[Task], list[Task]]], workers: int | None,
                    unmeasured: str | None) -> LadderForecast:
    """The forecast of ``phases`` (``PHASES`` → (to run, done)).
    ``unmeasured``: why the machine's speed is unknown (then no run is forecast)."""
    from ..engines import get_backend
    from ..scene import scene_to_toml
    from ..simulation import RunOptions, plan_run, work_folder
    from ..simulation.checkpoint import stopped_run
    from ..simulation.progress import time_left

    result = LadderForecast(workers=workers, unmeasured=unmeasured)
    cache: dict[RunSpec, tuple[float, str]] = {}
    for phase, (todo, done) in phases.items():
        for task in done:
            result.runs.append((task.spec.name, "reused", 0.0, "reused (its file is done)"))
        for task in todo:
            key = _key(task.spec)
            left = (time_left(work_folder(Path(task.path), task.spec.engine),
                              scene_to_toml(task.scene()))  # the run's, not the base's
                    if stopped_run(Path(task.path), task.spec.engine) else None)
            if left is not None:  # a stopped run of the sweep: what is left, at its own pace
                result.runs.append((task.spec.name, phase, *left))
                continue
            if unmeasured is not None:
                cache.setdefault(key, (math.nan, "no forecast"))
            elif key not in cache:
                scene = Task(key, task.scene_toml, task.path).scene()
                plan = plan_run(scene, get_backend(task.spec.engine),
                                RunOptions(out=Path(task.path)), dry_run=True)
                fc = plan.forecast
                cache[key] = ((fc.seconds, fc.line().removeprefix("forecast: "))
                              if fc is not None else (math.nan, "no forecast"))
            seconds, line = cache[key]
            result.runs.append((task.spec.name, phase, seconds, line))
    return result
