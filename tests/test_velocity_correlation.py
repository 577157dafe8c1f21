"""Velocity correlations C_aa(r), C_ab(r) and Malik's orientational correlation Lambda(y)
against exact cases. Dimensionless particle units: d = 1, m = 1."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import j0

from demstudy.analysis.velocity_correlation import (
    BinMeans,
    OrientationalCorrelation,
    VelocityCorrelation,
    orientational_correlation,
    velocity_correlations,
)
from demstudy.io.frames import Frame


def _frame(pos, vel, omega=None, box=None, tilt=0.0, t=0.0):
    n, dim = pos.shape
    box = np.full(dim, 1.0) if box is None else np.asarray(box, float)
    omega = np.zeros((n, 1 if dim == 2 else 3)) if omega is None else omega
    return Frame(t, np.zeros(dim), box, pos, vel, omega, np.full(n, 0.5), tilt=tilt)


def _shell_average(f, edges, dim):
    """Average of f(r) over each shell with the measure r^(dim-1) dr."""
    return np.array([quad(lambda r: f(r) * r ** (dim - 1), a, b)[0] / ((b**dim - a**dim) / dim)
                     for a, b in zip(edges[:-1], edges[1:], strict=True)])


@pytest.mark.parametrize("dim", [2, 3])
def test_cosine_field_gives_bessel_or_sinc_and_bin_means_are_removed(dim):
    """u_x = cos(k x) on uniform random positions: <cos(k dx)> over pairs at distance r is
    J0(k r) in 2D and sin(k r)/(k r) in 3D; u_y independent gives C_yy = 0. A mean velocity
    that is constant in each y-bin (a step profile) changes nothing."""
    rng = np.random.default_rng(7)
    L, n, r_max = (24.0, 2000, 6.0) if dim == 2 else (16.0, 2500, 4.0)
    k = 2 * np.pi * 2 / L
    box = np.full(dim, L)
    frames, stepped = [], []
    for t in range(8):
        pos = rng.uniform(0, L, (n, dim))
        vel = rng.normal(size=(n, dim))
        vel[:, 0] = np.cos(k * pos[:, 0])
        frames.append(_frame(pos, vel, box=box, t=t))
        v2 = vel.copy()
        v2[:, 0] += 3.0 * np.floor(pos[:, 1] / (L / 4)) ** 2  # constant in each of 4 bins
        stepped.append(_frame(pos, v2, box=box, t=t))
    opts = {"dim": dim, "n_bins": 4, "period": L, "r_max": r_max, "dr": 0.5}
    res = velocity_correlations(frames, **opts).results
    profile = (lambda r: j0(k * r)) if dim == 2 else (lambda r: np.sinc(k * r / np.pi))
    exact = _shell_average(profile, res["r_edges"], dim)
    c, err = res["C"], res["C_err"]
    assert np.all(np.isfinite(err)) and err[:, 0, 2:].max() < 0.05
    assert np.all(np.abs(c[:, 0, 1:] - exact[1:]) < 5 * err[:, 0, 1:] + 0.01)
    assert np.all(np.abs(c[:, 1, 1:]) < 5 * err[:, 1, 1:] + 0.01)
    np.testing.assert_allclose(res["temperature_components"][:, 0], 0.5, rtol=0.05)
    np.testing.assert_allclose(res["temperature_components"][:, 1], 1.0, rtol=0.05)
    np.testing.assert_allclose(res["covariance"][:, 0] / res["temperature_components"][:, :1],
                               c[:, 0])
    # u_x and u_y independent: C_xy = 0 (and xz, yz in 3D)
    off, off_err = res["C_offdiag"], res["C_offdiag_err"]
    assert off.shape == (4, dim * (dim - 1) // 2, res["r"].size)
    assert np.all(np.abs(off[:, :, 1:]) < 5 * off_err[:, :, 1:] + 0.01)
    stepped_res = velocity_correlations(stepped, **opts).results
    np.testing.assert_allclose(stepped_res["C"], c, rtol=1e-9, atol=1e-12)


def test_checkerboard_lattice_in_bin_and_across_bins():
    """Square lattice, one row per bin, u_x = (-1)^column, u_y = (-1)^(column + row): every
    neighbour pair is exactly (anti)correlated, so C is +-1 shell by shell, and the in-bin
    reading sees the row neighbours only."""
    nx = ny = 10
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    pos = np.stack([i.ravel() + 0.5, j.ravel() + 0.5], axis=1)
    sign_x = (-1.0) ** i.ravel()
    vel = np.stack([sign_x, sign_x * (-1.0) ** j.ravel()], axis=1)
    frame = _frame(pos, vel, box=[nx, ny])
    opts = {"dim": 2, "edges": np.arange(ny + 1.0), "r_max": 2.0, "dr": 0.25}
    across = VelocityCorrelation(**opts).run([frame]).results  # walls along y
    shell_1, shell_sqrt2 = 4, 5  # r = 1 in [1, 1.25), r = sqrt 2 in [1.25, 1.5)
    c = across["C"]
    np.testing.assert_allclose(c[:, 1, shell_1], -1.0)
    np.testing.assert_allclose(c[:, 1, shell_sqrt2], 1.0)
    np.testing.assert_allclose(c[:, 0, shell_sqrt2], -1.0)
    # u_x at r = 1: two row neighbours (-1) and up to two column neighbours (+1)
    np.testing.assert_allclose(c[1:-1, 0, shell_1], 0.0, atol=1e-12)
    np.testing.assert_allclose(c[[0, -1], 0, shell_1], -1.0 / 3.0)
    np.testing.assert_allclose(across["pairs_per_particle"][1:-1, shell_1], 4.0)
    np.testing.assert_allclose(across["C_malik"][:, 0, shell_sqrt2],
                               -across["pairs_per_particle"][:, shell_sqrt2] / (2 * 0.25))
    for distance in ("full", "planar"):
        inside = VelocityCorrelation(**opts, in_bin=True, distance=distance).run([frame]).results
        np.testing.assert_allclose(inside["pairs_per_particle"][:, shell_1], 2.0)
        np.testing.assert_allclose(inside["pairs_per_particle"][:, shell_sqrt2], 0.0)
        np.testing.assert_allclose(inside["C"][:, :, shell_1], -1.0)
    # one frame: instantaneous bin means are the run means
    two_pass = velocity_correlations([frame], **opts).results
    np.testing.assert_allclose(two_pass["C"], across["C"], equal_nan=True)


@pytest.mark.parametrize("dim", [2, 3])
def test_cross_correlation_of_a_shared_cosine_field(dim):
    """u_x = cos(k x), u_y = a cos(k x) + noise (s.d. s), u_z independent: for pairs i != j
    the noise drops out, so C_xy(r) = rho C_xx(r) with rho = a sqrt(T_x) / sqrt(a^2 T_x + s^2),
    T_x = 1/2 (-0.816 for a = -1, s = 0.5), the J0 / sinc shell average; C_xz = C_yz = 0.
    The antisymmetric part vanishes within errors (homogeneous statistics)."""
    rng = np.random.default_rng(11)
    L, n, r_max, a, s = (24.0, 2000, 6.0, -1.0, 0.5) if dim == 2 else (16.0, 2500, 4.0, -1.0,
                                                                       0.5)
    k = 2 * np.pi * 2 / L
    frames = []
    for t in range(8):
        pos = rng.uniform(0, L, (n, dim))
        vel = rng.normal(size=(n, dim))
        vel[:, 0] = np.cos(k * pos[:, 0])
        vel[:, 1] = a * vel[:, 0] + s * rng.normal(size=n)
        frames.append(_frame(pos, vel, box=np.full(dim, L), t=t))
    res = velocity_correlations(frames, dim=dim, n_bins=4, period=L, r_max=r_max,
                                dr=0.5).results
    profile = (lambda r: j0(k * r)) if dim == 2 else (lambda r: np.sinc(k * r / np.pi))
    rho = a * np.sqrt(0.5) / np.sqrt(a**2 * 0.5 + s**2)
    expected = rho * _shell_average(profile, res["r_edges"], dim)
    off, err = res["C_offdiag"][:, :, 1:], res["C_offdiag_err"][:, :, 1:]
    assert err.max() < 0.05
    assert np.all(np.abs(off[:, 0] - expected[1:]) < 5 * err[:, 0] + 0.01)
    assert np.all(np.abs(off[:, 1:]) < 5 * err[:, 1:] + 0.01)  # xz, yz (3D)
    anti = res["C_offdiag_antisym"][:, :, 1:]
    assert np.all(np.abs(anti) < 5 * res["C_offdiag_antisym_err"][:, :, 1:] + 0.01)
    np.testing.assert_allclose(res["covariance_offdiag"][:, 0] / np.sqrt(
        res["temperature_components"][:, :1] * res["temperature_components"][:, 1:2]),
        res["C_offdiag"][:, 0])


def _lattice(nx=10, ny=10):
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    return i.ravel(), j.ravel(), np.stack([i.ravel() + 0.5, j.ravel() + 0.5], axis=1)


def test_cross_correlation_on_a_lattice_exact_and_under_swaps():
    """Square lattice, one row j per bin (walls along y, x periodic).

    * u_y = s u_x in every particle: C_xy = sign(s) C_xx exactly, shell by shell.
    * u_x = (-1)^i, u_y = (-1)^i (j + 1)^2 (bin means 0): at r = 1 a particle of an interior
      row has two row neighbours (u_x product -1) and two column neighbours (+1), so
      S_xy = -2 c_j + c_(j+1) + c_(j-1) = 2 and S_yx = c_j (-2 + 2) = 0 with c_j = (j + 1)^2;
      over 4 pairs and sqrt(T_x T_y) = c_j: C_xy = 1/(4 c_j) and the antisymmetric part
      is the same. Swapping the velocity components keeps C_xy and flips the antisymmetric
      part; flipping u_y flips both; the diagonal is untouched by the sign flip.
    * one bin over a whole periodic box: the antisymmetric part is exactly 0."""
    i, j, pos = _lattice()
    opts = {"dim": 2, "edges": np.arange(11.0), "r_max": 2.0, "dr": 0.25}
    shell_1 = 4
    sign_x = (-1.0) ** i
    base = np.stack([sign_x, sign_x * (-1.0) ** j], axis=1)  # the checkerboard above
    for scale in (1.0, -2.0):
        vel = np.stack([base[:, 0], scale * base[:, 0]], axis=1)
        res = VelocityCorrelation(**opts).run([_frame(pos, vel, box=[10, 10])]).results
        has = res["pairs_per_particle"] > 0
        np.testing.assert_allclose(res["C_offdiag"][:, 0][has],
                                   np.sign(scale) * res["C"][:, 0][has], atol=1e-12)
        np.testing.assert_allclose(res["C_offdiag_antisym"][:, 0][has], 0.0, atol=1e-12)

    vel = np.stack([sign_x, sign_x * (j + 1.0) ** 2], axis=1)
    res = VelocityCorrelation(**opts).run([_frame(pos, vel, box=[10, 10])]).results
    rows = np.arange(1, 9)
    for key in ("C_offdiag", "C_offdiag_antisym"):
        np.testing.assert_allclose(res[key][rows, 0, shell_1], 1 / (4 * (rows + 1) ** 2))
    swapped = VelocityCorrelation(**opts).run([_frame(pos, vel[:, ::-1], box=[10, 10])])
    flipped = VelocityCorrelation(**opts).run([_frame(pos, vel * [1, -1], box=[10, 10])])
    swapped, flipped = swapped.results, flipped.results
    for key, swap_sign, flip_sign in (("C_offdiag", 1, -1), ("C_offdiag_antisym", -1, -1)):
        np.testing.assert_allclose(swapped[key], swap_sign * res[key], equal_nan=True)
        np.testing.assert_allclose(flipped[key], flip_sign * res[key], equal_nan=True)
    np.testing.assert_allclose(swapped["C"], res["C"][:, ::-1], equal_nan=True)
    np.testing.assert_allclose(flipped["C"], res["C"], equal_nan=True)

    whole = VelocityCorrelation(dim=2, n_bins=1, period=10.0, r_max=2.0, dr=0.25).run(
        [_frame(pos, vel, box=[10, 10])]).results
    has = whole["pairs_per_particle"][0] > 0  # empty shells are 0/0
    assert np.abs(whole["C_offdiag"][0, 0, has]).max() > 0.5
    np.testing.assert_allclose(whole["C_offdiag_antisym"][0, 0, has], 0.0, atol=1e-12)


def test_lees_edwards_partner_through_the_boundary():
    """Two particles 0.5 apart only through the sheared y boundary (image at x - tilt); the
    image keeps the partner's fluctuation. Without the tilt they are far apart."""
    lx, ly, tilt = 20.0, 10.0, 7.0
    pos = np.array([[3.0, 0.2], [3.0 + tilt, ly - 0.3]])
    vel = np.array([[1.0, 0.5], [2.0, -1.0]])
    ref = {"edges": [0.0, ly], "velocity": [[0.0, 0.0]], "spin": [[0.0]]}
    opts = {"dim": 2, "edges": [0.0, ly], "period": ly, "r_max": 2.0, "dr": 0.25,
            "reference": ref}
    res = VelocityCorrelation(**opts).run([_frame(pos, vel, box=[lx, ly], tilt=tilt)]).results
    shell = 2  # r = 0.5
    assert res["pairs_per_particle"][0, shell] == 1.0
    assert res["pairs_per_particle"][0].sum() == 1.0
    np.testing.assert_allclose(res["covariance"][0, :, shell], [2.0, -0.5])
    flat = VelocityCorrelation(**opts).run([_frame(pos, vel, box=[lx, ly])]).results
    assert flat["pairs_per_particle"].sum() == 0.0


