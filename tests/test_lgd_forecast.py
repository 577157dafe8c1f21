"""The lattice engine's wall-time forecast: node-updates, grain-steps and grain-samples at
given costs (no machine measurement in tests), none for a run counted in time.
Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts."""

from __future__ import annotations

import pytest

from demstudy.engines import get_backend
from demstudy.engines.lgd.forecast import counts
from demstudy.scene import load_scene
from demstudy.simulation.forecast import NoForecast, forecast_run
from demstudy.simulation.options import RunOptions
from demstudy.simulation.plan import plan_run

COSTS = {"node_update": 2e-8, "grain_step": 6e-9, "grain_sample": 7e-7, "run": 0.015}


def test_counts_follow_lattice_steps_and_samples():
    scene = load_scene("gutt1989/gas-box")  # 258 × 130 nodes, 4096 grains, 1024 steps
    c = counts(scene)
    assert c["node_update"] == 258 * 130 * 1024
    assert c["grain_step"] == 4096 * 1024
    assert c["grain_sample"] == 4096 * (1024 // 32)
    longer = load_scene("gutt1989/gas-box", ["run.production=2048"])
    assert counts(longer)["node_update"] == 2 * c["node_update"]


def test_forecast_is_the_costed_counts():
    scene = load_scene("gutt1989/gas-box")
    forecast = forecast_run(scene, get_backend("lgd"), costs=COSTS)
    expected = sum(COSTS[k] * v for k, v in counts(scene).items())
    assert forecast.seconds == pytest.approx(expected)
    assert "node-updates" in forecast.basis and "lattice runs" in forecast.line()


def test_time_counted_run_has_no_forecast_and_says_why():
    scene = load_scene("gutt1989/gas-box", ['run.unit="time"', "run.production=50",
                                            "run.sample_interval=5"])
    assert counts(scene) is None
    with pytest.raises(NoForecast, match="steps"):
        forecast_run(scene, get_backend("lgd"), costs=COSTS)
    plan = plan_run(scene, get_backend("lgd"), RunOptions(out=None, progress=False), costs=COSTS,
                    dry_run=True)
    assert plan.forecast is None and "peak" in plan.describe()
