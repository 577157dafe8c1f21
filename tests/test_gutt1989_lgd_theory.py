"""Gutt's Ch. 2 Couette solution on LGD Couette runs (demstudy.studies.gutt1989.lgd_theory):
the lattice wall's roughness ⟨k_τ²⟩ = 1/4 from the node geometry and from the engine's wall
impulses, the channel's h and Δh, the elastic-bulk regime (γ = 0: ω² > 0), and the part's
checks on a tiny LGD Couette run.

Units: particle units, d = 1 = the lattice spacing, m = 1, no gravity: the wall speed (or, with
walls at rest, the grains' initial speed) is the speed unit; md lines in the listing's integers.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from demstudy.io.results import read_results
from demstudy.scene import validate_scene
from demstudy.simulation import RunOptions, run_scene
from demstudy.studies.base import VERDICTS
from demstudy.studies.gutt1989 import lgd_measure as lm
from demstudy.studies.gutt1989 import lgd_theory
from demstudy.studies.gutt1989 import lgd_theory_measure as tm

ROW = math.sqrt(3) / 2


def _run(data: dict, out: Path) -> Path:
    return run_scene(validate_scene(data), "lgd", RunOptions(out=out, progress=False))


@pytest.mark.parametrize("nxt", [6, 12, 192])
def test_a_grain_touches_the_wall_row_along_two_60_degree_bonds(nxt):
    k2 = tm.wall_row_k2(nxt)
    np.testing.assert_allclose(k2, [0.25, 0.25], rtol=1e-12)


# velocities that approach one wall particle only, or (straight down) whose first bounce
# leaves the other bond receding: one collision per step with the wall row (a grain that
# approaches both bonds can hit both in one step, and the step's sum then mixes ±k_x)
@pytest.mark.parametrize("vx, vy", [(0, -4096), (-3000, -1000), (4000, -1500)])
def test_each_wall_collision_pushes_the_wall_along_a_bond(tmp_path, vx, vy):
    """One grain next to a resting wall row: its first step with a lower-wall impulse (one
    collision) has the wall's shear over normal ±k_x/k_y = ±1/√3, i.e. (k·τ)² = s²/(s² + n²)
    = 1/4; later steps may sum two collisions (both bonds), bounded by the same 1/4."""
    data = {"dimension": 2, "particles": {}, "contact": {"restitution": 1.0},
            "walls": [{"side": "lower", "restitution": 1.0},
                      {"side": "upper", "restitution": 1.0}],
            "run": {"equilibration": 0, "production": 40, "sample_interval": 1,
                    "unit": "steps"},
            "measure": {"bin_width": ROW},
            "lattice": {"nxt": 6, "nyt": 6, "initial": [
                {"md": 1, "x1": 3, "y1": 2, "x2": 0, "y2": 0, "vx": vx, "vy": vy}]}}
    ts = read_results(_run(data, tmp_path / "one.h5")).timeseries
    shear, normal = np.asarray(ts["wall_shear_lower"]), np.asarray(ts["wall_normal_lower"])
    hit = np.isfinite(normal) & (np.abs(normal) > 0)
    assert hit.sum() >= 1
    s, n = shear[hit], normal[hit]
    k2 = s**2 / (s**2 + n**2)
    assert k2[0] == pytest.approx(0.25, rel=2e-3)  # the listing's cos 60° is 780/1560 exactly
    assert np.all(k2 <= 0.25 * (1 + 2e-3))


def test_channel_of_gutts_couette_lattice():
    ch = tm.channel(192, 62, 5760)
    assert ch["h"] == pytest.approx(60 * ROW)
    assert ch["delta_h_2d"] == pytest.approx(30 * ROW)
    assert ch["delta_h"] == pytest.approx(1.5 * 30 * ROW)
    with pytest.raises(ValueError, match="grains"):
        tm.channel(192, 62, 192 * 61)


def tiny_couette(e_pp: float, e_w: float, steps: int = 256) -> dict:
    """A 48 × 16 Couette channel at density ½ (walls ±1, speed_scale 4096)."""
    return {"dimension": 2, "particles": {}, "contact": {"restitution": e_pp},
            "walls": [{"side": "lower", "restitution": e_w, "velocity": -1.0},
                      {"side": "upper", "restitution": e_w, "velocity": 1.0}],
            "run": {"equilibration": 0, "production": steps, "sample_interval": 16,
                    "unit": "steps", "seed": 7},
            "measure": {"bin_width": ROW, "keep_frames": True},
            "lattice": {"nxt": 48, "nyt": 16, "speed_scale": 4096, "fill": [
                {"x1": 1, "y1": 2, "x2": 48, "y2": 15, "density": 0.5}]}}


@pytest.fixture(scope="module")
def tiny_runs(tmp_path_factory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("lgdth")
    return {"lgd-couette-elastic-u4096-long": _run(tiny_couette(1.0, 0.75), d / "el.h5"),
            "lgd-couette-inelastic-u4096": _run(tiny_couette(0.75, 0.75), d / "in.h5"),
            "lgd-couette-elastic-u4096-ew1": _run(tiny_couette(1.0, 1.0), d / "ew1.h5")}


def test_elastic_bulk_gives_the_cos_regime_and_no_solution_without_loss(tiny_runs):
    el = lm.load("el", tiny_runs["lgd-couette-elastic-u4096-long"])
    c = tm.constants(el)
    assert (c.gamma, c.e_w, c.k2) == (0.0, 0.75, 0.25)
    sol = tm.solve(c)
    # (2.10) with γ = 0: ω² = t²R²/(q r d²) > 0, v peaked at the centre
    assert sol.omega2 == pytest.approx(c.t**2 * sol.sigma_ratio**2 / (c.q * c.r), rel=1e-12)
    assert sol.omega2 > 0 and np.argmax(sol.v) == len(sol.v) // 2
    assert tm.constants(lm.load("ew1", tiny_runs["lgd-couette-elastic-u4096-ew1"])) is None
    assert tm.constants(lm.load("in", tiny_runs["lgd-couette-inelastic-u4096"])).gamma == 0.16


def test_part_measures_the_drive_and_gives_verdicts(tiny_runs, tmp_path):
    meas = tm.measure(lm.load("el", tiny_runs["lgd-couette-elastic-u4096-long"]))
    # the grains drag the walls: 0 < σ0/p0 ≤ 1/√3 (every impulse along a ±60° bond)
    assert 0 < meas.v("R") <= 1 / math.sqrt(3)
    assert 0 < meas.v("slip") < 1 and 0 < meas.v("v_wall") < 1
    # the mean flow follows the walls: negative at the bottom, positive at the top
    assert meas.profile["u"][0] < 0 < meas.profile["u"][-1]
    an = lgd_theory.analyse(tiny_runs, tmp_path, quick=True)
    assert len(an.checks) == 8 and all(ch.verdict in VERDICTS for ch in an.checks)
    assert an.checks[0].verdict == "reproduced"  # ⟨k_τ²⟩ = 1/4 and R under the bound
    assert an.figures and an.figures[0].path.exists()


def test_parts_pass_the_runs_a_part_reads(tiny_runs, tmp_path):
    from demstudy.studies.gutt1989 import PARTS
    from demstudy.studies.parts import combined_analysis

    assert PARTS[-1] is lgd_theory and lgd_theory.cases(False) == []
    assert set(tiny_runs) <= set(lgd_theory.reads(False))
    # the part owns no case, so only ``reads`` lets the combined analysis hand it the runs
    an = combined_analysis((lgd_theory,))(tiny_runs, tmp_path, True)
    assert any("⟨k_τ²⟩ = (k·τ)²" in ch.statement and ch.verdict == "reproduced"
               for ch in an.checks)
