"""Analyses of particle frames (dimensionless particle units: d = 1, m = 1).

Requires the compiled extension ``demstudy._native`` (build with
``pip install --no-build-isolation -e .`` at the repository root).
"""

from demstudy.analysis.base import AnalysisBase
from demstudy.analysis.blocking import BlockAccumulator, blocking_curve, jackknife
from demstudy.analysis.pair_correlation import PairCorrelation, slab_shell_volume
from demstudy.analysis.profiles import ProfileAnalysis
from demstudy.analysis.vdf import (
    VelocityDistribution,
    folded_maxwellian,
    velocity_distributions,
)
from demstudy.analysis.volumes import (
    bin_overlaps,
    bin_profile_sums,
    disc_strip_area,
    particle_volume,
    profile_nvalues,
    sphere_slab_volume,
)

__all__ = [
    "AnalysisBase",
    "BlockAccumulator",
    "PairCorrelation",
    "ProfileAnalysis",
    "VelocityDistribution",
    "bin_overlaps",
    "bin_profile_sums",
    "blocking_curve",
    "disc_strip_area",
    "folded_maxwellian",
    "jackknife",
    "particle_volume",
    "profile_nvalues",
    "slab_shell_volume",
    "sphere_slab_volume",
    "velocity_distributions",
]
