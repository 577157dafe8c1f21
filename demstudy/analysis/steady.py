"""Is a run steady? Campbell's (1982) criterion, made quantitative.

Campbell judged a run converged when the kinetic energy "fluctuates within about 20 % of its
mean with no trend" (§2.5). Here the trend is the least-squares straight line through the
production part of the kinetic-energy record: ``trend`` = (change of the fitted line over the
window) / (mean), and the run is called steady when |trend| < 0.2. Dimensionless.
"""

from __future__ import annotations

import numpy as np

STEADY_LIMIT = 0.2


def energy_trend(time: np.ndarray, energy: np.ndarray) -> float:
    """Relative change of the fitted kinetic energy over the window (NaN if undefined)."""
    time, energy = np.asarray(time, float), np.asarray(energy, float)
    ok = np.isfinite(time) & np.isfinite(energy)
    time, energy = time[ok], energy[ok]
    mean = energy.mean() if energy.size else 0.0
    if time.size < 3 or not mean > 0 or np.ptp(time) == 0:
        return float("nan")
    slope = np.polyfit(time - time.mean(), energy, 1)[0]
    return float(slope * np.ptp(time) / mean)


def is_steady(trend: float) -> bool:
    return bool(np.isfinite(trend) and abs(trend) < STEADY_LIMIT)
