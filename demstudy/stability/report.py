"""The stability table: printed, and written as Markdown (docs/stability.md), CSV and JSON.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise the wall speed
or shear rate sets the time unit τ); every file written says so.
"""

from __future__ import annotations

import csv
import datetime as _dt
import io
import json
import os
from pathlib import Path

from .. import UNITS_NOTE, __version__
from .registry import Row, Suite

__all__ = ["format_markdown", "format_text", "machine", "write_outputs"]

#: a Markdown file's text after this line is kept when the table is written again
HAND_WRITTEN = "<!-- hand-written below: kept when demstudy stability rewrites the table -->"

COLUMNS = ("case", "engine", "checks", "measured", "limit", "status", "seconds", "note")


def machine() -> str:
    """The CPU, its logical cores, and whether it is a virtual machine."""
    from ..simulation.forecast import cpu_model

    text = cpu_model()
    try:
        if " hypervisor" in Path("/proc/cpuinfo").read_text():
            text += ", virtual machine"
    except OSError:
        pass
    return text


def _status(row: Row) -> str:
    return row.status.upper() if row.status in ("fail", "error") else row.status


def format_row(row: Row) -> str:
    """One row as a few lines of text (the terminal's table)."""
    return (f"{_status(row):7s} {row.case} [{row.engine}] ({row.seconds:.1f} s)\n"
            f"        checks:   {row.checks}\n"
            f"        measured: {row.measured}   limit: {row.limit}"
            + (f"\n        note:     {row.note}" if row.note else ""))


def format_text(suite: Suite) -> str:
    counts = {s: sum(r.status == s for r in suite.rows)
              for s in ("pass", "fail", "explained", "refused", "error")}
    summary = ", ".join(f"{n} {s}" for s, n in counts.items() if n)
    return ("\n".join(format_row(r) for r in suite.rows)
            + f"\n{len(suite.rows)} rows: {summary or 'none'} "
              f"({'quick' if suite.quick else 'full'} suite, {suite.seconds:.0f} s)")


def _cell(text: str) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def format_markdown(suite: Suite, command: str = "demstudy stability",
                    when: _dt.datetime | None = None) -> str:
    when = when or _dt.datetime.now(_dt.UTC)
    lines = [
        "# Stability: hard cases in every engine",
        "",
        f"Written by `{command}` (demstudy {__version__}) on "
        f"{when:%Y-%m-%d %H:%M} UTC, {'quick' if suite.quick else 'full'} suite, "
        f"{suite.seconds:.0f} s of wall time in all.",
        f"Machine: {machine()}.",
        "",
        f"Units: {UNITS_NOTE}; overlaps and distances in d, stiffness k_n in m/τ² (Hooke).",
        "",
        "Status: pass; fail (the measured figure is outside the limit); explained (outside "
        "the limit for a documented cause, not a bug: the case measured that cause's "
        "signature, and the note says which); refused (the engine "
        "cannot express the case: it refused before running, a legitimate outcome); error "
        "(the case itself broke). Each case is described in `demstudy/stability/`; the "
        "notes below the table say how each figure was measured.",
        "",
        "| case | engine | what is checked | measured | limit | status | wall time |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in suite.rows:
        lines.append(f"| {_cell(r.case)} | {r.engine} | {_cell(r.checks)} | "
                     f"{_cell(r.measured)} | {_cell(r.limit)} | **{_status(r)}** | "
                     f"{r.seconds:.1f} s |")
    lines += ["", "## Notes", ""]
    lines += [f"- **{r.case}** [{r.engine}]: {_cell(r.note)}" for r in suite.rows if r.note]
    return "\n".join(lines) + "\n"


def format_csv(suite: Suite) -> str:
    buf = io.StringIO()
    buf.write(f"# demstudy stability; {UNITS_NOTE}\n")
    writer = csv.DictWriter(buf, fieldnames=[*COLUMNS, "quick"], extrasaction="ignore")
    writer.writeheader()
    for row in suite.rows:
        writer.writerow(row.as_dict())
    return buf.getvalue()


def format_json(suite: Suite, command: str, when: _dt.datetime) -> str:
    return json.dumps({"command": command, "date": when.isoformat(), "machine": machine(),
                       "version": __version__, "units": UNITS_NOTE, "quick": suite.quick,
                       "seconds": suite.seconds, "rows": [r.as_dict() for r in suite.rows]},
                      indent=1) + "\n"


def write_outputs(suite: Suite, out: str | os.PathLike,
                  command: str = "demstudy stability") -> list[Path]:
    """Write the table as Markdown to ``out`` and as CSV and JSON next to it (same name,
    suffixes .csv and .json); returns the paths. Each file is replaced atomically; the text
    after :data:`HAND_WRITTEN` in an existing ``out`` is kept."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    when = _dt.datetime.now(_dt.UTC)
    markdown = format_markdown(suite, command, when)
    if out.exists():  # keep the hand-written part of a committed table (findings)
        old = out.read_text(encoding="utf-8")
        if HAND_WRITTEN in old:
            markdown += "\n" + HAND_WRITTEN + old.split(HAND_WRITTEN, 1)[1]
    written = []
    for path, text in ((out, markdown),
                       (out.with_suffix(".csv"), format_csv(suite)),
                       (out.with_suffix(".json"), format_json(suite, command, when))):
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(text, encoding="utf-8")
        tmp.replace(path)
        written.append(path)
    return written
