"""Marked-grain paths (``/tracks``) through the simulation loop with the LGD engine: the tracked
grains are the frames' grains with those marks, x is unwrapped across the periodic boundary,
a resumed run gives the same tracks, and scenes without markers get none.

Units: particle units (d = 1 = lattice spacing, m = 1; without gravity the grains' initial
r.m.s. speed is the speed unit); md lines in the listing's integers.
"""

from __future__ import annotations

import numpy as np

from demstudy.engines.lgd import backend as lgd_backend
from demstudy.errors import EngineError
from demstudy.io.results import read_results
from tests.test_lgd_backend import backend_of, gas, run

NXT = 24


def marked_gas(**changes) -> dict:
    """Gutt's gas box (24 × 14, elastic) with two marked grains (md > 10) moving ±x."""
    data = gas(**changes)
    data["lattice"]["initial"] += [{"md": 11, "x1": 3, "y1": 4, "vx": 1024},
                                   {"md": 12, "x1": 20, "y1": 10, "vx": -1024}]
    return data


def steps_of(data: dict, production: int, interval: int) -> dict:
    return {**data, "run": {"equilibration": 0, "production": production,
                            "sample_interval": interval, "unit": "steps"}}


def test_marked_grains_are_the_frames_grains_with_those_marks(tmp_path):
    backend = backend_of(marked_gas(), tmp_path)
    for _ in range(5):
        frame, record = backend.frame(), backend.marked()
        assert sorted(record["mark"]) == [1, 2] and record["period"] == NXT
        for mark, p, v in zip(record["mark"], record["position"], record["velocity"],
                              strict=True):
            i = np.flatnonzero(frame.extra["mark"] == mark)
            assert len(i) == 1  # one grain per marker number
            np.testing.assert_array_equal(frame.position[i[0]], p)
            np.testing.assert_array_equal(frame.velocity[i[0]], v)
        backend.advance_steps(backend.steps + 7)


def test_tracks_are_stored_unwrapped_and_read_back(tmp_path):
    data = steps_of(marked_gas(), 200, 4)
    res = run(data, tmp_path / "t.h5", keep_frames=True)
    tracks = res.groups["tracks"]
    np.testing.assert_array_equal(tracks["mark"], [1, 2])
    np.testing.assert_array_equal(tracks["time"], res.timeseries["time"])  # every sample
    pos, vel = tracks["position"], tracks["velocity"]
    assert pos.shape == vel.shape == (51, 2, 2) and np.isfinite(pos).all()
    assert res.dataset_attrs["tracks/position"]["units"] == "d"
    # initial state: the md lines' nodes (user column ix, row iy: x = ix + ((iy − 1) mod 2)/2,
    # y = (iy − 1)·√3/2)
    np.testing.assert_allclose(pos[0], [[3.5, 3 * np.sqrt(3) / 2], [20.5, 9 * np.sqrt(3) / 2]])
    np.testing.assert_array_equal(vel[0], [[1.0, 0.0], [-1.0, 0.0]])
    # continuous: a grain moves at most one spacing per step (4 steps per sample), yet the
    # paths leave the box: x was unwrapped, and wraps back onto the frames' grains
    assert np.abs(np.diff(pos[:, :, 0], axis=0)).max() <= 4 + 1e-9
    assert (pos[:, :, 0] < 0).any() or (pos[:, :, 0] >= NXT).any()
    frames = res.frames
    for k, t in enumerate(frames["time"]):
        j = int(np.flatnonzero(tracks["time"] == t)[0])
        for m in range(2):
            wrapped = np.array([pos[j, m, 0] % NXT, pos[j, m, 1]])
            hit = np.flatnonzero(np.all(np.isclose(frames["position"][k], wrapped), axis=1))
            assert len(hit) == 1
            np.testing.assert_array_equal(frames["velocity"][k][hit[0]], vel[j, m])


def test_resumed_run_gives_the_uninterrupted_tracks(tmp_path, monkeypatch):
    data = steps_of(marked_gas(), 60, 10)
    whole = read_results(run(data, tmp_path / "w.h5").path)
    monkeypatch.setattr(lgd_backend, "CHUNK", 7)  # stops inside the sample intervals too
    out, stops = tmp_path / "p.h5", 0
    for _ in range(50):
        try:
            run(data, out, wall_limit=0.0, resume=(tmp_path / "p.lgd").exists())
            break
        except EngineError as stopped:
            assert "--resume" in str(stopped)
            stops += 1
    assert stops == 11  # each interval of 10 steps: a chunk of 7 (stop inside), then 3
    parts = read_results(out)
    assert parts.groups["tracks"]["time"].shape == (7,)
    for key, value in whole.groups["tracks"].items():
        np.testing.assert_array_equal(value, parts.groups["tracks"][key], err_msg=key)


def test_no_tracks_without_marked_grains(tmp_path):
    assert backend_of(gas(), tmp_path).marked() is None
    res = run(steps_of(gas(), 20, 10), tmp_path / "n.h5")
    assert "tracks" not in res.groups
