"""The study framework (``demstudy study``): cases run once into the study folder and are
reused on a rerun, a changed case is redone, the forecast is printed before anything runs, a
failed case leaves the others and the analysis standing, the report lists every check with its
verdict, ``--docs`` publishes it with working figure links, bad input exits 2.

Dimensionless particle units: d = 1, m = 1; the wall speed U_T = 1 sets the time unit.
"""

from __future__ import annotations

import subprocess
import sys
import types
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import demstudy as ds  # noqa: E402
from demstudy import studies  # noqa: E402
from demstudy.studies import Analysis, Case, Check, Figure, Study, pm, within  # noqa: E402
from demstudy.studies.base import NOT_RUN, REPRODUCED, merge  # noqa: E402
from demstudy.studies.runner import publish, run_study  # noqa: E402

SHORT = {"run": {"equilibration": 5.0, "production": 10.0}}


def _toy_cases(quick: bool) -> list[Case]:
    cases = [Case("cell-a", "campbell1982/couette-rough", sections=SHORT, quick=True),
             Case("cell-b", "campbell1982/couette-rough",
                  sections=merge(SHORT, {"contact": {"restitution": 0.9}}))]
    return [c for c in cases if c.quick or not quick]


def _toy_analysis(runs, out: Path, quick: bool) -> Analysis:
    """One check per case: the mean solid fraction of the cell equals N (π/4) / area at the
    start (mass is conserved: the profile's ν integrates back to the number of discs)."""
    ana = Analysis()
    for case in _toy_cases(quick):
        if case.name not in runs:
            ana.checks.append(Check("toy", f"{case.name} ran", "-", "-", NOT_RUN,
                                    "the run is missing"))
            continue
        res = ds.load(runs[case.name])
        nu = res.profiles["solid_fraction"]
        ana.checks.append(Check("toy", f"{case.name}: discs in the profile", "40",
                                f"{nu.mean():.3f}", REPRODUCED))
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    path = out / "toy.png"
    fig.savefig(path)
    plt.close(fig)
    ana.figures.append(Figure(path, "a toy figure"))
    ana.sections.append(("Notes", "toy notes"))
    return ana


TOY = Study("toy", "A toy study", "nobody (2026)", "Two tiny Couette cells.",
            _toy_cases, _toy_analysis)


@pytest.fixture
def toy(monkeypatch):
    module = types.ModuleType("demstudy_toy_study")
    module.STUDY = TOY
    monkeypatch.setitem(sys.modules, "demstudy_toy_study", module)
    monkeypatch.setitem(studies._MODULES, "toy", "demstudy_toy_study")
    return TOY


def test_runs_are_made_once_then_reused_and_a_changed_case_is_redone(toy, tmp_path, monkeypatch):
    lines: list[str] = []
    first = run_study("toy", out=tmp_path, echo=lines.append)
    assert sorted(first.made) == ["cell-a", "cell-b"] and not first.reused
    assert any(line.startswith("forecast:") for line in lines), lines
    # the forecast comes before any run finished
    assert [i for i, s in enumerate(lines) if s.startswith("forecast:")][0] < \
        [i for i, s in enumerate(lines) if s.startswith("  done")][0]
    report = first.report.read_text()
    assert "| 1 | toy | cell-a: discs in the profile |" in report
    assert "2 reproduced" in report and "![a toy figure](toy.png)" in report
    assert "Dimensionless particle units" in report

    second = run_study("toy", out=tmp_path, echo=lines.append)
    assert second.made == [] and sorted(second.reused) == ["cell-a", "cell-b"]

    changed = Study("toy", TOY.title, TOY.reference, TOY.summary,
                    lambda q: [Case("cell-a", "campbell1982/couette-rough",
                                    sections=merge(SHORT, {"run": {"production": 12.0}}))],
                    _toy_analysis)
    monkeypatch.setattr(sys.modules["demstudy_toy_study"], "STUDY", changed)
    third = run_study("toy", out=tmp_path, echo=lines.append)
    assert third.made == ["cell-a"], "a case whose scene changed must be run again"


def test_quick_runs_only_the_quick_cases_and_missing_runs_say_not_run(toy, tmp_path):
    res = run_study("toy", quick=True, out=tmp_path, echo=lambda s: None)
    assert res.made == ["cell-a"]
    verdicts = [c.verdict for c in res.analysis.checks]
    assert verdicts == [REPRODUCED]
    assert "quick" in res.report.read_text()
    # --analyse-only on the full study: cell-b was never made → its check says "not run"
    full = run_study("toy", out=tmp_path, analyse_only=True, echo=lambda s: None)
    assert full.made == [] and [c.verdict for c in full.analysis.checks] == [REPRODUCED,
                                                                           NOT_RUN]


