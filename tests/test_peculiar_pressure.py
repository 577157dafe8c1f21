"""The ``pressure`` and ``temperature`` timeseries under Lees–Edwards shear are peculiar:
they measure the fluctuations about the mean flow, agree with ``/stress`` and ``/profiles``,
and do not grow with the box (the streaming profile's kinetic energy, n γ̇² L²/24 per volume
in the 2D pressure, would).

Dimensionless particle units: d = 1, m = 1; the shear rate γ̇ = 1 sets the time unit.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from liggghts_required import require_liggghts

from demstudy.analysis.blocking import BlockAccumulator, jackknife
from demstudy.engines.peculiar import peculiar_observables, peculiar_velocity
from demstudy.io.results import read_results
from demstudy.scene import validate_scene
from demstudy.simulation import RunOptions, run_scene

RATE, PHI, BIN = 1.0, 0.3, 1.0


def test_peculiar_velocity_removes_the_streaming_profile_and_the_drift():
    rng = np.random.default_rng(3)
    n = 500
    y = rng.uniform(0, 30, n)
    position = np.column_stack([rng.uniform(0, 30, n), y])
    mass = rng.uniform(0.5, 2.0, n)
    noise = rng.normal(size=(n, 2))
    noise -= (mass[:, None] * noise).sum(0) / mass.sum()  # zero momentum: the fluctuation
    velocity = noise + np.array([0.7, -0.2])  # a drift
    velocity[:, 0] += 2.5 * (y - 13.0)  # a streaming profile with its own origin
    np.testing.assert_allclose(peculiar_velocity(position, velocity, mass, 2.5), noise,
                               atol=1e-12)
    shifted = position + np.array([0.0, 4.0])  # the origin of y does not matter
    np.testing.assert_allclose(peculiar_velocity(shifted, velocity, mass, 2.5), noise,
                               atol=1e-12)
    obs = peculiar_observables(position, velocity, mass, 2.5)
    twice = float(np.sum(mass[:, None] * noise**2))
    assert obs["peculiar_kinetic_energy"] == pytest.approx(0.5 * twice)
    assert obs["temperature"] == pytest.approx(twice / (2 * n))


def _scene(length: float):
    """2D Lees–Edwards shear, ν = 0.3, e = 0.9 smooth discs, bins one diameter wide."""
    return validate_scene({
        "dimension": 2, "box": {"size": [length, length]},
        "particles": {"solid_fraction": PHI},
        "contact": {"restitution": 0.9},
        "shear": {"rate": RATE},
        "initial": {"placement": "random", "velocity": {"profile": "linear",
                                                          "temperature": 1.0}},
        "run": {"equilibration": 5.0, "production": 30.0, "sample_interval": 0.5, "seed": 1},
        "soft": {"stiffness": 2e4, "steps_per_contact": 30},
        "measure": {"bin_width": BIN, "statistics": ["profiles", "stress"]},
    })


def _mean_and_error(values: np.ndarray) -> tuple[float, float]:
    acc = BlockAccumulator(1, max_blocks=16)
    for v in values:
        acc.add([v])
    est, err = jackknife(acc, lambda mean: mean)
    return float(est[0]), float(err[0])


def _measure(engine: str, length: float, tmp_path: Path) -> dict[str, float]:
    scene = _scene(length)
    res = read_results(run_scene(scene, engine, RunOptions(
        out=tmp_path / f"{engine}-{length:g}.h5", progress=False)))
    ts = res.timeseries
    production = ts["time"] > scene.run.equilibration + 1e-9
    p, p_err = _mean_and_error(ts["pressure"][production])
    temp, temp_err = _mean_and_error(ts["temperature"][production])
    stress = res.groups.get("stress") or res.groups["statistics/stress"]
    diag = [0, 1]
    trace = np.asarray(stress["total"])[:, diag, diag].sum(1) / 2
    trace_err = np.sqrt((np.asarray(stress["total_err"])[:, diag, diag] ** 2).sum(1)) / 2
    # the bins' kinetic stress and temperature are about each bin's mean: the profile's
    # variation inside a bin adds γ̇² h²/12 to ⟨u'²⟩, which the peculiar velocity has not
    inside = RATE**2 * BIN**2 / 12
    number_density = PHI / (math.pi / 4)
    prof_t = res.profiles["temperature"]
    return {"p": p, "p_err": p_err, "t": temp, "t_err": temp_err,
            "p_stress": float(trace.mean()) - number_density * inside / 2,
            # bins correlated in time: at most the mean of their errors
            "p_stress_err": float(trace_err.mean()),
            "t_profiles": float(np.mean(prof_t)) - inside / 2,
            "t_profiles_err": float(np.mean(res.profiles["temperature_err"])),
            "n": scene.n_particles, "kinetic_energy": float(ts["kinetic_energy"][-1])}


@pytest.mark.parametrize("engine", ["edmd", "lammps"])
def test_lees_edwards_pressure_is_peculiar_and_independent_of_the_box(engine, tmp_path):
    """Measured (seed 1, 30 strain units; /stress less the in-bin profile term):
    edmd p = 3.585 ± 0.082 (L = 20, 153 discs) and 3.790 ± 0.059 (L = 40, 611 discs) against
    /stress 3.591 and 3.797; LAMMPS 3.667 ± 0.120 and 3.598 ± 0.067 against 3.665 and 3.598.
    T = 4.61, 4.88 (edmd), 4.96, 4.74 (LAMMPS), the profiles' 4.62, 4.91, 4.97, 4.75. The
    streaming profile would add n γ̇² L²/24 = 6.4 and 25.5 to p (the defect: a pressure
    growing with the box)."""
    runs = {length: _measure(engine, length, tmp_path) for length in (20.0, 40.0)}
    for length, m in runs.items():
        # the mean flow is really there: the total kinetic energy holds it
        assert m["kinetic_energy"] / m["n"] > RATE**2 * length**2 / 24
        sigma = math.hypot(m["p_err"], m["p_stress_err"])
        assert abs(m["p"] - m["p_stress"]) < 3 * sigma, (length, m)
        sigma_t = math.hypot(m["t_err"], m["t_profiles_err"])
        assert abs(m["t"] - m["t_profiles"]) < 3 * sigma_t, (length, m)
    small, large = runs[20.0], runs[40.0]
    assert abs(large["p"] - small["p"]) < 3 * math.hypot(large["p_err"], small["p_err"]), runs
    assert abs(large["t"] - small["t"]) < 3 * math.hypot(large["t_err"], small["t_err"]), runs


@pytest.mark.parametrize("engine", ["edmd", "lammps", "liggghts"])
def test_periodic_pressure_equals_the_stress_trace(engine, tmp_path):
    """A cooling gas in a periodic cube (1000 spheres, φ = 0.2, e = 0.98, no shear: the mean
    flow is the drift alone), every engine: the ``pressure`` timeseries averaged over the run
    equals tr /stress/total / 3 and the ``temperature`` timeseries the profiles' one, to the
    bins' own fluctuation term (measured: 0.828 against 0.827 in LIGGGHTS, 0.827 against
    0.826 in LAMMPS, 0.812 against 0.811 event-driven)."""
    if engine == "liggghts":
        require_liggghts()
    n, phi = 1000, 0.2
    length = (n * math.pi / 6 / phi) ** (1 / 3)
    scene = validate_scene({
        "dimension": 3, "box": {"size": [length] * 3}, "particles": {"count": n},
        "contact": {"restitution": 0.98},
        "initial": {"placement": "random", "velocity": {"temperature": 1.0}},
        "run": {"equilibration": 0.0, "production": 3.0, "sample_interval": 0.1, "seed": 1},
        "soft": {"hardness": {"overlap": 0.005, "impact_speed": 3.0}},
        "measure": {"bin_width": 2.0, "statistics": ["profiles", "stress"]},
    })
    res = read_results(run_scene(scene, engine, RunOptions(out=tmp_path / "r.h5",
                                                           progress=False, isolate=True)))
    ts = res.timeseries
    stress = res.groups.get("stress") or res.groups["statistics/stress"]
    trace = np.asarray(stress["total"])[:, [0, 1, 2], [0, 1, 2]].sum(1).mean() / 3
    assert np.nanmean(ts["pressure"][1:]) == pytest.approx(trace, rel=0.01)
    assert ts["temperature"].mean() == pytest.approx(np.mean(res.profiles["temperature"]),
                                                     rel=0.02)
    assert ts["temperature"][-1] < 0.9 * ts["temperature"][0]  # it cooled: a live gas


def test_lees_edwards_steadiness_is_judged_on_the_fluctuations(tmp_path):
    """A hot start (T0 = 20) under shear at L = 60 cools towards T ≈ 5 within a few strain
    units: the peculiar kinetic energy falls by far more than Campbell's 20 %, the total (the
    mean flow's N γ̇² L²/24 = 150 N of it) by less. The verdict must see the cooling."""
    scene = validate_scene({
        "dimension": 2, "box": {"size": [60.0, 60.0]}, "particles": {"solid_fraction": PHI},
        "contact": {"restitution": 0.9}, "shear": {"rate": RATE},
        "initial": {"placement": "random", "velocity": {"profile": "linear",
                                                          "temperature": 20.0}},
        "run": {"equilibration": 0.0, "production": 3.0, "sample_interval": 0.25, "seed": 1},
    })
    res = read_results(run_scene(scene, "edmd", RunOptions(out=tmp_path / "hot.h5",
                                                           progress=False)))
    ts = res.timeseries
    total = ts["kinetic_energy"]
    assert abs(total[-1] / total[0] - 1) < 0.2  # the total alone would look steady
    assert ts["peculiar_kinetic_energy"][-1] < 0.5 * ts["peculiar_kinetic_energy"][0]
    assert res.attrs["kinetic_energy_trend"] < -0.2 and not res.attrs["steady"]
