"""When a run samples, checkpoints and stops: the schedule in sample intervals, and stop
requests (Ctrl-C, a wall-clock limit).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts; with ``run.unit =
'collisions'`` the interval counts pair collisions per particle.
"""

from __future__ import annotations

import contextlib
import math
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from ..scene import Scene
from .options import RunOptions

__all__ = ["Schedule", "StopInInterval", "StopRequest", "interrupts_honoured", "stop_notice"]


def stop_notice(engine: str) -> str:
    """What the first Ctrl-C prints, at once, in the process the user sees."""
    return (f"\n{engine}: stopping after the current segment and a checkpoint (Ctrl-C again "
            "aborts without one)")


@contextlib.contextmanager
def interrupts_honoured() -> Iterator[None]:
    """Within: SIGINT raises ``KeyboardInterrupt`` (main thread) even where this process
    inherited it ignored or at its default action.

    Why: a shell starts a background job of a script (``demstudy run … &``, a CI step) with
    SIGINT ignored, and Python keeps that. The run loop's own handler (``StopRequest``)
    overrides it, so a Ctrl-C stopped an engine's child, but an interrupt sent to the caller
    alone (``kill -INT``, a notebook's interrupt) was lost: the run went on to its end, and
    the caller never printed the stopping notice. A handler the caller installed itself is
    kept."""
    if (threading.current_thread() is not threading.main_thread()
            or signal.getsignal(signal.SIGINT) not in (signal.SIG_IGN, signal.SIG_DFL, None)):
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


class StopRequest:
    """Ctrl-C (SIGINT, main thread only) or a wall-clock limit asks the run loop to stop at
    the end of its current segment; ``with StopRequest(limit) as stop: … stop.reason``.

    ``notice`` (the process the user sees; not an engine's child, whose parent prints it):
    the first Ctrl-C prints ``stop_notice(notice)`` at once, also while the main thread is
    inside a long engine call (a watcher thread reads the signal's wake-up byte: Python runs
    its handler only between two bytecodes), and a second Ctrl-C raises ``KeyboardInterrupt``
    in the main thread as soon as it runs Python again (the end of the current event chunk
    or segment), which the loop turns into ``RunAborted``. An engine's child only records the
    request (its parent kills it on the second Ctrl-C, and forwards the first, so two
    SIGINTs reach it from one Ctrl-C)."""

    def __init__(self, wall_limit: float | None, notice: str | None = None):
        self.wall_limit = wall_limit
        self.notice = notice
        self.reason: str | None = None
        self.interrupts = 0  # SIGINTs handled (not calls of ``request`` from code)
        self._seen = 0  # SIGINTs the watcher thread saw
        self.started = time.perf_counter()
        self._previous = None
        self._wakeup: tuple[int, int, int, threading.Thread] | None = None

    def request(self, signum=None, _frame=None) -> None:
        self.reason = self.reason or "interrupted"
        if signum is None:
            return
        self.interrupts += 1
        self._abort_on_second()

    def _abort_on_second(self) -> None:
        """Python runs the handler once for SIGINTs that arrive during one engine call; the
        watcher counts each (``_seen``), so two Ctrl-Cs there still abort."""
        if self.notice is not None and max(self.interrupts, self._seen) >= 2:
            raise KeyboardInterrupt  # the loop: RunAborted, the last checkpoint kept

    def check(self) -> bool:
        """True once a stop was asked for (checks the wall-clock limit too); raises
        ``KeyboardInterrupt`` after a second Ctrl-C (see the class)."""
        self._abort_on_second()
        elapsed = time.perf_counter() - self.started
        if self.wall_limit is not None and elapsed > self.wall_limit:
            self.reason = self.reason or "wall-clock limit"
        return self.reason is not None

    def __enter__(self) -> StopRequest:
        if threading.current_thread() is threading.main_thread():
            self._previous = signal.signal(signal.SIGINT, self.request)
            if self.notice is not None:
                self._watch()
        return self

    def __exit__(self, *exc) -> None:
        if self._wakeup is not None:
            previous, read, write, thread = self._wakeup
            signal.set_wakeup_fd(previous)
            os.close(write)  # the watcher's read returns b"": it ends
            thread.join(timeout=1.0)
            os.close(read)
            self._wakeup = None
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)
            self._previous = None

    def _watch(self) -> None:
        """The watcher thread: Python's C-level handler writes each signal's number to the
        wake-up fd at once; the first SIGINT's notice is printed from here."""
        read, write = os.pipe()
        os.set_blocking(write, False)
        try:
            previous = signal.set_wakeup_fd(write, warn_on_full_buffer=False)
        except ValueError:  # not the main interpreter
            os.close(read)
            os.close(write)
            return

        def watch() -> None:
            while True:
                try:
                    data = os.read(read, 64)
                except OSError:
                    return
                if not data:
                    return
                for byte in data:
                    if byte != signal.SIGINT:
                        continue
                    self._seen += 1
                    if self._seen == 1:
                        print(stop_notice(self.notice), file=sys.stderr, flush=True)

        thread = threading.Thread(target=watch, name="demstudy-ctrl-c", daemon=True)
        thread.start()
        self._wakeup = (previous, read, write, thread)


class StopInInterval(Exception):
    """A stop request honoured between two event chunks, inside a sample interval."""


@dataclass(frozen=True)
class Schedule:
    """Samples every ``interval`` (time, collisions per particle, or whole lattice steps with
    ``by_steps``); ``n_eq`` of them in equilibration, ``n_total`` in all, a checkpoint every
    ``n_ckpt`` (0: none)."""

    interval: float
    n_eq: int
    n_total: int
    n_ckpt: int
    by_collisions: bool
    by_steps: bool = False

    def done(self, backend: Any, samples: int) -> float:
        """Sample intervals done, with the part of the current one (a stop between two
        event chunks lands inside an interval): the backend's time, pair collisions per
        particle or lattice steps over the interval, kept within [samples, samples + 1]."""
        if self.by_steps:
            reached = backend.steps / self.interval
        elif self.by_collisions:
            reached = backend.collisions / (self.interval * backend.n_particles)
        else:
            reached = backend.time / self.interval
        return min(max(float(reached), samples), samples + 1.0)

    @classmethod
    def of(cls, scene: Scene, options: RunOptions, time_step: float | None) -> Schedule:
        run = scene.run
        ckpt = options.checkpoint_interval or run.checkpoint_interval
        if time_step and run.unit != "steps":  # the interval and phases in whole steps
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
                   max(1, round(ckpt / dt)) if ckpt else 0, run.unit == "collisions",
                   run.unit == "steps")


