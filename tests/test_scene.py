"""Scene files: loading every input, error messages, overrides, cross-field rules, initial
states and the canonical TOML dump.

Dimensionless particle units throughout: d = 1, m = 1 (g = 1 when gravity acts).
"""

from __future__ import annotations

import copy
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

from demstudy.scene import (
    Scene,
    SceneError,
    apply_overrides,
    load_scene,
    parse_scene_text,
    scene_to_toml,
    validate_scene,
)
from demstudy.scene.initial import MARGIN, build_initial_state
from demstudy.scene.load import read_scene_data
from demstudy.scene.schema import MAX_PACKING

ROOT = Path(__file__).resolve().parents[1]
INPUTS = sorted((ROOT / "inputs").glob("**/*.toml"))
IDS = [str(p.relative_to(ROOT / "inputs")) for p in INPUTS]

REQUIRED_INPUTS = [
    "campbell1982/chute-20.toml",
    "campbell1982/chute-30.toml",
    "campbell1982/chute-40.toml",
    "campbell1982/couette-rough.toml",
    "campbell1982/couette-noslip.toml",
    "malik2008/poiseuille-phi0.01.toml",
    "malik2008/poiseuille-phi0.1.toml",
    "malik2008/poiseuille-phi0.5.toml",
    "malik2008/waves-phi0.15-L45W15H15.toml",
    "malik2008/waves-phi0.15-L90W30H30.toml",
    "malik2008/waves-phi0.15-L150W50H50.toml",
    "shear/lees-edwards-2d.toml",
    "shear/lees-edwards-3d.toml",
    "cooling/hcs-3d.toml",
]


def base(**sections) -> dict:
    """A small valid 2D scene (periodic box, smooth discs); ``sections`` replace whole sections."""
    data = {
        "dimension": 2,
        "box": {"size": [10.0, 10.0]},
        "particles": {"count": 20},
        "contact": {"restitution": 0.9},
        "run": {"equilibration": 1.0, "production": 2.0, "sample_interval": 0.5},
    }
    data.update(copy.deepcopy(sections))
    return data


def problems_of(data: dict) -> str:
    with pytest.raises(SceneError) as info:
        validate_scene(data)
    return str(info.value)


# ---------------------------------------------------------------- the input scenes
def test_required_inputs_exist():
    missing = [name for name in REQUIRED_INPUTS if not (ROOT / "inputs" / name).is_file()]
    assert not missing


@pytest.mark.parametrize("path", INPUTS, ids=IDS)
def test_input_loads(path):
    scene = load_scene(path)
    assert isinstance(scene, Scene)
    assert scene.n_particles > 0
    assert scene.meta.name and scene.meta.reference
    header = [line for line in path.read_text().splitlines()[:12] if line.startswith("#")]
    assert header, "every scene file starts with a header comment"
    assert "d = 1" in " ".join(header), "the header states the units"


@pytest.mark.parametrize("path", INPUTS, ids=IDS)
def test_input_production_override(path):
    # 50: at least every shipped scene's sampling interval (Malik's largest boxes sample
    # every 40 √(d/g)); lattice scenes counted in steps take whole sample intervals
    interval = load_scene(path).run
    production = 50 if interval.unit != "steps" else 2 * int(interval.sample_interval)
    scene = load_scene(path, [f"run.production={production}"])
    assert scene.run.production == production


@pytest.mark.parametrize("path", INPUTS, ids=IDS)
def test_input_round_trips(path):
    scene = load_scene(path)
    again = validate_scene(parse_scene_text(scene_to_toml(scene)), "dump")
    assert again == scene
    assert scene_to_toml(again) == scene_to_toml(scene)


