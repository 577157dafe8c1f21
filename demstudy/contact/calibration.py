"""Binary-collision calibration, the engine-independent part: one measured collision
(:class:`CollisionRow`) against its analytic targets, the table ``demstudy calibrate``
prints, and the incline's analytic acceleration. Each soft-contact engine measures the rows
in its own binary collisions (``Backend.calibrate``).

Dimensionless particle units: d = 1, m = 1 (g = 1 on the incline).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

__all__ = ["CollisionRow", "MotionRow", "format_motion_table", "format_table",
           "incline_acceleration", "rolling_speed"]


@dataclass(frozen=True)
class CollisionRow:
    """One measured collision; angle from the normal in degrees, speed = |g| before impact."""

    dim: int
    kind: str
    model: str
    angle: float
    speed: float
    e: float
    beta: float
    contact_time: float
    e_target: float
    beta_target: float
    contact_time_target: float
    spin_after: float
    peak_force: float = math.nan
    peak_force_target: float = math.nan
    spin_before: float = 0.0


@dataclass(frozen=True)
class MotionRow:
    """One measured slow motion on a wall (``rolling`` incline, ``sliding`` to rolling)."""

    dim: int
    case: str
    quantity: str
    measured: float
    target: float



def incline_acceleration(alpha: float, K: float, mu: float | None = None) -> float:
    """Acceleration (g = 1) down an incline of ``alpha`` degrees: rolling g sin a / (1 + K),
    or sliding g (sin a - mu cos a) when mu < K tan a / (1 + K)."""
    a = math.radians(alpha)
    if mu is not None and mu < K * math.tan(a) / (1.0 + K):
        return math.sin(a) - mu * math.cos(a)
    return math.sin(a) / (1.0 + K)



def rolling_speed(v0: float, K: float) -> float:
    """Speed at which a particle launched sliding at v0 without spin on a rough horizontal wall
    starts rolling: friction conserves angular momentum about the contact point, m v0 d/2 =
    (m + I/R^2) v d/2, so v = v0 / (1 + K) (spheres 5/7, discs 2/3), whatever mu."""
    return v0 / (1.0 + K)


def _clean(x: float) -> float:
    return 0.0 if abs(x) < 1e-12 else x


def format_table(rows: Sequence[CollisionRow]) -> str:
    """Plain-text table of measured vs target e, beta, contact time and peak normal force."""
    head = (f"{'dim':>3} {'kind':>4} {'model':>5} {'angle':>6} {'speed':>6} {'spin0':>6} "
            f"{'e_tgt':>7} {'e_meas':>8} {'b_tgt':>7} {'b_meas':>8} {'tc_tgt':>10} "
            f"{'tc_meas':>10} {'tc_err%':>7} {'F_tgt':>10} {'F_meas':>10} {'F_err%':>7}")
    units = (f"{'':>3} {'':>4} {'':>5} {'[deg]':>6} {'[d/t]':>6} {'[1/t]':>6} {'':>7} {'':>8} "
             f"{'':>7} {'':>8} {'[t]':>10} {'[t]':>10} {'':>7} {'[m d/t2]':>10} "
             f"{'[m d/t2]':>10} {'':>7}")
    lines = [head, units, "-" * len(head)]
    for r in rows:
        err = 100.0 * (r.contact_time / r.contact_time_target - 1.0)
        ferr = 100.0 * (r.peak_force / r.peak_force_target - 1.0)
        lines.append(
            f"{r.dim:>3} {r.kind:>4} {r.model:>5} {r.angle:>6.1f} {r.speed:>6.3g} "
            f"{r.spin_before:>6.3g} {r.e_target:>7.4f} {r.e:>8.5f} {_clean(r.beta_target):>7.3f} "
            f"{r.beta:>8.4f} {r.contact_time_target:>10.4e} {r.contact_time:>10.4e} {err:>7.3f} "
            f"{r.peak_force_target:>10.4e} {r.peak_force:>10.4e} {ferr:>7.3f}")
    lines.append("e, b: normal and tangential restitution of the contact-point velocity (b target: "
                 "the spring's beta, or Walton's rule with mu); tc: contact time; F: peak normal "
                 "force (targets: damped Hooke oscillator or Hertz ODE). Units: d = m = 1, t "
                 "= the time unit of the speeds.")
    return "\n".join(lines)


def format_motion_table(rows: Sequence[MotionRow]) -> str:
    """Plain-text table of the incline (``rolling``) and ``sliding`` cases."""
    head = f"{'dim':>3} {'case':>8} {'quantity':>36} {'measured':>12} {'target':>12} {'err%':>8}"
    lines = [head, "-" * len(head)]
    for r in rows:
        err = 100.0 * (r.measured / r.target - 1.0)
        lines.append(f"{r.dim:>3} {r.case:>8} {r.quantity:>36} {r.measured:>12.6g} "
                     f"{r.target:>12.6g} {err:>8.3f}")
    lines.append("Units: d = m = g = 1 (speeds in sqrt(g d), accelerations in g).")
    return "\n".join(lines)
