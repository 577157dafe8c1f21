"""Streaming block averaging with jackknife errors for correlated time series.

Method
------
Successive samples from a simulation are correlated, so the naive standard error
``std/sqrt(n)`` underestimates the true one. Blocking (Flyvbjerg & Petersen, J. Chem. Phys.
91, 461 (1989)) groups consecutive samples into blocks; once a block is much longer than
the correlation time the block means are nearly independent and their scatter gives the
error of the mean. :class:`BlockAccumulator` does this with bounded memory: it keeps at most
``max_blocks`` completed block *sums*, and whenever that many are full it merges neighbouring
pairs and doubles the block length (Flyvbjerg-Petersen's transformation done online). Memory
is therefore ``O(max_blocks * n_values)``, independent of the run length, and for a run of
``n`` samples the blocks end up ``n/max_blocks .. 2n/max_blocks`` samples long.

Nonlinear estimators (ratios such as a mass-weighted mean velocity ``sum(V v)/sum(V)``,
or variances ``<v^2> - <v>^2``) are handled by the delete-one-block jackknife
(e.g. Efron & Stein 1981; Berg, Comput. Phys. Commun. 69, 7 (1992)): with ``M`` equal blocks,
``theta_k`` is the estimator on the means of all blocks but block ``k`` and

    var(theta) = (M - 1)/M * sum_k (theta_k - mean_k theta_k)^2,

which is consistent for smooth functions of means and needs no error propagation by hand.
The estimate itself is the estimator on the mean of *all* samples (the samples of the
incomplete trailing block included); its variance is the jackknife variance of the complete
blocks scaled by ``n_complete / n_all``. With fewer than two complete blocks the error is
NaN. Quantities are whatever the caller feeds (dimensionless particle units: d = 1, m = 1).

Block length from the measured correlation
------------------------------------------
The stored blocks are n/max_blocks .. 2n/max_blocks samples long, whatever the correlation
time. Blocks shorter than the correlation time give errors too small (by 2× in a sheared
gas sampled every half strain unit). :func:`jackknife` therefore follows Flyvbjerg and
Petersen's blocking curve: it merges the stored blocks pairwise while at least
``MIN_BLOCKS`` remain and, per output (each key of a dict estimator), takes the median over
its elements of the variance ratio r_l = err_l² / err_0² at each level l (the median over
the bins keeps the curve's noise at a few per cent). err_l² = σ² g(b_l)/n with g the
statistical inefficiency of blocks b_l long, and the error of the run's mean is σ² g(n)/n:
the curve must be followed to one block of the whole run. Each element's error is its
finest-level error (the finest level, with the most blocks, is the least noisy) times
√(g(n)/ĝ(b₀)), from a fit of the curve (:func:`_inefficiency`). Two one-parameter models
of g: exponential correlations (time τ; g(b) = 1 + 2 Σ_{k<b} (1 − k/b) ρ^k, ρ = e^{−1/τ})
and a power law g ∝ b^α (slowly growing correlations, as in sheared gases where bands
drift). Each is fitted as the run *measures* it: block means scatter about the run's own
mean, so the expected curve is ĝ(b) = (n g(b) − b g(n))/(n − b), which bends over before
the true plateau when the correlation is not short against the run (the old plateau rule
read that bend as convergence, the old power-law extrapolation overshot the plateau).
Weights: a variance of m blocks has relative variance 2/(m − 1). The exponential is kept
unless the power law fits better by Δχ² > 2. An output is *converged* when the exponential
fits and τ_int ≤ n/20; otherwise (a power law, a longer τ, or a trend such as a transient
that outlasts the equilibration) it is flagged, with the reason, and its factor is at most
what τ_int = n/5 would give (beyond that the fit is unconstrained and diverges: the slow part
cancels from the run's own curve). Correlations much longer than the run are invisible
to it altogether: only replicas measure them (docs/results-format.md, "Statistical
errors", with the replica ratios measured). Checked against processes of known error
(tests/test_blocking.py) and replicas (tests/test_error_replicas.py).
:func:`jackknife_report` returns these figures: the longest useful block length, the
factor r, convergence (with the model, τ_int and the reason), and the effective number of
independent samples n / (g₀ r), g₀ the statistical inefficiency of the stored blocks
themselves (from the samples' own variance).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["MIN_BLOCKS", "BlockAccumulator", "Estimator", "blocking_curve", "error_figures",
           "jackknife", "jackknife_report"]

#: fewest blocks a level of the blocking curve may have (its error's noise is ~1/√(2(M−1)))
MIN_BLOCKS = 8


F64 = NDArray[np.float64]
#: longest correlation time (τ_int, as a fraction of the run's n samples) whose errors count
#: as converged, and the longest the extrapolation may assume (beyond, the fit is unconstrained)
_TAU_LIMIT = 1.0 / 20
_TAU_CAP = 1.0 / 5
#: χ² by which the power law must beat the exponential (the physically expected form)
_MARGIN = 2.0
Result = F64 | dict[str, F64]
Estimator = Callable[[F64], "F64 | Mapping[str, F64]"]


class BlockAccumulator:
    """Bounded-memory block sums of per-sample vectors (e.g. per-bin sums of V, V v, V v^2).

    Parameters
    ----------
    n_values: length of each sample vector.
    max_blocks: maximal number of stored blocks (even, >= 4); when full, pairs are merged.
    """

    def __init__(self, n_values: int, max_blocks: int = 64) -> None:
        if n_values < 0:
            raise ValueError(f"n_values must be >= 0, got {n_values}")
        if max_blocks < 4 or max_blocks % 2:
            raise ValueError(f"max_blocks must be even and >= 4, got {max_blocks}")
        self.n_values = int(n_values)
        self.max_blocks = int(max_blocks)
        self.block_length = 1
        self.n_samples = 0
        self.n_blocks = 0
        self._blocks = np.zeros((self.max_blocks, self.n_values))
        self._partial = np.zeros(self.n_values)
        self._partial_count = 0
        self._squares = np.zeros(self.n_values)  # Σ x² over samples: their own variance

    def add(self, sample: ArrayLike) -> None:
        """Add one sample vector (shape ``(n_values,)``; other shapes are raveled)."""
        x = np.asarray(sample, dtype=np.float64).reshape(-1)
        if x.shape[0] != self.n_values:
            raise ValueError(f"sample has {x.shape[0]} values, expected {self.n_values}")
        self._partial += x
        self._squares += x * x
        self._partial_count += 1
        self.n_samples += 1
        if self._partial_count < self.block_length:
            return
        self._blocks[self.n_blocks] = self._partial
        self.n_blocks += 1
        self._partial[:] = 0.0
        self._partial_count = 0
        if self.n_blocks == self.max_blocks:
            half = self.max_blocks // 2
            self._blocks[:half] = self._blocks[0::2] + self._blocks[1::2]
            self._blocks[half:] = 0.0
            self.n_blocks = half
            self.block_length *= 2

    @property
    def block_sums(self) -> F64:
        """(n_blocks, n_values) sums over each complete block (a copy)."""
        return self._blocks[: self.n_blocks].copy()

    @property
    def total(self) -> F64:
        """Sum over all samples, the incomplete trailing block included."""
        return self._blocks[: self.n_blocks].sum(axis=0) + self._partial

    @property
    def mean(self) -> F64:
        """Mean over all samples (NaN before the first sample)."""
        if self.n_samples == 0:
            return np.full(self.n_values, np.nan)
        return self.total / self.n_samples

    @property
    def sample_variance(self) -> F64:
        """Variance of the single samples, per value (NaN with fewer than two)."""
        n = self.n_samples
        if n < 2:
            return np.full(self.n_values, np.nan)
        mean = self.total / n
        return np.maximum(self._squares / n - mean * mean, 0.0) * n / (n - 1)

    def inefficiency(self) -> float:
        """Statistical inefficiency g₀ of the stored blocks: b × var(block means) / var(samples)
        (1 for uncorrelated samples, 2τ for blocks much longer than a correlation time τ),
        the median over the values that vary; NaN with fewer than two blocks."""
        if self.n_blocks < 2:
            return float("nan")
        means = self.block_sums / self.block_length
        var_samples = self.sample_variance
        varies = var_samples > 1e-12 * np.maximum(self.mean**2, 1e-300)
        if not np.any(varies):
            return 1.0
        var_means = means[:, varies].var(axis=0, ddof=1)
        ratio = self.block_length * var_means / var_samples[varies]
        return float(max(1.0, np.median(ratio)))


def _flatten(result: F64 | Mapping[str, F64]) -> tuple[F64, Callable[[F64], Result]]:
    """Flatten an estimator result (array or dict of arrays) plus the inverse map."""
    if not isinstance(result, Mapping):
        arr = np.asarray(result, dtype=np.float64)
        return arr.reshape(-1), lambda flat: flat.reshape(arr.shape)
    keys = list(result)
    arrays = [np.asarray(result[k], dtype=np.float64) for k in keys]
    splits = np.cumsum([a.size for a in arrays])[:-1]

    def unflatten(flat: F64) -> dict[str, F64]:
        parts = np.split(flat, splits)
        return {k: p.reshape(a.shape) for k, p, a in zip(keys, parts, arrays, strict=True)}

    return np.concatenate([a.reshape(-1) for a in arrays]) if arrays else np.zeros(0), unflatten


def _jackknife_var(blocks: F64, length: int, estimator: Estimator) -> F64 | None:
    """Delete-one-block jackknife variance (flattened) for equal blocks; None if < 2 blocks."""
    m = blocks.shape[0]
    if m < 2:
        return None
    loo = (blocks.sum(axis=0) - blocks) / ((m - 1) * length)
    thetas = np.stack([_flatten(estimator(row))[0] for row in loo])
    with np.errstate(invalid="ignore"):
        return (m - 1) / m * ((thetas - thetas.mean(axis=0)) ** 2).sum(axis=0)


def _groups(result: F64 | Mapping[str, F64]) -> dict[str, slice]:
    """The flat slice of each output of an estimator result (one group for an array)."""
    if not isinstance(result, Mapping):
        return {"": slice(0, np.asarray(result).size)}
    out, start = {}, 0
    for key, value in result.items():
        size = np.asarray(value).size
        out[key] = slice(start, start + size)
        start += size
    return out


def _levels(acc: BlockAccumulator, estimator: Estimator,
            min_blocks: int) -> tuple[list[int], list[int], list[F64]]:
    """(block lengths, block counts, flat errors) of the blocking curve: the stored blocks,
    then merged pairwise while at least ``min_blocks`` remain (the first level always)."""
    blocks, length = acc.block_sums, acc.block_length
    lengths, counts, errors = [], [], []
    while blocks.shape[0] >= 2 and (not errors or blocks.shape[0] >= min_blocks):
        var = _jackknife_var(blocks, length, estimator)
        lengths.append(length)
        counts.append(blocks.shape[0])
        errors.append(np.sqrt(var * (blocks.shape[0] * length / acc.n_samples)))
        m = blocks.shape[0] // 2
        blocks, length = blocks[: 2 * m : 2] + blocks[1 : 2 * m : 2], 2 * length
    return lengths, counts, errors


def _g_exponential(b: F64, tau: float) -> F64:
    """Statistical inefficiency of blocks b samples long for exponential correlations
    ρ^k, ρ = exp(−1/τ): 1 + 2 Σ_{k<b} (1 − k/b) ρ^k in closed form (1 at b = 1, 2τ_int + ...
    → (1 + ρ)/(1 − ρ) for b ≫ τ)."""
    rho = np.exp(-1.0 / tau)
    return (1 + rho) / (1 - rho) - 2 * rho * (1 - rho**b) / (b * (1 - rho) ** 2)


def _g_power(b: F64, alpha: float) -> F64:
    """Inefficiency rising as a power of the block length, g ∝ b^α (no plateau)."""
    return b**alpha


def _measured(g: Callable[[F64], F64], b: F64, n: int) -> F64:
    """Expected blocking-curve value at block length b in a run of n samples: block means
    scatter about the run's own mean, so E[b s_b²/σ²] = (n g(b) − b g(n)) / (n − b). A curve
    still rising at b ~ n therefore bends over early; fitting this, not g, undoes it."""
    b = np.minimum(b, 0.5 * n)
    return (n * g(b) - b * g(np.float64(n))) / (n - b)


def _factor(g: Callable[[F64], F64], b0: float, n: int) -> float:
    """Variance factor g(n) / g_measured(b₀) that turns the finest level's error into the
    error of the run's mean under the inefficiency model g."""
    return float(g(np.float64(n)) / _measured(g, np.asarray([b0]), n)[0])