def test_bin_means_unwrap_lees_edwards_velocities():
    """A centre stored one period above the box is wrapped down with u - shear rate * L_y."""
    ly, shift = 10.0, 4.0
    pos = np.array([[1.0, 2.0], [5.0, ly + 2.5]])
    vel = np.array([[1.0, 0.0], [1.0 + shift, 2.0]])
    res = BinMeans(dim=2, n_bins=2, period=ly, image_velocity_shift=shift).run(
        [_frame(pos, vel, box=[20.0, ly], tilt=3.0)]).results
    np.testing.assert_allclose(res["count"], [2.0, 0.0])
    np.testing.assert_allclose(res["velocity"][0], [1.0, 1.0])


def _gas_3d(rng, n, mode, L=20.0):
    pos = rng.uniform(0, L, (n, 3))
    vel = rng.normal(size=(n, 3)) + [3.0, 0.0, 0.0]
    if mode == "random":
        omega = rng.normal(size=(n, 3))
    elif mode == "aligned":
        omega = -2.0 * (vel - [3.0, 0.0, 0.0])
    else:  # perpendicular
        omega = np.cross(vel - [3.0, 0.0, 0.0], rng.normal(size=(n, 3)))
    return _frame(pos, vel, omega=omega, box=[L, L, L])


def test_lambda_random_aligned_perpendicular():
    """Independent isotropic fluctuations give 1/3 within the error; parallel ones 1,
    perpendicular ones 0."""
    rng = np.random.default_rng(3)
    frames = [_gas_3d(rng, 2000, "random") for _ in range(32)]
    res = orientational_correlation(frames, n_bins=4).results
    lam, err = res["lambda"], res["lambda_err"]
    assert np.all((err > 0.001) & (err < 0.01))
    assert np.all(np.abs(lam - 1.0 / 3.0) < 4 * err)
    assert np.all(np.abs(res["lambda_pooled"] - 1.0 / 3.0) < 4 * res["lambda_pooled_err"])
    for mode, value in (("aligned", 1.0), ("perpendicular", 0.0)):
        frames = [_gas_3d(rng, 500, mode) for _ in range(4)]
        # the instantaneous bin means are not the true mean: compare with the exact reference
        ref = {"edges": np.linspace(0, 20, 3), "velocity": [[3.0, 0, 0]] * 2,
               "spin": [[0.0, 0, 0]] * 2}
        exact = OrientationalCorrelation(n_bins=2, reference=ref).run(frames).results
        np.testing.assert_allclose(exact["lambda"], value, atol=1e-12)
        two_pass = orientational_correlation(frames, n_bins=2).results["lambda"]
        assert np.all(np.abs(two_pass - value) < 0.02)


