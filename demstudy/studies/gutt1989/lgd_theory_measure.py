"""Gutt's Ch. 2 Couette solution mapped onto his LGD Couette lattice, and what the LGD
Couette runs measure in the solution's terms (used by :mod:`.lgd_theory`).

Dimensionless particle units: d = 1 (the lattice spacing), m = 1, no gravity: the wall speed
U = u_w = 1 sets the time scale (docs/lgd-engine.md). Stresses are forces per wall particle
(wall particles sit one spacing apart, so also per unit wall length, m U²/d²).

Mapping (docs/studies/gutt1989.md, LGD theory part):
* roughness: a grain touches the straight wall row only along the two bonds at ±60° from it
  (k = (±½, √3/2); the horizontal bond joins nodes of one row), so every grain–wall
  collision has (k·τ)² = 1/4 and ⟨k_τ²⟩ = 1/4 exactly (:func:`wall_row_k2` from the node
  geometry);
* gap: the open rows 2..nyt−1 each own a strip √3/2 high, h = (nyt − 2)·√3/2;
* inventory: packed against one wall the N grains fill N/nxt full rows, so the free space is
  Δh₂D = h − (N/nxt)·√3/2. Gutt's Δh = (3/d)∫s dy is the 3D cell model (ν ≈ ν_max(1 − 3s/d));
  in 2D ν ≈ ν_max(1 − 2s/d), i.e. Δh₂D = (2/d)∫s dy, so the solution (written with the 3D
  factor) gets Δh = (3/2)·Δh₂D. Δh sets only p0 and σ0, not any ratio compared here;
* restitutions from the run: e_pp = iep1/ke, e_w = iew1/ke (constant laws: iep1 = iep2);
* γ ∝ 1 − e_pp² (L719–L721): γ = 0 for the elastic bulk; for e_pp < 1 the thesis's 0.16
  (assumed: the thesis ties its γ to no particular e).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...theory import GuttWallConstants, WallCouette, wall_couette
from . import lgd_measure as m
from .couette_measure import fit_curvature

ROW = m.ROW
#: the thesis's bulk dissipation tag (fig 2.4 caption), used for an inelastic bulk (assumed)
THESIS_GAMMA = 0.16
#: grain rows next to each wall left out of the bulk fits of the profile's curvature
WALL_LAYER = 3


def wall_row_k2(nxt: int = 6) -> np.ndarray:
    """(k·τ)² of every bond between a grain node of storage row 1 and the nodes of the wall
    row 0, from the engine's node geometry (x = (c + 1 + r/2) mod nxt, y = r·√3/2): the
    nodes at distance one spacing (periodic in x)."""
    if nxt < 3:
        raise ValueError(f"nxt must be >= 3 (a periodic row with distinct neighbours), got {nxt}")
    c = np.arange(nxt)
    grain = np.array([(0 + 1 + 0.5) % nxt, ROW])
    wall = np.stack([(c + 1.0) % nxt, np.zeros(nxt)], 1)
    dx = (wall[:, 0] - grain[0] + nxt / 2) % nxt - nxt / 2
    d = np.hypot(dx, wall[:, 1] - grain[1])
    bonds = np.isclose(d, 1.0)
    return (dx[bonds] / d[bonds]) ** 2  # k_τ = k·x̂, the wall's slip direction


def channel(nxt: int, nyt: int, grains: int) -> dict[str, float]:
    """h, Δh₂D and the 3D-equivalent Δh of the lattice channel (module docstring)."""
    h = (nyt - 2) * ROW
    packed = grains / nxt * ROW
    if not 0 < packed < h:
        raise ValueError(f"grains = {grains} must fill less than the {nyt - 2} open rows of "
                         f"{nxt} nodes")
    return {"h": h, "delta_h_2d": h - packed, "delta_h": 1.5 * (h - packed)}


def restitutions(attrs: dict[str, Any]) -> tuple[float, float]:
    """(e_pp, e_w) of an LGD run from its integer coefficients."""
    ke = float(attrs["lgd_ke"])
    if attrs["lgd_iep1"] != attrs["lgd_iep2"] or attrs["lgd_iew1"] != attrs["lgd_iew2"]:
        raise ValueError("a piecewise restitution law has no single e_pp, e_w for Gutt's Ch. 2")
    return float(attrs["lgd_iep1"]) / ke, float(attrs["lgd_iew1"]) / ke


def constants(run: m.LgdRun, gamma: float | None = None) -> GuttWallConstants | None:
    """Gutt's constants for ``run`` (thesis tags, the lattice's h, Δh, ⟨k_τ²⟩ = 1/4, the run's
    e_w; γ from e_pp unless given). None when nothing dissipates (γ = 0 and e_w = 1)."""
    e_pp, e_w = restitutions(run.attrs)
    if gamma is None:
        gamma = 0.0 if e_pp == 1 else THESIS_GAMMA
    if gamma == 0 and e_w == 1:
        return None
    ch = channel(run.nxt, run.nyt, run.position.shape[1])
    return GuttWallConstants(gamma=gamma, e_w=e_w, k2=float(np.mean(wall_row_k2())),
                             h=ch["h"], delta_h=ch["delta_h"])


@dataclass
class Measured:
    """What one LGD Couette run gives in Gutt's terms (values, errors)."""

    name: str
    e_pp: float
    e_w: float
    values: dict[str, tuple[float, float]] = field(default_factory=dict)
    profile: dict[str, np.ndarray] = field(default_factory=dict)  # y from the centre, ...

    def v(self, key: str) -> float:
        return self.values[key][0]

    def e(self, key: str) -> float:
        return self.values[key][1]


