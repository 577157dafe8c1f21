"""Run options (what a run is asked besides its scene) and the checks every engine shares.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..analysis.registry import STATISTICS, engine_problems
from ..errors import EngineError, UnsupportedByEngine


@dataclass
class RunOptions:
    """``out``: results file; ``np``: MPI ranks; ``dump``: the engine's own trajectory dump;
    ``resume``: continue from the work folder's checkpoint; ``keep_frames``: store every
    production frame (None: the scene's ``measure.keep_frames``); ``checkpoint_interval``
    (None: the scene's); ``isolate``: run the engine in a child process (a crash becomes
    ``EngineError``); ``wall_limit``: seconds, then checkpoint and stop; ``extra``: the
    engine's own options (``Backend.options``, e.g. ``tc`` of the event-driven engine);
    ``plan``: run the pilot and the forecast before the run (:func:`plan_run`; False for
    benchmarks); ``pilot`` / ``forecast``: their results, set by the plan (the soft-contact
    engine takes its automatic stiffness from ``pilot``; the results file stores
    ``forecast``)."""

    out: Path
    np: int = 1
    dump: Path | None = None
    resume: bool = False
    progress: bool = True
    keep_frames: bool | None = None
    checkpoint_interval: float | None = None
    isolate: bool = False
    wall_limit: float | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    plan: bool = True
    pilot: Any = None  # demstudy.contact.pilot.PilotResult
    forecast: Any = None  # demstudy.simulation.forecast.Forecast


def work_folder(out: Path, engine: str) -> Path:
    """The engine's work folder of results file ``out``: its name with the suffix
    ``.<engine>`` (checkpoints, decks, logs)."""
    return Path(out).with_suffix(f".{engine}")


def frames_on_resume(requested: bool | None, kept: bool) -> bool:
    """Whether a resumed run keeps frames: as the run started (``kept``); a ``--keep-frames``
    that says otherwise (``requested``) is refused, as frames cover the whole run or none."""
    if requested is not None and requested != kept:
        raise EngineError(f"--resume: the run started {'with' if kept else 'without'} "
                          "--keep-frames; frames are kept for the whole run or not at all")
    return kept


def check_run_options(backend: Any, options: RunOptions) -> None:
    """Refuse run options ``backend`` (a backend class) cannot use, before any engine starts
    (``UnsupportedByEngine`` naming the option, the value and what is allowed): ranks, dump,
    wall-clock limit, the output's name, and the engine's own options."""
    engine, can = backend.name, backend.capabilities
    if options.np < 1:
        raise UnsupportedByEngine(engine, "--np", options.np, "at least 1 rank is needed")
    if options.np > 1 and not can.mpi:
        raise UnsupportedByEngine(engine, "--np", options.np, "the engine is serial")
    if options.dump is not None and not can.dump:
        raise UnsupportedByEngine(engine, "--dump", str(options.dump),
                                  "this engine writes no dump of its own; use --keep-frames")
    limit = options.wall_limit
    if limit is not None and not (math.isfinite(limit) and limit >= 0.0):
        raise UnsupportedByEngine(engine, "--wall-limit", limit,
                                  "a finite number of seconds >= 0 is allowed")
    for name, value in options.extra.items():
        option = backend.options.get(name)
        if option is None:
            from ..engines import backend_names, get_backend

            owners = [get_backend(e) for e in backend_names() if name in get_backend(e).options]
            where = "; ".join(f"an {b.kind} option (--engine {b.name})" for b in owners)
            raise UnsupportedByEngine(engine, f"--{name.replace('_', '-')}", value,
                                      "not an option of this engine" +
                                      (f": it is {where}" if where else ""))
        reason = option.check(value)
        if reason:
            raise UnsupportedByEngine(engine, f"--{name.replace('_', '-')}", value, reason)
    out = Path(options.out)
    if out.is_dir():
        raise UnsupportedByEngine(engine, "--out", str(out),
                                  "a results file name is needed; this is a folder")
    if work_folder(out, engine) == out:
        raise UnsupportedByEngine(engine, "--out", str(out),
                                  f"a name ending in .{engine} is the engine's work folder "
                                  "(use .h5)")
    blocking = next((p for p in out.resolve().parents if p.exists() and not p.is_dir()), None)
    if blocking is not None:
        raise UnsupportedByEngine(engine, "--out", str(out), f"{blocking} is a file, not a folder")


def keep_frames_refused(scene: Any, options: RunOptions) -> str | None:
    """The statistic that needs frames when the options say not to keep them (None: no
    conflict)."""
    if options.keep_frames is not False:
        return None
    return next((s for s in scene.measure.statistics if STATISTICS[s].source == "frames"),
                None)


def check_run(backend: Any, scene: Any, options: RunOptions) -> None:
    """Everything refused before any engine starts: the run options, the effects and the
    statistics the engine cannot supply (``UnsupportedByEngine``)."""
    check_run_options(backend, options)
    if scene.run.unit == "collisions" and not backend.capabilities.collision_count:
        raise UnsupportedByEngine(backend.name, "run.unit", scene.run.unit,
                                  "this engine counts no collisions: give times")
    if scene.run.unit == "steps" and not backend.capabilities.step_count:
        raise UnsupportedByEngine(backend.name, "run.unit", scene.run.unit,
                                  "this engine has no whole steps of its own (lattice scenes, "
                                  "--engine lgd): give times")
    needs_frames = keep_frames_refused(scene, options)
    if needs_frames:
        raise UnsupportedByEngine(backend.name, "keep_frames", False, f"{needs_frames!r} in "
                                  "measure.statistics needs the stored frames")
    backend.check(scene, options)
    for field_name, value, reason in engine_problems(scene, backend.capabilities):
        raise UnsupportedByEngine(backend.name, field_name, value, reason)
    log_every = int(options.extra.get("log_every", 1))
    for name in scene.measure.statistics:
        if STATISTICS[name].log_every and log_every != 1:
            raise UnsupportedByEngine(backend.name, "--log-every", log_every,
                                      f"{name!r} needs every collision logged (1)")
