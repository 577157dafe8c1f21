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


EVENT_COSTS = {"collision": 2e-6, "crossing": 3e-7, "large_event": 0.0, "atom_sample": 0.0,
               "sample": 0.0, "run": 0.0}


def test_event_forecast_from_the_pilot_and_from_enskog():
    """Event-driven: collisions and cell crossings apart, at the pilot's last window's rates
    per particle per τ × N × duration; with no pilot Enskog's pair collisions (ω/2 per
    particle) and the Maxwellian crossings Σ_a √(2T/π)/w_a at T = 1 (T0 here)."""
    scene = gas()
    n = scene.n_particles
    pilot = PilotResult(True, pair_collisions=1000, events=5000, simulated_time=2.0,
                        n_particles=100, window_collisions=300, window_crossings=900,
                        window_time=1.5)
    f = fc.forecast_run(scene, get_backend("edmd"), pilot=pilot, costs=EVENT_COSTS)
    per = 100 * 1.5
    assert f.seconds == pytest.approx((300 / per * 2e-6 + 900 / per * 3e-7) * n * 4.0,
                                      rel=1e-12)
    assert not f.lower_bound and "probably more than" not in f.line()
    from demstudy.simulation.forecast_events import cell_widths
    from demstudy.theory import collision_frequency

    omega = float(collision_frequency(scene.solid_fraction, 1.0, 2))
    crossings = sum(math.sqrt(2 / math.pi) / w for w in cell_widths(scene))
    enskog = fc.forecast_run(scene, get_backend("edmd"), costs=EVENT_COSTS)
    assert enskog.seconds == pytest.approx((omega / 2 * 2e-6 + crossings * 3e-7) * n * 4.0,
                                           rel=1e-12)
    assert "Enskog" in enskog.basis


def test_collision_counted_runs_know_their_events():
    """run.unit = 'collisions': (equilibration + production) × N pair collisions, with the
    pilot's cell crossings per collision."""
    scene = gas().model_copy(update={"run": gas().run.model_copy(update={"unit": "collisions"})})
    pilot = PilotResult(True, pair_collisions=100, events=250, simulated_time=1.0,
                        n_particles=10, window_collisions=100, window_crossings=150,
                        window_time=1.0)
    costs = dict(EVENT_COSTS, collision=1.0, crossing=0.5)
    f = fc.forecast_run(scene, get_backend("edmd"), pilot=pilot, costs=costs)
    assert f.seconds == pytest.approx(4.0 * scene.n_particles * (1.0 + 1.5 * 0.5), rel=1e-12)


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
                 dict(EVENT_COSTS, atom_sample=1e-7, sample=1e-4)), "fake")

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
        SOFT_COSTS if engine == "lammps" else dict(EVENT_COSTS, atom_sample=1e-7,
                                                   sample=1e-4)))


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
    assert res.attrs["forecast_seconds"] > 0 and "crossings" in res.attrs["forecast_basis"]
    assert res.attrs["wall_seconds"] > 0 and res.attrs["forecast_kind"] == "estimate"


# -- the event-driven model's parts (docs/forecast.md, "Why the Malik runs were missed") ----
def gas3d(n: int = 300, side: float = 30.0, **extra) -> object:
    data = {"dimension": 3, "box": {"size": [side] * 3}, "particles": {"count": n},
            "contact": {"restitution": 1.0},
            "initial": {"placement": "random", "velocity": {"temperature": 1.0}},
            "run": {"equilibration": 0.0, "production": 20.0, "sample_interval": 5.0}}
    data.update(extra)
    return validate_scene(data)


def channel(n: int = 120, length: float = 24.0, restitution: float = 0.8) -> object:
    """A 2D channel between walls at y = 0 and 10, driven by gravity along periodic x."""
    return validate_scene({
        "dimension": 2, "box": {"size": [length, 10.0]}, "particles": {"count": n},
        "contact": {"restitution": restitution},
        "walls": [{"side": "lower", "restitution": 1.0}, {"side": "upper", "restitution": 1.0}],
        "gravity": {"direction": [1.0, 0.0]},
        "initial": {"placement": "random", "velocity": {"temperature": 1.0}},
        "run": {"equilibration": 0.0, "production": 5.0, "sample_interval": 1.0}})


def test_cell_widths_are_the_engines(tmp_path):
    """forecast_events.cell_widths reproduces the event-driven engine's grid: one diameter
    in a dense box, coarsened to ≤ 8 cells per particle in a dilute one (walls: y bounded)."""
    from demstudy.engines.backend import Needs
    from demstudy.engines.edmd import EdmdBackend
    from demstudy.simulation import RunOptions
    from demstudy.simulation.forecast_events import cell_widths

    dilute = gas3d(walls=[{"side": "lower", "restitution": 1.0},
                         {"side": "upper", "restitution": 1.0}])
    for scene in (gas(), dilute, channel()):
        backend = EdmdBackend(scene, RunOptions(out=tmp_path / "r.h5"), tmp_path)
        backend.setup(Needs(), None, None)
        cells = backend.core.cells[:scene.dimension]
        backend.close()
        assert cell_widths(scene) == pytest.approx(
            [length / c for length, c in zip(scene.box.size, cells, strict=True)], rel=1e-9)
    assert min(cell_widths(dilute)) > 1.0  # 30³ cells for 300 particles: coarsened


