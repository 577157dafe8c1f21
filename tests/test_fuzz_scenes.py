"""A fuzzer of scene files: a seeded, reproducible sample of mutants of every shipped scene
(``inputs/**/*.toml`` and the packaged presets) goes through ``demstudy validate`` and
``demstudy run`` in this process, through the CLI's ``main``.

Mutations: a value replaced (wrong types, booleans, strings for numbers, NaN, ±inf, huge,
tiny, negative, zero, arrays, tables), two values at once, a key removed, an unknown key
added, a value nested far too deep, invalid UTF-8 bytes inserted, a ``--set`` override as
typed. Asserted for each mutant:

* no traceback and no uncaught exception: ``validate`` exits 0 or 2;
* every refusal names the file, and each of its problems names a field of the scene (or,
  for a file that is not UTF-8 TOML, the line or byte);
* ``validate`` and ``run`` agree: what ``validate`` refuses, ``run`` refuses with exit 2
  before anything is written to the output folder; what it accepts, ``run --dry-run`` does
  not refuse as an invalid scene (an engine may still refuse what it cannot express:
  "unsupported by …", exit 2). Accepted mutants are only dry-run (the pilot is skipped), to
  stay fast.

Hypothesis runs derandomised (the same sample on every run and machine); the module takes
about 30 s. Dimensionless particle units (d = 1, m = 1, g = 1 with gravity) as every scene.
"""

from __future__ import annotations

import copy
import math
import os
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path

import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from demstudy.cli import main
from demstudy.scene.load import dump_toml
from demstudy.scene.presets import list_presets, preset_path
from demstudy.simulation import plan

ROOT = Path(__file__).resolve().parents[1]
#: a fixed sample by default (reproducible CI); DEMSTUDY_FUZZ_EXAMPLES=5000 runs a longer,
#: randomised campaign (as tests/test_scene_fuzz.py, the validator's own fuzzer)
CAMPAIGN = int(os.environ.get("DEMSTUDY_FUZZ_EXAMPLES", "0"))


def shipped_scenes() -> dict[str, dict]:
    """Every shipped scene's data by file name, with a tiny run (mutations may change it)."""
    paths = {p.resolve() for p in (ROOT / "inputs").rglob("*.toml")}
    paths |= {preset_path(name).resolve() for name in list_presets()}
    scenes = {}
    for path in sorted(paths):
        data = tomllib.loads(path.read_text(encoding="utf-8"))
        run = data.setdefault("run", {})
        run.update(equilibration=0.0, production=0.5, sample_interval=0.25)
        run.pop("checkpoint_interval", None)
        scenes[path.name] = data
    return scenes


SCENES = shipped_scenes()
NEST = "__nested__"  # replaced by a deeply nested array in the TOML text
NUMBERISH = ["0.5", "1", "1e3", "nan", "inf", "", " ", "true", "-1", "0x10"]
ODD_VALUES = st.one_of(
    st.booleans(),
    st.sampled_from(NUMBERISH),
    st.text(max_size=6),
    st.sampled_from([math.nan, math.inf, -math.inf, 1e300, -1e300, 5e-324, 1e-300, 0.0,
                     -0.0, -1.0, -0.5, 1e6, 2.5]),
    st.sampled_from([0, -1, 1, 2, 3, 7, 10**6, 2**63 - 1, -(2**63), 10**30]),
    st.sampled_from([[], [1.0], [1, "a"], [[1.0, 2.0]], [True, False], [0.0, 0.0, 0.0],
                     [1e300, 1e300], [-5.0, 10.0], [10.0, 10.0, 10.0, 10.0]]),
    st.sampled_from([{}, {"x": 1}, {"model": "nonsense"}, {"model": 3}]),
).map(copy.deepcopy)  # a fresh copy: the mutant changes it in place (two values)
SET_TEXTS = ["nan", "inf", "-1", "0", "1e400", "5e-324", "true", "'0.5'", "[1,", "{a = 1}",
             "", "[]", "[[[[[[1]]]]]]", "x" * 200, "1e300", "{ model = 'beta' }", "\u00e9"]
INVALID_UTF8 = [b"\xff", b"\xfe\xff", b"\xc3\x28", b"\xed\xa0\x80", b"\x80", b"\xf8\x88\x80"]


def places(node, path=()) -> list[tuple]:
    """Paths of every key and array item below ``node`` (tables, arrays, leaves)."""
    out = []
    items = node.items() if isinstance(node, dict) else enumerate(node) \
        if isinstance(node, list) else ()
    for key, value in items:
        out.append((*path, key))
        out.extend(places(value, (*path, key)))
    return out


