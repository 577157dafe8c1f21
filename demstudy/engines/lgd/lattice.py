"""Gutt's (1989) lattice grain dynamics (LGD): the lattice state and the parameters, in the
listing's integer units (thesis App. 3; ../shared/reference/gutt1989.md §3).

This module fixes the interface between the LGD step (``demstudy.engines.lgd.reference``, a
numpy port of the C listing, and the native core ``demstudy._native.lgd_run``, which must
agree with it bit for bit) and everything above it (problem files, scenes, the backend).

Integer units (the listing's; [derived] in the digest §3.4): offsets ``ipx, ipy`` in 1/4096
of the listing's "cm", the lattice spacing ``idl`` in the same units (so d = idl/4096 cm),
velocities ``ivx, ivy`` in 1/256 cm/s, time ticks ``it`` in 1/65536 s, gravity ``igx, igy``
in cm/s². The backend converts to demstudy's dimensionless particle units (d = 1, m = 1,
g = 1 when gravity acts, otherwise the wall speed sets the time unit) when it writes frames.

Storage: arrays of shape ``(nyt, nxt)``; array row ``r = R - 1`` (Gutt's global row R, 1 =
bottom wall row, nyt = top wall row), array column ``c = G - 1`` (Gutt's axial storage column
G, periodic in x). Physical position of node (c, r), in lattice spacings:
``x = (c + 1 + r/2) mod nxt``, ``y = r·√3/2``. Neighbour offsets (Δc, Δr): d (+1, 0),
b (0, +1), a (−1, +1), c (−1, 0), e (0, −1), f (+1, −1) (digest §3.2 table).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["EMPTY", "MOVABLE", "MOVED", "WALL", "Lattice", "LgdParams", "STEP_LOG_FIELDS"]

#: ``mlp`` modes (digest §3.3)
WALL, EMPTY, MOVABLE, MOVED = -1, 0, 1, 2


@dataclass
class LgdParams:
    """Gutt's parameter-file fields (digest §3.4), integer units. Defaults marked "assumed"
    are not given in the thesis (digest §8 "Unknowns")."""

    nxt: int  # columns (periodic in x), a multiple of 6
    nyt: int  # rows, including the wall rows 1 and nyt
    idl: int = 4096  # lattice spacing in offset units (assumed: 1 cm)
    id: int | None = None  # min offset² for a move attempt; None: (idl // 2)**2 (assumed)
    icb: int = 0  # crossover normal speed c_b of the piecewise restitution (velocity units)
    ke: int = 16  # integer scale of the restitution coefficients (assumed)
    iep1: int = 16  # ke·e_pp below c_b (before the listing adds ke)
    iep2: int = 16  # ke·e_pp above c_b
    iew1: int = 16  # ke·e_pw below c_b
    iew2: int = 16  # ke·e_pw above c_b
    igx: int = 0  # gravity, cm/s²
    igy: int = 0
    jx1: int = 0  # x velocity of the bottom wall row (R = 1)
    jx2: int = 0  # x velocity of the top wall row (R = nyt)
    kq: int = 1560  # cos/sin 60° as kx/kq, ky/kq (thesis L999)
    kx: int = 780
    ky: int = 1351
    ntu: int = 3  # move passes (9 templates each) per step ("typically 3", assumed)
    idx: int | None = None  # x offset of a diagonal step; None: idl // 2
    idy: int | None = None  # y offset of a row; None: round(idl·√3/2)

    def resolved(self) -> LgdParams:
        """A copy with the None fields filled by their documented defaults."""
        out = LgdParams(**self.__dict__)
        if out.id is None:
            out.id = (out.idl // 2) ** 2
        if out.idx is None:
            out.idx = out.idl // 2
        if out.idy is None:
            out.idy = int(round(out.idl * np.sqrt(3.0) / 2.0))
        return out


@dataclass
class Lattice:
    """The LGD state: one grain per node (digest §3.3), arrays of shape (nyt, nxt).

    ``mlp``: −1 wall particle (infinite mass; may carry a velocity; its ``ipx, ipy``
    accumulate the impulse it absorbs during a step), 0 empty, 1 movable, 2 movable and done
    this step. ``nlp``: marked-grain number (0 = unmarked). ``pv``: the previous step's
    peak-speed grain (v², vx, vy), used by the next step's time step. ``nn``: the number of
    the next step (starts at 1; odd/even steps reverse the collision order). ``itt``: the
    elapsed time in ticks. ``ng``: movable grains, counted once at the start (the listing's
    normalisation of the statistics).
    """

    mlp: np.ndarray  # int8
    ipx: np.ndarray  # int64
    ipy: np.ndarray
    ivx: np.ndarray
    ivy: np.ndarray
    nlp: np.ndarray  # int32
    pv: tuple[int, int, int] = (0, 0, 0)
    nn: int = 1
    itt: int = 0
    ng: int = 0
    extra: dict = field(default_factory=dict)

    @classmethod
    def empty(cls, nxt: int, nyt: int) -> Lattice:
        shape = (nyt, nxt)
        z = lambda: np.zeros(shape, np.int64)  # noqa: E731
        return cls(mlp=np.zeros(shape, np.int8), ipx=z(), ipy=z(), ivx=z(), ivy=z(),
                   nlp=np.zeros(shape, np.int32))


#: what one step logs (the listing's step-summary line, L2480), one value per step:
#: nn, it (ticks), itt (ticks), sum_vx, sum_vy, sum_v2 (over movable grains), peak_v2,
#: is1, ip1 (bottom wall row: Σ accumulated x, y impulse per unit grain mass, not divided by
#: nxt), is2, ip2 (top wall row), is3, ip3 (extra wall particles), nq (movable grains with
#: x > nxt/2, counted only when extra walls exist; the hourglass discharge count)
STEP_LOG_FIELDS = ("nn", "it", "itt", "sum_vx", "sum_vy", "sum_v2", "peak_v2",
                   "is1", "ip1", "is2", "ip2", "is3", "ip3", "nq")