def _window(run: m.LgdRun) -> np.ndarray:
    """Frames of the steady window: the last 256 steps of a 1024-step run (as the LGD part),
    every kept frame (the last 1024 steps) of a longer one."""
    last = int(run.frame_steps.max())
    width = 1024 if last > 2048 else 256
    return np.flatnonzero(run.frame_steps > last - width)


def row_profiles(run: m.LgdRun, frames: np.ndarray) -> dict[str, np.ndarray]:
    """:func:`lgd_measure.mean_profiles` with every grain counted in an open row: a grain's
    offset reaches ½ spacing, more than half the row spacing √3/2, so rounding y/(√3/2)
    puts some grains of rows 2 and nyt − 1 into the wall rows; their y is clipped first."""
    y_lo, y_hi = ROW, (run.nyt - 2) * ROW
    profs = []
    for i in frames:
        pos = run.position[i].copy()
        pos[:, 1] = np.clip(pos[:, 1], y_lo, y_hi)
        profs.append(m.row_profiles(pos, run.velocity[i], run.nyt))
    out = {"y": profs[0]["y"]}
    with warnings.catch_warnings():  # the wall rows hold no grains: NaN
        warnings.simplefilter("ignore", RuntimeWarning)
        m._average(profs, out)
    return out


def _wall_pair(a: float, ea: float, b: float, eb: float) -> tuple[float, float]:
    return 0.5 * (a + b), 0.5 * math.hypot(ea, eb)


def measure(run: m.LgdRun) -> Measured:
    """σ0/p0 (wall-stress timeseries, second half, both walls), slip and thermal velocity at
    the grain rows next to the walls, the bulk's curvature ω² of v(y) and the profiles."""
    from .lgd_checks import wall_means

    e_pp, e_w = restitutions(run.attrs)
    out = Measured(run.name, e_pp, e_w)
    w = wall_means(run)
    (sh, esh), (pr, epr) = w["shear"], w["pressure"]
    ratio = sh / pr
    out.values["R"] = (ratio, abs(ratio) * math.hypot(esh / sh, epr / pr))
    out.values["shear"], out.values["pressure"] = (sh, esh), (pr, epr)
    p = row_profiles(run, _window(run))
    rows = np.flatnonzero(p["n"] > 0)
    lo, hi = rows[0], rows[-1]
    u_w = 1.0  # the walls move at ∓U = ∓1 (particle units)
    # slip: wall speed minus the flow at the grain rows touching the walls (lower at −U)
    out.values["slip"] = _wall_pair(u_w + p["vx"][lo], p["vx_err"][lo],
                                    u_w - p["vx"][hi], p["vx_err"][hi])
    out.values["v_wall"] = _wall_pair(p["thermal"][lo], p["thermal_err"][lo],
                                      p["thermal"][hi], p["thermal_err"][hi])
    y = p["y"] - (run.nyt - 1) * ROW / 2
    bulk = np.zeros(len(y), bool)
    bulk[lo + WALL_LAYER:hi - WALL_LAYER + 1] = True
    err = np.where(np.isfinite(p["thermal_err"]) & (p["thermal_err"] > 0), p["thermal_err"],
                   np.nanmedian(p["thermal_err"][rows]))
    w2, w2e, v_c = fit_curvature(y[bulk], p["thermal"][bulk], err[bulk])
    out.values["omega2"] = (w2, w2e)
    out.values["v_centre"] = (v_c, math.nan)
    out.values["wall_y"] = (float(y[hi]), 0.0)
    out.profile = {"y": y[rows], "u": p["vx"][rows], "u_err": p["vx_err"][rows],
                   "v": p["thermal"][rows], "v_err": p["thermal_err"][rows]}
    return out


def heating_rate(run: m.LgdRun, first_step: int) -> float:
    """Relative growth of the kinetic energy per 1000 steps from ``first_step`` to the end
    (least squares on the timeseries): 0 in a steady state."""
    ts = run.ts
    sel = ts["steps"] >= first_step
    steps, ke = ts["steps"][sel].astype(float), ts["kinetic_energy"][sel]
    slope = np.polyfit(steps, ke, 1)[0]
    return float(1000 * slope / np.mean(ke))


def fitted_gamma(meas: Measured, c: GuttWallConstants) -> tuple[float, float]:
    """γ that makes (2.10) give the bulk's measured ω² at the measured σ0/p0, with the
    thesis's t, q, r: γ = t²R²/q − r d² ω² (error propagated from R and ω²)."""
    ratio, e_ratio = meas.values["R"]
    w2, e_w2 = meas.values["omega2"]
    g = c.t**2 * ratio**2 / c.q - c.r * c.d**2 * w2
    err = math.hypot(2 * c.t**2 * ratio * e_ratio / c.q, c.r * c.d**2 * e_w2)
    return g, err


def solve(c: GuttWallConstants | None, **changes: float) -> WallCouette | None:
    if c is None:
        return None
    try:
        return wall_couette(c, n=401, **changes)
    except (ValueError, RuntimeError):
        return None


def theory_at(sol: WallCouette, y: np.ndarray, key: str) -> np.ndarray:
    """The solution's ``key`` profile (``u`` or ``v``) at positions ``y`` from the centre."""
    return np.interp(y, sol.y, getattr(sol, key))
