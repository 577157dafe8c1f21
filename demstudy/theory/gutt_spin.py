"""Gutt (1989) Chapter 1: continuum theory of rough, spinning, inelastic spheres (after Haff 1983).

Source: the digest /work/shared/reference/gutt1989.md §1 (thesis lines Lnnn quoted below).
**Units: arbitrary, as in the thesis** (it prints no parameter values and plots every velocity
in arbitrary units, captions L481-L491). Here d = 1 and rho = 1 unless changed; a velocity
scale is whatever the initial or wall values are: the equations are homogeneous of degree one
in (v, W), so the shapes do not depend on it. This is the project's particle-unit convention
with the time scale set by the chosen velocities (there is no gravity in these problems).

Fields: v (translational r.m.s. "thermal velocity"), W (r.m.s. spin fluctuation), u_x (mean
flow), omega_z (mean spin), s (mean surface-to-surface spacing). The solvers work with the
spin "velocity" Z = d W / 2 (so a = Z / v is the ratio of the thesis) and the energies v^2 and
Z^2 = d^2 W^2 / 4, which keep W = 0 regular.

Problems (digest §1.6):
* S1 homogeneous cooling (IVP): :func:`spin_cooling`, analytic (1.25) :func:`spin_cooling_analytic`.
* S2 vibrating plates (BVP): :func:`spin_plates`, analytic cosh solution (1.26)
  :func:`spin_plates_analytic`.
* S3 gravity-free Couette with spin (BVP): :func:`spin_couette`; constant ratio (1.32)
  :func:`spin_couette_ratio`; threshold :func:`spin_couette_threshold`; mean spin
  :func:`spin_mean_spin`.
* S4 analytic Couette with against without spin: :func:`spin_couette_analytic`.

OCR corrections used (digest §1.6, §8):
* L413: the viscous heating is eta_t (du/dy)^2 = sigma0^2 / eta_t (the square is lost).
* L425: the threshold sigma0/p0 > (sqrt(q_t)/t) (gamma_t + gamma'_t - gamma''_t gamma'_r /
  gamma''_r)^(1/2) needs the exponent 1/2 (checked here: it is the sigma0/p0 at which (1.30)
  and (1.31) admit a uniform v with a^2 = gamma'_r / gamma''_r).
* L459 (1.34): "-r_t d^2/lambda^2" reads "+r_t d^2/lambda^2" (substituting v = v0 cos(y/lambda)
  in (1.30) gives +, as Ch. 2's (2.10) does). The printed "∓" can be read as the cos (upper,
  +) against a cosh branch; only the cos branch of the thesis is implemented.

The very small seed v: with v = 0 there are no collisions and nothing evolves (L357); the
W-equations hold 1/v (L375, L419). Cases with a small v at t = 0 or at a wall are therefore
stiff; the IVP uses the energies v^2, Z^2 (right-hand sides proportional to v, no 1/W) and the
BVPs are reached by continuation from the analytic constant-ratio solution (each step starts
from the last), on a mesh crowded at the walls.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import cumulative_trapezoid, solve_bvp, solve_ivp

__all__ = [
    "GuttSpinConstants",
    "SpinCooling",
    "SpinCouette",
    "SpinCouetteAnalytic",
    "SpinProfiles",
    "spin_cooling",
    "spin_cooling_analytic",
    "spin_couette",
    "spin_couette_analytic",
    "spin_couette_ratio",
    "spin_couette_threshold",
    "spin_mean_spin",
    "spin_plates",
    "spin_plates_analytic",
]

K_SOLID_SPHERE = 0.4  # K = 4 I / (m d^2) for a solid sphere (L239)


def _n2(beta: float, k: float) -> float:
    return (1 + beta) / 2 * k / (1 + k)


# The defaults are the [derived] proportionalities of the digest (§1.4) at e = 0.6, beta = 0.5
# with a unit common rate factor: gamma_t = (1 - e^2)/4 = 0.16 (Ch. 2's gamma, fig 2.4 caption),
# n2 = (1 + beta)/7 = 3/14. All assumed: the thesis gives no Ch. 1 values.
_N2 = _n2(0.5, K_SOLID_SPHERE)


@dataclass(frozen=True)
class GuttSpinConstants:
    """The O(1) constants of Gutt's Ch. 1 model (digest §1.5). **Every default is assumed**:
    the thesis prints none (digest §8, "all Ch. 1 constants" unknown).

    * ``t``, ``q_t``, ``r_t`` = 1, 0.25, 1: equation of state (1.18), translational
      viscosity (1.19), translational diffusivity (1.21); assumed equal to Ch. 2's t, q, r
      (fig 2.4 caption).
    * ``q_r`` = 0.25: rotational viscosity (1.20); assumed. It drops out of every solved
      problem (in Couette flow omega_z = -du/dy/2 makes the antisymmetric stress vanish).
    * ``r_r`` = 1: spin diffusivity (1.22); assumed.
    * ``gamma_t`` = 0.16 (inelastic loss), ``gamma1_t`` = gamma'_t, ``gamma2_t`` = gamma''_t,
      ``gamma1_r`` = gamma'_r, ``gamma2_r`` = gamma''_r (spin transfer, (1.23)-(1.24)):
      assumed, = :meth:`from_restitution` (e = 0.6, beta = 0.5, rate = 1).
    * ``n2`` = (1 + beta) K / (2 (1 + K)) = 3/14 (beta = 0.5 assumed), ``k`` = 2/5 (solid
      sphere, L239), ``d`` = 1, ``theta`` = I/m = K d^2/4 (solid sphere), ``s`` = 0.1 d
      (assumed: about Ch. 2's Delta h/(3h) = 0.108), ``rho`` = 1 (assumed; only S4's p0).

    Validated: all finite and positive (gamma_t >= 0), and the thesis's constraints (L463)
    gamma'_t > gamma'_r and gamma''_r > gamma''_t; its third, gamma'_t gamma''_r -
    gamma''_t gamma'_r > 0, follows from these two (all gammas > 0).
    """

    t: float = 1.0
    q_t: float = 0.25
    q_r: float = 0.25
    r_t: float = 1.0
    r_r: float = 1.0
    gamma_t: float = 0.16
    gamma1_t: float = _N2 * (1 - _N2)
    gamma2_t: float = _N2**2
    gamma1_r: float = _N2**2 / K_SOLID_SPHERE
    gamma2_r: float = _N2 * (1 - _N2 / K_SOLID_SPHERE)
    n2: float = _N2
    k: float = K_SOLID_SPHERE
    d: float = 1.0
    theta: float = K_SOLID_SPHERE / 4
    s: float = 0.1
    rho: float = 1.0

    def __post_init__(self) -> None:
        for name in ("t", "q_t", "q_r", "r_t", "r_r", "gamma1_t", "gamma2_t", "gamma1_r",
                     "gamma2_r", "n2", "k", "d", "theta", "s", "rho"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"GuttSpinConstants.{name} must be a finite number > 0, "
                                 f"got {value!r}")
        if not (math.isfinite(self.gamma_t) and self.gamma_t >= 0):
            raise ValueError(f"GuttSpinConstants.gamma_t must be a finite number >= 0, "
                             f"got {self.gamma_t!r}")
        if not self.gamma1_t > self.gamma1_r:
            raise ValueError(
                f"GuttSpinConstants: gamma1_t = {self.gamma1_t!r} must exceed gamma1_r = "
                f"{self.gamma1_r!r} (thesis L463: gamma'_t > gamma'_r, translation loses more "
                "than spin gains)")
        if not self.gamma2_r > self.gamma2_t:
            raise ValueError(
                f"GuttSpinConstants: gamma2_r = {self.gamma2_r!r} must exceed gamma2_t = "
                f"{self.gamma2_t!r} (thesis L463: gamma''_r > gamma''_t)")
        # the third constraint of L463, gamma'_t gamma''_r - gamma''_t gamma'_r > 0, follows
        # from the two above for positive gammas: it needs no check of its own

    @classmethod
    def from_restitution(cls, e: float, beta: float, rate: float = 1.0,
                         **others: float) -> GuttSpinConstants:
        """[derived] constants from the Lun & Savage collision (digest §1.4): n1 = (1+e)/2,
        n2 = (1+beta)/2 K/(1+K); gamma_t = rate n1 (1-n1) = rate (1-e^2)/4,
        gamma'_t = rate n2 (1-n2), gamma'_r = rate n2^2/K, gamma''_t = rate n2^2,
        gamma''_r = rate n2 (1 - n2/K). These are the per-collision energy coefficients of
        (1.16)-(1.17) up to one common collision-rate factor ``rate`` (assumed); the thesis
        gives no functional forms. The constraints hold for every beta < 1 (at beta = 1,
        perfectly rough, gamma'_t = gamma'_r and there is no friction loss)."""
        if not (math.isfinite(e) and 0 < e <= 1):
            raise ValueError(f"e must be in (0, 1], got {e!r}")
        k = others.pop("k", K_SOLID_SPHERE)
        if not (math.isfinite(beta) and -1 < beta < 1):
            raise ValueError(f"beta must be in (-1, 1) (beta = 1 has no friction loss and "
                             f"violates gamma'_t > gamma'_r), got {beta!r}")
        n1, n2 = (1 + e) / 2, _n2(beta, k)
        return cls(gamma_t=rate * n1 * (1 - n1), gamma1_t=rate * n2 * (1 - n2),
                   gamma2_t=rate * n2**2, gamma1_r=rate * n2**2 / k,
                   gamma2_r=rate * n2 * (1 - n2 / k), n2=n2, k=k,
                   **{"theta": k * others.get("d", 1.0) ** 2 / 4, **others})

    @property
    def beta(self) -> float:
        """Tangential restitution from n2 = (1 + beta) K / (2 (1 + K))."""
        return 2 * self.n2 * (1 + self.k) / self.k - 1

    @property
    def determinant(self) -> float:
        """gamma'_t gamma''_r - gamma''_t gamma'_r (> 0 required, L463)."""
        return self.gamma1_t * self.gamma2_r - self.gamma2_t * self.gamma1_r

    @property
    def loss(self) -> float:
        """gamma_t + gamma'_t: the coefficient of v^3/s in I_t (1.23)."""
        return self.gamma_t + self.gamma1_t


