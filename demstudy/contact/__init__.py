"""Contact models: hard-particle collision rules (e, beta, mu) <-> LAMMPS granular parameters.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts. ``mapping`` is pure
Python; ``calibrate`` runs isolated LAMMPS collisions to measure what the mapping promises.
"""

from demstudy.contact.mapping import (
    ContactParameters,
    HertzContact,
    HookeContact,
    damping_ratio,
    hertz_contact,
    hertz_kn_for_overlap,
    hooke_contact,
    hooke_kn_for_overlap,
    hooke_max_overlap,
    inertia_factor,
    kn_from_kappa,
    kn_from_kstar,
    make_contact,
    mass_scale,
    pair_mass,
    pair_radius,
    spring_beta,
    tangential_stiffness_for_beta,
    timestep,
    walton_beta,
)

__all__ = [
    "ContactParameters",
    "HertzContact",
    "HookeContact",
    "damping_ratio",
    "hertz_contact",
    "hertz_kn_for_overlap",
    "hooke_contact",
    "hooke_kn_for_overlap",
    "hooke_max_overlap",
    "inertia_factor",
    "kn_from_kappa",
    "kn_from_kstar",
    "make_contact",
    "mass_scale",
    "pair_mass",
    "pair_radius",
    "spring_beta",
    "tangential_stiffness_for_beta",
    "timestep",
    "walton_beta",
]