def test_lambda_refuses_2d():
    with pytest.raises(ValueError, match="3D"):
        OrientationalCorrelation(dim=2)


def _results_file(path, scene_path, n, frames=4, tilt=0.0, seed=0):
    """A results file holding only the scene and synthetic random frames."""
    from demstudy.io.results import Results, write_results
    from demstudy.scene import load_scene, scene_to_toml

    scene = load_scene(scene_path)
    rng = np.random.default_rng(seed)
    dim, size = scene.dimension, np.asarray(scene.box.size, float)
    n_rot = 1 if dim == 2 else 3
    pos = rng.uniform(0.5, size - 0.5, (frames, n, dim))
    stored = {
        "time": np.arange(frames, dtype=float),
        "position": pos,
        "velocity": rng.normal(size=(frames, n, dim)),
        "angular_velocity": rng.normal(size=(frames, n, n_rot)),
        "radius": np.full((frames, n), 0.5),
        "box_lo": np.zeros((frames, dim)),
        "box_hi": np.tile(size, (frames, 1)),
        "tilt": np.full(frames, tilt),
    }
    write_results(path, Results(attrs={"engine": "synthetic", "scene_toml": scene_to_toml(scene),
                                       "scene_name": scene.meta.name}, frames=stored))
    return scene


def test_analyze_cli_stores_the_new_statistics(tmp_path, capsys):
    """`demstudy analyze RUN.h5 --what vcorr,lambda,waves,cgprofiles` on a 3D channel (walls
    at y = 0, 15; bins of 1) stores /statistics/<name> with the documented shapes; lambda is
    refused for a 2D scene with a one-line error."""
    from pathlib import Path

    from demstudy.cli import main
    from demstudy.io.results import read_results

    inputs = Path(__file__).resolve().parent.parent / "inputs"
    out = tmp_path / "run.h5"
    _results_file(out, inputs / "malik2008" / "waves-phi0.15-L45W15H15.toml", n=400)
    assert main(["analyze", str(out), "--what", "vcorr,lambda,waves,cgprofiles"]) == 0
    groups = read_results(out).groups
    vc, lam = groups["statistics/vcorr"], groups["statistics/lambda"]
    wav, cg = groups["statistics/waves"], groups["statistics/cgprofiles"]
    assert vc["C"].shape == vc["C_err"].shape == (15, 3, 50)  # r_max = 5, dr = 0.1
    assert vc["temperature_components"].shape == (15, 3)
    assert lam["lambda"].shape == lam["lambda_err"].shape == (15,)
    assert np.all(np.abs(lam["lambda"] - 1 / 3) < 0.2)
    assert wav["spectrum_xy"].shape == (22, 7) and wav["spectrum_yz"].shape == (7, 8)
    assert wav["field_xz"].shape == (22, 8)
    assert cg["solid_fraction"].shape == (30,) and cg["kinetic_stress"].shape == (30, 3, 3)
    assert read_results(out).group_attrs["statistics/waves"]["pattern"] == "none"

    flat = tmp_path / "le.h5"
    _results_file(flat, inputs / "shear" / "lees-edwards-2d.toml", n=300, tilt=5.0)
    assert main(["analyze", str(flat), "--what", "vcorr,waves,cgprofiles"]) == 0
    assert read_results(flat).groups["statistics/vcorr"]["C"].shape == (56, 2, 50)
    capsys.readouterr()
    assert main(["analyze", str(flat), "--what", "lambda"]) == 2  # refused: nothing computed
    err = capsys.readouterr().err
    assert "3D" in err and "Traceback" not in err


