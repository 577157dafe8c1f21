"""What the LGD part of the Gutt (1989) study measures, in the thesis's forms (digest §3.10):
row profiles "averaged along each row" (mean vx, vy and the thermal velocity, the listing's
av3 = √(⟨v²⟩ − ⟨vx⟩² − ⟨vy⟩²)), mvx × mvy block averages, the 2D Maxwellian test, the
explosion front, the hourglass discharge, the obstacles' void and cap proxies and the
momentum balance of the code test.

Dimensionless particle units: d = 1 (the lattice spacing), m = 1; g = 1 where gravity acts,
otherwise the scene's speed unit (wall speed or initial gas speed) sets the time scale.
Lattice geometry (docs/lgd-engine.md): storage row r (0 = the bottom wall row) sits at
y = r·√3/2, a grain's offset is less than half a spacing, so its row is round(y/(√3/2)).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy import stats

from ...analysis.blocking import split_mean
from ...io.results import read_results

ROW = math.sqrt(3) / 2


@dataclass
class LgdRun:
    """One LGD run: its attributes, timeseries and kept frames (positions, velocities, the
    step of each frame), the lattice size and the integer speed unit."""

    name: str
    attrs: dict[str, Any]
    ts: dict[str, np.ndarray]
    position: np.ndarray  # (frames, N, 2)
    velocity: np.ndarray
    frame_steps: np.ndarray
    nxt: int
    nyt: int
    scene_toml: str = ""
    extra: dict = field(default_factory=dict)

    def frame_at(self, step: int) -> int:
        """Index of the kept frame at ``step`` (refused if none was kept there)."""
        hits = np.flatnonzero(self.frame_steps == step)
        if hits.size == 0:
            raise ValueError(f"{self.name}: no frame at step {step} (kept: "
                             f"{self.frame_steps.min()}..{self.frame_steps.max()})")
        return int(hits[0])


def load(name: str, path: Path) -> LgdRun:
    r = read_results(path)
    if r.frames is None:
        raise ValueError(f"{path}: no frames kept (the LGD cases set measure.keep_frames)")
    ts = {k: np.asarray(v) for k, v in r.timeseries.items()}
    # frames are kept at production samples: their steps from the timeseries' time column
    idx = np.searchsorted(ts["time"], np.asarray(r.frames["time"]) - 1e-9)
    return LgdRun(name, dict(r.attrs), ts, np.asarray(r.frames["position"]),
                  np.asarray(r.frames["velocity"]), ts["steps"][idx].astype(int),
                  int(r.attrs["lgd_nxt"]), int(r.attrs["lgd_nyt"]),
                  str(r.attrs.get("scene_toml", "")),
                  {"scene": r.scene, "tracks": _tracks(r)})


def _tracks(r) -> dict | None:
    """The marked grains' paths (``/tracks``) with their period, or None."""
    if "tracks" not in r.groups:
        return None
    return {**r.groups["tracks"], "period_x": r.group_attrs["tracks"]["period_x"]}


def initial_state(run: LgdRun) -> dict[str, np.ndarray]:
    """The run's initial lattice rebuilt from its scene's md lines: the node centres
    (x = (c + 1 + r/2) mod nxt, y = r·√3/2) of the wall particles (``walls``, the wall rows
    included), of the grains (``grains``) and the grains' velocities in particle units."""
    from ...engines.lgd.effects import lattice_setup
    from ...engines.lgd.problem import build_lattice

    setup = lattice_setup(run.extra["scene"])
    lat = build_lattice(setup.params, setup.lines)
    r, c = np.indices(lat.mlp.shape)
    x = (c + 1 + r / 2) % run.nxt
    y = r * ROW
    wall, grain = lat.mlp == -1, lat.mlp > 0
    speed = setup.units.speed
    return {"walls": np.stack([x[wall], y[wall]], 1), "wall_rows": r[wall],
            "grains": np.stack([x[grain], y[grain]], 1),
            "velocity": np.stack([lat.ivx[grain], lat.ivy[grain]], 1) / speed}


def rows_of(y: np.ndarray) -> np.ndarray:
    return np.rint(np.asarray(y) / ROW).astype(int)


