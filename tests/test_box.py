"""The Box layer: wrapping with Lees-Edwards images, minimum images and pair queries.

Dimensionless particle units: d = 1 (lengths in diameters), velocities in d per time unit.
Every expectation is computed independently: by hand for the wrap, by brute force over
explicit periodic images for distances and pair counts.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from demstudy.analysis.box import Box, NeighbourQuery
from demstudy.io.frames import Frame


def le_box(dim: int = 2, tilt: float = 3.0, shear_velocity: float = 3.2,
           lo: tuple[float, ...] = (0.0, 0.0, 0.0)) -> Box:
    lengths = [10.0, 8.0, 6.0][:dim]
    return Box(lo[:dim], lengths, (True,) * dim, tilt=tilt, shear_velocity=shear_velocity)


# -- wrap ------------------------------------------------------------------------------------
def test_leaving_through_the_top_reenters_at_the_bottom_shifted_by_the_image():
    box = le_box(2, tilt=3.0, shear_velocity=3.2)  # L = (10, 8), gamma_dot L_y = 3.2
    pos = np.array([[2.0, 8.5], [9.5, -0.25], [4.0, 17.0], [5.0, 4.0]])
    vel = np.array([[1.0, 0.2], [0.5, 0.0], [0.0, 0.0], [0.7, -0.1]])
    w = box.wrap(pos, vel)
    # top: y - 8, x - 3 (-1 -> 9 after the x wrap), u - 3.2
    # bottom: y + 8, x + 3 (12.5 -> 2.5), u + 3.2; two periods up: x - 6 -> -2 -> 8
    assert np.allclose(w.position, [[9.0, 0.5], [2.5, 7.75], [8.0, 1.0], [5.0, 4.0]],
                       rtol=0, atol=1e-12)
    assert np.allclose(w.velocity, [[1.0 - 3.2, 0.2], [0.5 + 3.2, 0.0], [-6.4, 0.0],
                                    [0.7, -0.1]], rtol=0, atol=1e-12)
    assert w.image.tolist() == [[-1, 1], [1, -1], [-1, 2], [0, 0]]
    # the inputs are untouched
    assert pos[0].tolist() == [2.0, 8.5] and vel[0].tolist() == [1.0, 0.2]


def test_wrap_in_3d_with_an_offset_box_moves_z_independently():
    box = le_box(3, tilt=-2.5, shear_velocity=1.5, lo=(-5.0, 1.0, 2.0))  # hi = (5, 9, 8)
    w = box.wrap([[4.0, 9.25, 9.0]], [[0.0, 1.0, 2.0]])
    assert np.allclose(w.position, [[-3.5, 1.25, 3.0]], rtol=0, atol=1e-12)  # x: 4 + 2.5 - 10
    assert np.allclose(w.velocity, [[-1.5, 1.0, 2.0]], rtol=0, atol=1e-12)
    assert w.image.tolist() == [[1, 1, 1]]


def test_without_shear_or_with_a_bounded_y_the_velocities_stay():
    walls = Box([0.0, 0.0], [10.0, 8.0], (True, False))
    w = walls.wrap([[11.0, 9.0], [-1.0, -0.5]], [[1.0, 2.0], [3.0, 4.0]])
    assert np.allclose(w.position, [[1.0, 9.0], [9.0, -0.5]])  # y is never wrapped
    assert np.array_equal(w.velocity, [[1.0, 2.0], [3.0, 4.0]])
    assert walls.wrap([[11.0, 9.0]]).velocity is None


@pytest.mark.parametrize("dim", [2, 3])
def test_wrap_undoes_random_image_moves_and_is_idempotent(dim):
    rng = np.random.default_rng(7)
    box = le_box(dim, tilt=4.3, shear_velocity=2.0, lo=(-3.0, 0.7, 11.0))
    n = 2000
    inside = box.lo + rng.uniform(0, 1, (n, dim)) * box.lengths
    vel = rng.normal(0, 1, (n, dim))
    k = rng.integers(-3, 4, (n, dim))
    moved = inside + k * box.lengths
    moved[:, 0] += k[:, 1] * box.tilt  # the image rule: y + k L_y sits at x + k tilt ...
    moved_vel = vel.copy()
    moved_vel[:, 0] += k[:, 1] * box.shear_velocity  # ... and moves with u + k gamma_dot L_y
    w = box.wrap(moved, moved_vel)
    assert np.allclose(w.position, inside, rtol=0, atol=1e-12)
    assert np.allclose(w.velocity, vel, rtol=0, atol=1e-12)
    assert np.array_equal(w.image[:, 1], k[:, 1])
    again = box.wrap(w.position, w.velocity)
    assert np.array_equal(again.position, w.position)
    assert np.array_equal(again.velocity, w.velocity)
    assert not again.image.any()
    # points already inside come back bit for bit
    assert np.array_equal(box.wrap(inside).position, inside)


def test_wrap_keeps_round_off_cases_strictly_inside_and_consistent():
    box = Box([0.1, 0.3], [0.7, 0.9], (True, True), tilt=0.2)
    below, top = np.nextafter(0.3, 0.0), np.nextafter(1.2, 0.0)
    y = np.array([-1e-17, -np.finfo(float).eps, below, top, 1.2, np.nextafter(1.2, 2.0),
                  np.nextafter(2.1, 0.0), 0.3 - 1e-16])
    pos = np.stack([np.full(y.size, np.nextafter(0.8, 0.0)), y], axis=1)
    w = box.wrap(pos)
    rel = w.position - box.lo
    assert np.all(rel >= 0) and np.all(rel < box.lengths)  # cKDTree refuses x == L
    # the reported images explain the move, the tilt included (no stray tilt at an edge)
    back = w.position + w.image * box.lengths
    back[:, 0] += w.image[:, 1] * box.tilt
    assert np.allclose(back, pos, rtol=0, atol=1e-12)


# -- minimum image ---------------------------------------------------------------------------
def brute_minimum_image(d: np.ndarray, box: Box) -> np.ndarray:
    """Shortest of the explicit images d + n_x L_x + k (tilt, L_y) + n_z L_z."""
    reach = range(-4, 5) if box.dim < 3 else range(-3, 4)  # enough for these boxes
    ranges = [reach if p else range(1) for p in box.periodic]
    best = np.full(d.shape[0], np.inf)
    out = d.copy()
    for shift in itertools.product(*ranges):
        c = d + np.asarray(shift) * box.lengths
        if box.dim > 1:
            c[:, 0] += shift[1] * box.tilt
        n2 = (c * c).sum(1)
        better = n2 < best
        out[better], best[better] = c[better], n2[better]
    return out


BOXES = [
    ("2d periodic", ([0.0, 0.0], [9.0, 7.0], (True, True), 0.0)),
    ("2d tilt", ([0.0, 0.0], [9.0, 7.0], (True, True), 3.7)),
    ("2d flat box, large tilt", ([0.0, 0.0], [30.0, 5.0], (True, True), 14.0)),
    ("2d walls", ([0.0, -2.0], [9.0, 7.0], (True, False), 0.0)),
    ("3d periodic", ([1.0, 0.0, -3.0], [8.0, 7.0, 6.0], (True, True, True), 0.0)),
    ("3d tilt", ([1.0, 0.0, -3.0], [8.0, 7.0, 6.0], (True, True, True), -3.1)),
    ("3d walls", ([1.0, 0.0, -3.0], [8.0, 7.0, 6.0], (True, False, True), 0.0)),
]


@pytest.mark.parametrize("name, spec", BOXES, ids=[b[0] for b in BOXES])
def test_minimum_image_matches_brute_force(name, spec):
    lo, lengths, periodic, tilt = spec
    box = Box(lo, lengths, periodic, tilt=tilt)
    rng = np.random.default_rng(3)
    a = box.lo + rng.uniform(-0.2, 1.2, (3000, box.dim)) * box.lengths
    b = box.lo + rng.uniform(-0.2, 1.2, (3000, box.dim)) * box.lengths
    d = box.minimum_image(b - a)
    expected = brute_minimum_image(b - a, box)
    assert np.allclose(np.linalg.norm(d, axis=1), np.linalg.norm(expected, axis=1),
                       rtol=0, atol=1e-9)
    assert np.allclose(d, expected, rtol=0, atol=1e-9)
    if name == "2d flat box, large tilt":
        # the nearest image is often not in the nearest y period: a per-axis rounding
        # (y first, then x) would be wrong here
        naive = (b - a).copy()
        k = np.round(naive[:, 1] / box.lengths[1])
        naive[:, 1] -= k * box.lengths[1]
        naive[:, 0] -= k * box.tilt
        naive[:, 0] -= box.lengths[0] * np.round(naive[:, 0] / box.lengths[0])
        assert np.mean(np.linalg.norm(naive, axis=1)
                       > np.linalg.norm(expected, axis=1) + 1e-9) > 0.01


# -- pair queries ----------------------------------------------------------------------------
def brute_distances(points: np.ndarray, box: Box) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(i, j, r) of all ordered pairs i != j, r the brute-force minimum-image distance."""
    n = points.shape[0]
    i, j = np.nonzero(~np.eye(n, dtype=bool))
    d = brute_minimum_image(points[j] - points[i], box)
    return i, j, np.linalg.norm(d, axis=1)


