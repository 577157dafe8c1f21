"""Radial pair correlation g(r), whole box or inside bins along y (Malik's in-bin g(r)).

Dimensionless particle units: d = 1, m = 1 (r in particle diameters).
Axes: x flow (periodic), y wall-normal (the bin axis; periodic or bounded by walls),
z spanwise (3D, periodic).

Definition. Every frame, inside a *region* R (the whole box, or one bin
``edges[b] <= y < edges[b+1]``, both particles of a pair inside the region), the ordered
pairs i != j are counted in shells ``[r_k, r_k+1)`` of the minimum-image distance and

    g_k = < sum_frames n_k >  /  < sum_frames N_R (N_R - 1) / V_R >  /  Omega_k,

with ``N_R`` the number of particle centres in R, ``V_R`` its volume (area in 2D) and
``Omega_k`` the *effective shell volume*: the shell volume weighted by the probability that
the partner of a uniformly placed particle lies in R too. For two independent uniform points
in a slab of width w along y (periodic in the other directions) the separation s has density
``(1 - |s_y|/w)_+ / V_R``, so

    Omega_k = integral over the shell of (1 - |s_y| / w)_+ d^dim s,

which is 4 pi r^2 (1 - r/(2w)) dr (r <= w) and 2 pi r w dr (r > w) for spheres, and
r [2 pi - 4 r/w] dr (r <= w), 4 r [phi0 - (r/w)(1 - cos phi0)] dr (r > w, sin phi0 = w/r)
for discs (integrated over each shell by Gauss-Legendre quadrature). When y is periodic and R
is the whole period, Omega_k is the plain shell volume. With this normalisation an ideal gas
(uniform, independent points) gives g = 1 exactly in a bin of any width and between walls;
``N (N - 1)`` (not Malik's ``N^2``) makes it exact at fixed N (Malik's 2V/N^2 form equals
ours times (1 - 1/N)). This is reading ``distance="full"``: r is the full dim-D distance.
Reading ``distance="planar"`` (Malik: "the distance r spans along the (x, z) plane") uses
the separation projected on the periodic directions (x, z; x alone in 2D) and the plain
(dim-1)-D shell ``2 pi r dr`` (3D) or ``2 dr`` (2D) with ``V_R`` replaced by the area of the
periodic plane.

Periodic images: each frame's :class:`~demstudy.analysis.box.Box` (x, z periodic, y when
``periodic_y``, Lees-Edwards images from ``frame.tilt``) wraps the centres and its
:class:`~demstudy.analysis.box.NeighbourQuery` counts the pairs (minimum image; pairs inside
one bin never across y). Shells beyond half the shortest periodic length see more than one
image of a partner: they are flagged in ``results["image_artefact"]`` (and
``attrs["r_image_limit"]``), not removed.

Errors: the per-frame pair counts and ``N(N-1)/V`` are block-averaged
(:class:`~demstudy.analysis.blocking.BlockAccumulator`) and g's standard error is the
delete-one-block jackknife of the ratio. Memory is flat in the number of frames.
``results["pairs_per_particle"]`` is the mean number of partners per particle in each shell
(ordered pair count / N_R): summed over a peak it is the coordination number of that shell.
"""

from __future__ import annotations

import warnings

import numpy as np
from numpy.typing import ArrayLike

from demstudy import UNITS_NOTE
from demstudy.analysis.base import AnalysisBase
from demstudy.analysis.blocking import BlockAccumulator, jackknife
from demstudy.analysis.box import Box, NeighbourQuery
from demstudy.io.frames import Frame

__all__ = ["PairCorrelation", "slab_shell_volume"]


_GL_X, _GL_W = np.polynomial.legendre.leggauss(16)


