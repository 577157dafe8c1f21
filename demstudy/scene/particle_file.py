"""Read and check a particle file (``initial.placement = "file"``) before any engine starts.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts. A particle file is
plain text, one particle a row: ``x y [z]`` or ``x y [z] vx vy [vz]`` (``#`` starts a
comment, blank lines are skipped). A relative ``initial.path`` is relative to the working
directory (as when the run reads it). Every problem is a line of text naming
``initial.path``, the file, the row (1-based, counting particles) and its line, the value
and what is allowed; :class:`~demstudy.scene.scene.Scene` validation turns them into a
``SceneError`` (exit 2, nothing ran).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .scene import Scene

#: A centre may lie this much (in d) closer to a wall than its radius, and two particles may
#: overlap by this much: rounding in a file written with ~15 significant digits, not more.
TOLERANCE = 1e-9
#: Problems listed per file before "… and N more" (a broken file should not flood the screen).
MAX_LISTED = 5


@dataclass(frozen=True)
class ParticleFile:
    """The parsed rows (``data``: (N, columns)) and the file line of each row, or the reason
    the file cannot be used (``problem``; then ``data`` is empty)."""

    data: np.ndarray
    lines: np.ndarray
    problem: str | None = None


def read_particle_file(path: str | Path) -> ParticleFile:
    """Parse a particle file (cached on path, size and modification time: validation, the
    particle count and the run read it once)."""
    p = Path(path)
    try:
        stat = p.stat()
    except OSError as exc:
        return _failed(f"{_where(path)}: cannot read the file: {exc.strerror or exc}")
    return _read_cached(str(p.resolve()), stat.st_size, stat.st_mtime_ns, str(path))


def _failed(problem: str) -> ParticleFile:
    return ParticleFile(np.empty((0, 0)), np.empty(0, dtype=int), problem)


def _where(path: str | Path) -> str:
    return f"initial.path = {str(path)!r}"


@functools.lru_cache(maxsize=8)
def _read_cached(resolved: str, size: int, mtime_ns: int, shown: str) -> ParticleFile:
    where = _where(shown)
    try:
        text = Path(resolved).read_bytes().decode("utf-8")
    except OSError as exc:
        return _failed(f"{where}: cannot read the file: {exc.strerror or exc}")
    except UnicodeDecodeError as exc:
        return _failed(f"{where}: not UTF-8 text (byte {exc.start}); expected rows of numbers")
    rows, lines = [], []
    for number, raw in enumerate(text.splitlines(), start=1):
        fields = raw.split("#", 1)[0].split()
        if fields:
            rows.append(fields)
            lines.append(number)
    if not rows:
        return _failed(f"{where}: no particle rows (expected x y [z] [vx vy [vz]] per line)")
    width = len(rows[0])
    for k, fields in enumerate(rows):
        if len(fields) != width:
            return _failed(f"{where}: row {k + 1} (line {lines[k]}) has {len(fields)} "
                           f"columns, the first row {width}; every row needs the same")
    try:
        data = np.array(rows, dtype=float)
    except ValueError:
        for k, fields in enumerate(rows):
            for token in fields:
                try:
                    float(token)
                except ValueError:
                    return _failed(f"{where}: row {k + 1} (line {lines[k]}): {token!r} is "
                                   "not a number")
        raise  # unreachable: some token failed above
    return ParticleFile(data, np.array(lines))


def file_count(scene: Scene) -> int:
    """Particles in the scene's particle file (0 when it cannot be read)."""
    return len(read_particle_file(scene.initial.path).data)


def particle_file_problems(scene: Scene, diameter: np.ndarray | None = None) -> list[str]:
    """Everything wrong with the scene's particle file: it must exist and parse, have dim or
    2·dim columns, as many rows as ``particles.count`` (when given), finite values, centres
    inside the periodic box and a radius (less ``TOLERANCE``) from walls, and no two
    particles overlapping by more than ``TOLERANCE``. ``diameter``: the particles' diameters
    (default: those :func:`~demstudy.scene.initial.build_initial_state` draws)."""
    pf = read_particle_file(scene.initial.path)
    if pf.problem:
        return [pf.problem]
    dim, where, data = scene.dimension, _where(scene.initial.path), pf.data
    if data.shape[1] not in (dim, 2 * dim):
        names = "x y z vx vy vz" if dim == 3 else "x y vx vy"
        return [f"{where}: {data.shape[1]} columns; a {dim}D scene needs {dim} or {2 * dim} "
                f"({names})"]
    count = scene.particles.count
    if count is not None and count != len(data):
        return [f"{where}: {len(data)} rows but particles.count = {count}; give as many "
                "rows as particles (or leave particles.count out)"]
    bad = ~np.isfinite(data)
    if bad.any():
        k, col = np.argwhere(bad)[0]
        return [f"{where}: row {k + 1} (line {pf.lines[k]}) column {col + 1} = {data[k, col]}; "
                f"values must be finite ({int(bad.any(axis=1).sum())} rows are not)"]
    if diameter is None:
        from .initial import particle_diameters  # noqa: PLC0415 - initial imports scene

        diameter = particle_diameters(scene, np.random.default_rng(scene.run.seed))
    position = data[:, :dim]
    problems = _placement_problems(scene, position, diameter, pf.lines, where)
    if not problems:
        problems = _overlap_problems(scene, position, diameter, pf.lines, where)
    return problems


