"""Cost of dense random starts (Lubachevsky–Stillinger growth, demstudy.scene.fluid_start).

For each case: the whole ``build_initial_state`` (RSA of the shrunk particles, growth,
relaxation, velocities), best and median of ``--repeats`` runs (this VM's speed drifts:
compare ranges, not single numbers), the growth's events per particle and, for periodic
boxes, the old start (a random subset of a lattice) for comparison.

    python benchmarks/bench_fluid_start.py [--repeats 3]

Dimensionless particle units: d = 1, m = 1, T = 1.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from pathlib import Path

import numpy as np

from demstudy.scene import load_scene, parse_scene_text, validate_scene
from demstudy.scene.fluid_start import grow_fluid
from demstudy.scene.initial import _lattice_subset, build_initial_state

ROOT = Path(__file__).resolve().parents[1]


def periodic_scene(dim: int, phi: float, n: int):
    unit = math.pi / 6 if dim == 3 else math.pi / 4
    length = round((n * unit / phi) ** (1 / dim), 9)
    return validate_scene(parse_scene_text(f"""
dimension = {dim}
[box]
size = {[length] * dim}
[particles]
count = {n}
[contact]
restitution = 1.0
[initial.velocity]
temperature = 1.0
[run]
equilibration = 0.0
production = 1.0
sample_interval = 1.0
"""))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    cases = {
        "spheres φ = 0.5, N = 4000, periodic": periodic_scene(3, 0.5, 4000),
        "spheres φ = 0.3, N = 4000, periodic": periodic_scene(3, 0.3, 4000),
        "discs ν = 0.65, N = 4000, periodic": periodic_scene(2, 0.65, 4000),
        "malik2008/poiseuille-phi0.5 (walls)": load_scene(
            ROOT / "inputs/malik2008/poiseuille-phi0.5.toml"),
    }
    print("| case | N | build_initial_state best / median (s) | old lattice-subset start (s) | "
          "events per particle |")
    print("|---|---|---|---|---|")
    for name, scene in cases.items():
        whole = []
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            state = build_initial_state(scene)
            whole.append(time.perf_counter() - t0)
        dim, n = scene.dimension, scene.n_particles
        box = np.array(scene.box.size, float)
        g = grow_fluid(state.diameter, np.zeros(dim), box, np.ones(dim, bool), None,
                       np.random.default_rng(1)) if scene.y_periodic else None
        lattice = []
        for _ in range(args.repeats if scene.y_periodic else 0):
            t0 = time.perf_counter()
            _lattice_subset(n, np.zeros(dim), box, np.ones(dim, bool), 1.0,
                            np.random.default_rng(1))
            lattice.append(time.perf_counter() - t0)
        grow_text = f"{min(lattice):.2f}" if lattice else "–"
        events_text = f"{g.events / n:.0f}" if g is not None else "–"
        print(f"| {name} | {n} | {min(whole):.2f} / {statistics.median(whole):.2f} | "
              f"{grow_text} | {events_text} |")


if __name__ == "__main__":
    main()
