"""What the event-driven engine's TC time t_c costs and buys: the share of pair collisions the
TC model makes elastic and the wall time, at t_c = 1e-4, 1e-5 (the default for discs) and 1e-6
(the default for spheres), on the kinds of flow that decide the defaults (docs/edmd-engine.md,
"Why these t_c").

Run: .venv/bin/python benchmarks/bench_tc_choice.py [--repeat 2] [--only NAME ...]
     .venv/bin/python benchmarks/bench_tc_choice.py --pressure [CASE ...] [--soft]

Dimensionless particle units: d = 1, m = 1; g = 1 where gravity acts, otherwise the shear rate
sets the time unit τ. Cases (short versions of shipped scenes, the same scene at every t_c):
- ``le3d-0.55``: inputs/accuracy-cost/lees-edwards-3d-phi0.55.toml (dense sheared spheres,
  N = 1050), 10 + 20 strain units;
- ``le3d-0.3``: the same at φ = 0.3;
- ``le2d-0.5``: inputs/shear/lees-edwards-2d.toml (ν = 0.5 discs, N = 1996), 10 + 20;
- ``chute2d-30``: inputs/campbell1982/chute-bumpy-30.toml (Campbell's 40 discs on a bumpy
  30° base, a dense flowing 2D bed), 100 + 300 √(d/g);
- ``bed3d``: 100 rough spheres (e = 0.7, β = 0.5) dropped onto a flat floor, 15 √(d/g): a
  bed coming to rest.
After one warm-up run, the runs of a round go case by case, t_c by t_c, and the rounds repeat
(``--repeat``), so a drift of the machine's speed hits every t_c alike; the ratios to the
default's median wall time are what to quote. Prints one Markdown row per case and t_c: median
wall time (range), the ratio to t_c = 1e-5, the share of elastic pair collisions, pair
collisions per particle and time unit. No assertions.

``--pressure [CASE ...]``: what the share does not show. The φ = 0.55 shear (``le3d-0.55-e0.9``,
``-e0.7``) over 10 + 40 strain units, and rough discs (β = 0.5) sheared at ν = 0.7, e = 0.9
(``le2d-0.7-e0.9``) and ν = 0.75, e = 0.5 (``le2d-0.75-e0.5``) in a 30 × 30 box, at t_c = 1e-4 …
1e-7 (all four without a name): the mean pressure (the ``pressure`` timeseries: peculiar kinetic +
collisional), temperature and rotational energy over the production, with errors from 8 blocks, and
the share; ``--soft`` adds LAMMPS's soft spheres on the same scene (Hooke, k* = 10⁶, 10 steps per
contact: the stiffest rung of docs/accuracy-cost.md's ladder).
"""

from __future__ import annotations

import argparse
import platform
import statistics
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np

import demstudy as ds
from demstudy.analysis.blocking import split_mean
from demstudy.scene import Scene, parse_scene_text, validate_scene

ROOT = Path(__file__).resolve().parents[1]
TCS = (1e-4, 1e-5, 1e-6)

BED3D = """
dimension = 3
[meta]
name = "bench-bed3d"
description = "100 rough spheres dropped onto a flat floor: a bed coming to rest (d = m = g = 1)"
[box]
size = [6.0, 12.0, 6.0]
[particles]
count = 100
inertia = "sphere"
[contact]
restitution = 0.7
tangential = { model = "beta", beta = 0.5 }
[[walls]]
side = "lower"
restitution = 0.7
tangential = { model = "beta", beta = 0.5 }
[[walls]]
side = "upper"
restitution = 0.7
[gravity]
direction = [0.0, -1.0, 0.0]
[initial]
placement = "random"
[initial.velocity]
temperature = 1.0
[run]
equilibration = 0.0
production = 15.0
sample_interval = 1.0
seed = 3
"""


def shortened(path: str, equilibration: float, production: float, **sections) -> Scene:
    """The scene file (under the repository) with its run lengths and ``sections`` replaced."""
    run = {"equilibration": equilibration, "production": production}
    return ds.load_scene(ROOT / path, **{**sections, "run": {**sections.get("run", {}), **run}})


CASES = {
    "le3d-0.55": lambda: shortened("inputs/accuracy-cost/lees-edwards-3d-phi0.55.toml",
                                   10.0, 20.0),
    "le3d-0.3": lambda: shortened("inputs/accuracy-cost/lees-edwards-3d-phi0.3.toml",
                                  10.0, 20.0),
    "le2d-0.5": lambda: shortened("inputs/shear/lees-edwards-2d.toml", 10.0, 20.0),
    "chute2d-30": lambda: shortened("inputs/campbell1982/chute-bumpy-30.toml", 100.0, 300.0),
    "bed3d": lambda: validate_scene(parse_scene_text(BED3D)),
}


