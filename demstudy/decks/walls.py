"""Walls normal to y (flat granular planes, with bumps for bumpy walls), gravity, shear and
integration blocks.

Dimensionless particle units: d = 1, m = 1. Each wall is its own fix so that its contact
(m_eff = m, its own e_w and β_w) and its motion belong to it alone.
"""

from __future__ import annotations

from ..scene import Scene
from ..scene.schema import Wall
from .base import Block, fmt
from .bumps import bump_group, bump_type
from .contact import ContactSetup


def wall_fix_id(side: str) -> str:
    return f"wall_{side}"


def wall_force_sources(scene: Scene) -> list[tuple[str, str, float]]:
    """(side, compute ID, sign) of every force a wall exerts on the particles: the plane's
    force on the particles (+1), and for bumpy walls minus the particles' force on the
    bumps (−1). The driver sums them per wall."""
    sources = []
    for wall in scene.walls:
        sources.append((wall.side, f"{wall_fix_id(wall.side)}_force", 1.0))
        if wall.kind == "bumpy":
            sources.append((wall.side, f"{bump_group(wall.side)}_force", -1.0))
    return sources


def wall_block(scene: Scene, wall: Wall, setup: ContactSetup) -> Block:
    fid = wall_fix_id(wall.side)
    pos = fmt(scene.wall_position(wall.side))
    plane = f"yplane {pos} NULL" if wall.side == "lower" else f"yplane NULL {pos}"
    motion = f" shear x {fmt(wall.velocity)}" if wall.velocity != 0.0 else ""
    contact = setup.walls[wall.side]
    cmds = [
        f"fix {fid} mobile wall/gran granular {contact.granular_args()} {plane}{motion} contacts",
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


def gravity_block(scene: Scene) -> Block | None:
    g = scene.gravity_vector
    if g is None:
        return None
    mag = scene.gravity.magnitude
    vec = [c / mag for c in g] + ([0.0] if scene.dimension == 2 else [])
    what = f"chute angle {scene.gravity.angle:g}°" if scene.gravity.angle is not None else "vector"
    return Block(
        "gravity", f"g = {mag:g} ({what})",
        [f"fix gravity mobile gravity {fmt(mag)} vector {' '.join(fmt(c) for c in vec)}"],
    )


def shear_block(scene: Scene) -> Block | None:
    if scene.shear is None:
        return None
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


def integrate_block(scene: Scene, setup: ContactSetup) -> list[Block]:
    if scene.rotation_matters:
        disc = scene.dimension == 2 and abs(scene.inertia_k - 0.5) < 1e-12
        style = "nve/sphere" + (" disc" if disc else "")
        comment = "translation and rotation (velocity Verlet)"
    else:
        style = "nve"
        comment = "translation only: smooth contacts never change a spin"
    blocks = [
        Block("integrate", comment,
              [f"fix integrate mobile {style}", f"timestep {setup.timestep:.10g}"]),
    ]
    if scene.dimension == 2:
        blocks.append(Block("enforce2d", "keep discs in the plane (defined last)",
                            ["fix enforce2d all enforce2d"]))
    return blocks
