"""ProfileAnalysis against gases with known profiles (particle units: d = 1, m = 1)."""

from __future__ import annotations

import numpy as np
import pytest

from demstudy.analysis.profiles import ProfileAnalysis
from demstudy.io.frames import Frame

UNIT_VOLUME = {2: np.pi / 4, 3: np.pi / 6}


def frame(pos, vel, omega, radius, box, t=0.0) -> Frame:
    box = np.asarray(box, float)
    return Frame(t, np.zeros_like(box), box, pos, vel, omega, radius)


def gas(rng, n, box, radius=0.5, y_range=None):
    """Ideal-gas positions (overlaps allowed) uniform in the box (y in y_range if given)."""
    box = np.asarray(box, float)
    pos = rng.uniform(0, 1, (n, box.size)) * box
    if y_range is not None:
        pos[:, 1] = rng.uniform(*y_range, n)
    r = np.full(n, radius) if np.isscalar(radius) else rng.uniform(*radius, n)
    return pos, r


def mass(r, dim):
    return (2 * r) ** dim  # m = V / V_1 with uniform density


def zscores(res, key, expected):
    return (res[key] - expected) / res[f"{key}_err"]


def assert_calibrated(z, lo=0.5, hi=1.6, zmax=4.5):
    """Deviations are consistent with the reported errors (RMS z-score near 1)."""
    z = np.asarray(z).ravel()
    assert np.all(np.abs(z) < zmax), z
    assert lo < np.sqrt(np.mean(z**2)) < hi, np.sqrt(np.mean(z**2))


@pytest.mark.parametrize("dim", [2, 3])
def test_uniform_gas_has_flat_solid_fraction(dim):
    rng = np.random.default_rng(dim)
    box = [30.0, 15.0] if dim == 2 else [8.0, 15.0, 8.0]
    n = 200 if dim == 2 else 500
    pa = ProfileAnalysis(dim=dim, period=15.0)
    for t in range(200):
        pos, r = gas(rng, n, box)
        pa.feed(frame(pos, np.zeros((n, dim)), np.zeros((n, 1 if dim == 2 else 3)), r, box, t))
    res = pa.finish().results
    phi0 = n * UNIT_VOLUME[dim] / np.prod(box)
    assert_calibrated(zscores(res, "solid_fraction", phi0))
    assert res["solid_fraction"].mean() == pytest.approx(phi0, rel=0.01)
    np.testing.assert_allclose(res["number_density"], res["solid_fraction"] / UNIT_VOLUME[dim])
    np.testing.assert_allclose(res["y"], np.arange(15) + 0.5)
    assert pa.attrs["samples"] == 200 and pa.attrs["axis"] == "y"


def test_open_boundaries_flat_when_centres_reach_past_grid():
    """Non-periodic: parts outside the grid are dropped, so centres spread over
    [lo - r, hi + r] give the same flat material density in every bin, edge bins too."""
    rng = np.random.default_rng(5)
    box, n = [20.0, 10.0], 300
    pa = ProfileAnalysis(dim=2, bin_width=0.5)
    for _ in range(150):
        pos, r = gas(rng, n, box, y_range=(-0.5, 10.5))
        pa.feed(frame(pos, np.zeros((n, 2)), np.zeros((n, 1)), r, box))
    res = pa.finish().results
    assert res["y"].size == 20
    assert_calibrated(zscores(res, "solid_fraction", n * np.pi / 4 / (20.0 * 11.0)))


