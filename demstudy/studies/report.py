"""The study report (markdown): what was run, the checks table (one row per statement of the
thesis, with demstudy's value, its error and the verdict, and the reason for every verdict
other than "reproduced"), the figures and the analysis's own sections.
Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.
"""

from __future__ import annotations

import datetime as _dt
import re
from collections import Counter
from typing import TYPE_CHECKING

from .base import REPRODUCED, UNITS_NOTE, VERDICT_LEGEND, VERDICTS

if TYPE_CHECKING:
    from .runner import StudyRun


def _cell(text: str) -> str:
    return " ".join(str(text).split()).replace("|", "\\|")


#: the notes the checks append to a reason (unsteady run, TC share) start a sentence: a
#: reason that ran up to them without a full stop gets one
_NOTE = re.compile(r"(?<=[^.;:\s])\s+(?=The (?:run|engine)\b)")


def _reason(text: str) -> str:
    return _cell(_NOTE.sub(". ", str(text)))


def _tally(checks: list) -> str:
    count = Counter(c.verdict for c in checks)
    return ", ".join(f"{count[v]} {v}" for v in VERDICTS if count[v])


def render(result: StudyRun, quick: bool, machine: str, figure_prefix: str = "") -> str:
    study, ana = result.study, result.analysis
    checks = ana.checks if ana else []
    tally = _tally([c for c in checks if not c.own])
    own = [c for c in checks if c.own]
    if own:
        tally = "; and ".join(t for t in (tally, f"{len(own)} of demstudy's own checks: "
                                                 f"{_tally(own)}") if t)
    quick_text = (" This is the **quick** version (short runs, fewer cases): its verdicts "
                  "are indicative only; the full study is `demstudy study "
                  f"{study.name}`." if quick else "")
    lines = [
        f"# {study.title}",
        "",
        f"{study.summary}{quick_text}",
        "",
        f"Reference: {study.reference}. {UNITS_NOTE}",
        "",
        "```bash",
        f"demstudy study {study.name}{' --quick' if quick else ''}    # rerun: finished runs "
        "are reused",
        "```",
        "",
        f"Generated {_dt.date.today().isoformat()} on {machine}: {len(result.made)} runs made, "
        f"{len(result.reused)} reused"
        + (f" ({len(result.from_records)} from their records: demstudy.studies.records)"
           if result.from_records else "")
        + f", {len(result.failed)} failed"
        + (f" ({', '.join(result.failed)})" if result.failed else "")
        + f"; the runs took {result.run_seconds / 60:.1f} min of engine time in all"
        + f" (this invocation {result.wall_seconds / 60:.1f} min)"
        + (f" (forecast {result.forecast_seconds / 60:.1f} min)"
           if result.forecast_seconds else "") + ".",
        "",
        f"## Statements of the thesis checked ({tally or 'none'})",
        "",
        VERDICT_LEGEND,
        "",
        "| # | thesis | statement | thesis value | demstudy | verdict | reason |",
        "|---|---|---|---|---|---|---|",
    ]
    for i, c in enumerate(checks, 1):
        verdict = f"**{c.verdict}**" if c.verdict != REPRODUCED else c.verdict
        number = f"{i} (own)" if c.own else str(i)  # demstudy's own check, tallied apart
        lines.append(f"| {number} | {_cell(c.ref)} | {_cell(c.statement)} | {_cell(c.thesis)} | "
                     f"{_cell(c.measured)} | {verdict} | {_reason(c.reason)} |")
    lines.append("")
    if ana and ana.figures:
        lines += ["## Figures", ""]
        for fig in ana.figures:
            lines += [f"![{_cell(fig.caption)}]({figure_prefix}{fig.path.name})", "",
                      f"*{fig.caption}*", ""]
    for title, text in (ana.sections if ana else []):
        lines += [f"## {title}", "", text.strip(), ""]
    return "\n".join(lines).rstrip() + "\n"
