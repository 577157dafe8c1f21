"""LAMMPS custom dumps read with MDAnalysis, turned into ``Frame`` objects.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts. The dump must hold the
columns ``id type radius x y z vx vy vz`` (+ ``omegax omegay omegaz``), as written by
``demstudy run --dump`` or ``demstudy deck --dump``. MDAnalysis shifts coordinates so the box
starts at the origin; the box lower bounds are read from the dump's headers and added back.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from .frames import Frame

_BOUNDS = re.compile(rb"ITEM: BOX BOUNDS[^\n]*\n([^\n]*)\n([^\n]*)\n([^\n]*)\n")


def box_bounds(path: str | Path) -> np.ndarray:
    """(n_frames, 3, 2) box bounds (lo, hi per axis), one entry per frame, from the headers."""
    data = Path(path).read_bytes()
    rows = [[[float(v) for v in line.split()[:2]] for line in m.groups()]
            for m in _BOUNDS.finditer(data)]
    return np.array(rows, dtype=float)


def read_dump(path: str | Path, dim: int, dt: float = 1.0, mobile_type: int = 1,
              start_time: float = 0.0) -> Iterator[Frame]:
    """Frames of a LAMMPS custom dump (time = step × dt); only atoms of ``mobile_type``."""
    import MDAnalysis as mda  # noqa: PLC0415 - heavy import, only when reading dumps

    extra = ["radius", "omegax", "omegay", "omegaz"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # masses guessed / no dt: we use our own
        universe = mda.Universe(str(path), format="LAMMPSDUMP", additional_columns=extra,
                                lammps_coordinate_convention="unscaled")
    bounds = box_bounds(path)
    types = universe.atoms.types.astype(int)
    order = np.argsort(universe.atoms.ids)
    mobile = order[types[order] == mobile_type]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        steps = [int(ts.data["step"]) for ts in universe.trajectory]
    for index, step in enumerate(steps):
        time = step * dt
        if time < start_time - 1e-12:
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ts = universe.trajectory[index]
        lo, hi = bounds[index, :, 0], bounds[index, :, 1]
        pos = ts.positions.astype(float)[mobile] + lo
        omega = np.column_stack([ts.data[c] for c in extra[1:]]).astype(float)[mobile]
        yield Frame(
            time=time, box_lo=lo[:dim].copy(), box_hi=hi[:dim].copy(),
            position=pos[:, :dim], velocity=ts.velocities.astype(float)[mobile, :dim],
            angular_velocity=omega[:, 2:3] if dim == 2 else omega,
            radius=np.asarray(ts.data["radius"], float)[mobile],
        )
