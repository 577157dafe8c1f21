"""Hard-disc / hard-sphere kinetic theory: contact value g0, equation of state, Enskog
collision frequency and mean free path, Haff's homogeneous cooling law.

Conventions (stated once, used everywhere in :mod:`demstudy.theory`)
------------------------------------------------------------------
* ``dim`` = 2 (discs) or 3 (spheres); ``nu`` the solid (area / volume) fraction; ``sigma`` the
  diameter (default 1, particle units d = 1, m = 1); ``n`` the number density
  (n = nu / V_1 with V_1 = pi sigma^2 / 4 or pi sigma^3 / 6).
* ``T`` is the granular temperature **per translational degree of freedom, in energy units**:
  T = m <C_a^2> for each component a (so the kinetic energy per particle is dim T / 2, and
  the velocity variance per component is T / m). This is ``temperature`` of ``/profiles``
  times 1 (m = 1).
* Equation of state (elastic Enskog gas; Jenkins & Richman / Lun et al. for e < 1):
  p = n T Z with Z = 1 + (1 + e) nu g0 (2D) and Z = 1 + 2 (1 + e) nu g0 (3D). For e = 1:
  **Z = 1 + 2 nu g0 (discs) and Z = 1 + 4 phi g0 (spheres)**, i.e. Z = 1 + b n g0 with the
  second virial coefficient b = pi sigma^2 / 2 (2D), 2 pi sigma^3 / 3 (3D). (The 3D
  form "1 + 2 phi g0" sometimes quoted is wrong by a factor of 2: with Carnahan-Starling g0 the
  form 1 + 4 phi g0 reproduces the CS equation of state Z = (1 + phi + phi^2 - phi^3)/(1 - phi)^3
  and the exact second and third virial coefficients 4 and 10.)
* Collision frequency per particle (Enskog: Boltzmann times g0, molecular chaos):
  2D: omega = 2 n sigma g0 sqrt(pi T / m) (cross-section 2 sigma); 3D:
  omega = 4 n sigma^2 g0 sqrt(pi T / m) (cross-section pi sigma^2). Mean free path
  lambda = <|c|> / omega: 2D 1 / (2 sqrt(2) n sigma g0), 3D 1 / (sqrt(2) pi n sigma^2 g0).
  Each collision counts once for each partner (so N omega / 2 collisions per unit time).
* Haff's law (smooth inelastic particles, constant normal restitution e, homogeneous cooling
  state with a Maxwellian, no rotational degrees of freedom: dim translational degrees of
  freedom per particle): dT/dt = -(1 - e^2) omega(T) T / dim = -zeta0 T^(3/2), hence
  T(t) = T0 / (1 + t / t0)^2 with t0 = 2 dim / ((1 - e^2) omega(T0)).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "campbell_chi",
    "carnahan_starling_g0",
    "collision_frequency",
    "compressibility",
    "contact_value",
    "cooling_rate",
    "haff_t0",
    "haff_temperature",
    "henderson_g0",
    "mean_free_path",
    "mean_speed",
    "number_density",
    "pressure",
    "unit_volume",
]


def _dim(dim: int) -> int:
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim!r}")
    return dim


def unit_volume(dim: int, sigma: float = 1.0) -> float:
    """Volume (area in 2D) of one particle of diameter sigma: pi s^2/4 or pi s^3/6."""
    return math.pi * sigma**2 / 4 if _dim(dim) == 2 else math.pi * sigma**3 / 6


def number_density(nu: ArrayLike, dim: int, sigma: float = 1.0) -> np.ndarray:
    """n = nu / V_1."""
    return np.asarray(nu, float) / unit_volume(dim, sigma)


def carnahan_starling_g0(phi: ArrayLike) -> np.ndarray:
    """Carnahan-Starling contact value for hard spheres: (1 - phi/2) / (1 - phi)^3."""
    phi = np.asarray(phi, float)
    return (1 - 0.5 * phi) / (1 - phi) ** 3


def henderson_g0(nu: ArrayLike) -> np.ndarray:
    """Henderson (1975) contact value for hard discs: (1 - 7 nu / 16) / (1 - nu)^2."""
    nu = np.asarray(nu, float)
    return (1 - 7 * nu / 16) / (1 - nu) ** 2


def contact_value(nu: ArrayLike, dim: int) -> np.ndarray:
    """g0: Henderson for discs (dim = 2), Carnahan-Starling for spheres (dim = 3)."""
    return henderson_g0(nu) if _dim(dim) == 2 else carnahan_starling_g0(nu)


def compressibility(nu: ArrayLike, dim: int, restitution: float = 1.0) -> np.ndarray:
    """Z = p / (n T): 1 + (1 + e) nu g0 (2D), 1 + 2 (1 + e) nu g0 (3D)."""
    nu = np.asarray(nu, float)
    factor = 1.0 if _dim(dim) == 2 else 2.0
    return 1 + factor * (1 + restitution) * nu * contact_value(nu, dim)


def pressure(
    nu: ArrayLike,
    temperature: ArrayLike,
    dim: int,
    restitution: float = 1.0,
    sigma: float = 1.0,
) -> np.ndarray:
    """p = n T Z (T per degree of freedom, energy units)."""
    return (
        number_density(nu, dim, sigma)
        * np.asarray(temperature, float)
        * compressibility(nu, dim, restitution)
    )


def mean_speed(temperature: ArrayLike, dim: int, mass: float = 1.0) -> np.ndarray:
    """<|c|> of a Maxwellian: sqrt(pi T / (2 m)) (2D), sqrt(8 T / (pi m)) (3D)."""
    t = np.asarray(temperature, float) / mass
    return np.sqrt(np.pi * t / 2) if _dim(dim) == 2 else np.sqrt(8 * t / np.pi)


def collision_frequency(
    nu: ArrayLike, temperature: ArrayLike, dim: int, sigma: float = 1.0, mass: float = 1.0
) -> np.ndarray:
    """Enskog collisions per particle per unit time (each collision counted for both partners):
    2 n sigma g0 sqrt(pi T/m) (2D), 4 n sigma^2 g0 sqrt(pi T/m) (3D)."""
    n = number_density(nu, dim, sigma)
    g0 = contact_value(nu, dim)
    root = np.sqrt(np.pi * np.asarray(temperature, float) / mass)
    return 2 * n * sigma * g0 * root if dim == 2 else 4 * n * sigma**2 * g0 * root


def mean_free_path(nu: ArrayLike, dim: int, sigma: float = 1.0) -> np.ndarray:
    """Enskog mean free path <|c|>/omega: 1/(2 sqrt2 n s g0) (2D), 1/(sqrt2 pi n s^2 g0) (3D)."""
    n = number_density(nu, dim, sigma)
    g0 = contact_value(nu, dim)
    if dim == 2:
        return 1 / (2 * math.sqrt(2) * n * sigma * g0)
    return 1 / (math.sqrt(2) * math.pi * n * sigma**2 * g0)


def cooling_rate(
    nu: ArrayLike,
    temperature: ArrayLike,
    dim: int,
    restitution: float,
    sigma: float = 1.0,
    mass: float = 1.0,
) -> np.ndarray:
    """Homogeneous cooling rate zeta = -(dT/dt)/T = (1 - e^2) omega / dim (smooth particles)."""
    omega = collision_frequency(nu, temperature, dim, sigma, mass)
    return (1 - restitution**2) * omega / dim


def haff_t0(
    nu: float,
    temperature0: float,
    dim: int,
    restitution: float,
    sigma: float = 1.0,
    mass: float = 1.0,
) -> float:
    """Haff time t0 = 2 / zeta(T0) = 2 dim / ((1 - e^2) omega(T0))."""
    if not 0 <= restitution < 1:
        raise ValueError("Haff's law needs 0 <= e < 1")
    return float(2 / cooling_rate(nu, temperature0, dim, restitution, sigma, mass))


def haff_temperature(
    t: ArrayLike,
    nu: float,
    temperature0: float,
    dim: int,
    restitution: float,
    sigma: float = 1.0,
    mass: float = 1.0,
) -> np.ndarray:
    """T(t) = T0 / (1 + t/t0)^2 (homogeneous cooling of smooth inelastic discs/spheres)."""
    t0 = haff_t0(nu, temperature0, dim, restitution, sigma, mass)
    return temperature0 / (1 + np.asarray(t, float) / t0) ** 2


def campbell_chi(nu: ArrayLike, dim: int, restitution: float = 1.0) -> np.ndarray:
    """Campbell's equation-of-state function chi(nu) from kinetic theory.

    Campbell defines p = rho_p chi(nu) (<u'^2> + <v'^2>) (2D; rho_p the material density).
    With p = n T Z, n m = rho_p nu and T = m (<u'^2> + <v'^2>) / 2 this gives
    chi = nu Z / 2; in 3D with the sum over all three components, chi = nu Z / 3.
    """
    return np.asarray(nu, float) * compressibility(nu, dim, restitution) / _dim(dim)
