"""The LAMMPS engine's entry point (in a child process or on MPI ranks via ``engines.child``).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (``units lj``).
"""

from __future__ import annotations

from pathlib import Path

from ...decks import build_deck
from ...decks.contact import contact_setup
from ...scene import Scene
from ..base import RunOptions, work_folder
from ..child import in_worker, launch_child
from .driver import Driver


class LammpsEngine:
    """``run(scene, options)``: the scene's deck, driven through LAMMPS's Python interface."""

    name = "lammps"

    def run(self, scene: Scene, options: RunOptions) -> Path:
        if (options.np > 1 or options.isolate) and not in_worker():
            build_deck(scene)  # refuse unsupported scenes before launching anything
            return launch_child(self.name, scene, options)
        setup = contact_setup(scene)  # raises UnsupportedByEngine before LAMMPS starts
        deck = build_deck(scene, setup=setup)  # so does every effect LAMMPS cannot express
        out = Path(options.out).resolve()
        workdir = work_folder(out, self.name)
        workdir.mkdir(parents=True, exist_ok=True)
        for name, content in deck.files.items():
            (workdir / name).write_text(content)
        (workdir / "deck.in").write_text(deck.render(scene.meta.name))
        return Driver(scene, deck, setup.timestep, workdir, out, options).run()
