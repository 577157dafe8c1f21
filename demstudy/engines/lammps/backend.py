"""``--engine lammps``: the scene's deck driven through LAMMPS's Python interface, as a backend
of the simulation loop.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (``units lj``). The deck
(:mod:`.deck`) is written into the work folder and issued command by command; the loop
advances it in segments of one sample interval (``run N pre no post no``), gathering the
particles in memory at each sample. Wall forces are averaged over every step of a segment
(``fix ave/time``) and accumulated as impulses. The interaction stress is the contact stress
(per-bin sums of f_i ⊗ (r_i − r_j) over this sample's contacts, summed over the MPI ranks).
Servo walls are plane regions whose motion variables are redefined before the segment after
each update (LAMMPS then initialises again). Checkpoints are restart files plus the per-atom
forces and torques of that step, which restart files do not hold: a resumed run continues the
uninterrupted one to round-off.
"""

from __future__ import annotations

import math
import os
import sys
from pathlib import Path

import numpy as np

from ... import __version__
from ...analysis.base import bin_edges
from ...analysis.stress import branch_sums
from ...contact.health import contact_sample, impact_speeds
from ...effects.bumps import bump_rows
from ...errors import EngineError
from ...io.checksum import file_digest, verify_file
from ...io.frames import Frame
from ...scene import Scene
from ...scene.initial import build_initial_state
from ..backend import BackendBase, Capabilities, Needs, frame_energies, frame_mass
from ..peculiar import peculiar_observables
from .deck import build_deck, check_scene, write_deck
from .deck.effects import TRANSLATIONS, wall_fix_id, wall_force_sources
from .deck.output import (
    HEALTH_COLUMNS,
    HEALTH_IDS,
    HEALTH_PAIRS,
    STRESS_COLUMNS,
    STRESS_IDS,
    STRESS_PAIRS,
    VIRIAL_PRESSURE,
    WALL_FORCES,
    sample_steps,
)
from .deck.system import DATA_FILE, data_header, data_rows
from .library import mpirun_executable
from .session import LammpsSession, any_rank, quoted

__all__ = ["LammpsBackend"]

BOX_FILE = "initial-box.data"  # the data file's header alone: the box, no atoms
# the restart file of a checkpoint is named by its step and the checkpoint names it: the
# checkpoint's atomic rename commits the pair, so a cut-off checkpoint leaves the previous pair
CHECKPOINT_RESTARTS = "checkpoint-*.restart"


def servo_commands(servo, scene: Scene, t: float) -> list[str]:
    """The commands that realise the servo's wall motion from time ``t`` on: each region
    wall's displacement variables and, with ``scale_width``, the box's x boundaries."""
    cmds = []
    for side, wall in servo.walls.items():
        fid = wall_fix_id(side)
        y0 = wall.y - scene.wall_position(side)
        cmds.append(f"variable {fid}_dx equal {wall.x:.17g}+{wall.vx:.17g}*(time-{t:.17g})")
        cmds.append(f"variable {fid}_dy equal {y0:.17g}+{wall.vy:.17g}*(time-{t:.17g})")
    if servo.scale_width:
        # the periodic boundaries move (no remap): images approach at the width rate; a
        # variable counted from now, since fix deform takes the box at each init
        rate = servo.width_rate
        cmds += [f"variable servo_dw equal {rate:.17g}*(time-{t:.17g})",
                 f"variable servo_dw_rate equal {rate:.17g}",
                 "fix servo_width all deform 1 x variable v_servo_dw v_servo_dw_rate remap none"]
    return cmds


