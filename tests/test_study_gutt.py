"""``demstudy study gutt1989`` (Gutt 1989): the study is registered with its parts, the theory
part's checks reach the verdicts the computed numbers give, and the Couette part's
measurements recover known values from synthetic collision logs and profiles and the physics
of a tiny real run (wall shear = bulk shear stress; a frictionless flat wall passes none).

Units: Ch. 1 arbitrary (d = 1); otherwise dimensionless particle units d = 1, m = 1, no
gravity, the wall speed u_w = 1 sets the time scale.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

import demstudy as ds
from demstudy import studies
from demstudy.scene import load_scene
from demstudy.studies.base import NOT_REPRODUCED, NOT_RUN, PARTLY, REPRODUCED
from demstudy.studies.gutt1989 import (
    PARTS,
    STUDY,
    couette,
    couette_cases,
    lgd,
    lgd_theory,
    theory,
)
from demstudy.studies.gutt1989.couette_measure import (
    fit_curvature,
    layer_mean,
    roughness,
    summarise,
)
from demstudy.studies.gutt1989.couette_measure import theory as couette_theory


def test_registered_with_theory_and_couette_parts():
    assert "gutt1989" in studies.study_names()
    assert studies.get_study("gutt1989") is STUDY
    # the lgd part: tests/test_study_gutt_lgd.py; lgd_theory: tests/test_gutt1989_lgd_theory.py
    assert PARTS == (theory, couette, lgd, lgd_theory)
    assert theory.cases(False) == [] and theory.cases(True) == []
    full, quick = couette.cases(False), couette.cases(True)
    assert {c.name for c in quick} < {c.name for c in full}
    for case in full:
        scene = case.load()
        dim = scene.dimension
        assert scene.gravity is None and scene.contact.tangential.model == "smooth"
        assert [w.velocity for w in scene.walls] == [-1.0, 1.0]
        assert all(w.tangential.model == "smooth" for w in scene.walls)
        gap = scene.wall_position("upper") - scene.wall_position("lower")
        assert gap == 10.0
        # Gutt's inventory: the grains packed at close packing fill h − Δh = 6.75 d
        packed = {2: 2 / math.sqrt(3), 3: math.sqrt(2)}[dim]
        area = scene.box.size[0] * (scene.box.size[2] if dim == 3 else 1.0)
        assert scene.particles.count / (packed * area) == pytest.approx(6.75, abs=0.01)
        assert scene.walls[0].restitution in couette_cases.E_WALLS


def test_theory_checks_reach_the_verdicts_of_their_numbers():
    checks = theory.checks()
    assert len(checks) == 16
    allowed = {REPRODUCED, PARTLY, NOT_REPRODUCED}
    assert all(c.verdict in allowed and c.measured for c in checks)
    # a check short of reproduced says why
    assert all(c.reason for c in checks if c.verdict != REPRODUCED)
    # fig 2.11: recompute the verdict from its printed numbers ("+39 %/+66 %": change of
    # v(h/2)/change of u_s): all rises → at least partly; "modest" = every v(h/2) change < 50 %
    (fig211,) = [c for c in checks if "fig 2.11" in c.ref]
    pairs = [(float(a), float(b)) for a, b in
             re.findall(r"([+-]\d+) %/([+-]\d+) %", fig211.measured)]
    assert len(pairs) == 9
    rises = all(a > 0 and b > 0 for a, b in pairs)
    modest = all(abs(a) < 50 for a, _ in pairs)
    assert fig211.verdict == (REPRODUCED if rises and modest else PARTLY if rises
                              else NOT_REPRODUCED)
    # every Ch. 1 check says its constants are assumed or that it holds for any constants
    for c in checks[:8]:
        assert "assumed" in c.reason or "any constants" in c.reason or "constant sets" in \
            c.measured


def _synthetic(dim: int, geometry: str, **values: float) -> dict[str, couette.CouetteRun]:
    """One made-up rough-wall run at e_w = 0.84, keyed by its case name as the checks pick."""
    run = couette.CouetteRun(couette_cases.case_name(dim, geometry, 0.84), dim, 0.84, 1.0, 10.0)
    run.values.update({k: (v, 0.001) for k, v in values.items()})
    return {run.name: run}


def test_couette_verdicts_follow_their_numbers():
    tags = {"t_fit": 1.1, "q_fit": 0.24, "gamma_fit": 0.15, "t_fit_spread": 0.05,
            "q_fit_spread": 0.05, "k2": 0.2}
    good = _synthetic(3, "b1s15", **tags)
    assert couette.tags(good).verdict == REPRODUCED
    spread = _synthetic(3, "b1s15", **{**tags, "t_fit_spread": 0.4})
    assert couette.tags(spread).verdict == PARTLY and "vary across" in couette.tags(spread).reason
    far = _synthetic(3, "b1s15", **{**tags, "t_fit": 0.2, "q_fit": 2.0, "gamma_fit": 0.01,
                                    "t_fit_spread": 0.4})
    assert couette.tags(far).verdict == NOT_REPRODUCED
    # isotropy: ×1.05 reproduced, ×1.3 partly, ×2 not; in 2D nothing is said of ⟨k_z²⟩
    for aniso, verdict in ((1.05, REPRODUCED), (1.3, PARTLY), (2.0, NOT_REPRODUCED)):
        c = couette.isotropy(_synthetic(2, "b1s15", k2=0.2, anisotropy=aniso))
        assert c.verdict == verdict and "k_z" not in c.reason
    c = couette.isotropy(_synthetic(3, "b1s15", k2=0.2, k2_z=0.3, anisotropy=1.0))
    assert c.verdict == PARTLY and "⟨k_z²⟩/⟨k_x²⟩ 1.50" in c.reason
    # density: a uniform bulk with wall layers like it is reproduced; layering is not
    dens = {"k2": 0.2, "phi_bulk": 0.7, "phi_bulk_ptp": 0.02, "phi_wall_layer": 0.68}
    assert couette.density(_synthetic(2, "b1s15", **dens)).verdict == REPRODUCED
    layered = couette.density(_synthetic(2, "b1s15", **{**dens, "phi_wall_layer": 0.4,
                                                        "phi_bulk_ptp": 0.2}))
    assert layered.verdict == NOT_REPRODUCED and "0.70-0.70" in layered.reason


def test_a_wrong_sign_of_omega2_is_not_reproduced():
    runs = _synthetic(3, "b1s15", k2=0.25, R=0.2)
    (run,) = runs.values()
    sol = couette_theory(run, n=2)
    run.values["omega2"] = (math.copysign(0.01, sol.omega2), 0.001)
    assert couette.regimes(runs).verdict == REPRODUCED
    run.values["omega2"] = (-math.copysign(0.01, sol.omega2), 0.001)
    c = couette.regimes(runs)
    assert c.verdict == NOT_REPRODUCED and "3D ⟨k_τ²⟩ 0.250" in c.reason


def test_roughness_of_a_synthetic_collision_log():
    rng = np.random.default_rng(3)
    m = 20000
    # wall hits with normals uniform on the half circle: <k_x^2> = 1/2; a quarter on the plane
    theta = rng.uniform(-math.pi / 2, math.pi / 2, m)
    normal = np.stack([np.sin(theta), -np.cos(theta)], axis=1)
    plane = rng.random(m) < 0.25
    normal[plane] = (0.0, -1.0)
    kind = np.where(rng.random(m) < 0.5, 1, 2)
    # pair collisions (kind 0) along x must not count
    kind = np.concatenate([kind, np.zeros(5000, int)])
    normal = np.concatenate([normal, np.tile([1.0, 0.0], (5000, 1))])
    time = rng.random(kind.size)
    out = roughness(kind, normal, time)
    k2, err = out["k2"]
    assert k2 == pytest.approx(0.75 * 0.5, abs=4 * err) and 0 < err < 0.01
    assert out["plane_share"][0] == pytest.approx(0.25, abs=0.02)
    assert out["wall_collisions_logged"][0] == m
    with pytest.raises(ValueError, match="normal"):
        roughness(kind, normal[:10], time)


def test_layer_mean_and_curvature_fit():
    y = np.linspace(-4.75, 4.75, 20)
    weight = np.where(np.abs(y) > 4, 2.0, 1.0)
    value, err = y**2, np.full(y.size, 0.1)
    mean, e = layer_mean(y, weight, value, err, y > 4)
    # the two bins above y = 4 (4.25, 4.75), equal weights: independent errors add as 1/√2
    assert mean == pytest.approx((4.25**2 + 4.75**2) / 2) and e == pytest.approx(0.1 / 2**0.5)
    for w in (0.02, -0.03, 0.0):
        v = 0.3 * (np.cos(math.sqrt(w) * y) if w > 0 else np.cosh(math.sqrt(-w) * y))
        got, got_err, v_c = fit_curvature(y, v, np.full(y.size, 1e-4))
        assert got == pytest.approx(w, abs=max(5 * got_err, 1e-6)) and v_c == pytest.approx(0.3)


def _tiny(geometry: str, tmp_path) -> couette.CouetteRun:
    case = couette_cases.couette_case(2, geometry, 0.84)
    scene = load_scene(case.scene, **{**case.sections,
                                      "run": {"equilibration": 20.0, "production": 40.0,
                                              "sample_interval": 1.0}})
    path = tmp_path / f"{geometry}.h5"
    ds.run(scene, engine="edmd", out=path, progress=False, **case.options)
    return summarise(case.name, path)


def test_tiny_runs_wall_shear_is_the_bulk_shear_and_a_flat_wall_passes_none(tmp_path):
    rough = _tiny("b1s15", tmp_path)
    # momentum balance: the walls' shear stress is the bulk's −P_xy (Gutt's constant σ0)
    res = ds.load(tmp_path / "b1s15.h5")
    total = np.asarray(res.groups["stress"]["total"], float)[:, 0, 1]
    err = np.asarray(res.groups["stress"]["total_err"], float)[:, 0, 1]
    bulk = rough.arrays["bulk"]
    inner = -np.average(total[bulk], weights=1 / err[bulk] ** 2)
    assert inner == pytest.approx(rough.v("sigma0"), rel=0.1)
    assert 0.05 < rough.v("k2") < 0.5 and rough.v("plane_share") == 0.0  # touching bumps
    assert 0 < rough.v("R") < 1 and 0 < rough.v("slip") < 1 and rough.v("v_wall") > 0
    sol = couette_theory(rough)
    assert sol is not None and sol.constants.k2 == rough.v("k2")
    flat = _tiny("flat", tmp_path)
    assert flat.v("k2") == 0.0 and flat.v("plane_share") == 1.0
    assert flat.v("sigma0") == 0.0  # a frictionless plane: no tangential impulse at all
    assert couette_theory(flat) is None
    assert flat.v("ke_end_over_start") < rough.v("ke_end_over_start")


def test_couette_checks_without_runs_say_not_run(tmp_path):
    ana = couette.analyse({}, tmp_path, quick=True)
    assert ana.checks and all(c.verdict == NOT_RUN for c in ana.checks)
    assert not ana.figures
