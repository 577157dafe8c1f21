"""Quantities derived from a ``/profiles`` dict: Campbell's momentum-balance stresses, kinetic
stresses, shear rate, S, Bagnold/Savage f_s and f_N, chi(nu), wall slip, friction coefficient,
an Enskog Knudsen number.

Input: ``profiles`` is the ``results`` dict of :class:`~demstudy.analysis.profiles.ProfileAnalysis`
(or the ``/profiles`` group read into a dict): ``y`` (bin centres), ``solid_fraction``,
``velocity`` (n, dim), ``temperature_components`` (n, dim) = mean_mass <v_a'^2>,
``kinetic_shear`` = <u'v'>, ``mean_mass``, each with ``*_err``; ``edges`` if present (else
uniform bins around ``y``). Missing ``*_err`` count as 0; empty bins (NaN) as no material.

Conventions
-----------
* Particle units d = 1, m = 1 (g = 1 when gravity acts). Material density
  rho = m / V_1 = 4/pi per unit thickness in 2D (discs), 6/pi in 3D (spheres); rho nu is the
  local mass density. Campbell used R = 1 (lengths in radii) and rho_p = m/(pi R^2) = 1/pi:
  convert with R = d/2 before comparing numbers, e.g. his chute stress tau/(rho_p g R) is
  tau/(rho g / 2) here.
* x is the flow direction, y (``axis``) the wall-normal profile axis. Stresses follow
  Campbell's signs: tau_yy is compressive positive (= -sigma_yy of the tension-positive Cauchy
  stress), tau_xy positive when the material above y drags the material below in +x
  (= sigma_xy). For a static column tau_yy(y) is the weight above y per unit area.
* Momentum balance (d/dx = 0): the traction exerted by the material above y on the material
  below is t(y) = t(H) + int_y^H rho nu (g - a) dy', a the mean acceleration; tau_xy = t_x,
  tau_yy = -t_y. In chute axes g = (sin alpha, -cos alpha) this is Campbell's
  tau_xy = int rho nu (g sin alpha - u_t) dy', tau_yy = int rho nu (g cos alpha + v_t) dy'.
  (The thesis text writes "- v_t" in tau_yy; the listing's QT4 = -Delta M_n/... - nu cos/pi
  has the sign used here, with the overall tension-positive sign; the listing also divides
  the unsteady term by an extra pi, a probable bug, not reproduced.)
* Errors are propagated linearly from the ``*_err`` of the bins treated as independent
  (the bins' jackknife covariances are not stored), so they are estimates.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from demstudy.theory.kinetic import mean_free_path

__all__ = [
    "DERIVED_GROUP",
    "MATERIAL_DENSITY",
    "bagnold_coefficients",
    "campbell_depth",
    "derived_results",
    "equation_of_state",
    "friction_coefficient",
    "gravity_of",
    "kinetic_stress",
    "knudsen_enskog",
    "momentum_balance_stress",
    "s_parameter",
    "shear_rate",
    "stress_integration_matrix",
    "unsteady_inertia",
    "velocity_variances",
    "wall_slip",
]

MATERIAL_DENSITY = {2: 4 / math.pi, 3: 6 / math.pi}
"""rho = m / V_1 for m = 1, d = 1 (2D: per unit thickness)."""


# -- helpers ---------------------------------------------------------------------------
def _dim(profiles: dict[str, Any]) -> int:
    v = np.asarray(profiles["velocity"])
    dim = v.shape[1] if v.ndim == 2 else 0
    if dim not in (2, 3):
        raise ValueError(f"velocity must have shape (n_bins, 2 or 3), got {v.shape}")
    return dim


def _err(profiles: dict[str, Any], key: str) -> np.ndarray:
    val = np.asarray(profiles[key], float)
    e = profiles.get(f"{key}_err")
    e = np.zeros_like(val) if e is None else np.asarray(e, float)
    return np.where(np.isfinite(e), e, 0.0)


def _edges(profiles: dict[str, Any]) -> np.ndarray:
    if profiles.get("edges") is not None:
        return np.asarray(profiles["edges"], float)
    y = np.asarray(profiles["y"], float)
    if y.size < 2:
        raise ValueError("need 'edges' or at least two bin centres")
    mid = 0.5 * (y[1:] + y[:-1])
    return np.concatenate([[2 * y[0] - mid[0]], mid, [2 * y[-1] - mid[-1]]])


def gravity_of(source: Any, dim: int | None = None) -> np.ndarray:
    """Gravity vector from a Scene (``gravity_vector``; None -> zeros) or a sequence."""
    if hasattr(source, "gravity_vector"):
        g = source.gravity_vector
        d = source.dimension
        return np.zeros(d) if g is None else np.asarray(g, float)
    g = np.asarray(source, float)
    if dim is not None and g.shape != (dim,):
        raise ValueError(f"gravity must have {dim} components, got {g.shape}")
    return g


def velocity_variances(profiles: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """<v_a'^2> = temperature_components / mean_mass (n, dim), with errors."""
    tc = np.asarray(profiles["temperature_components"], float)
    tc_err = _err(profiles, "temperature_components")
    mm = np.asarray(profiles.get("mean_mass", np.ones(tc.shape[0])), float)[:, None]
    return tc / mm, tc_err / mm


