"""``demstudy stability``: the suite's rows, its writers and its verdicts.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts. A few quick cases run for
real (a very stiff binary collision restitutes to e; a time step too large for a Hertz contact
hit faster than designed is flagged; hard-particle resting states); the bookkeeping (a failing
case is "fail", a refusing engine "refused", an engine that cannot load "refused", a broken
case "error") uses cases and backends registered for the test.
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
from ballistic_backend import BallisticBackend  # noqa: E402

import demstudy as ds  # noqa: E402
from demstudy import engines  # noqa: E402
from demstudy.cli import main  # noqa: E402
from demstudy.errors import BadOption  # noqa: E402
from demstudy.stability import CASES, SOFT, Outcome, case_names, run_suite  # noqa: E402
from demstudy.stability.registry import Case, Row, Suite  # noqa: E402
from demstudy.stability.report import (  # noqa: E402
    HAND_WRITTEN,
    format_markdown,
    format_text,
    write_outputs,
)


def row_of(rows: list[Row], name: str, engine: str) -> Row:
    (row,) = [r for r in rows if r.case == name and r.engine == engine]
    return row


# -- real cases -----------------------------------------------------------------------------
def test_stiff_contacts_restitute_to_e_in_lammps():
    """k_n up to 1e9 with the automatic time step: |e_measured − e| < 0.01 for the pair and
    the wall (measured: ≤ 0.003), nothing lost."""
    (row,) = ds.stability(engines=["lammps"], cases=["stiff-contacts"], quick=True)
    assert row.status == "pass", row.note
    assert float(row.measured.split()[-1]) < 0.01
    assert "k_n 1e+09" in row.note


def test_a_time_step_too_large_for_the_contact_is_flagged():
    """Deliberately broken resolution: steps_per_contact = 5 is refused by the scene, and a
    Hertz contact made for speed 1 at 10 steps hit at 30 (t_c ∝ v^-1/5: about 5 steps) is
    flagged by the run's health verdict, not silently wrong."""
    (row,) = ds.stability(engines=["lammps"], cases=["timestep-too-large"], quick=True)
    assert row.status == "pass", row.note
    steps = float(row.measured.rsplit(" ", 1)[-1])
    assert 4.0 < steps < 10.0  # 10 / 30^(1/5) = 5.06 expected
    assert "min_steps_per_contact" in row.note and "greater than or equal to 10" in row.note


def test_dense_rough_shear_is_explained_as_the_elastic_regime():
    """Rough soft discs (β = 0) sheared at ν = 0.82: outside the limits (overlaps, heat), and
    the case measures why: 10 x k_n leaves the mean overlap (quick: 0.74 of it; a collisional
    flow: 10^-1/2) and doubles the heat about the shear profile (2.3 x), contacts persist."""
    (row,) = ds.stability(engines=["lammps"], cases=["dense-shear-2d"], quick=True)
    assert row.status == "explained", row.note
    assert row.note.startswith("explained: elastic regime")
    heat = float(row.measured.split("(heat ")[1].split(" x")[0])
    assert heat > 2.0  # soft heat against the event-driven run's (quick: 6.9 x)


def test_hard_resting_cases_pass_in_edmd():
    rows = ds.stability(engines=["edmd"], cases=["ball-rests-on-floor", "rests-on-bump",
                                                  "tc-prevents-collapse"], quick=True)
    assert [r.case for r in rows] == ["tc-prevents-collapse", "ball-rests-on-floor",
                                      "rests-on-bump"]  # the table's order
    assert case_names()[0] == "stiff-contacts"  # soft-contact cases first
    assert all(r.status == "pass" for r in rows), [r.note for r in rows]


def test_cases_run_in_the_engines_of_their_kind():
    names = case_names()
    assert {"stiff-contacts", "elastic-drift", "fast-impacts", "timestep-too-large",
            "dense-shear-2d", "dense-shear-3d", "servo-10x", "very-soft",
            "collapse-without-tc", "tc-dependence", "elastic-drift-hard"} <= set(names)
    from demstudy.stability import plan_rows

    pairs = [(c.name, e.name) for c, e in plan_rows()]
    soft_engines = [n for n in engines.backend_names() if engines.get_backend(n).kind == SOFT]
    for engine in soft_engines:  # every soft engine registered gets every soft case
        assert ("very-soft", engine) in pairs
    assert ("very-soft", "edmd") not in pairs and ("column-stacks", "lammps") not in pairs


