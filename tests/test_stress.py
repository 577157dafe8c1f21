"""Stress profiles: branch splitting, the collisional reducer, kinetic and wall stresses, and
the soft-contact stress of a LAMMPS column at rest against its weight.

Dimensionless particle units: d = 1, m = 1, g = 1.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from demstudy.analysis import derived as dv
from demstudy.analysis.profiles import ProfileAnalysis
from demstudy.analysis.stress import (
    ContactStress,
    branch_fractions,
    branch_sums,
    collisional_stress,
    kinetic_tensor,
    wall_stress,
)
from demstudy.io.frames import Frame
from demstudy.io.results import read_results
from demstudy.scene import validate_scene
from demstudy.simulation import RunOptions, run_scene

EDGES = np.array([0.0, 1.0, 2.0, 3.0])


def test_branch_fractions_exact_cases():
    f = branch_fractions([0.5, 2.5, 1.0, 1.0, 3.0, -1.0, 0.2], [2.5, 0.5, 1.0, 1.5, 3.0, 0.5, 0.2],
                         EDGES)
    np.testing.assert_allclose(f, [
        [0.25, 0.5, 0.25],  # three bins
        [0.25, 0.5, 0.25],  # direction does not matter
        [0.0, 1.0, 0.0],  # flat on an inner edge: the bin above
        [0.0, 1.0, 0.0],  # starts on an edge
        [0.0, 0.0, 1.0],  # flat on the top edge: the last bin
        [1 / 3, 0.0, 0.0],  # the part below the grid is dropped
        [1.0, 0.0, 0.0],  # flat inside
    ])
    # periodic: wrapped onto one period
    p = branch_fractions([2.5, -0.25, 5.5], [3.5, 0.25, 6.0], EDGES, period=3.0)
    np.testing.assert_allclose(p, [[0.5, 0.0, 0.5], [0.5, 0.0, 0.5], [0.0, 0.0, 1.0]])
    with pytest.raises(ValueError, match="period"):
        branch_fractions([0.0], [1.0], EDGES, period=2.0)


def test_branch_fractions_match_brute_force():
    rng = np.random.default_rng(0)
    edges = np.sort(rng.random(8)) * 10
    a, b = rng.random(200) * 12 - 1, rng.random(200) * 12 - 1
    frac = branch_fractions(a, b, edges)
    s = np.linspace(0, 1, 20001)[:, None]
    pts = a[None, :] + s * (b - a)[None, :]  # (samples, M)
    for k in range(edges.size - 1):
        inside = ((pts >= edges[k]) & (pts < edges[k + 1])).mean(0)
        np.testing.assert_allclose(frac[:, k], inside, atol=2e-4)


def test_collisional_reducer_and_its_jackknife():
    """sum / (Delta t V_bin); with chunks, the jackknife error of the ratio matches the
    scatter of independent repetitions."""
    dim, nb = 2, 3
    rng = np.random.default_rng(1)
    sums = np.ones((nb, dim, dim)) * np.arange(1, nb + 1)[:, None, None]
    est, err = collisional_stress(sums, 2.0, EDGES, 4.0)
    np.testing.assert_allclose(est[:, 0, 0], np.arange(1, nb + 1) / (2.0 * 1.0 * 4.0))
    assert np.all(np.isnan(err))
    rate = np.arange(nb * dim * dim, dtype=float).reshape(nb, dim, dim) + 1.0

    def repetition():
        dt = rng.uniform(0.5, 1.5, 40)
        s = rate[None] * dt[:, None, None, None] + rng.normal(scale=0.3, size=(40, nb, dim, dim))
        return collisional_stress(s, dt, EDGES, 2.0)

    runs = [repetition() for _ in range(300)]
    ests = np.array([r[0] for r in runs])
    errs = np.array([r[1] for r in runs])
    np.testing.assert_allclose(ests.mean(0), rate / 2.0, atol=4 * ests.std(0).max() / 17)
    np.testing.assert_allclose(errs.mean(0), ests.std(0), rtol=0.2)


def test_contact_stress_of_a_stack_is_the_weight_above_each_plane():
    """A vertical stack of n unit discs resting on a wall (centres at 0.5, 1.5, ...): the
    contact between discs k and k+1 carries the weight of the n-k-1 discs above, the wall
    carries n. Split along the branches, the bin stress is the bin average of the weight of
    the centres above each plane, per unit length: exact."""
    n, length, g = 5, 2.0, 1.0
    y = np.arange(n) + 0.5
    edges = np.linspace(0.0, 6.0, 25)
    cs = ContactStress(edges, 2)
    # force on the upper disc i = k+1 from the lower j = k: (n - k - 1) g upwards
    ups = np.arange(1, n)
    force = np.stack([np.zeros(n - 1), (n - ups) * g], 1)
    branch = np.stack([np.zeros(n - 1), np.ones(n - 1)], 1)  # r_i - r_j
    # the wall: force n g upwards on disc 0, branch from its contact point (y = 0)
    force = np.vstack([force, [0.0, n * g]])
    branch = np.vstack([branch, [0.0, 0.5]])
    cs.add_contacts(np.concatenate([y[ups], [y[0]]]), force, branch, length)
    cs.add_contacts(np.concatenate([y[ups], [y[0]]]), force, branch, length)
    p, err = cs.finish()
    fine = np.linspace(0, 6, 24001)
    weight = (y[None, :] > fine[:, None]).sum(1) * g / length
    expected = [weight[(fine >= a) & (fine < b)].mean() for a, b in zip(edges[:-1], edges[1:],
                                                                        strict=True)]
    np.testing.assert_allclose(p[:, 1, 1], expected, atol=2e-3)
    assert p[0, 1, 1] == pytest.approx(n * g / length)  # the wall's load
    np.testing.assert_allclose(p[:, 0, :], 0.0)
    np.testing.assert_allclose(branch_sums(y[ups], y[ups] - 1.0, np.ones((n - 1, 2, 2)),
                                           edges).sum(), 4 * (n - 1))


def test_kinetic_tensor_of_a_known_gas():
    """Two frames of a 2D gas with fixed velocity fluctuations: P_k = rho nu <v'v'>."""
    rng = np.random.default_rng(2)
    n = 400
    pos = np.stack([rng.random(n) * 40, 1 + rng.random(n) * 8], 1)
    vel = rng.normal(size=(n, 2)) * [1.0, 0.5]
    vel[:, 0] += 0.3 * vel[:, 1]  # correlated u'v'
    pa = ProfileAnalysis(dim=2, bin_width=10.0, lo=0.0, hi=10.0)
    for t in range(4):
        pa.feed(Frame(float(t), np.zeros(2), np.array([40.0, 10.0]), pos, vel,
                      np.zeros((n, 1)), np.full(n, 0.5)))
    prof = pa.finish().results
    p, _ = kinetic_tensor(prof)
    rho_nu = n * (math.pi / 4) / 400.0 * dv.MATERIAL_DENSITY[2]  # = n m / area
    c = vel - vel.mean(0)
    np.testing.assert_allclose(p[0], rho_nu * (c.T @ c) / n, rtol=1e-9)


def test_wall_stress_signs():
    """Particles pressing down and dragging +x on the lower wall, up on the upper wall."""
    t = np.arange(6.0)
    ts = {"time": t, "wall_force_lower": np.tile([2.0, -10.0], (6, 1)),
          "wall_force_upper": np.tile([-2.0, 10.0], (6, 1))}
    lower, _ = wall_stress(ts, "lower", 5.0, start=0.5)
    upper, _ = wall_stress(ts, "upper", 5.0, start=0.5)
    np.testing.assert_allclose(lower, [-0.4, 2.0])  # P_xy = -tau_xy, P_yy > 0
    np.testing.assert_allclose(upper, [-0.4, 2.0])  # the same uniform stress state


def test_lammps_column_at_rest_carries_its_weight(tmp_path):
    """63 rough discs settled on a flat wall under g = 1 (2D, L = 10). The contact stress
    from ``compute pair/local`` (+ the wall contacts), split along the branches:
    * equals, bin by bin, the weight of the centres above each plane averaged over the bin
      (exact for a static assembly, up to its residual ringing);
    * equals the wall's normal stress N g / L in the bin next to the wall;
    * agrees with the momentum balance of derived.py (weight of the *volume* above y) in
      column integrals (exact: a disc's centroid is its centre) and, on 1-wide blocks,
      within the bound set by the discs that the block edges cut (0.106 g per cut disc,
      the mean depth of a half disc / 2)."""
    n, length = 63, 10.0
    scene = validate_scene({
        "dimension": 2, "box": {"size": [length, 14.0]},
        "contact": {"restitution": 0.5, "tangential": {"model": "beta", "beta": 0.0}},
        "walls": [{"side": "lower", "restitution": 0.5,
                   "tangential": {"model": "beta", "beta": 0.0}}],
        "gravity": {"direction": [0.0, -1.0]}, "particles": {"count": n},
        "initial": {"placement": "lattice", "rows": 7, "columns": 9, "spacing": 1.1,
                    "jitter": True},
        "run": {"equilibration": 15.0, "production": 3.0, "sample_interval": 0.5},
        "soft": {"stiffness": 2e4, "steps_per_contact": 30},
        "measure": {"bin_width": 0.25, "keep_frames": True, "statistics": ["profiles",
                                                                           "stress"]},
    })
    res = read_results(run_scene(scene, "lammps", RunOptions(out=tmp_path / "r.h5",
                                                             progress=False)))
    st = res.groups["stress"]
    assert res.group_attrs["stress"]["contact_samples"] == 6
    edges = st["edges"]
    p_yy = st["contact"][:, 1, 1]
    assert res.timeseries["kinetic_energy"][-1] / n < 1e-4  # at rest
    # exact route: weight of the centres above each plane, bin-averaged, over the frames
    ys = res.frames["position"][:, :, 1]
    fine = np.linspace(edges[0], edges[-1], 56001)
    above = (ys[:, None, :] > fine[None, :, None]).sum(2).mean(0) / length
    ik = np.array([above[(fine >= a) & (fine < b)].mean()
                   for a, b in zip(edges[:-1], edges[1:], strict=True)])
    np.testing.assert_allclose(p_yy, ik, atol=5e-3 * n / length)
    # the wall bin carries the whole weight, and so does the wall
    assert p_yy[0] == pytest.approx(n / length, rel=3e-3)
    assert st["wall_lower"][1] == pytest.approx(n / length, rel=3e-3)
    assert p_yy[0] == pytest.approx(st["wall_lower"][1], rel=3e-3)
    assert abs(st["wall_lower"][0]) < 1e-2 * n / length
    # momentum balance (volume-weighted weight above y) against the contact stress
    tau_yy = st["balance_tau_yy"]
    total_yy = st["total"][:, 1, 1]
    width = np.diff(edges)
    assert np.sum(total_yy * width) == pytest.approx(np.sum(tau_yy * width), rel=1e-2)
    blocks = lambda q: (q * width).reshape(-1, 4).sum(1)  # noqa: E731 - 1-wide blocks
    per_layer = 11  # discs a block edge can cut (rows of 10, jammed a little wider)
    assert np.all(np.abs(blocks(total_yy) - blocks(tau_yy)) < 2 * per_layer * 0.106 / length)
    # at rest the kinetic part is negligible, the contact part is all
    assert np.nanmax(np.abs(st["kinetic"][:, 1, 1])) < 1e-3


def test_lammps_couette_shear_stress_is_uniform_and_equals_the_walls(tmp_path):
    """Steady 2D Couette flow without gravity between bumpy walls (upper at u = 2): the
    momentum balance makes the mean P_xy uniform across the gap and equal to each wall's
    shear stress, and likewise P_yy. Checked on the bins clear of the bump layers (the
    bins next to the walls are partly wall material: branches end at the bumps' contact
    points), total = contact + kinetic, with the block errors."""
    rough = {"model": "beta", "beta": 0.0}
    bumps = {"spacing": 1.0, "diameter": 1.0}
    scene = validate_scene({
        "dimension": 2, "box": {"size": [20.0, 10.0]},
        "contact": {"restitution": 0.8, "tangential": rough},
        "walls": [{"side": "lower", "restitution": 0.8, "tangential": rough, "kind": "bumpy",
                   "bumps": bumps},
                  {"side": "upper", "restitution": 0.8, "tangential": rough, "kind": "bumpy",
                   "bumps": bumps, "velocity": 2.0}],
        "particles": {"solid_fraction": 0.5},
        "initial": {"placement": "random", "velocity": {"profile": "linear",
                                                          "temperature": 0.5}},
        "run": {"equilibration": 10.0, "production": 40.0, "sample_interval": 0.1},
        "soft": {"stiffness": 2e4, "steps_per_contact": 30},
        "measure": {"bin_width": 1.0, "statistics": ["profiles", "stress"]},
    })
    res = read_results(run_scene(scene, "lammps", RunOptions(out=tmp_path / "c.h5",
                                                             progress=False)))
    st = res.groups["stress"]
    lower, upper = st["wall_lower"], st["wall_upper"]
    lower_err, upper_err = st["wall_lower_err"], st["wall_upper_err"]
    assert lower[0] < -5 * lower_err[0]  # the upper wall drags +x: sigma_xy > 0, P_xy < 0
    assert abs(lower[0] - upper[0]) < 4 * math.hypot(lower_err[0], upper_err[0])
    inner = slice(1, -1)
    for a in (0, 1):
        wall = 0.5 * (lower[a] + upper[a])
        wall_err = 0.5 * math.hypot(lower_err[a], upper_err[a])
        z = (st["total"][inner, a, 1] - wall) / np.hypot(st["total_err"][inner, a, 1], wall_err)
        assert np.mean(z**2) < 3.0 and np.abs(z).max() < 4.0, (a, z)
    assert np.all(st["contact"][inner, 0, 1] < 0) and np.all(st["kinetic"][inner, 0, 1] < 0)


def test_unsteady_inertia_is_the_momentum_change_per_bin_volume_and_time():
    """Two snapshots 2 apart: bin 0 holds particles gaining x momentum 3 in total, bin 1 one
    that moves in from bin 2 (its momentum counts where it is centred at each end), bin 2 the
    rest: rho nu a = dM / (T w A) exactly, and outside the bins nothing counts."""
    from demstudy.analysis.stress import momentum_snapshot, unsteady_inertia_between

    edges = np.array([0.0, 0.5, 1.0, 1.5])
    start = momentum_snapshot(1.0, [0.1, 0.2, 1.2, 9.0], [[1.0, 0.0], [0.0, 1.0], [2.0, 0.0],
                                                          [5.0, 5.0]])
    end = momentum_snapshot(3.0, [0.1, 0.2, 0.7, 9.0], [[2.5, 0.0], [1.5, 1.0], [2.0, -1.0],
                                                        [7.0, 5.0]])
    got = unsteady_inertia_between(start, end, edges, section=4.0)
    expected = np.array([[3.0, 0.0], [2.0, -1.0], [-2.0, 0.0]]) / (2.0 * 0.5 * 4.0)
    np.testing.assert_allclose(got, expected, rtol=1e-15)
    assert unsteady_inertia_between(end, end, edges, 4.0) is None  # no duration


# ---- three routes in a chute (event-driven) ----------------------------------------------------

def test_edmd_chute_three_stress_routes_agree(tmp_path):
    """Campbell's 30° chute (inputs/campbell1982/chute-30.toml, equilibration 50, production
    150 √(d/g); ~7 s) in the event-driven engine: the engine's kinetic + collisional stress,
    Campbell's momentum balance and the base's wall stress agree within errors. The bed
    accelerates down the slope (it does not reach a steady state at 30°), so τ_xy needs
    Campbell's unsteady term ρνa (from the momentum change of each bin over production): with
    it the routes agree; without it the steady balance overstates τ_xy at the base."""
    from demstudy.scene import load_scene
    from demstudy.scene.initial import build_initial_state

    chute = Path(__file__).resolve().parents[1] / "inputs/campbell1982/chute-30.toml"
    scene = load_scene(chute, ["run.equilibration=50", "run.production=150",
                               'measure.statistics=["profiles", "stress"]'])
    res = read_results(run_scene(scene, "edmd", RunOptions(out=tmp_path / "c.h5", progress=False)))
    st, prof, ts = res.groups["stress"], res.profiles, res.timeseries
    assert "unsteady" in res.group_attrs["stress"]["balance"]
    bed = np.asarray(prof["solid_fraction"]) > 0.1
    assert bed.sum() >= 8
    total, total_err = st["total"], st["total_err"]
    for comp, engine, err in (("tau_yy", total[:, 1, 1], total_err[:, 1, 1]),
                              ("tau_xy", -total[:, 0, 1], total_err[:, 0, 1])):
        balance, balance_err = st[f"balance_{comp}"], st[f"balance_{comp}_err"]
        z = (engine - balance)[bed] / np.hypot(err, balance_err)[bed]
        assert np.all(np.abs(z) < 3.0), (comp, z)
    # the base: the column P_ay against the whole bed's momentum balance, per unit width:
    # P_yy = M g cos α / W (no acceleration normal to the base), τ_xy = (M g sin α − dP_x/dt)/W
    g = scene.gravity_vector
    width = scene.box.size[0]
    mass = float(build_initial_state(scene).mass.sum())
    prod = ts["time"] >= res.attrs["equilibration_end"]
    t, px = ts["time"][prod], ts["momentum"][prod, 0]
    accel_force = (px[-1] - px[0]) / (t[-1] - t[0])
    wall, wall_err = st["wall_lower"], st["wall_lower_err"]
    assert abs(wall[1] - mass * -g[1] / width) < 3 * wall_err[1]
    assert abs(-wall[0] - (mass * g[0] - accel_force) / width) < 3 * wall_err[0]
    assert accel_force > 0.1 * mass * g[0]  # it accelerates: the unsteady term matters
    steady = dv.momentum_balance_stress(dict(prof), scene)
    z0 = (-total[0, 0, 1] - steady["tau_xy"][0]) / np.hypot(total_err[0, 0, 1],
                                                           steady["tau_xy_err"][0])
    assert z0 < -2.5  # the steady balance is above the measured base shear stress
