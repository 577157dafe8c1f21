"""LAMMPS collisions against analytic targets (demstudy.contact.calibrate). Units: d = m = g = 1
(masses ∝ d^dim for other sizes).

Every target is an input of the mapping (e, beta) or an independent formula (damped oscillator
contact time, Walton's sliding rule, g sin(alpha) / (1 + K)), never a LAMMPS output.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from demstudy.cli import main
from demstudy.contact.calibration import format_table, incline_acceleration, rolling_speed
from demstudy.contact.mapping import (
    default_beta0,
    inertia_factor,
    make_contact,
    pair_mass,
    spring_beta,
    walton_beta,
)
from demstudy.contact.stiffness import contact_setup
from demstudy.engines.lammps.calibrate import (
    calibrate,
    collide,
    impact,
    rolling_acceleration,
    sliding_to_rolling,
)
from demstudy.engines.lammps.deck.contact import granular_args
from demstudy.engines.lammps.library import open_lammps
from demstudy.errors import UnsupportedByEngine
from demstudy.scene import validate_scene

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


# ---------------------------------------------------------------- issue 12, item 5
def test_restitution_within_001_for_hooke_and_hertz():
    for dim in (2, 3):
        for model, kn in (("hooke", 1e5), ("hertz", 1e6)):
            for r in calibrate(dim, "pair", e=0.7, beta=0.5, model=model, kn=kn,
                               angles=(0.0, 45.0), speeds=(1.0,)):
                assert abs(r.e - 0.7) < 0.01, r


@pytest.mark.parametrize("kind", ["pair", "wall"])
def test_peak_force_and_contact_time_match_elastic_theory(kind):
    """e = 1: Hertz delta_max = (5 m v^2 / (4 kn sqrt R))^(2/5), F_max = kn sqrt(R)
    delta_max^1.5, t_c = 2.9432 delta_max / v; Hooke F_max = v sqrt(kn m), t_c = pi sqrt(m/kn)."""
    m, R = (1.0, 0.5) if kind == "wall" else (0.5, 0.25)
    v = 1.0
    (hz,) = calibrate(3, kind, e=1.0, beta=0.5, model="hertz", kn=1e6, angles=(0.0,),
                      speeds=(v,))
    dmax = (5 * m * v**2 / (4 * 1e6 * math.sqrt(R))) ** 0.4
    assert hz.peak_force == pytest.approx(1e6 * math.sqrt(R) * dmax**1.5, rel=0.02)
    assert hz.contact_time == pytest.approx(2.9432 * dmax / v, rel=0.02)
    assert hz.peak_force_target == pytest.approx(1e6 * math.sqrt(R) * dmax**1.5, rel=1e-3)
    (hk,) = calibrate(3, kind, e=1.0, beta=0.5, kn=1e5, angles=(0.0,), speeds=(v,))
    assert hk.peak_force == pytest.approx(v * math.sqrt(1e5 * m), rel=0.02)
    assert hk.contact_time == pytest.approx(math.pi * math.sqrt(m / 1e5), rel=0.01)
    assert "F_meas" in format_table([hz, hk])


def _walton_wall(v_t: float, v_n: float, beta: float, K: float, R: float = 0.5):
    """Hard wall impact without spin: tangential velocity and spin after Walton's beta."""
    jt = K / (1 + K) * (1 + beta) * v_t  # |tangential impulse| / m
    return v_t - jt, jt / (K * R)


@pytest.mark.parametrize("dim", [2, 3])
def test_gross_sliding_wall_impact_of_the_issue(dim):
    """40 deg, mu = 0.092, e = 0.98, default beta0 (= e): spin and tangential velocity within
    1 % of Walton's gross-sliding branch (was 12 % / 3.4 % off with the old default 0)."""
    K = inertia_factor(dim)
    p = make_contact(kn=1e5, e=0.98, m_eff=1.0, K=K, mu=0.092)
    hit = impact(dim, "wall", p, 1.0, 40.0, p.timestep(200))
    th = math.radians(40.0)
    beta = walton_beta(0.092, 0.98, 0.98, K, math.tan(th))
    assert beta < 0.98 - 0.5  # deep in the sliding branch
    vt, spin = _walton_wall(math.sin(th), math.cos(th), beta, K)
    x, v, w = hit.after
    assert v[0, 0] == pytest.approx(vt, rel=0.01)
    assert abs(w[0, 2]) == pytest.approx(spin, rel=0.01)
    # an explicit beta0 = 0 is still mapped (as a spring) and misses: why scenes refuse it
    p0 = make_contact(kn=1e5, e=0.98, m_eff=1.0, K=K, mu=0.092, beta0=0.0)
    miss = impact(dim, "wall", p0, 1.0, 40.0, p0.timestep(200))
    assert abs(miss.after[2][0, 2]) < 0.95 * spin


