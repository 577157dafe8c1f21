"""The one simulation loop over every engine backend, its run options, checkpoints and the
child process that isolates a run.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts. :func:`run_scene` is
what the CLI and :func:`demstudy.run` call: refuse what cannot run, then run the scene in a
child process (``isolate``, or MPI with ``np > 1``) or in this one, after its plan
(:func:`plan_run`: the pilot for automatic soft contacts and the wall-time forecast, printed
at the start and stored in the results file).
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path
from typing import Any

from ..scene import Scene
from .checkpoint import CHECKPOINT, saved_pilot
from .loop import Simulation
from .options import RunOptions, check_run, check_run_options, work_folder
from .plan import RunPlan, plan_run
from .schedule import interrupts_honoured
from .state import RunState

__all__ = ["RunOptions", "RunPlan", "RunState", "Simulation", "check_run",
           "check_run_options", "plan_run", "run_scene", "work_folder"]


def run_scene(scene: Scene, engine: str | Any, options: RunOptions) -> Path:
    """Run ``scene`` in ``engine`` (a registered name or a backend class) and return the
    results file's path. Everything the engine cannot do is refused before it starts
    (``UnsupportedByEngine``); ``options.isolate`` or ``options.np > 1`` runs it in a child
    process, where a crash becomes ``EngineError``. Ctrl-C is honoured throughout, also
    where this process inherited SIGINT ignored (:func:`interrupts_honoured`)."""
    with interrupts_honoured():
        return _run_scene(scene, engine, options)


def _run_scene(scene: Scene, engine: str | Any, options: RunOptions) -> Path:
    from ..engines import get_backend
    from .isolation import in_worker, launch_child

    backend = get_backend(engine) if isinstance(engine, str) else engine
    if options.resume and options.pilot is None and not in_worker():
        # continue with the checkpoint's own pilot (its k_n and dt), not a new measurement
        saved = saved_pilot(work_folder(Path(options.out).resolve(), backend.name) / CHECKPOINT)
        options = dataclasses.replace(options, pilot=saved)
    if options.plan and not in_worker():
        check_run(backend, scene, options)  # refused before the pilot runs
        plan = plan_run(scene, backend, options)
        options = dataclasses.replace(options, plan=False, pilot=plan.pilot,
                                      forecast=plan.forecast)
        if plan.setup is not None:
            print(f"{backend.name}: {plan.setup.note()}", file=sys.stderr)
            if plan.setup.basis in ("stiffness", "hardness"):  # a pilot's k_n is never soft
                from ..contact.stiffness import overlap_warning

                warning = overlap_warning(scene)
                if warning:
                    print(f"warning: {warning}", file=sys.stderr)
        if plan.forecast is not None:
            print(plan.forecast.line(), file=sys.stderr, flush=True)
        if plan.left is not None:
            print(plan.left.line(), file=sys.stderr, flush=True)
    if (options.isolate or options.np > 1) and not in_worker():
        check_run(backend, scene, options)
        return launch_child(backend, scene, options)
    return Simulation(scene, backend, options).run()
