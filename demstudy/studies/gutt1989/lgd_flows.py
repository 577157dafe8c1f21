"""The checks of the LGD part of the Gutt (1989) study for the gravity-driven scenes: the
hourglass, the four obstacles, the incline with its run-out and the Poiseuille channel
(digest §3.15, §4.3). Gravity points along +x in all of them but the incline.

Dimensionless particle units: d = 1 (lattice spacing), m = 1, g = 1: times in √(d/g), speeds
in √(g d), forces per wall particle in m g.

Proxies (the thesis's statements are about pictures; each proxy is named in its row):

* hourglass "nearly linear": the rates fitted to the two halves of the discharge window agree
  within ``LINEAR_RATE`` (relative); funnel flow: in the converging part of the bin the
  grains near the funnel walls move at less than ``SIDE_SLOW`` of the speed near the axis;
  surface depression: the free surface (per ``SURFACE_BAND``-wide band across the bin, the
  first 2 d slab along g that is more than half full) lies at least ``DEPRESSION`` deeper
  in the central third of the width than in the outer thirds;
* obstacles (frame at 512 steps; gravity along +x, so "below" is downstream): the **void**
  is the empty-node fraction of a box right below the obstacle (its half width along the
  flow, ±¼ of its width across), and its **length** the distance below the obstacle until
  the grain density along the axis reaches half the density in the flanks; the **cap** is
  the box right above the obstacle, stagnant when its grains move at less than
  ``STAGNANT`` of the speed in the flank boxes beside it at the same height;
* incline: grains that crossed the run-out are those above the height the run-out reaches
  before it wraps round x (the block starts below it); static: at least ``STATIC_NODES`` of
  their nodes stay occupied over the last kept frames (``lgd_measure.occupancy_overlap``);
* Poiseuille: bands from the row profiles (thermal velocity peak and where it falls to the
  midpoint between peak and plug); σ/p and σ against the steady value g·N/N_wall.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..base import NOT_REPRODUCED, PARTLY, REPRODUCED, Analysis, Check, not_run, pm
from . import lgd_figures as figs
from . import lgd_measure as m
from . import lgd_paths

LINEAR_RATE, SIDE_SLOW, STAGNANT, STATIC_NODES = 0.25, 0.5, 0.5, 0.9
#: thesis values (digest §3.15, L1119-L1127): band width, σ/p, final σ over g·N/N_wall
BAND_WIDTH, SIGMA_OVER_P, FINAL_SHEAR = 30.0, 0.25, 150.0 / 252.0
#: hourglass surface: band width across the bin (d) and the depth (d, along g) that counts
#: as a depression: a few grain diameters, well above the ±2 d a 2 d slab resolves
SURFACE_BAND, DEPRESSION = 8.0, 5.0
#: the step of the thesis's picture of the hourglass (fig 3.24b)
HOURGLASS_PICTURE = 2048


def flows(runs: Mapping[str, m.LgdRun], out: Path, an: Analysis, quick: bool) -> None:
    hourglass(runs.get("lgd-hourglass"), out, an)
    obstacles({n: r for n, r in runs.items() if n.startswith("lgd-obstacle")}, out, an)
    lgd_paths.obstacle_paths(runs, out, an)
    incline(runs.get("lgd-incline"), out, an, quick)
    lgd_paths.incline_paths(runs.get("lgd-incline-paths"), out, an)
    poiseuille(runs.get("lgd-poiseuille-small"), runs.get("lgd-poiseuille-thesis"), out, an,
               quick)


# --- hourglass ----------------------------------------------------------------------------

def funnel_speeds(pos: np.ndarray, vel: np.ndarray, walls: np.ndarray, x_range: tuple[float,
                  float], yc: float) -> tuple[float, float]:
    """Mean speed of the grains in the outer 30 % of the funnel's local half width and in
    the inner 30 % (the half width from the funnel-wall nodes in the same 4 d column)."""
    side, core = [], []
    speed = np.hypot(vel[:, 0], vel[:, 1])
    for x0 in np.arange(*x_range, 4.0):
        w = walls[(walls[:, 0] >= x0) & (walls[:, 0] < x0 + 4)]
        sel = (pos[:, 0] >= x0) & (pos[:, 0] < x0 + 4)
        if w.size == 0 or not sel.any():
            continue
        half = np.min(np.abs(w[:, 1] - yc))
        f = np.abs(pos[sel, 1] - yc) / half
        side += list(speed[sel][f > 0.7])
        core += list(speed[sel][f < 0.3])
    return (float(np.mean(side)) if side else math.nan,
            float(np.mean(core)) if core else math.nan)


def surface_depth(pos: np.ndarray, width: float, x_max: float) -> tuple[float, float]:
    """Mean free-surface position along g (+x) in the central third of the bin's width and
    in its outer thirds: per ``SURFACE_BAND``-wide band, the first 2 d slab (x < ``x_max``,
    the bin above the funnel) whose nodes are more than half occupied; a band with no such
    slab has drained below the bin (counted as ``x_max``)."""
    slab = 2.0
    centre, sides = [], []
    for y0 in np.arange(0.0, width - SURFACE_BAND / 2, SURFACE_BAND):
        x = pos[(pos[:, 1] >= y0) & (pos[:, 1] < y0 + SURFACE_BAND), 0]
        counts, edges = np.histogram(x, bins=np.arange(0.0, x_max + slab, slab))
        full = np.flatnonzero(counts / (slab * SURFACE_BAND / m.ROW) > 0.5)
        depth = float(edges[full[0]]) if full.size else x_max
        off = abs(y0 + SURFACE_BAND / 2 - width / 2) / width
        (centre if off < 1 / 6 else sides).append(depth)
    return (float(np.mean(centre)) if centre else math.nan,
            float(np.mean(sides)) if sides else math.nan)


def hourglass(run: m.LgdRun | None, out: Path, an: Analysis) -> None:
    ref = "L1081-L1091, figs 3.24-3.26"
    if run is None:
        an.checks += [not_run(ref, s, "qualitative", "lgd-hourglass") for s in
                      ("discharge nearly linear in time", "funnel flow, static side zones")]
        return
    n = run.position.shape[1]
    fit = m.discharge_linearity(run.ts["time"], run.ts["discharged"], n)
    lin = abs(fit["rate_ratio"] - 1) <= LINEAR_RATE
    an.checks.append(Check(
        ref, "the discharge count against time is nearly linear after start-up until the bin "
             "empties (fig 3.26)", "nearly linear",
        f"window t = {fit['t0']:.1f}-{fit['t1']:.1f} √(d/g) ({fit['points']} samples, count "
        f"from 5 % of the final to 90 % of N): rate {pm(fit['rate'], fit['rate_err'])} grains "
        f"per √(d/g), second-half/first-half rate {fit['rate_ratio']:.2f} (threshold "
        f"1 ± {LINEAR_RATE}), r.m.s. residual {100 * fit['residual']:.1f} % of the rise",
        REPRODUCED if lin else NOT_REPRODUCED,
        "" if lin else "the rate changes along the window"))
    ini = m.initial_state(run)
    walls = ini["walls"][(ini["wall_rows"] > 0) & (ini["wall_rows"] < run.nyt - 1)]
    funnel = walls[(walls[:, 0] > 60) & (walls[:, 0] < 118)]
    yc = 0.5 * (run.nyt - 1) * m.ROW
    i = (run.frame_at(HOURGLASS_PICTURE) if HOURGLASS_PICTURE in run.frame_steps
         else len(run.frame_steps) - 1)
    side, core = funnel_speeds(run.position[i], run.velocity[i], funnel, (80, 116), yc)
    ratio = side / core
    funnel_flow = ratio < SIDE_SLOW
    mid, outer = surface_depth(run.position[i], 2 * yc, float(funnel[:, 0].min()))
    depressed = mid - outer >= DEPRESSION
    verdict = (REPRODUCED if funnel_flow and depressed
               else PARTLY if funnel_flow or depressed else NOT_REPRODUCED)
    why = [s for s, failed in (
        (f"only {run.frame_steps[i]} steps kept (the thesis's picture is at "
         f"{HOURGLASS_PICTURE})", run.frame_steps[i] < HOURGLASS_PICTURE),
        ("the side zones move too (mass flow rather than funnel flow)", not funnel_flow),
        ("no surface depression", not depressed)) if failed]
    an.checks.append(Check(
        ref, "after 2048 steps: funnel (core) flow with static side zones and a surface "
             "depression (fig 3.24b)", "qualitative",
        f"step {run.frame_steps[i]}, converging part x = 80-116 d: mean speed in the outer "
        f"30 % of the half width {side:.2f}, in the inner 30 % {core:.2f} √(gd) (ratio "
        f"{ratio:.2f}, funnel flow if < {SIDE_SLOW}); free surface along g (bin x < "
        f"{funnel[:, 0].min():.0f} d) at {mid:.1f} d in the central third of the width vs "
        f"{outer:.1f} d in the outer thirds (a depression if ≥ {DEPRESSION:g} d deeper)",
        verdict, "; ".join(why)))
    an.figures.append(figs.positions(
        [(run, run.frame_at(s), ini["walls"], "hourglass") for s in (1024, 2048)
         if s in run.frame_steps], out, "lgd_hourglass_positions.png",
        "Hourglass (fig 3.24b): positions (walls red), gravity along +x"))
    an.figures.append(figs.discharge(run, fit, out, "lgd_hourglass_discharge.png",
                                     "Hourglass (fig 3.26): grains past x = nxt/2 against time"))


# --- obstacles -----------------------------------------------------------------------------

def obstacle_proxies(pos: np.ndarray, vel: np.ndarray, obstacle: np.ndarray
                     ) -> dict[str, float]:
    """Void and cap proxies around an obstacle (its wall-node centres); gravity along +x."""
    x0, x1 = obstacle[:, 0].min(), obstacle[:, 0].max()
    y0, y1 = obstacle[:, 1].min(), obstacle[:, 1].max()
    yc, hw = 0.5 * (y0 + y1), 0.5 * (y1 - y0)
    speed = np.hypot(vel[:, 0], vel[:, 1])

    def box(xa, xb, ya, yb):
        sel = (pos[:, 0] >= xa) & (pos[:, 0] < xb) & (pos[:, 1] >= ya) & (pos[:, 1] < yb)
        nodes = (xb - xa) * (yb - ya) / m.ROW
        return sel, 1 - sel.sum() / nodes

    below, void = box(x1 + 1, x1 + 1 + hw, yc - hw / 2, yc + hw / 2)
    cap, cap_empty = box(x0 - hw / 2, x0 - 1, yc - hw / 4, yc + hw / 4)
    flank_lo, _ = box(x0 - hw / 2, x0 - 1, y0 - hw / 2 - 2, y0 - 2)
    flank_hi, _ = box(x0 - hw / 2, x0 - 1, y1 + 2, y1 + hw / 2 + 2)
    flank = flank_lo | flank_hi
    # void length along the axis: 2 d strips below the obstacle until the density reaches
    # half the flanks' density next to the obstacle
    _, flank_empty = box(x0, x1, y1 + 2, y1 + hw / 2 + 2)
    ref_density = 1 - flank_empty
    length = math.nan
    for xa in np.arange(x1 + 1, x1 + 1 + 4 * hw, 2.0):
        _, e = box(xa, xa + 2, yc - hw / 4, yc + hw / 4)
        if 1 - e >= 0.5 * ref_density:
            length = float(xa - x1)
            break
    return {"void": float(void), "void_length": length,
            "cap_speed": float(speed[cap].mean()) if cap.any() else math.nan,
            "flank_speed": float(speed[flank].mean()) if flank.any() else math.nan,
            "cap_empty": float(cap_empty), "width": float(2 * hw)}


OBSTACLE_STATEMENTS = {
    "circle": ("circle: void below, stagnant cap above", True),
    "square": ("square: void below, stagnant cap above (as the circle)", True),
    "triangle-up": ("triangle point-up: no stagnant zone (60° faces steeper than repose)",
                    False),
    "triangle-down": ("triangle point-down: void below, larger than in the experiment", True),
}


def obstacles(runs: Mapping[str, m.LgdRun], out: Path, an: Analysis) -> None:
    ref = "L1093-L1107, figs 3.29-3.32"
    found: dict[str, dict] = {}
    panels = []
    for shape, (st, want_cap) in OBSTACLE_STATEMENTS.items():
        run = runs.get(f"lgd-obstacle-{shape}")
        if run is None or 512 not in run.frame_steps:
            an.checks.append(not_run(ref, st, "qualitative", f"lgd-obstacle-{shape}"))
            continue
        ini = m.initial_state(run)
        w = ini["walls"][(ini["wall_rows"] > 0) & (ini["wall_rows"] < run.nyt - 1)]
        ob = w[(w[:, 0] > 40) & (w[:, 0] < 150)]
        i = run.frame_at(512)
        q = obstacle_proxies(run.position[i], run.velocity[i], ob)
        found[shape] = q
        panels.append((run, i, ini["walls"], shape))
        ratio = q["cap_speed"] / q["flank_speed"]
        void_ok = q["void"] > 0.5
        cap_ok = (ratio < STAGNANT) == want_cap
        extra = ""
        if shape == "triangle-down" and {"circle", "square"} & set(found):
            others = [found[s]["void_length"] for s in ("circle", "square") if s in found]
            bigger = q["void_length"] > max(others)
            extra = (f"; void length {q['void_length']:.0f} d vs circle/square "
                     f"{', '.join(f'{v:.0f}' for v in others)} d")
            cap_ok = bigger  # the statement is about the void's size, not the cap
        ok = void_ok and cap_ok and shape != "triangle-down"
        an.checks.append(Check(
            ref, st + " (positions at 512 steps)", "qualitative",
            f"empty-node fraction right below {q['void']:.2f}; void length "
            f"{q['void_length']:.0f} d (obstacle {q['width']:.0f} d wide); cap speed / flank "
            f"speed {ratio:.2f} (stagnant if < {STAGNANT}){extra}",
            REPRODUCED if ok else (PARTLY if void_ok or cap_ok else NOT_REPRODUCED),
            "" if ok else _obstacle_reason(shape, void_ok, cap_ok, ratio)))
    if panels:
        an.figures.append(figs.positions(
            panels, out, "lgd_obstacle_positions.png",
            "Obstacles (figs 3.29a-3.32a): positions at 512 steps (walls red); gravity +x"))


def _obstacle_reason(shape: str, void_ok: bool, cap_ok: bool, ratio: float) -> str:
    if not void_ok:
        return "no void below the obstacle at 512 steps"
    if shape == "triangle-down":
        return ("the thesis compares the void with the experiment's, which demstudy does not "
                "have; as a proxy the void is " + ("longer" if cap_ok else "not longer")
                + " than the circle's and the square's")
    if shape == "triangle-up":
        return f"the grains above the apex move slowly too (ratio {ratio:.2f})"
    return (f"the cap moves at {ratio:.2f} of the flank speed: at 512 steps the whole bed is "
            "still accelerating past the obstacle, a slower cap rather than a stagnant one")


# --- incline --------------------------------------------------------------------------------

def incline(run: m.LgdRun | None, out: Path, an: Analysis, quick: bool) -> None:
    ref = "L1109-L1115, figs 3.33-3.34"
    st = ("after 6144 steps the grains have crossed the run-out and form a static pile "
          "against the upper diagonal wall")
    if run is None:
        an.checks.append(not_run(ref, st, "qualitative", "lgd-incline"))
        return
    ini = m.initial_state(run)
    walls = ini["walls"][(ini["wall_rows"] > 0) & (ini["wall_rows"] < run.nyt - 1)]
    top_first = float(walls[walls[:, 0] > run.nxt - 3][:, 1].max())  # where the run-out wraps
    start_top = float(ini["grains"][:, 1].max())
    i = len(run.frame_steps) - 1
    pos, vel = run.position[i], run.velocity[i]
    crossed = pos[:, 1] > top_first
    share = float(crossed.mean())
    first = run.position[0]
    kept = m.occupancy_overlap(first[first[:, 1] > top_first], pos[crossed], run.nxt)
    span = int(run.frame_steps[i] - run.frame_steps[0])
    g = np.array([run.attrs["lgd_igx"], run.attrs["lgd_igy"]], float)
    g /= np.linalg.norm(g)
    along_g = float(vel[crossed].mean(axis=0) @ g) if crossed.any() else math.nan
    rms_v = float(np.sqrt((vel[crossed] ** 2).sum(1).mean())) if crossed.any() else math.nan
    static = kept >= STATIC_NODES and span > 0
    ok = share > 0.1 and static
    an.checks.append(Check(
        ref, st, "qualitative",
        f"step {run.frame_steps[i]}: {100 * share:.0f} % of the grains above y = "
        f"{top_first:.0f} d (the run-out's height where it wraps round x; the block starts "
        f"below {start_top:.0f} d); {100 * kept:.1f} % of their nodes occupied both at step "
        f"{run.frame_steps[0]} and {run.frame_steps[i]} (static if ≥ {100 * STATIC_NODES:.0f} "
        f"%). Their velocities do not vanish (r.m.s. {rms_v:.1f}, mean {along_g:.1f} √(gd) "
        "along g, into the wall): in LGD a grain whose target site is full keeps its "
        "velocity without moving, and gravity kicks it every step (digest §5.8)",
        REPRODUCED if ok else (PARTLY if share > 0.1 else NOT_REPRODUCED),
        "" if ok else ("the pile's nodes still change" if share > 0.1 else
                       "few grains crossed the run-out")
        + (" (quick study: 1536 steps only)" if quick else "")))
    an.figures.append(figs.positions(
        [(run, 0, ini["walls"], "incline"), (run, i, ini["walls"], "incline")], out,
        "lgd_incline_positions.png",
        "Incline (fig 3.34a): positions at the first and last kept frames (walls red); "
        "gravity is normal to the diagonal wall", cols=1))


# --- Poiseuille -----------------------------------------------------------------------------

def shear_widths(p: dict, level: float = 0.9) -> tuple[float, float]:
    """Width of the sheared layer at each wall (lower, upper): the distance from the wall
    row to the first row where v̄x reaches ``level`` of the plug's (the central fifth's
    median) velocity, in d."""
    ok = np.flatnonzero(np.isfinite(p["vx"]) & (p["n"] > 0))
    y, v = p["y"][ok], p["vx"][ok]
    n = len(y)
    plug = float(np.median(v[2 * n // 5: 3 * n // 5]))
    lo = y[np.argmax(v >= level * plug)] - p["y"][0]
    hi = p["y"][-1] - y[n - 1 - np.argmax(v[::-1] >= level * plug)]
    return float(lo), float(hi)


def band_widths(p: dict) -> tuple[float, float, float, float]:
    """From the thermal-velocity row profile: the peak's distance from each wall and the
    band's width (wall to where the thermal velocity falls to the midpoint between its peak
    and the plug's value, the central fifth), lower then upper wall, in d."""
    ok = np.flatnonzero(np.isfinite(p["thermal"]) & (p["n"] > 0))
    y, th = p["y"][ok], p["thermal"][ok]
    n = len(y)
    plug = float(np.median(th[2 * n // 5: 3 * n // 5]))
    out = []
    for idx, wall_y in ((np.arange(n // 2), p["y"][0]), (np.arange(n - 1, n // 2, -1),
                                                         p["y"][-1])):
        k = idx[np.argmax(th[idx])]
        half = 0.5 * (th[k] + plug)
        after = idx[np.flatnonzero(idx == k)[0]:]
        edge = after[np.argmax(th[after] < half)] if np.any(th[after] < half) else after[-1]
        out += [abs(y[k] - wall_y), abs(y[edge] - wall_y)]
    return out[0], out[1], out[2], out[3]


def poiseuille(small: m.LgdRun | None, full: m.LgdRun | None, out: Path, an: Analysis,
               quick: bool) -> None:
    ref = "L1117-L1127, figs 3.35-3.36"
    sts = ("after 18432 steps: central plug, agitated bands ≈ 30 d wide at each wall, thermal "
           "velocity peaking in the bands",
           "σ and p grow from 0 at a constant ratio ≈ 0.25",
           "the wall shear rises towards g·N/N_wall (252 in g = 8 units); final ≈ 150, not "
           "steady")
    if small is None and full is None:
        an.checks += [not_run(ref, s, "see statement", "lgd-poiseuille-small") for s in sts]
        return
    for run, label in ((small, "1/16 length (504 × 128)"), (full, "thesis size (8064 × 128)")):
        if run is None:
            continue
        _poiseuille_run(run, label, ref, sts, out, an, quick)
    last = int(small.frame_steps.max()) if small is not None else -1
    if full is not None and small is not None and last in full.frame_steps:
        diff = m.same_as_periodic_copy(small, full, last)
        same = ("the long channel is an exact periodic copy of the short one: a start "
                "uniform along x stays so under the deterministic integer LGD step, which is "
                "the same in every period of its move and collision templates; with such a "
                "layout the 508 032-grain run adds no information to the 31 752-grain one")
        other = ("the long channel is not a periodic copy of the short one. Both start from "
                 "a seeded random fill at density ½ (the presets' assumed layout, drawn "
                 "independently for each length), so the 8064-column run averages over 16 "
                 "times as many independent grains")
        what = (f"differ from the 504-column run's by at most {diff:.3g} (positions in d, "
                "velocities in √(gd))" if math.isfinite(diff) else
                "hold a different number of grains than the 504-column run")
        text = (f"At step {last} the 8064-column run's grains in its first 504 columns {what}: "
                + (same if diff == 0 else other) + ".")
        an.sections.append(("LGD Poiseuille: the thesis size and the 1/16 channel", text))


def _poiseuille_run(run: m.LgdRun, label: str, ref: str, sts, out: Path, an: Analysis,
                    quick: bool) -> None:
    frames = np.arange(len(run.frame_steps))
    p = m.mean_profiles(run, frames)
    steps = f"steps {run.frame_steps[0]}-{run.frame_steps[-1]}"
    pk_lo, w_lo, pk_hi, w_hi = band_widths(p)
    s_lo, s_hi = shear_widths(p)
    ok = np.flatnonzero(p["n"] > 0)
    k = len(ok) // 5
    centre = ok[2 * k:len(ok) - 2 * k]
    v_c = p["vx"][centre]
    flat = float(np.ptp(v_c) / np.nanmax(p["vx"]))
    th_c = float(np.median(p["thermal"][centre]))
    th_peak = float(np.nanmax(p["thermal"]))
    in_band = pk_lo < s_lo and pk_hi < s_hi
    bands_ok = (flat < 0.1 and th_peak > 3 * th_c and in_band
                and all(abs(w - BAND_WIDTH) <= 0.5 * BAND_WIDTH for w in (s_lo, s_hi)))
    an.checks.append(Check(
        ref, sts[0] + f" [{label}]", "plug; bands ≈ 30 d",
        f"{steps}, row profiles averaged over {len(frames)} frames: v̄x varies by "
        f"{100 * flat:.0f} % of its maximum over the central fifth; sheared bands (wall to "
        f"90 % of the plug velocity) {s_lo:.0f} and {s_hi:.0f} d wide (reproduced within "
        f"±50 % of 30 d); thermal velocity plug {th_c:.2f}, peak {th_peak:.2f} √(gd), its "
        f"peaks {pk_lo:.0f} and {pk_hi:.0f} d from the walls (inside the bands: "
        f"{'yes' if in_band else 'no'}), falling to half-way to the plug's at {w_lo:.0f} and "
        f"{w_hi:.0f} d",
        REPRODUCED if bands_ok else PARTLY,
        "" if bands_ok else "bands narrower or wider than the thesis's, or no clear plug"
        + (" (quick study: 1536 steps only)" if quick else "")))
    ts = run.ts
    n = run.position.shape[1]
    expected = n / (2 * run.nxt)  # g·N/N_wall with g = 1, N_wall = 2 nxt wall particles
    shear = 0.5 * (ts["wall_shear_lower"] + ts["wall_shear_upper"])
    press = 0.5 * (-ts["wall_normal_lower"] + ts["wall_normal_upper"])
    t = ts["time"]
    half = t[len(t) // 2]
    s_m, s_e = m.interval_mean(t, shear, half)
    p_m, p_e = m.interval_mean(t, press, half)
    r, r_e = s_m / p_m, abs(s_m / p_m) * math.hypot(s_e / s_m, p_e / p_m)
    quarters = [float(shear[k].mean() / press[k].mean())
                for k in np.array_split(np.arange(1, len(t)), 4)]  # sample 0 has no interval
    ratio_ok = abs(r - SIGMA_OVER_P) <= 2 * r_e + 0.05
    an.checks.append(Check(
        ref, sts[1] + f" [{label}]", str(SIGMA_OVER_P),
        f"second half of the run (t ≥ {half:.0f} √(d/g)), both walls: σ = {pm(s_m, s_e)}, "
        f"p = {pm(p_m, p_e)} m g per wall particle, σ/p = {pm(r, r_e)}; over the run's four "
        f"quarters of samples σ/p = {', '.join(f'{q:.2f}' for q in quarters)}",
        REPRODUCED if ratio_ok else NOT_REPRODUCED,
        "" if ratio_ok else "the ratio differs from 0.25 by more than 2σ + 0.05"))
    last = t >= t[-1] - 0.1 * (t[-1] - t[0])
    f_m, f_e = m.interval_mean(t[last], shear[last], t[last][0], blocks=4)
    frac, frac_e = f_m / expected, f_e / expected
    rising = s_m < f_m
    ok = abs(frac - FINAL_SHEAR) <= 2 * frac_e + 0.15 and frac < 1
    an.checks.append(Check(
        ref, sts[2] + f" [{label}]", f"{FINAL_SHEAR:.2f} of the steady value",
        f"g·N/N_wall = {expected:.1f} m g per wall particle (thesis 252/8 = 31.5); wall shear "
        f"over the last 10 % of the run {pm(f_m, f_e)} = {pm(frac, frac_e)} of it "
        f"({'above' if rising else 'not above'} the second-half mean {s_m:.1f})",
        REPRODUCED if ok else PARTLY,
        "" if ok else "the final shear's share of the steady value differs from the "
        "thesis's 150/252 by more than 2σ + 0.15" + (" (quick study: 1536 steps only)"
                                                      if quick else "")))
    tag = "small" if "1/16" in label else "thesis"
    i = len(run.frame_steps) - 1
    # the thesis's 224 × 3 blocks on 8064 columns; a shorter channel keeps 36 blocks along x
    mvx = max(1, round(224 * run.nxt / 8064))
    blocks = m.block_average(run.position[i], run.velocity[i], run.nxt, run.nyt, mvx, 3)
    an.figures.append(figs.arrows(
        blocks, run, out, f"lgd_poiseuille_{tag}_blocks.png",
        f"Poiseuille {label} (fig 3.35a): velocities averaged over {mvx} × 3 blocks at step "
        f"{run.frame_steps[i]}, background: their thermal velocity", background=True,
        figsize=(8.0, 4.2)))
    an.figures.append(figs.profiles(
        [(p, f"Poiseuille {label}, {steps}")], out, f"lgd_poiseuille_{tag}_profiles.png",
        f"Poiseuille {label} (fig 3.35b): row profiles v̄x red, v̄y green, thermal velocity "
        f"blue, averaged over {len(frames)} frames", speed_label="velocity (√(g d))"))
    an.figures.append(figs.wall_stress(
        [(run, f"Poiseuille {label}")], out, f"lgd_poiseuille_{tag}_wall_stress.png",
        f"Poiseuille {label} (fig 3.36): shear (1, 3) and pressure (2, 4) per wall particle per "
        "unit time against time, in m g; dashed: the steady wall shear g·N/N_wall",
        ylabel="per wall particle (m g)", xlabel="time (√(d/g))", reference=expected,
        reference_label=f"g·N/N_wall = {expected:.1f}"))
