"""The LGD part of ``demstudy study gutt1989`` (Gutt 1989, Ch. 3): its cases are the thesis's
scenes on the lattice engine at his step counts, and each measurement recovers known values
from synthetic data and fails for inputs that break the thesis's statement (a non-Maxwellian
gas, a quadratic discharge, a square front, a moving cap); a tiny real run balances its
momentum exactly against the wall impulses.

Dimensionless particle units: d = 1 (lattice spacing), m = 1; g = 1 with gravity, otherwise
the scene's speed unit (wall or initial speed) = 1.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import demstudy as ds
from demstudy.scene import load_scene
from demstudy.studies.base import NOT_RUN, REPRODUCED
from demstudy.studies.gutt1989 import PARTS, lgd, lgd_checks
from demstudy.studies.gutt1989 import lgd_flows as flows
from demstudy.studies.gutt1989 import lgd_measure as m

RNG = np.random.default_rng(7)


def test_lgd_part_cases_are_the_thesis_scenes_at_its_step_counts():
    assert PARTS[2] is lgd  # after theory and couette; lgd_theory reads its Couette runs
    full, quick = lgd.cases(False), lgd.cases(True)
    assert {c.name for c in quick} < {c.name for c in full}
    assert all(c.name.startswith("lgd-") and c.engine == "lgd" for c in full)
    steps = {c.name: c.load().run for c in full}
    # the thesis's step counts (digest §4.3): the total run covers them
    for name, total in (("lgd-gas-box", 1024), ("lgd-explosion", 128),
                        ("lgd-couette-elastic-u4096", 1024), ("lgd-hourglass", 2048),
                        ("lgd-obstacle-circle", 1536), ("lgd-incline", 6144),
                        ("lgd-poiseuille-small", 18432)):
        run = steps[name]
        assert run.unit == "steps" and run.equilibration + run.production >= total
    for case in quick:
        q, f = case.load(quick=True).run, steps[case.name]
        assert q.equilibration + q.production <= f.equilibration + f.production
        assert case.load(quick=True).measure.keep_frames


def test_maxwell_test_accepts_a_maxwellian_and_rejects_others():
    gauss = RNG.normal(size=(4096, 2))
    ok = m.maxwell_test(gauss)
    assert ok["ks_speed"] < ok["ks_critical"] and max(ok["ks_vx"], ok["ks_vy"]) < ok["ks_critical"]
    assert abs(ok["anisotropy"] - 1) < 3 * ok["anisotropy_err"]
    # Gutt's start: every grain at one speed; and an anisotropic Gaussian
    angle = RNG.uniform(0, 2 * math.pi, 4096)
    ring = m.maxwell_test(np.stack([np.cos(angle), np.sin(angle)], 1))
    assert ring["ks_speed"] > 10 * ring["ks_critical"] and ring["tv_speed"] > 0.3
    aniso = m.maxwell_test(gauss * [1.3, 1.0])
    assert aniso["anisotropy"] - 1 > 5 * aniso["anisotropy_err"]


def test_discharge_linearity_passes_a_line_and_fails_a_parabola():
    t = np.linspace(0, 50, 60)
    line = np.clip(40 * (t - 5), 0, None)
    fit = m.discharge_linearity(t, line, total=10_000)
    assert fit["rate"] == pytest.approx(40, rel=1e-6) and fit["rate_ratio"] == pytest.approx(1)
    quad = m.discharge_linearity(t, 2 * t ** 2, total=10_000)
    # count ∝ t²: the window's late rate is ~1.9× its early one, far outside "nearly linear"
    assert quad["rate_ratio"] > 1 + 3 * flows.LINEAR_RATE


def _lattice_grains(nxt: int, nyt: int, every: int = 1) -> np.ndarray:
    r, c = np.mgrid[1:nyt - 1:every, 0:nxt]
    return np.stack([(c + 1 + r / 2).ravel() % nxt, (r * m.ROW).ravel()], 1)


def test_row_profiles_and_blocks_recover_a_sheared_thermal_flow():
    nxt, nyt, sigma = 96, 24, 0.2
    pos = _lattice_grains(nxt, nyt)
    vel = np.stack([0.05 * pos[:, 1], np.zeros(len(pos))], 1) + RNG.normal(0, sigma, pos.shape)
    p = m.row_profiles(pos, vel, nyt)
    rows = slice(1, nyt - 1)
    assert np.all(p["n"][rows] == nxt) and p["n"][0] == 0
    assert np.allclose(p["vx"][rows], 0.05 * p["y"][rows], atol=4 * sigma / math.sqrt(nxt))
    # thermal velocity √(⟨C²⟩) of 2 Gaussian components
    assert np.mean(p["thermal"][rows]) == pytest.approx(sigma * math.sqrt(2), rel=0.03)
    b = m.block_average(pos, vel, nxt, nyt, 8, 2)
    assert b["n"].sum() == len(pos)
    assert np.allclose(b["vx"].mean(axis=1), 0.05 * b["y"], atol=0.03)


def test_explosion_front_is_round_for_a_disc_and_not_for_a_square():
    xy = RNG.uniform(-50, 50, (40_000, 2))
    disc = xy[np.hypot(*xy.T) < 50]
    f = m.explosion_front(disc, disc / 50, (0.0, 0.0))
    assert f["rel_rms"] < 0.01 and f["mean"] == pytest.approx(50, rel=0.02)
    square = m.explosion_front(xy, xy / 50, (0.0, 0.0))
    assert square["rel_rms"] > lgd_checks.CIRCULAR and square["a4"] > 0.05
    b = m.block_average(disc + 60, disc / 50, 120, 140, 8, 8)
    assert m.radial_alignment(b, (60.0, 60.0))["within15"] > 0.95
    swirl = m.block_average(disc + 60, np.stack([-disc[:, 1], disc[:, 0]], 1), 120, 140, 8, 8)
    assert m.radial_alignment(swirl, (60.0, 60.0))["within30"] < 0.05


def test_obstacle_proxies_see_a_void_and_a_stagnant_cap():
    nxt, nyt = 120, 60
    pos = _lattice_grains(nxt, nyt)
    obstacle = np.array([[x, y] for x in range(40, 61) for y in np.arange(15, 36)], float)
    inside = (pos[:, 0] >= 39) & (pos[:, 0] <= 61) & (pos[:, 1] >= 14) & (pos[:, 1] <= 36)
    void = (pos[:, 0] > 61) & (pos[:, 0] < 75) & (np.abs(pos[:, 1] - 25) < 8)
    grains = pos[~inside & ~void]
    vel = np.ones_like(grains)
    cap = (grains[:, 0] < 40) & (grains[:, 0] > 28) & (np.abs(grains[:, 1] - 25) < 6)
    vel[cap] = 0.0
    q = flows.obstacle_proxies(grains, vel, obstacle)
    assert q["void"] > 0.9 and q["cap_speed"] / q["flank_speed"] < 0.1
    assert 10 <= q["void_length"] <= 16
    moving = flows.obstacle_proxies(grains, np.ones_like(grains), obstacle)
    assert moving["cap_speed"] / moving["flank_speed"] == pytest.approx(1)


def test_shear_widths_and_occupancy():
    y = np.arange(40) * m.ROW
    vx = np.minimum(y, 10.0)  # sheared over 10 d at each wall (mirrored), plug in between
    vx = np.minimum(vx, vx[::-1])
    p = {"y": y, "vx": vx, "n": np.ones(40)}
    lo, hi = flows.shear_widths(p)
    assert lo == pytest.approx(9, abs=m.ROW) and hi == pytest.approx(9, abs=m.ROW)
    pos = _lattice_grains(48, 12, every=2)
    assert m.occupancy_overlap(pos, pos, 48) == 1.0
    assert m.occupancy_overlap(pos, pos + [0.5, m.ROW], 48) == 0.0  # one row up: disjoint


def test_tiny_lgd_couette_balances_momentum_and_analyses(tmp_path):
    scene = load_scene("gutt1989/couette-elastic-u4096",
                       run={"unit": "steps", "production": 64, "sample_interval": 16})
    res = ds.run(scene, engine="lgd", out=tmp_path / "lgd-couette-elastic-u4096.h5",
                 keep_frames=True, progress=False)
    run = m.load("lgd-couette-elastic-u4096", res.path)
    bal = m.momentum_balance(run)
    assert bal["residual"] < 1e-12 < bal["impulse"]  # walls do push, nothing is lost
    assert bal["grains_min"] == bal["grains_max"] == 5760
    an = lgd_checks.analyse({run.name: res.path}, tmp_path, quick=True)
    verdicts = {c.statement[:20]: c.verdict for c in an.checks}
    assert an.checks[0].verdict == REPRODUCED  # the code test
    assert NOT_RUN in verdicts.values()  # the gas, explosion, ... were not run
    assert all(f.path.exists() for f in an.figures)


def _fake_run(pos: np.ndarray, vel: np.ndarray, nxt: int) -> m.LgdRun:
    return m.LgdRun("fake", {}, {}, pos[None], vel[None], np.array([100]), nxt, 12)


def test_periodic_copy_is_recognised_and_a_perturbed_copy_is_not():
    pos = _lattice_grains(12, 12, every=2)
    vel = RNG.normal(size=pos.shape)
    tiled = np.concatenate([pos + [12.0 * k, 0.0] for k in range(4)])
    tiled_v = np.tile(vel, (4, 1))
    small, full = _fake_run(pos, vel, 12), _fake_run(tiled, tiled_v, 48)
    assert m.same_as_periodic_copy(small, full, 100) == 0.0
    tiled_v[3] += 0.5  # a grain in the first period moves differently
    assert m.same_as_periodic_copy(small, _fake_run(tiled, tiled_v, 48), 100) == 0.5
