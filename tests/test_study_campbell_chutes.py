"""The chutes part of ``demstudy study campbell1982``: its cases (unique names, the quick
subset, scenes that validate, the base each statement is tested on) and its analysis on real
short runs (an accelerating bed is judged unsteady, the momentum balance closes at the base,
the verdict logic, "not run" for missing runs).

Dimensionless particle units: d = 1, m = 1, g = 1.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import demstudy as ds
from demstudy.studies import get_study
from demstudy.studies.base import NOT_REPRODUCED, NOT_RUN, REPRODUCED
from demstudy.studies.campbell1982 import chutes
from demstudy.studies.campbell1982.chute_checks import all_checks, c1_converged, c3_accelerates
from demstudy.studies.campbell1982.chute_measure import summarise

QUICK = {"chute-20-flat", "chute-30-bumpy", "chute-40-flat"}
#: groups whose statement is about a steady flow: tested on the bumpy base
STEADY_GROUPS = {"C1", "C4", "C6", "C7", "C8", "width", "tc", "soft"}


def test_case_names_are_unique_and_the_quick_subset_is_the_angle_series():
    full = chutes.cases(False)
    names = [c.name for c in full]
    assert len(set(names)) == len(names)
    assert all("chute" in n for n in names)  # `--only chute` selects them all
    quick = chutes.cases(True)
    assert {c.name for c in quick} == QUICK
    assert all(c.quick for c in quick)
    study = [c.name for c in get_study("campbell1982").cases(False)]
    assert len(set(study)) == len(study)  # unique across the whole study too


def test_every_scene_validates_and_quick_runs_are_shorter():
    for case in chutes.cases(False):
        scene = case.load(False)
        assert scene.gravity.angle in (20.0, 24.0, 26.0, 30.0, 40.0)
        assert "stress" in scene.measure.statistics
        if case.quick:
            q = case.load(True)
            assert (q.run.equilibration + q.run.production
                    < scene.run.equilibration + scene.run.production)


def test_each_statement_uses_the_base_the_study_says():
    by_name = {c.name: c for c in chutes.cases(False)}
    for case in by_name.values():
        base = case.load(False).wall("lower").kind
        if case.group in STEADY_GROUPS:
            assert base == "bumpy", case.name
        if case.name.endswith("-flat"):
            assert base == "flat", case.name
    depth = [by_name[f"chute-30-bumpy-{n}x4-var"].load(False) for n in (5, 10, 13)]
    assert [s.initial.rows for s in depth] == [5, 10, 13]
    assert all(s.contact.law.model == "campbell-exp" for s in depth)
    wide = by_name["chute-30-bumpy-10x8"].load(False)
    assert wide.n_particles == 80 and wide.box.size[0] == pytest.approx(9.6)
    assert by_name["chute-30-bumpy-tc1e-6"].options == {"tc": 1e-6}
    assert by_name["chute-30-bumpy-ew1"].load(False).wall("lower").restitution == 1.0
    assert by_name["chute-30-bumpy-lammps"].engine == "lammps"


@pytest.fixture(scope="module")
def accelerating(tmp_path_factory):
    """Campbell's 40° chute on his flat base, 40 √(d/g): the bed accelerates."""
    path = tmp_path_factory.mktemp("chute") / "chute-40-flat.h5"
    scene = ds.load_scene("campbell1982/chute-40", run={"equilibration": 5.0,
                                                        "production": 35.0},
                          measure={"statistics": ["profiles", "stress"]})
    ds.run(scene, engine="edmd", out=path, progress=False)
    return path


def test_an_accelerating_bed_is_judged_unsteady(accelerating):
    run = summarise("chute-40-flat", accelerating)
    assert run.trend > 0.2 and not run.converged and not run.steady
    assert run.ratio < run.tan_alpha  # the base cannot hold tan 40° of the weight
    assert c3_accelerates({"chute-40-flat": run}).verdict == REPRODUCED


