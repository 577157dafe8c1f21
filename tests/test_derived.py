"""demstudy.analysis.derived against exact cases (particle units d = 1, m = 1, g = 1)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from demstudy import theory as th
from demstudy.analysis import derived as dv
from demstudy.analysis.profiles import ProfileAnalysis
from demstudy.io.frames import Frame
from demstudy.scene import load_scene

INPUTS = Path(__file__).resolve().parents[1] / "inputs"

RHO = {2: 4 / math.pi, 3: 6 / math.pi}


def synthetic(edges, nu_int, u=None, var=(1.0, 1.0), dim=2, uv=0.0):
    """Profiles dict with bin-averaged nu (nu_int = antiderivative of nu), velocity u(y)
    at the centres, equal-mass particles and constant velocity variances."""
    edges = np.asarray(edges, float)
    y = 0.5 * (edges[1:] + edges[:-1])
    n = y.size
    nu = (nu_int(edges[1:]) - nu_int(edges[:-1])) / np.diff(edges)
    vel = np.zeros((n, dim))
    if u is not None:
        vel[:, 0] = u(y)
    comps = (
        np.tile(np.asarray(var, float)[:dim], (n, 1))
        if len(var) >= dim
        else np.tile(np.resize(np.asarray(var, float), dim), (n, 1))
    )
    return {
        "y": y,
        "edges": edges,
        "solid_fraction": nu,
        "velocity": vel,
        "temperature_components": comps,
        "mean_mass": np.ones(n),
        "kinetic_shear": np.full(n, uv),
    }


def column(h0=10.0, nu0=0.6):
    """nu = nu0 (1 - (y/h0)^2) on [0, h0]; returns (nu, antiderivative of nu)."""

    def nu(y):
        y = np.clip(y, 0, h0)
        return nu0 * (1 - (y / h0) ** 2)

    def nu_int(y):
        y = np.clip(y, 0, h0)
        return nu0 * (y - y**3 / (3 * h0**2))

    return nu, nu_int


@pytest.mark.parametrize("dim", [2, 3])
def test_static_column_weight_above_converges(dim):
    nu, nu_int = column()
    g = np.zeros(dim)
    g[1] = -1.0
    errs = {"trapezoid": [], "rectangle": []}
    widths = [1.0, 0.5, 0.25, 0.125]
    for w in widths:
        prof = synthetic(np.arange(0, 12 + w / 2, w), nu_int, dim=dim)
        exact = RHO[dim] * (nu_int(12.0) - nu_int(prof["y"]))
        for rule in errs:
            s = dv.momentum_balance_stress(prof, g, rule=rule)
            np.testing.assert_array_equal(s["tau_xy"], 0.0)
            errs[rule].append(np.max(np.abs(s["tau_yy"] - exact)))
            if rule == "rectangle":  # the listing's bias is the half bin below the centre
                bias = RHO[dim] * nu(prof["y"]) * w / 2
                assert np.max(np.abs(s["tau_yy"] - exact - bias)) < 0.05 * w
    trap, rect = np.array(errs["trapezoid"]), np.array(errs["rectangle"])
    assert np.all(trap[1:] / trap[:-1] < 0.3)  # O(w^2)
    np.testing.assert_allclose(rect[1:] / rect[:-1], 0.5, atol=0.03)  # O(w)
    assert trap[-1] < 1e-3 and rect[-1] > 0.01


def test_uniform_column_trapezoid_exact():
    nu0, h0 = 0.7, 6.0
    prof = synthetic(np.arange(0, 9.01, 0.5), lambda y: nu0 * np.clip(y, 0, h0))
    s = dv.momentum_balance_stress(prof, (0.0, -1.0))
    exact = RHO[2] * nu0 * np.clip(h0 - prof["y"], 0, None)
    np.testing.assert_allclose(s["tau_yy"], exact, atol=1e-12)
    # rectangle: integral from each bin's lower edge
    r = dv.momentum_balance_stress(prof, (0.0, -1.0), rule="rectangle")
    np.testing.assert_allclose(
        r["tau_yy"], RHO[2] * nu0 * np.clip(h0 - prof["edges"][:-1], 0, None), atol=1e-12
    )


def test_static_column_from_particles():
    """Real ProfileAnalysis output of a resting square lattice: the rectangle sum over all
    bins is the total weight per unit length exactly (volumes are exact)."""
    nx, ny, length = 8, 6, 8.0
    x, y = np.meshgrid(np.arange(nx) + 0.5, np.arange(ny) + 0.5)
    pos = np.stack([x.ravel(), y.ravel()], axis=1)
    n = pos.shape[0]
    pa = ProfileAnalysis(dim=2, bin_width=0.25, lo=0.0, hi=8.0)
    for t in range(3):
        pa.feed(
            Frame(
                float(t),
                np.zeros(2),
                np.array([length, 8.0]),
                pos,
                np.zeros((n, 2)),
                np.zeros((n, 1)),
                np.full(n, 0.5),
            )
        )
    prof = pa.finish().results
    rect = dv.momentum_balance_stress(prof, (0.0, -1.0), rule="rectangle")
    assert rect["tau_yy"][0] == pytest.approx(n / length, rel=1e-12)
    trap = dv.momentum_balance_stress(prof, (0.0, -1.0))
    assert trap["tau_yy"][0] == pytest.approx(n / length, rel=0.02)
    assert np.all(np.diff(trap["tau_yy"]) <= 1e-12)
    assert dv.campbell_depth(prof, 0.0) == pytest.approx(2 * 3.0, rel=1e-3)


@pytest.mark.parametrize("rule", ["trapezoid", "rectangle"])
@pytest.mark.parametrize("alpha", [20.0, 30.0])
def test_chute_friction_is_tan_alpha(rule, alpha):
    rng = np.random.default_rng(1)
    a = math.radians(alpha)
    edges = np.arange(0, 10.01, 0.5)
    prof = synthetic(edges, lambda y: 0.5 * y)  # uniform nu
    g = (math.sin(a), -math.cos(a))
    s = dv.momentum_balance_stress(prof, g, rule=rule)
    mu, _ = dv.friction_coefficient(s["tau_xy"], s["tau_yy"])
    np.testing.assert_allclose(mu, math.tan(a), rtol=1e-13)
    prof["solid_fraction"] = rng.uniform(0.1, 0.8, prof["y"].size)  # any nu profile
    s = dv.momentum_balance_stress(prof, g, rule=rule)
    np.testing.assert_allclose(s["tau_xy"] / s["tau_yy"], math.tan(a), rtol=1e-13)


def test_chute_from_scene_and_unsteady_term():
    scene = load_scene(INPUTS / "campbell1982" / "chute-30.toml")
    g = np.array(scene.gravity_vector)
    prof = synthetic(np.arange(0, 8.01, 0.5), lambda y: 0.4 * y)
    rho_nu = RHO[2] * prof["solid_fraction"]
    s = dv.momentum_balance_stress(prof, scene)
    np.testing.assert_allclose(s["tau_xy"] / s["tau_yy"], math.tan(math.radians(30)))
    # free fall: rho nu a = rho nu g everywhere -> no stress
    s = dv.momentum_balance_stress(prof, scene, inertia=rho_nu[:, None] * g[None, :])
    np.testing.assert_allclose(s["tau_xy"], 0, atol=1e-12)
    np.testing.assert_allclose(s["tau_yy"], 0, atol=1e-12)
    # momentum change -> rho nu a; top stress is added as given
    dm = np.ones((prof["y"].size, 2))
    np.testing.assert_allclose(dv.unsteady_inertia(dm, 2.0, 0.5, 10.0), 0.1)
    s = dv.momentum_balance_stress(prof, (0.0, 0.0), top_stress=(0.3, 1.2))
    np.testing.assert_allclose(s["tau_xy"], 0.3)
    np.testing.assert_allclose(s["tau_yy"], 1.2)


def test_top_cut_and_sparse_top():
    edges = np.arange(0, 6.01, 1.0)
    prof = synthetic(edges, lambda y: 0.5 * y)
    prof["solid_fraction"][4] = 0.1  # sparse top bin below a cut at H = 4.7
    t = dv.momentum_balance_stress(prof, (0.0, -1.0), top=4.7)
    assert np.all(np.isnan(t["tau_yy"][5:]))
    assert t["tau_yy"][4] == pytest.approx(RHO[2] * 0.1 * 0.2)
    r = dv.momentum_balance_stress(prof, (0.0, -1.0), rule="rectangle", top=4.7)
    assert r["tau_yy"][4] == pytest.approx(RHO[2] * 0.1)
    rs = dv.momentum_balance_stress(prof, (0.0, -1.0), rule="rectangle", top=4.7, sparse_top=True)
    assert np.isnan(rs["tau_yy"][4])
    assert rs["tau_yy"][3] == pytest.approx(RHO[2] * 0.5)


def test_stress_errors_match_monte_carlo():
    rng = np.random.default_rng(7)
    prof = synthetic(np.arange(0, 6.01, 0.5), lambda y: 0.5 * y)
    prof["solid_fraction_err"] = rng.uniform(0.01, 0.05, prof["y"].size)
    s = dv.momentum_balance_stress(prof, (0.2, -1.0))
    draws = []
    for _ in range(4000):
        p = dict(prof)
        p["solid_fraction"] = prof["solid_fraction"] + rng.normal(0, prof["solid_fraction_err"])
        draws.append(dv.momentum_balance_stress(p, (0.2, -1.0))["tau_yy"])
    np.testing.assert_allclose(np.std(draws, axis=0), s["tau_yy_err"], rtol=0.08)


def test_linear_and_cubic_shear_rate_exact():
    edges = np.linspace(0, 10, 21)
    prof = synthetic(edges, lambda y: 0.5 * y, u=lambda y: 0.3 + 1.7 * y, var=(0.4, 0.9))
    du, du_err = dv.shear_rate(prof)
    np.testing.assert_allclose(du, 1.7, rtol=1e-12)
    np.testing.assert_array_equal(du_err, 0.0)
    prof["velocity"][:, 0] = 0.02 * prof["y"] ** 3 - prof["y"]
    du, _ = dv.shear_rate(prof)
    np.testing.assert_allclose(du, 0.06 * prof["y"] ** 2 - 1, atol=1e-11)
    prof["velocity"][3, 0] = np.nan  # an empty bin is skipped
    du, _ = dv.shear_rate(prof)
    assert np.isnan(du[3]) and np.all(np.isfinite(np.delete(du, 3)))


def test_shear_rate_errors_match_monte_carlo():
    rng = np.random.default_rng(3)
    prof = synthetic(np.linspace(0, 10, 11), lambda y: 0.5 * y, u=lambda y: np.sin(y))
    prof["velocity_err"] = np.full((10, 2), 0.05)
    _, err = dv.shear_rate(prof)
    # the spline is linear in the data: one spline through 3000 noisy copies at once
    noise = rng.normal(0, 0.05, (10, 3000))
    draws = CubicSpline(prof["y"], noise, axis=0)(prof["y"], 1)
    np.testing.assert_allclose(np.std(draws, axis=1), err, rtol=0.08)


@pytest.mark.parametrize("dim", [2, 3])
def test_s_parameter_definitions(dim):
    gamma, uu, vv = 1.7, 0.4, 0.9
    prof = synthetic(
        np.linspace(0, 10, 21),
        lambda y: 0.5 * y,
        u=lambda y: -gamma * y,
        var=(uu, vv, 0.5),
        dim=dim,
    )
    s_text, _ = dv.s_parameter(prof, "text")
    np.testing.assert_allclose(s_text, 2 * 0.5 * (-gamma) / math.sqrt(uu), rtol=1e-12)
    s_list, _ = dv.s_parameter(prof, "listing")
    np.testing.assert_allclose(s_list, 2 * math.sqrt(gamma**2 / (uu + vv)) * 0.5, rtol=1e-12)
    prof["mean_mass"] = np.full(20, 2.0)  # temperature_components = m <u'^2>
    np.testing.assert_allclose(dv.s_parameter(prof, "text")[0], -gamma / math.sqrt(uu / 2))


def test_bagnold_definitions():
    tau, rate = np.array([0.8, -0.8]), np.array([2.0, 2.0])
    for dim in (2, 3):
        fc, _ = dv.bagnold_coefficients(tau, rate, dim, "campbell")
        np.testing.assert_allclose(fc, tau / (RHO[dim] * 0.25 * 4.0))
        fl, _ = dv.bagnold_coefficients(tau, rate, dim, "listing")
        np.testing.assert_allclose(
            fl, np.abs(fc) * (1 / math.pi if dim == 2 else 3 / (4 * math.pi))
        )
        fd, _ = dv.bagnold_coefficients(tau, rate, dim, "diameter")
        np.testing.assert_allclose(fd, fc / 4)
    f, e = dv.bagnold_coefficients(
        [1.0, 1.0], [0.0, 1.0], 2, tau_err=[0.1, 0.1], rate_err=[0.0, 0.05]
    )
    assert np.isnan(f[0])
    assert e[1] == pytest.approx(f[1] * math.hypot(0.1, 0.1))


@pytest.mark.parametrize("dim", [2, 3])
def test_equation_of_state_matches_kinetic_theory(dim):
    temp = 0.7
    prof = synthetic(np.linspace(0, 10, 11), lambda y: 0.03 * y**2, var=(temp,) * 3, dim=dim)
    nu = prof["solid_fraction"]
    p = th.pressure(nu, temp, dim)
    chi, _ = dv.equation_of_state(prof, p)
    np.testing.assert_allclose(chi, th.campbell_chi(nu, dim), rtol=1e-12)
    np.testing.assert_allclose(th.campbell_chi(1e-6, dim), 1e-6 / dim, rtol=1e-5)


def test_kinetic_stress_signs():
    prof = synthetic(np.linspace(0, 4, 5), lambda y: 0.5 * y, var=(0.4, 0.9), uv=-0.1)
    k = dv.kinetic_stress(prof)
    np.testing.assert_allclose(k["tau_xy"], RHO[2] * 0.5 * 0.1)
    np.testing.assert_allclose(k["tau_yy"], RHO[2] * 0.5 * 0.9)
    np.testing.assert_allclose(k["tau_xx"], RHO[2] * 0.5 * 0.4)


def test_wall_slip():
    edges = np.linspace(0, 10, 21)
    prof = synthetic(edges, lambda y: 0.5 * y, u=lambda y: 0.3 + 1.7 * y)
    prof["velocity_err"] = np.full((20, 2), 0.01)
    slip, err = dv.wall_slip(prof, 0.0)
    assert slip == pytest.approx(0.3) and err > 0.01
    assert dv.wall_slip(prof, 0.0, n_fit=4)[0] == pytest.approx(0.3)
    assert dv.wall_slip(prof, 10.0, "upper", wall_velocity=17.0)[0] == pytest.approx(0.3)
    assert dv.wall_slip(prof, 0.0, method="first_bin")[0] == pytest.approx(0.3 + 1.7 * 0.25)
    assert dv.wall_slip(prof, 0.0, method="malik")[0] == pytest.approx(0.3 + 1.7 * 0.5)


def test_knudsen_and_conversion():
    prof = synthetic(np.linspace(0, 10, 11), lambda y: 0.1 * y)
    np.testing.assert_allclose(dv.knudsen_enskog(prof, 50.0), th.mean_free_path(0.1, 2) / 50.0)


@pytest.mark.parametrize("rule", ["trapezoid", "rectangle"])
def test_integrating_up_from_the_wall(rule):
    # Couette without gravity: the stress is the wall stress everywhere
    prof = synthetic(np.arange(0, 10.01, 0.5), lambda y: 0.5 * y - 0.01 * y**2)
    s = dv.momentum_balance_stress(prof, (0.0, 0.0), rule=rule, wall_stress=(0.2, 1.5))
    np.testing.assert_allclose(s["tau_xy"], 0.2)
    np.testing.assert_allclose(s["tau_yy"], 1.5)
    # chute: starting from the true wall stress (the weight) gives the top-down result
    g = (0.5, -0.8)
    down = dv.momentum_balance_stress(prof, g, rule=rule)
    weight = RHO[2] * np.sum(prof["solid_fraction"] * 0.5)
    if rule == "trapezoid":  # the same quadrature of the total: first bin held constant
        weight = down["tau_yy"][0] / 0.8 + RHO[2] * prof["solid_fraction"][0] * 0.25
    up = dv.momentum_balance_stress(prof, g, rule=rule, wall_stress=(0.5 * weight, 0.8 * weight))
    np.testing.assert_allclose(up["tau_xy"], down["tau_xy"], atol=1e-12)
    np.testing.assert_allclose(up["tau_yy"], down["tau_yy"], atol=1e-12)


# ------------------------------------------------------------------ derived_results
def couette_results(a=0.2, b=0.05, nu0=0.5, var=(0.04, 0.02), tau0=0.01, p0=0.03):
    """A 2D Couette cell (walls at y = 0 and 12, upper at U = 1): u = a + b y, uniform nu and
    velocity variances, and a measured total stress P_xx = P_yy = p0, P_xy = -tau0."""
    from demstudy.io.results import Results

    prof = synthetic(np.linspace(0.0, 12.0, 13), lambda y: nu0 * y, u=lambda y: a + b * y,
                     var=var)
    n = prof["y"].size
    for key in ("solid_fraction", "velocity", "temperature_components"):
        prof[f"{key}_err"] = np.full_like(prof[key], 1e-3)
    total = np.zeros((n, 2, 2))
    total[:, 0, 0] = total[:, 1, 1] = p0
    total[:, 0, 1] = total[:, 1, 0] = -tau0
    stress = {"y": prof["y"], "edges": prof["edges"], "kinetic": np.zeros((n, 2, 2)),
              "collisional": total, "total": total, "total_err": np.full((n, 2, 2), 1e-4)}
    return Results({"equilibration_end": 0.0}, timeseries={"time": np.arange(3.0)},
                   profiles=prof, profile_attrs={"axis": "y"}, groups={"stress": stress})


def test_derived_results_of_an_analytic_couette_flow():
    a, b, nu0, var, tau0, p0 = 0.2, 0.05, 0.5, (0.04, 0.02), 0.01, 0.03
    scene = load_scene("campbell1982/couette-rough")
    data, attrs = dv.derived_results(couette_results(a, b, nu0, var, tau0, p0), scene)
    rho, radius = RHO[2], 0.5
    np.testing.assert_allclose(data["shear_rate"], b, rtol=1e-9)
    np.testing.assert_allclose(data["S_text"], 2 * radius * b / np.sqrt(var[0]), rtol=1e-9)
    np.testing.assert_allclose(data["S_listing"], 2 * radius * b / np.sqrt(sum(var)),
                               rtol=1e-9)
    np.testing.assert_allclose(data["tau_xy"], tau0)
    np.testing.assert_allclose(data["tau_yy"], p0)
    np.testing.assert_allclose(data["f_s"], tau0 / (rho * radius**2 * b**2), rtol=1e-9)
    np.testing.assert_allclose(data["f_N"], p0 / (rho * radius**2 * b**2), rtol=1e-9)
    np.testing.assert_allclose(data["friction"], tau0 / p0)
    np.testing.assert_allclose(data["chi"], p0 / (rho * sum(var)), rtol=1e-9)
    np.testing.assert_allclose(data["chi_theory"], th.campbell_chi(nu0, 2, 0.6), rtol=1e-12)
    assert data["slip_lower"] == pytest.approx(a)  # straight line: extrapolation exact
    assert data["slip_upper"] == pytest.approx(a + 12 * b - 1.0)
    np.testing.assert_allclose(data["knudsen_enskog"], th.mean_free_path(nu0, 2) / 12.0,
                               rtol=1e-9)
    assert attrs["knudsen_width_is"] == "wall gap" and attrs["knudsen_width"] == 12.0
    for key in ("shear_rate", "S_text", "f_s", "f_N", "friction", "chi", "slip_lower"):
        err = np.asarray(data[f"{key}_err"])
        assert np.all(np.isfinite(err)) and np.all(err > 0), key
    assert attrs["skipped"].startswith("balance_tau_xy") and attrs["skipped"].endswith(
        ": no gravity")
    assert "f_s" in attrs["computed"].split(",") and "slip_upper" in attrs["computed"]


def test_derived_results_of_a_static_chute_column_without_stress():
    """Gravity, open top, no /stress: the steady momentum balance from the profiles; no
    measured stress (said so); Kn from Campbell's flow depth."""
    from demstudy.io.results import Results

    scene = load_scene("campbell1982/chute-30")
    nu, nu_int = column(h0=10.0, nu0=0.6)
    prof = synthetic(np.arange(0.0, 12.5, 0.5), nu_int, u=lambda y: 1 + 0.5 * y)
    data, attrs = dv.derived_results(Results({}, profiles=prof), scene)
    expected = dv.momentum_balance_stress(prof, scene)
    np.testing.assert_allclose(data["balance_tau_yy"], expected["tau_yy"])
    np.testing.assert_allclose(data["balance_tau_xy"], expected["tau_xy"])
    np.testing.assert_allclose(data["friction_balance"][:10], math.tan(math.radians(30)),
                               rtol=1e-9)  # every layer of a steady column: tan(alpha)
    np.testing.assert_allclose(data["f_s_balance"],
                               expected["tau_xy"] / (RHO[2] * 0.25 * 0.5**2), rtol=1e-9)
    assert "tau_xy, tau_yy, pressure, f_s, f_N, friction, chi: no /stress" in attrs["skipped"]
    assert "free surface" in attrs["balance_source"]
    assert data["slip_lower"] == pytest.approx(1.0)
    assert attrs["knudsen_width_is"] == "flow depth (campbell_depth)"
    assert attrs["knudsen_width"] == pytest.approx(dv.campbell_depth(prof, 0.0))
    assert np.all(np.isnan(data["knudsen_enskog"][prof["solid_fraction"] == 0]))


