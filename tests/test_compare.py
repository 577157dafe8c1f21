"""demstudy compare / ds.compare: a planted difference is found, runs of one state agree,
runs on different bins are rebinned exactly and say so, the relative L2 error of a known
offset is exact, and the command line's exit codes. Dimensionless particle units: d = 1,
m = 1; the shear rate γ̇ = 1 sets the time scale (no gravity).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import demstudy as ds
from demstudy.cli import main
from demstudy.comparison.rebin import UNIT_VOLUME, rebin_profiles, rebin_stress
from demstudy.errors import NotComparable
from demstudy.io.results import Results, write_results

L = 20.0  # height of the synthetic shear cell (d)
T0 = 1.0  # temperature without the mean flow's spread (m (γ̇ d)²)
COLLISIONAL_XY = -0.8  # a collisional shear stress per unit solid fraction


def phi_of(y):
    return 0.4 + 0.01 * y  # a density gradient: the weights matter


def u_of(y):
    return y - L / 2  # u = γ̇ (y − L/2)


def truth(n_bins: int, lo: float = 0.0, hi: float = L) -> dict[str, np.ndarray]:
    """Exact bin averages of a sheared 2D state on ``n_bins`` bins (Gauss–Legendre, exact
    for these polynomials): volume means of ν and the stress, mass means of u, and strip
    temperatures that hold the spread of u inside the bin, T_x = T0 + <(u − U)²>."""
    edges = np.linspace(lo, hi, n_bins + 1)
    x, w = np.polynomial.legendre.leggauss(4)
    y = 0.5 * (edges[:-1, None] + edges[1:, None]) + 0.5 * np.diff(edges)[:, None] * x
    w = 0.5 * w[None, :]  # weights of a mean over the bin
    phi, u = phi_of(y), u_of(y)
    n = phi / UNIT_VOLUME[2]  # number density, m = 1
    mass = (w * n).sum(1)
    umean = (w * n * u).sum(1) / mass
    spread = (w * n * (u - umean[:, None]) ** 2).sum(1) / mass
    tx, ty = T0 + spread, np.full(n_bins, T0)
    kin_xx = (w * n * (T0 + (u - umean[:, None]) ** 2)).sum(1)  # Σ m v'v'/V, v' about U
    kin_yy = (w * n * T0).sum(1)
    stress = np.zeros((n_bins, 2, 2))
    stress[:, 0, 0], stress[:, 1, 1] = kin_xx, kin_yy
    stress[:, 0, 1] = stress[:, 1, 0] = COLLISIONAL_XY * (w * phi).sum(1)
    return {"edges": edges, "y": 0.5 * (edges[1:] + edges[:-1]),
            "solid_fraction": (w * phi).sum(1), "number_density": (w * n).sum(1),
            "mean_mass": np.ones(n_bins),
            "velocity": np.stack([umean, np.zeros(n_bins)], 1),
            "temperature_components": np.stack([tx, ty], 1), "temperature": (tx + ty) / 2,
            "stress": stress}


def synthetic(n_bins: int = 20, rng: np.random.Generator | None = None, rel_err: float = 0.01,
              plant: dict[str, float] | None = None, path=None) -> Results:
    """A run of the state above: each value measured with the standard error ``rel_err`` ×
    its typical size (noise drawn with ``rng``; none without), ``plant``: {field: offset in
    units of σ_Δ = √2 σ} added to every bin."""
    t = truth(n_bins)
    prof: dict[str, np.ndarray] = {"edges": t["edges"], "y": t["y"]}
    size = {"solid_fraction": 0.5, "number_density": 0.6, "mean_mass": 0.0, "velocity": 5.0,
            "temperature_components": 1.0, "temperature": 1.0, "stress": 1.0}
    noisy = {}
    for name, value in t.items():
        if name in ("edges", "y"):
            continue
        err = np.full(value.shape, rel_err * size[name])
        noise = rng.normal(0.0, 1.0, value.shape) * err if rng is not None else 0.0
        noisy[name] = (value + noise + (plant or {}).get(name, 0.0) * math.sqrt(2) * err, err)
    for name, (value, err) in noisy.items():
        if name != "stress":
            prof[name], prof[f"{name}_err"] = value, err
    stress = {"edges": t["edges"], "y": t["y"], "total": noisy["stress"][0],
              "total_err": noisy["stress"][1]}
    res = Results({"scene_name": "synthetic-shear", "engine": "none"}, profiles=prof,
                  profile_attrs={"dim": 2, "axis": "y", "n_blocks": 40,
                                 "inertia_factor": 0.5},
                  groups={"stress": stress}, group_attrs={"stress": {"dim": 2}})
    if path is not None:
        write_results(path, res)
    return res


def test_a_planted_difference_of_three_sigma_is_found(tmp_path):
    """Temperature moved by 3σ_Δ in every bin (σ_Δ the combined error): resolved, with
    |z| ≈ 3 per bin and the debiased L2 error that offset's; untouched fields agree."""
    rng = np.random.default_rng(3)
    ref = synthetic(rng=rng, path=tmp_path / "ref.h5")
    other = synthetic(rng=rng, plant={"temperature": 3.0}, path=tmp_path / "other.h5")
    (cmp,) = ds.compare(tmp_path / "ref.h5", tmp_path / "other.h5")
    t = cmp.fields["temperature"]
    assert t.resolved and "DIFFERS" in t.verdict
    z = t.delta / t.delta_err
    assert abs(np.median(z) - 3.0) < 0.5  # 20 values of N(3, 1)
    assert 3.0 < t.max_z < 3.0 + 3.5
    planted = 3.0 * math.sqrt(2) * 0.01 * math.sqrt(20) / np.linalg.norm(ref.profiles[
        "temperature"])
    assert t.rel_l2_debiased == pytest.approx(planted, rel=0.25)
    assert t.rel_l2 > t.rel_l2_floor
    assert [n for n, f in cmp.fields.items() if f.resolved] == ["temperature"]
    assert cmp.fields["solid_fraction"].verdict.startswith("agrees within errors")
    assert other.path is not None and "other.h5" in cmp.other