def test_rigid_translation_and_rotation_have_zero_temperature():
    rng = np.random.default_rng(7)
    box, n, v0, w0 = [6.0, 12.0, 6.0], 800, np.array([1.3, -0.7, 0.2]), np.array([2.0, 0, -1])
    pa = ProfileAnalysis(dim=3, bin_width=0.7, period=12.0)
    for _ in range(10):
        pos, r = gas(rng, n, box, radius=(0.3, 0.7))
        pa.feed(frame(pos, np.tile(v0, (n, 1)), np.tile(w0, (n, 1)), r, box))
    res = pa.finish().results
    np.testing.assert_allclose(res["velocity"], np.tile(v0, (res["y"].size, 1)), rtol=1e-13)
    np.testing.assert_allclose(res["spin"], np.tile(w0, (res["y"].size, 1)), rtol=1e-13, atol=1e-14)
    for key in ("temperature", "temperature_components", "kinetic_shear", "rotational_temperature"):
        assert np.max(np.abs(res[key])) < 1e-12, key
    assert np.max(res["velocity_err"]) < 1e-13


@pytest.mark.parametrize("dim", [2, 3])
def test_maxwellian_polydisperse_gas_recovers_temperatures(dim):
    """Equipartition: v_a ~ N(u_a, T_a/m_i), w ~ N(W, T_r/I_i) with m_i proportional to V_i.
    The particle temperatures sum m v'^2 / N per component are recovered within errors."""
    rng = np.random.default_rng(10 + dim)
    temps = np.array([1.5, 0.5, 1.0])[:dim]
    u = np.array([2.0, 0.0, -0.5])[:dim]
    t_rot, k, nrot = 0.8, 0.4 if dim == 3 else 0.5, 1 if dim == 2 else 3
    spin0 = np.array([0.3, -0.2, 1.0])[:nrot] if dim == 3 else np.array([0.7])
    box = [30.0, 12.0] if dim == 2 else [8.0, 12.0, 8.0]
    n = 300 if dim == 2 else 400
    pa = ProfileAnalysis(dim=dim, period=12.0, bin_width=1.5)
    for t in range(120):
        pos, r = gas(rng, n, box, radius=(0.35, 0.65))
        m = mass(r, dim)[:, None]
        vel = u + rng.normal(size=(n, dim)) * np.sqrt(temps / m)
        omega = spin0 + rng.normal(size=(n, nrot)) * np.sqrt(t_rot / (k * m * r[:, None] ** 2))
        pa.feed(frame(pos, vel, omega, r, box, t))
    res = pa.finish().results
    nb = res["y"].size
    assert_calibrated(zscores(res, "temperature_components", np.tile(temps, (nb, 1))))
    assert_calibrated(zscores(res, "temperature", temps.mean()))
    assert_calibrated(zscores(res, "rotational_temperature", t_rot))
    assert_calibrated(zscores(res, "velocity", np.tile(u, (nb, 1))))
    assert_calibrated(zscores(res, "spin", np.tile(spin0, (nb, 1))))
    assert_calibrated(zscores(res, "kinetic_shear", 0.0))
    assert np.all(res["temperature_err"] < 0.05 * temps.mean())


