"""The event-driven pilot: a short hard-particle run of a scene that measures its impacts, so
that the automatic soft-contact stiffness and time step fit the flow instead of a guess.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise a wall speed
or the shear rate sets the time unit τ). Speeds are normal impact speeds |(v_i − v_j)·n| (pairs)
and |(v_i − u_wall)·n| (walls) just before each collision, in d/τ; the collision rate is
impacts per particle per τ, τ_flight its inverse.

:func:`run_pilot` runs the scene in the event-driven core (in this process, no results file)
with every collision logged, in windows of ``PILOT_COLLISIONS`` pair collisions per
particle, until two successive windows agree after ``MIN_TIME`` (impact rates, q0.99 impact
speeds and event rates: the start-up transient is over: ``SETTLED``), the scene's own
duration (equilibration + production), ``MAX_WINDOWS`` windows or ``PILOT_SECONDS`` of wall
time; the last window is the measurement (its collisions and cell crossings, and the whole
pilot's, also go to the wall-time forecast). It adds the
initial state's own impacts as a floor (the DESIGN_QUANTILE of the normal approach speeds of
approaching neighbours and of particles towards a wall; a wall's own speed is tangential and
does not count), so particles fired at each other are seen even when the pilot stops first.
Results are cached by the scene's TOML (and its particles file), the pilot's caps
(``seconds``, ``collisions``) and version in ``demstudy.cache.cache_dir()``/pilot. Where
the event-driven engine refuses the scene (soft-only features) the result is unusable
(``usable`` False, ``reason`` says why) and the stiffness falls back to
:func:`demstudy.contact.stiffness.reference_speed` with a warning.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import tempfile
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..cache import cache_dir
from ..io.results import write_atomically
from ..scene import Scene, scene_to_toml

__all__ = ["PILOT_COLLISIONS", "PILOT_SECONDS", "PilotResult", "PilotWarning",
           "initial_floor", "pilot_cache_path", "run_pilot", "store_pilot"]

#: collisions per particle in one measuring window ...
PILOT_COLLISIONS = 20.0
#: ... and the wall-time cap of the whole pilot
PILOT_SECONDS = 5.0
#: impacts slower than this fraction of the design speed are resting contacts (TC hops,
#: chatter in a bed), not flights: they are not counted in the collision rate
RESTING_FRACTION = 0.01
#: quantiles kept in the summary (the design quantile is ``stiffness.DESIGN_QUANTILE``)
QUANTILES = (0.5, 0.99, 0.999)
#: successive windows whose impact rates and q0.99 speeds agree within this fraction: the
#: start-up transient is over
SETTLED = 0.25
#: ... and not before this much simulated time (τ: 1/γ̇, √(d/g) or d/U): the burst of a dense
#: start holds steady rates over many short windows (3D shear at φ = 0.55: ~10⁴ impacts per
#: particle per τ up to 0.1 τ, ~300 from 0.3 τ on)
MIN_TIME = 1.0
#: at most this many windows (the wall-time cap usually comes first in large scenes)
MAX_WINDOWS = 200
PILOT_VERSION = 5  # part of the cache key: a changed pilot measures again


class PilotWarning(UserWarning):
    """The pilot could not measure the scene: the stiffness comes from an estimate."""


@dataclass(frozen=True)
class PilotResult:
    """What the pilot measured (speeds in d/τ, rate in impacts per particle per τ).

    ``pair`` / ``wall``: normal impact speed quantiles {"q0.5", "q0.99", "q0.999", "max"}
    (empty when none was seen); ``floor``: the initial state's approach speeds' design
    quantile (:func:`initial_floor`); ``rate``: non-resting impacts per particle per τ (pair
    impacts count for both partners), 0 when none; ``usable`` False with ``reason`` when
    the pilot could not run.
    """

    usable: bool
    reason: str = ""
    pair: dict[str, float] = dataclasses.field(default_factory=dict)
    wall: dict[str, float] = dataclasses.field(default_factory=dict)
    floor: float = 0.0
    rate: float = 0.0
    pair_collisions: int = 0
    wall_collisions: int = 0
    simulated_time: float = 0.0
    wall_seconds: float = 0.0
    events: int = 0
    stopped_by: str = ""
    n_particles: int = 0
    # the last window's counts, for the forecast (forecast_events.pilot_rates): collisions
    # (pair + wall), cell crossings, its duration (τ), and its event rate over the first
    # window's (> 1: the flow sped up during the pilot)
    window_collisions: int = 0
    window_crossings: int = 0
    window_time: float = 0.0
    rate_growth: float = 1.0
    #: collisions (pair + wall) over the whole pilot, t = 0 … simulated_time (the rest of
    #: ``events`` are cell crossings)
    total_collisions: int = 0

    @property
    def tau_flight(self) -> float:
        """Mean free-flight time between impacts (inf: no impact seen)."""
        return 1.0 / self.rate if self.rate > 0 else math.inf

    def speed(self, kind: str, quantile: float) -> float:
        """The design impact speed of ``kind`` ("pair" or "wall"): its ``quantile`` of the
        measured speeds, never below the initial state's floor."""
        measured = (self.pair if kind == "pair" else self.wall).get(f"q{quantile:g}", 0.0)
        return max(measured, self.floor)

    def summary(self) -> str:
        """One line for the run's start and the results file."""
        if not self.usable:
            return f"no pilot ({self.reason})"
        parts = [f"{k} impacts: " + ", ".join(f"{q} {v:.3g}" for q, v in s.items())
                 for k, s in (("pair", self.pair), ("wall", self.wall)) if s]
        return (f"event-driven pilot over t = {self.simulated_time:.3g} ({self.stopped_by}, "
                f"{self.wall_seconds:.2g} s): " + "; ".join(parts or ["no impacts"]) +
                f"; initial floor {self.floor:.3g}; {self.rate:.3g} impacts per particle "
                f"per time unit (τ_flight = {self.tau_flight:.3g})")

    def to_json(self) -> str:
        return json.dumps(dataclasses.asdict(self))

    @classmethod
    def from_json(cls, text: str) -> PilotResult:
        return cls(**json.loads(text))


