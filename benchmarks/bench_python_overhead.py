"""`demstudy run` (LAMMPS engine) vs bare ``lmp -in deck.in`` on the same ~30k-sphere chute.

Both are whole processes, timed from outside: ``demstudy run`` validates the scene, starts its
child, builds the initial state (created in LAMMPS from memory), drives LAMMPS segment by
segment, gathers every particle at each sample, accumulates exact volume-weighted profiles and
writes the results file; the bare run reads the data file ``demstudy deck`` wrote and only
prints thermo.
Each case runs in interleaved pairs (python, bare, python, bare, …): this VM's speed drifts by
tens of per cent, so only pairwise ratios are meaningful. Per pair: wall and CPU seconds
(user + sys of the process and the children it waited for) and peak memory (the largest
single process, ``ru_maxrss``), from ``os.wait4``. This process imports nothing heavy (a
child inherits its parent's peak until it execs): the scene and the deck are written by a
``--prepare`` call of this script in a process of its own.

The extra cost of a run, A − B, is a fixed part (start-up, initial state) plus a cost per
sample. The fixed part is measured directly by a short case of one sample (100 steps; the
default's third case): its A − B is the fixed cost plus one sample. (Splitting the two long
cases' A − B into both parts is too noisy here: their times vary by ±0.3 s.)

    python benchmarks/bench_python_overhead.py [--cases 2000:100,5000:500,100:100] [--repeats 5]

Prints Markdown rows for docs/benchmarks.md. Dimensionless particle units: d = 1, m = 1, g = 1.
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def chute_scene(steps: int, sample_every: int, dt: float | None = None) -> dict:
    """3D chute, 32 × 30 × 32 = 30 720 rough spheres on a rough base at 25°."""
    from demstudy.contact.stiffness import contact_setup  # noqa: PLC0415 - see the docstring
    from demstudy.scene import validate_scene  # noqa: PLC0415

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


def timed(cmd: list[str], cwd: Path) -> tuple[float, float, float]:
    """Wall s, CPU s and peak MiB of one whole command (with the children it waited for)."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL)
    _pid, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} exited with {proc.returncode}")
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024


def demstudy_command() -> list[str]:
    script = Path(sys.executable).parent / "demstudy"
    return [str(script)] if script.exists() else [sys.executable, "-c",
                                                  "import sys; from demstudy.cli import main; "
                                                  "sys.exit(main())"]


def prepare(folder: Path, steps: int, every: int) -> None:
    """The scene file and the bare deck (its data file too) of one case, in ``folder``."""
    from demstudy.engines.lammps.deck import write_deck  # noqa: PLC0415 - see the docstring
    from demstudy.scene import scene_to_toml, validate_scene  # noqa: PLC0415

    scene = validate_scene(chute_scene(steps, every))
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "scene.toml").write_text(scene_to_toml(scene))
    write_deck(scene, folder / "bare")
    (folder / "particles").write_text(str(scene.n_particles))


def run_case(steps: int, every: int, repeats: int, tmp: Path) -> dict:
    folder = tmp / f"{steps}-{every}"
    subprocess.run([sys.executable, __file__, "--prepare", str(folder), str(steps), str(every)],
                   check=True)
    lmp = Path(sys.executable).parent / "lmp"
    python = [*demstudy_command(), "run", "scene.toml", "--out", "run.h5", "-q"]
    bare = [str(lmp) if lmp.exists() else "lmp", "-in", "deck.in", "-log", "none", "-screen",
            "none"]
    pairs = []
    for i in range(repeats + 1):  # the first pair warms the caches and is not counted
        a = timed(python, folder)
        b = timed(bare, folder / "bare")
        if i:
            pairs.append((a, b))
    return {"steps": steps, "every": every, "samples": steps // every,
            "n": int((folder / "particles").read_text()), "pairs": pairs}


def median(values) -> float:
    return statistics.median(values)


def report(cases: list[dict]) -> None:
    model = next((line.split(":", 1)[1].strip() for line in
                  Path("/proc/cpuinfo").read_text().splitlines()
                  if line.startswith("model name")), platform.processor() or platform.machine())
    print(f"machine: {model}, {os.cpu_count()} CPUs, Python {platform.python_version()}, "
          f"{datetime.date.today().isoformat()}")
    print("| N steps, samples | bare wall / cpu (s) | python wall / cpu (s) | ratio wall | "
          "ratio cpu | A − B wall / cpu (s) | peak MiB bare / python |")
    print("|---|---|---|---|---|---|---|")
    for case in cases:
        a = [p[0] for p in case["pairs"]]
        b = [p[1] for p in case["pairs"]]
        ratio_wall = [x[0] / y[0] for x, y in zip(a, b, strict=True)]
        ratio_cpu = [x[1] / y[1] for x, y in zip(a, b, strict=True)]
        case["delta"] = [(x[0] - y[0], x[1] - y[1]) for x, y in zip(a, b, strict=True)]
        print(f"| {case['steps']}, {case['samples']} | {median(y[0] for y in b):.2f} / "
              f"{median(y[1] for y in b):.2f} | {median(x[0] for x in a):.2f} / "
              f"{median(x[1] for x in a):.2f} | {median(ratio_wall):.3f} "
              f"({min(ratio_wall):.3f}–{max(ratio_wall):.3f}) | {median(ratio_cpu):.3f} "
              f"({min(ratio_cpu):.3f}–{max(ratio_cpu):.3f}) | "
              f"{median(d[0] for d in case['delta']):+.2f} / "
              f"{median(d[1] for d in case['delta']):+.2f} | "
              f"{median(y[2] for y in b):.0f} / {median(x[2] for x in a):.0f} |")
    for case in cases:
        if case["samples"] == 1:
            wall, cpu = (sorted(d[k] for d in case["delta"]) for k in (0, 1))
            print(f"fixed cost (A − B of {case['steps']} steps, one sample): "
                  f"{1000 * median(wall):.0f} ms wall ({1000 * wall[0]:.0f}–"
                  f"{1000 * wall[-1]:.0f}), {1000 * median(cpu):.0f} ms cpu "
                  f"({1000 * cpu[0]:.0f}–{1000 * cpu[-1]:.0f})")
    for case in cases:
        rows = " ".join(f"{x[0]:.2f}/{y[0]:.2f}" for x, y in case["pairs"])
        print(f"{case['steps']} steps, python/bare wall per pair: {rows}")


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--cases", default="2000:100,5000:500,100:100",
                        help="STEPS:SAMPLE_EVERY, comma-separated (default: 20, 10 and 1 "
                             "samples; a case of one sample measures the fixed cost)")
    parser.add_argument("--repeats", type=int, default=5, help="counted pairs per case")
    parser.add_argument("--prepare", nargs=3, metavar=("FOLDER", "STEPS", "EVERY"),
                        help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.prepare:
        prepare(Path(args.prepare[0]), int(args.prepare[1]), int(args.prepare[2]))
        return
    cases = [tuple(int(v) for v in c.split(":")) for c in args.cases.split(",") if c.strip()]
    with tempfile.TemporaryDirectory() as tmp:
        results = [run_case(steps, every, args.repeats, Path(tmp)) for steps, every in cases]
    print(f"{results[0]['n']} spheres; pairs python/bare interleaved, medians (min–max)")
    report(results)


if __name__ == "__main__":
    main()
