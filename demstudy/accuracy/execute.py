"""Running the ladder: one ``ds.run`` per task into its own results file, in a local process
pool or on a Dask cluster, skipping every task whose file is already there and whole.

Resumability rests on the results files: ``write_results`` writes atomically (a file is
whole or absent), and a file counts as done only if ``read_results`` reads it and its
``scene_toml`` is the scene this task would run (a file from other settings is redone). A run
stopped with a checkpoint (Ctrl-C, a wall-clock limit) continues from it on the next call.
Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.
"""

from __future__ import annotations

import math
import multiprocessing
import time
from collections.abc import Callable, Iterable, Mapping
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .plan import RunSpec, scene_for, scene_key


@dataclass(frozen=True)
class Task:
    """A run to make: its settings, the ladder's base scene (as TOML, so that it travels to
    any worker) and the results file."""

    spec: RunSpec
    scene_toml: str
    path: Path

    def scene(self):
        from ..scene import parse_scene_text, validate_scene

        base = validate_scene(parse_scene_text(self.scene_toml, str(self.path)), str(self.path))
        return scene_for(base, self.spec)


def wanted_tc(engine: str, options: Mapping[str, Any] | None,
              dimension: int | None) -> float | None:
    """The TC time a run of ``engine`` with ``options`` in a ``dimension``-D scene is made at:
    the ``tc`` option, else the event-driven engine's default for that dimension
    (``engines.edmd.core.default_tc``); None for engines without a TC model, and for the
    default of an unknown dimension."""
    if engine != "edmd":
        return None
    if "tc" in (options or {}):
        return float(options["tc"])
    from ..engines.edmd.core import default_tc

    return None if dimension is None else default_tc(dimension)


def _dimension(attrs: Mapping[str, Any]) -> int | None:
    """The dimension of the scene a results file's root ``attrs`` hold (None: unreadable)."""
    import tomllib

    text = attrs.get("scene_toml")
    if isinstance(text, bytes):
        text = text.decode("utf-8", "replace")
    try:
        return int(tomllib.loads(str(text))["dimension"])
    except (KeyError, TypeError, ValueError, tomllib.TOMLDecodeError):
        return None


def option_mismatch(attrs: Mapping[str, Any], engine: str,
                    options: Mapping[str, Any] | None) -> str | None:
    """Why a finished run (its results file's root ``attrs``) is not the run of ``engine``
    with ``options``, for the engine options that change the physics (None: it is): the
    event-driven engine's t_c (the option, else the engine's default for the scene's
    dimension). A file that does not record it (older than the attribute) cannot tell, and
    passes; so does one whose scene cannot be read when the default is asked for."""
    wanted = wanted_tc(engine, options, _dimension(attrs))
    if wanted is None or attrs.get("tc") is None:
        return None
    made = float(attrs["tc"])
    if math.isclose(made, wanted, rel_tol=1e-9):
        return None
    return f"made at t_c = {made:g}, the run asks for t_c = {wanted:g}"


def is_done(path: Path, expected_scene_toml: str, engine: str = "",
            options: Mapping[str, Any] | None = None) -> bool:
    """Whether ``path`` holds the finished run of that scene (readable, same scene) and, when
    ``engine`` is given, of its physics-changing ``options`` (:func:`option_mismatch`)."""
    from ..io.results import read_results

    if not path.is_file():
        return False
    try:
        attrs = read_results(path, skip=("frames", "collisions")).attrs
    except Exception:  # noqa: BLE001 - any unreadable file (truncated, not HDF5) is redone
        return False
    return (attrs.get("scene_toml") == expected_scene_toml and "wall_seconds" in attrs
            and option_mismatch(attrs, engine, options) is None)


def run_task(task: Task) -> dict[str, Any]:
    """Make one run (in a pool worker or a Dask worker); the engine runs in a child process
    (``isolate``) on one rank. Returns what the ladder records of the execution."""
    from ..api import run
    from ..scene import scene_to_toml
    from ..simulation.checkpoint import stopped_run

    options = task.spec.options()
    scene = task.scene()
    if stopped_run(Path(task.path), task.spec.engine, scene_to_toml(scene)):
        options["resume"] = True  # a stopped run of the sweep continues from its checkpoint
    started = time.perf_counter()
    res = run(scene, engine=task.spec.engine, out=task.path, isolate=True, np=1,
              progress=False, **options)
    return {"name": task.spec.name, "path": str(res.path),
            "task_seconds": time.perf_counter() - started,
            "wall_seconds": float(res.attrs.get("wall_seconds", float("nan")))}


