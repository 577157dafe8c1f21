"""LAMMPS collisions against analytic targets (demstudy.contact.calibrate). Units: d = m = g = 1.

Every target is an input of the mapping (e, beta) or an independent formula (damped oscillator
contact time, Walton's sliding rule, g sin(alpha) / (1 + K)), never a LAMMPS output.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from demstudy.contact.calibration import format_table, incline_acceleration
from demstudy.contact.mapping import (
    inertia_factor,
    make_contact,
    spring_beta,
    walton_beta,
)
from demstudy.engines.lammps.calibrate import calibrate, collide, rolling_acceleration
from demstudy.engines.lammps.deck.contact import granular_args
from demstudy.engines.lammps.library import open_lammps

DIMS_KINDS = [(2, "pair"), (2, "wall"), (3, "pair"), (3, "wall")]


@pytest.mark.parametrize(("dim", "kind"), DIMS_KINDS)
def test_hooke_restitution_and_contact_time(dim, kind):
    # 1000 steps per contact: the O(dt) error, which depends on where the contact falls between
    # steps, is then < 7e-4 for e >= 0.3 (it is ~2e-3 at the usual 200 steps, see docs)
    m_eff = 1.0 if kind == "wall" else 0.5
    for e in (0.5, 0.7, 0.9, 0.99):
        rows = calibrate(dim, kind, e=e, beta=0.5, steps_per_contact=1000, angles=(0.0, 30.0))
        zeta = -math.log(e) / math.hypot(math.pi, math.log(e))  # e = exp(-pi zeta/sqrt(1-zeta^2))
        tc = math.pi * math.sqrt(m_eff / 1e5) / math.sqrt(1 - zeta**2)
        for r in rows:
            assert abs(r.e - e) < 1e-3, r
            assert r.contact_time == pytest.approx(tc, rel=0.01), r


@pytest.mark.parametrize(("dim", "kind"), DIMS_KINDS)
def test_contact_time_at_oblique_impacts(dim, kind):
    m_eff = 1.0 if kind == "wall" else 0.5
    zeta = -math.log(0.8) / math.hypot(math.pi, math.log(0.8))
    tc = math.pi * math.sqrt(m_eff / 1e5) / math.sqrt(1 - zeta**2)
    for r in calibrate(dim, kind, e=0.8, beta=0.0, angles=(0.0, 45.0, 60.0)):
        assert r.contact_time == pytest.approx(tc, rel=0.01), r


@pytest.mark.parametrize(("dim", "kind"), DIMS_KINDS)
@pytest.mark.parametrize("beta", [-1.0, 0.0, 0.5, 0.99])
def test_tangential_restitution(dim, kind, beta):
    # 200 steps per contact: first-order error in beta up to ~0.0075 (phase dependent)
    rows = calibrate(dim, kind, e=0.8, beta=beta, angles=(30.0, 60.0), speeds=(0.5, 2.0))
    for r in rows:
        assert abs(r.beta - beta) < 0.01, r
        assert abs(r.e - 0.8) < 3e-3, r
        if beta == -1.0:  # smooth: no torque at all, tangential velocity unchanged
            assert r.spin_after == 0.0
            assert abs(r.beta + 1.0) < 1e-3


def test_wrong_inertia_is_detected():
    """kt made for spheres (K = 2/5) on discs (K = 1/2) misses beta = 0 measurably."""
    p = make_contact(kn=1e5, e=0.9, m_eff=1.0, K=0.4, beta=0.0)
    beta = collide(2, "wall", p, 1.0, 45.0, p.timestep(200))[1]
    expected = spring_beta(p.kt, 0.5, 1.0, p.contact_time)
    assert abs(beta) > 0.05 and beta == pytest.approx(expected, abs=0.01)


def test_smooth_deck_holds_no_history():
    p = make_contact(kn=1e5, e=0.9, m_eff=0.5, K=0.5)
    lmp = open_lammps()
    try:
        lmp.commands_string("\n".join([
            "units lj", "dimension 2", "atom_style sphere", "region box block -2 2 -2 2 -1 1",
            "create_box 1 box", "create_atoms 1 single 0 0 0", "comm_modify vel yes",
            "pair_style granular", f"pair_coeff * * {granular_args(p)}",
            "fix 1 all nve/sphere disc", "fix 2 all enforce2d", "run 0"]))
        assert "NEIGH_HISTORY_GRANULAR" not in lmp.available_ids("fix")
    finally:
        lmp.close()


@pytest.mark.parametrize("kind", ["pair", "wall"])
def test_coulomb_sliding_follows_walton(kind):
    rows = calibrate(3, kind, e=0.7, mu=0.1, beta0=0.5, angles=(60.0, 75.0))
    for r in rows:
        target = walton_beta(0.1, 0.5, 0.7, 0.4, math.tan(math.radians(r.angle)))
        assert target < 0.0  # sliding throughout
        assert abs(r.beta - target) < 0.01, r


def _hertz_time(kn: float, e: float, m: float, R: float, v: float) -> float:
    """Independent integration of LAMMPS's damped Hertz contact (coeff_restitution damping)."""
    c = math.sqrt(5) * -math.log(e) / math.hypot(math.pi, math.log(e))

    def rhs(_t, y):
        x = max(y[0], 0.0)
        return [y[1], (-kn * math.sqrt(R) * x**1.5
                       - c * math.sqrt(m * kn * math.sqrt(R * x)) * y[1]) / m]

    def out(_t, y):
        return y[0]

    out.terminal, out.direction = True, -1
    sol = solve_ivp(rhs, (0, 1.0), [0.0, v], events=out, rtol=1e-10, atol=1e-14,
                    max_step=1e-4)
    return float(np.asarray(sol.t_events[0])[0])


@pytest.mark.parametrize("kind", ["pair", "wall"])
def test_hertz(kind):
    rows = calibrate(3, kind, e=0.8, beta=0.5, model="hertz", kn=1e6, speeds=(0.1, 1.0),
                     angles=(0.0, 45.0))
    m_eff, r_eff = (1.0, 0.5) if kind == "wall" else (0.5, 0.25)
    for r in rows:
        vn = r.speed * math.cos(math.radians(r.angle))
        tc = _hertz_time(1e6, 0.8, m_eff, r_eff, vn)
        assert r.contact_time == pytest.approx(tc, rel=0.01), r
        assert abs(r.e - 0.8) < 2e-3, r
        if r.angle:
            assert abs(r.beta - r.beta_target) < 0.01, r
    assert "hertz" in format_table(rows)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize(("mu", "beta"), [(None, 0.9), (1.0, 0.5), (0.1, 0.5)])
def test_incline(dim, mu, beta):
    K = inertia_factor(dim)
    res = rolling_acceleration(dim, 30.0, beta=beta, mu=mu)
    if mu == 0.1:  # sliding: g (sin a - mu cos a)
        expected = 0.5 - 0.1 * math.cos(math.radians(30.0))
    else:  # rolling without slip
        expected = 0.5 / (1.0 + K)
    assert incline_acceleration(30.0, K, mu) == pytest.approx(expected)
    assert res.acceleration == pytest.approx(expected, rel=0.01)
