"""Accuracy versus cost: soft contacts (LAMMPS) against the hard-particle limit (the
event-driven engine), a resumable, parallel ladder over stiffness, steps per contact and
contact model (``demstudy cost SCENE``, docs/cost.md).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise the shear
rate or the wall speed sets the time unit).

    import demstudy as ds
    study = ds.cost("shear/lees-edwards-2d", quick=True, workers=2)
    study.recommendation, study.rows, study.fits
"""

from .._lazy import lazy_exports

__all__ = ["CostStudy", "cost", "fit_convergence", "pick_cheapest"]

__getattr__, __dir__ = lazy_exports(__name__, {
    "cost": ".study",
    "CostStudy": ".study",
    "fit_convergence": ".analyze",
    "pick_cheapest": ".analyze",
})

