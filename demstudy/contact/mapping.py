"""Hard-particle collision rules (e, beta, mu) <-> soft LAMMPS ``granular`` contact parameters.

Units: dimensionless particle units, diameter d = 1, mass m = 1, g = 1 when gravity acts; every
function takes plain numbers (no scene objects), so other units work if used consistently.

Conventions
-----------
* ``m_eff`` is the reduced mass of the contact: ``pair_mass(m1, m2)`` (= m/2 for equal
  particles) for particle-particle contacts, the particle mass m for a particle against a wall.
* ``K = 4 I / (m d^2)``: discs K = 1/2, spheres K = 2/5 (``inertia_factor``).
* Normal: LAMMPS ``damping coeff_restitution``. For ``hooke`` it applies the force
  ``-eta_n * v_n`` with ``eta_n = 2 zeta sqrt(m_eff kn)``, ``zeta = -ln e / sqrt(pi^2 + ln^2 e)``,
  which gives restitution e exactly. For ``hertz`` (F = kn a delta, a = sqrt(R_eff delta))
  it uses ``eta_n = sqrt(5) zeta sqrt(m_eff kn a)``; integrating that damped Hertz oscillator
  (``hertz_contact``) shows it also restitutes with e exactly (to 1e-9) at every speed, and gives
  the speed-dependent contact time and maximum overlap.
* Tangential: an uncapped Hookean spring (no tangential damping) gives the constant tangential
  restitution ``beta = -cos(omega_t t_c)``, ``omega_t^2 = kt (1 + K) / (K m_eff)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Literal

import numpy as np

from . import discrete

Model = Literal["hooke", "hertz"]
Tangential = Literal["none", "spring", "coulomb"]



def default_beta0(e: float) -> float:
    """Walton's sticking tangential restitution when a Coulomb rule leaves beta0 unset: beta0 = e,
    everywhere (scenes, ``make_contact``, ``calibrate``, the CLI, the event-driven core).

    Why: the contact's tangential compliance is taken to dissipate like its normal one (same
    damping ratio), so a sticking impact restitutes its tangential velocity as its normal one;
    e = 1 gives the elastic limit beta0 = 1 (k_t = K/(1+K) k_n, 2/7 k_n for spheres). It is the
    one beta0 whose soft Coulomb-capped spring *is* Walton's rule: with the tangential oscillator
    a scaled copy of the normal one (``walton_copy``), F_t/F_n is constant through the contact,
    so the cap is reached at once (gross sliding, impulse mu J_n) or never (beta = beta0).
    """
    return e


# ---------------------------------------------------------------- masses, radii, inertia
def pair_mass(m1: float, m2: float) -> float:
    """Reduced mass m1 m2 / (m1 + m2) of a particle pair (m/2 for equal particles)."""
    return m1 * m2 / (m1 + m2)


def pair_radius(r1: float, r2: float) -> float:
    """Effective radius r1 r2 / (r1 + r2) of a pair (d/4 for equal particles; wall: r)."""
    return r1 * r2 / (r1 + r2)


def inertia_factor(dim: int) -> float:
    """K = 4 I / (m d^2) of a uniform disc (dim 2: 1/2) or sphere (dim 3: 2/5)."""
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, not {dim}")
    return 0.5 if dim == 2 else 0.4


# ---------------------------------------------------------------- Hooke normal contact
def damping_ratio(e: float) -> float:
    """zeta = -ln e / sqrt(pi^2 + ln^2 e): damping ratio of a linear contact with restitution e."""
    if not 0.0 < e <= 1.0:
        raise ValueError(f"restitution must lie in (0, 1], not {e}")
    le = math.log(e)
    return -le / math.hypot(math.pi, le)


@dataclass(frozen=True)
class HookeContact:
    """Damped linear normal contact: gamma_n = damping force per unit normal velocity."""

    kn: float
    e: float
    m_eff: float
    gamma_n: float
    contact_time: float


def hooke_contact(kn: float, e: float, m_eff: float) -> HookeContact:
    """Exact damping and contact time of LAMMPS ``hooke`` + ``damping coeff_restitution``.

    ``gamma_n = 2 zeta sqrt(m_eff kn)``; ``t_c = pi / sqrt(kn/m_eff - (gamma_n / (2 m_eff))^2)``
    (the contact ends when the overlap returns to zero; the force may turn slightly attractive
    just before, as LAMMPS does without ``limit_damping``).
    """
    gamma = 2.0 * damping_ratio(e) * math.sqrt(m_eff * kn)
    omega_d2 = kn / m_eff - (gamma / (2.0 * m_eff)) ** 2
    return HookeContact(kn, e, m_eff, gamma, math.pi / math.sqrt(omega_d2))


def hooke_peak_force(kn: float, e: float, m_eff: float, v: float) -> float:
    """Largest total normal force k_n delta + gamma_n delta' of a damped linear contact hit at
    normal speed v: v sqrt(m_eff k_n) times a factor of e alone (1 at e = 1, where it is the
    elastic k_n delta_max); the damping force adds at touch-down, the spring later."""
    z = damping_ratio(e)
    w0 = 1.0  # scaled units: k_n = m_eff = v = 1
    wd = math.sqrt(1.0 - z * z)
    t = np.linspace(0.0, math.pi / wd, 20001)
    delta = np.exp(-z * w0 * t) * np.sin(wd * t) / wd
    rate = np.exp(-z * w0 * t) * (np.cos(wd * t) - z / wd * np.sin(wd * t))
    return float(np.max(delta + 2.0 * z * rate)) * v * math.sqrt(m_eff * kn)


def _overlap_factor(e: float) -> float:
    """delta_max / (v sqrt(m_eff/kn)) = exp(-zeta arccos(zeta) / sqrt(1 - zeta^2))."""
    z = damping_ratio(e)
    return math.exp(-z * math.acos(z) / math.sqrt(1.0 - z * z))


def hooke_max_overlap(kn: float, e: float, m_eff: float, v: float) -> float:
    """Exact maximum overlap of a damped linear contact hit at normal speed v."""
    return v * math.sqrt(m_eff / kn) * _overlap_factor(e)


def hooke_kn_for_overlap(overlap: float, v: float, m_eff: float, e: float, d: float = 1.0) -> float:
    """kn giving maximum overlap ``overlap * d`` at normal impact speed v (damping included)."""
    return m_eff * (v * _overlap_factor(e) / (overlap * d)) ** 2


# ---------------------------------------------------------------- Hertz normal contact
def hertz_damping_constant(e: float) -> float:
    """LAMMPS hertz coeff_restitution prefactor sqrt(5) zeta(e) (eta_n = c sqrt(m_eff kn a))."""
    return math.sqrt(5.0) * damping_ratio(e)


@lru_cache(maxsize=256)
def _hertz_scaled(c: float) -> tuple[float, float, float, float]:
    """Solve x'' = -x^1.5 - c x^0.25 x', x(0) = 0, x'(0) = 1: return (e, t_c, x_max, F_max)."""
    from scipy.integrate import solve_ivp  # noqa: PLC0415 - ~0.25 s to import, Hertz only

    def rhs(_t: float, y: np.ndarray) -> list[float]:
        x = max(y[0], 0.0)
        return [y[1], -(x**1.5) - c * x**0.25 * y[1]]

    def leave(_t: float, y: np.ndarray) -> float:
        return y[0]

    leave.terminal = True  # type: ignore[attr-defined]
    leave.direction = -1  # type: ignore[attr-defined]
    sol = solve_ivp(rhs, (0.0, 50.0), [0.0, 1.0], events=leave, rtol=1e-11, atol=1e-13,
                    max_step=0.01, dense_output=True)
    t_c = float(sol.t_events[0][0])
    e = -float(sol.y_events[0][0][1])
    ts = np.linspace(0.0, t_c, 4001)
    x, xdot = sol.sol(ts)
    xp = np.maximum(x, 0.0)
    return e, t_c, float(x.max()), float(np.max(xp**1.5 + c * xp**0.25 * xdot))


@dataclass(frozen=True)
class HertzContact:
    """Damped Hertz contact at impact speed v: true e, contact time, maximum overlap."""

    kn: float
    e: float
    m_eff: float
    r_eff: float
    v: float
    contact_time: float
    max_overlap: float
    peak_force: float


def _hertz_scales(kn: float, m_eff: float, r_eff: float, v: float) -> tuple[float, float]:
    """Overlap scale delta0 = (m v^2 / (kn sqrt R))^(2/5) and time scale delta0 / v."""
    delta0 = (m_eff * v * v / (kn * math.sqrt(r_eff))) ** 0.4
    return delta0, delta0 / v


def hertz_contact(kn: float, e: float, m_eff: float, r_eff: float, v: float) -> HertzContact:
    """LAMMPS ``hertz kn e damping coeff_restitution`` hit at normal speed v.

    Force ``kn sqrt(r_eff) delta^1.5 + sqrt(5) zeta sqrt(m_eff kn) (r_eff delta)^(1/4) v_n``.
    The ODE's own restitution is returned as ``e`` (it equals the input to ~1e-9, at any v);
    t_c and delta_max scale as v^(-1/5) and v^(4/5).
    Undamped limit: t_c = 2.9432 delta_max / v, delta_max = (5 m v^2 / (4 kn sqrt R))^(2/5),
    peak force kn sqrt(R) delta_max^1.5 (``peak_force``: largest total normal force, damping
    included, in the force unit m_eff v^2 / delta0).
    """
    e_ode, tc, xmax, fmax = _hertz_scaled(round(hertz_damping_constant(e), 14))
    delta0, tau = _hertz_scales(kn, m_eff, r_eff, v)
    return HertzContact(kn, e_ode, m_eff, r_eff, v, tc * tau, xmax * delta0,
                        fmax * m_eff * v * v / delta0)


def hertz_kn_for_overlap(overlap: float, v: float, m_eff: float, r_eff: float, e: float,
                         d: float = 1.0) -> float:
    """Hertz kn giving maximum overlap ``overlap * d`` at normal speed v, restitution e."""
    x_max = _hertz_scaled(round(hertz_damping_constant(e), 14))[2]
    delta0 = overlap * d / x_max
    return m_eff * v * v / (math.sqrt(r_eff) * delta0**2.5)


# ---------------------------------------------------------------- stiffness scales, time step
def mass_scale(m: float, dim: int) -> float:
    """rho d^3 in terms of the particle mass: 6 m / pi (spheres); 4 m / pi for discs.

    2D convention: rho is the areal density of LAMMPS ``density/disc`` (m = rho pi d^2/4) and the
    disc has unit thickness, so "rho d^3" means rho d^2 x (thickness 1) = 4 m / pi.
    """
    inertia_factor(dim)
    return (6.0 if dim == 3 else 4.0) * m / math.pi


def kn_from_kstar(kstar: float, shear_rate: float, m: float, dim: int) -> float:
    """Hooke kn from k* = kn / (rho d^3 gamma_dot^2) (see ``mass_scale`` for rho d^3)."""
    return kstar * mass_scale(m, dim) * shear_rate**2


def kn_from_kappa(kappa: float, pressure: float, dim: int, d: float = 1.0) -> float:
    """Hooke kn from kappa = kn / (P d) in 3D (P force/area) or kn / P in 2D (P force/length)."""
    inertia_factor(dim)
    return kappa * pressure * (d if dim == 3 else 1.0)


def timestep(contact_time: float, steps_per_contact: float) -> float:
    """Time step resolving one contact duration with ``steps_per_contact`` steps."""
    if steps_per_contact <= 0:
        raise ValueError("steps_per_contact must be positive")
    return contact_time / steps_per_contact


# ---------------------------------------------------------------- tangential contact
def tangential_stiffness_for_beta(beta: float, K: float, m_eff: float,
                                  contact_time: float) -> float:
    """kt of an uncapped, undamped tangential spring giving tangential restitution beta.

    ``omega_t t_c = arccos(-beta)``, ``kt = K m_eff / (1 + K) omega_t^2``; beta = -1 -> kt = 0
    (smooth). beta must lie in [-1, 1].
    """
    if not -1.0 <= beta <= 1.0:
        raise ValueError(f"beta must lie in [-1, 1], not {beta}")
    omega_t = math.acos(-beta) / contact_time
    return K * m_eff / (1.0 + K) * omega_t**2


def spring_beta(kt: float, K: float, m_eff: float, contact_time: float) -> float:
    """Tangential restitution -cos(omega_t t_c) of an uncapped tangential spring."""
    return -math.cos(math.sqrt(kt * (1.0 + K) / (K * m_eff)) * contact_time)


def walton_beta(mu: float, beta0: float, e: float, K: float, ratio: float) -> float:
    """Walton's rule: beta = min(beta0, -1 + mu (1 + e) (1 + 1/K) / ratio), ratio = |g_t|/|g_n|.

    The second branch is a collision that slides throughout (Coulomb impulse mu J_n).
    """
    if ratio == 0.0:
        return beta0
    return min(beta0, -1.0 + mu * (1.0 + e) * (1.0 + 1.0 / K) / ratio)


# ---------------------------------------------------------------- the soft-contact parameter set
@dataclass(frozen=True)
class ContactParameters:
    """One soft contact (pair or wall), dimensionless particle units: Hooke or Hertz normal
    force with the restitution damping model (LAMMPS's ``damping coeff_restitution``) and a
    tangential spring, uncapped or Coulomb-capped.

    ``mu`` None means no Coulomb cap; ``contact_time`` is the damped normal contact time (for
    hertz at the impact speed the parameters were made for).
    ``tangential``: 'none' (smooth, no history), 'spring' (constant beta), 'coulomb' (capped).
    """

    model: Model
    kn: float
    restitution: float
    kt: float
    mu: float | None
    tangential: Tangential
    m_eff: float
    contact_time: float
    #: LAMMPS tangential damping factor x_gamma_t (eta_t = xt eta_n); 0 = undamped spring
    xt: float = 0.0
    #: Mindlin spring k_t a (a = contact radius, LAMMPS ``tangential mindlin``): the Hertz copy
    mindlin: bool = False
    #: steps per contact at which LAMMPS's discrete update restitutes e (``damping_e``) and an
    #: uncapped spring's beta (``discrete.spring_stiffness``); None: continuous formulas (dt -> 0)
    steps_per_contact: float | None = None
    #: the e given to LAMMPS's ``damping coeff_restitution`` when compensated for
    #: steps_per_contact (``discrete.damping_restitution``); None: ``restitution`` itself
    damping_e: float | None = None

    def __post_init__(self) -> None:
        if self.model not in ("hooke", "hertz"):
            raise ValueError(f"unknown normal model {self.model!r}")
        if self.tangential == "none" and (self.kt != 0.0 or self.mu is not None):
            raise ValueError("smooth contacts take kt = 0 and mu = None")
        if self.tangential == "spring" and self.mu is not None:
            raise ValueError("'spring' contacts are uncapped: mu must be None")
        if self.tangential == "coulomb" and (self.mu is None or self.mu < 0.0):
            raise ValueError("'coulomb' contacts need mu >= 0")
        if self.tangential not in ("none", "spring", "coulomb"):
            raise ValueError(f"unknown tangential model {self.tangential!r}")
        if self.xt < 0.0 or (self.xt and self.tangential != "coulomb"):
            raise ValueError("tangential damping xt >= 0 is only used by 'coulomb' contacts")
        if self.mindlin and (self.model != "hertz" or self.tangential != "coulomb"):
            raise ValueError("the Mindlin spring is only used by hertz 'coulomb' contacts")

    def timestep(self, steps_per_contact: float) -> float:
        return timestep(self.contact_time, steps_per_contact)

    @property
    def lammps_e(self) -> float:
        """The restitution written to LAMMPS (compensated for the time step when set)."""
        return self.restitution if self.damping_e is None else self.damping_e


def make_contact(*, kn: float, e: float, m_eff: float, K: float, beta: float | None = None,
                 mu: float | None = None, beta0: float | None = None, model: Model = "hooke",
                 r_eff: float | None = None, speed: float | None = None,
                 steps_per_contact: float | None = None, wall: bool = False
                 ) -> ContactParameters:
    """Contact parameters for a target (e, beta) or a Walton (e, mu, beta0) collision rule.

    * ``beta`` None or -1 and ``mu`` None: smooth; ``beta`` in (-1, 1] with ``mu`` None: uncapped
      spring; ``mu`` given: Coulomb cap mu with beta0 (default ``default_beta0(e)`` = e, as in
      scenes; ``beta`` is ignored then). ``beta0 == e`` gives the damped copy of the normal
      oscillator (``walton_copy``; a Mindlin spring k_t a for hertz), which follows Walton's
      rule; any other beta0 a linear spring with beta = beta0 when uncapped
      (``walton_mismatch`` says whether it follows).
    * hertz needs ``r_eff`` and the normal impact ``speed`` at which t_c (hence beta) is matched.
    * ``steps_per_contact`` (this contact's t_c / dt): an uncapped spring gets the k_t whose
      beta, averaged over impact phases, is the target in LAMMPS's discrete update at that time
      step (``discrete.spring_stiffness``: 8 % below the continuous k_t at 10 steps, 1.4 % at
      50), and every contact's damping the e whose phase-averaged discrete restitution is the
      target (``damping_e``; −0.010 of e = 0.5 at 10 steps, < 0.001 from e = 0.8); None keeps
      the continuous formulas. ``wall``: a particle on a flat wall (the
      model's geometry; equal particles of diameter 1, or 4 r_eff for hertz, otherwise).
    """
    if model == "hooke":
        tc = hooke_contact(kn, e, m_eff).contact_time
    else:
        if r_eff is None or speed is None:
            raise ValueError("hertz contacts need r_eff and the impact speed")
        tc = hertz_contact(kn, e, m_eff, r_eff, speed).contact_time
    xt, mindlin, e_damp = 0.0, False, None
    if steps_per_contact is not None:  # first without the tangential force, refined below
        e_damp = _compensated_e(e, kn, m_eff, tc, steps_per_contact, model, wall, r_eff, speed)
    if mu is not None:
        b0 = default_beta0(e) if beta0 is None else beta0
        if b0 <= -1.0:
            raise ValueError("a Coulomb contact needs beta0 > -1 (a tangential spring)")
        if abs(b0 - e) < 1e-9:
            kt, xt = walton_copy(kn, K)
            mindlin = model == "hertz"
        else:
            kt = tangential_stiffness_for_beta(b0, K, m_eff, tc)
        tangential = "coulomb"
    elif beta is None or beta == -1.0:
        kt, tangential = 0.0, "none"
    else:
        kt, tangential = tangential_stiffness_for_beta(beta, K, m_eff, tc), "spring"
        if steps_per_contact is not None:
            kt = _compensated_kt(beta, kn, e_damp, m_eff, K, tc, steps_per_contact, model,
                                 wall, r_eff, speed)
    if steps_per_contact is not None and tangential != "none":
        e_damp = _compensated_e(e, kn, m_eff, tc, steps_per_contact, model, wall, r_eff, speed,
                                (K, kt, xt, mu, mindlin))
        if tangential == "spring":
            kt = _compensated_kt(beta, kn, e_damp, m_eff, K, tc, steps_per_contact, model,
                                 wall, r_eff, speed)
    return ContactParameters(model, kn, e, kt, mu, tangential, m_eff, tc,  # type: ignore[arg-type]
                             xt, mindlin, steps_per_contact, e_damp)


def _radius(wall: bool, r_eff: float | None) -> float:
    """Particle radius of the model collision: unit particles for hooke (r_eff None)."""
    return 0.5 if r_eff is None else (r_eff if wall else 2.0 * r_eff)


def _compensated_e(e: float, kn: float, m_eff: float, tc: float, steps: float, model: Model,
                   wall: bool, r_eff: float | None, speed: float | None,
                   tangential: tuple = (0.4, 0.0, 0.0, None, False)) -> float:
    """``discrete.damping_restitution`` for this contact's geometry and tangential law
    ``(K, k_t, x_t, mu, mindlin)`` (default: none)."""
    if not steps > 0:
        raise ValueError(f"steps_per_contact must be positive, not {steps}")
    K, kt, xt, mu, mindlin = tangential
    return discrete.damping_restitution(float(e), float(kn), float(m_eff), tc, float(steps),
                                        model, wall, _radius(wall, r_eff),
                                        1.0 if speed is None else float(speed), float(K),
                                        float(kt), float(xt), mu, bool(mindlin))


def _compensated_kt(beta: float, kn: float, e: float, m_eff: float, K: float, tc: float,
                    steps: float, model: Model, wall: bool, r_eff: float | None,
                    speed: float | None) -> float:
    """``discrete.spring_stiffness`` for this contact's geometry; e: LAMMPS's (compensated)."""
    return discrete.spring_stiffness(float(beta), float(kn), float(e), float(m_eff), float(K),
                                     tc, float(steps), model, wall, _radius(wall, r_eff),
                                     1.0 if speed is None else float(speed))


def walton_copy(kn: float, K: float) -> tuple[float, float]:
    """(k_t, x_gamma_t) making the tangential oscillator a scaled copy of the damped normal one:
    k_t / m_t = k_n / m_eff and eta_t / m_t = eta_n / m_eff with m_t = K m_eff / (1 + K).
    Hooke: linear spring k_t; Hertz (F_n = k_n a delta): Mindlin spring k_t a, same a.

    Then F_t / F_n = K/(1+K) |g_t|/|g_n| at every instant, so a contact sticks throughout (beta
    = e) or slides throughout (Coulomb impulse mu J_n): Walton's rule with beta0 = e, exactly.
    """
    c = K / (1.0 + K)
    return c * kn, c


#: largest |beta_soft - beta_Walton| over impact angles that scenes accept for a Coulomb rule
WALTON_TOLERANCE = 0.02
#: lowest e for which the damped copy (beta0 = e) stays within WALTON_TOLERANCE: below, the
#: attractive end of the damped normal force adds mu |F_n| of tangential impulse (0.015 at
#: e = 0.7, 0.041 at e = 0.5; docs/contact.md)
WALTON_MIN_E = 0.7
#: lowest e for which beta0 = 1 (undamped spring, omega_t t_c = pi) stays within the tolerance
WALTON_MIN_E_ELASTIC = 0.9
#: lowest e for which the Hertz (Mindlin) copy stays within the tolerance (-0.018 at e = 0.9,
#: pairs at |g| = 1; -0.031 at e = 0.7)
WALTON_MIN_E_HERTZ = 0.9


def walton_mismatch(e: float, beta0: float | None, model: Model) -> str | None:
    """Why the soft Coulomb-capped spring cannot stand for Walton's rule (e, beta0), or None.

    It follows Walton only when F_t/F_n stays constant through the contact (tangential and
    normal oscillators alike): beta0 = e with the damped copy (Hooke e >= WALTON_MIN_E, Hertz
    e >= WALTON_MIN_E_HERTZ), or beta0 = 1 for nearly elastic Hooke contacts
    (e >= WALTON_MIN_E_ELASTIC). Any other beta0 gives a
    spring that reaches the cap late or lets go early: beta0 = 0, e = 0.98, mu = 0.092 rebounds
    from a wall at 40 deg with 12 % too little spin (beta 0.23 below Walton's at 30 deg).
    """
    b0 = default_beta0(e) if beta0 is None else beta0
    if model == "hertz":
        if abs(b0 - e) < 1e-9 and e >= WALTON_MIN_E_HERTZ:
            return None
        return (f"with a Hertz normal force only the Mindlin copy (beta0 = e, e >= "
                f"{WALTON_MIN_E_HERTZ}) follows Walton's rule within {WALTON_TOLERANCE}; "
                f"beta0 = {b0:g} at e = {e:g} does not (docs/contact.md)")
    if abs(b0 - e) < 1e-9 and e >= WALTON_MIN_E:
        return None
    if b0 == 1.0 and e >= WALTON_MIN_E_ELASTIC:
        return None
    return (f"a Coulomb-capped soft spring follows Walton's rule within {WALTON_TOLERANCE} only "
            f"for beta0 = e with e >= {WALTON_MIN_E} (the default) or beta0 = 1 with e >= "
            f"{WALTON_MIN_E_ELASTIC}; beta0 = {b0:g} at e = {e:g} misses it by up to ~0.2 near "
            "the stick/slip crossover (docs/contact.md)")
