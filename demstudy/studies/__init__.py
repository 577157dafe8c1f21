"""The seed studies, one command each: ``demstudy study campbell1982 | malik2008 | gutt1989``
(docs/studies/). A study runs its cases, analyses them, writes figures in the thesis's forms
and a report with one row per statement of the thesis and its verdict.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise a wall speed
sets the time unit).
"""

from __future__ import annotations

from importlib import import_module

from .base import Analysis, Case, Check, Figure, Study, pm, within

#: study name → module that defines ``STUDY``
_MODULES = {"campbell1982": ".campbell1982", "gutt1989": ".gutt1989",
            "malik2008": ".malik2008"}

__all__ = ["Analysis", "Case", "Check", "Figure", "Study", "get_study", "pm", "run_study",
           "study", "study_names", "within"]


def study_names() -> list[str]:
    return sorted(_MODULES)


def get_study(name: str) -> Study:
    """The study called ``name`` (``study_names()``)."""
    from ..errors import BadOption

    if name not in _MODULES:
        raise BadOption("study", name, f"the studies {', '.join(study_names())} are allowed")
    return import_module(_MODULES[name], __name__).STUDY


def run_study(name: str, **kwargs):
    """See :func:`demstudy.studies.runner.run_study`."""
    from .runner import run_study as _run

    return _run(name, **kwargs)


def study(name: str, *, quick: bool = False, **kwargs):
    """Run the seed study ``name`` (``study_names()``) end to end and return its
    :class:`~demstudy.studies.runner.StudyRun` (``.report``, ``.analysis.checks``, ``.made``,
    ``.failed``); keywords as ``demstudy study``: ``out``, ``workers``, ``dask``, ``dry_run``,
    ``engines``, ``only``, ``analyse_only``, ``records`` (where the study keeps its run
    records, demstudy.studies.records), ``echo`` (a print function)."""
    return run_study(name, quick=quick, **kwargs)
