"""Main job: Campbell's (1982) 30° chute (10 × 4 rough discs) run in LAMMPS end to end.

Writes results/campbell1982-chute-30-lammps.h5 (profiles with block-averaged errors,
timeseries, the deck) and results/campbell1982-chute-30-profiles.png, and prints where they
are and a short summary. Dimensionless particle units: d = 1, m = 1, g = 1.

    python analysis/campbell_chute.py [--set run.production=100 ...]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from demstudy.engines.base import RunOptions, get_engine
from demstudy.io.results import read_results
from demstudy.plot import plot_profiles
from demstudy.scene import load_scene

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "inputs" / "campbell1982" / "chute-30.toml"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    parser.add_argument("--out", type=Path, default=ROOT / "results")
    args = parser.parse_args(argv)

    scene = load_scene(SCENE, args.set)
    h5 = args.out / "campbell1982-chute-30-lammps.h5"
    get_engine("lammps").run(scene, RunOptions(out=h5))
    fig = plot_profiles([h5], args.out / "campbell1982-chute-30-profiles.png")

    res = read_results(h5)
    prof, ts = res.profiles, res.timeseries
    y, nu, u = prof["y"], prof["solid_fraction"], prof["velocity"][:, 0]
    n = scene.n_particles
    alpha = scene.gravity.angle
    # H = twice the mass-mean height of the centres (Campbell's definition of the depth)
    mean_height = float(np.sum(y * nu) / np.sum(nu))
    production = ts["time"] > res.attrs["equilibration_end"]  # samples after equilibration
    ke = ts["kinetic_energy"][production] / n
    force = np.nanmean(ts["wall_force_lower"][production], axis=0)
    print(f"scene:   {SCENE.relative_to(ROOT)} ({n} discs, {alpha:g}°)")
    print(f"results: {h5}")
    print(f"figure:  {fig}")
    print(f"wall time {res.attrs['wall_seconds']:.1f} s; dt = {res.attrs['timestep']:.3g}; "
          f"{int(res.profile_attrs['samples'])} samples")
    print(f"kinetic energy per disc in production: mean {ke.mean():.3f}, "
          f"min {ke.min():.3f}, max {ke.max():.3f} (m g d)")
    print(f"H = 2 × mass-mean height = {2 * mean_height:.2f} d; "
          f"slip velocity u(y≈0.5) = {u[0]:.2f}, max u = {np.nanmax(u):.2f} (√(g d))")
    print(f"base: shear/normal force {abs(force[0] / force[1]):.3f} "
          f"(steady flow needs tan α = {np.tan(np.radians(alpha)):.3f}); normal force "
          f"{abs(force[1]):.2f} vs weight·cos α = {n * np.cos(np.radians(alpha)):.2f}")
    verdict = "steady" if res.attrs["steady"] else "NOT steady"
    print(f"convergence (Campbell: KE within ~20 % with no trend): {verdict}, "
          f"KE trend {100 * res.attrs['kinetic_energy_trend']:+.0f} % over production")
    return 0


if __name__ == "__main__":
    sys.exit(main())