@pytest.mark.parametrize(("dim", "width"), [(2, 1.0), (2, 0.5), (3, 1.0)])
def test_linear_shear_velocity_and_gradient_leak(dim, width):
    """u = g y + thermal noise under Lees-Edwards (periodic y, image x-velocity +- g L).
    Fluctuations are taken about each bin's mean, so the shear only enters T_xx through the
    spread of positions feeding a bin: g^2 (w^2/12 + r^2/4) for discs, r^2/5 for spheres."""
    rng = np.random.default_rng(20 + dim)
    g, t0, r = 0.8, 0.2, 0.5
    box = [40.0, 10.0] if dim == 2 else [8.0, 10.0, 8.0]
    n = 600
    pa = ProfileAnalysis(dim=dim, bin_width=width, period=10.0, image_velocity_shift=g * 10.0)
    for _ in range(150):
        pos, rad = gas(rng, n, box, radius=r)
        vel = np.sqrt(t0) * rng.normal(size=(n, dim))
        vel[:, 0] += g * pos[:, 1]
        pa.feed(frame(pos, vel, np.zeros((n, 1 if dim == 2 else 3)), rad, box))
    res = pa.finish().results
    leak = g**2 * (width**2 / 12 + r**2 / (4 if dim == 2 else 5))
    expected = np.full((res["y"].size, dim), t0)
    expected[:, 0] += leak
    assert_calibrated(zscores(res, "temperature_components", expected))
    assert_calibrated((res["velocity"][:, 0] - g * res["y"]) / res["velocity_err"][:, 0])
    assert_calibrated(zscores(res, "kinetic_shear", 0.0))
    assert leak > 10 * res["temperature_components_err"][:, 0].max()  # the bound is resolved

    # without the Lees-Edwards image velocity the boundary bins are corrupted
    pb = ProfileAnalysis(dim=dim, bin_width=width, period=10.0)
    pos, rad = gas(rng, 20 * n, box, radius=r)
    vel = np.sqrt(t0) * rng.normal(size=(20 * n, dim))
    vel[:, 0] += g * pos[:, 1]
    out = pb.run([frame(pos, vel, np.zeros((20 * n, 1 if dim == 2 else 3)), rad, box)]).results
    assert out["temperature_components"][0, 0] > t0 + 3 * leak


def test_solid_fraction_normalised_per_frame():
    """Lattice of unit discs, one per unit cell of a 10-wide block; frames with box widths
    10 and 20 have solid fractions pi/4 and pi/8 in every row: the mean is 3 pi / 16."""
    xs, ys = np.meshgrid(np.arange(10) + 0.5, np.arange(6) + 0.5)
    pos = np.column_stack([xs.ravel(), ys.ravel()])
    n = pos.shape[0]
    pa = ProfileAnalysis(dim=2, bin_width=1.0)
    for width in (10.0, 20.0) * 3:
        pa.feed(frame(pos, np.zeros((n, 2)), np.zeros((n, 1)), np.full(n, 0.5), [width, 6.0]))
    res = pa.finish().results
    np.testing.assert_allclose(res["solid_fraction"], 3 * np.pi / 16, rtol=1e-13)
    np.testing.assert_allclose(res["mean_mass"], 1.0, rtol=1e-13)


def test_grid_options_and_axis():
    rng = np.random.default_rng(1)
    box, n = [6.0, 5.0, 9.0], 50
    pos, r = gas(rng, n, box)
    fr = frame(pos, rng.normal(size=(n, 3)), rng.normal(size=(n, 3)), r, box)
    pa = ProfileAnalysis(axis="z", dim=3, edges=np.linspace(1.0, 7.0, 13)).run([fr, fr])
    np.testing.assert_allclose(pa.results["edges"], np.linspace(1.0, 7.0, 13))
    assert pa.attrs["axis"] == "z" and pa.attrs["bin_width"] == pytest.approx(0.5)
    pa = ProfileAnalysis(dim=3, bin_width=0.9).run([fr])  # 5/0.9 -> 6 equal bins
    assert pa.results["y"].size == 6 and pa.attrs["bin_width"] == pytest.approx(5 / 6)
    assert np.all(np.isnan(pa.results["temperature_err"]))  # one sample: no error estimate
    with pytest.raises(ValueError, match="uniformly"):
        ProfileAnalysis(dim=3, edges=[0.0, 1.0, 3.0])
    with pytest.raises(ValueError, match="axis"):
        ProfileAnalysis(axis="z", dim=2)
    with pytest.raises(ValueError, match="exceeds the period"):
        ProfileAnalysis(dim=3, lo=0.0, hi=6.0, period=5.0).feed(fr)
    with pytest.raises(ValueError, match="position"):
        ProfileAnalysis(dim=2).feed(fr)


