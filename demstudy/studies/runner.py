"""``run_study``: a seed study end to end: the forecast of its runs, the runs (a local process
pool or a Dask cluster, each run one results file, reused on a rerun: an interrupted study
resumes), the analysis, the report.

Runs go to ``<out>/runs/<case>.h5`` (``out`` default ``results/studies/<name>`` and
``results/studies/<name>-quick`` for ``--quick``); figures and the report ``<name>.md`` to
``out``; ``publish`` copies report and figures into the docs (``--docs``). A study that keeps
records of its runs (``Study.derive``, demstudy.studies.records) writes them to ``records``
(default ``<out>/records/``; ``--docs DOCS``: ``DOCS/data/studies/<name>/records/``, kept with
the docs) and counts a run whose record is there as made: its analysis reads the record.
Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.
"""

from __future__ import annotations

import math
import platform
import shutil
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from ..accuracy.execute import wanted_tc
from ..errors import BadOption, EngineError
from .base import Analysis, Case, Study

#: a study's run checkpoints this many times over its length (an interrupted study loses at
#: most this fraction of a run: a rerun resumes from the checkpoint)
CHECKPOINTS_PER_RUN = 10


@dataclass(frozen=True)
class _Spec:
    """What ``demstudy.accuracy.execute`` needs of a run's settings (duck-typed RunSpec):
    ``options()`` are the keywords of ``ds.run``: the engine options and the checkpoint
    interval (``run_task`` adds ``resume`` when the run's work folder holds a checkpoint)."""

    name: str
    engine: str
    engine_options: tuple[tuple[str, Any], ...] = ()
    relative_cost: float = 1.0
    checkpoint_interval: float | None = None

    def options(self) -> dict:
        options = dict(self.engine_options)
        if self.checkpoint_interval:
            options["checkpoint_interval"] = self.checkpoint_interval
        return options


def checkpoint_interval(scene) -> float | None:
    """Checkpoints ``CHECKPOINTS_PER_RUN`` times per run, in the run's own unit (time or
    collisions per particle), never more often than it samples."""
    run = scene.run
    length = run.equilibration + run.production
    interval = max(length / CHECKPOINTS_PER_RUN, run.sample_interval)
    return interval if math.isfinite(interval) and interval > 0 else None


@dataclass(frozen=True)
class StudyTask:
    """A case ready to run: duck-types ``demstudy.accuracy.execute.Task``."""

    case: Case
    quick: bool
    path: Path
    spec: _Spec
    scene_toml: str = ""

    def scene(self):
        return self.case.load(self.quick)


@dataclass
class StudyRun:
    """What ``run_study`` did: the analysis, the report, per-case wall seconds, the
    forecast (seconds on the workers, None when unknown) and failed cases."""

    study: Study
    out: Path
    report: Path | None = None
    analysis: Analysis | None = None
    forecast_seconds: float | None = None
    made: list[str] = field(default_factory=list)
    reused: list[str] = field(default_factory=list)
    failed: list[str] = field(default_factory=list)
    #: the reused runs whose results file is absent: read from their records
    from_records: list[str] = field(default_factory=list)
    wall_seconds: float = 0.0
    #: the runs' own wall times summed (the results files' ``wall_seconds``): the study's
    #: compute cost, whether its runs were made now or reused
    run_seconds: float = 0.0


def tasks_of(study: Study, quick: bool, out: Path, engines: Sequence[str] | None = None,
             only: Sequence[str] | None = None) -> list[StudyTask]:
    """The study's cases as tasks (``engines``: keep cases of these engines; ``only``: keep
    cases whose name contains one of these strings)."""
    from ..scene import scene_to_toml

    cases = list(study.cases(quick))
    names = [c.name for c in cases]
    if len(set(names)) != len(names):
        raise ValueError(f"study {study.name}: case names repeat")
    if engines:
        cases = [c for c in cases if c.engine in engines]
    if only:
        cases = [c for c in cases if any(s in c.name for s in only)]
    tasks = []
    for case in cases:
        scene = case.load(quick)
        path = out / "runs" / f"{case.name}.h5"
        tasks.append(StudyTask(case, quick, path,
                               _Spec(case.name, case.engine,
                                     tuple(sorted(case.options.items())),
                                     checkpoint_interval=checkpoint_interval(scene)),
                               scene_to_toml(scene)))
    return tasks