def test_the_momentum_balance_closes_at_the_base(accelerating):
    run = summarise("chute-40-flat", accelerating)
    s, n = run.stress, 40
    width = 4.8
    # the mean normal force of the base carries the weight's normal part, N g cos α / W
    weight = n * math.cos(math.radians(40.0)) / width
    assert s["wall_tau_yy"] == pytest.approx(weight, abs=3 * s["wall_tau_yy_err"] + 0.02 * weight)
    # integrated from the free surface with the unsteady term, the balance meets the wall
    for comp in ("tau_xy", "tau_yy"):
        err = math.hypot(s[f"wall_{comp}_err"], s[f"base_balance_{comp}_err"])
        assert abs(s[f"base_balance_{comp}"] - s[f"wall_{comp}"]) <= 3 * err + 0.02 * weight
    # depth: twice the mass-mean height lies inside the bed's extent
    assert 0.5 * run.depth < np.max(run.profiles["y"][run.profiles["nu"] > 0.3]) + 1.0


def test_the_verdict_follows_both_tests(accelerating):
    run = summarise("chute-40-flat", accelerating)
    steady = dataclasses.replace(run, angle=30.0, trend=0.05, ratio=math.tan(math.radians(30)),
                                 ratio_err=0.003)
    assert steady.steady
    assert c1_converged({"chute-30-bumpy": steady}).verdict == REPRODUCED
    drifting = dataclasses.replace(steady, trend=0.6, ratio=0.50)
    assert c1_converged({"chute-30-bumpy": drifting}).verdict == NOT_REPRODUCED


def test_missing_runs_give_not_run_checks(accelerating, tmp_path):
    empty = chutes.analyse({}, tmp_path, quick=False)
    assert empty.checks and all(c.verdict == NOT_RUN for c in empty.checks)
    assert empty.figures == []
    some = chutes.analyse({"chute-40-flat": accelerating}, tmp_path, quick=True)
    run = [c for c in some.checks if c.verdict != NOT_RUN]
    assert run and all(c.ref.startswith("C3") for c in run)
    assert all(f.path.is_file() for f in some.figures)
    assert len(all_checks({}, False)) == len(empty.checks)


def test_the_slip_is_compared_with_the_fit_at_the_first_strips_height(accelerating):
    """The measured slip is the first strip's u/u_max (disc centres at y ≈ d/2); Campbell's
    fit F(y/H) gives 0.20 at the base plane and 0.32 at y = d/2 in a 12.3 d bed: the row
    compares at the strip's height and shows both."""
    from demstudy.studies.campbell1982.chute_checks import c1_slip, fit_at_first_strip

    run = dataclasses.replace(summarise("chute-40-flat", accelerating), depth=12.28,
                              slip=0.32, slip_err=0.01)
    assert fit_at_first_strip(run) == pytest.approx(0.3233, abs=1e-4)
    assert fit_at_first_strip(dataclasses.replace(run, depth=1e9)) == pytest.approx(0.2018,
                                                                                   abs=1e-4)
    row = c1_slip({"chute-30-bumpy": run})
    assert row.verdict == REPRODUCED and "F(0) = 0.20 at the base plane" in row.measured
    low = c1_slip({"chute-30-bumpy": dataclasses.replace(run, slip=0.20)})
    assert low.verdict == NOT_REPRODUCED  # 0.20 at y = d/2 is below the fit there


