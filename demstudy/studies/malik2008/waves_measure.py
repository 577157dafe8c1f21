"""What the density-wave part measures in one run: the kinetic-energy trace against
collisions per particle, the energy balance, the density field's Fourier modes on the xy, xz
and yz planes (demstudy.analysis.waves.DensityWaves over the production frames, and over each
half of them for stationarity), the structure class, and a snapshot of the fields.

Dimensionless particle units: d = 1, m = 1, g = 1 (gravity acts): times in √(d/g), speeds in
√(gd), energies in m g d. Time in the thesis is collisions per particle: here c/p = 2 N_pair /
N (each pair collision counts for both partners; wall collisions apart, digest §1.6, §10).
"""

from __future__ import annotations

import tomllib
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from ...analysis.blocking import BlockAccumulator, jackknife, series_mean
from ...analysis.waves import DensityWaves
from ...io.frames import Frame
from ...io.results import read_attrs

PLANES = ("xy", "xz", "yz")
_AX = {"x": 0, "y": 1, "z": 2}
#: a "plateau": the KE of the production halves within 2σ, or within 2 % of their mean however
#: small their errors (a level read off a kinetic-energy trace, the thesis's test, is no more
#: precise); not the sum of both, which a noisy first half would stretch over a real rise
PLATEAU_TOL = 0.02
#: drift of a mode amplitude between the production halves above this many σ: not stationary
DRIFT_SIGMAS = 2.0
#: width (d) of the coarse cells of the second peak-density estimate (the thesis's unstated)
COARSE = 5.0
#: the thesis's snapshot times in collisions per particle (digest §1.8: [L1149]-[L1159],
#: [L1297]-[L1305]); its c/p is undefined: read as ours (2 N_pair/N) and as N_pair/N (ours × 2)
SNAPSHOTS = (4000.0, 8000.0, 10000.0, 11000.0, 14000.0)
#: half-width (c/p) of the frame window classified at each snapshot time (3-5 frames at the
#: thesis-span runs' 400 c/p spacing)
WINDOW = 800.0
#: fewest frames a window needs to be classified
WINDOW_FRAMES = 3


def snapshot_centres() -> list[float]:
    """Our c/p of the thesis's snapshots under both readings, sorted."""
    return sorted({*SNAPSHOTS, *(2.0 * t for t in SNAPSHOTS)})


@dataclass
class Modes:
    """One DensityWaves result: its datasets, attributes and class."""

    results: dict[str, np.ndarray]
    attrs: dict[str, Any]

    @property
    def cls(self) -> str:
        """The xy class alone (``pattern`` without "+ z")."""
        return str(self.attrs.get("pattern", "?"))

    @property
    def pattern(self) -> str:
        """The xy class (none / plug / s-wave / slug / mixed), "+ z" when the xz or yz plane
        has a dominant family varying along z (Malik's 3D structure)."""
        z = " + z" if self.attrs.get("z_structure") else ""
        return f"{self.attrs.get('pattern', '?')}{z}"

    def amplitude(self, plane: str, k: tuple[int, int]) -> tuple[float, float]:
        """√P_F of family k of ``plane`` and its error (jackknife)."""
        power = float(self.results[f"family_power_{plane}"][k])
        err = float(self.results[f"family_power_{plane}_err"][k])
        amp = float(np.sqrt(max(power, 0.0)))
        return amp, (0.5 * err / amp if amp > 0 else float("nan"))

    def dominant(self, plane: str) -> list[tuple[int, int]]:
        return [tuple(int(v) for v in row) for row in
                np.asarray(self.results[f"dominant_{plane}"], int).reshape(-1, 2)]

    def leading(self, plane: str, count: int) -> list[tuple[int, int]]:
        return [tuple(int(v) for v in row) for row in
                np.asarray(self.results[f"leading_{plane}"], int).reshape(-1, 2)[:count]]


@dataclass
class Drift:
    """A family's amplitude in the first and second half of the production."""

    plane: str
    k: tuple[int, int]
    first: tuple[float, float]
    second: tuple[float, float]

    @property
    def sigmas(self) -> float:
        err = float(np.hypot(self.first[1], self.second[1]))
        diff = abs(self.second[0] - self.first[0])
        return diff / err if err > 0 else float("inf")


@dataclass
class Snapshot:
    """The last frame: centres, and per plane the depth-averaged solid fraction and the mean
    velocity (the box mean subtracted) on the analysis grid."""

    time: float
    cpp: float
    position: np.ndarray
    planes: dict[str, tuple[np.ndarray, ...]] = field(default_factory=dict)