def _slab_density(r: np.ndarray, width: float, dim: int) -> np.ndarray:
    """d Omega / dr: shell measure at radius r weighted by (1 - |s_y|/width)_+."""
    r = np.asarray(r, float)
    q = r / width
    if dim == 3:
        return np.where(q <= 1, 4 * np.pi * r**2 * (1 - 0.5 * q), 2 * np.pi * r * width)
    with np.errstate(invalid="ignore", divide="ignore"):
        phi0 = np.arcsin(np.minimum(1.0, 1.0 / np.maximum(q, 1e-300)))
        outer = 4 * r * (phi0 - q * (1 - np.cos(phi0)))
    return np.where(q <= 1, r * (2 * np.pi - 4 * q), outer)


def slab_shell_volume(edges: ArrayLike, width: float, dim: int) -> np.ndarray:
    """Effective volume of each shell ``[edges[k], edges[k+1])`` for pairs inside a slab of
    ``width`` along y (see the module docstring); ``width = inf`` gives the plain shell."""
    edges = np.asarray(edges, float)
    if not np.isfinite(width):
        unit = np.pi if dim == 2 else 4 * np.pi / 3
        return unit * np.diff(edges**dim)
    out = np.zeros(edges.size - 1)
    for k, (a, b) in enumerate(zip(edges[:-1], edges[1:], strict=True)):
        pieces = [a, width, b] if a < width < b else [a, b]
        for lo, hi in zip(pieces[:-1], pieces[1:], strict=False):
            x = 0.5 * (hi - lo) * _GL_X + 0.5 * (hi + lo)
            out[k] += 0.5 * (hi - lo) * np.dot(_GL_W, _slab_density(x, width, dim))
    return out


