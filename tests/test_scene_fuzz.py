"""Fuzzing the scene validator: whatever the input, the only exception is ``SceneError``.

Arbitrary nested dicts and values, mutations of the real input scenes (a key deleted, a value
replaced by a random JSON-ish value, unknown keys inserted), arbitrary and mutated TOML text,
and ``--set`` overrides. A scene that validates must also survive the canonical dump.
Dimensionless particle units: d = 1, m = 1.
"""

from __future__ import annotations

import copy
import os
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from demstudy.scene import (
    Scene,
    SceneError,
    apply_overrides,
    parse_scene_text,
    scene_to_toml,
    validate_scene,
)
from demstudy.scene.load import read_scene_data

ROOT = Path(__file__).resolve().parents[1]
INPUTS = sorted((ROOT / "inputs").glob("**/*.toml"))
RAW = {str(p.relative_to(ROOT)): read_scene_data(p) for p in INPUTS}
TEXTS = {str(p.relative_to(ROOT)): p.read_text() for p in INPUTS}

#: Fixed examples by default (reproducible CI); DEMSTUDY_FUZZ_EXAMPLES=5000 runs a longer,
#: randomised campaign.
CAMPAIGN = int(os.environ.get("DEMSTUDY_FUZZ_EXAMPLES", "0"))
FUZZ = settings(max_examples=CAMPAIGN or 150, deadline=None, derandomize=not CAMPAIGN,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

#: Key names of the schema, so that random dicts reach the inner validators.
KEYS = sorted({
    "meta", "name", "description", "reference", "dimension", "box", "size", "periodic",
    "particles", "count", "solid_fraction", "inertia", "diameter_spread", "contact",
    "restitution", "law", "model", "e1", "e2", "crossover_speed", "tangential", "beta", "mu",
    "beta0", "walls", "side", "position", "kind", "velocity", "servo", "normal_stress",
    "interval_collisions", "scale_width", "hold_shear_rate", "bumps", "spacing", "diameter",
    "pattern", "gravity", "magnitude", "angle", "direction", "shear", "rate", "initial",
    "placement", "rows", "columns", "layers", "jitter", "path", "profile", "scale",
    "perturbation", "temperature", "run", "equilibration", "production", "sample_interval",
    "seed", "unit", "checkpoint_interval", "soft", "stiffness", "hardness", "overlap",
    "impact_speed", "k_star", "kappa", "pressure", "steps_per_contact", "measure", "axis",
    "bin_width", "statistics", "keep_frames",
})
WORDS = sorted({"lower", "upper", "flat", "bumpy", "smooth", "beta", "rough", "coulomb",
                "campbell-noslip", "hooke", "hertz", "lattice", "random", "file", "x", "y", "z",
                "disc", "sphere", "linear", "campbell-chute", "time", "collisions", "profiles"})

scalars = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.integers(min_value=-3, max_value=60),
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(min_value=-2.0, max_value=100.0),
    st.text(max_size=12),
    st.sampled_from(WORDS),
)
keys = st.one_of(st.sampled_from(KEYS), st.text(max_size=10))
jsonish = st.recursive(
    scalars,
    lambda children: st.one_of(
        st.lists(children, max_size=4),
        st.dictionaries(keys, children, max_size=5),
    ),
    max_leaves=25,
)


def check(data) -> Scene | None:
    """Validate; only SceneError may escape, and a valid scene must round-trip its dump."""
    try:
        scene = validate_scene(data)
    except SceneError as exc:
        assert exc.problems and all(isinstance(p, str) and p for p in exc.problems)
        return None
    again = validate_scene(parse_scene_text(scene_to_toml(scene)))
    assert again == scene
    return scene


@FUZZ
@given(st.dictionaries(keys, jsonish, max_size=8))
def test_arbitrary_dicts(data):
    check(data)


@FUZZ
@given(jsonish)
def test_arbitrary_values(data):
    check(data)


def paths(node, prefix=()):
    """Every (path) to a value inside nested dicts and lists."""
    if isinstance(node, dict):
        items = node.items()
    elif isinstance(node, list):
        items = enumerate(node)
    else:
        return
    for key, value in items:
        yield (*prefix, key)
        yield from paths(value, (*prefix, key))


def tables(node, prefix=()):
    if isinstance(node, dict):
        yield prefix
    if isinstance(node, dict | list):
        for key, value in node.items() if isinstance(node, dict) else enumerate(node):
            yield from tables(value, (*prefix, key))


def at(node, path):
    for key in path:
        node = node[key]
    return node


@st.composite
def mutated_scenes(draw):
    data = copy.deepcopy(RAW[draw(st.sampled_from(sorted(RAW)))])
    for _ in range(draw(st.integers(min_value=1, max_value=4))):
        op = draw(st.sampled_from(["delete", "replace", "insert"]))
        if op == "insert":
            where = draw(st.sampled_from(list(tables(data))))
            at(data, where)[draw(keys)] = draw(jsonish)
            continue
        all_paths = list(paths(data))
        if not all_paths:
            break
        path = draw(st.sampled_from(all_paths))
        parent = at(data, path[:-1])
        if op == "delete":
            del parent[path[-1]]
        else:
            parent[path[-1]] = draw(jsonish)
    return data


@FUZZ
@given(mutated_scenes())
def test_mutated_input_scenes(data):
    check(data)


@FUZZ
@given(st.text(max_size=200))
def test_arbitrary_toml_text(text):
    try:
        data = parse_scene_text(text)
    except SceneError:
        return
    check(data)


@st.composite
def mutated_texts(draw):
    lines = TEXTS[draw(st.sampled_from(sorted(TEXTS)))].splitlines()
    for _ in range(draw(st.integers(min_value=1, max_value=3))):
        i = draw(st.integers(min_value=0, max_value=len(lines) - 1))
        op = draw(st.sampled_from(["drop", "dup", "edit", "number"]))
        if op == "drop":
            del lines[i]
        elif op == "dup":
            lines.insert(i, lines[i])
        elif op == "edit" and lines[i]:
            j = draw(st.integers(min_value=0, max_value=len(lines[i]) - 1))
            lines[i] = lines[i][:j] + draw(st.text(max_size=3)) + lines[i][j + 1:]
        elif "=" in lines[i]:
            key = lines[i].split("=", 1)[0]
            value = draw(st.sampled_from(["-1", "0", "1e400", "nan", "-inf", "1e-320", "true",
                                          '"x"', "[]", "{}", "2", "0.5", "[1, 2, 3]"]))
            lines[i] = f"{key}= {value}"
        if not lines:
            break
    return "\n".join(lines)


@FUZZ
@given(mutated_texts())
def test_mutated_toml_text(text):
    try:
        data = parse_scene_text(text)
    except SceneError:
        return
    check(data)


@FUZZ
@given(st.lists(st.one_of(
    st.text(max_size=30),
    st.builds(lambda k, v: f"{k}={v}",
              st.lists(st.sampled_from(KEYS + ["0", "1", "walls", "x"]), min_size=1,
                       max_size=4).map(".".join),
              st.one_of(st.text(max_size=10), st.sampled_from(["1", "-1", "nan", "[1,2]",
                                                                "{model='beta', beta=0.5}"]))),
), max_size=4))
def test_overrides(items):
    data = copy.deepcopy(RAW["inputs/campbell1982/chute-30.toml"])
    try:
        out = apply_overrides(data, items)
    except SceneError:
        return
    check(out)
