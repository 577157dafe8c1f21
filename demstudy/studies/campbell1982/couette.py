"""PLACEHOLDER part of a study (being written): no cases, no checks yet.
Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from ..base import Analysis, Case


def cases(quick: bool) -> list[Case]:
    return []


def analyse(runs: Mapping[str, Path], out: Path, quick: bool) -> Analysis:
    return Analysis()