def test_dry_run_forecasts_and_writes_nothing(toy, tmp_path):
    lines: list[str] = []
    res = run_study("toy", out=tmp_path, dry_run=True, echo=lines.append)
    assert res.made == [] and res.report is None
    assert not (tmp_path / "runs").exists()
    assert any("cell-b (edmd):" in s for s in lines)


def test_a_lower_bound_makes_the_study_forecast_one(toy, tmp_path, monkeypatch):
    """A run whose forecast is a lower bound (a flow gravity accelerates) is listed with "at
    least", and so is the study's total, with the note why."""
    import demstudy.api as api
    from demstudy.studies.runner import LOWER_BOUND_NOTE

    def plan(scene, **kw):
        bound = scene.contact.restitution == 0.9  # cell-b
        return {"forecast_seconds": 30.0 if bound else 10.0,
                "forecast_kind": "lower bound" if bound else "estimate"}

    monkeypatch.setattr(api, "run", plan)
    lines: list[str] = []
    run_study("toy", out=tmp_path, dry_run=True, workers=1, echo=lines.append)
    assert lines[1].startswith("forecast: probably more than 40 s on 1 worker(s)")
    assert any(s.endswith("cell-b (edmd): probably more than 30 s") for s in lines)
    assert any(s.endswith("cell-a (edmd): 10 s") for s in lines)
    assert LOWER_BOUND_NOTE in lines


def test_a_finished_run_of_the_same_kind_turns_a_lower_bound_into_an_estimate(
        toy, tmp_path, monkeypatch):
    """A made run of the study whose own lower bound fell short ×3 scales the lower bound
    of a run of the same kind (engine, walls, drive, φ, run unit) to an estimate, naming
    the run; a made run of another kind (a chute: gravity) leaves the lower bound."""
    import h5py

    import demstudy.api as api
    from demstudy.scene import load_scene, scene_to_toml
    from demstudy.studies.runner import (
        CALIBRATED_NOTE,
        LOWER_BOUND_NOTE,
        OTHER_TC_NOTE,
        tasks_of,
    )

    def plan(scene, **kw):
        return {"forecast_seconds": 30.0, "forecast_kind": "lower bound"}

    monkeypatch.setattr(api, "run", plan)
    made = tasks_of(TOY, False, tmp_path)[0]  # cell-a
    made.path.parent.mkdir(parents=True)

    def finished(scene_toml: str, tc: float = 1e-5) -> list[str]:
        with h5py.File(made.path, "w") as f:
            f.attrs.update({"engine": "edmd", "forecast_kind": "lower bound",
                            "forecast_seconds": 30.0, "wall_seconds": 90.0,
                            "scene_toml": scene_toml, "tc": tc})
        lines: list[str] = []
        run_study("toy", out=tmp_path, dry_run=True, workers=1, echo=lines.append,
                  only=["cell-b"])
        return lines

    lines = finished(made.scene_toml)
    assert lines[1].startswith("forecast: about 90 s on 1 worker(s)"), lines
    assert any(s.endswith("cell-b (edmd): about 90 s (its lower bound 30 s × 3.00: cell-a, "
                          "N = 40, took 90 s against a lower bound of 30 s)") for s in lines)
    assert LOWER_BOUND_NOTE not in lines and CALIBRATED_NOTE in lines
    assert OTHER_TC_NOTE not in lines
    # made at another t_c: still the guide, and the line and a note say so
    lines = finished(made.scene_toml, tc=1e-6)
    assert any("cell-a, N = 40, made at t_c = 1e-06, took 90 s" in s for s in lines), lines
    assert OTHER_TC_NOTE in lines
    lines = finished(scene_to_toml(load_scene("campbell1982/chute-20")))
    assert lines[1].startswith("forecast: probably more than 30 s"), lines
    assert LOWER_BOUND_NOTE in lines


