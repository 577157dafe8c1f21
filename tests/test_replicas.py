"""Replicas (other seeds) combined into one run whose errors come from their scatter
(``ds.combine_replicas``), replica groups in ``ds.compare`` / ``demstudy compare``.
Synthetic runs of a 2D shear state (tests/test_compare.py): dimensionless particle units,
d = 1, m = 1; the shear rate γ̇ = 1 sets the time scale (no gravity)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import t as student_t
from test_compare import synthetic

import demstudy as ds
from demstudy.cli import main
from demstudy.comparison.stats import block_dof, z_test
from demstudy.errors import NotComparable
from demstudy.io.results import write_results

SCENE = 'dimension = 2\n[run]\nequilibration = 1.0\nproduction = {p}\nseed = {seed}\n'


def replica(rng: np.random.Generator, seed: int = 1, scatter: float = 1.0,
            production: float = 2.0, n_bins: int = 20, path=None):
    """A synthetic run whose values scatter ``scatter`` × its quoted errors (the quoted
    errors of a run shorter than its slowest correlation time are too small by that
    factor), with a scene, a seed, a wall time and a time series."""
    res = synthetic(n_bins, rng=rng, rel_err=0.01 * scatter)
    for group in (res.profiles, res.groups["stress"]):
        for name in [n for n in group if n.endswith("_err")]:
            group[name] = group[name] / scatter
    res.attrs.update(scene_toml=SCENE.format(p=production, seed=seed), seed=seed,
                     wall_seconds=1.5 + seed, engine="edmd")
    res.timeseries = {"time": np.arange(3.0) + seed}
    if path is not None:
        write_results(path, res)
    return res


def test_the_mean_and_its_standard_error_are_exact():
    rng = np.random.default_rng(1)
    runs = [replica(rng, seed=s) for s in (1, 2, 3, 4)]
    combined = ds.combine_replicas(runs)
    for name in ("temperature", "velocity", "temperature_components", "solid_fraction"):
        stack = np.stack([r.profiles[name] for r in runs])
        np.testing.assert_allclose(combined.profiles[name], stack.mean(0), rtol=1e-13)
        np.testing.assert_allclose(combined.profiles[f"{name}_err"],
                                   stack.std(0, ddof=1) / 2.0, rtol=1e-12)  # std/√4
    stack = np.stack([r.groups["stress"]["total"] for r in runs])  # per tensor component
    np.testing.assert_allclose(combined.groups["stress"]["total_err"],
                               stack.std(0, ddof=1) / 2.0, rtol=1e-12)
    # an exactly known quantity (equal masses) stays exact: compare leaves it out
    assert np.all(combined.profiles["mean_mass_err"] == 0)
    assert combined.profile_attrs["replicas"] == 4 and combined.profile_attrs[
        "error_method"] == "replicas"
    assert block_dof(combined.profile_attrs) == 3  # R − 1
    assert combined.attrs["wall_seconds"] == pytest.approx(sum(r.attrs["wall_seconds"]
                                                               for r in runs))
    np.testing.assert_array_equal(combined.timeseries["time"], runs[0].timeseries["time"])
    assert combined.attrs["replica_seeds"] == "1,2,3,4"


def test_replica_errors_measure_the_true_scatter_where_quoted_errors_are_too_small():
    """16 replicas scattering 2.7× their quoted errors (the rough-wall Couette bed): the
    combined standard errors are the true σ/√16 on average, and the combination reports the
    factor 2.7 (χ² over ~20 bins × 8 fields: a few per cent)."""
    rng = np.random.default_rng(2)
    combined = ds.combine_replicas([replica(rng, seed=s, scatter=2.7) for s in range(1, 17)])
    true_err = 0.01 * 2.7 * 1.0 / 4.0  # temperature: size 1, σ_true/√16
    measured = combined.profiles["temperature_err"]
    assert np.sqrt(np.mean(measured**2)) == pytest.approx(true_err, rel=0.1)
    assert combined.profile_attrs["scatter_to_quoted_error"] == pytest.approx(2.7, rel=0.05)


def test_replicas_of_other_scenes_or_bins_are_refused():
    rng = np.random.default_rng(3)
    with pytest.raises(NotComparable, match="production"):
        ds.combine_replicas([replica(rng, 1), replica(rng, 2, production=3.0)])
    with pytest.raises(NotComparable, match="bins"):
        ds.combine_replicas([replica(rng, 1), replica(rng, 2, n_bins=10)])
    with pytest.raises(NotComparable, match="seeds"):
        ds.combine_replicas([replica(rng, 1), replica(rng, 1)])
    other_engine = replica(rng, 2)
    other_engine.attrs["engine"] = "lammps"
    with pytest.raises(NotComparable, match="engine"):
        ds.combine_replicas([replica(rng, 1), other_engine])
    with pytest.raises(NotComparable, match="at least 2"):
        ds.combine_replicas([replica(rng, 1)])


def test_replica_groups_of_one_state_agree_with_r_minus_one_degrees_of_freedom():
    """Runs whose quoted errors are 2.7× too small: single runs of one state are called
    different in most fields, groups of 3 replicas only at the stated 0.27 % per field,
    because their errors come from the scatter and their t test uses R − 1 = 2 dof."""
    rng = np.random.default_rng(4)
    (single,) = ds.compare(replica(rng, 1, scatter=2.7), replica(rng, 2, scatter=2.7))
    assert len(single.resolved) >= 4, single.table()
    resolved: dict[str, int] = {}
    for _ in range(150):
        (cmp,) = ds.compare([replica(rng, s, scatter=2.7) for s in (1, 2, 3)],
                            [replica(rng, s, scatter=2.7) for s in (4, 5, 6)])
        for name, f in cmp.fields.items():
            resolved[name] = resolved.get(name, 0) + f.resolved
    assert max(resolved.values()) <= 4, resolved  # expected 0.4 per field
    f = cmp.fields["temperature"]
    assert "mean of 3 replicas" in cmp.reference and "mean of 3 replicas" in cmp.other
    assert any("2 degrees of freedom" in n for n in cmp.notes)
    # the p-value is Student's t on the Welch dof of two errors of 2 dof each
    z, dof, p = z_test(f.delta, f.other_err, f.reference_err, 2.0, 2.0)
    assert f.p == pytest.approx(float(p.min()), rel=1e-12)
    assert np.all((dof >= 2.0 - 1e-9) & (dof <= 4.0 + 1e-9))
    k = int(np.argmax(np.abs(z)))
    assert f.p == pytest.approx(2 * student_t.sf(abs(z[k]), dof[k]), rel=1e-9)
    assert f.p > math.erfc(abs(z[k]) / math.sqrt(2))  # heavier tails than the normal


def test_cli_compares_comma_separated_replica_groups(tmp_path, capsys):
    rng = np.random.default_rng(5)
    files = [tmp_path / f"run{s}.h5" for s in range(1, 6)]
    for s, path in enumerate(files, 1):
        replica(rng, s, path=path)
    group_a, group_b = ",".join(map(str, files[:3])), ",".join(map(str, files[3:]))
    assert main(["compare", group_a, group_b, "-o", "none"]) == 0
    out = capsys.readouterr().out
    assert "run{1,2,3}.h5 (edmd, mean of 3 replicas)" in out
    assert "note: other: mean of 2 replicas" in out and "1 degrees of freedom" in out
    # a group and a single run; a single file stays itself
    assert main(["compare", group_a, str(files[4]), "-o", "none"]) == 0
    assert "run5.h5 (edmd)" in capsys.readouterr().out
    # a group of replicas that are not (other bins): exit 2 naming the files
    replica(rng, 7, n_bins=10, path=tmp_path / "coarse.h5")
    assert main(["compare", f"{files[0]},{tmp_path / 'coarse.h5'}", str(files[1]),
                 "-o", "none"]) == 2
    assert "coarse.h5" in capsys.readouterr().err
    assert main(["compare", ",", str(files[1]), "-o", "none"]) == 2
    assert "RUN.h5" in capsys.readouterr().err


def test_replica_files_are_named_in_shell_brace_form():
    from demstudy.comparison.core import _brace

    assert _brace(["a-r0.h5", "a-r1.h5"]) == "a-r{0,1}.h5"
    # the ladder's own run (no suffix) beside its extra seeds: bash's {,-r1} form
    assert _brace(["s.h5", "s-r1.h5", "s-r2.h5"]) == "s{,-r1,-r2}.h5"
    assert _brace(["x.h5", "x.h5"]) == "x.h5,x.h5"  # not a set of distinct files