def test_campbell_numbers():
    chutes = {a: load_scene(ROOT / f"inputs/campbell1982/chute-{a}.toml") for a in (20, 30, 40)}
    for angle, scene in chutes.items():
        assert scene.gravity.angle == angle
        assert scene.n_particles == 40 and scene.box.size[0] == pytest.approx(4.8)
        assert scene.contact.restitution == 0.6 and scene.walls[0].restitution == 0.8
        assert scene.has_open_top and scene.contact.tangential.beta == 0.0
    for kind, rule in (("rough", "rough"), ("noslip", "campbell-noslip")):
        scene = load_scene(ROOT / f"inputs/campbell1982/couette-{kind}.toml")
        lower, upper = scene.wall("lower"), scene.wall("upper")
        assert scene.gravity is None and scene.n_particles == 40
        assert (lower.velocity, upper.velocity) == (0.0, 1.0)
        gap = scene.wall_position("upper") - scene.wall_position("lower")
        assert gap == pytest.approx(10 * 1.2)
        for wall in (lower, upper):
            assert wall.tangential.model == rule
            assert wall.servo.normal_stress == pytest.approx(0.567 * (1.0 / gap) ** 2)
        assert scene.solid_fraction == pytest.approx(math.pi / 5.76, rel=1e-3)


@pytest.mark.parametrize(
    ("name", "n", "size", "e", "beta", "e_w", "beta_w"),
    [
        ("poiseuille-phi0.01", 2744, [50, 50, 50], 0.8, 0.99, 1.0, 1.0),
        ("poiseuille-phi0.1", 24400, [50, 50, 50], 0.9, 0.99, 1.0, 1.0),
        ("poiseuille-phi0.5", 19600, [20, 50, 20], 0.9, 0.9, 1.0, 1.0),
        ("waves-phi0.15-L45W15H15", 3000, [45, 15, 15], 0.7, 0.1, 0.99, 0.99),
        ("waves-phi0.15-L90W30H30", 24000, [90, 30, 30], 0.7, 0.1, 0.99, 0.99),
        ("waves-phi0.15-L150W50H50", 107811, [150, 50, 50], 0.7, 0.1, 0.99, 0.99),
    ],
)
def test_malik_numbers(name, n, size, e, beta, e_w, beta_w):
    scene = load_scene(ROOT / f"inputs/malik2008/{name}.toml")
    assert scene.n_particles == n and scene.box.size == size
    assert scene.contact.restitution == e and scene.contact.tangential.beta == beta
    assert scene.gravity_vector == (1.0, 0.0, 0.0)
    assert scene.periodic == ("x", "z")
    assert (scene.wall_position("lower"), scene.wall_position("upper")) == (0.0, size[1])
    for wall in scene.walls:
        assert wall.restitution == e_w and wall.tangential.beta == beta_w
    assert scene.initial.placement == "random" and scene.initial.velocity.temperature > 0


def test_generic_inputs():
    hcs = load_scene(ROOT / "inputs/cooling/hcs-3d.toml")
    assert hcs.periodic == ("x", "y", "z") and not hcs.walls and hcs.gravity is None
    assert hcs.shear is None and hcs.contact.tangential.model == "smooth"
    assert hcs.solid_fraction == pytest.approx(0.1, rel=1e-3) and 1500 < hcs.n_particles < 2500
    for dim, phi in ((2, 0.5), (3, 0.3)):
        scene = load_scene(ROOT / f"inputs/shear/lees-edwards-{dim}d.toml")
        assert scene.dimension == dim and scene.shear.rate == 1.0 and not scene.walls
        assert scene.solid_fraction == pytest.approx(phi, rel=1e-3)
        assert 1000 < scene.n_particles < 5000 and scene.rotation_matters


# ---------------------------------------------------------------- error messages
@pytest.mark.parametrize(
    ("section", "key", "value", "expected"),
    [
        ("contact", "restitution", 1.5, ["contact.restitution", "1.5", "less than or equal to 1"]),
        ("contact", "restitution", 0.0,
         ["contact.restitution", "0.0", "greater than or equal to 0.000001"]),
        ("contact", "tangential", {"model": "beta", "beta": 2.0},
         ["contact.tangential.beta", "2.0", "less than or equal to 1"]),
        ("contact", "tangential", {"model": "sticky"},
         ["contact.tangential.model", "'sticky'", "'smooth'", "'coulomb'"]),
        ("box", "size", [-1.0, 10.0], ["box.size[0]", "-1.0", "greater than 0"]),
        ("box", "size", [10.0], ["box.size", "at least 2"]),
        ("box", "periodic", ["y"], ["periodic", "x (the flow direction) must be periodic"]),
        ("particles", "count", 0, ["particles.count", "0", "greater than 0"]),
        ("particles", "inertia", "cube", ["particles.inertia", "'cube'", "'disc', 'sphere'"]),
        ("particles", "diameter_spread", 0.7, ["particles.diameter_spread", "less than 0.5"]),
        ("run", "seed", 0, ["run.seed", "0", "greater than or equal to 1"]),
        ("run", "production", "long", ["run.production", "'long'", "a number", "not a string"]),
        ("run", "equilibration", math.nan, ["run.equilibration", "nan", "finite"]),
        ("initial", "placement", "grid", ["initial.placement", "'grid'", "'lattice'"]),
    ],
)
def test_error_names_field_value_and_allowed(section, key, value, expected):
    data = base()
    data.setdefault(section, {})[key] = value
    message = problems_of(data)
    for text in expected:
        assert text in message, (text, message)
    assert "constrained-" not in message and "function-" not in message


