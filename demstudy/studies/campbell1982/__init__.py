"""Campbell (1982), Shear Flows of Granular Materials: 2D chute and Couette flows of rough
inelastic discs (docs/studies/campbell1982.md; digest ../shared/reference/campbell1982.md).

Dimensionless particle units: d = 1, m = 1; g = 1 in the chutes (times √(d/g)), the wall
speed U_T = 1 in the Couette cells (times d/U_T). Campbell's unit of length was R = d/2.
"""

from __future__ import annotations

from ..base import Study
from ..parts import combined_analysis, combined_cases
from . import chutes, couette

PARTS = (chutes, couette)

STUDY = Study(
    name="campbell1982",
    title="Campbell (1982): chute and Couette flows of rough discs, reproduced",
    reference="C. S. Campbell, *Shear Flows of Granular Materials*, PhD thesis, Caltech "
              "(1982); digest shared/reference/campbell1982.md, beside this repository "
              "(../shared from its root), not in it",
    summary="Campbell's 2D chutes (20°, 30°, 40° and a depth series) and Couette cells "
            "(rough and no-slip walls, with his servo and at fixed gap) rerun with hard discs "
            "in the event-driven engine (the reference) and soft discs in LAMMPS where the "
            "scene can be expressed, analysed in the thesis's own forms.",
    cases=combined_cases(PARTS),
    analyse=combined_analysis(PARTS),
)
