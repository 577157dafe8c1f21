"""The pair contact block: ``pair_style granular`` with the scene's mapped parameters.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (``units lj``).
"""

from __future__ import annotations

from ....contact.mapping import ContactParameters
from ....contact.stiffness import ContactSetup
from ....effects.bumps import bumpy_walls
from ....scene import Scene
from .base import Block
from .system import bump_type

#: friction coefficient written for an uncapped ('spring') tangential contact
UNCAPPED_MU = 1e20


def granular_args(p: ContactParameters) -> str:
    """Model string after ``pair_coeff * *`` or after ``fix ID group wall/gran granular``."""
    normal = f"{p.model} {p.kn:.12g} {p.lammps_e:.12g} damping coeff_restitution"
    if p.tangential == "none":
        return f"{normal} tangential linear_nohistory 0.0 0.0"
    mu = UNCAPPED_MU if p.mu is None else p.mu
    xt = f"{p.xt:.12g}" if p.xt else "0.0"  # tangential damping (the Walton copy, beta0 = e)
    law = "mindlin" if p.mindlin else "linear_history"  # Mindlin: k_t a, the Hertz copy
    return f"{normal} tangential {law} {p.kt:.12g} {xt} {mu:.12g}"


def pair_block(scene: Scene, setup: ContactSetup) -> Block:
    p = setup.pair
    cmds = ["pair_style granular", f"pair_coeff * * {granular_args(p)}"]
    bumpy = bumpy_walls(scene)
    for wall in bumpy:
        # each wall's bumps collide with that wall's rule, with m_eff = m (they are heavy)
        kind = bump_type(scene, wall.side)
        cmds.append(f"pair_coeff 1 {kind} {granular_args(setup.walls[wall.side])}")
    types = [bump_type(scene, w.side) for w in bumpy]
    for i, a in enumerate(types):  # bumps never interact with bumps
        cmds += [f"neigh_modify exclude type {a} {b}" for b in types[i:]]
    cmds += ["neighbor 0.3 bin", "neigh_modify delay 0 every 1 check yes"]
    comment = (
        f"{p.model} contacts, k_n = {p.kn:.6g}, e = {p.restitution:g}, "
        f"t_c = {p.contact_time:.6g} (m_eff = m/2)"
        + ("" if p.tangential == "none" else f", k_t = {p.kt:.6g}, {p.tangential} tangential")
        + ("" if p.steps_per_contact is None else
           f"\ncompensated for {p.steps_per_contact:.4g} steps per contact (LAMMPS's discrete "
           f"update restitutes the targets, docs/contact.md): damping e = {p.lammps_e:.6g}"
           + (", k_t" if p.tangential == "spring" else ""))
        + f"\n{setup.note()}"
    )
    return Block("contact", comment, cmds)
