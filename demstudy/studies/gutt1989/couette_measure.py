"""What the Couette part of the Gutt (1989) study measures of one run, in Gutt's Ch. 2 forms.

Dimensionless particle units: d = 1, m = 1; no gravity: the wall speed u_w = 1 sets the time
scale (stresses in m u_w²/d² in 2D, m u_w²/d³ in 3D). The channel is y ∈ [0, h] in the runs
(Gutt's y' = y − h/2 ∈ [−h/2, h/2]), the lower wall moving at −u_w, the upper at +u_w.

Readings (each documented where it is made):

* **roughness** ⟨k_τ²⟩ = ⟨(k·x̂)²⟩ over the logged grain–wall collisions (kinds 1 and 2 of the
  collision log; k its normal, plane hits count with k·x̂ = 0), collision-weighted, as Gutt's
  f(k) enters his collision rate and impulses (L601-L611); error from 10 time blocks. τ = x̂,
  the slip direction; in 3D ⟨k_z²⟩ is reported too (the bumps' square grid is not isotropic);
* **σ0, p0**: the walls' time-mean stresses (−τ_x and τ_y of ``/stress`` wall_lower/upper,
  averaged over both walls, the engine's jackknife errors);
* **wall values** u(h/2), v(h/2): number-density-weighted means over the grain layer touching
  the wall (bins whose centre lies within ``LAYER`` = 1.25 d of the wall plane: flat-wall
  contacts at 0.5 d, bump contacts up to ~1 d), both walls averaged (u antisymmetric); slip
  u_s = u_w − u(h/2), Gutt's discontinuity between the wall and the grains at it;
* **thermal velocity** v = √(Σ_a ⟨C_a²⟩) over the dim components (Gutt's r.m.s. fluctuation,
  p = t d ρ v²/s);
* **solid fraction** as φ/φ_cp (φ_cp = 0.74 for spheres as Gutt's Δh, L777, and π/(2√3) for
  discs), the theory's 1 − 3 s/d of the cell model's Δh = (3/d)∫s dy (L765);
* **bulk fit** (bins at least ``BULK_SKIP`` = 1.5 d from both walls): v(y') = v_c cos(ω y')
  (cosh for ω² < 0) gives ω² (2.10-2.11); t = p s/(d ρ v²) (EOS, L625), q = σ s/(d² ρ v
  u'(y)) (L657) with s = (d/3)(1 − φ/φ_cp) and ρ = the number density (m = 1), bin means;
  then γ = t² R²/q − r d² ω² with r = 1 (thesis) and R = σ0/p0 measured.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import curve_fit

from ...analysis.blocking import split_mean
from ...io.results import read_results
from ...theory import GuttWallConstants, WallCouette, wall_couette

#: bins whose centre lies within this distance (d) of a wall plane form its grain layer
LAYER = 1.25
#: bins at least this far (d) from both walls are the bulk of the fits
BULK_SKIP = 1.5
#: close packing: Gutt's 0.74 for spheres (L777), hexagonal for discs
PHI_CP = {2: math.pi / (2 * math.sqrt(3)), 3: 0.74}
#: the theory's r (thesis, fig 2.4 caption) kept when γ is fitted
R_THESIS = 1.0


@dataclass
class CouetteRun:
    """One run's numbers (value, error) and profiles (y' from the channel's centre)."""

    name: str
    dim: int
    e_w: float
    u_w: float
    h: float
    values: dict[str, tuple[float, float]] = field(default_factory=dict)
    arrays: dict[str, np.ndarray] = field(default_factory=dict)

    def v(self, key: str) -> float:
        return self.values.get(key, (math.nan, math.nan))[0]

    def e(self, key: str) -> float:
        return self.values.get(key, (math.nan, math.nan))[1]


def roughness(kind: ArrayLike, normal: ArrayLike, time: ArrayLike,
              blocks: int = 10) -> dict[str, tuple[float, float]]:
    """⟨k_x²⟩ (and ⟨k_z²⟩ in 3D) over the wall collisions (kind > 0) of a collision log, the
    share of them on the flat plane between bumps (k = ±ŷ), errors from ``blocks``
    contiguous time blocks (nan with fewer collisions than blocks)."""
    kind, normal, time = np.asarray(kind), np.asarray(normal, float), np.asarray(time, float)
    wall = kind > 0
    if normal.ndim != 2 or normal.shape[0] != kind.shape[0]:
        raise ValueError(f"normal must be (M, dim) with M = {kind.shape[0]} collisions, got "
                         f"shape {normal.shape}")
    order = np.argsort(time[wall], kind="stable")
    k = normal[wall][order]
    out: dict[str, tuple[float, float]] = {}
    plane = np.abs(np.abs(k[:, 1]) - 1.0) < 1e-12 if len(k) else np.zeros(0, bool)
    series = {"k2": k[:, 0] ** 2, "plane_share": plane.astype(float)}
    if k.shape[1] == 3:
        series["k2_z"] = k[:, 2] ** 2
    for key, x in series.items():
        out[key] = split_mean(x, blocks)
    out["wall_collisions_logged"] = (float(k.shape[0]), 0.0)
    return out


