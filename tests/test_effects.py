"""The effect registry: presence and absence of each effect, every engine's table complete,
one refusal naming engine, field, value and reason. Units: d = 1, m = 1, g = 1.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from demstudy.effects import EFFECTS, Cannot, Translation, check_effects, present_effects
from demstudy.engines import backend_names, get_backend
from demstudy.engines.edmd import core_options
from demstudy.errors import UnsupportedByEngine
from demstudy.scene import load_scene, validate_scene

ROOT = Path(__file__).resolve().parents[1]
BARE = {"dimension": 3, "box": {"size": [6.0, 6.0, 6.0]}, "particles": {"count": 20},
        "contact": {"restitution": 0.9}, "run": {"equilibration": 0.0, "production": 1.0}}
LOWER = {"side": "lower", "restitution": 0.9}
UPPER = {"side": "upper", "restitution": 0.9}


def scene(**changes):
    return validate_scene({k: v for k, v in {**BARE, **changes}.items() if v is not None})


# each effect: a scene that calls for it (and for as little else as possible)
CALLS_FOR = {
    "planar": {"dimension": 2, "box": {"size": [6.0, 6.0]}},
    "rotation": {"contact": {"restitution": 0.9, "tangential": {"model": "rough"}}},
    "restitution-law": {"contact": {"restitution": 0.9, "law": {
        "model": "gutt-piecewise", "e1": 0.9, "e2": 0.5, "crossover_speed": 1.0}}},
    "walls": {"walls": [LOWER, UPPER]},
    "moving-walls": {"walls": [LOWER, {**UPPER, "velocity": 1.0}]},
    "noslip-walls": {"walls": [LOWER, {**UPPER, "tangential": {"model": "campbell-noslip"}}]},
    "servo": {"walls": [LOWER, {**UPPER, "servo": {"normal_stress": 0.1}}]},
    "bumpy-walls": {"walls": [{**LOWER, "kind": "bumpy", "bumps": {}}, UPPER]},
    "gravity": {"gravity": {"direction": [1.0, 0.0, 0.0]}},
    "lees-edwards": {"shear": {"rate": 1.0}},
    "lattice": {"dimension": 2, "box": None, "particles": {}, "walls": [LOWER, UPPER],
                "lattice": {"nxt": 6, "nyt": 4, "initial": [{"md": 1, "x1": 1, "y1": 2}]}},
}


def test_every_registered_effect_has_a_scene_here():
    assert set(CALLS_FOR) == set(EFFECTS)


def test_a_bare_scene_calls_for_no_effect():
    assert present_effects(scene()) == []


@pytest.mark.parametrize("name", sorted(CALLS_FOR))
def test_each_effect_is_present_exactly_when_asked(name):
    present = {e.name for e in present_effects(scene(**CALLS_FOR[name]))}
    assert name in present
    walls = {"walls", "moving-walls", "noslip-walls", "servo", "bumpy-walls"}
    # a lattice scene is 2D and has its two wall rows
    implied = {"lattice": {"planar", "walls"}}.get(name, walls if name in walls else set())
    assert present <= {name} | implied


@pytest.mark.parametrize("engine", backend_names())
def test_every_engine_decides_on_every_effect(engine):
    """A backend's table names every registered effect: a translation or a reason why not
    (adding an effect forces the decision in every engine)."""
    table = get_backend(engine).translations
    assert set(table) == set(EFFECTS), set(EFFECTS) ^ set(table)
    for name, entry in table.items():
        assert isinstance(entry, Translation | Cannot), name
        if isinstance(entry, Cannot):
            assert len(entry.reason) > 20, name


def test_an_effect_an_engine_cannot_express_is_refused_naming_field_value_and_reason():
    noslip = scene(**CALLS_FOR["noslip-walls"])
    table = get_backend("lammps").translations
    with pytest.raises(UnsupportedByEngine) as info:
        check_effects(noslip, "lammps", table)
    err = info.value
    assert (err.engine, err.field_name, err.value) == ("lammps", "walls.tangential.model",
                                                       "campbell-noslip")
    assert "edmd" in str(err)  # what to use instead
    law = scene(**CALLS_FOR["restitution-law"])
    with pytest.raises(UnsupportedByEngine, match="contact.law.model = 'gutt-piecewise'"):
        check_effects(law, "lammps", table)
    assert check_effects(law, "edmd", get_backend("edmd").translations)


def test_event_driven_core_options_only_for_present_effects():
    """The core is given gravity, shear, walls and special pair rules only when the scene
    calls for them."""
    bare = core_options(scene())
    assert bare == {"e": 0.9, "beta": -1.0, "inertia_k": 0.4}
    assert core_options(scene(gravity={"direction": [1.0, 0.0, 0.0]}))["gravity"] == [1, 0, 0]
    assert core_options(scene(shear={"rate": 0.5}))["shear_rate"] == 0.5
    walls = core_options(scene(**CALLS_FOR["moving-walls"]))
    assert walls["periodic_y"] is False
    assert [w["velocity"] for w in walls["walls"]] == [0.0, 1.0]
    rough = core_options(scene(**CALLS_FOR["rotation"]))
    assert rough["beta"] == 0.0 and "pair" not in rough
    law = core_options(scene(**CALLS_FOR["restitution-law"]))
    assert law["pair"]["law"] == "gutt-piecewise" and law["beta"] == -1.0
    coulomb = core_options(scene(contact={"restitution": 0.9, "tangential": {
        "model": "coulomb", "mu": 0.3}}))
    # unset beta0 = e of each collision (mapping.default_beta0), in the core as in soft engines
    assert coulomb["pair"] == {"tangential": "coulomb", "mu": 0.3, "beta0": 0.9,
                               "beta0_from_e": True}


def test_the_campbell_noslip_preset_runs_only_where_it_can():
    couette = load_scene(ROOT / "inputs/campbell1982/couette-noslip.toml")
    assert {"noslip-walls", "servo", "walls", "moving-walls"} <= {
        e.name for e in present_effects(couette)}
    get_backend("edmd").check(couette, None)
    with pytest.raises(UnsupportedByEngine, match="campbell-noslip"):
        get_backend("lammps").check(couette, None)
