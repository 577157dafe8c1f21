"""Forecast against actual wall time of lattice (LGD) runs: every thesis scene in
inputs/gutt1989/ that the lattice engine runs (the full Poiseuille case with --full), each
forecast from this machine's measured costs and then run, in one session.

Dimensionless particle units (d = 1, m = 1, g = 1 when gravity acts); times are wall-clock
seconds on this machine. Prints one row per scene and the largest ratio either way, the
number to put in ``demstudy.engines.lgd.forecast.ACCURACY`` and docs/benchmarks.md.

    python benchmarks/bench_lgd_forecast.py [--full] [--remeasure]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from demstudy.engines import get_backend
from demstudy.engines.lgd.forecast import counts
from demstudy.io.results import read_results
from demstudy.scene import load_scene
from demstudy.simulation import RunOptions, run_scene
from demstudy.simulation.forecast import cpu_model, forecast_run, measure_costs

SCENES = ("gas-box", "explosion", "couette-elastic-u4096", "couette-elastic-u16384",
          "couette-inelastic-u4096", "hourglass", "obstacle-circle", "obstacle-square",
          "obstacle-triangle-up", "obstacle-triangle-down", "incline", "poiseuille-small")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--full", action="store_true", help="also the 508 032-grain case")
    parser.add_argument("--remeasure", action="store_true", help="measure the costs again")
    args = parser.parse_args()
    backend = get_backend("lgd")
    measure_costs("lgd", 2, remeasure=args.remeasure)
    print(f"machine: {cpu_model()}; {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")
    ratios = []
    for name in SCENES + (("poiseuille-thesis",) if args.full else ()):
        scene = load_scene(f"gutt1989/{name}")
        if counts(scene) is None:
            print(f"{name}: counted in time, no forecast")
            continue
        forecast = forecast_run(scene, backend)
        with tempfile.TemporaryDirectory(prefix="demstudy-bench-") as tmp:
            options = RunOptions(out=Path(tmp) / "run.h5", progress=False, plan=False)
            actual = float(read_results(run_scene(scene, backend, options)).attrs["wall_seconds"])
        ratios.append(actual / forecast.seconds)
        print(f"{name:26s} forecast {forecast.seconds:8.3g} s  actual {actual:8.3g} s  "
              f"actual/forecast {ratios[-1]:.2f}")
    worst = max(max(ratios), 1 / min(ratios))
    print(f"{len(ratios)} runs: actual/forecast {min(ratios):.2f} … {max(ratios):.2f}; "
          f"within ×{worst:.2f}")


if __name__ == "__main__":
    main()