def test_cell_crossings_of_a_maxwellian_gas(tmp_path):
    """An elastic dilute gas keeps T = 1: its cell crossings per particle per τ are the
    Maxwellian flux Σ_a √(2T/π)/w_a (within 10 %, ~2·10⁴ crossings counted)."""
    from demstudy.simulation.forecast_events import crossing_rate

    scene = gas3d()
    res = ds.run(scene, engine="edmd", out=tmp_path / "r.h5", isolate=False, progress=False)
    measured = res.attrs["cell_crossings"] / (scene.n_particles * 20.0)
    assert measured == pytest.approx(crossing_rate(scene, 1.0), rel=0.1)


def test_pilot_keeps_its_last_windows_counts():
    """The pilot's last window: pair + wall collisions, cell crossings, its duration; in a
    wall-less gas its impact rate counts each pair collision twice."""
    from demstudy.contact.pilot import run_pilot

    pilot = run_pilot(gas3d(), cache=False)
    assert pilot.window_time > 0 and pilot.window_crossings > pilot.window_collisions > 0
    assert pilot.rate == pytest.approx(
        2 * pilot.window_collisions / (pilot.n_particles * pilot.window_time), rel=0.02)


def test_heavy_analyses_are_in_the_forecast(tmp_path, monkeypatch):
    """A run sampling g(r) often spends most of its loop in the analysis: the forecast times
    the scene's own streaming statistics (on a synthetic frame) and comes within ×2 of the
    run's own wall time, the engine's costs aside (given as nearly nothing here)."""
    monkeypatch.setattr(fc, "measure_costs", lambda *a, **k: dict(EVENT_COSTS,
                                                                  collision=1e-9,
                                                                  crossing=1e-9))
    scene = validate_scene({
        "dimension": 2, "box": {"size": [80.0, 80.0]}, "particles": {"count": 2400},
        "contact": {"restitution": 1.0},
        "initial": {"placement": "random", "velocity": {"temperature": 1.0}},
        "run": {"equilibration": 0.0, "production": 0.6, "sample_interval": 0.01},
        "measure": {"statistics": ["profiles", "gr"]}})
    res = ds.run(scene, engine="edmd", out=tmp_path / "r.h5", isolate=False, progress=False)
    forecast, actual = res.attrs["forecast_seconds"], res.attrs["wall_seconds"]
    assert "gr " in res.attrs["forecast_basis"]
    assert 0.5 < forecast / actual < 2.0, (forecast, actual)


def test_checkpoints_write_the_frames_kept_so_far():
    """Checkpoints every 2 τ of a 6 τ run (none at its end): at samples 2 and 4, with 0 and
    2 production frames kept (equilibration 2 τ), each with the engine's state."""
    from demstudy.simulation import forecast_sampling as fs

    scene = gas3d(run={"equilibration": 2.0, "production": 4.0, "sample_interval": 1.0})
    n = scene.n_particles
    count, written = fs.checkpoint_bytes(scene, True, 2.0)
    assert count == 2
    assert written == 2 * fs.ENGINE_BYTES_PER_PARTICLE * n + 2 * fs.frame_bytes(3) * n
    assert fs.checkpoint_bytes(scene, False, 2.0)[1] == 2 * fs.ENGINE_BYTES_PER_PARTICLE * n
    assert fs.checkpoint_bytes(scene, True, None) == (0, 0.0)


def test_a_flow_gravity_accelerates_gets_a_lower_bound():
    """Gravity along periodic x between walls: the pilot sees the flow's start, so the
    forecast is a lower bound and says so; a gas without gravity gets an estimate."""
    pilot = PilotResult(True, pair_collisions=100, events=400, simulated_time=3.0,
                        n_particles=120, window_collisions=100, window_crossings=300,
                        window_time=1.0, rate_growth=2.0, stopped_by="5 s wall-time cap")
    f = fc.forecast_run(channel(), get_backend("edmd"), pilot=pilot, costs=EVENT_COSTS)
    assert f.kind == "lower bound" and "gravity accelerates" in f.lower_bound
    assert f.line().startswith("forecast: probably more than ")
    assert "measured accuracy" not in f.line()
    assert f.attrs()["forecast_kind"] == "lower bound"
    assert fc.forecast_run(channel(), get_backend("edmd"), costs=EVENT_COSTS).lower_bound
    # without gravity: a pilot capped while its rate still rose is a lower bound, a
    # settled one an estimate
    assert "wall-time cap" in fc.forecast_run(gas(), get_backend("edmd"), pilot=pilot,
                                              costs=EVENT_COSTS).lower_bound
    import dataclasses

    settled = dataclasses.replace(pilot, stopped_by="settled after 3 windows", rate_growth=1.1)
    assert not fc.forecast_run(gas(), get_backend("edmd"), pilot=settled,
                               costs=EVENT_COSTS).lower_bound


