"""Density waves: spectra of synthetic density fields with known modes, the noise floor of a
uniform gas, the plug / slug / S-wave classification, the bounded amplitude series and the
sheared grid of Lees-Edwards boxes. Dimensionless particle units: d = 1, m = 1."""

from __future__ import annotations

import numpy as np
import pytest

from demstudy.analysis.waves import DensityWaves, classify_pattern
from demstudy.io.frames import Frame

L, W, H = 60.0, 30.0, 4.0


def _sample(rng, density, n, box, peak=2.0):
    """n points with probability density proportional to density(x, y) (rejection)."""
    out = np.empty((0, len(box)))
    while len(out) < n:
        p = rng.uniform(0, box, (3 * n, len(box)))
        out = np.vstack([out, p[rng.uniform(0, peak, 3 * n) < density(p[:, 0], p[:, 1])]])
    return out[:n]


def _frames(rng, density, n=8000, count=6, box=(L, W, H), tilt=0.0):
    dim = len(box)
    out = []
    for t in range(count):
        pos = _sample(rng, density, n, np.asarray(box))
        out.append(Frame(float(t), np.zeros(dim), np.asarray(box, float), pos,
                         np.zeros((n, dim)), np.zeros((n, 1 if dim == 2 else 3)),
                         np.full(n, 0.5), tilt=tilt))
    return out


def _sinc(t):
    return np.sinc(t / np.pi)


def test_oblique_wave_gives_its_mode_and_amplitude():
    """nu = nu0 (1 + 0.5 cos 2 pi (2 x / L + y / W)) in 2D: the only dominant family is (2, 1),
    with amplitude nu0 * 0.5 * the cell-average factors."""
    rng = np.random.default_rng(1)
    n, nx, ny = 20000, 30, 15
    frames = _frames(rng, lambda x, y: 1 + 0.5 * np.cos(2 * np.pi * (2 * x / L + y / W)), n=n,
                     box=(L, W))
    res = DensityWaves(dim=2, cells=(nx, ny)).run(frames).results
    assert res["dominant_xy"].tolist() == [[2, 1]]
    nu0 = n * np.pi / 4 / (L * W)
    expected = nu0 * 0.5 * _sinc(np.pi * 2 / nx) * _sinc(np.pi * 1 / ny)
    assert res["leading_xy"][0].tolist() == [2, 1]
    assert abs(res["leading_amplitude_xy"][0] - expected) < 0.02 * expected
    np.testing.assert_allclose(res["field_xy"].mean(), nu0, rtol=1e-12)
    assert res["spectrum_xy"].shape == (nx, ny) and res["amplitude_xy"].shape == (16, 8)


def test_uniform_gas_has_a_flat_shot_noise_spectrum_and_no_dominant_mode():
    """Independent uniform centres: every mode but (0, 0) has mean power
    2 nu0 V_p / (V_cell n_cells) (multinomial cell counts), flat in k."""
    rng = np.random.default_rng(2)
    n, cells = 6000, (30, 15, 2)
    frames = _frames(rng, lambda x, y: np.ones_like(x), n=n, count=20)
    ana = DensityWaves(dim=3, cells=cells).run(frames)
    res = ana.results
    assert ana.attrs["pattern"] == "none" and ana.attrs["z_structure"] is False
    for plane, (a, b) in (("xy", (0, 1)), ("xz", (0, 2)), ("yz", (1, 2))):
        p = res[f"spectrum_{plane}"].ravel()[1:]
        m = cells[a] * cells[b]
        v_cell = L * W * H / m
        nu0 = n * np.pi / 6 / (L * W * H)
        expected = 2 * nu0 * (np.pi / 6) / (v_cell * m)
        # P(k) = P(-k): about (m - 1) / 2 independent exponential modes per frame
        assert abs(p.mean() / expected - 1) < 4 * np.sqrt(2 / ((m - 1) * 20))
        assert res[f"dominant_{plane}"].shape == (0, 2)
    spec = res["spectrum_xy"]
    low, high = spec[1:4, 1:4].mean(), spec[10:20, 5:10].mean()
    assert abs(low / high - 1) < 0.2


