"""Block averaging and jackknife errors against processes with known statistics."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.signal import lfilter

from demstudy.analysis.blocking import BlockAccumulator, blocking_curve, jackknife


def ar1(rho: float, n: int, chains: int, seed: int) -> np.ndarray:
    """(n, chains) stationary AR(1) series x_t = rho x_{t-1} + e_t, e ~ N(0, 1)."""
    rng = np.random.default_rng(seed)
    e = rng.normal(size=(n, chains))
    e[0] *= 1.0 / np.sqrt(1.0 - rho**2)  # start in the stationary distribution
    return lfilter([1.0], [1.0, -rho], e, axis=0)


def ar1_error_of_mean(rho: float, n: int) -> float:
    """Exact standard error of the mean of n consecutive stationary AR(1) samples."""
    var_x = 1.0 / (1.0 - rho**2)
    factor = (1 + rho) / (1 - rho) - 2 * rho * (1 - rho**n) / (n * (1 - rho) ** 2)
    return float(np.sqrt(var_x * factor / n))


def feed(acc: BlockAccumulator, samples: np.ndarray) -> BlockAccumulator:
    for row in samples:
        acc.add(row)
    return acc


def test_ar1_error_matches_exact():
    rho, n, chains = 0.9, 2**16, 64
    x = ar1(rho, n, chains, seed=11)
    acc = feed(BlockAccumulator(chains, max_blocks=64), x)
    est, err = jackknife(acc, lambda m: m)
    exact = ar1_error_of_mean(rho, n)
    naive = x.std() / np.sqrt(n)
    assert exact / naive > 4  # the correlation matters: naive error is 4.4x too small
    assert np.mean(err) == pytest.approx(exact, rel=0.10)
    assert np.std(est) == pytest.approx(exact, rel=0.25)  # spread of independent chains
    assert np.mean(np.abs(err / exact - 1) < 0.25) > 0.8  # per chain, typically within 25 %
    np.testing.assert_allclose(est, x.mean(0), rtol=1e-12, atol=1e-12)


def test_ratio_estimator_of_correlated_series():
    """Jackknife error of sum(x)/sum(y) with x = 3 y + b, y = 2 + a (a, b AR(1))."""
    rho, n, chains = 0.8, 2**14, 100
    a, b = ar1(rho, n, chains, seed=1), ar1(rho, n, chains, seed=2)
    y = 2.0 + 0.3 * a
    x = 3.0 * y + b
    acc = feed(BlockAccumulator(2 * chains, max_blocks=32), np.hstack([x, y]))
    est, err = jackknife(acc, lambda m: m[:chains] / m[chains:])
    expected = ar1_error_of_mean(rho, n) / 2.0  # delta method: R - 3 ~ mean(b) / mean(y)
    assert np.mean(err) == pytest.approx(expected, rel=0.10)
    assert np.std(est) == pytest.approx(expected, rel=0.25)
    assert np.mean(est) == pytest.approx(3.0, abs=4 * expected / np.sqrt(chains))


def test_linear_jackknife_equals_block_standard_error():
    rng = np.random.default_rng(3)
    acc = feed(BlockAccumulator(3, max_blocks=8), rng.normal(size=(8 * 16, 3)))
    assert acc.n_blocks * acc.block_length == acc.n_samples  # no partial block
    means = acc.block_sums / acc.block_length
    _, err = jackknife(acc, lambda m: m)
    np.testing.assert_allclose(err, means.std(0, ddof=1) / np.sqrt(acc.n_blocks), rtol=1e-12)


@settings(max_examples=50, deadline=None)
@given(n=st.integers(1, 3000), max_blocks=st.sampled_from([4, 6, 16, 64]))
def test_memory_bounded_and_sums_exact(n, max_blocks):
    samples = np.arange(2 * n, dtype=float).reshape(n, 2) % 7  # integers: exact sums
    acc = feed(BlockAccumulator(2, max_blocks=max_blocks), samples)
    assert acc.n_blocks < max_blocks
    assert acc.n_samples == n
    assert acc.block_length & (acc.block_length - 1) == 0  # a power of two
    assert 0 <= n - acc.n_blocks * acc.block_length < acc.block_length
    np.testing.assert_array_equal(acc.total, samples.sum(0))
    if n >= max_blocks:
        assert acc.n_blocks >= max_blocks // 2 - 1


def test_dict_estimator_and_too_few_blocks():
    acc = BlockAccumulator(2)
    acc.add([1.0, 2.0])
    est, err = jackknife(acc, lambda m: {"ratio": m[0] / m[1], "both": m})
    assert est["ratio"] == 0.5 and np.all(np.isnan(err["both"]))
    for v in ([3.0, 2.0], [5.0, 2.0]):
        acc.add(v)
    est, err = jackknife(acc, lambda m: {"ratio": m[0] / m[1], "both": m})
    assert est["ratio"] == pytest.approx(1.5) and err["both"].shape == (2,)


def test_blocking_curve_rises_to_plateau():
    rho, n = 0.99, 2**16
    x = ar1(rho, n, 16, seed=5)
    acc = feed(BlockAccumulator(16, max_blocks=4096), x)
    lengths, errors = blocking_curve(acc, lambda m: m)
    curve = errors.mean(axis=1)
    exact = ar1_error_of_mean(rho, n)
    assert lengths[0] == 32 and np.all(np.diff(lengths) > 0)
    assert curve[0] < 0.75 * exact  # short blocks underestimate
    plateau = curve[(lengths >= 1024) & (lengths <= 4096)]
    np.testing.assert_allclose(plateau, exact, rtol=0.3)


def test_errors():
    with pytest.raises(ValueError):
        BlockAccumulator(2, max_blocks=5)
    with pytest.raises(ValueError):
        BlockAccumulator(2).add([1.0, 2.0, 3.0])
    with pytest.raises(ValueError):
        jackknife(BlockAccumulator(2), lambda m: m)


def test_blocks_shorter_than_the_correlation_are_lengthened():
    """AR(1) with ρ = 0.95 (2τ_int = 39 samples) over 2048 samples: the stored blocks (64
    samples) are too short, so their errors are > 15 % low; the blocking curve's longer
    blocks (>= 8 of them) recover the exact error, and the report says how."""
    from demstudy.analysis.blocking import jackknife_report

    rho, n, chains = 0.95, 2048, 200
    x = ar1(rho, n, chains, seed=3)
    acc = feed(BlockAccumulator(chains, max_blocks=64), x)
    exact = ar1_error_of_mean(rho, n)
    stored = np.sqrt(acc.n_blocks * acc.block_length / n * np.var(
        acc.block_sums / acc.block_length, axis=0, ddof=1) / acc.n_blocks)
    assert np.median(stored) < 0.85 * exact  # the fixed blocks' error is too small
    est, err, report = jackknife_report(acc, lambda m: m)
    assert np.median(err) == pytest.approx(exact, rel=0.1)
    (figures,) = report.values()
    assert figures["block_length"] > acc.block_length and figures["inefficiency"] > 1.1
    # 2τ_int = (1 + ρ)/(1 − ρ) = 39 samples: about 2048/39 = 53 independent samples
    assert 35 < figures["effective_samples"] < 80


def test_uncorrelated_samples_keep_their_errors_and_converge():
    rng = np.random.default_rng(8)
    x = rng.normal(size=(4096, 100))
    from demstudy.analysis.blocking import jackknife_report

    acc = feed(BlockAccumulator(100, max_blocks=64), x)
    _, err, report = jackknife_report(acc, lambda m: m)
    (figures,) = report.values()
    assert figures["converged"] and figures["inefficiency"] < 1.2
    assert np.median(err) == pytest.approx(1 / np.sqrt(4096), rel=0.1)
    assert 3400 < figures["effective_samples"] <= 4096


def test_correlations_as_long_as_the_run_are_flagged():
    """ρ = 0.999 (correlation ~ 2000 samples) over 2048 samples: no plateau within the run;
    the errors are lower bounds and the report says so."""
    from demstudy.analysis.blocking import jackknife_report

    x = ar1(0.999, 2048, 50, seed=4)
    acc = feed(BlockAccumulator(50, max_blocks=64), x)
    _, err, report = jackknife_report(acc, lambda m: m)
    (figures,) = report.values()
    assert not figures["converged"]
    assert np.median(err) < ar1_error_of_mean(0.999, 2048)


def _profile_like(acc: BlockAccumulator):
    """jackknife_report with the 200 chains as 20 outputs of 10 elements (like 20 fields of
    a 10-bin profile): (mean quoted variance, reports)."""
    from demstudy.analysis.blocking import jackknife_report

    _, err, report = jackknife_report(acc, lambda m: {f"f{i}": m[10 * i: 10 * i + 10]
                                                      for i in range(20)})
    return float(np.mean(np.concatenate(list(err.values())) ** 2)), list(report.values())


@pytest.mark.parametrize("rho", [0.9, 0.95, 0.97])
def test_fitted_curve_gives_exponential_errors_of_a_short_run(rho):
    """1200 samples, stored blocks of 32 (the Couette cell's runs): the curve has only three
    levels (32, 64, 128), still rising for τ_int = 10–33 samples. The fit of the curve the
    run measures gives the exact error of the mean (exact²/quoted² 1.07–1.09 here) and
    τ_int; the old rule (plateau or power law) gave 1.12–1.14."""
    n = 1200
    x = ar1(rho, n, 200, seed=12)
    acc = feed(BlockAccumulator(200, max_blocks=64), x)
    assert acc.block_length == 32
    variance, reports = _profile_like(acc)
    assert ar1_error_of_mean(rho, n) ** 2 / variance == pytest.approx(1.0, abs=0.12)
    tau_int = (1 + rho) / (2 * (1 - rho))
    assert np.median([r["correlation_time"] for r in reports]) == pytest.approx(tau_int, rel=0.2)
    assert all(r["converged"] and r["model"] == "exponential" for r in reports)


def test_correlation_beyond_a_twentieth_of_the_run_is_flagged_with_reason():
    """τ_int = 100 samples in a 1200-sample run (> n/20 = 60): flagged, the reason names the
    correlation time, and the quoted error is still the fit's (exact²/quoted² = 1.05; not
    capped below n/5). The old rule's power law overshot the plateau: 0.42."""
    n, rho = 1200, 0.99
    acc = feed(BlockAccumulator(200, max_blocks=64), ar1(rho, n, 200, seed=13))
    variance, reports = _profile_like(acc)
    assert sum(not r["converged"] for r in reports) >= 18
    assert all("correlation time" in r["reason"] for r in reports if not r["converged"])
    assert ar1_error_of_mean(rho, n) ** 2 / variance == pytest.approx(1.0, abs=0.3)
    from demstudy.analysis.blocking import error_figures

    figures = error_figures({k: r for k, r in zip("abc", reports[:3], strict=True)})
    assert not figures["errors_converged"] and "a: correlation time" in figures[
        "errors_unconverged_fields"]