# -- momentum-balance stresses -----------------------------------------------------------
def stress_integration_matrix(
    y: ArrayLike,
    edges: ArrayLike,
    top: float | None = None,
    rule: str = "trapezoid",
    sparse_top: ArrayLike | None = None,
) -> np.ndarray:
    """Matrix W with (W f)_i = int_{y_i}^H f dy' from bin values f (NaN rows above H).

    ``rule="trapezoid"`` (thesis text): trapezoids between the bin centres below H, and the
    last centre's value held constant up to H; exact for piecewise-linear f, error O(w^2).
    ``rule="rectangle"`` (listing, L2950-2965): QS6(i) = QS6(i+1) + QS4(i) ST, i.e. the sum of
    whole bins i...top, the top bin being the one containing H (its lower edge below H); the
    value reported at bin i is really the integral from the bin's lower edge: bias
    f w / 2 = O(w). ``sparse_top`` (rectangle only): the solid fractions; drop the top bin
    when it holds less than 1/3 of the density of the bin below (listing).
    H defaults to the upper edge of the grid.
    """
    y = np.asarray(y, float)
    edges = np.asarray(edges, float)
    n = y.size
    h = float(edges[-1]) if top is None else float(top)
    w = np.full((n, n), np.nan)
    if rule == "trapezoid":
        inside = np.flatnonzero(y < h)
        if inside.size == 0:
            return w
        last = inside[-1]
        half = 0.5 * np.diff(y[: last + 1])  # half-lengths of the segments between centres
        left = np.concatenate([[0.0], half])  # node j's share of segment j-1
        right = np.concatenate([half, [h - y[last]]])  # of segment j (last: up to H)
        i, j = np.meshgrid(np.arange(last + 1), np.arange(last + 1), indexing="ij")
        w[: last + 1, : last + 1] = (j >= i) * right[None, :] + (j > i) * left[None, :]
        w[: last + 1, last + 1 :] = 0.0
        return w
    if rule == "rectangle":
        inside = np.flatnonzero(edges[:-1] < h)
        if inside.size == 0:
            return w
        last = inside[-1]
        if sparse_top is not None and last > 0:
            nu = np.nan_to_num(np.asarray(sparse_top, float))
            if nu[last] < nu[last - 1] / 3:
                last -= 1
        width = np.diff(edges)
        i, j = np.meshgrid(np.arange(last + 1), np.arange(n), indexing="ij")
        w[: last + 1] = ((j >= i) & (j <= last)) * width[None, :]
        return w
    raise ValueError(f"rule must be 'trapezoid' or 'rectangle', got {rule!r}")


def unsteady_inertia(
    momentum_change: ArrayLike, duration: float, bin_width: float, cross_section: float
) -> np.ndarray:
    """rho nu a per bin from the momentum change of the bin's material over the averaging
    window (Campbell's QS, QT: sum A u at the end minus the start): Delta M / (T w A_cross),
    A_cross the bin's cross-section (periodic length in 2D, area in 3D)."""
    return np.asarray(momentum_change, float) / (duration * bin_width * cross_section)


