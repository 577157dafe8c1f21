"""``--engine edmd``: the event-driven hard-particle core as a backend of the simulation loop.

Dimensionless particle units: d = 1, m = 1 (mass ∝ d^dim), time in the scene's unit.
Observables per sample besides the loop's own: ``collisions`` (cumulative pair count),
``wall_collisions``, ``dissipated_energy`` (cumulative), ``gravity_work``, ``wall_work_<side>``
and in y-periodic boxes ``peculiar_kinetic_energy`` and ``temperature`` (fluctuations about
the mean flow, the Lees–Edwards streaming profile included: ``engines.peculiar``) and
``pressure``: the peculiar kinetic part 2 E'_kin/(dim V) at the sample plus the collisional
part ΔW/(dim V Δt) over the interval that ends at the sample (NaN at t = 0); W = Σ r_ij·J_i.
The interaction stress is collisional (cumulative per-bin sums of −J_i ⊗ r_ij). Checkpoints
restore the synchronised core state, so a resumed run is bit-identical to an uninterrupted
one.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ... import __version__
from ...effects.bumps import bump_rows
from ...errors import EngineError, UnsupportedByEngine
from ...io.frames import Frame
from ...scene import Scene
from ...scene.initial import InitialState, build_initial_state
from ..backend import BackendBase, Capabilities, EngineOption, Needs
from ..peculiar import peculiar_observables
from .core import EventDriven, advance_watched, default_tc, from_initial_state
from .effects import TRANSLATIONS, core_options
from .tc_share import TcShare, tc_share

__all__ = ["EdmdBackend", "with_bumps", "y_range"]


def _tc_problem(value) -> str | None:
    ok = isinstance(value, int | float) and math.isfinite(value) and value >= 0.0
    return None if ok else "a finite time >= 0 is allowed (0 switches the model off)"


def _log_problem(value) -> str | None:
    ok = isinstance(value, int) and value >= 0
    return None if ok else "a whole number >= 0 (1: every collision, 0: no log)"


def with_bumps(scene: Scene, state: InitialState) -> tuple[InitialState, np.ndarray]:
    """The initial state with every bumpy wall's bumps appended (``effects.bumps.bump_rows``:
    the layout every engine uses), and the core's ``fixed`` codes (0 mobile, 1 lower wall's
    bump, 2 upper wall's). Bumps move with their wall's velocity along x; the flat plane of a
    bumpy wall stays as a backstop with the same rule."""
    rows = bump_rows(scene)
    fixed = np.zeros(len(state.diameter), np.int8)
    if not rows:
        return state, fixed
    dim = scene.dimension
    pos, vel, omega = [state.position], [state.velocity], [state.angular_velocity]
    diam, codes = [state.diameter], [fixed]
    for row in rows:
        n = len(row.centres)
        v = np.zeros((n, dim))
        v[:, 0] = scene.wall(row.side).velocity
        pos.append(row.centres)
        vel.append(v)
        omega.append(np.zeros((n, state.angular_velocity.shape[1])))
        diam.append(np.full(n, row.diameter))
        codes.append(np.full(n, 1 if row.side == "lower" else 2, np.int8))
    full = dataclasses.replace(state, position=np.concatenate(pos), velocity=np.concatenate(vel),
                               angular_velocity=np.concatenate(omega),
                               diameter=np.concatenate(diam))
    return full, np.concatenate(codes)


def y_range(scene: Scene, positions: np.ndarray) -> tuple[float, float]:
    """Extent of the cell grid along a bounded y: from the lower wall (or the lowest particle)
    to the upper wall (or the top of the box or the highest particle); the first and last
    rows are open-ended, so walls that move out and particles that fly off stay covered."""
    y = positions[:, 1]
    lo = scene.wall_position("lower") if scene.wall("lower") else float(y.min()) - 1.0
    hi = scene.wall_position("upper") if scene.wall("upper") else \
        max(scene.box.size[1], float(y.max()) + 1.0)
    return lo, hi


class EdmdBackend(BackendBase):
    """Event-driven hard discs/spheres (see the module docstring and docs/edmd-engine.md)."""

    name = "edmd"
    kind = "event-driven"
    capabilities = Capabilities(collision_count=True, collision_log=True, stress="collisional")
    translations = TRANSLATIONS
    options = {
        "tc": EngineOption("tc", float, "TC-model time t_c (default 1e-6 for spheres, 1e-5 "
                           "for discs; 0 = off). A collision within t_c of a partner's previous "
                           "one is elastic, and a particle resting on a wall hops with period "
                           "t_c: a resting bed costs ~1/t_c events per particle and time unit "
                           "(docs/edmd-engine.md)",
                           _tc_problem, "TIME"),
        "log_every": EngineOption("log_every", int, "log every k-th collision in /collisions "
                                  "(default: 1 when a statistic needs the log, else none)",
                                  _log_problem, "K"),
    }
    version = (f"demstudy-edmd {__version__} (gravity, flat and bumpy walls, servo, "
               "Lees-Edwards, Walton, e(v), TC, events with wall collisions, synchronised "
               "every 10^7 events)")

    @classmethod
    def check(cls, scene: Scene, options) -> None:
        """The effect table (``core_options``) and the cell lists' minimum box."""
        core_options(scene)
        d_max = 1.0 + scene.particles.diameter_spread / 2
        short = [a for i, a in enumerate("xyz"[:scene.dimension])
                 if a in scene.periodic and scene.box.size[i] < 3 * d_max]
        if short:
            raise UnsupportedByEngine("edmd", "box.size", list(scene.box.size),
                                      f"every periodic box length must be at least 3 largest "
                                      f"diameters ({3 * d_max:g}) for the cell lists")

    def __init__(self, scene: Scene, options, workdir):
        super().__init__(scene, options, workdir)
        self.tc = float(options.extra.get("tc", default_tc(scene.dimension)))
        self.resumed_tc_note = ""
        # whether a collision can lose energy: with t_c = 0 a stall is then inelastic collapse
        self.dissipative = (scene.contact.restitution < 1.0
                            or scene.contact.law.model != "constant"
                            or any(w.restitution < 1.0 for w in scene.walls))

    # -- set-up ---------------------------------------------------------------------------
    def setup(self, needs: Needs, saved: dict | None, servo) -> None:
        scene = self.scene
        initial = build_initial_state(scene)
        self.radius = initial.diameter / 2
        self.mass = initial.mass
        self.n_particles = len(self.mass)  # mobile particles; bumps follow them in the core
        options = core_options(scene)
        if not scene.y_periodic:
            options["y_range"] = y_range(scene, initial.position)
        if needs.stress_bins is not None:
            lo, hi, n_bins = needs.stress_bins
            options["stress_bins"] = (lo, (hi - lo) / n_bins, n_bins)
        if needs.log_every > 0:
            options.update(log_every=needs.log_every, log_capacity=needs.log_capacity)
        self.log_every = needs.log_every
        everything, fixed = with_bumps(scene, initial)
        if fixed.any():
            options["fixed"] = fixed
        self.last_virial, self.last_time, self.first = 0.0, 0.0, True
        if saved is not None and saved["tc"] != self.tc:
            if "tc" in self.run_options.extra:  # asked for explicitly: refuse to change it
                raise EngineError(f"--resume: the checkpoint was run with --tc "
                                  f"{saved['tc']:g}, this call has {self.tc:g}")
            # not given: continue with the run's own t_c (a run started before the default
            # changed, e.g. spheres at 1e-5 before 1e-6), and say so at the end
            self.resumed_tc_note = (
                f"note: resumed at the checkpoint's t_c = {saved['tc']:g}, not the default "
                f"{self.tc:g} for this dimension; the results say t_c = {saved['tc']:g}, and a "
                f"study or cost ladder that asks for the default will remake the run (give "
                f"--tc {saved['tc']:g} to keep it)")
            self.tc = float(saved["tc"])
        self.core: EventDriven = from_initial_state(everything, scene.box.size, tc=self.tc,
                                                    **options)
        if saved is not None:
            self.core.set_state(saved["core"])
            self.last_virial, self.last_time = saved["last_virial"], saved["last_time"]
            self.first = False

    def get_state(self) -> dict:
        return {"tc": self.tc, "core": self.core.get_state(), "last_virial": self.last_virial,
                "last_time": self.last_time}

    # -- advancing ------------------------------------------------------------------------
    @property
    def time(self) -> float:
        return self.core.time

    @property
    def collisions(self) -> int:
        return self.core.collisions

    def advance(self, t: float, collisions: int = 0, stop=None) -> bool:
        """Events up to time ``t`` (True when reached), or until ``collisions`` pair
        collisions (a count > 0) or a stop request (both: False). A run counted in collisions
        gets an event budget, so one whose count cannot be reached ends instead of hanging."""
        budget = 0
        if collisions > 0:
            budget = 1000 * max(1, collisions - self.core.collisions) + 10_000_000
        return advance_watched(self.core, t, tc=self.tc, max_events=budget,
                               stop_collisions=collisions, stop_requested=stop,
                               dissipative=self.dissipative,
                               bumps=any(w.kind == "bumpy" for w in self.scene.walls))

    # -- sampling -------------------------------------------------------------------------
    def observe(self, production: bool) -> dict:
        core, scene, dim = self.core, self.scene, self.scene.dimension
        velocity = core.velocities()[:self.n_particles]
        kinetic = core.kinetic_energy
        values = {
            "momentum": np.sum(self.mass[:, None] * velocity, axis=0),
            "kinetic_energy": kinetic,
            "rotational_energy": core.rotational_energy,
            "collisions": core.collisions,
            "wall_collisions": core.wall_collisions,
            "elastic_tc_collisions": core.elastic_tc_collisions,
            "dissipated_energy": core.dissipated,
        }
        if scene.gravity is not None:
            values["gravity_work"] = core.gravity_work
        for wall in scene.walls:
            values[f"wall_work_{wall.side}"] = core.wall_work(self._wall(wall.side))
        t = core.time
        if scene.y_periodic:
            # the mean flow (Lees–Edwards streaming profile) is no pressure: peculiar part only
            rate = scene.shear.rate if scene.shear is not None else 0.0
            peculiar = peculiar_observables(core.positions()[:self.n_particles], velocity,
                                            self.mass, rate)
            values.update(peculiar)
            span = t - self.last_time
            virial = core.virial
            volume = math.prod(scene.box.size)
            values["pressure"] = float("nan") if self.first or span <= 0 else \
                (2 * peculiar["peculiar_kinetic_energy"] / dim
                 + (virial - self.last_virial) / (dim * span)) / volume
            self.last_virial = virial
        self.last_time, self.first = t, False
        return values

    def frame(self) -> Frame:
        core, scene, n = self.core, self.scene, self.n_particles
        lo, hi = np.zeros(scene.dimension), np.asarray(core.box, float)
        if not scene.y_periodic:
            lo[1] = core.wall_position(0) if scene.wall("lower") else 0.0
            hi[1] = core.wall_position(1) if scene.wall("upper") else hi[1]
        return Frame(time=core.time, box_lo=lo, box_hi=hi, position=core.positions()[:n],
                     velocity=core.velocities()[:n],
                     angular_velocity=core.angular_velocities()[:n], radius=self.radius,
                     tilt=self.tilt())

    @staticmethod
    def _wall(side: str) -> int:
        return 0 if side == "lower" else 1

    def wall_impulse(self) -> dict[str, np.ndarray]:
        return {w.side: self.core.wall_impulse(self._wall(w.side)) for w in self.scene.walls}

    def wall_positions(self) -> dict[str, float]:
        return {w.side: self.core.wall_position(self._wall(w.side)) for w in self.scene.walls}

    def width(self) -> float:
        return float(self.core.box[0])

    def tilt(self) -> float:
        """The image offset flipped into [−L_x/2, L_x/2), the convention of the results file
        (LAMMPS's ``flip yes``)."""
        lx = float(self.core.box[0])
        return (self.core.shear_offset + lx / 2) % lx - lx / 2

    def move_walls(self, servo) -> None:
        """The servo's new wall velocities from now on; the periodic width is rescaled
        (positions affinely) to keep width/gap when asked."""
        for side, wall in servo.walls.items():
            k = self._wall(side)
            wall.y = self.core.wall_position(k)  # the core's position is the truth
            self.core.set_wall(k, wall.y, wall.vy, wall.vx)
        if servo.scale_width:
            self.core.scale_width(servo.shape * servo.gap / float(self.core.box[0]))

    def set_stress_bins(self, lo: float, hi: float, n_bins: int) -> None:
        self.core.set_stress_bins(float(lo), float((hi - lo) / n_bins), n_bins)

    def stress_sums(self) -> np.ndarray:
        dim = self.scene.dimension
        return self.core.stress_sums[:, :dim, :dim].transpose(0, 2, 1)  # P_ab = Σ J_a r_b

    def take_collision_log(self) -> dict[str, np.ndarray] | None:
        return self.core.take_log() if self.log_every > 0 else None

    # -- end ------------------------------------------------------------------------------
    def result_attrs(self) -> dict:
        core, scene = self.core, self.scene
        notes = [f"TC model (Luding & McNamara): a pair collision within t_c = {self.tc:g} "
                 "of either partner's previous collision is elastic (e = 1, no tangential "
                 f"impulse); {core.elastic_tc_collisions} such collisions"]
        if scene.gravity is not None and scene.walls:
            notes.append("particles pressed onto a wall by gravity leave it at least at "
                         "½ t_c |g_n| (a hop of period t_c: resting contact); "
                         f"{core.resting_bounces} such bounces")
        servo = next((w.servo for w in scene.walls if w.servo is not None), None)
        if servo is not None and servo.scale_width:
            notes.append("servo width scaling: x positions are rescaled affinely at each "
                         "servo update")
        share = tc_share(core.elastic_tc_collisions, core.collisions, self.tc)
        return {"tc": self.tc, "elastic_tc_collisions": core.elastic_tc_collisions,
                "events": core.events, "cell_crossings": core.cell_crossings,
                "wall_collisions": core.wall_collisions, "approximations": "\n".join(notes),
                **share.attrs()}

    def end_notes(self, attrs: dict) -> list[str]:
        share = TcShare.from_attrs(attrs)
        return ([share.line()] + ([share.warning()] if share.warning() else [])
                + ([self.resumed_tc_note] if self.resumed_tc_note else []))