def layer_mean(y: ArrayLike, weight: ArrayLike, value: ArrayLike, err: ArrayLike,
               mask: ArrayLike) -> tuple[float, float]:
    """Weighted mean of ``value`` over the ``mask`` bins (weights ``weight``, e.g. the
    number density) with the errors propagated as independent."""
    w = np.where(np.asarray(mask, bool), np.nan_to_num(np.asarray(weight, float)), 0.0)
    v, e = np.asarray(value, float), np.nan_to_num(np.asarray(err, float))
    ok = w > 0
    if not ok.any():
        return math.nan, math.nan
    total = w[ok].sum()
    return float(w[ok] @ v[ok] / total), float(math.sqrt(np.sum((w[ok] * e[ok]) ** 2)) / total)


def _cos_like(y: np.ndarray, v_c: float, w: float) -> np.ndarray:
    """v_c cos(√w y) (cosh for w < 0), analytic through w = 0 (series for tiny |w| y²)."""
    z2 = w * y**2
    if np.all(np.abs(z2) < 1e-6):
        return v_c * (1 - z2 / 2 + z2**2 / 24)
    if w > 0:
        return v_c * np.cos(math.sqrt(w) * y)
    return v_c * np.cosh(math.sqrt(-w) * y)


def fit_curvature(y: ArrayLike, v: ArrayLike, err: ArrayLike) -> tuple[float, float, float]:
    """(ω², its error, v_c) of v(y) = v_c cos(ω y) by weighted least squares (y from the
    channel's centre); ω² < 0 is the cosh branch."""
    y, v = np.asarray(y, float), np.asarray(v, float)
    e = np.asarray(err, float)
    ok = np.isfinite(v) & np.isfinite(e)
    sigma = np.where(e[ok] > 0, e[ok], np.nanmax(e[ok]) if np.any(e[ok] > 0) else 1.0)
    par, cov = curve_fit(_cos_like, y[ok], v[ok], p0=(float(np.mean(v[ok])), 0.0), sigma=sigma,
                         absolute_sigma=True)
    return float(par[1]), float(math.sqrt(max(cov[1, 1], 0.0))), float(par[0])


def _wall_stress(stress: dict) -> dict[str, tuple[float, float]]:
    lo, up = (np.asarray(stress[f"wall_{s}"], float) for s in ("lower", "upper"))
    lo_e, up_e = (np.asarray(stress[f"wall_{s}_err"], float) for s in ("lower", "upper"))
    sigma = (-(lo[0] + up[0]) / 2, math.hypot(lo_e[0], up_e[0]) / 2)
    p = ((lo[1] + up[1]) / 2, math.hypot(lo_e[1], up_e[1]) / 2)
    out = {"sigma0": sigma, "p0": p}
    if p[0] > 0:
        r = sigma[0] / p[0]
        out["R"] = (r, abs(r) * math.hypot(sigma[1] / sigma[0] if sigma[0] else 0.0,
                                           p[1] / p[0]))
    return out


