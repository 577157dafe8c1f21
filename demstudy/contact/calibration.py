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

__all__ = ["CollisionRow", "format_table", "incline_acceleration"]


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



def incline_acceleration(alpha: float, K: float, mu: float | None = None) -> float:
    """Acceleration (g = 1) down an incline of ``alpha`` degrees: rolling g sin a / (1 + K),
    or sliding g (sin a - mu cos a) when mu < K tan a / (1 + K)."""
    a = math.radians(alpha)
    if mu is not None and mu < K * math.tan(a) / (1.0 + K):
        return math.sin(a) - mu * math.cos(a)
    return math.sin(a) / (1.0 + K)



def _clean(x: float) -> float:
    return 0.0 if abs(x) < 1e-12 else x


def format_table(rows: Sequence[CollisionRow]) -> str:
    """Plain-text table of measured vs target e, beta and contact time (for ``demstudy``)."""
    head = (f"{'dim':>3} {'kind':>4} {'model':>5} {'angle':>6} {'speed':>6} {'e_tgt':>7} "
            f"{'e_meas':>8} {'b_tgt':>7} {'b_meas':>8} {'tc_tgt':>10} {'tc_meas':>10} "
            f"{'tc_err%':>7}")
    lines = [head, "-" * len(head)]
    for r in rows:
        err = 100.0 * (r.contact_time / r.contact_time_target - 1.0)
        lines.append(
            f"{r.dim:>3} {r.kind:>4} {r.model:>5} {r.angle:>6.1f} {r.speed:>6.3g} "
            f"{r.e_target:>7.4f} {r.e:>8.5f} {_clean(r.beta_target):>7.3f} {r.beta:>8.4f} "
            f"{r.contact_time_target:>10.4e} {r.contact_time:>10.4e} {err:>7.3f}")
    return "\n".join(lines)