def _inefficiency(lengths: list[int], counts: list[int], ratios: list[float], elements: int,
                  n_samples: int) -> dict:
    """Fit the blocking curve ``ratios`` (r_l at block lengths ``lengths`` with ``counts``
    blocks, the median over ``elements`` values, r_0 = 1) and extrapolate it to one block of
    the whole run. Two one-parameter models of the run's statistical inefficiency g(b),
    each seen through the run's finite length (:func:`_measured`): exponential correlations
    (time τ) and a power law g ∝ b^α. Weights: a block variance of m blocks has relative
    variance 2/(m − 1), a median over the elements π/2 of a mean's. The exponential is taken
    unless the power law fits clearly better (χ² lower by more than 2). Returns the variance
    factor g(n)/g_measured(b₀) the finest errors need, the model, its parameter, and whether
    the errors converged: the exponential fits with τ_int = g(∞)/2 at most n/20 samples (else
    the factor is capped at τ_int = n/5 and the reason given)."""
    from scipy.optimize import minimize_scalar

    n = int(n_samples)
    b = np.asarray(lengths, float)
    r = np.maximum(np.asarray(ratios, float), 1e-3)
    if len(r) < 2:
        return {"factor": 1.0, "model": "none", "tau": float("nan"), "converged": False,
                "reason": "fewer than two levels of blocks"}
    weights = (np.asarray(counts[1:], float) - 1) / 2 * max(elements, 1) / (np.pi / 2)

    def chi2(g: Callable[[F64], F64]) -> float:
        model = _measured(g, b, n)
        if not np.all(model > 0):
            return np.inf
        return float(np.sum(weights * (np.log(r[1:]) - np.log(model[1:] / model[0])) ** 2))

    fits = {}
    exp_fit = minimize_scalar(lambda lt: chi2(lambda x: _g_exponential(x, np.exp(lt))),
                              bounds=(np.log(0.05), np.log(100.0 * n)), method="bounded")
    tau = float(np.exp(exp_fit.x))
    fits["exponential"] = (exp_fit.fun, lambda x: _g_exponential(x, tau))
    pow_fit = minimize_scalar(lambda a: chi2(lambda x: _g_power(x, a)), bounds=(0.0, 0.9),
                              method="bounded")
    alpha = float(pow_fit.x)
    fits["power"] = (pow_fit.fun, lambda x: _g_power(x, alpha))
    model = "power" if pow_fit.fun < exp_fit.fun - _MARGIN else "exponential"
    tau_int = 0.5 * float(_g_exponential(np.float64(1e12), tau))
    if model == "power":
        converged, reason = False, f"blocking curve still rising as b^{alpha:.2f}"
    else:
        converged = tau_int <= _TAU_LIMIT * n
        reason = "" if converged else (
            f"correlation time {tau_int:.0f} samples > run/20 = {_TAU_LIMIT * n:.0f}")
    factor = _factor(fits[model][1], b[0], n)
    if not converged:
        # far beyond what the run resolves the extrapolation is a guess that diverges as the
        # slow part cancels from the run's own curve: quote at most the error a correlation
        # time of n/5 would give (flagged; a lower bound when the correlation is longer)
        factor = min(factor, _factor(lambda x: _g_exponential(x, _TAU_CAP * n), b[0], n))
    return {"factor": max(1.0, factor), "model": model, "alpha": alpha, "tau": tau_int,
            "converged": converged, "reason": reason}


