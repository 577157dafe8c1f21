"""Contact models: hard-particle collision rules (e, beta, mu) <-> soft-contact parameters.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts. ``mapping`` is pure
Python (Hooke and Hertz contacts with restitution damping and tangential springs);
``stiffness`` chooses a scene's stiffness and time step; ``calibration`` holds the rows and
table of binary-collision calibrations, which each soft-contact engine measures in its own
collisions (``demstudy calibrate``).
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