def momentum_balance_stress(
    profiles: dict[str, Any],
    gravity: Any,
    rule: str = "trapezoid",
    top: float | None = None,
    top_stress: tuple[float, float] = (0.0, 0.0),
    inertia: ArrayLike | None = None,
    inertia_err: ArrayLike | None = None,
    axis: int = 1,
    sparse_top: bool = False,
    wall_stress: tuple[float, float] | None = None,
    wall: float | None = None,
) -> dict[str, np.ndarray]:
    """Campbell's tau_xy(y), tau_yy(y) from the momentum balance (conventions: module doc).

    gravity: a Scene or the gravity vector (dim components). inertia: optional rho nu a per
    bin, shape (n, dim) (see :func:`unsteady_inertia`); None means steady. top_stress:
    (tau_xy(H), tau_yy(H)), e.g. a top wall's measured stress; 0 for a free surface.
    wall_stress: instead integrate upwards from a measured lower-wall stress (Campbell's
    Couette programme, L4337-4348): tau(y) = tau_wall - int_wall^y rho nu (g - a) dy', with
    the wall at ``wall`` (default: the grid's lower edge); top_stress is then ignored. The
    stretch between the wall and the first centre uses the first bin's value (trapezoid).
    Returns ``y``, ``tau_xy``, ``tau_yy`` and their ``_err`` (NaN above H).
    """
    dim = _dim(profiles)
    g = gravity_of(gravity, dim)
    rho = MATERIAL_DENSITY[dim]
    nu = np.nan_to_num(np.asarray(profiles["solid_fraction"], float))
    nu_err = _err(profiles, "solid_fraction")
    n = nu.size
    acc = np.zeros((n, dim)) if inertia is None else np.nan_to_num(np.asarray(inertia, float))
    acc_err = (
        np.zeros((n, dim)) if inertia_err is None else np.nan_to_num(np.asarray(inertia_err, float))
    )
    fx = rho * nu * g[0] - acc[:, 0]
    fy = -rho * nu * g[axis] + acc[:, axis]
    fx_err = np.hypot(rho * g[0] * nu_err, acc_err[:, 0])
    fy_err = np.hypot(rho * g[axis] * nu_err, acc_err[:, axis])
    edges = _edges(profiles)
    w = stress_integration_matrix(profiles["y"], edges, top, rule, nu if sparse_top else None)
    if wall_stress is not None:
        y0 = float(edges[0]) if wall is None else float(wall)
        full = np.nan_to_num(w[0]).copy()  # int_wall^H as a row of weights
        full[0] += (profiles["y"][0] if rule == "trapezoid" else edges[0]) - y0
        w = w - full[None, :]
        top_stress = wall_stress
    out = {"y": np.asarray(profiles["y"], float)}
    for name, f, fe, t in (
        ("tau_xy", fx, fx_err, top_stress[0]),
        ("tau_yy", fy, fy_err, top_stress[1]),
    ):
        out[name] = w @ f + t
        out[f"{name}_err"] = np.sqrt((w * w) @ (fe * fe))
    return out


def campbell_depth(profiles: dict[str, Any], wall: float) -> float:
    """Campbell's flow depth H = 2 x the mass-mean height of the particles above ``wall``
    (volume weighting keeps a particle's centroid, so this is the mean centre height up to
    the bins' quadrature)."""
    nu = np.nan_to_num(np.asarray(profiles["solid_fraction"], float))
    y = np.asarray(profiles["y"], float)
    width = np.diff(_edges(profiles))
    mass = nu * width
    return float(2 * np.sum(mass * (y - wall)) / np.sum(mass))


def kinetic_stress(profiles: dict[str, Any]) -> dict[str, np.ndarray]:
    """Kinetic ("Reynolds") stresses in Campbell's signs: tau_xx = rho nu <u'^2>,
    tau_yy = rho nu <v'^2> (compressive positive), tau_xy = -rho nu <u'v'>.
    (Campbell's listing prints -nu <u'^2>, -nu <v'^2>, -nu <u'v'>: tension positive, rho_p = 1/pi
    omitted.) rho nu = the bin's mass density (n mean_mass)."""
    dim = _dim(profiles)
    rho = MATERIAL_DENSITY[dim]
    nu = np.asarray(profiles["solid_fraction"], float)
    nu_err = _err(profiles, "solid_fraction")
    var, var_err = velocity_variances(profiles)
    uv = np.asarray(profiles["kinetic_shear"], float)
    uv_err = _err(profiles, "kinetic_shear")
    out: dict[str, np.ndarray] = {"y": np.asarray(profiles["y"], float)}
    for name, q, qe, sign in (
        ("tau_xx", var[:, 0], var_err[:, 0], 1.0),
        ("tau_yy", var[:, 1], var_err[:, 1], 1.0),
        ("tau_xy", uv, uv_err, -1.0),
    ):
        out[name] = sign * rho * nu * q
        out[f"{name}_err"] = rho * np.hypot(nu_err * q, nu * qe)
    return out


