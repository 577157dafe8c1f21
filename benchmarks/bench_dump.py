"""Dump ingestion: numpy fast path vs the MDAnalysis reader (particle-frames per second).

Run: /tmp/venv/bin/python benchmarks/bench_dump.py [--n 30000] [--frames 20] [--passes 3]
Writes a synthetic demstudy-format custom dump (columns id type radius x y z vx vy vz
omegax omegay omegaz, ``%.17g`` as ``write_dump ... format float %.17g``; 3D spheres, d = 1,
random positions and Maxwellian velocities) to a temporary file, then times full passes of
``read_dump`` (MDAnalysis) and ``read_dump_fast`` (numpy) that build every Frame.
Prints Markdown rows (best of ``--passes``). No assertions.
"""

from __future__ import annotations

import argparse
import io
import tempfile
import time
from pathlib import Path

import numpy as np

from demstudy.io.dump import read_dump, read_dump_fast


def write_dump(path: Path, n: int, frames: int, seed: int = 0) -> None:
    rng = np.random.default_rng(seed)
    side = (n * np.pi / 6 / 0.3) ** (1 / 3)
    with open(path, "w") as fh:
        for f in range(frames):
            data = np.column_stack([
                np.arange(1, n + 1), np.ones(n), np.full(n, 0.5), rng.uniform(0, side, (n, 3)),
                rng.normal(size=(n, 3)), rng.normal(size=(n, 3)),
            ])
            fh.write(f"ITEM: TIMESTEP\n{1000 * f}\nITEM: NUMBER OF ATOMS\n{n}\n"
                     "ITEM: BOX BOUNDS pp pp pp\n" + f"0 {side!r}\n" * 3 +
                     "ITEM: ATOMS id type radius x y z vx vy vz omegax omegay omegaz\n")
            buf = io.StringIO()
            np.savetxt(buf, data, fmt=["%d", "%d"] + ["%.17g"] * 10)
            fh.write(buf.getvalue())


def rate(reader, path: Path, n: int, passes: int) -> tuple[float, int]:
    best = 0.0
    for _ in range(passes):
        t0 = time.perf_counter()
        count = sum(1 for _ in reader(path, 3, dt=0.001))
        best = max(best, count * n / (time.perf_counter() - t0))
    return best, count


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=int, default=30000)
    p.add_argument("--frames", type=int, default=20)
    p.add_argument("--passes", type=int, default=3)
    args = p.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "bench.dump"
        write_dump(path, args.n, args.frames)
        size = path.stat().st_size / 1e6
        slow, frames = rate(read_dump, path, args.n, args.passes)
        fast, frames_fast = rate(read_dump_fast, path, args.n, args.passes)
        assert frames == frames_fast == args.frames
    print(f"dump: {args.n} particles × {args.frames} frames, {size:.0f} MB\n")
    print("| reader | particle-frames/s | speed-up |")
    print("|---|---|---|")
    print(f"| read_dump (MDAnalysis) | {slow:.3g} | 1.0 |")
    print(f"| read_dump_fast (numpy) | {fast:.3g} | {fast / slow:.1f} |")


if __name__ == "__main__":
    main()
