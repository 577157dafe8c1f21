"""Analytic checks of demstudy.contact.mapping (no LAMMPS). Units: d = 1, m = 1."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from demstudy.contact import mapping as cm
from demstudy.engines.lammps.deck.contact import granular_args


def _oscillator(kn: float, gamma: float, m: float, v: float) -> tuple[float, float, float]:
    """Independent integration of m x'' = -kn x - gamma x': (e, contact time, max overlap)."""

    def rhs(_t, y):
        return [y[1], (-kn * y[0] - gamma * y[1]) / m]

    def out(_t, y):
        return y[0]

    out.terminal, out.direction = True, -1
    sol = solve_ivp(rhs, (0, 10 * math.pi * math.sqrt(m / kn)), [0.0, v], events=out,
                    rtol=1e-11, atol=1e-14, dense_output=True)
    tc = sol.t_events[0][0]
    xs = sol.sol(np.linspace(0, tc, 20001))[0]
    return -sol.y_events[0][0][1] / v, tc, xs.max()


@pytest.mark.parametrize("e", [0.1, 0.5, 0.9, 0.99, 1.0])
@pytest.mark.parametrize("m_eff", [0.5, 1.0])
def test_hooke_contact_matches_damped_oscillator(e, m_eff):
    c = cm.hooke_contact(1e5, e, m_eff)
    e_num, tc_num, xmax_num = _oscillator(1e5, c.gamma_n, m_eff, 1.0)
    assert e_num == pytest.approx(e, abs=1e-8)
    assert c.contact_time == pytest.approx(tc_num, rel=1e-8)
    assert cm.hooke_max_overlap(1e5, e, m_eff, 1.0) == pytest.approx(xmax_num, rel=1e-6)


def test_hooke_elastic_limits():
    c = cm.hooke_contact(4.0, 1.0, 1.0)
    assert c.gamma_n == 0.0 and c.contact_time == pytest.approx(math.pi / 2.0)
    assert cm.hooke_max_overlap(4.0, 1.0, 1.0, 3.0) == pytest.approx(1.5)
    # LAMMPS's coeff_restitution prefactor for hooke: -2 ln e / sqrt(pi^2 + ln^2 e)
    le = math.log(0.6)
    assert cm.hooke_contact(1e5, 0.6, 0.5).gamma_n == pytest.approx(
        -2 * le / math.sqrt(math.pi**2 + le**2) * math.sqrt(0.5 * 1e5))


@settings(max_examples=40, deadline=None)
@given(e=st.floats(0.05, 1.0), m_eff=st.floats(0.1, 5.0), overlap=st.floats(1e-4, 0.05),
       v=st.floats(0.01, 10.0))
def test_hooke_overlap_round_trip(e, m_eff, overlap, v):
    kn = cm.hooke_kn_for_overlap(overlap, v, m_eff, e)
    assert cm.hooke_max_overlap(kn, e, m_eff, v) == pytest.approx(overlap, rel=1e-10)


def test_hertz_undamped_matches_hertz_theory():
    m, R, v, k = 0.5, 0.25, 0.7, 3e6
    h = cm.hertz_contact(k, 1.0, m, R, v)
    dmax = (5 * m * v**2 / (4 * k * math.sqrt(R))) ** 0.4
    assert h.max_overlap == pytest.approx(dmax, rel=1e-6)
    assert h.contact_time == pytest.approx(2.94327 * dmax / v, rel=1e-5)
    # t_c ~ v^(-1/5)
    assert cm.hertz_contact(k, 1.0, m, R, 32 * v).contact_time == pytest.approx(
        h.contact_time / 2.0, rel=1e-6)


@pytest.mark.parametrize("e", [0.3, 0.6, 0.9])
def test_hertz_coeff_restitution_is_exact_and_speed_independent(e):
    for v in (0.01, 1.0, 30.0):
        assert cm.hertz_contact(1e6, e, 0.5, 0.25, v).e == pytest.approx(e, abs=1e-7)


def test_hertz_overlap_round_trip():
    kn = cm.hertz_kn_for_overlap(0.01, 2.0, 1.0, 0.5, 0.8)
    assert cm.hertz_contact(kn, 0.8, 1.0, 0.5, 2.0).max_overlap == pytest.approx(0.01, rel=1e-6)


