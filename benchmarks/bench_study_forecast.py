"""How well a study's calibrated forecast meets the actual wall time: leave-one-out over a
study's made runs whose forecast was a lower bound (docs/forecast.md, "In a study").

For each such run, the other made runs calibrate it as ``demstudy study`` would
(``demstudy.studies.runner.calibration``: the same kind, the closest in N, length, e and β),
both lower bounds forecast again now (``_bound_now``); printed: the ratio it actually took
against its lower bound, the one predicted, and their quotient. Dimensionless particle
units (d = 1, m = 1, g = 1); wall times in seconds of the machines that made the runs.

    .venv/bin/python benchmarks/bench_study_forecast.py [RECORDS_FOLDER]

(default: Malik's committed records, docs/data/studies/malik2008/records).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

from demstudy.studies.runner import _bound_now, calibration, finished_runs


def main(folder: Path) -> None:
    made = finished_runs({p.stem: p for p in sorted(folder.glob("*.h5"))})
    scratch = Path(tempfile.mkdtemp())
    now = {t.name: _bound_now(t, scratch) for t in made}
    quotients = []
    for t in made:
        actual = t.wall / now[t.name]
        like = calibration(t.scene, t.engine, [o for o in made if o.name != t.name],
                           t.options)
        if like is None:
            print(f"{t.name:45s} took ×{actual:6.2f} its bound; no run of its kind")
            continue
        predicted = like.wall / now[like.name]
        quotients.append(predicted / actual)
        print(f"{t.name:45s} took ×{actual:6.2f}, predicted ×{predicted:6.2f} from "
              f"{like.name}: ×{predicted / actual:.2f}")
    raw = np.array([t.wall / now[t.name] for t in made])
    if raw.size:
        print(f"{raw.size} lower bounds fell short by ×{raw.min():.2f}-{raw.max():.2f} "
              f"(median ×{np.median(raw):.2f})")
    q = np.array(quotients)
    if q.size:
        print(f"{q.size} of {len(made)} calibrated: predicted/actual median {np.median(q):.2f}, "
              f"range {q.min():.2f}-{q.max():.2f}, within ×2 in {np.sum((q > 0.5) & (q < 2))}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else
         Path("docs/data/studies/malik2008/records"))