# -- shear rate, S, Bagnold coefficients ------------------------------------------------
def shear_rate(
    profiles: dict[str, Any], component: int = 0, bc_type: str = "not-a-knot"
) -> tuple[np.ndarray, np.ndarray]:
    """du/dy at the bin centres from a scipy CubicSpline through the finite bins (Campbell:
    cubic-spline derivatives; his end points came from a least-squares quartic, here the
    spline's not-a-knot end conditions). Exact for polynomials of degree <= 3. The error is
    the spline's linear map applied to the velocity errors (bins independent)."""
    from scipy.interpolate import CubicSpline  # noqa: PLC0415 - not needed by engine runs

    y = np.asarray(profiles["y"], float)
    u = np.asarray(profiles["velocity"], float)[:, component]
    ue = _err(profiles, "velocity")[:, component]
    ok = np.isfinite(u)
    du, du_err = np.full(y.size, np.nan), np.full(y.size, np.nan)
    if ok.sum() < 2:
        return du, du_err
    yk = y[ok]
    du[ok] = CubicSpline(yk, u[ok], bc_type=bc_type)(yk, 1)
    basis = CubicSpline(yk, np.eye(yk.size), bc_type=bc_type, axis=0)(yk, 1)
    du_err[ok] = np.sqrt((basis * basis) @ (ue[ok] ** 2))
    return du, du_err