def test_a_calibrating_run_has_the_same_engine_options_and_is_the_closest(tmp_path):
    """Another t_c costs differently: a run at the same t_c calibrates first, one at another
    t_c only when there is none; among them the closest in N, length, e and β; a made run
    counts from its record when its results file is gone."""
    from demstudy.scene import load_scene
    from demstudy.studies.runner import Took, _made, calibration, tasks_of

    scene = load_scene("campbell1982/couette-rough", ["run.production=10"])
    near = Took("near", "edmd", scene, 90.0, 30.0, 1e-5)
    far = Took("far", "edmd", load_scene("campbell1982/couette-rough",
                                         ["run.production=1000"]), 900.0, 30.0, 1e-5)
    assert calibration(scene, "edmd", [far, near]) is near
    # no run at its t_c: the closest at another t_c (the forecast line says so), but a run
    # at its t_c is preferred however far
    assert calibration(scene, "edmd", [far, near], {"tc": 1e-6}) is near
    twin = Took("twin", "edmd", load_scene("campbell1982/couette-rough",
                                           ["run.production=1000"]), 9.0, 3.0, 1e-6)
    assert calibration(scene, "edmd", [near, twin], {"tc": 1e-6}) is twin
    assert calibration(scene, "lammps", [far, near]) is None
    records = tmp_path / "records"
    records.mkdir()
    (records / "cell-b.h5").write_bytes(b"x")
    task = tasks_of(TOY, False, tmp_path)[0]
    task.path.parent.mkdir(parents=True)
    task.path.write_bytes(b"x")
    assert _made(TOY, False, tmp_path, records) == {"cell-a": task.path,
                                                   "cell-b": records / "cell-b.h5"}


def test_a_failed_case_does_not_stop_the_others_nor_the_analysis(toy, tmp_path, monkeypatch):
    bad = Study("toy", TOY.title, TOY.reference, TOY.summary,
                lambda q: [Case("cell-a", "campbell1982/couette-rough", sections=SHORT),
                           Case("cell-b", "campbell1982/couette-rough", engine="liggghts",
                                sections=SHORT)],  # LIGGGHTS refuses the servo
                _toy_analysis)
    monkeypatch.setattr(sys.modules["demstudy_toy_study"], "STUDY", bad)
    res = run_study("toy", out=tmp_path, echo=lambda s: None, workers=1)
    assert res.made == ["cell-a"] and res.failed == ["cell-b"]
    assert [c.verdict for c in res.analysis.checks] == [REPRODUCED, NOT_RUN]
    assert "1 failed (cell-b)" in res.report.read_text()


def test_a_stopped_run_is_listed_without_the_single_runs_resume_advice():
    """A sweep's command has no --resume (it resumes by itself): the failures list keeps what
    stopped the run and drops the per-run advice, other errors stay whole."""
    from demstudy.accuracy.execute import _failure
    from demstudy.errors import RESUME_ADVICE, EngineError, RunStopped

    stopped = RunStopped(f"stopped (Ctrl-C) at t = 12.5 after a checkpoint{RESUME_ADVICE}")
    assert _failure("big", stopped) == "big: stopped (Ctrl-C) at t = 12.5 after a checkpoint"
    assert _failure("bad", EngineError("x: y")) == "bad: x: y"


def test_publish_copies_the_figures_and_rewrites_their_links(toy, tmp_path):
    res = run_study("toy", quick=True, out=tmp_path / "study", echo=lambda s: None)
    docs = tmp_path / "docs"
    page = publish(res, docs)
    text = page.read_text()
    assert page == docs / "studies" / "toy.md"
    assert "](../figures/studies/toy/toy.png)" in text
    assert (page.parent / "../figures/studies/toy/toy.png").resolve().is_file()


def test_check_verdicts_and_number_formatting():
    with pytest.raises(ValueError, match="allowed are"):
        Check("x", "y", "z", "w", "roughly")
    assert pm(0.57612, 0.0041) == "0.5761 ± 0.0041"
    assert pm(12.3, 4.0) == "12.3 ± 4.0"
    assert pm(float("nan")) == "n/a" and pm(3.14159) == "3.14"
    assert within(1.0, 0.1, 1.15) and not within(1.0, 0.05, 1.15)
    assert within(1.0, 0.0, 1.1, tolerance=0.11) and not within(1.0, 0.0, 1.2, tolerance=0.11)


