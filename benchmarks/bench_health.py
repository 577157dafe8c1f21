"""Cost of the soft-contact health (``health`` group) in a LAMMPS run: with against without.

The seed scene ``shear/lees-edwards-2d`` (1996 rough discs, ν = 0.5, k* = 1e5) runs for a
short production in this process, alternately with the health measured at every sample (A)
and with the backend's ``health_sample`` switched off (B), in interleaved pairs: this VM's
speed drifts, so only pairwise ratios mean something. The time compared is the loop's
``wall_seconds`` (advancing, sampling, profiles; LAMMPS start-up excluded).

    python benchmarks/bench_health.py [--production 5] [--interval 0.5] [--repeats 4]

Dimensionless particle units: d = 1, m = 1 (time in strain units 1/γ̇).
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

from demstudy.engines.lammps.backend import LammpsBackend
from demstudy.io.results import read_results
from demstudy.scene import load_scene
from demstudy.simulation import RunOptions, run_scene

ROOT = Path(__file__).resolve().parents[1]


SPENT = [0.0]  # seconds inside health_sample, this run


def once(scene, folder: Path, health: bool, index: int) -> float:
    original = LammpsBackend.health_sample
    SPENT[0] = 0.0

    def timed(self):
        start = time.perf_counter()
        try:
            return original(self)
        finally:
            SPENT[0] += time.perf_counter() - start

    # the loop skips a backend without it
    LammpsBackend.health_sample = timed if health else None
    try:
        path = run_scene(scene, "lammps", RunOptions(out=folder / f"r{index}.h5",
                                                     progress=False))
    finally:
        LammpsBackend.health_sample = original
    res = read_results(path)
    assert ("health" in res.groups) == health
    return float(res.attrs["wall_seconds"])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--production", type=float, default=5.0)
    parser.add_argument("--interval", type=float, default=0.5)
    parser.add_argument("--repeats", type=int, default=4)
    args = parser.parse_args()
    scene = load_scene(ROOT / "inputs" / "shear" / "lees-edwards-2d.toml",
                       ["run.equilibration=0", f"run.production={args.production}",
                        f"run.sample_interval={args.interval}"])
    ratios: list[float] = []
    fractions: list[float] = []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(args.repeats):
            a = once(scene, Path(tmp), True, 2 * i)
            spent, fractions = SPENT[0], fractions + [SPENT[0] / a]
            b = once(scene, Path(tmp), False, 2 * i + 1)
            ratios.append(a / b)
            print(f"pair {i + 1}: with {a:.3f} s ({spent:.3f} s in health_sample), "
                  f"without {b:.3f} s, ratio {a / b:.4f}")
    print(f"{scene.n_particles} particles, {args.production / args.interval:.0f} samples: "
          f"median ratio {statistics.median(ratios):.4f} "
          f"(range {min(ratios):.4f}-{max(ratios):.4f}); time inside health_sample: "
          f"{100 * statistics.median(fractions):.2f} % of the loop (median)")


if __name__ == "__main__":
    main()