def test_own_checks_are_tallied_apart_and_the_soft_rows_name_what_failed(accelerating):
    """The stress-route, TC and soft-contact rows are demstudy's own checks; a soft run that
    is not steady says so by name (the same rule for LAMMPS and LIGGGHTS)."""
    from demstudy.studies.campbell1982.chute_checks import soft_cross_check, tc_independence

    run = dataclasses.replace(summarise("chute-40-flat", accelerating), angle=30.0,
                              trend=0.05, ratio=math.tan(math.radians(30)), ratio_err=0.003)
    drifting = dataclasses.replace(run, trend=0.6, ratio=0.50)
    runs = {"chute-30-bumpy": run, "chute-30-bumpy-liggghts": drifting}
    row = soft_cross_check(runs, "liggghts")
    assert row.own and row.verdict != REPRODUCED
    assert "its base is not balanced (force ratio 0.500" in row.reason
    # a balanced base but a drifting energy: named too, and no agreement
    rising = dataclasses.replace(run, trend=0.9, trend_err=0.01)
    row = soft_cross_check({"chute-30-bumpy": run, "chute-30-bumpy-lammps": rising}, "lammps")
    assert row.verdict != REPRODUCED and "kinetic energy still drifts (trend 0.90" in row.reason
    assert "base is not balanced" not in row.reason
    assert tc_independence({}).own and soft_cross_check({}, "lammps").own
    from demstudy.studies.campbell1982.chute_checks import c1_stresses
    from demstudy.studies.campbell1982.couette_checks import lammps_cross_check

    assert c1_stresses({}).own and lammps_cross_check({}, "a", "b").own


def test_rows_on_a_tc_changed_run_are_weakened_unless_a_small_share_twin_agrees(accelerating):
    """Each chute row names the runs it rests on (the t_c row and the soft cross-checks none:
    the soft engines have no TC model); an agreement resting on a run with a large
    TC-elastic share becomes "partly", unless a twin at another t_c with a small share gives
    the same flow (twins with large shares of their own exempt nothing)."""
    from demstudy.studies.base import PARTLY, tc_caveats
    from demstudy.studies.campbell1982.chute_checks import tc_unchanged

    run = dataclasses.replace(summarise("chute-40-flat", accelerating), angle=30.0,
                              trend=0.05, ratio=math.tan(math.radians(30)), ratio_err=0.003,
                              tc_share=0.12, tc=1e-5)
    shares = {"chute-30-bumpy": (0.12, 1e-5)}
    rows = all_checks({"chute-30-bumpy": run}, False)
    assert rows[0].runs == ("chute-30-bumpy",) and rows[0].verdict == REPRODUCED
    assert all(not r.runs for r in rows if r.ref.startswith(("TC model", "soft-contact")))
    tc_caveats(rows, shares, tc_unchanged({"chute-30-bumpy": run}))
    assert rows[0].verdict == PARTLY and "chute-30-bumpy: 12.0 %" in rows[0].reason
    large = {"chute-30-bumpy": run,
             "chute-30-bumpy-tc1e-4": dataclasses.replace(run, tc=1e-4, tc_share=0.08),
             "chute-30-bumpy-tc1e-6": dataclasses.replace(run, tc=1e-6, tc_share=0.34)}
    assert tc_unchanged(large) == {}  # both twins above 5 %: no reference
    small = dict(large, **{"chute-30-bumpy-tc1e-6": dataclasses.replace(
        run, tc=1e-6, tc_share=0.03)})
    assert "t_c = 1e-06 (3.0 % elastic)" in tc_unchanged(small)["chute-30-bumpy"]
    rows = all_checks(small, False)
    tc_caveats(rows, shares, tc_unchanged(small))
    assert rows[0].verdict == REPRODUCED and "a twin with a small share agrees" in rows[0].reason
    differ = dict(small, **{"chute-30-bumpy-tc1e-6": dataclasses.replace(
        run, tc=1e-6, tc_share=0.03, u_max=3 * run.u_max)})
    assert tc_unchanged(differ) == {}


def test_each_run_has_one_colour_in_a_figure_and_the_reference_is_black(accelerating):
    """The study's figures give a run one colour in all their panels (the reference 30°
    bumpy chute black), and no two runs of one figure share a colour, past ten runs too."""
    from demstudy.studies.campbell1982.chute_figures import run_colours

    run = summarise("chute-40-flat", accelerating)
    runs = [dataclasses.replace(run, name=n) for n in
            ["chute-30-bumpy", *(f"chute-{k}" for k in range(13)), "chute-30-bumpy"]]
    colours = run_colours(runs)
    assert colours["chute-30-bumpy"] == "k" and len(colours) == 14
    assert len({str(c) for n, c in colours.items() if n != "chute-30-bumpy"}) == 13


