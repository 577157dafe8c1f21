"""What a seed study is made of: the runs it needs (``Case``), the statements of the thesis it
checks (``Check``) and the study itself (``Study``: cases, then an analysis that turns the
results files into figures and checks).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise a wall speed or
the shear rate sets the time unit). Every figure and report a study writes says so.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

#: the verdicts a check can reach (the report's last columns say why for every other than
#: the first)
REPRODUCED = "reproduced"
NOT_REPRODUCED = "not reproduced"
PARTLY = "partly"
#: demstudy measured it, but the thesis (as far as the digest gives it) states no value or
#: class to compare with: the row shows the measurement and what it could not test
NO_THESIS_VALUE = "no thesis value"
NOT_RUN = "not run"  # the case was not in this (quick) run of the study
VERDICTS = (REPRODUCED, PARTLY, NOT_REPRODUCED, NO_THESIS_VALUE, NOT_RUN)

#: what each verdict means, printed above every report's table
VERDICT_LEGEND = (
    "Verdicts: *reproduced* when demstudy's value agrees with the thesis's within the "
    "statistical errors (2σ) plus the precision of the thesis's own statement (a value read "
    "off a figure, a qualitative trend); *partly* when part of the statement agrees and part "
    "does not, or when it agrees but the run is a weakened test (not steady, or an "
    "approximation of demstudy's, such as the event-driven TC model, changed more of the "
    "physics than its warning level); *not reproduced* when demstudy's value disagrees "
    "beyond the errors (the reason gives the cause found, including demstudy's own "
    "approximations and unsteady runs); *no thesis value* when the thesis states nothing "
    "to compare with (demstudy's value is still shown); *not run* when the run is missing. "
    "demstudy's own checks (not statements of the thesis: engine cross-checks, model "
    "dependence, consistency with theory where the thesis gives no value) are marked "
    "\"(own)\" and tallied apart.")

UNITS_NOTE = ("Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise "
              "a wall speed sets the time unit).")


@dataclass(frozen=True)
class Case:
    """One run of a study: the scene (a preset name or file), typed section overrides merged
    into it (``load_scene(scene, **sections)``), the engine and its options. ``name`` is the
    results file's stem, unique in the study; ``quick``: also part of ``--quick``, with
    ``quick_sections`` merged on top (shorter runs); ``group`` tags cases an analysis
    treats together."""

    name: str
    scene: str
    engine: str = "edmd"
    sections: Mapping[str, Any] = field(default_factory=dict)
    options: Mapping[str, Any] = field(default_factory=dict)
    quick: bool = False
    quick_sections: Mapping[str, Any] = field(default_factory=dict)
    group: str = ""

    def load(self, quick: bool = False):
        """The case's validated scene."""
        from ..scene import load_scene

        sections = merge(self.sections, self.quick_sections) if quick else dict(self.sections)
        return load_scene(self.scene, **sections)


def merge(base: Mapping[str, Any], top: Mapping[str, Any]) -> dict[str, Any]:
    """``base`` with ``top`` merged into it, tables recursively (``top`` wins)."""
    out = dict(base)
    for key, value in top.items():
        if isinstance(value, Mapping) and isinstance(out.get(key), Mapping):
            out[key] = merge(out[key], value)
        else:
            out[key] = value
    return out


@dataclass
class Check:
    """One statement or figure of the thesis and what demstudy measured of it.

    ``ref``: where the thesis says it (figure, line numbers of the digest); ``statement``:
    what it says, in words; ``thesis``: its value where it gives one; ``measured``:
    demstudy's value with its statistical error (text), per engine where meaningful;
    ``verdict``: one of ``VERDICTS``; ``reason``: for every verdict other than
    "reproduced", the cause found (or what is still open)."""

    ref: str
    statement: str
    thesis: str
    measured: str
    verdict: str
    reason: str = ""
    #: demstudy's own check (a cross-check of engines, a model's influence), not a statement
    #: of the thesis: the report tallies it apart
    own: bool = False
    #: the runs (case names) the row's values rest on: what is said of a run study-wide (the
    #: TC model's share, :func:`tc_caveats`) reaches the rows through it
    runs: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if self.verdict not in VERDICTS:
            raise ValueError(f"verdict {self.verdict!r}: allowed are {', '.join(VERDICTS)}")


