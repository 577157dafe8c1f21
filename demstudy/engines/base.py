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
