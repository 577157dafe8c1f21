"""Event rate and memory of the event-driven engine (``--engine edmd``), elastic spheres.

Run: .venv/bin/python benchmarks/bench_edmd.py [--n 4000 32000 256000] [--seconds 10]
     [--system elastic|sheared] [--repeat 5]
Dimensionless particle units (d = 1, m = 1, T = 1). The issue-3 systems: elastic smooth hard
spheres at number density 0.5 (φ = 0.262), fully periodic cubic box, fcc start (N = 4 m³),
Maxwellian velocities with zero total momentum. Each N runs in a fresh child process:
a warm-up of 2 collisions per particle, then ``advance_to`` in chunks for ``--seconds`` of
wall time. Prints Markdown rows: events/s (collisions + cell crossings; with ``--repeat k``
the median and the range of k interleaved runs), collisions/s, ns per event, the engine's own
arrays in bytes per particle (``memory_bytes``) and the child's peak RSS growth per particle
(includes the numpy inputs; the largest of the runs). No assertions.
``--system sheared``: the issue's second system, inelastic smooth spheres (e = 0.9, TC model
t_c = 1e-5) under Lees–Edwards shear (rate 1) at the same density, started from the fcc
lattice with the linear profile u = y − L/2 on top of unit temperature; a warm-up of 2
collisions per particle, then the same measurement (the shear heats up and the inelasticity
cools: after the warm-up the temperature is near its steady value, ~ (γ̇ d)² × O(1)).
"""

from __future__ import annotations

import argparse
import json
import platform
import resource
import subprocess
import sys
import time

import numpy as np


def fcc(m: int, a: float) -> np.ndarray:
    basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]]) + 0.25
    grid = np.stack(np.meshgrid(*[np.arange(m)] * 3, indexing="ij"), -1).reshape(-1, 3)
    return ((grid[:, None, :] + basis[None]) * a).reshape(-1, 3)


def measure(n: int, seconds: float, system: str = "elastic", density: float = 0.5,
            seed: int = 1) -> dict:
    from demstudy._native import EventDriven

    np.random.default_rng(0).normal(size=8)  # load numpy's generator before the baseline
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # after the imports
    m = round((n / 4) ** (1 / 3))
    if 4 * m**3 != n:
        raise SystemExit(f"--n {n}: the fcc start needs N = 4 m^3")
    a = (4 / density) ** (1 / 3)
    x = fcc(m, a)
    rng = np.random.default_rng(seed)
    v = rng.normal(size=x.shape)
    v -= v.mean(axis=0)
    if system == "sheared":
        v[:, 0] += x[:, 1] - m * a / 2
        s = EventDriven(x, v, np.zeros_like(x), np.ones(n), np.ones(n), [m * a] * 3, 3,
                        e=0.9, tc=1e-5, shear_rate=1.0)
    else:
        s = EventDriven(x, v, np.zeros_like(x), np.ones(n), np.ones(n), [m * a] * 3, 3)
    del x, v
    t, dt = 0.0, 0.5  # ~5 collisions per particle per chunk: synchronising costs O(N)
    while s.collisions < 2 * n:  # warm-up: melt the lattice
        t += dt
        s.advance_to(t)
    e0, c0, w0 = s.events, s.collisions, time.perf_counter()
    while time.perf_counter() - w0 < seconds:
        t += dt
        s.advance_to(t)
    wall = time.perf_counter() - w0
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    events = s.events - e0
    return {"n": n, "events_per_s": events / wall, "collisions_per_s": (s.collisions - c0) / wall,
            "ns_per_event": 1e9 * wall / events, "engine_bytes": s.memory_bytes / n,
            "rss_bytes": (rss - rss0) / n, "events": events, "wall": wall,
            "cells": list(s.cells)}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=int, nargs="+", default=[4000, 32000, 256000])
    p.add_argument("--seconds", type=float, default=10.0)
    p.add_argument("--system", choices=["elastic", "sheared"], default="elastic")
    p.add_argument("--repeat", type=int, default=1,
                   help="measure every N this many times, interleaved (N1 N2 … N1 N2 …), and "
                        "print the median and the range of events/s: a virtual machine's speed "
                        "drifts by tens of per cent over minutes")
    p.add_argument("--child", type=int, help=argparse.SUPPRESS)
    args = p.parse_args()
    if args.child:
        print(json.dumps(measure(args.child, args.seconds, args.system)))
        return
    print(f"machine: {platform.processor() or platform.machine()}, {platform.system()}, "
          f"Python {platform.python_version()}; system: {args.system}")
    if args.repeat < 1:
        raise SystemExit(f"--repeat {args.repeat}: need at least 1")
    runs: dict[int, list[dict]] = {n: [] for n in args.n}
    for _ in range(args.repeat):
        for n in args.n:
            out = subprocess.run([sys.executable, __file__, "--child", str(n), "--seconds",
                                  str(args.seconds), "--system", args.system],
                                 capture_output=True, text=True, check=True)
            runs[n].append(json.loads(out.stdout.strip().splitlines()[-1]))
    print("| N | events/s (median) | range | collisions/s (median) | ns/event (median) | "
          "engine B/particle | peak RSS B/particle |")
    print("|---:|---:|---:|---:|---:|---:|---:|")
    for n, rs in runs.items():
        med = {k: float(np.median([r[k] for r in rs]))
               for k in ("events_per_s", "collisions_per_s", "ns_per_event")}
        ev = [r["events_per_s"] for r in rs]
        print(f"| {n} | {med['events_per_s']:.3g} | {min(ev):.3g}–{max(ev):.3g} | "
              f"{med['collisions_per_s']:.3g} | {med['ns_per_event']:.0f} | "
              f"{rs[0]['engine_bytes']:.0f} | {max(r['rss_bytes'] for r in rs):.0f} |",
              flush=True)


if __name__ == "__main__":
    main()