def test_a_selection_that_selects_nothing_is_refused_naming_what_is_allowed(toy, tmp_path):
    """A typo in --only or --engine would run nothing and report success, --analyse-only
    with no made run a report of nothing: refused (exit 2 on the command line), naming the
    option, the value and what the study has."""
    from demstudy.errors import BadOption

    for kw, words in (({"only": ["cell-z"]}, "--only = 'cell-z': matches no case of toy; "
                       "its cases are cell-a, cell-b"),
                      ({"engines": ["bogus"]}, "--engine = 'bogus': allowed are"),
                      ({"engines": ["lgd"]}, "no case of toy runs in it; its cases use edmd"),
                      ({"only": ["cell-b"], "quick": True}, "matches no case of toy (quick)"),
                      ({"analyse_only": True}, f"no made run of toy in {tmp_path}/runs/")):
        with pytest.raises(BadOption) as info:
            run_study("toy", out=tmp_path, dry_run=not kw.get("analyse_only"),
                      echo=lambda s: None, **kw)
        assert words in str(info.value), (kw, str(info.value))
    assert not (tmp_path / "runs").exists()


def test_cli_refuses_an_unknown_study_and_bad_workers_with_exit_2():
    for args in (["nope"], ["campbell1982", "--workers", "0"]):
        proc = subprocess.run([sys.executable, "-m", "demstudy.cli", "study", *args],
                              capture_output=True, text=True, timeout=120)
        assert proc.returncode == 2, proc.stderr
        assert "Traceback" not in proc.stderr
    assert "campbell1982, gutt1989, malik2008" in subprocess.run(
        [sys.executable, "-m", "demstudy.cli", "study", "nope"], capture_output=True,
        text=True, timeout=120).stderr


def test_an_interrupted_run_resumes_from_its_checkpoint(toy, tmp_path):
    """A study's runs checkpoint (10 per run); a run stopped midway (here by a wall-clock
    limit) is continued from its checkpoint by the next ``run_study``, not started again,
    and the study's forecast counts what is left of it at its own pace."""
    from demstudy.errors import RunStopped
    from demstudy.simulation.checkpoint import stopped_run
    from demstudy.simulation.options import work_folder
    from demstudy.simulation.progress import PROGRESS, read_progress
    from demstudy.studies.runner import OLD_CHECKPOINT_NOTE, OWN_PACE_NOTE, forecast, tasks_of

    task = next(t for t in tasks_of(TOY, False, tmp_path) if t.case.name == "cell-a")
    assert task.spec.checkpoint_interval == pytest.approx(1.5)  # (5 + 10)/10 time units
    assert not stopped_run(task.path, "edmd")
    with pytest.raises(RunStopped):
        ds.run(task.scene(), engine="edmd", out=task.path, wall_limit=1e-9,
               checkpoint_interval=task.spec.checkpoint_interval, progress=False)
    assert not task.path.exists() and stopped_run(task.path, "edmd")
    left = read_progress(work_folder(task.path, "edmd"), task.scene_toml)
    _total, lines, _refused, seconds = forecast([task], 1)
    line = next(s for s in lines if "cell-a" in s)
    assert "sample intervals done (t = " in line and "left at this run's own pace" in line
    assert seconds["cell-a"] == pytest.approx(left.seconds_left()) and OWN_PACE_NOTE in lines
    # an older checkpoint, without a progress file: the whole run's forecast, said to resume
    (work_folder(task.path, "edmd") / PROGRESS).unlink()
    _total, lines, _refused, _seconds = forecast([task], 1)
    line = next(s for s in lines if "cell-a" in s)
    assert "resumes;" in line and OLD_CHECKPOINT_NOTE in lines and OWN_PACE_NOTE not in lines
    res = run_study("toy", out=tmp_path, echo=lambda s: None)
    assert "cell-a" in res.made
    done = ds.load(task.path)
    assert done.attrs["resumes"] == 1  # continued from the checkpoint, not started again
    times = done.timeseries["time"]
    assert times[-1] == pytest.approx(15.0, abs=1.0)  # the whole run, equilibration + production


@pytest.mark.parametrize("name", studies.study_names())
def test_every_case_of_every_study_loads_from_any_folder(name, tmp_path, monkeypatch):
    """Cases name shipped presets, not paths relative to the repository: a study runs from
    any working folder (an installed package has no inputs/ beside it)."""
    monkeypatch.chdir(tmp_path)
    study = studies.get_study(name)
    for quick in (True, False):
        cases = study.cases(quick)
        assert cases and len({c.name for c in cases}) == len(cases)
        for case in cases:
            assert not case.scene.startswith(("inputs/", "/")), case.scene
            case.load(quick)