def jackknife_report(acc: BlockAccumulator, estimator: Estimator,
                     min_blocks: int = MIN_BLOCKS,
                     blocking: bool = True) -> tuple[Result, Result, dict]:
    """``(estimate, error, report)``: :func:`jackknife` with its blocking figures, per output
    (each key of a dict estimator; ``""`` for an array): ``block_length`` at the plateau,
    ``inefficiency`` (the variance ratio r applied), ``converged`` and
    ``effective_samples`` = n / (g₀ r) (module docstring). ``blocking`` False: the stored
    blocks' errors as they are (blocks that are not consecutive samples of a stationary
    series, e.g. chunks built to be independent)."""
    if acc.n_samples == 0:
        raise ValueError("no samples accumulated")
    with np.errstate(invalid="ignore", divide="ignore"):
        result = estimator(acc.mean)
        flat, unflatten = _flatten(result)
        lengths, counts, errors = _levels(acc, estimator, min_blocks if blocking else 10**9)
    if not errors:
        nan = np.full_like(flat, np.nan)
        return unflatten(flat), unflatten(nan), {}
    err = errors[0].copy()
    g0 = acc.inefficiency()
    report = {}
    for key, part in _groups(result).items():
        base = errors[0][part]
        ok = np.isfinite(base) & (base > 0)
        ratios = [1.0]
        for level in errors[1:]:
            with np.errstate(invalid="ignore", divide="ignore"):
                r = (level[part][ok] / base[ok]) ** 2
            r = r[np.isfinite(r)]
            ratios.append(float(np.median(r)) if r.size else 1.0)
        fit = _inefficiency(lengths, counts, ratios, int(ok.sum()), acc.n_samples)
        factor = fit["factor"]
        err[part] = base * np.sqrt(factor)
        report[key] = {"block_length": lengths[int(np.argmax(ratios))],
                       "blocks": counts[int(np.argmax(ratios))], "inefficiency": factor,
                       "converged": fit["converged"], "model": fit["model"],
                       "correlation_time": fit["tau"], "reason": fit["reason"],
                       "effective_samples": acc.n_samples / (g0 * factor)}
    return unflatten(flat), unflatten(err), report