@pytest.mark.parametrize(("dim", "kind"), DIMS_KINDS)
def test_oblique_impacts_follow_walton_sticking_and_sliding(dim, kind):
    """Default beta0 = e: sticking (beta = e) below tan(angle) = mu (1 + K) / K, sliding above."""
    K = inertia_factor(dim)
    crossover = math.degrees(math.atan(0.3 * (1 + K) / K))
    rows = calibrate(dim, kind, e=0.9, mu=0.3, angles=(10.0, 30.0, 50.0, 70.0), speeds=(1.0,))
    regimes = set()
    for r in rows:
        target = walton_beta(0.3, 0.9, 0.9, K, math.tan(math.radians(r.angle)))
        regimes.add(r.angle > crossover)
        assert r.beta_target == pytest.approx(target)
        assert abs(r.beta - target) < 0.015, r
    assert regimes == {True, False}


@pytest.mark.parametrize("kind", ["pair", "wall"])
def test_hertz_coulomb_mindlin_copy_follows_walton(kind):
    """Hertz: the Mindlin spring k_t a with the same damping ratio keeps F_t/F_n constant."""
    K = 0.4
    rows = calibrate(3, kind, e=0.95, mu=0.3, model="hertz", kn=1e6, speeds=(1.0,),
                     angles=(10.0, 30.0, 50.0, 70.0))
    for r in rows:
        target = walton_beta(0.3, 0.95, 0.95, K, math.tan(math.radians(r.angle)))
        assert r.beta_target == pytest.approx(target)
        assert abs(r.beta - target) < 0.02, r


@pytest.mark.parametrize("dim", [2, 3])
def test_spinning_head_on_wall_impact(dim):
    """Head-on, the contact point moves by R W: Walton's rule at |g_t|/|g_n| = R W / v."""
    K = inertia_factor(dim)
    for spin in (0.5, 4.0):  # ratio 0.25 (sticks, beta = e) and 2 (slides)
        (r,) = calibrate(dim, "wall", e=0.9, mu=0.3, angles=(0.0,), speeds=(1.0,), spin=spin)
        target = walton_beta(0.3, 0.9, 0.9, K, 0.5 * spin)
        assert r.beta_target == pytest.approx(target) and r.spin_before == spin
        assert abs(r.beta - target) < 0.015, r


@pytest.mark.parametrize("dim", [2, 3])
def test_unequal_sizes_conserve_momentum_and_angular_momentum(dim):
    K = inertia_factor(dim)
    d = (1.0, 2.0)
    m_eff = pair_mass(1.0, 2.0**dim)
    p = make_contact(kn=1e5, e=0.8, m_eff=m_eff, K=K, mu=0.3)
    hit = impact(dim, "pair", p, 1.0, 40.0, p.timestep(200), sizes=d, spin=3.0)
    m, r = hit.masses, 0.5 * hit.diameters
    assert list(m) == [1.0, 2.0**dim]
    x0, v0, w0 = hit.before
    contact = x0[0] - r[0] * np.array([0.0, 1.0, 0.0])  # touch point, particle 1 on top

    def momenta(x, v, w):
        lin = (m[:, None] * v).sum(axis=0)
        orbital = (m[:, None] * np.cross(x - contact, v)).sum(axis=0)
        return lin, orbital + ((K * m * r**2)[:, None] * w).sum(axis=0)

    (p0, l0), (p1, l1) = momenta(*hit.before), momenta(*hit.after)
    np.testing.assert_allclose(p1, p0, atol=1e-10)
    np.testing.assert_allclose(l1, l0, atol=1e-9)
    assert abs(hit.e - 0.8) < 0.01
    assert abs(l0[2]) > 0.1  # the test is not trivially zero


@pytest.mark.parametrize("dim", [2, 3])
def test_sliding_ends_rolling_at_v0_over_1_plus_K(dim):
    res = sliding_to_rolling(dim, v0=1.0, mu=0.3)
    expected = 2 / 3 if dim == 2 else 5 / 7
    assert rolling_speed(1.0, inertia_factor(dim)) == pytest.approx(expected)
    assert res.speed == pytest.approx(expected, rel=0.01)
    assert res.roll_time == pytest.approx(res.roll_time_target, rel=0.03)


