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
√(g(n)/g(b₀)): the curve's highest point where it levelled off (its last rise within twice
the median's noise; "converged"), else its power law r ∝ b^α over the last levels
extrapolated to b = n ("not converged": correlations as long as an eighth of the run, or
slowly growing ones, as in sheared gases, where bands drift slowly; replicas or longer runs
check it). Checked against processes of known error (tests/test_blocking.py); what it does
for sheared granular gases, measured against independent replicas: docs/results-format.md,
"Statistical errors".
:func:`jackknife_report` returns these figures: the plateau's block length, the
factor r, convergence, and the effective number of independent samples n / (g₀ r), g₀ the
statistical inefficiency of the stored blocks themselves (from the samples' own variance).
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


def _inefficiency(lengths: list[int], counts: list[int], ratios: list[float], elements: int,
                  n_samples: int) -> tuple[float, bool]:
    """(factor, converged): the variance factor g(n)/g(b₀) the finest errors need, from the
    blocking curve ``ratios`` (r_l at block lengths ``lengths``, with ``counts`` blocks, the
    median over ``elements`` values). Levelled off (its last rise within twice the median's
    noise): the curve's highest point. Still rising: extrapolated to one block of the whole
    run (the variance of the run's mean) along the power law of its last levels, r ∝ b^α
    with 0 <= α <= 1: conservative for exponentially decaying correlations, as a run too
    short for them has to be."""
    if len(ratios) < 2:
        return 1.0, False
    noise = 1.25 * np.sqrt(2.0 / max(counts[-1] - 1, 1)) / np.sqrt(max(elements, 1))
    converged = ratios[-1] <= ratios[-2] * (1.0 + 2.0 * noise)
    x, y = np.log(np.asarray(lengths, float)), np.log(np.maximum(ratios, 1e-300))
    alpha = float(np.clip(np.polyfit(x, y, 1)[0], 0.0, 1.0)) if not converged else 0.0
    return max(1.0, max(ratios), ratios[-1] * (n_samples / lengths[-1]) ** alpha), converged


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
        factor, converged = _inefficiency(lengths, counts, ratios, int(ok.sum()),
                                          acc.n_samples)
        err[part] = base * np.sqrt(factor)
        report[key] = {"block_length": lengths[int(np.argmax(ratios))],
                       "blocks": counts[int(np.argmax(ratios))], "inefficiency": factor,
                       "converged": converged,
                       "effective_samples": acc.n_samples / (g0 * factor)}
    return unflatten(flat), unflatten(err), report


def error_figures(report: Mapping[str, Mapping]) -> dict:
    """A report's figures over all outputs, as attributes of a results group: the longest
    block the errors needed, the largest variance factor, the fewest effective independent
    samples, and whether every output's blocking curve levelled off."""
    if not report:
        return {}
    figures = list(report.values())
    return {"error_block_length": max(f["block_length"] for f in figures),
            "error_inefficiency": max(f["inefficiency"] for f in figures),
            "effective_samples": min(f["effective_samples"] for f in figures),
            "errors_converged": all(f["converged"] for f in figures)}


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
