"""Soft-contact health (demstudy.contact.health, results group ``health``) against analytic
references: a head-on collision's overlap and impact speed, Little's law against Enskog's
collision rate in a dilute gas, enduring contacts in a resting bed, the verdict.

Dimensionless particle units: d = 1, m = 1 (g = 1 where gravity acts).
"""

from __future__ import annotations

import math
from pathlib import Path

import h5py
import numpy as np
import pytest

from demstudy.contact import mapping
from demstudy.contact.health import (
    LIMITS,
    assess,
    contact_sample,
    impact_speeds,
    shear_rate_of,
)
from demstudy.contact.stiffness import contact_setup
from demstudy.io.fields import UNKNOWN_UNITS
from demstudy.io.results import read_results
from demstudy.scene import validate_scene
from demstudy.simulation import RunOptions, run_scene


def run(scene, tmp_path: Path, engine: str = "lammps", name: str = "r.h5", **options):
    return read_results(run_scene(scene, engine, RunOptions(out=tmp_path / name,
                                                            progress=False, **options)))


# -- pure functions ------------------------------------------------------------------------
def test_contact_sample_counts_coordination_and_persistence():
    """Four particles: a chain 0-1-2 and 3 on a wall; 1 has two contacts."""
    values, keys = contact_sample(
        4, np.array([0, 1]), np.array([1, 2]), np.array([0.01, 0.03]),
        np.array([3]), np.array([0.02]), np.array([1.0, 2.0]), previous=None)
    assert values["coordination"] == pytest.approx((1 + 2 + 1 + 1) / 4)
    assert values["multi_contact_fraction"] == pytest.approx(1 / 4)
    assert values["max_overlap"] == pytest.approx(0.03)
    assert values["mean_overlap"] == pytest.approx(0.02)
    assert math.isnan(values["persistent_fraction"])
    # the next sample keeps the pair (2, 1) (either order) and gains (0, 3)
    again, _ = contact_sample(4, np.array([2, 0]), np.array([1, 3]), np.array([0.01, 0.01]),
                              np.array([], dtype=int), np.array([]), np.array([]), keys)
    assert again["persistent_fraction"] == pytest.approx(0.5)
    assert math.isnan(again["max_impact_speed"])


@pytest.mark.parametrize("model", ["hooke", "hertz"])
def test_impact_speed_from_energy_of_the_elastic_contact(model):
    """An undamped contact (e = 1) at any phase gives back its impact speed."""
    kn, v0, m_eff, r_eff = 1e4, 1.3, 0.5, 0.25
    if model == "hooke":
        omega = math.sqrt(kn / m_eff)
        t = np.linspace(0, math.pi / omega, 7)
        overlap, vn = v0 / omega * np.sin(omega * t), v0 * np.cos(omega * t)
    else:  # energy: ½ m v² + (2/5) k √R δ^{5/2} = ½ m v0²
        overlap = np.linspace(0, mapping.hertz_contact(kn, 1.0, m_eff, r_eff, v0).max_overlap,
                              7)
        vn = np.sqrt(v0**2 - 0.8 * kn * math.sqrt(r_eff) * overlap**2.5 / m_eff)
    np.testing.assert_allclose(impact_speeds(vn, overlap, kn, m_eff, r_eff, model), v0,
                               rtol=1e-3)


def test_assess_names_each_violation():
    ok = {"max_overlap": 0.01, "tc_flight": 0.01, "min_steps_per_contact": 50.0,
          "tc_shear": None, "persistent_fraction": math.nan}
    assert assess(ok) == []
    bad = assess({**ok, "max_overlap": 0.08, "min_steps_per_contact": 4.0})
    assert len(bad) == 2
    assert bad[0].startswith("max_overlap 0.08 > 0.05")
    assert "under-resolved" in bad[1]


