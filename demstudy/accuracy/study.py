"""``cost(scene, ...)``: the whole accuracy-versus-cost study of one scene (docs/cost.md).

The event-driven reference runs first (with a t_c ladder when its TC model acted), then the
soft ladder; every run is one results file in the ladder folder, reused on a rerun. With
``replicas`` every run is made that many times with successive seeds, and the ladder rates
each setting by the replicas' mean, errors from their scatter, cost the sum of their times.
Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise the shear rate
or wall speed sets the time unit).
"""

from __future__ import annotations

import math
import os
import re
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..engines import backend_names, get_backend
from ..errors import BadOption
from ..scene import Scene, load_scene, scene_to_toml
from . import analyze
from .execute import Task, execute, pending
from .forecast import LadderForecast, ladder_forecast, measure_machine
from .plan import (
    RunSpec,
    reference_ladder,
    replicate,
    soft_kn,
    soft_ladder,
    stiffness_scale,
)

DEFAULT_KSTARS = (1e3, 1e4, 1e5, 1e6)
DEFAULT_STEPS = (10.0, 50.0, 200.0)
DEFAULT_MODELS = ("hooke", "hertz")
QUICK = {"kstars": (1e2, 1e3, 1e4), "steps": (10.0,), "models": ("hooke",),
         "run": {"equilibration": 10.0, "production": 30.0}}

#: the reference's t_c is laddered when more than this fraction of its events were
#: collisions the TC model made elastic
TC_ACTIVE_FRACTION = 1e-4


@dataclass
class CostStudy:
    """What ``cost`` found: ``rows`` (one per run, reference first), the chosen reference,
    the fits, the choice at the tolerance, the recommendation, and which runs were made now
    (``executed``) or reused (``skipped``)."""

    folder: Path
    scale: str
    rows: list[dict]
    reference: dict
    tolerance: float
    choice: dict | None
    recommendation: str
    fits: dict[str, Any] = field(default_factory=dict)
    executed: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    scale_label: str = "$k^*$"
    #: the engine map's line for this scene (nearest grid point), None without a map
    map_hint: str | None = None
    #: seconds spent: "forecast" (measuring the machine if needed, the event-driven pilot,
    #: the forecasts), "runs" (executing, as the workers saw it: task_seconds summed),
    #: "ladder" (running everything), "analysis" (comparisons, fits, outputs)
    timings: dict[str, float] = field(default_factory=dict)
    #: the whole ladder's forecast, made before any run (printed first)
    forecast: LadderForecast | None = None


def _check(name: str, values: Sequence[float], low: float = 0.0,
           strict: bool = True) -> list[float]:
    """Finite numbers > ``low`` (``strict``) or ≥ ``low``."""
    values = [float(v) for v in values]
    bad = [v for v in values if not (math.isfinite(v) and (v > low if strict else v >= low))]
    if not values or bad:
        allowed = (f"positive numbers (> {low:g})" if strict else f"numbers ≥ {low:g}")
        raise BadOption(name, bad or values, f"{allowed} are allowed")
    return values


def check_folder(path: Path) -> Path:
    """The ladder folder, absolute (pool and Dask workers in another working directory write
    into it): refused when it, or a folder above it, is an existing file."""
    path = path.expanduser().resolve()
    for part in (path, *path.parents):
        if part.exists() and not part.is_dir():
            raise BadOption("--out", str(path), f"a folder is allowed; {part} is a file")
    return path


#: seconds to wait for a Dask scheduler before giving up
DASK_TIMEOUT = 5.0


def check_dask_address(address: str) -> str:
    """A scheduler address ``tcp://host:port`` or ``host:port`` (port 1–65535)."""
    rest = address[len("tcp://"):] if address.startswith("tcp://") else address
    host, _, port = rest.rpartition(":")
    if not (host and "/" not in host and port.isdigit() and 0 < int(port) < 65536):
        raise BadOption("--dask", address, "a Dask scheduler address tcp://host:port or "
                        "host:port is allowed")
    return address


