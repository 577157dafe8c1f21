"""How far a stopped run got, and what is left of it at its own pace.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts. Each checkpoint writes,
beside the checkpoint, ``progress.json``: the sample intervals done of the run's total (with
the part of the current interval: a stop between two event chunks lands inside one), the
simulated time reached and the wall seconds the run has taken at each of its checkpoints,
tied to the checkpoint by its SHA-256 and to the scene by the SHA-256 of its TOML. A resumed
run's forecast (``--resume``, also with ``--dry-run``; a study or sweep that continues a
stopped run) is then the time left *at this run's own pace* over its latest stretch, not its
whole forecast again: a run measured on this machine, in this state, beats any pilot (a flow
that gravity accelerates gets slower per sample as it heats, which only its own pace shows).

The time left is the loop's, as ``wall_seconds`` is: the process start, the engine's set-up
and the final analyses and write come on top. The file is informative only: a resume reads
the checkpoint, never this file; a missing file, one that belongs to another checkpoint or
scene, or one that cannot be written just means no such forecast.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .. import UNITS_NOTE
from ..io.results import write_atomically

__all__ = ["PROGRESS", "Progress", "progress_record", "read_progress", "scene_digest",
           "time_left", "write_progress"]

PROGRESS = "progress.json"

#: the pace of a stopped run is measured over its latest stretch of at least this share of
#: the sample intervals done (a Ctrl-C soon after a checkpoint leaves a stretch too short)
STRETCH_SHARE = 0.25


def scene_digest(scene_toml: str) -> str:
    """SHA-256 of a scene's TOML (``scene_to_toml``): the scene a checkpoint continues."""
    return hashlib.sha256(scene_toml.encode()).hexdigest()


@dataclass(frozen=True)
class Progress:
    """A stopped run: ``done`` of ``total`` sample intervals (fractional), simulated ``time``
    reached, and ``marks``: (intervals done, wall seconds taken) at each checkpoint."""

    done: float
    total: int
    time: float
    marks: tuple[tuple[float, float], ...]

    @property
    def wall_seconds(self) -> float:
        return self.marks[-1][1] if self.marks else 0.0

    def stretch(self) -> tuple[float, float]:
        """(intervals, wall seconds) of the latest stretch of checkpoints that covers at
        least ``STRETCH_SHARE`` of the intervals done (all of them when none is that long;
        (0, 0) without marks)."""
        if not self.marks:
            return 0.0, 0.0
        k, w = self.marks[-1]
        for k0, w0 in reversed(self.marks[:-1]):
            if k - k0 >= STRETCH_SHARE * k and k - k0 > 0:
                return k - k0, w - w0
        return k, w

    def seconds_left(self) -> float:
        """Wall seconds for the intervals left at the pace of the latest stretch (nan when
        no part of an interval is done yet)."""
        k, w = self.stretch()
        if not k > 0 or not w > 0:
            return math.nan
        return max(self.total - self.done, 0.0) * w / k

    def line(self) -> str:
        """What ``--resume`` continues and how long it takes at the run's own pace."""
        from .forecast import _duration

        done = (f"{self.done:.4g} of {self.total} sample intervals done "
                f"(t = {self.time:.6g})")
        left = self.seconds_left()
        if not math.isfinite(left):
            return f"resume: {done}; no pace measured yet"
        k, w = self.stretch()
        pace = f"{w / k:.3g} s per interval over the latest {k:.4g}"
        trend = ""
        whole = self.wall_seconds / self.done
        if k < self.done and abs(w / k / whole - 1) > 0.1:
            trend = f" (the run's average: {whole:.3g} s per interval)"
        return (f"resume: {done} in {_duration(self.wall_seconds)}; about "
                f"{_duration(left)} left at this run's own pace: {pace}{trend}")

    def attrs(self) -> dict[str, Any]:
        return {"left_seconds": self.seconds_left(), "left": self.line(),
                "intervals_done": self.done, "intervals_total": self.total}


def write_progress(workdir: Path, progress: Progress, checkpoint_sha256: str,
                   scene_sha256: str) -> None:
    """``progress.json`` in ``workdir`` (atomically), for the checkpoint just written; a
    failed write (a full disk) leaves no file and never stops the run."""
    data = {"units": UNITS_NOTE, "intervals_done": progress.done,
            "intervals_total": progress.total, "time": progress.time,
            "marks": [list(m) for m in progress.marks],
            "checkpoint_sha256": checkpoint_sha256, "scene_sha256": scene_sha256,
            "note": "informative (forecasts of a resumed run); a resume reads the checkpoint"}
    try:
        write_atomically(workdir / PROGRESS, json.dumps(data, indent=1).encode())
    except OSError:
        (workdir / PROGRESS).unlink(missing_ok=True)


def progress_record(workdir: Path) -> dict | None:
    """The progress file in ``workdir`` as written, when it belongs to the checkpoint there
    (its SHA-256); None otherwise (no checkpoint, no readable file, another checkpoint's)."""
    from .checkpoint import CHECKPOINT, checkpoint_digest

    digest = checkpoint_digest(workdir / CHECKPOINT)
    if digest is None:
        return None
    try:
        data = json.loads((workdir / PROGRESS).read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(data, dict) or data.get("checkpoint_sha256") != digest:
        return None
    return data


def read_progress(workdir: Path, scene_toml: str | None = None) -> Progress | None:
    """The progress of the run stopped in ``workdir``; None when there is no checkpoint, no
    readable progress file, or one written for another checkpoint or (``scene_toml`` given)
    another scene."""
    data = progress_record(workdir)
    if data is None:
        return None
    try:
        marks = tuple((float(k), float(w)) for k, w in data["marks"])
        progress = Progress(float(data["intervals_done"]), int(data["intervals_total"]),
                            float(data["time"]), marks)
        mine = scene_toml is None or data["scene_sha256"] == scene_digest(scene_toml)
    except (ValueError, KeyError, TypeError):
        return None
    if not mine or not marks or progress.total <= 0:
        return None
    return progress


def time_left(workdir: Path, scene_toml: str) -> tuple[float, str] | None:
    """(seconds, line) of what is left of the run of ``scene_toml`` stopped in ``workdir``
    at its own pace, for a forecast's list of runs; None when there is no such pace (no
    checkpoint or progress file of its own, another scene, nothing timed yet)."""
    progress = read_progress(workdir, scene_toml)
    if progress is None or not math.isfinite(progress.seconds_left()):
        return None
    return progress.seconds_left(), progress.line().removeprefix("resume: ")
