"""``demstudy stability`` / ``ds.stability``: a suite of hard cases run in every engine where
they mean something, as a table (case, engine, what is checked, measured figure, limit,
pass/fail/explained) written to docs/stability.md (and CSV, JSON).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise the wall speed
or shear rate sets the time unit τ).

Soft-contact cases (:mod:`.soft`) run in every registered backend whose ``kind`` is
"soft-contact"; an engine that cannot express a case refuses it, which gives a "refused" row.
Event-driven cases (:mod:`.hard`) run in ``edmd``. Cases register themselves with
:func:`~demstudy.stability.registry.case`.

    import demstudy as ds
    rows = ds.stability(cases=["stiff-contacts"], quick=True)
    [(r.case, r.engine, r.status, r.measured) for r in rows]
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Iterable

from .registry import CASES, SOFT, Case, Outcome, Row, Suite, case, plan_rows, run_suite

__all__ = ["CASES", "SOFT", "Case", "Outcome", "Row", "Suite", "case", "case_names",
           "plan_rows", "run_suite", "stability"]


def case_names() -> list[str]:
    """Every registered case, in the table's order."""
    from . import hard, soft  # noqa: F401 - registers the cases

    return sorted(CASES, key=lambda n: CASES[n].kind != SOFT)  # the table's order


def stability(engines: Iterable[str] | None = None, cases: Iterable[str] | None = None,
              quick: bool = False, out: str | os.PathLike | None = None,
              progress: Callable[[Row], None] | None = None) -> list[Row]:
    """Run the suite (default: every case in every engine it means something in; ``quick``:
    the short versions) and return its rows; with ``out`` also write the Markdown table
    there, and CSV and JSON next to it. Unknown engines or cases are refused
    (``BadOption``) before anything runs."""
    suite = run_suite(engines, cases, quick=quick, progress=progress)
    if out is not None:
        from .report import write_outputs

        write_outputs(suite, out)
    return suite.rows


class _CallableModule(sys.modules[__name__].__class__):
    """``ds.stability(...)`` calls :func:`stability` even after ``import
    demstudy.stability`` has made the attribute ``demstudy.stability`` this module (the
    import system sets a package's submodule as its attribute, shadowing the lazy export)."""

    def __call__(self, *args, **kwargs) -> list[Row]:
        return stability(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
