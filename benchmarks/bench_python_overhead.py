"""Python-driven LAMMPS run vs bare ``lmp -in deck.in`` on the same ~30k-sphere chute deck.

The Python run samples (gathers every particle from LAMMPS memory and accumulates exact
volume-weighted profiles) every ``--sample-every`` steps; the bare run only prints thermo.
Overhead = t_python / t_bare − 1 (goal ≤ 5 %). Prints a Markdown row for docs/benchmarks.md.

    python benchmarks/bench_python_overhead.py [--steps 2000] [--sample-every 100]

Dimensionless particle units: d = 1, m = 1, g = 1.
"""

from __future__ import annotations

import argparse
import platform
import resource
import subprocess
import tempfile
import time
from pathlib import Path

from demstudy.contact.stiffness import contact_setup
from demstudy.engines.lammps.deck import write_deck
from demstudy.engines.lammps.library import lmp_executable
from demstudy.scene import validate_scene
from demstudy.simulation import RunOptions, run_scene


def chute_scene(steps: int, sample_every: int, dt: float | None = None) -> dict:
    """3D chute, 32 × 30 × 32 = 30 720 rough spheres on a rough base at 25°."""
    scene = {
        "meta": {"name": "bench-chute-30k"},
        "dimension": 3,
        "box": {"size": [35.2, 40.0, 35.2]},
        "particles": {"inertia": "sphere"},
        "contact": {"restitution": 0.8, "tangential": {"model": "beta", "beta": 0.0}},
        "walls": [{"side": "lower", "restitution": 0.8, "tangential": {"model": "rough"}}],
        "gravity": {"angle": 25.0},
        "initial": {"placement": "lattice", "rows": 30, "columns": 32, "layers": 32,
                    "spacing": 1.1, "velocity": {"profile": "uniform", "scale": 1.0,
                                                 "perturbation": 0.1}},
        "run": {"equilibration": 0.0, "production": 1.0, "sample_interval": 1.0},
        "soft": {"stiffness": 1e5, "steps_per_contact": 50},
    }
    dt = dt or contact_setup(validate_scene(scene)).timestep
    scene["run"] = {"equilibration": 0.0, "production": steps * dt,
                    "sample_interval": sample_every * dt}
    return scene


def timed_pair(scene, tmp: Path) -> tuple[float, float, float, float]:
    """One bare and one Python-driven run of the same scene: wall and CPU seconds of each
    (CPU time is less sensitive to other load on a shared VM)."""
    deck = write_deck(scene, tmp / "bare")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run([lmp_executable(), "-in", deck.name, "-log", "none", "-screen", "none"],
                   cwd=deck.parent, check=True)
    bare = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    bare_cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    c0, t0 = time.process_time(), time.perf_counter()
    run_scene(scene, "lammps", RunOptions(out=tmp / "py.h5", progress=False))
    return bare, time.perf_counter() - t0, bare_cpu, time.process_time() - c0


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--sample-every", type=int, default=100)
    parser.add_argument("--repeats", type=int, default=5,
                        help="alternating bare/python pairs; the minimum of each is compared "
                             "(this VM's timings vary by tens of per cent between runs)")
    args = parser.parse_args()
    scene = validate_scene(chute_scene(args.steps, args.sample_every))
    runs = []
    for _ in range(args.repeats):
        with tempfile.TemporaryDirectory() as tmp:
            runs.append(timed_pair(scene, Path(tmp)))
    bare, python, bare_cpu, python_cpu = (list(col) for col in zip(*runs, strict=True))
    n = scene.n_particles
    print(f"machine: {platform.processor() or platform.machine()}, {platform.node()}")
    for name, values in (("bare wall", bare), ("python wall", python), ("bare cpu", bare_cpu),
                         ("python cpu", python_cpu)):
        print(f"{name:12s}: {' '.join(f'{t:.2f}' for t in values)} s")
    wall = 100 * (min(python) / min(bare) - 1)
    cpu = 100 * (min(python_cpu) / min(bare_cpu) - 1)
    print(f"| {n} spheres | {args.steps} steps | sample every {args.sample_every} | "
          f"bare {min(bare):.2f} s wall, {min(bare_cpu):.2f} s cpu | "
          f"python {min(python):.2f} s wall, {min(python_cpu):.2f} s cpu | "
          f"overhead {wall:+.1f} % wall, {cpu:+.1f} % cpu (minima of {args.repeats}) |")


if __name__ == "__main__":
    main()
