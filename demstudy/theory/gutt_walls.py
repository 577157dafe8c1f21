"""Gutt (1989) Chapter 2: three-slip wall boundary conditions and gravity-free Couette flow of
smooth, non-spinning inelastic spheres (after Haff 1983).

Source: the digest /work/shared/reference/gutt1989.md §2 (thesis lines Lnnn quoted below).
**Units**: particle units d = 1, m = 1 (material density rho_p = 6/pi); there is no gravity,
so the wall speed sets the time scale: u_w = 1 (every velocity is reported over u_w, every
stress over rho_p d^2 (2 u_w/h)^2 as in figs 2.8-2.9). Channel y in [-h/2, h/2], walls at
+-u_w, wall vibration v_w = 0 (the thesis's Couette solution).

The solution (L699-L785), with R = sigma0/p0, D = r t_w/(r_w t), E = (1 - e_w)/(1 + e_w),
F = t_w^2/(q_w^2 <k_tau^2>):
* (2.10) omega^2 = (t^2 R^2/q - gamma)/(r d^2); (2.11) v(y) = 2 v0 cos(omega y) (cosh for
  omega^2 < 0, L733);
* (2.13) omega d D tan(omega h/2) = [E - F R^2/(1 - F R^2)] (1 - F R^2)^(1/2) for R;
* (2.12) u_s = v(h/2) R t_w/(q_w <k_tau^2>) (1 - F R^2)^(-1/2) (slip velocity);
* (2.14) u(y) = (2t/q) R v0 sin(omega y)/(omega d); (2.15) u_w = u_s + u(h/2);
* (2.16) v0^2 = omega Delta h p0/(6 t rho [sin(omega h) + omega h]) from the inventory
  Delta h = (3/d) int_{-h/2}^{h/2} s dy (L765, the garbled limits read -h/2 ... h/2) with
  s = t d rho v^2/p0;
* Q_a/Q_g = E (1 - F R^2)/(F R^2) (L759);
* sigma0/(rho_p d^2 (2u_w/h)^2) (L775) and p0/(...) (fig 2.9). The printed L775 formula sets
  the bulk density rho equal to rho_p; here a factor ``density_ratio`` = rho/rho_p multiplies
  both (default 1, the thesis's formula).

Removable singularity at omega = 0 (simple shear): every function of omega is written as a
function of w = omega^2 that is analytic through 0 (sin(omega y)/omega -> y, omega
tan(omega h/2) -> w h/2, ...), with Taylor series where |w| h^2 is tiny, so omega^2 > 0,
< 0 and = 0 are one branch.

Simple-shear limit (derived here, docs/theory-gutt.md): omega = 0 means R^2 = q gamma/t^2, and
(2.13)'s left side vanishes, so F R^2 (1 + E) = E, i.e. Q_a/Q_g = 1, at
<k_tau^2>* = 2 t_w^2 q gamma/(q_w^2 t^2 (1 - e_w)) (= 0.125 for fig 2.10's constants, curve 2).
There u is linear, v and s are constant, s/d = Delta h/(3h).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import brentq

__all__ = [
    "GuttWallConstants",
    "WallCouette",
    "WallSweep",
    "wall_couette",
    "wall_couette_sweep",
    "wall_simple_shear_roughness",
    "wall_stress_ratio",
]

RHO_SPHERE = 6 / math.pi  # material density of a sphere of d = 1, m = 1
_SERIES = 1e-4  # |omega^2| h^2/4 below which the Taylor series replace the trigonometry


@dataclass(frozen=True)
class GuttWallConstants:
    """Constants of the Ch. 2 Couette problem; defaults from the fig 2.4 caption (L795),
    h and Delta h from L777/L803 (in d). ``k2`` = <k_tau^2> (wall roughness, L603) and
    ``e_w`` (grain-wall restitution) default to fig 2.10's curve 2 (0.125, 0.84).
    ``density_ratio`` = rho/rho_p: not in the thesis (its L775 formula sets it to 1).
    ``d`` = 1 and ``u_w`` = 1 (particle units, wall speed as the velocity scale)."""

    gamma: float = 0.16
    q: float = 0.25
    r: float = 1.0
    t: float = 1.0
    e_w: float = 0.84
    q_w: float = 1.0
    r_w: float = 1.0
    t_w: float = 0.5
    h: float = 10.0
    delta_h: float = 3.25
    k2: float = 0.125
    d: float = 1.0
    u_w: float = 1.0
    density_ratio: float = 1.0

    def __post_init__(self) -> None:
        for name in ("q", "r", "t", "q_w", "r_w", "t_w", "h", "delta_h", "d", "u_w",
                     "density_ratio"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"GuttWallConstants.{name} must be a finite number > 0, "
                                 f"got {value!r}")
        if not (math.isfinite(self.gamma) and self.gamma >= 0):
            raise ValueError(f"GuttWallConstants.gamma must be a finite number >= 0, "
                             f"got {self.gamma!r}")
        if not (math.isfinite(self.e_w) and 0 <= self.e_w <= 1):
            raise ValueError(f"GuttWallConstants.e_w must be in [0, 1], got {self.e_w!r}")
        if not (math.isfinite(self.k2) and 0 < self.k2 <= 1):
            raise ValueError(f"GuttWallConstants.k2 = <k_tau^2> must be in (0, 1] (0 is a flat "
                             f"wall: no stress, no solution), got {self.k2!r}")
        if self.gamma == 0 and self.e_w == 1:
            raise ValueError("GuttWallConstants: gamma = 0 with e_w = 1 dissipates nothing "
                             "(no steady state)")
        if self.delta_h >= self.h:
            raise ValueError(f"GuttWallConstants.delta_h = {self.delta_h!r} must be < h = "
                             f"{self.h!r} (free space inside the channel)")

    @property
    def D(self) -> float:  # noqa: N802 - the thesis's symbol
        return self.r * self.t_w / (self.r_w * self.t)

    @property
    def E(self) -> float:  # noqa: N802
        return (1 - self.e_w) / (1 + self.e_w)

    @property
    def F(self) -> float:  # noqa: N802
        return self.t_w**2 / (self.q_w**2 * self.k2)

    def omega2(self, sigma_ratio: float) -> float:
        """(2.10): omega^2 = (t^2 R^2/q - gamma)/(r d^2)."""
        return (self.t**2 * sigma_ratio**2 / self.q - self.gamma) / (self.r * self.d**2)


# -- functions of w = omega^2, analytic through w = 0 -------------------------------------------
def _cos(w: float, y: ArrayLike) -> np.ndarray:
    """cos(omega y) (cosh for w < 0)."""
    y = np.asarray(y, float)
    return np.cos(math.sqrt(w) * y) if w >= 0 else np.cosh(math.sqrt(-w) * y)


def _sin_over(w: float, y: ArrayLike) -> np.ndarray:
    """sin(omega y)/omega (sinh(kappa y)/kappa for w < 0, y at w = 0)."""
    y = np.asarray(y, float)
    z2 = w * y**2
    if np.all(np.abs(z2) < _SERIES):
        return y * (1 - z2 / 6 + z2**2 / 120)
    if w > 0:
        return np.sin(math.sqrt(w) * y) / math.sqrt(w)
    return np.sinh(math.sqrt(-w) * y) / math.sqrt(-w)


def _omega_tan(w: float, h: float) -> float:
    """omega tan(omega h/2) (-kappa tanh(kappa h/2) for w < 0; w h/2 (1 + z2/3 + ...) near 0,
    z2 = w h^2/4). Infinite at omega h/2 >= pi/2."""
    z2 = w * h**2 / 4
    if abs(z2) < _SERIES:
        return w * h / 2 * (1 + z2 / 3 + 2 * z2**2 / 15)
    if w > 0:
        z = math.sqrt(z2)
        return math.inf if z >= math.pi / 2 else math.sqrt(w) * math.tan(z)
    return -math.sqrt(-w) * math.tanh(math.sqrt(-z2))


def _residual(c: GuttWallConstants, ratio: float) -> float:
    """Left minus right side of (2.13); strictly increasing in R on the allowed interval."""
    f = c.F * ratio**2
    rhs = (c.E - f / (1 - f)) * math.sqrt(1 - f)
    return c.d * c.D * _omega_tan(c.omega2(ratio), c.h) - rhs


def _upper_bound(c: GuttWallConstants) -> float:
    """The largest admissible R: F R^2 < 1 (real slip) and omega h/2 < pi/2 (v > 0)."""
    slip = 1 / math.sqrt(c.F)
    positive = math.sqrt(c.q * (c.gamma + c.r * c.d**2 * (math.pi / c.h) ** 2)) / c.t
    return min(slip, positive)


def wall_stress_ratio(c: GuttWallConstants) -> float:
    """sigma0/p0 from (2.13) by Brent's method on (0, R_max). At R = 0 the residual is
    -dD kappa tanh(kappa h/2) - E < 0 (unless gamma = 0 and e_w = 1, excluded); towards R_max
    it tends to +inf (the slip term or the tangent diverges); it is strictly increasing (left
    side increasing in omega^2, right side decreasing in F R^2), so the root is unique."""
    hi = _upper_bound(c)
    top = hi * (1 - 1e-12)
    while not _residual(c, top) > 0:  # rounding near the bound: step back until the sign shows
        top = hi - 2 * (hi - top)
        if top <= 0:
            raise RuntimeError(f"(2.13) has no sign change for {c!r}")
    if _residual(c, 0.0) >= 0:
        return 0.0
    return brentq(lambda x: _residual(c, x), 0.0, top, xtol=1e-15, rtol=4 * np.finfo(float).eps,
                  maxiter=200)


def wall_simple_shear_roughness(c: GuttWallConstants) -> float:
    """<k_tau^2>* at which omega^2 = 0 (simple shear): 2 t_w^2 q gamma/(q_w^2 t^2 (1 - e_w))
    (derived: omega = 0 needs R^2 = q gamma/t^2 and then (2.13) needs F R^2 = E/(1 + E), with
    (1 + E)/E = 2/(1 - e_w)). Rougher walls give omega^2 > 0, smoother omega^2 < 0. It may
    exceed 1 (then no admissible wall gives simple shear); inf for e_w = 1."""
    if c.e_w == 1:
        return math.inf
    return 2 * c.t_w**2 * c.q * c.gamma / (c.q_w**2 * c.t**2 * (1 - c.e_w))


@dataclass(frozen=True)
class WallCouette:
    """The whole Ch. 2 Couette solution at one roughness (velocities in units of u_w = 1 unless
    ``u_w`` was changed; y in d). Profiles on ``y`` (n points from -h/2 to h/2)."""

    constants: GuttWallConstants
    sigma_ratio: float  # R = sigma0/p0, root of (2.13)
    omega2: float  # (2.10)
    v0: float  # v(y) = 2 v0 cos(omega y) (2.11)
    u_s: float  # slip velocity (2.12)
    u_wall_flow: float  # u(h/2) (2.14): u_w = u_s + u(h/2) (2.15)
    v_wall: float  # v(h/2)
    flux_ratio: float  # Q_a/Q_g (L759)
    p0: float  # pressure (particle units, rho = density_ratio * 6/pi)
    sigma0: float  # shear stress
    stress_norm: float  # sigma0/(rho_p d^2 (2 u_w/h)^2) (L775, fig 2.8)
    pressure_norm: float  # p0/(rho_p d^2 (2 u_w/h)^2) (fig 2.9)
    y: np.ndarray
    v: np.ndarray
    u: np.ndarray
    s: np.ndarray  # mean surface spacing s(y) = t d rho v^2/p0


def _amplitude_factor(c: GuttWallConstants, ratio: float, w: float) -> float:
    """u_w/(2 v0) from (2.15): cos(omega h/2) sqrt(k2 x^2/k2) + (t/q) R sin(omega h/2)/(omega d)."""
    f = c.F * ratio**2
    slip = math.sqrt(f / (c.k2 * (1 - f))) if f > 0 else 0.0
    return float(_cos(w, c.h / 2) * slip + c.t / c.q * ratio * _sin_over(w, c.h / 2) / c.d)


def wall_couette(c: GuttWallConstants | None = None, n: int = 201, **changes: float
                 ) -> WallCouette:
    """Solve the Ch. 2 gravity-free Couette problem (L699-L785) for constants ``c`` (defaults:
    fig 2.4/2.10 caption values) with ``changes`` applied (e.g. ``k2=0.25, e_w=0.96``)."""
    c = replace(c or GuttWallConstants(), **changes)
    if n < 2:
        raise ValueError(f"n must be >= 2, got {n!r}")
    ratio = wall_stress_ratio(c)
    w = c.omega2(ratio)
    v0 = c.u_w / (2 * _amplitude_factor(c, ratio, w))
    rho = c.density_ratio * RHO_SPHERE
    # (2.16) solved for p0: v0^2 = Delta h p0/(6 t rho [sin(omega h)/omega + h])
    p0 = 6 * c.t * rho * v0**2 * (float(_sin_over(w, c.h)) + c.h) / c.delta_h
    y = np.linspace(-c.h / 2, c.h / 2, n)
    v = 2 * v0 * _cos(w, y)
    u = 2 * c.t / c.q * ratio * v0 * _sin_over(w, y) / c.d
    v_wall = float(2 * v0 * _cos(w, c.h / 2))
    f = c.F * ratio**2
    u_s = v_wall * ratio * c.t_w / (c.q_w * c.k2) / math.sqrt(1 - f)
    scale = RHO_SPHERE * c.d**2 * (2 * c.u_w / c.h) ** 2
    return WallCouette(
        constants=c, sigma_ratio=ratio, omega2=w, v0=v0, u_s=u_s,
        u_wall_flow=float(2 * c.t / c.q * ratio * v0 * _sin_over(w, c.h / 2) / c.d),
        v_wall=v_wall, flux_ratio=c.E * (1 - f) / f if f > 0 else math.inf, p0=p0,
        sigma0=ratio * p0, stress_norm=ratio * p0 / scale, pressure_norm=p0 / scale,
        y=y, v=v, u=u, s=c.t * c.d * rho * v**2 / p0)


@dataclass(frozen=True)
class WallSweep:
    """Fig 2.4-2.9 quantities against <k_tau^2> (arrays over ``k2``)."""

    k2: np.ndarray
    sigma_ratio: np.ndarray  # fig 2.4
    slip_ratio: np.ndarray  # u_s/u_w, fig 2.5
    flux_ratio: np.ndarray  # Q_a/Q_g, fig 2.6
    v_wall_ratio: np.ndarray  # v(h/2)/u_w, fig 2.7
    stress_norm: np.ndarray  # fig 2.8
    pressure_norm: np.ndarray  # fig 2.9
    omega2: np.ndarray


def wall_couette_sweep(k2: ArrayLike, c: GuttWallConstants | None = None, **changes: float
                       ) -> WallSweep:
    """:func:`wall_couette` over roughnesses ``k2`` (each in (0, 1])."""
    c = replace(c or GuttWallConstants(), **changes)
    k2 = np.asarray(k2, float)
    sols = [wall_couette(c, n=2, k2=float(k)) for k in k2]

    def col(get) -> np.ndarray:
        return np.array([get(s) for s in sols])

    return WallSweep(k2, col(lambda s: s.sigma_ratio), col(lambda s: s.u_s / c.u_w),
                     col(lambda s: s.flux_ratio), col(lambda s: s.v_wall / c.u_w),
                     col(lambda s: s.stress_norm), col(lambda s: s.pressure_norm),
                     col(lambda s: s.omega2))
