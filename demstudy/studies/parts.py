"""A study made of parts (chutes, Couette cells, ...): each part module has ``cases(quick)``
and ``analyse(runs, out, quick)``; the study's cases and analysis are theirs, in order.
Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from types import ModuleType

from .base import Analysis, Case


def combined_cases(parts: Sequence[ModuleType]):
    def cases(quick: bool) -> list[Case]:
        return [case for part in parts for case in part.cases(quick)]
    return cases


def combined_analysis(parts: Sequence[ModuleType]):
    def analyse(runs: Mapping[str, Path], out: Path, quick: bool) -> Analysis:
        total = Analysis()
        for part in parts:
            # a part may also analyse other parts' runs (``reads(quick)``: their names)
            names = {c.name for c in part.cases(quick)} | set(
                getattr(part, "reads", lambda _quick: ())(quick))
            ana = part.analyse({n: p for n, p in runs.items() if n in names}, out, quick)
            total.checks += ana.checks
            total.figures += ana.figures
            total.sections += ana.sections
        return total
    return analyse


def combined_derive(parts: Sequence[ModuleType]):
    """The parts' ``derive(name, path)`` (what a study record keeps of a run, module
    demstudy.studies.records), merged: each part answers for its own cases."""
    def derive(name: str, path: Path) -> dict:
        out: dict = {}
        for part in parts:
            if hasattr(part, "derive"):
                out.update(part.derive(name, path))
        return out
    return derive
