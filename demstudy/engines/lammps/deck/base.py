"""Deck building blocks: each physical effect contributes one commented ``Block`` or nothing.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (LAMMPS ``units lj``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

Stage = Literal["setup", "physics", "run"]


@dataclass
class Block:
    """Commands of one effect, in the stage where they belong.

    setup: creates the box and the particles (replaced by ``read_restart`` on resume);
    physics: interactions, walls, body forces, integration (re-issued on resume);
    run: output and ``run`` commands of a bare deck (the Python driver runs its own loop).
    """

    effect: str
    comment: str
    commands: list[str]
    stage: Stage = "physics"


@dataclass
class Deck:
    blocks: list[Block] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    files: dict[str, str] = field(default_factory=dict)  # name -> content written beside the deck

    def effects(self) -> list[str]:
        return [b.effect for b in self.blocks]

    def commands(self, *stages: Stage) -> list[str]:
        wanted = stages or ("setup", "physics", "run")
        return [c for b in self.blocks if b.stage in wanted for c in b.commands]

    def render(self, title: str = "") -> str:
        lines = [
            f"# demstudy LAMMPS deck{': ' + title if title else ''}",
            "# Dimensionless particle units (units lj): diameter d = 1, mass m = 1,",
            "# g = 1 when gravity acts (otherwise a wall speed or shear rate sets the time scale).",
            "# Axes: x flow (periodic), y wall-normal, z spanwise (3D).",
        ]
        lines += [f"# NOTE: {n}" for n in self.notes]
        for block in self.blocks:
            first, *more = block.comment.split("\n")  # every comment line stays a comment
            lines += ["", f"# --- {block.effect}: {first}", *(f"# {m}" for m in more)]
            lines += block.commands
        return "\n".join(lines) + "\n"


def fmt(x: float) -> str:
    """Numbers in decks: full precision, no trailing noise."""
    return f"{x:.12g}"
