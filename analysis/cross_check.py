"""Main job (`make run`): soft contacts (LAMMPS and LIGGGHTS) against the hard-particle limit
on a small steady seed flow, with what each step closer costs.

The flow: Campbell's (1982) Couette cell of rough inelastic discs at ν ≈ 0.55 (10 × 10 discs,
his rough walls, fixed gap: inputs/accuracy-cost/couette-rough-nu0.55.toml). The job

1. prints the forecast of every run it is about to make and of the whole ladder on its
   workers (`ds.cost` does, first: demstudy.accuracy.forecast; this machine's measured
   speed, measured first if it never was, ~20 s),
2. runs the event-driven reference and a ladder of soft runs over stiffness
   k* = k_n/(m U_T²/d) and steps per contact, each in LAMMPS and in LIGGGHTS (`demstudy cost
   --engine lammps,liggghts`, resumable, both cores),
3. compares the three engines: the stiffest soft run of each engine overlaid on the
   reference with their differences per bin (`demstudy compare`), and prints the error
   tables,

and writes into results/: cross-check/ (the ladder's runs, ladder.csv, ladder.json),
cross-check-pareto.png (accuracy against cost), cross-check-profiles.png (overlay and
difference), cross-check.txt (the tables). Dimensionless particle units: d = 1, m = 1, the
wall speed U_T = 1 sets the time scale (no gravity). About a minute on 2 cores.

    python analysis/cross_check.py [--set run.production=600 ...] [--workers 2]
"""

from __future__ import annotations

import argparse
import dataclasses
import shutil
import sys
from pathlib import Path

import demstudy as ds
from demstudy.accuracy.execute import Task, execute, pending
from demstudy.accuracy.plan import RunSpec
from demstudy.accuracy.report import table
from demstudy.engines.liggghts.library import INSTALL_HINT, library_path
from demstudy.scene import scene_to_toml

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "inputs" / "accuracy-cost" / "couette-rough-nu0.55.toml"
KSTARS, STEPS = (1e2, 1e3, 1e4), (10, 50)
ENGINES = ("lammps", "liggghts")  # the soft-contact engines, beside the event-driven one
SOFT_REPLICAS = 4  # seeds of each engine's stiffest soft run in the three-engine comparison


def replicas_of(rows: list[dict], scene, folder: Path, workers: int) -> list[list[str]]:
    """For each ladder row, its file and those of SOFT_REPLICAS - 1 more seeds (made now,
    in parallel, reused when present): one replica group per row."""
    specs = [RunSpec(r["engine"], r["model"], r["kstar"], r["steps_per_contact"])
             for r in rows]
    base = scene_to_toml(scene)
    tasks = [Task(dataclasses.replace(spec, replica=i), base,
                  folder / f"{dataclasses.replace(spec, replica=i).name}.h5")
             for spec in specs for i in range(1, SOFT_REPLICAS)]
    todo, _done = pending(tasks)
    if todo:
        print(f"three-engine comparison: {len(todo)} more seeds of the stiffest soft runs")
    execute(todo, min(workers, len(todo)) if todo else 1)
    return [[r["path"], *(str(t.path) for t in tasks if t.spec.settings == spec.settings)]
            for r, spec in zip(rows, specs, strict=True)]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    parser.add_argument("--out", type=Path, default=ROOT / "results")
    parser.add_argument("--workers", type=int, default=None)
    args = parser.parse_args(argv)

    scene = ds.load_scene(SCENE, args.set)
    engines = ENGINES
    if library_path() is None:  # `make run` installs it when it runs as root
        engines = ("lammps",)
        print(f"note: LIGGGHTS is not installed, the ladder runs in LAMMPS only ({INSTALL_HINT})")
    print(f"scene: {SCENE.relative_to(ROOT)} ({scene.n_particles} discs, "
          f"{scene.run.equilibration:g} + {scene.run.production:g} d/U_T)")
    workers = args.workers or 2
    folder = args.out / "cross-check"
    # the event-driven reference is cheap: four replicas (other seeds) give its errors from
    # their scatter (this cell's wall slip is slower than one run: docs/results-format.md)
    study = ds.cost(scene, kstars=KSTARS, steps=STEPS, models=["hooke"], workers=workers,
                    out=folder, reference_replicas=4, engines=engines)
    shutil.copyfile(folder / "pareto.png", args.out / "cross-check-pareto.png")

    # replicas: their files, comma-joined (compare combines a list)
    reference = next(r for r in study.rows if r.get("reference"))["path"].split(",")
    # the three engines on one scene: the stiffest soft run of each engine, with SOFT_REPLICAS
    # - 1 more seeds (this cell's wall slip wanders between seeds by more than one run's
    # errors: a single soft run could look off, or agree, by luck)
    stiffest = [max((r for r in study.rows if r["engine"] == engine),
                    key=lambda r: (r["kstar"], r["steps_per_contact"])) for engine in engines]
    groups = replicas_of(stiffest, scene, folder, workers)
    comparisons = ds.compare(reference, *groups)
    figure = ds.plot_comparison(comparisons, args.out / "cross-check-profiles.png",
                                fields=["solid_fraction", "velocity[x]", "temperature",
                                        "rotational_temperature"])
    report = "\n\n".join([
        table(study),
        *(f"stiffest {engine} run ({SOFT_REPLICAS} seeds) against the event-driven "
          "reference:\n" + c.table()
          for engine, c in zip(engines, comparisons, strict=True)),
        f"recommendation: {study.recommendation}"]).strip() + "\n"
    (args.out / "cross-check.txt").write_text(report)
    print("\n" + report)
    print(f"figures: {args.out / 'cross-check-pareto.png'}, {figure}")
    print(f"tables:  {args.out / 'cross-check.txt'}, {folder / 'ladder.csv'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
