"""The engine protocol: every engine runs a scene and writes one results file.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol

from ..scene import Scene


class EngineError(RuntimeError):
    """An engine failed; the message says what the engine reported and where."""


class RunStopped(EngineError):
    """The run stopped on request (Ctrl-C, wall-clock limit) after writing a checkpoint."""


class RunRefused(EngineError):
    """The engine refused the scene or the options (reported by an engine's child process)."""


@dataclass
class RunOptions:
    out: Path
    np: int = 1
    dump: Path | None = None
    resume: bool = False
    progress: bool = True
    keep_frames: bool | None = None  # None: the scene's measure.keep_frames
    checkpoint_interval: float | None = None  # None: the scene's run.checkpoint_interval
    isolate: bool = False  # run the engine in a child process (crashes become EngineError)
    wall_limit: float | None = None  # seconds: checkpoint and stop when exceeded (resumable)
    extra: dict = field(default_factory=dict)


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


def check_run_options(engine: str, options: RunOptions) -> None:
    """Refuse run options no engine can use, before any engine starts (``UnsupportedByEngine``
    naming the option, the value and what is allowed); the output must not be the engine's
    work folder (``work_folder``)."""
    import math  # noqa: PLC0415

    from ..decks.base import UnsupportedByEngine  # noqa: PLC0415

    if options.np < 1:
        raise UnsupportedByEngine(engine, "--np", options.np, "at least 1 rank is needed")
    limit = options.wall_limit
    if limit is not None and not (math.isfinite(limit) and limit >= 0.0):
        raise UnsupportedByEngine(engine, "--wall-limit", limit,
                                  "a finite number of seconds >= 0 is allowed")
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


class Engine(Protocol):
    name: str

    def run(self, scene: Scene, options: RunOptions) -> Path:
        """Run the scene; return the path of the results file."""
        ...


def get_engine(name: str) -> Engine:
    if name == "lammps":
        from .lammps import LammpsEngine

        return LammpsEngine()
    if name == "edmd":
        from .edmd import EdmdEngine

        return EdmdEngine()
    raise ValueError(f"engine = {name!r}: unknown engine (allowed: lammps, edmd)")
