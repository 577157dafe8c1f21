"""What happens before a run starts: the pilot (automatic soft-contact settings) and the
wall-time forecast; ``demstudy run --dry-run`` shows them and stops there.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise a wall speed
or the shear rate sets the time unit τ). The pilot runs (or comes from its cache) when a
soft-contact engine must choose k_n itself (no ``soft.stiffness``, no ``soft.hardness``), and
for the event-driven engine's forecast; never for a resumed run's forecast alone. A resumed
run's plan also says how far it got and what is left at its own pace (simulation.progress).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..contact.pilot import PILOT_SECONDS, PilotResult, run_pilot
from ..contact.stiffness import ContactSetup, contact_setup
from ..errors import RunAborted, RunStopped
from ..scene import Scene, scene_to_toml
from .forecast import Forecast, NoForecast, RatesNotMeasured, forecast_run
from .options import RunOptions, work_folder
from .progress import Progress, read_progress

__all__ = ["FORECAST_ENGINES", "RunPlan", "needs_pilot", "plan_run"]

#: an event-driven run forecast (from Enskog) to last longer than this many seconds gets a
#: pilot to measure its collision rate (at most a tenth of the forecast)
PILOT_WORTH = 20.0

#: engines with a benchmark (``forecast.measure_rate``): the others get no forecast
FORECAST_ENGINES = ("lammps", "edmd", "liggghts", "lgd")


@dataclass(frozen=True)
class RunPlan:
    """A run's settings before it starts: the engine, N, the soft contacts (time-stepped
    engines), the pilot and the forecast (None when there is none)."""

    engine: str
    n_particles: int
    setup: ContactSetup | None
    pilot: PilotResult | None
    forecast: Forecast | None
    no_forecast: str = ""  # why there is none, when the run's cost is unknowable in advance
    #: a resumed run: how far it got and what is left at its own pace
    left: Progress | None = None

    def as_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"engine": self.engine, "n_particles": self.n_particles}
        if self.setup is not None:
            s = self.setup
            out.update(kn=s.kn, timestep=s.timestep, contact_time=s.pair.contact_time,
                       steps_per_contact=s.steps_per_contact, stiffness_basis=s.basis,
                       design_speed=s.speed)
        if self.pilot is not None:
            out.update(pilot_usable=self.pilot.usable, pilot_summary=self.pilot.summary(),
                       pair_impact_speeds=dict(self.pilot.pair),
                       wall_impact_speeds=dict(self.pilot.wall),
                       initial_floor_speed=self.pilot.floor,
                       collision_rate=self.pilot.rate, tau_flight=self.pilot.tau_flight)
        if self.forecast is not None:
            out.update(self.forecast.attrs())
        else:
            out["forecast"] = self._no_forecast()
        if self.left is not None:
            out.update(self.left.attrs())
        return out

    def _no_forecast(self) -> str:
        if self.no_forecast:
            return f"none: {self.no_forecast}"
        if self.engine in FORECAST_ENGINES:
            return "none (this machine's speed is not measured yet: demstudy forecast)"
        return f"none for the {self.engine} engine"

    def describe(self) -> str:
        lines = [f"engine: {self.engine}, {self.n_particles} particles"]
        if self.setup is not None:
            s = self.setup
            lines.append(f"contacts: {s.pair.model}, k_n = {s.kn:.6g}, dt = {s.timestep:.6g}, "
                         f"t_c = {s.pair.contact_time:.6g}, {s.steps_per_contact:.4g} steps "
                         f"per contact, stiffness basis: {s.basis}")
            if math.isfinite(s.speed):
                lines.append(f"design impact speed: {s.speed:.4g}")
        if self.pilot is not None:
            lines.append(f"pilot: {self.pilot.summary()}")
        lines.append(self.forecast.line() if self.forecast is not None
                     else f"forecast: {self._no_forecast()}")
        if self.left is not None:
            lines.append(self.left.line())
        return "\n".join(lines)


def needs_pilot(scene: Scene, backend: Any, dry_run: bool = False) -> bool:
    """A soft-contact engine choosing k_n itself; the event-driven engine's forecast on
    ``--dry-run`` (a run forecasts its events from the Enskog rate, and runs a pilot only
    when that forecast exceeds ``PILOT_WORTH``: a pilot of up to seconds would multiply the
    fixed cost of short event-driven runs)."""
    if backend.capabilities.soft_contact:
        return scene.soft.stiffness is None and scene.soft.hardness is None
    return dry_run and backend.name == "edmd" and scene.run.unit == "time"


def plan_run(scene: Scene, backend: Any, options: RunOptions, *,
             costs: dict[str, float] | None = None, dry_run: bool = False) -> RunPlan:
    """The pilot (cached), the soft contacts and the forecast of ``scene`` in ``backend``
    (a backend class); ``costs`` override the machine's measured ones
    (:func:`demstudy.simulation.forecast.measure_costs`; a run measures them once when not
    cached, announcing it on stderr; a ``dry_run`` never measures: no forecast then). A
    forecast that cannot be made (the benchmark failed) is a warning, never a refused run."""
    pilot = options.pilot
    if pilot is None and needs_pilot(scene, backend, dry_run):
        pilot = run_pilot(scene)
    setup = None
    if backend.capabilities.soft_contact:
        setup = contact_setup(scene, backend.name, pilot)
    forecast, no_forecast = None, ""
    if backend.name in FORECAST_ENGINES:
        try:
            forecast = forecast_run(scene, backend, setup.timestep if setup else None,
                                    pilot, costs, measure=not dry_run, options=options)
        except RatesNotMeasured:
            pass  # said by describe(): no forecast
        except NoForecast as exc:
            no_forecast = str(exc)
        except (RunStopped, RunAborted):  # Ctrl-C stopped a benchmark run: never a warning
            raise _interrupted(backend.name) from None
        except Exception as exc:  # noqa: BLE001 - a forecast never stops a run
            warnings.warn(f"no forecast: {type(exc).__name__}: {exc}", stacklevel=2)
    if (forecast is not None and pilot is None and not backend.capabilities.soft_contact
            and backend.name == "edmd" and scene.run.unit == "time"
            and "finished run" not in forecast.basis
            and (forecast.seconds > PILOT_WORTH or forecast.lower_bound)):
        # a long event-driven run: a pilot of ≤ 10 % of it measures the real collision rate;
        # a flow that gravity accelerates: Enskog knows nothing of its speed, a longer pilot
        # (at least 1 s, yet never more than a tenth of a longer run's own forecast)
        floor = 1.0 if forecast.lower_bound else 0.0
        seconds = min(PILOT_SECONDS, max(floor, 0.1 * forecast.seconds))
        pilot = run_pilot(scene, seconds=seconds)
        try:
            forecast = forecast_run(scene, backend, None, pilot, costs, measure=not dry_run,
                                    options=options)
        except (RunStopped, RunAborted):
            raise _interrupted(backend.name) from None
        except Exception as exc:  # noqa: BLE001 - a forecast never stops a run
            warnings.warn(f"no forecast: {type(exc).__name__}: {exc}", stacklevel=2)
    left = None
    if options.resume:  # the whole run's forecast, and what is left of it at its own pace
        left = read_progress(work_folder(Path(options.out).resolve(), backend.name),
                             scene_to_toml(scene))
    return RunPlan(backend.name, scene.n_particles, setup, pilot, forecast, no_forecast, left)


def _interrupted(engine: str) -> RunAborted:
    """Ctrl-C while the machine's speed was measured (benchmark runs in child processes,
    which stop on it): the run does not start, rather than start without its forecast."""
    return RunAborted(f"aborted by Ctrl-C while measuring this machine's speed for the "
                      f"forecast: the {engine} run did not start (nothing to resume)")