def connect(address: str):
    """A ``distributed.Client`` of the scheduler at ``address``; a scheduler that does not
    answer within ``DASK_TIMEOUT`` seconds is a BadOption (nothing ran)."""
    from distributed import Client

    try:
        return Client(address, timeout=f"{DASK_TIMEOUT:g}s")
    except (OSError, TimeoutError) as exc:
        raise BadOption("--dask", address, f"no Dask scheduler answered within "
                        f"{DASK_TIMEOUT:g} s ({type(exc).__name__}); start one (dask "
                        "scheduler) or check the address") from None


def _soft_engines(engines: Sequence[str] | None) -> list[str]:
    """The ladder's soft engines, checked: registered, time-stepped (soft contacts)."""
    names = ["lammps"] if engines is None else list(dict.fromkeys(engines))
    known = [n for n in backend_names() if get_backend(n).capabilities.soft_contact]
    bad = [n for n in names if n not in known]
    if bad or not names:
        raise BadOption("--engine", bad or names,
                        f"soft-contact engines ({', '.join(known)}) are allowed")
    return names


def _models_left_out(scene: Scene, engines: Sequence[str],
                     models: Sequence[str]) -> dict[tuple[str, str], str]:
    """(engine, model) pairs an engine refuses whatever the stiffness (LIGGGHTS: Hertz),
    with its reason; an engine that runs none of ``models`` is refused (``BadOption``)."""
    from ..errors import UnsupportedByEngine

    out = {}
    for engine in engines:
        for model in models:
            # the ladder gives k_n itself: check the contact model alone
            soft = scene.soft.model_copy(update={"model": model, "stiffness": 1e4,
                                                 "hardness": None})
            try:
                get_backend(engine).check(scene.model_copy(update={"soft": soft}), None)
            except UnsupportedByEngine as exc:
                if exc.field_name != "soft.model":
                    raise
                out[(engine, model)] = exc.reason
        if all((engine, m) in out for m in models):
            raise BadOption("--models", list(models), f"{engine} runs none of them: "
                            + out[(engine, models[0])])
    return out


