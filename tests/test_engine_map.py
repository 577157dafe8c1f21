"""The engine map (demstudy/cost/engine_map.py): the stiffness criterion, the classification,
a tiny map end to end, reading it back. Dimensionless particle units: d = 1, m = 1, shear
rate γ̇ = 1 (times in strain units)."""

import csv
import json
import math

import pytest

from demstudy.accuracy import engine_map as em
from demstudy.accuracy.map_output import map_hint, nearest_point
from demstudy.contact import mapping


@pytest.mark.parametrize("e", [0.5, 0.7, 0.9, 0.99, 1.0])
@pytest.mark.parametrize("tau", [1e-4, 0.1, 3.0])
def test_criterion_inverts_hooke_contact(e, tau):
    """k_n from t_c = R τ_flight gives back that contact time through hooke_contact, and k*
    is the same k_n through kn_from_kstar."""
    for dim in (2, 3):
        kn, kstar = em.soft_stiffness(tau, e, ratio=0.05, dim=dim, shear_rate=2.0)
        assert mapping.hooke_contact(kn, e, 0.5).contact_time == pytest.approx(0.05 * tau,
                                                                               rel=1e-12)
        assert mapping.kn_from_kstar(kstar, 2.0, 1.0, dim) == pytest.approx(kn, rel=1e-12)


def test_criterion_scales_as_inverse_square_of_contact_time():
    """A linear contact: halving t_c (R or τ_flight) quadruples the stiffness."""
    assert em.kn_for_contact(0.01, 0.9) == pytest.approx(4 * em.kn_for_contact(0.02, 0.9))
    with pytest.raises(ValueError, match="contact_time"):
        em.kn_for_contact(0.0, 0.9)


def test_classification_from_synthetic_costs():
    assert em.classify(1e-5, 2e-5) == em.SOFT_CHEAPER
    assert em.classify(3e-3, 2e-5) == em.EVENT_CHEAPER
    assert em.classify(2e-5, 2e-5) == em.EVENT_CHEAPER  # a tie goes to the exact engine
    assert em.classify(math.nan, math.nan, impractical=True) == em.IMPRACTICAL
    assert em.classify(1e-5, 2e-5, impractical=True) == em.IMPRACTICAL
    with pytest.raises(ValueError, match="costs must be > 0"):
        em.classify(-1.0, 2e-5)


def test_nearest_point_scales_each_axis_by_its_range():
    data = {"points": [{"dim": 2, "fraction": f, "restitution": e}
                       for f in (0.1, 0.5) for e in (0.5, 0.99)] + [
                      {"dim": 3, "fraction": 0.3, "restitution": 0.9}]}
    assert nearest_point(data, 2, 0.35, 0.6) == {"dim": 2, "fraction": 0.5, "restitution": 0.5}
    assert nearest_point(data, 3, 0.9, 0.1)["fraction"] == 0.3
    assert nearest_point(data, 3, 0.9, 0.1) is not None


def test_bad_options_exit_2():
    from demstudy.cli import main

    assert main(["engine-map", "--dim", "4"]) == 2
    assert main(["engine-map", "--ratio", "0"]) == 2
    assert main(["engine-map", "--dim", "2", "--fractions", "0.95"]) == 2
    assert main(["engine-map", "--restitutions", "1.2"]) == 2


def test_tiny_map_end_to_end(tmp_path):
    """Two 2D points of very short runs: csv, json and png written; every row obeys the
    criterion it was made with, and the measured collision rate is Enskog's for the measured
    temperature (2D: ω = 2 n d g0 √(π T/m), g0 = (1 − 7ν/16)/(1 − ν)²) within 20 %."""
    settings = em.MapSettings(production=40.0, min_strain=1.0, max_strain=5.0,
                              soft_strain=0.2, soft_steps=1000, ratio=0.05, repeats=2)
    result = em.engine_map((2,), (0.3,), (0.7, 0.9), settings, out=tmp_path, workers=1,
                           progress=lambda _: None)
    names = sorted(p.name for p in result.written)
    assert names == ["engine_map.csv", "engine_map.json", "engine_map.png"]
    assert (tmp_path / "engine_map.png").stat().st_size > 10_000
    assert not (tmp_path / "runs").exists()  # scratch runs removed
    lines = (tmp_path / "engine_map.csv").read_text().splitlines()
    assert lines[0].startswith("# dimensionless particle units")
    rows = list(csv.DictReader(line for line in lines if not line.startswith("#")))
    data = json.loads((tmp_path / "engine_map.json").read_text())
    assert len(rows) == len(data["points"]) == 2
    assert data["machine"]["cpu"] and data["machine"]["date"]
    for row in data["points"]:
        assert row["impractical"] == ""
        assert row["tc"] == pytest.approx(0.05 * row["tau_flight"], rel=1e-9)
        assert row["dt"] == pytest.approx(row["tc"] / settings.steps_per_contact, rel=1e-9)
        assert row["soft_steps"] == pytest.approx(row["soft_strain"] / row["dt"], abs=1)
        assert row["repeats"] == 2 and row["log10_ratio_err"] >= 0
        assert row["cost_ratio"] == pytest.approx(10 ** row["log10_ratio"])
        assert row["break_even_R"] == pytest.approx(0.05 * row["cost_ratio"])
        assert row["cheaper"] == em.classify(row["cost_ratio"], 1.0)
        nu, n = row["fraction_actual"], row["particles"] / row["box"] ** 2
        g0 = (1 - 7 * nu / 16) / (1 - nu) ** 2  # Henderson
        enskog = 2 * n * g0 * math.sqrt(math.pi * row["temperature"])
        assert row["collision_rate"] == pytest.approx(enskog, rel=0.2)
        assert row["tc_share"] < 0.01  # dilute: the TC model hardly acts
    # e = 0.9 runs hotter than e = 0.7 (less dissipation at the same shear rate)
    assert data["points"][1]["temperature"] > data["points"][0]["temperature"]

    from demstudy.scene import load_scene

    hint = map_hint(load_scene("shear/lees-edwards-2d"), tmp_path / "engine_map.json")
    assert "nearest point 2D fraction 0.3, e = 0.9" in hint
    assert map_hint(load_scene("shear/lees-edwards-2d"), tmp_path / "absent.json") is None


def test_the_cost_report_ends_with_the_map_line(tmp_path):
    from demstudy.accuracy.report import text_report
    from demstudy.accuracy.study import CostStudy

    study = CostStudy(tmp_path, "k*", [], {}, 0.02, None, "event-driven (edmd): ...",
                      map_hint="engine map: nearest point 2D fraction 0.5, e = 0.9: ...")
    lines = text_report(study).splitlines()
    assert lines[-3].startswith("recommendation: event-driven")
    assert lines[-2].startswith("engine map: nearest point")
