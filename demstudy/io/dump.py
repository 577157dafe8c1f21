"""LAMMPS custom dumps turned into ``Frame`` objects: MDAnalysis (general) or numpy (fast).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts. The dump must hold the
columns ``id type radius x y z vx vy vz`` (+ ``omegax omegay omegaz``), as written by
``demstudy run --dump`` or ``demstudy deck --dump``. A foreign dump is checked first
(:func:`check_dump_columns`): missing columns, or scaled/unwrapped coordinates, are refused
naming the file and the columns (:class:`~demstudy.errors.BadInputFile`); without the omega
columns the frames carry NaN angular velocities, so rotational fields come out NaN and the
translational ones are computed as usual. MDAnalysis shifts coordinates so the box starts at
the origin; the box lower bounds are read from the dump's headers and added back.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from ..errors import BadInputFile
from .frames import Frame
from .results import Results

_BOUNDS = re.compile(rb"ITEM: BOX BOUNDS([^\n]*)\n([^\n]*)\n([^\n]*)\n([^\n]*)\n")


def box_headers(path: str | Path) -> list[tuple[np.ndarray, float]]:
    """Per frame: the box (3, 2: lo, hi per axis; MDAnalysis subtracts its lower corner from
    the coordinates) and the xy tilt (see ``_box_from_header``)."""
    return [_box_from_header(m.group(1).split(), list(m.groups()[1:]))
            for m in _BOUNDS.finditer(Path(path).read_bytes())]


_REQUIRED = ("id", "type", "radius", "x", "y", "z", "vx", "vy", "vz")
_OMEGA = ("omegax", "omegay", "omegaz")
_OTHER_COORDINATES = {kind: tuple(a + suffix for a in "xyz")  # LAMMPS's other conventions
                      for suffix, kind in (("s", "scaled"), ("u", "unwrapped"),
                                           ("su", "scaled unwrapped"))}


def dump_columns(path: str | Path) -> list[str]:
    """The column names of the first ``ITEM: ATOMS`` header of the dump at ``path``;
    :class:`BadInputFile` when it has none (not a LAMMPS custom dump)."""
    with open(path, "rb") as fh:
        for line in fh:
            if line.startswith(b"ITEM: ATOMS"):
                return line.decode(errors="replace").split()[2:]
    raise BadInputFile(f"dump {path}: no 'ITEM: ATOMS' line: not a LAMMPS custom dump")


def check_dump_columns(path: str | Path) -> bool:
    """Refuse (:class:`BadInputFile`, naming ``path`` and the columns) a dump lacking any of
    ``id type radius x y z vx vy vz`` (z too in 2D: LAMMPS writes it there, both readers need
    it), saying so when it holds scaled or unwrapped coordinates instead of x y z (positions
    in box fractions would be read as lengths). True when it has ``omegax omegay omegaz``."""
    names = dump_columns(path)
    missing = [c for c in _REQUIRED if c not in names]
    if missing:
        kinds = [f"{kind} ({' '.join(c for c in names if c in cols)})"
                 for kind, cols in _OTHER_COORDINATES.items() if set(cols) & set(names)]
        found = f"; it has {', '.join(kinds)} coordinates instead" if kinds else ""
        raise BadInputFile(
            f"dump {path} lacks the columns {' '.join(missing)}{found}: demstudy reads "
            f"'{' '.join(_REQUIRED)}' (+ '{' '.join(_OMEGA)}'), unscaled coordinates in "
            f"d = 1 units, as 'demstudy run --dump' writes (columns found: {' '.join(names)})")
    return all(c in names for c in _OMEGA)


def read_dump(path: str | Path, dim: int, dt: float = 1.0, mobile_type: int = 1,
              start_time: float = 0.0) -> Iterator[Frame]:
    """Frames of a LAMMPS custom dump (time = step × dt); only atoms of ``mobile_type``."""
    import MDAnalysis as mda  # noqa: PLC0415 - heavy import, only when reading dumps

    rotation = check_dump_columns(path)
    extra = ["radius", *_OMEGA] if rotation else ["radius"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # masses guessed / no dt: we use our own
        universe = mda.Universe(str(path), format="LAMMPSDUMP", additional_columns=extra,
                                lammps_coordinate_convention="unscaled")
    headers = box_headers(path)
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
        box, tilt = headers[index]
        pos = ts.positions.astype(float)[mobile] + box[:, 0]
        omega = (np.column_stack([ts.data[c] for c in _OMEGA]).astype(float)[mobile]
                 if rotation else np.full((len(mobile), 3), np.nan))
        yield Frame(
            time=time, box_lo=box[:dim, 0].copy(), box_hi=box[:dim, 1].copy(),
            position=pos[:, :dim], velocity=ts.velocities.astype(float)[mobile, :dim],
            angular_velocity=omega[:, 2:3] if dim == 2 else omega,
            radius=np.asarray(ts.data["radius"], float)[mobile], tilt=tilt,
        )


_FAST_COLUMNS = _REQUIRED  # the omega columns are optional (NaN angular velocities)


def _box_from_header(words: list[bytes], lines: list[bytes]) -> tuple[np.ndarray, float]:
    """(3, 2) box (lo, hi per axis) and the xy tilt from a ``BOX BOUNDS`` header.

    Orthogonal boxes: the lines hold ``lo hi``. Triclinic boxes (``xy xz yz`` in the header,
    Lees-Edwards): the lines hold ``lo_bound hi_bound tilt``; the bounds are turned back
    into ``xlo, xhi`` as in the LAMMPS dump documentation and the xy tilt is returned.
    """
    rows = np.array([[float(v) for v in line.split()] for line in lines])
    if b"xy" not in words:
        return rows[:, :2].copy(), 0.0
    xy, xz, yz = rows[:, 2]
    box = rows[:, :2].copy()
    box[0, 0] -= min(0.0, xy, xz, xy + xz)
    box[0, 1] -= max(0.0, xy, xz, xy + xz)
    box[1, 0] -= min(0.0, yz)
    box[1, 1] -= max(0.0, yz)
    return box, float(xy)


def has_fast_columns(path: str | Path) -> bool:
    """True when the dump's first frame has the columns ``read_dump_fast`` needs."""
    with open(path, "rb") as fh:
        for line in fh:
            if line.startswith(b"ITEM: ATOMS"):
                names = line.decode().split()[2:]
                return all(c in names for c in _FAST_COLUMNS)
    return False


