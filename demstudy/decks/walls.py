"""Walls normal to y: flat granular planes, bumpy walls of heavy prescribed-motion particles.

Dimensionless particle units: d = 1, m = 1. Each wall is its own fix so that its contact
(m_eff = m, its own e_w and β_w) and its motion belong to it alone.
"""

from __future__ import annotations

import numpy as np

from ..scene import Scene
from ..scene.schema import Wall
from .base import Block, fmt
from .contact import ContactSetup

BUMP_MASS_FACTOR = 1e6  # bump particles are this much heavier: m_eff = m to 1 part in 1e6


def wall_fix_id(side: str) -> str:
    return f"wall_{side}"


def bump_positions(scene: Scene) -> np.ndarray | None:
    """Centres (and diameters, last column) of all bump particles, or None."""
    rows = []
    rng = np.random.default_rng(scene.run.seed + 7)
    for wall in scene.walls:
        if wall.kind != "bumpy":
            continue
        b = wall.bumps
        y0 = scene.wall_position(wall.side)
        nx = max(1, round(scene.box.size[0] / b.spacing))
        xs = (np.arange(nx) + 0.5) * scene.box.size[0] / nx
        if scene.dimension == 3:
            nz = max(1, round(scene.box.size[2] / b.spacing))
            zs = (np.arange(nz) + 0.5) * scene.box.size[2] / nz
            gx, gz = np.meshgrid(xs, zs, indexing="ij")
            pts = np.stack([gx.ravel(), np.full(gx.size, y0), gz.ravel()], axis=1)
        else:
            pts = np.stack([xs, np.full(nx, y0)], axis=1)
        if b.pattern == "random":
            # centres scattered by up to a quarter diameter normal to the wall (never inside it)
            sign = 1.0 if wall.side == "lower" else -1.0
            pts[:, 1] += sign * rng.uniform(0.0, 0.25 * b.diameter, len(pts))
        rows.append(np.column_stack([pts, np.full(len(pts), b.diameter)]))
    return np.vstack(rows) if rows else None


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
        comment += "; bumps: heavy particles of type 2 moving with the wall"
        v = fmt(wall.velocity)
        cmds.append(f"fix bumps_{wall.side} bumps move linear {v} 0.0 0.0")
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
