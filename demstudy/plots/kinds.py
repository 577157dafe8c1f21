"""The plot kinds (``demstudy plot --kind``), without matplotlib: the command line builds its
help from them in every process, a run included. Dimensionless particle units: d = 1, m = 1,
g = 1 with gravity.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..analysis.registry import STATISTICS

#: figures drawn from a run's time series, scene or own groups rather than from a statistic
HOW_PLOT_ONLY = {"cooling": "Haff's law needs every axis periodic, no walls, gravity or "
                            "shear, equal particles and a constant e < 1",
                 "health": "soft-contact (LAMMPS) runs store the contact health; "
                           "event-driven runs are hard and have none"}
#: the kinds that take ``scaled`` (against (y − y_0)/H)
SCALED = ("profiles", "cgprofiles")
#: the kinds, in the order ``--kind all`` draws them: each registered statistic's figures
#: (``demstudy.analysis.registry``), then those drawn from the time series
KINDS = tuple(dict.fromkeys([k for s in STATISTICS.values() for k in s.plots] +
                            list(HOW_PLOT_ONLY)))

__all__ = ["HOW_PLOT_ONLY", "KINDS", "SCALED", "parse_kinds"]


def parse_kinds(values: Sequence[str] | None) -> list[str]:
    """Kinds from ``--kind`` values (repeatable, comma-separated, ``all``); ValueError naming
    the allowed kinds for an unknown one."""
    kinds: list[str] = []
    for value in values or ["profiles"]:
        for item in (v.strip() for v in value.split(",")):
            if not item:
                continue
            if item == "all":
                kinds.extend(KINDS)
            elif item in KINDS:
                kinds.append(item)
            else:
                raise ValueError(f"unknown plot kind {item!r} (allowed: {', '.join(KINDS)}, all)")
    return list(dict.fromkeys(kinds)) or ["profiles"]