def test_lambda_in_malik_cells_removes_a_spanwise_mean_field():
    """Velocity and spin share a mean field varying along z, A sin(2π z/L_z) x̂, on top of
    independent isotropic noise: about the bin (strip) means the shared field aligns the
    fluctuations (Λ ≈ 0.40 > 1/3); about the means of 16 z-cells (Malik's cells) it is gone
    and Λ = 1/3 within errors (the residual variation of the field inside a cell is small)."""
    rng = np.random.default_rng(21)
    n, L, A = 4000, 12.0, 2.0
    frames = []
    for t in range(10):
        pos = rng.uniform(0, L, (n, 3))
        field = A * np.sin(2 * np.pi * pos[:, 2] / L)
        vel = rng.normal(size=(n, 3))
        spin = rng.normal(size=(n, 3))
        vel[:, 0] += field
        spin[:, 0] += field
        frames.append(Frame(time=float(t), box_lo=np.zeros(3), box_hi=np.full(3, L),
                            position=pos, velocity=vel, angular_velocity=spin,
                            radius=np.full(n, 0.5)))
    strip = orientational_correlation(frames, n_bins=2).results
    cells = orientational_correlation(frames, n_bins=2, z_cells=16)
    assert np.all(strip["lambda"] > 1 / 3 + 0.04)
    assert np.all(strip["lambda"] - 1 / 3 > 5 * strip["lambda_err"])
    lam, err = cells.results["lambda"], cells.results["lambda_err"]
    assert np.all(np.abs(lam - 1 / 3) < 4 * err + 0.01)
    assert cells.attrs["z_cells"] == 16