def _with_angles(run, approach: float):
    """``run`` with a two-level P(θ): ``approach`` of the collisions in 90°-180°."""
    theta = (np.arange(50) + 0.5) * math.pi / 50
    p = np.where(theta > math.pi / 2, 2 * approach, 2 * (1 - approach)) / math.pi
    err = np.full(50, 0.01)
    from demstudy.studies.campbell1982.collision_log import approach_share

    return dataclasses.replace(run, angles={"theta": theta, "p": p, "p_err": err,
                                            "collisions": 1e4,
                                            "approach": approach_share(p, err, theta),
                                            "window": (50.0, 99.0, 50.0, 400.0),
                                            "halves": (approach, approach)})


def test_the_chutes_collision_angles_row_wants_the_approach_quadrant(accelerating):
    """C9 (Fig 3.33): the 40° beds' share of collisions in 90°-180° beyond ½ + 2σ; an
    isotropic distribution is not the thesis's; without a collision log the row is not run."""
    from demstudy.studies.campbell1982.chute_checks import c9_angles

    run = summarise("chute-40-flat", accelerating)
    assert run.angles == {}  # the fixture kept no collision log
    assert c9_angles({"chute-40-flat": run}).verdict == NOT_RUN
    row = c9_angles({"chute-40-flat": _with_angles(run, 0.75)})
    assert row.verdict == REPRODUCED and "share in 90°-180° 0.750" in row.measured
    assert "logged over t = 50-99 of the production 50-400" in row.measured
    assert "the log of chute-40-flat covers only the start of the production" in row.reason
    assert c9_angles({"chute-40-flat": _with_angles(run, 0.5)}).verdict == NOT_REPRODUCED


def test_the_angle_distribution_is_read_from_a_run_with_a_collision_log(tmp_path):
    """A short 40° run with the angles statistic: P(θ) normalised over 0-180°, the pooled
    share between 0 and 1, and the collision count of the log."""
    from demstudy.studies.campbell1982.chute_cases import MEASURE_ANGLES

    path = tmp_path / "c9.h5"
    scene = ds.load_scene("campbell1982/chute-40", run={"equilibration": 2.0,
                                                        "production": 10.0},
                          measure=MEASURE_ANGLES)
    ds.run(scene, engine="edmd", out=path, progress=False)
    a = summarise("chute-40-flat", path).angles
    width = math.pi / a["theta"].size
    assert np.sum(a["p"]) * width == pytest.approx(1.0, rel=1e-6)
    assert 0.0 < a["approach"][0] < 1.0 and a["collisions"] > 100
    t0, t1, start, end = a["window"]
    assert start == pytest.approx(2.0) and end == pytest.approx(12.0)
    assert start <= t0 < t1 <= end  # a short run: the log spans its production
    assert all(0.0 < h < 1.0 for h in a["halves"])


def test_local_bagnold_coefficients_of_a_uniform_shear(accelerating):
    """f = τ/(ρ_p R² (du/dy)²) strip by strip: a linear u and a known τ give f exactly; the
    base's strip, dilute strips and strips without resolved shear are left out."""
    from demstudy.analysis.derived import MATERIAL_DENSITY
    from demstudy.studies.campbell1982.chute_measure import local_bagnold

    run = summarise("chute-40-flat", accelerating)
    y = np.arange(8) + 0.5
    nu = np.array([0.5, 0.6, 0.6, 0.6, 0.6, 0.6, 0.1, 0.6])
    prof = {**run.profiles, "y": y, "nu": nu, "nu_err": 0 * y, "u": 2.0 * y,
            "u_err": np.full(8, 0.01)}
    tau = 3.0 * np.ones(8)
    stress = {"balance_tau_xy": tau, "balance_tau_xy_err": 0 * tau,
              "balance_tau_yy": 2 * tau, "balance_tau_yy_err": 0 * tau}
    out = local_bagnold(dataclasses.replace(run, profiles=prof, stress=stress))
    rho, radius = MATERIAL_DENSITY[2], 0.5
    assert list(out["y"]) == [1.5, 2.5, 3.5, 4.5, 5.5, 7.5]  # not the base, not ν = 0.1
    assert out["f_s"] == pytest.approx(3.0 / (rho * radius**2 * 4.0))
    assert out["f_N"] == pytest.approx(2 * out["f_s"])
    flat = {**prof, "u": np.ones(8)}
    assert local_bagnold(dataclasses.replace(run, profiles=flat, stress=stress))["nu"].size == 0


