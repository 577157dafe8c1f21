"""LAMMPS deck writer: the scene's effects, each contributing its commands only when present.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (``units lj``). The
blocks every deck has (box and particles, groups, pair contact, sampling, integrator, the
bare deck's run commands) are written here; each physical effect the scene calls for adds
its own blocks through LAMMPS's translation table (:mod:`.effects`), and what LAMMPS cannot
express is refused by :func:`check_scene` before anything is written or started.
"""

from __future__ import annotations

from pathlib import Path

from ....contact.pilot import PilotResult
from ....contact.stiffness import ContactSetup, contact_setup
from ....effects import apply_effects, check_effects
from ....effects.bumps import bump_rows
from ....errors import UnsupportedByEngine
from ....scene import Scene
from ....scene.initial import InitialState, build_initial_state
from .base import Block, Deck
from .contact import pair_block
from .effects import TRANSLATIONS, DeckDraft
from .output import run_block, sampling_block
from .system import DATA_FILE, data_file, groups_block, integrate_block, setup_block

__all__ = ["Block", "Deck", "build_deck", "check_scene", "write_deck"]


def check_scene(scene: Scene, pilot: PilotResult | None = None) -> ContactSetup:
    """Refuse what LAMMPS cannot run (``UnsupportedByEngine``): collision-counted runs and
    effects without a LAMMPS translation; return the soft-contact set-up (automatic k_n from
    ``pilot`` when given, else estimated: ``contact_setup``)."""
    if scene.run.unit != "time":
        raise UnsupportedByEngine("lammps", "run.unit", scene.run.unit,
                                  "soft contacts have no collision count: give times")
    check_effects(scene, "lammps", TRANSLATIONS)
    return contact_setup(scene, "lammps", pilot)


def build_deck(scene: Scene, state: InitialState | None = None, dump: str | None = None,
               setup: ContactSetup | None = None, data: bool = True) -> Deck:
    """Compose the deck; raises ``UnsupportedByEngine`` for effects LAMMPS cannot express.
    ``data=False``: without the data file (no initial state is built): a run creates its
    atoms from memory (``LammpsSession.create_atoms``)."""
    setup = setup or check_scene(scene)
    draft = DeckDraft(setup)
    apply_effects(scene, "lammps", TRANSLATIONS, draft)
    bumps = bump_rows(scene)
    blocks: list[Block] = [
        setup_block(scene, bumps),
        groups_block(scene, bumps),
        pair_block(scene, setup),
        *draft.physics,
        sampling_block(scene, setup),
        integrate_block(scene, setup),
        *draft.final,
        run_block(scene, setup, dump),
    ]
    deck = Deck(blocks, notes=draft.notes)
    if data:
        deck.files[DATA_FILE] = data_file(scene, state or build_initial_state(scene), bumps)
    return deck


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
