"""Event-driven (hard-particle) cases of the stability suite: the engine's own hard cases
(tests/test_edmd.py, tests/test_edmd_walls.py) measured for the table, inelastic collapse with
the TC model switched off, and how a dense flow depends on t_c.

Dimensionless particle units: d = 1, m = 1 (mass ∝ d^dim), g = 1 when gravity acts; the
temperature T = 1 of a gas, or the shear rate γ̇ = 1, sets the time unit otherwise.
Most cases drive the engine's core (``demstudy.engines.edmd``) directly, as its tests do;
the collapse, servo and t_c cases run through the simulation loop, as a user's run would.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..engines.edmd import EventDriven, core_options, from_initial_state, y_range
from ..errors import EngineError
from ..io.results import read_results
from ..scene import load_scene, parse_scene_text, validate_scene
from ..scene.initial import build_initial_state
from ..simulation import RunOptions, run_scene
from .registry import Outcome, case

HARD = "event-driven"
EDMD = "edmd"


def gas_scene(dim: int, fraction: float, n: int, seed: int, e: float = 1.0,
              shear: float | None = None, production: float = 1.0,
              sample: float = 1.0):
    """n smooth particles at solid ``fraction`` in a periodic cube (square), T = 1 (with
    ``shear``: Lees–Edwards at that rate and the linear profile on top)."""
    unit = math.pi / 6 if dim == 3 else math.pi / 4
    size = [round((n * unit / fraction) ** (1 / dim), 9)] * dim
    text = f"""
