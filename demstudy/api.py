"""The public Python API: ``load_scene``, ``run``, ``load`` (see docs/api.md).

Dimensionless particle units everywhere: d = 1, m = 1, g = 1 when gravity acts (otherwise a
wall speed or the shear rate sets the time unit).

    import demstudy as ds
    scene = ds.load_scene("campbell1982/couette-noslip", run={"production": 50})
    res = ds.run(scene, engine="edmd")        # a Results object; the results file is written
    res.profiles["solid_fraction"], res.profiles["solid_fraction_err"], res.attrs["units"]
    res.analyze("vdf", "gr")                  # stored in the file too
    ds.load(res.path).plot("profiles")
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Any

from .io.results import Results, read_results
from .scene import Scene, load_scene

__all__ = ["load", "run"]


def run(scene: Scene | str | os.PathLike, engine: str | type | None = None,
        out: str | os.PathLike | None = None, *, isolate: bool = True, np: int = 1,
        resume: bool = False, keep_frames: bool | None = None,
        wall_limit: float | None = None, checkpoint_interval: float | None = None,
        dump: str | os.PathLike | None = None, progress: bool | None = None,
        dry_run: bool = False, **engine_options: Any) -> Results | dict[str, Any]:
    """Run ``scene`` (a Scene, a scene file or a preset name) in ``engine`` (default: the
    CLI's default, ``demstudy.engines.DEFAULT_ENGINE``; see ``demstudy.engines.backend_names``)
    (or a backend class) and return its :class:`Results`, also written to ``out`` (default
    ``results/<scene name>-<engine>.h5``).

    ``isolate`` (default True) runs the engine in a child process, so that a crash in
    compiled code becomes ``EngineError`` instead of killing the interpreter; ``np`` > 1
    runs on MPI ranks. ``resume`` continues from the checkpoint a stopped run left;
    ``wall_limit`` (seconds) checkpoints and stops (``RunStopped``); ``keep_frames`` stores
    every production frame (default: the scene's ``measure.keep_frames``); ``progress``
    shows a progress bar (default: when stderr is a terminal). Engine options go as keywords,
    e.g. ``tc=1e-4`` for the event-driven engine. Everything the engine cannot do is
    refused before it starts (``UnsupportedByEngine``).

    ``dry_run``: run nothing and write nothing; return the run's plan as a dict: engine, N,
    the soft contacts (``kn``, ``timestep``, ``contact_time``, ``steps_per_contact``,
    ``stiffness_basis``), the pilot's impact speeds and collision rate, and the wall-time
    forecast (``forecast_seconds``, ``forecast_basis``, ``forecast_factor``; without this
    machine's measured speed, which a dry run never measures, ``forecast`` says why there is
    none), as ``demstudy run --dry-run``; with ``resume``, what is left of the stopped run at
    its own pace (``left_seconds``, ``left``, ``intervals_done``, ``intervals_total``:
    ``demstudy.simulation.progress``)."""
    from .engines import DEFAULT_ENGINE, get_backend
    from .simulation import RunOptions, check_run, plan_run, run_scene

    if not isinstance(scene, Scene):
        scene = load_scene(scene)
    backend = get_backend(engine or DEFAULT_ENGINE) if not isinstance(engine, type) else engine
    if out is None:
        out = Path("results") / f"{scene.meta.name}-{backend.name}.h5"
    options = RunOptions(out=Path(out), np=np, dump=Path(dump) if dump else None,
                         resume=resume, keep_frames=keep_frames,
                         checkpoint_interval=checkpoint_interval, isolate=isolate,
                         wall_limit=wall_limit, extra=engine_options,
                         progress=sys.stderr.isatty() if progress is None else progress)
    if dry_run:
        check_run(backend, scene, options)
        return plan_run(scene, backend, options, dry_run=True).as_dict()
    return read_results(run_scene(scene, backend, options))


def load(path: str | os.PathLike) -> Results:
    """The :class:`Results` of a results file."""
    return read_results(path)
