"""Stress tensor profiles along y: kinetic, collisional (hard particles), contact (soft
particles), wall stresses and the momentum balance.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts; stresses are force per
length in 2D (discs: per unit thickness) and force per area in 3D, i.e. m / (d^(dim-2) t^2)
with the time unit of the scene (sqrt(d/g) with gravity).

Sign convention
---------------
Tensors ``P`` are stored **compressive positive** (the pressure tensor P = -sigma of the
tension-positive Cauchy stress sigma): a gas has P_aa > 0. Campbell's stresses
(:mod:`demstudy.analysis.derived`) are tau_yy = P_yy and tau_xy = -P_xy (= sigma_xy).

* kinetic: P_k = rho nu <v'v'> = sum_i m_i v_i' v_i' / V (velocity fluctuations about the
  bin's mean, from :class:`~demstudy.analysis.profiles.ProfileAnalysis`).
* collisional (hard particles): P_c = sum_collisions (-J_i (x) r_ij) / (Delta t V_bin),
  J_i the impulse received by i, r_ij = r_j - r_i at contact; each collision's tensor is
  split over the bins in proportion to the length of the branch segment r_i -> r_j inside
  each bin (:func:`branch_fractions`; the Irving–Kirkwood line distribution, so that the
  stress averaged over a bin is the exact mean of the planar stresses of its planes).
* contact (soft particles): P_c = sum_contacts f_i (x) (r_i - r_j) / V_bin per sample, f_i
  the force on i from j, split along the branch the same way. A wall contact counts as a
  contact with the wall's contact point (branch from the particle centre to that point), a
  contact with a wall bump likewise (branch to the contact point): the bin next to a wall
  then carries the wall's load.
* walls: P_ay = -F_a / A at the lower wall and +F_a / A at the upper wall, F the force of
  the particles on the wall (``/timeseries/wall_force_*``), A the wall area (periodic length
  in 2D).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from demstudy import UNITS_NOTE
from demstudy.analysis import derived as dv
from demstudy.analysis.base import bin_index
from demstudy.analysis.blocking import BlockAccumulator, jackknife

__all__ = [
    "CollisionalSums",
    "ContactStress",
    "branch_fractions",
    "branch_sums",
    "collisional_stress",
    "kinetic_tensor",
    "momentum_snapshot",
    "stress_results",
    "unsteady_inertia_between",
    "wall_stress",
]

STRESS_UNITS = ("stress, compressive positive (P = -sigma), in m / (d^(dim-2) t^2): force per "
                "length in 2D, per area in 3D; " + UNITS_NOTE)


def _edges(edges: ArrayLike) -> np.ndarray:
    e = np.asarray(edges, float)
    if e.ndim != 1 or e.size < 2 or not np.all(np.diff(e) > 0):
        raise ValueError("edges must be an increasing 1D array with at least 2 entries")
    return e


def branch_fractions(y_i: ArrayLike, y_j: ArrayLike, edges: ArrayLike,
                     period: float = 0.0) -> np.ndarray:
    """(M, n_bins) fraction of the length of each segment y_i -> y_j inside each bin.

    Exact length fractions (the segment's projection on y, so its direction does not
    matter); a segment lying in a plane y = const goes wholly to the bin containing it
    (a point on an inner edge to the bin above, the top edge to the last bin). Parts outside
    [edges[0], edges[-1]] are dropped (rows then sum to less than 1), unless ``period`` > 0:
    then the grid must span one period and the segment is wrapped onto it.
    """
    e = _edges(edges)
    a, b = np.asarray(y_i, float).ravel(), np.asarray(y_j, float).ravel()
    if a.shape != b.shape:
        raise ValueError("y_i and y_j must have the same shape")
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    if period > 0:
        if not np.isclose(e[-1] - e[0], period, rtol=1e-9, atol=1e-12):
            raise ValueError(f"the grid spans {e[-1] - e[0]}, not the period {period}")
        shift = np.floor((lo - e[0]) / period) * period
        lo, hi = lo - shift, hi - shift
        images = int(np.ceil(np.max((hi - e[0]) / period, initial=1.0)))
    else:
        images = 1
    length = hi - lo
    flat = length <= 0.0
    safe = np.where(flat, 1.0, length)
    out = np.zeros((a.size, e.size - 1))
    for k in range(images):
        ek = e + k * period
        inside = np.clip(hi[:, None], ek[None, :-1], ek[None, 1:]) - np.clip(
            lo[:, None], ek[None, :-1], ek[None, 1:])
        out += inside / safe[:, None]
    if np.any(flat):
        y = lo[flat]
        if period > 0:
            y = e[0] + np.mod(y - e[0], period)
        idx = np.searchsorted(e, y, side="right") - 1
        idx = np.where(y == e[-1], e.size - 2, idx)
        ok = (idx >= 0) & (idx < e.size - 1)
        rows = np.flatnonzero(flat)
        out[rows] = 0.0
        out[rows[ok], idx[ok]] = 1.0
    return out


def branch_sums(y_i: ArrayLike, y_j: ArrayLike, tensors: ArrayLike, edges: ArrayLike,
                period: float = 0.0) -> np.ndarray:
    """(n_bins, dim, dim) sums of ``tensors`` (M, dim, dim) split by :func:`branch_fractions`.

    For collisions pass T = -J_i (x) r_ij; for contacts T = f_i (x) (r_i - r_j)."""
    t = np.asarray(tensors, float)
    frac = branch_fractions(y_i, y_j, edges, period)
    if t.ndim != 3 or t.shape[0] != frac.shape[0]:
        raise ValueError(f"tensors must have shape ({frac.shape[0]}, dim, dim), got {t.shape}")
    return np.einsum("mb,mij->bij", frac, t)


def collisional_stress(sums: ArrayLike, duration: ArrayLike, edges: ArrayLike,
                       cross_section: float) -> tuple[np.ndarray, np.ndarray]:
    """sigma_c = sum / (Delta t * bin volume) from per-bin sums of -J_i (x) r_ij.

    ``sums``: (n_bins, dim, dim) accumulated over ``duration``, or (n_chunks, n_bins, dim,
    dim) with ``duration`` (n_chunks,): the estimate is then sum / (total time * volume) and
    its error the delete-one-chunk jackknife of that ratio (chunks should be longer than
    the stress's correlation time). Bin volume = bin width * ``cross_section`` (the periodic
    length in 2D, the periodic area in 3D). Returns (stress, error); error NaN for one sum.
    """
    s = np.asarray(sums, float)
    width = np.diff(_edges(edges))
    vol = (width * float(cross_section))[:, None, None]
    if s.ndim == 3:
        return s / (float(np.sum(duration)) * vol), np.full(s.shape, np.nan)
    dt = np.asarray(duration, float)
    if s.ndim != 4 or dt.shape != (s.shape[0],):
        raise ValueError("chunked sums must be (n_chunks, n_bins, dim, dim) with (n_chunks,) "
                         "durations")
    est = s.sum(0) / (dt.sum() * vol)
    m = s.shape[0]
    if m < 2:
        return est, np.full(est.shape, np.nan)
    loo = (s.sum(0)[None] - s) / ((dt.sum() - dt)[:, None, None, None] * vol[None])
    err = np.sqrt((m - 1) / m * ((loo - loo.mean(0)) ** 2).sum(0))
    return est, err


class CollisionalSums:
    """Collisional stress of hard particles from the engine's cumulative per-bin sums of
    −J_i ⊗ r_ij: the increments over the production sample intervals and their durations
    (``collisional_stress`` turns them into the stress with a jackknife error)."""

    def __init__(self) -> None:
        self.chunks: list[np.ndarray] = []
        self.durations: list[float] = []
        self.last: np.ndarray | None = None

    def add(self, sums: ArrayLike, span: float | None, cross_section: float = 0.0) -> None:
        """The engine's sums now; ``span``: the production interval that ends here (None:
        not in production, only the reference for the next increment)."""
        sums = np.asarray(sums, float)
        if span is not None and self.last is not None:
            self.chunks.append(sums - self.last)
            self.durations.append(span)
        self.last = sums


class ContactStress:
    """Contact stress profile of soft particles accumulated over samples.

    Each sample gives per-bin sums of f_i (x) (r_i - r_j) (:func:`branch_sums`, already
    reduced over MPI ranks) and the box's cross-section; the sample's stress is
    sums / (bin width * cross_section). Errors: jackknife over time blocks.
    """

    def __init__(self, edges: ArrayLike, dim: int, period: float = 0.0,
                 max_blocks: int = 64) -> None:
        self.edges = _edges(edges)
        self.dim, self.period = int(dim), float(period)
        self.n_bins = self.edges.size - 1
        self._acc = BlockAccumulator(self.n_bins * dim * dim, max_blocks)

    def add_sums(self, sums: ArrayLike, cross_section: float) -> None:
        vol = np.diff(self.edges)[:, None, None] * float(cross_section)
        self._acc.add(np.asarray(sums, float) / vol)

    def add(self, sums: ArrayLike, span: float | None, cross_section: float) -> None:
        """One production sample's sums (``span`` unused: contact sums are instantaneous)."""
        self.add_sums(sums, cross_section)

    def add_contacts(self, y_i: ArrayLike, force: ArrayLike, branch: ArrayLike,
                     cross_section: float) -> None:
        """One sample from contact arrays: ``force`` (M, dim) on i, ``branch`` = r_i - r_j
        (M, dim) (j: the partner's centre or a wall contact point), y_i (M,) the centres."""
        f, b = np.asarray(force, float), np.asarray(branch, float)
        y_i = np.asarray(y_i, float)
        sums = branch_sums(y_i, y_i - b[:, 1], f[:, :, None] * b[:, None, :], self.edges,
                           self.period)
        self.add_sums(sums, cross_section)

    @property
    def samples(self) -> int:
        return self._acc.n_samples

    def finish(self) -> tuple[np.ndarray, np.ndarray]:
        """(P_contact, error), each (n_bins, dim, dim)."""
        shape = (self.n_bins, self.dim, self.dim)
        est, err = jackknife(self._acc, lambda mean: mean)
        return np.asarray(est).reshape(shape), np.asarray(err).reshape(shape)


