"""Malik (2008), Density Waves and Fluctuations in 3D Granular Poiseuille Flow
(docs/studies/malik2008.md; digest ../shared/reference/malik2008.md).

Dimensionless particle units: d = 1, m = 1, g = 1 (times √(d/g), speeds √(gd), T in g d).
"""

from __future__ import annotations

from ..base import Study
from ..parts import combined_analysis, combined_cases, combined_derive
from . import poiseuille, waves

PARTS = (poiseuille, waves)

STUDY = Study(
    name="malik2008",
    title="Malik (2008): 3D granular Poiseuille flow and density waves, reproduced",
    reference="S. Malik, *Density Waves and Fluctuations in 3D Granular Poiseuille Flow*, "
              "thesis, JNCASR Bangalore (2008); digest shared/reference/malik2008.md, beside "
              "this repository (../shared from its root), not in it",
    summary="Malik's gravity-driven Poiseuille flows of rough inelastic spheres (φ ≈ 0.01, "
            "0.1, 0.5 over β and e) and the density waves at φ ≈ 0.15 in his boxes, rerun "
            "with hard spheres in the event-driven engine (the reference) and soft spheres "
            "in LAMMPS and LIGGGHTS where meaningful, analysed in the thesis's forms.",
    cases=combined_cases(PARTS),
    analyse=combined_analysis(PARTS),
    derive=combined_derive(PARTS),
    derive_version=2,  # 2: the density-wave windows at the thesis's snapshot times
)
