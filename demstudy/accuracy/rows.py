"""One table row per run of the ladder, read from its results file: cost (wall time, steps),
health figures of soft runs (when the results carry a ``health`` group) and the error against
the reference (``analyze.run_error``). A run made as R replicas (other seeds) is one row: its
error from the replicas' mean with errors from their scatter
(``demstudy.comparison.combine_replicas``), its cost the SUM of their wall times and steps.
Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..io.results import Results, read_results
from . import analyze
from .engine_map import TC_IMPRACTICAL
from .plan import RunSpec

NAN = math.nan
HEALTH = ("max_overlap", "tc_flight", "tc_shear", "healthy")


def _read(path: Path) -> Results:
    return read_results(path, skip=("frames", "collisions"))


def _read_group(folder: Path, specs: list[RunSpec]) -> tuple[Results, list[Results]]:
    """(the run, or its replicas combined; the replicas' own results)."""
    runs = [_read(folder / f"{spec.name}.h5") for spec in specs]
    if len(runs) == 1:
        return runs[0], runs
    from ..comparison import combine_replicas

    return combine_replicas(runs), runs


def _group_row(specs: list[RunSpec], runs: list[Results]) -> dict:
    """One row for the replicas of one run: wall time and steps summed (the cost of the
    settings at this precision), health the worst overlap, mean contact-time ratios, healthy
    only when all were; ``path``: the replicas' files, comma-separated."""
    rows = [_base(spec, res) for spec, res in zip(specs, runs, strict=True)]
    row = {**rows[0], "name": specs[0].settings, "replicas": len(rows)}
    if len(rows) == 1:
        return row
    row.update(wall_seconds=sum(r["wall_seconds"] for r in rows),
               steps=sum(r["steps"] for r in rows), path=",".join(r["path"] for r in rows))
    with_health = [r for r in rows if isinstance(r.get("healthy"), bool | np.bool_)]
    if len(with_health) == len(rows):
        row.update(max_overlap=max(r["max_overlap"] for r in rows),
                   tc_flight=float(np.mean([r["tc_flight"] for r in rows])),
                   tc_shear=float(np.mean([r["tc_shear"] for r in rows])),
                   healthy=all(bool(r["healthy"]) for r in rows))
    return row


def _base(spec: RunSpec, res: Results) -> dict:
    attrs = res.attrs
    time = res.timeseries.get("time")
    duration = float(time[-1]) if time is not None and len(time) else NAN
    dt = float(attrs.get("timestep", NAN))
    steps = (round(duration / dt) if spec.soft and math.isfinite(dt) and dt > 0
             else int(attrs.get("events", 0)))  # soft: time steps; edmd: events
    health = res.group_attrs.get("health", {})
    return {"name": spec.name, "engine": spec.engine, "model": spec.model or "—",
            "kstar": spec.kstar if spec.soft else NAN, "kn": NAN,
            "steps_per_contact": spec.steps if spec.soft else NAN,
            "tc": spec.tc if spec.tc is not None else NAN, "dt": dt, "steps": steps,
            "wall_seconds": float(attrs.get("wall_seconds", NAN)), "error": NAN,
            "field": "—", "rel_l2": NAN, "floor": NAN, "resolved": "",
            **{k: health.get(k, NAN) for k in HEALTH}, "path": str(res.path)}


def _error_columns(row: dict, reference: Results, res: Results) -> dict:
    from ..comparison import compare

    err = analyze.run_error(compare(reference, res)[0])
    row.update(error=err.error, field=err.field, rel_l2=err.rel_l2, floor=err.floor,
               resolved=",".join(err.resolved))
    return row


def soft_row(folder: Path, specs: list[RunSpec], kn: float, reference: dict) -> dict:
    """The row of a soft run (``specs``: it, or its replicas), its error against
    ``reference`` (the reference's row)."""
    res, runs = _read_group(folder, specs)
    row = _group_row(specs, runs)
    row["kn"] = kn
    return _error_columns(row, reference["results"], res)


def choose_reference(folder: Path, refs: list[list[RunSpec]], notes: list[str]
                     ) -> tuple[dict, list[dict]]:
    """The converged reference among the t_c ladder ``refs`` (largest t_c first; each entry
    the run or its replicas): the largest t_c whose profiles agree with the smallest t_c's
    (no field resolved), else the smallest. Returns (its row with its ``results``, the rows
    of every reference run)."""
    runs = []
    rows = []
    for specs in refs:
        res, replicas = _read_group(folder, specs)
        runs.append((specs[0], res))
        rows.append(_group_row(specs, replicas))
    chosen = len(runs) - 1
    if len(runs) > 1:
        finest = runs[-1][1]
        for i, (_, res) in enumerate(runs[:-1]):
            _error_columns(rows[i], finest, res)
        agree = [i for i, row in enumerate(rows[:-1]) if not row["resolved"]]
        chosen = agree[0] if agree else chosen
        notes.append(f"reference: t_c = {refs[chosen][0].tc:g} "
                     + ("(agrees with the smallest t_c)" if agree else
                        "(the smallest t_c: the larger ones differ resolvably)"))
    for i, row in enumerate(rows):
        row["reference"] = i == chosen
    share = tc_share([_read(folder / f"{spec.name}.h5") for spec in refs[chosen]])
    rows[chosen]["tc_share"] = share
    if share > TC_IMPRACTICAL:
        notes.append(tc_note(share))
    return {**rows[chosen], "results": runs[chosen][1]}, rows


def tc_share(runs: list[Results]) -> float:
    """The share of the pair collisions that the TC model made elastic, over ``runs`` (a
    reference, or its replicas): attribute ``elastic_tc_collisions`` over the timeseries'
    ``collisions`` count (both since t = 0); 0 when either is missing."""
    elastic = sum(int(r.attrs.get("elastic_tc_collisions", 0)) for r in runs)
    total = 0.0
    for r in runs:
        counts = r.timeseries.get("collisions")
        total += float(counts[-1]) if counts is not None and len(counts) else 0.0
    return elastic / total if total > 0 else 0.0


def tc_note(share: float) -> str:
    """The note (and recommendation caveat) of a TC-dominated reference."""
    return (f"no hard-particle reference: the TC model made {100 * share:.0f} % of "
            "collisions elastic")
