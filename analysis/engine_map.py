"""The engine map figure of docs/accuracy-cost.md ("Which engine? The engine map"):
redraws docs/figures/engine_map.png from docs/data/engine_map.json, or, with --measure, first
measures the map again (``demstudy engine-map``: about 5 minutes on 2 cores) into
results/engine-map/ and copies its csv/json into docs/data/.

Dimensionless particle units: d = 1, m = 1, shear rate γ̇ = 1 (strain units); costs in wall
seconds per particle per strain unit of the machine named in the files.

    python analysis/engine_map.py                          # redraw from docs/data
    nice -n 10 python analysis/engine_map.py --measure --workers 2
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from demstudy.accuracy.engine_map import MapSettings, engine_map
from demstudy.accuracy.map_figure import map_figure
from demstudy.io.results import write_atomically

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "docs" / "data"
FIGURE = ROOT / "docs" / "figures" / "engine_map.png"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--measure", action="store_true",
                        help="measure the map again first (results/engine-map/)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--ratio", type=float, default=MapSettings.ratio,
                        help="t_c / tau_flight of the soft runs (default %(default)s)")
    parser.add_argument("--steps", type=float, default=MapSettings.steps_per_contact,
                        help="soft steps per contact (default %(default)s)")
    args = parser.parse_args(argv)
    if args.measure:
        settings = MapSettings(ratio=args.ratio, steps_per_contact=args.steps)
        result = engine_map(settings=settings, workers=args.workers,
                            out=ROOT / "results" / "engine-map")
        DATA.mkdir(parents=True, exist_ok=True)
        for path in result.written[:2]:  # csv and json
            write_atomically(DATA / path.name, path.read_bytes())
    data = json.loads((DATA / "engine_map.json").read_text())
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    print(f"figure: {map_figure(data, FIGURE)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