@dataclass
class RunWaves:
    """Everything measured in one run (see the module docstring)."""

    path: Path
    n: int
    size: np.ndarray
    restitution: float
    time: np.ndarray
    cpp: np.ndarray
    ke: np.ndarray  # translational KE per particle (mean flow included)
    eq_end: float
    modes: Modes
    halves: tuple[Modes, Modes]
    series_cpp: np.ndarray
    drifts: list[Drift]
    ke_halves: tuple[tuple[float, float], tuple[float, float]]
    balance: tuple[float, float]  # dissipation rate / gravity power, error
    peak: tuple[float, float]  # densest xy cell column (≈ 2 d) per frame, mean over frames
    peak_coarse: tuple[float, float]  # the same on columns ≈ COARSE d wide
    close_packed: float  # last frame: fraction of particles with 12 neighbours within 1.05 d
    rate: float  # c/p per √(d/g) in the production
    wall_seconds: float
    tc_fraction: float  # pair collisions the engine's TC model made elastic (not in the thesis)
    snapshot: Snapshot
    tc: float = float("nan")  # the TC model's t_c the run used (√(d/g))
    #: the class at the thesis's snapshot times (Scan.windows: our c/p → modes)
    windows: dict[float, Modes] = field(default_factory=dict)

    @property
    def end_cpp(self) -> float:
        return float(self.cpp[-1])

    @property
    def eq_cpp(self) -> float:
        return float(np.interp(self.eq_end, self.time, self.cpp))

    @property
    def stationary(self) -> bool:
        """Modes stationary: the same class in both halves, no family drifting by more than
        DRIFT_SIGMAS, and no snapshot window of the production with another class (a plug
        turning into a slug early in the production hides in a half otherwise)."""
        same = self.halves[0].pattern == self.halves[1].pattern
        return (same and all(d.sigmas <= DRIFT_SIGMAS for d in self.drifts)
                and not self.window_changes)

    @property
    def window_changes(self) -> list[float]:
        """The snapshot windows (our c/p; all within the production) whose class, its first
        word, differs from the whole production's."""
        return [c for c, m in sorted(self.windows.items()) if m.cls != self.modes.cls]

    @property
    def max_drift(self) -> Drift | None:
        return max(self.drifts, key=lambda d: d.sigmas) if self.drifts else None

    @property
    def plateau(self) -> bool:
        """KE of the two production halves equal within the larger of 2σ and ``PLATEAU_TOL``
        of their mean (a significant but tiny difference is still a level to the eye that
        reads the thesis's KE traces)."""
        (m1, e1), (m2, e2) = self.ke_halves
        return abs(m2 - m1) <= max(2.0 * float(np.hypot(e1, e2)),
                                   PLATEAU_TOL * 0.5 * abs(m1 + m2))

    @property
    def balanced(self) -> bool:
        ratio, err = self.balance
        return abs(ratio - 1.0) <= 2.0 * err

    def clock(self) -> Clock:
        """The thesis's clock (collisions per particle) against time over the production: its
        rate over the first and the last fifth, and the KE's rise over the last fifth per
        1000 c/p and per 10 √(d/g). Dense clumps collide far more often than the dilute
        gas, so as a slug forms c/p runs ahead of time and the KE against c/p can look flat
        while the flow still accelerates (the thesis's warning, digest §1.8)."""
        keep = np.flatnonzero(self.time >= self.eq_end)
        if keep.size < 6:
            nan = float("nan")
            return Clock(nan, nan, nan, nan, nan)
        k = max(2, keep.size // 5)
        first, last = keep[:k], keep[-k:]

        def slope(y: np.ndarray, x: np.ndarray) -> float:
            return float(np.polyfit(x, y, 1)[0])

        ke_last = float(np.mean(self.ke[last]))
        return Clock(
            start=slope(self.cpp[first], self.time[first]),
            end=slope(self.cpp[last], self.time[last]),
            ke_per_kcpp=1e5 * slope(self.ke[last], self.cpp[last]) / ke_last,
            ke_per_10t=1e3 * slope(self.ke[last], self.time[last]) / ke_last,
            span=float(np.ptp(self.time[keep])))


@dataclass(frozen=True)
class Clock:
    """See RunWaves.clock: c/p per √(d/g) at the start and the end of the production, the
    KE's rise over the last fifth in % per 1000 c/p and per 10 √(d/g), and the production's
    length in √(d/g)."""

    start: float
    end: float
    ke_per_kcpp: float
    ke_per_10t: float
    span: float

    @property
    def speed_up(self) -> float:
        return self.end / self.start if self.start > 0 else float("nan")


def density_waves(size: np.ndarray) -> DensityWaves:
    """The package's density-wave analysis on a channel of ``size`` (walls along y: the
    centres reach y in [d/2, W - d/2], as ``demstudy analyze`` sets it), cells ≈ 2 d."""
    return DensityWaves(dim=3, ranges=[None, (0.5, float(size[1]) - 0.5), None])


def iter_frames(f: h5py.File, start: float) -> Iterator[Frame]:
    """The stored frames from time ``start`` on, read one at a time (a 10^5-particle run
    holds GBs of frames)."""
    fr = f["frames"]
    times = fr["time"][()]
    for i in np.flatnonzero(times >= start):
        yield Frame(time=float(times[i]), box_lo=fr["box_lo"][i], box_hi=fr["box_hi"][i],
                    position=fr["position"][i], velocity=fr["velocity"][i],
                    angular_velocity=np.zeros((0, 3)), radius=fr["radius"][i])


def _energy_balance(ts: dict[str, np.ndarray], start: float) -> tuple[float, float]:
    """Dissipation rate over gravity's power in the production, jackknife error over time
    blocks (steady state: 1; digest §1.8 [L1088])."""
    t = ts["time"]
    keep = t >= start
    rates = np.stack([np.diff(ts["gravity_work"][keep]), np.diff(ts["dissipated_energy"][keep])],
                     axis=1) / np.diff(t[keep])[:, None]
    if rates.shape[0] < 4:
        return float("nan"), float("nan")
    acc = BlockAccumulator(2, 16)
    for row in rates:
        acc.add(row)
    est, err = jackknife(acc, lambda m: np.array([m[1] / m[0]]))
    return float(np.ravel(est)[0]), float(np.ravel(err)[0])


def _ke_halves(time: np.ndarray, ke: np.ndarray, start: float):
    keep = np.flatnonzero(time >= start)
    half = keep.size // 2
    return (series_mean(ke[keep[:half]], 16), series_mean(ke[keep[half:]], 16))


def _drifts(modes: Modes, halves: tuple[Modes, Modes]) -> list[Drift]:
    """The two leading xy families and the leading xz and yz family, in both halves."""
    picks = [("xy", k) for k in modes.leading("xy", 2)]
    picks += [("xz", k) for k in modes.leading("xz", 1)]
    # yz: the leading family varying along z (its (k_y, 0) families repeat xy's (0, k_y))
    picks += [("yz", k) for k in modes.leading("yz", 5) if k[1] >= 1][:1]
    return [Drift(p, k, halves[0].amplitude(p, k), halves[1].amplitude(p, k))
            for p, k in picks]


def plane_fields(frame: Frame, lo: np.ndarray, hi: np.ndarray, cells: np.ndarray,
                 plane: str) -> tuple[np.ndarray, ...]:
    """(centres a, centres b, solid fraction, u_a, u_b) of one frame on ``plane``: cell
    columns averaged over the third axis, the velocity the mean over the particles of a
    column minus the frame's mean velocity (NaN in empty columns)."""
    a, b = _AX[plane[0]], _AX[plane[1]]
    c = 3 - a - b
    pos = np.asarray(frame.position, float)
    vel = np.asarray(frame.velocity, float) - np.mean(frame.velocity, axis=0)
    h = (hi - lo) / cells
    idx = np.floor((pos - lo) / h).astype(np.int64)
    idx[:, 0] %= cells[0]
    idx[:, 2] %= cells[2]
    inside = (idx[:, 1] >= 0) & (idx[:, 1] < cells[1])
    na, nb = int(cells[a]), int(cells[b])
    flat = idx[inside, a] * nb + idx[inside, b]
    vol = np.pi / 6.0 * (2.0 * np.asarray(frame.radius, float)[inside]) ** 3
    nu = np.bincount(flat, vol, na * nb) / (h[a] * h[b] * (hi[c] - lo[c]))
    count = np.bincount(flat, minlength=na * nb).astype(float)
    with np.errstate(invalid="ignore", divide="ignore"):
        ua = np.bincount(flat, vel[inside, a], na * nb) / count
        ub = np.bincount(flat, vel[inside, b], na * nb) / count
    ca = lo[a] + (np.arange(na) + 0.5) * h[a]
    cb = lo[b] + (np.arange(nb) + 0.5) * h[b]
    return ca, cb, nu.reshape(na, nb), ua.reshape(na, nb), ub.reshape(na, nb)


@dataclass
class Scan:
    """What one pass over the production frames gives (``_scan``), or its stored copy in a
    study record (``derive``/``_stored``): the modes of the whole production and of each
    half, the peak densities per frame (2 d and COARSE d columns) and the last frame."""

    modes: Modes
    halves: tuple[Modes, Modes]
    peaks: np.ndarray
    last: Frame
    #: the modes of the frames within ±WINDOW c/p of each of ``snapshot_centres()`` that has
    #: at least WINDOW_FRAMES of them (key: the centre, our c/p)
    windows: dict[float, Modes] = field(default_factory=dict)


def _scan(f: h5py.File, eq_end: float, size: np.ndarray) -> Scan:
    """One pass over the production frames (``Scan``)."""
    whole, halves = density_waves(size), (density_waves(size), density_waves(size))
    times = f["frames/time"][()]
    prod = times[times >= eq_end]
    split = prod[len(prod) // 2] if len(prod) else eq_end
    ts_time, coll = f["timeseries/time"][()], f["timeseries/collisions"][()]
    n = int(f["frames/position"].shape[1])
    windows = {c: density_waves(size) for c in snapshot_centres()}
    last, peaks = None, []
    for frame in iter_frames(f, eq_end):
        whole.feed(frame)
        halves[int(frame.time >= split)].feed(frame)
        cpp = 2.0 * float(np.interp(frame.time, ts_time, coll)) / n
        for centre, window in windows.items():
            if -WINDOW <= cpp - centre < WINDOW:  # half-open: a frame in one window per edge
                window.feed(frame)
        coarse = np.maximum(2, np.round(whole.length / COARSE)).astype(int)
        peaks.append([float(np.max(plane_fields(frame, whole.lo, whole.hi, grid, "xy")[2]))
                      for grid in (whole.n, coarse)])
        last = frame
    if last is None or whole.n_frames < 4 or min(h.n_frames for h in halves) < 2:
        raise ValueError(f"{f.filename}: {whole.n_frames} frames in the production (t >= "
                         f"{eq_end}); the mode analysis needs at least 4 (keep_frames = true)")
    return Scan(Modes(*_finish(whole)), (Modes(*_finish(halves[0])), Modes(*_finish(halves[1]))),
                np.array(peaks), last,
                {c: Modes(*_finish(w)) for c, w in windows.items()
                 if w.n_frames >= WINDOW_FRAMES})


#: the record groups (demstudy.studies.records) holding a ``Scan``
_STORED = ("waves_modes", "waves_first_half", "waves_second_half")
_WINDOW_GROUP = "waves_window_"


def derive(path: Path) -> dict[str, tuple[dict[str, Any], dict[str, Any]]]:
    """What a study record keeps of run ``path`` in place of its frames: the ``Scan``."""
    with h5py.File(path, "r") as f:
        attrs = read_attrs(f)
        scan = _scan(f, _equilibration_end(f, attrs),
                     f["frames/box_hi"][0] - f["frames/box_lo"][0])
    last = scan.last
    out = {name: (m.results, m.attrs) for name, m in
           zip(_STORED, (scan.modes, *scan.halves), strict=True)}
    for centre, modes in scan.windows.items():
        out[f"{_WINDOW_GROUP}{centre:.0f}"] = (modes.results, {**modes.attrs,
                                                                "centre_cpp": centre,
                                                                "half_width_cpp": WINDOW})
    out["waves_peaks"] = ({"peaks": scan.peaks}, {
        "description": "densest xy cell column per production frame: 2 d cells, COARSE d "
                       "columns", "coarse": COARSE})
    # single precision: ample for the figures and the 1.05 d neighbour count, half the bytes
    f32 = {k: np.asarray(getattr(last, k), np.float32) for k in ("position", "velocity", "radius")}
    out["waves_last_frame"] = ({**f32, "box_lo": last.box_lo,
                                "box_hi": last.box_hi}, {"time": last.time})
    return out


def _stored(f: h5py.File) -> Scan:
    """The ``Scan`` kept in a study record (``derive``)."""

    def group(name: str) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        g = f[f"study/{name}"]
        return {k: v[()] for k, v in g.items()}, read_attrs(g)

    modes = [Modes(*group(name)) for name in _STORED]
    last, last_attrs = group("waves_last_frame")
    wide = {k: np.asarray(last[k], float) for k in ("position", "velocity", "radius")}
    frame = Frame(time=float(last_attrs["time"]), box_lo=last["box_lo"], box_hi=last["box_hi"],
                  angular_velocity=np.zeros((0, 3)), **wide)
    windows = {}
    for name in f["study"]:
        if name.startswith(_WINDOW_GROUP):
            data, attrs = group(name)
            windows[float(attrs["centre_cpp"])] = Modes(data, attrs)
    return Scan(modes[0], (modes[1], modes[2]), group("waves_peaks")[0]["peaks"], frame,
                dict(sorted(windows.items())))


def _equilibration_end(f: h5py.File, attrs: dict[str, Any]) -> float:
    """The run's production start (the first frame's time when a file does not say)."""
    if "equilibration_end" in attrs:
        return float(attrs["equilibration_end"])
    if f["frames/time"].shape[0] == 0:
        raise ValueError(f"{f.filename}: no frames (keep_frames = true)")
    return float(f["frames/time"][0])


def measure(path: Path) -> RunWaves:
    """Measure one results file (module docstring): from its frames, or from what a study
    record kept of them."""
    with h5py.File(path, "r") as f:
        attrs = read_attrs(f)
        ts = {k: v[()] for k, v in f["timeseries"].items()}
        if "frames" in f:
            eq_end = _equilibration_end(f, attrs)
            scan = _scan(f, eq_end, f["frames/box_hi"][0] - f["frames/box_lo"][0])
        elif "study/waves_modes" in f:
            scan = _stored(f)
            eq_end = float(attrs.get("equilibration_end", scan.modes.results["series_time"][0]))
        else:
            raise ValueError(f"{path}: neither frames (keep_frames = true) nor a study "
                             "record's waves_* groups: the density modes cannot be measured")
    last = scan.last
    n = int(np.asarray(last.position).shape[0])
    size = np.asarray(last.box_hi, float) - np.asarray(last.box_lo, float)
    time = ts["time"]
    cpp = 2.0 * ts["collisions"] / n
    ke = ts["kinetic_energy"] / n
    modes, both, peaks = scan.modes, scan.halves, scan.peaks
    keep = time >= eq_end
    rate = float(np.ptp(cpp[keep]) / np.ptp(time[keep])) if keep.sum() > 1 else float("nan")
    lo, hi = np.asarray(modes.attrs["lo"], float), np.asarray(modes.attrs["hi"], float)
    cells = np.asarray(modes.attrs["cells"], int)
    snap = Snapshot(last.time, float(np.interp(last.time, time, cpp)),
                    np.asarray(last.position, float),
                    {p: plane_fields(last, lo, hi, cells, p) for p in PLANES})
    return RunWaves(
        path=Path(path), n=n, size=size,
        restitution=_scene_restitution(attrs), time=time, cpp=cpp, ke=ke, eq_end=eq_end,
        modes=modes, halves=both, series_cpp=np.interp(modes.results["series_time"], time, cpp),
        drifts=_drifts(modes, both), ke_halves=_ke_halves(time, ke, eq_end),
        balance=_energy_balance(ts, eq_end), peak=series_mean(peaks[:, 0], 16),
        peak_coarse=series_mean(peaks[:, 1], 16),
        close_packed=close_packed_fraction(last.position, size), rate=rate,
        wall_seconds=float(attrs.get("wall_seconds", float("nan"))),
        tc_fraction=float(attrs.get("tc_elastic_fraction", float("nan"))), snapshot=snap,
        tc=float(attrs.get("tc", float("nan"))), windows=scan.windows)


def close_packed_fraction(position: np.ndarray, size: np.ndarray) -> float:
    """Fraction of the particles with at least 12 neighbours closer than 1.05 d (x and z
    periodic): an FCC/HCP-like, touching shell, the signature of a close-packed core."""
    from scipy.spatial import cKDTree

    pos = np.array(position, float)
    pos[:, 0] %= size[0]
    pos[:, 2] %= size[2]
    tree = cKDTree(pos, boxsize=[size[0], 1e9, size[2]])
    counts = np.array([len(n) - 1 for n in tree.query_ball_point(pos, 1.05)])
    return float(np.mean(counts >= 12))


def _finish(analysis: DensityWaves) -> tuple[dict, dict]:
    analysis.finish()
    return analysis.results, analysis.attrs


def _scene_restitution(attrs: dict[str, Any]) -> float:
    try:
        return float(tomllib.loads(attrs["scene_toml"])["contact"]["restitution"])
    except (KeyError, ValueError, TypeError):
        return float("nan")
