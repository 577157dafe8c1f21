"""Measure e, beta and contact time of LAMMPS ``granular`` contacts from isolated collisions.

Units: dimensionless particle units, diameter d = 1, mass m = 1 (g = 1 on the incline).
Each collision is a fresh LAMMPS instance (opened with ``open_lammps``) holding
two equal particles (``kind='pair'``) or one particle above a ``wall/gran granular`` plane
(``kind='wall'``), stepped one step at a time. Contact-point relative velocities
``g = v_i - v_j - (R_i w_i + R_j w_j) x n`` (wall: ``v_i - R w_i x n``) are projected on the
collision normal n, the direction of the total normal impulse sum_k (f_k.n_k) n_k (the line of
centres turns by ~ g_t t_c / d during an oblique pair contact); e = -g'.n / g.n and
beta = -g'_t.t / |g_t|, t the unit pre-collision tangential direction. The contact time is the time
the overlap (hence the force) is positive, from interpolated zero crossings of the overlap.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ...contact.calibration import CollisionRow, incline_acceleration
from ...contact.mapping import (
    ContactParameters,
    Model,
    hertz_contact,
    hooke_contact,
    inertia_factor,
    make_contact,
    pair_mass,
    pair_radius,
    spring_beta,
    walton_beta,
)
from .deck.contact import granular_args
from .library import open_lammps

Kind = Literal["pair", "wall"]


def _f(x: float) -> str:
    return repr(float(x))


def _open(dim: int, wall: bool, params: ContactParameters, dt: float, d: float, m: float,
          atoms: Sequence[Sequence[float]], gravity: tuple[float, float] | None = None):
    """A LAMMPS instance with the given particles (x, y, z, vx, vy, vz) and contact model."""
    lmp = open_lammps()
    half = 5.0 * d
    zlo, zhi = (-0.5 * d, 0.5 * d) if dim == 2 else (-half, half)
    ylo = -d if wall else -half
    cmds = [
        "units lj", f"dimension {dim}", "atom_style sphere",
        f"boundary p {'f' if wall else 'p'} p", "atom_modify map array sort 0 0.0",
        "comm_modify vel yes",
        f"region box block {-half} {half} {ylo} {half} {zlo} {zhi}", "create_box 1 box",
    ]
    cmds += [f"create_atoms 1 single {_f(a[0])} {_f(a[1])} {_f(a[2])}" for a in atoms]
    cmds += [f"set type 1 diameter {_f(d)}", f"set type 1 mass {_f(m)}"]
    cmds += [f"set atom {i + 1} vx {_f(a[3])} vy {_f(a[4])} vz {_f(a[5])} omega 0 0 0"
             for i, a in enumerate(atoms)]
    cmds += ["pair_style granular", f"pair_coeff * * {granular_args(params)}",
             "neighbor 0.2 bin", "neigh_modify every 1 delay 0 check yes",
             f"fix integrate all nve/sphere{' disc' if dim == 2 else ''}"]
    if wall:
        cmds.append(f"fix wall all wall/gran granular {granular_args(params)} yplane 0.0 NULL")
    if gravity is not None:
        cmds.append(f"fix grav all gravity 1.0 vector {_f(gravity[0])} {_f(gravity[1])} 0.0")
    if dim == 2:
        cmds.append("fix planar all enforce2d")
    cmds += [f"timestep {_f(dt)}", "run 0"]
    lmp.commands_string("\n".join(cmds))
    return lmp


def _state(lmp, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    order = np.argsort(lmp.numpy.extract_atom("id")[:n])
    get = lmp.numpy.extract_atom
    return get("x")[:n][order].copy(), get("v")[:n][order].copy(), get("omega")[:n][order].copy()


def _overlap_normal(x: np.ndarray, wall: bool, d: float) -> tuple[float, np.ndarray]:
    if wall:
        return 0.5 * d - x[0, 1], np.array([0.0, 1.0, 0.0])
    r = x[0] - x[1]
    dist = float(np.linalg.norm(r))
    return d - dist, r / dist


def _contact_velocity(v: np.ndarray, w: np.ndarray, n: np.ndarray, wall: bool, d: float):
    if wall:
        return v[0] - 0.5 * d * np.cross(w[0], n)
    return v[0] - v[1] - 0.5 * d * np.cross(w[0] + w[1], n)


def collide(dim: int, kind: Kind, params: ContactParameters, speed: float, angle: float,
            dt: float, d: float = 1.0, m: float = 1.0,
            phase: float = 0.5) -> tuple[float, float, float, float]:
    """One isolated collision; returns (e, beta, contact time, max |omega| after).

    The relative velocity has magnitude ``speed`` at ``angle`` degrees from the inward normal;
    the pair's centre of mass is at rest; spins start at zero; the first overlap arrives
    ``phase`` steps after the start (0 < phase <= 1). beta is NaN for a head-on impact.
    """
    if not (0.0 <= angle < 90.0 and speed > 0.0 and 0.0 < phase <= 1.0):
        raise ValueError("need 0 <= angle < 90 degrees, speed > 0 and 0 < phase <= 1")
    wall = kind == "wall"
    th = math.radians(angle)
    g = np.array([speed * math.sin(th), -speed * math.cos(th), 0.0])  # normal = +y at touch
    t0 = phase * dt
    if wall:
        atoms = [(0.0, 0.5 * d - g[1] * t0, 0.0, *g)]
    else:
        r0 = np.array([0.0, d, 0.0]) - g * t0
        atoms = [(*(0.5 * r0), *(0.5 * g)), (*(-0.5 * r0), *(-0.5 * g))]
    lmp = _open(dim, wall, params, dt, d, m, atoms)
    n_at = 1 if wall else 2
    try:
        order = np.argsort(lmp.numpy.extract_atom("id")[:n_at])
        x, _, _ = _state(lmp, n_at)
        prev, _ = _overlap_normal(x, wall, d)
        t_in = t_out = None
        normals = []
        for step in range(1, 100000):
            lmp.command("run 1 pre no post no")
            x, v, w = _state(lmp, n_at)
            ov, n = _overlap_normal(x, wall, d)
            if t_in is None and ov > 0.0:
                t_in = (step - 1 + -prev / (ov - prev)) * dt
            if ov > 0.0:
                force = lmp.numpy.extract_atom("f")[:n_at][order][0]
                normals.append(float(force @ n) * n)
            elif t_in is not None:
                t_out = (step - 1 + prev / (prev - ov)) * dt
                break
            prev = ov
    finally:
        lmp.close()
    if t_out is None:
        raise RuntimeError("the particles never separated")
    nc = np.sum(normals, axis=0)
    nc /= np.linalg.norm(nc)
    g_after = _contact_velocity(v, w, nc, wall, d)
    gn, gn2 = float(g @ nc), float(g_after @ nc)
    gt = g - gn * nc
    gt_norm = float(np.linalg.norm(gt))
    beta = -float((g_after - gn2 * nc) @ gt) / gt_norm**2 if gt_norm > 1e-12 * speed else math.nan
    return -gn2 / gn, beta, t_out - t_in, float(np.abs(w).max())


def _normal_time(params: ContactParameters, r_eff: float, vn: float) -> float:
    if params.model == "hooke":
        return hooke_contact(params.kn, params.restitution, params.m_eff).contact_time
    return hertz_contact(params.kn, params.restitution, params.m_eff, r_eff, vn).contact_time


def calibrate(dim: int, kind: Kind = "pair", e: float = 0.9, beta: float | None = None,
              mu: float | None = None, beta0: float | None = None, K: float | None = None,
              kn: float = 1e5, steps_per_contact: float = 200,
              speeds: Sequence[float] = (1.0,), angles: Sequence[float] = (0.0, 30.0, 60.0),
              model: Model = "hooke", d: float = 1.0, m: float = 1.0) -> list[CollisionRow]:
    """Map (e, beta | mu, beta0) to LAMMPS parameters, then measure them in binary collisions.

    ``K`` defaults to the LAMMPS body (disc 1/2 in 2D, sphere 2/5 in 3D); another value is
    refused since LAMMPS fixes the moment of inertia. Hertz parameters (kt, time step) are
    matched at the largest speed; its beta target at other normal speeds uses that speed's t_c.
    Coulomb targets use Walton's rule with the impact ratio |g_t| / |g_n| = tan(angle) and, as
    beta0, the spring's own beta. Targets for e are the input e; for t_c the damped formula.
    """
    k_body = inertia_factor(dim)
    if K is not None and abs(K - k_body) > 1e-12:
        raise ValueError(f"LAMMPS {'discs' if dim == 2 else 'spheres'} have K = {k_body}")
    m_eff = m if kind == "wall" else pair_mass(m, m)
    r_eff = 0.5 * d if kind == "wall" else pair_radius(0.5 * d, 0.5 * d)
    v_ref = max(speeds)
    params = make_contact(kn=kn, e=e, m_eff=m_eff, K=k_body, beta=beta, mu=mu, beta0=beta0,
                          model=model, r_eff=r_eff, speed=v_ref)
    dt = params.timestep(steps_per_contact)
    rows = []
    for speed in speeds:
        for angle in angles:
            e_m, b_m, tc_m, spin = collide(dim, kind, params, speed, angle, dt, d, m)
            vn = speed * math.cos(math.radians(angle))
            tc = _normal_time(params, r_eff, vn)
            if angle == 0.0:
                b_t = math.nan
            elif params.tangential == "none":
                b_t = -1.0
            elif params.tangential == "spring":
                b_t = spring_beta(params.kt, k_body, m_eff, tc)
            else:
                b0 = spring_beta(params.kt, k_body, m_eff, tc)
                b_t = walton_beta(params.mu or 0.0, b0, e, k_body,
                                  math.tan(math.radians(angle)))
            rows.append(CollisionRow(dim, kind, model, angle, speed, e_m, b_m, tc_m, e, b_t, tc,
                                     spin))
    return rows


@dataclass(frozen=True)
class RollingResult:
    acceleration: float
    target: float
    contact: ContactParameters


def rolling_acceleration(dim: int, alpha: float = 30.0, e: float = 0.5, beta: float = 0.9,
                         mu: float | None = None, kn: float = 1e5,
                         steps_per_contact: float = 50, duration: float = 2.0,
                         samples: int = 40) -> RollingResult:
    """A disc (2D) or sphere (3D) released at rest on a rough wall, gravity tilted by ``alpha``
    degrees: fit x(t) = x0 + v0 t + a t^2 / 2 and compare with ``incline_acceleration``.

    Tangential: uncapped spring with ``beta`` (``mu`` None) or Coulomb with ``mu`` and
    beta0 = ``beta``. The particle starts at its static overlap g cos(alpha) / kn; the unloaded
    spring then oscillates about the rolling state, which averages out of the fit.
    """
    K = inertia_factor(dim)
    params = make_contact(kn=kn, e=e, m_eff=1.0, K=K, beta=beta, mu=mu, beta0=beta)
    a = math.radians(alpha)
    dt = params.timestep(steps_per_contact)
    y0 = 0.5 - math.cos(a) / kn
    lmp = _open(dim, True, params, dt, 1.0, 1.0, [(-4.0, y0, 0.0, 0.0, 0.0, 0.0)],
                gravity=(math.sin(a), -math.cos(a)))
    chunk = max(1, round(duration / samples / dt))
    ts, xs = [0.0], [-4.0]
    try:
        for i in range(1, samples + 1):
            lmp.command(f"run {chunk} pre no post no")
            ts.append(i * chunk * dt)
            xs.append(float(_state(lmp, 1)[0][0, 0]))
    finally:
        lmp.close()
    coef = np.polyfit(np.array(ts), np.array(xs), 2)
    return RollingResult(2.0 * float(coef[0]), incline_acceleration(alpha, K, mu), params)
