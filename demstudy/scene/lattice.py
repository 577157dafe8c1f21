"""The ``[lattice]`` section: a scene on Gutt's (1989) LGD lattice (``--engine lgd`` only).

Units: the section itself holds the listing's integers (docs/lgd-engine.md): md-line offsets
in 1/``idl`` of a lattice spacing, md-line velocities in 1/256 "cm/s", ``gravity_scale`` in
"cm/s²", ``speed_scale`` in 1/256 "cm/s". The rest of the scene stays in demstudy's
dimensionless particle units (d = 1 = the lattice spacing, m = 1, g = 1 when gravity acts;
without gravity a wall speed, or else the grains' initial r.m.s. speed, is the speed unit);
``speed_scale``/``gravity_scale`` link the two.

A lattice scene is 2D, its box is the lattice (``[nxt, (nyt − 1)·√3/2]``: x periodic, y from
the centres of the bottom wall row to those of the top one; filled in when ``[box]`` is left
out), its two walls are the wall rows 1 and nyt (both ``[[walls]]`` are required: the listing
always builds them), and its grains come from md lines (``initial`` and/or ``initial_file``)
and seeded random fills (``fill``) rather than ``[initial]``/``[particles]``.

``[[lattice.fill]]`` is demstudy's extension of Gutt's format (the listing has no random
fill): ``count`` grains (or round(``density`` × nodes)) drawn without replacement from the
empty nodes of a user rectangle, seeded by the fill's ``seed`` or else the scene's
``run.seed``. Fills apply after every md line, in their order (:mod:`demstudy.engines.lgd.fill`),
and become md ±1 lines, so a problem file written from the scene holds the same lattice.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path
from typing import Literal

from pydantic import Field, model_validator

from .base import Float, Int, PosFloat, PosInt, StrictModel

__all__ = ["ROW_HEIGHT", "LatticeFill", "LatticeLine", "LatticeSpec", "lattice_box",
           "lattice_grains"]

#: y distance between two lattice rows, in spacings
ROW_HEIGHT = math.sqrt(3.0) / 2.0


class LatticeLine(StrictModel):
    """One of Gutt's initial-data lines (``md x1 y1 x2 y2 vx vy``, user coordinates, the
    listing's integers): md ±1 one grain/wall particle with offset (x2, y2), ±2 a line, ±3 a
    rectangle, ±6 a rectangle at density 1/3, 0 empty, > 10 a marked grain (docs/lgd-engine.md,
    :mod:`demstudy.engines.lgd.problem`)."""

    md: Int
    x1: Int
    y1: Int
    x2: Int = 0
    y2: Int = 0
    vx: Int = 0
    vy: Int = 0

    @model_validator(mode="after")
    def _known_code(self) -> LatticeLine:
        from ..engines.lgd.problem import md_problem  # noqa: PLC0415 (numpy)

        problem = md_problem(self.md)
        if problem:
            raise ValueError(problem)
        return self


class LatticeFill(StrictModel):
    """A seeded random fill (demstudy's extension of Gutt's md lines; module docstring):
    ``count`` grains, or ``density`` × the rectangle's nodes (rounded), on empty nodes of the
    user rectangle [x1, x2] × [y1, y2], each with offset 0 and velocity (vx, vy) in the
    listing's integers; md 1 movable grains, md −1 wall particles."""

    x1: Int
    y1: Int
    x2: Int
    y2: Int
    density: Float | None = Field(default=None, gt=0.0, le=1.0)
    count: PosInt | None = None
    md: Literal[1, -1] = 1
    vx: Int = 0
    vy: Int = 0
    #: None: the scene's run.seed
    seed: Int | None = Field(default=None, ge=0, lt=2**63)

    @model_validator(mode="after")
    def _one_amount(self) -> LatticeFill:
        if (self.density is None) == (self.count is None):
            raise ValueError(f"density = {self.density}, count = {self.count}: give exactly "
                             "one (density in (0, 1] of the rectangle's nodes, or a count)")
        if self.x1 > self.x2 or self.y1 > self.y2:
            raise ValueError(f"rectangle x1 = {self.x1}, x2 = {self.x2}, y1 = {self.y1}, "
                             f"y2 = {self.y2}: allowed: x1 <= x2 and y1 <= y2")
        return self

    def amount(self) -> int:
        from ..engines.lgd.fill import fill_count  # noqa: PLC0415 (numpy)

        return fill_count(self.x1, self.y1, self.x2, self.y2, self.density, self.count)