def _quadratic_root(b: float, c: float, a: float) -> float:
    """The positive root of a x^2 - b x - c = 0 (a, c > 0), the form of (1.25), (1.26), (1.32)."""
    return (b + math.sqrt(b * b + 4 * a * c)) / (2 * a)


# -- S1: homogeneous cooling -----------------------------------------------------------------
@dataclass(frozen=True)
class SpinCooling:
    """v(t), W(t) of a uniform system; ``ratio`` = d W / (2 v) (-> a, L359)."""

    t: np.ndarray
    v: np.ndarray
    W: np.ndarray
    ratio: np.ndarray
    a: float
    b: float


def _cooling_a2(c: GuttSpinConstants) -> float:
    spin = c.d**2 / (4 * c.theta)  # = 1/K for a solid sphere
    return _quadratic_root(c.loss - spin * c.gamma2_r, spin * c.gamma1_r, c.gamma2_t)


def spin_cooling_analytic(c: GuttSpinConstants, v0: float, t: np.ndarray) -> SpinCooling:
    """Special solution (1.25), L353-L355: v = v0/(b v0 t + 1), W = W0/(b v0 t + 1) with
    a^2 = d^2 W^2/(4 v^2) = {G - (d^2/4theta) gamma''_r + [(G - (d^2/4theta) gamma''_r)^2
    + (d^2/theta) gamma'_r gamma''_t]^(1/2)} / (2 gamma''_t), G = gamma_t + gamma'_t,
    b = (G - gamma''_t a^2)/s and W0 = 2 a v0/d (Haff-like 1/t decay)."""
    if not (math.isfinite(v0) and v0 > 0):
        raise ValueError(f"v0 must be a finite number > 0, got {v0!r}")
    a2 = _cooling_a2(c)
    a = math.sqrt(a2)
    b = (c.loss - c.gamma2_t * a2) / c.s
    t = np.asarray(t, float)
    v = v0 / (b * v0 * t + 1)
    return SpinCooling(t, v, 2 * a * v / c.d, np.full_like(t, a), a, b)


