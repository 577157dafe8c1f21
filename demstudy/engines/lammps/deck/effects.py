"""How LAMMPS expresses each physical effect (``TRANSLATIONS``), and what it cannot.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (``units lj``). Each
wall is its own fix so that its contact (m_eff = m, its own e_w and β_w) and its motion
belong to it alone. A translation appends its blocks to the ``DeckDraft`` under
construction: ``physics`` between the pair contact and the sampling computes, ``final``
after the integrator (``fix enforce2d`` must come last).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ....contact.stiffness import ContactSetup
from ....effects import LATTICE_ONLY, Cannot, Translation
from ....effects.servo import servo_samples
from ....errors import UnsupportedByEngine
from ....scene import Scene
from ....scene.schema import Wall
from .base import Block, fmt
from .contact import granular_args
from .system import bump_group, bump_type

#: moments of inertia LAMMPS's nve/sphere integrates: K = 4I/(m d²) (disc, sphere)
LAMMPS_K = {2: (0.5, 0.4), 3: (0.4,)}


@dataclass
class DeckDraft:
    """What the effects contribute to a deck: blocks and the notes printed at its top."""

    setup: ContactSetup
    physics: list[Block] = field(default_factory=list)
    final: list[Block] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


def wall_fix_id(side: str) -> str:
    return f"wall_{side}"


def wall_force_sources(scene: Scene) -> list[tuple[str, str, float]]:
    """(side, compute ID, sign) of every force a wall exerts on the particles: the plane's
    force on the particles (+1), and for bumpy walls minus the particles' force on the
    bumps (−1). The backend sums them per wall."""
    sources = []
    for wall in scene.walls:
        sources.append((wall.side, f"{wall_fix_id(wall.side)}_force", 1.0))
        if wall.kind == "bumpy":
            sources.append((wall.side, f"{bump_group(wall.side)}_force", -1.0))
    return sources


def servo_interval_steps(scene: Scene, dt: float) -> int:
    """Steps between servo updates: whole sample intervals (updates happen at sample ends)."""
    return max(1, round(scene.run.sample_interval / dt)) * servo_samples(scene)


# ---------------------------------------------------------------- walls
def wall_block(scene: Scene, wall: Wall, setup: ContactSetup) -> Block:
    fid = wall_fix_id(wall.side)
    pos = fmt(scene.wall_position(wall.side))
    plane = f"yplane {pos} NULL" if wall.side == "lower" else f"yplane NULL {pos}"
    motion = f" shear x {fmt(wall.velocity)}" if wall.velocity != 0.0 else ""
    contact = setup.walls[wall.side]
    cmds = [
        f"fix {fid} mobile wall/gran granular {granular_args(contact)} {plane}{motion} contacts",
        # force of the wall on the particles, summed (columns 2-4 of the contacts array)
        f"compute {fid}_force mobile reduce sum f_{fid}[2] f_{fid}[3] f_{fid}[4]",
    ]
    moving = f", moving at u = {wall.velocity:g}" if motion else ""
    comment = (f"{wall.kind} {wall.side} wall at y = {pos}, e_w = {wall.restitution:g}, "
               f"{wall.tangential.model} tangential{moving}")
    if wall.kind == "bumpy":
        kind = bump_type(scene, wall.side)
        comment += f"; bumps: heavy particles of type {kind} moving with the wall"
        group = bump_group(wall.side)
        cmds += [
            f"fix {group}_move {group} move linear {fmt(wall.velocity)} 0.0 0.0",
            # the particles' force on the bumps (pair forces only: bumps feel no gravity)
            f"compute {group}_force {group} reduce sum fx fy fz",
        ]
    return Block(f"wall:{wall.side}", comment, cmds)


def region_wall_block(scene: Scene, wall: Wall, setup: ContactSetup) -> Block:
    """A wall on a plane region that moves with variables (``<fix>_dx``, ``_dy``): the servo
    redefines them between run segments (``engines.lammps.backend``)."""
    fid = wall_fix_id(wall.side)
    y = scene.wall_position(wall.side)
    normal = "0 1 0" if wall.side == "lower" else "0 -1 0"
    # displacements as inline linear functions of time: the servo redefines them (one parse
    # per evaluation: nested variables would triple the cost of every step)
    cmds = [
        f"variable {fid}_dx equal {fmt(wall.velocity)}*time",
        f"variable {fid}_dy equal 0.0",
        f"region {fid} plane 0 {fmt(y)} 0 {normal} side in "
        f"move v_{fid}_dx v_{fid}_dy NULL units box",
        f"fix {fid} mobile wall/gran/region granular {granular_args(setup.walls[wall.side])} "
        f"region {fid} contacts",
        f"compute {fid}_force mobile reduce sum f_{fid}[2] f_{fid}[3] f_{fid}[4]",
    ]
    servo = wall.servo
    comment = (f"{wall.side} wall on a moving plane region at y = {fmt(y)}, "
               f"e_w = {wall.restitution:g}")
    if servo is not None:
        n = servo_interval_steps(scene, setup.timestep)
        comment += (f"; servo to sigma_n = {servo.normal_stress:.6g} every {n} steps "
                    "(driven from Python: the wall keeps its place in a bare lmp run)")
    return Block(f"wall:{wall.side}", comment, cmds)


def _walls(scene: Scene, draft: DeckDraft) -> None:
    servo = any(w.servo is not None for w in scene.walls)
    block = region_wall_block if servo else wall_block
    draft.physics += [block(scene, wall, draft.setup) for wall in scene.walls]


def _servo_note(scene: Scene, draft: DeckDraft) -> None:
    draft.notes.append(
        "servo walls are plane regions moved from Python between run segments (Campbell's "
        "rule every servo interval); the periodic width follows the gap by moving the "
        "box boundaries (fix deform x variable); in a bare lmp run the walls stay fixed")


def _check_servo(scene: Scene) -> None:
    for wall in scene.walls:
        if wall.servo is not None and wall.servo.interval_time is None:
            raise UnsupportedByEngine(
                "lammps", f"walls[{wall.side}].servo.interval_time", None,
                "soft-contact engines count time, not collisions: give the servo update "
                "interval in time units (e.g. interval_time = 0.5)")
        if wall.kind == "bumpy" and any(w.servo is not None for w in scene.walls):
            raise UnsupportedByEngine("lammps", f"walls[{wall.side}].kind", "bumpy",
                                      "bumpy walls cannot be combined with the servo in LAMMPS")


def _bumps_note(scene: Scene, draft: DeckDraft) -> None:
    draft.notes.append("bumpy walls: bumps are particles 1e6 times heavier than m, moved "
                       "with the wall by fix move (m_eff = m to 1 part in 1e6)")


# ---------------------------------------------------------------- rotation
def _check_rotation(scene: Scene) -> None:
    K, allowed = scene.inertia_k, LAMMPS_K[scene.dimension]
    if not any(abs(K - k) < 1e-12 for k in allowed):
        raise UnsupportedByEngine(
            "lammps", "particles.inertia", scene.particles.inertia,
            f"LAMMPS fixes the moment of inertia: K = 4I/(m d²) must be one of {allowed} in "
            f"{scene.dimension}D (disc 1/2, sphere 2/5) when contacts are rough")


def _beta_note(scene: Scene, draft: DeckDraft) -> None:
    rules = [scene.contact.tangential] + [w.tangential for w in scene.walls]
    if any(rule.model in ("beta", "rough") for rule in rules):
        draft.notes.append(
            "constant tangential restitution beta is realised by an uncapped tangential spring "
            "(beta = -cos(omega_t t_c)); exact for binary collisions, but a lasting contact "
            "never slides: near jamming (measured: 2D nu >= 0.8, 3D phi = 0.62) a sheared rough "
            "flow jams into a stiffness-dependent solid (docs/contact.md); use a Coulomb mu there")


# ---------------------------------------------------------------- body force, shear, 2D
def gravity_block(scene: Scene) -> Block:
    g = scene.gravity_vector
    mag = scene.gravity.magnitude
    vec = [c / mag for c in g] + ([0.0] if scene.dimension == 2 else [])
    what = f"chute angle {scene.gravity.angle:g}°" if scene.gravity.angle is not None else "vector"
    return Block(
        "gravity", f"g = {mag:g} ({what})",
        [f"fix gravity mobile gravity {fmt(mag)} vector {' '.join(fmt(c) for c in vec)}"],
    )


def shear_block(scene: Scene) -> Block:
    rate = fmt(scene.shear.rate)
    tilt_rate = fmt(scene.shear.rate * scene.box.size[1])
    # `xy erate` leaves the tilt unchanged in the 22Jul2025 wheel: drive the tilt by a
    # variable instead, counted from the time this fix is defined (also after a restart)
    return Block(
        "lees-edwards", f"simple shear at rate {rate}: tilting triclinic box, velocities remapped",
        [
            "variable lees_edwards_t0 equal $(time)",
            f"variable lees_edwards_tilt equal {tilt_rate}*(time-v_lees_edwards_t0)",
            f"variable lees_edwards_rate equal {tilt_rate}",
            "fix lees_edwards all deform 1 xy variable v_lees_edwards_tilt v_lees_edwards_rate "
            "remap v flip yes",
        ],
    )


def enforce2d_block() -> Block:
    return Block("enforce2d", "keep discs in the plane (defined last)",
                 ["fix enforce2d all enforce2d"])


#: every effect's LAMMPS translation, or why LAMMPS cannot express it
TRANSLATIONS: dict[str, Translation | Cannot] = {
    "lattice": LATTICE_ONLY,
    "planar": Translation(lambda s, d: d.final.append(enforce2d_block()),
                          how="dimension 2, density/disc masses, nve/sphere disc, enforce2d"),
    "rotation": Translation(_beta_note, _check_rotation,
                            how="nve/sphere and granular tangential springs"),
    "restitution-law": Cannot("LAMMPS granular contacts have a constant restitution; use "
                              "--engine edmd"),
    "walls": Translation(_walls, how="one fix wall/gran per wall (wall/gran/region with "
                                     "the servo)"),
    "moving-walls": Translation(how="the wall fix's `shear x` keyword (a region's motion "
                                    "variable with the servo)"),
    "noslip-walls": Cannot("Campbell's no-slip wall (centre takes the wall velocity, spin "
                           "unchanged) has no soft-contact equivalent; use model = 'rough' "
                           "or run it with --engine edmd"),
    "servo": Translation(_servo_note, _check_servo,
                         how="region walls moved from Python between run segments"),
    "bumpy-walls": Translation(_bumps_note, how="heavy bump particles of their own atom type "
                                                "moved by fix move (wall blocks)"),
    "gravity": Translation(lambda s, d: d.physics.append(gravity_block(s))),
    "lees-edwards": Translation(lambda s, d: d.physics.append(shear_block(s)),
                                how="fix deform on the xy tilt, velocities remapped"),
}