def _count(name: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise BadOption(name, value, "a whole number of runs >= 1 is allowed")
    return value


def cost(scene: Scene | str | os.PathLike, *, kstars: Sequence[float] | None = None,
         steps: Sequence[float] | None = None, models: Sequence[str] | None = None,
         tolerance: float = 0.02, workers: int | None = None, dask: Any = None,
         out: str | os.PathLike | None = None, overrides: Sequence[str] = (),
         quick: bool = False, tc_ladder: bool | None = None, figure: bool = True,
         replicas: int = 1, reference_replicas: int | None = None, dry_run: bool = False,
         engines: Sequence[str] | None = None, progress=print) -> CostStudy:
    """Run (or resume) the cost ladder of ``scene`` and write its table, summary and figure
    into ``out`` (default ``results/cost/<scene name>/``, made absolute). ``kstars``:
    dimensionless stiffnesses (``plan.stiffness_scale``; default 1e3…1e6), ``steps``: steps
    per contact (≥ 10; default 10, 50, 200), ``models``: hooke and/or hertz (default both);
    ``workers`` local processes (default: the machine's cores) or ``dask`` (a scheduler
    address ``tcp://host:port`` or ``host:port``, or a ``distributed.Client``). ``quick``: a
    tiny ladder of short runs (not with ``kstars``, ``steps`` or ``models``). ``tc_ladder``:
    force (True) or forbid (False) the reference's t_c ladder (default: when its TC model
    acted). ``replicas``: make every soft run that many times (seeds seed, seed + 1, …; files
    ``…-r0.h5``, ``…-r1.h5``): errors from the replicas' scatter, cost the sum of their wall
    times; ``reference_replicas``: the same for the reference (default ``replicas``; the
    event-driven reference is cheap). The forecast of the whole ladder (``study.forecast``)
    is printed first; ``dry_run``: print it and stop (nothing runs, nothing is written).
    ``engines``: the soft-contact engines of the ladder (default ``lammps``; ``liggghts`` too:
    every soft setting runs in each, runs of other engines than LAMMPS are named
    ``soft-ENGINE-…``); an engine that cannot express the scene is refused before anything
    runs.
    ``progress``: called with one line per event. Bad values raise ``BadOption`` before
    anything runs."""
    replicas = _count("--replicas", replicas)
    reference_replicas = _count("--reference-replicas", replicas if reference_replicas is None
                                else reference_replicas)
    if quick:
        given = [n for n, v in (("--kstar", kstars), ("--steps", steps), ("--models", models))
                 if v is not None]
        if given:
            raise BadOption("--quick", True, f"not together with {', '.join(given)} (--quick "
                            "sets its own ladder: drop one of them)")
        kstars, steps, models = QUICK["kstars"], QUICK["steps"], QUICK["models"]
    kstars = _check("--kstar", DEFAULT_KSTARS if kstars is None else kstars)
    steps = _check("--steps", DEFAULT_STEPS if steps is None else steps, 10.0, strict=False)
    models = list(DEFAULT_MODELS if models is None else models)
    if not tolerance > 0:
        raise BadOption("--tolerance", tolerance, "a relative error > 0 is allowed")
    bad = [m for m in models if m not in ("hooke", "hertz")]
    if bad or not models:
        raise BadOption("--models", bad or list(models), "hooke and/or hertz are allowed")
    engines = _soft_engines(engines)
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or workers < 1):
        raise BadOption("--workers", workers, "a whole number of processes >= 1 is allowed")
    if isinstance(dask, str | os.PathLike):
        dask = check_dask_address(str(dask))
    if not isinstance(scene, Scene):
        sections = {"run": QUICK["run"]} if quick else {}
        scene = load_scene(scene, overrides, **sections)
    elif quick:
        scene = scene.model_copy(update={"run": scene.run.model_copy(update=QUICK["run"])})
    for engine in engines:  # refuse before anything runs, naming the field
        get_backend(engine).check(scene, None)
    left_out = _models_left_out(scene, engines, models)
    # absolute: Dask workers (and pool workers) in another directory write into this folder
    folder = check_folder(Path(out or Path("results") / "cost" / scene.meta.name))
    workers = workers or os.cpu_count() or 1
    scale = stiffness_scale(scene)
    study = CostStudy(folder, scale.definition, [], {}, tolerance, None, "",
                      scale_label=scale.label)

    from ..engines.edmd.core import default_tc

    if max(replicas, reference_replicas) > 1:
        top = scene.run.seed + max(replicas, reference_replicas) - 1
        if top >= 2**31:
            raise BadOption("--replicas", max(replicas, reference_replicas),
                            f"seeds run.seed ({scene.run.seed}) + i must stay below 2^31")
        study.notes.append(f"replicas: {reference_replicas} per reference, {replicas} per soft "
                           f"run (seeds {scene.run.seed}, {scene.run.seed + 1}, …); errors "
                           "from their scatter, cost = the SUM of their wall times")
    refs = [replicate([r], reference_replicas)
            for r in reference_ladder(default_tc(scene.dimension))]
    softs = [replicate([s], replicas) for s in soft_ladder(kstars, steps, models, engines)
             if (s.engine, s.model) not in left_out]
    for (engine, model), why in left_out.items():
        progress(f"note: {engine} runs no {model} contacts ({why}): left out of the ladder")
    # an unreachable scheduler is refused before anything runs (a dry run runs nothing)
    client = connect(dask) if isinstance(dask, str) and not dry_run else dask
    try:
        return _study(study, scene, client, dask, refs, softs, tc_ladder, workers, dry_run,
                      figure, progress)
    finally:
        if client is not dask:
            client.close()