def read_dump_fast(path: str | Path, dim: int, dt: float = 1.0, mobile_type: int = 1,
                   start_time: float = 0.0) -> Iterator[Frame]:
    """Frames of a demstudy custom dump, parsed with numpy (same frames as :func:`read_dump`).

    Fast path for the dumps demstudy writes (``write_dump ... custom ... id type radius
    x y z vx vy vz omegax omegay omegaz``, unscaled coordinates, any column order as long
    as these columns are present): one frame is read at a time (memory flat in the number
    of frames) and its atom block is parsed in one ``numpy.fromstring`` call, in double
    precision (MDAnalysis stores single precision). Atoms are sorted by id and only atoms of
    ``mobile_type`` are kept; time = step × dt, frames before ``start_time`` are skipped.
    Both readers decode a triclinic (Lees-Edwards) header: ``box_lo``, ``box_hi`` are the box
    edges (not the bounding box) and ``Frame.tilt`` is the xy tilt.
    """
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim!r}")
    with open(path, "rb") as fh:
        while True:
            line = fh.readline()
            if not line:
                return
            if not line.startswith(b"ITEM: TIMESTEP"):
                if line.strip():
                    raise ValueError(f"{path}: expected 'ITEM: TIMESTEP', got {line[:60]!r}")
                continue
            step = int(fh.readline())
            if not fh.readline().startswith(b"ITEM: NUMBER OF ATOMS"):
                raise ValueError(f"{path}: missing 'ITEM: NUMBER OF ATOMS' at step {step}")
            n = int(fh.readline())
            header = fh.readline()
            if not header.startswith(b"ITEM: BOX BOUNDS"):
                raise ValueError(f"{path}: missing 'ITEM: BOX BOUNDS' at step {step}")
            box, tilt = _box_from_header(header.split()[3:],
                                         [fh.readline() for _ in range(3)])
            atoms = fh.readline()
            if not atoms.startswith(b"ITEM: ATOMS"):
                raise ValueError(f"{path}: missing 'ITEM: ATOMS' at step {step}")
            names = atoms.decode().split()[2:]
            missing = [c for c in _FAST_COLUMNS if c not in names]
            if missing:
                raise ValueError(f"{path}: the fast reader needs columns {missing} "
                                 "(use read_dump for other dumps)")
            block = b"".join(fh.readline() for _ in range(n))
            time = step * dt
            if time < start_time - 1e-12:
                continue
            data = np.fromstring(block, dtype=np.float64, sep=" ")
            if data.size != n * len(names):
                raise ValueError(f"{path}: truncated or malformed atom block at step {step}")
            data = data.reshape(n, len(names))
            col = {c: names.index(c) for c in (*_FAST_COLUMNS, *_OMEGA) if c in names}
            data = data[np.argsort(data[:, col["id"]], kind="stable")]
            data = data[data[:, col["type"]] == mobile_type]
            omega = (data[:, [col[c] for c in _OMEGA]] if all(c in col for c in _OMEGA)
                     else np.full((len(data), 3), np.nan))
            yield Frame(
                time=time, box_lo=box[:dim, 0].copy(), box_hi=box[:dim, 1].copy(),
                position=np.ascontiguousarray(data[:, [col[c] for c in "xyz"[:dim]]]),
                velocity=np.ascontiguousarray(data[:, [col[f"v{c}"] for c in "xyz"[:dim]]]),
                angular_velocity=np.ascontiguousarray(omega[:, 2:3] if dim == 2 else omega),
                radius=data[:, col["radius"]].copy(), tilt=tilt,
            )


