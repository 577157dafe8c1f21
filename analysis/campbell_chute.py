"""Main job: Campbell's (1982) 30° chute (10 × 4 rough discs), soft discs in LAMMPS and hard
discs in the event-driven engine, from the same scene file.

Writes results/campbell1982-chute-30-{lammps,edmd}.h5 (profiles with block-averaged errors,
timeseries, stresses; the LAMMPS deck) and results/campbell1982-chute-30-profiles.png (both
engines overlaid), and prints where they are and a short summary per engine.
Dimensionless particle units: d = 1, m = 1, g = 1.

    python analysis/campbell_chute.py [--set run.production=100 ...]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from demstudy.io.results import read_results
from demstudy.plot import plot_profiles
from demstudy.scene import load_scene
from demstudy.simulation import RunOptions, run_scene

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "inputs" / "campbell1982" / "chute-30.toml"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    parser.add_argument("--out", type=Path, default=ROOT / "results")
    args = parser.parse_args(argv)

    scene = load_scene(SCENE, args.set)
    print(f"scene:   {SCENE.relative_to(ROOT)} ({scene.n_particles} discs, "
          f"{scene.gravity.angle:g}°)")
    files = []
    for engine in ("lammps", "edmd"):
        h5 = args.out / f"campbell1982-chute-30-{engine}.h5"
        run_scene(scene, engine, RunOptions(out=h5))
        files.append(h5)
    fig = plot_profiles(files, args.out / "campbell1982-chute-30-profiles.png")
    print(f"figure:  {fig}")
    for h5 in files:
        summarise(scene, h5)
    return 0


def summarise(scene, h5: Path) -> None:
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
    engine = res.attrs["engine"]
    how = (f"dt = {res.attrs['timestep']:.3g}" if "timestep" in res.attrs else
           f"{int(res.attrs['events'])} events, TC t_c = {res.attrs['tc']:g}")
    print(f"\n[{engine}] results: {h5}")
    print(f"  wall time {res.attrs['wall_seconds']:.1f} s; {how}; "
          f"{int(res.profile_attrs['samples'])} samples")
    print(f"  kinetic energy per disc in production: mean {ke.mean():.3f}, "
          f"min {ke.min():.3f}, max {ke.max():.3f} (m g d)")
    print(f"  H = 2 × mass-mean height = {2 * mean_height:.2f} d; "
          f"slip velocity u(y≈0.5) = {u[0]:.2f}, max u = {np.nanmax(u):.2f} (√(g d))")
    print(f"  base: shear/normal force {abs(force[0] / force[1]):.3f} "
          f"(steady flow needs tan α = {np.tan(np.radians(alpha)):.3f}); normal force "
          f"{abs(force[1]):.2f} vs weight·cos α = {n * np.cos(np.radians(alpha)):.2f}")
    # the bed's x-momentum balance: M g sin α − base shear force = dP_x/dt (m = 1 per disc)
    t, px = ts["time"][production], ts["momentum"][production, 0]
    accel = (px[-1] - px[0]) / (t[-1] - t[0])
    drive = n * np.sin(np.radians(alpha))
    trend = "accelerates" if accel > 0 else "decelerates"
    print(f"  x momentum: M g sin α − base shear force = {drive - abs(force[0]):.2f} vs "
          f"dP_x/dt = {accel:.2f} (m g): the bed {trend}")
    verdict = "steady" if res.attrs["steady"] else "NOT steady"
    print(f"  convergence (Campbell: KE within ~20 % with no trend): {verdict}, "
          f"KE trend {100 * res.attrs['kinetic_energy_trend']:+.0f} % over production")


if __name__ == "__main__":
    sys.exit(main())
