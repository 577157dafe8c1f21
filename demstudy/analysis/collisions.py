"""Collision-angle distribution P(theta) per y-bin from a collision log (Campbell 1982).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.

The log (``/collisions`` in a results file of an event-driven run) holds M sampled collisions:
``time`` (M,), ``kind`` (M,) int8 (0 pair, 1 lower wall, 2 upper wall), ``position``
(M, dim) contact point, ``normal`` (M, dim) unit normal from i to j, ``branch``, ``impulse``,
``velocity`` (pre-collision v_i - v_j), ``spin_velocity``. Only pair collisions enter P(theta);
each is binned by the y of its contact point.

Angle conventions (both stored):

* ``text``: theta is the angle of the line of centres from the flow direction x, on [0, pi):
  theta = atan2(n_y, n_x) mod pi (the sign of n does not matter).
* ``listing``: Campbell's code, NA = 1 + INT((pi/2 - atan(BS/BC)) / (pi/50)) with BS, BC the
  normal and along-flow components: theta_listing = (pi/2 - theta_text) mod pi. (The code
  sends BC = 0 to bin 25; that measure-zero special case is not reproduced.)

In 3D theta is the angle of the projection of n on the shear (x, y) plane.

P(theta) = count / (N_bin * Delta theta), normalised on [0, pi) in each y-bin. For an
isotropic gas it is uniform, 1/pi (in 3D too: the azimuth of an isotropic direction about z
is uniform). Savage & Jeffrey's prediction (:func:`demstudy.theory.savage_jeffrey`, 2D)
P = (1/pi) erfc(S cos(theta) sin(theta) / sqrt 2), symmetric under theta -> pi/2 - theta and
therefore the same in both conventions, is the probability that two particles approach for
a relative velocity Gaussian with variance <u'^2> per component about the mean-shear
difference -(du/dy) d n_y x (not weighted by the approach rate). In 3D the projected-angle
analogue is :func:`savage_jeffrey_projected`. The overlay uses S per bin from the profiles
(text: S = 2R du/dy / sqrt<u'^2>; listing: S = 2R |du/dy| / sqrt(<u'^2> + <v'^2>)), with the
length R, or with the mean spacing C = R sqrt(pi/nu) (text) / C/2 (listing).

:class:`CollisionAngles` is an :class:`~demstudy.analysis.base.AnalysisBase` fed with *log
chunks* (mappings with the datasets above, one per time window) instead of frames; per-chunk
histograms go to a block accumulator, so the errors are block-averaged over chunks (make
chunks longer than the correlation time of the collision statistics).
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy.integrate import quad
from scipy.special import erfc

from demstudy import UNITS_NOTE
from demstudy.analysis import derived as dv
from demstudy.analysis.base import AnalysisBase
from demstudy.analysis.blocking import BlockAccumulator, jackknife
from demstudy.theory import corrected_s, savage_jeffrey

__all__ = [
    "CONVENTIONS",
    "CollisionAngles",
    "collision_angles",
    "collision_chunks",
    "savage_jeffrey_projected",
]

CONVENTIONS = ("text", "listing")
PAIR, LOWER_WALL, UPPER_WALL = 0, 1, 2


def collision_angles(normal: ArrayLike, convention: str = "text") -> np.ndarray:
    """theta in [0, pi) of each normal (M, dim) in Campbell's ``text`` or ``listing`` sense."""
    n = np.asarray(normal, float)
    theta = np.mod(np.arctan2(n[:, 1], n[:, 0]), np.pi)
    if convention == "text":
        return theta
    if convention == "listing":
        return np.mod(0.5 * np.pi - theta, np.pi)
    raise ValueError(f"convention must be 'text' or 'listing', got {convention!r}")


def savage_jeffrey_projected(theta: ArrayLike, s: float) -> np.ndarray:
    """3D analogue of Savage–Jeffrey for the projected angle theta of an isotropic normal
    n = (sin psi cos theta, sin psi sin theta, cos psi): P(theta) = (1/pi) int_0^pi (1/2)
    sin psi erfc(S sin^2(psi) cos(theta) sin(theta) / sqrt 2) dpsi, normalised on [0, pi)."""
    theta = np.atleast_1d(np.asarray(theta, float))
    out = np.empty(theta.shape)
    for k, th in np.ndenumerate(theta):
        cs = math.cos(th) * math.sin(th)
        val, _ = quad(lambda p, cs=cs: 0.5 * math.sin(p) * erfc(s * math.sin(p) ** 2 * cs
                                                                 / math.sqrt(2)), 0.0, math.pi)
        out[k] = val / math.pi
    return out