class LatticeSpec(StrictModel):
    """Gutt's lattice: size, integer scales and initial data. Defaults marked "assumed" are
    not given in the thesis (digest §8)."""

    nxt: PosInt  # columns (x, periodic): a multiple of 6
    nyt: PosInt  # rows including the wall rows 1 and nyt: >= 4
    idl: PosInt = 4096  # offset units per spacing (assumed: "1 cm")
    idx: PosInt | None = None  # None: idl // 2
    idy: PosInt | None = None  # None: round(idl·√3/2)
    id: Int | None = Field(default=None, ge=0)  # min offset² to move; None: (idl//2)² (assumed)
    ke: PosInt = 16  # integer scale of the restitution coefficients (assumed)
    ntu: PosInt = 3  # move passes per step ("typically three", L936; assumed for every run)
    kq: PosInt = 1560  # cos/sin 60° as kx/kq, ky/kq (L999)
    kx: PosInt = 780
    ky: PosInt = 1351
    #: |g| in the listing's cm/s² when [gravity] acts (assumed 8: the Poiseuille run's g)
    gravity_scale: PosFloat = Field(default=8.0, le=1e6)
    #: without gravity: the listing's integer speed of particle speed 1 (needed with moving
    #: walls, e.g. Gutt's Couette wall speed 4096; default with walls at rest: the grains'
    #: initial r.m.s. speed)
    speed_scale: PosFloat | None = Field(default=None, le=1e9)
    #: grain–wall restitution above the crossover speed (None: the walls' restitution, i.e.
    #: constant); needs contact.law 'gutt-piecewise' for the crossover speed
    wall_e2: Float | None = Field(default=None, ge=0.0, le=1.0)
    initial: list[LatticeLine] = []
    #: Gutt's initial-data file (``nl = N`` + md lines), applied before ``initial``; a
    #: relative path is relative to the working directory
    initial_file: str | None = None
    #: seeded random fills, applied after the md lines in order (an extension of Gutt's
    #: format; module docstring); None (not []) keeps older scenes' dumps unchanged
    fill: list[LatticeFill] | None = None

    @model_validator(mode="after")
    def _sizes(self) -> LatticeSpec:
        problems = []
        if self.nxt < 6 or self.nxt % 6:
            problems.append(f"lattice.nxt = {self.nxt}: allowed: a multiple of 6 (move "
                            "templates have period 3, collision templates period 2)")
        if self.nyt < 4:
            problems.append(f"lattice.nyt = {self.nyt}: allowed: >= 4 (two wall rows and at "
                            "least two open rows)")
        if self.nxt * self.nyt > 50_000_000:
            problems.append(f"lattice: nxt × nyt = {self.nxt * self.nyt} nodes; allowed: at "
                            "most 5e7")
        if not self.initial and self.initial_file is None and not self.fill:
            problems.append("lattice: give the grains as md lines (initial), Gutt's "
                            "initial-data file (initial_file) or random fills (fill)")
        for k, f in enumerate(self.fill or []):
            if not (1 <= f.x1 and f.x2 <= self.nxt and 1 <= f.y1 and f.y2 <= self.nyt):
                problems.append(f"lattice.fill[{k}]: rectangle x {f.x1}..{f.x2}, y {f.y1}.."
                                f"{f.y2}; allowed: inside the lattice, x in 1..{self.nxt} "
                                f"(user columns), y in 1..{self.nyt} (rows)")
                continue
            nodes = (f.x2 - f.x1 + 1) * (f.y2 - f.y1 + 1)
            if not 1 <= f.amount() <= nodes:
                what = f"count = {f.count}" if f.count is not None else \
                    f"density = {f.density} gives {f.amount()} grains"
                problems.append(f"lattice.fill[{k}]: {what}; allowed: 1..{nodes} (the "
                                "rectangle's nodes)")
        if problems:
            raise ValueError("; ".join(problems))
        return self

    def lines(self, seed: int) -> list:
        """Every md line as ``problem.MdLine``: ``initial_file``'s, then ``initial``, then
        each fill's ±1 lines (drawn with the fill's seed or else ``seed``, the scene's
        run.seed). ValueError naming the fill when its rectangle lacks empty nodes."""
        from ..engines.lgd.fill import fill_lines  # noqa: PLC0415 (numpy)
        from ..engines.lgd.lattice import LgdParams  # noqa: PLC0415
        from ..engines.lgd.problem import MdLine, build_lattice, read_initial_data  # noqa: PLC0415

        out = list(read_initial_data(Path(self.initial_file))) if self.initial_file else []
        out += [MdLine(*(getattr(ln, k) for k in ("md", "x1", "y1", "x2", "y2", "vx", "vy")))
                for ln in self.initial]
        if not self.fill:
            return out
        par = LgdParams(nxt=self.nxt, nyt=self.nyt)
        lat = build_lattice(par, out)  # the empty nodes the first fill draws from
        for k, f in enumerate(self.fill):  # not None here
            new = fill_lines(lat, x1=f.x1, y1=f.y1, x2=f.x2, y2=f.y2, count=f.amount(),
                             md=f.md, vx=f.vx, vy=f.vy, seed=seed if f.seed is None else
                             f.seed, index=k, where=f"lattice.fill[{k}]")
            out += new
            if k + 1 < len(self.fill):
                lat = build_lattice(par, out)
        return out


def lattice_box(spec: LatticeSpec) -> list[float]:
    """The box of a lattice scene: [nxt, (nyt − 1)·√3/2] (wall-row centre to centre)."""
    return [float(spec.nxt), (spec.nyt - 1) * ROW_HEIGHT]


@functools.lru_cache(maxsize=32)
def _grain_count(spec_json: str, seed: int, _file_stamp: int) -> tuple[int, float]:
    spec = LatticeSpec.model_validate_json(spec_json)
    from ..engines.lgd.lattice import LgdParams  # noqa: PLC0415
    from ..engines.lgd.problem import build_lattice, speed_rms  # noqa: PLC0415

    lat = build_lattice(LgdParams(nxt=spec.nxt, nyt=spec.nyt), spec.lines(seed))
    return lat.ng, speed_rms(lat)


def lattice_grains(spec: LatticeSpec, seed: int) -> tuple[int, float]:
    """Movable grains of the initial lattice and their r.m.s. speed (integer units);
    ``seed``: the scene's run.seed (for fills without their own)."""
    stamp = 0
    if spec.initial_file is not None:  # an edited file is read again
        try:
            stamp = Path(spec.initial_file).stat().st_mtime_ns
        except OSError:
            stamp = -1
    return _grain_count(spec.model_dump_json(), seed, stamp)
