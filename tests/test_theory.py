"""demstudy.theory against exact values and identities (particle units d = 1, m = 1)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

from demstudy import theory as th

SPHERE = {2: 2 * math.pi, 3: 4 * math.pi}  # |S^(D-1)|


def test_contact_values_limits_and_virials():
    assert th.carnahan_starling_g0(0.0) == 1.0
    assert th.henderson_g0(0.0) == 1.0
    h = 1e-6  # slopes at 0: exact third virial 10 (spheres) -> 5/2; Henderson 25/16
    assert (th.carnahan_starling_g0(h) - 1) / h == pytest.approx(2.5, rel=1e-5)
    assert (th.henderson_g0(h) - 1) / h == pytest.approx(25 / 16, rel=1e-5)
    phi = np.linspace(0, 0.6, 13)
    cs = (1 + phi + phi**2 - phi**3) / (1 - phi) ** 3
    np.testing.assert_allclose(th.compressibility(phi, 3), cs, rtol=1e-13)
    np.testing.assert_allclose(
        th.compressibility(phi, 2), (1 + phi**2 / 8) / (1 - phi) ** 2, rtol=1e-13
    )
    # disc virials: Z = 1 + 2 nu + 4 B3/B2^2 nu^2, exact B3/B2^2 = 4/3 - sqrt3/pi (0.1 %)
    b3 = 4 * (4 / 3 - math.sqrt(3) / math.pi)
    z2 = (th.compressibility(1e-3, 2) - 1 - 2e-3) / 1e-6
    assert z2 == pytest.approx(b3, rel=2e-3)
    assert np.all(np.isfinite(th.contact_value(0.9, 2)))
    assert th.contact_value(0.3, 3) == th.carnahan_starling_g0(0.3)
    # inelastic EOS reduces to the elastic one at e = 1, ideal gas at nu -> 0
    assert th.compressibility(0.2, 2, 0.5) < th.compressibility(0.2, 2, 1.0)
    assert th.pressure(1e-9, 2.0, 3) / th.number_density(1e-9, 3) == pytest.approx(2.0)


def _gn_moment(k: int, temperature: float) -> float:
    """E[(g_n^+)^k] for the normal relative velocity (Gaussian, variance 2T/m)."""
    s2 = 2 * temperature

    def pdf(g):
        return math.exp(-g * g / (2 * s2)) / math.sqrt(2 * math.pi * s2)

    return quad(lambda g: g**k * pdf(g), 0, np.inf)[0]


@pytest.mark.parametrize("dim", [2, 3])
def test_collision_frequency_and_free_path(dim):
    nu, temp = 0.25, 1.7
    n, g0 = th.number_density(nu, dim), th.contact_value(nu, dim)
    # omega = n g0 sigma^(D-1) * integral over contact directions of (g.k)^+
    expected = n * g0 * SPHERE[dim] * _gn_moment(1, temp)
    assert th.collision_frequency(nu, temp, dim) == pytest.approx(expected, rel=1e-8)
    speed = th.mean_speed(temp, dim)
    assert th.mean_free_path(nu, dim) == pytest.approx(
        speed / th.collision_frequency(nu, temp, dim), rel=1e-12
    )
    # mean speed of the Maxwellian by quadrature
    sig = math.sqrt(temp)
    if dim == 2:
        m = quad(lambda c: c * c / sig**2 * math.exp(-c * c / (2 * sig**2)), 0, np.inf)[0]
    else:
        m = quad(
            lambda c: math.sqrt(2 / math.pi) * c**3 / sig**3 * math.exp(-c * c / (2 * sig**2)),
            0,
            np.inf,
        )[0]
    assert speed == pytest.approx(m, rel=1e-8)
    # dilute limits: lambda = 1 / (2 sqrt2 n) in 2D, 1 / (sqrt2 pi n) in 3D (sigma = 1)
    n0 = th.number_density(1e-8, dim)
    lam0 = 1 / (2 * math.sqrt(2) * n0) if dim == 2 else 1 / (math.sqrt(2) * math.pi * n0)
    assert th.mean_free_path(1e-8, dim) == pytest.approx(lam0, rel=1e-7)


@pytest.mark.parametrize("dim", [2, 3])
def test_haff_cooling_rate_and_ode(dim):
    nu, t0_, e = 0.1, 2.0, 0.8
    n, g0 = th.number_density(nu, dim), th.contact_value(nu, dim)
    # energy lost per particle per time: (n g0 |S| / 2) (1 - e^2) (m/4) E[(g_n^+)^3]
    loss = n * g0 * SPHERE[dim] / 2 * (1 - e * e) / 4 * _gn_moment(3, t0_)
    zeta = loss / (dim * t0_ / 2)
    assert th.cooling_rate(nu, t0_, dim, e) == pytest.approx(zeta, rel=1e-8)
    t0 = th.haff_t0(nu, t0_, dim, e)

    def rhs(_t, y):
        return [-th.cooling_rate(nu, y[0], dim, e) * y[0]]

    ts = np.linspace(0, 20 * t0, 41)
    sol = solve_ivp(rhs, (0, ts[-1]), [t0_], t_eval=ts, rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(sol.y[0], th.haff_temperature(ts, nu, t0_, dim, e), rtol=1e-7)
    assert th.haff_temperature(t0, nu, t0_, dim, e) == pytest.approx(t0_ / 4)
    with pytest.raises(ValueError):
        th.haff_t0(nu, t0_, dim, 1.0)


@pytest.mark.parametrize("i", [1, 2, 3, 4, 5])
def test_campbell_references_normalised(i):
    norm = quad(lambda x: float(th.campbell_reference(x, i)), 0, np.inf)[0]
    second = quad(lambda x: x * x * float(th.campbell_reference(x, i)), 0, np.inf)[0]
    assert norm == pytest.approx(1.0, rel=1e-10)
    assert second == pytest.approx(1.0, rel=1e-10)
    x = np.linspace(0, 5, 51)
    np.testing.assert_allclose(
        th.campbell_reference(x, i), th.chi_density(x, th.CAMPBELL_DOF[i]), rtol=1e-12
    )
    assert th.CAMPBELL_A[i] == {1: 0.5, 2: 0.5, 3: 0.5, 4: 1.0, 5: 1.5}[i]
    if i <= 3:  # the thesis's printed (unfolded) form is half the folded one
        np.testing.assert_allclose(
            th.campbell_reference(x, i, folded=False), 0.5 * th.campbell_reference(x, i)
        )
    assert th.campbell_reference(-1.0, i) == 0.0


def test_malik_gaussian():
    assert th.malik_gaussian(0.0) == 1.0
    assert th.malik_gaussian(1.0) == pytest.approx(math.exp(-0.5))
    assert quad(lambda x: float(th.malik_gaussian(x)), -np.inf, np.inf)[0] == pytest.approx(
        math.sqrt(2 * math.pi)
    )


@pytest.mark.parametrize("s", [0.0, 0.3, 1.0, 2.5, 10.0])
def test_savage_jeffrey_normalised_and_symmetric(s):
    for length in ("R", "C", "C/2"):
        total = quad(
            lambda t, ln=length: float(th.savage_jeffrey(t, s, 0.5, ln)), 0, math.pi, limit=200
        )[0]
        assert total == pytest.approx(1.0, rel=1e-9)
    theta = np.linspace(0, math.pi / 2, 19)
    np.testing.assert_allclose(
        th.savage_jeffrey(theta, s), th.savage_jeffrey(math.pi / 2 - theta, s), atol=1e-14
    )
    # peak on the compressive diagonal (theta = 135 deg) for positive S
    assert th.savage_jeffrey(3 * math.pi / 4, s) >= th.savage_jeffrey(math.pi / 4, s)
    assert th.savage_jeffrey(0.0, s) == pytest.approx(1 / math.pi)


def test_corrected_s_conventions():
    nu = 0.5
    assert th.corrected_s(1.0, nu, "text") == pytest.approx(math.sqrt(math.pi / nu))
    assert th.corrected_s(1.0, nu, "listing") == pytest.approx(0.5 * math.sqrt(math.pi / nu))
    # C = R sqrt(pi/nu) is the mean spacing
    assert th.mean_spacing(nu, 2) == pytest.approx(math.sqrt(math.pi / nu))
    np.testing.assert_allclose(
        th.savage_jeffrey(0.7, 1.2, nu, "C"),
        th.savage_jeffrey(0.7, th.corrected_s(1.2, nu), None, "R"),
    )
    with pytest.raises(ValueError):
        th.savage_jeffrey(0.1, 1.0, None, "C")
    with pytest.raises(ValueError):
        th.corrected_s(1.0, nu, "other")


def test_packings_and_conversion():
    assert th.NU_HEXAGONAL == pytest.approx(0.9069, abs=1e-4)
    assert th.NU_SHEARABLE == pytest.approx(0.8210, abs=1e-4)
    assert th.NU_SQUARE == pytest.approx(0.7854, abs=1e-4)
    assert th.PHI_CUBIC == pytest.approx(0.5236, abs=1e-4)
    nu = np.linspace(0.05, 0.9, 18)
    phi = th.nu_3d_from_2d(nu)
    np.testing.assert_allclose(th.nu_2d_from_3d(phi), nu, rtol=1e-12)
    # equal mean spacing is the definition of the conversion
    np.testing.assert_allclose(th.mean_spacing(nu, 2), th.mean_spacing(phi, 3), rtol=1e-12)
    assert th.nu_3d_from_2d(th.NU_SQUARE) == pytest.approx(
        4 / (3 * math.sqrt(math.pi)) * (math.pi / 4) ** 1.5
    )
