"""Throughput of ProfileAnalysis and of the bare binning kernel (particle-frames per second).

Run: /tmp/venv/bin/python benchmarks/bench_profiles.py [--n 30000] [--frames 20] [--passes 5]
Dimensionless particle units (d = 1, m = 1); random ideal-gas frames at solid fraction 0.5,
monodisperse d = 1. Prints median and best per-frame rates (the best is what an idle core
does; the median includes whatever else runs on the machine). No assertions.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import numpy as np

from demstudy import _native
from demstudy.analysis.profiles import ProfileAnalysis
from demstudy.analysis.volumes import bin_overlaps
from demstudy.io.frames import Frame


def make_frames(n: int, dim: int, count: int, seed: int = 0) -> list[Frame]:
    rng = np.random.default_rng(seed)
    side = (n * (np.pi / 6 if dim == 3 else np.pi / 4) / 0.5) ** (1 / dim)  # phi = 0.5
    box = np.full(dim, side)
    nrot = 1 if dim == 2 else 3
    return [
        Frame(
            float(t),
            np.zeros(dim),
            box,
            rng.uniform(0, side, (n, dim)),
            rng.normal(size=(n, dim)),
            rng.normal(size=(n, nrot)),
            np.full(n, 0.5),
        )
        for t in range(count)
    ]


def frame_times(fn: Callable[[Frame], None], frames: list[Frame], passes: int) -> np.ndarray:
    """Wall time of each call fn(frame), over `passes` sweeps of the frames."""
    times = []
    for _ in range(passes):
        for f in frames:
            t0 = time.perf_counter()
            fn(f)
            times.append(time.perf_counter() - t0)
    return np.asarray(times)


def report(label: str, n: int, times: np.ndarray) -> None:
    print(
        f"{label:44s} median {n / np.median(times) / 1e6:6.1f} M/s   "
        f"best {n / times.min() / 1e6:6.1f} M/s"
    )


def kernel_call(nvalues: int, dim: int) -> Callable[[Frame], None]:
    """The generic kernel alone on F = nvalues columns, bins of width ~1, open grid."""
    state: dict[str, np.ndarray] = {}

    def call(f: Frame) -> None:
        side = float(f.box_hi[1])
        nbins = int(side)
        if not state:
            state["vals"] = np.ones((f.n, nvalues))
            state["v"], state["s"] = np.zeros(nbins), np.zeros((nbins, nvalues))
        coord = np.ascontiguousarray(f.position[:, 1])
        bin_overlaps(
            coord,
            f.radius,
            state["vals"],
            0.0,
            side / nbins,
            nbins,
            dim,
            0.0,
            state["v"],
            state["s"],
        )

    return call


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--n", type=int, default=30_000)
    ap.add_argument("--frames", type=int, default=20)
    ap.add_argument("--passes", type=int, default=5)
    args = ap.parse_args()
    print(
        f"N = {args.n} particles, {args.frames} frames x {args.passes} passes, one thread, "
        f"kernels: {_native.simd_variant()}; rates in particle-frames/s per feed() call"
    )
    for dim in (3, 2):
        frames = make_frames(args.n, dim, args.frames)
        side = float(frames[0].box_hi[1])
        for width in (1.0, 0.25):
            for period in (0.0, side):
                pa = ProfileAnalysis(dim=dim, bin_width=width, period=period)
                times = frame_times(pa.feed, frames, args.passes)
                pa.finish()
                label = "periodic" if period else "open"
                report(f"ProfileAnalysis {dim}D width {width} {label}", args.n, times)
        times = frame_times(kernel_call(8, dim), frames, args.passes)
        report(f"bin_overlaps    {dim}D F = 8, width ~1, open", args.n, times)


if __name__ == "__main__":
    main()
