"""The physical effects a scene can call for, each declared once, and the one place where an
engine's ability to express them is checked.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.

An :class:`Effect` says when a scene calls for it (``present``) and which scene field asks
for it (``asked_by``, for error messages). It says nothing about engines: each engine
backend carries a table ``{effect name: Translation | Cannot}`` (LAMMPS's granular
sub-model registry is the model). A ``Translation`` contributes the effect to the engine
(deck commands, core options) and may refuse parameter values the engine cannot express; a
``Cannot`` says what the engine offers instead. :func:`check_effects` walks the effects a
scene calls for and refuses, before anything starts, the first one the engine cannot
express (``UnsupportedByEngine`` naming the engine, the field, the value and the reason);
:func:`apply_effects` then lets each present effect contribute, and only those. Adding an
engine means writing its table; a table that forgets an effect is caught by the tests
(``tests/test_effects.py``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from ..errors import UnsupportedByEngine
from ..scene import Scene

__all__ = ["EFFECTS", "LATTICE_ONLY", "Cannot", "Effect", "Translation", "apply_effects",
           "check_effects", "present_effects"]


@dataclass(frozen=True)
class Effect:
    """One physical effect: ``present(scene)`` and ``asked_by(scene)`` → (field, value)."""

    name: str
    description: str
    present: Callable[[Scene], bool]
    asked_by: Callable[[Scene], tuple[str, Any]]


@dataclass(frozen=True)
class Translation:
    """How one engine expresses one effect: ``apply(scene, target)`` contributes it to the
    engine's input (None: expressed elsewhere, say where in ``how``); ``check(scene)``
    raises ``UnsupportedByEngine`` for parameter values the engine cannot express."""

    apply: Callable[[Scene, Any], None] | None = None
    check: Callable[[Scene], None] | None = None
    how: str = ""


@dataclass(frozen=True)
class Cannot:
    """The engine cannot express the effect at all; ``reason`` says what to use instead."""

    reason: str


def _walls(scene: Scene, test: Callable[[Any], bool]) -> list:
    return [w for w in scene.walls if test(w)]


def _first_wall(scene: Scene, test: Callable[[Any], bool], field: str) -> tuple[str, Any]:
    wall = next(w for w in scene.walls if test(w))
    value: Any = wall
    for part in field.split("."):
        value = getattr(value, part)
    return f"walls[{wall.side}].{field}", value


def _rough(rule: Any) -> bool:
    return rule.model not in ("smooth", "campbell-noslip")


#: what every off-lattice engine says to a lattice scene
LATTICE_ONLY = Cannot("a [lattice] scene is Gutt's lattice grain dynamics: grains on the nodes "
                      "of a triangular lattice with integer offsets, moved by whole lattice "
                      "steps and colliding along the lattice bonds only; an off-lattice engine "
                      "would simulate different physics, so only --engine lgd runs it (for "
                      "the same flow off the lattice, write an ordinary scene)")

#: every effect, in the order engines apply them (a LAMMPS deck lists its blocks this way)
EFFECTS: dict[str, Effect] = {e.name: e for e in (
    Effect("lattice", "Gutt's lattice grain dynamics ([lattice]: grains on lattice nodes)",
           lambda s: s.lattice is not None,
           lambda s: ("lattice", f"nxt = {s.lattice.nxt}, nyt = {s.lattice.nyt}")),
    Effect("planar", "2D discs confined to the plane",
           lambda s: s.dimension == 2, lambda s: ("dimension", s.dimension)),
    Effect("rotation", "tangential contact forces that change spins (rough, β or Coulomb "
           "rules)",
           lambda s: s.rotation_matters,
           lambda s: ("contact.tangential.model", s.contact.tangential.model)
           if _rough(s.contact.tangential)
           else _first_wall(s, lambda w: _rough(w.tangential), "tangential.model")),
    Effect("restitution-law", "a velocity-dependent normal restitution",
           lambda s: s.contact.law.model != "constant",
           lambda s: ("contact.law.model", s.contact.law.model)),
    Effect("walls", "flat walls normal to y",
           lambda s: bool(s.walls), lambda s: ("walls", [w.side for w in s.walls])),
    Effect("moving-walls", "walls sliding along x",
           lambda s: bool(_walls(s, lambda w: w.velocity != 0.0)),
           lambda s: _first_wall(s, lambda w: w.velocity != 0.0, "velocity")),
    Effect("noslip-walls", "Campbell's no-slip wall rule (the centre takes the wall's "
           "tangential velocity, the spin is unchanged)",
           lambda s: bool(_walls(s, lambda w: w.tangential.model == "campbell-noslip")),
           lambda s: ("walls.tangential.model", "campbell-noslip")),
    Effect("servo", "Campbell's normal-stress servo on the walls",
           lambda s: bool(_walls(s, lambda w: w.servo is not None)),
           lambda s: _first_wall(s, lambda w: w.servo is not None, "servo.normal_stress")),
    Effect("bumpy-walls", "walls roughened by fixed bumps",
           lambda s: bool(_walls(s, lambda w: w.kind == "bumpy")),
           lambda s: _first_wall(s, lambda w: w.kind == "bumpy", "kind")),
    Effect("gravity", "a body force",
           lambda s: s.gravity is not None,
           lambda s: ("gravity", s.gravity.model_dump(exclude_none=True))),
    Effect("lees-edwards", "Lees–Edwards simple shear (sliding periodic images along y)",
           lambda s: s.shear is not None, lambda s: ("shear.rate", s.shear.rate)),
)}


def present_effects(scene: Scene) -> list[Effect]:
    """The effects ``scene`` calls for, in registry order."""
    return [e for e in EFFECTS.values() if e.present(scene)]


def check_effects(scene: Scene, engine: str,
                  table: Mapping[str, Translation | Cannot]) -> list[Effect]:
    """Refuse (``UnsupportedByEngine``) the first effect of ``scene`` that ``engine``
    cannot express, per its ``table``; return the present effects."""
    present = present_effects(scene)
    for effect in present:
        entry = table.get(effect.name)
        if not isinstance(entry, Translation):
            field, value = effect.asked_by(scene)
            reason = entry.reason if isinstance(entry, Cannot) else \
                f"the {engine} engine cannot express {effect.description}"
            raise UnsupportedByEngine(engine, field, value, reason)
        if entry.check is not None:
            entry.check(scene)
    return present


def apply_effects(scene: Scene, engine: str, table: Mapping[str, Translation | Cannot],
                  target: Any) -> list[Effect]:
    """Check every present effect, then let each contribute to ``target`` (the engine's
    input under construction); absent effects contribute nothing."""
    present = check_effects(scene, engine, table)
    for effect in present:
        apply = table[effect.name].apply
        if apply is not None:
            apply(scene, target)
    return present
