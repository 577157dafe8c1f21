"""Analyses of particle frames (dimensionless particle units: d = 1, m = 1).

Requires the compiled extension ``demstudy._native`` (build with
``pip install --no-build-isolation -e .`` at the repository root).
"""

from demstudy.analysis.base import AnalysisBase
from demstudy.analysis.blocking import BlockAccumulator, blocking_curve, jackknife
from demstudy.analysis.coarse_graining import CoarseGrainedProfiles, gaussian_kernel
from demstudy.analysis.collisions import CollisionAngles, savage_jeffrey_projected
from demstudy.analysis.pair_correlation import PairCorrelation, slab_shell_volume
from demstudy.analysis.profiles import ProfileAnalysis
from demstudy.analysis.stress import (
    ContactStress,
    branch_fractions,
    branch_sums,
    collisional_stress,
    kinetic_tensor,
    stress_results,
    wall_stress,
)
from demstudy.analysis.vdf import (
    VelocityDistribution,
    folded_maxwellian,
    velocity_distributions,
)
from demstudy.analysis.velocity_correlation import (
    BinMeans,
    OrientationalCorrelation,
    VelocityCorrelation,
    orientational_correlation,
    velocity_correlations,
)
from demstudy.analysis.volumes import (
    bin_overlaps,
    bin_profile_sums,
    disc_strip_area,
    particle_volume,
    profile_nvalues,
    sphere_slab_volume,
)
from demstudy.analysis.waves import DensityWaves, classify_pattern

__all__ = [
    "AnalysisBase",
    "BinMeans",
    "BlockAccumulator",
    "CollisionAngles",
    "ContactStress",
    "CoarseGrainedProfiles",
    "DensityWaves",
    "OrientationalCorrelation",
    "PairCorrelation",
    "ProfileAnalysis",
    "VelocityCorrelation",
    "VelocityDistribution",
    "bin_overlaps",
    "bin_profile_sums",
    "blocking_curve",
    "branch_fractions",
    "branch_sums",
    "collisional_stress",
    "classify_pattern",
    "disc_strip_area",
    "folded_maxwellian",
    "gaussian_kernel",
    "jackknife",
    "kinetic_tensor",
    "orientational_correlation",
    "particle_volume",
    "profile_nvalues",
    "savage_jeffrey_projected",
    "slab_shell_volume",
    "sphere_slab_volume",
    "stress_results",
    "velocity_correlations",
    "velocity_distributions",
    "wall_stress",
]
