"""Measure e, beta, contact time and peak force of LAMMPS ``granular`` contacts from isolated
collisions, and the slow wall motions (incline rolling, sliding to rolling) of ``motion.py``.

Units: dimensionless particle units, diameter d = 1, mass m = 1 (masses ∝ d^dim for other
sizes; g = 1 on the incline and in the sliding case).
Each collision is a fresh LAMMPS instance (opened with ``open_lammps``) holding
two particles (``kind='pair'``, diameters ``sizes``) or one particle above a
``wall/gran granular`` plane (``kind='wall'``), stepped one step at a time. Contact-point
relative velocities ``g = v_i - v_j - (R_i w_i + R_j w_j) x n`` (wall: ``v_i - R w_i x n``) are
projected on the collision normal n, the direction of the total normal impulse
sum_k (f_k.n_k) n_k (the line of centres turns by ~ g_t t_c / d during an oblique pair
contact); e = -g'.n / g.n and beta = -g'_t.t / |g_t|, t the unit pre-collision tangential
direction. The contact time is the time the overlap (hence the force) is positive, from
interpolated zero crossings of the overlap; the peak force is the largest f.n on particle i.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ...contact.calibration import CollisionRow, MotionRow
from ...contact.discrete import DiscreteContact, mean_restitution
from ...contact.mapping import (
    ContactParameters,
    Model,
    hertz_contact,
    hooke_contact,
    hooke_peak_force,
    inertia_factor,
    make_contact,
    pair_mass,
    pair_radius,
    spring_beta,
    walton_beta,
)
from ...errors import UnsupportedByEngine
from .bodies import Atom, open_bodies, read_state
from .motion import rolling_acceleration, sliding_to_rolling

__all__ = ["Impact", "calibrate", "calibrate_case", "collide", "impact",
           "rolling_acceleration", "sliding_to_rolling"]

Kind = Literal["pair", "wall"]
Case = Literal["impact", "rolling", "sliding"]


def _overlap_normal(x: np.ndarray, wall: bool, r: Sequence[float]) -> tuple[float, np.ndarray]:
    if wall:
        return r[0] - x[0, 1], np.array([0.0, 1.0, 0.0])
    sep = x[0] - x[1]
    dist = float(np.linalg.norm(sep))
    return r[0] + r[1] - dist, sep / dist


def _contact_velocity(v: np.ndarray, w: np.ndarray, n: np.ndarray, wall: bool,
                      r: Sequence[float]) -> np.ndarray:
    if wall:
        return v[0] - r[0] * np.cross(w[0], n)
    return v[0] - v[1] - np.cross(r[0] * w[0] + r[1] * w[1], n)


@dataclass(frozen=True)
class Impact:
    """One measured collision. States (x, v, omega per particle, id order) before and after;
    ``normal`` is the collision normal (direction of the total normal impulse)."""

    e: float
    beta: float
    contact_time: float
    spin_after: float
    peak_force: float
    normal: np.ndarray
    masses: np.ndarray
    diameters: np.ndarray
    before: tuple[np.ndarray, np.ndarray, np.ndarray]
    after: tuple[np.ndarray, np.ndarray, np.ndarray]


def impact(dim: int, kind: Kind, params: ContactParameters, speed: float, angle: float,
           dt: float, *, sizes: Sequence[float] = (1.0, 1.0), spin: float = 0.0,
           phase: float = 0.5, masses: Sequence[float] | None = None,
           bodies: tuple = (open_bodies, read_state)) -> Impact:
    """One isolated collision of particle 1 (diameter ``sizes[0]``, spin ``spin`` about z, the
    axis normal to the plane of impact) with particle 2 (``sizes[1]``, no spin) or a wall.

    The centres' relative velocity has magnitude ``speed`` at ``angle`` degrees from the inward
    normal (the contact point also moves by the spin); the pair's centre of mass is at rest;
    masses ∝ d^dim unless given; the first overlap arrives ``phase`` steps after the start.
    ``bodies``: the engine's (open, read) pair (``bodies.open_bodies``, ``read_state``; the
    LIGGGHTS engine passes its own).
    """
    if not (0.0 <= angle < 90.0 and speed > 0.0 and 0.0 < phase <= 1.0):
        raise ValueError("need 0 <= angle < 90 degrees, speed > 0 and 0 < phase <= 1")
    wall = kind == "wall"
    d = [float(s) for s in sizes[: 1 if wall else 2]]
    m = [di**dim for di in d] if masses is None else [float(x) for x in masses[: len(d)]]
    r = [0.5 * di for di in d]
    th = math.radians(angle)
    g = np.array([speed * math.sin(th), -speed * math.cos(th), 0.0])  # normal = +y at touch
    t0 = phase * dt
    if wall:
        atoms: list[Atom] = [(0.0, r[0] - g[1] * t0, 0.0, *g, spin, d[0], m[0])]
    else:
        sep, mt = np.array([0.0, r[0] + r[1], 0.0]) - g * t0, m[0] + m[1]
        atoms = [(*(m[1] / mt * sep), *(m[1] / mt * g), spin, d[0], m[0]),
                 (*(-m[0] / mt * sep), *(-m[0] / mt * g), 0.0, d[1], m[1])]
    opener, reader = bodies
    lmp = opener(dim, wall, params, dt, atoms)
    n_at = len(atoms)
    try:
        x, v, w, _ = reader(lmp, n_at)
        before = (x, v, w)
        prev = _overlap_normal(x, wall, r)[0]
        t_in = t_out = None
        normals, peak = [], 0.0
        for step in range(1, 1_000_000):
            lmp.command("run 1 pre no post no")
            x, v, w, f = reader(lmp, n_at)
            ov, n = _overlap_normal(x, wall, r)
            if t_in is None and ov > 0.0:
                t_in = (step - 1 + -prev / (ov - prev)) * dt
            if ov > 0.0:
                fn = float(f[0] @ n)
                normals.append(fn * n)
                peak = max(peak, fn)
            elif t_in is not None:
                t_out = (step - 1 + prev / (prev - ov)) * dt
                break
            prev = ov
    finally:
        lmp.close()
    if t_out is None or t_in is None:
        raise RuntimeError("the particles never separated")
    nc = np.sum(normals, axis=0)
    nc /= np.linalg.norm(nc)
    g0 = _contact_velocity(before[1], before[2], nc, wall, r)
    g1 = _contact_velocity(v, w, nc, wall, r)
    gn, gn2 = float(g0 @ nc), float(g1 @ nc)
    gt = g0 - gn * nc
    gt_norm = float(np.linalg.norm(gt))
    beta = -float((g1 - gn2 * nc) @ gt) / gt_norm**2 if gt_norm > 1e-12 * speed else math.nan
    return Impact(-gn2 / gn, beta, t_out - t_in, float(np.abs(w).max()), peak, nc,
                  np.array(m), np.array(d), before, (x, v, w))


def collide(dim: int, kind: Kind, params: ContactParameters, speed: float, angle: float,
            dt: float, d: float = 1.0, m: float = 1.0,
            phase: float = 0.5) -> tuple[float, float, float, float]:
    """(e, beta, contact time, max |omega| after) of one collision of equal particles (mass m,
    diameter d) without initial spin; see ``impact`` for everything else."""
    r = impact(dim, kind, params, speed, angle, dt, sizes=(d, d), masses=(m, m), phase=phase)
    return r.e, r.beta, r.contact_time, r.spin_after


def _normal_targets(params: ContactParameters, r_eff: float, vn: float) -> tuple[float, float]:
    """Contact time and peak normal force of the damped Hooke oscillator or Hertz ODE."""
    if params.model == "hooke":
        tc = hooke_contact(params.kn, params.restitution, params.m_eff).contact_time
        return tc, hooke_peak_force(params.kn, params.restitution, params.m_eff, vn)
    h = hertz_contact(params.kn, params.restitution, params.m_eff, r_eff, vn)
    return h.contact_time, h.peak_force


def _beta_target(params: ContactParameters, K: float, tc: float, ratio: float,
                 speed: float, wall: bool, r_eff: float) -> float:
    """The hard rule the contact stands for, at |g_t|/|g_n| = ratio (NaN head-on): a spring
    compensated for its steps per contact restitutes, averaged over impact phases, what the
    discrete model says (the requested beta at the matched speed)."""
    if ratio == 0.0:
        return math.nan
    if params.tangential == "none":
        return -1.0
    if params.tangential == "spring" and params.steps_per_contact is not None:
        c = DiscreteContact.of(params, K, wall, r_eff if wall else 2.0 * r_eff)
        return mean_restitution(c, params.contact_time, params.steps_per_contact, speed)[1]
    b0 = spring_beta(params.kt, K, params.m_eff, tc)
    if params.tangential == "spring":
        return b0
    if params.xt > 0.0:  # the damped copy (beta0 = e): sticks with the normal restitution
        b0 = params.restitution
    return walton_beta(params.mu or 0.0, b0, params.restitution, K, ratio)


def calibrate(dim: int, kind: Kind = "pair", e: float = 0.9, beta: float | None = None,
              mu: float | None = None, beta0: float | None = None, K: float | None = None,
              kn: float = 1e5, steps_per_contact: float = 200,
              speeds: Sequence[float] = (1.0,), angles: Sequence[float] = (0.0, 30.0, 60.0),
              model: Model = "hooke", sizes: Sequence[float] = (1.0, 1.0),
              spin: float = 0.0, phases: int = 1, engine: str = "lammps",
              bodies: tuple = (open_bodies, read_state)) -> list[CollisionRow]:
    """Map (e, beta | mu, beta0) to LAMMPS parameters, then measure them in binary collisions.

    ``K`` defaults to the LAMMPS body (disc 1/2 in 2D, sphere 2/5 in 3D); another value is
    refused since LAMMPS fixes the moment of inertia. ``beta0`` unset = e (``default_beta0``,
    as in scenes). Hertz parameters (kt, time step) are matched at the largest speed; its beta
    target at other normal speeds uses that speed's t_c. Coulomb targets use Walton's rule at
    the contact point's |g_t| / |g_n| (spin included). Targets: e the input; t_c and the peak
    normal force of the damped Hooke oscillator / Hertz ODE at the normal speed.
    ``sizes``: the two diameters (a wall collision uses the first); masses ∝ d^dim.
    An uncapped spring's k_t is compensated for ``steps_per_contact`` (LAMMPS's discrete
    update, ``contact.discrete``), as in scenes. ``phases``: 1 measures each collision with
    its first overlap half a step after a step; n > 1 averages e, beta, t_c, spin and peak
    force over n impact phases (bin midpoints), as the collisions of a flow do. ``engine``
    and ``bodies``: the engine measured (its name in refusals, its (open, read) pair).
    """
    k_body = inertia_factor(dim)
    if K is not None and abs(K - k_body) > 1e-12:
        raise UnsupportedByEngine(engine, "K", K, f"{engine}'s "
                                  f"{'discs' if dim == 2 else 'spheres'} have K = {k_body}")
    if kind not in ("pair", "wall"):
        raise UnsupportedByEngine(engine, "kind", kind, "use 'pair' or 'wall'")
    if not (isinstance(phases, int) and 1 <= phases <= 256):
        raise UnsupportedByEngine(engine, "phases", phases, "a whole number from 1 to 256")
    if len(sizes) != 2 or min(sizes) <= 0.0:
        raise UnsupportedByEngine(engine, "sizes", tuple(sizes), "two positive diameters")
    r0, r1 = 0.5 * sizes[0], 0.5 * sizes[1]
    m0, m1 = sizes[0] ** dim, sizes[1] ** dim
    m_eff = m0 if kind == "wall" else pair_mass(m0, m1)
    r_eff = r0 if kind == "wall" else pair_radius(r0, r1)
    v_ref = max(speeds)
    params = make_contact(kn=kn, e=e, m_eff=m_eff, K=k_body, beta=beta, mu=mu, beta0=beta0,
                          model=model, r_eff=r_eff, speed=v_ref,
                          steps_per_contact=steps_per_contact, wall=kind == "wall")
    dt = params.timestep(steps_per_contact)
    offsets = [0.5] if phases == 1 else [(i + 0.5) / phases for i in range(phases)]
    rows = []
    for speed in speeds:
        for angle in angles:
            hits = [impact(dim, kind, params, speed, angle, dt, sizes=sizes, spin=spin,
                           phase=ph, bodies=bodies) for ph in offsets]
            e_m, b_m, tc_m, spin_m, peak_m = (float(np.mean([getattr(h, k) for h in hits]))
                                              for k in ("e", "beta", "contact_time",
                                                        "spin_after", "peak_force"))
            th = math.radians(angle)
            vn = speed * math.cos(th)
            tc, f_max = _normal_targets(params, r_eff, vn)
            ratio = abs(speed * math.sin(th) + r0 * spin) / vn  # contact point: g + R W x
            target = _beta_target(params, k_body, tc, ratio, speed, kind == "wall", r_eff)
            rows.append(CollisionRow(dim, kind, model, angle, speed, e_m, b_m, tc_m, e, target,
                                     tc, spin_m, peak_m, f_max, spin))
    return rows


def calibrate_case(case: Case = "impact", **settings) -> list[CollisionRow] | list[MotionRow]:
    """``demstudy calibrate --case``: ``impact`` (``calibrate``), ``rolling`` (the incline,
    ``rolling_acceleration``; settings dim, alpha, e, beta, mu, beta0, kn, steps_per_contact)
    or ``sliding`` (``sliding_to_rolling``; settings dim, v0, mu, e, beta0, kn,
    steps_per_contact). Options a case cannot use are refused (UnsupportedByEngine, exit 2)."""
    if case == "impact":
        settings.pop("alpha", None)
        settings.pop("v0", None)
        settings = {k: v for k, v in settings.items() if v is not None}
        return calibrate(**settings)
    if case not in ("rolling", "sliding"):
        raise UnsupportedByEngine("lammps", "case", case, "use impact, rolling or sliding")
    if settings.get("phases") is not None:
        raise UnsupportedByEngine("lammps", "phases", settings["phases"],
                                  "impact phases are averaged only in --case impact")
    inert = {"kind": "wall", "model": "hooke", "sizes": (1.0, 1.0), "spin": 0.0}
    for key, ok in inert.items():
        if key in settings and settings[key] is not None and _differs(settings[key], ok):
            raise UnsupportedByEngine("lammps", key, settings[key],
                                      f"--case {case} is one unit particle on a Hooke wall "
                                      f"({key} must stay {ok!r})")
    K = settings.get("K")
    dim = settings["dim"]
    if K is not None and abs(K - inertia_factor(dim)) > 1e-12:
        raise UnsupportedByEngine("lammps", "K", K, f"LAMMPS bodies have K = {inertia_factor(dim)}")
    common = {k: settings[k] for k in ("e", "mu", "beta0", "kn", "steps_per_contact")
              if settings.get(k) is not None}
    if case == "rolling":
        res = rolling_acceleration(dim, alpha=settings.get("alpha", 30.0),
                                   beta=settings.get("beta") or 0.9, **common)
        return [MotionRow(dim, "rolling", "acceleration down the incline [g]",
                          res.acceleration, res.target)]
    if settings.get("mu") is None:
        raise UnsupportedByEngine("lammps", "mu", None, "--case sliding needs friction: --mu")
    res2 = sliding_to_rolling(dim, v0=settings.get("v0", 1.0), **common)
    return [MotionRow(dim, "sliding", "final speed [sqrt(g d)]", res2.speed, res2.target),
            MotionRow(dim, "sliding", "time to start rolling [sqrt(d/g)]", res2.roll_time,
                      res2.roll_time_target)]


def _differs(value, allowed) -> bool:
    if isinstance(allowed, tuple):
        return tuple(float(x) for x in value) != allowed
    return value != allowed