def _bound_now(made: Took, folder: Path) -> float:
    """The lower bound of a made run forecast again now, as the runs to make are (the
    pilot and its rules change between versions; a stored bound may be of another method):
    the stored one when this forecast fails."""
    from ..api import run

    try:
        plan = run(made.scene, engine=made.engine, out=folder / f"{made.name}.h5",
                   dry_run=True, progress=False, **made.options)
        s = float(plan.get("forecast_seconds", math.nan))
    except Exception:  # noqa: BLE001 - a made run that cannot be forecast now: its own bound
        return made.bound
    return s if math.isfinite(s) and s > 0 else made.bound


def forecast(tasks: Sequence[StudyTask], workers: int,
             finished: Callable[[], Sequence[Took]] = tuple
             ) -> tuple[float | None, list[str], dict[str, str], dict[str, float]]:
    """The wall time of ``tasks`` on ``workers`` (each run's ``--dry-run`` forecast,
    scheduled longest first; None when a run has no forecast), one line per run, the runs
    the engine refuses (name → why: they are not run) and each forecast run's seconds.
    A stopped run (a checkpoint in its work folder) counts what is left of it at its own
    pace (:mod:`demstudy.simulation.progress`). A run's lower bound becomes an estimate
    when a made run of the study like it (from ``finished()``, called only when a lower
    bound needs it) says how much longer such runs took than their own lower bounds
    (:func:`calibration`)."""
    from ..accuracy.forecast import makespan

    each = _Forecasts(finished)
    for task in tasks:
        each.add(task)
    total = makespan(list(each.seconds.values()), workers) if each.seconds else 0.0
    notes = [note for note, used in ((OWN_PACE_NOTE, each.own), (OLD_CHECKPOINT_NOTE, each.old),
                                     (CALIBRATED_NOTE, bool(each.again)),
                                     (OTHER_TC_NOTE, each.other_tc),
                                     # the runs' lower bounds: the study takes longer,
                                     # by how much is unknown
                                     (LOWER_BOUND_NOTE, each.lower)) if used]
    return (None if each.unknown else total), each.lines + notes, each.refused, each.seconds


