"""LAMMPS and LIGGGHTS from identical initial states: do their contacts and walls agree?

Both engines start from the same seeded state (demstudy makes it, not the engine), so their
trajectories agree until round-off grows chaotically; any systematic difference in contact
forces, damping, tangential springs or wall driving shows up first as a drift of the total
(translational + rotational) energy E(t) between them, long before chaos hides it. Runs
each variant of the Couette cell (inputs/accuracy-cost/couette-rough-nu0.55.toml, k* = 1e4,
50 steps per contact) for a few seeds in both engines and prints <E_liggghts>/<E_lammps> - 1
against time with its standard error over the seeds:

- ``cool``: walls still, a Haff-type free cooling of the same rough discs (β = 0, e = 0.6,
  rough walls e_w = 0.8) from temperature T0 (T0 = 1e-3 U² is the cell's sheared T),
- ``cool-dense``: the same in a 10.5 × 10.5 box (ν = 0.71, the sheared cell's mid-gap ν),
- ``shear``: the cell itself (upper wall at U = 1) from its lattice start.

Dimensionless particle units: d = 1, m = 1; the wall speed U = 1 sets the time scale
(τ = d/U), also in the cooling variants (temperatures in U²). About a minute on one core.

    python analysis/twin_engines.py [--seeds 4] [--variant cool --variant shear] [--out DIR]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import demstudy as ds
from demstudy.scene.schema import Soft

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "inputs" / "accuracy-cost" / "couette-rough-nu0.55.toml"
ENGINES = ("lammps", "liggghts")
SOFT = Soft(model="hooke", stiffness=1e4, steps_per_contact=50)  # the cross-check's stiffest
COMMON = ["run.equilibration=0.0"]
# duration and sampling per variant: long enough for chaos to take over at the end
VARIANTS: dict[str, list[str]] = {
    "cool": ["walls[1].velocity=0.0", "initial.velocity.perturbation=0.0",
             "initial.velocity.temperature=0.001", "run.production=50.0",
             "run.sample_interval=0.5"],
    "cool-dense": ["walls[1].velocity=0.0", "initial.velocity.perturbation=0.0",
                   "initial.velocity.temperature=0.001", "run.production=50.0",
                   "run.sample_interval=0.5", "box.size=[10.5, 10.5]",
                   "initial.spacing=1.05"],
    "shear": ["run.production=20.0", "run.sample_interval=0.1"],
}


def energies(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Sample times and total kinetic (translational + rotational) energy of one run."""
    ts = ds.load(path).timeseries
    return np.asarray(ts["time"]), np.asarray(ts["kinetic_energy"]) + np.asarray(
        ts["rotational_energy"])


def wall_forces(out: Path, variant: str, seed: int, before: float = 5.0) -> None:
    """Each wall's x force, LIGGGHTS against LAMMPS, in the samples before ``before`` (still
    the same trajectory) that had a wall contact: a systematic ratio is a wall difference."""
    runs = [ds.load(out / f"{variant}-{engine}-s{seed}.h5").timeseries for engine in ENGINES]
    early = np.asarray(runs[0]["time"]) < before
    for side in ("upper", "lower"):
        lmp, lig = (np.asarray(ts[f"wall_force_{side}"])[early, 0] for ts in runs)
        hit = np.abs(lmp) > 1e-3
        if hit.any():
            ratio = lig[hit] / lmp[hit] - 1
            print(f"seed {seed}, {side} wall x force before t = {before:g}: LIGGGHTS/LAMMPS - 1 "
                  f"= {ratio.mean():+.1e} (range {ratio.min():+.1e} … {ratio.max():+.1e}, "
                  f"{hit.sum()} samples)")


def compare(variant: str, seeds: int, out: Path) -> None:
    """Run ``variant`` in both engines for ``seeds`` seeds and print the energy ratio."""
    curves: dict[str, list[np.ndarray]] = {engine: [] for engine in ENGINES}
    time = np.empty(0)
    for seed in range(1, seeds + 1):
        sets = [*COMMON, *VARIANTS[variant], f"run.seed={seed}"]
        scene = ds.load_scene(SCENE, sets).model_copy(update={"soft": SOFT})
        for engine in ENGINES:
            path = out / f"{variant}-{engine}-s{seed}.h5"
            if not path.exists():
                ds.run(scene, engine, path, progress=False)
            time, energy = energies(path)
            curves[engine].append(energy)
        if variant == "shear":
            wall_forces(out, variant, seed)
    lmp, lig = (np.array(curves[engine]) for engine in ENGINES)
    print(f"\n{variant}: {seeds} seeds, identical initial states in both engines")
    print("    t/τ      <E> LAMMPS  <E> LIGGGHTS  ratio - 1   ± s.e. (paired over seeds)")
    for i in np.unique(np.linspace(1, len(time) - 1, 12).astype(int)):
        rel = lig[:, i] / lmp[:, i] - 1  # paired: same start, same seed
        err = rel.std(ddof=1) / np.sqrt(seeds) if seeds > 1 else float("nan")
        print(f"{time[i]:8.2f}  {lmp[:, i].mean():11.5g}  {lig[:, i].mean():11.5g}  "
              f"{lig[:, i].mean() / lmp[:, i].mean() - 1:+10.2e}   {err:.1e}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=4)
    parser.add_argument("--variant", action="append", choices=sorted(VARIANTS))
    parser.add_argument("--out", type=Path, default=ROOT / "results" / "twin-engines")
    args = parser.parse_args(argv)
    if args.seeds < 1:
        parser.error(f"--seeds {args.seeds}: at least 1 seed is needed")
    args.out.mkdir(parents=True, exist_ok=True)
    for variant in args.variant or sorted(VARIANTS):
        compare(variant, args.seeds, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
