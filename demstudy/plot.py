"""Figures from results files (dimensionless particle units: d = m = 1, g = 1 with gravity)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .io.results import read_results  # noqa: E402

PANELS = (
    ("solid_fraction", "solid fraction ν"),
    ("velocity", "mean velocity u_x"),
    ("temperature", "temperature T (per d.o.f.)"),
    ("rotational_temperature", "rotational temperature"),
)


def plot_profiles(paths: Sequence[str | Path], out: str | Path) -> Path:
    """ν, u and T (translational and rotational) against y, one curve per results file."""
    fig, axes = plt.subplots(1, len(PANELS), figsize=(4 * len(PANELS), 4.5), sharey=True)
    for path in paths:
        res = read_results(path)
        prof = res.profiles
        if not prof:
            raise ValueError(f"{path}: the results file holds no profiles")
        y = prof["y"]
        label = f"{res.attrs.get('scene_name', Path(path).stem)} ({res.attrs.get('engine')})"
        if "steady" in res.attrs and not res.attrs["steady"]:
            trend = 100 * res.attrs["kinetic_energy_trend"]
            label += f"\nNOT STEADY: kinetic energy changed {trend:+.0f} % over production"
        occupied = prof["solid_fraction"] > 1e-3
        for ax, (key, title) in zip(axes, PANELS, strict=True):
            if key not in prof:
                continue
            val, err = prof[key], prof.get(f"{key}_err")
            if val.ndim == 2:  # vectors: the flow (x) component
                val, err = val[:, 0], None if err is None else err[:, 0]
            mask = occupied if key != "solid_fraction" else np.ones_like(occupied)
            ax.errorbar(val[mask], y[mask], xerr=None if err is None else err[mask],
                        marker="o", ms=3, capsize=2, label=label)
            ax.set_xlabel(title)
            ax.grid(alpha=0.3)
    axes[0].set_ylabel(f"{res.profile_attrs.get('axis', 'y')} (particle diameters)")
    axes[0].legend(fontsize=8, loc="upper right")
    fig.suptitle("profiles in particle units: d = 1, m = 1, g = 1 (with gravity)", fontsize=9)
    fig.tight_layout()
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out