def test_runs_of_one_state_agree_at_the_stated_rate():
    """300 pairs of synthetic runs of one state: each field resolved in about 0.27 % of them
    (3σ family), and ‖Δ‖ is on average its noise floor; the same for 200 pairs on different
    bins (measured: 0–2 of 300 per field, with or without rebinning)."""
    rng = np.random.default_rng(5)
    resolved, ratio = {}, []
    for _ in range(300):
        (cmp,) = ds.compare(synthetic(rng=rng), synthetic(rng=rng))
        for name, f in cmp.fields.items():
            resolved[name] = resolved.get(name, 0) + f.resolved
        ratio.append(cmp.fields["temperature"].rel_l2 / cmp.fields["temperature"].rel_l2_floor)
    assert max(resolved.values()) <= 5, resolved  # expected 0.8 per field
    assert np.mean(ratio) == pytest.approx(1.0, abs=0.05)  # ⟨χ_20⟩/√20 = 0.99
    # rebinned (20 bins against 10): the moved values and their errors keep the rate
    resolved = {}
    for _ in range(200):
        (cmp,) = ds.compare(synthetic(10, rng=rng), synthetic(20, rng=rng))
        for name, f in cmp.fields.items():
            resolved[name] = resolved.get(name, 0) + f.resolved
    assert max(resolved.values()) <= 4, resolved  # expected 0.5 per field


def test_a_known_offset_gives_the_exact_relative_l2():
    ref = synthetic()
    other = synthetic()
    other.profiles["temperature"] = other.profiles["temperature"] + 0.05
    (cmp,) = ds.compare(ref, other, fields=["temperature"])
    f = cmp.fields["temperature"]
    norm = np.linalg.norm(ref.profiles["temperature"])
    assert f.rel_l2 == pytest.approx(0.05 * math.sqrt(20) / norm, rel=1e-12)
    assert f.rel_l2_floor == pytest.approx(math.sqrt(20 * 2 * 0.01**2) / norm, rel=1e-12)
    assert f.rel_l2_debiased == pytest.approx(
        math.sqrt(20 * 0.05**2 - 20 * 2 * 0.01**2) / norm, rel=1e-12)
    assert f.max_z == pytest.approx(0.05 / (math.sqrt(2) * 0.01))
    assert list(cmp.fields) == ["temperature"]


