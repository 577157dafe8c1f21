"""Little's-law collision rate of the ``health`` group against counted contact starts.

The health group estimates the collision rate per particle from the contacts touching at the
samples, ω = Z / t_c (Little's law; docs/contact.md). Here a short run samples every step, so
that each pair contact is seen to start: the pair collision rate counted is 2 × (pairs touching
now that did not touch one step before) / (N × duration), compared with 2 ⟨pairs⟩ / (N t_c).

    python benchmarks/check_flight_time.py shear/lees-edwards-2d run.equilibration=2 \\
        run.production=0.3
    python benchmarks/check_flight_time.py campbell1982/chute-30 run.equilibration=4 \\
        run.production=1

Dimensionless particle units: d = 1, m = 1 (g = 1 with gravity).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

from demstudy.contact.stiffness import contact_setup
from demstudy.io.results import read_results
from demstudy.scene import load_scene
from demstudy.simulation import RunOptions, run_scene

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    name, sets = sys.argv[1], sys.argv[2:]
    path = ROOT / "inputs" / f"{name}.toml"
    dt = contact_setup(load_scene(path, [*sets, "run.sample_interval=0.01"])).timestep
    scene = load_scene(path, [*sets, f"run.sample_interval={dt!r}"])
    with tempfile.TemporaryDirectory() as tmp:
        res = read_results(run_scene(scene, "lammps", RunOptions(out=Path(tmp) / "r.h5",
                                                                 progress=False)))
    h, attrs = res.groups["health"], res.group_attrs["health"]
    n = scene.n_particles
    pairs = h["pair_contacts"][1:]
    starts = np.nan_to_num(pairs * (1 - h["persistent_fraction"][1:]))  # none touching: 0
    counted = 2 * starts.sum() / (n * (h["time"][-1] - h["time"][0]))
    little = 2 * pairs.mean() / (n * attrs["contact_time"])
    print(f"{name}: pair collision rate counted {counted:.4g}, Little's law {little:.4g}, "
          f"ratio {little / counted:.3f} ({starts.sum():.0f} contact starts, "
          f"{len(pairs)} steps)")


if __name__ == "__main__":
    main()
