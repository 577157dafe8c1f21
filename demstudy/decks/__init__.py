"""LAMMPS deck writer: the scene's effects, each contributing its commands only when present.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (``units lj``).
"""

from __future__ import annotations

from pathlib import Path

from ..scene import Scene
from ..scene.initial import InitialState, build_initial_state
from .base import Block, Deck, UnsupportedByEngine
from .bumps import bump_rows
from .contact import ContactSetup, contact_setup, pair_block
from .output import run_block, sampling_block
from .servo import has_servo, region_wall_block
from .system import DATA_FILE, data_file, groups_block, setup_block
from .walls import gravity_block, integrate_block, shear_block, wall_block

__all__ = ["Block", "Deck", "UnsupportedByEngine", "build_deck", "write_deck"]


def build_deck(scene: Scene, state: InitialState | None = None, dump: str | None = None,
               setup: ContactSetup | None = None) -> Deck:
    """Compose the deck; raises ``UnsupportedByEngine`` for effects LAMMPS cannot express."""
    if scene.run.unit != "time":
        raise UnsupportedByEngine("lammps", "run.unit", scene.run.unit,
                                  "soft contacts have no collision count: give times")
    setup = setup or contact_setup(scene)
    state = state or build_initial_state(scene)
    bumps = bump_rows(scene)
    blocks: list[Block | None] = [
        setup_block(scene, bumps),
        groups_block(bumps),
        pair_block(scene, setup),
        *[_wall(scene, wall, setup) for wall in scene.walls],
        gravity_block(scene),
        shear_block(scene),
        sampling_block(scene, setup),
        *integrate_block(scene, setup),
        run_block(scene, setup, dump),
    ]
    deck = Deck([b for b in blocks if b is not None])
    deck.files[DATA_FILE] = data_file(scene, state, bumps)
    if scene.contact.tangential.model in ("beta", "rough") or any(
        w.tangential.model in ("beta", "rough") for w in scene.walls
    ):
        deck.notes.append(
            "constant tangential restitution beta is realised by an uncapped tangential spring "
            "(beta = -cos(omega_t t_c)); exact for binary collisions, approximate for lasting "
            "contacts"
        )
    if has_servo(scene):
        deck.notes.append(
            "servo walls are plane regions moved from Python between run segments (Campbell's "
            "rule every servo interval); the periodic width follows the gap by moving the "
            "box boundaries (fix deform x variable); in a bare lmp run the walls stay fixed"
        )
    if bumps:
        deck.notes.append("bumpy walls: bumps are particles 1e6 times heavier than m, moved "
                          "with the wall by fix move (m_eff = m to 1 part in 1e6)")
    return deck


def _wall(scene: Scene, wall, setup: ContactSetup) -> Block:
    if not has_servo(scene):
        return wall_block(scene, wall, setup)
    if wall.kind == "bumpy":
        raise UnsupportedByEngine("lammps", f"walls[{wall.side}].kind", "bumpy",
                                  "bumpy walls cannot be combined with the servo in LAMMPS")
    return region_wall_block(scene, wall, setup)


def write_deck(scene: Scene, directory: str | Path, dump: str | None = None) -> Path:
    """Write ``deck.in`` and its data file into ``directory``; return the deck path."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    deck = build_deck(scene, dump=dump)
    for name, content in deck.files.items():
        (directory / name).write_text(content)
    path = directory / "deck.in"
    path.write_text(deck.render(scene.meta.name))
    return path
