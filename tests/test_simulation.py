"""The one simulation loop: a third backend added without touching it, statistics honoured or
refused by name, engine options checked. Units: d = 1, m = 1 (no gravity: the initial
temperature sets the time scale).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from ballistic_backend import BallisticBackend

from demstudy.analysis.registry import STATISTICS
from demstudy.engines import backend_names, get_backend, register_backend
from demstudy.errors import EngineError, UnsupportedByEngine
from demstudy.io.results import read_results
from demstudy.scene import SceneError, scene_to_toml, validate_scene
from demstudy.simulation import RunOptions, Simulation, run_scene

GAS = {"dimension": 2, "box": {"size": [12.0, 12.0]}, "particles": {"count": 40},
       "contact": {"restitution": 1.0}, "initial": {"velocity": {"temperature": 1.0}},
       "run": {"equilibration": 1.0, "production": 4.0, "sample_interval": 0.5}}


def gas(**changes):
    data = {**GAS, **changes}
    return validate_scene(data)


@pytest.fixture(autouse=True)
def ballistic(monkeypatch):
    """The third backend, registered for these tests only (register_backend in a user's
    code; here the registry is restored afterwards)."""
    from demstudy import engines

    monkeypatch.setattr(engines, "_BACKENDS", dict(engines._BACKENDS))
    register_backend(BallisticBackend)


def test_a_third_backend_runs_through_the_loop_unchanged(tmp_path):
    """Ballistic particles: x(t) = x0 + v t wrapped, energy and momentum exactly constant,
    every production sample in the profiles and frames, derived quantities written; the
    loop knows nothing of this engine but its class."""
    from demstudy.scene.initial import build_initial_state

    scene = gas(measure={"keep_frames": True, "statistics": ["profiles", "gr", "vdf",
                                                              "derived"]})
    assert "ballistic" in backend_names()
    res = read_results(run_scene(scene, "ballistic", RunOptions(out=tmp_path / "b.h5",
                                                                progress=False)))
    ts = res.timeseries
    np.testing.assert_allclose(ts["time"], np.arange(11) * 0.5)
    assert np.ptp(ts["kinetic_energy"]) == 0.0 and np.ptp(ts["momentum"], axis=0).max() == 0
    assert res.attrs["engine"] == "ballistic" and res.attrs["equilibration_end"] == 1.0
    start = build_initial_state(scene)
    t = res.frames["time"]
    assert len(t) == 8 and t[0] == 1.5
    expected = np.mod(start.position + start.velocity * t[-1], 12.0)
    np.testing.assert_allclose(res.frames["position"][-1], expected, atol=1e-12)
    assert res.profile_attrs["samples"] == 8
    total = res.profiles["solid_fraction"].sum() * res.profile_attrs["bin_width"] * 12.0
    assert total == pytest.approx(40 * math.pi / 4, rel=1e-12)  # every disc, once
    for name in ("gr", "vdf", "derived"):
        assert f"statistics/{name}" in res.groups, name


def test_a_third_backend_resumes_through_the_loop(tmp_path):
    scene = gas()
    whole = read_results(run_scene(scene, "ballistic", RunOptions(out=tmp_path / "w.h5",
                                                                  progress=False)))
    out = tmp_path / "p.h5"
    with pytest.raises(EngineError, match="--resume"):
        run_scene(scene, "ballistic", RunOptions(out=out, progress=False, wall_limit=0.0))
    parts = read_results(run_scene(scene, "ballistic", RunOptions(out=out, progress=False,
                                                                  resume=True)))
    for key, value in whole.profiles.items():
        np.testing.assert_array_equal(value, parts.profiles[key], err_msg=key)


def test_what_a_backend_lacks_is_refused_before_it_starts(tmp_path):
    """Effects without a translation, statistics needing a capability, options it does not
    have: UnsupportedByEngine before any work folder exists."""
    out = tmp_path / "x.h5"
    cases = [
        (gas(gravity={"direction": [1.0, 0.0]}), {}, "gravity"),
        (gas(measure={"statistics": ["angles"]}), {}, "measure.statistics"),
        (gas(measure={"statistics": ["stress"]}), {}, "measure.statistics"),
        (gas(), {"tc": 1e-4}, "--tc"),
        (gas(), {"np": 2}, "--np"),
    ]
    for scene, options, field in cases:
        extra = {k: v for k, v in options.items() if k != "np"}
        opts = RunOptions(out=out, progress=False, np=options.get("np", 1), extra=extra)
        with pytest.raises(UnsupportedByEngine) as info:
            Simulation(scene, BallisticBackend, opts)
        assert info.value.engine == "ballistic" and info.value.field_name == field, field
    assert not (tmp_path / "x.ballistic").exists() and not out.exists()


# ---- every statistic named in a scene ends in the results file or is refused ------------

def small_scene(name: str) -> dict:
    """A small scene where statistic ``name`` can be computed by the event-driven engine."""
    data = {"dimension": 3, "box": {"size": [7.0, 7.0, 7.0]}, "particles": {"count": 60},
            "contact": {"restitution": 0.95}, "initial": {"velocity": {"temperature": 1.0}},
            "run": {"equilibration": 0.5, "production": 2.0, "sample_interval": 0.25},
            "measure": {"statistics": [name]}}
    if name == "stress":
        data["walls"] = [{"side": "lower", "restitution": 0.9},
                         {"side": "upper", "restitution": 0.9}]
    return data


def group_of(res, name: str) -> dict:
    if name == "profiles":
        return res.profiles
    return res.groups.get(f"statistics/{name}") or res.groups.get(name, {})


@pytest.mark.parametrize("name", list(STATISTICS))
def test_each_statistic_a_scene_names_ends_in_the_results_file(name, tmp_path):
    res = read_results(run_scene(validate_scene(small_scene(name)), "edmd",
                                 RunOptions(out=tmp_path / "r.h5", progress=False)))
    data = group_of(res, name)
    # no dominant density wave in a small gas: waves' "dominant" lists are empty, rightly
    assert data and sum(np.asarray(v).size > 0 for v in data.values()) >= len(data) - 3, name


@pytest.mark.parametrize("name", [n for n, s in STATISTICS.items() if s.dims != (2, 3)])
def test_a_statistic_the_dimension_forbids_is_a_scene_error(name):
    data = small_scene(name)
    data.update(dimension=2, box={"size": [7.0, 7.0]})
    with pytest.raises(SceneError, match=f"'{name}'.*needs a 3D scene"):
        validate_scene(data)


def test_an_unknown_statistic_is_a_scene_error_listing_the_known_ones():
    with pytest.raises(SceneError, match="unknown statistic 'vfd'.*vdf"):
        validate_scene(small_scene("vfd"))


@pytest.mark.parametrize("name", [n for n, s in STATISTICS.items() if s.capability])
def test_a_statistic_an_engine_cannot_supply_is_refused_before_it_starts(name, tmp_path):
    """Capabilities are per engine: each statistic needing one is refused by every
    registered engine that lacks it, and accepted by those that have it."""
    scene = validate_scene(small_scene(name))
    capability = STATISTICS[name].capability
    for engine in backend_names():
        backend = get_backend(engine)
        opts = RunOptions(out=tmp_path / f"{engine}.h5", progress=False)
        if getattr(backend.capabilities, capability):
            continue
        with pytest.raises(UnsupportedByEngine) as info:
            run_scene(scene, engine, opts)
        try:  # an engine that can express the scene refuses it for the statistic
            backend.check(scene, opts)  # its effects (and the lattice engine: a lattice)
            assert info.value.value == name, info.value
        except UnsupportedByEngine:
            pass
        assert not (tmp_path / f"{engine}.{engine}").exists()
    assert any(getattr(get_backend(e).capabilities, capability) for e in backend_names())


def test_what_the_loop_is_asked_that_contradicts_itself_is_refused(tmp_path):
    """A statistic needing frames with keep_frames = False, a collision-counted run in an
    engine that counts none: refused before anything starts, naming the field."""
    out = tmp_path / "x.h5"
    vdf = gas(measure={"statistics": ["vdf"]})
    with pytest.raises(UnsupportedByEngine, match="'vdf' in measure.statistics needs the "
                                                  "stored frames") as info:
        run_scene(vdf, "edmd", RunOptions(out=out, progress=False, keep_frames=False))
    assert info.value.field_name == "keep_frames"
    counted = gas(run={**GAS["run"], "unit": "collisions"})
    with pytest.raises(UnsupportedByEngine) as info:
        run_scene(counted, "ballistic", RunOptions(out=out, progress=False))
    assert (info.value.field_name, info.value.value) == ("run.unit", "collisions")
    assert not out.exists()


def test_a_statistic_failing_after_the_run_keeps_the_results(tmp_path):
    """10 discs for half a time unit: no disc collides twice, so the free paths cannot be
    computed. The run's results are written all the same, the failure is recorded in them,
    and the caller is told (EngineError naming the file), through the child process too."""
    import demstudy as ds

    scene = gas(particles={"count": 10},
                run={"equilibration": 0.0, "production": 0.5, "sample_interval": 0.25},
                measure={"statistics": ["profiles", "freepath", "derived"]})
    out = tmp_path / "fp.h5"
    with pytest.raises(EngineError, match=rf"(?s)results are in {out}.*freepath: .*no particle "
                                          "collides twice"):
        ds.run(scene, engine="edmd", out=out)
    res = ds.load(out)
    assert "freepath" in res.attrs["statistics_failed"] and res.profiles
    assert "collisions" in res.groups and "statistics/derived" in res.groups
    assert not (tmp_path / "fp.edmd").exists()  # the run finished: no checkpoint left


def test_collisions_logged_before_a_stop_inside_an_interval_are_kept(tmp_path, monkeypatch):
    """Stops between event chunks (chunks of 50 events here) keep the collisions logged on
    the way: the resumed run's log and collision angles equal the uninterrupted run's."""
    from demstudy.engines.edmd import core

    monkeypatch.setattr(core, "STALL_CHUNK", 50)
    scene = validate_scene({**small_scene("angles"), "run": {
        "equilibration": 0.25, "production": 1.0, "sample_interval": 0.5}})
    whole = read_results(run_scene(scene, "edmd", RunOptions(out=tmp_path / "w.h5",
                                                             progress=False)))
    out = tmp_path / "p.h5"
    for _ in range(200):  # each part stops after its first chunk
        try:
            run_scene(scene, "edmd", RunOptions(out=out, progress=False, wall_limit=0.0,
                                                resume=(tmp_path / "p.edmd").exists()))
            break
        except EngineError as stopped:
            assert "after a checkpoint" in str(stopped)
    parts = read_results(out)
    assert len(whole.groups["collisions"]["time"]) > 20
    for key, value in whole.groups["collisions"].items():
        np.testing.assert_array_equal(value, parts.groups["collisions"][key], err_msg=key)
    for key, value in whole.groups["statistics/angles"].items():
        np.testing.assert_array_equal(value, parts.groups["statistics/angles"][key], key)


def test_a_stopped_run_tells_how_far_it_got_and_what_is_left_at_its_own_pace(tmp_path):
    """Each checkpoint leaves progress.json beside it; a resumed run's plan (``--resume
    --dry-run``, a study or sweep continuing it) counts what is left at the run's own pace,
    and the finished run leaves no work folder behind."""
    from demstudy.simulation import plan_run
    from demstudy.simulation.progress import PROGRESS, read_progress

    scene = gas()  # 1 + 4 time units in samples of 0.5: 10 sample intervals
    out, work = tmp_path / "p.h5", tmp_path / "p.ballistic"
    with pytest.raises(EngineError, match="--resume"):
        run_scene(scene, "ballistic", RunOptions(out=out, progress=False, wall_limit=0.0))
    done = read_progress(work)
    assert done.total == 10 and 1 <= done.done < 10 and done.done == int(done.done)
    assert done.time == pytest.approx(0.5 * done.done)
    assert done.marks[-1][0] == done.done and done.wall_seconds > 0
    plan = plan_run(scene, get_backend("ballistic"), RunOptions(out=out, resume=True),
                    dry_run=True)
    left = (10 - done.done) * done.wall_seconds / done.done
    assert plan.as_dict()["left_seconds"] == pytest.approx(left)
    assert f"{done.done:.4g} of 10 sample intervals done (t = {done.time:.6g})" in (
        plan.describe())
    fresh = plan_run(scene, get_backend("ballistic"), RunOptions(out=out), dry_run=True)
    assert fresh.left is None and "left_seconds" not in fresh.as_dict()
    other = gas(particles={"count": 41})  # another scene: its progress is not this one
    assert read_progress(work, scene_to_toml(other)) is None
    assert read_progress(work, scene_to_toml(scene)) == done
    whole = read_results(run_scene(scene, "ballistic", RunOptions(out=out, progress=False,
                                                                   resume=True)))
    assert whole.attrs["resumes"] == 1
    assert not (work / PROGRESS).exists() and not work.exists()
    assert read_progress(work) is None


def test_a_stop_inside_an_interval_counts_the_part_done(tmp_path, monkeypatch):
    """A stop between two event chunks lands inside a sample interval: the progress counts
    the part done (t / interval), not a whole interval less or more."""
    from demstudy.engines.edmd import core
    from demstudy.simulation.progress import read_progress

    monkeypatch.setattr(core, "STALL_CHUNK", 50)
    scene = validate_scene({**small_scene("profiles"), "run": {
        "equilibration": 0.0, "production": 4.0, "sample_interval": 2.0}})
    out = tmp_path / "p.h5"
    with pytest.raises(EngineError, match="inside a sample interval"):
        run_scene(scene, "edmd", RunOptions(out=out, progress=False, wall_limit=0.0))
    done = read_progress(tmp_path / "p.edmd", scene_to_toml(scene))
    assert 0 < done.time < 2.0 and done.total == 2
    assert done.done == pytest.approx(done.time / 2.0)  # a fraction of the first interval
    assert done.seconds_left() == pytest.approx(
        (2 - done.done) * done.wall_seconds / done.done)


def test_a_progress_file_of_another_checkpoint_is_ignored(tmp_path):
    """progress.json names the checkpoint it belongs to (SHA-256): one left by a crash
    between the two writes, or a checkpoint rewritten by a version that writes none, is not
    read as this checkpoint's progress; a checkpoint pickled before RunState.marks resumes
    (no pace until its next checkpoint, which has one mark)."""
    from demstudy.simulation.checkpoint import CHECKPOINT, pickle_atomically, read_checkpoint
    from demstudy.simulation.progress import PROGRESS, read_progress

    scene = gas()
    out, work = tmp_path / "p.h5", tmp_path / "p.ballistic"
    with pytest.raises(EngineError, match="--resume"):
        run_scene(scene, "ballistic", RunOptions(out=out, progress=False, wall_limit=0.0))
    assert read_progress(work) is not None
    saved = read_checkpoint(work / CHECKPOINT)
    del saved["run"].__dict__["marks"]  # as pickled before RunState.marks
    assert saved["run"].marks == ()
    pickle_atomically(work / CHECKPOINT, saved)  # the old progress file is now another's
    assert (work / PROGRESS).exists() and read_progress(work) is None
    (work / PROGRESS).unlink()
    with pytest.raises(EngineError, match="--resume"):
        run_scene(scene, "ballistic", RunOptions(out=out, progress=False, resume=True,
                                                 wall_limit=0.0))
    again = read_progress(work)
    assert len(again.marks) == 1 and again.done > saved["run"].samples
    parts = read_results(run_scene(scene, "ballistic", RunOptions(
        out=out, progress=False, resume=True)))
    np.testing.assert_allclose(parts.timeseries["time"], np.arange(11) * 0.5)
    assert parts.attrs["resumes"] == 2  # the old checkpoint (no count) resumed twice


def test_the_pace_left_is_the_latest_stretch_not_the_average():
    """A run that slows as it goes (a flow gravity heats): 10 intervals in 100 s, 10 more in
    200 s, 2 in 30 s (a stop soon after a checkpoint); the stretch timed is the latest one
    of at least a quarter of the intervals done (12 in 230 s), so 18 intervals are left for
    18 × 230/12 = 345 s (the average pace would say 270 s)."""
    from demstudy.simulation.progress import Progress

    progress = Progress(22, 40, 11.0, ((10, 100.0), (20, 300.0), (22, 330.0)))
    assert progress.stretch() == (12, pytest.approx(230.0))
    assert progress.seconds_left() == pytest.approx(345.0)
    line = progress.line()
    assert "5.75 min left" in line and "average: 15 s per interval" in line
    assert Progress(3, 10, 1.0, ((3, 6.0),)).seconds_left() == pytest.approx(14.0)
    assert Progress(2.5, 4, 1.0, ((2.5, 5.0),)).seconds_left() == pytest.approx(3.0)
    for nothing in (Progress(0, 10, 0.0, ()), Progress(0, 10, 0.0, ((0, 0.0),))):
        assert math.isnan(nothing.seconds_left()) and "no pace" in nothing.line()
