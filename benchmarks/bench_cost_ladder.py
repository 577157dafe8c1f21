"""A whole ``demstudy cost`` ladder: orchestration overhead and parallel efficiency.

Run: .venv/bin/python benchmarks/bench_cost_ladder.py [--box 40] [--production 40]
     [--kstar 1e3,1e4] [--steps 10,50] [--workers 2]

The ladder (2D Lees–Edwards preset in a smaller box, dimensionless particle units d = 1,
m = 1, γ̇ = 1: the reference plus soft Hooke runs over k* and steps per contact) runs twice
into fresh folders: on 1 worker and on ``--workers`` workers. Reported:

* overhead = (ladder wall time on 1 worker) / (sum of its runs' bare engine times, the
  ``wall_seconds`` attribute of each results file) − 1 (goal ≤ 5 %): process start, scene
  handling, results files, comparisons, table and figure;
* parallel efficiency = T(1 worker) / (workers × T(workers)) (goal ≥ 85 %).

Prints Markdown rows; no assertions. Measure on a quiet machine.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from demstudy.accuracy.study import cost


def ladder(out: Path, args: argparse.Namespace, workers: int) -> tuple[float, float, int]:
    """(ladder wall time, sum of the runs' engine times, number of runs); prints where the
    time went."""
    t0 = time.perf_counter()
    study = cost("shear/lees-edwards-2d", out=out, workers=workers, progress=lambda _: None,
                 overrides=[f"box.size=[{args.box}, {args.box}]", "run.equilibration=2.0",
                            f"run.production={args.production}", "run.sample_interval=0.5"],
                 kstars=[float(k) for k in args.kstar.split(",")],
                 steps=[float(s) for s in args.steps.split(",")], models=["hooke"])
    total = time.perf_counter() - t0
    t = study.timings
    print(f"{workers} worker(s): total {total:.2f} s = forecast {t.get('forecast', 0):.2f} s "
          f"(the pilot and the machine's speed: cached after the first ladder) + running "
          f"{t.get('ladder', 0):.2f} s (tasks as the workers saw them: "
          f"{t.get('runs', 0):.2f} s) + analysis and outputs {t.get('analysis', 0):.2f} s + "
          "setup")
    return total, sum(r["wall_seconds"] for r in study.rows), len(study.rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--box", type=float, default=40.0, help="box side (d)")
    parser.add_argument("--production", type=float, default=40.0, help="strain units")
    parser.add_argument("--kstar", default="1e3,1e4")
    parser.add_argument("--steps", default="10,50")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        t1, engine1, n = ladder(Path(tmp) / "one", args, 1)
        tw, engine_w, _ = ladder(Path(tmp) / "many", args, args.workers)
    print("| runs | ladder, 1 worker (s) | sum of engine times (s) | overhead | "
          f"ladder, {args.workers} workers (s) | parallel efficiency |")
    print("|---|---|---|---|---|---|")
    print(f"| {n} | {t1:.2f} | {engine1:.2f} | {100 * (t1 / engine1 - 1):.1f} % | {tw:.2f} | "
          f"{100 * t1 / (args.workers * tw):.0f} % |")
    print(f"(engine times on {args.workers} workers sum to {engine_w:.2f} s: contention "
          "between the workers shows as a larger sum)")


if __name__ == "__main__":
    main()
