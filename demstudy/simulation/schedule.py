"""When a run samples, checkpoints and stops: the schedule in sample intervals, and stop
requests (Ctrl-C, a wall-clock limit).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts; with ``run.unit =
'collisions'`` the interval counts pair collisions per particle.
"""

from __future__ import annotations

import math
import signal
import threading
import time
from dataclasses import dataclass

from ..scene import Scene
from .options import RunOptions

__all__ = ["Schedule", "StopInInterval", "StopRequest"]


class StopRequest:
    """Ctrl-C (SIGINT, main thread only) or a wall-clock limit asks the run loop to stop at
    the end of its current segment; ``with StopRequest(limit) as stop: … stop.reason``."""

    def __init__(self, wall_limit: float | None):
        self.wall_limit = wall_limit
        self.reason: str | None = None
        self.started = time.perf_counter()
        self._previous = None

    def request(self, _signum=None, _frame=None) -> None:
        self.reason = self.reason or "interrupted"

    def check(self) -> bool:
        """True once a stop was asked for (checks the wall-clock limit too)."""
        elapsed = time.perf_counter() - self.started
        if self.wall_limit is not None and elapsed > self.wall_limit:
            self.reason = self.reason or "wall-clock limit"
        return self.reason is not None

    def __enter__(self) -> StopRequest:
        if threading.current_thread() is threading.main_thread():
            self._previous = signal.signal(signal.SIGINT, self.request)
        return self

    def __exit__(self, *exc) -> None:
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)


class StopInInterval(Exception):
    """A stop request honoured between two event chunks, inside a sample interval."""


@dataclass(frozen=True)
class Schedule:
    """Samples every ``interval`` (time, or collisions per particle); ``n_eq`` of them in
    equilibration, ``n_total`` in all, a checkpoint every ``n_ckpt`` (0: none)."""

    interval: float
    n_eq: int
    n_total: int
    n_ckpt: int
    by_collisions: bool

    @classmethod
    def of(cls, scene: Scene, options: RunOptions, time_step: float | None) -> Schedule:
        run = scene.run
        ckpt = options.checkpoint_interval or run.checkpoint_interval
        if time_step:  # whole steps: the interval and both phases rounded to them
            n_sample = max(1, round(run.sample_interval / time_step))

            def steps(duration: float) -> int:
                return max(0, math.ceil(duration / time_step - 1e-9))

            n_eq = round(steps(run.equilibration) / n_sample)
            n_prod = max(1, round(steps(run.production) / n_sample))
            n_ckpt = max(1, round(ckpt / time_step / n_sample)) if ckpt else 0
            return cls(n_sample * time_step, n_eq, n_eq + n_prod, n_ckpt, False)
        dt = run.sample_interval
        n_eq = round(run.equilibration / dt)
        return cls(dt, n_eq, n_eq + max(1, round(run.production / dt)),
                   max(1, round(ckpt / dt)) if ckpt else 0, run.unit == "collisions")


