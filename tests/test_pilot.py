"""The event-driven pilot and the automatic soft-contact settings it gives.

Dimensionless particle units: d = 1, m = 1 (no gravity here: the impact speed sets the time
scale). References: a binary collision's normal restitution is the contact's e exactly
(damped linear contact), and no particle may leave the box.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from demstudy.contact import pilot as pilot_mod
from demstudy.contact.mapping import hooke_max_overlap
from demstudy.contact.pilot import PilotWarning, run_pilot
from demstudy.contact.stiffness import (
    DESIGN_QUANTILE,
    TARGET_CONTACT_RATIO,
    TARGET_OVERLAP,
    contact_setup,
)
from demstudy.io.results import read_results
from demstudy.scene import validate_scene
from demstudy.simulation import RunOptions, run_scene

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(autouse=True)
def cache_home(tmp_path, monkeypatch):
    """Every test gets its own cache folder (pilots and machine rates)."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))


def file_scene(tmp_path: Path, rows: list[list[float]], walls: list | None = None,
               **run) -> object:
    """A 3D scene whose particles (positions and velocities) come from a file."""
    path = tmp_path / "particles.txt"
    np.savetxt(path, np.asarray(rows, float))
    data = {
        "dimension": 3, "box": {"size": [10.0, 10.0, 10.0]},
        "particles": {"count": len(rows)},
        "contact": {"restitution": 0.8},
        "initial": {"placement": "file", "path": str(path)},
        "run": {"equilibration": 0.0, "production": 2.0, "sample_interval": 0.05, **run},
        "measure": {"keep_frames": True},
    }
    if walls is not None:
        data["walls"] = walls
    return validate_scene(data)


def head_on(tmp_path: Path) -> object:
    """Two spheres fired at each other at relative speed 5 along x."""
    return file_scene(tmp_path, [[3.0, 5.0, 5.0, 2.5, 0.0, 0.0],
                                 [7.0, 5.0, 5.0, -2.5, 0.0, 0.0]])


def oblique_wall(tmp_path: Path) -> object:
    """One sphere hitting the lower wall at speed 5, 37° from the wall (v = (4, −3, 0))."""
    walls = [{"side": "lower", "restitution": 0.7}, {"side": "upper", "restitution": 0.7}]
    return file_scene(tmp_path, [[2.0, 4.0, 5.0, 4.0, -3.0, 0.0]], walls=walls)


def test_head_on_pair_gets_a_stiffness_that_holds(tmp_path):
    """The estimate (no pilot) guesses a speed of 1e-3 for file velocities: k_n ~ 0.01, the
    spheres pass through each other. The pilot sees the impact at 5: the LAMMPS run gives
    the restitution 0.8 (within 0.02) and the largest overlap at most the target."""
    scene = head_on(tmp_path)
    estimate = contact_setup(scene, "lammps")
    assert estimate.basis == "estimate" and estimate.kn < 1.0
    pilot = run_pilot(scene)
    assert pilot.usable and pilot.pair["max"] == pytest.approx(5.0, rel=1e-9)
    setup = contact_setup(scene, "lammps", pilot)
    assert setup.basis == "pilot" and setup.speed == pytest.approx(5.0, rel=1e-9)
    # the overlap target at the design speed holds exactly (m_eff = m/2)
    assert hooke_max_overlap(setup.kn, 0.8, 0.5, 5.0) <= TARGET_OVERLAP * (1 + 1e-9)

    res = read_results(run_scene(scene, "lammps", RunOptions(out=tmp_path / "r.h5",
                                                             progress=False)))
    assert res.attrs["stiffness_basis"] == "pilot"
    assert res.attrs["kn"] == pytest.approx(setup.kn)
    v = res.frames["velocity"]
    assert v.shape[1] == 2  # no atom lost
    before, after = v[0, 0, 0] - v[0, 1, 0], v[-1, 0, 0] - v[-1, 1, 0]
    assert before == pytest.approx(5.0)
    assert -after / before == pytest.approx(0.8, abs=0.02)
    # they bounced back: the left one moves left at the end
    assert v[-1, 0, 0] < 0 < v[-1, 1, 0]


