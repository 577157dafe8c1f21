"""What the Couette part measures of one run, in Campbell's forms (digest §4).

Dimensionless particle units: d = 1, m = 1; no gravity: the upper wall's speed U_T sets the
time scale. Campbell's length unit was R = d/2: his temperatures are printed ×(H/U_T)² with
R = 1, i.e. as ⟨q'²⟩/(R γ̇)² = 4 ⟨q'²⟩/(d γ̇)² here (γ̇ = U_T/H, H the gap).

Everything comes from the package's analyses stored in the results file (``/profiles``,
``statistics/derived``: S, f_s, f_N, χ, wall slip; ``statistics/vdf``, ``statistics/angles``,
``statistics/structure``). "Centre" values average the bins whose centre lies at least
``WALL_SKIP`` diameters from both walls (the wall layers are Campbell's boundary effect);
their error is the bins' errors propagated as independent, or the scatter of the bins about
their mean divided by √n when that is larger.

Servo cells: the servo walls wander by 0.4-3 d during production. The package bins their
profiles in wall-relative strips, as Campbell did (n strips between the current walls,
ST = HGT/FND, L3689-3690, L3950; :mod:`demstudy.analysis.walls`). Its runs fix n from the gap
when production starts (Campbell's FND); this study recomputes the profiles of servo runs
from the stored frames with the package's wall-relative :class:`ProfileAnalysis` and
n = round(H̄ / bin_width) strips of the mean gap H̄ (:func:`wall_relative_profiles`), the
convention its numbers were first made with. Their f_s, f_N and χ then use the walls'
measured stresses (Campbell's Couette stress, integrated from the lower wall's: uniform
without gravity, L4337-4348), not the engine's strips (fixed where the walls stood when
production started).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ...analysis import derived as dv
from ...analysis.blocking import split_mean
from ...analysis.profiles import ProfileAnalysis
from ...analysis.steady import energy_trend
from ...io.results import read_results
from .collision_log import approach_share, log_window_of

#: bins closer than this (d) to a wall are left out of the centre averages
WALL_SKIP = 2.0
#: Campbell's radius in particle units
R = 0.5
#: the listing's f is the thesis's f / π (2D; derived.bagnold_coefficients "listing")
LISTING_FACTOR = 1.0 / math.pi


@dataclass
class RunSummary:
    """One run's numbers (value, error) and the arrays its figures need."""

    name: str
    values: dict[str, tuple[float, float]] = field(default_factory=dict)
    arrays: dict[str, Any] = field(default_factory=dict)
    attrs: dict[str, Any] = field(default_factory=dict)

    def v(self, key: str) -> float:
        return self.values.get(key, (math.nan, math.nan))[0]

    def e(self, key: str) -> float:
        return self.values.get(key, (math.nan, math.nan))[1]


def centre_mean(values: np.ndarray, errors: np.ndarray, mask: np.ndarray) -> tuple[float, float]:
    """Mean over the ``mask`` bins with the larger of the propagated and the scatter error."""
    v = np.asarray(values, float)[mask]
    e = np.nan_to_num(np.asarray(errors, float)[mask], nan=0.0)
    ok = np.isfinite(v)
    v, e = v[ok], e[ok]
    if v.size == 0:
        return math.nan, math.nan
    prop = float(np.sqrt(np.sum(e**2)) / v.size)
    scatter = float(v.std(ddof=1) / math.sqrt(v.size)) if v.size > 1 else 0.0
    return float(v.mean()), max(prop, scatter)


def ratio(a: tuple[float, float], b: tuple[float, float]) -> tuple[float, float]:
    """a/b with independent errors."""
    q = a[0] / b[0]
    return q, abs(q) * math.hypot(a[1] / a[0], b[1] / b[0])


def _production(ts: dict[str, np.ndarray], start: float) -> np.ndarray:
    t = np.asarray(ts["time"], float)
    keep = t > start + 1e-9
    return keep if keep.any() else np.ones(t.shape, bool)