def test_the_approach_quadrant_is_where_a_positive_shear_brings_discs_together():
    """θ = atan2(n_y, n_x) mod π from the flow direction x (downslope; u grows with y): a
    collision whose line of centres points up-and-back (n = (−1, 1)/√2, θ = 135°) is an
    approach one, (1, 1)/√2 (θ = 45°) a recession one; wall collisions and the settling
    before ``start`` do not count."""
    from demstudy.studies.campbell1982.chute_measure import _approach_halves

    r = 1 / math.sqrt(2)
    log = {"time": np.array([0.5, 1.0, 2.0, 3.0, 4.0, 5.0]),
           "kind": np.array([0, 0, 0, 1, 0, 0]),
           "normal": np.array([[r, r], [-r, r], [-r, r], [-r, r], [r, r], [r, -r]])}
    # from t = 1: first half (t ≤ 3) two pairs, both approach; second half (4, 5): (1,1) is 45°,
    # (1,-1) is 135° mod π, approach
    assert _approach_halves(log, 1.0) == (1.0, 0.5)


def test_campbells_2d_to_3d_conversion_keeps_the_mean_spacing(accelerating):
    """ν_3D = (4/(3√π)) ν^{3/2} (equal mean spacing): the square packing π/4 maps onto the
    cubic π/6 exactly; a bed below the 3D dense range is the thesis's "probably too small"."""
    from demstudy.studies.campbell1982.chute_checks import c8_conversion, nu_3d

    assert nu_3d(math.pi / 4) == pytest.approx(math.pi / 6)
    run = summarise("chute-40-flat", accelerating)
    bed = dataclasses.replace(run, profiles={**run.profiles, "nu": np.array([0.3, 0.68, 0.6])})
    row = c8_conversion({"chute-30-bumpy": bed})
    assert row.verdict == REPRODUCED and "ν = 0.680 → ν_3D = 0.422" in row.measured
    dense = dataclasses.replace(run, profiles={**run.profiles, "nu": np.array([0.85])})
    assert c8_conversion({"chute-30-bumpy": dense}).verdict == NOT_REPRODUCED
    assert c8_conversion({}).verdict == NOT_RUN


def test_the_reference_chutes_twins_are_quoted_when_their_shares_are_large(accelerating):
    """tc_quoted: both t_c twins of the 30° bumpy chute with shares above 5 % give the same
    flow: quoted in its rows, not an exemption; a small-share twin leaves it to tc_unchanged."""
    from demstudy.studies.campbell1982.chute_checks import tc_quoted

    run = dataclasses.replace(summarise("chute-40-flat", accelerating), name="chute-30-bumpy",
                              tc=1e-5, tc_share=0.116)
    runs = {"chute-30-bumpy": run,
            "chute-30-bumpy-tc1e-4": dataclasses.replace(run, tc=1e-4, tc_share=0.079),
            "chute-30-bumpy-tc1e-6": dataclasses.replace(run, tc=1e-6, tc_share=0.335)}
    quoted = tc_quoted(runs)["chute-30-bumpy"]
    assert quoted.startswith("the twins of chute-30-bumpy at t_c = 0.0001 (7.9 %) and 1e-06 "
                             "(33.5 %) √(d/g) give the same u_max, KE/N and H within 2σ + 10 %")
    runs["chute-30-bumpy-tc1e-6"] = dataclasses.replace(run, tc=1e-6, tc_share=0.02)
    assert tc_quoted(runs) == {}
