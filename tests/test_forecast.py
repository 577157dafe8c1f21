"""The wall-time forecast (arithmetic with injected costs; no timing), the machine-cost
cache, and ``demstudy run --dry-run`` / ``ds.run(dry_run=True)``.

Dimensionless particle units: d = 1, m = 1 (the shear rate or the thermal speed sets τ).
"""

from __future__ import annotations

import json
import math

import pytest

import demstudy as ds
from demstudy.cli import main
from demstudy.contact.pilot import PilotResult
from demstudy.engines import get_backend
from demstudy.scene import scene_to_toml, validate_scene
from demstudy.simulation import forecast as fc


@pytest.fixture(autouse=True)
def cache_home(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))


def gas(n_side: float = 20.0, **soft) -> object:
    return validate_scene({
        "dimension": 2, "box": {"size": [n_side, n_side]}, "particles": {"solid_fraction": 0.3},
        "contact": {"restitution": 0.9},
        "initial": {"placement": "random", "velocity": {"temperature": 1.0}},
        "run": {"equilibration": 1.0, "production": 3.0, "sample_interval": 0.5},
        "soft": soft,
    })


SOFT_COSTS = {"step": 1e-6, "atom_step": 2e-8, "contact_step": 1e-7, "atom_sample": 5e-7,
              "sample": 1e-3, "shear_atom_step": 1e-8, "history_atom_step": 3e-8,
              "wall_step": 4e-7}


def test_soft_forecast_is_the_sum_of_costs_times_counts():
    """N atoms × steps: each count times its cost; steps = duration / dt, rounded up."""
    scene = gas(stiffness=1e4)
    n, dt = scene.n_particles, 1e-3
    f = fc.forecast_run(scene, get_backend("lammps"), dt, costs=SOFT_COSTS)
    steps, samples, nu = 4000, 8, scene.solid_fraction
    expected = (steps * 1e-6 + n * steps * 2e-8 + n * steps * nu * 1e-7 + n * samples * 5e-7
                + samples * 1e-3)
    assert f.seconds == pytest.approx(expected, rel=1e-12)
    assert f"{n} atoms × {steps} steps" in f.basis
    # twice the duration, twice the cost; half the time step, twice the steps' cost
    doubled = scene.model_copy(update={"run": scene.run.model_copy(
        update={"equilibration": 2.0, "production": 6.0})})
    assert fc.forecast_run(doubled, get_backend("lammps"), dt, costs=SOFT_COSTS).seconds == \
        pytest.approx(2 * expected, rel=1e-12)
    half = fc.forecast_run(scene, get_backend("lammps"), dt / 2, costs=SOFT_COSTS).seconds
    assert half == pytest.approx(2 * expected - n * samples * 5e-7 - samples * 1e-3, rel=1e-12)


def test_event_forecast_from_the_pilot_and_from_enskog():
    """Event-driven: the pilot's events per particle per τ × N × duration; with no pilot the
    Enskog collision frequency at T = v_ref² (T0 = 1 here) × 3 events per collision."""
    scene = gas()
    n, costs = scene.n_particles, {"event": 1e-6, "atom_sample": 0.0, "sample": 0.0}
    pilot = PilotResult(True, pair_collisions=1000, events=5000, simulated_time=2.0,
                        n_particles=100)
    f = fc.forecast_run(scene, get_backend("edmd"), pilot=pilot, costs=costs)
    assert f.seconds == pytest.approx(5000 / (100 * 2.0) * n * 4.0 * 1e-6, rel=1e-12)
    from demstudy.theory import collision_frequency

    omega = float(collision_frequency(scene.solid_fraction, 1.0, 2))
    enskog = fc.forecast_run(scene, get_backend("edmd"), costs=costs)
    assert enskog.seconds == pytest.approx(omega * n * 4.0 / 2 * 3.0 * 1e-6, rel=1e-12)
    assert "Enskog" in enskog.basis


def test_collision_counted_runs_know_their_events():
    """run.unit = 'collisions': (equilibration + production) × N pair collisions, × the
    pilot's events per collision."""
    scene = gas().model_copy(update={"run": gas().run.model_copy(update={"unit": "collisions"})})
    pilot = PilotResult(True, pair_collisions=100, events=250, simulated_time=1.0,
                        n_particles=10)
    costs = {"event": 1.0, "atom_sample": 0.0, "sample": 0.0}
    f = fc.forecast_run(scene, get_backend("edmd"), pilot=pilot, costs=costs)
    assert f.seconds == pytest.approx(4.0 * scene.n_particles * 2.5, rel=1e-12)


