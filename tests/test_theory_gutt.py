"""Gutt (1989) continuum theory (demstudy.theory.gutt_spin, gutt_walls) against its analytic
solutions, its boundary conditions and the trends the thesis states (digest
/work/shared/reference/gutt1989.md §1, §2). Ch. 1 in arbitrary units (d = 1), Ch. 2 in particle
units with the wall speed u_w = 1."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import simpson

from demstudy.theory import (
    GuttSpinConstants,
    GuttWallConstants,
    spin_cooling,
    spin_cooling_analytic,
    spin_couette,
    spin_couette_analytic,
    spin_couette_ratio,
    spin_couette_threshold,
    spin_plates,
    spin_plates_analytic,
    wall_couette,
    wall_couette_sweep,
    wall_simple_shear_roughness,
)

C = GuttSpinConstants()


# -- Ch. 1: constants --------------------------------------------------------------------------
def test_defaults_are_the_derived_proportionalities_and_satisfy_the_thesis_constraints():
    derived = GuttSpinConstants.from_restitution(0.6, 0.5)
    for name in C.__dataclass_fields__:
        assert getattr(C, name) == pytest.approx(getattr(derived, name), rel=1e-12), name
    assert C.beta == pytest.approx(0.5)
    assert C.theta == pytest.approx(C.k * C.d**2 / 4)
    # the friction loss per collision n2 (1 - beta)/2 is gamma'_t - gamma'_r at unit rate
    assert C.gamma1_t - C.gamma1_r == pytest.approx(C.n2 * (1 - C.beta) / 2)


@pytest.mark.parametrize("changes, field", [
    ({"gamma1_r": 0.2}, "gamma1_t"),  # gamma'_t > gamma'_r violated
    ({"gamma2_t": 0.12}, "gamma2_r"),  # gamma''_r > gamma''_t violated
    ({"r_t": 0.0}, "r_t"),
    ({"gamma_t": -0.1}, "gamma_t"),
])
def test_constants_violating_the_thesis_constraints_are_refused(changes, field):
    with pytest.raises(ValueError, match=field):
        GuttSpinConstants(**changes)


def test_the_determinant_constraint_follows_from_the_other_two():
    rng = np.random.default_rng(1)
    for _ in range(1000):
        g1t, g2r = rng.uniform(0.01, 1, 2)
        g1r, g2t = g1t * rng.uniform(0, 1), g2r * rng.uniform(0, 1)
        assert g1t * g2r - g2t * g1r > 0


def test_perfectly_rough_spheres_are_refused_by_the_derived_constructor():
    with pytest.raises(ValueError, match="beta"):
        GuttSpinConstants.from_restitution(0.9, 1.0)


# -- S1: homogeneous cooling -------------------------------------------------------------------
def test_cooling_started_on_the_ratio_follows_the_special_solution_1_25():
    t = np.linspace(0, 50, 26)
    exact = spin_cooling_analytic(C, 2.0, t)
    numeric = spin_cooling(C, 2.0, exact.W[0], t)
    np.testing.assert_allclose(numeric.v, exact.v, rtol=1e-7)
    np.testing.assert_allclose(numeric.W, exact.W, rtol=1e-7)
    assert exact.v[-1] < 0.02 * exact.v[0]  # the test covers real decay


def test_cooling_ratio_is_the_slow_eigenvector_of_the_energy_equations():
    """In the time tau = int v dt/s the S1 equations for (v^2, d^2W^2/4) are linear; (1.25)'s
    a^2 must be the ratio of the slower eigenvector and -2 b s its eigenvalue."""
    spin = C.d**2 / (4 * C.theta)
    matrix = 2 * np.array([[-C.loss, C.gamma2_t], [spin * C.gamma1_r, -spin * C.gamma2_r]])
    values, vectors = np.linalg.eig(matrix)
    slow = np.argmax(values)
    sol = spin_cooling_analytic(C, 1.0, np.zeros(1))
    assert vectors[1, slow] / vectors[0, slow] == pytest.approx(sol.a**2, rel=1e-12)
    assert values[slow] == pytest.approx(-2 * sol.b * C.s, rel=1e-12)


@pytest.mark.parametrize("v0, W0", [(1.0, 0.0), (1e-3, 3.0)], ids=["b: W(0)=0", "c: small v(0)"])
def test_cooling_ratio_relaxes_to_a(v0, W0):
    t = np.geomspace(1e-3, 1e4, 60)
    sol = spin_cooling(C, v0, W0, np.concatenate([[0.0], t]))
    assert abs(sol.ratio[0] - sol.a) > 0.5 * sol.a
    assert sol.ratio[-1] == pytest.approx(sol.a, rel=1e-6)
    # late times: Haff-like v -> 1/(b t)
    assert sol.v[-1] * sol.b * sol.t[-1] == pytest.approx(1.0, rel=0.02)


def test_cooling_without_translation_does_nothing():
    sol = spin_cooling(C, 0.0, 2.0, np.linspace(0, 10, 5))
    np.testing.assert_array_equal(sol.W, 2.0)
    np.testing.assert_array_equal(sol.v, 0.0)
    start = spin_cooling(C, 1.0, 0.5, np.zeros(1))  # only the initial state asked for
    assert start.v.tolist() == [1.0] and start.W.tolist() == [0.5]


# -- S2: vibrating plates ----------------------------------------------------------------------
def _lambda() -> float:
    return 1 / math.sqrt(-spin_plates_analytic(C, 1.0, 1.0).curvature)


def test_plates_bvp_reproduces_the_cosh_solution_1_26():
    h = 3 * _lambda()
    exact = spin_plates_analytic(C, h, 1.0)
    numeric = spin_plates(C, h, 1.0, exact.W[-1])
    np.testing.assert_allclose(numeric.v, exact.v, rtol=1e-6)
    np.testing.assert_allclose(numeric.W, exact.W, rtol=1e-6)
    # the cosh solution really solves L373-L375: residuals by finite differences
    y = np.linspace(-h / 2, h / 2, 4001)
    v = 1.0 * np.cosh(y / _lambda()) / np.cosh(h / 2 / _lambda())
    z = exact.a * v
    d2v = np.gradient(np.gradient(v, y), y)
    flux = z * np.gradient(z, y) / v
    res_t = C.r_t * d2v - C.loss * v + C.gamma2_t * z**2 / v
    res_r = C.r_r * C.n2 * np.gradient(flux, y) + C.gamma1_r * v - C.gamma2_r * z**2 / v
    assert np.max(np.abs(res_t[5:-5])) < 1e-5 and np.max(np.abs(res_r[5:-5])) < 1e-5


@pytest.mark.parametrize("case", ["b", "c"])
def test_plates_low_mode_rises_off_the_wall_and_the_ratio_tends_to_a(case):
    h = 8 * _lambda()
    w_a = spin_plates_analytic(C, h, 1.0).W[-1]
    v_wall, w_wall = (1.0, 0.0) if case == "b" else (0.01, w_a)
    sol = spin_plates(C, h, v_wall, w_wall)
    low = sol.W if case == "b" else sol.v
    peak = np.argmax(low[: len(low) // 2])
    assert 0 < peak < len(low) // 2 - 1  # an interior maximum between wall and centre
    assert sol.ratio[len(sol.y) // 2] == pytest.approx(sol.a, rel=0.1)
    assert abs(sol.ratio[5] - sol.a) > 0.5 * sol.a


# -- S3: Couette with spin ---------------------------------------------------------------------
def test_couette_threshold_gives_a_uniform_v_with_the_ratio_1_32():
    thr = spin_couette_threshold(C)
    a, k = spin_couette_ratio(C, thr)
    assert a**2 == pytest.approx(C.gamma1_r / C.gamma2_r, rel=1e-12) and k == pytest.approx(0.0)
    sol = spin_couette(C, thr, 5.0, 1.0, 2 * a / C.d)
    np.testing.assert_allclose(sol.v, 1.0, rtol=1e-8)
    np.testing.assert_allclose(sol.ratio, a, rtol=1e-8)


def test_couette_constant_ratio_solution_matches_the_analytic_s4_formulas():
    """Above the threshold with the wall ratio of (1.32) the BVP gives v = v_c cos(y/lambda),
    lambda = k^(-1/2); S4's (1.33) and (1.34) (with +r_t d^2/lambda^2) at that lambda must
    return the same ratio and the given sigma0/p0, and L469 the same wall speed."""
    ratio = 1.4 * spin_couette_threshold(C)
    a, k = spin_couette_ratio(C, ratio)
    lam = 1 / math.sqrt(k)
    h = 2.2 * lam
    sol = spin_couette(C, ratio, h, 0.5, 2 * a * 0.5 / C.d)
    v_c = 0.5 / math.cos(h / (2 * lam))
    np.testing.assert_allclose(sol.v, v_c * np.cos(sol.y / lam), rtol=1e-6)
    s4 = spin_couette_analytic(C, lam, h, v_c, delta_h=1.0)
    assert s4.a2 == pytest.approx(a**2, rel=1e-10)
    assert s4.sigma_ratio_spin == pytest.approx(ratio, rel=1e-10)
    assert sol.u_wall == pytest.approx(s4.u_wall_spin, rel=1e-6)
    # mean spin (1.27): omega_z = -du/dy/2, and |omega_z| = (t/2q_t) sigma0 v/(p0 d)
    np.testing.assert_allclose(sol.omega_z, -0.5 * np.gradient(sol.u, sol.y), rtol=2e-3)


@pytest.mark.parametrize("case", [1, 2])
def test_couette_profiles_solve_the_energy_equations_1_30_1_31(case):
    ratio = 1.5 * spin_couette_threshold(C)
    a, k = spin_couette_ratio(C, ratio)
    h = 2.0 / math.sqrt(k)
    v_wall, w_wall = (0.5, 0.0) if case == 1 else (0.005, 2 * a * 0.5)
    sol = spin_couette(C, ratio, h, v_wall, w_wall, n=4001)
    y, v, z = sol.y, sol.v, C.d * sol.W / 2
    heat = C.t**2 * ratio**2 / C.q_t
    res_t = (np.gradient(np.gradient(v, y), y)
             + (-C.loss + C.gamma2_t * z**2 / v**2 + heat) * v / (C.r_t * C.d**2))
    # Z Z'/v as (Z^2)'/(2v): Z = d W/2 has a square-root corner where W_wall = 0
    res_r = (np.gradient(np.gradient(z**2, y) / (2 * v), y)
             + (C.gamma1_r - C.gamma2_r * z**2 / v**2) * v / (C.r_r * C.d**2 * C.n2))
    inner = slice(50, -50)  # the sin mesh is coarse mid-channel, fine at the walls
    assert np.max(np.abs(res_t[inner])) < 2e-3 * np.max(v) and np.max(np.abs(res_r[inner])) < 2e-3
    assert sol.v[0] == pytest.approx(v_wall) and sol.W[-1] == pytest.approx(w_wall, abs=1e-9)
    assert np.argmax(sol.v) == len(y) // 2  # generation beats dissipation: v peaks mid-channel
    if case == 2:  # W dips away from the wall (energy to translation) before rising again
        assert np.min(sol.W) < 0.9 * w_wall and np.argmin(sol.W) != 0


# -- S4 -----------------------------------------------------------------------------------------
@pytest.mark.parametrize("lam_over_h", [0.4, 1.0, 5.0])
def test_spin_raises_the_stress_ratio_and_the_wall_speed(lam_over_h):
    h = 4.0
    lam = lam_over_h * h
    s4 = spin_couette_analytic(C, lam, h, 1.0, delta_h=1.3)
    assert C.determinant > 0 and s4.sigma_ratio_spin > s4.sigma_ratio_no_spin
    extra = (C.gamma1_t * C.r_r * C.n2 / lam**2 + C.determinant) / (
        C.gamma2_r + C.r_r * C.n2 / lam**2)
    assert (s4.sigma_ratio_spin**2 - s4.sigma_ratio_no_spin**2) * C.t**2 / C.q_t == (
        pytest.approx(extra, rel=1e-12))
    assert s4.u_wall_spin / s4.u_wall_no_spin == pytest.approx(
        s4.sigma_ratio_spin / s4.sigma_ratio_no_spin, rel=1e-12)
    # p0 (L453) reproduces the inventory Delta h = (3/d) int t d rho v^2/p0 dy
    y = np.linspace(-h / 2, h / 2, 2001)
    spacing = C.t * C.d * C.rho * np.cos(y / lam) ** 2 / s4.p0
    assert 3 / C.d * simpson(spacing, x=y) == pytest.approx(1.3, rel=1e-9)


# -- Ch. 2 ---------------------------------------------------------------------------------------
W = GuttWallConstants()


def _direct_residual(c: GuttWallConstants, ratio: float) -> float:
    """(2.13) written out with tan/tanh (no series), for an independent check."""
    w = c.omega2(ratio)
    if w > 0:
        left = math.sqrt(w) * math.tan(math.sqrt(w) * c.h / 2)
    else:
        left = -math.sqrt(-w) * math.tanh(math.sqrt(-w) * c.h / 2)
    f = c.t_w**2 / (c.q_w**2 * c.k2) * ratio**2
    e = (1 - c.e_w) / (1 + c.e_w)
    return c.d * c.r * c.t_w / (c.r_w * c.t) * left - (e - f / (1 - f)) * math.sqrt(1 - f)


@pytest.mark.parametrize("k2, sign", [(0.0625, -1), (0.25, 1), (0.125, 0)])
def test_root_satisfies_2_13(k2, sign):
    sol = wall_couette(W, k2=k2)
    assert abs(_direct_residual(sol.constants, sol.sigma_ratio)) < 1e-12
    assert np.sign(round(sol.omega2, 12)) == sign
    f = sol.constants.F * sol.sigma_ratio**2
    assert f < 1 and (sol.omega2 <= 0 or math.sqrt(sol.omega2) * W.h / 2 < math.pi / 2)


def test_solution_is_continuous_across_simple_shear():
    star = wall_simple_shear_roughness(W)
    mid = wall_couette(W, k2=star)

    def q(s):
        return np.array([s.sigma_ratio, s.u_s, s.v_wall, s.stress_norm])

    for delta in (1e-6, 1e-9):
        lo, hi = wall_couette(W, k2=star - delta), wall_couette(W, k2=star + delta)
        assert lo.omega2 < 0 < hi.omega2
        np.testing.assert_allclose(q(lo), q(mid), rtol=50 * delta / star)
        np.testing.assert_allclose(q(hi), q(mid), rtol=50 * delta / star)


def test_simple_shear_limit_is_analytic():
    """omega = 0: R = sqrt(q gamma)/t, Q_a/Q_g = 1, uniform v and s = Delta h/(3h) d, linear u
    (docs/theory-gutt.md). Fig 2.10's constants put it at <k_tau^2> = 0.125 (curve 2)."""
    star = wall_simple_shear_roughness(W)
    assert star == pytest.approx(0.125, rel=1e-12)
    sol = wall_couette(W, k2=star)
    ratio = math.sqrt(W.q * W.gamma) / W.t
    assert sol.sigma_ratio == pytest.approx(ratio, rel=1e-12)
    assert sol.flux_ratio == pytest.approx(1.0, rel=1e-10)
    np.testing.assert_allclose(sol.v, sol.v_wall, rtol=1e-12)
    np.testing.assert_allclose(sol.s, W.delta_h / (3 * W.h) * W.d, rtol=1e-12)
    np.testing.assert_allclose(sol.u, sol.u[-1] * sol.y / (W.h / 2), rtol=1e-12, atol=1e-15)
    # u_w = u_s + (t/q) R v h/(2d) with u_s = v R t_w/(q_w k2)/sqrt(1 - F R^2)
    f = W.t_w**2 / (W.q_w**2 * star) * ratio**2
    slip = ratio * W.t_w / (W.q_w * star) / math.sqrt(1 - f)
    assert sol.v_wall / W.u_w == pytest.approx(1 / (slip + W.t / W.q * ratio * W.h / 2), rel=1e-12)