def spin_cooling(c: GuttSpinConstants, v0: float, W0: float, t: np.ndarray,
                 rtol: float = 1e-10) -> SpinCooling:
    """Integrate S1 (L347-L349) from v(0) = v0, W(0) = W0 to the times ``t`` (solve_ivp,
    LSODA). Unknowns X = v^2, Y = d^2 W^2/4:
    dX/dt = 2 (-G X + gamma''_t Y) sqrt(X)/s, dY/dt = (d^2/4theta) 2 (gamma'_r X - gamma''_r Y)
    sqrt(X)/s. With v0 = 0 nothing evolves (L357); a small v0 is the thesis's seed (case c).
    ``ratio`` is nan where v = 0."""
    for name, value in (("v0", v0), ("W0", W0)):
        if not (math.isfinite(value) and value >= 0):
            raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    t = np.asarray(t, float)
    if t.ndim != 1 or t.size < 1 or t[0] < 0 or np.any(np.diff(t) <= 0):
        raise ValueError("t must be a 1-D increasing array of times >= 0")
    spin = c.d**2 / (4 * c.theta)

    def rhs(_time: float, y: np.ndarray) -> np.ndarray:
        x, z2 = y
        rate = 2 * math.sqrt(max(x, 0.0)) / c.s
        return np.array([rate * (-c.loss * x + c.gamma2_t * z2),
                         rate * spin * (c.gamma1_r * x - c.gamma2_r * z2)])

    y0 = [v0**2, (c.d * W0 / 2) ** 2]
    if t[-1] == 0:  # only the initial state asked for
        t = np.concatenate([t, [1.0]])
        return _drop_last(spin_cooling(c, v0, W0, t, rtol))
    sol = solve_ivp(rhs, (0.0, float(t[-1])), y0, method="LSODA", t_eval=t, rtol=rtol,
                    atol=1e-14 * max(y0[0] + y0[1], 1e-300))
    if not sol.success:
        raise RuntimeError(f"spin_cooling: solve_ivp failed: {sol.message}")
    v = np.sqrt(np.clip(sol.y[0], 0, None))
    z = np.sqrt(np.clip(sol.y[1], 0, None))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(v > 0, z / v, np.nan)
    a2 = _cooling_a2(c)
    return SpinCooling(t, v, 2 * z / c.d, ratio, math.sqrt(a2),
                       (c.loss - c.gamma2_t * a2) / c.s)