def test_error_top_level_and_nested_lists():
    message = problems_of({**base(), "dimension": 4})
    assert "dimension = 4" in message and "2 or 3" in message
    data = base(walls=[{"side": "lower", "restitution": 2.0}], box={"size": [10.0, 10.0]})
    message = problems_of(data)
    assert "walls[0].restitution = 2.0" in message and "less than or equal to 1" in message
    data = base(walls=[{"side": "lower", "restitution": 0.9, "velocity": math.inf}])
    assert "walls[0].velocity = inf" in problems_of(data)
    message = problems_of({k: v for k, v in base().items() if k != "run"})
    assert "run: required field is missing" in message


def test_missing_field_and_file_errors(tmp_path):
    data = base()
    del data["run"]["production"]
    assert "run.production: required field is missing" in problems_of(data)
    bad = tmp_path / "bad.toml"
    bad.write_text("dimension = 2\n[box\n")
    with pytest.raises(SceneError, match="not valid TOML") as info:
        load_scene(bad)
    assert str(bad) in str(info.value)
    with pytest.raises(SceneError, match="cannot read"):
        load_scene(tmp_path / "absent.toml")
    with pytest.raises(SceneError, match="expected a table"):
        validate_scene([1, 2])  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("where", "typo", "hint"),
    [
        ("contact", "restitutoin", "restitution"),
        ("particles", "solid_fracton", "solid_fraction"),
        ("run", "prodution", "production"),
        ("initial", "placment", "placement"),
        (None, "partikles", "particles"),
        (None, "gravty", "gravity"),
    ],
)
def test_unknown_key_suggests_nearest(where, typo, hint):
    data = base()
    (data if where is None else data.setdefault(where, {})).update({typo: 1})
    message = problems_of(data)
    assert f"unknown key {typo!r}" in message
    assert f"did you mean {hint!r}" in message


def test_unknown_key_in_union_and_list_members():
    data = base(walls=[{"side": "lower", "restitution": 0.9, "restituton": 0.9}])
    message = problems_of(data)
    assert "walls[0]" in message and "did you mean 'restitution'" in message
    data = base()
    data["contact"]["tangential"] = {"model": "beta", "bta": 0.1}
    message = problems_of(data)
    assert "contact.tangential" in message and "did you mean 'beta'" in message
    data = base()
    data["contact"]["zzzzqq"] = 1
    message = problems_of(data)
    assert "unknown key 'zzzzqq'" in message and "did you mean" not in message
    assert "allowed: law, restitution, tangential" in message


# ---------------------------------------------------------------- --set overrides
def test_overrides_types_and_lists():
    data = base(walls=[{"side": "lower", "restitution": 0.9}])
    out = apply_overrides(
        data,
        [
            "run.production=20",
            "box.size=[12.0, 8.0]",
            "meta.name=my run",
            "contact.tangential={ model = 'beta', beta = 0.5 }",
            "walls.0.restitution=0.7",
            "gravity.angle=25",
            "measure.keep_frames=true",
        ],
    )
    assert data["run"]["production"] == 2.0, "the input is not modified"
    scene = validate_scene(out)
    assert scene.run.production == 20.0 and scene.box.size == [12.0, 8.0]
    assert scene.meta.name == "my run" and scene.contact.tangential.beta == 0.5
    assert scene.walls[0].restitution == 0.7 and scene.gravity.angle == 25.0
    assert scene.measure.keep_frames is True


