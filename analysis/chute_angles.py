"""Campbell's (1982) chute on a flat sticking base: which angles give a steady flow, and which
base gives his steady 30° flow (issue 14; docs/studies/campbell1982-chute30.md).

Runs Campbell's 10 × 4 chute (inputs/campbell1982/chute-30.toml: ε_p = 0.6, ε_w = 0.8, fully
rough discs and base, Campbell's initial state) with hard discs in the event-driven engine, one
run at a time: on the flat base over a scan of angles, and at 30° on particle-roughened bases
(random bumps of diameter d at spacings 1.0 and 1.2 d), each far longer than the thesis could
afford. From each run it takes the kinetic-energy history, the base's shear-to-normal force
ratio early (while the bed is dense) and late (second half), the basal solid fraction and the
wall slip; and it applies Campbell's convergence criterion to short windows of the early part
(10⁴-10⁵ collisions, the length of a thesis run, or 10-100 √(d/g)) to show transients that
pass it.

Writes results/chute-angles[-quick]/*.h5, the summary chute_angles.json and the figure
chute_angles.png; the full run also copies them to docs/data/ and docs/figures/.
Dimensionless particle units: d = 1, m = 1, g = 1 (lengths d, times √(d/g), energies m g d).

    python analysis/chute_angles.py --quick     # 4 runs of 400 √(d/g): about 30 s
    python analysis/chute_angles.py             # the study: 10 runs, about 6 minutes (2 cores)
    python analysis/chute_angles.py --tc 1e-6 --angles 26 30 --duration 800   # a t_c check
    python analysis/chute_angles.py --reuse     # analyse the existing results files again
    python analysis/chute_angles.py --redraw    # the figure again from docs/data/
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import demstudy as ds
from demstudy.analysis.steady import energy_trend, is_steady
from demstudy.engines.edmd import DEFAULT_TC_2D
from demstudy.io.results import write_atomically

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "docs" / "data" / "chute_angles.json"
FIGURE = ROOT / "docs" / "figures" / "chute_angles.png"
SCENE = "campbell1982/chute-30"
SAMPLE = 0.25          # √(d/g): fine enough for windows of 10⁴ collisions (≈ 2-5 √(d/g) early)
EARLY = (25.0, 200.0)  # √(d/g): the dense phase, after the initial deceleration transient
WINDOWS = (10_000, 30_000, 100_000)  # pair collisions: "many thousands" (thesis L813)
TIME_WINDOWS = (10.0, 25.0, 50.0, 100.0)  # √(d/g)
PANEL_WINDOW = 25.0    # √(d/g): the window length shown in the figure's early panel
EARLY_END = 400.0      # √(d/g): the early part searched for windows that pass the criterion
EARLY_PLOT = EARLY_END  # √(d/g): the early history kept at full resolution for the figure


@dataclass(frozen=True)
class Case:
    angle: float
    base: str          # "flat" or "bumps-<spacing>"
    duration: float    # √(d/g)
    seed: int | None = None  # None: the scene's (Campbell's 12345)

    @property
    def label(self) -> str:
        return f"{self.base}-{self.angle:g}"

    def scene(self, equilibration: float | None = None):
        """Campbell's chute at this angle and base; the production window is the second half
        (or what follows ``equilibration``)."""
        eq = self.duration / 2 if equilibration is None else equilibration
        sections = dict(gravity={"angle": self.angle}, measure={"statistics": []},
                        run={"equilibration": eq, "production": self.duration - eq,
                             "sample_interval": SAMPLE}
                        | ({} if self.seed is None else {"seed": self.seed}))
        if self.base != "flat":
            spacing = float(self.base.split("-")[1])
            # random bumps: the engine refuses regular ones under gravity (the bottom layer
            # cages itself in the hollows: docs/edmd-engine.md)
            sections["walls"] = {0: {"kind": "bumpy", "bumps": {
                "spacing": spacing, "diameter": 1.0, "pattern": "random"}}}
        return ds.load_scene(SCENE, **sections)


def cases(quick: bool) -> list[Case]:
    if quick:
        return ([Case(a, "flat", 400.0) for a in (22.0, 26.0, 30.0)]
                + [Case(30.0, "bumps-1.2", 400.0)])
    flat = [Case(a, "flat", 3200.0) for a in (22.0, 24.0, 26.0, 27.0, 28.0, 29.0, 30.0)]
    # at 20° the bed locks into a resting plug and the event-driven engine pays ~1/t_c
    # events per resting disc per time unit (docs/edmd-engine.md): shorter runs there
    low = [Case(20.0, "flat", 800.0)]
    bumpy = [Case(30.0, f"bumps-{s:g}", 3200.0) for s in (1.0, 1.2)]
    return flat + bumpy + low  # the costly resting bed last


# -- measures ---------------------------------------------------------------------------
def window_ratio(t: np.ndarray, force: np.ndarray, lo: float, hi: float) -> tuple[float, float]:
    """Base shear-to-normal force ratio |F_x/F_y| over lo < t ≤ hi, with a standard error from
    up to 10 blocks (the forces are interval means: their mean over the window is the impulse's)."""
    sel = (t > lo) & (t <= hi) & np.isfinite(force[:, 0])
    fx, fy = force[sel, 0], force[sel, 1]
    ratio = abs(fx.mean() / fy.mean())
    n_blocks = min(10, fx.size)
    if n_blocks < 2:
        return float(ratio), float("nan")
    pairs = zip(np.array_split(fx, n_blocks), np.array_split(fy, n_blocks), strict=True)
    # a block without wall contact (a bed at rest between resting hops) has no ratio
    blocks = [abs(a.mean() / b.mean()) for a, b in pairs if b.mean() != 0.0]
    if len(blocks) < 2:
        return float(ratio), float("nan")
    return float(ratio), float(np.std(blocks, ddof=1) / np.sqrt(len(blocks)))


def passes_campbell(t: np.ndarray, ke: np.ndarray) -> bool:
    """Campbell's criterion (§2.5): the kinetic energy fluctuates within about 20 % of its mean
    with no trend; quantified as |fitted change| < 20 % of the mean (demstudy.analysis.steady)
    and 95 % of the samples within ±20 % of the mean."""
    if t.size < 5:
        return False
    within = np.mean(np.abs(ke / ke.mean() - 1.0) <= 0.2)
    return is_steady(energy_trend(t, ke)) and within >= 0.95


def early_windows(t, ke, collisions, force, angle) -> list[dict]:
    """Windows that start in the early part (t ≤ EARLY_END, every 1/4 window) and pass Campbell's
    criterion: per window length in pair collisions (WINDOWS) and in time (TIME_WINDOWS), how
    many pass, and the passing windows' [t0, t1, mean KE per disc, base force ratio]."""
    out = []
    early = t <= EARLY_END
    for unit, clock, lengths in (("collisions", collisions, WINDOWS), ("time", t, TIME_WINDOWS)):
        for length in lengths:
            starts = np.arange(clock[0], clock[early][-1] - length, length / 4)
            passing = []
            for c0 in starts:
                sel = (clock >= c0) & (clock < c0 + length)
                if passes_campbell(t[sel], ke[sel]):
                    lo, hi = float(t[sel][0]), float(t[sel][-1])
                    passing.append([round(lo, 3), round(hi, 3), round(float(ke[sel].mean()), 3),
                                    round(window_ratio(t, force, lo, hi)[0], 4)])
            out.append({"unit": unit, "length": length, "windows": len(starts),
                        "passed": len(passing), "first": passing[0] if passing else None,
                        # every passing window only for the time windows (the figure's panel)
                        "passing": passing if unit == "time" else None,
                        "tan_alpha": float(np.tan(np.radians(angle)))})
    return out


def rounded(values: np.ndarray) -> list[float]:
    """Four significant digits: the stored histories are for the figure."""
    return [float(f"{v:.4g}") for v in values]


def summarise(case: Case, res, wall_seconds: float) -> dict:
    ts, n = res.timeseries, res.scene.n_particles
    t, ke = ts["time"], ts["kinetic_energy"] / n
    force = ts["wall_force_lower"]
    half = case.duration / 2
    prof = res.profiles
    y, nu, u = prof["y"], prof["solid_fraction"], prof["velocity"][:, 0]
    # the bed's fastest strip: strips above the free surface hold a few saltating discs
    u_max = float(np.nanmax(np.where(nu >= 0.05, u, np.nan)))
    late_ratio, late_err = window_ratio(t, force, half, case.duration)
    early_ratio, early_err = window_ratio(t, force, *EARLY)
    # the bed's x-momentum balance over the production half: M g sin α − F_x = dP_x/dt
    late = t > half
    px = ts["momentum"][late, 0]
    accel = float((px[-1] - px[0]) / (t[late][-1] - t[late][0]) / n)
    collisions = ts["collisions"].astype(float)
    step = max(1, int(round(4.0 / SAMPLE)))  # the stored history: every 4 √(d/g)
    return {
        "angle": case.angle, "base": case.base, "duration": case.duration,
        "wall_seconds": wall_seconds, "tan_alpha": float(np.tan(np.radians(case.angle))),
        "ratio_early": early_ratio, "ratio_early_err": early_err,
        "ratio_late": late_ratio, "ratio_late_err": late_err,
        "ke_late": float(ke[late].mean()),
        "ke_trend_late": float(res.attrs["kinetic_energy_trend"]),
        "steady_late": bool(res.attrs["steady"]), "accel_late": accel,
        "depth": float(2 * np.sum(y * nu) / np.sum(nu)),  # Campbell's H = 2 × mass-mean height
        "nu_base": float(nu[0]), "nu_max": float(np.max(nu)),
        "slip": float(u[0] / u_max), "u_max": u_max,
        "tc_share": float(ts["elastic_tc_collisions"][-1] / max(1.0, ts["collisions"][-1])),
        "pair_collisions": float(collisions[-1]),
        "wall_collisions": float(ts["wall_collisions"][-1]),
        "early_windows": early_windows(t, ke, collisions, force, case.angle),
        "history": {"time": t[::step].tolist(), "ke": rounded(ke[::step])},
        # the early part at full resolution for the figure's panel (the 30° flat base only)
        "early": ({"time": t[t <= EARLY_PLOT].tolist(), "ke": rounded(ke[t <= EARLY_PLOT])}
                  if case.angle == 30.0 and case.base == "flat" else None),
    }


# -- figure -----------------------------------------------------------------------------
def figure(data: dict, path: Path) -> Path:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    runs = data["runs"]
    flat = sorted((r for r in runs if r["base"] == "flat"), key=lambda r: r["angle"])
    bumpy = [r for r in runs if r["base"] != "flat"]
    fig, ((ax1, ax2), (ax3, ax4)) = plt.subplots(2, 2, figsize=(13, 10))
    cmap = plt.get_cmap("plasma")
    span = max(1.0, flat[-1]["angle"] - flat[0]["angle"]) if flat else 1.0
    for r in flat:
        h = r["history"]
        ax1.plot(h["time"], h["ke"], color=cmap(0.85 * (r["angle"] - flat[0]["angle"]) / span),
                 lw=1, label=f"{r['angle']:g}°")
    ax1.set(yscale="log", xlabel="t [√(d/g)]", ylabel="kinetic energy per disc [m g d]",
            title="flat sticking base: kinetic energy per angle", ylim=(0.3, 5e3))
    stopped = [r for r in flat if min(r["history"]["ke"]) < 0.3]
    if stopped:  # a bed at rest: its energy falls off the panel
        ax1.text(0.02, 0.03, "off the panel: " + ", ".join(f"{r['angle']:g}°" for r in stopped)
                 + " comes to rest", transform=ax1.transAxes, fontsize=8)
    ax1.legend(fontsize=8, ncol=2, loc="lower right", title="α")
    for r in [r for r in flat if r["angle"] == 30.0] + bumpy:
        h = r["history"]
        flat_base = r["base"] == "flat"
        base = "flat base" if flat_base else f"random bumps, spacing {r['base'][6:]} d"
        colour = "C1" if flat_base else f"C{2 + bumpy.index(r)}"
        ax2.plot(h["time"], h["ke"], lw=1, color=colour, label=base)
    ax2.set(yscale="log", xlabel="t [√(d/g)]", ylabel="kinetic energy per disc [m g d]",
            title="α = 30°: flat base against particle-roughened bases")
    if ax2.lines:  # a partial run may hold neither the 30° flat base nor a bumpy one
        ax2.legend(fontsize=8, loc="lower right")
    angles = np.array([r["angle"] for r in flat])
    for key, marker, colour, name in (
            ("ratio_early", "o", "C0", f"dense phase, t = {EARLY[0]:g}-{EARLY[1]:g}"),
            ("ratio_late", "s", "C1", "second half of the run")):
        ax3.errorbar(angles, [r[key] for r in flat], [r[key + "_err"] for r in flat],
                     fmt=marker, ms=5, capsize=2, color=colour, label=f"flat base, {name}")
    for r in bumpy:
        ax3.errorbar([r["angle"] + 0.15 * (1 + bumpy.index(r))], [r["ratio_late"]],
                     [r["ratio_late_err"]], fmt="^", ms=6, capsize=2,
                     color=f"C{2 + bumpy.index(r)}",
                     label=f"bumps {r['base'][6:]} d, second half")
    grid = np.linspace(angles.min() - 1, angles.max() + 1, 50) if flat else np.linspace(17, 31, 50)
    ax3.plot(grid, np.tan(np.radians(grid)), "k-", lw=1, label="tan α (steady flow)")
    ax3.set(xlabel="α [°]", ylabel="base force ratio |F_x / F_y|",
            title="base shear-to-normal force ratio")
    ax3.legend(fontsize=8, loc="upper left")
    early_panel(ax4, flat)
    fig.text(0.5, 0.01, f"Campbell's 10 × 4 chute, ε_p = 0.6, ε_w = 0.8, fully rough; hard discs "
             f"(event-driven, t_c = {data['tc']:g}); units d = m = g = 1. {data['machine']}",
             ha="center", fontsize=8)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def early_panel(ax, flat: list[dict]) -> None:
    """The early part of the flat-base 30° run at full resolution, with the windows of
    PANEL_WINDOW √(d/g) that pass Campbell's criterion shaded: a thesis-length run ending in
    one would have been called converged, yet the base force ratio inside is below tan α."""
    runs = [r for r in flat if r["angle"] == 30.0]
    if not runs:
        return
    r = runs[0]
    ax.plot(r["early"]["time"], r["early"]["ke"], "C1-", lw=1, label="flat base, α = 30°")
    win = next(w for w in r["early_windows"]
               if w["unit"] == "time" and w["length"] == PANEL_WINDOW)
    for t0, t1, _, _ in win["passing"]:
        ax.axvspan(t0, t1, color="C2", alpha=0.15, lw=0)
    if win["passing"]:
        ratios = np.array([w[3] for w in win["passing"]])
        below = int(np.sum(ratios < r["tan_alpha"]))
        ax.axvspan(0, 0, color="C2", alpha=0.3,
                   label=f"windows of {PANEL_WINDOW:g} √(d/g) passing Campbell's criterion;\n"
                         f"base ratio in them {ratios.mean():.3f} on average, below "
                         f"tan 30° = {r['tan_alpha']:.3f}\nin {below} of {ratios.size}: "
                         "the bed accelerates through them")
    ax.set(xlabel="t [√(d/g)]", ylabel="kinetic energy per disc [m g d]",
           title=f"early part at 30° (flat): {win['passed']} of {win['windows']} windows of "
                 f"{PANEL_WINDOW:g} √(d/g) pass", xlim=(0, EARLY_END))
    ax.legend(fontsize=8, loc="upper left")


# -- the base's contacts ------------------------------------------------------------------
CONTACT_CASES = (Case(24.0, "flat", 200.0), Case(30.0, "flat", 200.0),
                 Case(30.0, "bumps-1.2", 200.0))
LOG_EVERY = 200  # every 200th collision: the log's 200 000 records then span 200 √(d/g)


def base_contacts(case: Case, out: Path, tc: float, reuse: bool) -> dict:
    """How the discs meet the base in the dense phase (t = EARLY), from the collision log of a
    short run: the median speed of a disc's contact point along x relative to its centre's
    (≈ 0: the disc rolls), wall events per √(d/g), and |ΣJ_x/ΣJ_y| of the logged wall impulses."""
    path = out / f"contacts-{case.label}.h5"
    if reuse and path.exists():
        res = ds.load(path)
    else:
        res = ds.run(case.scene(equilibration=0.0), engine="edmd", out=path, progress=False,
                     tc=tc, log_every=LOG_EVERY)
    log = res.groups["collisions"]
    wall = log["kind"] == 1
    t = log["time"][wall]
    sel = (t > EARLY[0]) & (t <= EARLY[1])
    u = np.abs(log["velocity"][wall][sel, 0])
    slip = np.abs(log["spin_velocity"][wall][sel, 0])
    impulse = log["impulse"][wall][sel]
    ts = res.timeseries
    span = (ts["time"] > EARLY[0]) & (ts["time"] <= EARLY[1])
    events = np.diff(ts["wall_collisions"][span][[0, -1]])[0] / np.ptp(ts["time"][span])
    return {"angle": case.angle, "base": case.base, "logged": int(sel.sum()),
            "median_slip_over_speed": float(np.median(slip / np.maximum(u, 1e-12))),
            "wall_events_per_time": float(events),
            "logged_impulse_ratio": float(abs(impulse[:, 0].sum() / impulse[:, 1].sum()))}


# -- main -------------------------------------------------------------------------------
def measure(selected: list[Case], out: Path, tc: float, reuse: bool, quick: bool) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    runs = []
    for case in selected:
        path = out / f"{case.label}.h5"
        start = time.perf_counter()
        if reuse and path.exists():  # analyse again without running
            res = ds.load(path)
            seconds = float(res.attrs["wall_seconds"])
        else:
            res = ds.run(case.scene(), engine="edmd", out=path, progress=False, tc=tc)
            seconds = time.perf_counter() - start
        runs.append(summarise(case, res, seconds))
        r = runs[-1]
        print(f"{case.label:>14}: {r['wall_seconds']:6.1f} s  ratio early {r['ratio_early']:.3f} "
              f"late {r['ratio_late']:.3f} (tan α {r['tan_alpha']:.3f})  KE/N late "
              f"{r['ke_late']:8.2f}  trend {r['ke_trend_late']:+.2f}  ν_base {r['nu_base']:.2f}  "
              f"slip {r['slip']:.2f}  TC share {r['tc_share']:.2f}", flush=True)
    contacts = [] if quick else [base_contacts(c, out, tc, reuse) for c in CONTACT_CASES]
    for c in contacts:
        print(f"contacts {c['base']}-{c['angle']:g}: contact point / centre speed "
              f"{c['median_slip_over_speed']:.1e}, {c['wall_events_per_time']:.3g} wall events "
              f"per √(d/g), logged |ΣJx/ΣJy| {c['logged_impulse_ratio']:.3f}", flush=True)
    machine = f"{platform.node()}, {platform.processor() or platform.machine()}"
    return {"units": "d = 1, m = 1, g = 1: times in √(d/g), energies in m g d, forces in m g",
            "base_contacts": contacts,
            "scene": SCENE, "engine": "edmd", "tc": tc,
            "machine": f"machine: {machine}, Python {platform.python_version()}",
            "runs": runs}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="4 short runs (about 1 minute)")
    parser.add_argument("--redraw", action="store_true", help="only the figure, from docs/data")
    parser.add_argument("--tc", type=float, default=DEFAULT_TC_2D,
                        help="TC-model time of the event-driven engine (default %(default)g); "
                             "another value is a sensitivity check, written to "
                             "results/chute-angles-tc<tc>/ only")
    parser.add_argument("--duration", type=float,
                        help="run length of every selected case in √(d/g) (a partial run)")
    parser.add_argument("--seed", type=int,
                        help="another seed of the initial jitter and velocities (a partial run)")
    parser.add_argument("--reuse", action="store_true",
                        help="analyse the results files already in results/ again (no runs)")
    parser.add_argument("--angles", type=float, nargs="*",
                        help="only these flat-base angles (and no bumpy base), e.g. 26 30")
    args = parser.parse_args(argv)
    if args.redraw:
        print(f"figure: {figure(json.loads(DATA.read_text()), FIGURE)}")
        return 0
    selected = cases(args.quick)
    if args.angles:
        selected = [c for c in selected if c.base == "flat" and c.angle in args.angles]
    if args.duration or args.seed is not None:
        selected = [Case(c.angle, c.base, args.duration or c.duration, args.seed)
                    for c in selected]
    partial = (args.quick or args.angles or args.duration or args.seed is not None
               or args.tc != DEFAULT_TC_2D)
    name = "chute-angles" + ("-quick" if args.quick else "") + (
        f"-tc{args.tc:g}" if args.tc != DEFAULT_TC_2D else "") + (
        "-some" if args.angles or args.duration else "") + (
        f"-seed{args.seed}" if args.seed is not None else "")
    out = ROOT / "results" / name
    data = measure(selected, out, args.tc, args.reuse, partial)
    text = json.dumps(data, separators=(",", ":"))
    write_atomically(out / "chute_angles.json", text.encode())
    print(f"figure: {figure(data, out / 'chute_angles.png')}")
    if not partial:  # only the whole study at the default t_c goes into the docs
        DATA.parent.mkdir(parents=True, exist_ok=True)
        write_atomically(DATA, text.encode())
        print(f"figure: {figure(data, FIGURE)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
