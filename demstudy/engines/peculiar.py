"""Peculiar (fluctuation) kinetic observables of a y-periodic box, shared by the backends.

Dimensionless particle units: d = 1, m = 1 (mass ∝ d^dim); the shear rate (Lees–Edwards) or
the initial temperature sets the time unit.

A pressure or a granular temperature measures the velocity fluctuations about the local mean
flow, not the mean flow itself: under Lees–Edwards shear the streaming profile
u = γ̇ y x̂ carries a kinetic energy N m γ̇² L_y²/24 that grows with the box and is no
pressure. In a y-periodic box (no walls) the mean flow is known: the imposed streaming
profile (slope γ̇, zero without shear) plus a uniform velocity, the mass-weighted mean of
v − γ̇ y x̂ (the offset of the profile, a centre-of-mass drift). This is the same fluctuation
``/stress``'s kinetic part and the ``/profiles`` temperatures measure (about each bin's
mean), up to the profile's variation inside a bin, γ̇² h²/12 in ⟨u'²⟩ for bins of width h.

Why the imposed profile and not each bin's own mean: a bin's instantaneous mean of a few
particles takes 1/N_bin of their thermal energy with it (a dilute gas's pressure would come
out low by that), while the imposed profile is exact for the homogeneous shear these boxes
make. A flow whose mean profile departs from it (shear bands, a plug in a dense box) keeps
the departure's kinetic energy, ⟨ρ (u − γ̇ y)²⟩/2 per volume, in these observables; the
``/stress`` and ``/profiles`` routes, which subtract each bin's time-averaged mean, do not:
compare them when a band is suspected.
"""

from __future__ import annotations

import numpy as np

__all__ = ["peculiar_observables", "peculiar_velocity"]


def peculiar_velocity(position: np.ndarray, velocity: np.ndarray, mass: np.ndarray,
                      shear_rate: float = 0.0) -> np.ndarray:
    """v − u(y), u = (γ̇ y + c) x̂ + V_⊥ with c and V_⊥ the mass-weighted means of
    v − γ̇ y x̂ (the offset and the drift fitted with the imposed slope γ̇). Any origin of
    y gives the same result (it moves into c)."""
    v = np.array(velocity, float)  # a copy: the caller's velocities stay as they are
    if shear_rate:
        v[:, 0] -= shear_rate * np.asarray(position, float)[:, 1]
    m = np.asarray(mass, float)
    v -= (m[:, None] * v).sum(0) / m.sum()
    return v


def peculiar_observables(position: np.ndarray, velocity: np.ndarray, mass: np.ndarray,
                         shear_rate: float = 0.0) -> dict[str, float]:
    """``peculiar_kinetic_energy`` ½ Σ m v'² and ``temperature`` Σ m v'²/(dim N) (per
    translational degree of freedom, energy units) of the fluctuations about the mean flow
    (:func:`peculiar_velocity`)."""
    v = peculiar_velocity(position, velocity, mass, shear_rate)
    twice = float(np.sum(np.asarray(mass, float)[:, None] * v**2))
    n, dim = v.shape
    return {"peculiar_kinetic_energy": 0.5 * twice,
            "temperature": twice / (dim * n) if n else float("nan")}
