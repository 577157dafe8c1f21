"""Run records: what a study keeps of each run so that its report and figures can be made again
without the run's results file.

A study's results files hold the frames and the collision log (10² MB to GBs each) and stay in
its ``runs/`` folder, which a fresh checkout does not have. A *record* is the same results file
without ``frames`` and ``collisions``, plus what the study's analysis derives from them, in
groups ``study/<name>`` (e.g. Malik's in-bin g(r), the density-wave modes, the last frame): a
few MB, small enough to keep with the docs. A study that defines ``derive`` (``Study.derive``)
writes a record of each of its runs; ``demstudy study NAME --docs DOCS`` keeps the records in
``DOCS/data/studies/NAME/records/`` and reuses them as finished runs, so that a rerun in a fresh
checkout makes only the runs that are missing and ``--analyse-only --docs docs`` rebuilds the
report and figures from the records alone (CPU-days of runs are not repeated to fix a caption).

A record is written atomically and read back like any results file (``read_results`` verifies
it; a damaged record is remade from its run, or the run is made again). Its root attributes are
the run's (scene, engine, wall time, TC share, …) plus ``record_of`` (the results file's name)
and ``record_version``. Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

#: the prefix of the derived groups
DERIVED = "study"
#: raised when what a record holds, or how it is derived, changes: older records are remade
#: from their runs where the runs exist (and still read otherwise)
RECORD_VERSION = 1
#: the groups of a results file a record leaves out (the large ones)
LEFT_OUT = ("frames", "collisions")

#: what a study derives from a full results file: ``derive(case_name, path)`` returns
#: {name: (datasets, attributes)}, stored as groups ``study/<name>``
Derive = Callable[[str, Path], Mapping[str, tuple[Mapping[str, Any], Mapping[str, Any]]]]


def write_record(full: Path, record: Path, derived: Mapping[str, tuple[Mapping[str, Any],
                                                                        Mapping[str, Any]]]
                 ) -> Path:
    """The record of results file ``full`` at ``record`` (module doc), ``derived`` added."""
    from ..io.results import read_results, write_results

    res = read_results(full, skip=LEFT_OUT)
    res.skipped = ()  # a different file: nothing of it is lost by writing
    for name, (data, attrs) in derived.items():
        key = f"{DERIVED}/{name}"
        res.groups[key] = {k: np.asarray(v) for k, v in data.items()}
        res.group_attrs[key] = dict(attrs)
    res.attrs["record_of"] = Path(full).name
    res.attrs["record_version"] = RECORD_VERSION
    res.attrs["record_note"] = (f"a study record: the results file without "
                                f"{' and '.join(LEFT_OUT)}, with what the study derives "
                                f"from them in groups {DERIVED}/* (demstudy.studies.records)")
    return write_results(record, res, command_line=str(res.attrs.get("command_line", "")))


def is_record(attrs: Mapping[str, Any]) -> bool:
    """Whether root attributes ``attrs`` are a record's."""
    return "record_of" in attrs


def derived(groups: Mapping[str, Mapping[str, np.ndarray]], name: str
            ) -> dict[str, np.ndarray] | None:
    """The derived group ``name`` among a results file's ``groups`` (None when absent)."""
    found = groups.get(f"{DERIVED}/{name}")
    return dict(found) if found is not None else None


def derived_attrs(group_attrs: Mapping[str, Mapping[str, Any]], name: str) -> dict[str, Any]:
    return dict(group_attrs.get(f"{DERIVED}/{name}", {}))


def current(record: Path, full: Path | None, scene_toml: str) -> bool:
    """Whether ``record`` is a readable record of this scene, of this record version and, when
    the run ``full`` exists, not older than it."""
    import h5py

    from ..io.results import read_attrs

    if not record.is_file():
        return False
    try:
        with h5py.File(record, "r") as f:
            attrs = read_attrs(f)
    except Exception:  # noqa: BLE001 - any unreadable record is remade or ignored
        return False
    if attrs.get("scene_toml") != scene_toml or "wall_seconds" not in attrs:
        return False
    if full is not None and full.is_file():
        if attrs.get("record_version") != RECORD_VERSION:
            return False
        return record.stat().st_mtime >= full.stat().st_mtime
    return True
