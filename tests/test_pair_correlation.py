"""Radial and in-bin pair correlation g(r): ideal gas, lattices, hard cores, Lees-Edwards.

Dimensionless particle units: d = 1 (r in diameters), m = 1.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from demstudy.analysis.pair_correlation import PairCorrelation, slab_shell_volume
from demstudy.io.frames import Frame


def frame(pos: np.ndarray, box: np.ndarray, tilt: float = 0.0, t: float = 0.0) -> Frame:
    n, dim = pos.shape
    nrot = 1 if dim == 2 else 3
    return Frame(t, np.zeros(dim), np.asarray(box, float), pos, np.zeros((n, dim)),
                 np.zeros((n, nrot)), np.full(n, 0.5), tilt=tilt)


def ideal_frames(n: int, box, count: int, seed: int = 1):
    rng = np.random.default_rng(seed)
    box = np.asarray(box, float)
    return [frame(rng.uniform(0, box, (n, box.size)), box, t=i) for i in range(count)]


def assert_unity(g: np.ndarray, err: np.ndarray) -> None:
    z = (g - 1) / err
    assert np.all(np.isfinite(z))
    assert np.max(np.abs(z)) < 5.0, np.max(np.abs(z))
    assert abs(np.mean(z)) < 4.0 / np.sqrt(z.size) + 0.3  # no overall bias
    assert 0.5 < np.mean(z**2) < 2.0  # errors of the right size


@pytest.mark.parametrize("periodic_y", [True, False])
@pytest.mark.parametrize("dim", [2, 3])
def test_ideal_gas_whole_box(dim, periodic_y):
    box = [16.0, 12.0] if dim == 2 else [8.0, 7.0, 9.0]
    ana = PairCorrelation(dim, r_max=3.0, dr=0.1, periodic_y=periodic_y)
    ana.run(ideal_frames(300, box, 64, seed=dim + 2 * periodic_y))
    assert_unity(ana.results["g"][0], ana.results["g_err"][0])
    assert not ana.results["image_artefact"].any()


@pytest.mark.parametrize("distance", ["full", "planar"])
@pytest.mark.parametrize("dim", [2, 3])
def test_ideal_gas_in_bins(dim, distance):
    """Malik's in-bin g(r): bins narrower than r_max need the slab-weighted shells."""
    box = [16.0, 12.0] if dim == 2 else [8.0, 9.0, 8.0]
    ana = PairCorrelation(dim, r_max=3.0, dr=0.1, edges_y=[0.0, 1.5, 4.0, 9.0],
                          distance=distance)
    ana.run(ideal_frames(400, box, 64, seed=7 + dim))
    for b in range(3):
        assert_unity(ana.results["g"][b], ana.results["g_err"][b])


def test_slab_shell_volume_exact_in_3d():
    w, edges = 1.3, np.linspace(0, 4, 41)

    def cumulative(r):
        r = np.asarray(r)
        inner = 4 * np.pi * (r**3 / 3 - r**4 / (8 * w))
        return np.where(r <= w, inner, 5 * np.pi * w**3 / 6 + np.pi * w * (r**2 - w**2))

    np.testing.assert_allclose(slab_shell_volume(edges, w, 3), np.diff(cumulative(edges)),
                               rtol=1e-12)
    # a wide slab is the plain shell at small r
    np.testing.assert_allclose(slab_shell_volume(edges[:3], 1e9, 2),
                               np.pi * np.diff(edges[:3] ** 2), rtol=1e-8)


def lattice_shells(ana: PairCorrelation, distances: list[float]) -> list[float]:
    ppp = ana.results["pairs_per_particle"][0]
    r = ana.results["r"]
    return [float(ppp[np.abs(r - d) < 0.04].sum()) for d in distances]


