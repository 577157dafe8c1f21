"""Malik (2008) Ch. 5: every box of the thesis's table (digest §1.4-1.5) with its figure, and
the structure class the thesis reports for it where the digest says (§1.8, §4.11, §7).

Dimensionless particle units: d = 1, m = 1, g = 1 (gravity acts): times in √(d/g).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

#: e, β, e_w, β_w of every Ch. 5 run (digest §1.4, [L1080]-[L1086]); e varies only in the e study
RESTITUTION, BETA, WALL_E, WALL_BETA = 0.7, 0.1, 0.99, 0.99


@dataclass(frozen=True)
class Box:
    """One box of the thesis's table: N particles in L × W × H (d = 1), its figure(s), and
    e (0.7 unless the e study)."""

    fig: str
    n: int
    length: int
    width: int
    height: int
    restitution: float = RESTITUTION

    @property
    def tag(self) -> str:
        return f"L{self.length}W{self.width}H{self.height}"

    @property
    def scene(self) -> str:
        """The shipped scene (preset) of the box (the e study overrides e only)."""
        return f"malik2008/waves-phi0.15-{self.tag}"

    @property
    def name(self) -> str:
        e = "" if self.restitution == RESTITUTION else f"-e{self.restitution:g}"
        return f"waves-phi0.15-{self.tag}{e}-edmd"

    @property
    def phi(self) -> float:
        """Actual solid fraction N π/6 / (L W H) (digest §1.5)."""
        return self.n * math.pi / 6.0 / (self.length * self.width * self.height)

    @property
    def aspect(self) -> float:
        return self.length / self.width


#: the thesis's table (digest §1.5), in its order of W then L/W, then the H/W series (5.19,
#: 5.20) and the e study (5.23, 5.24)
BOXES: tuple[Box, ...] = (
    Box("5.1", 600, 9, 15, 15), Box("5.4", 1400, 21, 15, 15), Box("5.11", 3000, 45, 15, 15),
    Box("5.14", 4800, 75, 15, 15),
    Box("5.2", 4800, 18, 30, 30), Box("5.5", 10800, 42, 30, 30), Box("5.12", 24000, 90, 30, 30),
    Box("5.15", 40000, 150, 30, 30),
    Box("5.3", 22000, 30, 50, 50), Box("5.6-5.10", 50094, 70, 50, 50),
    Box("5.13", 107811, 150, 50, 50), Box("5.16-5.18", 180000, 250, 50, 50),
    Box("5.19", 21952, 150, 50, 10), Box("5.20-5.22", 323433, 150, 50, 150),
    Box("5.23", 107811, 150, 50, 50, restitution=0.9),
    Box("5.24", 107811, 150, 50, 50, restitution=0.99),
)

#: the quick subset: the two smallest W = 15 boxes, short runs
QUICK = ("L9W15H15", "L45W15H15")


@dataclass(frozen=True)
class ThesisClass:
    """What the digest says the thesis found for a box: ``cls`` one of the classifier's
    classes ("plug", "s-wave", "slug", "mixed", "none"), or "" when the digest does not say;
    ``text`` the statement and where it is."""

    cls: str
    text: str
    #: the thesis's time (c/p) of that class, when the class is a snapshot's
    time: float | None = None
    #: the classes the thesis saw in turn before settling (its snapshots' order), if any
    sequence: tuple[str, ...] = ()


#: only what the digest states (§1.8 [L1149]-[L1159]; §4.11 cites [L1118] for the plug
#: definition, right after Fig 5.2's caption [L1116], and [L1155] for the plug → S-wave
#: transition inside the N = 50094 discussion). No other box's class is in the digest.
THESIS: dict[str, ThesisClass] = {
    "5.6-5.10": ThesisClass("slug", "N = 50094, L/W = 1.4, W/d = 50: the energy plateaus at "
                            "t ≈ 11000 c/p but the structure keeps evolving (plug → one-hump "
                            "S-wave, birth of (1,1), [L1155]) until a slug forms at t ≈ 14000 "
                            "c/p (digest §1.8, [L1149]-[L1159])", time=14000.0,
                            sequence=("plug", "s-wave", "slug")),
}


def box_of(name: str) -> Box:
    """The box of a case name (KeyError naming the allowed names)."""
    for box in BOXES:
        if box.name == name:
            return box
    raise KeyError(f"case {name!r}: not a density-wave case (allowed: "
                   f"{', '.join(b.name for b in BOXES)})")