def summarise(name: str, path: Path) -> CouetteRun:
    """Read one Couette results file into a :class:`CouetteRun`."""
    res = read_results(path)
    scene = res.scene
    dim = scene.dimension
    upper = scene.wall("upper")
    h = scene.wall_position("upper") - scene.wall_position("lower")
    run = CouetteRun(name, dim, float(upper.restitution), float(upper.velocity), h)
    log = res.groups.get("collisions")
    if log is not None and "kind" in log:
        run.values.update(roughness(log["kind"], log["normal"], log["time"]))
    run.values.update(_wall_stress(res.groups["stress"]))
    prof = res.profiles
    y = np.asarray(prof["y"], float) - scene.wall_position("lower") - h / 2
    n = np.asarray(prof["number_density"], float)
    comps = np.asarray(prof["temperature_components"], float)[:, :dim]
    comps_e = np.asarray(prof["temperature_components_err"], float)[:, :dim]
    v2 = comps.sum(axis=1)
    v2_e = np.sqrt(np.sum(comps_e**2, axis=1))
    u = np.asarray(prof["velocity"], float)[:, 0]
    u_e = np.asarray(prof["velocity_err"], float)[:, 0]
    phi = np.asarray(prof["solid_fraction"], float) / PHI_CP[dim]
    phi_e = np.asarray(prof["solid_fraction_err"], float) / PHI_CP[dim]
    with np.errstate(invalid="ignore", divide="ignore"):
        v = np.sqrt(v2)
        v_e = np.where(v > 0, v2_e / (2 * v), np.nan)
    run.arrays.update(y=y, u=u / run.u_w, u_err=u_e / run.u_w, v=v / run.u_w,
                      v_err=v_e / run.u_w, phi=phi, phi_err=phi_e,
                      t_x=comps[:, 0], t_y=comps[:, 1])
    top, bottom = y > h / 2 - LAYER, y < -h / 2 + LAYER
    u_top, u_bot = layer_mean(y, n, u, u_e, top), layer_mean(y, n, u, u_e, bottom)
    u_wall = ((u_top[0] - u_bot[0]) / 2, math.hypot(u_top[1], u_bot[1]) / 2)
    run.values["slip"] = (1 - u_wall[0] / run.u_w, u_wall[1] / run.u_w)
    v2_top, v2_bot = layer_mean(y, n, v2, v2_e, top), layer_mean(y, n, v2, v2_e, bottom)
    v2_wall = (v2_top[0] + v2_bot[0]) / 2
    run.values["v_wall"] = (math.sqrt(v2_wall) / run.u_w,
                            math.hypot(v2_top[1], v2_bot[1]) / 2 / (2 * math.sqrt(v2_wall))
                            / run.u_w if v2_wall > 0 else math.nan)
    bulk = np.abs(y) <= h / 2 - BULK_SKIP
    run.arrays["bulk"] = bulk
    mid = np.abs(y) < 1.0
    run.values["v_centre"] = (*(x / run.u_w for x in layer_mean(y, n, np.sqrt(v2), v_e,
                                                                 mid)),)
    run.values["phi_bulk"] = layer_mean(y, np.ones_like(y), phi, phi_e, bulk)
    layer = top | bottom
    run.values["phi_wall_layer"] = layer_mean(y, np.ones_like(y), phi, phi_e, layer)
    run.values["phi_bulk_ptp"] = (float(np.ptp(phi[bulk])), 0.0)
    run.values["anisotropy"] = layer_mean(y, n, comps[:, 0] / comps[:, 1],
                                          np.zeros_like(y), bulk)
    ke = np.asarray(res.timeseries["kinetic_energy"], float)
    t = np.asarray(res.timeseries["time"], float)
    prod = ke[t > float(res.attrs.get("equilibration_end", 0.0)) + 1e-9]
    if prod.size >= 4 and prod[: prod.size // 2].mean() > 0:
        half = prod.size // 2
        run.values["ke_drift"] = (prod[half:].mean() / prod[:half].mean() - 1, 0.0)
    run.values["ke_end_over_start"] = (float(ke[-1] / ke[0]) if ke[0] > 0 else math.nan, 0.0)
    # a flat (frictionless) wall transmits no shear: no flow to fit
    if run.v("k2") > 0 and run.v("R") > 0 and np.sum(bulk) >= 4:
        _fit_bulk(run, y, n, u, v, v_e, phi, bulk)
    return run


def _fit_bulk(run: CouetteRun, y: np.ndarray, n: np.ndarray, u: np.ndarray, v: np.ndarray,
              v_e: np.ndarray, phi: np.ndarray, bulk: np.ndarray) -> None:
    """ω², t, q, γ of the bulk (module docstring)."""
    w, w_e, _ = fit_curvature(y[bulk], v[bulk], v_e[bulk])
    run.values["omega2"] = (w, w_e)
    s = (1 - phi) / 3  # d = 1
    dudy = np.gradient(u, y)
    p0, sigma0 = run.v("p0"), run.v("sigma0")
    t_bins = p0 * s / (n * v**2)
    q_bins = sigma0 * s / (n * v * dudy)
    sel = bulk & np.isfinite(t_bins) & np.isfinite(q_bins) & (s > 0)
    for key, x in (("t_fit", t_bins[sel]), ("q_fit", q_bins[sel])):
        run.values[key] = (float(np.mean(x)), float(np.std(x, ddof=1) / math.sqrt(x.size)))
        run.values[f"{key}_spread"] = (float(np.std(x, ddof=1) / np.mean(x)), 0.0)
    t, q, r = run.v("t_fit"), run.v("q_fit"), run.v("R")
    run.values["gamma_fit"] = (t**2 * r**2 / q - R_THESIS * w, math.nan)


def theory(run: CouetteRun, fitted: bool = False, n: int = 201) -> WallCouette | None:
    """Gutt's Ch. 2 solution at the run's measured ⟨k_τ²⟩ and e_w (h = 10 d, Δh = 3.25 d):
    the thesis's constants, or (``fitted``) t, q, γ from the run's bulk (r, t_w, q_w, r_w
    the thesis's). None where it has no solution (a flat wall, ⟨k_τ²⟩ = 0, or a fit that
    leaves γ < 0 or t, q ≤ 0)."""
    k2 = run.v("k2")
    if not (math.isfinite(k2) and 0 < k2 <= 1):
        return None
    changes: dict[str, Any] = {"e_w": run.e_w, "k2": k2, "u_w": run.u_w}
    if fitted:
        t, q, g = run.v("t_fit"), run.v("q_fit"), run.v("gamma_fit")
        if not all(math.isfinite(x) and x > 0 for x in (t, q, g)):
            return None
        changes.update(t=t, q=q, gamma=g)
    try:
        return wall_couette(GuttWallConstants(**changes), n=n)
    except (ValueError, RuntimeError):
        return None