def test_square_and_cubic_lattice_coordination():
    sq = np.array(list(itertools.product(range(10), repeat=2)), float) + 0.25
    ana = PairCorrelation(2, r_max=2.5, dr=0.06, periodic_y=True).run([frame(sq, [10, 10])])
    assert lattice_shells(ana, [1, np.sqrt(2), 2, np.sqrt(5)]) == [4, 4, 4, 8]
    assert ana.results["pairs_per_particle"][0].sum() == 20  # nothing else up to 2.5
    peak = ana.results["g"][0][np.argmin(np.abs(ana.results["r"] - 1))]
    # g at the first peak: 4 partners in a shell of area 2 pi r dr at density 1
    assert peak == pytest.approx(4 / (np.pi * ((17 * 0.06) ** 2 - (16 * 0.06) ** 2)) / (99 / 100))
    cube = np.array(list(itertools.product(range(6), repeat=3)), float) + 0.5
    ana = PairCorrelation(3, r_max=2.5, dr=0.06, periodic_y=True).run([frame(cube, [6, 6, 6])])
    assert lattice_shells(ana, [1, np.sqrt(2), np.sqrt(3), 2]) == [6, 12, 8, 6]
    # the same lattice between walls (y not periodic): the layers at the walls lose partners
    ana = PairCorrelation(3, r_max=1.5, dr=0.06).run([frame(cube, [6, 6, 6])])
    assert lattice_shells(ana, [1])[0] == pytest.approx(6 - 2 / 6)


def test_hard_core_gap():
    rng = np.random.default_rng(3)
    box = np.array([12.0, 12.0])
    frames = []
    for t in range(8):
        pts: list[np.ndarray] = []
        while len(pts) < 70:
            p = rng.uniform(0, box)
            if pts:
                d = np.abs(np.array(pts) - p)
                d = np.minimum(d, box - d)
                if np.min(np.hypot(d[:, 0], d[:, 1])) < 1.0:
                    continue
            pts.append(p)
        frames.append(frame(np.array(pts), box, t=t))
    ana = PairCorrelation(2, r_max=3.0, dr=0.05, periodic_y=True).run(frames)
    g, r = ana.results["g"][0], ana.results["r"]
    assert np.all(g[r < 1.0] == 0)
    assert g[(r > 1.0) & (r < 1.1)].min() > 0.5  # contact peak of a dense-ish RSA packing


def brute_force_counts(pos, box, tilt, edges):
    """Ordered pair counts over explicit images (r_max < half of every period): the image
    at y + k L_y is shifted by k × tilt along x."""
    dim = pos.shape[1]
    counts = np.zeros(edges.size - 1)
    for s in itertools.product(range(-2, 3), [-1, 0, 1], *([[-1, 0, 1]] * (dim - 2))):
        off = np.array(s, float) * box
        off[0] += s[1] * tilt
        d = np.linalg.norm(pos[:, None, :] - (pos[None, :, :] + off), axis=2)
        if not any(s):
            d[np.diag_indices(len(pos))] = np.inf
        counts += np.histogram(d, edges)[0]
    return counts


@pytest.mark.parametrize("dim", [2, 3])
def test_lees_edwards_images_match_brute_force(dim):
    rng = np.random.default_rng(11)
    box = np.array([9.0, 8.0] if dim == 2 else [9.0, 8.0, 7.0])
    pos = rng.uniform(0, box, (80, dim))
    for tilt in (0.0, 2.7, -4.1):
        ana = PairCorrelation(dim, r_max=3.4, dr=0.2, periodic_y=True)
        ana.run([frame(pos, box, tilt=tilt)])
        expected = brute_force_counts(pos, box, tilt, ana.r_edges)
        np.testing.assert_allclose(ana.results["pairs_per_particle"][0] * len(pos), expected)
        # centres given outside the box along y (lazy wrapping) are mapped to their image
        moved = pos.copy()
        moved[::4, 1] += box[1]
        moved[::4, 0] += tilt
        moved[1::4, 1] -= box[1]
        moved[1::4, 0] -= tilt
        again = PairCorrelation(dim, r_max=3.4, dr=0.2, periodic_y=True)
        again.run([frame(moved, box, tilt=tilt)])
        np.testing.assert_allclose(again.results["pairs_per_particle"], ana.results[
            "pairs_per_particle"], rtol=1e-12)


def test_image_artefacts_are_flagged():
    with pytest.warns(UserWarning, match="images"):
        ana = PairCorrelation(2, r_max=6.0, dr=0.5).run(ideal_frames(50, [10.0, 30.0], 2))
    assert ana.attrs["r_image_limit"] == 5.0
    np.testing.assert_array_equal(ana.results["image_artefact"], ana.r_edges[1:] > 5.0)