def test_rebinning_is_exact_for_the_strip_definitions():
    """The 20-bin state rebinned to 10 bins is the 10-bin state: mass-weighted u, and
    temperatures and kinetic stresses that gain the spread of the fine bins' mean u (without
    it, T_x would miss 0.25 (γ̇ d)², 18 σ_Δ here). Exact values: no errors, so no noise
    bias is taken off."""
    fine, coarse = synthetic(20, rel_err=0.0), synthetic(10, rel_err=0.0)
    edges = coarse.profiles["edges"]
    prof, left = rebin_profiles(fine.profiles, edges, 2, 0.5)
    assert left == []
    for name in ("solid_fraction", "number_density", "velocity", "temperature",
                 "temperature_components"):
        np.testing.assert_allclose(prof[name], coarse.profiles[name], rtol=1e-12, atol=1e-12,
                                   err_msg=name)
    stress = rebin_stress(fine.groups["stress"], fine.profiles, edges, 2)
    np.testing.assert_allclose(stress["total"], coarse.groups["stress"]["total"], rtol=1e-12)
    naive = fine.profiles["temperature_components"][:, 0].reshape(10, 2).mean(1)
    gap = coarse.profiles["temperature_components"][:, 0] - naive
    assert np.all(gap > 15 * math.sqrt(2) * 0.01)  # > 15 σ_Δ at 1 % errors
    # through compare, with 1 % errors: the same within a fraction of σ_Δ (the noise bias)
    (cmp,) = ds.compare(synthetic(10), synthetic(20))
    assert cmp.rebinned and "[rebinned" in cmp.table()
    for name in ("velocity[x]", "temperature", "temperature_components[x]", "stress/xx",
                 "stress/xy", "stress/yy"):
        f = cmp.fields[name]
        assert f.rebinned and len(f.y) == 10
        assert np.all(np.abs(f.delta) < 0.2 * f.delta_err), name


def test_a_20_and_a_10_bin_run_of_one_state_agree_and_say_rebinned(tmp_path, capsys):
    rng = np.random.default_rng(11)
    synthetic(20, rng=rng, path=tmp_path / "fine.h5")
    synthetic(10, rng=rng, path=tmp_path / "coarse.h5")
    (cmp,) = ds.compare(tmp_path / "fine.h5", tmp_path / "coarse.h5")
    assert not cmp.resolved, cmp.table()
    assert all(f.rebinned for f in cmp.fields.values())
    note = next(n for n in cmp.notes if n.startswith("rebinned"))
    assert "20 bins" in note and "10 common bins" in note and "moved: fine.h5" in note
    # other ranges: the coarser grid's bins inside the overlap [2, 18]
    part = synthetic(20, rng=rng)
    for name, value in list(part.profiles.items()):
        part.profiles[name] = value[2:19] if name == "edges" else value[2:18]
    part.groups["stress"] = {k: (v[2:19] if k == "edges" else v[2:18])
                             for k, v in part.groups["stress"].items()}
    (cut,) = ds.compare(tmp_path / "coarse.h5", part)
    np.testing.assert_allclose(cut.fields["temperature"].y, np.arange(3.0, 18.0, 2.0))
    assert len(cut.resolved) <= 1, cut.table()  # 0.27 % per field by chance (below)
    assert "8 common bins on [2, 18]" in cut.table()
    # grids that do not nest: compared, with the assumption stated
    (odd,) = ds.compare(synthetic(20), synthetic(15))
    assert len(odd.fields["temperature"].y) == 15
    assert any("do not nest" in n for n in odd.notes)


def test_runs_that_cannot_be_compared_are_refused_naming_both(tmp_path):
    a = synthetic(path=tmp_path / "a.h5")
    b3 = synthetic(path=tmp_path / "b3.h5")
    b3.profile_attrs["dim"] = 3
    write_results(tmp_path / "b3.h5", b3)
    with pytest.raises(ValueError, match=r"a\.h5.* 2D.*b3\.h5.* 3D"):
        ds.compare(a.path, tmp_path / "b3.h5")
    bx = synthetic()
    bx.profile_attrs["axis"] = "x"
    with pytest.raises(NotComparable, match="different axes"):
        ds.compare(a, bx)
    with pytest.raises(NotComparable, match="unknown field 'pressure'"):
        ds.compare(a, synthetic(), fields=["pressure"])
    far = synthetic()
    far.profiles["edges"] = far.profiles["edges"] + 100.0
    far.profiles["y"] = far.profiles["y"] + 100.0
    with pytest.raises(NotComparable, match="do not overlap"):
        ds.compare(a, far)


def test_two_seeds_of_one_state_agree(tmp_path):
    """Two short event-driven runs of the 2D Lees–Edwards state (a 20 × 20 box, 200 strain
    units) with different seeds: no field differs beyond its errors."""
    runs = [ds.run(ds.load_scene("shear/lees-edwards-2d", box={"size": [20.0, 20.0]},
                                 run={"equilibration": 20.0, "production": 200.0, "seed": s},
                                 measure={"statistics": ["stress"]}),
                   engine="edmd", out=tmp_path / f"seed{s}.h5") for s in (1, 2)]
    assert runs[0].attrs["seed"] != runs[1].attrs["seed"]
    (cmp,) = ds.compare(*runs)
    assert {"temperature", "stress/xy", "velocity[x]"} <= set(cmp.fields)
    assert not cmp.resolved, cmp.table()
    for f in cmp.fields.values():
        assert f.verdict.startswith("agrees within errors")
    out = ds.plot_comparison([cmp], tmp_path / "seeds.png")
    assert out.stat().st_size > 20_000


