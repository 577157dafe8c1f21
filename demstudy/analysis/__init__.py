"""Analyses of particle frames (dimensionless particle units: d = 1, m = 1).

Every statistic is registered by name in :mod:`demstudy.analysis.registry`; the classes and
functions below are importable from here, loaded on first use (importing the package stays
cheap: the engines' child processes import only what they run). The volume kernels need the
compiled extension ``demstudy._native``.
"""

from __future__ import annotations

from demstudy._lazy import lazy_exports

#: public name -> the module of this package that defines it
_WHERE = {
    'AnalysisBase': 'base',
    'BinMeans': 'velocity_correlation',
    'BlockAccumulator': 'blocking',
    'Box': 'box',
    'CoarseGrainedProfiles': 'coarse_graining',
    'CollisionAngles': 'collisions',
    'ContactStress': 'stress',
    'DensityWaves': 'waves',
    'NeighbourQuery': 'box',
    'OrientationalCorrelation': 'velocity_correlation',
    'PairCorrelation': 'pair_correlation',
    'ProfileAnalysis': 'profiles',
    'VelocityCorrelation': 'velocity_correlation',
    'VelocityDistribution': 'vdf',
    'bin_overlaps': 'volumes',
    'bin_profile_sums': 'volumes',
    'blocking_curve': 'blocking',
    'branch_fractions': 'stress',
    'branch_sums': 'stress',
    'classify_pattern': 'waves',
    'collisional_stress': 'stress',
    'disc_strip_area': 'volumes',
    'folded_maxwellian': 'vdf',
    'gaussian_kernel': 'coarse_graining',
    'jackknife': 'blocking',
    'kinetic_tensor': 'stress',
    'orientational_correlation': 'velocity_correlation',
    'particle_volume': 'volumes',
    'profile_nvalues': 'volumes',
    'savage_jeffrey_projected': 'collisions',
    'slab_shell_volume': 'pair_correlation',
    'sphere_slab_volume': 'volumes',
    'stress_results': 'stress',
    'velocity_correlations': 'velocity_correlation',
    'velocity_distributions': 'vdf',
    'wall_stress': 'stress',
}

__all__ = sorted(_WHERE)


__getattr__, __dir__ = lazy_exports(__name__, {k: f".{v}" for k, v in _WHERE.items()})