NO_ROTATION = ("absent: the dump has no omegax omegay omegaz columns, so rotational fields "
               "(rotational temperature, spin) are NaN; translational ones are computed")


def dump_source(path: str | Path, scene, dt: float | None, reader: str = "auto",
                start: float = 0.0):
    """(an empty ``Results`` naming the dump, a callable returning its frames) for
    ``demstudy analyze DUMP``: ``dt`` the dump's time step (None: the scene's soft-contact
    time step), ``reader`` "fast" (numpy, demstudy's column layout), "mdanalysis" or
    "auto" (fast when the columns allow)."""
    from ..contact.stiffness import contact_setup
    from ..scene import scene_to_toml

    path = Path(path)
    if not path.is_file():
        raise BadInputFile(f"dump {path}: no such file")
    rotation = check_dump_columns(path)  # before any reading: names the file and columns
    dt = dt if dt is not None else contact_setup(scene).timestep
    fast = reader == "fast" or (reader == "auto" and has_fast_columns(path))
    read = read_dump_fast if fast else read_dump
    results = Results({"engine": "dump", "source_format": "custom dump (id type radius x y z "
                       "vx vy vz omegax omegay omegaz)",
                       "engine_version": "numpy fast reader" if fast else "MDAnalysis",
                       "scene_toml": scene_to_toml(scene), "scene_name": scene.meta.name,
                       "seed": scene.run.seed, "wall_seconds": 0.0, "source": str(path)})
    if not rotation:
        results.attrs["angular_velocity"] = NO_ROTATION

    def frames():
        return read(path, scene.dimension, dt=dt, start_time=start)

    return results, frames
