"""A few particles (and a ``wall/gran granular`` plane) in a fresh LAMMPS instance, for the
binary collisions and wall motions of ``calibrate`` and ``motion``.

Dimensionless particle units: d = 1, m = 1 (g = 1 when gravity is on).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...contact.mapping import ContactParameters
from .deck.contact import granular_args
from .library import open_lammps


def _f(x: float) -> str:
    return repr(float(x))


#: one particle: x, y, z, vx, vy, vz, omega_z, diameter, mass
Atom = tuple[float, float, float, float, float, float, float, float, float]


def open_bodies(dim: int, wall: bool, params: ContactParameters, dt: float,
                atoms: Sequence[Atom], gravity: tuple[float, float] | None = None):
    """A LAMMPS instance with the given particles and contact model (and a ``yplane 0`` wall)."""
    lmp = open_lammps()
    half = 5.0 * max(a[7] for a in atoms)
    zlo, zhi = (-0.5, 0.5) if dim == 2 else (-half, half)
    ylo = -1.0 if wall else -half
    cmds = [
        "units lj", f"dimension {dim}", "atom_style sphere",
        f"boundary p {'f' if wall else 'p'} p", "atom_modify map array sort 0 0.0",
        "comm_modify vel yes",
        f"region box block {-half} {half} {ylo} {half} {zlo} {zhi}", "create_box 1 box",
    ]
    cmds += [f"create_atoms 1 single {_f(a[0])} {_f(a[1])} {_f(a[2])}" for a in atoms]
    cmds += [f"set atom {i + 1} diameter {_f(a[7])}\nset atom {i + 1} mass {_f(a[8])}\n"
             f"set atom {i + 1} vx {_f(a[3])} vy {_f(a[4])} vz {_f(a[5])} omega 0 0 {_f(a[6])}"
             for i, a in enumerate(atoms)]
    cmds += ["pair_style granular", f"pair_coeff * * {granular_args(params)}",
             "neighbor 0.2 bin", "neigh_modify every 1 delay 0 check yes",
             f"fix integrate all nve/sphere{' disc' if dim == 2 else ''}"]
    if wall:
        cmds.append(f"fix wall all wall/gran granular {granular_args(params)} yplane 0.0 NULL")
    if gravity is not None:
        cmds.append(f"fix grav all gravity 1.0 vector {_f(gravity[0])} {_f(gravity[1])} 0.0")
    if dim == 2:
        cmds.append("fix planar all enforce2d")
    cmds += [f"timestep {_f(dt)}", "run 0"]
    lmp.commands_string("\n".join(cmds))
    return lmp


def read_state(lmp, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Positions, velocities, angular velocities and forces of the n atoms, in id order."""
    get = lmp.numpy.extract_atom
    order = np.argsort(get("id")[:n])
    return tuple(get(k)[:n][order].copy() for k in ("x", "v", "omega", "f"))  # type: ignore


