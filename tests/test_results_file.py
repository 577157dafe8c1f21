"""Atomic writes of results files and checkpoints (demstudy.io.results, engines.common).

A failing disk must give a plain OSError and leave the previous file intact, with no partial
or temporary file behind. The failure is injected at the flush to disk (os.fsync), after the
bytes went to the temporary file. Dimensionless particle units throughout.
"""

from __future__ import annotations

import errno
import os
import pickle

import numpy as np
import pytest

from demstudy import UNITS_NOTE
from demstudy.io.results import Results, read_results, write_results
from demstudy.simulation.checkpoint import pickle_atomically


def results(scale: float) -> Results:
    t = np.linspace(0.0, 1.0, 5)
    return Results(attrs={"engine": "synthetic"},
                   timeseries={"time": t, "kinetic_energy": scale * (1 + t)},
                   profiles={"y": np.arange(3.0), "density": scale * np.ones((5, 3))},
                   groups={"stress": {"collisional": scale * np.ones((5, 3, 3, 3))}})


def full_disk(monkeypatch):
    def fail(fd):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    monkeypatch.setattr(os, "fsync", fail)


def test_results_round_trip_with_units(tmp_path):
    path = write_results(tmp_path / "r.h5", results(2.0))
    back = read_results(path)
    assert back.attrs["units"] == UNITS_NOTE and back.attrs["engine"] == "synthetic"
    t = np.linspace(0.0, 1.0, 5)
    np.testing.assert_array_equal(back.timeseries["kinetic_energy"], 2.0 * (1 + t))
    np.testing.assert_array_equal(back.groups["stress"]["collisional"], 2.0 * np.ones((5, 3, 3, 3)))
    assert [p.name for p in tmp_path.iterdir()] == ["r.h5"]


def test_a_full_disk_leaves_the_previous_results_intact(tmp_path, monkeypatch):
    path = write_results(tmp_path / "r.h5", results(1.0))
    full_disk(monkeypatch)
    with pytest.raises(OSError, match="No space left"):
        write_results(path, results(5.0))
    assert [p.name for p in tmp_path.iterdir()] == ["r.h5"]  # no temporary file
    assert read_results(path).timeseries["kinetic_energy"][0] == 1.0  # the old content


def test_a_full_disk_leaves_the_previous_checkpoint_intact(tmp_path, monkeypatch):
    path = tmp_path / "checkpoint.pkl"
    pickle_atomically(path, {"t": 1.0})
    full_disk(monkeypatch)
    with pytest.raises(OSError, match="No space left"):
        pickle_atomically(path, {"t": 2.0})
    assert [p.name for p in tmp_path.iterdir()] == ["checkpoint.pkl"]
    assert pickle.loads(path.read_bytes()) == {"t": 1.0}
