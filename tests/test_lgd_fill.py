"""Seeded random fills of a lattice scene (``[[lattice.fill]]``, demstudy's extension of
Gutt's (1989) md lines): exact counts inside the rectangle, reproducible by seed, written to
Gutt's problem files as md ±1 lines, and why the Couette/Poiseuille presets use them (a
layout uniform along x stays 6-column periodic for ever; a random fill does not).

Units: [lattice] in the listing's integers (user coordinates, velocities 1/256 "cm/s"); the
rest of a scene in particle units (d = 1 = lattice spacing, m = 1, the wall speed U = 1).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from demstudy.engines.lgd import core
from demstudy.engines.lgd.convert import load_scene_or_problem, scene_problem
from demstudy.engines.lgd.effects import lattice_setup
from demstudy.engines.lgd.lattice import MOVABLE, WALL
from demstudy.engines.lgd.problem import (
    build_lattice,
    read_problem,
    storage_column,
    write_problem,
)
from demstudy.scene import SceneError, load_scene, parse_scene_text, scene_to_toml
from demstudy.scene import validate_scene as validate

FIELDS = ("mlp", "ipx", "ipy", "ivx", "ivy")


def scene_data(fills, initial=(), seed: int = 7, nxt: int = 24, nyt: int = 12) -> dict:
    lattice = {"nxt": nxt, "nyt": nyt, "speed_scale": 1024.0, "fill": list(fills)}
    if initial:
        lattice["initial"] = list(initial)
    return {"dimension": 2, "particles": {}, "contact": {"restitution": 1.0},
            "walls": [{"side": "lower", "restitution": 1.0, "velocity": -1.0},
                      {"side": "upper", "restitution": 1.0, "velocity": 1.0}],
            "run": {"equilibration": 0, "production": 20, "sample_interval": 10,
                    "unit": "steps", "seed": seed},
            "lattice": lattice}


def lattice_of(scene):
    setup = lattice_setup(scene)
    return build_lattice(setup.params, setup.lines), setup


def user_nodes(lat, mode: int) -> set[tuple[int, int]]:
    """(ix, iy) of the nodes in ``mode``, user coordinates."""
    nyt, nxt = lat.mlp.shape
    out = set()
    for iy in range(1, nyt + 1):
        for ix in range(1, nxt + 1):
            if lat.mlp[iy - 1, storage_column(ix, iy, nxt)] == mode:
                out.add((ix, iy))
    return out


RECT = {"x1": 5, "y1": 3, "x2": 16, "y2": 9}  # 12 × 7 = 84 nodes


def test_a_fill_places_exactly_its_count_inside_its_rectangle_reproducibly():
    s = validate(scene_data([{**RECT, "count": 30, "vx": 256, "vy": -128}]))
    lat, _ = lattice_of(s)
    grains = user_nodes(lat, MOVABLE)
    assert len(grains) == 30 == s.n_particles
    assert all(5 <= ix <= 16 and 3 <= iy <= 9 for ix, iy in grains)
    moving = lat.mlp == MOVABLE
    assert (lat.ivx[moving] == 256).all() and (lat.ivy[moving] == -128).all()
    assert (lat.ipx[moving] == 0).all() and (lat.ipy[moving] == 0).all()
    again, _ = lattice_of(validate(scene_data([{**RECT, "count": 30, "vx": 256,
                                                "vy": -128}])))
    assert user_nodes(again, MOVABLE) == grains  # the same seed: the same nodes
    other, _ = lattice_of(validate(scene_data([{**RECT, "count": 30, "vx": 256, "vy": -128}],
                                              seed=8)))
    assert user_nodes(other, MOVABLE) != grains  # run.seed seeds the draw
    own, _ = lattice_of(validate(scene_data([{**RECT, "count": 30, "seed": 8}], seed=7)))
    assert user_nodes(own, MOVABLE) == user_nodes(other, MOVABLE)  # its own seed wins


def test_density_counts_the_rectangle_and_fills_only_empty_nodes_after_the_md_lines():
    # md lines first: a wall line through row 5 and a grain row 7, then the fill (density
    # ½ of 84 nodes = 42) on the 60 nodes still empty; a second fill makes walls
    initial = [{"md": -2, "x1": 5, "y1": 5, "x2": 16, "y2": 5},
               {"md": 2, "x1": 5, "y1": 7, "x2": 16, "y2": 7}]
    fills = [{**RECT, "density": 0.5}, {"x1": 1, "y1": 10, "x2": 24, "y2": 11, "count": 5,
                                        "md": -1}]
    lat, _ = lattice_of(validate(scene_data(fills, initial)))
    grains = user_nodes(lat, MOVABLE)
    assert len(grains) == 42 + 12
    assert {(ix, 7) for ix in range(5, 17)} <= grains
    walls = user_nodes(lat, WALL) - {(ix, iy) for iy in (1, 12) for ix in range(1, 25)}
    assert {(ix, 5) for ix in range(5, 17)} <= walls
    assert len(walls) == 12 + 5 and all(10 <= iy <= 11 for _, iy in walls - {(ix, 5) for ix
                                                                             in range(5, 17)})


@pytest.mark.parametrize(("fill", "message"), [
    ({**RECT, "density": 0.0}, r"density.*greater than 0"),
    ({**RECT, "density": 1.5}, r"density.*less than or equal to 1"),
    ({**RECT, "density": 0.5, "count": 4}, r"density = 0.5, count = 4: give exactly one"),
    ({**RECT}, r"density = None, count = None: give exactly one"),
    ({**RECT, "x1": 17, "count": 1}, r"x1 = 17, x2 = 16.*allowed: x1 <= x2"),
    ({**RECT, "x2": 25, "count": 1}, r"lattice.fill\[0\]: rectangle x 5..25, y 3..9; allowed: "
                                     r"inside the lattice, x in 1..24"),
    ({**RECT, "y2": 13, "count": 1}, r"y in 1..12"),
    ({**RECT, "count": 85}, r"lattice.fill\[0\]: count = 85; allowed: 1..84"),
    ({**RECT, "density": 0.001}, r"density = 0.001 gives 0 grains; allowed: 1..84"),
    ({**RECT, "md": 2, "count": 3}, r"lattice.fill\[0\].md = 2: Input should be 1 or -1"),
])
def test_fill_errors_name_field_value_and_allowed(fill, message):
    with pytest.raises(SceneError, match=message):
        validate(scene_data([fill]))


def test_a_fill_larger_than_the_empty_nodes_left_is_refused():
    initial = [{"md": 3, "x1": 5, "y1": 3, "x2": 16, "y2": 8}]  # 72 of the 84 nodes taken
    with pytest.raises(SceneError, match=r"lattice.fill\[0\]: count = 13 grains but the "
                                         r"rectangle x 5..16, y 3..9 has 12 empty nodes.*"
                                         r"allowed: 1..12"):
        validate(scene_data([{**RECT, "count": 13}], initial))


def test_fills_round_trip_through_toml_and_gutts_files_as_md_1_lines(tmp_path: Path):
    s = validate(scene_data([{**RECT, "density": 0.4, "vx": -512},
                             {"x1": 1, "y1": 10, "x2": 24, "y2": 11, "count": 5, "md": -1}],
                            [{"md": 2, "x1": 1, "y1": 2, "x2": 24, "y2": 2}]))
    assert validate(parse_scene_text(scene_to_toml(s))) == s
    lat, setup = lattice_of(s)
    problem = scene_problem(s)
    filled = problem.lines[1:]  # after the one md line: the fills' grains, one line each
    assert len(filled) == round(0.4 * 84) + 5
    assert {ln.md for ln in filled} == {1, -1}
    assert all((ln.x2, ln.y2) == (0, 0) for ln in filled)
    write_problem(tmp_path, problem)
    again = build_lattice(setup.params, read_problem(tmp_path).lines)
    for k in FIELDS:
        assert (getattr(again, k) == getattr(lat, k)).all(), k
    imported = load_scene_or_problem(tmp_path)  # lgd-import: md lines, no fill
    assert imported.lattice.fill is None
    back, _ = lattice_of(imported)
    assert all((getattr(back, k) == getattr(lat, k)).all() for k in FIELDS)


# -- why the presets use random fills ------------------------------------------------------
def periodic_in_six_columns(lat) -> bool:
    return all((np.roll(getattr(lat, k), 6, axis=1) == getattr(lat, k)).all() for k in FIELDS)


def test_a_random_fill_couette_is_not_6_column_periodic_and_the_uniform_layout_was():
    """The deterministic step commutes with a 6-column shift
    (tests/test_lgd_listing_order.py), so a layout uniform along x (the old preset: every
    other row full) is 6-column periodic after any number of steps: the 192-column cell was
    32 copies of a 6-column one. The random fill at the same count breaks that."""
    preset = load_scene("gutt1989/couette-elastic-u4096")
    uniform = load_scene("gutt1989/couette-elastic-u4096", lattice={
        "fill": None, "initial": [{"md": 2, "x1": 1, "y1": iy, "x2": 192, "y2": iy}
                                  for iy in range(2, 62, 2)]})
    assert preset.n_particles == uniform.n_particles == 5760
    for scene, periodic in ((uniform, True), (preset, False)):
        lat, setup = lattice_of(scene)
        core.run_steps(core.prepare(lat, setup.params), setup.params, 64)
        assert lat.ivx[1:-1].any()  # the shear has reached the grains
        assert periodic_in_six_columns(lat) is periodic


def _primes(n: int) -> list[int]:
    out, p = [], 2
    while n > 1:
        if n % p == 0:
            out.append(p)
            while n % p == 0:
                n //= p
        p += 1
    return out


@pytest.mark.parametrize("name", ["gas-box", "explosion", "couette-elastic-u4096",
                                  "couette-elastic-u16384", "couette-inelastic-u4096",
                                  "hourglass", "obstacle-circle", "obstacle-square",
                                  "obstacle-triangle-up", "obstacle-triangle-down", "incline",
                                  "poiseuille-small", "poiseuille-thesis"])
def test_no_gutt_preset_starts_periodic_in_a_multiple_of_6_columns(name):
    """A start invariant under a shift by 6k columns stays so for ever (the step commutes
    with it); the lattice would then be nxt/6k copies of a smaller one. A shift by 6k leaves
    the state alone iff one by gcd(6k, nxt) does, so the shifts nxt/q (q a prime factor of
    nxt/6) cover every 6k < nxt."""
    scene = load_scene(f"gutt1989/{name}")
    lat, _ = lattice_of(scene)
    nxt = lat.mlp.shape[1]
    for q in _primes(nxt // 6):
        shifted = all((np.roll(getattr(lat, k), nxt // q, axis=1) == getattr(lat, k)).all()
                      for k in FIELDS)
        assert not shifted, f"{name}: periodic under a shift by {nxt // q} columns"