@pytest.mark.parametrize(
    ("pattern", "density"),
    [
        ("none", lambda x, y: np.ones_like(x)),
        ("plug", lambda x, y: 1 - 0.5 * np.cos(2 * np.pi * y / W)),
        ("slug", lambda x, y: 1 - 0.5 * np.cos(2 * np.pi * y / W)
         + 0.5 * np.cos(2 * np.pi * x / L)),
        ("s-wave", lambda x, y: 1 - 0.5 * np.cos(2 * np.pi * y / W)
         + 0.5 * np.cos(2 * np.pi * x / L) * np.sin(2 * np.pi * (y / W - 0.5))),
        ("mixed", lambda x, y: 1 - 0.4 * np.cos(2 * np.pi * y / W)
         + 0.35 * np.cos(2 * np.pi * x / L)
         + 0.45 * np.cos(2 * np.pi * x / L) * np.sin(2 * np.pi * (y / W - 0.5))),
    ],
)
def test_constructed_fields_classify(pattern, density):
    """Plug (0,1); slug (0,1) + (1,0), symmetric about the centreline; S-wave (0,1) + (1,1),
    antisymmetric; both together: mixed; uniform: none."""
    rng = np.random.default_rng(3)
    ana = DensityWaves(dim=3, cells=(30, 15, 2)).run(_frames(rng, density))
    assert ana.attrs["pattern"] == pattern
    dom = {tuple(k) for k in ana.results["dominant_xy"]}
    expected = {"none": set(), "plug": {(0, 1)}, "slug": {(0, 1), (1, 0)},
                "s-wave": {(0, 1), (1, 1)}, "mixed": {(0, 1), (1, 0), (1, 1)}}[pattern]
    assert dom == expected
    # averaging over y leaves only the x-variation that does not depend on y in the xz plane
    xz = {tuple(k) for k in ana.results["dominant_xz"]}
    assert xz == ({(1, 0)} if pattern in ("slug", "mixed") else set())


def test_classify_pattern_rule():
    assert classify_pattern(np.zeros((0, 2)), [], []) == "none"
    assert classify_pattern([[0, 1], [0, 2]], [1, 1], [0, 0]) == "plug"
    assert classify_pattern([[0, 1], [2, 1]], [5, 0.1], [0, 1]) == "s-wave"
    assert classify_pattern([[1, 0]], [1], [0]) == "slug"
    assert classify_pattern([[1, 0], [1, 1]], [1, 0], [0, 1]) == "mixed"


def test_amplitude_series_is_bounded_and_follows_a_growing_plug():
    """The plug grows linearly in time: the (0,1) amplitude series grows, and with
    max_series = 8 the 21 frames are kept in at most 9 averaged points."""
    rng = np.random.default_rng(4)
    frames = []
    for t in range(21):
        eps = 0.04 * t
        frames += [Frame(float(t), f.box_lo, f.box_hi, f.position, f.velocity,
                         f.angular_velocity, f.radius)
                   for f in _frames(rng, lambda x, y, e=eps: 1 - e * np.cos(2 * np.pi * y / W),
                                    n=4000, count=1, box=(L, W))]
    res = DensityWaves(dim=2, cells=(30, 15), k_series=2, max_series=8).run(frames).results
    modes = res["series_modes_xy"].tolist()
    series = res["series_xy"][:, modes.index([0, 1])]
    assert len(series) <= 9 and res["series_frames"].sum() == 21
    assert np.all(np.diff(series[:-1]) > 0)
    np.testing.assert_allclose(res["series_time"][0], np.mean(np.arange(res["series_frames"][0])))


def test_lees_edwards_grid_follows_the_sheared_box():
    """A wave periodic in the sheared box, nu ~ 1 + 0.5 cos 2 pi (x - tilt y / L_y) / L_x, is
    the pure (1, 0) mode of the sheared grid."""
    rng = np.random.default_rng(5)
    lx, ly, tilt = 40.0, 20.0, 13.0
    frames = _frames(rng, lambda x, y: 1 + 0.5 * np.cos(2 * np.pi * (x - tilt * y / ly) / lx),
                     n=10000, box=(lx, ly), tilt=tilt)
    res = DensityWaves(dim=2, cells=(20, 10), periodic_y=True).run(frames).results
    assert res["dominant_xy"].tolist() == [[1, 0]]
    nu0 = 10000 * np.pi / 4 / (lx * ly)
    expected = nu0 * 0.5 * _sinc(np.pi / 20)
    assert abs(res["leading_amplitude_xy"][0] - expected) < 0.03 * expected