def kinetic_tensor(profiles: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """P_k = rho nu <v'v'> (n_bins, dim, dim) from a ``/profiles`` dict, with errors.

    Diagonal from ``temperature_components``, xy from ``kinetic_shear`` (via
    :func:`demstudy.analysis.derived.kinetic_stress`); in 3D the xz and yz components are not
    stored by the profiles and are NaN."""
    dim = np.asarray(profiles["velocity"]).shape[1]
    rho = dv.MATERIAL_DENSITY[dim]
    nu = np.asarray(profiles["solid_fraction"], float)
    nu_err = dv._err(dict(profiles), "solid_fraction")
    var, var_err = dv.velocity_variances(dict(profiles))
    k = dv.kinetic_stress(dict(profiles))
    n = nu.size
    p, e = np.full((n, dim, dim), np.nan), np.full((n, dim, dim), np.nan)
    for a in range(dim):
        p[:, a, a] = rho * nu * var[:, a]
        e[:, a, a] = rho * np.hypot(nu_err * var[:, a], nu * var_err[:, a])
    p[:, 0, 1] = p[:, 1, 0] = -k["tau_xy"]
    e[:, 0, 1] = e[:, 1, 0] = k["tau_xy_err"]
    known = np.eye(dim, dtype=bool)
    known[0, 1] = known[1, 0] = True  # the components the profiles give
    empty = ~(np.nan_to_num(nu) > 0)  # no material: no kinetic stress
    p[empty[:, None, None] & known[None]] = 0.0
    e[empty[:, None, None] & known[None]] = 0.0
    return p, e


def wall_stress(timeseries: Mapping[str, Any], side: str, area: float | ArrayLike,
                start: float = 0.0, max_blocks: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """Mean wall stress (P_xy, P_yy[, P_zy]) = the column P_ay at the wall, with errors.

    From ``wall_force_<side>`` (force of the particles on the wall, averaged over each
    sample interval) over samples with time > ``start`` (production); ``area``: wall area
    (periodic length in 2D), a scalar or one value per sample (servo widths)."""
    t = np.asarray(timeseries["time"], float)
    f = np.asarray(timeseries[f"wall_force_{side}"], float)
    sign = -1.0 if side == "lower" else 1.0
    area = np.broadcast_to(np.asarray(area, float), t.shape)
    keep = (t > start) & np.all(np.isfinite(f), axis=1)
    acc = BlockAccumulator(f.shape[1], max_blocks)
    for row in sign * f[keep] / area[keep, None]:
        acc.add(row)
    if acc.n_samples == 0:
        return np.full(f.shape[1], np.nan), np.full(f.shape[1], np.nan)
    est, err = jackknife(acc, lambda mean: mean)
    return np.asarray(est), np.asarray(err)


def momentum_snapshot(time: float, y: ArrayLike, momentum: ArrayLike) -> dict[str, Any]:
    """The particles' y and momenta (n, dim) at one time: an end of the averaging window of
    :func:`unsteady_inertia_between`."""
    return {"time": float(time), "y": np.array(y, float),
            "momentum": np.array(momentum, float)}


def unsteady_inertia_between(start: Mapping[str, Any], end: Mapping[str, Any],
                             edges: ArrayLike, section: float) -> np.ndarray | None:
    """Campbell's unsteady term rho nu a per bin (n_bins, dim): the momentum of the particles
    centred in each bin at ``end`` minus that at ``start`` (his QT − QS, sums of m u over the
    strip), over the duration and the bin volume (:func:`derived.unsteady_inertia`). None for
    an empty window. A flow accelerating down a chute needs it: the steady balance then
    overstates tau_xy by the bed's rho nu a above each plane."""
    edges = np.asarray(edges, float)
    duration = float(end["time"]) - float(start["time"])
    if not duration > 0:
        return None
    n = edges.size - 1

    def binned(snap: Mapping[str, Any]) -> np.ndarray:
        p = np.asarray(snap["momentum"], float)
        b = bin_index(edges, np.asarray(snap["y"], float))
        inside = (b >= 0) & (b < n)
        out = np.zeros((n, p.shape[1]))
        np.add.at(out, b[inside], p[inside])
        return out

    return dv.unsteady_inertia(binned(end) - binned(start), duration,
                               float(edges[1] - edges[0]), section)


def stress_results(scene: Any, profiles: Mapping[str, Any], timeseries: Mapping[str, Any],
                   start: float = 0.0, contact: tuple[np.ndarray, np.ndarray] | None = None,
                   collisional: tuple[np.ndarray, np.ndarray] | None = None,
                   momentum: tuple[Mapping[str, Any] | None, Mapping[str, Any] | None]
                   | None = None,
                   ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
    """The ``/stress`` group: ``edges``, ``y``, ``kinetic`` and optional ``contact`` /
    ``collisional`` (n_bins, dim, dim) with ``*_err``, ``total`` (their sum), the walls'
    ``wall_<side>`` columns P_ay, and with gravity the momentum balance ``balance_tau_xy``,
    ``balance_tau_yy`` (Campbell's signs, integrated down from a free surface or from the
    upper wall's measured stress). ``momentum``: snapshots (:func:`momentum_snapshot`) at the
    start and the end of production; with both, the balance includes Campbell's unsteady term
    (``balance_inertia``, rho nu a per bin), otherwise it assumes a steady flow."""
    dim = scene.dimension
    edges = np.asarray(profiles["edges"], float)
    section = float(np.prod([scene.box.size[i] for i in range(dim) if i != 1]))
    out: dict[str, np.ndarray] = {"edges": edges, "y": np.asarray(profiles["y"], float)}
    out["kinetic"], out["kinetic_err"] = kinetic_tensor(profiles)
    total, total_var = out["kinetic"].copy(), out["kinetic_err"] ** 2
    for name, part in (("contact", contact), ("collisional", collisional)):
        if part is not None:
            out[name], out[f"{name}_err"] = part
            total = total + part[0]
            total_var = total_var + np.nan_to_num(part[1]) ** 2
    out["total"], out["total_err"] = total, np.sqrt(total_var)
    walls = {}
    for wall in scene.walls:
        if f"wall_force_{wall.side}" in timeseries:
            area = timeseries.get("width", section) if dim == 2 else section
            walls[wall.side] = wall_stress(timeseries, wall.side, area, start)
            out[f"wall_{wall.side}"], out[f"wall_{wall.side}_err"] = walls[wall.side]
    g = scene.gravity_vector
    if g is not None and scene.measure.axis == "y":
        top = (0.0, 0.0)
        if "upper" in walls:  # Campbell's tau(H) = (-P_xy, P_yy) at the upper wall
            top = (-float(walls["upper"][0][0]), float(walls["upper"][0][1]))
        inertia = None
        if momentum is not None and None not in momentum:
            inertia = unsteady_inertia_between(*momentum, edges, section)
        bal = dv.momentum_balance_stress(dict(profiles), scene, top_stress=top, inertia=inertia)
        for key in ("tau_xy", "tau_yy", "tau_xy_err", "tau_yy_err"):
            out[f"balance_{key}"] = bal[key]
        if inertia is not None:
            out["balance_inertia"] = inertia
    measured = [n for n, part in (("contact", contact), ("collisional", collisional))
                if part is not None]
    attrs = {"units": STRESS_UNITS, "dim": dim, "axis": "y", "cross_section": section,
             "total_of": " + ".join(["kinetic", *measured]) + (
                 "" if measured else " only: no interaction stress was measured (run with "
                                     "'stress' in measure.statistics)"),
             "convention": "P = -sigma (compressive positive); Campbell tau_yy = P_yy, "
                           "tau_xy = -P_xy; wall_<side> = column P_ay at that wall",
             "balance": ("unsteady: includes rho nu a from the momentum change of each bin "
                         "over production (Campbell's QT - QS); its error is not included"
                         if "balance_inertia" in out else "steady (no inertia term)")}
    return out, attrs
