"""Marker-path checks of the LGD part of ``demstudy study gutt1989`` (figs 3.29b-3.32b, 3.34b):
a path through the obstacle is counted and one around it is not; free flights under gravity
are found as parabolic arcs with the right g, and a path with contacts or a blocked grain is
not one.

Dimensionless particle units: d = 1 (lattice spacing), m = 1, g = 1.
"""

from __future__ import annotations

import numpy as np

from demstudy.studies.gutt1989 import lgd
from demstudy.studies.gutt1989 import lgd_paths as paths


def disc_nodes(centre=(100.0, 56.0), radius=28.0) -> np.ndarray:
    x, y = np.meshgrid(np.arange(60.0, 140.0), np.arange(20.0, 100.0) * np.sqrt(3) / 2)
    pts = np.column_stack([x.ravel(), y.ravel()])
    return pts[np.hypot(*(pts - centre).T) <= radius]


def test_path_through_the_obstacle_is_counted_and_one_around_it_is_not():
    nodes = disc_nodes()
    x = np.arange(20.0, 200.0, 2.0)
    through = np.column_stack([x, np.full_like(x, 56.0)])
    around = np.column_stack([x, 56.0 + 31.0 * (np.abs(x - 100.0) < 40)])  # steps over it
    grazing = np.column_stack([x, np.full_like(x, 56.0 + 28.8)])  # within the margin
    tracks = np.stack([through, around, grazing], axis=1)
    got = paths.path_crossings(tracks, nodes, 0.0)
    # the crossing path is inside for about the obstacle's width (56 d) in 2 d segments; the
    # one around it and the grazing one never
    assert 20 <= got[0] <= 30 and got[1] == 0 and got[2] == 0
    # unwrapped x: the same path shifted by the period is the same path
    shifted = tracks + np.array([288.0, 0.0])
    np.testing.assert_array_equal(paths.path_crossings(shifted, nodes, 288.0), got)


def ballistic(t, p0, v0, g):
    return p0 + v0 * t[:, None] + 0.5 * g * t[:, None] ** 2, v0 + g * t[:, None]


def test_free_flights_are_parabolic_arcs_with_the_right_g():
    g = np.array([0.4, -np.sqrt(1 - 0.16)])
    t = np.arange(0.0, 4.0, 0.1)
    p1, v1 = ballistic(t, np.array([0.0, 10.0]), np.array([3.0, 2.0]), g)
    # a bounce (velocity reversed along g) then a second flight, then a blocked grain: its
    # velocity grows by g·Δt but it stays put (an LGD grain whose target site is full)
    v_b = v1[-1] - 2 * (v1[-1] @ g) * g
    p2, v2 = ballistic(t, p1[-1], v_b, g)
    p3 = np.repeat(p2[-1:], len(t), axis=0)
    _p, v3 = ballistic(t, p2[-1], v2[-1], g)
    time = np.concatenate([t, t + 4.0, t + 8.0])
    fl = paths.flights(time, np.concatenate([p1, p2, p3]), np.concatenate([v1, v2, v3]), g)
    arcs = [f for f in fl if paths.is_arc(f)]
    assert len(arcs) == 2
    for f in arcs:
        assert abs(f["g"] - 1.0) < 1e-9 and f["rms"] < 1e-9
    # velocities of a grain under 2g without any contact, the same positions (a bounce and a
    # rest): one long "flight" whose positions fit no parabola
    fl2 = paths.flights(time, np.concatenate([p1, p2, p3]),
                        np.concatenate([v1, v2, v3]) * 0 + 2 * g * time[:, None], 2 * g)
    assert not [f for f in fl2 if paths.is_arc(f)]


def test_path_cases_sample_the_thesis_step_counts_finely():
    full = {c.name: c.load().run for c in lgd.cases(False)}
    for shape in ("circle", "square", "triangle-up", "triangle-down"):
        run = full[f"lgd-obstacle-{shape}-paths"]
        assert run.equilibration + run.production == 1536 and run.sample_interval == 2
    run = full["lgd-incline-paths"]
    assert run.equilibration + run.production == 6144 and run.sample_interval == 2