def tc_caveats(checks: Sequence[Check], shares: Mapping[str, tuple[float, float]],
               unchanged: Mapping[str, str] | None = None,
               quoted: Mapping[str, str] | None = None,
               unit: str | Mapping[str, str] = "time units") -> None:
    """The rule of :data:`VERDICT_LEGEND` for the event-driven engine's TC model (Luding &
    McNamara: a pair colliding again within t_c is elastic; no thesis has it): every row
    resting on a run (``Check.runs``) whose ``shares`` (case name → (share of pair collisions
    made elastic, t_c)) exceed the engine's warning level (a fixed cut: 5 %) names the share
    in its reason, unless the reason discusses the TC model already, and an agreement becomes
    *partly* (a weaker test); a disagreement stays, the TC model one possible cause. A run in
    ``unchanged`` (case name → the evidence: a twin at another t_c with a share below the
    level agrees) keeps the row's verdict. ``quoted`` (case name → what a twin at another t_c
    whose own share is large found, :func:`twin_comparison`) is quoted in the reason but
    exempts nothing: with both shares large there is no reference free of the model. Rows
    about the TC model itself, and comparisons with engines without it, are the caller's to
    leave out (give them no ``runs``). ``unit``: the scenes' time unit, for t_c (or per run)."""
    from ..engines.edmd.tc_share import WARN_SHARE

    unchanged, quoted = unchanged or {}, quoted or {}
    for c in checks:
        large = [(n, *shares[n]) for n in c.runs
                 if n in shares and math.isfinite(shares[n][0]) and shares[n][0] > WARN_SHARE]
        if c.verdict == NOT_RUN or not large:
            continue
        text = ", ".join(f"{n}: {100 * s:.1f} % (t_c = {tc:g} "
                         f"{unit if isinstance(unit, str) else unit.get(n, 'time units')})"
                         for n, s, tc in large)
        note = (f"The engine's TC model made more than {100 * WARN_SHARE:g} % of the pair "
                f"collisions elastic ({text}; the thesis has no TC model)")
        shown = [unchanged[n] for n, _s, _tc in large if n in unchanged]
        if len(shown) == len(large):
            note += (", but a twin with a small share agrees: "
                     + "; ".join(dict.fromkeys(shown)))
        else:
            note += (": the flow dissipates less than its restitution says, a weaker test "
                     "either way")
            told = [quoted[n] for n, _s, _tc in large if n in quoted and n not in unchanged]
            if told:
                note += " (" + "; ".join(dict.fromkeys(told)) + ")"
            if c.verdict == REPRODUCED:
                c.verdict = PARTLY
        if "TC model" not in c.reason:
            c.reason = ". ".join(p for p in (c.reason.strip().rstrip("."), note) if p) + "."


#: how far a TC twin (the same run at another t_c) may differ from its run and still count
#: as the same flow: 2σ of the two runs' combined errors plus this fraction of the value
TWIN_TOLERANCE = 0.10


def twin_comparison(base: Mapping[str, tuple[float, float]],
                    twin: Mapping[str, tuple[float, float]],
                    labels: Mapping[str, str]) -> tuple[bool, str, list[str]]:
    """Whether ``twin`` gives ``base``'s values (key → (value, error)) for every key of
    ``labels`` (key → the name to print) within 2σ of the combined errors plus
    :data:`TWIN_TOLERANCE`, the comparison as text (e.g. ``"S 1.121 ± 0.041 (-2.9 %)"``) and
    the values that differ (e.g. ``"T +74 %"``); keys missing from either side are left out
    (none in common: not the same)."""
    parts, off = [], []
    for key, label in labels.items():
        if key not in base or key not in twin:
            continue
        (x, xe), (y, ye) = base[key], twin[key]
        if not all(map(math.isfinite, (x, y))):
            continue
        err = math.hypot(xe, ye) if math.isfinite(xe) and math.isfinite(ye) else 0.0
        # rounded, + 0.0: a change that rounds to zero prints "+0.0", not "-0.0"
        change = f" ({round(100 * (y - x) / x, 1) + 0.0:+.1f} %)" if x else ""
        parts.append(f"{label} {pm(y, ye)}{change}")
        if not within(y, err, x, 2.0, TWIN_TOLERANCE * abs(x)):
            off.append(f"{label} {100 * (y - x) / x:+.0f} %" if x else label)
    return bool(parts) and not off, ", ".join(parts), off


