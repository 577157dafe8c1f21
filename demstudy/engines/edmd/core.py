"""Thin Python layer over the C++ event-driven core ``demstudy._native.EventDriven``.

Dimensionless particle units: d = 1, m = 1 (mass ∝ d^dim), no gravity in milestone 1.

``EventDriven(positions, velocities, angular_velocities, diameters, masses, box, dim, e=1,
beta=-1, inertia_k=0.4, tc=0)``: positions/velocities (N, dim), angular velocities (N, 1) in
2D and (N, 3) in 3D, box lengths (dim,), every axis periodic. ``advance_to(t)`` processes all
events up to t, then synchronises every particle to t (``advance_to(t, max_events=k)`` stops
after k events if t is not reached and returns False). ``get_state()`` returns every array
needed to continue (positions, velocities, spins, cells, last-collision times, counters and
the scheduled events); ``set_state(state)`` on a system built from the same particles
continues bit-identically (events are processed in the total order (time, index)).
Accessors: ``positions()`` (wrapped into [0, L)), ``velocities()``, ``angular_velocities()``,
``kinetic_energy``, ``rotational_energy``, ``time``; counters ``collisions``,
``cell_crossings``, ``events`` (= pair + wall collisions + crossings), ``invalid_events`` (stale
predictions discarded), ``elastic_tc_collisions``; ``virial`` = Σ r_ij·J_i over all collisions
(r_ij = r_i − r_j, J_i the impulse on i) and ``virial_tensor`` Σ r_ij ⊗ J_i, so the collisional
pressure over an interval Δt is ΔW / (dim V Δt); ``dissipated`` = energy lost in collisions
(translational + rotational); ``min_gap()`` = smallest |r_ij| − σ_ij (negative: overlap).

Collision rule (Lun; Malik 2008 eqs. 2.5–2.11 for unequal masses): with the unit normal n from
i to j and the contact-point relative velocity g = v_i − v_j + (r_i ω_i + r_j ω_j) × n, the
impulse on i is J = −m*(1 + e)(g·n) n − m*(1 + β) K/(1 + K) g_t, m* = m_i m_j/(m_i + m_j),
I = K m r². So g_n' = −e g_n, g_t' = −β g_t, and for equal masses
ΔE = −(m/4)[(1 − e²) g_n² + K/(1 + K)(1 − β²)|g_t|²]. β = −1 (smooth) never changes spins.

Inelastic collapse: the TC model (Luding & McNamara 1998). A collision in which either
partner had its previous collision less than ``tc`` earlier is elastic (e = 1, no tangential
impulse). The default t_c depends on the dimension (:func:`default_tc`): 1e-6 time units for
spheres (``DEFAULT_TC_3D``), 1e-5 for discs (``DEFAULT_TC_2D``); 0 disables the model. Why
these, measured: docs/edmd-engine.md ("Why these t_c") and benchmarks/bench_tc_choice.py.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..._native import EventDriven, edmd_collide_pair
from ...errors import EngineError
from ...scene.initial import InitialState

#: the TC time of 3D runs: dense sheared spheres keep their elastic share at 0.3-6 % and their
#: pressure converged (φ = 0.55 shear, e = 0.9: P 42.0 ± 0.9 at 1e-5, 47.1 ± 1.3 at 1e-6,
#: 46.1 ± 1.7 at 1e-7; e = 0.7: 58.7, 76.5, 78.7) at ×1.0-2.1 the cost of 1e-5; a bed at rest
#: costs ~1/t_c events per particle and time unit (×5 at 1e-6)
DEFAULT_TC_3D = 1e-6
#: the TC time of 2D runs: mildly dissipative dense shear is converged at any t_c, strongly
#: dissipative shear at none (ν = 0.75, e = 0.5: the run warns), and in Campbell's chute a
#: smaller t_c raised the share (a cluster's re-collisions) at ×7.6 the cost
DEFAULT_TC_2D = 1e-5
# events between two synchronisations and checks for a stop request; the simulated time's
# progress is checked over windows of at least STALL_CHUNK and STALL_CHUNK_PER_PARTICLE × N
STALL_CHUNK = 10_000_000
STALL_CHUNK_PER_PARTICLE = 1000

__all__ = ["DEFAULT_TC_2D", "DEFAULT_TC_3D", "STALL_CHUNK", "EventDriven", "advance_watched",
           "collide_pair", "default_tc", "from_initial_state", "stall_message"]


def default_tc(dimension: int) -> float:
    """The TC time t_c of a run without the ``tc`` option: ``DEFAULT_TC_3D`` (1e-6) for
    spheres, ``DEFAULT_TC_2D`` (1e-5) for discs, in the scene's time unit."""
    return DEFAULT_TC_3D if dimension == 3 else DEFAULT_TC_2D


def collide_pair(n, ri, rj, mi, mj, inertia_k, e, beta, vi, vj, wi, wj):
    """One collision: returns (vi', vj', wi', wj', J) as 3-vectors (z = 0 / spin z in 2D)."""
    as3 = [np.asarray(a, float).ravel().tolist() for a in (n, vi, vj, wi, wj)]
    n3, vi3, vj3, wi3, wj3 = as3
    return edmd_collide_pair(n3, float(ri), float(rj), float(mi), float(mj), float(inertia_k),
                             float(e), float(beta), vi3, vj3, wi3, wj3)


def from_initial_state(state: InitialState, box, e: float = 1.0, beta: float = -1.0,
                       inertia_k: float = 0.4, tc: float = 0.0, **options) -> EventDriven:
    """An ``EventDriven`` system from ``demstudy.scene.initial.build_initial_state`` output;
    ``options`` as ``EventDriven`` (gravity, shear_rate, periodic_y, y_range, walls, pair,
    stress_bins, log_every, log_capacity)."""
    dim = state.position.shape[1]
    c = np.ascontiguousarray
    return EventDriven(c(state.position, float), c(state.velocity, float),
                       c(state.angular_velocity, float), c(state.diameter, float),
                       c(state.mass, float), [float(b) for b in box], dim, e=e, beta=beta,
                       inertia_k=inertia_k, tc=tc, **options)