def _listed(problems: list[str]) -> list[str]:
    if len(problems) <= MAX_LISTED:
        return problems
    return problems[:MAX_LISTED] + [f"... and {len(problems) - MAX_LISTED} more such rows"]


def _placement_problems(scene: Scene, position: np.ndarray, diameter: np.ndarray,
                        lines: np.ndarray, where: str) -> list[str]:
    problems = []
    radius = diameter / 2
    names = "xyz"
    for ax in range(scene.dimension):
        size = scene.box.size[ax]
        value = position[:, ax]
        if ax == 1 and not scene.y_periodic:
            # bounded y: a radius from the lower wall's surface and from the upper wall (or,
            # with an open top, from the top of the box, which the engines treat as its end)
            top = scene.wall_surface("upper") if scene.wall("upper") else size
            low = scene.wall_surface("lower") + radius - TOLERANCE
            high = top - radius + TOLERANCE
            for k in np.flatnonzero((value < low) | (value > high)):
                problems.append(
                    f"{where}: row {k + 1} (line {lines[k]}) y = {value[k]:.10g}: allowed "
                    f"{low[k] + TOLERANCE:.10g} <= y <= {high[k] - TOLERANCE:.10g} (a radius "
                    f"{radius[k]:g} from the walls, tolerance {TOLERANCE:g} d)"
                )
            continue
        # periodic axis: refuse rather than wrap, since a centre outside the box is more
        # likely a file written for another box than a deliberate image
        for k in np.flatnonzero((value < 0.0) | (value >= size)):
            problems.append(
                f"{where}: row {k + 1} (line {lines[k]}) {names[ax]} = {value[k]:.10g}: outside "
                f"the periodic box; allowed 0 <= {names[ax]} < box.size[{ax}] = {size:g}"
            )
    return _listed(problems)


def _overlap_problems(scene: Scene, position: np.ndarray, diameter: np.ndarray,
                      lines: np.ndarray, where: str) -> list[str]:
    from scipy.spatial import cKDTree  # noqa: PLC0415 - scipy.spatial costs ~0.1 s to import

    dim = scene.dimension
    periodic = np.array([ax == 0 or ax == 2 or scene.y_periodic for ax in range(dim)])
    lengths = np.asarray(scene.box.size[:dim], dtype=float)
    # a periodic box for the tree; bounded y is shifted to start at 0 and left unbounded
    shift = np.where(periodic, 0.0, position.min(axis=0))
    box = np.where(periodic, lengths, 1e12)
    tree = cKDTree(np.where(periodic, np.mod(position, lengths), position - shift),
                   boxsize=box)
    pairs = tree.query_pairs(float(diameter.max()) - TOLERANCE, output_type="ndarray")
    if not len(pairs):
        return []
    i, j = pairs[:, 0], pairs[:, 1]
    delta = position[i] - position[j]
    delta -= np.where(periodic, lengths * np.round(delta / lengths), 0.0)
    distance = np.linalg.norm(delta, axis=1)
    contact = (diameter[i] + diameter[j]) / 2
    overlap = contact - distance
    problems = []
    for m in np.flatnonzero(overlap > TOLERANCE)[np.argsort(-overlap[overlap > TOLERANCE])]:
        a, b = sorted((int(i[m]), int(j[m])))
        problems.append(
            f"{where}: rows {a + 1} and {b + 1} (lines {lines[a]}, {lines[b]}) are "
            f"{distance[m]:.10g} apart, overlapping by {overlap[m]:.3g} d; allowed at least "
            f"{contact[m]:g} (the sum of their radii) less {TOLERANCE:g} d"
        )
    return _listed(problems)
