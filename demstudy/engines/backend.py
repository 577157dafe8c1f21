"""The engine backend protocol: what the one simulation loop asks of every engine.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise a wall speed
or the shear rate sets the time unit τ).

A backend runs one scene in one engine and knows nothing of sampling, analyses, checkpoints
or results files: :class:`demstudy.engines.simulation.Simulation` owns those (HOOMD-blue's
Simulation/Operations split is the model). The loop calls, in this order:

* ``Backend.check(scene, options)`` (class method) before anything starts: refuse what the
  engine cannot express (its effect table, :func:`demstudy.effects.check_effects`) or run;
* ``Backend(scene, options, workdir)``, then ``setup(needs, saved, servo)``: build the
  engine from the scene, or from a checkpoint's ``saved`` state;
* ``advance(t, collisions, stop)`` to the next sample (or servo update), then
  ``observe()`` (the sample's timeseries values), ``frame()`` (a :class:`Frame`) when the
  sample needs the particles, ``wall_impulse()``, ``stress_sums()`` and
  ``take_collision_log()`` where the engine has them (its ``capabilities``);
* ``move_walls(servo)`` after each servo update;
* ``get_state()`` for a checkpoint (``cleanup`` removes the engine's files of older ones);
* ``result_attrs()`` and ``close()`` at the end.

:class:`BackendBase` gives every optional method a default, so a minimal backend implements
``setup``, ``advance``, ``time``, ``frame``, ``observe`` and ``get_state`` (see
``tests/ballistic_backend.py``, a complete one in under 100 lines, and docs/engines.md).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from ..effects import Cannot, Translation, check_effects
from ..errors import UnsupportedByEngine
from ..io.frames import Frame
from ..scene import Scene

__all__ = ["LOG_CAPACITY", "BackendBase", "Capabilities", "EngineOption", "Needs"]

#: collision-log records a run keeps (sampled every ``log_every`` collisions)
LOG_CAPACITY = 200_000


@dataclass(frozen=True)
class Capabilities:
    """What an engine can do beyond advancing particles.

    ``time_step``: time-stepped (samples fall on whole steps; the servo updates at sample
    ends) rather than event-driven (exact times, collision counts); ``soft_contact``: soft
    contacts whose stiffness and step the contact mapping chooses (the pilot, calibration,
    the soft forecast); ``step_count``: counts whole steps of its own (``run.unit = 'steps'``:
    the lattice engine); ``collision_count``:
    counts pair collisions (``run.unit = 'collisions'``, collision-counted servo);
    ``collision_log``: logs collisions (angles, free paths); ``stress``: the interaction
    stress it sums per bin, "collisional" (cumulative impulse moments) or "contact"
    (instantaneous force moments), or None; ``mpi``: runs on several MPI ranks (``--np``);
    ``dump``: writes a trajectory dump of its own (``--dump``); ``inputs``: writes input
    files that run without demstudy (``demstudy deck``)."""

    time_step: bool = False
    soft_contact: bool = False
    step_count: bool = False
    collision_count: bool = False
    collision_log: bool = False
    stress: str | None = None
    mpi: bool = False
    dump: bool = False
    inputs: bool = False


@dataclass(frozen=True)
class EngineOption:
    """A run option only one engine has (``--NAME`` on the command line, ``NAME=`` from
    Python): its type, help and check (returns the reason when a value is not allowed)."""

    name: str
    kind: type
    help: str
    check: Callable[[Any], str | None] = lambda _value: None
    metavar: str = "VALUE"


@dataclass(frozen=True)
class Needs:
    """What the loop needs from the engine, fixed at set-up: interaction-stress bins along y
    (lo, hi, number of bins; None: no stress), and every how many collisions to log (0: no
    log)."""

    stress_bins: tuple[float, float, int] | None = None
    log_every: int = 0
    log_capacity: int = LOG_CAPACITY


class BackendBase:
    """Defaults for the optional parts of the protocol (see the module docstring)."""

    name: ClassVar[str] = "engine"
    kind: ClassVar[str] = "engine"  # what it simulates, in words: "event-driven", "soft-contact"
    capabilities: ClassVar[Capabilities] = Capabilities()
    options: ClassVar[Mapping[str, EngineOption]] = {}
    #: the engine's translation of every effect (``demstudy.effects``)
    translations: ClassVar[Mapping[str, Translation | Cannot]] = {}
    #: set by ``setup``; a checkpoint continues only with the same version
    version: str = ""
    rank: int = 0  # MPI rank: only rank 0 analyses and writes
    time_step: float | None = None  # time-stepped engines: the step (known after __init__)
    n_particles: int = 0  # mobile particles (known after setup)

    def __init__(self, scene: Scene, options: Any, workdir: Path):
        self.scene, self.run_options, self.workdir = scene, options, workdir

    @classmethod
    def check(cls, scene: Scene, options: Any) -> None:
        """Refuse, before anything starts, what this engine cannot express or run."""
        check_effects(scene, cls.name, cls.translations)

    @staticmethod
    def launcher(np_ranks: int) -> list[str] | None:
        """The command prefix that starts ``np_ranks`` ranks (MPI engines), else None."""
        return None

    @staticmethod
    def fork_safe() -> bool:
        """Whether a one-rank child run may be a fork of this process (the isolation's
        default when it is single-threaded): False while this process holds something the
        engine must not inherit in a fork (an initialised MPI runtime, say)."""
        return True

    @staticmethod
    def log_file(workdir: Path) -> Path | None:
        """The engine's own log in the work folder, named in failure messages."""
        return None

    @staticmethod
    def crash_report(workdir: Path) -> str:
        """What a dead child's engine left in the work folder (the command it was given last,
        its log's error), for the parent's ``EngineError``; empty if nothing."""
        return ""

    @classmethod
    def write_inputs(cls, scene: Scene, folder: Path, dump: str | None = None) -> Path:
        """Write the engine's own input files for ``scene`` (``capabilities.inputs``)."""
        raise UnsupportedByEngine(cls.name, "deck", scene.meta.name,
                                  "this engine has no input files of its own")

    @staticmethod
    def run_inputs_hint(path: Path) -> str:
        """How to run the input files written by ``write_inputs`` without demstudy."""
        return f"see {path.name}"

    @classmethod
    def calibrate(cls, **settings: Any) -> list:
        """Binary collisions measured in the engine (``demstudy calibrate``)."""
        raise UnsupportedByEngine(cls.name, "calibrate", cls.name,
                                  "only soft-contact engines are calibrated")

    # -- per sample -------------------------------------------------------------------
    @property
    def collisions(self) -> int:
        """Pair collisions so far (collision-counting engines)."""
        return 0

    @property
    def steps(self) -> int:
        """Whole steps so far (step-counting engines: ``capabilities.step_count``)."""
        return 0

    def advance_steps(self, steps: int, stop: Callable[[], bool] | None = None) -> bool:
        """Advance to step number ``steps`` (``run.unit = 'steps'``); False when a stop
        request (``stop()`` true) ended it earlier."""
        raise NotImplementedError(f"{self.name} counts no steps of its own")

    def wall_impulse(self) -> dict[str, np.ndarray]:
        """Cumulative impulse of each wall on the particles since the start, (3,) per side."""
        return {}

    def wall_positions(self) -> dict[str, float] | None:
        """Where the engine's walls are now (None: where the servo bookkeeping says)."""
        return None

    def width(self) -> float:
        """The periodic length along x now."""
        return float(self.scene.box.size[0])

    def tilt(self) -> float:
        """The Lees–Edwards image offset, flipped into [−L_x/2, L_x/2)."""
        return 0.0

    def move_walls(self, servo: Any) -> None:
        raise NotImplementedError(f"{self.name} has no servo walls")

    def set_stress_bins(self, lo: float, hi: float, n_bins: int) -> None:
        raise NotImplementedError(f"{self.name} sums no interaction stress")

    def stress_sums(self) -> np.ndarray:
        raise NotImplementedError(f"{self.name} sums no interaction stress")

    def take_collision_log(self) -> dict[str, np.ndarray] | None:
        return None

    def marked(self) -> dict[str, Any] | None:
        """The scene's marked grains now, for their paths (``/tracks``,
        :mod:`demstudy.simulation.tracks`): ``mark`` (n,) numbers, ``position`` and
        ``velocity`` (n, dim), ``period`` (the periodic length along x, 0: none); None when
        the scene has no marked grains (the default)."""
        return None

    # -- MPI, checkpoints, end ----------------------------------------------------------
    def agree(self, flag: bool) -> bool:
        """True on every rank if ``flag`` is true on any rank (collective on MPI ranks; the
        loop's last call, after ``close``, is the barrier before the ranks exit)."""
        return flag

    def cleanup(self, keep: dict | None) -> None:
        """Remove the engine's checkpoint files except those of ``keep`` (None: all)."""

    def result_attrs(self) -> dict[str, Any]:
        return {}

    def end_notes(self, attrs: dict[str, Any]) -> list[str]:
        """Lines printed (stderr) when the run's results are written, from the results
        file's root attributes ``attrs`` (the event-driven engine: the TC model's share)."""
        return []

    def close(self) -> None:
        """Release the engine (called on every rank, also after a failure)."""


def frame_mass(frame: Frame) -> np.ndarray:
    """Particle masses of a frame: m = d^dim (d = 1 has m = 1)."""
    return (2 * np.asarray(frame.radius, float)) ** frame.dim


def frame_energies(frame: Frame, inertia_k: float) -> dict[str, Any]:
    """Total momentum, translational and rotational kinetic energy of a frame's particles
    (mean flow included: the peculiar parts are :mod:`demstudy.engines.peculiar`'s);
    ``inertia_k``: I = K m r²."""
    mass = frame_mass(frame)
    inertia = inertia_k * mass * frame.radius**2
    return {"momentum": np.sum(mass[:, None] * frame.velocity, axis=0),
            "kinetic_energy": 0.5 * float(np.sum(mass[:, None] * frame.velocity**2)),
            "rotational_energy": 0.5 * float(np.sum(inertia[:, None] *
                                                    frame.angular_velocity**2))}