def test_the_command_line(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    rng = np.random.default_rng(2)
    for name, n in (("a", 20), ("b", 20), ("c", 10)):
        synthetic(n, rng=rng, path=tmp_path / f"{name}.h5")
    assert main(["compare", "a.h5", "b.h5", "c.h5"]) == 0
    out = capsys.readouterr().out
    assert out.count("reference: a.h5 (none)") == 2 and "rebinned" in out
    assert "stress/xy" in out and (tmp_path / "compare.png").stat().st_size > 20_000
    assert main(["compare", "a.h5", "b.h5", "--fields", "temperature,velocity[x]",
                 "-o", "t.png"]) == 0
    assert (tmp_path / "t.png").exists()
    assert "solid_fraction" not in capsys.readouterr().out
    write_results(tmp_path / "empty.h5", Results({"engine": "none"}))
    for argv, says in ((["missing.h5", "a.h5"], "missing.h5: no such results file"),
                       (["a.h5", "b.h5", "--fields", "pressure"], "unknown field 'pressure'"),
                       (["a.h5", "empty.h5"], "empty.h5 (none): no profiles"),
                       (["a.h5"], "at least one other run")):
        assert main(["compare", *argv, "-o", "none"]) == 2, argv
        assert says in capsys.readouterr().err


@pytest.mark.parametrize("effective, dof", [(5.0, 4.0), (100.0, 39.0), (None, 39.0)])
def test_degrees_of_freedom_come_from_the_effective_samples(effective, dof):
    """A single run's errors rest on min(n_blocks, effective_samples) independent samples:
    40 blocks but 5 effective samples give 4 degrees of freedom, not 39; each bin's p-value
    is Student's t on the Welch–Satterthwaite dof of the pair (equal errors: 2 × dof), and
    the notes say which dof each run got."""
    from scipy.stats import t as student_t

    rng = np.random.default_rng(3)
    runs = [synthetic(rng=rng), synthetic(rng=rng, plant={"temperature": 3.0})]
    for run in runs:
        if effective is not None:
            run.profile_attrs["effective_samples"] = effective
    (cmp,) = ds.compare(*runs)
    t = cmp.fields["temperature"]
    assert t.p == pytest.approx(2 * student_t.sf(t.max_z, 2 * dof), rel=1e-9)
    note = next(n for n in cmp.notes if n.startswith("degrees of freedom"))
    assert f"reference {dof:g} (40 blocks" in note and f"other {dof:g}" in note


def test_replica_means_keep_r_minus_one_degrees_of_freedom():
    from demstudy.comparison.stats import block_dof

    assert block_dof({"n_blocks": 3, "error_method": "replicas"}) == 2.0
    assert block_dof({"n_blocks": 40, "effective_samples": 1.5}) == 1.0  # at least 1
    assert block_dof({}) == math.inf


def test_fields_known_to_round_off_are_left_out_and_named():
    """mean_mass of equal particles: errors ~1e-16 in both runs and equal values is no
    comparison (rows of noise): left out, one note; a real difference of such a field is
    kept (and resolved)."""
    rng = np.random.default_rng(4)
    runs = [synthetic(rng=rng), synthetic(rng=rng)]
    for run in runs:
        run.profiles["mean_mass_err"] = np.full(20, 1.1e-16)
    (cmp,) = ds.compare(*runs)
    assert "mean_mass" not in cmp.fields and "exact in both runs: mean_mass" in cmp.notes
    assert "solid_fraction" in cmp.fields
    runs[1].profiles["mean_mass"] = runs[1].profiles["mean_mass"] * (1 + 1e-9)
    (cmp,) = ds.compare(*runs)
    assert cmp.fields["mean_mass"].resolved
    assert not any(n.startswith("exact in both") for n in cmp.notes)


@pytest.mark.parametrize("argv, named", [
    (["-o", "figure.xyz"], "-o/--out"),
    (["-o", "figure"], "-o/--out"),
    (["--sigma", "0"], "sigma"),
])
def test_cli_refuses_bad_values_before_computing(argv, named, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    rng = np.random.default_rng(2)
    for name in ("a", "b"):
        synthetic(rng=rng, path=tmp_path / f"{name}.h5")
    assert main(["compare", "a.h5", "b.h5", *argv]) == 2
    captured = capsys.readouterr()
    assert named in captured.err and "reference:" not in captured.out  # nothing computed
    assert not list(tmp_path.glob("figure*"))
