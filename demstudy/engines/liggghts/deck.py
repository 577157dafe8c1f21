"""The LIGGGHTS deck of a scene: box, particles, contacts, walls, body force, integration.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (``units lj``: LIGGGHTS's
stiffness and damping inputs are then taken as they are, ``nktv2p`` = 1).

The contact is ``pair_style gran model hooke/stiffness tangential history``: demstudy picks
k_n and the time step (:mod:`demstudy.contact.stiffness`, as for LAMMPS) and maps (e, β | μ)
to the per-type-pair matrices LIGGGHTS reads from ``fix property/global``:

* ``kn`` = k_n; ``gamman`` = η_n / m_eff with η_n = 2 ζ(e) √(m_eff k_n) (LIGGGHTS multiplies
  by the contact's m_eff unless ``absolute_damping``, which its walls do not accept), so a
  Hooke contact restitutes e exactly; e is the time-step-compensated one LAMMPS gets;
* ``kt`` = k_t of the tangential rule, ``gammat`` = x_t · gamman (the damped Walton copy of
  a Coulomb rule, else 0), ``coefficientFriction`` = μ (1e20 for an uncapped β spring).

Atom types: 1 the particles; each wall a type of its own (2, 3 in ``scene.walls`` order), the
``primitive type`` of its ``fix wall/gran``, so that its contact has its own e_w, β_w and
m_eff = m; a bumpy wall's bumps are atoms of that same type, 1e6 times heavier (m_eff = m to
1e-6), moved with the wall by ``fix move``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...contact.mapping import ContactParameters, damping_ratio
from ...contact.stiffness import ContactSetup
from ...effects import LATTICE_ONLY, Cannot, Translation, apply_effects
from ...effects.bumps import bump_padding, bump_rows
from ...errors import EngineError, UnsupportedByEngine
from ...scene import Scene
from ...scene.initial import InitialState
from ..lammps.deck.base import fmt
from ..lammps.deck.system import format_rows

__all__ = ["DATA_FILE", "NEIGHBOUR_COMMANDS", "TRANSLATIONS", "LiggghtsDeck", "build_deck",
           "data_text", "run_commands", "state_rows", "wall_command", "write_deck"]

DATA_FILE = "initial.data"
DENSITY = {2: 4 / math.pi, 3: 6 / math.pi}  # m = 1 for d = 1 (per area in 2D)
BUMP_MASS_FACTOR = 1e6
UNCAPPED_MU = 1e20  # an uncapped β spring
WALL_FORCES = "wall_forces"  # fix ave/time of every wall's summed force
#: how far inside a fixed y boundary a particle must lie (LIGGGHTS drops atoms on it)
BOUNDARY_MARGIN = 1e-9
#: room between a wall plane and the box boundary behind it, in d (``y_bounds``)
WALL_MARGIN = 1.0
#: A parted pair must forget its tangential spring the step it parts, as LAMMPS does. LIGGGHTS
#: zeroes a listed pair's spring only in its contact models' ``surfacesClose`` (called for
#: a pair closer than ``contact_distance_factor`` × (r_i + r_j) but not touching;
#: src/pair_gran_base.h) or when a neighbour rebuild drops it. With the default factor 1
#: ``surfacesClose`` is never called, so a parted pair kept its spring until the next
#: rebuild (hundreds of steps with the displacement check): a second collision before it
#: started with the first one's spring, and a mirrored Couette cell left its mirror image
#: (tests/test_liggghts.py). Factor 1.05 zeroes the spring the step the gap opens, as long
#: as no pair separates by more than 0.05 (r_i + r_j) in one step (a relative speed of
#: 0.05 d / dt: 60 in the units of accuracy-cost/couette-rough-nu0.55, whose walls move at
#: 1, and 350–1500 in the chute, cooling and Poiseuille scenes). A healthy contact keeps
#: far inside that: a pair parts at about the speed v it met with, and with n ≥ 10 steps per
#: contact it moves v t_c / n ≈ π δ_max / n ≤ 0.016 d per step for the health limit δ_max =
#: 0.05 d (Hooke: δ_max = v t_c / π). It only adds the ring
#: 1 < r/(r_i + r_j) < 1.05 to the lists: ``compute pair/gran/local`` still reports
#: touching pairs only (its rows are the overlapping ones), and a wall contact is zeroed
#: the step it opens either way. Rebuilding every step instead
#: (the earlier fix) made LIGGGHTS several times slower (docs/benchmarks.md).
CONTACT_DISTANCE_FACTOR = 1.05
NEIGHBOUR_COMMANDS = ("neighbor 0.2 bin", "neigh_modify delay 0 every 1 check yes "
                      f"contact_distance_factor {CONTACT_DISTANCE_FACTOR}")


@dataclass
class LiggghtsDeck:
    """Setup commands (box; the atoms come from the data file), physics commands, notes."""

    setup: list[str] = field(default_factory=list)
    physics: list[str] = field(default_factory=list)
    final: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    wall_sides: list[str] = field(default_factory=list)  # the wall-force columns, 3 per side

    def commands(self) -> list[str]:
        return [*self.setup, *self.physics, *self.final]

    def render(self, title: str = "") -> str:
        head = [f"# demstudy LIGGGHTS deck{': ' + title if title else ''}",
                "# Dimensionless particle units (units lj): diameter d = 1, mass m = 1,",
                "# g = 1 when gravity acts (otherwise a wall speed sets the time scale).",
                "# Axes: x flow (periodic), y wall-normal, z spanwise (3D).",
                *(f"# NOTE: {n}" for n in self.notes)]
        return "\n".join([*head, "", *self.commands()]) + "\n"


def wall_type(scene: Scene, side: str) -> int:
    return 2 + [w.side for w in scene.walls].index(side)


def n_types(scene: Scene) -> int:
    return 1 + len(scene.walls)


def y_bounds(scene: Scene, margin: bool = True) -> tuple[float, float]:
    """The box along y: the periodic length, else from wall to wall (an open top: the box
    height, which the ``m`` boundary then grows as particles rise). ``margin``: the LIGGGHTS
    box reaches WALL_MARGIN beyond each wall (and its bumps), so that a centre pushed
    through a wall plane by a deep overlap stays an atom whose position the run reports,
    rather than one LIGGGHTS drops silently at the boundary; False: the walls themselves."""
    if scene.y_periodic:
        return 0.0, scene.box.size[1]
    pad = bump_padding(scene) + (WALL_MARGIN if margin else 0.0)
    lo = scene.wall_position("lower") - pad if scene.wall("lower") else 0.0
    hi = scene.wall_position("upper") + pad if scene.wall("upper") else scene.box.size[1]
    return lo, hi


def boundary(scene: Scene) -> str:
    y = "p" if scene.y_periodic else "fm" if scene.has_open_top else "f"
    return f"p {y} p"


def z_bounds(scene: Scene) -> tuple[float, float]:
    return (0.0, scene.box.size[2]) if scene.dimension == 3 else (-0.5, 0.5)


# ---------------------------------------------------------------- atoms
def state_rows(scene: Scene, x: np.ndarray, v: np.ndarray, omega: np.ndarray,
               diameter: np.ndarray, types: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The data file's Atoms (id type diameter density x y z) and Velocities (id vx vy vz
    wx wy wz) rows, checked and folded into the box: LIGGGHTS silently drops an atom on or
    outside a fixed boundary and segfaults on a NaN, so those are refused here naming the
    atom, and periodic coordinates are wrapped into [lo, hi)."""
    n = len(x)
    pos = np.zeros((n, 3))
    pos[:, :x.shape[1]] = x
    vel = np.zeros((n, 6))
    vel[:, :v.shape[1]] = v
    if omega.shape[1] == 1:
        vel[:, 5] = omega[:, 0]
    else:
        vel[:, 3:] = omega
    bad = ~np.all(np.isfinite(pos), axis=1) | ~np.all(np.isfinite(vel), axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise EngineError(f"particle {i + 1}: position {pos[i]} or velocity {vel[i]} is not "
                          "finite (LIGGGHTS would crash on it)")
    lo = np.array([0.0, y_bounds(scene)[0], z_bounds(scene)[0]])
    hi = np.array([scene.box.size[0], y_bounds(scene)[1], z_bounds(scene)[1]])
    for axis in (0, 2) if scene.dimension == 3 else (0,):
        pos[:, axis] = lo[axis] + np.mod(pos[:, axis] - lo[axis], hi[axis] - lo[axis])
        pos[pos[:, axis] >= hi[axis], axis] = lo[axis]  # mod may round up to the length
    if scene.y_periodic:
        pos[:, 1] = np.mod(pos[:, 1], hi[1])
        pos[pos[:, 1] >= hi[1], 1] = 0.0
    else:
        top = math.inf if scene.has_open_top else hi[1] - BOUNDARY_MARGIN
        outside = (pos[:, 1] <= lo[1] + BOUNDARY_MARGIN) | (pos[:, 1] >= top)
        if outside.any():
            i = int(np.flatnonzero(outside)[0])
            raise EngineError(f"particle {i + 1} at y = {pos[i, 1]:.17g} is on or outside the "
                              f"box's fixed y boundary [{lo[1]:g}, {hi[1]:g}] (LIGGGHTS would "
                              "drop it without a word)")
        mobile = types == 1  # bumps sit on their wall plane
        for wall in scene.walls:  # a centre on or beyond a wall plane has tunnelled
            plane = scene.wall_position(wall.side)
            beyond = mobile & ((pos[:, 1] <= plane) if wall.side == "lower"
                               else (pos[:, 1] >= plane))
            if beyond.any():
                i = int(np.flatnonzero(beyond)[0])
                raise EngineError(f"particle {i + 1} at y = {pos[i, 1]:.17g} is on or beyond "
                                  f"the {wall.side} wall at y = {plane:g}")
    density = np.where(types > 1, BUMP_MASS_FACTOR, 1.0) * DENSITY[scene.dimension]
    ids = np.arange(1, n + 1)
    atoms = np.column_stack([ids, types, diameter, density, pos])
    return atoms, np.column_stack([ids, vel])


def initial_atoms(scene: Scene, state: InitialState) -> tuple[np.ndarray, np.ndarray]:
    """The particles (type 1) then every bumpy wall's bumps (their wall's type), as rows."""
    rows = bump_rows(scene)
    dim = scene.dimension
    x = np.vstack([state.position] + [r.centres for r in rows])
    nb = len(x) - len(state.position)
    v = np.vstack([state.velocity, np.zeros((nb, dim))])
    w = np.vstack([state.angular_velocity,
                   np.zeros((nb, state.angular_velocity.shape[1]))])
    d = np.concatenate([state.diameter] + [np.full(len(r.centres), r.diameter) for r in rows])
    types = np.concatenate([np.ones(len(state.position))]
                           + [np.full(len(r.centres), wall_type(scene, r.side)) for r in rows])
    return state_rows(scene, x, v, w, d, types)


def data_text(scene: Scene, atoms: np.ndarray, velocities: np.ndarray) -> str:
    """A LIGGGHTS data file (atom_style granular) with these rows."""
    (ylo, yhi), (zlo, zhi) = y_bounds(scene), z_bounds(scene)
    if len(atoms) and not scene.y_periodic:
        yhi = max(yhi, float(atoms[:, 5].max()) + 1.0)  # an open top above the box height
    lines = ["demstudy state (dimensionless particle units: d = 1, m = 1)", "",
             f"{len(atoms)} atoms", f"{n_types(scene)} atom types", "",
             f"0 {fmt(scene.box.size[0])} xlo xhi", f"{ylo!r} {yhi!r} ylo yhi",
             f"{fmt(zlo)} {fmt(zhi)} zlo zhi", "", "Atoms", "", format_rows(atoms), "",
             "Velocities", "", format_rows(velocities)]
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------- contacts
def _coefficients(p: ContactParameters) -> dict[str, float]:
    """One contact's LIGGGHTS inputs (see the module docstring)."""
    gamman = 2.0 * damping_ratio(p.lammps_e) * math.sqrt(p.kn / p.m_eff)
    mu = 0.0 if p.tangential == "none" else UNCAPPED_MU if p.mu is None else p.mu
    return {"kn": p.kn, "kt": p.kt, "gamman": gamman, "gammat": p.xt * gamman,
            "coefficientFriction": mu}


def contact_commands(scene: Scene, setup: ContactSetup) -> list[str]:
    if setup.pair.model != "hooke":
        raise UnsupportedByEngine("liggghts", "soft.model", setup.pair.model,
                                  "the LIGGGHTS engine maps Hooke contacts only "
                                  "(hooke/stiffness); use soft.model = 'hooke'")
    nt = n_types(scene)
    table = {(1, 1): _coefficients(setup.pair)}
    for wall in scene.walls:
        table[(1, wall_type(scene, wall.side))] = _coefficients(setup.walls[wall.side])
    cmds = []
    for name in ("kn", "kt", "gamman", "gammat", "coefficientFriction"):
        matrix = []
        for i in range(1, nt + 1):
            for j in range(1, nt + 1):
                entry = table.get((min(i, j), max(i, j)))
                # wall-wall and bump-bump pairs never meet (neigh_modify exclude); the
                # matrices still need a value for them
                matrix.append(entry[name] if entry else table[(1, 1)][name])
        cmds.append(f"fix m_{name} all property/global {name} peratomtypepair {nt} "
                    + " ".join(f"{x!r}" for x in matrix))
    cmds += ["pair_style gran model hooke/stiffness tangential history", "pair_coeff * *"]
    walls = list(range(2, nt + 1))
    cmds += [f"neigh_modify exclude type {a} {b}" for i, a in enumerate(walls)
             for b in walls[i:]]
    return cmds


# ---------------------------------------------------------------- effects
def wall_command(fid: str, group: str, atom_type: int, plane: float, velocity: float = 0.0,
                 extra: str = "") -> str:
    """The ``fix wall/gran`` of a flat wall: the plane y = ``plane`` whose contacts take the
    per-type-pair inputs of ``atom_type``, sliding along x at ``velocity`` (``shear x V``:
    the plane stays put, its contacts see the wall velocity V x̂; LIGGGHTS's tangential
    springs integrate the contact point's velocity relative to it, so an impact on the
    moving wall is the still wall's seen from a frame moving at V; tests/test_liggghts.py)."""
    motion = f" shear x {velocity!r}" if velocity != 0.0 else ""
    return (f"fix {fid} {group} wall/gran model hooke/stiffness tangential history primitive "
            f"type {atom_type} yplane {plane!r}{motion}{extra}")


def _walls(scene: Scene, deck: LiggghtsDeck) -> None:
    for wall in scene.walls:
        fid = f"wall_{wall.side}"
        deck.physics.append(wall_command(fid, "mobile", wall_type(scene, wall.side),
                                         scene.wall_position(wall.side), wall.velocity,
                                         " store_force yes"))
        # the wall's force on the particles, summed (the per-atom store of store_force)
        deck.physics.append(f"compute {fid}_force mobile reduce sum f_force_{fid}[1] "
                            f"f_force_{fid}[2] f_force_{fid}[3]")
        deck.wall_sides.append(wall.side)
        if wall.kind == "bumpy":
            group = f"bumps_{wall.side}"
            deck.physics.append(f"group {group} type {wall_type(scene, wall.side)}")
            deck.physics.append(f"fix {group}_move {group} move linear {wall.velocity!r} "
                                "0.0 0.0")
            deck.physics.append(f"compute {group}_force {group} reduce sum fx fy fz")
            deck.wall_sides.append(f"-{wall.side}")  # minus the particles' force on the bumps


def _check_inertia(scene: Scene) -> None:
    natural = 0.5 if scene.dimension == 2 else 0.4
    if abs(scene.inertia_k - natural) > 1e-12:
        raise UnsupportedByEngine(
            "liggghts", "particles.inertia", scene.particles.inertia,
            f"LIGGGHTS fixes the moment of inertia of its {scene.dimension}D bodies: K = "
            f"4I/(m d²) = {natural} when contacts are rough")


def _gravity(scene: Scene, deck: LiggghtsDeck) -> None:
    g = scene.gravity_vector
    mag = scene.gravity.magnitude
    vec = [c / mag for c in g] + ([0.0] if scene.dimension == 2 else [])
    deck.physics.append(f"fix gravity mobile gravity {mag!r} vector "
                        + " ".join(f"{c!r}" for c in vec))


def _planar(scene: Scene, deck: LiggghtsDeck) -> None:
    deck.final.append("fix enforce2d all enforce2d")


def _bump_note(scene: Scene, deck: LiggghtsDeck) -> None:
    deck.notes.append("bumpy walls: bumps are atoms of their wall's type (its contact, "
                      f"{BUMP_MASS_FACTOR:g} times heavier: m_eff = m), moved by fix move")


#: every effect's LIGGGHTS translation, or why LIGGGHTS cannot express it
TRANSLATIONS: dict[str, Translation | Cannot] = {
    "lattice": LATTICE_ONLY,
    "planar": Translation(_planar, how="dimension 2 and fix enforce2d (LIGGGHTS gives 2D "
                                       "bodies the disc inertia ½ m R² itself)"),
    "rotation": Translation(check=_check_inertia,
                            how="nve/sphere and hooke/stiffness tangential history springs"),
    "restitution-law": Cannot("LIGGGHTS's hooke/stiffness contact has a constant "
                              "restitution; use --engine edmd"),
    "walls": Translation(_walls, how="fix wall/gran … primitive type T yplane Y per wall"),
    "moving-walls": Translation(how="the wall fix's `shear x V` keyword"),
    "noslip-walls": Cannot("Campbell's no-slip wall (centre takes the wall velocity, spin "
                           "unchanged) has no soft-contact equivalent; use model = 'rough' "
                           "or --engine edmd"),
    "servo": Cannot("the servo's walls move between run segments; the LIGGGHTS engine's "
                    "primitive walls stay put: use --engine lammps or edmd"),
    "bumpy-walls": Translation(_bump_note, how="heavy atoms of the wall's type moved by "
                                               "fix move"),
    "gravity": Translation(_gravity),
    "lees-edwards": Cannot("LIGGGHTS 3.8 has no sheared-periodic (triclinic) granular box "
                           "for Lees–Edwards shear: use --engine lammps or edmd"),
}


def build_deck(scene: Scene, setup: ContactSetup, sample_steps: int,
               data: str | Path = DATA_FILE) -> LiggghtsDeck:
    """The deck for ``scene`` (effects refused per ``TRANSLATIONS``); the atoms come from the
    data file ``data``."""
    deck = LiggghtsDeck()
    deck.setup = [
        "units lj",
        "atom_style granular",
        "atom_modify map array sort 0 0.0",
        f"dimension {scene.dimension}",
        f"boundary {boundary(scene)}",
        "newton off",
        "communicate single vel yes",
        f"read_data {data}",
        *NEIGHBOUR_COMMANDS,
        "group mobile type 1",
    ]
    deck.physics = contact_commands(scene, setup)
    apply_effects(scene, "liggghts", TRANSLATIONS, deck)
    deck.final.insert(0, "fix integrate mobile nve/sphere")
    deck.final.append(f"timestep {setup.timestep!r}")
    if deck.wall_sides:
        values = " ".join(
            f"c_{'bumps' if s.startswith('-') else 'wall'}_{s.lstrip('-')}_force[{k}]"
            for s in deck.wall_sides for k in (1, 2, 3))
        deck.final.append(f"fix {WALL_FORCES} all ave/time 1 {sample_steps} {sample_steps} "
                          f"{values}")
    deck.notes.append(setup.note())
    deck.notes.append("the contact history (tangential springs) is not carried across a "
                      "checkpoint: a resumed run starts its contacts afresh")
    if scene.particles.diameter_spread:
        deck.notes.append("damping is set per type pair for equal particles: a pair of unequal "
                          "sizes restitutes e only approximately (ζ ∝ √(m_eff/m_eff,0))")
    return deck


def run_commands(scene: Scene, setup: ContactSetup, sample_steps: int,
                 dump: str | None = None) -> list[str]:
    """What makes the deck run unchanged in bare LIGGGHTS (``liggghts -in deck.in``): the
    mobile particles' kinetic energy every sample, an optional dump, equilibration and
    production (``demstudy run`` drives its own segments instead)."""
    dt = setup.timestep
    cmds = ["compute ke mobile ke", "thermo_style custom step atoms c_ke",
            "thermo_modify norm no format float %.17g", f"thermo {sample_steps}"]
    if dump:
        cmds += [f"dump frames mobile custom {sample_steps} {dump} id type radius x y z vx vy "
                 "vz omegax omegay omegaz", "dump_modify frames sort id"]
    for what, duration in (("equilibration", scene.run.equilibration),
                           ("production", scene.run.production)):
        n = max(0, math.ceil(duration / dt - 1e-9))
        if n:
            cmds.append(f"run {n}  # {what}: {duration:g} time units")
    return cmds


def write_deck(scene: Scene, setup: ContactSetup, sample_steps: int, folder: Path,
               dump: str | None = None) -> Path:
    """``deck.in`` and its data file (the scene's initial state) in ``folder``."""
    from ...scene.initial import build_initial_state

    folder.mkdir(parents=True, exist_ok=True)
    atoms, velocities = initial_atoms(scene, build_initial_state(scene))
    (folder / DATA_FILE).write_text(data_text(scene, atoms, velocities))
    deck = build_deck(scene, setup, sample_steps)
    deck.final += run_commands(scene, setup, sample_steps, dump)
    path = folder / "deck.in"
    path.write_text(deck.render(scene.meta.name))
    return path
