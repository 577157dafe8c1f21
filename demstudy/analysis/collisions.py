"""Collision-angle distribution P(theta) (Campbell 1982) and free paths (Malik 2008) per y-bin
from a collision log.

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

Free paths (:func:`free_flights`, :func:`flight_chunks`, :class:`FreePath`): the reading is
*every particle's flights, path measured centre to centre*: each particle's consecutive
logged collisions (pairs as i or j via the ``i``, ``j`` datasets, walls and bumps as i) bound
a flight of exact duration tau; lambda is the distance its centre travels *relative to the
local mean flow* u(y) (the chord through the periodic image nearest to the one the mean
flow and gravity predict, Lees–Edwards offset included, less u_f tau with u_f the mean of u
along the flight; the parabola's arc length under gravity in the frame moving at u_f).
Kinetic theory's mean free path <|C|>/omega is that of the peculiar velocity C = c - u: in
the lab frame a flight in a shear or Poiseuille
flow also carries the mean-flow drift u tau, which grows with |u| and makes <lambda> and Kn
depend on the frame (a sheared dilute gas: about twice Enskog's lambda next to the
Lees–Edwards boundaries). Malik (2008) writes l = sqrt(dx^2 + dy^2 + dz^2) "between
successive collisions" without naming the frame; the lab-frame value is kept as
``lab_length`` / ``lab_mean_free_path`` / ``lab_knudsen``. The log must hold every
collision (``log_every`` = 1). Censored flights (before a particle's first and after its
last logged collision) are dropped, and only flights starting
a horizon before the log's end count, longer ones weighted, so that the window's censoring
does not favour short flights; flights longer than the window are never seen. Malik's
Kn = <lambda>/W is stored per bin with W; with profiles, Enskog's references
(:func:`demstudy.theory.mean_free_path`, 1/:func:`demstudy.theory.collision_frequency`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy.integrate import quad
from scipy.special import erfc

from demstudy import UNITS_NOTE
from demstudy.analysis import derived as dv
from demstudy.analysis.base import AnalysisBase, bin_index
from demstudy.analysis.blocking import BlockAccumulator, jackknife
from demstudy.theory import collision_frequency, corrected_s, mean_free_path, savage_jeffrey

__all__ = [
    "CONVENTIONS",
    "CollisionAngles",
    "FreePath",
    "collision_angles",
    "collision_chunks",
    "flight_chunks",
    "flight_length",
    "flight_mean_flow",
    "free_flights",
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


def _y_edges(edges: ArrayLike, dim: int) -> np.ndarray:
    """Checked y-bin edges (increasing, at least one bin) of a 2D or 3D log analysis."""
    out = np.asarray(edges, float)
    if out.ndim != 1 or out.size < 2 or np.any(np.diff(out) <= 0):
        raise ValueError("edges must be increasing with at least 2 entries")
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim!r}")
    return out


def _check_overlay(analysis: AnalysisBase, profiles: Mapping[str, Any], name: str) -> None:
    """An overlay needs the finished analysis and profiles on the same y-bins."""
    if not analysis._finished:
        raise RuntimeError("call finish() before overlay()")
    y = np.asarray(profiles["y"], float)
    mine = analysis.results["y"]
    if y.shape != mine.shape or not np.allclose(y, mine):
        raise ValueError(f"the profiles must use the same y-bins as the {name}")


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
        self.edges = _y_edges(edges, dim)
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
        ybin = bin_index(self.edges, y)
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
        _check_overlay(self, profiles, "collision angles")
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


# -- free paths ------------------------------------------------------------------------------

def flight_length(delta: ArrayLike, tau: ArrayLike,
                  gravity: ArrayLike | None = None) -> np.ndarray:
    """Distance travelled along each flight (M,) from its end-to-end displacement ``delta``
    (M, dim) and duration ``tau`` (M,): the chord |delta| without gravity; with gravity g the
    exact arc length of the parabola, int_0^tau |v1 + g s| ds with v1 = delta/tau - g tau/2
    (the only parabola through both ends in that time). With a = v1.g^, b = |v1 - a g^| the
    speed is sqrt(b^2 + u^2), u = a + |g| s, whose integral is F(u) = (u sqrt(u^2 + b^2)
    + b^2 asinh(u/b)) / 2 (F = u|u|/2 for b = 0: a vertical flight up and down)."""
    d, t = np.asarray(delta, float), np.asarray(tau, float)
    chord = np.linalg.norm(d, axis=1)
    if gravity is None or not np.any(gravity):
        return chord
    g = np.asarray(gravity, float)[: d.shape[1]]
    gm = float(np.linalg.norm(g))
    with np.errstate(divide="ignore", invalid="ignore"):
        v1 = d / t[:, None] - 0.5 * g * t[:, None]
        a = v1 @ (g / gm)
        b = np.linalg.norm(v1 - a[:, None] * (g / gm), axis=1)

        def antiderivative(u: np.ndarray) -> np.ndarray:
            tail = np.where(b > 0, b**2 * np.arcsinh(u / np.where(b > 0, b, 1.0)), 0.0)
            return 0.5 * (u * np.hypot(u, b) + tail)

        arc = (antiderivative(a + gm * t) - antiderivative(a)) / gm
    return np.where(t > 0, arc, chord)  # tau = 0: no flight (simultaneous collisions)


def flight_mean_flow(mean_flow: Callable[[np.ndarray], np.ndarray], y0: ArrayLike,
                     dy: ArrayLike, tau: ArrayLike,
                     gravity: ArrayLike | None = None) -> np.ndarray:
    """Mean of the mean flow u(y(s)) (M, dim) along each flight from height ``y0`` rising
    ``dy`` in ``tau``: Simpson's rule on the exact y(s) = y0 + v_y s + g_y s^2/2, whose
    mid-flight height is y0 + dy/2 - g_y tau^2/8 (exact for u linear in y, which makes
    u(y(s)) at most quadratic in s)."""
    y0, dy, t = (np.asarray(a, float) for a in (y0, dy, tau))
    g_y = float(np.asarray(gravity, float)[1]) if gravity is not None else 0.0
    mid = y0 + 0.5 * dy - g_y * t**2 / 8
    return (mean_flow(y0) + 4 * mean_flow(mid) + mean_flow(y0 + dy)) / 6


def free_flights(log: Mapping[str, Any], radius: ArrayLike, periods: ArrayLike,
                 gravity: ArrayLike | None = None,
                 shear_offset: Callable[[np.ndarray], np.ndarray] | None = None,
                 x_period: Callable[[np.ndarray], np.ndarray] | None = None,
                 start: float = 0.0,
                 mean_flow: Callable[[np.ndarray], np.ndarray] | None = None) -> dict[str, Any]:
    """Every particle's free flights between consecutive logged collisions.

    ``log``: the ``/collisions`` datasets with ``i``, ``j`` (every collision: ``log_every`` =
    1); ``radius`` (N,): radii of the mobile particles in input order; ``periods`` (dim,):
    period of each axis, 0 when not periodic; ``shear_offset(t)``: Lees–Edwards x offset of
    the image above at time t; ``x_period(t)``: the x period at t when it changes (servo);
    records before ``start`` are ignored. A particle collides as i (pairs and walls, bumps
    included) or as j (pairs); its centre is contact - r_i n (i) or that + branch (j: the
    branch points to j's nearest image, which across the y boundary is mapped back to j with
    the offset at t1). A flight runs from one collision of a particle to its next:
    tau = t2 - t1 exactly, the displacement is a periodic image of c2 - c1: the nearest one
    along y (a y wrap under Lees–Edwards also shifts x by the offset at t2), along x and z
    the one nearest to the displacement u_f tau + g tau^2/2 the mean flow and gravity
    predict (a flight whose free path exceeds half a period is aliased: keep the periods
    >> lambda); and
    ``lab_length`` = :func:`flight_length` of that displacement (the lab frame). The free
    path proper, ``length``, is measured relative to the local mean flow ``mean_flow(y)``
    ((M,) y, unwrapped across a Lees–Edwards boundary, -> (M, dim) velocity): the flight's
    displacement less u_f tau, u_f the mean of u(y(s)) along the flight (Simpson's rule on
    the exact y(s): exact for a linear profile), i.e. the flight seen from the frame moving
    with the local mean flow (the arc length there under gravity). Without ``mean_flow`` it
    is the lab-frame length. Censored flights (before a particle's first logged collision,
    after its last) are dropped.

    Returns ``t0``, ``t1`` (the logged window), ``collisions`` (particle collisions: 2 per
    pair, 1 per wall), ``event_time``, ``event_y`` (every particle collision: time, centre y)
    and per flight ``particle``, ``start_time``, ``tau``, ``length``, ``lab_length``,
    ``start`` (M, dim) starting centre, ``y_wrapped`` (crossed the y period)."""
    if "i" not in log or "j" not in log:
        raise ValueError("the collision log has no particle indices i, j (an older results "
                         "file): free paths need them")
    t = np.asarray(log["time"], float)
    keep = t >= start
    if not np.any(keep):
        raise ValueError("the collision log holds no collisions after the start time")
    t = t[keep]
    kind = np.asarray(log["kind"])[keep]
    i = np.asarray(log["i"])[keep].astype(np.intp)
    j = np.asarray(log["j"])[keep].astype(np.intp)
    n = np.asarray(log["normal"], float)[keep]
    r = np.asarray(radius, float)
    c_i = np.asarray(log["position"], float)[keep] - r[i][:, None] * n
    pair = kind == PAIR
    c_j = c_i[pair] + np.asarray(log["branch"], float)[keep][pair]
    per = np.asarray(periods, float)
    if per[1] > 0:
        # the branch points to j's nearest image (the engine's separation()): one across the
        # y boundary sits at ± (offset(t), L_y) from j itself; map it back to j
        k = np.floor(c_j[:, 1] / per[1])
        c_j[:, 1] -= k * per[1]
        if shear_offset is not None:
            c_j[:, 0] -= k * shear_offset(t[pair])
    who = np.concatenate([i, j[pair]])
    when = np.concatenate([t, t[pair]])
    where = np.concatenate([c_i, c_j])
    order = np.lexsort((np.arange(who.size), when, who))  # by particle, then in time
    who, when, where = who[order], when[order], where[order]
    nxt = np.flatnonzero(who[1:] == who[:-1])  # flight from event k to event k + 1
    tau = when[nxt + 1] - when[nxt]
    delta = where[nxt + 1] - where[nxt]
    wrapped = np.zeros(tau.size, bool)
    if per[1] > 0:  # y first: a Lees–Edwards wrap moves the image along x
        k = np.rint(-delta[:, 1] / per[1])
        delta[:, 1] += k * per[1]
        wrapped = k != 0
        if shear_offset is not None:
            delta[:, 0] += k * shear_offset(when[nxt + 1])
    # x, z: the image nearest to the displacement the mean flow and gravity predict, so that
    # a long flight carried along by the flow is not aliased (the mean flow along the flight
    # needs only delta_y, fixed above)
    u_f = np.zeros_like(delta)
    if mean_flow is not None:
        u_f = flight_mean_flow(mean_flow, where[nxt, 1], delta[:, 1], tau, gravity)
    expected = u_f * tau[:, None]
    if gravity is not None:
        expected += 0.5 * np.asarray(gravity, float)[: delta.shape[1]] * tau[:, None] ** 2
    for a in (0, 2)[: delta.shape[1] - 1]:
        if per[a] > 0:
            length = x_period(when[nxt + 1]) if a == 0 and x_period is not None else per[a]
            delta[:, a] -= length * np.rint((delta[:, a] - expected[:, a]) / length)
    lab = flight_length(delta, tau, gravity)
    length = lab if mean_flow is None else flight_length(delta - u_f * tau[:, None], tau,
                                                         gravity)
    y = where[:, 1] if per[1] == 0 else np.mod(where[:, 1], per[1])
    return {"t0": float(t.min()), "t1": float(t.max()),
            "collisions": int(2 * pair.sum() + (~pair).sum()),
            "event_time": when, "event_y": y,
            "particle": who[nxt], "start_time": when[nxt], "tau": tau,
            "length": length, "lab_length": lab,
            "start": np.column_stack([where[nxt, :1], y[nxt], where[nxt, 2:]]),
            "y_wrapped": wrapped}


def flight_chunks(flights: Mapping[str, Any], n_chunks: int = 64,
                  horizon: float | None = None) -> Iterator[dict[str, Any]]:
    """Split :func:`free_flights` into ``n_chunks`` equal windows of starting times over
    [t0, t1 - h] (flights by start time, collisions by time; empty windows kept, so that
    every chunk lasts ``duration``). A flight of duration tau is seen only if it ends by t1:
    with starts up to t1 - h every flight with tau <= h is (so each chunk samples the same
    distribution and the chunk-to-chunk scatter is statistical); a longer one only if it
    starts in the first T - tau of the window, T = t1 - t0, and gets the weight
    (T - h) / (T - tau) for the ones missed. ``horizon`` h: default 8 x the mean duration
    of the complete flights, at most T/4."""
    if not (isinstance(n_chunks, int | np.integer) and n_chunks >= 1):
        raise ValueError(f"n_chunks = {n_chunks!r}: must be an integer >= 1")
    t0, t1 = float(flights["t0"]), float(flights["t1"])
    span = t1 - t0
    tau = np.asarray(flights["tau"], float)
    if span <= 0 or tau.size == 0:
        raise ValueError("the collision log spans no time or holds no complete flight")
    h = min(8.0 * float(tau.mean()), 0.25 * span) if horizon is None else float(horizon)
    if not 0 <= h < span:
        raise ValueError(f"horizon {h} must be in [0, {span})")
    bounds = np.linspace(t0, t1 - h, n_chunks + 1)

    def which(t: np.ndarray) -> np.ndarray:  # -1 / n_chunks: outside the start window
        k = np.searchsorted(bounds, t, side="right") - 1
        return np.where(t == bounds[-1], n_chunks - 1, k)

    weight = np.where(tau <= h, 1.0, (span - h) / np.maximum(span - tau, np.finfo(float).tiny))
    f_chunk, e_chunk = which(np.asarray(flights["start_time"])), which(flights["event_time"])
    y, ey = np.asarray(flights["start"], float)[:, 1], np.asarray(flights["event_y"], float)
    length = np.asarray(flights["length"], float)
    lab = np.asarray(flights.get("lab_length", length), float)
    for c in range(n_chunks):
        sel, ev = f_chunk == c, e_chunk == c
        yield {"y": y[sel], "length": length[sel], "lab_length": lab[sel], "tau": tau[sel],
               "weight": weight[sel], "event_y": ey[ev], "duration": (span - h) / n_chunks,
               "horizon": h}


class FreePath(AnalysisBase):
    """Free-path and free-time distributions per y-bin, fed with :func:`flight_chunks`.

    Reading: every particle's flights (each particle's consecutive collisions, pairs as i or
    j and walls), path measured centre to centre relative to the local mean flow (the arc
    length under gravity; chunks may carry ``lab_length``, the lab-frame one), binned by
    the y of the flight's starting centre, starting up to a horizon before the log's end
    (flights longer than it weighted against the window's censoring, :func:`flight_chunks`).
    Per bin: P(lambda), P(tau) (normalised over
    every flight of the bin, so flights beyond ``lambda_max`` / ``tau_max`` leave the area
    short by their fraction), <lambda>, <tau>, the moment ratios <x^2>/<x>^2 (2 for an
    exponential), Kn = <lambda>/``width``, the lab-frame ``lab_mean_free_path`` and
    ``lab_knudsen``, and the collision rate (particle collisions whose
    centre is in the bin, per unit time); errors by jackknife over blocks of chunks.

    Parameters
    ----------
    edges: y-bin edges; lambda_max, tau_max: histogram ranges (n_hist bins from 0);
    width: the length of Kn (wall gap, periodic height or flow depth); dim: 2 or 3.
    """

    _SUMS = ("weight", "weight_length", "weight_length2", "weight_tau", "weight_tau2",
             "events", "flights", "weight_lab_length")

    def __init__(self, edges: ArrayLike, lambda_max: float, tau_max: float, width: float,
                 n_hist: int = 50, dim: int = 3, max_blocks: int = 64,
                 verbose: bool = False) -> None:
        super().__init__(verbose=verbose)
        self.edges = _y_edges(edges, dim)
        if not (lambda_max > 0 and tau_max > 0 and width > 0):
            raise ValueError("lambda_max, tau_max and width must be > 0")
        if not (isinstance(n_hist, int | np.integer) and n_hist >= 1):
            raise ValueError(f"n_hist = {n_hist!r}: must be an integer >= 1")
        self.n_bins, self.n_hist, self.dim = self.edges.size - 1, int(n_hist), dim
        self.width = float(width)
        self.lambda_edges = np.linspace(0.0, lambda_max, self.n_hist + 1)
        self.tau_edges = np.linspace(0.0, tau_max, self.n_hist + 1)
        self._size = self.n_bins * self.n_hist
        self._acc = BlockAccumulator(2 * self._size + len(self._SUMS) * self.n_bins, max_blocks)
        self.duration = self.horizon = float("nan")
        self.n_flights = 0

    def _hist(self, ybin: np.ndarray, x: np.ndarray, edges: np.ndarray,
              w: np.ndarray) -> np.ndarray:
        k = np.searchsorted(edges, x, side="right") - 1
        ok = (k >= 0) & (k < self.n_hist)
        return np.bincount(ybin[ok] * self.n_hist + k[ok], w[ok], minlength=self._size)


    def _single_frame(self, chunk: Mapping[str, Any]) -> None:  # type: ignore[override]
        self.duration, self.horizon = float(chunk["duration"]), float(chunk["horizon"])
        ybin = bin_index(self.edges, np.asarray(chunk["y"], float))
        ok = (ybin >= 0) & (ybin < self.n_bins)
        ybin = ybin[ok]
        lam, tau = np.asarray(chunk["length"], float)[ok], np.asarray(chunk["tau"], float)[ok]
        lab = np.asarray(chunk.get("lab_length", chunk["length"]), float)[ok]
        w = np.asarray(chunk["weight"], float)[ok]
        ebin = bin_index(self.edges, np.asarray(chunk["event_y"], float))
        ebin = ebin[(ebin >= 0) & (ebin < self.n_bins)]
        nb = self.n_bins
        sums = [np.bincount(ybin, v, minlength=nb) for v in (w, w * lam, w * lam**2, w * tau,
                                                             w * tau**2)]
        sums += [np.bincount(ebin, minlength=nb), np.bincount(ybin, minlength=nb),
                 np.bincount(ybin, w * lab, minlength=nb)]
        self._acc.add(np.concatenate([self._hist(ybin, lam, self.lambda_edges, w),
                                      self._hist(ybin, tau, self.tau_edges, w), *sums]))
        self.n_flights += int(ok.sum())

    def _estimate(self, mean: np.ndarray) -> dict[str, np.ndarray]:
        nb, nh, size = self.n_bins, self.n_hist, self._size
        s = dict(zip(self._SUMS, mean[2 * size:].reshape(len(self._SUMS), nb), strict=True))
        w, wl, wl2, wt, wt2 = (s[k] for k in self._SUMS[:5])
        tot = {k: v.sum() for k, v in s.items()}
        return {
            "p_lambda": mean[:size].reshape(nb, nh) / (w[:, None] * np.diff(self.lambda_edges)),
            "p_tau": mean[size:2 * size].reshape(nb, nh) / (w[:, None] * np.diff(self.tau_edges)),
            "mean_free_path": wl / w, "mean_free_time": wt / w,
            "lambda_ratio": wl2 * w / wl**2, "tau_ratio": wt2 * w / wt**2,
            "knudsen": wl / w / self.width,
            "lab_mean_free_path": s["weight_lab_length"] / w,
            "lab_knudsen": s["weight_lab_length"] / w / self.width,
            "all_lab_mean_free_path": np.asarray(tot["weight_lab_length"] / tot["weight"]),
            "collision_rate": s["events"] / self.duration,
            "all_mean_free_path": np.asarray(tot["weight_length"] / tot["weight"]),
            "all_mean_free_time": np.asarray(tot["weight_tau"] / tot["weight"]),
            "all_lambda_ratio": np.asarray(tot["weight_length2"] * tot["weight"]
                                           / tot["weight_length"] ** 2),
            "all_tau_ratio": np.asarray(tot["weight_tau2"] * tot["weight"]
                                        / tot["weight_tau"] ** 2),
        }

    def _conclude(self) -> None:
        # chunks of flights by start time, weighted to be independent: no blocking
        est, err = jackknife(self._acc, self._estimate, blocking=False)
        total = self._acc.total
        nb, size = self.n_bins, self._size
        counts = total[2 * size:].reshape(len(self._SUMS), nb)
        self.results = {
            "edges": self.edges, "y": 0.5 * (self.edges[1:] + self.edges[:-1]),
            "lambda_edges": self.lambda_edges, "tau_edges": self.tau_edges,
            "lambda": 0.5 * (self.lambda_edges[1:] + self.lambda_edges[:-1]),
            "tau": 0.5 * (self.tau_edges[1:] + self.tau_edges[:-1]),
            "flights": counts[self._SUMS.index("flights")],
            "collisions": counts[self._SUMS.index("events")],
        }
        for key, value in est.items():
            self.results[key], self.results[f"{key}_err"] = value, err[key]
        self.attrs = {
            "dim": self.dim, "n_hist": self.n_hist, "chunks": self.n_frames,
            "chunk_duration": self.duration, "horizon": self.horizon,
            "flights_total": self.n_flights,
            "block_length": self._acc.block_length, "n_blocks": self._acc.n_blocks,
            "knudsen_width": self.width,
            "reading": "every particle's flights between consecutive collisions (pairs as i "
                       "or j, walls and bumps), centre to centre relative to the local mean "
                       "flow (displacement less the flight's mean of u(y) times tau; arc "
                       "length under gravity; lab_*: the lab-frame displacement), "
                       "binned by the starting centre's y; starts up to t1 - horizon, flights "
                       "longer than the horizon weighted (T - horizon)/(T - tau) for the "
                       "window's censoring",
            "units": "lambda in d, tau and 1/rate in particle time units; " + UNITS_NOTE,
        }

    def overlay(self, profiles: Mapping[str, Any], cross_section: float) -> None:
        """Enskog references per bin from ``profiles`` (same y-bins): ``lambda_enskog``
        (mean_free_path at the bin's solid fraction), ``tau_enskog`` (1/collision_frequency
        at its solid fraction and temperature), ``knudsen_enskog``, and the measured
        ``collision_frequency`` = collision_rate / (n V_bin), V_bin = bin width x
        ``cross_section``."""
        _check_overlay(self, profiles, "free paths")
        nu = np.asarray(profiles["solid_fraction"], float)
        with np.errstate(divide="ignore", invalid="ignore"):
            self.results["lambda_enskog"] = mean_free_path(nu, self.dim)
            self.results["tau_enskog"] = 1.0 / collision_frequency(
                nu, np.asarray(profiles["temperature"], float), self.dim)
            self.results["knudsen_enskog"] = dv.knudsen_enskog(dict(profiles), self.width)
            if "number_density" in profiles:
                volume = np.diff(self.edges) * cross_section
                n = np.asarray(profiles["number_density"], float) * volume
                self.results["collision_frequency"] = self.results["collision_rate"] / n
                self.results["collision_frequency_err"] = self.results["collision_rate_err"] / n
