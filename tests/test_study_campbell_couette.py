"""The Couette part of the Campbell (1982) study: its cases, the analytic pieces its checks
rest on (cubic-spline f_s, Savage-Jeffrey's normalisation), the verdicts on a real short run,
and "not run" checks when runs are missing.

Dimensionless particle units: d = 1, m = 1; no gravity: the upper wall's speed U_T sets the
time scale.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad

from demstudy.analysis import derived as dv
from demstudy.studies.base import NOT_REPRODUCED, NOT_RUN, PARTLY, REPRODUCED, VERDICTS
from demstudy.studies.campbell1982 import couette
from demstudy.studies.campbell1982 import couette_checks as ck
from demstudy.studies.campbell1982.couette_cases import _run, fixed_case, nu_tag, spacing_for
from demstudy.studies.campbell1982.couette_measure import LISTING_FACTOR, RunSummary
from demstudy.theory import savage_jeffrey


# ------------------------------------------------------------------ cases
def test_case_names_are_unique_and_prefixed() -> None:
    names = [c.name for c in couette.cases(False)]
    assert len(names) == len(set(names))
    assert all(n.startswith("couette-") for n in names)


def test_quick_cases_are_a_short_subset() -> None:
    full = {c.name: c for c in couette.cases(False)}
    quick = couette.cases(True)
    assert quick and set(c.name for c in quick) < set(full)
    for case in quick:
        short, long = case.load(True), case.load(False)
        assert short.run.production < long.run.production


@pytest.mark.parametrize("quick", [True, False])
def test_every_scene_validates(quick: bool) -> None:
    for case in couette.cases(quick):
        scene = case.load(quick)  # raises SceneError if invalid
        assert scene.dimension == 2 and scene.contact.law.model == "constant"


@pytest.mark.parametrize("nu", [0.35, 0.55, 0.75])
def test_fixed_gap_lattice_sets_the_solid_fraction(nu: float) -> None:
    scene = fixed_case("t", nu).load()
    n = scene.initial.rows * scene.initial.columns
    gap = scene.wall_position("upper") - scene.wall_position("lower")
    assert n * math.pi / 4 / (gap * scene.box.size[0]) == pytest.approx(nu, rel=1e-12)
    assert scene.walls[0].servo is None and scene.walls[1].servo is None


def test_spacing_refuses_impossible_solid_fraction() -> None:
    with pytest.raises(ValueError, match="nu = 0.8"):
        spacing_for(0.8)


def test_servo_cases_hold_campbells_stress_scaling() -> None:
    """σ_n = factor × 0.567 m γ̇² with γ̇ = U_T/12 (Campbell's 0.567 (R/H)²)."""
    for case in couette.cases(False):
        scene = case.load()
        upper = scene.wall("upper")
        if upper.servo is None:
            continue
        # "...-servo-s<factor>[-lammps]"; the K3 rate series runs at factor 1
        factor = (float(case.name.split("-servo-s")[1].split("-")[0])
                  if "-servo-s" in case.name else 1.0)
        assert upper.servo.normal_stress == pytest.approx(
            factor * 0.567 * (upper.velocity / 12.0) ** 2, rel=1e-12)


# ------------------------------------------------------------------ analytic pieces
def _profiles(y: np.ndarray, u: np.ndarray) -> dict:
    n = y.size
    return {"y": y, "velocity": np.stack([u, np.zeros(n)], axis=1),
            "velocity_err": np.zeros((n, 2)), "solid_fraction": np.full(n, 0.5),
            "temperature_components": np.ones((n, 2)), "mean_mass": np.ones(n)}


def test_spline_bagnold_coefficient_on_a_cubic_profile() -> None:
    """u = a y + b (y − H/2)³ is a cubic: the not-a-knot spline's derivative is exact, so
    f_s = τ/(ρ_p R² (du/dy)²) matches the analytic value; the listing's f is f/π."""
    h, a, b, tau = 10.0, 0.1, 2e-4, 0.013
    y = np.arange(0.5, h, 1.0)
    du = a + 3 * b * (y - h / 2) ** 2
    rate, rate_err = dv.shear_rate(_profiles(y, a * y + b * (y - h / 2) ** 3))
    np.testing.assert_allclose(rate, du, rtol=1e-10)
    f, _ = dv.bagnold_coefficients(np.full(y.size, tau), rate, 2, "campbell")
    rho_p = 4 / math.pi  # m / (π R²) with R = 1/2
    np.testing.assert_allclose(f, tau / (rho_p * 0.25 * du**2), rtol=1e-9)
    listing, _ = dv.bagnold_coefficients(np.full(y.size, tau), rate, 2, "listing")
    np.testing.assert_allclose(listing, f * LISTING_FACTOR, rtol=1e-12)


@pytest.mark.parametrize("s", [0.0, 0.7, 1.5, 4.0, 9.0])
def test_savage_jeffrey_is_normalised_on_zero_to_pi(s: float) -> None:
    total, _ = quad(lambda t: float(savage_jeffrey(t, s)), 0.0, math.pi, limit=200)
    assert total == pytest.approx(1.0, abs=1e-8)
    corrected, _ = quad(lambda t: float(savage_jeffrey(t, s, nu=0.4, length="C")), 0.0,
                        math.pi, limit=200)
    assert corrected == pytest.approx(1.0, abs=1e-8)


def test_savage_jeffrey_prefers_the_approach_quadrant() -> None:
    """For S > 0 (du/dy > 0) P(θ) is larger on 90°-180° than on 0°-90°, by symmetry
    θ → π − θ the two halves swap."""
    share, _ = quad(lambda t: float(savage_jeffrey(t, 1.5)), math.pi / 2, math.pi)
    assert share > 0.6


# ------------------------------------------------------------------ verdict logic
def test_trend_verdicts() -> None:
    assert ck.trend_verdict([(1.0, 0.1), (2.0, 0.1), (3.0, 0.1)])[0] == REPRODUCED
    assert ck.trend_verdict([(1.0, 0.5), (1.2, 0.5), (1.4, 0.5)])[0] == PARTLY
    # the weakest step by name, in σ, and the longer runs that would resolve a step that size
    why = ck.trend_verdict([(1.0, 0.1), (2.0, 0.1), (2.1, 0.1)])[1]
    assert "point 2 → 3 by 0.7σ (2σ in runs ×8.0 longer)" in why and "1 → 2" not in why
    assert ck.trend_verdict([(1.0, 0.1), (0.5, 0.1)])[0] == NOT_REPRODUCED


def _cell(name: str, s: float, plug: bool) -> RunSummary:
    """A fixed-gap cell's summary: S and a u/U_T profile over y/H, uniform shear or a plug
    (flat centre, dilute wall bins)."""
    y = np.linspace(0.05, 0.95, 10)
    u = np.clip((y - 0.5) * 4, -0.5, 0.5) if plug else y - 0.5
    u = np.where(np.abs(y - 0.5) < 0.2, 0.0, u) if plug else u
    nu = np.full(10, 0.75)
    if plug:
        nu[[0, -1]] = 0.5
    return RunSummary(name, values={"S_text": (s, 0.05), "nu": (0.75, 0.001)},
                      arrays={"u_over_ut": u, "y_over_h": y, "nu": nu,
                              "centre": np.abs(y - 0.5) < 0.25})


def test_the_larger_cell_stands_in_for_the_layered_dense_one() -> None:
    """S(ν) and the plug: the 10 × 4 cell at ν = 0.75 keeps its start lattice; where the
    20 × 8 cell in its place gives the thesis's trend or plug the row is "partly" and says so,
    where it does not either the row stays "not reproduced"; without it nothing changes."""
    names, nus = ["a", "b", "c"], [0.35, 0.55, 0.75]
    runs = {"a": _cell("a", 1.2, False), "b": _cell("b", 1.1, False),
            "c": _cell("c", 0.9, False)}
    assert ck.s_trend(runs, names, nus).verdict == NOT_REPRODUCED
    assert ck.s_trend(runs, names, nus, "big").verdict == NOT_REPRODUCED  # absent
    runs["big"] = _cell("big", 0.5, False)
    low = ck.s_trend(runs, names, nus, "big")
    assert low.verdict == NOT_REPRODUCED and "not rising either" in low.reason
    runs["a"] = _cell("a", 1.0, False)
    runs["big"] = _cell("big", 3.0, False)
    up = ck.s_trend(runs, names, nus, "big")
    assert up.verdict == PARTLY and "20 × 8 cell at ν = 0.75: 3.000 ± 0.050" in up.measured
    plug = ck.plug(runs, "c", 0.75, "big")
    assert plug.verdict == NOT_REPRODUCED and "shears through too" in plug.reason
    runs["big"] = _cell("big", 3.0, True)
    plug = ck.plug(runs, "c", 0.75, "big")
    assert plug.verdict == PARTLY and "the 20 × 8 cell at the same ν forms the plug" in plug.reason
    runs["c"] = _cell("c", 0.9, True)
    assert ck.plug(runs, "c", 0.75, "big").verdict == REPRODUCED


def test_missing_runs_give_not_run_checks(tmp_path: Path) -> None:
    ana = couette.analyse({}, tmp_path, quick=False)
    assert ana.checks and all(c.verdict == NOT_RUN for c in ana.checks)
    assert all("not in this run of the study" in c.reason for c in ana.checks)


@pytest.fixture(scope="module")
def short_runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Two short fixed-gap cells (ν = 0.35 and 0.65), about a second each."""
    from demstudy.api import run
    from demstudy.scene import load_scene
    from demstudy.studies.base import merge

    out = tmp_path_factory.mktemp("couette")
    runs = {}
    for nu in (0.35, 0.65):
        name = f"couette-fixed-nu{nu_tag(nu)}"
        base = fixed_case(name, nu)
        gap = base.load().wall_position("upper")
        # 30 + 60 strain units, 6 frames per strain unit
        scene = load_scene(base.scene, **merge(base.sections,
                                               {"run": _run(gap, 1.0, 30.0, 60.0, 6.0)}))
        runs[name] = out / f"{name}.h5"
        run(scene, engine="edmd", out=runs[name], progress=False)
    return runs


def test_verdicts_on_a_real_short_run(short_runs: dict[str, Path], tmp_path: Path) -> None:
    ana = couette.analyse(short_runs, tmp_path, quick=True)
    by_ref = {c.statement: c for c in ana.checks}
    assert all(c.verdict in VERDICTS for c in ana.checks)
    # the checks that need only the two fixed-gap runs ran; the others say not run
    ran = [c for c in ana.checks if c.verdict != NOT_RUN]
    assert len(ran) >= 8
    for c in ana.checks:
        if c.verdict != NOT_RUN:
            assert c.measured != "n/a"
        if c.verdict != REPRODUCED and c.verdict != NOT_RUN:
            assert c.reason, c.statement
    # physics: sheared discs collide mostly from the approach quadrant (beyond 2σ)
    approach = next(c for s, c in by_ref.items() if "approach quadrant" in s)
    assert approach.verdict == REPRODUCED
    # the equation of state: χ/ν grows with ν (dense-gas collisional pressure), a trend
    # far beyond the errors of even a short run
    chi = next(c for s, c in by_ref.items() if "equation of state" in s)
    assert chi.verdict in (REPRODUCED, PARTLY), chi.measured
    assert ana.figures and all(f.path.is_file() for f in ana.figures)


def _history(name: str, trend: float, within: float, drift: float = 0.0,
             thermal: float = 0.0) -> RunSummary:
    return RunSummary(name, values={"ke_trend": (trend, 0.02), "ke_within": (within, 0.0),
                                    "gap_drift": (drift, 0.0),
                                    "dissipation_trend": (thermal, 0.05)})


def test_campbells_convergence_criterion_for_the_cells_energy() -> None:
    """K7 (Fig 2.4), the chutes' rule: no trend beyond 20 % (2σ) in the kinetic energy and
    in the dissipation rate (the mean flow steadies the energy); the ±20 % band is reported,
    not required; a servo cell still moving its walls is named."""
    steady = {"a": _history("a", 0.05, 1.0), "b": _history("b", -0.1, 0.95)}
    row = ck.energy_history(steady, ["a", "b"], ["ν = 0.35", "ν = 0.45"])
    assert row.verdict == REPRODUCED and "ν = 0.35: KE trend 0.050 ± 0.020" in row.measured
    assert "dissipation-rate trend 0.000 ± 0.050" in row.measured
    assert ck.ke_converged(_history("x", 0.22, 1.0)) == (True, True)  # 0.22 − 2σ < 0.2
    assert ck.ke_converged(_history("x", 0.25, 1.0)) == (False, True)
    assert ck.ke_converged(_history("x", 0.0, 1.0, thermal=0.4)) == (True, False)
    mixed = {**steady, "c": _history("c", 0.46, 0.88, drift=0.25),
             "d": _history("d", -0.1, 0.5), "e": _history("e", 0.0, 1.0, thermal=0.5)}
    row = ck.energy_history(mixed, ["a", "c", "d", "e"],
                            ["ν = 0.35", "K2 σ_n×0.5", "K1 σ_n×1", "ν = 0.65"])
    assert row.verdict == PARTLY
    assert "not met: K2 σ_n×0.5 (KE trend), ν = 0.65 (dissipation trend)" in row.reason
    assert "K1 σ_n×1 (" not in row.reason.split("not met")[1].split(";")[0]  # band only
    assert "K2 σ_n×0.5 (gap +25 % over the production)" in row.reason
    assert "leaves the ±20 % band in K2 σ_n×0.5 (12 % of the samples), K1 σ_n×1 (50 %" in \
        row.reason
    row = ck.energy_history({"d": _history("d", 0.6, 0.5)}, ["d"], ["ν = 0.55"])
    assert row.verdict == NOT_REPRODUCED and "slips as a block" not in row.reason


def test_a_servo_cell_still_moving_its_walls_weakens_the_density_row() -> None:
    def cell(nu: float, drift: float) -> RunSummary:
        return RunSummary("x", values={"nu_cell": (nu, 0.001), "gap_drift": (drift, 0.0)})

    runs = {"a": cell(0.4, 0.0), "b": cell(0.5, 0.01), "c": cell(0.6, -0.02)}
    names = ["a", "b", "c"]
    assert ck.servo_density(runs, "K2", names, (0.5, 1, 2), "Fig 3.16",
                            "no-slip").verdict == REPRODUCED
    runs["a"] = cell(0.4, 0.25)
    row = ck.servo_density(runs, "K2", names, (0.5, 1, 2), "Fig 3.16", "no-slip")
    assert row.verdict == PARTLY and "σ_n×0.5 (gap +25 % over the production)" in row.reason


def test_a_tc_twin_exempts_its_cell_only_with_a_small_share() -> None:
    """couette.tc_twins: the same values from a twin below the warning level exempt the cell;
    from a twin with a large share they are only quoted; other values are quoted as such."""
    values = {"nu": (0.66, 0.005), "S_text": (1.15, 0.04), "f_s": (6.7, 0.7)}

    def run(share: float, **change: tuple[float, float]) -> RunSummary:
        return RunSummary("x", values={**values, **change},
                          attrs={"tc_elastic_fraction": share, "tc": 1e-6})

    base, twin = "couette-fixed-nu65", couette.TC_TWINS["couette-fixed-nu65"]
    unchanged, told = couette.tc_twins({base: run(0.06), twin: run(0.02)})
    assert base in unchanged and not told and "the same values" in unchanged[base]
    unchanged, told = couette.tc_twins({base: run(0.06), twin: run(0.066)})
    assert not unchanged and "no run free of the model" in told[base]
    unchanged, told = couette.tc_twins({base: run(0.06), twin: run(0.02, S_text=(2.0, 0.04))})
    assert not unchanged and told[base].endswith("gives other values (S +74 %)")
    assert couette.tc_twins({base: run(0.06)}) == ({}, {})


def test_chute_strips_are_compared_with_the_cells_f_curve() -> None:
    """Figs 3.21-3.24: strips on the cells' log-linear f(ν) within 2σ + 20 % count; a strip
    ×3 off does not; strips outside the cells' ν range are not compared; the layered ν = 0.75
    cell is not part of the curve."""
    def cell(nu: float, f: float) -> RunSummary:
        return RunSummary(f"c{nu}", values={"nu": (nu, 0.001), "f_s": (f, 0.01 * f),
                                            "f_N": (2 * f, 0.02 * f)})

    runs = {"a": cell(0.35, 1.0), "b": cell(0.55, 4.0), "c": cell(0.75, 0.5)}
    names = ["a", "b", "c"]
    curve, _ = ck.couette_curve([runs["a"], runs["b"]], "f_s", np.array([0.45, 0.3]))
    assert curve[0] == pytest.approx(2.0) and np.isnan(curve[1])  # geometric mean; outside
    strips = {"nu": np.array([0.45, 0.5, 0.7]), "f_s": np.array([2.1, 2.8, 99.0]),
              "f_s_err": np.full(3, 0.05), "f_N": np.array([4.0, 5.7, 99.0]),
              "f_N_err": np.full(3, 0.05)}
    row = ck.chute_on_curve(runs, names, {"chute-30-bumpy": strips})
    assert row.verdict == REPRODUCED and "(0 strip values are)" in row.reason
    assert "ν 0.70" not in row.measured and row.runs[-1] == "chute-30-bumpy"
    assert "1 of the 3 strips lie beyond the cells' ν range" in row.reason
    assert "f_s: ν 0.45: 2.100 ± 0.050 (curve 2, ×1.05)" in row.measured
    off = {**strips, "f_s": np.array([6.3, 2.8, 99.0])}
    row = ck.chute_on_curve(runs, names, {"chute-30-bumpy": off})
    assert row.verdict == PARTLY and "(1 strip value is)" in row.reason
    assert "×3.15" in row.measured
    assert ck.chute_on_curve(runs, names, {}).verdict == NOT_RUN


def test_the_angle_rows_say_how_much_of_the_production_the_log_spans() -> None:
    from demstudy.studies.campbell1982.collision_log import logged_fraction

    assert logged_fraction((50.0, 99.0, 50.0, 400.0)) == pytest.approx(49 / 350)
    runs = {n: RunSummary(n, values={"approach_share": (0.8, 0.01)},
                          attrs={"log_window": (100.0, 100.0 + span, 100.0, 1100.0)})
            for n, span in (("a", 300.0), ("b", 1000.0))}
    row = ck.angles_approach(runs, ["a", "b"], [0.35, 0.45])
    assert row.verdict == REPRODUCED and "spans the first 30-100 % of each production" in \
        row.measured