def twin_evidence(pairs: Sequence[tuple[str, Mapping, Mapping, float, float]],
                  labels: Mapping[str, str], unit: str = "time units"
                  ) -> tuple[dict[str, str], dict[str, str]]:
    """What TC twins say, for :func:`tc_caveats`: ``pairs`` of (run name, its values, its
    twin's values, the twin's TC-elastic share and t_c) give (runs a twin with a share below
    the warning level reproduces → the evidence, runs whose twin differs or has a large share
    itself → what it found), each compared by :func:`twin_comparison` on ``labels``."""
    from ..engines.edmd.tc_share import WARN_SHARE

    unchanged, told = {}, {}
    for name, base, twin, share, tc in pairs:
        same, _text, off = twin_comparison(base, twin, labels)
        found = (f"the twin of {name} at t_c = {tc:g} {unit} ({100 * share:.1f} % elastic) "
                 "gives "
                 + (f"the same values within 2σ + {100 * TWIN_TOLERANCE:.0f} %" if same else
                    "other values (" + ", ".join(off) + ")"))
        if same and share < WARN_SHARE:
            unchanged[name] = found
        else:
            told[name] = found + ("; the twin's own share is large too, so no run free of "
                                  "the model exists" if same else "")
    return unchanged, told


def not_run(ref: str, statement: str, thesis: str, needs: str | Sequence[str],
            own: bool = False) -> Check:
    """The row of a statement whose run(s) are not in this run of the study (a quick study,
    ``--only``, a failed run): ``needs`` names them, as case names or in words."""
    what = needs if isinstance(needs, str) else "the run(s) " + ", ".join(needs)
    return Check(ref, statement, thesis, "n/a", NOT_RUN,
                 f"needs {what}, not in this run of the study", own=own)


@dataclass
class Figure:
    """A figure the study wrote: its file and a one-line caption."""

    path: Path
    caption: str


@dataclass
class Analysis:
    """What a study's analysis returns: the checks, the figures and free-form sections of
    the report (markdown, in order)."""

    checks: list[Check] = field(default_factory=list)
    figures: list[Figure] = field(default_factory=list)
    sections: list[tuple[str, str]] = field(default_factory=list)


@dataclass(frozen=True)
class Study:
    """A seed study: ``cases(quick)`` lists its runs; ``analyse(runs, out, quick)`` reads
    them (``runs``: case name → results file path, only the cases of this run of the
    study) and writes its figures into ``out``; ``derive`` (optional) lets the study keep
    records of its runs that its analysis reads as it reads the runs."""

    name: str
    title: str
    reference: str
    summary: str
    cases: Callable[[bool], Sequence[Case]]
    analyse: Callable[[Mapping[str, Path], Path, bool], Analysis]
    #: what a record keeps of a run in place of its frames and collision log (``derive(case
    #: name, results file)``, demstudy.studies.records); None: the study keeps no records
    #: (its analysis needs the full results files)
    derive: Callable[[str, Path], Mapping[str, Any]] | None = None
    #: raised whenever ``derive`` changes what it keeps: records of an older one are remade
    #: from their runs where the runs exist
    derive_version: int = 1


def pm(value: float, err: float | None = None, digits: int = 2) -> str:
    """``value ± err`` with the error to ``digits`` significant figures and the value to the
    same decimal place (``err`` None or not finite: the value alone, 3 significant)."""
    if value is None or not math.isfinite(value):
        return "n/a"
    if err is None or not math.isfinite(err) or err <= 0:
        return f"{value:.3g}"
    place = digits - 1 - math.floor(math.log10(err))
    place = max(place, 0)
    return f"{value:.{place}f} ± {err:.{place}f}"


def within(value: float, err: float, target: float, sigmas: float = 2.0,
           tolerance: float = 0.0) -> bool:
    """Whether ``value`` agrees with ``target`` within ``sigmas`` errors plus an absolute
    ``tolerance`` (the thesis's own precision, e.g. a value read off a figure)."""
    return abs(value - target) <= sigmas * abs(err) + tolerance