# -- runs -----------------------------------------------------------------------------------
def two_spheres(tmp_path: Path, model: str, e: float, v: float, kn: float):
    """Two spheres 0.2 d apart closing head-on at speed v, sampled every step."""
    start = tmp_path / "pair.txt"
    start.write_text(f"3.0 5.0 5.0 {v / 2} 0 0\n4.2 5.0 5.0 {-v / 2} 0 0\n")
    spec = {"dimension": 3, "box": {"size": [10.0, 10.0, 10.0]}, "particles": {"count": 2},
            "contact": {"restitution": e},
            "initial": {"placement": "file", "path": str(start)},
            "run": {"equilibration": 0.0, "production": 1.0, "sample_interval": 1.0},
            "soft": {"model": model, "stiffness": kn, "steps_per_contact": 50}}
    if model == "hertz":  # Hertz's t_c depends on the speed: the time step is made for v
        del spec["soft"]["stiffness"]
        spec["soft"]["hardness"] = {"overlap": 0.01, "impact_speed": v}
    dt = contact_setup(validate_scene(spec)).timestep
    tc = 50 * dt
    spec["run"].update(production=(0.2 / v + 2 * tc), sample_interval=dt)
    return validate_scene(spec)


@pytest.mark.parametrize("model", ["hooke", "hertz"])
def test_head_on_collision_overlap_and_impact_speed(tmp_path, model):
    """Largest sampled overlap = the contact model's maximum overlap (sampled every step,
    50 steps per contact: within 1 %); the reconstructed impact speed is the approach speed
    (damping, e = 0.9, makes it a slight underestimate)."""
    v, e = 1.0, 0.9
    scene = two_spheres(tmp_path, model, e, v, 1e4)
    kn = contact_setup(scene).kn
    res = run(scene, tmp_path)
    h, attrs = res.groups["health"], res.group_attrs["health"]
    if model == "hooke":
        expected = mapping.hooke_max_overlap(kn, e, 0.5, v)
        assert attrs["steps_per_contact"] == pytest.approx(scene.soft.steps_per_contact)
    else:
        expected = mapping.hertz_contact(kn, e, 0.5, 0.25, v).max_overlap
        # t_c at the measured impact speeds (close to v: so are the steps realised)
        tc = mapping.hertz_contact(kn, e, 0.5, 0.25, attrs["median_impact_speed"])
        assert attrs["contact_time"] == pytest.approx(tc.contact_time)
        assert attrs["steps_per_contact"] == pytest.approx(50, rel=0.02)
    assert attrs["max_overlap"] == pytest.approx(expected, rel=0.01)
    assert attrs["max_impact_speed"] == pytest.approx(v, rel=0.05)
    assert attrs["max_impact_speed"] <= v * (1 + 1e-3)
    # while touching, each sphere has exactly one contact, never two
    touching = h["contacts"] > 0
    assert touching.sum() >= 40
    np.testing.assert_allclose(h["coordination"][touching], 1.0)
    assert np.all(h["multi_contact_fraction"] == 0)
    assert attrs["shear_time"] is None and attrs["tc_shear"] is None
    # sampled every step, a collision persists from sample to sample as expected of it
    assert not any(p.startswith("persistent") for p in attrs["problems"])


