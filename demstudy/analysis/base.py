"""Base class for frame-by-frame analyses (the MDAnalysis ``AnalysisBase`` pattern).

Subclasses implement ``_prepare()`` (allocate accumulators; ``self.first_frame`` is set),
``_single_frame(frame)`` (accumulate one :class:`~demstudy.io.frames.Frame`) and
``_conclude()`` (fill ``self.results`` and ``self.attrs``). Frames come either from an
iterable via :meth:`AnalysisBase.run`, or are pushed one at a time by an engine during a
run via :meth:`AnalysisBase.feed` and closed with :meth:`AnalysisBase.finish`.
Dimensionless particle units throughout: d = 1, m = 1.
"""

from __future__ import annotations

from collections.abc import Iterable
from itertools import islice
from typing import Any

import numpy as np

from demstudy.io.frames import Frame

__all__ = ["AnalysisBase", "bin_edges", "bin_index", "default_y_edges", "z_slab"]


class AnalysisBase:
    """Streaming analysis over :class:`Frame` objects.

    Attributes
    ----------
    results: dict of numpy arrays, filled by :meth:`finish`.
    attrs: dict of scalar/string metadata (HDF5 attributes), filled by :meth:`finish`.
    n_frames: number of frames accumulated so far.
    first_frame: the first frame fed (set before ``_prepare()`` is called).
    """

    def __init__(self, verbose: bool = False) -> None:
        self.verbose = verbose
        self.results: dict[str, np.ndarray] = {}
        self.attrs: dict[str, Any] = {}
        self.n_frames = 0
        self.first_frame: Frame | None = None
        self._finished = False

    # -- hooks -------------------------------------------------------------------------
    def _prepare(self) -> None:
        """Set up accumulators; called once, on the first frame."""

    def _single_frame(self, frame: Frame) -> None:
        """Accumulate one frame."""
        raise NotImplementedError

    def _conclude(self) -> None:
        """Turn the accumulators into ``self.results`` / ``self.attrs``."""

    # -- public API --------------------------------------------------------------------
    def feed(self, frame: Frame) -> None:
        """Accumulate one frame (an engine may call this during a run)."""
        if self._finished:
            raise RuntimeError(f"{type(self).__name__} is finished; create a new one")
        if self.first_frame is None:
            self.first_frame = frame
            self._prepare()
        self._single_frame(frame)
        self.n_frames += 1

    def finish(self) -> AnalysisBase:
        """Conclude after the last frame; returns ``self`` (see ``results``, ``attrs``)."""
        if self._finished:
            return self
        if self.n_frames == 0:
            raise ValueError(f"{type(self).__name__}: no frames were fed")
        self._conclude()
        self._finished = True
        return self

    def run(
        self,
        frames: Iterable[Frame],
        start: int | None = None,
        stop: int | None = None,
        step: int | None = None,
    ) -> AnalysisBase:
        """Feed ``frames[start:stop:step]`` and conclude; returns ``self``."""
        for frame in islice(frames, start, stop, step):
            self.feed(frame)
            if self.verbose and self.n_frames % 100 == 0:
                print(f"{type(self).__name__}: {self.n_frames} frames")
        return self.finish()


def bin_edges(lo: float, hi: float, bin_width: float) -> np.ndarray:
    """Equal bins over [lo, hi] of about ``bin_width`` (at least one): the profile grid of a
    scene's ``measure.bin_width`` between its walls or over its box."""
    n_bins = max(1, round((hi - lo) / bin_width))
    return lo + (hi - lo) / n_bins * np.arange(n_bins + 1)


def bin_index(edges: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Index of the bin [e_k, e_k+1) holding each x: −1 below the first edge, n_bins at or
    above the last (callers mask those)."""
    return np.searchsorted(edges, x, side="right") - 1


def default_y_edges(frame: Frame, period: float, n_bins: int) -> np.ndarray:
    """``n_bins`` equal bins along y over the frame's box (from its lower edge over one period
    when y is periodic)."""
    lo = float(np.asarray(frame.box_lo, float)[1])
    hi = lo + period if period else float(np.asarray(frame.box_hi, float)[1])
    return np.linspace(lo, hi, n_bins + 1)


def z_slab(frame: Frame, z: np.ndarray, n: int) -> np.ndarray:
    """Index of the slab (of ``n`` equal slabs of the periodic z length) holding each z:
    Malik's cells are y-bins split into such slabs."""
    lo = float(np.asarray(frame.box_lo, float)[2])
    length = float(np.asarray(frame.box_hi, float)[2]) - lo
    return np.minimum((np.mod(z - lo, length) / length * n).astype(np.intp), n - 1)
