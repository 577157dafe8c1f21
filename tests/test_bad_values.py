"""Scene values that used to validate but were wrong: booleans or strings taken as numbers,
numbers so large they overflow the decks, and combinations that give nonsense physics.

Dimensionless particle units throughout: d = 1, m = 1 (g = 1 when gravity acts).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from demstudy.cli import main
from demstudy.scene import SceneError, load_scene
from demstudy.scene.schema import MAX_SAMPLES, MAX_SPEED, MIN_INTERVAL

ROOT = Path(__file__).resolve().parent.parent
CHUTE = ROOT / "inputs" / "campbell1982" / "chute-30.toml"


def _refused(capsys, argv: list[str]) -> str:
    """Run the CLI, check it refuses the input with exit 2 and no traceback; its stderr."""
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and "invalid scene" in err
    return err


# ---- 1. strict numbers ------------------------------------------------------------------
@pytest.mark.parametrize("setting, field, kind", [
    ('contact.restitution="0.6"', "contact.restitution = '0.6'", "string"),
    ("particles.inertia=true", "particles.inertia = True", "boolean"),  # was read as K = 1
    ("run.seed=1.0", "run.seed = 1.0", "decimal number"),
    ("run.production=true", "run.production = True", "boolean"),
])
def test_booleans_and_strings_are_not_numbers(capsys, setting, field, kind):
    err = _refused(capsys, ["validate", str(CHUTE), "--set", setting])
    assert field in err and f"not a {kind}" in err
    assert "is allowed" in err  # says what the field takes


def test_integers_are_still_taken_where_decimals_are_expected():
    scene = load_scene(CHUTE, ["contact.restitution=1", "run.production=3"])
    assert scene.contact.restitution == 1.0 and isinstance(scene.contact.restitution, float)
    assert scene.run.production == 3.0


def test_switches_take_only_booleans():
    with pytest.raises(SceneError, match=r"measure.keep_frames = 1: true or false"):
        load_scene(CHUTE, ["measure.keep_frames=1"])


@pytest.mark.parametrize("path", sorted((ROOT / "inputs").glob("*/*.toml")),
                         ids=lambda p: p.parent.name + "/" + p.name)
def test_every_preset_still_validates(path):
    load_scene(path)


# ---- 2. numbers that overflowed the decks -----------------------------------------------
HUGE_IMPACT = "soft={hardness={overlap=0.01, impact_speed=1e300}}"


@pytest.mark.parametrize("setting, field", [
    ("run.sample_interval=5e-324", "run.sample_interval = 5e-324"),
    (HUGE_IMPACT, "soft.hardness.impact_speed = 1e+300"),
    ("walls.0.velocity=1e300", "walls[0].velocity = 1e+300"),
])
@pytest.mark.parametrize("command", [["deck"], ["run", "--engine", "lammps", "-q"]])
def test_overflowing_values_are_refused_before_any_deck(tmp_path, capsys, setting, field,
                                                        command):
    out = ["-o", str(tmp_path / "deck")] if command == ["deck"] else [
        "--out", str(tmp_path / "r.h5")]
    err = _refused(capsys, [command[0], str(CHUTE), "--set", setting, *command[1:], *out])
    assert field in err and "OverflowError" not in err
    assert not (tmp_path / "deck").exists() and not (tmp_path / "r.h5").exists()


def test_sample_count_is_bounded():
    """An interval above MIN_INTERVAL can still ask for more than MAX_SAMPLES samples."""
    run_length = 200.0 + 400.0  # chute-30: equilibration + production
    interval = 0.5 * run_length / MAX_SAMPLES
    assert interval > MIN_INTERVAL
    with pytest.raises(SceneError, match=r"run.sample_interval = .*at most 1e\+09 samples"):
        load_scene(CHUTE, [f"run.sample_interval={interval!r}"])
    load_scene(CHUTE, [f"run.sample_interval={2 * run_length / MAX_SAMPLES!r}"])


def test_speeds_at_the_bound_still_give_finite_contacts():
    """At the largest allowed speed the hardness mapping is finite (k_n ∝ v²/δ²)."""
    from demstudy.contact.stiffness import contact_setup

    scene = load_scene(CHUTE, [f"soft={{hardness={{overlap=1e-6, impact_speed={MAX_SPEED!r}}}}}"])
    setup = contact_setup(scene)
    assert 0 < setup.timestep and setup.kn < float("inf")


# ---- 3. values that validated but gave nonsense -----------------------------------------
LE_2D = ROOT / "inputs" / "shear" / "lees-edwards-2d.toml"


@pytest.mark.parametrize("gravity", ["{angle=30.0}", "{direction=[0.0, -1.0]}",
                                     "{direction=[1.0, 1.0]}"])
def test_gravity_across_lees_edwards_images_is_refused(capsys, gravity):
    err = _refused(capsys, ["validate", str(LE_2D), "--set", f"gravity={gravity}"])
    assert "gravity." in err and "y component" in err and "sliding images" in err
    assert "along x" in err  # what is allowed instead


@pytest.mark.parametrize("gravity", ["{direction=[1.0, 0.0]}", "{angle=90.0}",
                                     "{angle=-90.0}"])
def test_gravity_along_the_flow_is_allowed_with_shear(gravity):
    scene = load_scene(LE_2D, [f"gravity={gravity}"])
    assert abs(scene.gravity_vector[1]) < 1e-12 and abs(scene.gravity_vector[0]) == 1.0


def test_wall_speed_is_bounded():
    """A 1e300 wall speed used to validate and run as a silently frictionless wall."""
    with pytest.raises(SceneError, match=r"walls\[0\].velocity = -1e\+300"):
        load_scene(CHUTE, ["walls.0.velocity=-1e300"])
    # the bound itself is allowed, with contacts stiff enough for impacts that fast (the
    # scene's k_n = 1e5 would overlap by 2840 d at 1e6: refused, stiffness_problem)
    fastest = load_scene(CHUTE, [f"walls.0.velocity={MAX_SPEED!r}", "soft.stiffness=1e17"])
    assert fastest.walls[0].velocity == MAX_SPEED


SOFT = ["run.equilibration=0", "run.production=4", "run.sample_interval=0.05"]


def test_contacts_too_soft_for_hard_particles_are_warned_and_the_run_agrees(tmp_path, capsys):
    """A stiffness whose head-on overlap at the scene's impact speed (4 √(gd) in chute-30)
    exceeds the health limit is warned about at validation (still exit 0); a short LAMMPS
    run of it then measures an overlap above the limit too, and no more than the estimate
    (its impacts are no faster than the estimated speed)."""
    from demstudy.contact.health import LIMITS
    from demstudy.contact.stiffness import estimated_overlap
    from demstudy.io.results import read_results

    soft = load_scene(CHUTE, ["soft.stiffness=600", *SOFT])
    estimate = estimated_overlap(soft)
    assert estimate > LIMITS["max_overlap"]
    assert main(["validate", str(CHUTE), "--set", "soft.stiffness=600"]) == 0
    err = capsys.readouterr().err
    assert "warning:" in err and "soft.stiffness = 600" in err and "'health'" in err
    out = tmp_path / "soft.h5"
    sets = [a for s in ["soft.stiffness=600", *SOFT] for a in ("--set", s)]
    assert main(["run", str(CHUTE), "--engine", "lammps", "--out", str(out), "-q", *sets]) == 0
    measured = read_results(out).group_attrs["health"]["max_overlap"]
    assert LIMITS["max_overlap"] < measured <= estimate


def test_hard_enough_contacts_are_not_warned_about():
    from demstudy.contact.stiffness import overlap_warning

    for path in sorted((ROOT / "inputs").glob("*/*.toml")):
        assert overlap_warning(load_scene(path)) is None, path
    # the preset's own k_n = 1e5: δ ≈ 1.8e-3 d at 1 √(gd), i.e. 7e-3 d at 4 √(gd)
    assert overlap_warning(load_scene(CHUTE, ["soft.stiffness=1e5"])) is None