@dataclass
class _Forecasts:
    """The study forecast's runs one by one: a stopped run by what is left of it, else its
    ``--dry-run`` forecast, a lower bound calibrated by a made run like it when there is
    one. Collects the seconds, lines and which notes the list needs."""

    finished: Callable[[], Sequence[Took]]
    seconds: dict[str, float] = field(default_factory=dict)
    lines: list[str] = field(default_factory=list)
    refused: dict[str, str] = field(default_factory=dict)
    unknown: bool = False  # a run without a forecast: no total
    lower: bool = False  # an uncalibrated lower bound among the runs
    own: bool = False  # a stopped run counted at its own pace
    old: bool = False  # a checkpoint without a progress file: the whole run's forecast
    other_tc: bool = False  # a lower bound calibrated by a made run at another t_c
    #: made run → its lower bound forecast again now
    again: dict[str, float] = field(default_factory=dict)
    made: list[Took] | None = None  # read when a lower bound first needs it

    def add(self, task: StudyTask) -> None:
        from ..api import run
        from ..errors import UnsupportedByEngine
        from ..simulation.checkpoint import stopped_run
        from ..simulation.options import work_folder
        from ..simulation.progress import time_left

        name = f"  {task.case.name} ({task.case.engine}):"
        left = time_left(work_folder(task.path, task.case.engine), task.scene_toml)
        if left is not None:  # a stopped run of this scene: what is left of it (no pilot)
            self.seconds[task.case.name], line = left
            self.lines.append(f"{name} {line}")
            self.own = True
            return
        resumes = stopped_run(task.path, task.case.engine, task.scene_toml)
        try:
            plan = run(task.scene(), engine=task.case.engine, out=task.path, dry_run=True,
                       progress=False, **task.case.options)
        except (UnsupportedByEngine, BadOption) as exc:
            self.refused[task.case.name] = str(exc)
            self.lines.append(f"{name} refused: {exc}")
            return
        s = plan.get("forecast_seconds")
        if s is None or not math.isfinite(s):
            self.unknown = True
            self.lines.append(f"{name} no forecast ({plan.get('forecast', 'not measured')})")
            return
        name += " resumes;" if resumes else ""
        self.old = self.old or resumes  # the note goes with a line that says so
        bound = plan.get("forecast_kind") == "lower bound"
        like = self._like(task) if bound else None
        if like is None:
            self.seconds[task.case.name] = float(s)
            self.lower = self.lower or bound
            self.lines.append(f"{name} {'probably more than ' if bound else ''}{_duration(s)}")
            return
        if like.name not in self.again:  # its bound by today's method, in the same folder
            self.again[like.name] = _bound_now(like, task.path.parent)
        ratio = like.wall / self.again[like.name]
        self.seconds[task.case.name] = float(s) * ratio
        tc = wanted_tc(task.case.engine, task.case.options, task.scene().dimension)
        other = like.tc is not None and tc is not None and not math.isclose(like.tc, tc)
        self.other_tc = self.other_tc or other
        self.lines.append(
            f"{name} about {_duration(s * ratio)} (its lower bound {_duration(s)} × "
            f"{ratio:.2f}: {like.name}, N = {like.scene.n_particles}"
            + (f", made at t_c = {like.tc:g}" if other else "") + ", took "
            f"{_duration(like.wall)} against a lower bound of "
            f"{_duration(self.again[like.name])})")

    def _like(self, task: StudyTask) -> Took | None:
        """The made run that calibrates ``task``'s lower bound (:func:`calibration`)."""
        if self.made is None:
            self.made = list(self.finished())
        return calibration(task.scene(), task.case.engine, self.made, task.case.options)


@dataclass(frozen=True)
class Took:
    """A made run of a study whose forecast was a lower bound: its loop's ``wall`` seconds
    and that ``bound`` (``wall_seconds`` and ``forecast_seconds`` of its results file or
    record, measured on the machine that made it, under whatever load it met) and the
    event-driven engine's ``tc`` (None for other engines)."""

    name: str
    engine: str
    scene: Any
    wall: float
    bound: float
    tc: float | None = None

    @property
    def options(self) -> dict:
        return {} if self.tc is None else {"tc": self.tc}


def finished_runs(paths: Mapping[str, Path]) -> list[Took]:
    """The runs among ``paths`` (case name → results file or record) whose forecast was a
    lower bound; unreadable files, and files without a forecast, are left out."""
    import h5py

    from ..scene import parse_scene_text, validate_scene

    took = []
    for name, path in paths.items():
        try:
            with h5py.File(path, "r") as f:
                a = dict(f.attrs)
            if a.get("forecast_kind") != "lower bound":
                continue
            wall, bound = float(a["wall_seconds"]), float(a["forecast_seconds"])
            scene = validate_scene(parse_scene_text(str(a["scene_toml"])), name)
            tc = float(a["tc"]) if "tc" in a else None
        except Exception:  # noqa: BLE001 - an unreadable or older file calibrates nothing
            continue
        if wall > 0 and bound > 0 and math.isfinite(wall / bound):
            took.append(Took(name, str(a.get("engine", "")), scene, wall, bound, tc))
    return took