def test_only_selects_what_to_run_and_the_report_covers_every_run_made(toy, tmp_path):
    first = run_study("toy", out=tmp_path, only=["cell-a"], echo=lambda s: None)
    assert first.made == ["cell-a"]
    assert [c.verdict for c in first.analysis.checks] == [REPRODUCED, NOT_RUN]
    second = run_study("toy", out=tmp_path, only=["cell-b"], echo=lambda s: None)
    assert second.made == ["cell-b"]
    assert [c.verdict for c in second.analysis.checks] == [REPRODUCED, REPRODUCED]


# -- run records: a study's report made again without its results files ------------------
def _toy_derive(name: str, path: Path) -> dict:
    """What the toy study keeps of a run in place of its frames: the frames' count and the
    mean x of the first frame (something only the frames hold)."""
    res = ds.load(path)
    frames = list(res.iter_frames())
    return {"toy": ({"first_mean_x": frames[0].position[:, 0].mean()},
                    {"frames": len(frames)})}


def _recorded_toy(monkeypatch) -> Study:
    from dataclasses import replace

    kept = merge(SHORT, {"measure": {"keep_frames": True}})
    study = replace(TOY, cases=lambda q: [Case("cell-a", "campbell1982/couette-rough",
                                               sections=kept)],
                    derive=_toy_derive)
    monkeypatch.setattr(sys.modules["demstudy_toy_study"], "STUDY", study)
    return study


def test_records_stand_in_for_missing_runs_and_are_remade_when_stale(toy, tmp_path, monkeypatch):
    """A study with ``derive`` writes a record of each run (no frames, no collision log, the
    derived group, the run's attributes); without the runs a rerun reuses the records as made
    runs and its analysis reads them; a record older than its run or of an older ``derive``
    is remade from the run; a damaged record or one of another scene is not used (the run is
    made again, with a warning)."""
    import os
    from dataclasses import replace

    import h5py

    study = _recorded_toy(monkeypatch)
    records = tmp_path / "records"
    first = run_study("toy", out=tmp_path / "a", records=records, echo=lambda s: None)
    assert first.made == ["cell-a"]
    record = records / "cell-a.h5"
    full = tmp_path / "a" / "runs" / "cell-a.h5"
    with h5py.File(record, "r") as f:
        assert "frames" not in f and "collisions" not in f
        assert "frames" in h5py.File(full, "r")
        assert f.attrs["record_of"] == "cell-a.h5"
        assert f.attrs["record_version"] == "1/toy:1"
        assert f["study/toy"].attrs["frames"] > 2
        assert "scene_toml" in f.attrs and "wall_seconds" in f.attrs
    kept = ds.load(full)
    assert ds.load(record).groups["study/toy"]["first_mean_x"] == pytest.approx(
        next(kept.iter_frames()).position[:, 0].mean())

    # stale: a run newer than its record, or a newer derive, remakes the record from the run
    written = record.stat().st_mtime
    os.utime(full, (written + 10, written + 10))
    lines: list[str] = []
    again = run_study("toy", out=tmp_path / "a", records=records, echo=lines.append)
    assert again.made == [] and any(line.startswith("  record ") for line in lines)
    monkeypatch.setattr(sys.modules["demstudy_toy_study"], "STUDY",
                        replace(study, derive_version=2))
    run_study("toy", out=tmp_path / "a", records=records, echo=lambda s: None)
    assert h5py.File(record, "r").attrs["record_version"] == "1/toy:2"

    # a fresh checkout: the study folder is gone, the records are there
    second = run_study("toy", out=tmp_path / "b", records=records, echo=lambda s: None)
    assert second.made == [] and second.from_records == ["cell-a"]
    assert second.analysis.checks[0].verdict == REPRODUCED
    assert second.analysis.checks[0].measured == first.analysis.checks[0].measured
    assert "1 from their records" in second.report.read_text()

    # damaged data behind intact attributes (a dataset that cannot be read): not used, the
    # run is made again
    with h5py.File(record, "r+") as f:
        f["timeseries"].create_dataset("lost", data=np.arange(10000.0), compression="gzip")
        chunk = f["timeseries/lost"].id.get_chunk_info(0)
    with open(record, "r+b") as fh:  # the compressed chunk overwritten: inflating it fails
        fh.seek(chunk.byte_offset)
        fh.write(b"\xff" * chunk.size)
    assert h5py.File(record, "r").attrs["record_of"] == "cell-a.h5"
    lines = []
    third = run_study("toy", out=tmp_path / "c", records=records, echo=lines.append)
    assert third.made == ["cell-a"]
    assert "lost" not in h5py.File(record, "r")["timeseries"]  # remade from the new run
    assert any("record of cell-a is not used" in line for line in lines), lines

    changed = merge(SHORT, {"measure": {"keep_frames": True}, "run": {"production": 12.0}})
    monkeypatch.setattr(sys.modules["demstudy_toy_study"], "STUDY", replace(
        sys.modules["demstudy_toy_study"].STUDY,
        cases=lambda q: [Case("cell-a", "campbell1982/couette-rough", sections=changed)]))
    fourth = run_study("toy", out=tmp_path / "d", records=records, echo=lambda s: None)
    assert fourth.made == ["cell-a"], "a record of another scene is not the run"


