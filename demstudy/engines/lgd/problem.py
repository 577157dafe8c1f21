"""Gutt's (1989) own LGD problem files: the control file ``in``, the parameter file and the
initial-data file (thesis App. 3, main L1584–L2006; ../shared/reference/gutt1989.md §3.11),
read so that his files run as they are, and written back in the same format.

Units: the listing's integers (:mod:`demstudy.engines.lgd.lattice`): offsets in 1/4096 "cm"
(``idl`` per lattice spacing), velocities in 1/256 cm/s, gravity in cm/s². Nothing here is in
demstudy's particle units; the backend converts.

* ``in``: ``ist``, then the names ``nam1`` (parameter file), ``nam3`` (step summary), ``nam4``
  (dump) and, read only when ist > 1, ``nam5`` (marked grains), one per line.
* Parameter file: 6 lines of ``name = value`` fields in the listing's order (``PARAMETER_LINES``;
  line 1 starts with ``nam2 = FILE``, the initial-data file). The listing reads them by
  position (``fscanf``'s ``%s%s%6d``); here every name must be the listing's, whitespace is free
  and ``name=value`` may be glued.
* Initial-data file: ``nl = N`` then N lines ``md x1 y1 x2 y2 vx vy`` in user coordinates
  (ix = column as the user counts it in its row, iy = global row R, 1 = bottom wall row):

  ====  =================================================================================
  md    meaning
  ====  =================================================================================
  ±1    one grain (+) or wall particle (−) at (x1, y1) with offset (x2, y2)
  ±2    a line from (x1, y1) to (x2, y2): points ``p1 + Δ·l/npl``, C truncation, l = 0..npl
  ±3    a filled rectangle [x1, x2] × [y1, y2] (density 1)
  ±6    a rectangle at density 1/3: every 3rd column, alternate rows displaced by 2 (odd
        row) or 1 (even row)
  0     an empty node at (x1, y1) (offsets and velocity set as given)
  > 10  a marked grain at (x1, y1) with offset (x2, y2), numbered 1, 2, … by its line
  ====  =================================================================================

  Lines apply in order, later ones overwriting earlier ones, onto a lattice whose rows 1 and
  nyt are already wall rows with x velocities jx1 and jx2 (L1831–L1856). As in the listing,
  ±2/±3/±6 set only ``ivx, ivy, mlp`` (offsets and marks of what they overwrite stay), ±1, 0
  and > 10 set offsets and velocity, and a node's mark survives being overwritten.

User (ix, iy) → storage column G = ((ix − 1 − (iy − 1)/2) mod nxt) + 1 (C's ``/``; L1920), i.e.
array ``[iy − 1, G − 1]``; rows outside 1..nyt are skipped, as the node-local listing does.

Choices where the listing is silent or garbled (each also in docs/lgd-engine.md):
* the OCR shows ``if (md == 3 …)`` after the ±6 block, not ``else if``, which would also put a
  single grain at (x1, y1) after every ±6 rectangle; the braces around it are garbled, and the
  digest reads ±6 as a rectangle only, which is what is done here;
* a ±2 line from a point to itself divides 0/0 in the listing (a crash); here it is that point;
* md codes other than ±1, ±2, ±3, ±6, 0 and > 10 are refused (the listing would store md
  itself as the node's mode);
* more lines than ``nl`` are refused (the listing ignores them; a miscounted nl loses grains).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, fields
from pathlib import Path

import numpy as np

from ...errors import BadInputFile
from .lattice import MOVABLE, WALL, Lattice, LgdParams

__all__ = ["MD_CODES", "PARAMETER_LINES", "Control", "MdLine", "Problem", "ProblemError",
           "build_lattice", "lattice_to_lines", "read_control", "read_initial_data",
           "read_parameters", "read_problem", "storage_column", "user_column",
           "write_problem"]

#: the parameter file's fields, line by line, in the listing's fscanf order (L1596–L1612)
PARAMETER_LINES: tuple[tuple[str, ...], ...] = (
    ("nam2", "id", "icb", "iep1", "iew1"),
    ("idl", "idx", "idy", "iep2", "iew2"),
    ("igx", "igy", "jx1", "jx2"),
    ("kq", "kx", "ky", "ke"),
    ("mvx", "mvy"),
    ("nt", "nxt", "nyt", "ntu", "nto"),
)
#: the md codes the listing's initial-data reader knows (besides any md > 10: a marked grain)
MD_CODES = (-6, -3, -2, -1, 0, 1, 2, 3, 6)


class ProblemError(BadInputFile):
    """A problem file that cannot be read: names the file, the line and the field (exit 2 on
    the command line: nothing ran)."""


@dataclass(frozen=True)
class MdLine:
    """One line of the initial-data file (user coordinates, the listing's integer units)."""

    md: int
    x1: int
    y1: int
    x2: int = 0
    y2: int = 0
    vx: int = 0
    vy: int = 0

    def values(self) -> tuple[int, ...]:
        return (self.md, self.x1, self.y1, self.x2, self.y2, self.vx, self.vy)


def md_problem(md: int) -> str | None:
    """Why ``md`` is not an initial-data code (None: it is one)."""
    if md in MD_CODES or md > 10:
        return None
    return (f"md = {md}: not a code of the listing; allowed: ±1 (one grain/wall particle), "
            "±2 (line), ±3 (rectangle), ±6 (rectangle at density 1/3), 0 (empty), "
            "> 10 (marked grain)")


@dataclass
class Control:
    """The control file ``in``: output mode ``ist`` and the file names."""

    ist: int
    nam1: str  # parameter file
    nam3: str = "sum"  # step summary
    nam4: str = "dump"  # particle dump
    nam5: str | None = None  # marked grains (read only when ist > 1)


@dataclass
class Problem:
    """A whole problem: parameters, initial data and the run settings of the listing."""

    params: LgdParams
    lines: list[MdLine]
    nt: int  # steps
    nto: int = 0  # steps between dumps (<= 0: only at the end)
    mvx: int = 1  # block sizes of the averaged-velocity output
    mvy: int = 1
    control: Control = field(default_factory=lambda: Control(0, "par"))
    nam2: str = "init"  # initial-data file
    notes: list[str] = field(default_factory=list)  # what the reading skipped

    def lattice(self) -> Lattice:
        return build_lattice(self.params, self.lines, self.notes)


# -- coordinates ---------------------------------------------------------------------------
def storage_column(ix, iy, nxt: int):
    """0-based storage column c = G − 1 of user (ix, iy): (ix − 1 − (iy − 1)/2) mod nxt (C's
    truncating ``/``; iy >= 1 makes it a floor)."""
    iy = np.asarray(iy)
    half = np.where(iy >= 1, (iy - 1) // 2, -((1 - iy) // 2))
    return np.mod(np.asarray(ix) - 1 - half, nxt)


def user_column(c, r, nxt: int):
    """User column ix (1..nxt) of storage (column c, row r), both 0-based."""
    return np.mod(np.asarray(c) + np.asarray(r) // 2, nxt) + 1


# -- reading -------------------------------------------------------------------------------
def _int(text: str, where: str, name: str) -> int:
    if not re.fullmatch(r"[+-]?\d+", text):
        raise ProblemError(f"{where}: {name} = {text!r} is not an integer")
    return int(text)


def _fields(line: str, where: str) -> list[tuple[str, str]]:
    """``name = value`` pairs of one line; '=' may touch either side."""
    tokens = line.replace("=", " = ").split()
    if len(tokens) % 3 or any(t != "=" for t in tokens[1::3]):
        raise ProblemError(f"{where}: {line.strip()!r} is not a sequence of 'name = value' "
                           "fields")
    return list(zip(tokens[0::3], tokens[2::3], strict=True))


def read_parameters(path: Path) -> tuple[dict[str, int], str]:
    """The parameter file: every field of ``PARAMETER_LINES`` as an int, and ``nam2``."""
    path = Path(path)
    numbered = [(k + 1, ln) for k, ln in enumerate(_read_text(path).splitlines())
                if ln.strip()]
    if len(numbered) != len(PARAMETER_LINES):
        raise ProblemError(f"{path}: {len(numbered)} non-empty lines; the parameter file has "
                           f"{len(PARAMETER_LINES)} (fields: "
                           + "; ".join(" ".join(n) for n in PARAMETER_LINES) + ")")
    values: dict[str, int] = {"_line_" + n: no for (no, _), names in
                              zip(numbered, PARAMETER_LINES, strict=True) for n in names}
    nam2 = ""
    for (number, line), names in zip(numbered, PARAMETER_LINES, strict=True):
        where = f"{path}, line {number}"
        pairs = _fields(line, where)
        got = [p[0] for p in pairs]
        if got != list(names):
            raise ProblemError(f"{where}: fields {got}; expected {list(names)} (name = value, "
                               "in the listing's order)")
        for name, value in pairs:
            if name == "nam2":
                nam2 = value
            else:
                values[name] = _int(value, where, name)
    _check_parameters(values, path)
    return {k: v for k, v in values.items() if not k.startswith("_line_")}, nam2


def _check_parameters(v: dict[str, int], path: Path) -> None:
    """The listing's own checks (L1645–L1675) and the positivity its divisions need."""
    def bad(name: str, allowed: str) -> ProblemError:
        return ProblemError(f"{path}, line {v['_line_' + name]}: {name} = {v[name]}; "
                            f"allowed: {allowed}")

    for name in ("idl", "idx", "idy", "kq", "ke", "mvx", "mvy", "ntu"):
        if v[name] <= 0:
            raise bad(name, "> 0")
    for name in ("id", "icb", "nt", "iep1", "iep2", "iew1", "iew2"):
        if v[name] < 0:
            raise bad(name, ">= 0")
    if v["nxt"] < 6 or v["nxt"] % 6:
        raise bad("nxt", "a multiple of 6 (move templates have period 3, collision "
                         "templates period 2; listing L1671)")
    if v["nyt"] < 4:
        raise bad("nyt", ">= 4 (rows 1 and nyt are the wall rows; the step needs two more)")
    if v["nxt"] % v["mvx"]:
        raise bad("mvx", f"a divisor of nxt = {v['nxt']} (listing L1645)")
    if (v["nyt"] - 2) % v["mvy"]:
        raise bad("mvy", f"a divisor of nyt − 2 = {v['nyt'] - 2} (listing L1657)")


def read_initial_data(path: Path) -> list[MdLine]:
    """The initial-data file: ``nl = N`` and N md lines (7 integers each)."""
    path = Path(path)
    lines = _read_text(path).splitlines()
    numbered = [(k + 1, ln) for k, ln in enumerate(lines) if ln.strip()]
    if not numbered:
        raise ProblemError(f"{path}: empty; expected 'nl = N' and N lines md x1 y1 x2 y2 vx vy")
    first_no, first = numbered[0]
    pairs = _fields(first, f"{path}, line {first_no}")
    if len(pairs) != 1 or pairs[0][0] != "nl":
        raise ProblemError(f"{path}, line {first_no}: {first.strip()!r}; expected 'nl = N'")
    nl = _int(pairs[0][1], f"{path}, line {first_no}", "nl")
    if nl < 0:
        raise ProblemError(f"{path}, line {first_no}: nl = {nl}; allowed: >= 0")
    body = numbered[1:]
    if len(body) != nl:
        raise ProblemError(f"{path}: nl = {nl} but {len(body)} md lines follow (line "
                           f"{first_no} + 1 on); each is 'md x1 y1 x2 y2 vx vy'")
    out = []
    names = ("md", "x1", "y1", "x2", "y2", "vx", "vy")
    for number, line in body:
        where = f"{path}, line {number}"
        tokens = line.split()
        if len(tokens) != 7:
            raise ProblemError(f"{where}: {len(tokens)} values {tokens}; expected 7: "
                               + " ".join(names))
        ints = [_int(t, where, n) for t, n in zip(tokens, names, strict=True)]
        problem = md_problem(ints[0])
        if problem:
            raise ProblemError(f"{where}: {problem}")
        out.append(MdLine(*ints))
    return out


def read_control(path: Path) -> Control:
    """The control file ``in``: ist, nam1, nam3, nam4 [, nam5]."""
    path = Path(path)
    tokens = _read_text(path).split()
    if len(tokens) < 4:
        raise ProblemError(f"{path}: {len(tokens)} entries; expected ist, nam1 (parameter "
                           "file), nam3 (step summary), nam4 (dump) [, nam5 (marked grains)]")
    ist = _int(tokens[0], f"{path}, line 1", "ist")
    if ist not in range(5):
        raise ProblemError(f"{path}, line 1: ist = {ist}; allowed: 0..4 (output modes)")
    return Control(ist, tokens[1], tokens[2], tokens[3], tokens[4] if len(tokens) > 4 else None)


def read_problem(path: Path) -> Problem:
    """A whole problem from its control file ``in`` (or the folder holding it); the other
    files' names are relative to the control file's folder."""
    path = Path(path)
    if path.is_dir():
        path = path / "in"
    control = read_control(path)
    folder = path.parent
    values, nam2 = read_parameters(folder / control.nam1)
    lines = read_initial_data(folder / nam2)
    names = {f.name for f in fields(LgdParams)}
    params = LgdParams(**{k: v for k, v in values.items() if k in names})
    return Problem(params=params, lines=lines, nt=values["nt"], nto=values["nto"],
                   mvx=values["mvx"], mvy=values["mvy"], control=control, nam2=nam2)


def _read_text(path: Path) -> str:
    try:
        return Path(path).read_text()
    except OSError as exc:
        raise ProblemError(f"{path}: cannot be read ({exc.strerror or exc})") from None


# -- building the lattice ------------------------------------------------------------------
def _cdiv(a: np.ndarray, b: int) -> np.ndarray:
    """C's integer division (truncation toward zero), b != 0."""
    q = np.abs(a) // abs(b)
    return np.where((a < 0) != (b < 0), -q, q)


def _points(line: MdLine) -> tuple[np.ndarray, np.ndarray]:
    """User (ix, iy) of the nodes a ±2, ±3 or ±6 line covers, in the listing's order."""
    if abs(line.md) == 2:
        dx, dy = line.x2 - line.x1, line.y2 - line.y1
        npl = max(abs(dx), abs(dy))
        if npl == 0:  # the listing divides 0/0 here; take the one point
            return np.array([line.x1]), np.array([line.y1])
        ll = np.arange(npl + 1)
        return line.x1 + _cdiv(dx * ll, npl), line.y1 + _cdiv(dy * ll, npl)
    xs, ys = [], []
    for iy in range(line.y1, line.y2 + 1):
        if abs(line.md) == 3:
            start, step = line.x1, 1
        else:  # density 1/3: displaced rows start 2 (odd row) or 1 (even row) further on
            iox = (2 if iy % 2 == 1 else 1) if (iy - line.y1) % 2 == 1 else 0
            start, step = line.x1 + iox, 3
        ix = np.arange(start, line.x2 + 1, step)
        xs.append(ix)
        ys.append(np.full(len(ix), iy))
    if not xs:
        return np.zeros(0, int), np.zeros(0, int)
    return np.concatenate(xs), np.concatenate(ys)


def wall_rows(lat: Lattice, par: LgdParams) -> None:
    """Rows 1 and nyt: wall particles moving along x at jx1 and jx2 (L1831–L1856)."""
    for row, jx in ((0, par.jx1), (-1, par.jx2)):
        lat.mlp[row] = WALL
        lat.ivx[row] = jx


def build_lattice(par: LgdParams, lines: list[MdLine], notes: list[str] | None = None
                  ) -> Lattice:
    """The initial lattice of ``lines`` (the listing's main L1831–L2006): wall rows, then the
    lines in order. Points outside rows 1..nyt are skipped (counted in ``notes``)."""
    nxt, nyt = par.nxt, par.nyt
    lat = Lattice.empty(nxt, nyt)
    wall_rows(lat, par)
    skipped, marked = 0, 0
    k = 0
    while k < len(lines):
        line = lines[k]
        problem = md_problem(line.md)
        if problem:
            raise ProblemError(problem)
        if line.md in (-1, 0, 1):  # a run of single-node lines at once (fills: 1e5+ lines)
            end = k
            while end < len(lines) and lines[end].md in (-1, 0, 1):
                end += 1
            skipped += _single_nodes(lat, lines[k:end])
            k = end
            continue
        k += 1
        if line.md > 10:
            marked += 1  # numbered by its line, placed or not (L1986)
        if abs(line.md) in (2, 3, 6):
            ix, iy = _points(line)
            inside = (iy >= 1) & (iy <= nyt)
            skipped += int(np.count_nonzero(~inside))
            r, c = iy[inside] - 1, storage_column(ix[inside], iy[inside], nxt)
            lat.ivx[r, c] = line.vx
            lat.ivy[r, c] = line.vy
            lat.mlp[r, c] = MOVABLE if line.md > 0 else WALL
            continue
        if not 1 <= line.y1 <= nyt:
            skipped += 1
            continue
        r, c = line.y1 - 1, int(storage_column(line.x1, line.y1, nxt))
        lat.ipx[r, c], lat.ipy[r, c] = line.x2, line.y2
        lat.ivx[r, c], lat.ivy[r, c] = line.vx, line.vy
        lat.nlp[r, c] = marked
        lat.mlp[r, c] = MOVABLE
    if skipped and notes is not None:
        notes.append(f"{skipped} points outside rows 1..{nyt} skipped (as the listing does)")
    lat.ng = int(np.count_nonzero(lat.mlp > 0))
    return lat


def _single_nodes(lat: Lattice, lines: list[MdLine]) -> int:
    """Apply md ±1 / 0 lines in order (a later line on the same node wins); returns the
    number skipped for lying outside rows 1..nyt."""
    nyt, nxt = lat.mlp.shape
    v = np.array([ln.values() for ln in lines], dtype=np.int64).reshape(-1, 7)
    inside = (v[:, 2] >= 1) & (v[:, 2] <= nyt)
    v = v[inside]
    flat = (v[:, 2] - 1) * nxt + storage_column(v[:, 1], v[:, 2], nxt)
    # the last line on each node: unique over the reversed order keeps first occurrences
    _, first = np.unique(flat[::-1], return_index=True)
    last = len(flat) - 1 - first
    v, flat = v[last], flat[last]
    for name, col in (("ipx", 3), ("ipy", 4), ("ivx", 5), ("ivy", 6), ("mlp", 0)):
        np.put(getattr(lat, name), flat, v[:, col])
    return int(np.count_nonzero(~inside))


# -- writing -------------------------------------------------------------------------------
def lattice_to_lines(lat: Lattice, par: LgdParams) -> list[MdLine]:
    """md lines that rebuild ``lat`` with :func:`build_lattice` (wall rows as jx1/jx2 give
    them): runs of identical plain grains or walls along a user row as ±2 lines, every other
    node as one ±1, 0 or marked line. Marked grains are written in their number order, and a
    gap in the numbers as a marked line outside the lattice (row 0), which the listing counts
    but does not place."""
    nyt, nxt = lat.mlp.shape
    default = Lattice.empty(nxt, nyt)
    wall_rows(default, par)
    out: list[MdLine] = []
    for r in range(nyt):
        ix_of_c = user_column(np.arange(nxt), r, nxt)
        order = np.argsort(ix_of_c)  # storage columns in user order ix = 1..nxt
        k = 0
        while k < nxt:
            c = order[k]
            here = _node(lat, r, c)
            if here == _node(default, r, c) or lat.nlp[r, c]:
                k += 1
                continue
            plain = here[0] in (MOVABLE, WALL) and here[1] == here[2] == 0
            end = k
            while plain and end + 1 < nxt and _node(lat, r, order[end + 1]) == here \
                    and not lat.nlp[r, order[end + 1]]:
                end += 1
            ix1, ix2 = int(ix_of_c[c]), int(ix_of_c[order[end]])
            md, _, _, vx, vy = here
            if end > k:
                out.append(MdLine(2 * md, ix1, r + 1, ix2, r + 1, vx, vy))
            else:
                out.append(MdLine(md, ix1, r + 1, here[1], here[2], vx, vy))
            k = end + 1
    marks = np.argwhere(lat.nlp > 0)
    numbered = sorted((int(lat.nlp[r, c]), int(r), int(c)) for r, c in marks)
    expected = 1
    for number, r, c in numbered:
        if number < expected:
            raise ProblemError(f"marked-grain number {number} is used twice; the file format "
                               "numbers marked grains 1, 2, … by line")
        out += [MdLine(11, 1, 0)] * (number - expected)  # counted, not placed
        md, ipx, ipy, vx, vy = _node(lat, r, c)
        ix = int(user_column(c, r, nxt))
        if md == MOVABLE:
            out.append(MdLine(11, ix, r + 1, ipx, ipy, vx, vy))
        else:  # a mark left on a node overwritten later (the listing keeps marks)
            out += [MdLine(11, ix, r + 1), MdLine(md, ix, r + 1, ipx, ipy, vx, vy)]
        expected = number + 1
    return out


def _node(lat: Lattice, r: int, c: int) -> tuple[int, int, int, int, int]:
    return (int(lat.mlp[r, c]), int(lat.ipx[r, c]), int(lat.ipy[r, c]), int(lat.ivx[r, c]),
            int(lat.ivy[r, c]))


def write_problem(folder: Path, problem: Problem) -> Path:
    """Write ``problem`` as Gutt's three files in ``folder`` (its control's and nam2's
    names); returns the control file's path. ``id``/``idx``/``idy`` left None are written
    with their documented defaults (``LgdParams.resolved``)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    par = problem.params.resolved()
    ctl = problem.control
    names = [str(ctl.ist), ctl.nam1, ctl.nam3, ctl.nam4] + ([ctl.nam5] if ctl.nam5 else [])
    (folder / "in").write_text("\n".join(names) + "\n")
    values = {f.name: getattr(par, f.name) for f in fields(LgdParams)}
    values.update(nam2=problem.nam2, nt=problem.nt, nto=problem.nto, mvx=problem.mvx,
                  mvy=problem.mvy)
    text = "".join(" ".join(f"{n:>4} = {values[n]:>6}" for n in names) + "\n"
                   for names in PARAMETER_LINES)
    (folder / ctl.nam1).write_text(text)
    rows = [f"  nl = {len(problem.lines):6d}"]
    rows += ["{:3d}{:7d}{:7d}{:7d}{:7d}{:8d}{:8d}".format(*ln.values()) for ln in problem.lines]
    (folder / problem.nam2).write_text("\n".join(rows) + "\n")
    return folder / "in"


def c_field_problems(problem: Problem) -> list[str]:
    """Values the listing's fixed-width reads (``%6d``, ``%6s``) could not take whole: the
    files stay readable here, but not by the C program."""
    par = problem.params.resolved()
    out = []
    values = {f.name: getattr(par, f.name) for f in fields(LgdParams)}
    values.update(nt=problem.nt, nto=problem.nto, mvx=problem.mvx, mvy=problem.mvy)
    for names in PARAMETER_LINES:
        for name in names:
            if name != "nam2" and len(str(values[name])) > 6:
                out.append(f"{name} = {values[name]}: more than the 6 characters of %6d")
    if len(problem.nam2) > 6:
        out.append(f"nam2 = {problem.nam2!r}: more than the 6 characters of %6s")
    return out


def speed_rms(lat: Lattice) -> float:
    """Root mean square speed of the movable grains (integer units; 0 without grains)."""
    grains = lat.mlp > 0
    if not grains.any():
        return 0.0
    v2 = lat.ivx[grains].astype(float) ** 2 + lat.ivy[grains].astype(float) ** 2
    return math.sqrt(float(v2.mean()))