def _study(study: CostStudy, scene: Scene, client: Any, dask: Any,
           refs: list[list[RunSpec]], softs: list[list[RunSpec]], tc_ladder: bool | None,
           workers: int, dry_run: bool, figure: bool, progress) -> CostStudy:
    """The forecast, then (unless ``dry_run``) the runs and the outputs of ``cost``."""
    folder, base = study.folder, scene_to_toml(scene)
    # the whole ladder's forecast first; the machine measured here, once, before any worker
    # starts (workers then read it from the cache instead of benchmarking a loaded machine)
    started = time.perf_counter()
    phases = {name: pending(Task(s, base, folder / f"{s.name}.h5") for s in specs)
              for name, specs in (("reference", refs[0]),
                                  (_tc_phase(folder, refs, tc_ladder),
                                   [s for g in refs[1:] for s in g]),
                                  ("soft", [s for g in softs for s in g]))}
    phases.pop("none", None)
    study.forecast = ladder_forecast(phases, None if dask is not None else workers,
                                     measure_machine(scene.dimension, sorted(
                                         {g[0].model for g in softs}), sorted(
                                         {g[0].engine for g in softs})))
    study.timings["forecast"] = time.perf_counter() - started
    for line in study.forecast.lines():
        progress(line)
    if dry_run:
        study.recommendation = "dry run: nothing ran"
        return study
    folder.mkdir(parents=True, exist_ok=True)

    def run_all(specs: list[RunSpec]) -> None:
        todo, done = pending(Task(s, base, folder / f"{s.name}.h5") for s in specs)
        study.skipped += [t.spec.name for t in done]
        if todo:
            progress(f"cost: {len(todo)} run(s) to make, {len(done)} reused, "
                     f"{'dask' if client is not None else f'{min(workers, len(todo))} worker(s)'}")
        started = time.perf_counter()
        records = execute(todo, min(workers, len(todo)) if client is None else workers, client,
                          lambda r: (study.executed.append(r["name"]),
                                     progress(f"  done {r['name']} ({r['wall_seconds']:.3g} s)")))
        study.timings["ladder"] = study.timings.get("ladder", 0.0) + time.perf_counter() - started
        study.timings["runs"] = study.timings.get("runs", 0.0) + sum(
            r["task_seconds"] for r in records)

    _run_ladder(study, run_all, refs, softs, tc_ladder)
    started = time.perf_counter()
    _assemble(study, scene, refs, softs)
    from .report import write_outputs

    write_outputs(study, figure=figure)
    study.timings["analysis"] = time.perf_counter() - started
    return study


def _run_ladder(study: CostStudy, run_all, refs: list[list[RunSpec]],
                softs: list[list[RunSpec]], tc_ladder: bool | None) -> None:
    """The reference, its t_c ladder when asked for or when its TC model acted, the soft
    runs (``refs`` is cut to the references made)."""
    run_all(refs[0])
    if tc_ladder or (tc_ladder is None and _tc_active(study.folder / f"{refs[0][0].name}.h5")):
        study.notes.append("reference t_c laddered (" + (
            "asked for)" if tc_ladder else "its TC model acted)"))
        run_all([s for group in refs[1:] for s in group])
    else:
        del refs[1:]
    run_all([s for group in softs for s in group])


def _tc_phase(folder: Path, refs: list[list[RunSpec]], tc_ladder: bool | None) -> str:
    """The forecast's phase of the reference's t_c ladder: "tc-ladder" (it will run),
    "none" (it will not) or "tc-ladder?" (the reference, not made yet, decides)."""
    from .forecast import MAYBE

    if tc_ladder is not None:
        return "tc-ladder" if tc_ladder else "none"
    done = [folder / f"{s.name}.h5" for s in refs[0]]
    if not all(p.is_file() for p in done):
        return MAYBE
    try:
        return "tc-ladder" if _tc_active(done[0]) else "none"
    except Exception:  # noqa: BLE001 - an unreadable file is redone: undecided
        return MAYBE


