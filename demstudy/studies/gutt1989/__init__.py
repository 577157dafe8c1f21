"""Gutt (1989), The Physics of Granular Systems: continuum theory with spin (Ch. 1), three-slip
wall boundary conditions and Couette flow (Ch. 2), Lattice Grain Dynamics (Ch. 3)
(docs/studies/gutt1989.md; digest ../shared/reference/gutt1989.md).

Parts, in order (``PARTS``): ``theory`` solves Chapters 1 and 2 with
demstudy.theory.gutt_spin / gutt_walls (no runs); ``couette`` overlays Gutt's Ch. 2 Couette
solution on event-driven 2D and 3D runs with his wall rule; ``lgd`` reruns his Ch. 3 lattice
scenes on the lattice engine (``--engine lgd``; cases named ``lgd-*``); ``lgd_theory``
overlays the Ch. 2 Couette solution on the ``lgd`` part's Couette runs (no runs of its own).

Units: Ch. 1 in arbitrary units as the thesis (d = 1); elsewhere dimensionless particle
units d = 1, m = 1, no gravity, the wall speed u_w = 1 sets the time scale.
"""

from __future__ import annotations

from ..base import Study
from ..parts import combined_analysis, combined_cases
from . import couette, lgd, lgd_theory, theory

PARTS = (theory, couette, lgd, lgd_theory)

STUDY = Study(
    name="gutt1989",
    title="Gutt (1989): continuum theory with spin, three-slip walls, Couette flow and lattice "
          "grain dynamics",
    reference="G. M. Gutt, *The Physics of Granular Systems*, PhD thesis (1989); digest "
              "shared/reference/gutt1989.md, beside this repository (../shared from its "
              "root), not in it",
    summary="Gutt's Ch. 1 model problems (uniform cooling, vibrating plates, Couette with "
            "spin) and Ch. 2 three-slip Couette solution solved with demstudy.theory and "
            "checked against the trends the thesis states; the Ch. 2 Couette solution "
            "overlaid on event-driven Couette runs of smooth inelastic discs and spheres "
            "between bumpy, frictionless, lossy walls at the measured wall roughness; his "
            "Ch. 3 lattice-grain-dynamics scenes (gas, explosion, Couette, hourglass, "
            "obstacles, incline, Poiseuille up to his 508 032 grains) rerun on demstudy's "
            "LGD engine at his step counts.",
    cases=combined_cases(PARTS),
    analyse=combined_analysis(PARTS),
)