def error_figures(report: Mapping[str, Mapping]) -> dict:
    """A report's figures over all outputs, as attributes of a results group: the longest
    block the errors needed, the largest variance factor, the fewest effective independent
    samples, whether every output's errors converged, and the outputs whose did not, with the
    reason ("name: reason; ...", empty when all did)."""
    if not report:
        return {}
    figures = list(report.values())
    return {"error_block_length": max(f["block_length"] for f in figures),
            "error_inefficiency": max(f["inefficiency"] for f in figures),
            "effective_samples": min(f["effective_samples"] for f in figures),
            "errors_converged": all(f["converged"] for f in figures),
            # which outputs are lower bounds, and why (HDF5 attributes hold one string)
            "errors_unconverged_fields": "; ".join(
                f"{key}: {f['reason']}" for key, f in report.items() if not f["converged"])}


def jackknife(acc: BlockAccumulator, estimator: Estimator,
              blocking: bool = True) -> tuple[Result, Result]:
    """Estimate ``estimator(mean)`` and its standard error by delete-one-block jackknife,
    with blocks as long as the blocking curve shows the correlation needs (module
    docstring; ``blocking`` False: the stored blocks as they are). ``estimator`` maps a mean
    sample vector to an array or to a dict of arrays; the return value is ``(estimate,
    error)`` of the same structure. Errors are NaN with < 2 blocks."""
    est, err, _report = jackknife_report(acc, estimator, blocking=blocking)
    return est, err