def test_feed_finish_equals_run_and_memory_is_bounded():
    rng = np.random.default_rng(2)
    box, n = [10.0, 8.0], 60
    frames = []
    for t in range(300):
        pos, r = gas(rng, n, box)
        frames.append(frame(pos, rng.normal(size=(n, 2)), rng.normal(size=(n, 1)), r, box, t))
    a = ProfileAnalysis(dim=2, period=8.0, max_blocks=8).run(frames, step=2)
    b = ProfileAnalysis(dim=2, period=8.0, max_blocks=8)
    for f in frames[::2]:
        b.feed(f)
    b.finish()
    for key in a.results:
        np.testing.assert_array_equal(a.results[key], b.results[key])
    assert a.attrs["samples"] == 150 and a._acc.n_blocks < 8
    with pytest.raises(RuntimeError):
        b.feed(frames[0])
    with pytest.raises(ValueError, match="no frames"):
        ProfileAnalysis(dim=2).finish()


def test_empty_frames_count_as_samples_with_zero_solid_fraction():
    xs, ys = np.meshgrid(np.arange(4) + 0.5, np.arange(3) + 0.5)
    pos = np.column_stack([xs.ravel(), ys.ravel()])
    n, box = pos.shape[0], [4.0, 3.0]
    full = frame(pos, np.ones((n, 2)), np.ones(n), np.full(n, 0.5), box)  # (N,) spin in 2D
    empty = frame(np.zeros((0, 2)), np.zeros((0, 2)), np.zeros((0, 1)), np.zeros(0), box)
    res = ProfileAnalysis(dim=2).run([full, empty] * 4).results
    np.testing.assert_allclose(res["solid_fraction"], np.pi / 8, rtol=1e-13)
    np.testing.assert_allclose(res["velocity"], 1.0, rtol=1e-13)


def spanwise_shear_frames(rng, a, t0, n_frames, n=1500, box=(8.0, 12.0, 8.0)):
    """3D unit spheres, uniform centres, u_x = a z + a Maxwellian of temperature t0 (m = 1),
    spins of rotational temperature t0 (I = 0.1) with a mean omega_y = a z as well."""
    box = np.asarray(box, float)
    for t in range(n_frames):
        pos, r = gas(rng, n, box)
        vel = np.sqrt(t0) * rng.normal(size=(n, 3))
        vel[:, 0] += a * pos[:, 2]
        omega = np.sqrt(t0 / 0.1) * rng.normal(size=(n, 3))
        omega[:, 1] += a * pos[:, 2]
        yield frame(pos, vel, omega, r, box, t)


def test_malik_cells_remove_a_spanwise_gradient_and_converge_to_t():
    """u_x = a z inside each y-bin (z uniform on [0, L_z)): about the strip mean <u'^2> =
    T + a^2 L_z^2/12; about the run means of N z-slabs only the slab's own spread is left,
    T + a^2 (L_z/N)^2/12 -> T as N grows. The spin's mean omega_y = a z leaks the same way into
    the rotational temperature, j a^2 (L_z/N)^2/12 / 3 (j = I/m = 0.1). The other fields are
    the strip ones, identical whatever N."""
    a, t0, lz = 0.6, 0.5, 8.0
    frames = list(spanwise_shear_frames(np.random.default_rng(31), a, t0, 80))
    strip = ProfileAnalysis(dim=3, period=12.0).run(frames)
    res = strip.results
    nb = res["y"].size
    expected = np.tile([t0 + a**2 * lz**2 / 12, t0, t0], (nb, 1))
    assert_calibrated(zscores(res, "temperature_components", expected))
    assert "cell_temperature" not in res and strip.attrs["z_cells"] == 1
    previous = np.inf
    for n_cells in (2, 4, 16):
        cells = ProfileAnalysis(dim=3, period=12.0, z_cells=n_cells).run(frames)
        out, leak = cells.results, a**2 * (lz / n_cells) ** 2 / 12
        expected = np.tile([t0 + leak, t0, t0], (nb, 1))
        assert_calibrated(zscores(out, "cell_temperature_components", expected))
        assert_calibrated(zscores(out, "cell_temperature", t0 + leak / 3))
        assert_calibrated(zscores(out, "cell_rotational_temperature", t0 + 0.1 * leak / 3))
        assert out["cell_temperature"].mean() < previous  # approaches T from above
        previous = out["cell_temperature"].mean()
        for key in (
            "solid_fraction",
            "velocity",
            "temperature",
            "temperature_err",
            "rotational_temperature",
            "kinetic_shear",
            "spin",
        ):
            np.testing.assert_allclose(out[key], res[key], rtol=1e-10, atol=1e-14, err_msg=key)
        assert cells.attrs["z_cells"] == n_cells and "Malik" in cells.attrs["fluctuations"]
    # with 16 cells the leak (0.0075) is below the resolution: the cell temperature is T
    assert_calibrated(zscores(out, "cell_temperature_components", np.tile([t0] * 3, (nb, 1))))


