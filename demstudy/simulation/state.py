"""What the loop carries from sample to sample and into checkpoints.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..analysis.base import AnalysisBase
from ..analysis.stress import CollisionalSums, ContactStress
from ..effects.servo import ServoController
from .tracks import MarkedTracks

__all__ = ["RunState"]


@dataclass
class RunState:
    """Everything the loop needs to continue a run (pickled into checkpoints)."""

    samples: int = 0  # sample intervals done
    timeseries: dict[str, list] = field(default_factory=dict)
    frames: dict[str, list] = field(default_factory=dict)
    keep_frames: bool = False  # fixed when the run starts, kept on resume
    profiles: AnalysisBase | None = None
    streams: dict[str, AnalysisBase] = field(default_factory=dict)  # other stream statistics
    stress: CollisionalSums | ContactStress | None = None
    stress_edges: np.ndarray | None = None
    wall_seconds: float = 0.0
    last_time: float = 0.0
    last_impulse: dict[str, np.ndarray] = field(default_factory=dict)
    servo: ServoController | None = None
    next_servo: int = 0  # collision count of the next servo update
    next_servo_time: float = 0.0  # time of the next servo update
    servo_impulse: dict[str, np.ndarray] = field(default_factory=dict)
    servo_time: float = 0.0
    log: dict[str, list] = field(default_factory=dict)
    logged: int = 0
    # particle y and momenta where production starts and ends (the unsteady momentum term)
    momentum_start: dict | None = None
    momentum_end: dict | None = None
    in_production: bool = False
    # soft-contact engines: the contact health at each production sample (contact.health)
    health: dict[str, list] = field(default_factory=dict)
    # marked grains' paths, every sample from t = 0 (engines with ``marked``), else None
    tracks: MarkedTracks | None = None
    # (sample intervals done, wall seconds taken) at each checkpoint: the run's own pace, for the
    # forecast of what is left when it resumes (simulation.progress); a checkpoint pickled
    # before it unpickles with this class default
    marks: tuple[tuple[float, float], ...] = ()
    # how many times the run was resumed (the results file's ``resumes``; class default 0
    # for checkpoints pickled before it)
    resumes: int = 0

    def record(self, key: str, value) -> None:
        self.timeseries.setdefault(key, []).append(value)