def test_oblique_wall_impact_keeps_its_atom(tmp_path):
    """A sphere hitting a wall obliquely at 5 (normal 3): with the estimated stiffness it
    would sink through (LAMMPS: "Lost atoms"); the pilot's k_n (m_eff = m at the wall)
    returns it with the wall's e = 0.7 within 0.02."""
    scene = oblique_wall(tmp_path)
    pilot = run_pilot(scene)
    assert pilot.wall["max"] == pytest.approx(3.0, rel=1e-9)
    setup = contact_setup(scene, "lammps", pilot)
    assert hooke_max_overlap(setup.kn, 0.7, 1.0, 3.0) <= TARGET_OVERLAP * (1 + 1e-9)
    res = read_results(run_scene(scene, "lammps", RunOptions(out=tmp_path / "r.h5",
                                                             progress=False)))
    v, y = res.frames["velocity"], res.frames["position"][:, :, 1]
    assert v.shape[1] == 1 and y.min() > 0.5 - 2 * TARGET_OVERLAP
    assert v[0, 0, 1] == pytest.approx(-3.0)
    # first sample after the bounce (moving up) and before it reaches the upper wall
    up = np.flatnonzero(v[:, 0, 1] > 0)[0]
    assert v[up, 0, 1] / 3.0 == pytest.approx(0.7, abs=0.02)
    assert v[up, 0, 0] == pytest.approx(4.0, abs=1e-6)  # smooth: tangential kept


def test_flight_time_target_stiffens_dense_flows(tmp_path):
    """In a gas the contact time is at most TARGET_CONTACT_RATIO × the measured flight time
    and the overlap at the design speed at most TARGET_OVERLAP."""
    scene = validate_scene({
        "dimension": 2, "box": {"size": [20.0, 20.0]}, "particles": {"solid_fraction": 0.5},
        "contact": {"restitution": 0.9},
        "initial": {"placement": "random", "velocity": {"temperature": 1.0}},
        "run": {"equilibration": 0.0, "production": 5.0, "sample_interval": 0.5},
    })
    pilot = run_pilot(scene)
    assert pilot.rate > 0 and math.isfinite(pilot.tau_flight)
    setup = contact_setup(scene, "lammps", pilot)
    assert setup.pair.contact_time <= TARGET_CONTACT_RATIO * pilot.tau_flight * (1 + 1e-9)
    v = pilot.speed("pair", DESIGN_QUANTILE)
    assert v >= pilot.pair[f"q{DESIGN_QUANTILE:g}"]
    assert hooke_max_overlap(setup.kn, 0.9, 0.5, v) <= TARGET_OVERLAP * (1 + 1e-9)


def test_unrunnable_scene_falls_back_to_the_estimate_and_says_so(tmp_path):
    """A scene the event-driven engine refuses (a periodic box shorter than 3 d) gives an
    unusable pilot, a PilotWarning, and stiffness_basis 'estimate'."""
    scene = validate_scene({
        "dimension": 2, "box": {"size": [2.5, 10.0]}, "particles": {"count": 2},
        "contact": {"restitution": 0.9},
        "walls": [{"side": "lower", "restitution": 0.9},
                  {"side": "upper", "restitution": 0.9, "velocity": 1.0}],
        "initial": {"placement": "random", "velocity": {"temperature": 1.0}},
        "run": {"equilibration": 0.0, "production": 1.0, "sample_interval": 0.5},
    })
    with pytest.warns(PilotWarning, match="estimate"):
        pilot = run_pilot(scene)
    assert not pilot.usable and "box.size" in pilot.reason
    setup = contact_setup(scene, "lammps", pilot)
    assert setup.basis == "estimate"
    assert setup.kn == contact_setup(scene, "lammps").kn


def test_the_cache_is_reused(tmp_path, monkeypatch):
    """A second pilot of the same scene is read from the cache (the measurement is not run
    again); another scene is measured."""
    scene = head_on(tmp_path)
    calls = []
    measure = pilot_mod._measure

    def counting(*args, **kwargs):
        calls.append(1)
        return measure(*args, **kwargs)

    monkeypatch.setattr(pilot_mod, "_measure", counting)
    first = run_pilot(scene)
    second = run_pilot(scene)
    assert len(calls) == 1 and first == second
    assert pilot_mod.pilot_cache_path(scene).is_file()
    run_pilot(oblique_wall(tmp_path))
    assert len(calls) == 2


def test_the_particles_file_is_part_of_the_cache_key(tmp_path):
    """Same scene TOML, other velocities in the file: another pilot."""
    scene = head_on(tmp_path)
    key = pilot_mod.pilot_cache_path(scene)
    np.savetxt(tmp_path / "particles.txt", [[3.0, 5.0, 5.0, 1.0, 0.0, 0.0],
                                            [7.0, 5.0, 5.0, -1.0, 0.0, 0.0]])
    assert pilot_mod.pilot_cache_path(scene) != key
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert run_pilot(scene).pair["max"] == pytest.approx(2.0, rel=1e-9)


