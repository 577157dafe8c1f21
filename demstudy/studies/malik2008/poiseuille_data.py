"""What the Poiseuille part reads from a results file, in Malik's (2008) forms: the binwise
profiles (25 bins of 2 d, bin 1 at the lower wall), the wall values (the two bins adjacent to
the walls, bins 1 and 25, §4.5), Kn = λ/W per bin (free paths relative to the local mean flow,
§4.4), the VDFs, Λ(y), the velocity correlations, the in-bin g(r) (computed here from the kept
frames) and the run's length in collisions per particle (2 N_pp / N: each pair collision
counts for both particles; wall collisions are not counted).

Dimensionless particle units: d = 1, m = 1, g = 1 (gravity acts): speeds in √(gd), spins in
√(g/d), temperatures in g d, times in √(d/g); Malik's u* = u/√(gd) etc. are these numbers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ...analysis.pair_correlation import PairCorrelation
from ...io.results import Results, read_results
from ..records import derived
from .poiseuille_cases import Flow

#: Malik's bins (1-based) shown in the g(r) figures and the φ = 0.1 VDFs (φ = 0.5: 1, 3, 13)
BINS = (1, 4, 13)
BINS_DENSE = (1, 3, 13)
#: the φ = 0.01 VDFs' bins: the shear-layer bins 4 and 21 and the centre 13 (digest §4.6,
#: [L746]); φ = 0.1 and 0.5 show theirs at BINS and BINS_DENSE
BINS_DILUTE_VDF = (4, 13, 21)


def vdf_bins(phi: float) -> tuple[int, ...]:
    """The bins (1 at y = 0, 13 the centre, 25 at y = W) whose VDFs the thesis shows at φ."""
    return BINS_DILUTE_VDF if phi == 0.01 else BINS_DENSE if phi == 0.5 else BINS


CENTRE_BIN = 13


@dataclass(eq=False)  # identity: a run is hashable (figure legends, colours)
class FlowData:
    """One run of a flow, read: ``res`` without frames and log; ``gr`` the in-bin g(r)."""

    flow: Flow
    path: Path
    res: Results
    gr: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def prof(self) -> dict[str, np.ndarray]:
        return self.res.profiles

    def stat(self, name: str) -> dict[str, np.ndarray]:
        return self.res.groups.get(f"statistics/{name}", {})

    @property
    def y(self) -> np.ndarray:
        return self.prof["y"]

    def series(self, key: str) -> tuple[np.ndarray, np.ndarray]:
        """(value, error) profile of ``key``: ux, omz, phi, T, theta, Kn, Kn_lab."""
        p = self.prof
        if key == "ux":
            return p["velocity"][:, 0], p["velocity_err"][:, 0]
        if key == "omz":
            return p["spin"][:, 2], p["spin_err"][:, 2]
        if key == "phi":
            return p["solid_fraction"], p["solid_fraction_err"]
        if key == "T":
            return p["temperature"], p["temperature_err"]
        if key == "theta":
            return p["rotational_temperature"], p["rotational_temperature_err"]
        if key in ("Kn", "Kn_lab"):
            # Kn: free paths relative to the local mean flow; Kn_lab: the lab-frame
            # displacements between collisions of the thesis's formula (digest §4.4)
            name = "knudsen" if key == "Kn" else "lab_knudsen"
            fp = self.stat("freepath")
            if name not in fp:
                n = self.y.size
                return np.full(n, np.nan), np.full(n, np.nan)
            return fp[name], fp[f"{name}_err"]
        raise KeyError(f"profile {key!r}: allowed ux, omz, phi, T, theta, Kn, Kn_lab")

    def mean_temperature(self) -> tuple[float, float]:
        """The run's mass-weighted mean translational T over the bins and its jackknife
        error (the profiles analysis's ``mean_temperature``)."""
        return (float(self.prof["mean_temperature"]),
                float(self.prof["mean_temperature_err"]))

    def wall_value(self, key: str) -> tuple[float, float]:
        """Malik's wall value (§4.5): the mean of the two bins adjacent to the walls (bins 1
        and 25); ω_z is antisymmetric, so its lower-wall value enters with the opposite sign
        (the rotational slip is then positive when particles roll on both walls)."""
        v, e = self.series(key)
        sign = -1.0 if key == "omz" else 1.0
        return 0.5 * (sign * v[0] + v[-1]), 0.5 * math.hypot(e[0], e[-1])

    def centre_value(self, key: str) -> tuple[float, float]:
        v, e = self.series(key)
        return float(v[CENTRE_BIN - 1]), float(e[CENTRE_BIN - 1])

    def run_info(self) -> dict[str, Any]:
        """Steady-state flag, production length in √(d/g) and collisions per particle."""
        ts, attrs = self.res.timeseries, self.res.attrs
        n = self.res.scene.particles.count
        t0 = float(attrs.get("equilibration_end", 0.0))
        t, coll = ts["time"], ts["collisions"]
        start = int(np.searchsorted(t, t0))
        per_particle = 2.0 * float(coll[-1] - coll[min(start, coll.size - 1)]) / n
        return {"steady": bool(attrs.get("steady", False)),
                "trend": float(attrs.get("kinetic_energy_trend", float("nan"))),
                "production": float(t[-1] - t0), "collisions_per_particle": per_particle,
                "equilibration_collisions": 2.0 * float(coll[min(start, coll.size - 1)]) / n,
                "wall_seconds": float(attrs.get("wall_seconds", float("nan"))),
                # the engine's TC model (not in the thesis): share of pair collisions elastic
                "tc_fraction": float(attrs.get("tc_elastic_fraction", float("nan"))),
                "tc": float(attrs.get("tc", float("nan")))}


def in_bin_gr(path: Path, edges: np.ndarray, r_max: float = 5.0, dr: float = 0.05,
              distance: str = "full") -> dict[str, np.ndarray]:
    """Malik's in-bin g(r) (§4.7: both particles in one y-bin; ``distance="full"``: the 3D
    distance with slab-corrected shells, so that an ideal gas gives 1; the planar reading is
    the ``"planar"`` option) from the run's kept frames."""
    full = read_results(path, skip=("collisions",))
    if not full.frames:
        return {}
    pc = PairCorrelation(dim=3, r_max=r_max, dr=dr, edges_y=edges, distance=distance)
    pc.run(full.iter_frames())
    return dict(pc.results)


def flow_gr(flow: Flow, path: Path, edges: np.ndarray) -> dict[str, np.ndarray]:
    """The in-bin g(r) of the run of ``flow`` at ``path`` from its frames (dilute: wider
    shells, g ≈ 1 is flat and the counts are few)."""
    return in_bin_gr(Path(path), edges, dr=0.1 if flow.phi < 0.05 else 0.05)


def load_flow(flow: Flow, path: Path, with_gr: bool = True) -> FlowData:
    """The run of ``flow`` at ``path`` (``with_gr``: the in-bin g(r), as a study record keeps
    it or computed from the frames)."""
    res = read_results(path, skip=("frames", "collisions"))
    data = FlowData(flow, Path(path), res)
    if with_gr:
        kept = derived(res.groups, "gr")
        data.gr = kept if kept is not None else flow_gr(flow, Path(path), res.profiles["edges"])
    return data


def wall_distance(y: np.ndarray, b: int) -> float:
    """The distance from bin ``b``'s centre (0-based, bin centres ``y`` spanning the channel
    symmetrically) to the nearer wall, in d."""
    return float(min(y[b], y[-1] + y[0] - y[b]))


def wall_gradient(u: np.ndarray, e: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """dU_x/dy at the walls from the profile ``u`` ± ``e`` on bin centres ``y`` (bins 1-2
    and 24-25: the symmetric profile's two gradients have opposite signs, this is their
    mean magnitude, positive for a flow faster at the centre) and its error, per √(d/g)."""
    dy = float(y[1] - y[0])
    value = 0.5 * ((u[1] - u[0]) + (u[-2] - u[-1])) / dy
    err = 0.5 * math.sqrt(e[0] ** 2 + e[1] ** 2 + e[-1] ** 2 + e[-2] ** 2) / dy
    return float(value), float(err)


def contact_value(gr: dict[str, np.ndarray], b: int) -> tuple[float, float]:
    """g at contact in bin ``b`` (0-based): the first two shells beyond r = d extrapolated
    linearly to r = d (hard spheres: g jumps at d and falls off beyond)."""
    r_edges = gr["r_edges"]
    k = int(np.searchsorted(r_edges, 1.0 - 1e-9))
    g, e = gr["g"][b], gr["g_err"][b]
    g1, g2 = g[k], g[k + 1]
    r1, r2 = 0.5 * (r_edges[k] + r_edges[k + 1]), 0.5 * (r_edges[k + 1] + r_edges[k + 2])
    w = (1.0 - r1) / (r2 - r1)  # weight of the extrapolation (negative)
    value = g1 + w * (g2 - g1)
    err = math.hypot((1 - w) * e[k], w * e[k + 1])
    return float(value), float(err)


def carnahan_starling(phi: float) -> float:
    """Enskog's contact value χ(φ) of Carnahan-Starling: (1 - φ/2)/(1 - φ)³."""
    return (1 - 0.5 * phi) / (1 - phi) ** 3


def collisions_text(datas: list[FlowData]) -> str:
    """The production lengths of ``datas`` in collisions per particle (range)."""
    c = [d.run_info()["collisions_per_particle"] for d in datas]
    if not c:
        return "n/a"
    lo, hi = min(c), max(c)
    return f"{lo:.3g}" if abs(hi - lo) < 0.05 * hi else f"{lo:.3g}-{hi:.3g}"