def test_derived_results_skip_what_the_file_lacks():
    from demstudy.io.results import Results

    scene = load_scene("shear/lees-edwards-2d")
    data, attrs = dv.derived_results(Results({}), scene)
    assert attrs["skipped"] == "everything: no /profiles" and attrs["computed"] == ""
    res = couette_results()
    res.profile_attrs["axis"] = "x"
    assert "profiles along x" in dv.derived_results(res, scene)[1]["skipped"]
    res = couette_results()
    res.groups["stress"] = {k: v for k, v in res.groups["stress"].items() if k != "collisional"}
    data, attrs = dv.derived_results(res, scene)  # periodic in y, no walls
    assert "only the kinetic part" in attrs["skipped"] and "slip: no walls" in attrs["skipped"]
    assert "f_s" not in data and "slip_lower" not in data
    assert attrs["knudsen_width_is"] == "periodic height"


def test_derived_results_of_a_short_run_stored_as_a_group(tmp_path):
    """couette-rough in the event-driven engine (5 time units of production, ~1 s): every
    quantity of a sheared wall-bounded flow comes out, with the servo's mean gap and wall
    speed; written as /statistics/derived it reads back with units from the table."""
    from demstudy.cli import main
    from demstudy.io.fields import UNKNOWN_UNITS
    from demstudy.io.results import read_results, write_results

    out = tmp_path / "couette.h5"
    assert main(["run", "campbell1982/couette-rough", "--engine", "edmd", "-q",
                 "--set", "run.production=5",
                 "--set", 'measure.statistics=["stress", "derived"]',
                 "--out", str(out)]) == 0
    res = read_results(out)
    data, attrs = dv.derived_results(res)  # the scene from the file
    stored = res.groups[dv.DERIVED_GROUP]  # the run wrote them: its scene asked
    np.testing.assert_array_equal(stored["f_s"], data["f_s"])
    for key in ("shear_rate", "S_text", "f_s", "f_N", "friction", "chi", "chi_theory",
                "knudsen_enskog", "slip_lower", "slip_upper"):
        assert key in data, (key, attrs["skipped"])
    filled = res.profiles["solid_fraction"] > 0.2
    assert np.all(np.isfinite(data["f_s"][filled])) and np.all(data["tau_yy"][filled] > 0)
    np.testing.assert_allclose(data["friction"], data["tau_xy"] / data["tau_yy"])
    gap = res.timeseries["gap"][res.timeseries["time"] > res.attrs["equilibration_end"]]
    assert attrs["knudsen_width"] == pytest.approx(gap.mean())
    assert 0.9 < attrs["slip_upper_wall_velocity"] < 1.1  # the servo holds the shear rate
    assert attrs["skipped"].endswith("no gravity")
    res.groups[dv.DERIVED_GROUP], res.group_attrs[dv.DERIVED_GROUP] = data, attrs
    back = read_results(write_results(out, res))
    np.testing.assert_array_equal(back.groups[dv.DERIVED_GROUP]["f_s"], data["f_s"])
    assert back.group_attrs[dv.DERIVED_GROUP]["knudsen_width"] == attrs["knudsen_width"]
    units = {k: v["units"] for k, v in back.dataset_attrs.items()
             if k.startswith(dv.DERIVED_GROUP)}
    assert units and UNKNOWN_UNITS not in units.values()
    assert units[f"{dv.DERIVED_GROUP}/tau_xy"] == "m/τ^2 (force per length)"