# -- cache ----------------------------------------------------------------------------------
def pilot_cache_path(scene: Scene, seconds: float = PILOT_SECONDS,
                     collisions: float = PILOT_COLLISIONS) -> Path:
    """The cache file of ``scene``'s pilot: keyed by its TOML, its particles file's content
    (placement = 'file'), the pilot's caps (``seconds``, ``collisions``: a pilot cut short by
    a smaller wall-time cap is not the answer to an uncapped call) and its version."""
    key = hashlib.sha256(scene_to_toml(scene).encode())
    key.update(f"{PILOT_VERSION} {collisions!r} {seconds!r} {RESTING_FRACTION}".encode())
    if scene.initial.placement == "file":
        key.update(Path(scene.initial.path).read_bytes())
    return cache_dir() / "pilot" / f"{key.hexdigest()[:24]}.json"


def store_pilot(path: Path, result: PilotResult) -> None:
    """``result`` to the cache file ``path``, atomically (a concurrent reader sees the old
    file or the new one)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    write_atomically(path, result.to_json().encode())


# -- the initial state's own impacts --------------------------------------------------------
def initial_floor(scene: Scene, position: np.ndarray, velocity: np.ndarray) -> float:
    """The initial state's own impact speed: the larger of the DESIGN_QUANTILE of the normal
    approach speeds over approaching neighbour pairs (centres within 3 d; with two particles,
    their one pair) and of the speeds of particles moving towards a wall. A quantile, not the
    maximum: the maximum over N particles grows with N. A wall's own ``velocity`` slides
    along x and brings nothing closer; a servo wall's normal motion is slow and not known up
    front (left out)."""
    from scipy.spatial import cKDTree

    from .stiffness import DESIGN_QUANTILE  # one place for the targets

    floors = [0.0]
    if scene.walls:
        sides = {w.side for w in scene.walls}
        towards = np.zeros(len(velocity))
        if "lower" in sides:
            towards = np.maximum(towards, -velocity[:, 1])
        if "upper" in sides:
            towards = np.maximum(towards, velocity[:, 1])
        floors.append(_quantile(towards[towards > 0], DESIGN_QUANTILE))
    pairs = cKDTree(position).query_pairs(3.0, output_type="ndarray")
    if len(pairs):
        branch = position[pairs[:, 1]] - position[pairs[:, 0]]
        relative = velocity[pairs[:, 0]] - velocity[pairs[:, 1]]
        approach = np.einsum("ij,ij->i", relative, branch) / np.linalg.norm(branch, axis=1)
        floors.append(_quantile(approach[approach > 0], DESIGN_QUANTILE))
    return max(floors)


# -- the run --------------------------------------------------------------------------------
def run_pilot(scene: Scene, *, cache: bool = True, seconds: float = PILOT_SECONDS,
              collisions: float = PILOT_COLLISIONS) -> PilotResult:
    """The pilot of ``scene`` (from the cache when it ran before, unless ``cache`` is False).
    Warns (``PilotWarning``) and returns an unusable result when the event-driven engine
    cannot run the scene."""
    path = pilot_cache_path(scene, seconds, collisions)
    if cache and path.is_file():
        try:
            return PilotResult.from_json(path.read_text())
        except (ValueError, TypeError):
            pass  # an older or damaged cache file: measure again
    result = _measure(scene, seconds, collisions)
    if not result.usable:
        warnings.warn(f"no event-driven pilot: {result.reason}; the soft-contact stiffness "
                      "comes from the estimated reference speed (stiffness_basis = "
                      "'estimate'); give soft.stiffness or soft.hardness to choose it",
                      PilotWarning, stacklevel=2)
    if cache:
        store_pilot(path, result)
    return result


def _measure(scene: Scene, seconds: float, collisions: float) -> PilotResult:
    from ..engines.backend import Needs
    from ..engines.edmd import EdmdBackend
    from ..errors import EngineError, UnsupportedByEngine
    from ..simulation.options import RunOptions

    if scene.run.unit != "time":
        return PilotResult(False, "run.unit = 'collisions': soft contacts need times")
    with tempfile.TemporaryDirectory(prefix="demstudy-pilot-") as tmp:
        options = RunOptions(out=Path(tmp) / "pilot.h5", progress=False)
        try:
            EdmdBackend.check(scene, options)
            backend = EdmdBackend(scene, options, Path(tmp))
            backend.setup(Needs(log_every=1), None, None)
        except UnsupportedByEngine as exc:
            return PilotResult(False, f"the event-driven engine cannot run the scene ({exc})")
        try:
            return _advance(scene, backend, seconds, collisions)
        except EngineError as exc:
            return PilotResult(False, f"the event-driven pilot failed ({exc})")
        finally:
            backend.close()


def _advance(scene: Scene, backend, seconds: float, collisions: float) -> PilotResult:
    """Run windows of ``collisions`` pair collisions per particle until two successive
    windows agree (impact rate and q0.99 pair speed within ``SETTLED``), the scene's
    duration, ``MAX_WINDOWS`` or the wall-time cap; the last window is the measurement.
    Why windows: a dense start (a jittered lattice at φ = 0.55, say) collapses in a burst of
    collisions far faster and harder than the flow that follows (measured: q0.999 impact
    speed 114 and 1 700 impacts per particle per τ in the first 0.02 τ of a 3D Lees–Edwards
    shear, 2.5 and ~300 after 0.3 τ); a soft run goes through that start once, the contacts
    must fit the flow."""
    core, n = backend.core, backend.n_particles
    frame = backend.frame()
    floor = initial_floor(scene, frame.position, frame.velocity)
    t_end = scene.run.equilibration + scene.run.production
    per_window = math.ceil(collisions * n)
    chunk = max(n, 100)  # pair collisions between two wall-clock checks
    started = time.perf_counter()

    def over_time() -> bool:
        return time.perf_counter() - started > seconds

    windows: list[dict] = []
    stopped_by = "the scene's duration"
    while True:
        t0, target = core.time, core.collisions + per_window
        counts0 = _counts(core)
        pair, wall, reached = [], [], False
        while True:
            reached = backend.advance(t_end, min(core.collisions + chunk, target), over_time)
            log = backend.take_collision_log()
            if log is not None and len(log["time"]):
                vn = np.abs(np.einsum("ij,ij->i", log["velocity"], log["normal"]))
                pair.append(vn[log["kind"] == 0])
                wall.append(vn[log["kind"] != 0])
            if reached or core.collisions >= target or over_time():
                break
        windows.append(_window(pair, wall, core.time - t0, n))
        windows[-1].update({k: v - counts0[k] for k, v in _counts(core).items()})
        windows[-1]["events_rate"] = (windows[-1]["events"] / (n * windows[-1]["duration"])
                                      if windows[-1]["duration"] > 0 else 0.0)
        if reached:
            break
        if over_time():
            stopped_by = f"{seconds:g} s wall-time cap"
            break
        if len(windows) >= 2 and core.time >= MIN_TIME and _settled(windows[-2], windows[-1]):
            stopped_by = (f"settled after {len(windows)} windows of {collisions:g} collisions "
                          "per particle")
            break
        if len(windows) >= MAX_WINDOWS:
            stopped_by = f"{MAX_WINDOWS} windows of {collisions:g} collisions per particle"
            break
    last = windows[-1]
    from .stiffness import DESIGN_QUANTILE  # one place for the targets

    pair_speeds, wall_speeds = last["pair"], last["wall"]
    design = max(_quantile(pair_speeds, DESIGN_QUANTILE), _quantile(wall_speeds,
                                                                   DESIGN_QUANTILE), floor)
    resting = RESTING_FRACTION * design
    impacts = 2 * np.count_nonzero(pair_speeds > resting) + \
        np.count_nonzero(wall_speeds > resting)
    return PilotResult(
        True, pair=_summary(pair_speeds), wall=_summary(wall_speeds), floor=floor,
        rate=impacts / (n * last["duration"]) if last["duration"] > 0 else 0.0,
        pair_collisions=len(pair_speeds), wall_collisions=len(wall_speeds),
        simulated_time=core.time, wall_seconds=time.perf_counter() - started,
        events=int(core.events), stopped_by=stopped_by, n_particles=n,
        window_collisions=int(last["pair_count"] + last["wall_count"]),
        window_crossings=int(last["events"] - last["pair_count"] - last["wall_count"]),
        window_time=float(last["duration"]),
        total_collisions=int(core.collisions) + int(core.wall_collisions),
        rate_growth=(last["events_rate"] / windows[0]["events_rate"]
                     if windows[0]["events_rate"] > 0 else 1.0))


def _counts(core) -> dict[str, int]:
    """The core's cumulative event counters: every event, pair and wall collisions."""
    return {"events": int(core.events), "pair_count": int(core.collisions),
            "wall_count": int(core.wall_collisions)}