@pytest.mark.parametrize(("beta", "phase"), [(-1.0, 0.0), (0.0, 0.5), (1.0, 1.0)])
def test_tangential_stiffness_special_values(beta, phase):
    K, m, tc = 0.5, 0.5, 0.01
    kt = cm.tangential_stiffness_for_beta(beta, K, m, tc)
    assert math.sqrt(kt * (1 + K) / (K * m)) * tc == pytest.approx(phase * math.pi)


@settings(max_examples=40, deadline=None)
@given(beta=st.floats(-1.0, 1.0), K=st.sampled_from([0.4, 0.5]), m=st.floats(0.1, 3.0),
       tc=st.floats(1e-4, 1.0))
def test_beta_round_trip(beta, K, m, tc):
    kt = cm.tangential_stiffness_for_beta(beta, K, m, tc)
    assert cm.spring_beta(kt, K, m, tc) == pytest.approx(beta, abs=1e-9)


def test_hooke_kt_over_kn_is_the_same_for_pairs_and_walls():
    ratios = []
    for m_eff in (0.5, 1.0):
        c = cm.make_contact(kn=1e5, e=0.7, m_eff=m_eff, K=0.5, beta=0.3)
        ratios.append(c.kt / c.kn)
    assert ratios[0] == pytest.approx(ratios[1], rel=1e-12)


def test_walton_rule():
    K, e, mu = 0.4, 0.8, 0.2
    assert cm.walton_beta(mu, 0.5, e, K, 0.1) == 0.5  # sticking
    slide = cm.walton_beta(mu, 0.5, e, K, 10.0)
    assert slide == pytest.approx(-1 + mu * 1.8 * 3.5 / 10.0)
    # Coulomb impulse check: |dg_t| = mu (1 + e) g_n (1 + 1/K) for a sliding impact
    gn, gt = 1.0, 10.0
    assert gt * (1 + slide) == pytest.approx(mu * (1 + e) * gn * (1 + 1 / K))


def test_granular_args():
    smooth = cm.make_contact(kn=1e5, e=0.9, m_eff=0.5, K=0.5)
    assert smooth.tangential == "none"
    assert granular_args(smooth) == (
        "hooke 100000 0.9 damping coeff_restitution tangential linear_nohistory 0.0 0.0")
    assert "linear_history" not in granular_args(smooth)
    assert cm.make_contact(kn=1e5, e=0.9, m_eff=0.5, K=0.5, beta=-1.0).tangential == "none"
    spring = cm.make_contact(kn=1e5, e=0.6, m_eff=0.5, K=0.5, beta=0.4)
    args = granular_args(spring).split()
    assert args[:7] == ["hooke", "100000", "0.6", "damping", "coeff_restitution",
                        "tangential", "linear_history"]
    assert float(args[7]) == pytest.approx(spring.kt) and args[8:] == ["0.0", "1e+20"]
    coul = cm.make_contact(kn=1e5, e=0.6, m_eff=0.5, K=0.5, mu=0.3, beta0=0.4)
    assert coul.tangential == "coulomb" and coul.kt == pytest.approx(spring.kt)
    assert granular_args(coul).endswith(" 0.0 0.3")
    hz = cm.make_contact(kn=1e6, e=0.6, m_eff=0.5, K=0.4, beta=0.0, model="hertz",
                         r_eff=0.25, speed=1.0)
    assert granular_args(hz).startswith("hertz 1000000 0.6 damping coeff_restitution")


def test_contact_parameter_validation():
    with pytest.raises(ValueError):
        cm.ContactParameters("hooke", 1e5, 0.9, 1.0, None, "none", 0.5, 0.01)
    with pytest.raises(ValueError):
        cm.ContactParameters("hooke", 1e5, 0.9, 1.0, 0.5, "spring", 0.5, 0.01)
    with pytest.raises(ValueError):
        cm.ContactParameters("hooke", 1e5, 0.9, 1.0, None, "coulomb", 0.5, 0.01)
    with pytest.raises(ValueError):
        cm.ContactParameters("dmt", 1e5, 0.9, 0.0, None, "none", 0.5, 0.01)  # type: ignore[arg-type]
    with pytest.raises(ValueError):
        cm.tangential_stiffness_for_beta(1.2, 0.5, 0.5, 0.01)
    with pytest.raises(ValueError):
        cm.damping_ratio(0.0)
    with pytest.raises(ValueError):
        cm.make_contact(kn=1e5, e=0.9, m_eff=0.5, K=0.5, mu=0.3, beta0=-1.0)
    with pytest.raises(ValueError):
        cm.make_contact(kn=1e5, e=0.9, m_eff=0.5, K=0.5, model="hertz")