def one_run(scene: Scene, tc: float, folder: Path) -> dict:
    particles = scene.n_particles
    out = folder / f"{scene.meta.name}-tc{tc:g}.h5"
    start = time.perf_counter()
    ds.run(scene, "edmd", out, isolate=False, progress=False, tc=tc)
    wall = time.perf_counter() - start
    with h5py.File(out, "r") as h5:
        attrs = h5.attrs
        span = scene.run.equilibration + scene.run.production
        rate = 2 * int(attrs["pair_collisions"]) / particles / span
        share = float(attrs["tc_elastic_fraction"])
    out.unlink()
    return {"wall": wall, "share": share, "rate": rate}


def dense_discs(nu: float, e: float) -> Scene:
    """The 2D shear scene (β = 0.5) in a 30 × 30 box at ν and e, 10 + 40 strain units."""
    return shortened("inputs/shear/lees-edwards-2d.toml", 10.0, 40.0, box={"size": [30.0, 30.0]},
                     particles={"solid_fraction": nu}, contact={"restitution": e})


def dense_spheres(e: float, **sections) -> Scene:
    """The φ = 0.55 shear (β = 0.5, N = 1050) at e, 10 + 40 strain units."""
    return shortened("inputs/accuracy-cost/lees-edwards-3d-phi0.55.toml", 10.0, 40.0,
                     contact={"restitution": e}, **sections)


PRESSURE_CASES = {  # name: (label, scene)
    "le3d-0.55-e0.9": ("spheres φ = 0.55, e = 0.9", lambda: dense_spheres(0.9)),
    "le3d-0.55-e0.7": ("spheres φ = 0.55, e = 0.7", lambda: dense_spheres(0.7)),
    "le2d-0.7-e0.9": ("discs ν = 0.7, e = 0.9", lambda: dense_discs(0.7, 0.9)),
    "le2d-0.75-e0.5": ("discs ν = 0.75, e = 0.5", lambda: dense_discs(0.75, 0.5)),
}


def pressure_ladder(names: list[str], soft: bool) -> None:
    runs = []
    for key in names:
        name, scene_of = PRESSURE_CASES[key]
        scene = scene_of()
        runs += [(name, "edmd", scene, {"tc": tc}, f"{tc:g}") for tc in (1e-4, 1e-5, 1e-6, 1e-7)]
    if soft:
        stiff = dense_spheres(0.9, soft={"hardness": {"k_star": 1e6}, "steps_per_contact": 10})
        runs.append(("spheres φ = 0.55, e = 0.9", "lammps", stiff, {}, "soft, k* = 1e6"))
    print("\n| case | t_c | P | T | E_rot | elastic share |\n|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for name, engine, scene, options, label in runs:
            out = Path(tmp) / "p.h5"
            ds.run(scene, engine, out, isolate=False, progress=False, **options)
            with h5py.File(out, "r") as h5:
                ts = h5["timeseries"]
                keep = ts["time"][:] > scene.run.equilibration
                cells = [split_mean(ts[k][:][keep], blocks=8) for k in
                         ("pressure", "temperature", "rotational_energy")]
                share = float(h5.attrs.get("tc_elastic_fraction", np.nan))
            out.unlink()
            print(f"| {name} | {label} | " + " | ".join(f"{m:.4g} ± {e:.2g}" for m, e in cells)
                  + f" | {100 * share:.3g} % |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--only", nargs="*", choices=sorted(CASES), default=sorted(CASES))
    parser.add_argument("--pressure", nargs="*", choices=sorted(PRESSURE_CASES), default=None,
                        help="dense shear flows' pressure at t_c = 1e-4 … 1e-7 instead (the "
                             "cases named, all without a name)")
    parser.add_argument("--soft", action="store_true",
                        help="with --pressure: also LAMMPS at k* = 1e6")
    args = parser.parse_args()
    if args.pressure is not None:
        pressure_ladder(args.pressure or list(PRESSURE_CASES), args.soft)
        return
    scenes = {name: CASES[name]() for name in args.only}
    found: dict[tuple[str, float], list[dict]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        one_run(CASES["bed3d"](), 1e-4, Path(tmp))  # warm-up: imports and the first run's set-up
        for _ in range(args.repeat):
            for name, scene in scenes.items():
                for tc in TCS:
                    found.setdefault((name, tc), []).append(one_run(scene, tc, Path(tmp)))
    print(f"\n{platform.processor() or platform.machine()}, Python {platform.python_version()}, "
          f"{args.repeat} interleaved rounds\n")
    print("| case | t_c | wall time (s), median (range) | × t_c = 1e-5 | elastic share | "
          "pair collisions per particle per τ |")
    print("|---|---|---|---|---|---|")
    for name in scenes:
        base = statistics.median(r["wall"] for r in found[(name, 1e-5)])
        for tc in TCS:
            runs = found[(name, tc)]
            walls = [r["wall"] for r in runs]
            median = statistics.median(walls)
            share = 100 * statistics.median(r["share"] for r in runs)
            print(f"| {name} | {tc:g} | {median:.3g} ({min(walls):.3g}-{max(walls):.3g}) | "
                  f"×{median / base:.2f} | {share:.3g} % | "
                  f"{statistics.median(r['rate'] for r in runs):.4g} |")


if __name__ == "__main__":
    main()
