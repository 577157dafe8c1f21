"""Scene presets (demstudy.scene.presets) and keyword overrides of load_scene.

Every scene of inputs/ is a preset named by its path below inputs/ without the suffix; a wheel
built from the repository carries them as demstudy/presets/<group>/<name>.toml. Dimensionless
particle units throughout (d = 1, m = 1, g = 1 when gravity acts).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from demstudy.scene import (
    SceneError,
    apply_sections,
    list_presets,
    load_scene,
    preset_path,
    scene_to_toml,
)
from demstudy.scene.load import read_scene_data
from demstudy.scene.presets import close_presets, preset_roots

ROOT = Path(__file__).resolve().parents[1]
INPUTS = sorted((ROOT / "inputs").glob("**/*.toml"))
NAMES = [p.relative_to(ROOT / "inputs").with_suffix("").as_posix() for p in INPUTS]


# ------------------------------------------------------------------ resolving presets
def test_every_input_is_a_preset():
    assert NAMES and list_presets() == NAMES
    assert preset_roots()[0] == (ROOT / "inputs").resolve()  # a checkout: its inputs/ first


@pytest.mark.parametrize("name", NAMES)
def test_preset_loads_as_its_file(name):
    path = ROOT / "inputs" / f"{name}.toml"
    assert preset_path(name).resolve() == path.resolve()
    assert preset_path(f"{name}.toml").resolve() == path.resolve()
    scene = load_scene(name)
    assert scene == load_scene(path)
    assert load_scene(f"{name}.toml") == scene
    assert scene_to_toml(scene) == scene_to_toml(load_scene(str(path)))


def test_an_existing_file_wins_over_a_preset(tmp_path, monkeypatch):
    data = read_scene_data(ROOT / "inputs/campbell1982/chute-30.toml")
    local = tmp_path / "campbell1982" / "chute-30.toml"
    local.parent.mkdir()
    local.write_text((ROOT / "inputs/campbell1982/chute-30.toml").read_text()
                     .replace("restitution = 0.6 ", "restitution = 0.5 ", 1))
    monkeypatch.chdir(tmp_path)
    assert data["contact"]["restitution"] == 0.6
    assert load_scene("campbell1982/chute-30.toml").contact.restitution == 0.5  # the file
    assert load_scene("campbell1982/chute-30").contact.restitution == 0.6  # no such file


def test_an_unknown_preset_names_it_and_the_close_ones():
    with pytest.raises(SceneError) as info:
        load_scene("campbell1982/chute-31")
    text = str(info.value)
    assert "'campbell1982/chute-31' is not a preset" in text
    assert "did you mean 'campbell1982/chute-30'" in text
    listed = text.split("presets: ", 1)[1]  # every preset, sorted
    assert "campbell1982/chute-20" in listed and "shear/lees-edwards-3d" in listed
    assert "accuracy-cost/couette-rough-nu0.55" in listed
    with pytest.raises(SceneError, match="not a preset"):
        preset_path("nothing/like-this")
    assert close_presets("chute-30")[0] == "campbell1982/chute-30"  # group forgotten
    assert close_presets("malik2008/poiseuille-phi0.05")[0].startswith("malik2008/poiseuille")


def test_an_absent_path_still_says_the_file_cannot_be_read(tmp_path):
    with pytest.raises(SceneError, match="cannot read the file"):
        load_scene(tmp_path / "absent.toml")


# ------------------------------------------------------------------ keyword overrides
def test_keyword_overrides_reach_the_scene_with_their_types():
    scene = load_scene("campbell1982/couette-noslip", run={"production": 50, "seed": 7},
                       walls={1: {"restitution": 0.9}},
                       contact={"tangential": {"model": "beta", "beta": 0.25}},
                       measure={"keep_frames": True})
    assert scene.run.production == 50.0 and isinstance(scene.run.production, float)
    assert scene.run.seed == 7 and isinstance(scene.run.seed, int)
    assert scene.walls[1].restitution == 0.9
    assert scene.walls[0].restitution == load_scene("campbell1982/couette-noslip") \
        .walls[0].restitution  # the other wall untouched
    assert scene.contact.tangential.model == "beta" and scene.contact.tangential.beta == 0.25
    assert scene.measure.keep_frames is True
    # numpy values are plain numbers in the scene
    assert load_scene("campbell1982/chute-30", run={"production": np.float64(3.5)}
                      ).run.production == 3.5


def test_keyword_overrides_combine_with_set_strings():
    scene = load_scene("campbell1982/chute-30", ["run.production=20", "contact.restitution=0.7"],
                       run={"production": 5, "equilibration": 1})
    assert scene.run.production == 20.0  # --set strings are applied after the keywords
    assert scene.run.equilibration == 1.0 and scene.contact.restitution == 0.7


def test_a_list_replaces_and_none_removes():
    base = load_scene("campbell1982/chute-30")
    walls = [dict(w) for w in read_scene_data(preset_path("campbell1982/chute-30"))["walls"]]
    walls[0]["restitution"] = 0.5
    scene = load_scene("campbell1982/chute-30", walls=walls)
    assert len(scene.walls) == len(base.walls) and scene.walls[0].restitution == 0.5
    data = read_scene_data(preset_path("shear/lees-edwards-2d"))
    assert "sample_interval" in data["run"]
    cleared = apply_sections(data, {"run": {"sample_interval": None}})
    assert "sample_interval" not in cleared["run"] and "sample_interval" in data["run"]
    assert load_scene("shear/lees-edwards-2d", run={"sample_interval": None}).run \
        .sample_interval == 1.0  # the schema default


def test_bad_keywords_name_the_field():
    with pytest.raises(SceneError, match=r"rn: unknown section 'rn'; did you mean 'run'\?"):
        load_scene("campbell1982/chute-30", rn={"production": 5})
    with pytest.raises(SceneError, match=r"run: unknown key 'prodution'; did you mean "
                                         r"'production'\?"):
        load_scene("campbell1982/chute-30", run={"prodution": 5})
    with pytest.raises(SceneError, match=r"run\.production = 'long'"):
        load_scene("campbell1982/chute-30", run={"production": "long"})
    with pytest.raises(SceneError, match=r"walls\[4\]: 4 is not an index of a list of 1"):
        load_scene("campbell1982/chute-30", walls={4: {"restitution": 0.5}})
    with pytest.raises(SceneError, match=r"contact\.restitution = 1\.5"):
        load_scene("campbell1982/chute-30", contact={"restitution": 1.5})


# ------------------------------------------------------------------ the wheel
def test_the_wheel_carries_every_preset(tmp_path):
    """pip wheel reuses the cached CMake build in build/ (--no-build-isolation): ~2 s."""
    # an installed demstudy tested without its sources cannot build a wheel; CI and every
    # checkout have both, so there this test always runs
    if shutil.which("cmake") is None or not (ROOT / "pyproject.toml").is_file():
        pytest.skip("needs a source checkout and cmake")
    pytest.importorskip("scikit_build_core")
    out = tmp_path / "wheel"
    subprocess.run([sys.executable, "-m", "pip", "wheel", str(ROOT), "--no-build-isolation",
                    "--no-deps", "--quiet", "-w", str(out)], check=True, cwd=ROOT,
                   capture_output=True)
    (wheel,) = out.glob("demstudy-*.whl")
    with zipfile.ZipFile(wheel) as zf:
        names = set(zf.namelist())
        zf.extractall(tmp_path / "site")
    expected = {f"demstudy/presets/{name}.toml" for name in NAMES}
    assert expected <= names, sorted(expected - names)
    for name in NAMES:  # byte-identical copies
        shipped = (tmp_path / "site" / "demstudy" / "presets" / f"{name}.toml").read_bytes()
        assert shipped == (ROOT / "inputs" / f"{name}.toml").read_bytes()
    # the unpacked wheel, imported without the editable hook, outside any checkout
    probe = (
        "import sys, json\n"
        "sys.meta_path[:] = [f for f in sys.meta_path if 'ScikitBuild' not in type(f).__name__]\n"
        f"sys.path.insert(0, {str(tmp_path / 'site')!r})\n"
        "from demstudy.scene import list_presets, load_scene, scene_to_toml\n"
        "from demstudy.scene.presets import preset_roots\n"
        "print(json.dumps({'roots': [str(r) for r in preset_roots()],\n"
        "                  'names': list_presets(),\n"
        "                  'toml': scene_to_toml(load_scene('campbell1982/chute-30'))}))\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    done = subprocess.run([sys.executable, "-c", probe], check=True, cwd=tmp_path,
                          capture_output=True, text=True, env=env)
    found = json.loads(done.stdout)
    assert found["roots"] == [str((tmp_path / "site" / "demstudy" / "presets").resolve())]
    assert found["names"] == NAMES
    assert found["toml"] == scene_to_toml(load_scene("campbell1982/chute-30"))
