"""Wall-time forecast of a lattice (LGD) run: node-updates × this machine's measured cost per
node-update, plus the loop's cost per sample (a frame of every grain, the statistics).

Dimensionless particle units outside the integer core: d = 1, m = 1, g = 1 when gravity acts.
A lattice step costs the same whatever the grains do (every node is visited by the 9 × ntu
move templates and the 12 collision sweeps), so a run's cost is known before it starts when
its length is counted in steps (``run.unit = "steps"``, every thesis scene). A run counted in
time takes as many steps as its peak speed dictates (Δt = d / v_max), unknown in advance: no
forecast then. The costs are measured once on this machine (two short runs of the gas-box
and Couette presets through the loop, ~2 s) and cached with the other engines' (docs/forecast.md).
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from ...scene import Scene

__all__ = ["ACCURACY", "COSTS", "benchmark", "counts", "forecast_basis"]

#: the counts a lattice run's cost is fitted on: node-updates (nodes × steps, whatever
#: ``ntu``), grain-steps (grains × steps: moves and collisions cost more on a denser
#: lattice), grains × production samples (a frame of every grain and the statistics) and
#: the run's fixed cost (set-up, results file)
COSTS = ("node_update", "grain_step", "grain_sample", "run")
#: forecast against actual wall time over the thesis scenes (benchmarks/bench_lgd_forecast.py,
#: docs/benchmarks.md); re-measured tables update this one place
ACCURACY = {"factor": 2.3, "met": "12 of 12 lattice runs"}


def _steps(scene: Scene) -> int | None:
    run = scene.run
    if run.unit != "steps":
        return None
    return int(round(run.equilibration + run.production))


def counts(scene: Scene) -> dict[str, float] | None:
    """The counts of ``scene`` (None: a run counted in time, whose steps are unknown)."""
    steps = _steps(scene)
    if steps is None or scene.lattice is None:
        return None
    nodes = scene.lattice.nxt * scene.lattice.nyt
    samples = max(1, int(round(scene.run.production / scene.run.sample_interval)))
    return {"node_update": float(nodes * steps),
            "grain_step": float(steps * scene.n_particles),
            "grain_sample": float(samples * scene.n_particles), "run": 1.0}


def forecast_basis(scene: Scene) -> str:
    c = counts(scene)
    assert c is not None
    return (f"{scene.lattice.nxt}×{scene.lattice.nyt} nodes × {_steps(scene)} steps "
            f"= {c['node_update']:.3g} node-updates, "
            f"{int(round(c['grain_sample'] / max(scene.n_particles, 1)))} samples")


def benchmark() -> tuple[dict[str, float], str]:
    """Seconds per node-update, grain-step, grain-sample and run on this machine: four short
    runs of the gas-box and Couette presets through the loop (each count dominates one),
    fitted by non-negative least squares on relative errors."""
    from scipy.optimize import nnls

    from ...engines import get_backend
    from ...io.results import read_results
    from ...scene import load_scene
    from ...simulation import RunOptions, run_scene

    backend = get_backend("lgd")
    # (preset, steps, sample interval in steps): a dilute gas (12 % of the nodes hold a
    # grain) and a dense Couette cell (48 %), long runs, many samples, a nearly empty run
    cases = (("gas-box", 600, 300), ("couette-elastic-u4096", 1200, 600),
             ("gas-box", 60, 1), ("gas-box", 2, 2))
    rows, seconds, what = [], [], []
    for preset, steps, interval in cases:
        scene = load_scene(f"gutt1989/{preset}", [
            "run.equilibration=0", f"run.production={steps}",
            f"run.sample_interval={interval}", 'measure.statistics=["profiles"]'])
        with tempfile.TemporaryDirectory(prefix="demstudy-benchmark-") as tmp:
            options = RunOptions(out=Path(tmp) / "bench.h5", progress=False, isolate=True,
                                 plan=False)
            attrs = read_results(run_scene(scene, backend, options)).attrs
        rows.append([counts(scene)[k] for k in COSTS])
        seconds.append(float(attrs["wall_seconds"]))
        what.append(f"{preset}, {steps} steps, {steps // interval} samples: "
                    f"{seconds[-1]:.3g} s")
    a, b = np.array(rows, float), np.array(seconds)
    coef, _ = nnls(a / b[:, None], np.ones(len(b)))
    return dict(zip(COSTS, map(float, coef), strict=True)), "; ".join(what)


def seconds(costs: dict[str, Any], c: dict[str, float]) -> float:
    return float(sum(float(costs.get(k, 0.0)) * v for k, v in c.items()))
