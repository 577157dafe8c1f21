"""Seed ensembles of a sheared cell, engine against engine: temperature and wall power.

Each argument is one ensemble, ``label=glob[,glob…]`` (results files of the same scene,
other seeds).
Per ensemble: the mean over its runs, with the standard error from their scatter, of the
mean temperature T, its x and y components and the rotational temperature, the upper
wall's shear force (the power the moving wall puts in, per unit wall speed), T per unit of
that power, and the wall slips 1 - u(top bin) and u(bottom bin). Then each ensemble
against the first: relative differences ± their errors and Welch's p-value.

One run's T wanders with the cell's wall slip over times longer than a run (about ±6-9 %
per run here), so four seeds can show a "3σ" gap by luck: use 15 or more per ensemble.
Dimensionless particle units: d = 1, m = 1; the wall speed U = 1 sets the time scale.

    python analysis/seed_ensemble.py 'edmd=runs/edmd-*.h5' 'lammps=runs/lmp-*.h5' ...
"""

from __future__ import annotations

import argparse
import glob
import sys

import numpy as np
from scipy import stats

import demstudy as ds

FIELDS = ("T", "T_x", "T_y", "T_rot", "power", "T/power", "slip_top", "slip_bottom")


def measures(path: str) -> dict[str, float]:
    """One run's production means (wall force averaged after the equilibration)."""
    res = ds.load(path)
    prof, ts = res.profiles, res.timeseries
    time = np.asarray(ts["time"])
    production = time >= float(res.attrs["equilibration_end"])
    power = -float(np.mean(np.asarray(ts["wall_force_upper"])[production, 0]))
    temperature = float(prof["mean_temperature"])
    components = np.asarray(prof["temperature_components"]).mean(axis=0)
    velocity = np.asarray(prof["velocity"])[:, 0]
    return {"T": temperature, "T_x": components[0], "T_y": components[1],
            "T_rot": float(np.mean(prof["rotational_temperature"])), "power": power,
            "T/power": temperature / power, "slip_top": 1.0 - velocity[-1],
            "slip_bottom": velocity[0]}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("ensembles", nargs="+", metavar="LABEL=GLOB[,GLOB]")
    args = parser.parse_args(argv)
    groups: dict[str, dict[str, np.ndarray]] = {}
    for item in args.ensembles:
        label, sep, pattern = item.partition("=")
        files = sorted({f for part in pattern.split(",") for f in glob.glob(part)})
        if not sep or len(files) < 2:
            parser.error(f"ensemble {item!r}: give LABEL=GLOB matching 2 or more results files "
                         f"(matched {len(files)})")
        rows = [measures(f) for f in files]
        groups[label] = {k: np.array([r[k] for r in rows]) for k in FIELDS}
    for label, g in groups.items():
        n = len(g["T"])
        print(f"{label} ({n} runs): " + "  ".join(
            f"{k} = {v.mean():.4g} ± {v.std(ddof=1) / np.sqrt(n):.2g}" for k, v in g.items()))
    first, base = next(iter(groups.items()))
    for label, g in list(groups.items())[1:]:
        print(f"\n{label} against {first}: relative difference ± error (Welch p)")
        for k in FIELDS:
            a, b = base[k], g[k]
            rel = b.mean() / a.mean() - 1
            err = np.hypot(a.std(ddof=1) / np.sqrt(len(a)) / a.mean(),
                           b.std(ddof=1) / np.sqrt(len(b)) / a.mean())
            p = stats.ttest_ind(b, a, equal_var=False).pvalue
            print(f"  {k:12s} {rel:+.3f} ± {err:.3f}  (p = {p:.2f})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