@pytest.mark.parametrize("k2", [0.0625, 0.125, 0.25, 0.02])
def test_profiles_satisfy_the_wall_conditions_and_the_inventory(k2):
    sol = wall_couette(W, n=20001, k2=k2)
    c, y = sol.constants, sol.y
    dy = y[1] - y[0]

    def wall_slope(f):  # second-order one-sided difference at y = +h/2
        return (3 * f[-1] - 4 * f[-2] + f[-3]) / (2 * dy)

    root = math.sqrt(sol.v_wall**2 + sol.u_s**2 * c.k2)
    slip_bc = c.q_w / c.q * c.t / c.t_w * sol.u_s / c.d * c.k2 * sol.v_wall / root  # (2.6)
    heat_bc = (c.r_w / c.r * c.t / c.t_w / c.d
               * (sol.u_s**2 * c.k2 - c.E * sol.v_wall**2) * sol.v_wall / root)  # (2.8)
    assert wall_slope(sol.u) == pytest.approx(slip_bc, rel=1e-6)
    assert wall_slope(0.5 * sol.v**2) == pytest.approx(heat_bc, rel=1e-5, abs=1e-9)
    assert sol.u_s + sol.u[-1] == pytest.approx(c.u_w, rel=1e-12)  # (2.15)
    assert 3 / c.d * simpson(sol.s, x=y) == pytest.approx(c.delta_h, rel=1e-9)  # (2.16)
    # bulk shear stress = wall shear stress (2.5) with the density slip (2.4)
    assert sol.sigma_ratio == pytest.approx(c.q_w / c.t_w * sol.u_s * c.k2 / root, rel=1e-12)


