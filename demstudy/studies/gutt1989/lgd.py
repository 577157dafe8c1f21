"""Gutt (1989), the LGD part: his Ch. 3 lattice-grain-dynamics scenes (digest §3.15, §4.3)
rerun on demstudy's lattice engine and checked statement by statement.

Dimensionless particle units: d = 1 (lattice spacing), m = 1; g = 1 where gravity acts,
otherwise the scene's speed unit (wall speed or initial gas speed) sets the time scale.
Runs: :mod:`.lgd_cases`; measurements: :mod:`.lgd_measure`; checks: :mod:`.lgd_checks`;
figures: :mod:`.lgd_figures`.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from ..base import Analysis, Case
from .lgd_cases import all_cases


def cases(quick: bool) -> list[Case]:
    return [c for c in all_cases() if c.quick or not quick]


def analyse(runs: Mapping[str, Path], out: Path, quick: bool) -> Analysis:
    from .lgd_checks import analyse as _analyse

    return _analyse(runs, out, quick)