class LammpsBackend(BackendBase):
    """Soft contacts in LAMMPS (see the module docstring and docs/lammps-engine.md)."""

    name = "lammps"
    kind = "soft-contact"
    capabilities = Capabilities(time_step=True, soft_contact=True, stress="contact", mpi=True,
                                dump=True,
                                inputs=True)
    translations = TRANSLATIONS
    #: False: the deck's data file is written and read (``read_data``), as ``lmp -in``
    #: would; the tests compare the two set-ups
    state_from_memory = True
    version = f"demstudy {__version__} (lammps checkpoint 6)"  # 6: restart checksum

    @classmethod
    def check(cls, scene: Scene, options) -> None:
        check_scene(scene, getattr(options, "pilot", None))

    @staticmethod
    def launcher(np_ranks: int) -> list[str]:
        return [mpirun_executable(), "-np", str(np_ranks)]

    @staticmethod
    def fork_safe() -> bool:
        """Not once LAMMPS was imported in this process: its MPI runtime may be initialised
        here, and MPI cannot be initialised again in a fork."""
        return "lammps" not in sys.modules

    @staticmethod
    def log_file(workdir: Path) -> Path:
        return workdir / "log.lammps"

    @classmethod
    def write_inputs(cls, scene: Scene, folder: Path, dump: str | None = None) -> Path:
        return write_deck(scene, folder, dump=dump)

    @staticmethod
    def run_inputs_hint(path: Path) -> str:
        return f"lmp -in {path.name}"

    @classmethod
    def calibrate(cls, **settings) -> list:
        from .calibrate import calibrate_case

        return calibrate_case(**settings)

    def __init__(self, scene: Scene, options, workdir: Path):
        super().__init__(scene, options, workdir)
        self.contact = check_scene(scene, getattr(options, "pilot", None))
        self.time_step = self.contact.timestep
        self.n_sample = sample_steps(scene, self.time_step)
        self.dump = Path(options.dump).resolve() if options.dump else None
        self.sources = wall_force_sources(scene)
        self.session: LammpsSession | None = None
        self.nprocs = 1
        self._mobile: np.ndarray | None = None
        self._frame: Frame | None = None
        self._all: tuple[np.ndarray, ...] | None = None  # (x, radius, v) of every atom
        self._health_keys: np.ndarray | None = None  # the previous sample's touching pairs
        self._initialise = False  # the wall motion changed: LAMMPS sets up again
        self.servo = None

    # -- set-up ---------------------------------------------------------------------------
    def setup(self, needs: Needs, saved: dict | None, servo) -> None:
        scene, workdir = self.scene, self.workdir
        self.servo = servo
        self.step = 0
        self.impulse = {w.side: np.zeros(3) for w in scene.walls}
        self.edges = None
        if needs.stress_bins is not None:
            self.set_stress_bins(*needs.stress_bins)
        # a fresh run creates its atoms from memory (no data file is formatted and parsed);
        # a resumed one reads its restart file
        memory = saved is None and self.state_from_memory
        self.deck = build_deck(scene, setup=self.contact,
                               data=saved is None and not self.state_from_memory)
        workdir.mkdir(parents=True, exist_ok=True)
        files = dict(self.deck.files)
        if memory:  # the data file's header alone: the box, no atoms (read before the atoms)
            files[BOX_FILE] = "\n".join(data_header(scene, 0)) + "\n"
        for name, content in files.items():  # before LAMMPS starts (every rank writes them)
            (workdir / name).write_text(content)
        (workdir / "deck.in").write_text(self.deck.render(scene.meta.name))
        restart = None
        if saved is not None:
            self._same_contacts(saved["contact"])
            dump = str(self.dump) if self.dump else None
            if saved["dump"] != dump:
                raise EngineError(f"--resume: the run started with --dump {saved['dump']}, "
                                  f"this call has {dump}: the dump continues only in its file")
            restart = workdir / saved["restart"]
            if not restart.exists():
                raise EngineError(f"--resume: {restart}, the restart file of the checkpoint, "
                                  "is missing")
            # a damaged restart file made read_restart spin for minutes, past --wall-limit
            verify_file(restart, saved["restart_sha256"])
        self.session = session = LammpsSession(workdir)
        self.rank, self.nprocs = session.rank, session.nprocs
        self.n_particles = scene.n_particles
        rows = None
        if memory:
            rows = data_rows(scene, build_initial_state(scene), bump_rows(scene))
        self._issue_deck(restart, rows)
        if saved is None:
            if self.dump is not None and self.rank == 0:
                self.dump.unlink(missing_ok=True)
            session.command("run 0 post no")
            return
        step = session.lmp.extract_global("ntimestep")
        if step != saved["step"]:  # a safety net: the checkpoint names its own restart file
            raise EngineError(f"--resume: {restart} holds step {step}, the checkpoint's state "
                              f"step {saved['step']}; remove {workdir} to start afresh")
        self.step, self.impulse = saved["step"], saved["impulse"]
        self.edges = saved["edges"]  # servo runs re-bin where production starts
        if self.dump is not None and self.rank == 0 and self.dump.exists():
            os.truncate(self.dump, saved["dump_size"])  # drop frames after the checkpoint
        self._set_up_again(saved["forces"])

    def _same_contacts(self, saved: dict) -> None:
        """Refuse to continue a checkpoint whose k_n or dt differ from this run's beyond
        round-off (the pilot measured again, e.g. its cache gone on another node: the run
        would change its contacts halfway). ``run_scene`` normally passes the checkpoint's
        own pilot (``checkpoint.saved_pilot``), so this is a safety net."""
        now = self.contact
        if all(math.isclose(saved[k], v, rel_tol=1e-9)
               for k, v in (("kn", now.kn), ("timestep", now.timestep))):
            return
        remedy = ("give soft.stiffness (a new run), or restore the pilot's cache "
                  "($XDG_CACHE_HOME/demstudy/pilot) and resume without passing a pilot")
        raise EngineError(
            f"--resume: the checkpoint ran with k_n = {saved['kn']:.9g}, dt = "
            f"{saved['timestep']:.9g} (stiffness_basis = {saved['stiffness_basis']}), this "
            f"run has k_n = {now.kn:.9g}, dt = {now.timestep:.9g} ({now.basis}): continuing "
            f"would change the contacts mid-run; {remedy}")

    def _issue_deck(self, restart: Path | None,
                    rows: tuple[np.ndarray, np.ndarray] | None = None) -> None:
        """The deck's set-up and physics commands. ``rows``: the initial state as the data
        file's Atoms and Velocities rows (``deck.system.data_rows``): the box from the data
        file's header alone (``BOX_FILE``), the atoms through the library interface, in place
        of the deck's ``read_data`` (~0.2 s less on 30 000 spheres; the same state, bit for
        bit)."""
        session = self.session
        for cmd in self.deck.commands("setup"):
            if cmd.startswith("read_data") and rows is not None and restart is None:
                session.command(f"read_data {quoted(self.workdir / BOX_FILE)}")
                session.create_atoms(*rows)
                continue
            if cmd.startswith("read_data"):
                cmd = (f"read_restart {quoted(restart)}" if restart
                       else f"read_data {quoted(self.workdir / DATA_FILE)}")
            elif restart and cmd.startswith("set "):
                continue  # masses are in the restart file
            session.command(cmd)
        for cmd in self.deck.commands("physics"):
            session.command(cmd)
        session.command("thermo 0")

    def _reanchor(self) -> None:
        """Re-issue the time-anchored variables before LAMMPS initialises again.

        At every initialisation (``run … pre yes``, ``write_restart``, ``read_restart``) fix
        deform takes the current box as its start, so the Lees–Edwards tilt and the servo's
        width change must count from that moment; the servo's walls are re-anchored too."""
        t = self.time
        if self.scene.shear is not None:
            self.session.command(f"variable lees_edwards_t0 equal {t:.17g}")
        if self.servo is not None:
            self.servo.advance(t)
            self._apply_servo(t)

    def _apply_servo(self, t: float) -> None:
        for cmd in servo_commands(self.servo, self.scene, t):
            self.session.command(cmd)

    def _set_up_again(self, forces: dict[str, np.ndarray]) -> None:
        """LAMMPS after ``write_restart`` or ``read_restart``: re-anchor the variables, set up
        (``run 0``) and put back the forces and torques of the checkpoint's step. The set-up
        would otherwise have recomputed them from full-step velocities, changing every
        velocity-dependent (damping) force for one step; with them restored, a checkpoint
        leaves the run as it was and a resumed run continues as the uninterrupted one."""
        self._reanchor()
        self.session.command("run 0 post no")
        for name, value in forces.items():
            self.session.scatter(name, value)

    # -- advancing ------------------------------------------------------------------------
    @property
    def time(self) -> float:
        return self.step * self.time_step

    def advance(self, t: float, collisions: int = 0, stop=None) -> bool:
        """One segment to time ``t`` (one sample interval: the wall-force average covers it)."""
        n = round(t / self.time_step) - self.step
        if n != self.n_sample:
            raise EngineError(f"LAMMPS advances one sample interval ({self.n_sample} steps) at "
                              f"a time, not {n}")
        if self._initialise:
            self._reanchor()
        self.session.command(f"run {n} pre {'yes' if self._initialise else 'no'} post no")
        self._initialise = False
        self.step += n
        if self.sources:
            means = self.session.fix_vector(WALL_FORCES, 3 * len(self.sources)).reshape(-1, 3)
            for (side, _compute, sign), row in zip(self.sources, means, strict=True):
                self.impulse[side] = self.impulse[side] + sign * row * (n * self.time_step)
        return True

    def move_walls(self, servo) -> None:
        self._initialise = True  # new wall motion: re-anchor, LAMMPS sets up again

    # -- sampling -------------------------------------------------------------------------
    def frame(self) -> Frame:
        """The particles now, gathered from every rank (collective), ordered by atom ID."""
        if self._frame is not None and self._frame.time == self.time:
            return self._frame
        session, dim = self.session, self.scene.dimension
        if self._mobile is None:  # atom types never change: gather them once
            self._mobile = session.gather("type", 1, integer=True) == 1
        mobile = self._mobile
        x_all, r_all = session.gather("x", 3), session.gather("radius", 1)
        v_all = session.gather("v", 3)
        self._all = (x_all, r_all, v_all)
        omega = session.gather("omega", 3)[mobile]
        boxlo, boxhi, xy, *_ = session.lmp.extract_box()
        self._frame = Frame(time=self.time, box_lo=np.array(boxlo[:dim]),
                            box_hi=np.array(boxhi[:dim]), position=x_all[mobile, :dim],
                            velocity=v_all[mobile, :dim],
                            angular_velocity=omega[:, 2:3] if dim == 2 else omega,
                            radius=r_all[mobile], tilt=float(xy))
        return self._frame

    def observe(self, production: bool) -> dict:
        frame = self.frame()  # collective: every rank gathers
        if production and self.dump is not None:  # collective too
            self.session.command(
                f"write_dump mobile custom {quoted(self.dump)} id type radius x y z vx vy vz "
                "omegax omegay omegaz modify sort id append yes format float %.17g")
        scene = self.scene
        mass = frame_mass(frame)
        values = frame_energies(frame, scene.inertia_k)
        if scene.y_periodic:
            # the mean flow (Lees–Edwards streaming profile) is no pressure: peculiar part
            # from the velocities, contact part from LAMMPS's virial at this step
            rate = scene.shear.rate if scene.shear is not None else 0.0
            peculiar = peculiar_observables(frame.position, frame.velocity, mass, rate)
            volume = float(np.prod(frame.box_hi - frame.box_lo))
            values.update(peculiar)
            values["pressure"] = (2 * peculiar["peculiar_kinetic_energy"]
                                  / (scene.dimension * volume)
                                  + self.session.compute_scalar(VIRIAL_PRESSURE))
        return values

    def wall_impulse(self) -> dict[str, np.ndarray]:
        return {side: value.copy() for side, value in self.impulse.items()}

    def width(self) -> float:
        return float(self.session.box_lengths()[0])

    def tilt(self) -> float:
        return self.frame().tilt

    def set_stress_bins(self, lo: float, hi: float, n_bins: int) -> None:
        self.edges = bin_edges(lo, hi, (hi - lo) / n_bins)

    def stress_sums(self) -> np.ndarray:
        """Per-bin sums of f_i ⊗ (r_i − r_j) over the contacts of every rank (collective):
        pairs from ``compute pair/local``, wall contacts from the wall fixes' per-atom arrays
        (branch to a bump's or a wall's contact point)."""
        session, dim = self.session, self.scene.dimension
        self.frame()  # the positions of every atom, this step
        x_all, r_all, _v = self._all
        mobile = self._mobile
        rows = session.local_array(STRESS_PAIRS, STRESS_COLUMNS)
        ids = session.local_array(STRESS_IDS, 2).astype(np.int64) - 1
        if ids.shape[0] != rows.shape[0]:
            raise EngineError(f"{STRESS_PAIRS} and {STRESS_IDS} disagree on the contacts")
        force = rows[:, 0:3] + rows[:, 3:6]  # on i: normal + tangential
        sep = rows[:, 6:9]  # x_i - x_j (minimum image)
        i, j = ids[:, 0], ids[:, 1]
        dist = np.linalg.norm(sep, axis=1)
        both = mobile[i] & mobile[j]
        ends = [(x_all[i[both], 1], force[both], sep[both])]
        for a, b, sign in ((i, j, 1.0), (j, i, -1.0)):  # mobile a, bump b
            sel = mobile[a] & ~mobile[b] & (dist > 0)
            reach = r_all[a[sel]] - 0.5 * (r_all[a[sel]] + r_all[b[sel]] - dist[sel])
            unit = sign * sep[sel] / dist[sel, None]
            ends.append((x_all[a[sel], 1], sign * force[sel], unit * reach[:, None]))
        local_x = None
        for wall in self.scene.walls:
            contacts = session.fix_atom_array(wall_fix_id(wall.side))
            if contacts.size == 0:
                continue
            if local_x is None:
                local_x = session.local_positions()
            on = contacts[:, 0] != 0
            ends.append((local_x[on, 1], contacts[on, 1:4], local_x[on] - contacts[on, 4:7]))
        y = np.concatenate([e[0] for e in ends])
        f = np.concatenate([e[1] for e in ends])[:, :dim]
        br = np.concatenate([e[2] for e in ends])[:, :dim]
        period = self.scene.box.size[1] if self.scene.y_periodic else 0.0
        sums = branch_sums(y, y - br[:, 1], f[:, :, None] * br[:, None, :], self.edges, period)
        return session.sum_ranks(sums)

    def health_sample(self) -> dict[str, float]:
        """The contacts touching now, for :mod:`demstudy.contact.health` (collective): pairs
        from ``compute pair/local`` gathered from every rank, wall contacts from the wall
        fixes' per-atom arrays (overlap = radius − distance to the wall's contact point); a
        bump counts as a wall. Impact speeds are reconstructed for mobile pairs only."""
        session, scene = self.session, self.scene
        self.frame()
        x_all, r_all, v_all = self._all
        mobile = self._mobile
        index = np.cumsum(mobile) - 1  # atom index -> mobile particle index
        local = session.local_array(HEALTH_PAIRS, HEALTH_COLUMNS)
        ids = session.local_array(HEALTH_IDS, 2)
        if ids.shape[0] != local.shape[0]:
            raise EngineError(f"{HEALTH_PAIRS} and {HEALTH_IDS} disagree on the contacts")
        rows = session.gather_rows(np.hstack([local, ids]))
        dist, sep = rows[:, 0], rows[:, 1:4]
        i, j = rows[:, 4].astype(np.int64) - 1, rows[:, 5].astype(np.int64) - 1
        overlap = r_all[i] + r_all[j] - dist
        both = mobile[i] & mobile[j]
        one = mobile[i] != mobile[j]  # a mobile particle on a bump
        walls = [(np.where(mobile[i[one]], i[one], j[one]), overlap[one])]
        i, j, sep, dist, pair_overlap = i[both], j[both], sep[both], dist[both], overlap[both]
        dv = v_all[i] - v_all[j]
        if scene.shear is not None:  # j's Lees–Edwards image moves by n γ̇ L_y along x
            ly = scene.box.size[1]
            image = np.round((x_all[i, 1] - x_all[j, 1] - sep[:, 1]) / ly)
            dv[:, 0] -= image * scene.shear.rate * ly
        vn = np.einsum("ij,ij->i", dv, sep) / np.maximum(dist, 1e-300)
        mass = (2 * r_all) ** scene.dimension  # m = d^dim (frame_mass)
        speeds = impact_speeds(vn, np.maximum(pair_overlap, 0.0), self.contact.kn,
                               mass[i] * mass[j] / (mass[i] + mass[j]),
                               r_all[i] * r_all[j] / (r_all[i] + r_all[j]), scene.soft.model)
        if scene.walls:
            nlocal = int(session.lmp.extract_setting("nlocal"))
            atom_ids = np.array(session.lmp.numpy.extract_atom("id")[:nlocal], dtype=np.int64)
            local_x = session.local_positions()
            found = []
            for wall in scene.walls:
                contacts = session.fix_atom_array(wall_fix_id(wall.side))
                if contacts.size == 0:
                    continue
                on = contacts[:, 0] != 0
                gap = np.linalg.norm(local_x[on] - contacts[on, 4:7], axis=1)
                found.append(np.column_stack([atom_ids[on] - 1, contacts[on, 7] - gap]))
            wall_rows = session.gather_rows(np.vstack(found) if found else np.zeros((0, 2)))
            walls.append((wall_rows[:, 0].astype(np.int64), wall_rows[:, 1]))
        wall_i = np.concatenate([w[0] for w in walls])
        values, self._health_keys = contact_sample(
            int(mobile.sum()), index[i], index[j], pair_overlap, index[wall_i],
            np.concatenate([w[1] for w in walls]), speeds, self._health_keys)
        return values

    # -- checkpoints, MPI, end ------------------------------------------------------------
    def get_state(self) -> dict:
        """Write the restart file (collective) and return what the checkpoint needs besides
        it: the per-atom forces and torques of this step (velocity Verlet's, from half-step
        velocities), unless LAMMPS sets up again here anyway (a servo update)."""
        session = self.session
        resetup = self._initialise
        forces = ({} if resetup else
                  {name: session.gather(name, 3).copy() for name in ("f", "torque")})
        restart = self.workdir / f"checkpoint-{self.step}.restart"
        session.command(f"write_restart {quoted(restart)}")
        # rank 0 writes the checkpoint; write_restart has closed the file on return
        digest = file_digest(restart) if self.rank == 0 else ""
        dump_size = 0
        if self.dump is not None and self.rank == 0 and self.dump.exists():
            dump_size = self.dump.stat().st_size
        if not resetup:  # write_restart re-initialised LAMMPS
            self._set_up_again(forces)
        return {"restart": restart.name, "restart_sha256": digest, "forces": forces,
                "step": self.step,
                "impulse": self.wall_impulse(), "edges": self.edges,
                "dump": str(self.dump) if self.dump else None, "dump_size": dump_size,
                # k_n, dt, basis and the pilot: a resume continues with the same contacts
                "contact": self.contact.attrs()}

    def cleanup(self, keep: dict | None) -> None:
        if self.rank != 0:
            return
        for old in self.workdir.glob(CHECKPOINT_RESTARTS):
            if keep is None or old.name != keep["restart"]:
                old.unlink(missing_ok=True)

    def agree(self, flag: bool) -> bool:
        return any_rank(flag, self.nprocs)  # also after close: the loop's last barrier

    def result_attrs(self) -> dict:
        return {**self.contact.attrs(),
                "engine_version": f"LAMMPS {self.session.lmp.version()}",
                "timestep": self.time_step, "deck": self.deck.render(self.scene.meta.name),
                "approximations": "\n".join(self.deck.notes)}

    def close(self) -> None:
        if self.session is not None:
            self.session.close()
            self.session = None
