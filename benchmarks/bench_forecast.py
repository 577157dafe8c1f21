"""Wall-time forecast against the actual wall time, on short runs of seed scenes (issue 12:
goal ±30 %). Runs without farm-bench.

Measures this machine's costs first (``demstudy forecast --measure``, unless
``--keep-rates``), then runs each case ``--repeats`` times, interleaved (case 1, 2, …, 1,
2, …), and prints a markdown table: forecast, actual (the results file's ``wall_seconds``,
the loop the forecast covers) and the error of each repeat. Dimensionless particle units
(d = 1, m = 1; τ = 1/γ̇, d/U or √(d/g) per scene).

    python benchmarks/bench_forecast.py [--repeats 2] [--keep-rates]
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import demstudy as ds
from demstudy.simulation.forecast import cpu_model, measure_costs

#: (label, scene, engine, overrides): short seed runs of both engines, 2D and 3D
CASES = [
    ("shear/lees-edwards-2d", "shear/lees-edwards-2d", "lammps",
     {"run": {"equilibration": 0.0, "production": 4.0}}),
    ("shear/lees-edwards-2d", "shear/lees-edwards-2d", "edmd", {"run": {"production": 50.0}}),
    ("couette-rough-nu0.55", "accuracy-cost/couette-rough-nu0.55", "lammps",
     {"run": {"equilibration": 0.0, "production": 300.0}}),
    ("couette-rough-nu0.55", "accuracy-cost/couette-rough-nu0.55", "edmd", {}),
    ("lees-edwards-3d φ = 0.3", "accuracy-cost/lees-edwards-3d-phi0.3", "lammps",
     {"run": {"equilibration": 0.0, "production": 4.0}}),
    ("lees-edwards-3d φ = 0.3", "accuracy-cost/lees-edwards-3d-phi0.3", "edmd", {}),
    ("campbell1982/chute-20", "campbell1982/chute-20", "lammps",
     {"run": {"equilibration": 0.0, "production": 20.0}}),
]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--keep-rates", action="store_true",
                        help="use the cached costs instead of measuring them first")
    args = parser.parse_args(argv)
    if not args.keep_rates:
        for engine, dim, model in (("lammps", 2, "hooke"), ("lammps", 3, "hooke"),
                                   ("edmd", 2, None), ("edmd", 3, None)):
            measure_costs(engine, dim, model, remeasure=True)
    rows: dict[int, list] = {i: [] for i in range(len(CASES))}
    with tempfile.TemporaryDirectory() as tmp:
        for repeat in range(args.repeats):
            for i, (_label, scene, engine, overrides) in enumerate(CASES):
                sc = ds.load_scene(scene, **overrides)
                res = ds.run(sc, engine=engine, out=Path(tmp) / f"{i}-{repeat}.h5",
                             progress=False)
                rows[i].append((res.attrs.get("forecast_seconds"), res.attrs["wall_seconds"]))
    print(f"machine: {cpu_model()}; {args.repeats} interleaved repeats per case\n")
    print("| scene | engine | forecast (s) | actual (s) | error |")
    print("|---|---|---|---|---|")
    within = total = 0
    for i, (label, _scene, engine, _o) in enumerate(CASES):
        forecast = rows[i][0][0]
        actual = [a for _f, a in rows[i]]
        errors = [forecast / a - 1 for a in actual] if forecast else []
        within += sum(abs(e) <= 0.3 for e in errors)
        total += len(errors)
        print(f"| {label} | {engine} | {forecast:.3g} | "
              + " / ".join(f"{a:.3g}" for a in actual) + " | "
              + " / ".join(f"{100 * e:+.0f} %" for e in errors) + " |")
    print(f"\nwithin ±30 %: {within} of {total}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