def test_a_record_scene_that_differs_only_by_written_defaults_is_the_same_scene():
    """A schema field added later with its default changes the scene text, not the scene:
    such a record still stands for its run; another value does not."""
    from demstudy.scene import load_scene, scene_to_toml
    from demstudy.studies.records import same_scene

    text = scene_to_toml(load_scene("campbell1982/couette-rough"))
    lines = text.splitlines()
    sparse = "\n".join(line for line in lines if not line.startswith("sample_interval"))
    assert sparse != text and same_scene(sparse, text)  # the default is written back
    other = text.replace("restitution = ", "restitution = 0.5 #", 1)
    assert not same_scene(other, text) and not same_scene(None, text)


def test_a_study_without_derive_keeps_no_records(toy, tmp_path):
    run_study("toy", out=tmp_path, only=["cell-a"], echo=lambda s: None)
    assert not (tmp_path / "records").exists()


def test_cli_records_option_analyses_kept_records_without_publishing(toy, tmp_path,
                                                                     monkeypatch):
    """``demstudy study NAME --analyse-only --records DIR``: the report from the records in
    DIR alone (no runs folder), nothing published."""
    from demstudy.cli import main

    _recorded_toy(monkeypatch)
    records = tmp_path / "kept"
    run_study("toy", out=tmp_path / "made", records=records, echo=lambda s: None)
    code = main(["study", "toy", "--analyse-only", "--records", str(records),
                 "--out", str(tmp_path / "fresh")])
    assert code == 0
    report = (tmp_path / "fresh" / "toy.md").read_text()
    assert "1 from their records" in report and "| 1 | toy | cell-a" in report
    assert not (tmp_path / "fresh" / "runs").exists()


def test_report_reasons_start_the_appended_notes_as_sentences():
    """A check's reason that runs into an appended note (an unsteady run, a TC share) gets a
    full stop before it; reasons that already have one, and table pipes, stay as they are."""
    from demstudy.studies.report import _reason

    assert _reason("longer runs needed The run (β = 0) is not steady") == \
        "longer runs needed. The run (β = 0) is not steady"
    assert _reason("not measured) The engine's TC model") == "not measured). The engine's TC model"
    assert _reason("done. The run x") == "done. The run x"
    assert _reason("The run first") == "The run first"
    assert _reason("|κ - 3| falls;  The engine") == "\\|κ - 3\\| falls; The engine"


def test_the_report_tallies_the_thesis_statements_apart_from_demstudys_own_checks(tmp_path):
    """The heading counts the thesis's statements by verdict ("no thesis value" among them:
    a measurement with nothing to compare to) and demstudy's own checks (engine cross-checks,
    model dependence) apart, and the legend explains every verdict."""
    from demstudy.studies.base import NO_THESIS_VALUE, NOT_REPRODUCED, PARTLY, VERDICTS
    from demstudy.studies.report import render
    from demstudy.studies.runner import StudyRun

    checks = [Check("a", "s", "1", "1", REPRODUCED), Check("b", "s", "1", "3", NOT_REPRODUCED),
              Check("c", "s", "-", "2", NO_THESIS_VALUE, "not in the digest"),
              Check("d", "soft = hard", "-", "x", PARTLY, "noisy", own=True),
              Check("e", "t_c", "-", "y", REPRODUCED, own=True)]
    study = types.SimpleNamespace(title="T", summary="S", reference="R", name="toy")
    text = render(StudyRun(study, tmp_path, analysis=Analysis(checks=checks)), False, "m")
    heading = next(line for line in text.splitlines() if line.startswith("## Statements"))
    assert heading == ("## Statements of the thesis checked (1 reproduced, 1 not reproduced, "
                       "1 no thesis value; and 2 of demstudy's own checks: 1 reproduced, "
                       "1 partly)")
    legend = text.split(heading)[1].split("| # |")[0]
    assert all(f"*{v}*" in legend for v in VERDICTS)
    assert "| 4 (own) | d |" in text and "| 1 | a |" in text
    alone = render(StudyRun(study, tmp_path, analysis=Analysis(checks=checks[3:])), False, "m")
    assert "## Statements of the thesis checked (2 of demstudy's own checks: 1 reproduced, " \
        "1 partly)" in alone
    with pytest.raises(ValueError, match="allowed are reproduced, partly"):
        Check("x", "s", "1", "1", "inconclusive")


