"""Wall-time forecast against the actual wall time, on short runs of seed scenes (issue 12:
goal ±30 %), including analysis-heavy runs (g(r) and Campbell's structure sampled often),
dilute ones (cell crossings) and flows that gravity accelerates (Malik's channels: their
forecast is a lower bound). Runs without farm-bench.

Measures this machine's costs first (in ``--cache``, never the user's cache, unless
``--keep-rates``), then runs each case ``--repeats`` times, interleaved (case 1, 2, …, 1,
2, …), each in its own folder (no finished run of the family next to it: the forecast from
the pilot or Enskog), and prints a markdown table: forecast, its kind (estimate or lower
bound), actual (the results file's ``wall_seconds``, the loop the forecast covers) and the
error of each repeat. ``--before PYTHON``: also the forecast of another checkout's
demstudy (its ``plan_run`` as a real run makes it, its own costs measured first in a
cache of its own), for a before/after table. Dimensionless particle units (d = 1, m = 1;
τ = 1/γ̇, d/U or √(d/g) per scene).

    python benchmarks/bench_forecast.py [--repeats 2] [--keep-rates] [--before PYTHON]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import tempfile
from pathlib import Path

import demstudy as ds
from demstudy.scene import scene_to_toml
from demstudy.simulation.forecast import cpu_model, measure_costs

MALIK = {"profiles", "freepath", "vdf", "lambda", "vcorr"}
#: (label, scene, engine, overrides, run options): short seed runs of both engines, 2D and 3D
CASES = [
    ("shear/lees-edwards-2d (4 τ)", "shear/lees-edwards-2d", "lammps",
     {"run": {"equilibration": 0.0, "production": 4.0}}, {}),
    ("shear/lees-edwards-2d (150 τ)", "shear/lees-edwards-2d", "edmd",
     {"run": {"production": 50.0}}, {}),
    ("couette-rough-nu0.55 (300 τ)", "accuracy-cost/couette-rough-nu0.55", "lammps",
     {"run": {"equilibration": 0.0, "production": 300.0}}, {}),
    ("couette-rough-nu0.55", "accuracy-cost/couette-rough-nu0.55", "edmd", {}, {}),
    ("lees-edwards-3d φ = 0.3 (4 τ)", "accuracy-cost/lees-edwards-3d-phi0.3", "lammps",
     {"run": {"equilibration": 0.0, "production": 4.0}}, {}),
    ("lees-edwards-3d φ = 0.3 (80 τ)", "accuracy-cost/lees-edwards-3d-phi0.3", "edmd", {}, {}),
    ("campbell1982/chute-20 (20 τ)", "campbell1982/chute-20", "lammps",
     {"run": {"equilibration": 0.0, "production": 20.0}}, {}),
    # analysis-heavy: g(r) and the structure distributions every 0.05 τ (2D, N = 1996)
    ("lees-edwards-2d + g(r), structure (10 τ, 200 samples)", "shear/lees-edwards-2d", "edmd",
     {"run": {"equilibration": 0.0, "production": 10.0, "sample_interval": 0.05},
      "measure": {"statistics": ["profiles", "gr", "structure"]}}, {}),
    ("lees-edwards-2d + g(r), structure (1 τ, 100 samples)", "shear/lees-edwards-2d",
     "lammps", {"run": {"equilibration": 0.0, "production": 1.0, "sample_interval": 0.01},
                "measure": {"statistics": ["profiles", "gr", "structure"]}}, {}),
    # dilute: cell crossings outnumber collisions (3D shear at φ = 0.02, N = 2444)
    ("lees-edwards-3d φ = 0.02, 40³ (50 τ)", "accuracy-cost/lees-edwards-3d-phi0.3", "edmd",
     {"box": {"size": [40.0, 40.0, 40.0]}, "particles": {"solid_fraction": 0.02},
      "run": {"equilibration": 10.0, "production": 40.0}}, {}),
    # flows gravity accelerates, with Malik's statistics, kept frames and checkpoints
    ("malik2008 poiseuille φ = 0.01, e 0.8, β 0.99 (250 τ)", "malik2008/poiseuille-phi0.01",
     "edmd", {"contact": {"restitution": 0.8, "tangential": {"model": "beta", "beta": 0.99}},
              "run": {"equilibration": 150.0, "production": 100.0, "sample_interval": 4.0},
              "measure": {"bin_width": 2.0, "statistics": sorted(MALIK),
                          "keep_frames": True}},
     {"checkpoint_interval": 25.0}),
    ("malik2008 waves L9W15H15 (200 τ)", "malik2008/waves-phi0.15-L9W15H15", "edmd",
     {"run": {"equilibration": 100.0, "production": 100.0}}, {"checkpoint_interval": 20.0}),
    ("accuracy-cost/poiseuille-phi0.1-small (100 τ)", "accuracy-cost/poiseuille-phi0.1-small",
     "edmd", {"run": {"equilibration": 50.0, "production": 50.0}}, {}),
]

#: the other checkout's forecast as a real run makes it (plan_run, not a dry run)
BEFORE = """
import json, sys
from pathlib import Path
import demstudy as ds
from demstudy.engines import get_backend
from demstudy.scene import parse_scene_text, validate_scene
from demstudy.simulation import RunOptions, plan_run
toml, engine, out, ckpt = sys.argv[1:5]
scene = validate_scene(parse_scene_text(Path(toml).read_text()))
options = RunOptions(out=Path(out), checkpoint_interval=float(ckpt) or None)
plan = plan_run(scene, get_backend(engine), options)
print(json.dumps(plan.forecast.seconds if plan.forecast else None))
"""
MEASURE_BEFORE = """
from demstudy.simulation.forecast import measure_costs
for key in (("lammps", 2, "hooke"), ("lammps", 3, "hooke"), ("edmd", 2, None), ("edmd", 3, None)):
    measure_costs(*key, remeasure=True)
