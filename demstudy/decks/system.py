"""Box, boundaries and particles: the setup stage (replaced by read_restart on resume).

Dimensionless particle units: d = 1, m = 1 (density 6/π for spheres, 4/π per unit area for
discs, so a particle of diameter 1 has mass 1; masses scale with volume).
"""

from __future__ import annotations

import math

import numpy as np

from ..scene import Scene
from ..scene.initial import InitialState
from .base import Block, fmt

DATA_FILE = "initial.data"
DENSITY = {2: 4 / math.pi, 3: 6 / math.pi}


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


def data_file(scene: Scene, state: InitialState, bumps: np.ndarray | None) -> str:
    """LAMMPS data file (atom_style sphere) holding the initial state and any wall bumps."""
    dim = scene.dimension
    n = len(state.position)
    nb = 0 if bumps is None else len(bumps)
    lo_y, hi_y = y_bounds(scene)
    z = (0.0, scene.box.size[2]) if dim == 3 else (-0.5, 0.5)
    lines = [
        "demstudy initial state (dimensionless particle units: d = 1, m = 1)",
        "",
        f"{n + nb} atoms",
        f"{2 if nb else 1} atom types",
        "",
        f"0 {fmt(scene.box.size[0])} xlo xhi",
        f"{fmt(lo_y)} {fmt(hi_y)} ylo yhi",
        f"{fmt(z[0])} {fmt(z[1])} zlo zhi",
    ]
    if scene.shear is not None:
        lines.append("0 0 0 xy xz yz")
    lines += ["", "Atoms # sphere", ""]
    pos3 = np.zeros((n, 3))
    pos3[:, :dim] = state.position
    rho = DENSITY[3]  # 2D discs are re-densified with `set density/disc` after reading
    for i in range(n):
        x, y, zz = pos3[i]
        lines.append(f"{i + 1} 1 {state.diameter[i]:.15g} {rho:.15g} {x:.15g} {y:.15g} {zz:.15g}")
    for j in range(nb):
        b = np.zeros(4)
        b[: bumps.shape[1]] = bumps[j]
        x, y, zz, d = (b[0], b[1], b[2], b[3]) if dim == 3 else (b[0], b[1], 0.0, b[2])
        lines.append(f"{n + j + 1} 2 {d:.15g} {rho * 1e6:.15g} {x:.15g} {y:.15g} {zz:.15g}")
    lines += ["", "Velocities", ""]
    vel = np.zeros((n, 3))
    vel[:, :dim] = state.velocity
    omega = np.zeros((n, 3))
    if dim == 2:
        omega[:, 2] = state.angular_velocity[:, 0]
    else:
        omega[:] = state.angular_velocity
    for i in range(n):
        v, w = vel[i], omega[i]
        lines.append(f"{i + 1} " + " ".join(f"{c:.15g}" for c in (*v, *w)))
    for j in range(nb):
        lines.append(f"{n + j + 1} 0 0 0 0 0 0")
    return "\n".join(lines) + "\n"


def setup_block(scene: Scene, has_bumps: bool) -> Block:
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
        if has_bumps:
            cmds.append(f"set type 2 density/disc {DENSITY[2] * 1e6:.15g}")
    comment = (
        f"{'discs' if dim == 2 else 'spheres'}, {scene.n_particles} particles, "
        f"box {' x '.join(f'{s:g}' for s in scene.box.size)}, boundary {boundary(scene)}"
    )
    return Block("system", comment, cmds, stage="setup")


def groups_block(has_bumps: bool) -> Block:
    cmds = ["group mobile type 1"]
    if has_bumps:
        cmds.append("group bumps type 2")
    return Block("groups", "mobile particles" + (" and wall bumps" if has_bumps else ""), cmds)