def test_the_tc_rule_weakens_agreements_resting_on_a_run_the_tc_model_changed():
    """VERDICT_LEGEND's rule, study-wide: a row resting on a run whose TC-elastic share
    exceeds the engine's warning level names the share and an agreement becomes "partly"; a
    disagreement stays; a run shown not to depend on t_c keeps its rows' verdicts; rows
    below the level, without runs (the t_c row itself) and not run are left alone."""
    from demstudy.engines.edmd.tc_share import WARN_SHARE
    from demstudy.studies.base import NOT_REPRODUCED, NOT_RUN, PARTLY, REPRODUCED, tc_caveats

    def row(verdict, runs):
        return Check("ref", "statement", "thesis", "value", verdict, "why", runs=runs)

    shares = {"hot": (0.16, 1e-5), "cold": (0.5 * WARN_SHARE, 1e-5), "tested": (0.2, 1e-5),
              "soft": (float("nan"), float("nan"))}
    agree, differ, below, none, missing, tested, soft = (
        row(REPRODUCED, ("cold", "hot")), row(NOT_REPRODUCED, ("hot",)),
        row(REPRODUCED, ("cold",)), row(REPRODUCED, ()), row(NOT_RUN, ("hot",)),
        row(REPRODUCED, ("tested",)), row(REPRODUCED, ("soft",)))
    tc_caveats([agree, differ, below, none, missing, tested, soft], shares,
               {"tested": "its twin at t_c = 1e-6 agrees"})
    assert agree.verdict == PARTLY and "hot: 16.0 % (t_c = 1e-05 time units)" in agree.reason
    assert "cold" not in agree.reason.split("elastic (")[1]
    assert agree.reason.startswith("why. The engine's TC model") and agree.reason.endswith(".")
    assert differ.verdict == NOT_REPRODUCED and "hot: 16.0 %" in differ.reason
    assert tested.verdict == REPRODUCED and "its twin at t_c = 1e-6 agrees" in tested.reason
    for untouched in (below, none, missing, soft):
        assert "TC model" not in untouched.reason
    assert (below.verdict, none.verdict, missing.verdict) == (REPRODUCED, REPRODUCED, NOT_RUN)
    # a reason that discusses the TC model already gets no second note, but the same verdict
    named = Check("ref", "statement", "thesis", "value", REPRODUCED,
                  "the TC model's share is the cause here", runs=("hot",))
    tc_caveats([named], shares)
    assert named.verdict == PARTLY and named.reason == "the TC model's share is the cause here"


def test_a_twin_with_a_large_share_is_quoted_but_exempts_nothing():
    """A twin at another t_c whose own share is large shows whether the results converged in
    t_c, not a reference free of the TC model: its finding is quoted, the agreement still
    becomes "partly"."""
    from demstudy.studies.base import PARTLY, REPRODUCED, tc_caveats

    row = Check("ref", "statement", "thesis", "value", REPRODUCED, "", runs=("hot",))
    tc_caveats([row], {"hot": (0.06, 1e-5)}, {}, {"hot": "the twin of hot gives the same"})
    assert row.verdict == PARTLY and "(the twin of hot gives the same)" in row.reason
    # a run in both maps is exempted, and the twin's finding is not repeated
    row = Check("ref", "statement", "thesis", "value", REPRODUCED, "", runs=("hot",))
    tc_caveats([row], {"hot": (0.06, 1e-5)}, {"hot": "small twin agrees"}, {"hot": "told"})
    assert row.verdict == REPRODUCED and "small twin agrees" in row.reason
    assert "told" not in row.reason


