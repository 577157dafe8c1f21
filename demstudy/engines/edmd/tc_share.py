"""The share of pair collisions the TC model made elastic, reported by every event-driven run.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts; t_c is a time in the
scene's unit τ. The TC model (Luding & McNamara 1998) makes a pair collision elastic when
either partner collided less than t_c earlier: it stops inelastic collapse, but every such
collision dissipates nothing. While their share is small the dissipation is the scene's; above
``WARN_SHARE`` (5 %) the results may depend on t_c, so the run warns and suggests a smaller
``--tc`` (and comparing the two runs). The share is written to the results file
(``tc_elastic_fraction``, described in ``tc_elastic_fraction_description``) and printed at
the end of the run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

__all__ = ["WARN_SHARE", "TcShare", "tc_share"]

#: above this share of elastic pair collisions the run warns that results may depend on t_c
WARN_SHARE = 0.05


@dataclass(frozen=True)
class TcShare:
    """``elastic`` of ``collisions`` pair collisions (since t = 0) were made elastic with
    the TC time ``tc`` (0: the model is off)."""

    elastic: int
    collisions: int
    tc: float

    @property
    def fraction(self) -> float:
        """elastic / collisions; NaN without any pair collision."""
        return self.elastic / self.collisions if self.collisions else math.nan

    def attrs(self) -> dict[str, Any]:
        """Root attributes of the results file."""
        return {"pair_collisions": self.collisions, "tc_elastic_fraction": self.fraction,
                "tc_elastic_fraction_description": (
                    f"fraction of the run's pair collisions since t = 0 that the TC model "
                    f"made elastic (a partner's previous collision less than t_c = "
                    f"{self.tc:g} τ earlier: e = 1, no tangential impulse): "
                    f"{self.elastic} of {self.collisions}; NaN without pair collisions. "
                    f"Above {100 * WARN_SHARE:g} % the results may depend on t_c (rerun with a "
                    "smaller --tc and compare)"),
                "tc_elastic_warning": self.warning() or ""}

    @classmethod
    def from_attrs(cls, attrs: dict[str, Any]) -> TcShare:
        """From a results file's root attributes (those of :meth:`attrs`)."""
        return cls(int(attrs["elastic_tc_collisions"]), int(attrs["pair_collisions"]),
                   float(attrs["tc"]))

    def line(self) -> str:
        """One line for the end of a run."""
        if self.tc == 0.0:
            return "TC model: off (t_c = 0): no pair collision was made elastic"
        if not self.collisions:
            return f"TC model: no pair collisions (t_c = {self.tc:g})"
        return (f"TC model: {100 * self.fraction:.3g} % of pair collisions made elastic "
                f"({self.elastic} of {self.collisions}, t_c = {self.tc:g})")

    def warning(self) -> str | None:
        """The warning above ``WARN_SHARE``, else None."""
        if not self.collisions or self.fraction <= WARN_SHARE:
            return None
        return (f"warning: the TC model made {100 * self.fraction:.3g} % of pair collisions "
                f"elastic (more than {100 * WARN_SHARE:g} %): the results may depend on t_c = "
                f"{self.tc:g}; rerun with a smaller --tc (e.g. --tc {self.tc / 10:g}) and "
                "compare the results, not only the share (in dense sheared 3D flows a smaller "
                "t_c lowered the share at ×1.0-2.1 the cost; in beds at rest and dense 2D "
                "flows it did not fall, the elastic collisions being a cluster's "
                "re-collisions, and cost ×5-8: docs/edmd-engine.md)")


def tc_share(elastic: int, collisions: int, tc: float) -> TcShare:
    """The share of an event-driven core's counters (plain ints and a float)."""
    return TcShare(int(elastic), int(collisions), float(tc))
