"""The stability suite's registry: hard cases, the engines each one means something in, and
the rows they give.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise a wall speed or
the shear rate sets the time unit τ); overlaps and distances in d.

A :class:`Case` names what it checks and its limit, and runs in one engine (``run(engine,
quick, workdir)`` returns an :class:`Outcome`: the measured figure, pass or fail, a note).
Soft-contact cases run in every registered backend whose ``kind`` is "soft-contact", so a new
soft engine gets its rows without any change here; an engine that cannot express a case's
scene refuses it (``UnsupportedByEngine``, ``RunRefused``), which is a legitimate row
("refused: reason"), not a failure.
"""

from __future__ import annotations

import time
import traceback
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass, field
from pathlib import Path

from ..errors import BadOption, RunRefused, UnsupportedByEngine

__all__ = ["CASES", "SOFT", "Case", "Outcome", "Row", "case", "plan_rows", "run_suite"]

#: a backend's ``kind`` for soft-contact (time-stepped DEM) engines
SOFT = "soft-contact"


@dataclass(frozen=True)
class Outcome:
    """What a case measured in one engine: the figure (``measured``, as shown in the table),
    whether it is within the limit, and a note (how it was measured, what it means)."""

    measured: str
    passed: bool
    note: str = ""
    #: why a figure outside its limit is understood: the case measured the signature of a
    #: documented cause (not a bug), so the row is "explained" instead of "fail"; "" = not
    explained: str = ""


@dataclass(frozen=True)
class Case:
    """A hard case: ``kind`` is the backend kind it runs in ("soft-contact" or
    "event-driven"), ``engine`` a single engine when the case drives that engine's own core;
    ``checks`` and ``limit`` are the table's words; ``run(engine, quick, workdir)`` measures."""

    name: str
    kind: str
    checks: str
    limit: str
    run: Callable[[str, bool, Path], Outcome]
    engine: str | None = None
    slow: bool = False  # its full version takes minutes (the quick one seconds)

    def applies(self, engine: str, kind: str) -> bool:
        return engine == self.engine if self.engine else kind == self.kind


@dataclass
class Row:
    """One row of the table: ``status`` is "pass", "fail", "explained" (outside the limit
    for a documented cause whose signature the case measured: not a fail), "refused" (the
    engine cannot express the case: a legitimate outcome) or "error" (the case itself
    broke: a fail)."""

    case: str
    engine: str
    checks: str
    measured: str
    limit: str
    status: str
    note: str = ""
    seconds: float = 0.0
    quick: bool = False

    def as_dict(self) -> dict:
        return asdict(self)


#: every case, by name, in the order of the table
CASES: dict[str, Case] = {}


def case(name: str, kind: str, checks: str, limit: str, *, engine: str | None = None,
         slow: bool = False) -> Callable:
    """Register the decorated ``run(engine, quick, workdir) -> Outcome`` as a case."""

    def register(run: Callable[[str, bool, Path], Outcome]) -> Callable:
        CASES[name] = Case(name, kind, checks, limit, run, engine, slow)
        return run

    return register


@dataclass
class _Engine:
    name: str
    kind: str | None
    problem: str | None = None


def _engines(names: Iterable[str] | None) -> list[_Engine]:
    """The engines asked for (default: every registered one) with their kinds; an engine
    whose backend cannot be loaded keeps its load error as ``problem``."""
    from ..engines import backend_names, get_backend

    known = backend_names()
    chosen = list(names) if names else known
    unknown = [n for n in chosen if n not in known]
    if unknown:
        raise BadOption("--engine", unknown[0], f"a registered engine ({', '.join(known)}) "
                                                "is allowed")
    out = []
    for name in chosen:
        try:
            out.append(_Engine(name, get_backend(name).kind))
        except Exception as exc:  # noqa: BLE001 - an engine that cannot load is a row
            out.append(_Engine(name, None, f"{type(exc).__name__}: {exc}"))
    return out


def plan_rows(engines: Iterable[str] | None = None,
              cases: Iterable[str] | None = None) -> list[tuple[Case, _Engine]]:
    """(case, engine) pairs to run, in table order; unknown case names are refused."""
    from . import hard, soft  # noqa: F401 - registers the cases

    wanted = list(cases) if cases else list(CASES)
    unknown = [c for c in wanted if c not in CASES]
    if unknown:
        raise BadOption("--case", unknown[0], f"a case of the suite ({', '.join(CASES)}) is "
                                              "allowed")
    pool = _engines(engines)
    pairs = []
    # the table's order, whatever the order asked: soft-contact cases first (as issue 13
    # lists them), then the event-driven ones, each in the order they were registered
    for name in sorted(CASES, key=lambda n: CASES[n].kind != SOFT):
        if name not in wanted:
            continue
        c = CASES[name]
        for engine in pool:
            if engine.kind is None and c.engine in (None, engine.name):
                pairs.append((c, engine))  # its kind is unknown: say why it did not run
            elif engine.kind is not None and c.applies(engine.name, engine.kind):
                pairs.append((c, engine))
    return pairs


def run_case(c: Case, engine: _Engine, quick: bool, workdir: Path) -> Row:
    """One row: the case run in the engine, timed; the engine's refusal is a "refused" row,
    anything else that escapes the case (an invalid scene of its own included) an "error"
    row naming the exception."""
    base = {"case": c.name, "engine": engine.name, "checks": c.checks, "limit": c.limit,
            "quick": quick}
    if engine.problem is not None:
        return Row(**base, measured="-", status="refused",
                   note=f"engine unavailable: {engine.problem}")
    folder = workdir / f"{c.name}-{engine.name}"
    folder.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    try:
        outcome = c.run(engine.name, quick, folder)
    except (UnsupportedByEngine, RunRefused) as exc:
        return Row(**base, measured="-", status="refused", note=f"refused: {exc}",
                   seconds=time.perf_counter() - start)
    except Exception as exc:  # noqa: BLE001 - a broken case is a failed row, not a crash
        last = traceback.format_exception_only(type(exc), exc)[-1].strip()
        return Row(**base, measured="-", status="error", note=f"the case broke: {last}",
                   seconds=time.perf_counter() - start)
    status = "pass" if outcome.passed else "explained" if outcome.explained else "fail"
    note = outcome.note
    if status == "explained":
        note = f"explained: {outcome.explained}" + (f"; {note}" if note else "")
    return Row(**base, measured=outcome.measured, status=status, note=note,
               seconds=time.perf_counter() - start)


@dataclass
class Suite:
    """The rows of one suite run and how it ran."""

    rows: list[Row] = field(default_factory=list)
    quick: bool = False
    seconds: float = 0.0

    @property
    def failed(self) -> list[Row]:
        return [r for r in self.rows if r.status in ("fail", "error")]


def run_suite(engines: Iterable[str] | None = None, cases: Iterable[str] | None = None,
              quick: bool = False, workdir: Path | None = None,
              progress: Callable[[Row], None] | None = None) -> Suite:
    """Run the chosen cases in the chosen engines (default all) in ``workdir`` (default a
    temporary folder, removed afterwards); ``progress(row)`` after each row."""
    import tempfile

    pairs = plan_rows(engines, cases)
    suite = Suite(quick=quick)
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="demstudy-stability-") as tmp:
        folder = Path(workdir) if workdir is not None else Path(tmp)
        for c, engine in pairs:
            row = run_case(c, engine, quick, folder)
            suite.rows.append(row)
            if progress is not None:
                progress(row)
    suite.seconds = time.perf_counter() - start
    return suite
