"""Campbell's normal-stress servo for LAMMPS: walls on moving regions, driven from Python.

Dimensionless particle units: d = 1, m = 1 (the wall speed sets the time scale in Couette
flow). A servo wall is a ``fix wall/gran/region`` on a plane region that moves by equal-style
variables; between run segments the controller measures the mean normal stress on each wall
(``fix ave/time`` over the servo interval), applies Campbell's rule
v ← ½ v ± gain · clamp(σ − σ_n, −σ_n, σ_n), and redefines the variables so that the wall
positions stay continuous. With ``scale_width`` the periodic width follows the gap
(``fix deform x variable``, boundaries only, as in Campbell's code); with ``hold_shear_rate`` the
upper wall's speed is rescaled with the gap. In a bare ``lmp -in deck.in`` run nobody drives
the variables: the walls then stay at their initial positions (the deck says so).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..scene import Scene
from ..scene.schema import Wall
from .base import Block, UnsupportedByEngine, fmt
from .contact import ContactSetup
from .walls import wall_fix_id


def has_servo(scene: Scene) -> bool:
    return any(w.servo is not None for w in scene.walls)


def servo_interval_steps(scene: Scene, dt: float) -> int:
    wall = next(w for w in scene.walls if w.servo is not None)
    if wall.servo.interval_time is None:
        raise UnsupportedByEngine(
            "lammps", f"walls[{wall.side}].servo.interval_time", None,
            "soft-contact engines count time, not collisions: give the servo update interval "
            "in time units (e.g. interval_time = 0.5)",
        )
    # rounded to whole sample intervals: servo updates happen at sample ends
    n_sample = max(1, round(scene.run.sample_interval / dt))
    return n_sample * max(1, round(wall.servo.interval_time / scene.run.sample_interval))


def region_wall_block(scene: Scene, wall: Wall, setup: ContactSetup) -> Block:
    """A wall on a plane region that moves with variables (``<fix>_x0``, ``_vx``, …)."""
    fid = wall_fix_id(wall.side)
    y = scene.wall_position(wall.side)
    normal = "0 1 0" if wall.side == "lower" else "0 -1 0"
    # displacements as inline linear functions of time: the servo redefines them (one parse
    # per evaluation: nested variables would triple the cost of every step)
    cmds = [
        f"variable {fid}_dx equal {fmt(wall.velocity)}*time",
        f"variable {fid}_dy equal 0.0",
        f"region {fid} plane 0 {fmt(y)} 0 {normal} side in "
        f"move v_{fid}_dx v_{fid}_dy NULL units box",
        f"fix {fid} mobile wall/gran/region granular {setup.walls[wall.side].granular_args()} "
        f"region {fid} contacts",
        f"compute {fid}_force mobile reduce sum f_{fid}[2] f_{fid}[3] f_{fid}[4]",
    ]
    servo = wall.servo
    comment = (f"{wall.side} wall on a moving plane region at y = {fmt(y)}, "
               f"e_w = {wall.restitution:g}")
    if servo is not None:
        n = servo_interval_steps(scene, setup.timestep)
        comment += (f"; servo to sigma_n = {servo.normal_stress:.6g} every {n} steps "
                    "(driven from Python: the wall keeps its place in a bare lmp run)")
    return Block(f"wall:{wall.side}", comment, cmds)


@dataclass
class WallMotion:
    side: str
    y: float  # current position
    x: float  # current tangential displacement
    vy: float
    vx: float


class ServoController:
    """State and update rule of Campbell's servo, issuing LAMMPS commands through ``command``.

    Each servo wall uses its own σ_n and gain; all share one update interval (the scene
    validation enforces it). ``update`` computes new wall velocities; ``apply`` issues the
    variables that realise the motion from the current time on and must be followed by a
    LAMMPS initialisation (``run … pre yes``), which also re-reads the box for fix deform.
    """

    def __init__(self, scene: Scene, dt: float | None):
        self.scene = scene
        # time-stepped engines update every n_steps; event-driven ones count collisions
        self.n_steps = servo_interval_steps(scene, dt) if dt is not None else 0
        self.walls = {
            w.side: WallMotion(w.side, scene.wall_position(w.side), 0.0, 0.0, w.velocity)
            for w in scene.walls
        }
        first = next(w.servo for w in scene.walls if w.servo is not None)
        self.scale_width, self.hold_shear_rate = first.scale_width, first.hold_shear_rate
        self.gap0 = self.gap
        self.shape = scene.box.size[0] / self.gap0  # width / gap, held when scale_width
        lower, upper = self.walls["lower"], self.walls["upper"]
        self.shear_rate = (upper.vx - lower.vx) / self.gap0
        self.t_last = 0.0

    @property
    def gap(self) -> float:
        return self.walls["upper"].y - self.walls["lower"].y

    @property
    def width_rate(self) -> float:
        if not self.scale_width:
            return 0.0
        return self.shape * (self.walls["upper"].vy - self.walls["lower"].vy)

    def advance(self, t: float) -> None:
        """Move the bookkeeping of the wall positions to time ``t``."""
        dt = t - self.t_last
        for wall in self.walls.values():
            wall.y += wall.vy * dt
            wall.x += wall.vx * dt
        self.t_last = t

    def update(self, t: float, normal_force: dict[str, float], width: float) -> None:
        """One servo step at time ``t``: ``normal_force[side]`` is the interval-mean y force of
        that wall on the particles, ``width`` the current periodic length along x."""
        self.advance(t)
        area = width * (self.scene.box.size[2] if self.scene.dimension == 3 else 1.0)
        for side, wall in self.walls.items():
            servo = self.scene.wall(side).servo
            if servo is None:
                continue
            # stress the particles exert on this wall (positive = pushing it outwards)
            sigma = (normal_force[side] if side == "lower" else -normal_force[side]) / area
            sigma_n = servo.normal_stress
            excess = sigma - sigma_n
            if servo.clamp:  # Campbell's rule
                excess = max(-sigma_n, min(sigma_n, excess))
            outward = -1.0 if side == "lower" else 1.0
            wall.vy = 0.5 * wall.vy + outward * servo.gain * excess
            if not math.isfinite(wall.vy):
                raise FloatingPointError(f"servo: non-finite wall velocity at t = {t}")
        if self.hold_shear_rate:
            lower, upper = self.walls["lower"], self.walls["upper"]
            upper.vx = lower.vx + self.shear_rate * self.gap

    def apply(self, command) -> None:
        """Issue the commands that realise the current wall motion from ``t_last`` on."""
        t = self.t_last
        for side, wall in self.walls.items():
            fid = wall_fix_id(side)
            y0 = wall.y - self.scene.wall_position(side)
            command(f"variable {fid}_dx equal {wall.x:.17g}+{wall.vx:.17g}*(time-{t:.17g})")
            command(f"variable {fid}_dy equal {y0:.17g}+{wall.vy:.17g}*(time-{t:.17g})")
        if self.scale_width:
            # the periodic boundaries move (no remap): images approach at the width rate;
            # a variable counted from now, since fix deform takes the box at each init
            rate = self.width_rate
            command(f"variable servo_dw equal {rate:.17g}*(time-{t:.17g})")
            command(f"variable servo_dw_rate equal {rate:.17g}")
            command("fix servo_width all deform 1 x variable v_servo_dw v_servo_dw_rate "
                    "remap none")

    def state(self) -> dict[str, float]:
        return {"gap": self.gap,
                "wall_position_lower": self.walls["lower"].y,
                "wall_position_upper": self.walls["upper"].y,
                "wall_velocity_upper": self.walls["upper"].vx}