# -- bookkeeping ----------------------------------------------------------------------------
@pytest.fixture
def fake_cases(monkeypatch):
    """Four soft cases: one passes, one fails, one breaks, one runs a real scene; and a
    soft engine that refuses every scene (the ballistic test backend)."""
    def passing(engine, quick, folder):
        return Outcome("1.0", True, "fine")

    def failing(engine, quick, folder):
        return Outcome("7.0", False, "7 is above the limit")

    def breaking(engine, quick, folder):
        raise ZeroDivisionError("division by zero in the case")

    def explaining(engine, quick, folder):
        return Outcome("9.0", False, "9 is above the limit", "a documented cause, measured")

    def passing_with_cause(engine, quick, folder):  # within the limit: a cause changes nothing
        return Outcome("2.0", True, "fine", "a documented cause, measured")

    def scene_run(engine, quick, folder):  # a real scene through the loop
        from demstudy.stability.soft import very_soft
        return very_soft(engine, quick, folder)

    cases = {name: Case(name, SOFT, f"{name} checks", "< 5", run) for name, run in
             (("p", passing), ("f", failing), ("b", breaking), ("s", scene_run),
              ("x", explaining), ("px", passing_with_cause))}
    monkeypatch.setattr("demstudy.stability.registry.CASES", cases)

    class RefusingSoft(BallisticBackend):
        name = "refusing-soft"
        kind = SOFT

    backends = dict(engines._BACKENDS)
    backends["refusing-soft"] = RefusingSoft
    monkeypatch.setattr(engines, "_BACKENDS", backends)
    return cases


def test_fail_refused_and_error_rows(fake_cases, tmp_path):
    engines._BACKENDS["missing"] = "demstudy.engines.no_such_module:Backend"
    suite = run_suite(["refusing-soft", "missing"], ["p", "f", "b", "s"], quick=True,
                      workdir=tmp_path)
    status = {(r.case, r.engine): r.status for r in suite.rows}
    assert status[("f", "refusing-soft")] == "fail"
    assert status[("p", "refusing-soft")] == "pass"
    assert status[("b", "refusing-soft")] == "error"
    assert "ZeroDivisionError" in row_of(suite.rows, "b", "refusing-soft").note
    # the engine refuses the scene before anything runs: a legitimate row
    refused = row_of(suite.rows, "s", "refusing-soft")
    assert refused.status == "refused" and "unsupported by refusing-soft" in refused.note
    # an engine that cannot load gives refused rows naming the load error
    assert all(r.status == "refused" and "engine unavailable" in r.note
               for r in suite.rows if r.engine == "missing")
    assert {r.case for r in suite.failed} == {"f", "b"}
    text = format_text(suite)
    assert "FAIL    f [refusing-soft]" in text and "refused" in text


def test_an_explained_row_is_neither_pass_nor_fail(fake_cases, tmp_path, capsys):
    """A figure outside its limit whose cause the case measured is "explained": listed with
    the cause in its note, counted apart, not a failure (the CLI exits 0)."""
    suite = run_suite(["lammps"], ["x", "px", "p"], quick=True, workdir=tmp_path)
    status = {r.case: r.status for r in suite.rows}
    assert status == {"x": "explained", "px": "pass", "p": "pass"}
    row = row_of(suite.rows, "x", "lammps")
    assert row.note == "explained: a documented cause, measured; 9 is above the limit"
    assert suite.failed == []
    assert "1 explained" in format_text(suite)
    assert "| **explained** |" in format_markdown(suite)
    assert main(["stability", "--engine", "lammps", "--case", "x",
                 "--out", str(tmp_path / "s.md")]) == 0
    assert "explained x [lammps]" in capsys.readouterr().out


