"""Outputs of a cost study in its folder: the table (terminal and ``ladder.csv``), the
summary ``ladder.json`` (written atomically) and the accuracy-versus-cost figure
``pareto.png``. Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts; wall
times in seconds of this machine."""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

from .. import UNITS_NOTE
from ..io.results import write_atomically
from .analyze import ConvergenceFit, meets

COLUMNS = ("name", "engine", "model", "kstar", "kn", "steps_per_contact", "tc", "dt", "steps",
           "replicas", "wall_seconds", "error", "field", "rel_l2", "floor", "resolved",
           "max_overlap", "tc_flight", "tc_shear", "healthy", "meets_tolerance")
SHOWN = (("name", 24, "s"), ("wall_seconds", 9, ".3g"), ("steps", 10, "d"),
         ("error", 9, ".3g"), ("field", 22, "s"), ("floor", 8, ".2g"),
         ("max_overlap", 9, ".2g"), ("tc_flight", 9, ".2g"), ("tc_shear", 9, ".2g"),
         ("healthy", 7, "s"))


def _cell(value, fmt: str) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)) or value == "":
        return "—"
    if fmt == "s" or isinstance(value, bool | str):
        return str(value)
    return format(value, fmt)


def table(study) -> str:
    """The terminal table: one line per run (reference first, marked *); with replicas, their
    number (wall time and steps are then their sums)."""
    shown = SHOWN
    if any(row.get("replicas", 1) > 1 for row in study.rows):
        shown = (SHOWN[0], ("replicas", 8, "d"), *SHOWN[1:])
    head = "  ".join(f"{n:>{w}}" if i else f"{n:<{w}}" for i, (n, w, _) in enumerate(shown))
    lines = [head]
    for row in study.rows:
        cells = [_cell(row.get(n), f) for n, _, f in shown]
        cells[0] = ("*" if row.get("reference") else " ") + cells[0]
        lines.append("  ".join(f"{c:>{w}}" if i else f"{c:<{w}}"
                               for i, (c, (_, w, _)) in enumerate(zip(cells, shown, strict=True))))
    return "\n".join(lines)


def _meets(study, row: dict) -> bool | str:
    return "" if row["engine"] == "edmd" else meets(row, study.tolerance)


def summary(study) -> dict:
    """Everything the study found, JSON-ready."""
    fits = {k: (v.__dict__ | {"law": v.law("x")} if isinstance(v, ConvergenceFit) else v)
            for k, v in study.fits.items()}
    clean = [{k: (None if isinstance(v, float) and math.isnan(v) else v)
              for k, v in row.items() if k != "results"} | {"meets_tolerance":
                                                             _meets(study, row)}
             for row in study.rows]
    return {"units": UNITS_NOTE + "; wall times in seconds", "stiffness": study.scale,
            "error_rule": "worst field's rel_l2 minus its noise floor rel_l2_floor (>= 0)",
            "tolerance_rule": "meets the tolerance when error <= tolerance and floor <= "
                              "tolerance",
            "replicas_rule": "a run of R > 1 replicas (seeds seed, seed+1, ...): error of their "
                             "mean with the standard error across them; wall_seconds and "
                             "steps: the SUM over the replicas",
            "tolerance": study.tolerance, "reference": study.reference["name"],
            "choice": study.choice["name"] if study.choice else None,
            "recommendation": study.recommendation, "engine_map": study.map_hint,
            "fits": fits, "notes": study.notes,
            "runs": clean}


def write_outputs(study, figure: bool = True) -> list[Path]:
    """ladder.csv, ladder.json (both atomically) and pareto.png in the study's folder."""
    folder = study.folder
    buffer = io.StringIO()
    buffer.write(f"# {UNITS_NOTE}; {study.scale}; wall_seconds in seconds\n")
    writer = csv.DictWriter(buffer, COLUMNS, extrasaction="ignore")
    writer.writeheader()
    for row in study.rows:
        writer.writerow({**row, "meets_tolerance": _meets(study, row)})
    written = [folder / "ladder.csv", folder / "ladder.json"]
    write_atomically(written[0], buffer.getvalue().encode())
    write_atomically(written[1], json.dumps(summary(study), indent=1, default=str).encode())
    if figure:
        from .figure import pareto_figure

        written.append(pareto_figure(study, folder / "pareto.png"))
    return written


def text_report(study) -> str:
    """What the command line prints after the runs."""
    lines = [table(study), "", f"stiffness axis: {study.scale}",
             "error: worst profile's rel_l2 beyond its noise floor (docs/cost.md)"]
    for key, fit in study.fits.items():
        lines.append(f"fit {key}: " + (fit.law("k*" if "k*" in key else "(tau/t_c)")
                                        if isinstance(fit, ConvergenceFit) else fit))
    lines += [f"note: {n}" for n in study.notes]
    lines.append(f"recommendation: {study.recommendation}")
    if study.map_hint:
        lines.append(study.map_hint)
    lines.append(f"outputs: {study.folder}/ladder.csv, ladder.json, pareto.png")
    return "\n".join(lines)