K2 = np.concatenate([np.geomspace(1e-4, 0.05, 12), np.linspace(0.06, 1.0, 25)])


@pytest.mark.parametrize("e_w", [0.96, 0.92, 0.84])
def test_trends_stated_in_the_thesis(e_w):
    sw = wall_couette_sweep(K2, W, e_w=e_w)
    # fig 2.4: ~0 for smooth walls, rising, then saturating
    assert sw.sigma_ratio[0] < 0.06 * sw.sigma_ratio[-1]
    assert np.all(np.diff(sw.sigma_ratio) > 0)
    assert sw.sigma_ratio[-1] - sw.sigma_ratio[K2 >= 0.5][0] < 0.03 * sw.sigma_ratio[-1]
    # fig 2.5: slip falls with roughness; total slip at smooth walls
    assert np.all(np.diff(sw.slip_ratio) < 0) and sw.slip_ratio[0] > 0.99
    # fig 2.7: v(h/2)/u_w zero at smooth walls, a maximum, then a slight fall
    peak = np.argmax(sw.v_wall_ratio)
    assert sw.v_wall_ratio[0] < 0.1 * sw.v_wall_ratio[peak] and 0 < peak < len(K2) - 1
    assert 0.7 * sw.v_wall_ratio[peak] < sw.v_wall_ratio[-1] < sw.v_wall_ratio[peak]
    # figs 2.8-2.9: stress and pressure vanish at smooth walls and grow with roughness
    assert np.all(np.diff(sw.stress_norm) > 0) and np.all(np.diff(sw.pressure_norm) > 0)
    assert sw.stress_norm[0] < 1e-3 * sw.stress_norm[-1]


