"""How far a stopped run got, and what is left of it at its own pace.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts. Each checkpoint writes,
beside the checkpoint, ``progress.json``: the sample intervals done of the run's total, the
simulated time reached and the wall seconds the run has taken at each of its checkpoints. A
resumed run's forecast (``--resume --dry-run``, a study or sweep that continues a stopped
run) is then the time left *at this run's own pace* over its latest stretch, not its whole
forecast again: a run measured on this machine, in this state, beats any pilot (a flow that
gravity accelerates gets slower per sample as it heats, which only its own pace shows).

The file is informative only: a resume reads the checkpoint, never this file, and a missing
or unreadable file just means no such forecast.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .. import UNITS_NOTE
from ..io.results import write_atomically

__all__ = ["PROGRESS", "Progress", "read_progress", "write_progress"]

PROGRESS = "progress.json"

#: the pace of a stopped run is measured over its latest stretch of at least this share of
#: the samples done (a Ctrl-C soon after a checkpoint leaves a stretch too short to time)
STRETCH_SHARE = 0.25


@dataclass(frozen=True)
class Progress:
    """A stopped run: ``samples`` of ``total`` sample intervals done, simulated ``time``
    reached, and ``marks``: (samples done, wall seconds taken) at each checkpoint so far."""

    samples: int
    total: int
    time: float
    marks: tuple[tuple[int, float], ...]

    @property
    def wall_seconds(self) -> float:
        return self.marks[-1][1] if self.marks else 0.0

    def stretch(self) -> tuple[int, float]:
        """(samples, wall seconds) of the latest stretch of checkpoints that covers at least
        ``STRETCH_SHARE`` of the samples done (all of them when none is that long)."""
        k, w = self.marks[-1]
        for k0, w0 in reversed(self.marks[:-1]):
            if k - k0 >= max(1, STRETCH_SHARE * k):
                return k - k0, w - w0
        return k, w

    def seconds_left(self) -> float:
        """Wall seconds for the samples left at the pace of the latest stretch (nan when
        nothing is done yet)."""
        k, w = self.stretch()
        if k <= 0 or not self.marks:
            return math.nan
        return max(self.total - self.samples, 0) * w / k

    def line(self) -> str:
        """What ``--resume`` continues and how long it takes at the run's own pace."""
        from .forecast import _duration

        left = self.seconds_left()
        done = f"{self.samples} of {self.total} samples done (t = {self.time:.6g})"
        if not math.isfinite(left):
            return f"resume: {done}; no pace measured yet"
        k, w = self.stretch()
        pace = f"{w / k:.3g} s per sample over the latest {k} samples"
        whole = self.wall_seconds / self.samples
        trend = ""
        if self.samples > k and abs(w / k / whole - 1) > 0.1:
            trend = f" (the run's average: {whole:.3g} s per sample)"
        return (f"resume: {done} in {_duration(self.wall_seconds)}; about "
                f"{_duration(left)} left at this run's own pace: {pace}{trend}")

    def attrs(self) -> dict[str, Any]:
        return {"left_seconds": self.seconds_left(), "left": self.line(),
                "samples_done": self.samples, "samples_total": self.total}


def write_progress(workdir: Path, samples: int, total: int, time: float,
                   marks: tuple[tuple[int, float], ...]) -> None:
    """``progress.json`` in ``workdir`` (atomically), next to the checkpoint just written."""
    data = {"units": UNITS_NOTE, "samples": samples, "samples_total": total, "time": time,
            "marks": [list(m) for m in marks],
            "note": "informative (forecasts of a resumed run); a resume reads the checkpoint"}
    write_atomically(workdir / PROGRESS, json.dumps(data, indent=1).encode())


def read_progress(workdir: Path) -> Progress | None:
    """The progress of the run stopped in ``workdir`` (None: no checkpoint there, or no
    readable progress file beside it)."""
    from .checkpoint import CHECKPOINT

    if not (workdir / CHECKPOINT).is_file():
        return None
    try:
        data = json.loads((workdir / PROGRESS).read_text())
        marks = tuple((int(k), float(w)) for k, w in data["marks"])
        progress = Progress(int(data["samples"]), int(data["samples_total"]),
                            float(data["time"]), marks)
    except (OSError, ValueError, KeyError, TypeError):
        return None
    if not marks or progress.total <= 0:
        return None
    return progress