def test_split_mean_of_independent_samples_has_the_standard_error():
    """Independent N(2, 1) samples: the block-means error is σ/√n (to its own ~25 %
    scatter with 10 blocks); a constant series has no error; too few samples give NaN."""
    from demstudy.analysis.blocking import split_mean

    rng = np.random.default_rng(5)
    errs = []
    for _ in range(40):
        mean, err = split_mean(rng.normal(2.0, 1.0, 4000), blocks=10)
        errs.append(err)
        assert abs(mean - 2.0) < 5 * 1.0 / np.sqrt(4000)
    assert np.mean(errs) == pytest.approx(1.0 / np.sqrt(4000), rel=0.1)
    assert split_mean(np.full(100, 3.0), blocks=10) == (3.0, 0.0)
    m, e = split_mean([1.0, 2.0, np.nan], blocks=10)
    assert m == 1.5 and np.isnan(e)


def test_series_mean_sees_the_correlation_of_an_ar1_series():
    """AR(1) with φ = 0.9: the true error of the mean is σ_x √((1 + φ)/(1 - φ)) / √n, ≈ 4.4×
    the naive one; the blocked jackknife recovers it within its statistical scatter."""
    from demstudy.analysis.blocking import series_mean

    rng = np.random.default_rng(6)
    phi, n = 0.9, 2**15
    x = np.empty(n)
    x[0] = 0.0
    noise = rng.normal(0.0, 1.0, n)
    for i in range(1, n):
        x[i] = phi * x[i - 1] + noise[i]
    sigma_x = 1.0 / np.sqrt(1 - phi**2)
    true = sigma_x * np.sqrt((1 + phi) / (1 - phi)) / np.sqrt(n)
    mean, err = series_mean(x)
    assert err == pytest.approx(true, rel=0.35)
    assert err > 2.5 * x.std() / np.sqrt(n)
    assert np.isnan(series_mean([np.nan])[0])
