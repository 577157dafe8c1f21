"""LIGGGHTS against LAMMPS on the same scene: steps per second, interleaved.

Run: .venv/bin/python benchmarks/bench_liggghts.py [--repeats 3] [--production 20]
     [--scene accuracy-cost/poiseuille-phi0.1-small ...]

Each scene runs in both soft-contact engines with the same k_n and time step (both chosen by
demstudy/contact/stiffness.py from the scene), one rank, alternating LAMMPS and LIGGGHTS
``--repeats`` times so that the machine's drift hits both alike. Reported per scene: the
median steps per second of each engine over the whole run (the results file's
``wall_seconds``, start-up included: the LIGGGHTS child is always a fresh interpreter) and the
ratio LIGGGHTS/LAMMPS of the paired runs (median and range). Dimensionless particle units:
d = 1, m = 1, g = 1 when gravity acts. Prints Markdown rows; no assertions.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
from pathlib import Path

import demstudy as ds
from demstudy.io.results import read_results

SCENES = ("accuracy-cost/poiseuille-phi0.1-small", "cooling/hcs-3d",
          "accuracy-cost/couette-rough-nu0.55")
ENGINES = ("lammps", "liggghts")


def steps_per_second(scene: str, engine: str, production: float, folder: Path) -> tuple[
        float, int]:
    """One run: (steps per second, particles)."""
    loaded = ds.load_scene(scene, ["run.equilibration=0", f"run.production={production}"])
    out = folder / f"{engine}.h5"
    ds.run(loaded, engine=engine, out=out, progress=False)
    attrs = read_results(out, skip=("frames", "collisions")).attrs
    steps = production / float(attrs["timestep"])
    return steps / float(attrs["wall_seconds"]), loaded.n_particles


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scene", action="append", help=f"default: {', '.join(SCENES)}")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--production", type=float, default=20.0,
                        help="time units of each run (no equilibration)")
    args = parser.parse_args()
    rows = []
    for scene in args.scene or SCENES:
        rates: dict[str, list[float]] = {e: [] for e in ENGINES}
        with tempfile.TemporaryDirectory() as tmp:
            for i in range(args.repeats):
                order = ENGINES if i % 2 == 0 else ENGINES[::-1]  # alternate who goes first
                for engine in order:
                    rate, n = steps_per_second(scene, engine, args.production,
                                               Path(tmp) / f"{i}")
                    rates[engine].append(rate)
                    print(f"{scene} {engine} run {i}: {rate:.0f} steps/s", flush=True)
        ratios = [g / m for g, m in zip(rates["liggghts"], rates["lammps"], strict=True)]
        rows.append(f"| `{scene}` | {n} | {statistics.median(rates['liggghts']):.0f} | "
                    f"{statistics.median(rates['lammps']):.0f} | "
                    f"{statistics.median(ratios):.2f} ({min(ratios):.2f}–{max(ratios):.2f}) |")
    print("\n| scene | particles | LIGGGHTS steps/s | LAMMPS steps/s | "
          "LIGGGHTS/LAMMPS (median, range) |")
    print("|---|---|---|---|---|")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