def _drop_last(sol: SpinCooling) -> SpinCooling:
    return SpinCooling(sol.t[:-1], sol.v[:-1], sol.W[:-1], sol.ratio[:-1], sol.a, sol.b)


# -- S2 and S3: the thermal boundary-value problem ---------------------------------------------
@dataclass(frozen=True)
class SpinProfiles:
    """v(y), W(y) across a channel y in [-h/2, h/2]; ``ratio`` = d W/(2 v)."""

    y: np.ndarray
    v: np.ndarray
    W: np.ndarray
    ratio: np.ndarray
    a: float
    curvature: float  # k of v'' = -k v for the constant-ratio solution (1/lambda^2 or -1/lambda^2)


@dataclass(frozen=True)
class SpinCouette(SpinProfiles):
    """S3 profiles plus the flow u(y), the mean spin omega_z(y) (1.27) and u(h/2)."""

    u: np.ndarray = field(default_factory=lambda: np.empty(0))
    omega_z: np.ndarray = field(default_factory=lambda: np.empty(0))
    u_wall: float = 0.0
    sigma_ratio: float = 0.0


def _shear_heating(c: GuttSpinConstants, sigma_ratio: float) -> float:
    """t^2 sigma0^2/(q_t p0^2): the viscous heating per unit (p0/t d) v (1.30)."""
    return c.t**2 * sigma_ratio**2 / c.q_t


def spin_couette_ratio(c: GuttSpinConstants, sigma_ratio: float) -> tuple[float, float]:
    """(a, k): the constant ratio a = d W/(2 v) of (1.32), L429, and the curvature k of the
    matching profile v'' = -k v, k = (t^2 sigma0^2/(q_t p0^2) - G + gamma''_t a^2)/(r_t d^2)
    (k > 0: v = v_c cos(sqrt(k) y), above the threshold; k < 0: cosh). With sigma0 = 0 this is
    the vibrating-plate solution (1.26): a the same and k = -1/lambda^2."""
    if not (math.isfinite(sigma_ratio) and sigma_ratio >= 0):
        raise ValueError(f"sigma_ratio must be a finite number >= 0, got {sigma_ratio!r}")
    heat = _shear_heating(c, sigma_ratio)
    diff = c.r_t / (c.r_r * c.n2)
    a2 = _quadratic_root(c.loss - heat - diff * c.gamma2_r, diff * c.gamma1_r, c.gamma2_t)
    return math.sqrt(a2), (heat - c.loss + c.gamma2_t * a2) / (c.r_t * c.d**2)