class PairCorrelation(AnalysisBase):
    """Radial g(r) over the whole box or inside y-bins, periodic and Lees-Edwards aware.

    Parameters
    ----------
    dim: 2 (discs) or 3 (spheres).
    r_max, dr: shells ``[0, dr), [dr, 2 dr), ...`` up to ``r_max``.
    edges_y: bin edges along y (Malik's in-bin g(r): both particles in the bin); None means
        one region, the whole box along y.
    periodic_y: y is periodic (Lees-Edwards boxes); otherwise it is bounded (walls) and
        no minimum image is taken along y. x and z are always periodic.
    distance: "full" (the dim-D distance, slab-corrected shells) or "planar" (the
        separation in the periodic x(z) plane of pairs in the same bin).
    max_blocks: bound on the stored time blocks.
    """

    def __init__(
        self,
        dim: int = 2,
        r_max: float = 5.0,
        dr: float = 0.05,
        edges_y: ArrayLike | None = None,
        periodic_y: bool = False,
        distance: str = "full",
        max_blocks: int = 64,
        verbose: bool = False,
    ) -> None:
        super().__init__(verbose=verbose)
        if dim not in (2, 3):
            raise ValueError(f"dim must be 2 or 3, got {dim!r}")
        if not (r_max > 0 and dr > 0):
            raise ValueError("r_max and dr must be positive")
        if distance not in ("full", "planar"):
            raise ValueError(f"distance must be 'full' or 'planar', got {distance!r}")
        self.dim, self.distance = dim, distance
        self.n_r = max(1, int(round(r_max / dr)))
        self.r_edges = np.linspace(0.0, self.n_r * dr, self.n_r + 1)
        self.periodic_y = bool(periodic_y)
        self.max_blocks = int(max_blocks)
        self._edges_y = None if edges_y is None else np.asarray(edges_y, float)
        if self._edges_y is not None and (
            self._edges_y.ndim != 1 or self._edges_y.size < 2 or np.any(np.diff(self._edges_y) <= 0)
        ):
            raise ValueError("edges_y must be increasing with at least 2 entries")

    # -- hooks -------------------------------------------------------------------------
    def _prepare(self) -> None:
        frame = self.first_frame
        assert frame is not None
        if frame.dim != self.dim:
            raise ValueError(f"frame is {frame.dim}D, analysis is {self.dim}D")
        lo, hi = np.asarray(frame.box_lo, float), np.asarray(frame.box_hi, float)
        self.edges_y = np.array([lo[1], hi[1]]) if self._edges_y is None else self._edges_y
        self.n_bins = self.edges_y.size - 1
        whole_period = self.periodic_y and self._edges_y is None
        widths = np.diff(self.edges_y)
        if self.distance == "planar":
            plain = slab_shell_volume(self.r_edges, np.inf, self.dim - 1) if self.dim == 3 \
                else 2 * np.diff(self.r_edges)
            self.shell = np.tile(plain, (self.n_bins, 1))
        else:
            self.shell = np.stack([
                slab_shell_volume(self.r_edges, np.inf if whole_period else w, self.dim)
                for w in widths
            ])
        self.r_image_limit = Box.from_frame(frame, periodic_y=self.periodic_y).image_limit
        if self.r_edges[-1] > self.r_image_limit:
            warnings.warn(
                f"g(r) beyond r = {self.r_image_limit:g} (half the shortest periodic length) "
                "counts several images of a partner: flagged in results['image_artefact']",
                stacklevel=3,
            )
        self._n_values = self.n_bins * (self.n_r + 2)
        self._acc = BlockAccumulator(self._n_values, self.max_blocks)

    def _single_frame(self, frame: Frame) -> None:
        box = Box.from_frame(frame, periodic_y=self.periodic_y)
        # centres outside the box (engines wrap lazily) move to their image inside it
        pos = box.wrap(frame.position).position
        lengths = box.lengths
        section = lengths[0] * (lengths[2] if self.dim == 3 else 1.0)
        sample = np.zeros((self.n_bins, self.n_r + 2))
        bins = np.searchsorted(self.edges_y, pos[:, 1], side="right") - 1
        whole = self._edges_y is None
        # pairs inside one bin are never seen across y; the planar distance ignores y
        pair_box = box if whole else box.with_bounded_y()
        plane = [0, 2] if self.dim == 3 else [0]
        if self.distance == "planar":
            pair_box, pos = pair_box.project(plane), pos[:, plane]
        for b in range(self.n_bins):
            sel = pos if whole else pos[bins == b]
            n = sel.shape[0]
            volume = section * (self.edges_y[b + 1] - self.edges_y[b])
            if self.distance == "planar":
                volume = section
            sample[b, 0] = n
            sample[b, 1] = n * (n - 1) / volume
            if n >= 2:
                # ordered pairs i != j per shell (r_k, r_k+1]: the same as [r_k, r_k+1)
                # except on a measure-zero set
                sample[b, 2:] = NeighbourQuery(pair_box, sel).count(self.r_edges)
        self._acc.add(sample)

    def _estimate(self, mean: np.ndarray) -> dict[str, np.ndarray]:
        s = mean.reshape(self.n_bins, self.n_r + 2)
        n, pair_density, counts = s[:, 0], s[:, 1], s[:, 2:]
        return {
            "g": counts / (pair_density[:, None] * self.shell),
            "pairs_per_particle": counts / n[:, None],
            "count": n,
        }

    def _conclude(self) -> None:
        est, err = jackknife(self._acc, self._estimate)
        r = 0.5 * (self.r_edges[1:] + self.r_edges[:-1])
        self.results = {
            "r": r,
            "r_edges": self.r_edges,
            "edges_y": self.edges_y,
            "y": 0.5 * (self.edges_y[1:] + self.edges_y[:-1]),
            "g": est["g"],
            "g_err": err["g"],
            "pairs_per_particle": est["pairs_per_particle"],
            "pairs_per_particle_err": err["pairs_per_particle"],
            "mean_count": est["count"],
            "shell_volume": self.shell,
            "image_artefact": self.r_edges[1:] > self.r_image_limit + 1e-12,
        }
        self.attrs = {
            "dim": self.dim,
            "distance": self.distance,
            "periodic_y": self.periodic_y,
            "in_bin": self._edges_y is not None,
            "dr": float(self.r_edges[1]),
            "r_max": float(self.r_edges[-1]),
            "r_image_limit": self.r_image_limit,
            "normalisation": "ordered pairs / (<N(N-1)/V> * slab-weighted shell volume)",
            "samples": self.n_frames,
            "block_length": self._acc.block_length,
            "n_blocks": self._acc.n_blocks,
            "units": UNITS_NOTE,
        }
