"""LAMMPS's discrete update of one binary collision, step by step, in plain numpy: what a
soft contact restitutes at a finite time step, and the k_t that restitutes a target β there.

Units: dimensionless particle units, d = 1, m = 1 (no gravity; the impact speed sets the time
scale, and β does not depend on it for Hooke contacts).

Why: an uncapped tangential spring (``linear_history``) integrated by LAMMPS restitutes
β = −cos(ω_t t_c) + ≈ 0.9 / S at S steps per contact (e = 0.9, β = 0.5), where the
continuous formula (``mapping.tangential_stiffness_for_beta``) assumes S → ∞. The error is
first order in dt because LAMMPS adds v_t dt to the tangential history in the same step
that first sees the overlap, with the velocity of the half step before it: the spring starts
preloaded by about half a step's displacement (a phase lead ω_t dt / 2). The normal
restitution drifts less (the damping force sees the half-step normal velocity): phase-averaged
−0.010 at e = 0.5, −0.003 at e = 0.7, < 0.001 from e = 0.8 at 10 steps; it is compensated
too (``damping_restitution``).

The model replays, for an array of impact phases at once, what ``pair_style granular`` /
``fix wall/gran granular`` with ``fix nve/sphere`` do (LAMMPS 22Jul2025,
src/GRANULAR/granular_model.cpp, gran_sub_mod_tangential.cpp, fix_nve_sphere.cpp):

1. initial integrate: v += dt/2 f/m, ω += dt/2 τ/I, x += dt v;
2. force, with x(t + dt) and the half-step v, ω: overlap δ = R_i + R_j − r, n = x_ij / r;
   g_t = v_t − (R_i ω_i + R_j ω_j) × n; the history ξ is projected onto the tangent plane
   (magnitude kept), then ξ += g_t dt; F_t = −k_t ξ − η_t g_t, capped at μ |F_n| (then
   ξ = −(F_t + η_t g_t)/k_t); torque −(R − δ/2) n × F_t on each particle of a pair,
   −R n × F_t against a wall; no overlap: no force and ξ = 0;
3. final integrate: v += dt/2 f/m, ω += dt/2 τ/I.

Equal particles in the plane of impact (the 3D sphere moves in that plane too); the pair's
centre of mass at rest, so its relative coordinates suffice. e and β are measured as
``engines.lammps.calibrate.impact`` does: along the direction of the total normal impulse.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

#: impact phases (first overlap this fraction of a step after a step) averaged over: in a flow
#: the phase of each collision is uniformly random, and β(phase) varies by ~±1/S around its mean
PHASES = 16
#: LAMMPS's threshold on the history's normal component before it is rotated
_EPSILON = 1e-10


@dataclass(frozen=True)
class DiscreteContact:
    """The LAMMPS contact model of one collision (``mapping.ContactParameters`` plus geometry):
    Hooke F_n = k_n δ or Hertz k_n a δ (a = √(R_eff δ)), restitution damping for e;
    tangential spring k_t (Mindlin: k_t a), damping x_t η_n, Coulomb cap μ (None: uncapped)."""

    kn: float
    e: float
    m_eff: float
    K: float
    kt: float
    xt: float = 0.0
    mu: float | None = None
    model: str = "hooke"
    mindlin: bool = False
    wall: bool = False
    #: particle radius (equal particles; a flat wall has none)
    radius: float = 0.5

    @property
    def r_eff(self) -> float:
        return self.radius if self.wall else self.radius / 2

    @classmethod
    def of(cls, p, K: float, wall: bool = False, radius: float = 0.5) -> DiscreteContact:
        """The model of ``mapping.ContactParameters`` p as LAMMPS gets it (``p.lammps_e``)."""
        return cls(p.kn, p.lammps_e, p.m_eff, K, p.kt, p.xt, p.mu, p.model, p.mindlin, wall,
                   radius)


def _damp_constant(model: str, e: float) -> float:
    """LAMMPS coeff_restitution: η_n = c √(m_eff k_n) (Hooke) or c √(m_eff k_n a) (Hertz)."""
    le = math.log(e)
    zeta = -le / math.hypot(math.pi, le)
    return 2.0 * zeta if model == "hooke" else math.sqrt(5.0) * zeta


def collide(c: DiscreteContact, dt: float, angle: float, speed: float = 1.0,
            phases: np.ndarray | float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """(e, β) of one collision per phase: relative speed ``speed`` at ``angle`` degrees from the
    inward normal, no spin, first overlap ``phase`` steps after the start (0 < phase <= 1)."""
    ph = np.atleast_1d(np.asarray(phases, dtype=float))
    if not (0.0 <= angle < 90.0 and speed > 0.0 and dt > 0.0 and np.all((ph > 0) & (ph <= 1))):
        raise ValueError("need 0 <= angle < 90, speed > 0, dt > 0 and 0 < phase <= 1")
    n_ph, r = ph.size, c.radius
    radsum = r if c.wall else 2.0 * r
    # reduced masses: relative acceleration F / m_eff; d(R_i ω_i + R_j ω_j)/dt per unit torque
    # arm factor: the wall's particle has m = m_eff, a pair's particles m = 2 m_eff each
    m_body = c.m_eff if c.wall else 2.0 * c.m_eff
    inertia = c.K * m_body * r * r
    th = math.radians(angle)
    g0 = np.array([speed * math.sin(th), -speed * math.cos(th)])
    x = np.zeros((n_ph, 2))
    x[:, 1] = radsum
    x -= np.outer(ph * dt, g0)
    v = np.tile(g0, (n_ph, 1))
    w = np.zeros(n_ph)  # W = R_i ω_i + R_j ω_j (a pair's equal spins: 2 R ω)
    acc = np.zeros((n_ph, 2))
    wdot = np.zeros(n_ph)
    hist = np.zeros((n_ph, 2))
    impulse = np.zeros((n_ph, 2))
    damp_c = _damp_constant(c.model, c.e)
    touched = np.zeros(n_ph, dtype=bool)
    done = np.zeros(n_ph, dtype=bool)
    h = 0.5 * dt
    for _ in range(100_000):
        v += h * acc
        w += h * wdot
        x += dt * v
        if c.wall:
            dist = x[:, 1].copy()
            nx = np.zeros_like(x)
            nx[:, 1] = 1.0
        else:
            dist = np.linalg.norm(x, axis=1)
            nx = x / dist[:, None]
        delta = radsum - dist
        on = delta > 0.0
        touched |= on
        done |= touched & ~on
        if done.all():
            break
        dpos = np.where(on, delta, 0.0)
        vn = np.einsum("ij,ij->i", v, nx)
        tan = np.stack([-nx[:, 1], nx[:, 0]], axis=1)  # z × n
        vtr = v - vn[:, None] * nx - w[:, None] * tan
        a = np.ones(n_ph) if c.model == "hooke" else np.sqrt(c.r_eff * dpos)
        k_n = c.kn * a
        eta_n = damp_c * np.sqrt(c.m_eff * k_n)
        fn = np.where(on, k_n * dpos - eta_n * vn, 0.0)
        # history: project onto the tangent plane keeping its magnitude, then add g_t dt
        kt = c.kt * (a if c.mindlin else np.ones(n_ph))
        rsht = np.einsum("ij,ij->i", hist, nx)
        mag = np.linalg.norm(hist, axis=1)
        rot = on & (np.abs(rsht) * kt > _EPSILON * (c.mu if c.mu is not None else 1e20)
                    * np.abs(fn))
        proj = hist - rsht[:, None] * nx
        pm = np.linalg.norm(proj, axis=1)
        scale = np.where(pm > 0.0, mag / np.where(pm > 0.0, pm, 1.0), 0.0)
        hist = np.where(rot[:, None], proj * scale[:, None], hist)
        hist = np.where(on[:, None], hist + dt * vtr, 0.0)
        fdamp = -(c.xt * eta_n)[:, None] * vtr
        fs = -kt[:, None] * hist + fdamp
        if c.mu is not None:
            cap = c.mu * np.abs(fn)
            fmag = np.linalg.norm(fs, axis=1)
            over = on & (fmag > cap) & (np.linalg.norm(hist, axis=1) > 0.0)
            sc = np.where(over, cap / np.where(fmag > 0, fmag, 1.0), 1.0)
            fs = fs * sc[:, None]
            safe = np.where(kt > 0.0, kt, 1.0)[:, None]
            hist = np.where(over[:, None], -(fs - fdamp) / safe, hist)
        fs = np.where(on[:, None], fs, 0.0)
        force = fn[:, None] * nx + fs
        impulse += fn[:, None] * nx
        arm = np.ones(n_ph) * r if c.wall else 2.0 * (r - 0.5 * dpos)  # R_i, R_j arms summed
        torque = -(nx[:, 0] * fs[:, 1] - nx[:, 1] * fs[:, 0])
        acc = force / c.m_eff
        wdot = torque * arm * r / inertia
        v += h * acc
        w += h * wdot
    else:
        raise RuntimeError("the discrete collision never ended")
    ncol = impulse / np.linalg.norm(impulse, axis=1)[:, None]
    tan = np.stack([-ncol[:, 1], ncol[:, 0]], axis=1)
    gn0 = ncol @ g0
    gt0 = g0 - gn0[:, None] * ncol
    g1 = v - w[:, None] * tan
    gn1 = np.einsum("ij,ij->i", g1, ncol)
    gt1 = g1 - gn1[:, None] * ncol
    gt_sq = np.einsum("ij,ij->i", gt0, gt0)
    beta = np.where(gt_sq > 1e-24 * speed**2,
                    -np.einsum("ij,ij->i", gt1, gt0) / np.where(gt_sq > 0, gt_sq, 1.0), np.nan)
    return -gn1 / gn0, beta


def phases(n: int = PHASES) -> np.ndarray:
    """Midpoints of n equal phase bins in (0, 1]: the average over uniformly random phases."""
    return (np.arange(n) + 0.5) / n


#: above this many steps per contact the continuous k_t is kept (β drifts by ≲ 0.002 there)
MAX_COMPENSATED_STEPS = 500.0
#: impact angle (degrees from the normal) of the model collisions: β depends on it only
#: through the line of centres' turn during a pair contact (±0.001 between 20 and 70 degrees)
ANGLE = 45.0


def _n_phases(steps: float) -> int:
    """Phases that resolve the jump of β(phase) (≈ 1.8 / S, where a contact gains a step)
    to < 5e-4 in the mean; the cost, phases × steps, stays ≈ 2000 collision steps."""
    return int(np.clip(math.ceil(2000.0 / steps), 8, 256))


def mean_restitution(c: DiscreteContact, contact_time: float, steps_per_contact: float,
                     speed: float = 1.0, angle: float = ANGLE) -> tuple[float, float]:
    """(e, β) averaged over uniformly random impact phases at ``steps_per_contact`` steps per
    ``contact_time`` (dt = contact_time / steps), at ``speed`` and ``angle``: what the
    contacts of a flow restitute on average."""
    e, b = collide(c, contact_time / steps_per_contact, angle, speed,
                   phases(_n_phases(steps_per_contact)))
    return float(e.mean()), float(b.mean())


@lru_cache(maxsize=512)
def spring_stiffness(beta: float, kn: float, e: float, m_eff: float, K: float,
                     contact_time: float, steps_per_contact: float, model: str = "hooke",
                     wall: bool = False, radius: float = 0.5, speed: float = 1.0) -> float:
    """k_t of an uncapped ``linear_history`` spring whose phase-averaged discrete β equals
    ``beta`` at ``steps_per_contact`` (scipy brentq on ``mean_restitution``).

    Starts from the continuous k_t (ω_t t_c = arccos(−β)); β = −1 gives 0 and more than
    MAX_COMPENSATED_STEPS the continuous k_t. A β beyond the discrete maximum (β → 1 at few
    steps) gets the k_t of the largest discrete β.
    """
    from scipy.optimize import brentq, minimize_scalar  # noqa: PLC0415 - only when compensating

    mt = K * m_eff / (1.0 + K)  # the tangential oscillator's mass
    kt0 = mt * (math.acos(-beta) / contact_time) ** 2
    if beta <= -1.0 or steps_per_contact > MAX_COMPENSATED_STEPS:
        return kt0

    def discrete(kt: float) -> float:
        c = DiscreteContact(kn, e, m_eff, K, kt, model=model, wall=wall, radius=radius)
        return mean_restitution(c, contact_time, steps_per_contact, speed)[1]

    kt_pi = mt * (math.pi / contact_time) ** 2  # continuous β = 1
    lo, hi = 0.25 * kt0, min(1.5 * kt0, kt_pi)
    if discrete(lo) > beta:
        lo = 1e-6 * kt0
    if discrete(hi) < beta:
        best = minimize_scalar(lambda k: -discrete(k), bounds=(0.5 * kt_pi, 1.2 * kt_pi),
                               method="bounded", options={"xatol": 1e-6 * kt_pi})
        if -best.fun < beta:
            return float(best.x)
        hi = float(best.x)
    return float(brentq(lambda k: discrete(k) - beta, lo, hi, xtol=1e-10 * kt0, rtol=1e-10))


@lru_cache(maxsize=512)
def damping_restitution(e: float, kn: float, m_eff: float, contact_time: float,
                        steps_per_contact: float, model: str = "hooke", wall: bool = False,
                        radius: float = 0.5, speed: float = 1.0, K: float = 0.4,
                        kt: float = 0.0, xt: float = 0.0, mu: float | None = None,
                        mindlin: bool = False) -> float:
    """The e to give LAMMPS's ``damping coeff_restitution`` so that the phase-averaged
    discrete normal restitution is ``e`` at ``steps_per_contact`` (scipy brentq): the half-step
    velocity in the damping force loses ≈ 0.010 of e = 0.5 at 10 steps (0.003 at e = 0.7,
    < 0.001 from e = 0.8). e = 1 (no damping) and more than MAX_COMPENSATED_STEPS keep e.
    The tangential force (K, kt, xt, mu, mindlin) moves a pair's e by ~2e-4 at 20 steps
    (the line of centres turns), so the contact's own tangential law is passed."""
    from scipy.optimize import brentq  # noqa: PLC0415 - only when compensating

    if e >= 1.0 or steps_per_contact > MAX_COMPENSATED_STEPS:
        return e

    def discrete(e_lammps: float) -> float:
        c = DiscreteContact(kn, e_lammps, m_eff, K, kt, xt, mu, model, mindlin, wall, radius)
        return mean_restitution(c, contact_time, steps_per_contact, speed)[0] - e

    lo, hi = 0.5 * e, min(1.0, e + 0.2)
    if discrete(hi) < 0.0:
        return hi
    return float(brentq(discrete, lo, hi, xtol=1e-12))