def _window(pair: list, wall: list, duration: float, n: int) -> dict:
    pair_speeds = np.concatenate(pair or [np.zeros(0)])
    wall_speeds = np.concatenate(wall or [np.zeros(0)])
    rate = (2 * len(pair_speeds) + len(wall_speeds)) / (n * duration) if duration > 0 else 0.0
    return {"pair": pair_speeds, "wall": wall_speeds, "duration": duration, "rate": rate,
            "speed": _quantile(np.concatenate([pair_speeds, wall_speeds]), 0.99)}


def _settled(a: dict, b: dict) -> bool:
    """Two windows with impact rates, q0.99 impact speeds and event rates within
    ``SETTLED``."""
    def close(x: float, y: float) -> bool:
        return abs(x - y) <= SETTLED * max(abs(x), abs(y))
    # the event rate too: a flow accelerating under gravity keeps its collision rate and
    # impact speeds while its mean flow (and its cell crossings) still grow
    return (close(a["rate"], b["rate"]) and close(a["speed"], b["speed"])
            and close(a.get("events_rate", 0.0), b.get("events_rate", 0.0)))


def _quantile(speeds: np.ndarray, q: float) -> float:
    return float(np.quantile(speeds, q)) if len(speeds) else 0.0


def _summary(speeds: np.ndarray) -> dict[str, float]:
    if not len(speeds):
        return {}
    out = {f"q{q:g}": _quantile(speeds, q) for q in QUANTILES}
    out["max"] = float(speeds.max())
    return out