def test_health_uses_the_runs_own_contacts_when_the_pilot_chose_them(tmp_path, monkeypatch):
    """Automatic stiffness (no soft.stiffness, no soft.hardness): the pilot sees the impact at
    v = 1 and sets k_n; the health group's contact time and steps per contact are those of the
    run (its attrs, the scene's steps_per_contact), not of the guessed reference speed
    (1e-3 for file velocities: a contact ~10³ × longer)."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))  # the pilot's cache
    start = tmp_path / "pair.txt"
    start.write_text("3.0 5.0 5.0 0.5 0 0\n4.2 5.0 5.0 -0.5 0 0\n")
    scene = validate_scene({
        "dimension": 3, "box": {"size": [10.0, 10.0, 10.0]}, "particles": {"count": 2},
        "contact": {"restitution": 0.9}, "initial": {"placement": "file", "path": str(start)},
        "run": {"equilibration": 0.0, "production": 0.4, "sample_interval": 0.01},
        "soft": {"steps_per_contact": 40}})
    res = run(scene, tmp_path)
    attrs = res.group_attrs["health"]
    assert res.attrs["stiffness_basis"] == "pilot"
    assert attrs["contact_time"] == pytest.approx(res.attrs["contact_time"], rel=1e-12)
    assert attrs["steps_per_contact"] == pytest.approx(scene.soft.steps_per_contact)
    assert attrs["timestep"] == res.attrs["timestep"]
    guessed = contact_setup(scene).pair.contact_time
    assert attrs["contact_time"] < guessed / 100


def gas(n: int, phi: float, stiffness: float, production: float = 6.0):
    """Elastic smooth discs at T = 1 (no cooling: e = 1), sampled every 0.05."""
    length = math.sqrt(n * math.pi / 4 / phi)
    return validate_scene({
        "dimension": 2, "box": {"size": [length, length]}, "particles": {"count": n},
        "contact": {"restitution": 1.0},
        "initial": {"placement": "random", "velocity": {"temperature": 1.0}},
        "run": {"equilibration": 0.0, "production": production, "sample_interval": 0.05,
                "seed": 3},
        "soft": {"stiffness": stiffness, "steps_per_contact": 30},
    })


def test_stiff_dilute_gas_is_healthy_and_follows_enskog(tmp_path, capsys):
    """φ = 0.1, stiff contacts: coordination ≈ 0, the hard limit holds, and the flight time
    from Little's law (contacts per particle / t_c) is Enskog's 1/ω within the sampling
    error (~300 contacts counted: ±6 %; Enskog itself is good to a few % at φ = 0.1)."""
    res = run(gas(1000, 0.1, 1e5), tmp_path)
    attrs = res.group_attrs["health"]
    assert attrs["healthy"], attrs["problems"]
    assert attrs["problems"] == []
    assert attrs["coordination"] < 0.01
    assert attrs["multi_contact_fraction"] < 1e-3
    assert attrs["max_overlap"] < LIMITS["max_overlap"]
    assert attrs["tc_flight"] < 0.02
    assert res.groups["health"]["contacts"].sum() > 150
    assert attrs["flight_time"] == pytest.approx(attrs["flight_time_enskog"], rel=0.25)
    assert "warning" not in capsys.readouterr().err
    with h5py.File(res.path) as f:  # every dataset has its units and description
        for name, data in f["health"].items():
            assert data.attrs["units"] not in ("", UNKNOWN_UNITS), name
            assert data.attrs["description"], name


def test_soft_gas_is_flagged_with_the_overlap_named(tmp_path, capsys):
    """k_n = 30: a typical impact (v ≈ 2) overlaps by ~0.25 d: unhealthy, said at the end."""
    res = run(gas(300, 0.1, 30.0, production=2.0), tmp_path)
    attrs = res.group_attrs["health"]
    assert not attrs["healthy"]
    assert attrs["max_overlap"] > LIMITS["max_overlap"]
    assert any(p.startswith("max_overlap") and "too soft" in p for p in attrs["problems"])
    err = capsys.readouterr().err
    assert "violate the hard-particle assumptions" in err and "max_overlap" in err
    # the health figure draws the stored series and the limit the run broke
    from demstudy.plots import Run, draw_health

    fig = draw_health([Run.of(res)])
    lines = {line.get_gid(): line for ax in fig.axes for line in ax.get_lines()}
    drawn = lines[f"{res.path.name}:max_overlap"].get_ydata()
    np.testing.assert_array_equal(drawn, res.groups["health"]["max_overlap"])
    assert LIMITS["max_overlap"] in [line.get_ydata()[0] for line in fig.axes[0].get_lines()
                                     if line.get_gid() is None]


def test_lees_edwards_shear_time_and_image_velocities(tmp_path):
    """Under Lees–Edwards shear the shear time is 1/γ̇ and t_c γ̇ follows; pairs across the
    sheared boundary get the image's velocity γ̇ L_y: no reconstructed impact speed comes
    near γ̇ L_y = 20 (without the shift they reach ~36)."""
    scene = validate_scene({
        "dimension": 2, "box": {"size": [20.0, 20.0]}, "particles": {"solid_fraction": 0.4},
        "contact": {"restitution": 0.8}, "shear": {"rate": 1.0},
        "initial": {"placement": "random", "velocity": {"profile": "linear",
                                                          "temperature": 0.5}},
        "run": {"equilibration": 1.0, "production": 3.0, "sample_interval": 0.1},
        "soft": {"stiffness": 2e4, "steps_per_contact": 50},
    })
    attrs = run(scene, tmp_path).group_attrs["health"]
    assert attrs["shear_rate_source"] == "scene shear rate"
    assert attrs["shear_time"] == pytest.approx(1.0)
    assert attrs["tc_shear"] == pytest.approx(attrs["contact_time"])
    assert attrs["contact_time"] == pytest.approx(
        mapping.hooke_contact(2e4, 0.8, 0.5).contact_time)
    assert 0 < attrs["max_impact_speed"] < 10


def test_shear_rate_from_walls_and_from_the_profile():
    couette = validate_scene({
        "dimension": 2, "box": {"size": [10.0, 8.0]}, "particles": {"count": 10},
        "contact": {"restitution": 0.9},
        "walls": [{"side": "lower", "restitution": 0.9, "velocity": -1.0},
                  {"side": "upper", "restitution": 0.9, "velocity": 1.0}],
        "initial": {"placement": "random"},
        "run": {"equilibration": 0.0, "production": 1.0},
    })
    assert shear_rate_of(couette, None) == (pytest.approx(2.0 / 8.0),
                                            "wall speed difference / gap (Couette)")
    gas_scene = gas(10, 0.1, 1e5)
    y = np.linspace(0.5, 9.5, 10)
    profile = {"y": y, "velocity": np.column_stack([0.3 * y + 1.0, 0 * y]),
               "solid_fraction": np.full(10, 0.1)}
    rate, source = shear_rate_of(gas_scene, profile)
    assert rate == pytest.approx(0.3) and "fit" in source
    profile["velocity"][:, 0] = 2.0  # plug flow: no shear
    assert shear_rate_of(gas_scene, profile) == (None, "no shear")


def resting_bed():
    return validate_scene({
        "dimension": 2, "box": {"size": [10.001, 12.0]},
        "contact": {"restitution": 0.5},
        "gravity": {"angle": 0.0}, "particles": {},
        "walls": [{"side": "lower", "restitution": 0.5}],
        "initial": {"placement": "lattice", "rows": 5, "columns": 10, "spacing": 1.0001,
                    "jitter": False},
        "run": {"equilibration": 3.0, "production": 1.0, "sample_interval": 0.25},
        "soft": {"stiffness": 1e4, "steps_per_contact": 30},
    })


def test_resting_bed_has_enduring_contacts(tmp_path):
    """A lattice settled under gravity on a flat wall: every particle rests on others
    (coordination well above 1), the contacts persist from sample to sample, and the run
    is flagged as not made of binary collisions."""
    res = run(resting_bed(), tmp_path)
    attrs = res.group_attrs["health"]
    assert attrs["coordination"] > 1.5
    assert attrs["persistent_fraction"] > 0.9
    assert attrs["multi_contact_fraction"] > 0.5
    assert not attrs["healthy"]
    assert any(p.startswith("persistent_fraction") for p in attrs["problems"])
    # the wall's contacts count: the bottom row (10 particles) rests on it
    assert np.all(res.groups["health"]["wall_contacts"] == 10)


def test_two_mpi_ranks_see_the_same_contacts(tmp_path):
    """--np 2: pair rows and wall contacts of both ranks are gathered (each pair once), so
    the health of the bed is the single rank's to round-off."""
    one = run(resting_bed(), tmp_path, name="one.h5").groups["health"]
    two = run(resting_bed(), tmp_path, name="two.h5", np=2).groups["health"]
    for key in ("contacts", "pair_contacts", "wall_contacts", "coordination",
                "multi_contact_fraction"):
        np.testing.assert_array_equal(two[key], one[key], err_msg=key)
    for key in ("max_overlap", "mean_overlap"):
        np.testing.assert_allclose(two[key], one[key], rtol=1e-6, err_msg=key)


def test_resumed_run_keeps_every_sample_once(tmp_path):
    """A run stopped after its first sample (a checkpoint) and resumed: the health series
    holds each production sample once, as the uninterrupted run's."""
    from demstudy.errors import EngineError

    scene = gas(200, 0.1, 1e5, production=1.0)
    whole = run(scene, tmp_path, name="whole.h5").groups["health"]
    with pytest.raises(EngineError, match="--resume"):
        run(scene, tmp_path, name="parts.h5", wall_limit=0.0)
    parts = run(scene, tmp_path, name="parts.h5", resume=True).groups["health"]
    np.testing.assert_allclose(parts["time"], whole["time"])
    np.testing.assert_allclose(parts["max_overlap"], whole["max_overlap"], rtol=1e-6)


def test_event_driven_runs_have_no_health_group(tmp_path):
    res = run(gas(50, 0.1, 1e5, production=1.0), tmp_path, engine="edmd")
    assert "health" not in res.groups and "health" not in res.group_attrs
