"""Run records: what a study keeps of each run so that its report and figures can be made again
without the run's results file.

A study's results files hold the frames and the collision log (10² MB to GBs each) and stay in
its ``runs/`` folder, which a fresh checkout does not have. A *record* is the same results file
without ``frames`` and ``collisions``, plus what the study's analysis derives from them, in
groups ``study/<name>`` (e.g. Malik's in-bin g(r), the density-wave modes, the last frame):
0.2-1.5 MB for runs of up to 5·10⁴ particles (Malik's largest box, 323 433 spheres, ≈ 9 MB:
its last frame), small enough to keep with the docs (each remade record adds its bytes to the
repository's history). A study that defines ``derive`` (``Study.derive``)
writes a record of each of its runs; ``demstudy study NAME --docs DOCS`` keeps the records in
``DOCS/data/studies/NAME/records/`` and reuses them as finished runs, so that a rerun in a fresh
checkout makes only the runs that are missing and ``--analyse-only --docs docs`` rebuilds the
report and figures from the records alone (CPU-days of runs are not repeated to fix a caption).

A record is written atomically and read back like any results file (``read_results`` verifies
it; a damaged record is remade from its run, or the run is made again, with a warning). Its
root attributes are the run's (scene, engine, wall time, TC share, …) plus ``record_of`` (the
results file's name) and ``record_version`` (``RECORD_VERSION`` / study : ``derive_version``).
A record stands for its run: to make a run again, delete its record too.
Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

#: the prefix of the derived groups
DERIVED = "study"
#: raised when what every record holds changes (the part of ``record_version`` common to all
#: studies; each study adds its own ``Study.derive_version``, raised when its ``derive``
#: changes): records of another version are remade from their runs where the runs exist
#: (and still read otherwise)
RECORD_VERSION = 1
#: the groups of a results file a record leaves out (the large ones)
LEFT_OUT = ("frames", "collisions")


def record_version(study_name: str, derive_version: int) -> str:
    """The version a record of ``study_name`` is written with and checked against."""
    return f"{RECORD_VERSION}/{study_name}:{derive_version}"


def write_record(full: Path, record: Path, derived: Mapping[str, tuple[Mapping[str, Any],
                                                                        Mapping[str, Any]]],
                 version: str = "") -> Path:
    """The record of results file ``full`` at ``record`` (module doc), ``derived`` added,
    stamped with ``version`` (:func:`record_version`)."""
    from ..io.results import read_results, write_results

    res = read_results(full, skip=LEFT_OUT)
    res.skipped = ()  # a different file: nothing of it is lost by writing
    for name, (data, attrs) in derived.items():
        key = f"{DERIVED}/{name}"
        res.groups[key] = {k: np.asarray(v) for k, v in data.items()}
        res.group_attrs[key] = dict(attrs)
    res.attrs["record_of"] = Path(full).name
    res.attrs["record_version"] = version or record_version("?", 0)
    res.attrs["record_note"] = (f"a study record: the results file without "
                                f"{' and '.join(LEFT_OUT)}, with what the study derives "
                                f"from them in groups {DERIVED}/* (demstudy.studies.records)")
    return write_results(record, res, command_line=str(res.attrs.get("command_line", "")))


def derived(groups: Mapping[str, Mapping[str, np.ndarray]], name: str
            ) -> dict[str, np.ndarray] | None:
    """The derived group ``name`` among a results file's ``groups`` (None when absent)."""
    found = groups.get(f"{DERIVED}/{name}")
    return dict(found) if found is not None else None


def same_scene(stored: Any, expected: str) -> bool:
    """Whether the scene text ``stored`` (a record's ``scene_toml``) is the scene ``expected``
    (``scene_to_toml`` of the case): equal texts, or equal once the stored one is validated
    again with this version's schema (a field added since, with its default, changes the text
    of every scene but not the scene)."""
    if not isinstance(stored, str):
        return False
    if stored == expected:
        return True
    from ..scene import scene_to_toml
    from ..scene.load import parse_scene_text, validate_scene

    try:
        return scene_to_toml(validate_scene(parse_scene_text(stored, "record"), "record")) == \
            expected
    except Exception:  # noqa: BLE001 - a scene this schema refuses is another scene
        return False


def why_not_current(record: Path, full: Path | None, scene_toml: str, version: str,
                    engine: str = "", options: Mapping[str, Any] | None = None
                    ) -> str | None:
    """Why ``record`` cannot stand for the run of this scene (None: it can). It must be a
    readable results file (read whole: ``read_results`` verifies it) of this scene and of
    ``engine``'s physics-changing ``options`` (the t_c: ``accuracy.execute.option_mismatch``);
    when the run ``full`` exists it must also be of this ``version`` and not older than the
    run (else it is remade from the run)."""
    from ..accuracy.execute import option_mismatch
    from ..io.results import read_results

    if not record.is_file():
        return "no record"
    try:
        attrs = read_results(record).attrs
    except Exception as exc:  # noqa: BLE001 - any damage: the record is not used
        return f"unreadable ({exc})"
    if not same_scene(attrs.get("scene_toml"), scene_toml) or "wall_seconds" not in attrs:
        return "the record is of another scene or an unfinished run"
    other = option_mismatch(attrs, engine, options)
    if other:
        return f"the record was {other}"
    if full is not None and full.is_file():
        if attrs.get("record_version") != version:
            return f"record version {attrs.get('record_version')!r}, now {version!r}"
        if record.stat().st_mtime < full.stat().st_mtime:
            return "older than its run"
    return None


def current(record: Path, full: Path | None, scene_toml: str, version: str,
            engine: str = "", options: Mapping[str, Any] | None = None) -> bool:
    """Whether ``record`` stands for the run of this scene (:func:`why_not_current`)."""
    return why_not_current(record, full, scene_toml, version, engine, options) is None