def test_malik_cells_agree_with_strips_for_a_uniform_polydisperse_gas():
    """No mean-velocity variation: both conventions recover the equipartition temperatures
    (m v_a'^2 = T_a, I w'^2 = T_r) within errors, and differ from each other by far less."""
    rng = np.random.default_rng(32)
    temps, t_rot, n, box = np.array([1.5, 0.5, 1.0]), 0.8, 400, [8.0, 12.0, 8.0]
    pa = ProfileAnalysis(dim=3, period=12.0, bin_width=1.5, z_cells=4)
    for t in range(120):
        pos, r = gas(rng, n, box, radius=(0.35, 0.65))
        m = mass(r, 3)[:, None]
        vel = np.array([2.0, 0.0, -0.5]) + rng.normal(size=(n, 3)) * np.sqrt(temps / m)
        omega = rng.normal(size=(n, 3)) * np.sqrt(t_rot / (0.4 * m * r[:, None] ** 2))
        pa.feed(frame(pos, vel, omega, r, box, t))
    res = pa.finish().results
    nb = res["y"].size
    for prefix in ("", "cell_"):
        assert_calibrated(zscores(res, f"{prefix}temperature_components", np.tile(temps, (nb, 1))))
        assert_calibrated(zscores(res, f"{prefix}rotational_temperature", t_rot))
    diff = np.abs(res["cell_temperature"] - res["temperature"])
    assert np.all(diff < res["temperature_err"])


def test_malik_cells_in_a_rigid_rotation_and_under_lees_edwards():
    """Rigid rotation about y, v = W x r about the box centre: u_x = W (z - z_c), w_z =
    -W (x - x_c), every spin W e_y. Strips: <u'^2> = W^2 L_z^2/12, <w'^2> = W^2 L_x^2/12;
    z-cells take out the z spread only: <u'^2> = W^2 (L_z/N)^2/12, <w'^2> unchanged; <v'^2>
    and the rotational temperatures are 0 exactly. Plus a Lees-Edwards shear u += g y (image
    x velocity +- g L_y): the images keep their slab and add g^2 (w^2/12 + r^2/5) in both."""
    rng = np.random.default_rng(33)
    w0, g, n_cells, n = 0.5, 0.3, 4, 1500
    box = np.array([6.0, 10.0, 8.0])
    pa = ProfileAnalysis(dim=3, period=10.0, z_cells=n_cells, image_velocity_shift=g * 10.0)
    for t in range(60):
        pos, r = gas(rng, n, box)
        rel = pos - box / 2
        vel = np.cross(np.array([0.0, w0, 0.0]), rel)
        vel[:, 0] += g * pos[:, 1]
        pa.feed(frame(pos, vel, np.tile([0.0, w0, 0.0], (n, 1)), r, box, t))
    res = pa.finish().results
    nb, shear = res["y"].size, g**2 * (1 / 12 + 0.25 / 5)
    strip = np.tile([w0**2 * 64 / 12 + shear, 0.0, w0**2 * 36 / 12], (nb, 1))
    cells = np.tile([w0**2 * (8 / n_cells) ** 2 / 12 + shear, 0.0, w0**2 * 36 / 12], (nb, 1))
    for key, expected in (
        ("temperature_components", strip),
        ("cell_temperature_components", cells),
    ):
        assert_calibrated((res[key] - expected)[:, [0, 2]] / res[f"{key}_err"][:, [0, 2]])
        assert np.max(np.abs(res[key][:, 1])) < 1e-12
    for key in ("rotational_temperature", "cell_rotational_temperature"):
        assert np.max(np.abs(res[key])) < 1e-12


