"""The cost ladder (demstudy.accuracy): convergence fit, the choice at a tolerance, resuming,
the Dask path, and the command line's refusals. Tiny 2D Lees–Edwards runs (≈ 75 discs, a
few strain units): dimensionless particle units, d = 1, m = 1, γ̇ = 1."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import demstudy as ds
from demstudy.accuracy.analyze import fit_convergence, pick_cheapest
from demstudy.accuracy.figure import pareto_front
from demstudy.cli import main
from demstudy.io.results import read_results

TINY = ["box.size=[10.0, 10.0]", "run.equilibration=1.0", "run.production=2.0",
        "run.sample_interval=0.5"]
LADDER = {"kstars": [1e2, 1e3], "steps": [10], "models": ["hooke"], "figure": False,
          "progress": lambda line: None}


def test_fit_recovers_a_synthetic_power_law():
    rng = np.random.default_rng(7)
    k = np.logspace(2, 7, 11)
    exact = 3.0 * k**-0.7 + 2e-4
    noisy = exact * (1 + 0.05 * rng.standard_normal(k.size))
    fit = fit_convergence(k, noisy)
    assert abs(fit.p - 0.7) < 3 * fit.p_err  # within its (three-sigma) error
    assert fit.p_err < 0.2  # and the error is informative
    assert abs(fit.floor - 2e-4) < 3 * fit.floor_err + 1e-5
    assert fit.resolved and "no decay" not in fit.law()


def test_a_flat_ladder_resolves_no_decay():
    """Errors flat within their noise (every run at the noise floor) fit any exponent: the
    law says that no decay is resolved."""
    rng = np.random.default_rng(3)
    k = np.logspace(3, 6, 4)
    fit = fit_convergence(k, 0.025 * (1 + 0.2 * rng.standard_normal(k.size)))
    assert not fit.resolved and "no decay resolved" in fit.law()


def test_fit_without_floor_is_exact_on_an_exact_law():
    k = np.array([1e3, 1e4, 1e5])
    fit = fit_convergence(k, 0.5 * k**-1.0)
    assert fit.p == pytest.approx(1.0, rel=1e-6) and fit.a == pytest.approx(0.5, rel=1e-5)
    with pytest.raises(ValueError, match="at least 3"):
        fit_convergence([1e3, 1e4], [0.1, 0.01])


def test_tolerance_picks_the_cheapest_qualifying_run():
    """A run meets the tolerance when its error AND its noise floor are within it: a run
    whose floor exceeds the tolerance cannot tell, however small its debiased error."""
    rows = [{"name": "a", "error": 0.05, "floor": 0.01, "wall_seconds": 1.0},  # inaccurate
            {"name": "b", "error": 0.015, "floor": 0.01, "wall_seconds": 9.0},
            {"name": "c", "error": 0.019, "floor": 0.01, "wall_seconds": 4.0},  # cheapest
            {"name": "d", "error": 0.0, "floor": 0.005, "wall_seconds": 30.0},
            {"name": "f", "error": 0.0, "floor": 0.03, "wall_seconds": 2.0},  # too noisy
            {"name": "e", "error": math.nan, "floor": 0.0, "wall_seconds": 0.1}]  # no error
    assert pick_cheapest(rows, 0.02)["name"] == "c"
    assert pick_cheapest(rows, 0.01)["name"] == "d"
    assert pick_cheapest(rows, 0.03)["name"] == "f"
    assert pick_cheapest([{**rows[2], "floor": math.nan}], 0.02) is None  # floor unknown
    assert pick_cheapest(rows[:1], 0.02) is None
    with pytest.raises(ValueError, match="tolerance"):
        pick_cheapest(rows, 0.0)


def test_recommendation_names_the_cheaper_engine_and_the_cost_ratio():
    from demstudy.accuracy.analyze import recommend

    soft = {"name": "soft-hooke-k1e+4-s10", "wall_seconds": 2.0, "error": 0.01, "floor": 0.005}
    assert recommend(soft, 8.0, 0.02, 0.005).startswith("soft contacts")
    assert "0.25 x" in recommend(soft, 8.0, 0.02, 0.005)
    assert recommend(soft, 1.0, 0.02, 0.005).startswith("event-driven")
    assert "caution" in recommend(None, 1.0, 0.02, 0.05)


def test_every_soft_setting_runs_in_each_soft_engine_under_its_own_name():
    from demstudy.accuracy.plan import soft_ladder

    specs = soft_ladder([1e3], [10.0], ["hooke"], ["lammps", "liggghts"])
    assert [(s.engine, s.name) for s in specs] == [
        ("lammps", "soft-hooke-k1e+3-s10"), ("liggghts", "soft-liggghts-hooke-k1e+3-s10")]
    soft = {"name": specs[1].name, "engine": "liggghts", "wall_seconds": 2.0, "error": 0.01}
    assert recommend_text(soft).startswith("soft contacts (liggghts)")


def recommend_text(choice: dict) -> str:
    from demstudy.accuracy.analyze import recommend

    return recommend(choice, 8.0, 0.02, 0.005)


def test_pareto_front_keeps_the_non_dominated_runs():
    points = [(1.0, 0.5), (2.0, 0.6), (3.0, 0.1), (4.0, 0.1), (5.0, 0.01)]
    assert pareto_front(points) == [(1.0, 0.5), (3.0, 0.1), (5.0, 0.01)]


def test_ladder_resumes_and_skips_what_was_done(tmp_path):
    out = tmp_path / "ladder"
    first = ds.cost("shear/lees-edwards-2d", overrides=TINY, out=out, workers=1, **LADDER)
    names = {"ref-edmd-tc1e-05", "soft-hooke-k100-s10", "soft-hooke-k1e+3-s10"}
    assert set(first.executed) == names and not first.skipped
    for name in names:  # each run's file is whole and holds its settings
        assert read_results(out / f"{name}.h5").attrs["wall_seconds"] > 0
    soft = {r["name"]: r for r in first.rows if r["engine"] == "lammps"}
    assert soft["soft-hooke-k100-s10"]["kn"] < soft["soft-hooke-k1e+3-s10"]["kn"]
    summary = json.loads((out / "ladder.json").read_text())
    assert "d = 1" in summary["units"] and len(summary["runs"]) == 3
    # a run killed mid-write leaves no file (atomic writes); a corrupted one is redone too
    (out / "soft-hooke-k100-s10.h5").unlink()
    (out / "soft-hooke-k1e+3-s10.h5").write_bytes(b"half a file")
    second = ds.cost("shear/lees-edwards-2d", overrides=TINY, out=out, workers=2, **LADDER)
    assert set(second.executed) == {"soft-hooke-k100-s10", "soft-hooke-k1e+3-s10"}
    assert second.skipped == ["ref-edmd-tc1e-05"]
    third = ds.cost("shear/lees-edwards-2d", overrides=TINY, out=out, workers=2, **LADDER)
    assert third.executed == [] and set(third.skipped) == names
    # the forecast lists done runs as reused, not forecast
    lines: list[str] = []
    dry = ds.cost("shear/lees-edwards-2d", overrides=TINY, out=out, workers=2, dry_run=True,
                  **{**LADDER, "progress": lines.append})
    assert {n for n, phase, _, _ in dry.forecast.runs if phase == "reused"} == names
    assert "0 run(s) to make, 3 reused" in lines[-1] and dry.executed == []
    # other settings of the scene (a longer run) are not mistaken for done ones
    longer = ds.cost("shear/lees-edwards-2d", overrides=[*TINY, "run.production=2.5"],
                     out=out, workers=1, **{**LADDER, "kstars": [1e2]})
    assert set(longer.executed) == {"ref-edmd-tc1e-05", "soft-hooke-k100-s10"}


def test_replicas_make_one_file_per_replica_and_resume(tmp_path):
    """--replicas 2: every run twice with successive seeds (files -r0, -r1), one row per
    setting whose cost is the sum of its replicas' wall times and whose errors come from
    their scatter; a rerun reuses every replica, a lost replica alone is redone, and more
    reference replicas add only the missing ones."""
    out = tmp_path / "ladder"
    ladder = {**LADDER, "kstars": [1e2]}
    first = ds.cost("shear/lees-edwards-2d", overrides=TINY, out=out, workers=2, replicas=2,
                    **ladder)
    names = {f"{stem}-r{i}" for stem in ("ref-edmd-tc1e-05", "soft-hooke-k100-s10")
             for i in (0, 1)}
    assert set(first.executed) == names and {p.stem for p in out.glob("*.h5")} == names
    runs = {n: read_results(out / f"{n}.h5", skip=("frames",)) for n in names}
    seeds = {n: r.scene.run.seed for n, r in runs.items()}
    assert seeds["soft-hooke-k100-s10-r1"] == seeds["soft-hooke-k100-s10-r0"] + 1
    assert seeds["ref-edmd-tc1e-05-r1"] == seeds["ref-edmd-tc1e-05-r0"] + 1
    assert not np.array_equal(runs["ref-edmd-tc1e-05-r0"].profiles["temperature"],
                              runs["ref-edmd-tc1e-05-r1"].profiles["temperature"])
    assert [r["name"] for r in first.rows] == ["ref-edmd-tc1e-05", "soft-hooke-k100-s10"]
    for row in first.rows:
        assert row["replicas"] == 2
        assert row["wall_seconds"] == pytest.approx(sum(
            runs[f"{row['name']}-r{i}"].attrs["wall_seconds"] for i in (0, 1)))
    assert first.reference["results"].profile_attrs["n_blocks"] == 2  # 1 dof
    assert any("SUM of their wall times" in n for n in first.notes)
    summary = json.loads((out / "ladder.json").read_text())
    assert summary["runs"][1]["replicas"] == 2 and "SUM" in summary["replicas_rule"]
    (out / "soft-hooke-k100-s10-r1.h5").unlink()
    again = ds.cost("shear/lees-edwards-2d", overrides=TINY, out=out, workers=1, replicas=2,
                    **ladder)
    assert again.executed == ["soft-hooke-k100-s10-r1"]
    assert set(again.skipped) == names - {"soft-hooke-k100-s10-r1"}
    more = ds.cost("shear/lees-edwards-2d", overrides=TINY, out=out, workers=1, replicas=2,
                   reference_replicas=3, **ladder)
    assert more.executed == ["ref-edmd-tc1e-05-r2"] and more.rows[0]["replicas"] == 3


def test_a_ladder_killed_after_its_first_runs_resumes_with_the_rest(tmp_path):
    import os
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "ladder"
    argv = [sys.executable, "-m", "demstudy.cli", "cost", "shear/lees-edwards-2d", "--out",
            str(out), "--kstar", "1e2,1e3", "--steps", "10", "--models", "hooke",
            "--workers", "1", *[a for kv in TINY for a in ("--set", kv)]]
    proc = subprocess.Popen(argv, start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    first = out / "ref-edmd-tc1e-05.h5"
    deadline = time.monotonic() + 120
    while not first.exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    os.killpg(proc.pid, signal.SIGKILL)  # the whole ladder, engine children included
    proc.wait()
    assert first.exists()
    done = {p.stem for p in out.glob("*.h5")}  # whole files only (atomic writes)
    study = ds.cost("shear/lees-edwards-2d", overrides=TINY, out=out, workers=1, **LADDER)
    names = {"ref-edmd-tc1e-05", "soft-hooke-k100-s10", "soft-hooke-k1e+3-s10"}
    assert set(study.skipped) == done and set(study.executed) == names - done


def test_ladder_runs_on_a_dask_local_cluster(tmp_path):
    import distributed  # a declared dependency: the Dask path is always tested
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        study = ds.cost("shear/lees-edwards-2d", overrides=TINY, out=tmp_path, dask=client,
                        **{**LADDER, "kstars": [1e2]})
    assert set(study.executed) == {"ref-edmd-tc1e-05", "soft-hooke-k100-s10"}
    row = next(r for r in study.rows if r["engine"] == "lammps")
    assert row["wall_seconds"] > 0 and row["steps"] > 0 and math.isfinite(row["floor"])


@pytest.mark.parametrize("argv, named", [
    (["--set", "soft.stiffnes=3"], "stiffnes"),
    (["--dask", "notanaddress"], "--dask"),
    (["--dask", "tcp://host:port"], "--dask"),
    (["--dask", "tcp://127.0.0.1:1"], "--dask"),  # no scheduler there: refused, named
    (["--workers", "0"], "--workers"),
    (["--workers", "-3"], "--workers"),
    (["--quick", "--kstar", "1e3"], "--kstar"),
    (["--quick", "--models", "hooke"], "--quick"),
    (["--out", "FILE"], "--out"),
    (["--out", "FILE/ladder"], "--out"),
    (["--kstar", "1e3,-1e4"], "--kstar"),
    (["--kstar", "1e3,abc"], "--kstar"),
    (["--steps", "5"], "--steps"),
    (["--tolerance", "0"], "--tolerance"),
    (["--models", "hooke,jkr"], "--models"),
    (["--replicas", "0"], "--replicas"),
    (["--replicas", "-2"], "--replicas"),
    (["--replicas", "two"], "--replicas"),
    (["--replicas", "2", "--reference-replicas", "0"], "--reference-replicas"),
    (["--engine", "edmd"], "--engine"),  # the reference is not a soft engine
    (["--engine", "lammps,gromacs"], "gromacs"),
])
def test_cli_refuses_bad_input_naming_the_option(argv, named, capsys, tmp_path):
    (tmp_path / "FILE").write_text("not a folder")
    argv = [str(tmp_path / a) if a.startswith("FILE") else a for a in argv]
    code = main(["cost", "shear/lees-edwards-2d", "--out", str(tmp_path / "ladder"), *argv])
    assert code == 2
    assert named in capsys.readouterr().err
    assert not list(tmp_path.rglob("*.h5"))  # nothing ran
    assert (tmp_path / "FILE").read_text() == "not a folder"


FAKE_COSTS = {"step": 2e-6, "atom_step": 1e-7, "contact_step": 1e-7, "atom_sample": 1e-7,
              "sample": 1e-3, "shear_atom_step": 5e-8, "history_atom_step": 5e-8,
              "wall_step": 1e-6, "collision": 1e-6, "crossing": 1e-6, "large_event": 0.0,
              "run": 0.0}


def test_dry_run_forecasts_the_whole_ladder_measuring_the_machine_once(tmp_path, monkeypatch,
                                                                       capsys):
    """--dry-run: every planned run with its forecast (replicas and the t_c ladder share
    one), the total and the wall time on the workers (longest first onto the least busy),
    the machine's costs asked for in this process before anything else; nothing runs,
    nothing is written."""
    import demstudy.simulation.forecast as fc

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))  # the pilot's cache
    asked: list[tuple] = []

    def fake_costs(engine, dim, model=None, **kw):
        asked.append((engine, dim, model))
        return dict(FAKE_COSTS)

    monkeypatch.setattr(fc, "measure_costs", fake_costs)
    out = tmp_path / "ladder"
    assert main(["cost", "shear/lees-edwards-2d", "--out", str(out), "--kstar", "1e2,1e3",
                 "--steps", "10", "--models", "hooke", "--workers", "2", "--replicas", "2",
                 "--dry-run", *[a for kv in TINY for a in ("--set", kv)]]) == 0
    printed = capsys.readouterr().out
    assert not out.exists()  # nothing written
    assert asked[:2] == [("lammps", 2, "hooke"), ("edmd", 2, None)]  # measured first
    study = ds.cost("shear/lees-edwards-2d", overrides=TINY, out=out, workers=2, replicas=2,
                    dry_run=True, **LADDER)
    runs = {name: (phase, s) for name, phase, s, _ in study.forecast.runs}
    assert len(runs) == (3 + 2) * 2 and all(name in printed for name in runs)
    assert runs["soft-hooke-k1e+3-s10-r0"][1] > runs["soft-hooke-k100-s10-r0"][1] > 0
    assert runs["soft-hooke-k100-s10-r1"] == runs["soft-hooke-k100-s10-r0"]
    assert runs["ref-edmd-tc1e-06-r0"][0] == "tc-ladder?"  # decided by the reference
    ref = [s for phase, s in runs.values() if phase == "reference"]
    soft = [s for phase, s in runs.values() if phase == "soft"]
    assert study.forecast.total == pytest.approx(sum(ref) + sum(soft))
    # two workers: each phase takes at least half its work and at least its longest run
    wall = study.forecast.wall
    assert max(sum(ref) / 2, max(ref)) + max(sum(soft) / 2, max(soft)) <= wall + 1e-12
    assert wall <= study.forecast.total
    assert f"{wall:.3g} s on 2 worker(s)" in printed and not out.exists()


def test_ladder_task_paths_are_absolute(tmp_path, monkeypatch):
    """A relative --out becomes absolute, so workers in another directory (Dask) write into
    the ladder folder."""
    import demstudy.accuracy.study as study_module

    seen = []

    class Stop(Exception):
        pass

    def fake_execute(tasks, *args, **kwargs):
        seen.extend(tasks)
        raise Stop

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(study_module, "execute", fake_execute)
    with pytest.raises(Stop):
        ds.cost("shear/lees-edwards-2d", overrides=TINY, out="relative/ladder", workers=1,
                **LADDER)
    assert seen and all(t.path.is_absolute() for t in seen)
    assert all(t.path.parent == tmp_path / "relative" / "ladder" for t in seen)


def test_a_tc_dominated_reference_says_it_is_not_the_hard_particle_limit(tmp_path):
    """A reference whose TC model made more than 10 % of its collisions elastic (synthetic
    attributes) is no hard-particle reference: a note and the recommendation say so; 5 %
    does not."""
    from demstudy.accuracy.plan import RunSpec
    from demstudy.accuracy.study import CostStudy, _assemble
    from demstudy.io.results import Results, write_results

    scene = ds.load_scene("shear/lees-edwards-2d", TINY)
    spec = RunSpec("edmd", tc=1e-5)
    for elastic, says in ((300, True), (50, False)):
        write_results(tmp_path / f"{spec.name}.h5", Results(
            {"engine": "edmd", "wall_seconds": 1.0, "events": 4000,
             "elastic_tc_collisions": elastic},
            timeseries={"time": np.array([0.0, 3.0]), "collisions": np.array([0, 1000])}))
        study = CostStudy(tmp_path, "k*", [], {}, 0.02, None, "")
        _assemble(study, scene, [[spec]], [])
        note = f"no hard-particle reference: the TC model made {elastic // 10} % of collisions"
        assert (note in " ".join(study.notes)) is says
        assert (note in study.recommendation) is says


def test_reference_tc_ladder_keeps_the_largest_tc_when_the_tc_model_never_acts(tmp_path):
    study = ds.cost("shear/lees-edwards-2d", overrides=TINY, out=tmp_path, workers=1,
                    tc_ladder=True, **{**LADDER, "kstars": [1e2]})
    refs = [r for r in study.rows if r["engine"] == "edmd"]
    assert [r["tc"] for r in refs] == pytest.approx([1e-5, 1e-6, 1e-7])
    elastic = [read_results(r["path"]).attrs["elastic_tc_collisions"] for r in refs]
    # the premise, not a skip: in this dilute scene (seeded) the TC model never acts
    assert not any(elastic), f"the TC model acted ({elastic}): t_c changes the dynamics"
    # t_c only matters through TC collisions: without any, the runs are the same trajectory,
    # agree with the smallest t_c, and the cheapest (largest t_c) is the reference
    assert [r["steps"] for r in refs] == [refs[0]["steps"]] * 3
    assert [r["reference"] for r in refs] == [True, False, False]
    assert study.reference["name"] == "ref-edmd-tc1e-05"


def test_health_figures_when_present_give_the_contact_time_law():
    from demstudy.accuracy.study import _fits

    ratio = np.array([0.3, 0.1, 0.03, 0.01])  # t_c/τ_flight of four soft runs
    rows = [{"model": "hooke", "steps_per_contact": 50.0, "kstar": 1e2 / r**2,
             "error": 0.4 * r**1.5, "tc_flight": r} for r in ratio]
    fits = _fits(rows)
    assert fits["error(t_c/tau_flight)"].p == pytest.approx(1.5, abs=1e-3)
    assert fits["error(k*) hooke, 50 steps/contact"].p == pytest.approx(0.75, abs=1e-3)
    without = _fits([{k: v for k, v in r.items() if k != "tc_flight"} for r in rows])
    assert "error(t_c/tau_flight)" not in without


def test_a_ladder_run_stopped_with_a_checkpoint_continues_from_it(tmp_path, monkeypatch):
    """A sweep's command takes no --resume: a run whose work folder holds a checkpoint (it
    was stopped by Ctrl-C or a wall-clock limit) is continued from it, any other run starts
    afresh."""
    import types

    import demstudy.api as api
    from demstudy.accuracy.execute import Task, run_task
    from demstudy.accuracy.plan import RunSpec
    from demstudy.scene import load_scene, scene_to_toml
    from demstudy.simulation.checkpoint import CHECKPOINT
    from demstudy.simulation.options import work_folder

    seen = []

    def spy(scene, **kw):
        seen.append(kw)
        return types.SimpleNamespace(path=kw["out"], attrs={"wall_seconds": 1.0})

    monkeypatch.setattr(api, "run", spy)
    task = Task(RunSpec("edmd", tc=1e-5), scene_to_toml(load_scene("shear/lees-edwards-2d")),
                tmp_path / "ref-edmd-tc1e-05.h5")
    run_task(task)
    folder = work_folder(task.path, "edmd")
    folder.mkdir(parents=True)
    (folder / CHECKPOINT).write_bytes(b"a checkpoint")
    run_task(task)
    assert "resume" not in seen[0] and seen[1]["resume"] is True
    assert seen[1]["tc"] == 1e-5
    # the ladder's forecast counts what is left of the stopped run at its own pace
    from demstudy.accuracy.forecast import ladder_forecast
    from demstudy.simulation.checkpoint import pickle_atomically
    from demstudy.simulation.progress import Progress, scene_digest, write_progress

    digest = pickle_atomically(folder / CHECKPOINT, {"a": "checkpoint"})
    write_progress(folder, Progress(2, 10, 0.4, ((2, 10.0),)),  # 2 of 10 intervals in 10 s
                   digest, scene_digest(task.scene_toml))
    plan = ladder_forecast({"reference": ([task], [])}, workers=1, unmeasured="not measured")
    (name, phase, seconds, line), = plan.runs
    assert phase == "reference" and seconds == pytest.approx(40.0)
    assert "2 of 10 sample intervals done" in line and plan.total == pytest.approx(40.0)
    # a checkpoint whose progress file names another scene (the case changed since): the
    # run starts afresh instead of failing on --resume; of this scene: it resumes
    write_progress(folder, Progress(2, 10, 0.4, ((2, 10.0),)), digest, scene_digest("other"))
    run_task(task)
    assert "resume" not in seen[-1]
    write_progress(folder, Progress(2, 10, 0.4, ((2, 10.0),)), digest,
                   scene_digest(task.scene_toml))
    run_task(task)
    assert seen[-1]["resume"] is True
    # a soft run's scene is the base with its soft section (scene_for): its progress file
    # names that scene, which the ladder's forecast matches (not the base's)
    soft = Task(RunSpec("lammps", "hooke", 1e4, 50), task.scene_toml,
                tmp_path / "soft-lammps.h5")
    assert scene_to_toml(soft.scene()) != task.scene_toml
    sfolder = work_folder(soft.path, "lammps")
    sfolder.mkdir(parents=True)
    sdigest = pickle_atomically(sfolder / CHECKPOINT, {"a": "checkpoint"})
    write_progress(sfolder, Progress(3, 10, 0.6, ((3, 6.0),)), sdigest,
                   scene_digest(scene_to_toml(soft.scene())))
    plan = ladder_forecast({"soft": ([soft], [])}, workers=1, unmeasured="not measured")
    assert plan.runs[0][2] == pytest.approx(14.0)
