"""Accuracy versus cost: soft contacts (LAMMPS) against the hard-particle limit (the
event-driven engine), a resumable, parallel ladder over stiffness, steps per contact and
contact model (``demstudy cost SCENE``, docs/cost.md).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise the shear
rate or the wall speed sets the time unit).

    import demstudy as ds
    study = ds.cost("shear/lees-edwards-2d", quick=True, workers=2)
    study.recommendation, study.rows, study.fits
"""

import sys
import types

from .._lazy import lazy_exports

__all__ = ["CostStudy", "cost", "fit_convergence", "pick_cheapest"]

__getattr__, __dir__ = lazy_exports(__name__, {
    "cost": ".study",
    "CostStudy": ".study",
    "fit_convergence": ".analyze",
    "pick_cheapest": ".analyze",
})


class _CallablePackage(types.ModuleType):
    """``ds.cost(...)`` calls :func:`demstudy.cost.study.cost`: ``demstudy.cost`` is this
    package (Python binds the subpackage to that name once it is imported), so the package
    itself is callable."""

    def __call__(self, *args, **kwargs):
        from .study import cost

        return cost(*args, **kwargs)


sys.modules[__name__].__class__ = _CallablePackage
