"""Gutt's elastic Couette flow on the LGD engine (thesis §3.15, fig. 3.21b): row profiles of
the mean velocity and of the thermal velocity, by window, layout and definition.

Units: speeds in the wall speed U (the walls move at ∓U; U = lattice.speed_scale = 4096 of
the listing's integer units), heights y in lattice spacings d (row R at y = (R − 1)·√3/2),
time in steps (the thesis reports step counts).

Why (docs/lgd-review.md): ``demstudy run gutt1989/couette-elastic-u4096`` followed by the
``profiles`` analysis shows a thermal-velocity dip at mid-channel, where the thesis has a
peak. This script separates the three things that matter:

* the window: the scene samples steps 32..1024 from rest (equilibration 0), during the
  start-up; 544..1024 is later, 4128..8192 is steady (the wall shear has settled);
* the definition: "pooled" is the profiles analysis's (each row's fluctuations about the
  window's mean of that row, i.e. √(2T)); "instant" is Gutt's av3 per row and per sample,
  √(⟨v²⟩ − ⟨vx⟩² − ⟨vy⟩²) over the grains of the row, averaged over the window's samples;
* the layout: "uniform" is the presets' former layout, every other row full uniformly along
  x, so the lattice is periodic with period 6 columns and stays so
  (tests/test_lgd_listing_order.py): 32 copies of a 6-column system, whose rows hold a few
  independent grains. "random" is the preset's layout since: the same number of grains at
  rest on open nodes drawn by its seeded random fill ([[lattice.fill]]; an assumption too).

Run: ``python analysis/lgd_couette_rows.py [--png docs/figures/lgd-couette-rows.png]``
(about 15 s); it prints the profiles in 10 bins of 6 rows, bottom to top.
"""

from __future__ import annotations

import argparse
import dataclasses

import numpy as np

from demstudy.engines.lgd import core
from demstudy.engines.lgd.effects import lattice_setup
from demstudy.engines.lgd.problem import build_lattice
from demstudy.scene import load_scene

SCENE = "gutt1989/couette-elastic-u4096"
EVERY = 32  # steps between samples, as the preset's run.sample_interval
STEPS = 8192
WINDOWS = {"32-1024 (preset)": (32, 1024), "544-1024": (544, 1024),
           "4128-8192 (steady)": (4128, 8192)}
BIN = 6  # rows per printed bin


def couette(layout: str):
    """The preset's lattice and parameters; ``layout`` 'uniform' (every other row full) or
    'random' (the preset's seeded fill)."""
    sections = {}
    if layout == "uniform":
        sections = {"lattice": {"fill": None, "initial": [
            {"md": 2, "x1": 1, "y1": iy, "x2": 192, "y2": iy} for iy in range(2, 62, 2)]}}
    setup = lattice_setup(load_scene(SCENE, **sections))
    par = dataclasses.replace(setup.params)
    lat = build_lattice(par, setup.lines)
    core.prepare(lat, par)
    return lat, par, setup.units.speed


def row_moments(lat) -> np.ndarray:
    """(4, nyt): per row the grain count and the sums of vx, vy and v² (integer units)."""
    g = lat.mlp > 0
    return np.stack([g.sum(1), np.where(g, lat.ivx, 0).sum(1), np.where(g, lat.ivy, 0).sum(1),
                     np.where(g, lat.ivx ** 2 + lat.ivy ** 2, 0).sum(1)]).astype(float)


def thermal(m: np.ndarray, speed: float) -> tuple[np.ndarray, np.ndarray]:
    """(mean vx, thermal velocity) of moments m (4, ...), in units of U."""
    n = np.maximum(m[0], 1)
    vx, vy, v2 = m[1] / n / speed, m[2] / n / speed, m[3] / n / speed ** 2
    return vx, np.sqrt(np.maximum(v2 - vx ** 2 - vy ** 2, 0.0))


def study(layout: str) -> dict:
    lat, par, speed = couette(layout)
    samples, shear = [], []
    for _ in range(STEPS // EVERY):
        log = core.run_steps(lat, par, EVERY)
        samples.append(row_moments(lat))
        shear.append((log["is1"].sum(), log["is2"].sum()))
    samples, shear = np.array(samples), np.array(shear, float)
    steps = EVERY * np.arange(1, len(samples) + 1)
    out = {"periodic6": bool((np.roll(lat.ivx, 6, 1) == lat.ivx).all())}
    for name, (lo, hi) in WINDOWS.items():
        pick = (steps >= lo) & (steps <= hi)
        vx, pooled = thermal(samples[pick].sum(0), speed)
        instant = np.mean([thermal(s, speed)[1] for s in samples[pick]], axis=0)
        # wall shear: Δv the walls absorb per step and wall particle, in U (is1 > 0, is2 < 0)
        per_step = shear[pick].sum(0) / (EVERY * pick.sum() * lat.mlp.shape[1] * speed)
        out[name] = {"vx": vx, "pooled": pooled, "instant": instant, "shear": per_step}
    return out


def bins(a: np.ndarray) -> np.ndarray:
    open_rows = a[1:-1]  # rows 2..nyt−1
    return open_rows.reshape(-1, BIN).mean(1)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--png", help="also plot the thermal and mean velocity profiles here")
    args = ap.parse_args()
    np.set_printoptions(precision=3, suppress=True, linewidth=120)
    results = {layout: study(layout) for layout in ("uniform", "random")}
    for layout, res in results.items():
        print(f"== layout {layout}: 6-column periodic after {STEPS} steps: {res['periodic6']}")
        for name in WINDOWS:
            r = res[name]
            print(f"  steps {name}: wall shear per step (is1, is2)/(nxt·U) = "
                  f"{r['shear'][0]:.5f}, {r['shear'][1]:.5f}")
            for key in ("vx", "pooled", "instant"):
                print(f"    {key:8s}", bins(r[key]))
    if args.png:
        plot(results, args.png)


def plot(results: dict, path: str) -> None:
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    fig, (ax_t, ax_v) = plt.subplots(1, 2, figsize=(10, 4.6), sharey=True)
    nyt = len(next(iter(results.values()))[next(iter(WINDOWS))]["vx"])
    yb = bins((np.arange(1, nyt + 1) - 1) * np.sqrt(3) / 2)  # row R at (R − 1)·√3/2
    styles = {"uniform": "-", "random": "--"}
    colours = dict(zip(WINDOWS, ("tab:red", "tab:orange", "tab:blue"), strict=True))
    for layout, res in results.items():
        for name in WINDOWS:
            label = f"{layout}, steps {name}"
            ax_t.plot(bins(res[name]["pooled"]), yb, styles[layout], color=colours[name],
                      marker="o", ms=3, label=label)
            ax_v.plot(bins(res[name]["vx"]), yb, styles[layout], color=colours[name],
                      marker="o", ms=3)
    ax_t.set_xlabel("thermal velocity √(2T) per row (pooled), units of U")
    ax_v.set_xlabel("mean velocity ⟨vx⟩ per row, units of U")
    ax_t.set_ylabel("height y above the lower wall row, d")
    ax_t.set_xlim(0.15, 0.5)
    ax_v.axvline(0, color="0.7", lw=0.8)
    fig.legend(loc="lower center", ncol=3, fontsize=8, frameon=False)
    fig.suptitle("LGD elastic Couette (e_pp = 1, e_pw = 0.75, walls ∓4096): 6-row bins",
                 fontsize=10)
    fig.tight_layout(rect=(0, 0.13, 1, 1))
    fig.savefig(path, dpi=120)


if __name__ == "__main__":
    main()