def _start_method() -> str:
    """fork (cheap: no new interpreter, no imports) while this process is one thread without
    the LAMMPS runtime loaded, as the command line is; spawn otherwise (a fork must not
    inherit threads' locks or an initialised MPI)."""
    import sys
    import threading

    safe = (sys.platform == "linux" and threading.active_count() == 1
            and "lammps" not in sys.modules)
    return "fork" if safe else "spawn"


def _worker_start() -> None:
    """Pool worker start: take tqdm's multiprocessing lock now, so that the engine's forked
    child inherits it instead of creating a semaphore of its own that its hard exit would
    leave registered (a 'leaked semaphore' warning at shutdown)."""
    from tqdm import tqdm

    tqdm.get_lock()


def pending(tasks: Iterable[Task]) -> tuple[list[Task], list[Task]]:
    """(to run, already done)."""
    todo, done = [], []
    for task in tasks:
        (done if is_done(task.path, scene_key(task.scene())) else todo).append(task)
    return todo, done


def execute(tasks: list[Task], workers: int = 1, dask: Any = None,
            on_done: Callable[[dict], None] | None = None) -> list[dict]:
    """Run ``tasks`` (all of them: filter with :func:`pending` first) and return their
    records in completion order. ``dask``: a scheduler address or a ``distributed.Client``;
    else ``workers`` local processes (1: in this process, one after the other). A failed
    run raises after the others finished (their files are kept for the rerun)."""
    if not tasks:
        return []
    # longest first (LPT scheduling): the last run to start is a short one, so the workers
    # finish together instead of one waiting for the stiffest run started last
    tasks = sorted(tasks, key=lambda t: t.spec.relative_cost, reverse=True)
    if dask is not None:
        return _on_dask(tasks, dask, on_done)
    records, failures = [], []

    def finished(record: dict) -> None:
        records.append(record)
        if on_done is not None:
            on_done(record)

    if workers <= 1:
        for task in tasks:
            try:
                finished(run_task(task))
            except Exception as exc:  # noqa: BLE001 - reported together below
                failures.append(_failure(task.spec.name, exc))
    else:
        context = multiprocessing.get_context(_start_method())
        with ProcessPoolExecutor(max_workers=workers, mp_context=context,
                                 initializer=_worker_start) as pool:
            futures = {pool.submit(run_task, t): t for t in tasks}
            for future in as_completed(futures):
                try:
                    finished(future.result())
                except Exception as exc:  # noqa: BLE001
                    failures.append(_failure(futures[future].spec.name, exc))
    _raise_failures(failures)
    return records


def _on_dask(tasks: list[Task], dask: Any, on_done) -> list[dict]:
    from distributed import Client
    from distributed import as_completed as dask_completed

    client = dask if isinstance(dask, Client) else Client(dask)
    try:
        futures = {client.submit(run_task, t, pure=False, key=f"demstudy-cost-{t.spec.name}-"
                                 f"{time.time_ns()}"): t for t in tasks}
        records, failures = [], []
        for future in dask_completed(list(futures)):
            try:
                record = future.result()
            except Exception as exc:  # noqa: BLE001
                failures.append(_failure(futures[future].spec.name, exc))
                continue
            records.append(record)
            if on_done is not None:
                on_done(record)
    finally:
        if client is not dask:
            client.close()
    _raise_failures(failures)
    return records


def _failure(name: str, exc: BaseException) -> str:
    """One line of the failures list. A run stopped with a checkpoint says so without the
    single run's "--resume" advice: a sweep's command takes no --resume, it resumes itself
    (:func:`run_task`)."""
    from ..errors import RESUME_ADVICE

    return f"{name}: {str(exc).removesuffix(RESUME_ADVICE)}"


def _raise_failures(failures: list[str]) -> None:
    if failures:
        from ..errors import EngineError

        # shared by the cost ladder and the studies: the message names neither
        raise EngineError("runs failed (finished ones are kept; the same command again "
                          "resumes the others from their checkpoints):\n  "
                          + "\n  ".join(failures))