def blocking_curve(
    acc: BlockAccumulator, estimator: Estimator, min_blocks: int = 4
) -> tuple[np.ndarray, F64]:
    """Jackknife error versus block length, merging the stored blocks pairwise further.

    Returns ``(block_lengths, errors)`` with errors of shape ``(levels, n_flat)``; a
    plateau in ``errors`` as the block length grows signals blocks longer than the
    correlation time (the Flyvbjerg-Petersen criterion). Levels with fewer than
    ``min_blocks`` blocks are omitted.
    """
    blocks, length = acc.block_sums, acc.block_length
    lengths, errors = [], []
    with np.errstate(invalid="ignore", divide="ignore"):
        while blocks.shape[0] >= max(min_blocks, 2):
            var = _jackknife_var(blocks, length, estimator)
            lengths.append(length)
            errors.append(np.sqrt(var * (blocks.shape[0] * length / acc.n_samples)))
            m = blocks.shape[0] // 2
            blocks, length = blocks[: 2 * m : 2] + blocks[1 : 2 * m : 2], 2 * length
    n = _flatten(estimator(acc.mean))[0].size
    return np.asarray(lengths), np.asarray(errors).reshape(len(lengths), n)


def series_mean(values: ArrayLike, max_blocks: int = 32) -> tuple[float, float]:
    """Mean of a correlated scalar series and its error: a ``BlockAccumulator`` of
    ``max_blocks`` blocks and the jackknife with the block length the blocking curve asks for
    (module docstring). Non-finite samples are dropped; (NaN, NaN) without any."""
    v = np.asarray(values, float).ravel()
    v = v[np.isfinite(v)]
    if v.size == 0:
        return float("nan"), float("nan")
    acc = BlockAccumulator(1, max_blocks)
    for x in v:
        acc.add(np.array([x]))
    est, err = jackknife(acc, lambda mean: mean)
    return float(np.ravel(est)[0]), float(np.ravel(err)[0])


def split_mean(values: ArrayLike, blocks: int = 10) -> tuple[float, float]:
    """Mean of a scalar series and its error from ``blocks`` contiguous block means taken as
    independent (std of the block means / √blocks): for series whose blocks are known to be
    longer than the correlation time (e.g. a run's production split in 8-10 parts).
    Non-finite samples are dropped; with fewer samples than blocks the error is NaN; a
    constant series (round-off only) has error 0."""
    v = np.asarray(values, float).ravel()
    v = v[np.isfinite(v)]
    if v.size < max(blocks, 2):
        return (float(v.mean()) if v.size else float("nan")), float("nan")
    means = np.array([b.mean() for b in np.array_split(v, blocks)])
    mean = float(v.mean())
    err = float(means.std(ddof=1) / np.sqrt(blocks))
    return mean, (err if err > 1e-12 * abs(mean) else 0.0)