"""


def before_forecasts(python: str, cache: Path, tmp: Path) -> list[float | None]:
    env = dict(os.environ, XDG_CACHE_HOME=str(cache))
    subprocess.run([python, "-c", MEASURE_BEFORE], env=env, check=True,
                   capture_output=True)
    out = []
    for i, (_label, scene, engine, overrides, opts) in enumerate(CASES):
        toml = tmp / f"before-{i}.toml"
        toml.write_text(scene_to_toml(ds.load_scene(scene, **overrides)))
        res = subprocess.run([python, "-c", BEFORE, str(toml), engine,
                              str(tmp / f"before-{i}" / "r.h5"),
                              str(opts.get("checkpoint_interval", 0.0))],
                             env=env, check=True, capture_output=True, text=True)
        out.append(json.loads(res.stdout.strip().splitlines()[-1]))
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--keep-rates", action="store_true",
                        help="use the cached costs instead of measuring them first")
    parser.add_argument("--cache", default=None,
                        help="the cache folder for costs and pilots (default: a new one)")
    parser.add_argument("--before", default=None, metavar="PYTHON",
                        help="another checkout's Python: its forecasts too")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        os.environ["XDG_CACHE_HOME"] = args.cache or str(tmp / "cache")
        before = before_forecasts(args.before, tmp / "before-cache", tmp) \
            if args.before else None
        if not args.keep_rates:
            for engine, dim, model in (("lammps", 2, "hooke"), ("lammps", 3, "hooke"),
                                       ("edmd", 2, None), ("edmd", 3, None)):
                measure_costs(engine, dim, model, remeasure=True)
        rows: dict[int, list] = {i: [] for i in range(len(CASES))}
        load = os.getloadavg()
        for repeat in range(args.repeats):
            for i, (_label, scene, engine, overrides, opts) in enumerate(CASES):
                sc = ds.load_scene(scene, **overrides)
                res = ds.run(sc, engine=engine, out=tmp / f"{i}-{repeat}" / "r.h5",
                             progress=False, **opts)
                rows[i].append((res.attrs.get("forecast_seconds"),
                                res.attrs.get("forecast_kind", "estimate"),
                                res.attrs["wall_seconds"]))
        load = (load, os.getloadavg())
    print(f"machine: {cpu_model()}; {args.repeats} interleaved repeats per case; load "
          f"average {load[0][0]:.1f} at the start, {load[1][0]:.1f} at the end\n")
    head = "| scene | engine | " + ("before (s) | " if before else "") + \
        "forecast (s) | kind | actual (s) | actual / forecast |"
    print(head)
    print("|" + "---|" * (head.count("|") - 1))
    within = total = bounds = bounds_held = 0
    worst = 1.0
    for i, (label, _scene, engine, _o, _opts) in enumerate(CASES):
        forecast, kind = rows[i][0][0], rows[i][0][1]
        actual = [a for _f, _k, a in rows[i]]
        ratios = [a / forecast for a in actual] if forecast else []
        if kind == "lower bound":
            bounds += len(ratios)
            bounds_held += sum(r >= 1 for r in ratios)
        else:
            within += sum(abs(1 / r - 1) <= 0.3 for r in ratios)
            worst = max([worst, *(max(r, 1 / r) for r in ratios)])
            total += len(ratios)
        old = ""
        if before:
            b = before[i]
            old = (f"{b:.3g} (×{actual[0] / b:.2g}) | " if b else "none | ")
        print(f"| {label} | {engine} | {old}{forecast:.3g} | {kind} | "
              + " / ".join(f"{a:.3g}" for a in actual) + " | "
              + " / ".join(f"×{r:.2f}" for r in ratios) + " |")
    print(f"\nestimates within ±30 %: {within} of {total}; all within ×{worst:.2f}; lower "
          f"bounds that held: {bounds_held} of {bounds}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
