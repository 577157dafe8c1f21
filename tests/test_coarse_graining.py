"""Gaussian coarse-grained profiles (MercuryCG convention) against exact cases.
Dimensionless particle units: d = 1, m = 1."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from demstudy.analysis.coarse_graining import (
    TRUNCATED_VARIANCE,
    CoarseGrainedProfiles,
    gaussian_kernel,
)
from demstudy.analysis.profiles import ProfileAnalysis
from demstudy.io.frames import Frame


def _frame(pos, vel, box, t=0.0, radius=0.5):
    n, dim = pos.shape
    return Frame(t, np.zeros(dim), np.asarray(box, float), pos, vel,
                 np.zeros((n, 1 if dim == 2 else 3)), np.full(n, radius))


def test_kernel_is_normalised_on_its_cutoff_and_has_the_truncated_variance():
    w = 0.7
    assert quad(lambda s: gaussian_kernel(s, w), -3 * w, 3 * w)[0] == pytest.approx(1, abs=1e-12)
    assert gaussian_kernel(3.01 * w, w) == 0.0
    var = quad(lambda s: s * s * gaussian_kernel(s, w), -3 * w, 3 * w)[0]
    assert var == pytest.approx(TRUNCATED_VARIANCE * w**2, rel=1e-10)


@pytest.mark.parametrize("dim", [2, 3])
def test_uniform_gas_gives_the_true_solid_fraction(dim):
    """Uniform random centres: flat nu equal to N V_p / V within the errors; between walls
    (centres in [d/2, H - d/2]) the same value N V_p / (A (H - d)) holds farther than 3 w from
    the reach of the centres, and nu drops at the walls (kernel mass lost beyond them)."""
    rng = np.random.default_rng(11)
    box = np.array([12.0, 20.0] + ([6.0] if dim == 3 else []))
    vp = np.pi / 4 if dim == 2 else np.pi / 6
    n, w = 400, 0.5
    periodic = [_frame(rng.uniform(0, box, (n, dim)), rng.normal(size=(n, dim)), box, t)
                for t in range(40)]
    res = CoarseGrainedProfiles(width=w, dim=dim, period=box[1]).run(periodic).results
    nu, err = res["solid_fraction"], res["solid_fraction_err"]
    true = n * vp / np.prod(box)
    assert np.all(np.abs(nu - true) < 4.5 * err)
    assert abs(nu.mean() / true - 1) < 0.01  # the mean over the period is exact per frame
    lo_c, hi_c = 0.5, box[1] - 0.5
    walls = []
    for t in range(40):
        pos = rng.uniform(0, box, (n, dim))
        pos[:, 1] = rng.uniform(lo_c, hi_c, n)
        walls.append(_frame(pos, rng.normal(size=(n, dim)), box, t))
    res = CoarseGrainedProfiles(width=w, dim=dim, lo=0.0, hi=box[1]).run(walls).results
    y, nu, err = res["y"], res["solid_fraction"], res["solid_fraction_err"]
    true = n * vp / (np.prod(box) / box[1] * (hi_c - lo_c))
    bulk = (y > lo_c + 3 * w) & (y < hi_c - 3 * w)
    assert np.all(np.abs(nu[bulk] - true) < 4.5 * err[bulk])
    assert nu[0] < 0.6 * true and nu[-1] < 0.6 * true


def test_rigid_rotation_in_a_lees_edwards_box():
    """v = Omega x (r - r_c) in a y-periodic box whose image at y + L_y moves with
    -Omega L_y (a Lees-Edwards shift), centres partly stored one period too high: V_x is
    linear everywhere, V_y = 0, sigma_yy / rho = Omega^2 L_x^2 / 12 and sigma_xx / rho =
    Omega^2 s^2 with s^2 the variance of the truncated kernel (gradient leaking in)."""
    rng = np.random.default_rng(5)
    lx, ly, om, n, w = 20.0, 30.0, 0.3, 3000, 0.7
    frames = []
    for t in range(20):
        pos = rng.uniform(0, [lx, ly], (n, 2))
        vel = np.stack([-om * (pos[:, 1] - ly / 2), om * (pos[:, 0] - lx / 2)], axis=1)
        lazy = rng.random(n) < 0.2
        pos[lazy, 1] += ly
        vel[lazy, 0] -= om * ly
        frames.append(_frame(pos, vel, [lx, ly], t))
    res = CoarseGrainedProfiles(width=w, dim=2, period=ly, image_velocity_shift=-om * ly,
                                n_points=60).run(frames).results
    y, v, verr = res["y"], res["velocity"], res["velocity_err"]
    assert np.all(np.abs(v[:, 0] + om * (y - ly / 2)) < 4.5 * verr[:, 0] + 1e-3)
    assert np.all(np.abs(v[:, 1]) < 4.5 * verr[:, 1])
    per_mass = res["kinetic_stress"] / res["density"][:, None, None]
    assert per_mass[:, 1, 1].mean() == pytest.approx(om**2 * lx**2 / 12, rel=0.02)
    assert per_mass[:, 0, 0].mean() == pytest.approx(om**2 * w**2 * TRUNCATED_VARIANCE, rel=0.02)
    assert np.all(np.abs(per_mass[:, 0, 1]) < 0.02 * om**2 * lx * w)
    # without the shift the images near y = 0 and L_y carry the wrong velocity
    wrong = CoarseGrainedProfiles(width=w, dim=2, period=ly, n_points=60).run(frames).results
    assert abs(wrong["velocity"][0, 0] + om * (y[0] - ly / 2)) > 1.0


def test_narrow_kernel_averaged_over_bins_is_the_binned_profile():
    """Particles lying entirely inside bins of width 2 (centres >= 0.6 from the edges), w =
    0.02: the CG fields averaged over each bin reproduce ProfileAnalysis's exact binned
    solid fraction, velocity and temperature."""
    rng = np.random.default_rng(8)
    lx, n_bins, width, w = 15.0, 5, 2.0, 0.02
    frames = []
    for t in range(6):
        n = 300
        b = rng.integers(0, n_bins, n)
        y = width * b + rng.uniform(0.6, 1.4, n)
        pos = np.stack([rng.uniform(0, lx, n), y], axis=1)
        vel = rng.normal(size=(n, 2)) * [1.0, 0.5] + np.stack([y, 0 * y], axis=1)
        frames.append(_frame(pos, vel, [lx, width * n_bins], t))
    prof = ProfileAnalysis(bin_width=width, lo=0.0, hi=width * n_bins, dim=2).run(frames).results
    per_bin = 2000
    cg = CoarseGrainedProfiles(width=w, dim=2, lo=0.0, hi=width * n_bins,
                               n_points=n_bins * per_bin).run(frames).results

    def bin_mean(a):
        return a.reshape(n_bins, per_bin, *a.shape[1:]).mean(axis=1)

    rho, nu, num = bin_mean(cg["density"]), bin_mean(cg["solid_fraction"]), \
        bin_mean(cg["number_density"])
    mom = bin_mean(cg["momentum_density"])
    mvv = bin_mean(np.nan_to_num(cg["kinetic_stress"] + cg["density"][:, None, None]
                                 * cg["velocity"][:, :, None] * cg["velocity"][:, None, :]))
    np.testing.assert_allclose(nu, prof["solid_fraction"], rtol=1e-5)
    np.testing.assert_allclose(mom / rho[:, None], prof["velocity"], rtol=1e-5, atol=1e-5)
    temp = (np.trace(mvv, axis1=1, axis2=2) - (mom**2).sum(1) / rho) / (2 * num)
    np.testing.assert_allclose(temp, prof["temperature"], rtol=1e-5)