def calibration(scene, engine: str, finished: Sequence[Took],
                options: Mapping[str, Any] | None = None) -> Took | None:
    """The made run that says how far ``scene``'s lower bound falls short: the same engine,
    at the same t_c when one is made (else at another: the forecast line says so), the same
    drive (``forecast_events.drive``: walls with their
    kind and speed, gravity, shear), run unit and solid fraction (within ``FAMILY_PHI``;
    the wall gap may differ); the closest in N, run length, e and
    β (``forecast_events.family_distance``); None when there is none.

    Why: a flow that gravity accelerates outruns its pilot, and the event-driven engine's
    cost per event grows with N beyond what the cost benchmarks (N ≤ 20000) measured. How
    far the bound falls short is a property of the kind of run more than of the run: Malik's
    two N = 107811 boxes took 2.04× their lower bounds, both, while over all of that
    study's lower-bound runs the shortfall spans ×1.0–68 (docs/forecast.md)."""
    from ..simulation.forecast_events import drive, family_distance, similar_fraction

    tc = wanted_tc(engine, options or {}, scene.dimension)
    if not scene.solid_fraction > 0:
        return None
    like = [t for t in finished if t.engine == engine and drive(t.scene) == drive(scene)
            and t.scene.run.unit == scene.run.unit and (t.tc is None) == (tc is None)
            and similar_fraction(scene, t.scene)]
    # the same t_c first: another t_c costs differently (a TC twin at 1e-6 took ×1.0–2.1
    # its 1e-5 run's time in Malik's wave study), but is a far better guide than none
    same = [t for t in like if tc is None or math.isclose(t.tc, tc, rel_tol=1e-9)]
    if not like:
        return None
    return min(same or like, key=lambda t: (family_distance(scene, t.scene), t.name))


#: under a forecast that resumes a checkpoint without a progress file of its own
OLD_CHECKPOINT_NOTE = ("  (resumes: a checkpoint without a progress file (written by an older "
                       "demstudy) does not say how far it got: the whole run's forecast)")
#: under the list of runs when a stopped run is counted by what is left of it
OWN_PACE_NOTE = ("  (a stopped run: what is left of it at its own pace over its latest "
                 "stretch, the loop's time; its set-up and final analyses come on top: "
                 "docs/forecast.md)")
#: under the list of runs when some lower bound was calibrated by a made run
CALIBRATED_NOTE = ("  (about: a lower bound × what a made run of its kind took against its "
                   "own; such estimates met ×0.30–4.0 of the actual time, ×2 or better in "
                   "14 of 20 of Malik's runs: benchmarks/bench_study_forecast.py)")
#: under the list of runs when a lower bound was calibrated by a run at another t_c
OTHER_TC_NOTE = ("  (made at another t_c: no made run of its kind has its t_c; a TC twin at "
                 "t_c = 1e-6 took ×1.0–2.1 the time of its run at 1e-5 in Malik's wave study, "
                 "so a run at a smaller t_c than its guide's may take longer, at a larger one "
                 "less)")
#: under the list of runs when some forecast is a lower bound (the total then is one too)
LOWER_BOUND_NOTE = ("  (probably more: a flow that gravity accelerates outruns its pilot; "
                    "such forecasts met ×0.7–2.3 of the actual time in the forecast "
                    "benchmark's short runs, ×1.0–68 in Malik's study runs, docs/forecast.md)")