def test_twin_comparison_allows_two_sigma_and_the_tolerance():
    from demstudy.studies.base import TWIN_TOLERANCE, twin_comparison, twin_evidence

    base = {"a": (1.0, 0.01), "b": (2.0, 0.0), "skip": (float("nan"), 0.0)}
    labels = {"a": "A", "b": "B", "skip": "S", "absent": "X"}
    same, text, off = twin_comparison(base, {"a": (1.0 + TWIN_TOLERANCE, 0.01),
                                             "b": (2.0, 0.0), "skip": (1.0, 0.0)}, labels)
    # 2σ of √2 · 0.01 plus 10 % of 1: a 10 % change passes; NaN and absent keys are left out
    assert same and text == "A 1.100 ± 0.010 (+10.0 %), B 2 (+0.0 %)" and off == []
    same, _text, off = twin_comparison(base, {"a": (1.0 + TWIN_TOLERANCE + 0.03, 0.01),
                                              "b": (2.0, 0.0)}, labels)
    assert not same and off == ["A +13 %"]
    assert not twin_comparison(base, {"c": (1.0, 0.0)}, labels)[0]  # nothing in common
    # the evidence: a small share exempts; a large one, or other values, is only told
    pairs = [("r1", base, base, 0.02, 1e-6), ("r2", base, base, 0.07, 1e-6),
             ("r3", base, {"a": (2.0, 0.01), "b": (2.0, 0.0)}, 0.02, 1e-6)]
    unchanged, told = twin_evidence(pairs, labels)
    assert list(unchanged) == ["r1"] and unchanged["r1"] == (
        "the twin of r1 at t_c = 1e-06 time units (2.0 % elastic) gives the same values "
        "within 2σ + 10 %")
    assert "the twin's own share is large too" in told["r2"]
    assert told["r3"].endswith("gives other values (A +100 %)")


def test_a_run_at_another_t_c_is_not_taken_for_the_case(tmp_path):
    """A results file (or record) of the right scene but made at another t_c is not the
    case's run: the runner makes it again and says why; files that predate the attribute,
    and engines without a t_c, pass."""
    from demstudy.accuracy.execute import is_done, option_mismatch
    from demstudy.scene import load_scene, scene_to_toml
    from demstudy.studies.records import why_not_current

    discs, spheres = {"scene_toml": "dimension = 2\n"}, {"scene_toml": "dimension = 3\n"}
    assert option_mismatch({"tc": 1e-5, **discs}, "edmd", {}) is None  # the 2D default
    assert option_mismatch({"tc": 1e-6, **spheres}, "edmd", {}) is None  # the 3D default
    # a 3D run made before the default for spheres became 1e-6 is not today's default run
    assert option_mismatch({"tc": 1e-5, **spheres}, "edmd", {}) == (
        "made at t_c = 1e-05, the run asks for t_c = 1e-06")
    assert option_mismatch({"tc": 1e-5, **spheres}, "edmd", {"tc": 1e-5}) is None
    assert option_mismatch({"tc": 1e-5, **discs}, "edmd", {"tc": 1e-6}) == (
        "made at t_c = 1e-05, the run asks for t_c = 1e-06")
    assert option_mismatch(discs, "edmd", {"tc": 1e-6}) is None  # older than the attribute
    assert option_mismatch({"tc": 1e-5}, "edmd", {"tc": 1e-6}) == (  # no scene, explicit t_c
        "made at t_c = 1e-05, the run asks for t_c = 1e-06")
    assert option_mismatch({"tc": 1e-5}, "edmd", {}) is None  # no scene: the default unknown
    assert option_mismatch({"tc": 1e-5, "scene_toml": b"dimension = 3\n"}, "edmd", {}) == (
        "made at t_c = 1e-05, the run asks for t_c = 1e-06")
    assert option_mismatch({"tc": 1e-5, **discs}, "lammps", {"tc": 1e-6}) is None
    scene = load_scene("campbell1982/couette-rough", ["run.equilibration=0",
                                                      "run.production=2"])
    path = tmp_path / "cell.h5"
    ds.run(scene, engine="edmd", out=path, progress=False)
    toml = scene_to_toml(scene)
    assert is_done(path, toml) and is_done(path, toml, "edmd", {})
    assert not is_done(path, toml, "edmd", {"tc": 1e-6})
    assert why_not_current(path, None, toml, "", "edmd", {"tc": 1e-6}) == (
        "the record was made at t_c = 1e-05, the run asks for t_c = 1e-06")
    assert why_not_current(path, None, toml, "", "edmd", {}) is None