def test_missing_cost_is_a_clear_error():
    with pytest.raises(ValueError, match="step"):
        fc.forecast_run(gas(stiffness=1e4), get_backend("lammps"), 1e-3,
                        costs={"atom_step": 1e-8})


def test_costs_are_cached_per_cpu_and_remeasured_on_demand(monkeypatch):
    """The benchmark runs once; the cache answers next; another CPU or remeasure runs it
    again."""
    calls = []

    def bench(engine, dim, model):
        calls.append((engine, dim, model))
        return {"event": 1e-6 * len(calls)}, "fake"

    monkeypatch.setattr(fc, "_benchmark", bench)
    monkeypatch.setenv(fc.MEASURE_ENV, "0")  # measuring inside a run forbidden: refused
    with pytest.raises(fc.RatesNotMeasured, match="demstudy forecast"):
        fc.measure_costs("edmd", 2)
    assert not calls
    monkeypatch.setenv(fc.MEASURE_ENV, "1")
    assert fc.measure_costs("edmd", 2) == {"event": 1e-6}
    assert fc.measure_costs("edmd", 2) == {"event": 1e-6} and len(calls) == 1
    data = json.loads(fc.rates_path().read_text())
    assert data["cpu"] == fc.cpu_model() and "edmd-2d" in data["rates"]
    assert fc.measure_costs("edmd", 2, remeasure=True) == {"event": 2e-6}
    monkeypatch.setattr(fc, "cpu_model", lambda: "another CPU")
    assert fc.load_rates() == {}
    fc.measure_costs("edmd", 2)
    assert len(calls) == 3


def test_forecast_line_says_the_measured_accuracy_and_basis():
    """The printed band is the one measured constant (ACCURACY), not a ±30 % goal."""
    f = fc.Forecast(12.0, "N × steps")
    assert f.line().startswith("forecast: 12 s (measured accuracy: within ×")
    assert f"×{fc.ACCURACY['factor']:g} in {fc.ACCURACY['met']})" in f.line()
    assert "±" not in f.line() and f.line().endswith("from N × steps")
    assert f.attrs()["forecast_seconds"] == 12.0 and f.attrs()["forecast_basis"] == "N × steps"
    assert f.attrs()["forecast_factor"] == fc.ACCURACY["factor"]


def fake_benchmark(monkeypatch, capsys=None) -> list:
    """Replace the benchmark (no timing): each call records the stderr printed before it."""
    calls = []

    def bench(engine, dim, model):
        calls.append(capsys.readouterr().err if capsys else "")
        return ((SOFT_COSTS if engine == "lammps" else
                 {"event": 1e-6, "atom_sample": 1e-7, "sample": 1e-4}), "fake")

    monkeypatch.setattr(fc, "_benchmark", bench)
    monkeypatch.setenv(fc.MEASURE_ENV, "1")  # measuring allowed: only a dry run refrains
    return calls


def test_dry_run_never_measures_the_machine(tmp_path, monkeypatch, capsys):
    """`demstudy run --dry-run` and ds.run(dry_run=True) with no cached speed: no benchmark,
    no rates file; the plan says there is no forecast and why."""
    calls = fake_benchmark(monkeypatch)
    scene = tmp_path / "gas.toml"
    scene.write_text(scene_to_toml(gas(stiffness=1e4)))
    assert main(["run", str(scene), "--engine", "lammps", "--out", str(tmp_path / "r.h5"),
                 "--dry-run"]) == 0
    out = capsys.readouterr()
    assert ("forecast: none (this machine's speed is not measured yet: demstudy forecast)"
            in out.out)
    assert "measuring" not in out.err
    plan = ds.run(gas(stiffness=1e4), engine="lammps", out=tmp_path / "r.h5", dry_run=True)
    assert "forecast_seconds" not in plan and "not measured yet" in plan["forecast"]
    assert not calls and not fc.rates_path().exists()


