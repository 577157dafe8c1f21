"""Results files (demstudy.io.results, engines.common): atomic writes of results files and
checkpoints, attribute types, units and descriptions of every dataset, provenance.

A failing disk must give a plain OSError and leave the previous file intact, with no partial
or temporary file behind. The failure is injected at the flush to disk (os.fsync), after the
bytes went to the temporary file. Dimensionless particle units throughout.
"""

from __future__ import annotations

import errno
import json
import os
import pickle
import platform
import shlex
import sys

import h5py
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


def test_a_damaged_results_file_is_refused_by_name(tmp_path, capsys):
    """A results file whose tail was zeroed (a crash of the disk, not of the writer) or that
    is no HDF5 at all: read_results raises BadInputFile naming the file, and `analyze` and
    `plot` end with exit 2 and that message, no traceback, nothing written."""
    from demstudy.cli import main
    from demstudy.errors import BadInputFile

    big = results(1.0)
    big.timeseries = {"time": np.linspace(0.0, 1.0, 20000),
                      "kinetic_energy": np.linspace(1.0, 2.0, 20000)}
    path = write_results(tmp_path / "r.h5", big)
    assert read_results(path).timeseries["time"].size == 20000  # intact: it reads
    size = path.stat().st_size
    with open(path, "r+b") as fh:
        fh.seek(size // 2)
        fh.write(bytes(size - size // 2))
    junk = tmp_path / "junk.h5"
    junk.write_bytes(b"not hdf5" * 10)
    for bad in (path, junk, tmp_path / "absent.h5"):
        with pytest.raises(BadInputFile, match=f"results file {bad}"):
            read_results(bad)
        for argv in (["analyze", str(bad), "--what", "profiles"],
                     ["plot", str(bad), "--out", str(tmp_path / "f.png")]):
            assert main(argv) == 2, argv
            err = capsys.readouterr().err
            assert err.startswith(f"error: results file {bad}") and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["junk.h5", "r.h5"]


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


# ------------------------------------------------------------------ attribute types
ATTRS = {
    "an_int": 3, "a_float": 2.5, "a_bool": True, "false": False, "a_str": "text ✓",
    "nothing": None, "numpy_int": np.int32(4), "numpy_float": np.float32(1.5),
    "numpy_bool": np.bool_(False), "a_dict": {"a": 1, "b": [1.0, 2.5], "c": None, "d": "x"},
    "a_list": [1, 2.5, 3], "a_tuple": (1, 2), "strings": ["u", "v"], "empty": [],
    "array": np.arange(3.0), "nan": float("nan"),
}
EXPECTED = {**ATTRS, "numpy_int": 4, "numpy_float": 1.5, "numpy_bool": False,
            "a_tuple": [1, 2]}


def same(a, b) -> bool:
    if isinstance(b, np.ndarray):
        return isinstance(a, np.ndarray) and np.array_equal(a, b)
    if isinstance(b, float) and np.isnan(b):
        return isinstance(a, float) and np.isnan(a)
    return type(a) is type(b) and a == b


def test_attributes_keep_their_python_types(tmp_path):
    res = Results(attrs=dict(ATTRS), timeseries={"time": np.arange(3.0)},
                  profiles={"y": np.arange(2.0)}, profile_attrs=dict(ATTRS),
                  groups={"statistics/x": {"a": np.ones(2)}},
                  group_attrs={"statistics/x": dict(ATTRS)})
    back = read_results(write_results(tmp_path / "r.h5", res))
    for attrs in (back.attrs, back.profile_attrs, back.group_attrs["statistics/x"]):
        for key, value in EXPECTED.items():
            assert same(attrs[key], value), (key, attrs[key], value)
        assert "json_attributes" not in attrs
    assert type(back.attrs["format_version"]) is int
    # other readers see plain HDF5 types and JSON text, listed in json_attributes
    with h5py.File(tmp_path / "r.h5") as f:
        assert json.loads(f.attrs["a_dict"]) == ATTRS["a_dict"]
        assert f.attrs["nothing"] == "null"
        assert set(json.loads(f.attrs["json_attributes"])) == {
            "nothing", "a_dict", "a_list", "a_tuple", "strings", "empty"}


def test_a_none_attribute_no_longer_fails_the_write(tmp_path):
    """h5py cannot store None: it used to abort the write (and a run's results with it)."""
    res = Results({"engine": "synthetic"}, groups={"stress": {"y": np.arange(2.0)}},
                  group_attrs={"stress": {"contact_samples": None}})
    back = read_results(write_results(tmp_path / "r.h5", res))
    assert back.group_attrs["stress"]["contact_samples"] is None


def test_root_records_command_line_versions_and_time_unit(tmp_path, monkeypatch):
    from demstudy import __version__
    from demstudy.io.results import COMMAND_LINE_ENV, set_command_line
    from demstudy.scene import load_scene, scene_to_toml

    monkeypatch.setenv(COMMAND_LINE_ENV, "")  # restored after the test
    monkeypatch.delenv(COMMAND_LINE_ENV)
    scene = scene_to_toml(load_scene("campbell1982/chute-30"))
    attrs = {"engine": "synthetic", "engine_version": "x 1.0", "scene_toml": scene}
    plain = read_results(write_results(tmp_path / "a.h5", Results(dict(attrs)))).attrs
    assert plain["command_line"] == shlex.join(sys.argv)
    assert plain["demstudy_version"] == __version__ and plain["engine_version"] == "x 1.0"
    assert plain["python_version"] == platform.python_version()
    assert plain["numpy_version"] == np.__version__ and plain["h5py_version"] == h5py.__version__
    assert plain["time_unit"] == "τ = √(d/g): gravity g = 1 d/τ²"
    assert "last_written_by" not in plain
    given = write_results(tmp_path / "b.h5", Results(dict(attrs)), command_line="demstudy x")
    assert read_results(given).attrs["command_line"] == "demstudy x"
    set_command_line(["demstudy", "run", "a b.toml"])  # what the CLI records for its children
    first = read_results(write_results(tmp_path / "c.h5", Results(dict(attrs))))
    assert first.attrs["command_line"] == "demstudy run 'a b.toml'"
    # written again (demstudy analyze): the run's provenance stays, the rewrite is noted
    set_command_line(["demstudy", "analyze", "c.h5"])
    again = read_results(write_results(tmp_path / "c.h5", first)).attrs
    assert again["command_line"] == "demstudy run 'a b.toml'"
    assert again["created"] == first.attrs["created"]
    assert again["last_written_by"].startswith("demstudy analyze c.h5 (demstudy ")
    no_scene = read_results(write_results(tmp_path / "d.h5", Results({}))).attrs
    assert no_scene["time_unit"].startswith("not recorded")


# ------------------------------------------------------------------ dataset units
def test_every_dataset_has_units_and_a_description(tmp_path):
    from demstudy.io.fields import UNKNOWN_UNITS

    res = Results({"engine": "synthetic"},
                  timeseries={"time": np.arange(3.0), "kinetic_energy": np.ones(3),
                              "invented": np.ones(3)},
                  profiles={"y": np.arange(2.0), "temperature": np.ones(2),
                            "temperature_err": np.ones(2)},
                  groups={"statistics/waves": {"spectrum_xz": np.ones((2, 2)),
                                               "spectrum_xz_err": np.ones((2, 2))},
                          "statistics/new": {"thing_err": np.ones(2)}},
                  dataset_attrs={"timeseries/invented": {"note": "given by the caller"}})
    path = write_results(tmp_path / "r.h5", res)
    with h5py.File(path) as f:
        info = {name: dict(obj.attrs) for name, obj in _datasets(f)}
    assert all(a["units"] and a["description"] for a in info.values())
    assert info["timeseries/time"]["units"] == "τ"
    assert info["profiles/temperature_err"]["description"] == \
        "standard error of " + info["profiles/temperature"]["description"]
    assert info["profiles/temperature_err"]["units"] == "m d^2/τ^2"
    assert "plane xz" in info["statistics/waves/spectrum_xz_err"]["description"]
    assert info["timeseries/invented"]["units"] == UNKNOWN_UNITS
    assert "/timeseries" in info["timeseries/invented"]["description"]
    assert info["timeseries/invented"]["note"] == "given by the caller"
    assert info["statistics/new/thing_err"]["description"].startswith("standard error of")
    back = read_results(path)
    assert back.dataset_attrs["timeseries/time"]["units"] == "τ"


def _datasets(f: h5py.File) -> list[tuple[str, h5py.Dataset]]:
    found = []
    f.visititems(lambda name, obj: found.append((name, obj))
                 if isinstance(obj, h5py.Dataset) else None)
    return found


def test_every_dataset_of_real_runs_is_in_the_units_table(tmp_path):
    """Event-driven runs and every analysis (2D servo Couette, 3D Lees–Edwards with the
    collision log): no dataset falls back to 'see docs'; stresses carry the dimension's
    units; the root says what τ is. ~5 s."""
    from demstudy.cli import main
    from demstudy.io.fields import UNKNOWN_UNITS

    couette, shear = tmp_path / "couette.h5", tmp_path / "shear.h5"
    assert main(["run", "campbell1982/couette-rough", "--engine", "edmd", "-q",
                 "--keep-frames", "--set", "run.production=5",
                 "--set", 'measure.statistics=["profiles", "stress"]', "--out", str(couette)]) == 0
    assert main(["analyze", str(couette), "--what",
                 "profiles,vdf,gr,vcorr,waves,cgprofiles,stress,structure"]) == 0
    assert main(["run", "shear/lees-edwards-3d", "--engine", "edmd", "-q",
                 "--set", "run.production=1", "--set", "run.equilibration=0.5",
                 "--set", "run.sample_interval=0.5", "--set", "measure.keep_frames=true",
                 "--set", 'measure.statistics=["angles","stress"]', "--out", str(shear)]) == 0
    assert main(["analyze", str(shear), "--what", "lambda,angles,freepath,waves"]) == 0
    for path, stress_units, unit in (
            (couette, "m/τ^2 (force per length)", "τ = d/U: the upper wall moves at U = 1 d/τ"),
            (shear, "m/(d τ^2) (force per area)", "τ = 1/γ̇ (strain units): shear rate γ̇ = 1/τ")):
        with h5py.File(path) as f:
            assert f.attrs["time_unit"] == unit
            assert f.attrs["engine_version"].startswith("demstudy-edmd")
            for key in ("command_line", "demstudy_version", "python_version", "numpy_version",
                        "h5py_version"):
                assert f.attrs[key], key
            found = _datasets(f)
            missing = [n for n, d in found if d.attrs.get("units") in (None, "", UNKNOWN_UNITS)
                       or not d.attrs.get("description")]
            assert not missing, missing
            assert f["stress/total"].attrs["units"] == stress_units
            assert len(found) > 60