class CollisionAngles(AnalysisBase):
    """Histograms of theta (both conventions) per y-bin, fed with collision-log chunks.

    Parameters
    ----------
    edges: y-bin edges (contact points outside are ignored); usually the profile grid.
    n_theta: angle bins on [0, pi) (Campbell: 50 bins of 3.6 degrees).
    dim: 2 or 3.
    max_blocks: bound on the stored blocks of chunks.
    """

    def __init__(self, edges: ArrayLike, n_theta: int = 50, dim: int = 2,
                 max_blocks: int = 64, verbose: bool = False) -> None:
        super().__init__(verbose=verbose)
        self.edges = np.asarray(edges, float)
        if self.edges.ndim != 1 or self.edges.size < 2 or np.any(np.diff(self.edges) <= 0):
            raise ValueError("edges must be increasing with at least 2 entries")
        if dim not in (2, 3):
            raise ValueError(f"dim must be 2 or 3, got {dim!r}")
        self.n_bins, self.n_theta, self.dim = self.edges.size - 1, int(n_theta), dim
        self.theta_edges = np.linspace(0.0, np.pi, self.n_theta + 1)
        self.max_blocks = max_blocks
        self._size = self.n_bins * self.n_theta
        # per chunk: counts (text) | counts (listing) | pair collisions | wall collisions
        self._acc = BlockAccumulator(2 * self._size + 2 * self.n_bins, max_blocks)
        self.n_collisions = 0

    def _single_frame(self, chunk: Mapping[str, Any]) -> None:  # type: ignore[override]
        kind = np.asarray(chunk["kind"])
        y = np.asarray(chunk["position"], float)[:, 1]
        ybin = np.searchsorted(self.edges, y, side="right") - 1
        inside = (ybin >= 0) & (ybin < self.n_bins)
        pair = inside & (kind == PAIR)
        normal = np.asarray(chunk["normal"], float)[pair]
        sample = np.zeros(self._acc.n_values)
        for k, conv in enumerate(CONVENTIONS):
            th = collision_angles(normal, conv)
            tbin = np.minimum((th / (np.pi / self.n_theta)).astype(int), self.n_theta - 1)
            sample[k * self._size:(k + 1) * self._size] = np.bincount(
                ybin[pair] * self.n_theta + tbin, minlength=self._size)
        sample[2 * self._size:2 * self._size + self.n_bins] = np.bincount(
            ybin[pair], minlength=self.n_bins)
        sample[2 * self._size + self.n_bins:] = np.bincount(
            ybin[inside & (kind != PAIR)], minlength=self.n_bins)
        self.n_collisions += int(pair.sum())
        self._acc.add(sample)

    def _estimate(self, mean: np.ndarray) -> dict[str, np.ndarray]:
        nb, nt, size = self.n_bins, self.n_theta, self._size
        total = mean[2 * size:2 * size + nb]
        width = np.pi / nt
        with np.errstate(invalid="ignore", divide="ignore"):
            return {conv: mean[k * size:(k + 1) * size].reshape(nb, nt) / (total[:, None] * width)
                    for k, conv in enumerate(CONVENTIONS)}

    def _conclude(self) -> None:
        est, err = jackknife(self._acc, self._estimate)
        total = self._acc.total
        nb, size = self.n_bins, self._size
        self.results = {
            "edges": self.edges,
            "y": 0.5 * (self.edges[1:] + self.edges[:-1]),
            "theta_edges": self.theta_edges,
            "theta": 0.5 * (self.theta_edges[1:] + self.theta_edges[:-1]),
            "pair_collisions": total[2 * size:2 * size + nb],
            "wall_collisions": total[2 * size + nb:],
        }
        for conv in CONVENTIONS:
            self.results[f"p_{conv}"] = est[conv]
            self.results[f"p_{conv}_err"] = err[conv]
        self.attrs = {
            "dim": self.dim, "n_theta": self.n_theta, "chunks": self.n_frames,
            "collisions": self.n_collisions, "block_length": self._acc.block_length,
            "n_blocks": self._acc.n_blocks,
            "conventions": "p_text: theta = atan2(n_y, n_x) mod pi from the flow direction; "
                           "p_listing: Campbell's code, (pi/2 - theta_text) mod pi",
            "units": "P(theta) per radian, normalised on [0, pi) per y-bin; " + UNITS_NOTE,
        }

    def overlay(self, profiles: Mapping[str, Any]) -> None:
        """Add Savage–Jeffrey predictions from ``profiles`` on the same y-bins: S per bin
        (``s_text``, ``s_listing`` with ``_err``) and, for the bin-centre angles,
        ``sj_text_R``, ``sj_text_C``, ``sj_listing_R``, ``sj_listing_C`` (n_bins, n_theta);
        3D uses :func:`savage_jeffrey_projected` with the same effective S."""
        if not self._finished:
            raise RuntimeError("call finish() before overlay()")
        y = np.asarray(profiles["y"], float)
        if y.shape != self.results["y"].shape or not np.allclose(y, self.results["y"]):
            raise ValueError("the profiles must use the same y-bins as the collision angles")
        nu = np.asarray(profiles["solid_fraction"], float)
        theta = self.results["theta"]
        for variant, c_length in (("text", "C"), ("listing", "C/2")):
            s, s_err = dv.s_parameter(dict(profiles), variant)
            self.results[f"s_{variant}"], self.results[f"s_{variant}_err"] = s, s_err
            for length in ("R", c_length):
                rows = np.full((self.n_bins, self.n_theta), np.nan)
                for b in np.flatnonzero(np.isfinite(s) & (nu > 0)):
                    s_eff = float(s[b]) if length == "R" else float(
                        corrected_s(s[b], nu[b], variant))
                    rows[b] = (savage_jeffrey(theta, s_eff) if self.dim == 2
                               else savage_jeffrey_projected(theta, s_eff))
                key = "R" if length == "R" else "C"
                self.results[f"sj_{variant}_{key}"] = rows


def collision_chunks(log: Mapping[str, Any], n_chunks: int = 64,
                     start: float = 0.0) -> Iterator[dict[str, np.ndarray]]:
    """Split a collision log (the ``/collisions`` datasets) into ``n_chunks`` equal time
    windows from ``start`` on (empty windows are skipped)."""
    t = np.asarray(log["time"], float)
    keep = t >= start
    if not np.any(keep):
        raise ValueError("the collision log holds no collisions after the start time")
    t0, t1 = float(t[keep].min()), float(t[keep].max())
    bounds = np.linspace(t0, t1, n_chunks + 1)
    which = np.minimum(np.searchsorted(bounds, t, side="right") - 1, n_chunks - 1)
    for c in range(n_chunks):
        sel = keep & (which == c)
        if np.any(sel):
            yield {k: np.asarray(v)[sel] for k, v in log.items()}