def test_a_run_says_it_measures_before_measuring(tmp_path, monkeypatch, capsys):
    """A real run's plan measures the missing speed once, after one line on stderr naming
    the cache file; the next plan reads the cache silently."""
    from demstudy.simulation import RunOptions, plan_run

    calls = fake_benchmark(monkeypatch, capsys)
    backend = get_backend("lammps")
    options = RunOptions(out=tmp_path / "r.h5", progress=False)
    plan = plan_run(gas(stiffness=1e4), backend, options)
    assert len(calls) == 1 and plan.forecast is not None
    assert calls[0].strip() == ("measuring this machine's speed once for the forecasts (~10 s; "
                                f"cached in {fc.rates_path()})")
    capsys.readouterr()
    plan_run(gas(stiffness=1e4), backend, options)
    assert len(calls) == 1 and "measuring" not in capsys.readouterr().err


def test_rates_are_updated_under_a_lock(monkeypatch):
    """_store_rate waits for the lock a parallel worker holds (its read-modify-write would
    otherwise drop the other's entry), then adds its key next to the existing ones."""
    import threading

    from demstudy.cache import locked

    fc._store_rate("edmd-2d", {"model": fc.COST_MODEL, "costs": {"event": 1.0}})
    writer = threading.Thread(target=fc._store_rate,
                              args=("edmd-3d", {"model": fc.COST_MODEL, "costs": {}}))
    with locked(fc.rates_path()):
        writer.start()
        writer.join(0.3)
        assert writer.is_alive()  # blocked on the lock
        assert "edmd-3d" not in fc.load_rates()
    writer.join()
    assert set(fc.load_rates()) == {"edmd-2d", "edmd-3d"}
    assert [p.name for p in fc.rates_path().parent.iterdir()
            if ".tmp" in p.name] == []  # written atomically, nothing left behind


def fake_costs(monkeypatch):
    monkeypatch.setattr(fc, "measure_costs", lambda engine, dim, model=None, **_: (
        SOFT_COSTS if engine == "lammps" else {"event": 1e-6, "atom_sample": 1e-7,
                                                "sample": 1e-4}))


def test_dry_run_runs_nothing_and_prints_the_settings(tmp_path, monkeypatch, capsys):
    """Exit 0, no results file, no work folder; the settings and the forecast printed."""
    fake_costs(monkeypatch)
    scene = tmp_path / "gas.toml"
    scene.write_text(scene_to_toml(gas()))
    out = tmp_path / "r.h5"
    assert main(["run", str(scene), "--engine", "lammps", "--out", str(out), "--dry-run"]) == 0
    text = capsys.readouterr().out
    assert not out.exists() and not out.with_suffix(".lammps").exists()
    for needed in ("engine: lammps", "k_n =", "dt =", "t_c =", "steps per contact",
                   "stiffness basis: pilot", "pilot:", "q0.999", "impacts per particle",
                   "forecast:"):
        assert needed in text, needed


def test_api_dry_run_returns_the_plan(tmp_path, monkeypatch):
    fake_costs(monkeypatch)
    plan = ds.run(gas(stiffness=1e4), engine="lammps", out=tmp_path / "r.h5", dry_run=True)
    assert not (tmp_path / "r.h5").exists()
    assert plan["engine"] == "lammps" and plan["stiffness_basis"] == "stiffness"
    assert plan["kn"] == 1e4 and "pilot_summary" not in plan  # k_n given: no pilot
    assert plan["steps_per_contact"] == pytest.approx(50.0)
    assert plan["forecast_seconds"] > 0 and math.isfinite(plan["forecast_seconds"])
    edmd = ds.run(gas(), engine="edmd", out=tmp_path / "e.h5", dry_run=True)
    assert edmd["collision_rate"] > 0 and "the pilot's" in edmd["forecast_basis"]
    assert not (tmp_path / "e.h5").exists()


def test_a_run_stores_its_forecast_next_to_the_wall_time(tmp_path, monkeypatch):
    fake_costs(monkeypatch)
    scene = gas().model_copy(update={"run": gas().run.model_copy(
        update={"equilibration": 0.0, "production": 1.0})})
    res = ds.run(scene, engine="edmd", out=tmp_path / "r.h5", isolate=False, progress=False)
    assert res.attrs["forecast_seconds"] > 0 and "events" in res.attrs["forecast_basis"]
    assert res.attrs["wall_seconds"] > 0