@pytest.mark.parametrize(
    ("item", "expected"),
    [
        ("rnu.production=1", ["unknown section 'rnu'", "did you mean 'run'"]),
        ("contcat.restitution=1", ["did you mean 'contact'"]),
        ("run.production", ["expected key.path=value"]),
        ("=3", ["expected key.path=value"]),
        ("walls.5.restitution=1", ["'5' is not an index"]),
        ("walls.x.restitution=1", ["'x' is not an index"]),
        ("run.production.x=1", ["'production' is a value, not a table"]),
    ],
)
def test_override_errors(item, expected):
    data = base(walls=[{"side": "lower", "restitution": 0.9}])
    with pytest.raises(SceneError) as info:
        apply_overrides(data, [item])
    for text in expected:
        assert text in str(info.value)


def test_override_unknown_key_is_caught_by_validation(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text((ROOT / "inputs/campbell1982/chute-30.toml").read_text())
    with pytest.raises(SceneError, match="did you mean 'production'"):
        load_scene(path, ["run.prodution=3"])
    with pytest.raises(SceneError, match="run.production = -3"):
        load_scene(path, ["run.production=-3"])


# ---------------------------------------------------------------- cross-field rules
WALLS2 = [{"side": "lower", "restitution": 0.9}, {"side": "upper", "restitution": 0.9}]


@pytest.mark.parametrize(
    ("changes", "expected"),
    [
        ({"box": {"size": [10.0, 10.0, 10.0]}}, "box.size = [10.0, 10.0, 10.0]: needs 2 lengths"),
        ({"dimension": 3}, "needs 3 lengths for dimension = 3"),
        ({"box": {"size": [10.0, 10.0], "periodic": ["x", "y"]}, "walls": WALLS2},
         "y cannot be periodic with walls"),
        ({"box": {"size": [10.0, 10.0], "periodic": ["x"]}}, "y is bounded but no wall is given"),
        ({"box": {"size": [10.0, 10.0], "periodic": ["x", "y", "z"]}}, "2D scenes have no z axis"),
        ({"dimension": 3, "box": {"size": [10.0] * 3, "periodic": ["x", "y"]}},
         "z must be periodic in 3D"),
        ({"box": {"size": [10.0, 10.0], "periodic": ["x", "x", "y"]}}, "an axis is listed twice"),
        ({"shear": {"rate": 1.0}, "walls": WALLS2}, "Lees–Edwards shear needs a y-periodic box"),
        ({"initial": {"placement": "lattice", "rows": 4, "columns": 9, "spacing": 1.2}},
         "columns × spacing = 10.8 exceeds box.size[0] = 10"),
        ({"initial": {"placement": "lattice", "rows": 9, "columns": 4, "spacing": 1.2},
          "walls": WALLS2}, "rows × spacing = 10.8 exceeds the wall gap"),
        ({"initial": {"placement": "lattice", "rows": 9, "columns": 4, "spacing": 1.2}},
         "rows × spacing = 10.8 exceeds box.size[1] = 10"),
        ({"initial": {"placement": "lattice", "rows": 2, "columns": 2, "spacing": 1.2,
                      "layers": 2}}, "initial.layers: 2D lattices have rows and columns only"),
        ({"initial": {"placement": "lattice", "rows": 2, "columns": 2}},
         "placement = 'lattice' needs rows, columns and spacing"),
        ({"initial": {"placement": "file"}}, "placement = 'file' needs path"),
        ({"particles": {"count": 120}}, "exceeds the densest packing 0.9069 in 2D"),
        ({"particles": {"solid_fraction": 0.85}}, "is above 0.8 for placement = 'random'"),
        ({"particles": {"count": 20, "solid_fraction": 0.1}},
         "give either count or solid_fraction"),
        ({"particles": {}}, "give count or solid_fraction for placement = 'random'"),
        ({"particles": {"count": 7},
          "initial": {"placement": "lattice", "rows": 2, "columns": 2, "spacing": 1.2}},
         "particles.count = 7: the lattice holds 4 particles"),
        ({"particles": {"count": 4, "diameter_spread": 0.4},
          "initial": {"placement": "lattice", "rows": 2, "columns": 2, "spacing": 1.2}},
         "initial.spacing = 1.2: must exceed the largest diameter"),
        ({"particles": {"solid_fraction": 0.7, "diameter_spread": 0.4}},
         "as if all had the largest diameter 1.2"),
        ({"walls": [WALLS2[0], WALLS2[0]]}, "2 walls with side = 'lower'; at most 1"),
        ({"walls": [WALLS2[1]]}, "an upper wall needs a lower wall"),
        ({"walls": [WALLS2[0], {**WALLS2[1], "position": 1.5}]}, "gap 1.5 between lower and upper"),
        ({"walls": [{**WALLS2[0], "position": 12.0}]}, "walls[0].position = 12: outside the box"),
        ({"walls": [{**WALLS2[0], "position": 9.0}]}, "leaves 1 < 2 d below the top"),
        ({"walls": [{**WALLS2[0], "servo": {"normal_stress": 1.0}}]},
         "normal-stress control needs two walls"),
        ({"walls": [{**WALLS2[0], "kind": "bumpy"}]}, "a [walls.bumps] table is needed"),
        ({"walls": [{**WALLS2[0], "bumps": {}}]}, "a [walls.bumps] table is needed"),
        ({"gravity": {"angle": 30.0, "direction": [1.0, 0.0]}}, "give exactly one of angle"),
        ({"gravity": {}}, "give exactly one of angle"),
        ({"gravity": {"direction": [0.0, 0.0]}}, "must be a non-zero vector"),
        ({"gravity": {"direction": [1.0, 0.0, 0.0]}}, "needs 2 components"),
        ({"initial": {"velocity": {"profile": "campbell-chute"}}}, "needs gravity.angle"),
        ({"initial": {"velocity": {"profile": "linear"}}}, "needs two walls or shear"),
        ({"run": {"equilibration": 0.0, "production": 1.0, "sample_interval": 2.0}},
         "run.sample_interval = 2.0: longer than run.production = 1.0"),
        ({"contact": {"restitution": 0.9, "law": {"model": "gutt-piecewise"}}},
         "needs e1, e2 and crossover_speed"),
        ({"soft": {"hardness": {}}}, "give exactly one of overlap"),
        ({"soft": {"hardness": {"overlap": 0.01}}}, "overlap needs impact_speed"),
        ({"soft": {"hardness": {"kappa": 1e3}}}, "kappa = k/(P d) needs pressure"),
        ({"soft": {"stiffness": 1e5, "hardness": {"k_star": 1e5}}}, "stiffness or hardness, not"),
    ],
)
def test_cross_field_rules(changes, expected):
    message = problems_of(base(**changes))
    assert expected in message, message


def test_all_problems_reported_together():
    message = problems_of(base(box={"size": [10.0, 10.0, 10.0]}, shear={"rate": 1.0},
                               walls=WALLS2))
    assert "needs 2 lengths" in message and "Lees–Edwards" in message


def test_derived_periodicity_and_axes():
    assert validate_scene(base()).periodic == ("x", "y")
    assert validate_scene(base(dimension=3, box={"size": [8.0] * 3})).periodic == ("x", "y", "z")
    assert validate_scene(base(walls=WALLS2)).periodic == ("x",)
    open_top = validate_scene(base(walls=WALLS2[:1]))
    assert open_top.has_open_top and not open_top.y_periodic
    assert validate_scene(base(gravity={"angle": 30.0})).gravity_vector == pytest.approx(
        (0.5, -math.sqrt(3) / 2))


# ---------------------------------------------------------------- initial states
def pair_gaps(scene: Scene, state) -> np.ndarray:
    """Surface gaps of all pairs closer than 1.5 d (periodic images included)."""
    dim = scene.dimension
    pos = state.position.copy()
    size = np.array(scene.box.size, float)
    periodic = np.array([ax in scene.periodic for ax in "xyz"[:dim]])
    assert np.all(pos[:, periodic] >= -1e-12) and np.all(pos[:, periodic] <= size[periodic])
    pos[:, periodic] = np.mod(pos[:, periodic], size[periodic])
    # bounded axes: a box far larger than the extent, so no wrap distance is short
    span = np.where(periodic, size, 4.0 * (np.abs(pos).max(axis=0) + 10.0))
    pos[:, ~periodic] -= pos[:, ~periodic].min(axis=0)
    tree = cKDTree(pos, boxsize=span)
    pairs = tree.query_pairs(1.5, output_type="ndarray")
    if len(pairs) == 0:
        return np.array([1.0])
    delta = pos[pairs[:, 0]] - pos[pairs[:, 1]]
    delta = np.where(periodic, delta - span * np.round(delta / span), delta)
    dist = np.linalg.norm(delta, axis=1)
    contact = 0.5 * (state.diameter[pairs[:, 0]] + state.diameter[pairs[:, 1]])
    return dist - contact


def check_state(scene: Scene) -> None:
    state = build_initial_state(scene)
    n, dim = scene.n_particles, scene.dimension
    assert state.position.shape == (n, dim) and state.velocity.shape == (n, dim)
    assert state.angular_velocity.shape == (n, 1 if dim == 2 else 3)
    assert np.all(np.isfinite(state.position)) and np.all(np.isfinite(state.velocity))
    assert pair_gaps(scene, state).min() > 0.0, "no overlaps"
    radius = state.diameter / 2
    y = state.position[:, 1]
    if scene.walls:
        assert np.all(y - radius >= scene.wall_position("lower")), "inside the lower wall"
        top = scene.wall_position("upper") if scene.wall("upper") else scene.box.size[1]
        assert np.all(y + radius <= top), "inside the upper wall / box"


def scene3(**sections) -> dict:
    return base(dimension=3, box={"size": [8.0, 8.0, 8.0]}, **sections)


STATE_CASES = {
    "lattice-2d-walls": base(
        box={"size": [6.0, 12.0]}, walls=WALLS2, particles={},
        initial={"placement": "lattice", "rows": 10, "columns": 5, "spacing": 1.2}),
    "lattice-2d-periodic": base(
        particles={}, initial={"placement": "lattice", "rows": 8, "columns": 8, "spacing": 1.25}),
    "lattice-3d-walls": scene3(
        walls=WALLS2, particles={},
        initial={"placement": "lattice", "rows": 6, "columns": 6, "layers": 6, "spacing": 1.3}),
    "lattice-2d-spread": base(
        walls=WALLS2, particles={"diameter_spread": 0.3},
        initial={"placement": "lattice", "rows": 8, "columns": 8, "spacing": 1.2}),
    "random-2d-dilute": base(box={"size": [20.0, 20.0]}, particles={"solid_fraction": 0.2}),
    "random-2d-dense": base(box={"size": [20.0, 20.0]}, particles={"solid_fraction": 0.7}),
    "random-2d-dense-walls": base(box={"size": [20.0, 16.0]}, walls=WALLS2,
                                  particles={"solid_fraction": 0.7}),
    "random-2d-open-top": base(box={"size": [10.0, 30.0]}, walls=WALLS2[:1],
                               particles={"count": 150}),
    "random-2d-spread": base(box={"size": [20.0, 20.0]}, walls=WALLS2,
                             particles={"solid_fraction": 0.4, "diameter_spread": 0.4}),
    "random-3d-dilute": scene3(particles={"solid_fraction": 0.1}),
    "random-3d-dense": base(dimension=3, box={"size": [10.0, 10.0, 10.0]},
                            particles={"solid_fraction": 0.5}),
    "random-3d-dense-walls": base(dimension=3, box={"size": [10.0, 12.0, 10.0]}, walls=WALLS2,
                                  particles={"solid_fraction": 0.5}),
    "random-3d-limit": base(dimension=3, box={"size": [10.0, 10.0, 10.0]},
                            particles={"solid_fraction": 0.59}),
    "random-2d-limit": base(box={"size": [24.0, 24.0]}, particles={"solid_fraction": 0.79}),
}


@pytest.mark.parametrize("name", list(STATE_CASES))
def test_initial_state_no_overlap(name):
    check_state(validate_scene(STATE_CASES[name]))


@pytest.mark.parametrize("path", INPUTS, ids=IDS)
def test_input_initial_state(path):
    check_state(load_scene(path))  # the 107 811-particle box takes ~5 s


def test_dense_random_fraction_is_exact():
    scene = validate_scene(STATE_CASES["random-3d-dense"])
    state = build_initial_state(scene)
    phi = len(state.position) * math.pi / 6 / scene.box_volume
    assert phi == pytest.approx(0.5, abs=1e-3) and phi < MAX_PACKING[3]


@pytest.mark.parametrize("spread", [0.0, 0.3])
@pytest.mark.parametrize("dim", [2, 3])
def test_temperature_start_has_zero_momentum(dim, spread):
    size = [20.0] * 2 if dim == 2 else [12.0] * 3
    scene = validate_scene(base(
        dimension=dim, box={"size": size},
        particles={"solid_fraction": 0.2, "diameter_spread": spread},
        contact={"restitution": 0.9, "tangential": {"model": "beta", "beta": 0.5}},
        initial={"velocity": {"temperature": 2.0}},
    ))
    state = build_initial_state(scene)
    momentum = (state.mass[:, None] * state.velocity).sum(axis=0)
    assert np.abs(momentum).max() < 1e-9 * scene.n_particles
    # T per degree of freedom: <m v_a²> = T (sampling error ~ sqrt(2/(N dim)))
    kinetic = (state.mass[:, None] * state.velocity**2).mean()
    assert kinetic == pytest.approx(2.0, rel=0.15)
    assert np.any(state.angular_velocity != 0.0), "rough particles get spins"


def test_smooth_particles_start_without_spin():
    scene = validate_scene(base(box={"size": [20.0, 20.0]}, particles={"count": 100},
                                initial={"velocity": {"temperature": 1.0}}))
    assert not scene.rotation_matters
    assert np.all(build_initial_state(scene).angular_velocity == 0.0)


def test_velocity_profiles():
    couette = validate_scene(base(
        box={"size": [10.0, 10.0]}, particles={"count": 30},
        walls=[WALLS2[0], {**WALLS2[1], "velocity": 2.0}],
        initial={"velocity": {"profile": "linear"}}))
    state = build_initial_state(couette)
    assert np.allclose(state.velocity[:, 0], 2.0 * state.position[:, 1] / 10.0)
    assert np.all(state.velocity[:, 1] == 0.0)
    sheared = validate_scene(base(shear={"rate": 0.5}, initial={"velocity": {"profile": "linear"}}))
    state = build_initial_state(sheared)
    assert np.allclose(state.velocity[:, 0], 0.5 * (state.position[:, 1] - 5.0))


def test_initial_state_deterministic_for_a_seed():
    data = base(box={"size": [20.0, 20.0]}, particles={"solid_fraction": 0.3},
                initial={"velocity": {"temperature": 1.0}})
    first = build_initial_state(validate_scene(data))
    again = build_initial_state(validate_scene(data))
    assert np.array_equal(first.position, again.position)
    assert np.array_equal(first.velocity, again.velocity)
    other = copy.deepcopy(data)
    other["run"]["seed"] = 999
    different = build_initial_state(validate_scene(other))
    assert not np.array_equal(first.position, different.position)


def test_lattice_start_matches_campbell():
    scene = load_scene(ROOT / "inputs/campbell1982/chute-30.toml")
    state = build_initial_state(scene)
    s, gap = 1.2, (1.2 - 1.0) / 2
    rows = np.round((state.position[:, 1] - s / 2) / s)
    cols = np.round((state.position[:, 0] - s / 2) / s)
    assert sorted(set(rows)) == list(range(10)) and sorted(set(cols)) == list(range(4))
    offsets = np.abs(state.position - s / 2 - s * np.stack([cols, rows], axis=1))
    assert offsets.max() <= gap - MARGIN / 2 + 1e-12
    assert np.all(np.diff(rows) >= 0), "numbered row by row, as Campbell did"


# ---------------------------------------------------------------- canonical TOML dump
def test_dump_round_trips_awkward_strings():
    data = base(meta={"name": 'a "quoted" \\ name',
                      "description": "line one\nline two\ttab \x7f \x01 é ∞ 😀",
                      "reference": "Campbell (1982) — §2"},
                walls=[{**WALLS2[0], "tangential": {"model": "coulomb", "mu": 0.5}}],
                gravity={"direction": [1.0, -1e-300]}, soft={"stiffness": 1e20})
    scene = validate_scene(data)
    text = scene_to_toml(scene)
    assert validate_scene(tomllib.loads(text)) == scene


def test_dump_is_canonical_for_equal_scenes(tmp_path):
    original = ROOT / "inputs/campbell1982/chute-30.toml"
    scene = load_scene(original)
    dumped = tmp_path / "dump.toml"
    dumped.write_text(scene_to_toml(scene))
    assert load_scene(dumped) == scene
    assert read_scene_data(dumped)["contact"]["tangential"] == {"model": "beta", "beta": 0.0}