def test_initial_floor_sees_particles_fired_at_each_other():
    """Approaching neighbours count with their normal approach speed, receding ones do not; a
    wall's own velocity slides along x and is no impact speed (it was: the floor of a
    Couette cell was the wall speed); a particle moving towards a wall is."""
    scene = validate_scene({"dimension": 2, "box": {"size": [10.0, 10.0]},
                            "particles": {"count": 2}, "contact": {"restitution": 0.9},
                            "walls": [{"side": "lower", "restitution": 0.9},
                                      {"side": "upper", "restitution": 0.9, "velocity": 5.0}],
                            "initial": {"placement": "random"},
                            "run": {"equilibration": 0.0, "production": 1.0,
                                    "sample_interval": 0.5}})
    pos = np.array([[2.0, 5.0], [4.0, 5.0]])
    approach = np.array([[1.5, 0.0], [-1.5, 0.0]])
    assert pilot_mod.initial_floor(scene, pos, approach) == pytest.approx(3.0)
    assert pilot_mod.initial_floor(scene, pos, -approach) == 0.0
    falling = np.array([[0.0, -2.0], [0.0, 0.0]])
    assert pilot_mod.initial_floor(scene, pos, falling) == pytest.approx(2.0)


def test_initial_floor_is_a_quantile_not_the_largest_pair():
    """2000 isolated pairs closing at 1 and one at 100: the floor is the pairs'
    DESIGN_QUANTILE (1), not the one outlier, whose weight shrinks with N."""
    scene = validate_scene({"dimension": 2, "box": {"size": [20000.0, 10.0]},
                            "particles": {"count": 2}, "contact": {"restitution": 0.9},
                            "initial": {"placement": "random"},
                            "run": {"equilibration": 0.0, "production": 1.0,
                                    "sample_interval": 0.5}})
    n = 2001
    pos = np.zeros((2 * n, 2))
    pos[0::2, 0] = 10.0 * np.arange(n)
    pos[1::2, 0] = 10.0 * np.arange(n) + 2.0
    vel = np.zeros((2 * n, 2))
    vel[0::2, 0], vel[1::2, 0] = 0.5, -0.5
    vel[0, 0], vel[1, 0] = 50.0, -50.0
    speeds = np.r_[100.0, np.ones(n - 1)]
    assert pilot_mod.initial_floor(scene, pos, vel) == pytest.approx(
        np.quantile(speeds, DESIGN_QUANTILE))
    assert pilot_mod.initial_floor(scene, pos, vel) < 2.0


def test_couette_floor_leaves_out_the_wall_speed():
    """Campbell's rough Couette cell with automatic stiffness: the impacts are slow against
    the wall speed U = 1 (relative speeds ~ γ̇ d), so the design speed, hence k_n, comes from
    the measured impacts and the initial approach speeds, not from U (before: floor 1,
    k_n ~ 50 × stiffer than needed)."""
    import tomllib

    data = tomllib.loads((ROOT / "inputs/campbell1982/couette-rough.toml").read_text())
    del data["soft"]["hardness"]
    data["run"].update(equilibration=0.0, production=200.0)
    scene = validate_scene(data)
    wall_speed = max(abs(w.velocity) for w in scene.walls)
    pilot = run_pilot(scene)
    assert pilot.usable and pilot.floor < 0.5 * wall_speed
    setup = contact_setup(scene, "lammps", pilot)
    measured = max(pilot.pair[f"q{DESIGN_QUANTILE:g}"], pilot.wall[f"q{DESIGN_QUANTILE:g}"],
                   pilot.floor)
    assert setup.basis == "pilot" and setup.speed == pytest.approx(measured)
    assert setup.speed < 0.5 * wall_speed


def test_capped_pilots_are_cached_apart(tmp_path, monkeypatch):
    """A pilot cut by a smaller wall-time cap or collision window (plan.py runs one with
    seconds = min(5, 0.1 × forecast)) is not returned for an uncapped call: seconds and
    collisions are part of the cache key."""
    scene = head_on(tmp_path)
    calls = []
    measure = pilot_mod._measure

    def counting(*args, **kwargs):
        calls.append(args[1:])
        return measure(*args, **kwargs)

    monkeypatch.setattr(pilot_mod, "_measure", counting)
    paths = {pilot_mod.pilot_cache_path(scene), pilot_mod.pilot_cache_path(scene, seconds=0.5),
             pilot_mod.pilot_cache_path(scene, collisions=5.0)}
    assert len(paths) == 3
    run_pilot(scene, seconds=0.5)
    run_pilot(scene)
    run_pilot(scene, collisions=5.0)
    assert calls == [(0.5, pilot_mod.PILOT_COLLISIONS),
                     (pilot_mod.PILOT_SECONDS, pilot_mod.PILOT_COLLISIONS),
                     (pilot_mod.PILOT_SECONDS, 5.0)]
    run_pilot(scene, seconds=0.5)  # each from its own cache now
    run_pilot(scene)
    assert len(calls) == 3
    assert all(p.is_file() for p in paths)