def advance_watched(core: EventDriven, t: float, *, tc: float, max_events: int = 0,
                    stop_collisions: int = 0,
                    stop_requested: Callable[[], bool] | None = None,
                    dissipative: bool = False, bumps: bool = False) -> bool:
    """``core.advance_to(t, max_events, stop_collisions)``, watched for a stall.

    Events (collisions, crossings and stale predictions) are processed in chunks of
    ``STALL_CHUNK`` (10⁷). A window of at least max(``STALL_CHUNK``, 1000 N) events that
    moves the simulated time by no more than max(t_c, 1e-9) means the run can never finish,
    so it raises ``EngineError`` naming the time and the cause (:func:`stall_message`)
    instead of hanging: with the TC model off (t_c = 0) and dissipative collisions
    (``dissipative``: some restitution below 1) an inelastic collapse, otherwise (or when
    the stalled events are mostly collisions with the fixed particles of bumpy walls,
    ``bumps``) a zero-time
    collision loop of exactly touching particles (a particle caged at zero gaps between
    fixed bumps, a crystalline row). A legitimately slow run is not caught: a bed resting
    under the TC model costs about N/t_c events per time unit, so one window still moves the
    time by about 1000 t_c.

    Returns True when t is reached. Returns False when the run stopped early at
    ``max_events`` (> 0, counted from the call), at ``stop_collisions``, or because
    ``stop_requested()`` (asked after every chunk) said so: Ctrl-C is then honoured within
    one chunk (10⁷ events: seconds to a minute), not only at the next sample.

    Between chunks every particle is synchronised (as ``advance_to`` does at t), so the chunk
    size belongs to the trajectory. It is fixed, so runs stay deterministic and resume
    bit-identically (a resumed run's chunks start where the stopped one's ended).
    """
    chunk = max(STALL_CHUNK, STALL_CHUNK_PER_PARTICLE * core.n)
    start = _processed(core)
    window = _Window.at(core)  # the stall window: at least `chunk` events
    while True:
        budget = STALL_CHUNK  # a large system's window in steps, so stops come in time
        if max_events > 0:
            budget = min(budget, max_events - (_processed(core) - start))
            if budget <= 0:
                return False
        if core.advance_to(t, max_events=budget, stop_collisions=stop_collisions):
            return True
        if stop_collisions > 0 and core.collisions >= stop_collisions:
            return False
        if _processed(core) - window.events >= chunk:
            if core.time - window.time <= max(tc, 1e-9):
                raise EngineError(stall_message(core, window, tc, dissipative, bumps))
            window = _Window.at(core)
        if stop_requested is not None and stop_requested():
            return False


@dataclass(frozen=True)
class _Window:
    """The core's counters where a stall window starts."""

    time: float
    events: int
    pairs: int
    walls: int

    @classmethod
    def at(cls, core: EventDriven) -> _Window:
        return cls(core.time, _processed(core), core.collisions, core.wall_collisions)


def stall_message(core: EventDriven, window: _Window, tc: float, dissipative: bool,
                  bumps: bool = False) -> str:
    """Why the run stalled, diagnosed from what the window's events were.

    With t_c = 0 and dissipative collisions: collisions (mostly between particles, or of
    particles with a flat wall) whose intervals shrink geometrically while the relative
    velocities go to zero, so infinitely many of them fall before a finite time: inelastic
    collapse (McNamara & Young 1994), which the TC model exists to stop. Otherwise, and when
    the window's collisions are mostly with walls that carry bumps (``bumps``: a particle
    caged at zero gaps keeps bouncing, elastically within t_c, for any t_c), exactly
    touching particles bouncing in a loop that takes no time, which no t_c cures."""
    events = _processed(core) - window.events
    pairs, walls = core.collisions - window.pairs, core.wall_collisions - window.walls
    head = (f"the event-driven run stalled at t = {core.time:.9g}: {events} events "
            f"({pairs} pair and {walls} wall collisions) moved the time by "
            f"{core.time - window.time:.3g} (at most max(t_c, 1e-9) = {max(tc, 1e-9):.3g}). ")
    if tc == 0.0 and dissipative and pairs + walls > 0 and (pairs >= walls or not bumps):
        partners = "particles" if pairs >= walls else "particles and a wall"
        return head + (f"This is inelastic collapse: with the TC model switched off (--tc 0) "
                       f"and a restitution below 1, a cluster of {partners} collides ever "
                       "faster while their relative velocities go to zero, infinitely often "
                       "before a finite time. Rerun without --tc (the default t_c, "
                       f"{_short(DEFAULT_TC_2D)} for discs and {_short(DEFAULT_TC_3D)} for "
                       "spheres: a collision within t_c of a partner's previous one is "
                       "elastic), or use the LAMMPS engine")
    return head + ("Most likely a cluster of exactly touching particles is colliding in a "
                   "loop that takes no time, for example a particle caged at zero gaps "
                   "between fixed bumps or in a crystalline row. Perturb the start (another "
                   "seed, random bumps) or use the LAMMPS engine")


def _processed(core: EventDriven) -> int:
    """Events the core has worked through: collisions, crossings and stale predictions (the
    budget of ``advance_to(max_events=…)`` counts all three)."""
    return core.events + core.invalid_events


def _short(value: float) -> str:
    """1e-05 → 1e-5 (as one types it on the command line)."""
    return f"{value:g}".replace("e-0", "e-").replace("e+0", "e+")
