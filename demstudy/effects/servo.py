"""Campbell's normal-stress servo: the state and update rule, shared by every engine.

Dimensionless particle units: d = 1, m = 1 (the wall speed sets the time scale in Couette
flow). Each update, every servo wall's normal velocity becomes
v ← ½ v ± gain · clamp(σ − σ_n, −σ_n, σ_n) (outwards when the particles push harder than σ_n;
``clamp = false`` drops the clamp), from the mean normal force σ of the particles on it over
the interval since the previous update. With ``scale_width`` the periodic width follows the
gap; with ``hold_shear_rate`` the upper wall's speed is rescaled with the gap. The simulation
loop (:mod:`demstudy.engines.simulation`) decides when to update and hands the new wall
motion to the engine, which realises it in its own way.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..scene import Scene

__all__ = ["ServoController", "WallMotion", "has_servo", "servo_samples", "servo_settings"]


def has_servo(scene: Scene) -> bool:
    return any(w.servo is not None for w in scene.walls)


def servo_settings(scene: Scene):
    """The servo settings the walls share (interval, width and shear-rate rules)."""
    return next(w.servo for w in scene.walls if w.servo is not None)


def servo_samples(scene: Scene) -> int:
    """Sample intervals between two servo updates in time-stepped engines, which update at
    sample ends: ``interval_time`` rounded to whole sample intervals (at least one)."""
    return max(1, round(servo_settings(scene).interval_time / scene.run.sample_interval))


@dataclass
class WallMotion:
    side: str
    y: float  # current position
    x: float  # current tangential displacement
    vy: float
    vx: float


class ServoController:
    """State and update rule of Campbell's servo (see the module docstring).

    Each servo wall uses its own σ_n and gain; all share one update interval (the scene
    validation enforces it). ``update`` computes new wall velocities; the engine then moves
    its walls accordingly."""

    def __init__(self, scene: Scene):
        self.scene = scene
        self.walls = {
            w.side: WallMotion(w.side, scene.wall_position(w.side), 0.0, 0.0, w.velocity)
            for w in scene.walls
        }
        first = servo_settings(scene)
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

    def state(self) -> dict[str, float]:
        return {"gap": self.gap,
                "wall_position_lower": self.walls["lower"].y,
                "wall_position_upper": self.walls["upper"].y,
                "wall_velocity_upper": self.walls["upper"].vx}
