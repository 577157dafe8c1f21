"""Speed of the LGD step (Gutt 1989): node-updates per second (nxt·nyt·steps / wall time) of
the native core and of the numpy reference, against the goal of 2 × 10^7 per core.

Run: .venv/bin/python benchmarks/lgd_speed.py [--repeats 5] [--steps 200]

Units: the listing's integers (offsets idl/4096 = 1/4096 "cm", velocities 1/256 cm/s, ticks
1/65536 s); no dimensionless conversion is needed for a speed. Scenes (one core, in place):
* obstacle-like: 288 × 130 lattice, random fill of the open rows at density 0.4, gravity
  igy = −8 (the only g the thesis gives, Poiseuille), e1 = .75, e2 = .9375 (iep1 = iew1 = 12,
  iep2 = iew2 = 15 with ke = 16) and c_b = √(2gd) → icb = 4·√(2·8·4096) = 1024 (digest
  §3.4, §3.14); started at rest and run 100 steps before timing, so it is settling;
* elastic gas: 288 × 130, density 0.124 (the thesis's gas box), e = 1 everywhere, no
  gravity, random speeds up to 4096 (1/256 cm/s);
* the reference: the obstacle-like settings on a 48 × 26 lattice (numpy is ~10^3× slower).
The cases run interleaved ``--repeats`` times in one session (a shared machine's drift hits
all alike); each prints the median and range. No assertions.
"""

from __future__ import annotations

import argparse
import datetime
import platform
import statistics
import time

import numpy as np

from demstudy.engines.lgd import core
from demstudy.engines.lgd.lattice import MOVABLE, WALL, Lattice, LgdParams
from demstudy.simulation.forecast import cpu_model

GOAL = 2e7  # node-updates per second on one core (issue: the thesis's 512 nodes did ~2e5)


def scene(kind: str, nxt: int = 288, nyt: int = 130, seed: int = 1):
    rng = np.random.default_rng(seed)
    lat = Lattice.empty(nxt, nyt)
    lat.mlp[0] = lat.mlp[-1] = WALL
    inner = lat.mlp[1:-1]
    if kind == "gas":
        inner[rng.random(inner.shape) < 0.124] = MOVABLE
        m = lat.mlp == MOVABLE
        lat.ivx[m], lat.ivy[m] = rng.integers(-4096, 4097, (2, int(m.sum())))
        par = LgdParams(nxt=nxt, nyt=nyt, iep1=16, iep2=16, iew1=16, iew2=16)
        warm = 10
    else:
        inner[rng.random(inner.shape) < 0.4] = MOVABLE
        par = LgdParams(nxt=nxt, nyt=nyt, igy=-8, iep1=12, iep2=15, iew1=12, iew2=15,
                        icb=1024)
        warm = 100
    core.prepare(lat, par)
    return lat, par, warm


def rate(lat: Lattice, par: LgdParams, steps: int, impl: str) -> float:
    t0 = time.perf_counter()
    core.run_steps(lat, par, steps, impl=impl)
    return lat.mlp.size * steps / (time.perf_counter() - t0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--steps", type=int, default=200, help="native steps per measurement")
    ap.add_argument("--ref-steps", type=int, default=5, help="reference steps per measurement")
    args = ap.parse_args()
    cases = {"native, obstacle-like 288x130": ("obstacle", {}, "native", args.steps),
             "native, elastic gas 288x130": ("gas", {}, "native", args.steps),
             "reference, obstacle-like 48x26": ("obstacle", {"nxt": 48, "nyt": 26},
                                                "reference", args.ref_steps)}
    states = {}
    for name, (kind, size, _impl, _) in cases.items():
        lat, par, warm = scene(kind, **size)
        core.run_steps(lat, par, warm)  # native warm-up (fast) for every case
        states[name] = (lat, par)
    rates = {name: [] for name in cases}
    for _ in range(args.repeats):
        for name, (_, _, impl, steps) in cases.items():
            rates[name].append(rate(*states[name], steps, impl))
    print(f"machine: {cpu_model()}, Python {platform.python_version()}, "
          f"{datetime.date.today().isoformat()}; {args.repeats} interleaved repeats")
    print("| case | node-updates/s (median) | range | ratio to the 2e7 goal |")
    print("|---|---|---|---|")
    for name, values in rates.items():
        med = statistics.median(values)
        print(f"| {name} | {med:.3g} | {min(values):.3g} – {max(values):.3g} | "
              f"{med / GOAL:.2f} |")
    nat = statistics.median(rates["native, obstacle-like 288x130"])
    refr = statistics.median(rates["reference, obstacle-like 48x26"])
    print(f"native / reference (obstacle-like): {nat / refr:.0f}x")


if __name__ == "__main__":
    main()