def spin_couette_threshold(c: GuttSpinConstants) -> float:
    """sigma0/p0 above which shear generation exceeds dissipation (L425, exponent 1/2 restored):
    (sqrt(q_t)/t) (gamma_t + gamma'_t - gamma''_t gamma'_r/gamma''_r)^(1/2). At it, a uniform v
    with a^2 = gamma'_r/gamma''_r solves (1.30)-(1.31)."""
    return math.sqrt(c.q_t) / c.t * math.sqrt(c.loss - c.gamma2_t * c.gamma1_r / c.gamma2_r)


def _cos_like(k: float, y: np.ndarray) -> np.ndarray:
    if k > 0:
        return np.cos(math.sqrt(k) * y)
    return np.cosh(math.sqrt(-k) * y)


def spin_plates_analytic(c: GuttSpinConstants, h: float, v_wall: float,
                         n: int = 201) -> SpinProfiles:
    """The cosh solution (1.26), L379-L385: v = v0 cosh(x/lambda), W = 2 a v/d, with a from
    (1.26) and lambda^2 = r_t d^2/(G - gamma''_t a^2); v0 set by v(+-h/2) = v_wall."""
    return _analytic_profiles(c, 0.0, h, v_wall, n)


def _analytic_profiles(c: GuttSpinConstants, sigma_ratio: float, h: float, v_wall: float,
                       n: int) -> SpinProfiles:
    _check_channel(h, v_wall, 0.0)
    a, k = spin_couette_ratio(c, sigma_ratio)
    if k > 0 and math.sqrt(k) * h / 2 >= math.pi / 2:
        raise ValueError(f"h = {h!r} too wide for sigma_ratio = {sigma_ratio!r}: the "
                         f"constant-ratio profile cos(sqrt(k) y) needs sqrt(k) h/2 < pi/2, "
                         f"i.e. h < {math.pi / math.sqrt(k)!r}")
    y = _wall_mesh(h, n)
    v = v_wall * _cos_like(k, y) / _cos_like(k, np.array([h / 2]))[0]
    return SpinProfiles(y, v, 2 * a * v / c.d, np.full_like(y, a), a, k)


def _check_channel(h: float, v_wall: float, w_wall: float) -> None:
    if not (math.isfinite(h) and h > 0):
        raise ValueError(f"h must be a finite number > 0, got {h!r}")
    if not (math.isfinite(v_wall) and v_wall > 0):
        raise ValueError(f"v_wall must be a finite number > 0 (a small seed, not 0: with v = 0 "
                         f"nothing evolves, L357), got {v_wall!r}")
    if not (math.isfinite(w_wall) and w_wall >= 0):
        raise ValueError(f"W_wall must be a finite number >= 0, got {w_wall!r}")


def _wall_mesh(h: float, n: int) -> np.ndarray:
    """Nodes crowded at both walls (sin spacing), where small wall values make thin layers."""
    return h / 2 * np.sin(np.linspace(-np.pi / 2, np.pi / 2, n))