def test_a_finished_run_of_the_family_scales_the_forecast(tmp_path):
    """A finished run of the same channel (another e, half the length and N) next to the
    results file gives the rates: its collisions and cell crossings per particle per τ × N ×
    duration (crossings × the ratio of Σ 1/w); no longer a lower bound."""
    from demstudy.simulation import RunOptions
    from demstudy.simulation.forecast_events import cell_widths

    short = channel(60, 12.0, restitution=0.9)
    ref = ds.run(short, engine="edmd", out=tmp_path / "short.h5", isolate=False,
                 progress=False)
    a = ref.attrs
    scene = channel()
    f = fc.forecast_run(scene, get_backend("edmd"), costs=EVENT_COSTS,
                        options=RunOptions(out=tmp_path / "long.h5"))
    assert not f.lower_bound and "short.h5" in f.basis
    per = 60 * 5.0
    collisions = (a["pair_collisions"] + a["wall_collisions"]) / per
    widths = (sum(1 / w for w in cell_widths(scene))
              / sum(1 / w for w in cell_widths(short)))
    crossings = (a["events"] / per - collisions) * widths
    n = scene.n_particles * 5.0
    assert f.seconds == pytest.approx((collisions * 2e-6 + crossings * 3e-7) * n, rel=1e-9)
    # a denser channel is another family: no reference, the start-only lower bound again
    dense = channel(240)
    assert fc.forecast_run(dense, get_backend("edmd"), costs=EVENT_COSTS,
                           options=RunOptions(out=tmp_path / "dense.h5")).lower_bound


def test_the_pilots_own_counts_then_its_last_windows_rates():
    """What the pilot counted from t = 0 (its whole run: the slow start of an accelerating
    flow included), then its last window's rates for the rest of the run; a run shorter
    than the pilot gets the pilot's counts scaled down."""
    pilot = PilotResult(True, pair_collisions=100, events=1000, simulated_time=2.0,
                        n_particles=100, window_collisions=100, window_crossings=300,
                        window_time=1.0, total_collisions=150)
    scene = gas()  # 4 τ
    n = scene.n_particles
    f = fc.forecast_run(scene, get_backend("edmd"), pilot=pilot, costs=EVENT_COSTS)
    collisions = (1.5 + 1.0 * 2.0) * n
    crossings = (8.5 + 3.0 * 2.0) * n
    assert f.seconds == pytest.approx(collisions * 2e-6 + crossings * 3e-7, rel=1e-12)
    short = scene.model_copy(update={"run": scene.run.model_copy(
        update={"equilibration": 0.0, "production": 1.0})})
    f = fc.forecast_run(short, get_backend("edmd"), pilot=pilot, costs=EVENT_COSTS)
    assert f.seconds == pytest.approx((1.5 * 2e-6 + 8.5 * 3e-7) * n / 2, rel=1e-12)


def test_gravity_given_as_an_angle_is_forecast_and_matched():
    """Chutes give gravity as an angle (no direction vector): the forecast's acceleration
    test and the finished-run family both read the scene's gravity vector; a different
    drive (wall speed) is another family."""
    from demstudy.scene import load_scene
    from demstudy.simulation.forecast import accelerates
    from demstudy.simulation.forecast_events import drive, same_family

    chute = load_scene("campbell1982/chute-20")
    assert chute.gravity.direction is None and accelerates(chute)
    assert same_family(chute, load_scene("campbell1982/chute-20", ["run.production=10"]))
    assert not same_family(chute, load_scene("campbell1982/chute-30"))
    couette = load_scene("campbell1982/couette-rough")
    faster = load_scene("campbell1982/couette-rough", ["walls.1.velocity=10.0"])
    assert not same_family(couette, faster)
    # a bumpy base adds wall collisions: another family than the flat base at the same angle
    flat, bumpy = load_scene("campbell1982/chute-30"), load_scene("campbell1982/chute-bumpy-30")
    assert not same_family(flat, bumpy)
    (f_dim, f_walls, *f_rest), (b_dim, b_walls, *b_rest) = drive(flat), drive(bumpy)
    assert (f_dim, f_rest) == (b_dim, b_rest)  # the same angle, the same wall speeds ...
    assert [(w[0], w[2]) for w in f_walls] == [(w[0], w[2]) for w in b_walls]
    assert [w[1] for w in b_walls] == ["bumpy"] != [w[1] for w in f_walls]  # ... but the kind
