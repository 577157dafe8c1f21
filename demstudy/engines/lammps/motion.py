"""Slow motions of one particle on a rough LAMMPS wall, against mechanics: rolling down an
incline (``rolling_acceleration``) and sliding on a level wall until it rolls
(``sliding_to_rolling``).

Dimensionless particle units: d = 1, m = 1, g = 1 (gravity on).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...contact.calibration import incline_acceleration, rolling_speed
from ...contact.mapping import ContactParameters, inertia_factor, make_contact
from .bodies import open_bodies, read_state

__all__ = ["RollingResult", "SlidingResult", "rolling_acceleration", "sliding_to_rolling"]


@dataclass(frozen=True)
class RollingResult:
    acceleration: float
    target: float
    contact: ContactParameters


def rolling_acceleration(dim: int, alpha: float = 30.0, e: float = 0.5, beta: float = 0.9,
                         mu: float | None = None, beta0: float | None = None, kn: float = 1e5,
                         steps_per_contact: float = 50, duration: float = 2.0,
                         samples: int = 40) -> RollingResult:
    """A disc (2D) or sphere (3D) released at rest on a rough wall, gravity tilted by ``alpha``
    degrees: fit x(t) = x0 + v0 t + a t^2 / 2 and compare with ``incline_acceleration``.

    Tangential: uncapped spring with ``beta`` (``mu`` None) or Coulomb with ``mu`` and ``beta0``
    (unset: e, the default everywhere). The particle starts at its static overlap
    g cos(alpha) / kn; the unloaded spring then oscillates about the rolling state, which
    averages out of the fit.
    """
    K = inertia_factor(dim)
    rule = {"mu": mu, "beta0": beta0} if mu is not None else {"beta": beta}
    params = make_contact(kn=kn, e=e, m_eff=1.0, K=K, **rule)
    a = math.radians(alpha)
    dt = params.timestep(steps_per_contact)
    y0 = 0.5 - math.cos(a) / kn
    lmp = open_bodies(dim, True, params, dt, [(-4.0, y0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0)],
                      gravity=(math.sin(a), -math.cos(a)))
    chunk = max(1, round(duration / samples / dt))
    ts, xs = [0.0], [-4.0]
    try:
        for i in range(1, samples + 1):
            lmp.command(f"run {chunk} pre no post no")
            ts.append(i * chunk * dt)
            xs.append(float(read_state(lmp, 1)[0][0, 0]))
    finally:
        lmp.close()
    coef = np.polyfit(np.array(ts), np.array(xs), 2)
    return RollingResult(2.0 * float(coef[0]), incline_acceleration(alpha, K, mu), params)


@dataclass(frozen=True)
class SlidingResult:
    """Final speed (mean over the last quarter) and the time the contact point stopped
    slipping, against v0 / (1 + K) and K v0 / ((1 + K) mu g)."""

    speed: float
    target: float
    roll_time: float
    roll_time_target: float
    contact: ContactParameters


def sliding_to_rolling(dim: int, v0: float = 1.0, mu: float = 0.3, e: float = 0.5,
                       beta0: float | None = None, kn: float = 1e5,
                       steps_per_contact: float = 50, samples: int = 400) -> SlidingResult:
    """A disc or sphere launched without spin at speed v0 along a level rough wall (gravity
    normal to it) slides, friction mu g slows it and spins it up, and it rolls from
    t = K v0 / ((1 + K) mu g) at v = v0 / (1 + K): 2/3 v0 for discs, 5/7 v0 for spheres.

    Coulomb contact with ``mu`` and ``beta0`` (unset: e). Runs for twice the rolling time;
    the final speed is the mean over the last quarter (the tangential spring rings about
    rolling), the rolling time the first sample with |slip| < 1 % of v0 (interpolated).
    """
    if mu <= 0.0:
        raise ValueError(f"mu must be > 0 for the particle to start rolling, not {mu}")
    K = inertia_factor(dim)
    params = make_contact(kn=kn, e=e, m_eff=1.0, K=K, mu=mu, beta0=beta0)
    dt = params.timestep(steps_per_contact)
    t_roll = K * v0 / ((1.0 + K) * mu)
    duration = 2.0 * t_roll
    lmp = open_bodies(dim, True, params, dt,
                      [(-4.0, 0.5 - 1.0 / kn, 0.0, v0, 0.0, 0.0, 0.0, 1.0, 1.0)],
                      gravity=(0.0, -1.0))
    chunk = max(1, round(duration / samples / dt))
    ts, vs, slips = [], [], []
    try:
        for i in range(1, samples + 1):
            lmp.command(f"run {chunk} pre no post no")
            _, v, w, _ = read_state(lmp, 1)
            ts.append(i * chunk * dt)
            vs.append(float(v[0, 0]))
            slips.append(float(v[0, 0] + 0.5 * w[0, 2]))  # contact point: v - R w x n, n = +y
    finally:
        lmp.close()
    slip = np.array(slips)
    stop = int(np.argmax(np.abs(slip) < 0.01 * v0))
    t_meas = float(np.interp(0.0, -slip[: stop + 1], ts[: stop + 1])) if stop else math.nan
    return SlidingResult(float(np.mean(vs[-samples // 4:])), rolling_speed(v0, K), t_meas,
                         t_roll, params)