def _thermal_bvp(c: GuttSpinConstants, sigma_ratio: float, h: float, v_wall: float,
                 w_wall: float, steps: int, tol: float) -> tuple[object, float, float]:
    """Solve (1.30)-(1.31) (with sigma0 = 0: L373-L375) for the state
    [v, v', Y = Z^2, q = Z Z'/v, u]: v'' = (G v - gamma''_t Y/v - H v)/(r_t d^2),
    Y' = 2 v q, q' = (gamma''_r Y/v - gamma'_r v)/(r_r n2 d^2), u' = (t/q_t)(sigma0/p0) v/d.
    Continuation in the wall values from the analytic constant-ratio solution."""
    a, k = spin_couette_ratio(c, sigma_ratio)
    heat = _shear_heating(c, sigma_ratio)
    flow = c.t / c.q_t * sigma_ratio / c.d
    dt2, dr2 = c.r_t * c.d**2, c.r_r * c.n2 * c.d**2

    def rhs(_y: np.ndarray, s: np.ndarray) -> np.ndarray:
        v, dv, yy, q, _u = s
        v = np.maximum(v, 1e-300)  # the 1/v terms: v > 0 on any solution (seeded walls)
        return np.vstack([dv, (c.loss * v - c.gamma2_t * yy / v - heat * v) / dt2,
                          2 * v * q, (c.gamma2_r * yy / v - c.gamma1_r * v) / dr2, flow * v])

    # start: the constant-ratio solution whose wall value of v is the larger of the two modes
    z_target = c.d * w_wall / 2
    v_ref = max(v_wall, z_target / a)
    start = _analytic_profiles(c, sigma_ratio, h, v_ref, 101)
    y = start.y
    v = start.v
    dv = np.gradient(v, y)
    u = flow * cumulative_trapezoid(v, y, initial=0.0)
    guess = np.vstack([v, dv, (a * v) ** 2, a**2 * dv, u - 0.5 * (u[0] + u[-1])])
    sol, done = None, 0.0
    step = 1.0 / steps
    while done < 1.0:
        frac = min(1.0, done + step)
        vw = v_ref ** (1 - frac) * v_wall**frac  # geometric: small seeds need small steps
        yw = (1 - frac) * (a * v_ref) ** 2 + frac * z_target**2

        def bc(lo: np.ndarray, hi: np.ndarray, vw: float = vw, yw: float = yw) -> np.ndarray:
            return np.array([lo[0] - vw, hi[0] - vw, lo[2] - yw, hi[2] - yw, lo[4] + hi[4]])

        trial = solve_bvp(rhs, bc, y, guess, tol=tol, max_nodes=200_000)
        if trial.success and np.all(trial.y[0] > 0) and np.all(trial.y[2] > -1e-12 * yw - 1e-30):
            sol, done = trial, frac
            y, guess = trial.x, trial.y
            step = min(2 * step, 1.0)
        else:
            step /= 2
            if step < 1e-4:
                raise RuntimeError(
                    f"spin BVP did not converge (sigma_ratio = {sigma_ratio!r}, h = {h!r}, "
                    f"v_wall = {v_wall!r}, W_wall = {w_wall!r}): {trial.message}")
    return sol, a, k


