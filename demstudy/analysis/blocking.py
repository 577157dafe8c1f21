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
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["BlockAccumulator", "Estimator", "blocking_curve", "jackknife"]

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

    def add(self, sample: ArrayLike) -> None:
        """Add one sample vector (shape ``(n_values,)``; other shapes are raveled)."""
        x = np.asarray(sample, dtype=np.float64).reshape(-1)
        if x.shape[0] != self.n_values:
            raise ValueError(f"sample has {x.shape[0]} values, expected {self.n_values}")
        self._partial += x
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


def jackknife(acc: BlockAccumulator, estimator: Estimator) -> tuple[Result, Result]:
    """Estimate ``estimator(mean)`` and its standard error by delete-one-block jackknife.

    ``estimator`` maps a mean sample vector to an array or to a dict of arrays; the return
    value is ``(estimate, error)`` of the same structure. Errors are NaN with < 2 blocks.
    """
    if acc.n_samples == 0:
        raise ValueError("no samples accumulated")
    with np.errstate(invalid="ignore", divide="ignore"):
        flat, unflatten = _flatten(estimator(acc.mean))
        var = _jackknife_var(acc.block_sums, acc.block_length, estimator)
    if var is None:
        err = np.full_like(flat, np.nan)
    else:
        err = np.sqrt(var * (acc.n_blocks * acc.block_length / acc.n_samples))
    return unflatten(flat), unflatten(err)


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