def s_parameter(
    profiles: dict[str, Any],
    variant: str = "text",
    radius: float = 0.5,
    rate: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Savage-Jeffrey S per bin.

    ``variant="text"``: S = 2R (du/dy) / sqrt(<u'^2>) (signed; the thesis text).
    ``variant="listing"``: S = 2R |du/dy| / sqrt(<u'^2> + <v'^2>) (the listing's
    QR = 2 sqrt(DUY2/(QUP+QVP)) with R = 1; in 3D still the x and y components).
    R = d/2 = 0.5 in particle units. ``rate``: (du/dy, err), default :func:`shear_rate`.
    """
    du, du_err = shear_rate(profiles) if rate is None else rate
    var, var_err = velocity_variances(profiles)
    if variant == "text":
        q, qe, num = var[:, 0], var_err[:, 0], 2 * radius * du
    elif variant == "listing":
        q, qe, num = (
            var[:, 0] + var[:, 1],
            np.hypot(var_err[:, 0], var_err[:, 1]),
            2 * radius * np.abs(du),
        )
    else:
        raise ValueError(f"variant must be 'text' or 'listing', got {variant!r}")
    with np.errstate(divide="ignore", invalid="ignore"):
        s = num / np.sqrt(q)
        err = np.hypot(2 * radius * du_err / np.sqrt(q), 0.5 * s * qe / q)
    return s, err


def bagnold_coefficients(
    tau: ArrayLike,
    rate: ArrayLike,
    dim: int,
    definition: str = "campbell",
    tau_err: ArrayLike | None = None,
    rate_err: ArrayLike | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """f(nu) = tau / (rho L^2 (du/dy)^2): f_s from tau_xy, f_N from tau_yy.

    ``definition``:
    * ``"campbell"``: the thesis, tau = rho_p f R^2 (du/dy)^2 (R = d/2): f = 4 tau / (rho gamma^2).
    * ``"listing"``: the listing's FNU = |tau| / DUY2 in its units (R = 1, m = 1, rho_p = 1/pi
      in 2D), i.e. without the pi: f_campbell * rho R^dim / m = f_campbell / pi (2D),
      3 f_campbell / (4 pi) (3D).
    * ``"diameter"``: Bagnold with d, f = tau / (rho d^2 gamma^2) = f_campbell / 4.
    The listing takes |tau|; the other two keep the sign of tau. NaN where du/dy = 0.
    """
    rho = MATERIAL_DENSITY[dim]
    tau = np.asarray(tau, float)
    rate = np.asarray(rate, float)
    te = np.zeros_like(tau) if tau_err is None else np.asarray(tau_err, float)
    re = np.zeros_like(rate) if rate_err is None else np.asarray(rate_err, float)
    radius = 0.5
    if definition == "campbell":
        scale, t = 1 / (rho * radius**2), tau
    elif definition == "listing":
        scale, t = radius ** (dim - 2), np.abs(tau)  # tau R^(dim-2) / (m gamma^2), m = 1
    elif definition == "diameter":
        scale, t = 1 / rho, tau
    else:
        raise ValueError(
            f"definition must be 'campbell', 'listing' or 'diameter', got {definition!r}"
        )
    with np.errstate(divide="ignore", invalid="ignore"):
        f = scale * t / rate**2
        err = np.abs(f) * np.hypot(te / tau, 2 * re / rate)
        f = np.where(rate == 0, np.nan, f)
    return f, err


# -- equation of state, slip, friction, Knudsen ------------------------------------------
def equation_of_state(
    profiles: dict[str, Any], pressure: ArrayLike, pressure_err: ArrayLike | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Campbell's chi(nu) = p / (rho sum_a <v_a'^2>) with the given pressure p (2D:
    rho_p (<u'^2> + <v'^2>); 3D: all three components; chute: p = tau_yy, the weight above).
    Compare with :func:`demstudy.theory.campbell_chi` = nu Z / dim."""
    dim = _dim(profiles)
    var, var_err = velocity_variances(profiles)
    q = var.sum(1)
    qe = np.sqrt((var_err**2).sum(1))
    p = np.asarray(pressure, float) * np.ones_like(q)
    pe = (
        np.zeros_like(q)
        if pressure_err is None
        else np.asarray(pressure_err, float) * np.ones_like(q)
    )
    rho = MATERIAL_DENSITY[dim]
    with np.errstate(divide="ignore", invalid="ignore"):
        chi = p / (rho * q)
        err = np.abs(chi) * np.hypot(pe / p, qe / q)
    return chi, err


def wall_slip(
    profiles: dict[str, Any],
    wall: float,
    side: str = "lower",
    wall_velocity: float = 0.0,
    method: str = "extrapolate",
    n_fit: int = 2,
    component: int = 0,
) -> tuple[float, float]:
    """Slip velocity u(wall) - U_wall at one wall.

    ``method="extrapolate"`` (default): least-squares straight line through the ``n_fit``
    finite bins nearest the wall, evaluated at ``wall`` (pass the wall plane, or the contact
    plane wall +- d/2 if that is the reference wanted). ``"first_bin"``: the nearest bin's
    velocity. ``"malik"``: the mean of the two bins nearest the wall (Malik's "average of
    two bins adjacent to the wall", one reading).
    """
    y = np.asarray(profiles["y"], float)
    u = np.asarray(profiles["velocity"], float)[:, component]
    ue = _err(profiles, "velocity")[:, component]
    idx = np.flatnonzero(np.isfinite(u))
    if side == "upper":
        idx = idx[::-1]
    elif side != "lower":
        raise ValueError(f"side must be 'lower' or 'upper', got {side!r}")
    if method == "first_bin":
        weights, sel = np.array([1.0]), idx[:1]
    elif method == "malik":
        weights, sel = np.array([0.5, 0.5]), idx[:2]
    elif method == "extrapolate":
        if n_fit < 2:
            raise ValueError("n_fit must be >= 2")
        sel = idx[:n_fit]
        a = np.stack([np.ones(sel.size), y[sel] - wall], axis=1)
        weights = np.linalg.pinv(a)[0]  # intercept at the wall = weights @ u
    else:
        raise ValueError(f"unknown method {method!r}")
    if sel.size < weights.size:
        raise ValueError("not enough finite bins near the wall")
    return (
        float(weights @ u[sel] - wall_velocity),
        float(np.sqrt(np.sum((weights * ue[sel]) ** 2))),
    )


def friction_coefficient(
    tau_xy: ArrayLike,
    tau_yy: ArrayLike,
    tau_xy_err: ArrayLike | None = None,
    tau_yy_err: ArrayLike | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """mu = tau_xy / tau_yy (Campbell's local friction angle is atan(mu)); errors assume the
    two stresses independent (they are positively correlated: an overestimate)."""
    a, b = np.asarray(tau_xy, float), np.asarray(tau_yy, float)
    ae = np.zeros_like(a) if tau_xy_err is None else np.asarray(tau_xy_err, float)
    be = np.zeros_like(b) if tau_yy_err is None else np.asarray(tau_yy_err, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        mu = a / b
        err = np.hypot(ae / b, mu * be / b)
    return mu, err


def knudsen_enskog(profiles: dict[str, Any], width: float) -> np.ndarray:
    """Kn(y) = lambda_Enskog(nu(y)) / W (Malik's Kn = lambda / W with the theoretical mean
    free path of the local solid fraction, frame-independent; the measured one, relative to
    the local mean flow, needs the collision log: ``statistics/freepath``)."""
    dim = _dim(profiles)
    nu = np.asarray(profiles["solid_fraction"], float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return mean_free_path(nu, dim) / width


# -- everything a results file supports, as the group /statistics/derived -----------------
DERIVED_GROUP = "statistics/derived"
"""Where :func:`derived_results` belongs in a results file."""

_CONVENTIONS = (
    "Campbell's signs: tau_yy = P_yy (compressive positive), tau_xy = -P_xy; R = d/2; "
    "rho = 4/pi (2D, per unit thickness), 6/pi (3D); f = tau / (rho R^2 (du/dy)^2) "
    "(bagnold_coefficients 'campbell'); chi = p / (rho sum_a <v_a'^2>); slip = u(wall) - "
    "U_wall; errors propagated linearly from the *_err with the bins independent")


def _production(results: Any) -> np.ndarray | None:
    """Mask of the production samples of /timeseries (time > equilibration_end)."""
    t = results.timeseries.get("time")
    if t is None:
        return None
    t = np.asarray(t, float)
    start = results.attrs.get("equilibration_end")
    if start is None:
        return np.ones(t.shape, bool)
    start = float(start)
    keep = t > start + 1e-9 * max(1.0, abs(start))
    return keep if keep.any() else np.ones(t.shape, bool)


def _production_mean(results: Any, key: str) -> float | None:
    values = results.timeseries.get(key)
    keep = _production(results)
    if values is None or keep is None:
        return None
    values = np.asarray(values, float)[keep]
    values = values[np.isfinite(values)]
    return float(values.mean()) if values.size else None


def _scene_of(results: Any) -> Any:
    from demstudy.scene import parse_scene_text, validate_scene  # noqa: PLC0415

    text = results.attrs.get("analysis_scene_toml") or results.attrs.get("scene_toml")
    if not text:
        raise ValueError("derived_results: give the scene (the results hold no scene_toml)")
    return validate_scene(parse_scene_text(text, "scene_toml"), "scene_toml")


def derived_results(
    results: Any,
    scene: Any = None,
    *,
    slip_method: str = "extrapolate",
    n_fit: int = 2,
) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
    """Every derived quantity that ``results`` supports, as the group ``/statistics/derived``
    (``DERIVED_GROUP``): ``(datasets, attrs)``.

    ``results``: a :class:`demstudy.io.results.Results` (``/profiles`` along y, optional
    ``/stress`` or ``/statistics/stress``, ``/timeseries``); ``scene``: its Scene (default: the
    file's ``analysis_scene_toml`` or ``scene_toml``). Computed when the data allow, with
    ``*_err`` where the functions give errors:

    * ``shear_rate`` du/dy (:func:`shear_rate`), ``S_text``, ``S_listing`` (:func:`s_parameter`);
    * with a measured stress (``/stress`` holding ``contact`` or ``collisional``):
      ``tau_xy`` = −P_xy, ``tau_yy`` = P_yy and ``pressure`` = tr P/dim of ``total``, the
      Bagnold coefficients ``f_s``, ``f_N`` (:func:`bagnold_coefficients`, Campbell's
      definition), ``friction`` μ and ``chi`` (:func:`equation_of_state` with p = pressure);
    * with gravity: the momentum balance ``balance_tau_xy``, ``balance_tau_yy`` (those of
      ``/stress`` when present, with the unsteady term; else steady,
      :func:`momentum_balance_stress`, from a free surface or the upper wall's stress) and
      ``f_s_balance``, ``f_N_balance``, ``friction_balance``, ``chi_balance`` (p = τ_yy, the
      weight above: Campbell's chute reading);
    * ``chi_theory`` = ν Z/dim (:func:`demstudy.theory.campbell_chi`) for a constant restitution;
    * per wall ``slip_<side>`` (:func:`wall_slip`, ``slip_method``, ``n_fit``) at the mean
      production wall position and speed (servo walls move);
    * ``lambda_enskog`` and ``knudsen_enskog`` (:func:`knudsen_enskog`) with W the wall gap
      (mean over production with the servo), the periodic height, or Campbell's flow depth
      (open top); attributes ``knudsen_width``, ``knudsen_width_is``.

    What cannot be computed is left out and said in ``attrs["skipped"]`` (one
    ``"name: reason"`` per line, ``"none"`` when nothing was skipped); ``attrs["computed"]``
    lists the datasets (without ``_err``). Empty bins give NaN.
    """
    from demstudy import UNITS_NOTE  # noqa: PLC0415
    from demstudy.analysis.stress import wall_stress  # noqa: PLC0415 (stress imports us)
    from demstudy.theory import campbell_chi  # noqa: PLC0415

    if scene is None:
        scene = _scene_of(results)
    dim = scene.dimension
    profiles = dict(results.profiles or {})
    data: dict[str, np.ndarray] = {}
    skipped: dict[str, str] = {}
    attrs: dict[str, Any] = {"units": UNITS_NOTE, "dim": dim, "conventions": _CONVENTIONS}

    def finish() -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        attrs["skipped"] = "\n".join(f"{k}: {v}" for k, v in skipped.items()) or "none"
        attrs["computed"] = ",".join(k for k in data if not k.endswith("_err")
                                     and k not in ("y", "edges"))
        return data, attrs

    needed = ("y", "solid_fraction", "velocity", "temperature_components")
    missing = [k for k in needed if k not in profiles]
    if missing:
        why = "no /profiles" if not profiles else f"/profiles lacks {', '.join(missing)}"
        skipped["everything"] = why
        return finish()
    axis = (getattr(results, "profile_attrs", None) or {}).get("axis", scene.measure.axis)
    if axis != "y":
        skipped["everything"] = (f"profiles along {axis}: the derived quantities need "
                                 "profiles along y (the wall-normal, gradient axis)")
        return finish()
    y = np.asarray(profiles["y"], float)
    nu = np.asarray(profiles["solid_fraction"], float)
    data["y"] = y
    if "edges" in profiles:
        data["edges"] = np.asarray(profiles["edges"], float)

    # shear rate and S
    rate = shear_rate(profiles)
    if np.isfinite(rate[0]).any():
        data["shear_rate"], data["shear_rate_err"] = rate
        for variant in ("text", "listing"):
            data[f"S_{variant}"], data[f"S_{variant}_err"] = s_parameter(profiles, variant,
                                                                         rate=rate)
    else:
        skipped["shear_rate, S_text, S_listing, f_*"] = "fewer than two bins hold particles"

    def coefficients(suffix: str, txy, txy_e, tyy, tyy_e) -> None:
        if "shear_rate" not in data:
            return
        for name, tau, err in (("f_s", txy, txy_e), ("f_N", tyy, tyy_e)):
            data[f"{name}{suffix}"], data[f"{name}{suffix}_err"] = bagnold_coefficients(
                tau, rate[0], dim, "campbell", err, rate[1])

    # the measured stress
    stress = results.groups.get("stress") or results.groups.get("statistics/stress") or {}
    measured = [p for p in ("contact", "collisional") if p in stress]
    n = y.size
    if not stress or "total" not in stress:
        skipped["tau_xy, tau_yy, pressure, f_s, f_N, friction, chi"] = "no /stress"
    elif not measured:
        skipped["tau_xy, tau_yy, pressure, f_s, f_N, friction, chi"] = (
            "/stress holds only the kinetic part (no contact or collisional stress)")
    elif np.asarray(stress["total"]).shape[0] != n:
        skipped["tau_xy, tau_yy, pressure, f_s, f_N, friction, chi"] = (
            "/stress bins differ from the /profiles bins")
    else:
        total = np.asarray(stress["total"], float)
        total_err = np.asarray(stress.get("total_err", np.zeros_like(total)), float)
        txy, txy_e = -total[:, 0, 1], total_err[:, 0, 1]
        tyy, tyy_e = total[:, 1, 1], total_err[:, 1, 1]
        diag = np.arange(dim)
        p = total[:, diag, diag].sum(1) / dim
        p_e = np.sqrt((total_err[:, diag, diag] ** 2).sum(1)) / dim
        data.update(tau_xy=txy, tau_xy_err=txy_e, tau_yy=tyy, tau_yy_err=tyy_e,
                    pressure=p, pressure_err=p_e)
        coefficients("", txy, txy_e, tyy, tyy_e)
        data["friction"], data["friction_err"] = friction_coefficient(txy, tyy, txy_e, tyy_e)
        data["chi"], data["chi_err"] = equation_of_state(profiles, p, p_e)
        attrs["stress_parts"] = "kinetic + " + " + ".join(measured)

    # the momentum balance
    balance_names = ("balance_tau_xy, balance_tau_yy, f_s_balance, f_N_balance, "
                     "friction_balance, chi_balance")
    if scene.gravity_vector is None:
        skipped[balance_names] = "no gravity"
    else:
        bal = None
        if "balance_tau_xy" in stress and np.asarray(stress["balance_tau_xy"]).shape == (n,):
            bal = {k: np.asarray(stress[f"balance_{k}"], float)
                   for k in ("tau_xy", "tau_yy", "tau_xy_err", "tau_yy_err")
                   if f"balance_{k}" in stress}
            attrs["balance_source"] = "/stress (" + str(
                (results.group_attrs.get("stress") or {}).get("balance", "as stored")) + ")"
        else:
            top = (0.0, 0.0)
            upper = scene.wall("upper")
            why = None
            if upper is not None:
                if "wall_force_upper" in results.timeseries:
                    section = float(np.prod([scene.box.size[i] for i in range(dim) if i != 1]))
                    area = (results.timeseries.get("width", section) if dim == 2 else section)
                    start = float(results.attrs.get("equilibration_end", 0.0))
                    column, _ = wall_stress(results.timeseries, "upper", area, start)
                    top = (-float(column[0]), float(column[1]))
                else:
                    why = "an upper wall whose force is not in /timeseries"
            if why is None:
                bal = momentum_balance_stress(profiles, scene, top_stress=top)
                attrs["balance_source"] = ("steady momentum balance from the profiles, "
                                           + ("the upper wall's stress" if upper is not None
                                              else "a free surface"))
            else:
                skipped[balance_names] = why
        if bal is not None:
            zero = np.zeros(n)
            bxy, byy = bal["tau_xy"], bal["tau_yy"]
            bxy_e, byy_e = bal.get("tau_xy_err", zero), bal.get("tau_yy_err", zero)
            data.update(balance_tau_xy=bxy, balance_tau_xy_err=bxy_e,
                        balance_tau_yy=byy, balance_tau_yy_err=byy_e)
            coefficients("_balance", bxy, bxy_e, byy, byy_e)
            data["friction_balance"], data["friction_balance_err"] = friction_coefficient(
                bxy, byy, bxy_e, byy_e)
            data["chi_balance"], data["chi_balance_err"] = equation_of_state(profiles, byy,
                                                                             byy_e)

    # kinetic theory's chi
    law = scene.contact.law.model
    if law == "constant":
        with np.errstate(divide="ignore", invalid="ignore"):
            chi = np.asarray(campbell_chi(np.nan_to_num(nu), dim, scene.contact.restitution),
                             float)
        data["chi_theory"] = np.where(np.isfinite(nu) & (nu > 0), chi, np.nan)
    else:
        skipped["chi_theory"] = f"restitution law {law!r} is not constant"

    # wall slip
    if not scene.walls:
        skipped["slip"] = "no walls"
    for wall in scene.walls:
        side = wall.side
        position = _production_mean(results, f"wall_position_{side}")
        position = scene.wall_position(side) if position is None else position
        speed = _production_mean(results, f"wall_velocity_{side}")
        speed = float(wall.velocity) if speed is None else speed
        try:
            slip, err = wall_slip(profiles, position, side, speed, slip_method, n_fit)
        except ValueError as exc:
            skipped[f"slip_{side}"] = str(exc)
            continue
        data[f"slip_{side}"], data[f"slip_{side}_err"] = np.float64(slip), np.float64(err)
        attrs[f"slip_{side}_wall_position"] = position
        attrs[f"slip_{side}_wall_velocity"] = speed
    if scene.walls:
        attrs["slip_method"] = slip_method if slip_method != "extrapolate" else \
            f"extrapolate: straight line through the {n_fit} finite bins nearest the wall"

    # Enskog Knudsen number
    if scene.y_periodic:
        width, what = float(scene.box.size[1]), "periodic height"
    elif scene.has_open_top:
        width = campbell_depth(profiles, scene.wall_position("lower"))
        what = "flow depth (campbell_depth)"
    else:
        gap = _production_mean(results, "gap")
        width = (scene.wall_position("upper") - scene.wall_position("lower")
                 if gap is None else gap)
        what = "wall gap" + (" (mean over production)" if gap is not None else "")
    with np.errstate(divide="ignore", invalid="ignore"):
        lam = np.asarray(mean_free_path(nu, dim), float)
    lam = np.where(np.isfinite(lam) & (nu > 0), lam, np.nan)
    data["lambda_enskog"] = lam
    data["knudsen_enskog"] = lam / width
    attrs["knudsen_width"], attrs["knudsen_width_is"] = width, what
    return finish()
