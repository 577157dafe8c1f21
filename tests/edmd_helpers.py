"""Helpers shared by the event-driven engine's tests (test_edmd.py, test_edmd_walls.py).

Dimensionless particle units: d = 1, m = 1 (g = 1 with gravity).
"""

from __future__ import annotations

import math

import numpy as np

from demstudy.engines.edmd import EventDriven, core_options, from_initial_state, y_range
from demstudy.scene import parse_scene_text, validate_scene
from demstudy.scene.initial import build_initial_state


def make_scene(dim: int, phi: float, n: int, seed: int = 1, e: float = 1.0,
               extra: str = "", spread: float = 0.0, tangential: str = "smooth",
               production: float = 1.0, sample: float = 1.0, profile: str = "none"):
    """n particles at solid fraction phi in a periodic cube (square), T = 1."""
    unit = math.pi / 6 if dim == 3 else math.pi / 4
    length = (n * unit * (1 + spread**2 / 4) / phi) ** (1 / dim)
    size = [round(length, 9)] * dim
    tang = ('{ model = "smooth" }' if tangential == "smooth"
            else f'{{ model = "beta", beta = {tangential} }}')
    return validate_scene(parse_scene_text(f"""
dimension = {dim}
[box]
size = {size}
[particles]
count = {n}
diameter_spread = {spread}
[contact]
restitution = {e}
tangential = {tang}
[initial.velocity]
temperature = 1.0
profile = "{profile}"
[run]
equilibration = 0.0
production = {production}
sample_interval = {sample}
seed = {seed}
{extra}
"""))


def scene_with(text: str, overrides: dict | None = None):
    """The scene of TOML ``text`` with dotted-key ``overrides`` set to Python values."""
    data = parse_scene_text(text)
    for key, value in (overrides or {}).items():
        target = data
        *path, last = key.split(".")
        for part in path:
            target = target.setdefault(part, {})
        target[last] = value
    return validate_scene(data)


def system(scene, tc: float = 0.0, **kw) -> EventDriven:
    """The core for a scene (with its cell range along a bounded y)."""
    params = core_options(scene)
    initial = build_initial_state(scene)
    if not scene.y_periodic:
        params["y_range"] = y_range(scene, initial.position)
    params.update(kw)
    return from_initial_state(initial, scene.box.size, tc=tc, **params)


def resumed(scene, saved, start: float, until: float, tc: float = 1e-5) -> EventDriven:
    """A fresh system for ``scene`` restored from ``saved`` (taken at ``start``), continued to
    ``until``."""
    b = system(scene, tc=tc)
    b.set_state(saved)
    assert b.time == start
    b.advance_to(until)
    return b


def whole_and_resumed(scene, tmp_path):
    """The results of ``scene`` run in one go and run in two parts (stopped at once by a
    zero wall limit, which checkpoints, then resumed)."""
    import pytest

    from demstudy.errors import EngineError
    from demstudy.io.results import read_results
    from demstudy.simulation import RunOptions, run_scene

    whole = run_scene(scene, "edmd", RunOptions(out=tmp_path / "whole.h5", progress=False))
    out = tmp_path / "parts.h5"
    with pytest.raises(EngineError, match="--resume"):
        run_scene(scene, "edmd", RunOptions(out=out, progress=False, wall_limit=0.0))
    assert (tmp_path / "parts.edmd" / "checkpoint.pkl").exists()
    run_scene(scene, "edmd", RunOptions(out=out, progress=False, resume=True))
    return read_results(whole), read_results(out)


def assert_same_particles(a: EventDriven, b: EventDriven) -> None:
    """Bit-identical positions, velocities and spins."""
    for get in ("positions", "velocities", "angular_velocities"):
        assert np.array_equal(getattr(a, get)(), getattr(b, get)()), get


def energy(s: EventDriven) -> float:
    return s.kinetic_energy + s.rotational_energy


#: A small engine scene: 2D discs at ν = 0.3, e = 0.95, β = 0.4, periodic (override for
#: walls, shear, …).
ENGINE_SCENE = """
dimension = 2
[meta]
name = "edmd-small"
[box]
size = [20.0, 20.0]
[particles]
solid_fraction = 0.3
[contact]
restitution = 0.95
tangential = { model = "beta", beta = 0.4 }
[initial.velocity]
temperature = 1.0
[run]
equilibration = 2.0
production = 4.0
sample_interval = 0.5
seed = 3
[measure]
bin_width = 2.0
"""


def engine_scene(overrides: dict | None = None):
    """ENGINE_SCENE with dotted-key ``overrides``."""
    return scene_with(ENGINE_SCENE, overrides)