def test_scales_and_helpers():
    assert cm.pair_mass(1.0, 1.0) == 0.5 and cm.pair_mass(1.0, 3.0) == 0.75
    assert cm.pair_radius(0.5, 0.5) == 0.25
    assert cm.inertia_factor(2) == 0.5 and cm.inertia_factor(3) == 0.4
    # rho d^3 for a unit sphere of unit mass: rho = 1 / (pi/6)
    assert cm.mass_scale(1.0, 3) == pytest.approx(6 / math.pi)
    assert cm.mass_scale(1.0, 2) == pytest.approx(4 / math.pi)
    assert cm.kn_from_kstar(1e4, 2.0, 1.0, 3) == pytest.approx(1e4 * 6 / math.pi * 4.0)
    assert cm.kn_from_kappa(1e3, 0.01, 3, d=2.0) == pytest.approx(20.0)
    assert cm.kn_from_kappa(1e3, 0.01, 2) == pytest.approx(10.0)
    assert cm.timestep(0.01, 50) == pytest.approx(2e-4)
    with pytest.raises(ValueError):
        cm.timestep(0.01, 0)


# ---------------------------------------------------------------- Walton in a soft contact
def test_walton_copy_keeps_tangential_and_normal_oscillators_alike():
    """k_t/m_t = k_n/m_eff with m_t = K m_eff/(1+K); the same for the damping (x_gamma_t)."""
    for K in (0.4, 0.5):
        kt, xt = cm.walton_copy(1e5, K)
        m_eff = 0.5
        m_t = K * m_eff / (1 + K)
        assert kt / m_t == pytest.approx(1e5 / m_eff)
        eta_n = cm.hooke_contact(1e5, 0.7, m_eff).gamma_n
        assert xt * eta_n / m_t == pytest.approx(eta_n / m_eff)
        # the default beta0 (= e) picks the copy, an explicit other beta0 an undamped spring
        p = cm.make_contact(kn=1e5, e=0.7, m_eff=m_eff, K=K, mu=0.3)
        assert (p.kt, p.xt) == pytest.approx((kt, xt)) and cm.default_beta0(0.7) == 0.7
        assert cm.make_contact(kn=1e5, e=0.7, m_eff=m_eff, K=K, mu=0.3, beta0=0.5).xt == 0.0
    with pytest.raises(ValueError, match="xt"):
        cm.ContactParameters("hooke", 1e5, 0.9, 1.0, None, "spring", 0.5, 0.01, 0.3)


def test_walton_mismatch_allows_only_rules_the_spring_follows():
    assert cm.walton_mismatch(0.9, None, "hooke") is None
    assert cm.walton_mismatch(0.7, 0.7, "hooke") is None
    assert cm.walton_mismatch(0.98, 1.0, "hooke") is None
    for e, b0 in ((0.98, 0.0), (0.8, 1.0), (0.5, None), (0.9, 0.35)):
        assert "beta0" in cm.walton_mismatch(e, b0, "hooke")
    assert cm.walton_mismatch(0.9, None, "hertz") is None  # the Mindlin copy
    assert "Hertz" in cm.walton_mismatch(0.8, None, "hertz")
    assert "Hertz" in cm.walton_mismatch(0.95, 1.0, "hertz")
    hertz = cm.make_contact(kn=1e6, e=0.9, m_eff=0.5, K=0.4, mu=0.3, model="hertz", r_eff=0.25,
                            speed=1.0)
    assert hertz.mindlin and "tangential mindlin" in granular_args(hertz)
    assert "tangential linear_history" in granular_args(
        cm.make_contact(kn=1e5, e=0.9, m_eff=0.5, K=0.4, mu=0.3))


def test_peak_forces_reduce_to_elastic_formulas():
    assert cm.hooke_peak_force(1e5, 1.0, 0.5, 2.0) == pytest.approx(2.0 * math.sqrt(0.5e5))
    assert cm.hooke_peak_force(1e5, 0.5, 0.5, 2.0) < cm.hooke_peak_force(1e5, 0.99, 0.5, 2.0)
    h = cm.hertz_contact(1e6, 1.0, 0.5, 0.25, 1.0)
    dmax = (5 * 0.5 / (4 * 1e6 * math.sqrt(0.25))) ** 0.4
    assert h.peak_force == pytest.approx(1e6 * math.sqrt(0.25) * dmax**1.5, rel=1e-5)
