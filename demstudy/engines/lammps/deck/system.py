"""Box, boundaries, particles (the setup stage, replaced by read_restart on resume), atom
types and groups, and the integrator.

Dimensionless particle units: d = 1, m = 1 (density 6/π for spheres, 4/π per unit area for
discs, so a particle of diameter 1 has mass 1; masses scale with volume).

Each bumpy wall owns an atom type and a group (type 2 for the first bumpy wall, 3 for the
second), so each collides with its own wall rule and moves with its own wall. Bumps are 1e6
times heavier than a particle of their size, so the pair contact sees m_eff = m to 1 part in
1e6, and ``fix move`` prescribes their motion.
"""

from __future__ import annotations

import io
import math

import numpy as np

from ....contact.stiffness import ContactSetup
from ....effects.bumps import BumpRow, bump_padding, bumpy_walls
from ....scene import Scene
from ....scene.initial import InitialState
from .base import Block, fmt

DATA_FILE = "initial.data"
DENSITY = {2: 4 / math.pi, 3: 6 / math.pi}
MASS_FACTOR = 1e6


def bump_group(side: str) -> str:
    """LAMMPS group (and ID prefix) of one wall's bumps."""
    return f"bumps_{side}"


def bump_type(scene: Scene, side: str) -> int:
    sides = [w.side for w in bumpy_walls(scene)]
    return 2 + sides.index(side)


def n_atom_types(scene: Scene) -> int:
    return 1 + len(bumpy_walls(scene))


def boundary(scene: Scene) -> str:
    if scene.y_periodic:
        y = "p"
    elif any(w.servo is not None for w in scene.walls):
        y = "m"  # servo walls move: the box follows the particles
    elif scene.has_open_top:
        y = "fm"
    else:
        y = "f"
    return f"p {y} p"


def y_bounds(scene: Scene) -> tuple[float, float]:
    if scene.y_periodic:
        return 0.0, scene.box.size[1]
    lo = scene.wall_position("lower")
    hi = scene.wall_position("upper") if scene.wall("upper") else scene.box.size[1]
    return lo, hi


def data_file(scene: Scene, state: InitialState, bumps: list[BumpRow]) -> str:
    """LAMMPS data file (atom_style sphere) holding the initial state and any wall bumps."""
    dim = scene.dimension
    n = len(state.position)
    bump_xyz = [row.centres for row in bumps]
    nb = sum(len(c) for c in bump_xyz)
    lo_y, hi_y = y_bounds(scene)
    pad = 0.0 if scene.y_periodic else bump_padding(scene)  # bumps sit on the wall planes
    z = (0.0, scene.box.size[2]) if dim == 3 else (-0.5, 0.5)
    lines = [
        "demstudy initial state (dimensionless particle units: d = 1, m = 1)",
        "",
        f"{n + nb} atoms",
        f"{n_atom_types(scene)} atom types",
        "",
        f"0 {fmt(scene.box.size[0])} xlo xhi",
        f"{fmt(lo_y - pad)} {fmt(hi_y + pad)} ylo yhi",
        f"{fmt(z[0])} {fmt(z[1])} zlo zhi",
    ]
    if scene.shear is not None:
        lines.append("0 0 0 xy xz yz")
    # columns: id type diameter density x y z (bumps: their wall's type, 1e6 times denser)
    pos = np.zeros((n + nb, 3))
    pos[:n, :dim] = state.position
    if nb:
        pos[n:, :dim] = np.vstack(bump_xyz)
    diameter = np.concatenate([state.diameter] + [np.full(len(r.centres), r.diameter)
                                                  for r in bumps])
    types = np.concatenate([np.ones(n)] + [np.full(len(r.centres), bump_type(scene, r.side))
                                           for r in bumps])
    rho = DENSITY[3]  # 2D discs are re-densified with `set density/disc` after reading
    density = np.where(types > 1, rho * MASS_FACTOR, rho)
    ids = np.arange(1, n + nb + 1)
    atoms = np.column_stack([ids, types, diameter, density, pos])
    vel = np.zeros((n + nb, 6))
    vel[:n, :dim] = state.velocity
    if dim == 2:
        vel[:n, 5] = state.angular_velocity[:, 0]
    else:
        vel[:n, 3:] = state.angular_velocity
    lines += ["", "Atoms # sphere", "", _table(atoms, "%d %d" + " %.17g" * 5)]
    lines += ["", "Velocities", "", _table(np.column_stack([ids, vel]), "%d" + " %.17g" * 6)]
    return "\n".join(lines) + "\n"


def _table(rows: np.ndarray, fmt_row: str) -> str:
    buffer = io.StringIO()
    np.savetxt(buffer, rows, fmt=fmt_row)
    return buffer.getvalue().rstrip("\n")


def setup_block(scene: Scene, bumps: list[BumpRow]) -> Block:
    dim = scene.dimension
    cmds = [
        "units lj",
        "atom_style sphere",
        f"dimension {dim}",
        f"boundary {boundary(scene)}",
        "newton off",
        "comm_modify vel yes",
        f"read_data {DATA_FILE}",
    ]
    if dim == 2:
        # read_data gives sphere masses; discs need m = ρ π r² with ρ = 4/π
        cmds.append(f"set type 1 density/disc {DENSITY[2]:.15g}")
        cmds += [f"set type {bump_type(scene, row.side)} density/disc "
                 f"{DENSITY[2] * MASS_FACTOR:.15g}" for row in bumps]
    comment = (
        f"{'discs' if dim == 2 else 'spheres'}, {scene.n_particles} particles, "
        f"box {' x '.join(f'{s:g}' for s in scene.box.size)}, boundary {boundary(scene)}"
    )
    return Block("system", comment, cmds, stage="setup")


def groups_block(scene: Scene, bumps: list[BumpRow]) -> Block:
    cmds = ["group mobile type 1"]
    cmds += [f"group {bump_group(row.side)} type {bump_type(scene, row.side)}" for row in bumps]
    return Block("groups", "mobile particles" + (" and wall bumps" if bumps else ""), cmds)


def integrate_block(scene: Scene, setup: ContactSetup) -> Block:
    if scene.rotation_matters:
        disc = scene.dimension == 2 and abs(scene.inertia_k - 0.5) < 1e-12
        style = "nve/sphere" + (" disc" if disc else "")
        comment = "translation and rotation (velocity Verlet)"
    else:
        style = "nve"
        comment = "translation only: smooth contacts never change a spin"
    return Block("integrate", comment,
                 [f"fix integrate mobile {style}", f"timestep {setup.timestep:.10g}"])