def _duration(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def _check_selection(study: Study, quick: bool, engines: Sequence[str] | None,
                     only: Sequence[str] | None) -> None:
    """Refuse (exit 2) an engine that does not exist or that none of the study's cases use,
    and an ``--only`` text that matches no case: a typo would otherwise run nothing and
    report success."""
    from ..engines import backend_names

    cases = list(study.cases(quick))
    used = sorted({c.engine for c in cases})
    for engine in engines or ():
        if engine not in backend_names():
            raise BadOption("--engine", engine, f"allowed are {', '.join(backend_names())}")
        if engine not in used:
            raise BadOption("--engine", engine, f"no case of {study.name}"
                            f"{' (quick)' if quick else ''} runs in it; its cases use "
                            f"{', '.join(used)}")
    names = [c.name for c in cases]
    for text in only or ():
        if not any(text in n for n in names):
            raise BadOption("--only", text, f"matches no case of {study.name}"
                            f"{' (quick)' if quick else ''}; its cases are {', '.join(names)}")
    if engines and only and not any(c.engine in engines and any(t in c.name for t in only)
                                    for c in cases):
        raise BadOption("--only", ", ".join(only), f"matches no case of {study.name} that "
                        f"runs in {', '.join(engines)}")


def run_study(name: str, *, quick: bool = False, out: str | Path | None = None,
              workers: int = 1, dask: Any = None, dry_run: bool = False,
              engines: Sequence[str] | None = None, only: Sequence[str] | None = None,
              analyse_only: bool = False, records: str | Path | None = None,
              echo=print) -> StudyRun:
    """Run study ``name`` (module doc). ``dry_run``: the forecast only. ``analyse_only``:
    no runs, analyse the results files already there. ``engines``/``only`` select the cases
    to run; the analysis and report cover every run of the study already made. A failed run
    does not stop the others nor the analysis: its checks say "not run" and ``failed`` lists
    it. ``records``: where the study's run records are kept (module doc)."""
    from ..accuracy.execute import execute, is_done
    from . import get_study
    from .records import current, record_version, why_not_current

    study = get_study(name)
    if workers < 1:
        raise BadOption("--workers", workers, "a whole number >= 1 is allowed")
    out = Path(out) if out is not None else Path("results") / "studies" / (
        study.name + ("-quick" if quick else ""))
    _check_selection(study, quick, engines, only)
    started = time.perf_counter()
    tasks = tasks_of(study, quick, out, engines, only)
    result = StudyRun(study, out)
    record_dir = (Path(records) if records is not None else out / "records") \
        if study.derive is not None else None
    todo, done = [], []
    for task in tasks:
        # a run is made when its scene and its physics-changing engine options (t_c) match
        same = {"engine": task.case.engine, "options": task.case.options}
        if is_done(task.path, task.scene_toml, **same):
            done.append(task)
        elif record_dir is not None and current(record_dir / f"{task.case.name}.h5", None,
                                                task.scene_toml,
                                                record_version(study.name,
                                                               study.derive_version),
                                                **same):
            done.append(task)
            result.from_records.append(task.case.name)
        else:
            todo.append(task)
            if record_dir is not None and (record_dir / f"{task.case.name}.h5").is_file():
                why = why_not_current(record_dir / f"{task.case.name}.h5", None,
                                      task.scene_toml, "", **same)
                echo(f"warning: the record of {task.case.name} is not used ({why}): "
                     "the run is made again")
    result.reused = [t.case.name for t in done]
    echo(f"study {study.name}{' (quick)' if quick else ''}: {len(tasks)} runs, "
         f"{len(done)} already made, {len(todo)} to make; results in {out}/")
    if todo and not analyse_only:
        seconds, lines, refused, each = forecast(
            todo, 1 if dask is not None else workers,
            lambda: finished_runs(_made(study, quick, out, record_dir)))
        result.forecast_seconds = seconds
        result.failed = list(refused)
        todo = [t for t in todo if t.case.name not in refused]
        where = "a Dask cluster" if dask is not None else f"{workers} worker(s)"
        bound = ("probably more than " if LOWER_BOUND_NOTE in lines else
                 "about " if CALIBRATED_NOTE in lines or OWN_PACE_NOTE in lines else "")
        head = (f"forecast: {bound}{_duration(seconds)} on {where}" if seconds is not None
                else "forecast: unknown for some runs (listed)")
        echo(head + (" (measured speed of this machine; docs/forecast.md)"))
        for line in lines:
            echo(line)
        if dry_run:
            return result
        todo = [StudyTask(t.case, t.quick, t.path,
                          replace(t.spec, relative_cost=each.get(t.case.name, 1.0)),
                          t.scene_toml)
                for t in todo]

        def finished(record: dict) -> None:
            result.made.append(record["name"])
            echo(f"  done {record['name']}: {record['task_seconds']:.1f} s")

        try:
            execute(todo, workers=workers, dask=dask, on_done=finished)
        except EngineError as exc:
            result.failed += [t.case.name for t in todo if t.case.name not in result.made]
            echo(f"warning: {exc}")
    elif dry_run:
        return result
    # the analysis reads every run of the study already made, not only those selected to
    # make now (``engines``/``only`` choose what to run; the report covers the whole study)
    every = tasks_of(study, quick, out) if (engines or only) else tasks
    runs = {}
    for t in every:
        record = record_dir / f"{t.case.name}.h5" if record_dir is not None else None
        if record is not None and keep_record(study, t, record, echo):
            runs[t.case.name] = record
            if t.case.name not in result.from_records and not t.path.is_file():
                result.from_records.append(t.case.name)
        elif t.path.is_file():
            runs[t.case.name] = t.path
    if analyse_only and not runs:
        where = f"{out}/runs/" + (f" nor in {record_dir}/" if record_dir is not None else "")
        raise BadOption("--analyse-only", True, f"no made run of {study.name} in {where}: "
                        "make the runs first, or point --out (or --records) at them")
    result.run_seconds = sum(_run_seconds(p) for p in runs.values())
    out.mkdir(parents=True, exist_ok=True)
    result.analysis = study.analyse(runs, out, quick)
    result.wall_seconds = time.perf_counter() - started
    result.report = write_report(result, quick)
    echo(f"report: {result.report}")
    return result


def _made(study: Study, quick: bool, out: Path, record_dir: Path | None) -> dict[str, Path]:
    """Every made run of the study (not only those selected to run now): its results file,
    else its record (both written atomically: a file there is a finished run)."""
    paths = {}
    for t in tasks_of(study, quick, out):
        record = record_dir / f"{t.case.name}.h5" if record_dir is not None else None
        if t.path.is_file():
            paths[t.case.name] = t.path
        elif record is not None and record.is_file():
            paths[t.case.name] = record
    return paths


def keep_record(study: Study, task: StudyTask, record: Path, echo=print) -> bool:
    """Whether ``record`` holds the run of ``task`` after this call: a finished results file
    without a current record gets one (``Study.derive``); a record whose run is absent is
    kept as it is (module doc)."""
    from ..accuracy.execute import is_done
    from .records import current, record_version, write_record

    version = record_version(study.name, study.derive_version)
    same = {"engine": task.case.engine, "options": task.case.options}
    full = task.path if is_done(task.path, task.scene_toml, **same) else None
    if current(record, full, task.scene_toml, version, **same):
        return True
    if full is None:
        return False
    try:
        write_record(full, record, study.derive(task.case.name, full), version)
    except Exception as exc:  # noqa: BLE001 - whatever derive meets: a warning, not a crash
        # the analysis then reads the results file itself, as without records
        echo(f"warning: no record of {task.case.name} ({type(exc).__name__}: {exc})")
        return False
    echo(f"  record {record}")
    return True


def _run_seconds(path: Path) -> float:
    """A results file's ``wall_seconds`` (0 when unreadable: it is then redone anyway)."""
    import h5py

    try:
        with h5py.File(path, "r") as f:
            return float(f.attrs.get("wall_seconds", 0.0))
    except (OSError, ValueError):
        return 0.0


def _machine() -> str:
    from ..simulation.forecast import cpu_model

    return f"{cpu_model()}, Python {platform.python_version()}"


def write_report(result: StudyRun, quick: bool) -> Path:
    """``<out>/<name>.md``: the checks table, the figures and the analysis's sections."""
    from ..io.results import write_atomically
    from .report import render

    path = result.out / f"{result.study.name}.md"
    text = render(result, quick, _machine())
    write_atomically(path, text.encode())
    return path


def publish(result: StudyRun, docs: Path) -> Path:
    """Copy the report to ``docs/studies/<name>.md`` and its figures to
    ``docs/figures/studies/<name>/``, links rewritten; returns the report's new path."""
    from ..io.results import write_atomically
    from .report import render

    fig_dir = docs / "figures" / "studies" / result.study.name
    fig_dir.mkdir(parents=True, exist_ok=True)
    for figure in result.analysis.figures if result.analysis else []:
        shutil.copy2(figure.path, fig_dir / figure.path.name)
    path = docs / "studies" / f"{result.study.name}.md"
    path.parent.mkdir(parents=True, exist_ok=True)
    text = render(result, False, _machine(),
                  figure_prefix=f"../figures/studies/{result.study.name}/")
    write_atomically(path, text.encode())
    return path


def runs_by_group(runs: Mapping[str, Path], cases: Sequence[Case], group: str) -> dict[str, Path]:
    """The runs of the cases tagged ``group``."""
    names = {c.name for c in cases if c.group == group}
    return {n: p for n, p in runs.items() if n in names}
