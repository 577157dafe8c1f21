"""The accuracy-against-cost studies of docs/accuracy-cost.md: one `demstudy cost` ladder per
flow (event-driven reference, soft LAMMPS runs over stiffness and steps per contact).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise the wall
speed or the shear rate sets the time scale). Each ladder is resumable: rerunning skips the
runs whose results files are there.

    python analysis/accuracy_cost.py                 # every study (hours on 2 cores)
    python analysis/accuracy_cost.py couette le3d-0.3 --workers 2

Writes results/accuracy-cost/<study>/ (ladder.csv, ladder.json, pareto.png, the runs' files).
"""

from __future__ import annotations

import argparse
import shutil
from pathlib import Path

import numpy as np

import demstudy as ds

ROOT = Path(__file__).resolve().parent.parent
INPUTS = ROOT / "inputs" / "accuracy-cost"

#: study name → scene, ladder (k* values, steps per contact, contact models), overrides;
#: the cheap event-driven reference is replicated (other seeds) to shrink its noise
STUDIES: dict[str, dict] = {
    "couette": dict(scene=INPUTS / "couette-rough-nu0.55.toml",
                    kstars=[1e2, 1e3, 1e4, 1e5], steps=[10, 50], models=["hooke"],
                    overrides=["run.production=2400"], reference_replicas=4),
    "le3d-0.3": dict(scene=INPUTS / "lees-edwards-3d-phi0.3.toml",
                     kstars=[1e3, 1e4, 1e5, 1e6], steps=[10, 50], models=["hooke"],
                     reference_replicas=4),
    "le3d-0.55": dict(scene=INPUTS / "lees-edwards-3d-phi0.55.toml",
                      kstars=[1e3, 1e4, 1e5, 1e6], steps=[10], models=["hooke"]),
    # starts from the event-driven steady state (steady_state below): 300 √(d/g) of
    # transient would cost hours per stiff soft run
    "poiseuille": dict(scene=INPUTS / "poiseuille-phi0.1-small.toml",
                       kstars=[1e4, 1e5, 1e6, 1e7], steps=[10], models=["hooke"],
                       overrides=["run.equilibration=10", "run.production=60"],
                       steady=True, reference_replicas=4),
}


def steady_state(scene_path: Path, folder: Path) -> list[str]:
    """Run the scene's transient in the event-driven engine once and return the overrides
    that start every run of the ladder from its last frame (positions and velocities)."""
    state = folder / "steady-state.txt"
    if not state.exists():
        folder.mkdir(parents=True, exist_ok=True)
        scene = ds.load_scene(scene_path, run={"production": 1.0})
        res = ds.run(scene, engine="edmd", out=folder / "transient-edmd.h5", keep_frames=True)
        last = list(res.iter_frames())[-1]
        np.savetxt(state, np.hstack([last.position, last.velocity]), fmt="%.6f",
                   header=f"steady state of {scene_path.name} after t = {last.time:g} "
                          "(event-driven); columns x y z vx vy vz; units d = m = g = 1")
    return ["initial.placement=file", f"initial.path={state}"]


def figures(name: str, study, into: Path) -> None:
    """docs/figures/accuracy-<study>-pareto.png and -profiles.png: the ladder's accuracy
    against cost, and the stiffest soft run at the most steps per contact overlaid on the
    reference (its replicas combined) with their difference per bin."""
    into.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(study.folder / "pareto.png", into / f"accuracy-{name}-pareto.png")
    reference = study.reference["path"].split(",")  # replicas: their files, comma-joined
    softs = [r for r in study.rows if r["engine"] == "lammps"]
    best = max(softs, key=lambda r: (r["steps_per_contact"], r["kstar"]))
    (comparison,) = ds.compare(reference, best["path"].split(","))
    ds.plot_comparison(comparison, into / f"accuracy-{name}-profiles.png",
                       fields=["solid_fraction", "velocity[x]", "temperature",
                               "rotational_temperature"])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("studies", nargs="*", metavar="STUDY",
                        help=f"of {', '.join(STUDIES)} (default: all)")
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--out", type=Path, default=ROOT / "results" / "accuracy-cost")
    parser.add_argument("--figures", type=Path, default=ROOT / "docs" / "figures",
                        help="where the studies' figures go (default docs/figures)")
    args = parser.parse_args(argv)
    unknown = [s for s in args.studies if s not in STUDIES]
    if unknown:
        parser.error(f"unknown studies {', '.join(unknown)}: choose from {', '.join(STUDIES)}")
    for name in args.studies or STUDIES:
        spec = dict(STUDIES[name])
        folder = args.out / name
        overrides = list(spec.pop("overrides", []))
        if spec.pop("steady", False):
            overrides += steady_state(spec["scene"], folder)
        study = ds.cost(spec.pop("scene"), out=folder, overrides=overrides,
                        workers=args.workers, **spec)
        print(f"{name}: {study.recommendation}")
        figures(name, study, args.figures)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