def test_z_cells_is_refused_where_it_has_no_meaning():
    for kwargs, where in (
        ({"dim": 2, "z_cells": 4}, "2D"),
        ({"dim": 3, "z_cells": 0}, "3D"),
        ({"dim": 3, "axis": "z", "z_cells": 2}, "axis z"),
    ):
        with pytest.raises(ValueError, match=rf"z_cells = {kwargs['z_cells']}.*{where}"):
            ProfileAnalysis(**kwargs)
    assert ProfileAnalysis(dim=2, z_cells=1).z_cells == 1  # the strip default exists in 2D


@pytest.mark.parametrize("dim", [2, 3])
def test_centres_left_outside_a_sheared_box_keep_their_image_velocity(dim):
    """Engines leave centres slightly outside a Lees–Edwards box (LAMMPS remaps lazily).
    A centre at y + k L_y is the image of one at y moving k γ̇ L_y faster along x: the
    profiles of a frame holding such images equal those of the frame put back by the image
    rule, to round-off. Without the velocity shift the edge bins of a linear shear profile
    would see a particle γ̇ L_y off its neighbours (a temperature ~40 % high there)."""
    rng = np.random.default_rng(7)
    n, ly, rate = 400, 10.0, 0.5
    lengths = np.array([10.0, ly, 10.0][:dim])
    pos = rng.uniform(0.0, 1.0, (n, dim)) * lengths
    vel = rng.normal(0.0, 0.1, (n, dim))
    vel[:, 0] += rate * (pos[:, 1] - ly / 2)  # u = γ̇ (y − L_y/2)
    omega = rng.normal(0.0, 0.1, (n, 1 if dim == 2 else 3))
    radius = np.full(n, 0.5)
    turns = np.zeros(n)
    turns[(pos[:, 1] < 0.3)] = 1.0  # shown as their image one period up ...
    turns[(pos[:, 1] > ly - 0.3)] = -1.0  # ... or down, as an engine may leave them
    assert np.count_nonzero(turns) > 10
    shown_pos, shown_vel = pos.copy(), vel.copy()
    shown_pos[:, 1] += turns * ly
    shown_vel[:, 0] += turns * rate * ly

    def profiles(p, v):
        frame = Frame(time=0.0, box_lo=np.zeros(dim), box_hi=lengths, position=p,
                      velocity=v, angular_velocity=omega, radius=radius)
        ana = ProfileAnalysis(axis="y", bin_width=1.0, lo=0.0, hi=ly, dim=dim,
                              period=ly, image_velocity_shift=rate * ly)
        return ana.run([frame, frame]).results

    inside, outside = profiles(pos, vel), profiles(shown_pos, shown_vel)
    for key in ("solid_fraction", "velocity", "temperature", "temperature_components"):
        np.testing.assert_allclose(outside[key], inside[key], rtol=1e-12, atol=1e-14,
                                   err_msg=key)
    # and the edge bins' temperature is that of the bulk (the shift would add (γ̇ L_y)² ×
    # the images' share of the bin: several times the bulk value)
    t = inside["temperature"]
    bulk = np.mean(t[1:-1])
    assert abs(t[0] / bulk - 1) < 0.3 and abs(t[-1] / bulk - 1) < 0.3, (t[0], t[-1], bulk)
