"""Scene values that used to validate but were wrong: booleans or strings taken as numbers,
numbers so large they overflow the decks, and combinations that give nonsense physics.

Dimensionless particle units throughout: d = 1, m = 1 (g = 1 when gravity acts).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from demstudy.cli import main
from demstudy.scene import SceneError, load_scene

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
