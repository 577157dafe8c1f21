"""Velocity distributions: Maxwellian samples against the folded references, moments.

Dimensionless particle units: d = 1, m = 1. Synthetic frames: uniform positions, bin-wise
mean flow, isotropic Maxwellian fluctuations whose temperature depends on the bin
(equipartition between u', v', w' and sqrt(j) omega', as X4 and X5 assume).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.special import erf

from demstudy.analysis.vdf import (
    VelocityDistribution,
    folded_maxwellian,
    velocity_distributions,
)
from demstudy.io.frames import Frame

EDGES = np.array([0.0, 4.0, 10.0, 20.0])


def frames(dim: int, count: int, n: int, sampler=None, seed: int = 0) -> list[Frame]:
    rng = np.random.default_rng(seed)
    nrot = 1 if dim == 2 else 3
    box = np.array([10.0, 20.0, 10.0][:dim])
    k = 0.5 if dim == 2 else 0.4
    j = k * 0.25  # j = K r^2, r = 1/2
    sampler = sampler or (lambda size: rng.normal(size=size))
    out = []
    for t in range(count):
        pos = rng.uniform(0, box, (n, dim))
        b = np.searchsorted(EDGES, pos[:, 1], side="right") - 1
        sigma = np.array([0.5, 1.0, 2.0])[b]
        vel = sigma[:, None] * sampler((n, dim))
        vel[:, 0] += np.array([3.0, 1.0, -2.0])[b]  # mean flow, constant in each bin
        omega = sigma[:, None] / np.sqrt(j) * sampler((n, nrot)) + 0.7
        out.append(Frame(float(t), np.zeros(dim), box, pos, vel, omega, np.full(n, 0.5)))
    return out


def z_scores(value, expected, err):
    with np.errstate(divide="ignore", invalid="ignore"):
        return (np.asarray(value) - expected) / np.asarray(err)


@pytest.mark.parametrize("dim", [2, 3])
def test_maxwellian_moments_and_folded_references(dim):
    ana = velocity_distributions(frames(dim, 40, 4000, seed=dim), dim=dim, edges=EDGES)
    res = ana.results
    n_phys = dim + (1 if dim == 2 else 3)
    # moments: skewness 0, kurtosis 3 for every component, within errors
    for key, expected in (("kurtosis", 3.0), ("skewness", 0.0)):
        z = z_scores(res[key], expected, res[f"{key}_err"])
        assert np.max(np.abs(z)) < 4.5, (key, z)
    assert np.all(res["kurtosis_err"] < 0.05)
    expected_var = np.broadcast_to(np.array([0.25, 1.0, 4.0])[:, None], (3, dim))
    np.testing.assert_allclose(res["variance"][:, :dim], expected_var, rtol=0.03)
    # Campbell's X1..X5 histograms follow the folded Maxwellians (bin averages) in every bin
    ref = res["X_reference"]
    assert res["X"].shape == (3, 5, 50)
    for b in range(3):
        z = z_scores(res["X"][b], ref, res["X_err"][b])
        ok = ref > 1e-2
        assert np.max(np.abs(z[ok])) < 5.0
        assert 0.6 < np.mean(z[ok] ** 2) < 1.6
    # folded forms: a = 1/2, 1/2, 1/2, 1, 3/2 in 2D; normalised on [0, inf)
    x = np.linspace(0, 12, 24001)
    for k in ana.dof:
        assert np.trapezoid(folded_maxwellian(x, k), x) == pytest.approx(1, abs=1e-6)
        assert np.trapezoid(x**2 * folded_maxwellian(x, k), x) == pytest.approx(1, abs=1e-6)
    if dim == 2:
        assert ana.attrs["X_a"] == "0.5,0.5,0.5,1,1.5"
    # Malik's C/sigma: P(0) = 1 by construction, and the density is the normal one
    assert res["malik_P"].shape == (3, n_phys, 100)
    np.testing.assert_allclose(0.5 * (res["malik_P"][:, :, 49] + res["malik_P"][:, :, 50]), 1)
    gauss = np.diff(0.5 * (1 + erf(res["malik_edges"] / np.sqrt(2)))) / 0.1
    z = z_scores(res["malik_pdf"], gauss, res["malik_pdf_err"])
    ok = np.broadcast_to(gauss > 1e-2, z.shape)  # >= ~30 expected counts per bin
    assert np.max(np.abs(z[ok])) < 5.0
    assert 0.6 < np.mean(z[ok] ** 2) < 1.6
    np.testing.assert_allclose(res["gaussian"], np.exp(-0.5 * res["malik_centres"] ** 2))


def test_uniform_velocities_are_detected():
    rng = np.random.default_rng(5)
    uniform = lambda size: rng.uniform(-np.sqrt(3), np.sqrt(3), size)  # noqa: E731
    ana = VelocityDistribution(2, edges=EDGES).run(frames(2, 30, 4000, uniform, seed=9))
    res = ana.results
    z_uniform = z_scores(res["kurtosis"], 1.8, res["kurtosis_err"])
    z_gauss = z_scores(res["kurtosis"], 3.0, res["kurtosis_err"])
    assert np.max(np.abs(z_uniform)) < 4.5
    assert np.min(np.abs(z_gauss)) > 30
    # the X1 histogram of a uniform distribution is far from the folded Maxwellian
    second = VelocityDistribution(2, edges=EDGES, reference=res).run(
        frames(2, 30, 4000, uniform, seed=9))
    z = z_scores(second.results["X"][:, 0], second.results["X_reference"][0],
                 second.results["X_err"][:, 0])
    assert np.nanmax(np.abs(z)) > 20


def test_reference_must_match_the_bins():
    first = VelocityDistribution(2, edges=EDGES).run(frames(2, 3, 200))
    with pytest.raises(ValueError, match="other bin edges"):
        VelocityDistribution(2, edges=[0, 5, 20], reference=first.results).run(frames(2, 2, 200))


def test_two_passes_need_a_reiterable_source():
    with pytest.raises(TypeError, match="twice"):
        velocity_distributions(iter(frames(2, 2, 50)), dim=2, edges=EDGES)
    res = velocity_distributions(lambda: iter(frames(2, 4, 300)), dim=2, edges=EDGES)
    assert res.attrs["passes"] == 2 and res.attrs["samples"] == 4


def test_memory_is_flat_in_frames():
    ana = VelocityDistribution(2, edges=EDGES, max_blocks=8)
    for f in frames(2, 50, 100):
        ana.feed(f)
    assert ana._acc._blocks.shape[0] == 8
    ana.finish()
    assert ana.attrs["samples"] == 50


def test_lees_edwards_images_are_wrapped_with_their_velocity_shift():
    """Centres moved up by one period carry the Lees-Edwards image velocity (+ shift);
    with ``period`` and ``image_velocity_shift`` the analysis maps them back exactly."""
    base = frames(2, 6, 500, seed=3)
    shift, period = 7.5, 20.0
    moved = []
    for f in base:
        pos, vel = f.position.copy(), f.velocity.copy()
        up = np.arange(f.n) % 3 == 0
        pos[up, 1] += period
        vel[up, 0] += shift
        down = np.arange(f.n) % 3 == 1
        pos[down, 1] -= period
        vel[down, 0] -= shift
        moved.append(Frame(f.time, f.box_lo, f.box_hi, pos, vel, f.angular_velocity, f.radius))
    a = velocity_distributions(base, dim=2, edges=EDGES).results
    b = velocity_distributions(moved, dim=2, edges=EDGES, period=period,
                               image_velocity_shift=shift).results
    for key in ("mean", "variance", "kurtosis", "X", "malik_P"):
        np.testing.assert_allclose(b[key], a[key], rtol=1e-9, atol=1e-9, err_msg=key)


def test_malik_cell_convention_removes_a_spanwise_mean_flow():
    """3D gas with a mean flow varying along z, u = A sin(2π z/L_z), A = 2, plus a unit
    Maxwellian: relative to the strip mean (Campbell) the u variance is 1 + A²/2 = 3 and the
    distribution is not Gaussian; relative to the means of 16 z-cells (Malik) it is
    1 + A² (2π/16)²/24 ≈ 1.026 (the mean's variation inside a cell) with kurtosis ≈ 3."""
    from demstudy.analysis.vdf import velocity_distributions
    from demstudy.io.frames import Frame

    rng = np.random.default_rng(11)
    n, L, A = 6000, 12.0, 2.0
    frames = []
    for t in range(12):
        pos = rng.uniform(0, L, (n, 3))
        vel = rng.normal(size=(n, 3))
        vel[:, 0] += A * np.sin(2 * np.pi * pos[:, 2] / L)
        frames.append(Frame(time=float(t), box_lo=np.zeros(3), box_hi=np.full(3, L),
                            position=pos, velocity=vel, angular_velocity=rng.normal(size=(n, 3)),
                            radius=np.full(n, 0.5)))
    strip = velocity_distributions(frames, dim=3, n_bins=2)
    cells = velocity_distributions(frames, dim=3, n_bins=2, z_cells=16)
    assert strip.results["variance"][:, 0] == pytest.approx(1 + A**2 / 2, rel=0.05)
    expected = 1 + A**2 * (2 * np.pi / 16) ** 2 / 24
    var, err = cells.results["variance"][:, 0], cells.results["variance_err"][:, 0]
    assert np.all(np.abs(var - expected) < 4 * err + 0.01)
    assert np.all(np.abs(cells.results["kurtosis"][:, 0] - 3.0) < 0.15)
    assert np.all(np.abs(strip.results["kurtosis"][:, 0] - 3.0) > 0.3)
    assert cells.results["cell_mean"].shape == (2 * 16, cells.n_comp)
    assert cells.attrs["z_cells"] == 16
    with pytest.raises(ValueError, match="z_cells"):
        velocity_distributions(frames[:1], dim=2, z_cells=4)