def test_unknown_case_or_engine_is_refused_before_running():
    with pytest.raises(BadOption, match="--case = 'no-such-case'"):
        run_suite(None, ["no-such-case"])
    with pytest.raises(BadOption, match="--engine = 'nope'"):
        run_suite(["nope"], None)
    assert main(["stability", "--case", "no-such-case", "--out", "/nonexistent/x.md"]) == 2


def test_markdown_csv_and_json_hold_every_row(tmp_path):
    rows = [Row("a-case", "lammps", "checks a | b", "0.5 d", "< 1", "pass", "why", 1.25),
            Row("b-case", "edmd", "checks b", "9", "< 1", "fail", "too big", 0.5),
            Row("c-case", "liggghts", "checks c", "-", "< 1", "refused", "refused: no", 0.0)]
    suite = Suite(rows, quick=True, seconds=2.0)
    md_path, csv_path, json_path = write_outputs(suite, tmp_path / "out" / "stab.md",
                                                 command="demstudy stability --quick")
    md = md_path.read_text()
    assert "dimensionless particle units" in md and "Machine:" in md
    assert "`demstudy stability --quick`" in md and "quick suite" in md
    assert "| a-case | lammps | checks a \\| b | 0.5 d | < 1 | **pass** | 1.2 s |" in md
    assert "**FAIL**" in md and "**refused**" in md
    table = list(csv.DictReader(line for line in csv_path.read_text().splitlines()
                                if not line.startswith("#")))
    assert [r["status"] for r in table] == ["pass", "fail", "refused"]
    data = json.loads(json_path.read_text())
    assert data["quick"] is True and data["rows"][1]["measured"] == "9"
    assert "d = 1" in data["units"]
    assert format_markdown(suite).count("\n| ") == 4  # header + 3 rows
    # a hand-written part after the marker survives a rewrite; the table is new
    md_path.write_text(md.replace("a-case", "old-case") + HAND_WRITTEN + "\n## Findings\n")
    write_outputs(suite, md_path)
    again = md_path.read_text()
    assert again.endswith(HAND_WRITTEN + "\n## Findings\n") and "old-case" not in again


def test_cli_writes_the_table_and_exits_by_the_verdict(tmp_path, capsys):
    out = tmp_path / "stability.md"
    assert main(["stability", "--quick", "--case", "rests-on-bump", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "pass    rests-on-bump [edmd]" in printed and str(out) in printed
    assert out.exists() and out.with_suffix(".csv").exists() and out.with_suffix(".json").exists()
    assert "--case rests-on-bump" in out.read_text()


def test_cli_exit_1_when_a_row_fails(fake_cases, tmp_path):
    assert main(["stability", "--engine", "lammps", "--case", "f",
                 "--out", str(tmp_path / "s.md")]) == 1


def test_ds_stability_is_callable_after_importing_the_package():
    import demstudy.stability as module

    assert ds.stability is module and callable(ds.stability)
    assert "stiff-contacts" in CASES


class HookeOnly(engines.get_backend("lammps")):
    """LAMMPS refusing Hertz contacts, as the LIGGGHTS engine does (module level: an isolated
    run's child process imports it)."""

    @classmethod
    def check(cls, scene, options):
        from demstudy.errors import UnsupportedByEngine

        if scene.soft.model == "hertz":
            raise UnsupportedByEngine("hooke-only", "soft.model", "hertz", "Hooke only")
        super().check(scene, options)


def test_an_engine_refusing_part_of_a_case_still_gets_its_row(monkeypatch, tmp_path):
    """An engine without Hertz contacts: fast-impacts reports its Hooke runs and names the
    refused Hertz ones; timestep-too-large keeps its validation check."""
    from demstudy.stability.soft import fast_impacts, timestep_too_large

    monkeypatch.setattr(engines, "_BACKENDS", {**engines._BACKENDS, "lammps": HookeOnly})
    impacts = fast_impacts("lammps", True, tmp_path)
    assert "hooke pairs" in impacts.measured and "hertz" not in impacts.measured
    assert "hertz pairs: unsupported by hooke-only" in impacts.note
    step = timestep_too_large("lammps", True, tmp_path)
    assert step.passed and "Hertz refused" in step.measured
