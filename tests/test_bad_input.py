"""Bad input refused before any engine starts: particle files (``initial.placement = "file"``)
and ``demstudy validate`` on broken scene files (exit 2, every file named).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest

from demstudy.cli import main
from demstudy.scene import SceneError, validate_scene
from demstudy.scene.initial import build_initial_state
from demstudy.scene.load import dump_toml
from demstudy.scene.particle_file import TOLERANCE

#: 2D couette cell: x periodic (length 10), walls at y = 0 and y = 10 (no bumps).
COUETTE = {
    "dimension": 2,
    "box": {"size": [10.0, 10.0]},
    "particles": {},
    "walls": [{"side": "lower", "velocity": 0.0, "restitution": 0.9},
              {"side": "upper", "velocity": 1.0, "restitution": 0.9}],
    "contact": {"restitution": 0.9},
    "run": {"equilibration": 0.0, "production": 1.0, "sample_interval": 0.5},
}
GOOD = [[2.0, 2.0], [5.0, 5.0], [8.0, 8.0]]


def file_scene(tmp_path: Path, rows, count: int | None = None, name: str = "p.txt",
               **changes) -> dict:
    path = tmp_path / name
    path.write_text("# x y\n" + "\n".join(" ".join(repr(v) for v in r) for r in rows) + "\n")
    data = copy.deepcopy(COUETTE) | changes
    data["initial"] = {"placement": "file", "path": str(path)}
    if count is not None:
        data["particles"] = {"count": count}
    else:
        data["particles"] = {}
    return data


def refused(data: dict) -> str:
    with pytest.raises(SceneError) as info:
        validate_scene(data)
    return str(info.value)


def test_good_file_gives_count_and_positions(tmp_path):
    scene = validate_scene(file_scene(tmp_path, GOOD))
    assert scene.n_particles == len(GOOD)  # no particles.count: the file's rows are the count
    state = build_initial_state(scene)
    np.testing.assert_array_equal(state.position, GOOD)


@pytest.mark.parametrize("rows, expected", [
    ([[2.0, 1e6], *GOOD], "row 1 (line 2) y = 1000000: allowed 0.5 <= y <= 9.5"),
    ([*GOOD, [4.0, 0.3]], "row 4 (line 5) y = 0.3: allowed 0.5 <= y"),
    ([[-0.5, 3.0], *GOOD], "row 1 (line 2) x = -0.5: outside the periodic box; allowed 0 <= x"),
    ([[10.0, 3.0]], "x = 10: outside the periodic box; allowed 0 <= x < box.size[0] = 10"),
    ([[3.0, 3.0], [3.3, 3.0]], "rows 1 and 2 (lines 2, 3) are 0.3 apart, overlapping by 0.7 d"),
    # across the periodic x boundary: 0.2 and 9.9 are 0.3 apart
    ([[0.2, 3.0], [9.9, 3.0]], "rows 1 and 2 (lines 2, 3) are 0.3 apart"),
    ([[3.0, 3.0, 1.0]], "3 columns; a 2D scene needs 2 or 4 (x y vx vy)"),
    ([[3.0, float("nan")]], "row 1 (line 2) column 2 = nan; values must be finite"),
])
def test_bad_particle_file_names_field_file_row_and_value(tmp_path, rows, expected):
    message = refused(file_scene(tmp_path, rows))
    assert "initial.path = " in message and "p.txt" in message
    assert expected in message


def test_wall_and_overlap_tolerance(tmp_path):
    """Touching (distance = d) and a radius from the wall are allowed, up to the tolerance."""
    eps = TOLERANCE / 2
    ok = [[3.0, 0.5 - eps], [4.0 - eps, 0.5], [5.0, 9.5 + eps]]
    assert validate_scene(file_scene(tmp_path, ok)).n_particles == 3
    bad = [[3.0, 0.5], [4.0 - 3 * TOLERANCE, 0.5]]
    assert "overlapping by 3e-09 d" in refused(file_scene(tmp_path, bad))


def test_overlap_uses_the_run_diameters(tmp_path):
    """With a diameter spread, the check uses the diameters the run draws for this seed."""
    data = file_scene(tmp_path, [[3.0, 3.0], [4.0, 3.0]])
    data["particles"] = {"diameter_spread": 0.2}
    outcomes = set()
    for seed in range(1, 21):  # some seeds give a pair larger on average than 1: overlap
        data["run"] = COUETTE["run"] | {"seed": seed}
        no_spread = copy.deepcopy(data)
        no_spread["particles"] = {}
        d = build_initial_state(validate_scene(no_spread | {"particles": {
            "diameter_spread": 0.2, "count": 2}, "initial": {"placement": "random"}})).diameter
        overlapping = d.sum() / 2 > 1.0 + TOLERANCE  # the diameters this seed draws
        try:
            validate_scene(data)
            outcomes.add(False)
            assert not overlapping
        except SceneError as exc:
            outcomes.add(True)
            assert overlapping and "rows 1 and 2" in str(exc)
    assert outcomes == {True, False}


def test_row_count_against_particles_count(tmp_path):
    message = refused(file_scene(tmp_path, GOOD, count=5))
    assert "3 rows but particles.count = 5" in message


@pytest.mark.parametrize("text, expected", [
    ("1 2\n3 4 5\n", "row 2 (line 2) has 3 columns, the first row 2"),
    ("1 2\n3 x\n", "row 2 (line 2): 'x' is not a number"),
    ("# only a comment\n", "no particle rows"),
])
def test_unparsable_particle_file(tmp_path, text, expected):
    data = file_scene(tmp_path, GOOD)
    Path(data["initial"]["path"]).write_text(text)
    assert expected in refused(data)


def test_missing_particle_file(tmp_path):
    data = file_scene(tmp_path, GOOD)
    data["initial"]["path"] = str(tmp_path / "absent.txt")
    assert "absent.txt'" in refused(data) and "cannot read the file" in refused(data)


def test_cli_refuses_bad_file_before_any_engine(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text(dump_toml(file_scene(tmp_path, [[3.0, 3.0], [3.3, 3.0]])))
    for command in (["validate", str(scene)],
                    ["run", str(scene), "--out", str(tmp_path / "r.h5"), "-q"]):
        assert main(command) == 2
        err = capsys.readouterr().err
        assert "initial.path" in err and "rows 1 and 2" in err and "Traceback" not in err
    assert not (tmp_path / "r.h5").exists()


def test_validate_counts_file_rows(tmp_path, capsys):
    """A one-row file: validate reports 1 particle (it said 0 and run refused it)."""
    scene = tmp_path / "s.toml"
    scene.write_text(dump_toml(file_scene(tmp_path, [[5.0, 5.0]])))
    assert main(["validate", str(scene)]) == 0
    assert "1 particles" in capsys.readouterr().out


# ------------------------------------------------------------ demstudy validate on broken files

ROOT = Path(__file__).resolve().parent.parent
CHUTE = ROOT / "inputs" / "campbell1982" / "chute-30.toml"


def broken_scenes(tmp_path: Path) -> dict[str, Path]:
    """One scene file per way of being broken (each was once exit 1, a traceback or a stop)."""
    files = {
        "utf8": b"dimension = 2\nmeta = { name = 'caf\xe9' }\n",  # Latin-1, not UTF-8
        "toml": b"dimension = [2,\n",
        "value": CHUTE.read_bytes().replace(b"restitution = 0.6", b"restitution = 1.6"),
        "deep": b"a = " + b"[" * 10_000 + b"]" * 10_000 + b"\n",
        "deep-ok-for-tomllib": b"[meta]\nname = " + b"[" * 100 + b"]" * 100 + b"\n",
    }
    out = {}
    for name, content in files.items():
        out[name] = tmp_path / f"{name}.toml"
        out[name].write_bytes(content)
    out["missing"] = tmp_path / "missing.toml"
    return out


@pytest.mark.parametrize("kind", ["utf8", "toml", "value", "deep", "deep-ok-for-tomllib",
                                  "missing"])
def test_validate_exits_2_on_each_kind_of_broken_file(tmp_path, capsys, kind):
    path = broken_scenes(tmp_path)[kind]
    assert main(["validate", str(path)]) == 2
    err = capsys.readouterr().err
    assert f"invalid scene {path}" in err and "Traceback" not in err


def test_validate_checks_every_file_and_names_each(tmp_path, capsys):
    broken = broken_scenes(tmp_path)
    files = [*broken.values(), CHUTE]
    assert main(["validate", *map(str, files)]) == 2
    captured = capsys.readouterr()
    for path in broken.values():
        assert f"invalid scene {path}:" in captured.err
    assert f"ok: {CHUTE}" in captured.out  # the good file after the broken ones is checked
    assert "byte 0xe9 at line 2" in captured.err and "nested more than" in captured.err


def test_deep_values_refused_without_recursion(tmp_path):
    """load_scene, --set values and keyword sections: nesting is measured, not recursed."""
    from demstudy.scene import load_scene
    from demstudy.scene.load import MAX_DEPTH

    deep: object = 1
    for _ in range(5000):
        deep = [deep]
    with pytest.raises(SceneError, match="nested more than"):
        load_scene(CHUTE, meta={"name": deep})
    with pytest.raises(SceneError, match=r"meta.name\[0\].*nested more than"):
        load_scene(CHUTE, ["meta.name=" + "[" * 400 + "]" * 400])
    shallow: object = "x"
    for _ in range(MAX_DEPTH - 2):
        shallow = [shallow]
    # within the limit: an ordinary validation error (a name is a string), not a depth error
    with pytest.raises(SceneError, match="meta.name = ") as info:
        load_scene(CHUTE, meta={"name": shallow})
    assert "nested" not in str(info.value)


def test_damaged_checkpoint_given_to_resume_exits_2_naming_it(tmp_path, capsys):
    """A damaged checkpoint is bad input given with --resume: the CLI refuses it with exit 2
    (README: 2 = nothing ran) naming the file, for the isolated child run as for the
    in-process one, writes no results file, and the intact checkpoint then resumes."""
    scene = tmp_path / "couette.toml"
    scene.write_text(dump_toml(COUETTE | {"particles": {"count": 20}}))
    out = tmp_path / "r.h5"
    args = ["run", str(scene), "--engine", "edmd", "--out", str(out), "-q"]
    assert main([*args, "--wall-limit", "0"]) == 3  # stopped after a checkpoint
    ckpt = tmp_path / "r.edmd" / "checkpoint.pkl"
    intact = ckpt.read_bytes()
    flipped = bytearray(intact)
    flipped[len(flipped) // 2] ^= 0xFF
    ckpt.write_bytes(bytes(flipped))
    capsys.readouterr()
    assert main([*args, "--resume"]) == 2
    err = capsys.readouterr().err
    assert f"checkpoint {ckpt} is damaged" in err and "Traceback" not in err
    assert not out.exists()
    ckpt.write_bytes(intact)
    assert main([*args, "--resume"]) == 0 and out.exists()