def summarise(name: str, path: Path) -> RunSummary:
    """Read one Couette results file (frames only for servo cells)."""
    res = read_results(path, skip=("collisions",))
    scene = res.scene
    servo = any(w.servo is not None for w in scene.walls)
    out = RunSummary(name, attrs=dict(res.attrs))
    ts = res.timeseries
    start = float(res.attrs.get("equilibration_end", 0.0))
    keep = _production(ts, start)
    n = _count(res)
    gap = ts.get("gap", np.full(keep.shape, scene.wall_position("upper")))[keep]
    width = ts.get("width", np.full(keep.shape, scene.box.size[0]))[keep]
    speed = ts.get("wall_velocity_upper", np.full(keep.shape, scene.wall("upper").velocity))
    speed = np.asarray(speed, float)[keep]
    out.values["gap"] = split_mean(gap)
    # a servo cell still moving its walls: the gap's change from the production's first
    # tenth to its last, relative (0 for a fixed gap)
    tenth = max(gap.size // 10, 1)
    out.values["gap_drift"] = (float(gap[-tenth:].mean() / gap[:tenth].mean() - 1.0), 0.0)
    out.values["width"] = split_mean(width)
    out.values["U_T"] = split_mean(speed)
    out.values["nu_cell"] = split_mean(n * math.pi / 4 / (gap * width))
    if servo and "wall_position_lower" in ts:
        out.values["wall_wander"] = (float(np.ptp(ts["wall_position_lower"][keep])), 0.0)
    h, u_t = out.v("gap"), out.v("U_T")
    rate = u_t / h
    out.values["shear_rate_nominal"] = (rate, 0.0)
    if servo and res.frames:
        prof, der = _servo_derived(res, scene, start, h, u_t)
        out.attrs["profiles_from"] = "wall-relative strips from the frames; wall stresses"
    else:
        prof = dict(res.profiles)
        der = res.groups.get("statistics/derived", {})
        out.attrs["profiles_from"] = "the run's strips; the engine's strip stresses"
    edges = np.asarray(prof["edges"], float)
    y = np.asarray(prof["y"], float)
    lo, hi = edges[0], edges[-1]
    centre = (y - lo >= WALL_SKIP) & (hi - y >= WALL_SKIP)
    out.arrays.update(y_over_h=(y - lo) / (hi - lo), nu=prof["solid_fraction"],
                      nu_err=prof["solid_fraction_err"],
                      u_over_ut=np.asarray(prof["velocity"])[:, 0] / u_t,
                      u_err=np.asarray(prof["velocity_err"])[:, 0] / u_t, centre=centre)
    out.values["nu"] = centre_mean(prof["solid_fraction"], prof["solid_fraction_err"], centre)
    for key in ("S_text", "S_listing", "f_s", "f_N", "chi", "chi_theory", "shear_rate",
                "friction"):
        if key in der:
            err = der.get(f"{key}_err", np.zeros_like(der[key]))
            out.values[key] = centre_mean(der[key], err, centre)
    if "S_text" in out.values:
        for variant, factor in (("text", 1.0), ("listing", 0.5)):
            s = out.values[f"S_{variant}"]
            c = factor * math.sqrt(math.pi / out.v("nu"))
            out.values[f"S_{variant}_C"] = (s[0] * c, s[1] * c)
    for key in ("f_s", "f_N"):
        if key in out.values:
            f = out.values[key]
            out.values[f"{key}_listing"] = (f[0] * LISTING_FACTOR, f[1] * LISTING_FACTOR)
    for side in ("lower", "upper"):
        key = f"slip_{side}"
        if key in der:
            out.values[key] = (float(der[key]) / u_t, float(der[f"{key}_err"]) / u_t)
    _temperatures(out, prof, centre, rate)
    _distributions(out, res, (float(edges[0]), float(edges[-1])) if not servo else
                   (float(res.profiles["edges"][0]), float(res.profiles["edges"][-1])))
    _energy_history(out, ts, keep, n, u_t)
    out.attrs["log_window"] = log_window_of(path, res)
    if res.frames and "position" in res.frames:  # the last frame: Fig 2.3's snapshot
        out.arrays.update(snapshot=np.asarray(res.frames["position"][-1], float),
                          snapshot_radius=np.asarray(res.frames["radius"][-1], float),
                          snapshot_box=np.array([res.frames["box_lo"][-1],
                                                 res.frames["box_hi"][-1]], float))
    out.attrs["tc_elastic_fraction"] = float(res.attrs.get("tc_elastic_fraction", math.nan))
    out.attrs["tc"] = float(res.attrs.get("tc", math.nan))  # the event-driven engine's t_c
    out.attrs["engine"] = res.attrs.get("engine", "?")
    out.attrs["rows_columns"] = (scene.initial.rows, scene.initial.columns)
    out.attrs["eps"] = (scene.walls[0].restitution, scene.contact.restitution)
    out.attrs["wall_model"] = scene.walls[0].tangential.model
    return out


def _energy_history(out: RunSummary, ts: dict, keep: np.ndarray, n: int, u_t: float) -> None:
    """Fig 2.4: the kinetic energy per disc (translation + rotation, in m U_T² of each
    sample's wall speed) against the
    strain γ̇t, and Campbell's convergence numbers over the production: the fitted relative
    change (``ke_trend``, its error from 8 block means) and the share of samples within ±20 %
    of the mean (``ke_within``; his "fluctuates within about 20 %", L578)."""
    from .chute_measure import BAND, trend_error

    if "kinetic_energy" not in ts or not keep.any():
        return
    t = np.asarray(ts["time"], float)
    # each sample in its own U_T² (a servo holding the shear rate changes the wall's speed)
    speed = np.asarray(ts.get("wall_velocity_upper", np.full(t.shape, u_t)), float)
    energy = (np.asarray(ts["kinetic_energy"], float)
              + np.asarray(ts.get("rotational_energy", 0 * t), float)) / n / speed**2
    rate = out.v("shear_rate_nominal")
    out.arrays.update(ke_strain=t * rate, ke=energy,
                      ke_start=np.array(float(t[keep][0]) * rate))
    prod_t, prod_e = t[keep], energy[keep]
    out.values["ke_trend"] = (energy_trend(prod_t, prod_e), trend_error(prod_t, prod_e))
    if "dissipated_energy" in ts:
        # a thermal indicator: the mean flow carries ≈ 98 % of a no-slip cell's energy, the
        # dissipation rate (collisions × their energy loss) only the fluctuations'
        mid_t, loss = _block_rates(prod_t, np.asarray(ts["dissipated_energy"], float)[keep])
        out.values["dissipation_trend"] = (energy_trend(mid_t, loss), trend_error(mid_t, loss))
    out.values["ke_within"] = (float(np.mean(np.abs(prod_e / prod_e.mean() - 1.0) <= BAND)),
                               0.0)
    out.values["ke_mean"] = split_mean(prod_e)


def wall_relative_profiles(res: Any, scene: Any, start: float, gap: float) -> dict:
    """Profiles over the production frames in strips that follow the servo walls (the
    package's wall-relative bins, Campbell's ST = HGT/FND): round(gap / bin_width) strips,
    reported on the grid between the mean wall positions."""
    ana = ProfileAnalysis(axis="y", bin_width=scene.measure.bin_width, dim=2,
                          inertia_factor=scene.inertia_k, wall_relative=True,
                          strips=max(1, round(gap / scene.measure.bin_width)))
    return dict(ana.run(res.iter_frames(start + 1e-9)).results)


def _servo_derived(res: Any, scene: Any, start: float, gap: float,
                   u_t: float) -> tuple[dict, dict]:
    """Wall-relative profiles and what derives from them: S, wall slip, and f_s, f_N, χ
    with the walls' mean stress (τ_xy = −P_xy, τ_yy = P_yy at the walls, averaged)."""
    prof = wall_relative_profiles(res, scene, start, gap)
    der: dict[str, Any] = {}
    rate = dv.shear_rate(prof)
    der["shear_rate"], der["shear_rate_err"] = rate
    for variant in ("text", "listing"):
        der[f"S_{variant}"], der[f"S_{variant}_err"] = dv.s_parameter(prof, variant, rate=rate)
    stress = res.groups.get("stress", {})
    walls = [(np.asarray(stress[f"wall_{s}"], float), np.asarray(stress[f"wall_{s}_err"], float))
             for s in ("lower", "upper") if f"wall_{s}" in stress]
    if walls:
        col = np.mean([w[0] for w in walls], axis=0)
        col_err = np.sqrt(np.sum([w[1] ** 2 for w in walls], axis=0)) / len(walls)
        txy, tyy = (-col[0], col_err[0]), (col[1], col_err[1])
        n = prof["y"].size
        for key, (tau, err) in (("f_s", txy), ("f_N", tyy)):
            der[key], der[f"{key}_err"] = dv.bagnold_coefficients(
                np.full(n, tau), rate[0], 2, "campbell", np.full(n, err), rate[1])
        der["chi"], der["chi_err"] = dv.equation_of_state(prof, np.full(n, tyy[0]),
                                                          np.full(n, tyy[1]))
        der["friction"], der["friction_err"] = (np.full(n, txy[0] / tyy[0]),
                                                np.full(n, 0.0))
    from demstudy.theory import campbell_chi  # noqa: PLC0415

    nu = np.nan_to_num(np.asarray(prof["solid_fraction"], float))
    der["chi_theory"] = np.asarray(campbell_chi(nu, 2, scene.contact.restitution), float)
    edges = np.asarray(prof["edges"], float)  # the mean walls
    for side, wall, speed in (("lower", edges[0], 0.0), ("upper", edges[-1], u_t)):
        der[f"slip_{side}"], der[f"slip_{side}_err"] = dv.wall_slip(prof, wall, side, speed,
                                                                    "extrapolate", 2)
    return prof, der


def _count(res: Any) -> int:
    scene = res.scene
    return int(scene.initial.rows * scene.initial.columns)


def _temperatures(out: RunSummary, prof: dict, centre: np.ndarray, rate: float) -> None:
    """⟨u'²⟩, ⟨v'²⟩, β⟨ω'²⟩ ×(H/U_T)² in Campbell's R = 1 units, and the rotational share."""
    var, var_err = dv.velocity_variances(prof)
    mm = np.asarray(prof.get("mean_mass", np.ones(var.shape[0])), float)
    rot = np.asarray(prof["rotational_temperature"], float) / mm
    rot_err = np.asarray(prof["rotational_temperature_err"], float) / mm
    scale = 1.0 / (R * rate) ** 2
    parts = {"Tu": (var[:, 0], var_err[:, 0]), "Tv": (var[:, 1], var_err[:, 1]),
             "Tw": (rot, rot_err)}
    for key, (v, e) in parts.items():
        m, s = centre_mean(v * scale, e * scale, centre)
        out.values[key] = (m, s)
        out.arrays[key] = v * scale
        out.arrays[f"{key}_err"] = np.nan_to_num(e) * scale
    total = sum(out.v(k) for k in parts)
    total_err = math.sqrt(sum(out.e(k) ** 2 for k in parts))
    out.values["T_total"] = (total, total_err)
    out.values["rot_share"] = ratio(out.values["Tw"], (total, total_err))
    # the thesis's QFL/3: the mean over the three degrees of freedom
    out.values["T_mean"] = (total / 3, total_err / 3)


def _centre_of(group: dict, walls: tuple[float, float]) -> np.ndarray:
    """The centre bins of a statistic's own y grid (the vdf's grid spans the scene's initial
    gap, the profiles' the gap when production started: with the servo they differ)."""
    y = np.asarray(group["y"], float)
    return (y - walls[0] >= WALL_SKIP) & (walls[1] - y >= WALL_SKIP)


def _distributions(out: RunSummary, res: Any, walls: tuple[float, float]) -> None:
    """The VDF histograms, collision-angle histograms and structure distributions pooled
    over the centre bins (count-weighted)."""
    vdf = res.groups.get("statistics/vdf")
    if vdf is not None and "X" in vdf:
        centre = _centre_of(vdf, walls)
        count = np.asarray(vdf["count"], float)
        w = np.where(centre, count, 0.0)
        x = np.asarray(vdf["X"], float)
        xe = np.asarray(vdf["X_err"], float)
        out.arrays["vdf_x"] = np.asarray(vdf["X_centres"], float)
        out.arrays["vdf"] = np.tensordot(w, np.nan_to_num(x), axes=(0, 0)) / w.sum()
        out.arrays["vdf_err"] = np.sqrt(np.tensordot(w**2, np.nan_to_num(xe) ** 2,
                                                     axes=(0, 0))) / w.sum()
        out.arrays["vdf_ref"] = np.asarray(vdf["X_reference"], float)
        dx = float(np.diff(vdf["X_edges"])[0])
        tv = 0.5 * np.sum(np.abs(out.arrays["vdf"] - out.arrays["vdf_ref"]), axis=1) * dx
        out.arrays["vdf_tv"] = tv
        kurt = np.asarray(vdf["kurtosis"], float)
        for k, comp in enumerate(("u", "v")):
            out.values[f"kurtosis_{comp}"] = centre_mean(kurt[:, k], vdf["kurtosis_err"][:, k],
                                                         centre & (count > 0))
    ang = res.groups.get("statistics/angles")
    if ang is not None and "p_text" in ang:
        centre = _centre_of(ang, walls)
        pairs = np.asarray(ang["pair_collisions"], float)
        w = np.where(centre, pairs, 0.0)
        theta = np.asarray(ang["theta"], float)
        out.arrays["theta"] = theta
        for conv in ("text", "listing"):
            p = np.nan_to_num(np.asarray(ang[f"p_{conv}"], float))
            pe = np.nan_to_num(np.asarray(ang[f"p_{conv}_err"], float))
            out.arrays[f"p_{conv}"] = w @ p / w.sum()
            out.arrays[f"p_{conv}_err"] = np.sqrt((w**2) @ pe**2) / w.sum()
            for length in ("R", "C"):
                key = f"sj_{conv}_{length}"
                if key in ang:
                    out.arrays[key] = w @ np.nan_to_num(np.asarray(ang[key], float)) / w.sum()
        out.values["approach_share"] = approach_share(out.arrays["p_text"],
                                                       out.arrays["p_text_err"], theta)
        # Savage-Jeffrey's approach share with S, with the text's S' = S·C/R and with the
        # listing's QRH = S·C/(2R) (S from √(⟨u'²⟩+⟨v'²⟩), its own angle convention:
        # θ_code = 90° − θ maps the approach quadrant 90°-180° onto itself)
        for key, name in (("sj_text_R", "R"), ("sj_text_C", "C"), ("sj_listing_C", "listing")):
            if key in out.arrays:
                out.values[f"approach_share_sj_{name}"] = approach_share(
                    out.arrays[key], np.zeros_like(theta), theta)
        out.values["collisions"] = (float(np.sum(pairs)), 0.0)
    st = res.groups.get("statistics/structure")
    if st is not None and "normal" in st:
        for key in ("r", "normal", "normal_err", "parallel", "parallel_err"):
            out.arrays[f"st_{key}"] = np.asarray(st[key], float)
        out.values["layering"] = _layering(out.arrays["st_r"], out.arrays["st_normal"],
                                           out.arrays["st_normal_err"])


#: blocks of the production the dissipation rate is taken over (25 strain units each in a
#: full run: longer than a collision time, short enough to see a trend)
RATE_BLOCKS = 40


def _block_rates(t: np.ndarray, cumulative: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rate of a cumulative series over RATE_BLOCKS equal blocks: (block mid-times,
    rates)."""
    idx = np.linspace(0, t.size - 1, min(RATE_BLOCKS, t.size - 1) + 1).astype(int)
    return 0.5 * (t[idx][1:] + t[idx][:-1]), np.diff(cumulative[idx]) / np.diff(t[idx])


def _layering(r: np.ndarray, normal: np.ndarray, err: np.ndarray) -> tuple[float, float]:
    """Amplitude of the normal distribution's oscillation for 0.5 < |Δy| < 2 relative to its
    mean there: (max − min)/mean (0 for an uncorrelated gas, ~1 and more when layered)."""
    sel = (r > 0.5) & (r < 2.0)
    v, e = normal[sel], err[sel]
    if v.size < 3 or not np.all(np.isfinite(v)):
        return math.nan, math.nan
    mean = float(v.mean())
    amp = (float(v.max()) - float(v.min())) / mean
    return amp, float(math.hypot(e[np.argmax(v)], e[np.argmin(v)]) / mean)
