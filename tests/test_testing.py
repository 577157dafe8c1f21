"""demstudy.testing: profiles compared within their combined errors. False alarms at the
stated rate for runs of the same state, disagreement found and tabled, and two engines
compared on a state both must get right. Units: d = 1, m = 1, g = 1.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from demstudy.io.results import Results
from demstudy.testing import assert_profiles_agree, compare_profiles

N_BINS = 40


def synthetic(rng, shift: dict | None = None, err: float = 0.01) -> Results:
    """Profiles of one state measured with standard errors ``err`` (velocity: 2 components);
    ``shift``: {(field, bin): offset} moves single values."""
    edges = np.linspace(0.0, 20.0, N_BINS + 1)
    truth = {"solid_fraction": np.full(N_BINS, 0.3), "temperature": np.full(N_BINS, 1.0),
             "velocity": np.zeros((N_BINS, 2))}
    prof = {"edges": edges, "y": 0.5 * (edges[1:] + edges[:-1])}
    for name, value in truth.items():
        prof[name] = value + rng.normal(0.0, err, value.shape)
        prof[f"{name}_err"] = np.full(value.shape, err)
    for (name, b), offset in (shift or {}).items():
        prof[name][b] += offset
    return Results({"scene_name": "synthetic", "engine": "none"}, profiles=prof)


def test_runs_of_one_state_fail_at_the_stated_rate():
    """160 values per comparison; 3σ for the whole comparison: 0.27 % false alarms. Over
    3000 pairs about 8 fail (a per-value 3σ test would fail 35 % of them)."""
    rng = np.random.default_rng(1)
    fails = sum(not compare_profiles(synthetic(rng), synthetic(rng), sigma=3.0).ok
                for _ in range(3000))
    assert fails <= 20, fails
    per_value = sum(compare_profiles(synthetic(rng), synthetic(rng)).worst > 3.0
                    for _ in range(300))
    assert per_value > 60  # why the correction is needed


def blocked(rng, n_blocks: int) -> Results:
    """Profiles of one state whose errors are estimated from ``n_blocks`` block means, as
    the profiles' jackknife estimates them."""
    edges = np.linspace(0.0, 20.0, N_BINS + 1)
    blocks = rng.normal(0.0, 1.0, (n_blocks, N_BINS))
    prof = {"edges": edges, "y": 0.5 * (edges[1:] + edges[:-1]),
            "temperature": 1.0 + blocks.mean(axis=0),
            "temperature_err": blocks.std(axis=0, ddof=1) / np.sqrt(n_blocks)}
    return Results({"scene_name": "blocked", "engine": "none"}, profiles=prof,
                   profile_attrs={"n_blocks": n_blocks})


def test_estimated_errors_are_judged_with_students_t():
    """Errors estimated from 10 blocks: judged with the normal distribution, a 3σ
    comparison of 40 bins fails far more often than 0.27 %; with Student's t on the blocks'
    degrees of freedom it keeps its rate."""
    rng = np.random.default_rng(4)
    trials = 2000
    fails = sum(not compare_profiles(blocked(rng, 10), blocked(rng, 10),
                                     fields=["temperature"]).ok for _ in range(trials))
    assert fails <= 16, fails  # 0.27 % is 5.4 expected
    as_normal = 0
    for _ in range(trials // 4):
        a, b = blocked(rng, 10), blocked(rng, 10)
        a.profile_attrs.clear()
        b.profile_attrs.clear()  # no block count: errors taken as exact
        as_normal += not compare_profiles(a, b, fields=["temperature"]).ok
    assert as_normal > 5, as_normal  # > 1 %: why the degrees of freedom matter


def test_a_single_bin_off_by_seven_sigma_is_found_and_tabled():
    rng = np.random.default_rng(2)
    a, b = synthetic(rng), synthetic(rng, {("temperature", 12): 0.1})  # 0.1 = 7 × √2 σ
    with pytest.raises(AssertionError) as info:
        assert_profiles_agree(a, b)
    text = str(info.value)
    assert "temperature" in text and "  13 " in text  # 1-based bin number in the table
    assert text.count("\n") < 10  # only the disagreeing rows
    vx = synthetic(rng, {("velocity", 3): np.array([0.1, 0.0])})
    with pytest.raises(AssertionError, match=r"velocity\[x\]"):
        assert_profiles_agree(synthetic(rng), vx)


def test_empty_bins_are_left_out_and_bins_must_match():
    rng = np.random.default_rng(3)
    a, b = synthetic(rng), synthetic(rng)
    a.profiles["temperature"][:5] = np.nan  # empty bins have no temperature
    result = assert_profiles_agree(a, b, fields=["temperature"])
    assert result.skipped == 5 and len(result.rows) == N_BINS - 5
    for res in (a, b):  # a bin empty in both runs: ν = 0 ± 0, nothing to compare
        res.profiles["solid_fraction"][7] = 0.0
        res.profiles["solid_fraction_err"][7] = 0.0
    assert compare_profiles(a, b, fields=["solid_fraction"]).skipped == 1
    b.profiles["solid_fraction"][7] = 0.1  # one run has particles there: a disagreement
    with pytest.raises(AssertionError, match="solid_fraction"):
        assert_profiles_agree(a, b, fields=["solid_fraction"])
    b.profiles["edges"] = b.profiles["edges"] * 1.01
    with pytest.raises(ValueError, match="different bins"):
        compare_profiles(a, b)
    with pytest.raises(ValueError, match="rotational_temperature"):
        compare_profiles(a, a, fields=["rotational_temperature"])


@pytest.mark.slow
def test_soft_and_hard_gas_columns_agree_within_errors(tmp_path):
    """An elastic gas settled under gravity on an elastic floor has the same profiles in
    the hard-particle engine and with stiff soft contacts (dilute: the contacts' duration
    hardly matters); compared with demstudy.testing, as a user's pytest file would."""
    import demstudy as ds

    scene = ds.load_scene("campbell1982/chute-30", gravity={"angle": 0.0},
                          contact={"restitution": 1.0, "tangential": {"model": "smooth"}},
                          walls={0: {"restitution": 1.0, "tangential": {"model": "smooth"}}},
                          initial={"velocity": {"profile": "none", "temperature": 4.0}},
                          run={"equilibration": 20.0, "production": 200.0,
                               "sample_interval": 0.5},
                          soft={"stiffness": 1e6})
    hard = ds.run(scene, "edmd", tmp_path / "hard.h5", progress=False)
    soft = ds.run(scene, "lammps", tmp_path / "soft.h5", progress=False)
    result = assert_profiles_agree(hard, soft, fields=["solid_fraction", "temperature"],
                                   min_solid_fraction=0.02)
    assert len(result.rows) > 20
    # the column is barometric-like: denser at the floor
    nu = hard.profiles["solid_fraction"]
    assert nu[0] > 2 * nu[len(nu) // 2] > 0
    assert math.isfinite(result.worst)