def _profiles(sol, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The BVP solution on a wall-crowded mesh of n points: y, v, Z = d W/2, full state."""
    y = _wall_mesh(float(sol.x[-1] - sol.x[0]), n)
    state = sol.sol(y)
    v = state[0]
    z = np.sqrt(np.clip(state[2], 0, None))
    return y, v, z, state


def spin_plates(c: GuttSpinConstants, h: float, v_wall: float, W_wall: float,
                n: int = 201, steps: int = 4, tol: float = 1e-6) -> SpinProfiles:
    """S2 (L361-L389): steady v, W between plates at y = +-h/2 with v = v_wall, W = W_wall
    there (set arbitrarily, no spin boundary theory, L363); no flow, no gravity, p uniform.
    Solved with scipy ``solve_bvp``: 0 = r_t d^2 v'' - G v + gamma''_t Z^2/v,
    0 = r_r n2 d^2 (Z Z'/v)' + gamma'_r v - gamma''_r Z^2/v (Z = d W/2). Cases of fig 1.5:
    (a) W_wall = 2 a v_wall/d (the analytic cosh solution), (b) W_wall = 0, (c) v_wall small."""
    _check_channel(h, v_wall, W_wall)
    sol, a, k = _thermal_bvp(c, 0.0, h, v_wall, W_wall, steps, tol)
    y, v, z, _ = _profiles(sol, n)
    return SpinProfiles(y, v, 2 * z / c.d, z / v, a, k)


def spin_couette(c: GuttSpinConstants, sigma_ratio: float, h: float, v_wall: float,
                 W_wall: float, n: int = 201, steps: int = 4, tol: float = 1e-6) -> SpinCouette:
    """S3 (L391-L437): gravity-free Couette with spin for a given sigma0/p0 and wall values of
    v and W at y = +-h/2; solves (1.30)-(1.31) with ``solve_bvp`` and integrates
    du/dy = (t/q_t)(sigma0/p0) v/d (sigma0 = eta_t du/dy, (1.29)) with u(0) = 0;
    omega_z = -du/dy/2 (1.27). Case 1 (fig 1.7): W_wall = 0, sigma0/p0 above
    :func:`spin_couette_threshold`; the wall speed u_wall that gives this v_wall is returned.
    Case 2 (fig 1.8): v_wall very small."""
    _check_channel(h, v_wall, W_wall)
    sol, a, k = _thermal_bvp(c, sigma_ratio, h, v_wall, W_wall, steps, tol)
    y, v, z, state = _profiles(sol, n)
    return SpinCouette(y, v, 2 * z / c.d, z / v, a, k, u=state[4],
                       omega_z=spin_mean_spin(c, sigma_ratio, v), u_wall=float(state[4][-1]),
                       sigma_ratio=sigma_ratio)


def spin_mean_spin(c: GuttSpinConstants, sigma_ratio: float, v: np.ndarray) -> np.ndarray:
    """omega_z = -(1/2) du/dy = -(t/(2 q_t)) sigma0 v/(p0 d) (L435-L437 give the magnitude;
    the sign follows (1.27) for a flow u_x increasing with y): the mean spin follows v."""
    return -c.t / (2 * c.q_t) * sigma_ratio * np.asarray(v, float) / c.d


# -- S4: Couette with against without spin, analytic ------------------------------------------
@dataclass(frozen=True)
class SpinCouetteAnalytic:
    """S4 (L439-L473) at fixed lambda, v = v0 cos(y/lambda), W/v constant."""

    a2: float  # (d W/(2 v))^2 from (1.33)
    sigma_ratio_spin: float  # (1.34) with +r_t d^2/lambda^2
    sigma_ratio_no_spin: float  # without spin: (sqrt(q_t)/t)(gamma_t + r_t d^2/lambda^2)^(1/2)
    p0: float  # from Delta h (L453), the same with and without spin
    u_wall_spin: float  # u(h/2) (L469)
    u_wall_no_spin: float


def spin_couette_analytic(c: GuttSpinConstants, lam: float, h: float, v0: float,
                          delta_h: float) -> SpinCouetteAnalytic:
    """S4: (1.33) (dW/2v)^2 = gamma'_r/(gamma''_r + r_r n2 d^2/lambda^2);
    (1.34) sigma0/p0 = (sqrt(q_t)/t)[gamma_t + r_t d^2/lambda^2 + (gamma'_t r_r n2 d^2/lambda^2
    + gamma'_t gamma''_r - gamma''_t gamma'_r)/(gamma''_r + r_r n2 d^2/lambda^2)]^(1/2)
    (OCR "-r_t d^2/lambda^2" corrected to "+", digest §1.6); without spin the bracket is
    gamma_t + r_t d^2/lambda^2 (Ch. 2's (2.10)). p0 = 3 t rho v0^2 [(lambda/Delta h)
    sin(h/2lambda) cos(h/2lambda) + h/(2 Delta h)] (L453) and u(h/2) = (t/q_t)(sigma0/p0)
    (lambda/d) v0 sin(h/2lambda) (L469). Spin raises sigma0/p0 (and so sigma0 and u(h/2)) when
    gamma'_t gamma''_r - gamma''_t gamma'_r > 0 (L465), which the constants guarantee."""
    for name, value in (("lam", lam), ("h", h), ("v0", v0), ("delta_h", delta_h)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    if h / (2 * lam) >= math.pi / 2:
        raise ValueError(f"h/(2 lam) = {h / (2 * lam)!r} must be < pi/2 (v > 0 at the walls)")
    curv = c.d**2 / lam**2
    spin_diff = c.r_r * c.n2 * curv
    a2 = c.gamma1_r / (c.gamma2_r + spin_diff)
    base = c.gamma_t + c.r_t * curv
    extra = (c.gamma1_t * spin_diff + c.determinant) / (c.gamma2_r + spin_diff)
    pref = math.sqrt(c.q_t) / c.t
    ratio_spin, ratio_plain = pref * math.sqrt(base + extra), pref * math.sqrt(base)
    half = h / (2 * lam)
    p0 = 3 * c.t * c.rho * v0**2 * (lam / delta_h * math.sin(half) * math.cos(half)
                                    + h / (2 * delta_h))
    wall = c.t / c.q_t * lam / c.d * v0 * math.sin(half)
    return SpinCouetteAnalytic(a2, ratio_spin, ratio_plain, p0, wall * ratio_spin,
                               wall * ratio_plain)