def tables(node, path=()) -> list[tuple]:
    """Paths of every table (the root is ``()``)."""
    out = [path] if isinstance(node, dict) else []
    items = node.items() if isinstance(node, dict) else enumerate(node) \
        if isinstance(node, list) else ()
    for key, value in items:
        out.extend(tables(value, (*path, key)))
    return out


def at(data, path: tuple):
    for key in path:
        data = data[key]
    return data


@dataclass
class Mutant:
    scene: str
    how: str
    text: bytes
    keys: set[str]  # every key name of the original and the mutant (what a message may name)
    overrides: tuple[str, ...] = ()  # --set arguments given with it

    def __repr__(self) -> str:  # what hypothesis prints for a failing example
        return f"Mutant({self.scene}: {self.how})"


@st.composite
def mutants(draw) -> Mutant:
    name = draw(st.sampled_from(sorted(SCENES)))
    data = copy.deepcopy(SCENES[name])
    keys = {k for p in places(data) for k in p if isinstance(k, str)}
    kind = draw(st.sampled_from(["value", "value", "value", "two values", "delete",
                                 "unknown", "nest", "utf8", "--set"]))
    how, depth = kind, 0
    if kind == "two values":  # two fields at once: rules that relate fields
        changed = []
        for _ in range(2):
            path = draw(st.sampled_from(places(data)))
            at(data, path[:-1])[path[-1]] = value = draw(ODD_VALUES)
            changed.append(f"{'.'.join(map(str, path))} = {value!r}")
        how = f"values {'; '.join(changed)}"
    elif kind in ("value", "delete", "nest"):
        path = draw(st.sampled_from(places(data)))
        parent, key = at(data, path[:-1]), path[-1]
        if kind == "delete":
            del parent[key]
        elif kind == "nest":
            depth = draw(st.sampled_from([4, 40, 3000]))
            parent[key] = NEST
        else:
            parent[key] = draw(ODD_VALUES)
            how = f"{kind} {'.'.join(map(str, path))} = {parent[key]!r}"
        how = how if kind == "value" else f"{kind} {'.'.join(map(str, path))}"
    elif kind == "--set":  # the file intact, a command-line override as typed
        path = draw(st.sampled_from(places(data)))
        dotted = ".".join(map(str, path))
        text = draw(st.sampled_from(SET_TEXTS))
        keys |= {k for p in places(data) for k in p if isinstance(k, str)}
        return Mutant(name, f"--set {dotted}={text}", dump_toml(data).encode(), keys,
                      ("--set", f"{dotted}={text}"))
    elif kind == "unknown":
        path = draw(st.sampled_from(tables(data)))
        at(data, path)["unknown_key"] = draw(ODD_VALUES)
        keys.add("unknown_key")
        how = f"unknown key in [{'.'.join(map(str, path))}]"
    text = dump_toml(data).encode()
    if depth:
        text = text.replace(f'"{NEST}"'.encode(), b"[" * depth + b"1" + b"]" * depth)
    if kind == "utf8":
        where = draw(st.integers(0, len(text)))
        text = text[:where] + draw(st.sampled_from(INVALID_UTF8)) + text[where:]
        how = f"invalid UTF-8 at byte {where}"
    keys |= {k for p in places(data) for k in p if isinstance(k, str)}
    return Mutant(name, how, text, keys)


class PilotSkipped(Exception):
    """The dry run reached the pilot (an engine run): the scene was not refused before it."""


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("fuzz")


def cli(capsys, *args: str) -> tuple[int, str]:
    """Exit code and stderr of ``demstudy ARGS`` in this process (argparse's SystemExit too);
    any other exception escapes: a traceback is a failure."""
    capsys.readouterr()
    try:
        code = main(list(args))
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    err = capsys.readouterr().err
    assert "Traceback" not in err, err
    return code, err


FILE_PROBLEM = re.compile(r"not UTF-8|not valid TOML|nested more than|line \d+|byte")


def assert_names_fields(err: str, mutant: Mutant, path: Path) -> None:
    """A refusal names the file, and every problem a field of the scene (or where in the
    file it is not UTF-8 TOML)."""
    assert str(path) in err, err
    problems = [line.strip()[2:] for line in err.splitlines() if line.strip().startswith("- ")]
    assert problems, err
    for problem in problems:
        named = set(re.findall(r"[A-Za-z_][A-Za-z0-9_]*", problem)) & mutant.keys
        assert named or FILE_PROBLEM.search(problem), f"{mutant}: names no field: {problem}"