def row_profiles(pos: np.ndarray, vel: np.ndarray, nyt: int) -> dict[str, np.ndarray]:
    """Per storage row (0..nyt−1): grain count n, mean vx, vy and the thermal velocity
    (listing av3 per row) with standard errors (σ/√n; the thermal one from the spread of
    v² by the delta method). Rows without grains are NaN."""
    r = rows_of(pos[:, 1])
    n = np.bincount(r, minlength=nyt).astype(float)[:nyt]
    out: dict[str, np.ndarray] = {"y": np.arange(nyt) * ROW, "n": n}
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = {}
        for key, col in (("vx", vel[:, 0]), ("vy", vel[:, 1])):
            s1 = np.bincount(r, col, nyt)[:nyt]
            s2 = np.bincount(r, col * col, nyt)[:nyt]
            mean[key] = s1 / n
            out[key] = mean[key]
            out[key + "_err"] = np.sqrt(np.maximum(s2 / n - mean[key] ** 2, 0) / n)
        c2 = (vel[:, 0] - mean["vx"][r]) ** 2 + (vel[:, 1] - mean["vy"][r]) ** 2
        t2 = np.bincount(r, c2, nyt)[:nyt] / n
        t4 = np.bincount(r, c2 * c2, nyt)[:nyt] / n
        out["thermal"] = np.sqrt(t2)
        out["thermal_err"] = np.sqrt(np.maximum(t4 - t2 ** 2, 0) / n) / (2 * np.sqrt(t2))
        out["density"] = n / max(1, np.max(n))
    return out


def mean_profiles(run: LgdRun, frames: np.ndarray) -> dict[str, np.ndarray]:
    """Row profiles averaged over ``frames`` (indices); errors: the frames' standard error
    when there are several (frames are correlated: a lower bound), else the single frame's."""
    profs = [row_profiles(run.position[i], run.velocity[i], run.nyt) for i in frames]
    out = {"y": profs[0]["y"]}
    with warnings.catch_warnings():  # rows without grains (the wall rows) stay NaN
        warnings.simplefilter("ignore", RuntimeWarning)
        _average(profs, out)
    return out


def _average(profs: list[dict], out: dict) -> None:
    for key in ("n", "vx", "vy", "thermal", "density"):
        stack = np.array([p[key] for p in profs])
        out[key] = np.nanmean(stack, axis=0) if len(profs) > 1 else stack[0]
        if key != "n":
            if len(profs) > 1:
                out[key + "_err"] = np.nanstd(stack, axis=0, ddof=1) / math.sqrt(len(profs))
            elif key + "_err" in profs[0]:
                out[key + "_err"] = profs[0][key + "_err"]