dimension = {dim}
[box]
size = {size}
[particles]
count = {n}
[contact]
restitution = {e}
[initial.velocity]
temperature = 1.0
profile = "{'linear' if shear else 'none'}"
[run]
equilibration = 0.0
production = {production}
sample_interval = {sample}
seed = {seed}
""" + (f"[shear]\nrate = {shear}\n" if shear else "")
    return validate_scene(parse_scene_text(text))


def core_of(scene, tc: float) -> EventDriven:
    """The event-driven core for a scene, as the backend builds it (without bumps)."""
    options = core_options(scene)
    initial = build_initial_state(scene)
    if not scene.y_periodic:
        options["y_range"] = y_range(scene, initial.position)
    return from_initial_state(initial, scene.box.size, tc=tc, **options)


def energy(s: EventDriven) -> float:
    return s.kinetic_energy + s.rotational_energy


def unit_particles(pos, vel, dim: int, box, **options) -> EventDriven:
    """Unit discs/spheres at rest in spin (d = 1, m = 1)."""
    pos = np.ascontiguousarray(pos, float).reshape(-1, dim)
    n = len(pos)
    return EventDriven(pos, np.ascontiguousarray(vel, float).reshape(n, dim),
                       np.zeros((n, 1 if dim == 2 else 3)), np.ones(n), np.ones(n),
                       [float(b) for b in box], dim, **options)


#: the dense cooling gas in which inelastic collapse happens without the TC model: 500 discs,
#: ν = 0.6, e = 0.3 (measured: t_c = 0 stalls at t = 0.607 after 3e6 events)
COLLAPSE = {"dim": 2, "fraction": 0.6, "n": 500, "seed": 9, "e": 0.3}


@case("tc-prevents-collapse", HARD,
      "dense cooling (500 discs, nu = 0.6, e = 0.3) with the TC model t_c = 1e-5 reaches "
      "t = 100; energy falls; no overlap", "reaches t = 100 within 1e7 events; gap > -1e-9 d",
      engine=EDMD)
def tc_prevents_collapse(engine: str, quick: bool, folder: Path) -> Outcome:
    s = core_of(gas_scene(**COLLAPSE), 1e-5)
    e0 = energy(s)
    reached = s.advance_to(100.0, max_events=10_000_000)
    gap = s.min_gap()
    note = (f"{s.events:.3g} events, {s.elastic_tc_collisions / max(1, s.collisions):.2%} of "
            f"collisions made elastic by TC, E/E0 = {energy(s) / e0:.2g}, min gap {gap:.2g}")
    return Outcome(f"t = {s.time:.4g}, {s.events:.2g} events",
                   bool(reached and energy(s) < 1e-2 * e0 and gap > -1e-9), note)


@case("collapse-without-tc", HARD,
      "the same gas with the TC model off (--tc 0): the run ends with an error naming the "
      "cause and the remedy", 'EngineError containing "inelastic collapse" and "--tc"',
      engine=EDMD)
def collapse_without_tc(engine: str, quick: bool, folder: Path) -> Outcome:
    scene = gas_scene(**COLLAPSE, production=10.0)
    try:
        run_scene(scene, engine, RunOptions(out=folder / "collapse.h5", progress=False,
                                            plan=False, isolate=True, extra={"tc": 0.0}))
    except EngineError as exc:
        message = str(exc).split("EngineError: ")[-1]  # the engine's own words
        names = "inelastic collapse" in message.lower() and "--tc" in message
        return Outcome("EngineError" + (" naming cause and --tc" if names else
                                        " without cause or --tc"), names,
                       f"message: {message}")
    return Outcome("ran to the end", False, "no collapse with t_c = 0: the case no longer "
                                            "tests what it should")


@case("ball-rests-on-floor", HARD,
      "a disc dropped from y = 2 on a floor (e_w = 0.5, g = 1, t_c = 1e-5) comes to rest",
      "at rest by t = 10: height above contact < 1e-9 d, |v| < 1e-4, <= 2e5 wall events/t",
      engine=EDMD)
def ball_rests(engine: str, quick: bool, folder: Path) -> Outcome:
    s = unit_particles([1.5, 2.0], [0.0, 0.0], 2, [3.0, 4.0], periodic_y=False,
                       y_range=(0.0, 4.0), gravity=[0.0, -1.0], tc=1e-5,
                       walls=[{"side": "lower", "position": 0.0, "e": 0.5}])
    reached = s.advance_to(10.0, max_events=3_000_000)
    height = s.positions()[0, 1] - 0.5
    speed = float(np.abs(s.velocities()[0]).max())
    ok = reached and 0.0 <= height < 1e-9 and speed < 1e-4 and s.wall_collisions <= 2e6
    return Outcome(f"height {height:.2g} d, |v| {speed:.2g}", bool(ok),
                   f"{s.wall_collisions:.3g} wall collisions to t = 10, "
                   f"{s.resting_bounces:.3g} resting bounces")


@case("column-stacks", HARD,
      "10 discs in a column (e = e_w = 0.3, g = 1, t_c = 1e-5) fall onto a floor and stack",
      "stacked by t = 2 within 1e7 events: gaps < 1e-6 d, no overlap, |v| < 1e-4",
      engine=EDMD)
def column_stacks(engine: str, quick: bool, folder: Path) -> Outcome:
    n = 10
    s = unit_particles([[1.5, 0.55 + 1.1 * k] for k in range(n)], np.zeros((n, 2)), 2,
                       [3.0, 20.0], periodic_y=False, y_range=(0.0, 20.0), e=0.3,
                       gravity=[0.0, -1.0], tc=1e-5,
                       walls=[{"side": "lower", "position": 0.0, "e": 0.3}])
    reached = s.advance_to(2.0, max_events=10_000_000)
    y = np.sort(s.positions()[:, 1])
    gaps = np.append(y[0] - 0.5, np.diff(y) - 1.0)
    speed = float(np.abs(s.velocities()).max())
    ok = (reached and gaps.max() < 1e-6 and gaps.min() > -1e-9 and s.min_gap() > -1e-9
          and speed < 1e-4)
    return Outcome(f"largest gap {gaps.max():.2g} d, |v| {speed:.2g}", bool(ok),
                   f"{s.events:.3g} events")


@case("rests-on-bump", HARD,
      "a disc bouncing onto a fixed bump (e = 0.5, g = 1, t_c = 1e-4) settles on top and "
      "hops instead of stalling", "reaches t = 1; 0.5/t_c..1.5/t_c hops; stays on top "
      "within 1e-8 d", engine=EDMD)
def rests_on_bump(engine: str, quick: bool, folder: Path) -> Outcome:
    tc = 1e-4
    s = unit_particles([[5.0, 3.0], [5.0, 2.0]], [[0.0, 0.1], [0.0, 0.0]], 2, [10.0, 10.0],
                       e=0.5, periodic_y=False, y_range=(0.0, 10.0),
                       fixed=np.array([0, 1], np.int8), tc=tc, gravity=[0.0, -1.0],
                       walls=[{"side": "lower", "position": 0.0, "e": 0.5}])
    reached = s.advance_to(1.0, max_events=200_000)
    drift = float(np.abs(s.positions()[0] - [5.0, 3.0]).max())
    hops = s.wall_collisions
    ok = reached and 0.5 / tc < hops < 1.5 / tc and drift < 1e-8 and s.min_gap() > -1e-9
    return Outcome(f"{hops} hops, off top {drift:.2g} d", bool(ok),
                   f"{s.resting_bounces} resting bounces, {s.invalid_events} stale events")


SERVO_SEED = "campbell1982/couette-rough"


@case("servo-10x-converges", HARD,
      f"{SERVO_SEED}, servo at 10 x its sigma_n (time intervals of 10, no clamp, gain "
      "0.025): the mean wall stress converges to sigma_n; no wall penetration",
      "|mean stress / sigma_n - 1| < 0.02 (--quick: < 0.1); centres >= r from walls",
      engine=EDMD)
def servo_converges(engine: str, quick: bool, folder: Path) -> Outcome:
    sigma = 10 * load_scene(SERVO_SEED).walls[0].servo.normal_stress
    sets = [f"walls.{k}.servo.{key}={value}" for k in (0, 1)
            for key, value in (("normal_stress", sigma), ("interval_unit", "time"),
                               ("clamp", "false"), ("gain", 0.025))]
    equilibration, production = (2000, 4000) if quick else (10000, 20000)
    sets += [f"run.equilibration={equilibration}", f"run.production={production}",
             "run.sample_interval=10"]
    res = read_results(run_scene(load_scene(SERVO_SEED, sets), engine, RunOptions(
        out=folder / "servo.h5", progress=False, keep_frames=True, plan=False)))
    ts = res.timeseries
    steady = ts["time"] > equilibration
    width = ts["width"][steady]
    ratios, errors = [], []
    for side, sign in (("lower", -1.0), ("upper", 1.0)):
        stress = sign * ts[f"wall_force_{side}"][steady, 1] / width / sigma
        blocks = stress[: len(stress) // 20 * 20].reshape(20, -1).mean(axis=1)
        ratios.append(stress.mean())
        errors.append(blocks.std(ddof=1) / math.sqrt(20))
    y = res.frames["position"][..., 1]
    lower, upper = ts["wall_position_lower"][steady], ts["wall_position_upper"][steady]
    inside = float(min((y.min(axis=1) - 0.5 - lower).min(), (upper - y.max(axis=1) - 0.5).min()))
    worst = max(abs(r - 1) for r in ratios)
    ok = worst < (0.1 if quick else 0.02) and inside > -1e-9
    return Outcome(f"stress/sigma_n {ratios[0]:.3f}, {ratios[1]:.3f}", bool(ok),
                   f"lower {ratios[0]:.3f} ± {errors[0]:.3f}, upper {ratios[1]:.3f} ± "
                   f"{errors[1]:.3f} (20 blocks); {production} time units; closest "
                   f"wall-contact gap {inside:.2g} d; final gap {ts['gap'][-1]:.3g} d")


@case("elastic-drift-hard", HARD,
      "elastic smooth gas, 4000 spheres at n = 0.5: energy over 1e7 collisions (--quick "
      "1e6); momentum; no overlap", "max |E - E0|/E0 < 1e-10; gap > -1e-9 d", engine=EDMD,
      slow=True)
def elastic_drift_hard(engine: str, quick: bool, folder: Path) -> Outcome:
    target = 1_000_000 if quick else 10_000_000
    s = core_of(gas_scene(3, 0.5 * math.pi / 6, 4000, 5), 0.0)
    e0, p0 = energy(s), s.velocities().sum(axis=0)
    t, drift = 0.0, 0.0
    while s.collisions < target:
        t += 20.0
        s.advance_to(t, stop_collisions=target)
        drift = max(drift, abs(energy(s) - e0) / e0)
    momentum = float(np.abs(s.velocities().sum(axis=0) - p0).max())
    ok = drift < 1e-10 and s.min_gap() > -1e-9 and momentum < 1e-10 * math.sqrt(4000)
    return Outcome(f"{drift:.2g} over {s.collisions:.2g} collisions", bool(ok),
                   f"momentum change {momentum:.2g}, min gap {s.min_gap():.2g} d")


#: t_c values of the dependence case, the two smallest compared
TC_LADDER = (1e-4, 1e-5, 1e-6)


@case("tc-dependence", HARD,
      "dense Lees-Edwards shear (400 discs, nu = 0.75, e = 0.5, rate 1): temperature and "
      "the elastic share at t_c = 1e-4, 1e-5, 1e-6",
      "T(1e-5) - T(1e-6) within 2 combined standard errors",
      engine=EDMD)
def tc_dependence(engine: str, quick: bool, folder: Path) -> Outcome:
    seeds = range(1, 3 if quick else 5)
    equilibration, production = (10.0, 20.0) if quick else (20.0, 80.0)
    table = {}
    for tc in TC_LADDER:
        temps, shares = [], []
        for seed in seeds:
            scene = gas_scene(2, 0.75, 400, seed, e=0.5, shear=1.0)
            s = core_of(scene, tc)
            s.advance_to(equilibration)
            c0, k0 = s.collisions, s.elastic_tc_collisions
            samples = []
            for k in range(1, int(production / 2) + 1):
                s.advance_to(equilibration + 2.0 * k)
                v = s.velocities()
                v[:, 0] -= s.positions()[:, 1] - scene.box.size[1] / 2  # u = γ̇ (y − L/2)
                samples.append(float((v**2).sum()) / (2 * len(v)))  # 2D: T = <|c|²>/2
            temps.append(np.mean(samples))
            shares.append((s.elastic_tc_collisions - k0) / (s.collisions - c0))
        err = np.std(temps, ddof=1) / math.sqrt(len(temps))
        table[tc] = (float(np.mean(temps)), float(err), float(np.mean(shares)))
    (t5, e5, _), (t6, e6, _) = table[TC_LADDER[1]], table[TC_LADDER[2]]
    diff, bound = abs(t5 - t6), 2 * math.hypot(e5, e6)
    note = "; ".join(f"t_c {tc:g}: T = {t:.4f} ± {e:.4f}, elastic share {sh:.2%}"
                     for tc, (t, e, sh) in table.items())
    note += (f" ({len(seeds)} seeds, {production:g} time units after {equilibration:g}; T "
             "in (γ̇ d)², the fluctuation about u = γ̇ (y − L/2))")
    return Outcome(f"|ΔT| {diff:.4f} vs {bound:.4f}", diff < bound, note)
