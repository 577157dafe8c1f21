"""The simulation box: periodic axes, walls, Lees–Edwards images, and one neighbour query.

Dimensionless particle units: d = 1, m = 1 (lengths in diameters, velocities in d per time
unit). Axes: x (0) the flow direction, always periodic; y (1) wall-normal, periodic only
without walls; z (2) spanwise (3D), periodic. Modelled on freud's ``Box`` /
``NeighborQuery``: the analyses (g(r), velocity and orientational correlations, Campbell's
structure distributions) state the geometry once, as a :class:`Box`, and share its
:meth:`Box.wrap` and :class:`NeighbourQuery` instead of restating them.

Lees–Edwards. With shear the y axis is periodic and the image at ``y + k L_y`` sits at
``x + k tilt`` and moves with ``u_x + k shear_velocity`` (``shear_velocity`` = γ̇ L_y). A
centre moved across y by k periods (``wrap``) therefore gets ``x -= k tilt`` and
``u_x -= k γ̇ L_y`` together; partners seen through the y boundary are the explicit images
at ``y ± L_y``, ``x ± tilt``.

Why scipy's ``cKDTree`` and not freud (``freud-analysis`` 3.4, checked): freud holds
positions and distances in single precision, so pair counts would move between shells at
their edges (the results would change, not merely by double round-off); its pair queries
refuse a box with a non-periodic axis ("Pair queries in a non-periodic box are not
implemented"), which walls need; and its boxes are 2D or 3D only, while Malik's "planar"
distance in 2D is a 1D periodic query. ``cKDTree`` (double precision, per-axis ``boxsize``)
does all of these: a bounded axis is embedded in a period long enough never to wrap, and
the Lees–Edwards images are added explicitly. The query below keeps exactly the tree
layouts the three analyses used before, so their results did not change.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numpy.typing import ArrayLike

if TYPE_CHECKING:
    from demstudy.io.frames import Frame

__all__ = ["Box", "NeighbourQuery", "Pairs", "Wrapped"]


class Wrapped(NamedTuple):
    """Centres put into the box by :meth:`Box.wrap`.

    position: (N, dim) inside the box along every periodic axis.
    velocity: (N, dim) with the Lees–Edwards image velocity removed (None if not given).
    image: (N, dim) int, the periods each centre was moved by along each axis:
        ``position = original - image * lengths`` and, along x, ``- image_y * tilt``.
    """

    position: np.ndarray
    velocity: np.ndarray | None
    image: np.ndarray


class Pairs(NamedTuple):
    """Ordered pairs (i, j), i != j, with their minimum-image distance (diameters)."""

    i: np.ndarray
    j: np.ndarray
    distance: np.ndarray


def _periods(rel: np.ndarray, length: float) -> tuple[np.ndarray, np.ndarray]:
    """(k, r) with rel = r + k * length and 0 <= r < length, consistently after round-off."""
    k = np.floor(rel / length)
    r = rel - k * length
    below = r < 0
    k[below] -= 1
    r[below] += length
    above = r >= length  # also a tiny negative r that rounded up to length above
    k[above] += 1
    r[above] -= length
    return k, r


def wrap_periodic(values: np.ndarray, lo: float, length: float) -> tuple[np.ndarray, np.ndarray]:
    """(wrapped, turns): ``values`` put into [lo, lo + length) along one periodic axis, and
    how many periods each moved (``wrapped = values - turns * length``); values already
    inside come back bit for bit. The image rule of every periodic coordinate (a Lees–Edwards
    centre that moved by ``turns`` periods along y moves its x velocity by ``-turns`` times
    the image velocity)."""
    out = np.array(values, dtype=float)
    turns = np.zeros(out.shape)
    rel = out - lo
    outside = np.flatnonzero(~((rel >= 0) & (rel < length)))
    if outside.size:
        k, r = _periods(rel[outside], length)
        out[outside] = _into(lo, r, length)
        turns[outside] = k
    return out, turns


@dataclass(frozen=True, eq=False)
class Box:
    """An immutable box ``[lo, lo + lengths)`` with per-axis periodicity.

    lo, lengths: (dim,) origin and edge lengths (diameters); dim 1, 2 or 3 (1: a projection).
    periodic: (dim,) which axes wrap; x and z always do in demstudy, y only without walls.
    tilt: Lees–Edwards x offset of the image at ``y + L_y`` (needs x and y periodic).
    shear_velocity: x velocity of the image at ``y + L_y`` relative to the original, γ̇ L_y
        (0 when unknown or not needed: only velocities are shifted by it).
    walls: (lower, upper) wall positions along a bounded y, if known (carried for callers;
        the query never looks across a bounded axis, walls or not).
    """

    lo: np.ndarray
    lengths: np.ndarray
    periodic: tuple[bool, ...]
    tilt: float = 0.0
    shear_velocity: float = 0.0
    walls: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        lo, lengths = np.array(self.lo, float).ravel(), np.array(self.lengths, float).ravel()
        periodic = tuple(bool(p) for p in self.periodic)
        if not 1 <= lo.size <= 3 or lengths.shape != lo.shape or len(periodic) != lo.size:
            raise ValueError("lo, lengths and periodic need one entry per axis (1 to 3)")
        if not np.all(np.isfinite(lo)) or not np.all((lengths > 0) & np.isfinite(lengths)):
            raise ValueError(f"box lengths must be positive and finite, got {lengths}")
        y_images = lo.size >= 2 and periodic[0] and periodic[1]
        if (self.tilt or self.shear_velocity) and not y_images:
            raise ValueError("a Lees-Edwards tilt or shear velocity needs periodic x and y")
        if self.walls is not None and (lo.size < 2 or periodic[1]):
            raise ValueError("walls bound a non-periodic y")
        lo.flags.writeable = lengths.flags.writeable = False
        object.__setattr__(self, "lo", lo)
        object.__setattr__(self, "lengths", lengths)
        object.__setattr__(self, "periodic", periodic)
        object.__setattr__(self, "tilt", float(self.tilt))
        object.__setattr__(self, "shear_velocity", float(self.shear_velocity))
        if self.walls is not None:
            object.__setattr__(self, "walls", (float(self.walls[0]), float(self.walls[1])))

    @classmethod
    def from_frame(cls, frame: Frame, periodic_y: bool | None = None,
                   shear_velocity: float | None = None) -> Box:
        """The box of ``frame``: x and z periodic, y periodic when ``periodic_y`` (default:
        ``frame.periodic_y``); the tilt and ``shear_velocity`` (default:
        ``frame.shear_velocity``) count only with a periodic y and are dropped otherwise
        (bounded y: there is no image across it)."""
        y = frame.periodic_y if periodic_y is None else bool(periodic_y)
        shift = frame.shear_velocity if shear_velocity is None else float(shear_velocity)
        lo = np.asarray(frame.box_lo, float)
        periodic = tuple(a != 1 or y for a in range(lo.size))
        return cls(lo, np.asarray(frame.box_hi, float) - lo, periodic,
                   tilt=float(frame.tilt) if y else 0.0, shear_velocity=shift if y else 0.0)

    # -- geometry ------------------------------------------------------------------------
    @property
    def dim(self) -> int:
        return int(self.lo.size)

    @property
    def hi(self) -> np.ndarray:
        return self.lo + self.lengths

    @property
    def sheared(self) -> bool:
        """Lees–Edwards images: y periodic and the image across it offset along x."""
        return self.tilt != 0.0

    @property
    def image_limit(self) -> float:
        """Half the shortest periodic length: farther partners may be seen twice (inf if no
        axis is periodic)."""
        lengths = self.lengths[list(self.periodic)]
        return 0.5 * float(lengths.min()) if lengths.size else float("inf")

    def with_bounded_y(self) -> Box:
        """This box with y bounded (no images across it, no Lees–Edwards offset): pairs
        restricted to one y-bin."""
        periodic = tuple(p and a != 1 for a, p in enumerate(self.periodic))
        return Box(self.lo, self.lengths, periodic)

    def project(self, axes: Sequence[int]) -> Box:
        """The box seen along ``axes`` only, e.g. (0, 2): the x-z plane of Malik's "planar"
        distance. The kept axes are renumbered; dropping y drops the Lees–Edwards offset
        and the walls with it."""
        axes = list(axes)
        if 1 in axes and axes[:2] != [0, 1]:
            raise ValueError("a projection keeping y must start with axes (0, 1)")
        keep_y = 1 in axes
        return Box(self.lo[axes], self.lengths[axes], tuple(self.periodic[a] for a in axes),
                   tilt=self.tilt if keep_y else 0.0,
                   shear_velocity=self.shear_velocity if keep_y else 0.0,
                   walls=self.walls if keep_y else None)

    # -- wrapping ------------------------------------------------------------------------
    def wrap(self, position: ArrayLike, velocity: ArrayLike | None = None) -> Wrapped:
        """Put centres into the box along every periodic axis (copies; inputs untouched).

        A centre moved across y by k periods gets ``x -= k tilt`` and ``u_x -= k
        shear_velocity`` (Lees–Edwards); then x and z are wrapped. Centres already inside
        are returned bit for bit, so wrapping twice changes nothing. Afterwards
        ``0 <= position - lo < lengths`` holds in floating point on the periodic axes.
        """
        pos = np.array(position, dtype=float, ndmin=2)
        if pos.ndim != 2 or pos.shape[1] != self.dim:
            raise ValueError(f"positions must be (N, {self.dim}), got {pos.shape}")
        vel = None if velocity is None else np.array(velocity, dtype=float, ndmin=2)
        if vel is not None and vel.shape != pos.shape:
            raise ValueError("velocities must have the shape of the positions")
        image = np.zeros(pos.shape, np.int64)
        order = (1, 0, 2) if self.dim > 1 else (0,)  # y first: it moves x
        for axis in (a for a in order if a < self.dim and self.periodic[a]):
            pos[:, axis], k = wrap_periodic(pos[:, axis], self.lo[axis], self.lengths[axis])
            out = np.flatnonzero(k)
            if out.size == 0:
                continue
            image[out, axis] = k[out].astype(np.int64)
            if axis == 1:
                pos[out, 0] -= k[out] * self.tilt
                if vel is not None:
                    vel[out, 0] -= k[out] * self.shear_velocity
        return Wrapped(pos, vel, image)

    def minimum_image(self, delta: ArrayLike) -> np.ndarray:
        """The shortest periodic image of separations ``delta`` (..., dim).

        Without tilt each periodic axis is reduced to ``[-L/2, L/2]``. With Lees–Edwards
        images the nearest image need not have the nearest y period (a large tilt can bring
        the next row closer), so every y period that can win is tried.
        """
        d = np.array(delta, dtype=float)
        plain = [a for a in range(self.dim) if self.periodic[a] and not (a == 1 and
                                                                      self.sheared)]
        if not self.sheared:
            return _reduce(d, plain, self.lengths)
        ly = self.lengths[1]
        reach = 0.5 * float(np.sqrt(np.sum(self.lengths**2)))  # |nearest image| <= reach
        span = int(np.ceil(reach / ly)) + 1
        k0 = np.round(d[..., 1] / ly)
        best, best2 = d, np.full(d.shape[:-1], np.inf)
        for step in range(-span, span + 1):
            k = k0 + step
            c = d.copy()
            c[..., 1] -= k * ly
            c[..., 0] -= k * self.tilt
            c = _reduce(c, plain, self.lengths)
            c2 = np.sum(c * c, axis=-1)
            better = c2 < best2
            best = np.where(better[..., None], c, best)
            best2 = np.where(better, c2, best2)
        return best


def _into(lo: float, r: np.ndarray, length: float) -> np.ndarray:
    """lo + r for 0 <= r < length, nudged down where round-off puts it at lo + length."""
    x = lo + r
    high = x - lo >= length
    while np.any(high):
        x[high] = np.nextafter(x[high], -np.inf)
        high = x - lo >= length
    return x


def _reduce(d: np.ndarray, axes: list[int], lengths: np.ndarray) -> np.ndarray:
    for a in axes:
        d[..., a] -= lengths[a] * np.round(d[..., a] / lengths[a])
    return d


class NeighbourQuery:
    """Pairs of points closer than a distance in a :class:`Box`.

    Periodic axes use ``cKDTree``'s ``boxsize`` (the minimum image); a bounded axis is
    embedded in a period longer than its extent plus twice the reach, so the tree never
    wraps there; with a Lees–Edwards tilt, y is embedded like a bounded axis and the images
    at ``y ± L_y``, ``x ± tilt`` of the points within reach of the y boundaries are added
    as partners. Only the images of the nearest y periods are added: beyond
    ``box.image_limit`` (half the shortest period) partners may be counted through several
    images, as with the plain minimum image, and ``count`` then also sees a point's own
    images (the analyses flag those shells).

    points: (N, dim) centres; wrapped here with ``box.wrap`` (a no-op on wrapped ones).
    """

    def __init__(self, box: Box, points: ArrayLike) -> None:
        self.box = box
        self.points = box.wrap(points).position
        self._rel = self.points - box.lo

    @property
    def n(self) -> int:
        return int(self._rel.shape[0])

    def _layout(self, r_max: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(points, partners, owner of each partner, boxsize) for a tree search to r_max."""
        box, rel = self.box, self._rel
        pts, size = rel.copy(), box.lengths.copy()
        owner = np.arange(self.n)
        pad = r_max + 1.0
        for a in range(box.dim):
            if box.periodic[a] and not (a == 1 and box.sheared):
                continue
            bottom = float(rel[:, a].min(initial=0.0))  # <= 0: centres below lo too
            pts[:, a] += (pad - bottom) if bottom else pad
            size[a] = max(box.lengths[a], float(rel[:, a].max(initial=0.0)) - bottom) \
                + 2 * pad + r_max
        if not box.sheared:
            return pts, pts, owner, size
        ly, lx, tilt = box.lengths[1], box.lengths[0], box.tilt
        low = np.flatnonzero(pts[:, 1] - pad < r_max)  # near y = 0: image at y + L_y, x + tilt
        high = np.flatnonzero(pts[:, 1] - pad > ly - r_max)  # near L_y: y - L_y, x - tilt
        up, down = pts[low].copy(), pts[high].copy()
        up[:, 1] += ly
        up[:, 0] = _periods(up[:, 0] + tilt, lx)[1]
        down[:, 1] -= ly
        down[:, 0] = _periods(down[:, 0] - tilt, lx)[1]
        return pts, np.concatenate([pts, up, down]), np.concatenate([owner, low, high]), size

    def count(self, r_edges: ArrayLike) -> np.ndarray:
        """Ordered pairs (i, j) — j any point or image — with ``r_edges[k] < r <=
        r_edges[k+1]``, per shell (int, one fewer than the edges). With ``r_edges[0] = 0``
        a point is not its own partner (coincident points are not counted either). A
        dual-tree count: memory does not grow with the number of pairs."""
        from scipy.spatial import cKDTree  # noqa: PLC0415 - ~0.1 s, not needed by a run

        r_edges = np.asarray(r_edges, float)
        pts, others, _, size = self._layout(float(r_edges[-1]))
        tree = cKDTree(pts, boxsize=size)
        other = tree if others is pts else cKDTree(others, boxsize=size)
        counts = tree.count_neighbors(other, r_edges, cumulative=False)
        return np.asarray(counts, np.int64)[1:]  # [0]: r <= r_edges[0]

    def pairs(self, r_max: float, of: ArrayLike | None = None, chunk: int = 4096) -> Pairs:
        """Ordered pairs (i, j), i != j, at minimum-image distance ``<= r_max``: i over
        ``of`` (indices; default all points), j over all points (an image counts as its
        point). ``chunk`` bounds how many i are searched at once (memory)."""
        from scipy.spatial import cKDTree  # noqa: PLC0415

        pts, others, owner, size = self._layout(float(r_max))
        other_tree = cKDTree(others, boxsize=size)
        chosen = None if of is None else np.asarray(of, np.intp).ravel()
        total = self.n if chosen is None else chosen.size
        chunk = max(1, int(chunk))
        out_i, out_j, out_r = [np.zeros(0, np.intp)], [np.zeros(0, np.intp)], [np.zeros(0)]
        for start in range(0, total, chunk):
            rows = slice(start, start + chunk) if chosen is None else chosen[start:start + chunk]
            sub = cKDTree(pts[rows], boxsize=size)
            res = sub.sparse_distance_matrix(other_tree, r_max, output_type="ndarray")
            local = res["i"].astype(np.intp)
            i = local + start if chosen is None else rows[local]
            j = owner[res["j"]]
            ok = i != j
            out_i.append(i[ok])
            out_j.append(j[ok])
            out_r.append(res["v"][ok])
        return Pairs(np.concatenate(out_i), np.concatenate(out_j), np.concatenate(out_r))