def random_points(box: Box, n: int, seed: int, outside: float = 0.0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return box.lo + rng.uniform(-outside, 1 + outside, (n, box.dim)) * box.lengths


@pytest.mark.parametrize("name, spec", BOXES, ids=[b[0] for b in BOXES])
def test_pair_counts_match_brute_force(name, spec):
    lo, lengths, periodic, tilt = spec
    box = Box(lo, lengths, periodic, tilt=tilt)
    r_edges = np.linspace(0.0, 0.95 * min(box.image_limit, 3.4), 25)
    # centres slightly outside along every axis: the query wraps them (with the LE rule)
    pts = random_points(box, 400, seed=11, outside=0.05)
    counts = NeighbourQuery(box, pts).count(r_edges)
    wrapped = box.wrap(pts).position
    _, _, r = brute_distances(wrapped, box)
    expected = np.bincount(np.searchsorted(r_edges, r[r <= r_edges[-1]], side="left") - 1,
                           minlength=r_edges.size - 1)
    assert counts.sum() > 1000
    assert np.array_equal(counts, expected)


@pytest.mark.parametrize("name, spec", BOXES, ids=[b[0] for b in BOXES])
def test_pairs_match_brute_force(name, spec):
    lo, lengths, periodic, tilt = spec
    box = Box(lo, lengths, periodic, tilt=tilt)
    r_max = 0.9 * min(box.image_limit, 3.0)
    pts = random_points(box, 300, seed=5, outside=0.05)
    of = np.arange(0, 300, 3)
    bi, bj, br = brute_distances(box.wrap(pts).position, box)
    for chosen, chunk in ((None, 4096), (None, 17), (of, 7)):
        i, j, r = NeighbourQuery(box, pts).pairs(r_max, of=chosen, chunk=chunk)
        near = br <= r_max
        if chosen is not None:
            near &= np.isin(bi, chosen)
        got = sorted(zip(i.tolist(), j.tolist(), np.round(r, 9).tolist(), strict=True))
        want = sorted(zip(bi[near].tolist(), bj[near].tolist(), np.round(br[near], 9).tolist(),
                          strict=True))
        assert len(got) > 100
        assert got == want


def test_bounded_y_sees_no_partner_across_the_boundary_and_walls_none_either():
    sheared = Box([0.0, 0.0], [10.0, 8.0], (True, True), tilt=2.0)
    # 1's image below sits at (1.0, -0.1): 0.2 from 0 and 3.26 from 2 (directly 5.0)
    pts = np.array([[1.0, 0.1], [3.0, 7.9], [2.0, 3.0]])
    i, j, r = NeighbourQuery(sheared, pts).pairs(0.5)
    assert sorted(zip(i.tolist(), j.tolist(), strict=True)) == [(0, 1), (1, 0)]
    assert r == pytest.approx([0.2, 0.2])
    edges = [0.0, 0.5, 3.9]  # below the image limit L_y / 2 = 4
    assert NeighbourQuery(sheared, pts).count(edges).tolist() == [2, 4]
    for box in (sheared.with_bounded_y(), Box([0.0, 0.0], [10.0, 8.0], (True, False),
                                              walls=(0.0, 8.0))):
        assert NeighbourQuery(box, pts).pairs(0.5).i.size == 0
        assert NeighbourQuery(box, pts).count(edges).tolist() == [0, 2]  # 0-2 at 3.07


def test_a_bounded_y_takes_centres_far_outside_the_box():
    # an open boundary: box_lo / box_hi need not bound the centres along y
    box = Box([0.0, 2.0, 0.0], [7.0, 5.0, 6.0], (True, False, True))
    rng = np.random.default_rng(2)
    pts = rng.uniform([0.0, -20.0, 0.0], [7.0, 30.0, 6.0], (600, 3))
    r_edges = np.linspace(0.0, 2.9, 30)
    _, _, r = brute_distances(pts, box)
    expected = np.bincount(np.searchsorted(r_edges, r[r <= r_edges[-1]], side="left") - 1,
                           minlength=r_edges.size - 1)
    assert expected.sum() > 500
    assert np.array_equal(NeighbourQuery(box, pts).count(r_edges), expected)


def test_planar_projection_drops_y_and_the_tilt():
    box = Box([0.0, 0.0, 0.0], [10.0, 8.0, 6.0], (True, True, True), tilt=3.0,
              shear_velocity=1.0)
    plane = box.project([0, 2])
    assert plane.dim == 2 and plane.tilt == 0.0 and plane.shear_velocity == 0.0
    assert plane.lengths.tolist() == [10.0, 6.0]
    pts = np.array([[0.2, 1.0, 0.1], [9.9, 7.0, 5.9]])  # 0.3 apart in x, 0.2 in z
    i, _, r = NeighbourQuery(plane, pts[:, [0, 2]]).pairs(1.0)
    assert i.size == 2 and r == pytest.approx([np.hypot(0.3, 0.2)] * 2)
    line = Box([0.0, 0.0], [10.0, 8.0], (True, True)).project([0])
    assert NeighbourQuery(line, [[0.25], [9.75], [5.0]]).count([0.0, 0.5, 1.0]).tolist() \
        == [2, 0]


# -- the Box and the Frame -------------------------------------------------------------------
def test_box_refuses_inconsistent_geometry_and_is_immutable():
    with pytest.raises(ValueError, match="periodic x and y"):
        Box([0.0, 0.0], [1.0, 1.0], (True, False), tilt=0.5)
    with pytest.raises(ValueError, match="walls"):
        Box([0.0, 0.0], [1.0, 1.0], (True, True), walls=(0.0, 1.0))
    with pytest.raises(ValueError, match="positive"):
        Box([0.0, 0.0], [1.0, 0.0], (True, True))
    box = Box([0.0, 0.0], [1.0, 2.0], (True, True))
    with pytest.raises(ValueError):
        box.lo[0] = 3.0
    with pytest.raises(AttributeError):
        box.tilt = 1.0  # type: ignore[misc]
    with pytest.raises(ValueError, match=r"\(N, 2\)"):
        box.wrap(np.zeros((3, 3)))


def make_frame(tilt: float = 0.0, **fields) -> Frame:
    n = 4
    return Frame(0.0, np.zeros(2), np.array([10.0, 8.0]), np.zeros((n, 2)), np.zeros((n, 2)),
                 np.zeros((n, 1)), np.full(n, 0.5), tilt, **fields)


def test_frame_box_from_its_fields_and_the_analyses_arguments():
    walls = make_frame().box
    assert walls.periodic == (True, False) and walls.tilt == 0.0
    le = make_frame(2.5, periodic_y=True, shear_velocity=4.0).box
    assert le.periodic == (True, True) and le.tilt == 2.5 and le.shear_velocity == 4.0
    assert le.lengths.tolist() == [10.0, 8.0] and le.hi.tolist() == [10.0, 8.0]
    with pytest.raises(ValueError, match="periodic_y"):
        _ = make_frame(2.5).box  # sheared but not saying so
    # an analysis's own arguments win over the frame's defaults
    box = Box.from_frame(make_frame(2.5), periodic_y=True, shear_velocity=1.0)
    assert box.periodic == (True, True) and box.tilt == 2.5 and box.shear_velocity == 1.0
    assert Box.from_frame(make_frame(2.5, periodic_y=True), periodic_y=False).tilt == 0.0
