"""How well a stopped run's "time left at its own pace" meets the time the rest then takes
(docs/forecast.md, "A stopped run: what is left at its own pace").

Each scene runs with checkpoints every tenth of its length and a wall-clock limit that stops
it part way (after a checkpoint); ``ds.run(..., resume=True, dry_run=True)`` gives the time
left (``left_seconds``, from ``progress.json``); the run is then resumed to its end, and the
time the rest took is the results file's ``wall_seconds`` (every part summed) less the wall
seconds at the stop. Printed per scene: the forecast, the actual, their ratio. Scenes: a
steady Lees–Edwards gas (event-driven), Malik's smallest density-wave box from rest (N = 600,
event-driven; gravity accelerates the flow, so each interval of time holds more collisions
than the last) and the Lees–Edwards gas with soft contacts in LAMMPS. Dimensionless
particle units (d = 1, m = 1, g = 1 when gravity acts); wall times in seconds of this
machine.

    .venv/bin/python benchmarks/bench_resume_forecast.py [--stop-share 0.3]
"""

from __future__ import annotations

import argparse
import platform
import tempfile
import time
from pathlib import Path

import demstudy as ds
from demstudy.errors import RunStopped
from demstudy.scene import scene_to_toml
from demstudy.simulation.progress import read_progress

SCENES = (
    ("shear/lees-edwards-2d", "edmd", ["run.production=150", "run.sample_interval=1"]),
    ("malik2008/waves-phi0.15-L9W15H15", "edmd", ["run.equilibration=0",
                                                  "run.production=600",
                                                  "run.sample_interval=10"]),
    ("shear/lees-edwards-2d", "lammps", ["run.equilibration=0", "run.production=6",
                                         "run.sample_interval=0.2"]),
)


def one(preset: str, engine: str, sets: list[str], share: float, folder: Path) -> float:
    scene = ds.load_scene(preset, sets)
    run = scene.run
    every = (run.equilibration + run.production) / 10
    out = folder / f"{preset.replace('/', '-')}-{engine}.h5"
    started = time.perf_counter()
    whole = ds.run(scene, engine=engine, out=folder / "whole.h5", progress=False)
    alone = float(whole.attrs["wall_seconds"])  # the loop's time of the uninterrupted run
    del whole
    try:
        ds.run(scene, engine=engine, out=out, progress=False, checkpoint_interval=every,
               wall_limit=share * alone)
    except RunStopped:
        pass
    work = out.with_suffix(f".{engine}")
    done = read_progress(work, scene_to_toml(scene)) if work.exists() else None
    if done is None:
        print(f"{preset} ({engine}): not stopped before its end; raise --stop-share")
        return float("nan")
    plan = ds.run(scene, engine=engine, out=out, resume=True, dry_run=True, progress=False)
    left = float(plan["left_seconds"])
    res = ds.run(scene, engine=engine, out=out, resume=True, progress=False,
                 checkpoint_interval=every)
    took = float(res.attrs["wall_seconds"]) - done.wall_seconds
    print(f"{preset} ({engine}, N = {scene.n_particles}): stopped at "
          f"{done.done:.3g} of {done.total} intervals after {done.wall_seconds:.2f} s; left "
          f"forecast {left:.2f} s, took {took:.2f} s (×{took / left:.2f}); the run alone "
          f"{alone:.2f} s; bench {time.perf_counter() - started:.0f} s")
    return took / left


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stop-share", type=float, default=0.3,
                        help="stop each run after this share of its uninterrupted wall time")
    args = parser.parse_args()
    print(f"{platform.processor() or platform.machine()}, Python {platform.python_version()}, "
          f"{time.strftime('%Y-%m-%d %H:%M')}")
    with tempfile.TemporaryDirectory() as tmp:
        ratios = [one(p, e, s, args.stop_share, Path(tmp)) for p, e, s in SCENES]
    print("took / forecast: " + ", ".join(f"×{r:.2f}" for r in ratios))


if __name__ == "__main__":
    main()