def _tc_active(path: Path) -> bool:
    """Whether more than TC_ACTIVE_FRACTION of the reference's events were collisions its TC
    model made elastic (attribute ``elastic_tc_collisions``, else its approximations note)."""
    from ..io.results import read_results

    attrs = read_results(path, skip=("frames", "collisions")).attrs
    count = attrs.get("elastic_tc_collisions")
    if count is None:
        found = re.search(r"(\d+) such collisions", str(attrs.get("approximations", "")))
        count = int(found.group(1)) if found else 0
    return count > TC_ACTIVE_FRACTION * max(int(attrs.get("events", 0)), 1)


def _assemble(study: CostStudy, scene: Scene, refs: list[list[RunSpec]],
              softs: list[list[RunSpec]]) -> None:
    """The rows: one per run (its replicas combined), reference first."""
    from .engine_map import TC_IMPRACTICAL
    from .rows import choose_reference, soft_row, tc_note

    reference, ref_rows = choose_reference(study.folder, refs, study.notes)
    study.reference = reference
    rows = [soft_row(study.folder, group, soft_kn(scene, group[0].model, group[0].kstar),
                     reference) for group in softs]
    study.rows = ref_rows + rows
    study.choice = analyze.pick_cheapest(rows, study.tolerance)
    # the noise that limits the verdict: the chosen run's, else the quietest run's
    floor = (study.choice["floor"] if study.choice else
             min((r["floor"] for r in rows if math.isfinite(r["floor"])), default=math.nan))
    study.recommendation = analyze.recommend(study.choice, reference["wall_seconds"],
                                             study.tolerance, floor)
    share = reference.get("tc_share", 0.0)
    if share > TC_IMPRACTICAL:  # the reference is not the hard-particle limit: say so
        study.recommendation += f" ({tc_note(share)}; the errors are against it)"
    study.fits = _fits(rows)
    from .map_output import map_hint

    try:  # the map is advice: a study never fails on it
        study.map_hint = map_hint(scene)
    except (OSError, ValueError, KeyError) as exc:
        study.map_hint = f"engine map unreadable: {exc}"


def _fits(rows: list[dict]) -> dict[str, Any]:
    """error(k*) per model at its largest steps per contact, and error(t_c/τ_flight) over
    the runs with health figures at the ladder's largest steps per contact: fitted where
    enough runs have an error > 0."""
    fits: dict[str, Any] = {}
    for model in sorted({r["model"] for r in rows}):
        mine = [r for r in rows if r["model"] == model]
        top = max(r["steps_per_contact"] for r in mine)
        mine = [r for r in mine if r["steps_per_contact"] == top]
        key = f"error(k*) {model}, {top:g} steps/contact"
        try:
            fits[key] = analyze.fit_convergence([r["kstar"] for r in mine],
                                                [r["error"] for r in mine])
        except (ValueError, RuntimeError) as exc:
            fits[key] = f"not fitted: {exc}"
    # at the most steps per contact only: fewer steps add an integration error of their own
    # (10 steps per contact: the rotational temperature off by ~15 % at any stiffness)
    top = max((r["steps_per_contact"] for r in rows), default=math.nan)
    flight = [r for r in rows if math.isfinite(r.get("tc_flight", math.nan))
              and r["steps_per_contact"] == top]
    if flight:
        try:  # error = a (t_c/τ)^p + floor: fitted as a function of τ/t_c
            fits["error(t_c/tau_flight)"] = analyze.fit_convergence(
                [1 / r["tc_flight"] for r in flight], [r["error"] for r in flight])
        except (ValueError, RuntimeError) as exc:
            fits["error(t_c/tau_flight)"] = f"not fitted: {exc}"
    return fits
