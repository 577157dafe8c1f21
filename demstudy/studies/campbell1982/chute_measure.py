"""Campbell (1982) chutes: what one chute run measured, in the thesis's definitions.

Dimensionless particle units: d = 1, m = 1, g = 1 (lengths d, times √(d/g), speeds √(gd),
energies m g d, 2D stresses m g/d). Campbell's definitions (digest §1.2, §3.9, §4):

* kinetic energy per disc: translational + rotational (his QE: ½⟨u²⟩ + ½⟨v²⟩ + ½β⟨w²⟩), mean
  flow included;
* convergence (§2.5, L574-586): the energy "fluctuates within about 20 % of its mean with no
  trend". Quantified with :mod:`demstudy.analysis.steady`: the fitted change over the
  production window is below 20 % of the mean (|trend| < 0.2) within 2σ, σ the trend's error
  from the scatter of 8 block means about the fitted line (the energy of 40 discs wanders over
  hundreds of √(d/g): a single window's trend is noisy); the share of samples within
  ±20 % of the mean is reported beside it (40 discs fluctuate by factors 2-4 even when steady,
  docs/studies/campbell1982-chute30.md, so it is not a pass/fail test);
* steady momentum balance: the base's shear-to-normal force ratio |F_x/F_y| must equal tan α
  (x-momentum of the bed: M g sin α − F_x = dP_x/dt, F_y = M g cos α);
* depth H = 2 × the mass-mean height of the disc centres above the base plane y = 0 (L964);
* profiles against y/H: ν, u/u_max (u_max: the fastest strip holding ν ≥ 0.05; above the
  surface a few saltating discs make the strip means noisy), T = (⟨u'²⟩ + ⟨v'²⟩)/2 per degree
  of freedom and the rotational T = β⟨w'²⟩ (profiles' ``temperature``,
  ``rotational_temperature``), strips 1 d wide ("about one particle diameter", L801);
* wall slip: u in the strip 0 < y < 1 next to the base over u_max;
* stresses three ways, Campbell's signs (τ_yy compressive, τ_xy > 0 when the material above
  drags the material below downslope): the momentum balance integrated from the free surface
  (with his unsteady term), the base's wall stress, and kinetic + collisional (contact for soft
  discs) from the ``stress`` statistic.

Errors: block averages with jackknife (:mod:`demstudy.analysis.blocking`) of the production
samples; profile errors are those stored in the results file.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ...analysis.blocking import BlockAccumulator, jackknife, series_mean
from ...analysis.derived import MATERIAL_DENSITY, campbell_depth
from ...analysis.steady import energy_trend, is_steady

#: the dense phase of a flat-base bed, after the initial deceleration (chute30 study)
DENSE = (25.0, 200.0)
#: strips holding less than this are above the bed's surface (saltating discs)
SURFACE_NU = 0.05
#: Campbell's band: the energy fluctuates within about 20 % of its mean
BAND = 0.2


def no_trend(trend: float, err: float) -> bool:
    """Campbell's "no trend" made quantitative, for every history of the study: the fitted
    change over the production is below the criterion's 20 % (BAND) of the mean, or its
    excess over 20 % is within 2σ."""
    return is_steady(trend) or bool(np.isfinite(trend) and np.isfinite(err)
                                    and abs(trend) - 2 * err < BAND)


def trend_error(t: np.ndarray, energy: np.ndarray, blocks: int = 8) -> float:
    """Standard error of ``energy_trend`` from ``blocks`` block means (taken as independent:
    blocks of 200 √(d/g) are longer than the energy's correlation time) about their line."""
    t, energy = np.asarray(t, float), np.asarray(energy, float)
    if t.size < 2 * blocks:
        return float("nan")
    tb = np.array([c.mean() for c in np.array_split(t, blocks)])
    eb = np.array([c.mean() for c in np.array_split(energy, blocks)])
    fit = np.polyfit(tb - tb.mean(), eb, 1)
    resid = eb - np.polyval(fit, tb - tb.mean())
    slope_err = np.sqrt(np.sum(resid ** 2) / (blocks - 2) / np.sum((tb - tb.mean()) ** 2))
    return float(slope_err * np.ptp(t) / energy.mean())


def force_ratio(force: np.ndarray, max_blocks: int = 32) -> tuple[float, float]:
    """|mean F_x / mean F_y| of the base force over samples, with a jackknife block error."""
    force = np.asarray(force, float)
    force = force[np.all(np.isfinite(force), axis=1)]
    if force.shape[0] == 0 or force[:, 1].sum() == 0.0:
        return float("nan"), float("nan")
    acc = BlockAccumulator(2, max_blocks)
    for row in force[:, :2]:
        acc.add(row)

    def ratio(mean: np.ndarray) -> np.ndarray:
        return np.array([abs(mean[0] / mean[1]) if mean[1] != 0 else np.nan])

    est, err = jackknife(acc, ratio)
    return float(np.ravel(est)[0]), float(np.ravel(err)[0])


@dataclass
class ChuteRun:
    """One chute run reduced to Campbell's quantities (module doc)."""

    name: str
    angle: float
    rows: int
    columns: int
    base: str              # "flat" or "bumpy"
    law: str               # "constant" or "campbell-exp"
    e_p: float
    e_w: float
    engine: str
    tc: float | None
    t: np.ndarray          # all samples (equilibration too)
    energy: np.ndarray     # kinetic energy per disc (translation + rotation)
    start: float           # end of equilibration
    trend: float
    trend_err: float
    within: float          # share of production samples within ±20 % of the mean
    energy_mean: float
    energy_err: float
    ratio: float
    ratio_err: float
    ratio_dense: float
    ratio_dense_err: float
    depth: float
    u_max: float
    u_max_err: float
    slip: float
    slip_err: float
    tc_share: float
    wall_seconds: float
    seed: int = 12345
    profiles: dict[str, np.ndarray] = field(default_factory=dict)
    stress: dict[str, Any] = field(default_factory=dict)
    #: the collision-angle distribution (:func:`collision_angles`), empty without a log
    angles: dict[str, Any] = field(default_factory=dict)

    @property
    def tan_alpha(self) -> float:
        return math.tan(math.radians(self.angle))

    @property
    def converged(self) -> bool:
        """Campbell's criterion: no trend (|fitted change| < 20 % of the mean) within 2σ."""
        return no_trend(self.trend, self.trend_err)

    @property
    def balanced(self) -> bool:
        """The steady momentum balance: base force ratio = tan α within 2σ + 0.01 (the ratio's
        blocks are correlated: the error is an estimate)."""
        return bool(np.isfinite(self.ratio) and
                    abs(self.ratio - self.tan_alpha) <= 2 * np.nan_to_num(self.ratio_err) + 0.01)

    @property
    def steady(self) -> bool:
        """Steady by both tests: no energy trend and the base carries tan α of the weight."""
        return self.converged and self.balanced

    @property
    def label(self) -> str:
        law = "variable ε" if self.law != "constant" else f"ε_p {self.e_p:g}"
        return f"{self.angle:g}°, {self.base}, {self.rows}×{self.columns}, {law}, ε_w {self.e_w:g}"


def _production(t: np.ndarray, start: float) -> np.ndarray:
    keep = t > start + 1e-9 * max(1.0, start)
    return keep if keep.any() else np.ones(t.shape, bool)


def _profiles(res: Any) -> dict[str, np.ndarray]:
    p = res.profiles or {}
    out = {"y": np.asarray(p["y"], float), "edges": np.asarray(p["edges"], float)}
    for key, name in (("solid_fraction", "nu"), ("temperature", "T"),
                      ("rotational_temperature", "T_rot")):
        out[name] = np.asarray(p[key], float)
        out[f"{name}_err"] = np.nan_to_num(np.asarray(p.get(f"{key}_err", 0 * out[name]), float))
    out["u"] = np.asarray(p["velocity"], float)[:, 0]
    out["u_err"] = np.nan_to_num(np.asarray(p["velocity_err"], float)[:, 0])
    return out


def _stress(res: Any, prof: dict[str, np.ndarray], g: np.ndarray) -> dict[str, Any]:
    """The three routes in Campbell's signs, and each at the base."""
    s = res.groups.get("stress") or res.groups.get("statistics/stress") or {}
    if "balance_tau_xy" not in s:
        return {}
    out: dict[str, Any] = {k: np.asarray(s[k], float) for k in
                           ("balance_tau_xy", "balance_tau_xy_err", "balance_tau_yy",
                            "balance_tau_yy_err")}
    total = np.asarray(s["total"], float)
    total_err = np.nan_to_num(np.asarray(s["total_err"], float))
    out["stat_tau_xy"], out["stat_tau_xy_err"] = -total[:, 0, 1], total_err[:, 0, 1]
    out["stat_tau_yy"], out["stat_tau_yy_err"] = total[:, 1, 1], total_err[:, 1, 1]
    out["stat_parts"] = "kinetic + " + ("contact" if "contact" in s else "collisional")
    wall = np.asarray(s["wall_lower"], float)
    wall_err = np.asarray(s["wall_lower_err"], float)
    out["wall_tau_xy"], out["wall_tau_xy_err"] = -wall[0], wall_err[0]
    out["wall_tau_yy"], out["wall_tau_yy_err"] = wall[1], wall_err[1]
    # the balance continued from the first strip's centre down to the base plane y = 0:
    # + ρ ν₀ (g − a₀) over the half strip below the centre
    rho = MATERIAL_DENSITY[2]
    nu0 = float(np.nan_to_num(prof["nu"][0]))
    acc = np.asarray(s.get("balance_inertia", np.zeros((prof["y"].size, 2))), float)[0]
    half = float(prof["y"][0] - prof["edges"][0])
    out["base_balance_tau_xy"] = out["balance_tau_xy"][0] + (rho * nu0 * g[0] - acc[0]) * half
    out["base_balance_tau_yy"] = out["balance_tau_yy"][0] + (-rho * nu0 * g[1] + acc[1]) * half
    out["base_balance_tau_xy_err"] = out["balance_tau_xy_err"][0]
    out["base_balance_tau_yy_err"] = out["balance_tau_yy_err"][0]
    return out


def collision_angles(res: Any) -> dict[str, Any]:
    """Campbell's collision-angle distribution (Fig 3.33): P(θ) of the logged pair collisions
    of the production (θ, the text's convention: the line of centres from the flow direction,
    0-180°; his code counted every particle collision, digest §3.8), pooled over the strips
    by their collision counts, its block error, the share in the approach quadrant 90°-180°
    (where du/dy > 0 brings particles together), the logged ``window`` (:func:`log_window`:
    the log holds the production's first 2·10⁵ collisions, walls included) and the share in
    its two ``halves``. Empty when the run kept no collision log (``measure.statistics``
    without ``angles``)."""
    from .collision_log import approach_share, log_window

    ang = res.groups.get("statistics/angles")
    if ang is None or "p_text" not in ang:
        return {}
    pairs = np.asarray(ang["pair_collisions"], float)
    if pairs.sum() <= 0:
        return {}
    p = np.nan_to_num(np.asarray(ang["p_text"], float))
    pe = np.nan_to_num(np.asarray(ang["p_text_err"], float))
    theta = np.asarray(ang["theta"], float)
    out = {"theta": theta, "p": pairs @ p / pairs.sum(),
           "p_err": np.sqrt((pairs**2) @ pe**2) / pairs.sum(), "collisions": float(pairs.sum())}
    out["approach"] = approach_share(out["p"], out["p_err"], theta)
    out["window"] = log_window(res.groups["collisions"]["time"], res)
    out["halves"] = _approach_halves(res.groups["collisions"], out["window"][2])
    return out


def _approach_halves(log: dict, start: float) -> tuple[float, float]:
    """The share of the production's logged pair collisions in the approach quadrant
    (θ = atan2(n_y, n_x) mod π in 90°-180°) in the first and the second half of the logged
    window: a drifting share marks a transient."""
    t = np.asarray(log["time"], float)
    pair = (np.asarray(log["kind"]) == 0) & (t >= start)
    n = np.asarray(log["normal"], float)[pair]
    t = t[pair]
    if t.size < 2:
        return math.nan, math.nan
    theta = np.mod(np.arctan2(n[:, 1], n[:, 0]), math.pi)
    mid = 0.5 * (t.min() + t.max())
    return tuple(float(np.mean(theta[sel] > math.pi / 2)) for sel in (t <= mid, t > mid))


def summarise(name: str, path: str | Path) -> ChuteRun:
    """Read one chute run's results file (``demstudy.load``) into a :class:`ChuteRun`."""
    import demstudy as ds

    res = ds.load(path)
    scene, ts = res.scene, res.timeseries
    n = scene.n_particles
    t = np.asarray(ts["time"], float)
    energy = (np.asarray(ts["kinetic_energy"], float)
              + np.asarray(ts.get("rotational_energy", 0 * t), float)) / n
    start = float(res.attrs.get("equilibration_end", 0.0))
    prod = _production(t, start)
    force = np.asarray(ts["wall_force_lower"], float)
    dense = (t > DENSE[0]) & (t <= DENSE[1])
    e_mean, e_err = series_mean(energy[prod])
    ratio, ratio_err = force_ratio(force[prod])
    ratio_d, ratio_d_err = force_ratio(force[dense]) if dense.any() else (np.nan, np.nan)
    prof = _profiles(res)
    bed = np.nan_to_num(prof["nu"]) >= SURFACE_NU
    fast = int(np.nanargmax(np.where(bed, prof["u"], np.nan))) if bed.any() else 0
    u_max, u_max_err = float(prof["u"][fast]), float(prof["u_err"][fast])
    with np.errstate(divide="ignore", invalid="ignore"):
        slip = prof["u"][0] / u_max
        slip_err = abs(slip) * math.hypot(prof["u_err"][0] / prof["u"][0], u_max_err / u_max)
    wall = scene.wall("lower")
    g = np.asarray(scene.gravity_vector, float)
    tc = res.attrs.get("tc")
    return ChuteRun(
        name=name, angle=float(scene.gravity.angle), rows=int(scene.initial.rows),
        columns=int(scene.initial.columns), base=wall.kind, law=scene.contact.law.model,
        e_p=float(scene.contact.restitution), e_w=float(wall.restitution),
        engine=str(res.attrs.get("engine", "")), tc=None if tc is None else float(tc),
        t=t, energy=energy, start=start, trend=energy_trend(t[prod], energy[prod]),
        trend_err=trend_error(t[prod], energy[prod]),
        within=float(np.mean(np.abs(energy[prod] / energy[prod].mean() - 1.0) <= BAND)),
        energy_mean=e_mean, energy_err=e_err, ratio=ratio, ratio_err=ratio_err,
        ratio_dense=ratio_d, ratio_dense_err=ratio_d_err,
        depth=campbell_depth({"solid_fraction": prof["nu"], "y": prof["y"],
                              "edges": prof["edges"], "velocity": np.zeros((prof["y"].size, 2))},
                             wall=0.0),
        u_max=u_max, u_max_err=u_max_err, slip=float(slip), slip_err=float(slip_err),
        tc_share=float(res.attrs.get("tc_elastic_fraction", np.nan)),
        wall_seconds=float(res.attrs.get("wall_seconds", np.nan)),
        seed=int(scene.run.seed), profiles=prof, stress=_stress(res, prof, g),
        angles=collision_angles(res),
    )


def summarise_all(runs: dict[str, Path]) -> dict[str, ChuteRun]:
    """Every run that reads (a damaged file is left out: its checks say "not run")."""
    out = {}
    for name, path in runs.items():
        try:
            out[name] = summarise(name, path)
        except (OSError, KeyError, ValueError) as exc:  # an unreadable or partial file
            print(f"warning: {name}: {path} not analysed ({exc})")
    return out


def local_bagnold(run: ChuteRun) -> dict[str, np.ndarray]:
    """Campbell's f_s and f_N strip by strip in a chute (Figs 3.21-3.24 put chute strips
    beside the Couette cells): τ_xy, τ_yy from the momentum balance (with the unsteady term),
    du/dy from the cubic spline through the strips' u (``demstudy.analysis.derived``), f =
    τ/(ρ_p R² (du/dy)²). Only strips inside the bed (ν ≥ 0.3, above the base's strip) whose
    shear rate is resolved (du/dy > 2σ) are kept: elsewhere f is noise or undefined (a plug,
    H12). Arrays ``y``, ``nu``, ``f_s``, ``f_N`` with ``*_err``; empty without stresses."""
    from ...analysis.derived import bagnold_coefficients, shear_rate

    p, st = run.profiles, run.stress
    if not p or "balance_tau_xy" not in st:
        return {}
    zero = np.zeros_like(p["u"])
    du, du_err = shear_rate({"y": p["y"], "velocity": np.stack([p["u"], zero], axis=1),
                             "velocity_err": np.stack([p["u_err"], zero], axis=1)})
    keep = ((np.nan_to_num(p["nu"]) >= 0.3) & (np.arange(p["y"].size) > 0)
            & (np.nan_to_num(du) > 2 * np.nan_to_num(du_err, nan=np.inf)))
    out = {"y": p["y"][keep], "nu": p["nu"][keep], "nu_err": p["nu_err"][keep]}
    for key, tau in (("f_s", "balance_tau_xy"), ("f_N", "balance_tau_yy")):
        f, err = bagnold_coefficients(st[tau], du, 2, tau_err=st[f"{tau}_err"],
                                      rate_err=du_err)
        out[key], out[f"{key}_err"] = f[keep], err[keep]
    return out


def centre_plug(run: ChuteRun, lo: float = 0.25, hi: float = 0.75) -> tuple[float, float]:
    """The densest strip of the bed's centre (lo < y/H < hi): ν and its error."""
    p = run.profiles
    sel = (p["y"] / run.depth > lo) & (p["y"] / run.depth < hi) & np.isfinite(p["nu"])
    if not sel.any():
        return float("nan"), float("nan")
    i = np.flatnonzero(sel)[int(np.argmax(p["nu"][sel]))]
    return float(p["nu"][i]), float(p["nu_err"][i])


def basal_layer(run: ChuteRun) -> tuple[float, float, float]:
    """(ν of the strip 1 < y < 2 just above the base's strip, its error, the bed's ν max):
    a low-density basal layer has the first strips far below the maximum."""
    p = run.profiles
    k = 1 if p["y"].size > 1 else 0
    return float(p["nu"][k]), float(p["nu_err"][k]), float(np.nanmax(p["nu"]))