def test_beta0_default_is_the_same_everywhere(capsys):
    """CLI, make_contact, calibrate and a scene all take beta0 = e when it is unset."""
    e, K = 0.9, 0.4
    explicit = make_contact(kn=1e5, e=e, m_eff=0.5, K=K, mu=0.3, beta0=e)
    assert make_contact(kn=1e5, e=e, m_eff=0.5, K=K, mu=0.3) == explicit
    assert default_beta0(e) == e
    (row,) = calibrate(3, "pair", e=e, mu=0.3, angles=(10.0,), speeds=(1.0,))
    assert row.beta_target == pytest.approx(e)  # sticking: beta = beta0
    scene = validate_scene({
        "dimension": 3, "box": {"size": [10.0] * 3}, "particles": {"count": 12},
        "contact": {"restitution": e, "tangential": {"model": "coulomb", "mu": 0.3}},
        "run": {"equilibration": 1.0, "production": 2.0, "sample_interval": 0.5}})
    assert scene.contact.tangential.beta0 is None
    pair = contact_setup(scene).pair
    assert (pair.kt / pair.kn, pair.xt) == pytest.approx((explicit.kt / explicit.kn, explicit.xt))
    assert main(["calibrate", "--dim", "3", "--e", "0.9", "--mu", "0.3", "--angles", "10",
                 "--speeds", "1"]) == 0
    line = capsys.readouterr().out.splitlines()[3].split()
    assert float(line[8]) == pytest.approx(e, abs=1e-3)  # b_tgt column


def test_scene_refuses_a_coulomb_rule_the_soft_spring_cannot_follow():
    base = {"dimension": 2, "box": {"size": [10.0] * 2}, "particles": {"count": 12},
            "run": {"equilibration": 1.0, "production": 2.0, "sample_interval": 0.5}}
    bad = validate_scene({**base, "contact": {"restitution": 0.98, "tangential": {
        "model": "coulomb", "mu": 0.092, "beta0": 0.0}}})
    with pytest.raises(UnsupportedByEngine, match=r"contact\.tangential\.beta0 = 0\.0"):
        contact_setup(bad, "lammps")
    ok = validate_scene({**base, "contact": {"restitution": 0.98, "tangential": {
        "model": "coulomb", "mu": 0.092, "beta0": 1.0}}})
    assert contact_setup(ok).pair.xt == 0.0  # beta0 = 1, nearly elastic: the undamped spring


@pytest.mark.parametrize(("argv", "code", "option"), [
    (["--case", "sliding"], 2, "--mu"),
    (["--case", "rolling", "--spin", "2"], 2, "--spin"),
    (["--case", "rolling", "--model", "hertz"], 2, "--model"),
    (["--K", "0.3"], 2, "--K"),
    (["--beta0", "0.3"], 2, "--beta0"),
    (["--mu", "0.3", "--beta", "0.5"], 2, "--beta"),
    (["--kind", "wall", "--sizes", "1", "2"], 2, "--sizes"),
    (["--sizes", "1", "-2"], 2, "--sizes"),
    (["--sizes", "1", "1", "1"], 2, "--sizes"),
    (["--sizes", "1"], 2, "--sizes"),  # a pair needs two diameters
    (["--e", "0"], 2, "--e"),
    (["--e", "1.2"], 2, "--e"),
    (["--mu", "-0.1"], 2, "--mu"),
    (["--steps", "0.5"], 2, "--steps"),
    (["--speeds", "1", "0"], 2, "--speeds"),
    (["--speeds", "-1"], 2, "--speeds"),
    (["--kn", "0"], 2, "--kn"),
    (["--kn=-1e5"], 2, "--kn"),
    (["--case", "rolling", "--alpha", "0"], 2, "--alpha"),
    (["--case", "rolling", "--alpha", "90"], 2, "--alpha"),
])
def test_cli_refusals_name_the_option(capsys, argv, code, option):
    assert main(["calibrate", *argv]) == code
    assert option in capsys.readouterr().err


def test_cli_cases_run(capsys):
    assert main(["calibrate", "--case", "sliding", "--dim", "2", "--mu", "0.3",
                 "--speeds", "1"]) == 0
    out = capsys.readouterr().out
    assert "final speed" in out and "0.666667" in out
    assert main(["calibrate", "--model", "hertz", "--kn", "1e6", "--sizes", "1", "1.5",
                 "--spin", "1", "--speeds", "1", "--angles", "30"]) == 0
    assert "hertz" in capsys.readouterr().out
