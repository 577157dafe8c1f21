"""Figures from results files (dimensionless particle units: d = m = 1, g = 1 with gravity).

The figures live in :mod:`demstudy.plots` (one module per family of kinds); this module keeps
the historical entry point ``from demstudy.plot import plot_profiles``.
"""

from __future__ import annotations

from .plots import (
    KINDS,
    draw,
    draw_angles,
    draw_gr,
    draw_lambda,
    draw_profiles,
    draw_stress,
    draw_vcorr,
    draw_vdf,
    draw_waves,
    plot_files,
    plot_profiles,
)

__all__ = ["KINDS", "draw", "draw_angles", "draw_gr", "draw_lambda", "draw_profiles",
           "draw_stress", "draw_vcorr", "draw_vdf", "draw_waves", "plot_files",
           "plot_profiles"]
