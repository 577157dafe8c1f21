"""Fluid random starts by Lubachevsky–Stillinger growth (dense ``placement = "random"``).

Dimensionless particle units: d = 1, m = d^dim, thermal speed 1 during the growth.

Random sequential addition (RSA) stalls near its jamming limit (φ ≈ 0.38 spheres, 0.547
discs) and a random subset of a lattice stays crystalline, so a dense random start is made in
three steps: RSA of the particles shrunk by a common factor s0 to the solid fraction
``GROWTH_START`` (quick), then event-driven growth of every diameter at the rate ds/dt =
``GROWTH_RATE`` (elastic, smooth collisions in the frame of the growing surfaces; the speeds
are rescaled to T = 1 every ``CHUNK``), then an elastic run of ``RELAX_TIME`` at full size
that relaxes the compressed packing towards the equilibrium fluid. The native core is
:func:`demstudy._native.edmd_grow_packing` (native/src/edmd/growth.cpp).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Solid fraction of the shrunk RSA start (well below RSA's jamming limits: it fills in ms).
GROWTH_START = {2: 0.30, 3: 0.20}
#: ds/dt in units of the thermal speed (T = 1): fast enough to take ~1 s for N = 4000 at
#: φ = 0.5, slow enough that the packing stays a fluid and not a jammed glass.
GROWTH_RATE = 0.1
#: Time between velocity rescalings (growth heats the system).
CHUNK = 0.25
#: Elastic relaxation at full size, in units of d/√T (~20–50 collisions per particle when dense).
RELAX_TIME = 1.0
#: Growth is given up (a lattice start is used instead) beyond this many events per particle:
#: the packing has jammed below the target (too dense for a fluid). Reaching the densest
#: allowed random starts takes ≤ 171 (φ = 0.60 spheres) and ≤ 83 (ν = 0.80 discs).
MAX_EVENTS_PER_PARTICLE = 1000
#: Diameters are grown to (1 + SAFETY) × their value, so contacts left at the end have a gap.
SAFETY = 1e-9


@dataclass
class Growth:
    position: np.ndarray  # (N, dim), inside the region, no overlap at the full diameters
    reached: bool         # False: jammed before the target (positions then unusable)
    collisions: int
    events: int
    pressure: float       # reduced pressure P/(n T) of the relaxation run (nan if none)


def grow_fluid(
    diameter: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    periodic: np.ndarray,
    walls: tuple[float, float] | None,
    rng: np.random.Generator,
    relax_time: float = RELAX_TIME,
) -> Growth:
    """A fluid packing of particles of ``diameter`` whose centres lie in [lo, hi).

    ``periodic[ax]`` says which axes wrap (x, z always; y unless ``walls`` = the surfaces of
    the lower and upper walls, which the particle surfaces must not cross). ``lo``/``hi``
    bound the centres of the largest particle (for the RSA start).
    """
    from demstudy._native import edmd_grow_packing  # noqa: PLC0415 - native module

    from .initial import _sequential_addition  # noqa: PLC0415 - initial imports this module

    n, dim = len(diameter), len(lo)
    lengths = hi - lo
    # RSA excludes s0 × the largest diameter around every centre: shrink by that measure
    phi = n * _volume(diameter.max(), dim) / np.prod(lengths)
    s0 = min(1.0, (GROWTH_START[dim] / phi) ** (1.0 / dim))
    start = _sequential_addition(n, lo, hi, periodic, s0 * diameter.max(), rng)
    if start is None:
        raise ValueError(f"random sequential addition failed at solid fraction {phi * s0**dim:.3g}")
    mass = diameter**dim
    velocity = rng.normal(size=(n, dim)) / np.sqrt(mass)[:, None]
    velocity -= (mass[:, None] * velocity).sum(axis=0) / mass.sum()
    # periodic axes start at 0 (as in initial._random_placement); walls bound y absolutely
    box = [float(hi[ax]) if periodic[ax] else float(hi[ax] - lo[ax]) for ax in range(dim)]
    y_range = [0.0, box[1]] if walls is None else [float(walls[0]), float(walls[1])]
    out = edmd_grow_packing(
        np.ascontiguousarray(start), np.ascontiguousarray(velocity),
        np.ascontiguousarray(diameter, dtype=float), np.ascontiguousarray(mass, dtype=float),
        box, dim, walls is None, y_range, s0, 1.0 + SAFETY, GROWTH_RATE, relax_time, CHUNK,
        1.0, MAX_EVENTS_PER_PARTICLE * n,
    )
    # virial theorem at T = 1: P/(nT) = 1 + Σ m_ij Δu r_ij / (dim N T t)
    t_relax = relax_time if out["reached"] else 0.0
    pressure = 1.0 + out["relax_virial"] / (dim * n * t_relax) if t_relax > 0 else float("nan")
    return Growth(out["positions"], bool(out["reached"]), int(out["collisions"]),
                  int(out["events"]), pressure)


def _volume(diameter, dim: int):
    return np.pi / 4 * diameter**2 if dim == 2 else np.pi / 6 * diameter**3