def test_fig_2_10_regimes_and_lossier_walls():
    curves = [wall_couette(W, k2=k) for k in (0.0625, 0.125, 0.25)]
    one, two, three = curves
    assert one.omega2 < 0 and one.flux_ratio < 1 and one.v[0] > one.v[len(one.v) // 2]
    assert one.s[len(one.s) // 2] < one.s[0]  # densest mid-channel
    assert abs(two.omega2) < 1e-12 and two.flux_ratio == pytest.approx(1.0)
    assert three.omega2 > 0 and three.flux_ratio > 1 and three.v[0] < three.v[len(three.v) // 2]
    assert three.s[len(three.s) // 2] > three.s[0]  # least dense mid-channel
    # L785: v_wall a fraction of u_w that falls with wall lossiness; slip insensitive to e_w
    lossy = [wall_couette(W, k2=0.25, e_w=e) for e in (0.96, 0.92, 0.84)]
    assert lossy[0].v_wall > lossy[1].v_wall > lossy[2].v_wall
    sweeps = [wall_couette_sweep(K2, W, e_w=e) for e in (0.96, 0.92, 0.84)]
    slips = np.array([sw.slip_ratio for sw in sweeps])
    # u_s/u_w falls from 1 to ~0.02 over the roughness range, but differs by < 0.03 between
    # e_w = 0.96 and 0.84 at any roughness (relatively up to ~20 % at the roughest walls)
    assert np.max(np.ptp(slips, axis=0)) < 0.03


@pytest.mark.parametrize("changes, field", [
    ({"k2": 0.0}, "k2"), ({"e_w": 1.2}, "e_w"), ({"delta_h": 12.0}, "delta_h"),
    ({"q_w": -1.0}, "q_w"),
])
def test_bad_wall_constants_are_refused(changes, field):
    with pytest.raises(ValueError, match=field):
        GuttWallConstants(**changes)


def test_bad_channel_is_refused():
    with pytest.raises(ValueError, match="v_wall"):
        spin_plates(C, 3.0, 0.0, 1.0)
    with pytest.raises(ValueError, match="too wide"):
        spin_couette(C, 2 * spin_couette_threshold(C), 100.0, 1.0, 0.0)


@pytest.mark.parametrize("k2", [0.0625, 0.25])
def test_normalised_stress_is_the_l775_formula_and_independent_of_the_wall_speed(k2):
    sol = wall_couette(W, k2=k2)
    c, ratio = sol.constants, sol.sigma_ratio
    om = math.sqrt(abs(sol.omega2))
    trig = (math.sin, math.cos) if sol.omega2 > 0 else (math.sinh, math.cosh)
    f = c.F * ratio**2
    bracket = (trig[1](om * c.h / 2) * math.sqrt(f / (c.k2 * (1 - f)))
               + c.t / c.q * ratio * trig[0](om * c.h / 2) / (om * c.d))
    printed = (3 / 8 * c.t * ratio * c.h**2 / (c.d * c.delta_h)
               * (trig[0](om * c.h) / (om * c.d) + c.h / c.d) / bracket**2)
    assert sol.stress_norm == pytest.approx(printed, rel=1e-12)
    assert sol.pressure_norm == pytest.approx(printed / ratio, rel=1e-12)
    faster = wall_couette(W, k2=k2, u_w=3.0)
    assert faster.stress_norm == pytest.approx(sol.stress_norm, rel=1e-12)
    np.testing.assert_allclose(faster.v, 3 * sol.v, rtol=1e-12)
    assert faster.sigma0 == pytest.approx(9 * sol.sigma0, rel=1e-12)  # Bagnold scaling
    # rho/rho_p multiplies both (the thesis's printed formula has rho = rho_p)
    half = wall_couette(W, k2=k2, density_ratio=0.5)
    assert half.stress_norm == pytest.approx(0.5 * sol.stress_norm, rel=1e-12)
