"""The share of pair collisions the TC model made elastic: printed at the end of every
event-driven run, written to the results file with its description, and a warning above 5 %.
Dimensionless particle units: d = 1, m = 1; the HCS's initial temperature T0 = 1 sets τ."""

from __future__ import annotations

import math
import re

import pytest

from demstudy.cli import main
from demstudy.engines.edmd.tc_share import WARN_SHARE, TcShare
from demstudy.io.results import read_results

HCS = ["run", "cooling/hcs-3d", "--engine", "edmd", "-q", "--set", "run.production=20"]
# 357 discs at φ = 0.7, e = 0.3: clusters collide so often that ~13 % of the pair collisions
# fall within t_c = 1e-5 of a partner's previous one
DENSE = [*HCS, "--set", "dimension=2", "--set", "box.size=[20,20]",
         "--set", "particles.solid_fraction=0.7", "--set", "contact.restitution=0.3"]
LINE = re.compile(r"TC model: ([\d.]+) % of pair collisions made elastic \((\d+) of (\d+), "
                  r"t_c = ([\de.+-]+)\)")


def run(args: list[str], tmp_path, capfd) -> tuple[dict, str]:
    out = tmp_path / "r.h5"
    assert main([*args, "--out", str(out)]) == 0
    results = read_results(out)
    return results, capfd.readouterr().err


def test_dense_gas_reports_its_share_and_warns(tmp_path, capfd):
    """The printed share, the results file's attribute and the cumulative counters of the
    timeseries agree; above 5 % the run warns and suggests a ten times smaller t_c."""
    results, err = run(DENSE, tmp_path, capfd)
    attrs = results.attrs
    elastic, pairs = results.timeseries["elastic_tc_collisions"][-1], \
        results.timeseries["collisions"][-1]
    assert attrs["pair_collisions"] == pairs and attrs["elastic_tc_collisions"] == elastic
    assert attrs["tc_elastic_fraction"] == pytest.approx(elastic / pairs)
    assert attrs["tc_elastic_fraction"] > WARN_SHARE  # the premise: the model acts a lot
    assert "made elastic" in attrs["tc_elastic_fraction_description"]
    assert "t_c = 1e-05" in attrs["tc_elastic_fraction_description"]
    match = LINE.search(err)
    assert match, err
    assert float(match[1]) == pytest.approx(100 * elastic / pairs, rel=1e-2)
    assert (int(match[2]), int(match[3]), float(match[4])) == (elastic, pairs, 1e-5)
    warning = [line for line in err.splitlines() if line.startswith("warning: the TC model")]
    assert len(warning) == 1 and "more than 5 %" in warning[0]
    assert "--tc 1e-06" in warning[0] and warning[0] == attrs["tc_elastic_warning"]


def test_dilute_gas_reports_a_small_share_without_warning(tmp_path, capfd):
    """The shipped 3D HCS (φ = 0.1, e = 0.9): the share is printed and written, below 5 %,
    and nothing warns."""
    results, err = run(HCS, tmp_path, capfd)
    fraction = results.attrs["tc_elastic_fraction"]
    assert 0.0 <= fraction < WARN_SHARE and results.attrs["pair_collisions"] > 1000
    assert LINE.search(err) and "warning: the TC model" not in err
    assert results.attrs["tc_elastic_warning"] == ""


def test_tc_off_and_no_collisions():
    """t_c = 0 says the model is off; a run without pair collisions has a NaN share and no
    warning (a share of nothing is not large)."""
    assert TcShare(0, 500, 0.0).line().startswith("TC model: off (t_c = 0)")
    empty = TcShare(0, 0, 1e-5)
    assert math.isnan(empty.fraction) and empty.warning() is None
    assert "no pair collisions" in empty.line()
    assert TcShare(6, 100, 1e-4).warning() and TcShare(5, 100, 1e-4).warning() is None


# the dense sheared spheres of the accuracy study (φ = 0.55, e = 0.9, β = 0.5, N = 1050),
# shortened: 3 + 5 strain units
DENSE_SHEAR = ["run", "inputs/accuracy-cost/lees-edwards-3d-phi0.55.toml", "--engine", "edmd",
               "-q", "--set", "run.equilibration=3", "--set", "run.production=5"]


def test_default_tc_is_1e6_for_spheres_and_1e5_for_discs(tmp_path, capfd):
    """Without --tc a 3D run is made at t_c = 1e-6 and a 2D one at 1e-5 (the results say so);
    --tc overrides either. In dense sheared spheres the 3D default is what keeps the elastic
    share small: 1e-5 makes several times more collisions elastic (≈ 2 % against ≈ 0.3 %
    over a long run; benchmarks/bench_tc_choice.py, docs/edmd-engine.md)."""
    from demstudy.engines.edmd import default_tc

    assert (default_tc(3), default_tc(2)) == (1e-6, 1e-5)
    spheres, err = run(DENSE_SHEAR, tmp_path, capfd)
    assert spheres.attrs["tc"] == 1e-6 and "t_c = 1e-06" in err
    small = spheres.attrs["tc_elastic_fraction"]
    discs, _ = run(DENSE, tmp_path, capfd)
    assert discs.attrs["tc"] == 1e-5
    older, _ = run([*DENSE_SHEAR, "--tc", "1e-5"], tmp_path, capfd)
    assert older.attrs["tc"] == 1e-5
    larger = older.attrs["tc_elastic_fraction"]
    assert 0.0 < small < 0.01 and 3 * small < larger < 0.2, (small, larger)