def block_average(pos: np.ndarray, vel: np.ndarray, nxt: int, nyt: int, mvx: int,
                  mvy: int) -> dict[str, np.ndarray]:
    """The listing's mvx × mvy block averages (L2362-L2608): block (x // mvx, (r − 1) // mvy)
    over the open rows 1..nyt−2; mean vx, vy, thermal velocity, count and block centres."""
    r = rows_of(pos[:, 1])
    keep = (r >= 1) & (r <= nyt - 2)
    bx = (np.floor(pos[keep, 0]).astype(int) % nxt) // mvx
    by = (r[keep] - 1) // mvy
    nbx, nby = -(-nxt // mvx), -(-(nyt - 2) // mvy)
    flat = by * nbx + bx
    size = nbx * nby
    n = np.bincount(flat, minlength=size).astype(float)
    v = vel[keep]
    with np.errstate(invalid="ignore", divide="ignore"):
        vx = np.bincount(flat, v[:, 0], size) / n
        vy = np.bincount(flat, v[:, 1], size) / n
        v2 = np.bincount(flat, (v ** 2).sum(1), size) / n
        th = np.sqrt(np.maximum(v2 - vx ** 2 - vy ** 2, 0))
    cx = (np.arange(nbx) + 0.5) * mvx
    cy = (1 + np.arange(nby) * mvy + (mvy - 1) / 2) * ROW  # the block's middle row
    shape = (nby, nbx)
    return {"n": n.reshape(shape), "vx": vx.reshape(shape), "vy": vy.reshape(shape),
            "thermal": th.reshape(shape), "x": cx, "y": cy}


# --- the gas: 2D Maxwellian ----------------------------------------------------------------

def maxwell_test(vel: np.ndarray) -> dict[str, float]:
    """How far the velocities are from the 2D Maxwellian with their own ⟨v²⟩ (thesis L1039:
    f_s = (2v/⟨v²⟩) e^{−v²/⟨v²⟩}, i.e. v²/⟨v²⟩ ~ Exp(1); each component N(0, ⟨v²⟩/2)).
    Returns the KS distances of v²/⟨v²⟩ (speed) and of vx, vy against those laws, the
    critical KS distance at 1 % for this N (independent grains assumed), the total-variation
    distance of the speed histogram (40 bins to 3 √⟨v²⟩) and ⟨vx²⟩/⟨vy²⟩ with its error
    (relative √(2/N) per component for Gaussian components)."""
    v = np.asarray(vel, float)
    v = v - v.mean(axis=0)  # the box's mean flow is zero; its round-off drift is removed
    n = len(v)
    v2 = (v ** 2).sum(1)
    m2 = v2.mean()
    ks_speed = stats.kstest(v2 / m2, "expon").statistic
    sig = math.sqrt(m2 / 2)
    ks_x = stats.kstest(v[:, 0] / sig, "norm").statistic
    ks_y = stats.kstest(v[:, 1] / sig, "norm").statistic
    edges = np.linspace(0, 3 * math.sqrt(m2), 41)
    hist, _ = np.histogram(np.sqrt(v2), edges)
    cdf = 1 - np.exp(-edges ** 2 / m2)
    tv = 0.5 * np.abs(hist / n - np.diff(cdf)).sum()
    ratio = float((v[:, 0] ** 2).mean() / (v[:, 1] ** 2).mean())
    return {"ks_speed": float(ks_speed), "ks_vx": float(ks_x), "ks_vy": float(ks_y),
            "ks_critical": 1.628 / math.sqrt(n), "tv_speed": float(tv), "anisotropy": ratio,
            "anisotropy_err": ratio * math.sqrt(4 / n), "n": n, "v2": float(m2)}


# --- the explosion --------------------------------------------------------------------------

def explosion_front(pos: np.ndarray, vel: np.ndarray, centre: tuple[float, float],
                    sectors: int = 72, quantile: float = 0.98) -> dict[str, np.ndarray | float]:
    """The front radius per angular sector: the ``quantile`` of the distances of the moving
    grains (the background starts at rest, so a moving grain has been reached by the blast).
    Anisotropy: relative r.m.s. of R(θ) and the Fourier amplitudes |a_k|/a_0 for k = 2 (an
    elongation), 4 (the square block) and 6 (the lattice's directions)."""
    moving = np.hypot(vel[:, 0], vel[:, 1]) > 0
    d = pos[moving] - np.asarray(centre)
    radius = np.hypot(d[:, 0], d[:, 1])
    theta = np.arctan2(d[:, 1], d[:, 0])
    s = ((theta + math.pi) / (2 * math.pi) * sectors).astype(int) % sectors
    front = np.array([np.quantile(radius[s == k], quantile) if np.any(s == k) else np.nan
                      for k in range(sectors)])
    angles = -math.pi + (np.arange(sectors) + 0.5) * 2 * math.pi / sectors
    ok = np.isfinite(front)
    a0 = front[ok].mean()
    coef = {k: np.mean(front[ok] * np.exp(-1j * k * angles[ok])) for k in (2, 4, 6)}
    amp = {k: abs(c) * 2 / a0 for k, c in coef.items()}
    return {"theta": angles, "front": front, "mean": float(a0),
            "rel_rms": float(front[ok].std() / a0), "a2": float(amp[2]), "a4": float(amp[4]),
            "a6": float(amp[6]),
            # direction of the longest axis of the k = 2 (elliptic) part, in degrees
            "a2_angle": float(np.degrees(np.angle(coef[2]) / 2))}


def radial_alignment(blocks: dict[str, np.ndarray], centre: tuple[float, float],
                     min_count: int = 8, min_speed: float = 0.0) -> dict[str, Any]:
    """Angle between each block's mean velocity and the radial direction from ``centre``,
    over the blocks with at least ``min_count`` grains and a mean speed above ``min_speed``."""
    gx, gy = np.meshgrid(blocks["x"], blocks["y"])
    rx, ry = gx - centre[0], gy - centre[1]
    speed = np.hypot(blocks["vx"], blocks["vy"])
    use = (blocks["n"] >= min_count) & (speed > min_speed) & (np.hypot(rx, ry) > 0)
    cos = (blocks["vx"] * rx + blocks["vy"] * ry)[use] / (speed[use] * np.hypot(rx, ry)[use])
    ang = np.degrees(np.arccos(np.clip(cos, -1, 1)))
    return {"angles": ang, "count": int(use.sum()),
            "within15": float(np.mean(ang <= 15)) if ang.size else math.nan,
            "within30": float(np.mean(ang <= 30)) if ang.size else math.nan}


# --- the hourglass --------------------------------------------------------------------------

def discharge_linearity(t: np.ndarray, count: np.ndarray, total: int,
                        start_fraction: float = 0.05, end_fraction: float = 0.9
                        ) -> dict[str, float]:
    """Fit count = a + b t over the window after start-up (count ≥ ``start_fraction`` of the
    final count) until the bin empties (count ≤ ``end_fraction`` of ``total``). "Nearly
    linear": the rates fitted to the window's two halves agree (ratio ``rate_ratio``, 1 for
    a constant rate, 3 for a count ∝ t² from t = 0); also the r.m.s. residual of the line
    relative to the count's rise over the window."""
    t, count = np.asarray(t, float), np.asarray(count, float)
    final = count[-1]
    use = (count >= start_fraction * final) & (count <= end_fraction * total)
    if use.sum() < 6:
        return {"rate": math.nan, "rate_err": math.nan, "rate_ratio": math.nan,
                "residual": math.nan, "t0": math.nan, "t1": math.nan, "points": int(use.sum())}
    tw, cw = t[use], count[use]
    (b, a), cov = np.polyfit(tw, cw, 1, cov=True)
    resid = cw - (a + b * tw)
    half = len(tw) // 2
    b1 = np.polyfit(tw[:half + 1], cw[:half + 1], 1)[0]
    b2 = np.polyfit(tw[half:], cw[half:], 1)[0]
    return {"rate": float(b), "rate_err": float(math.sqrt(cov[0, 0])),
            "rate_ratio": float(b2 / b1), "residual": float(resid.std() / (cw[-1] - cw[0])),
            "t0": float(tw[0]), "t1": float(tw[-1]), "points": int(use.sum()),
            "intercept": float(a)}


# --- momentum balance (the code test) -------------------------------------------------------

def momentum_balance(run: LgdRun) -> dict[str, float]:
    """Δp of the grains between samples against the wall impulses (−force on the walls × Δt;
    lower, upper and the extra wall particles) and gravity (N·ĝ·Δt, g = 1): the largest
    residual over the run relative to N·√⟨v²⟩ (the grains' momentum scale); and the grain
    count in every kept frame."""
    ts = run.ts
    t, p = ts["time"], ts["momentum"]
    dt = np.diff(t)[:, None]
    wall = ts["wall_force_lower"][1:] + ts["wall_force_upper"][1:]
    nw = int(run.attrs.get("lgd_extra_wall_particles", 0) or 0)
    if nw:
        wall = wall + nw * np.stack([ts["wall_shear_extra"][1:], ts["wall_normal_extra"][1:]], 1)
    n = run.position.shape[1]
    g = np.array([run.attrs.get("lgd_igx", 0), run.attrs.get("lgd_igy", 0)], float)
    g = g / np.linalg.norm(g) if np.any(g) else g
    expected = -wall * dt + n * g[None, :] * dt
    resid = np.diff(p, axis=0) - expected
    scale = n * max(float(np.sqrt(np.nanmax(ts["kinetic_energy"]) * 2 / n)), 1e-12)
    counts = np.isfinite(run.position[:, :, 0]).sum(1)
    return {"residual": float(np.nanmax(np.abs(resid)) / scale),
            "impulse": float(np.nanmax(np.abs(expected)) / scale),
            "grains_min": int(counts.min()), "grains_max": int(counts.max()),
            "grains": int(run.attrs.get("lgd_ng", n) if "lgd_ng" in run.attrs else n)}


def interval_mean(t: np.ndarray, y: np.ndarray, t0: float, blocks: int = 8
                  ) -> tuple[float, float]:
    """Mean of the sampled ``y`` over t ≥ t0 and its error from ``blocks`` block means."""
    return split_mean(np.asarray(y, float)[np.asarray(t) >= t0], blocks)


def nodes_of(pos: np.ndarray, nxt: int) -> np.ndarray:
    """The storage node (row·nxt + column) of each grain (offsets < ½ spacing)."""
    r = rows_of(pos[:, 1])
    c = np.rint(pos[:, 0] - 1 - r / 2).astype(int) % nxt
    return r * nxt + c


def occupancy_overlap(pos_a: np.ndarray, pos_b: np.ndarray, nxt: int) -> float:
    """Share of the nodes occupied in either frame that are occupied in both (Jaccard): 1
    for a pile whose grains stay on their nodes; the LGD grains keep velocities where a
    full neighbour site blocks their move (static load is carried by repeated gravity
    kicks, digest §5.8), so resting is read from the nodes, not from the velocities."""
    a, b = set(nodes_of(pos_a, nxt).tolist()), set(nodes_of(pos_b, nxt).tolist())
    union = a | b
    return len(a & b) / len(union) if union else math.nan


def same_as_periodic_copy(small: LgdRun, full: LgdRun, step: int) -> float:
    """Largest difference in position or velocity between ``small``'s frame at ``step`` and
    ``full``'s grains in its first ``small.nxt`` columns (NaN if their counts differ): 0 when
    the long channel is an exact periodic copy of the short one (a uniform start and the
    deterministic, translation-invariant integer step keep every period of the templates
    identical)."""
    pa, va = small.position[small.frame_at(step)], small.velocity[small.frame_at(step)]
    ib = full.frame_at(step)
    sel = full.position[ib][:, 0] < small.nxt
    pb, vb = full.position[ib][sel], full.velocity[ib][sel]
    if len(pa) != len(pb):
        return math.nan
    ka, kb = np.lexsort((pa[:, 0], pa[:, 1])), np.lexsort((pb[:, 0], pb[:, 1]))
    return float(max(np.abs(pa[ka] - pb[kb]).max(), np.abs(va[ka] - vb[kb]).max()))
