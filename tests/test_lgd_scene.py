"""Lattice scenes ([lattice], run.unit = 'steps'), their errors, and the LGD effect table:
what each present effect sets in the listing's integers and what an absent one leaves alone,
what LGD cannot express, and that every other engine refuses a lattice scene.

Units: scene values in particle units (d = 1 = lattice spacing, m = 1, g = 1 with gravity;
without gravity the wall speed or the initial r.m.s. speed); [lattice] in the listing's
integers.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from demstudy.engines import backend_names, get_backend
from demstudy.engines.lgd.effects import lattice_setup
from demstudy.errors import UnsupportedByEngine
from demstudy.scene import SceneError, parse_scene_text, scene_to_toml, validate_scene
from demstudy.simulation import RunOptions, check_run

GAS = [{"md": 6, "x1": 1, "y1": 2, "x2": 12, "y2": 4, "vx": 1024},
       {"md": 6, "x1": 1, "y1": 5, "x2": 12, "y2": 6, "vx": -1024}]


def lattice_scene(**changes) -> dict:
    data = {"dimension": 2, "particles": {}, "contact": {"restitution": 1.0},
            "walls": [{"side": "lower", "restitution": 1.0},
                      {"side": "upper", "restitution": 1.0}],
            "run": {"equilibration": 0, "production": 40, "sample_interval": 10,
                    "unit": "steps"},
            "lattice": {"nxt": 12, "nyt": 8, "initial": GAS}}
    for key, value in changes.items():
        if value is None:
            data.pop(key, None)
        else:  # a whole section
            data[key] = value
    return data


def scene(**changes):
    return validate_scene(lattice_scene(**changes))


def test_a_lattice_scene_gets_its_box_and_counts_its_grains():
    s = scene()
    assert s.box.size == [12.0, pytest.approx(7 * math.sqrt(3) / 2)]
    assert s.n_particles == 20  # 4 per row × 5 rows at density 1/3
    again = validate_scene(parse_scene_text(scene_to_toml(s)))
    assert again == s  # the dumped scene (box filled in) reads back the same


@pytest.mark.parametrize(("change", "message"), [
    ({"lattice": {"nxt": 16, "nyt": 8, "initial": GAS}}, r"lattice.nxt = 16.*multiple of 6"),
    ({"lattice": {"nxt": 12, "nyt": 3, "initial": GAS}}, r"lattice.nyt = 3.*>= 4"),
    ({"lattice": {"nxt": 12, "nyt": 8}}, r"give the grains as md lines"),
    ({"lattice": {"nxt": 12, "nyt": 8, "initial": [{"md": 4, "x1": 1, "y1": 2}]}},
     r"md = 4: not a code"),
    ({"lattice": {"nxt": 12, "nyt": 8, "initial": [{"md": 1, "x1": 1, "y1": 9}]}},
     r"place no movable grain"),
    ({"lattice": {"nxt": 12, "nyt": 8, "initial": GAS, "idl": 2.5}}, r"lattice.idl"),
    ({"lattice": {"nxt": 12, "nyt": 8, "initial_file": "/no/such/file"}},
     r"lattice.initial_file = '/no/such/file': .*cannot be read"),
    ({"dimension": 3}, r"a lattice scene is 2D"),
    ({"box": {"size": [12.0, 6.0]}}, r"box.size = \[12.0, 6.0\]: a lattice scene's box is "
                                     r"its lattice"),
    ({"walls": [{"side": "lower", "restitution": 1.0}]}, r"needs both walls"),
    ({"walls": [{"side": "lower", "restitution": 1.0, "position": 1.0},
                {"side": "upper", "restitution": 1.0}]}, r"walls\[0\].position = 1"),
    ({"initial": {"velocity": {"temperature": 1.0}}}, r"leave \[initial\] out"),
    ({"particles": {"count": 15}}, r"particles.count = 15: the lattice's md lines place 20"),
    ({"run": {"equilibration": 0, "production": 40.5, "sample_interval": 10,
              "unit": "steps"}}, r"run.production = 40.5: with unit = 'steps' a whole"),
])
def test_lattice_scene_errors_name_field_value_and_allowed(change, message):
    with pytest.raises(SceneError, match=message):
        scene(**change)


def test_steps_need_a_lattice():
    data = {"dimension": 2, "box": {"size": [10.0, 10.0]}, "particles": {"count": 5},
            "contact": {"restitution": 0.9},
            "run": {"equilibration": 0, "production": 4, "unit": "steps"}}
    with pytest.raises(SceneError, match=r"run.unit = 'steps': whole lattice steps exist only"):
        validate_scene(data)


def test_initial_file_is_gutts_initial_data(tmp_path: Path):
    path = tmp_path / "init"
    path.write_text("  nl = 2\n 3 1 2 12 3 0 0\n 0 5 2 0 0 0 0\n")
    s = scene(lattice={"nxt": 12, "nyt": 8, "initial_file": str(path)})
    assert s.n_particles == 23
    s = scene(lattice={"nxt": 12, "nyt": 8, "initial_file": str(path),
                       "initial": [{"md": 1, "x1": 5, "y1": 2}]})  # applied after the file
    assert s.n_particles == 24


def test_relative_initial_file_is_the_scene_folders(tmp_path: Path, monkeypatch):
    """A scene file naming its initial-data file relatively means the file beside it, from
    any working directory, and keeps meaning it once stored (the path is made absolute)."""
    from demstudy.scene import load_scene

    folder = tmp_path / "problem"
    folder.mkdir()
    (folder / "init").write_text("  nl = 1\n 3 1 2 12 3 0 0\n")
    text = scene_to_toml(scene(lattice={"nxt": 12, "nyt": 8,
                                        "initial_file": str(folder / "init")}))
    (folder / "scene.toml").write_text(text.replace(str(folder / "init"), "init"))
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    loaded = load_scene(folder / "scene.toml")
    assert loaded.n_particles == 24
    assert loaded.lattice.initial_file == str((folder / "init").resolve())
    again = validate_scene(parse_scene_text(scene_to_toml(loaded)), "stored")
    assert again.n_particles == 24


# -- effects: presence and absence -------------------------------------------------------
def test_absent_effects_leave_the_lattice_at_rest_and_elastic():
    setup = lattice_setup(scene())
    p = setup.params
    assert (p.igx, p.igy, p.jx1, p.jx2, p.icb) == (0, 0, 0, 0, 0)
    assert (p.iep1, p.iep2, p.iew1, p.iew2) == (16, 16, 16, 16)  # ke·e with e = 1
    assert setup.units.speed == 1024  # no gravity, walls at rest: the r.m.s. speed
    assert setup.units.ticks_per_time == 4096 * 4096 / 1024


def test_gravity_sets_igx_igy_and_the_unit_root_g_d():
    down = scene(gravity={"direction": [0.0, -1.0]})
    p, units = lattice_setup(down).params, lattice_setup(down).units
    assert (p.igx, p.igy) == (0, -8)
    # time unit √(d/g): 1024·√(idl/g) ticks (the listing's itm is √2 of it)
    assert units.ticks_per_time == pytest.approx(1024 * math.sqrt(4096 / 8))
    slope = scene(gravity={"direction": [1.0, -1.0]},
                  lattice={"nxt": 12, "nyt": 8, "initial": GAS, "gravity_scale": 1000.0})
    assert (lattice_setup(slope).params.igx, lattice_setup(slope).params.igy) == (707, -707)


def test_gravity_rounded_off_its_direction_is_refused():
    with pytest.raises(UnsupportedByEngine, match=r"\(igx, igy\) = \(1, -1\), 5\.\d+° off"):
        lattice_setup(scene(gravity={"direction": [math.tan(math.radians(40)), -1.0]},
                            lattice={"nxt": 12, "nyt": 8, "initial": GAS,
                                     "gravity_scale": 1.5}))


def test_moving_walls_need_and_use_the_speed_scale():
    walls = [{"side": "lower", "restitution": 0.75, "velocity": -1.0},
             {"side": "upper", "restitution": 0.75, "velocity": 1.0}]
    with pytest.raises(UnsupportedByEngine, match=r"lattice.speed_scale = None: moving walls"):
        lattice_setup(scene(walls=walls))
    s = scene(walls=walls, lattice={"nxt": 12, "nyt": 8, "initial": GAS,
                                    "speed_scale": 16384})
    p = lattice_setup(s).params
    assert (p.jx1, p.jx2, p.iew1, p.iew2, p.iep1) == (-16384, 16384, 12, 12, 16)


def test_piecewise_law_sets_icb_and_both_coefficients():
    law = {"restitution": 0.75, "law": {"model": "gutt-piecewise", "e1": 0.75, "e2": 0.9375,
                                        "crossover_speed": math.sqrt(2)}}
    s = scene(contact=law, gravity={"direction": [0.0, -1.0]},
              lattice={"nxt": 12, "nyt": 8, "initial": GAS, "wall_e2": 0.9375})
    p = lattice_setup(s).params
    assert (p.iep1, p.iep2, p.iew1, p.iew2) == (12, 15, 16, 15)
    assert p.icb == round(4 * math.sqrt(2 * 8 * 4096))  # c_b = √(2 g d), digest §3.4


@pytest.mark.parametrize(("change", "field"), [
    ({"contact": {"restitution": 0.9}}, "contact.restitution"),  # 0.9·16 is not whole
    ({"contact": {"restitution": 1.0, "tangential": {"model": "rough"}}},
     "contact.tangential.model"),
    ({"contact": {"restitution": 1.0, "law": {"model": "campbell-exp"}},
      "gravity": {"direction": [0.0, -1.0]}}, "contact.law.model"),
    ({"walls": [{"side": "lower", "restitution": 1.0},
                {"side": "upper", "restitution": 0.75}]}, "walls[upper].restitution"),
    ({"walls": [{"side": "lower", "restitution": 1.0},
                {"side": "upper", "restitution": 1.0, "servo": {"normal_stress": 1.0}}]},
     "walls[upper].servo.normal_stress"),
    ({"walls": [{"side": "lower", "restitution": 1.0, "kind": "bumpy", "bumps": {}},
                {"side": "upper", "restitution": 1.0}]}, "walls[lower].kind"),
    ({"walls": [{"side": "lower", "restitution": 1.0},
                {"side": "upper", "restitution": 1.0,
                 "tangential": {"model": "campbell-noslip"}}]}, "walls.tangential.model"),
    ({"gravity": {"direction": [0.0, -1.0]},
      "lattice": {"nxt": 12, "nyt": 8, "initial": GAS, "speed_scale": 100.0}},
     "lattice.speed_scale"),
    ({"lattice": {"nxt": 12, "nyt": 8, "initial": GAS, "wall_e2": 0.5}}, "lattice.wall_e2"),
])
def test_what_lgd_cannot_express_is_refused_naming_the_field(change, field, tmp_path):
    s = scene(**change)
    with pytest.raises(UnsupportedByEngine) as info:
        check_run(get_backend("lgd"), s, RunOptions(out=tmp_path / "x.h5"))
    assert info.value.engine == "lgd" and info.value.field_name == field


@pytest.mark.parametrize("engine", [e for e in backend_names() if e != "lgd"])
def test_every_other_engine_refuses_a_lattice_scene(engine, tmp_path):
    with pytest.raises(UnsupportedByEngine) as info:
        check_run(get_backend(engine), scene(), RunOptions(out=tmp_path / "x.h5"))
    assert info.value.field_name in ("lattice", "run.unit")
    assert "lgd" in str(info.value)


def test_lgd_refuses_a_scene_without_a_lattice(tmp_path):
    data = {"dimension": 3, "box": {"size": [6.0, 6.0, 6.0]}, "particles": {"count": 10},
            "contact": {"restitution": 0.9}, "run": {"equilibration": 0, "production": 1}}
    with pytest.raises(UnsupportedByEngine, match=r"lattice = None: .*lattice scenes only"):
        check_run(get_backend("lgd"), validate_scene(data), RunOptions(out=tmp_path / "x.h5"))


def test_steps_phases_must_be_whole_sample_intervals():
    """With run.unit = 'steps' the samples fall on whole intervals: a production that is no
    multiple of the interval is refused (it would silently run another number of steps)."""
    from demstudy.scene import load_scene

    with pytest.raises(SceneError, match=r"run.production = 1000: .* multiple of "
                                         r"run.sample_interval = 32"):
        load_scene("gutt1989/gas-box", ["run.production=1000"])
    assert load_scene("gutt1989/gas-box", ["run.production=1024"]).run.production == 1024