@settings(max_examples=CAMPAIGN or 300, derandomize=not CAMPAIGN, database=None, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow,
                                 HealthCheck.data_too_large])
@given(mutant=mutants(), engine=st.sampled_from(["edmd", "lammps"]))
def test_mutated_scenes_are_refused_by_name_or_agree(mutant, engine, folder, capsys,
                                                     monkeypatch):
    def skip_pilot(*_args, **_kw):
        raise PilotSkipped

    monkeypatch.setattr(plan, "run_pilot", skip_pilot)
    path = folder / "scene.toml"
    path.write_bytes(mutant.text)
    code, err = cli(capsys, "validate", str(path), *mutant.overrides)
    event(f"validate exit {code}")
    assert code in (0, 2), f"{mutant}: validate exit {code}: {err}"
    if code == 2:
        assert_names_fields(err, mutant, path)
        out = folder / "out"
        out.mkdir(exist_ok=True)
        for extra in (["--dry-run"], []):
            run_code, run_err = cli(capsys, "run", str(path), *mutant.overrides, "--engine",
                                    engine, "--out", str(out / "r.h5"), "-q", *extra)
            assert run_code == 2, f"{mutant}: validate refused, run exit {run_code}: {run_err}"
            assert not list(out.iterdir()), f"{mutant}: refused, yet wrote {list(out.iterdir())}"
        return
    try:
        run_code, run_err = cli(capsys, "run", str(path), *mutant.overrides, "--engine",
                                engine, "--out", str(folder / "r.h5"), "-q", "--dry-run")
    except PilotSkipped:
        event("dry run reached the pilot")
        return  # the scene got as far as the engine's pilot: not refused
    event(f"dry run exit {run_code}")
    assert run_code in (0, 2), f"{mutant}: dry run exit {run_code}: {run_err}"
    if run_code == 2:  # only the engine may refuse what validate accepted
        assert "unsupported by" in run_err and "invalid scene" not in run_err, \
            f"{mutant}: validate accepted, run --dry-run refused: {run_err}"


# -- defects the fuzzer found, each refused by name now -------------------------------------
@pytest.mark.parametrize(("scene", "change", "named"), [
    # k_n ∝ impact_speed²: 5e-324 gave k_n = 0 and a ZeroDivisionError traceback in validate
    ("malik2008/poiseuille-phi0.01", "soft.hardness.impact_speed=5e-324",
     "soft.hardness.impact_speed = 5e-324"),
    # an overlap of 1.1e5 d: the restitution compensation's model collision never ended
    # (RuntimeError traceback from run --dry-run, after validate accepted it)
    ("malik2008/poiseuille-phi0.01", "soft.hardness.impact_speed=1e-6", "soft.hardness = "),
    ("cooling/hcs-3d", "soft={ stiffness = 1e-6 }", "soft.stiffness = 1e-06"),
    # an overlap of 7e-151 d is lost in the positions: the model collision never touched
    ("cooling/hcs-3d", "soft={ stiffness = 1e300 }", "soft.stiffness = 1e+300"),
    # k_n = k* γ̇² d underflowed to 0: ZeroDivisionError traceback in validate
    ("shear/lees-edwards-2d", "shear.rate=5e-324", "shear.rate = 4.94066e-324"),
    # the soft engines' damping root search failed: "error: math domain error", exit 1
    ("cooling/hcs-3d", "contact.restitution=5e-324", "contact.restitution = 5e-324"),
])
@pytest.mark.parametrize("engine", ["lammps", "edmd"])
def test_values_the_fuzzer_broke_are_refused_by_validate_and_run(
        scene, change, named, engine, tmp_path, capsys):
    """Contacts so soft that particles pass through each other, or so stiff that the overlap
    is lost in double precision, and restitutions no soft engine can damp for: validate and
    run (also the event-driven engine, for which the scene as a whole is invalid) refuse them
    with exit 2 naming the field, and write nothing."""
    code, err = cli(capsys, "validate", scene, "--set", change)
    assert code == 2 and named in err, err
    out = tmp_path / "out"
    code, err = cli(capsys, "run", scene, "--set", change, "--engine", engine, "--dry-run",
                    "--out", str(out / "r.h5"))
    assert code == 2 and named in err and not out.exists(), err


def test_soft_but_usable_contacts_still_only_warn(capsys):
    """k_n = 600 in chute-30 overlaps by about 0.24 d: far from hard particles, warned about,
    but a valid run (the overlap range refuses only from half a diameter on)."""
    code, err = cli(capsys, "validate", "campbell1982/chute-30", "--set", "soft.stiffness=600")
    assert code == 0 and "warning:" in err and "soft.stiffness = 600" in err
