"""Command line: ``demstudy validate | deck | run | plot | analyze | compare | forecast |
calibrate | cost | engine-map | stability | study``.

All quantities are in dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts
(otherwise a wall speed or the shear rate sets the time scale).
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from .scene import SceneError, load_scene


def _cmd_validate(args: argparse.Namespace) -> int:
    failed = 0
    for path in args.scenes:
        try:
            scene = load_scene(path, args.set)
        except SceneError as exc:
            print(exc, file=sys.stderr)
            failed += 1
            continue
        where = "open top" if scene.has_open_top else f"solid fraction {scene.solid_fraction:.4g}"
        print(f"ok: {path} ({scene.dimension}D, {scene.n_particles} particles, {where})")
        from .contact.stiffness import overlap_warning  # numpy/scipy: only when needed

        warning = overlap_warning(scene)
        if warning:
            print(f"warning: {path}: {warning}", file=sys.stderr)
    return 2 if failed else 0


def _cmd_deck(args: argparse.Namespace) -> int:
    from .engines import get_backend

    scene = load_scene(args.scene, args.set)
    backend = get_backend(args.engine)
    path = backend.write_inputs(scene, Path(args.out), dump=args.dump)
    print(f"wrote {path} (run it with: cd {path.parent} && {backend.run_inputs_hint(path)})")
    return 0


def _engine_options(args: argparse.Namespace) -> dict:
    """The engine options given on the command line (``--tc`` …), by name."""
    prefix = "engine_option_"
    return {key.removeprefix(prefix): value for key, value in vars(args).items()
            if key.startswith(prefix) and value is not None}


def _cmd_run(args: argparse.Namespace) -> int:
    from .engines import get_backend
    from .engines.lgd.convert import load_scene_or_problem
    from .simulation import RunOptions, check_run, plan_run, run_scene

    scene = load_scene_or_problem(args.scene, args.set)  # or Gutt's LGD problem (`in`)
    name = scene.meta.name if Path(args.scene).name == "in" else Path(args.scene).stem
    out = Path(args.out or Path("results") / f"{name}-{args.engine}.h5")
    options = RunOptions(out=out, np=args.np, dump=args.dump, resume=args.resume,
                         progress=not args.quiet, keep_frames=args.keep_frames or None,
                         isolate=True, wall_limit=args.wall_limit,
                         extra=_engine_options(args))
    if args.dry_run:  # the settings and the forecast; nothing runs, nothing is written
        backend = get_backend(args.engine)
        check_run(backend, scene, options)
        print(plan_run(scene, backend, options, dry_run=True).describe())
        return 0
    path = run_scene(scene, args.engine, options)
    print(f"results: {path}")
    return 0


def _cmd_lgd_import(args: argparse.Namespace) -> int:
    from .engines.lgd.convert import load_scene_or_problem
    from .scene import scene_to_toml

    scene = load_scene_or_problem(args.problem, args.set)
    text = ("# Gutt's LGD problem " + str(args.problem) + " as a demstudy lattice scene\n"
            "# (demstudy lgd-import). Units: [lattice] and its md lines in the listing's "
            "integers;\n# the rest in particle units (d = 1 = lattice spacing, m = 1, g = 1 "
            "with gravity,\n# otherwise the wall speed or the initial r.m.s. speed; "
            "docs/lgd-engine.md).\n" + scene_to_toml(scene))
    if args.out:
        Path(args.out).write_text(text)
        print(f"wrote {args.out}")
    else:
        print(text, end="")
    return 0


def _cmd_plot(args: argparse.Namespace) -> int:
    from .plots import parse_kinds, plot_files

    try:
        kinds = parse_kinds(args.kind)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    try:
        bins = [int(b) for b in args.bins.split(",") if b.strip()] if args.bins else None
    except ValueError:
        print(f"error: --bins {args.bins!r}: 1-based bin numbers, e.g. 1,4,13", file=sys.stderr)
        return 2
    written = plot_files(args.results, kinds, args.out, scaled=args.scaled, bins=bins)
    for path in written:
        print(f"figure: {path}")
    if not written:
        print(f"no figure written: none of the files holds {', '.join(kinds)}", file=sys.stderr)
    return 0


def _cmd_analyze(args: argparse.Namespace) -> int:
    from .analysis.registry import Context, compute_statistics
    from .analysis.walls import first_walls, strips_for, walls_move
    from .io.results import frames_of, read_results, write_results
    from .scene import apply_overrides, parse_scene_text, scene_to_toml, validate_scene

    what = [w.strip() for w in args.what.split(",") if w.strip()]
    source = Path(args.source)
    if source.suffix in (".h5", ".hdf5"):
        results = read_results(source)
        if not args.scene and "scene_toml" not in results.attrs:
            from .errors import BadInputFile

            raise BadInputFile(f"results file {source} has no scene_toml attribute: pass the "
                               "scene it ran with --scene SCENE.toml")
        if args.scene:
            scene = load_scene(args.scene, args.set)
        else:  # the run's own scene, with any --set applied
            data = apply_overrides(parse_scene_text(results.attrs["scene_toml"], str(source)),
                                   args.set, str(source))
            scene = validate_scene(data, str(source))
        if scene_to_toml(scene) != results.attrs["scene_toml"]:
            results.attrs["analysis_scene_toml"] = scene_to_toml(scene)
        out = Path(args.out or source)

        def frames():
            return (f for f in frames_of(results, scene.dimension) if f.time >= args.start)

        if not results.frames:
            frames = None  # statistics from frames are refused, naming themselves
    else:
        from .io.dump import dump_source

        if not args.scene:
            raise ValueError("analyzing a dump needs --scene SCENE.toml (the scene it ran)")
        scene = load_scene(args.scene, args.set)
        results, frames = dump_source(source, scene, args.dt, args.reader, args.start)
        if "angular_velocity" in results.attrs:  # a foreign dump without omega columns
            print(f"note: {source}: angular velocity {results.attrs['angular_velocity']}",
                  file=sys.stderr)
        out = Path(args.out or source.with_suffix(".h5"))
        if walls_move(scene) and not args.fixed_strips:
            print(f"note: {source}: a dump does not record where the servo walls were: "
                  "fixed strips between the scene's walls", file=sys.stderr)
            args.fixed_strips = True

    relative = strips_for(scene, frames, False if args.fixed_strips else None, str(source))
    ctx = Context(scene, frames=frames, results=results, z_cells=args.z_cells,
                  wall_relative=relative,
                  walls=first_walls(frames) if relative is False else None)
    for name, (data, attrs) in compute_statistics(what, ctx).items():
        if name == "profiles":
            results.profiles, results.profile_attrs = data, attrs
        else:
            results.groups[f"statistics/{name}"] = data
            results.group_attrs[f"statistics/{name}"] = attrs
    write_results(out, results)
    print(f"results: {out} ({', '.join(what)})")
    return 0


def _cmd_compare(args: argparse.Namespace) -> int:
    from .comparison import compare, plot_comparison
    from .errors import NotComparable

    if args.out != "none":
        _check_figure_file("-o/--out", args.out)
    fields = [f.strip() for f in args.fields.split(",") if f.strip()] if args.fields else None
    # A,B,C: replicas of one run (other seeds), combined before the comparison
    groups = [[p for p in arg.split(",") if p.strip()] for arg in args.results]
    empty = [arg for arg, group in zip(args.results, groups, strict=True) if not group]
    if empty:
        raise NotComparable(f"RUN.h5 = {empty[0]!r}: a results file, or replicas of one run "
                            "as A.h5,B.h5,... are allowed")
    try:
        comparisons = compare(*groups, fields=fields, sigma=args.sigma,
                              min_solid_fraction=args.min_solid_fraction)
    except OSError as exc:  # not a readable HDF5 file: nothing was compared
        raise NotComparable(f"cannot read the results: {exc}") from exc
    for comparison in comparisons:
        print(comparison.table(), end="\n\n")
    if args.out != "none":
        print(f"figure: {plot_comparison(comparisons, args.out, fields)}")
    return 0


def _check_figure_file(option: str, path: str) -> None:
    """A figure file matplotlib can write (by its extension), checked before computing."""
    from matplotlib.backend_bases import FigureCanvasBase

    from .errors import BadOption

    kinds = FigureCanvasBase.get_supported_filetypes()
    if Path(path).suffix.lower().lstrip(".") not in kinds:
        raise BadOption(option, path, "a figure file ending in ."
                        + ", .".join(sorted(kinds)) + " (or none: no figure) is allowed")


def _cmd_forecast(args: argparse.Namespace) -> int:
    from .engines import get_backend
    from .simulation.forecast import cpu_model, load_rates, measure_costs, rates_path

    for engine in args.engine or ["lammps", "edmd"]:
        for dim in args.dim or [2, 3]:
            soft = get_backend(engine).capabilities.soft_contact
            for model in (args.model or ["hooke"]) if soft else [None]:
                measure_costs(engine, dim, model, remeasure=args.measure)
    rates = load_rates()
    print(f"machine rates ({cpu_model()}), cached in {rates_path()}:")
    for key, entry in sorted(rates.items()):
        costs = ", ".join(f"{k} {v:.3g} s" for k, v in entry["costs"].items())
        load = f", load {entry['load']:.2g}" if entry.get("load") is not None else ""
        print(f"  {key} ({entry['measured']}{load}): {costs}\n    benchmarks: {entry['what']}")
    return 0


def _cmd_calibrate(args: argparse.Namespace) -> int:
    from .contact.calibration import CollisionRow, format_motion_table, format_table
    from .contact.mapping import walton_mismatch
    from .errors import UnsupportedByEngine

    engine = args.engine
    _check_calibrate(args)
    if args.beta0 is not None and args.mu is None:
        raise UnsupportedByEngine(engine, "--beta0", args.beta0, "beta0 is Walton's sticking "
                                  "restitution: it needs Coulomb friction, --mu")
    if args.mu is not None and args.beta is not None:
        raise UnsupportedByEngine(engine, "--beta", args.beta, "with --mu the sticking "
                                  "restitution is --beta0 (default: e)")
    sizes = args.sizes or [1.0, 1.0]
    if args.kind == "wall" and len(sizes) == 2 and sizes[0] != sizes[1]:
        raise UnsupportedByEngine(engine, "--sizes", " ".join(map(str, sizes)),
                                  "a wall collision has one particle: give one diameter")
    try:
        rows = _calibrate_rows(engine, args, sizes)
    except UnsupportedByEngine as exc:  # name the command-line option
        name = exc.field_name if exc.field_name.startswith("--") else f"--{exc.field_name}"
        raise UnsupportedByEngine(exc.engine, name.replace("steps_per_contact", "steps"),
                                  exc.value, exc.reason) from exc
    is_impact = rows and isinstance(rows[0], CollisionRow)
    print(format_table(rows) if is_impact else format_motion_table(rows))
    why = (walton_mismatch(args.e, args.beta0, args.model or "hooke")
           if args.mu is not None else None)
    if why and args.case == "impact":
        print(f"note: scenes refuse this rule for soft engines: {why}")
    return 0


def _check_calibrate(args: argparse.Namespace) -> None:
    """Values no calibration case can use: exit 2 naming the option, before anything runs."""
    from .errors import BadOption

    if not 0.0 < args.e <= 1.0:
        raise BadOption("--e", args.e, "a normal restitution in (0, 1] is allowed")
    if args.mu is not None and not args.mu >= 0.0:
        raise BadOption("--mu", args.mu, "a friction coefficient >= 0 is allowed")
    if not args.steps >= 1.0:
        raise BadOption("--steps", args.steps, "steps per contact >= 1 are allowed")
    if not args.kn > 0.0:
        raise BadOption("--kn", args.kn, "a normal stiffness > 0 is allowed")
    bad = [v for v in args.speeds if not v > 0.0]
    if bad:
        raise BadOption("--speeds", bad, "impact speeds > 0 are allowed")
    if args.sizes is not None and len(args.sizes) != 2 and (args.kind != "wall"
                                                            or len(args.sizes) != 1):
        raise BadOption("--sizes", args.sizes, "two diameters (a wall collision: one) are "
                        "allowed")
    if args.case == "rolling" and not 0.0 < args.alpha < 90.0:
        raise BadOption("--alpha", args.alpha, "an incline angle in (0, 90) degrees is "
                        "allowed")


def _calibrate_rows(engine: str, args: argparse.Namespace, sizes: list[float]) -> list:
    from .engines import get_backend

    return get_backend(engine).calibrate(
        case=args.case, dim=args.dim, kind=args.kind, e=args.e,
        beta=args.beta if args.beta is not None or args.mu is not None else 0.5,
        mu=args.mu, beta0=args.beta0, K=args.K, kn=args.kn, model=args.model,
        steps_per_contact=args.steps, speeds=args.speeds, angles=args.angles,
        sizes=(sizes[0], sizes[-1]), spin=args.spin, alpha=args.alpha, v0=args.speeds[0],
        phases=args.phases)


def _numbers(option: str, text: str) -> list[float]:
    from .errors import BadOption

    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise BadOption(option, text, "comma-separated numbers, e.g. 1e3,1e4") from None


def _whole(option: str, text: str | None) -> int | None:
    from .errors import BadOption

    try:
        return None if text is None else int(text)
    except ValueError:
        raise BadOption(option, text, "a whole number of runs >= 1 is allowed") from None


def _cmd_cost(args: argparse.Namespace) -> int:
    from .accuracy.report import text_report
    from .accuracy.study import cost

    study = cost(args.scene, overrides=args.set, quick=args.quick, tolerance=args.tolerance,
                 kstars=_numbers("--kstar", args.kstar) if args.kstar else None,
                 steps=_numbers("--steps", args.steps) if args.steps else None,
                 models=([m.strip() for m in args.models.split(",") if m.strip()]
                         if args.models else None),
                 workers=args.workers, dask=args.dask, out=args.out,
                 replicas=_whole("--replicas", args.replicas),
                 reference_replicas=_whole("--reference-replicas", args.reference_replicas),
                 dry_run=args.dry_run,
                 engines=[e.strip() for e in ",".join(args.engine).split(",") if e.strip()]
                 if args.engine else None)
    if not args.dry_run:
        print(text_report(study))
    return 0


def _cmd_study(args: argparse.Namespace) -> int:
    from .accuracy.study import check_dask_address
    from .studies.runner import publish, run_study

    dask = check_dask_address(args.dask) if args.dask else None
    result = run_study(args.name, quick=args.quick, out=args.out,
                       workers=args.workers if args.workers is not None else (os.cpu_count() or 1),
                       dask=dask,
                       dry_run=args.dry_run, analyse_only=args.analyse_only,
                       engines=[e.strip() for e in ",".join(args.engine).split(",")
                                if e.strip()] if args.engine else None,
                       only=args.only,
                       # the full study keeps its run records with the docs (DOCS/data/...)
                       records=(Path(args.records) if args.records else
                                Path(args.docs) / "data" / "studies" / args.name / "records"
                                if args.docs and not args.quick else None))
    if args.dry_run:
        return 0
    if args.docs:
        if args.quick:
            print("--docs publishes the full study only; the quick report stays in "
                  f"{result.out}/", file=sys.stderr)
        else:
            print(f"published: {publish(result, Path(args.docs))}")
    return 1 if result.failed else 0


def _cmd_engine_map(args: argparse.Namespace) -> int:
    from .accuracy.engine_map import QUICK, RESTITUTIONS, MapSettings, engine_map

    settings = MapSettings(ratio=args.ratio, timeout=args.timeout)
    dims = _numbers("--dim", args.dim)
    fractions = _numbers("--fractions", args.fractions) if args.fractions else None
    restitutions = (_numbers("--restitutions", args.restitutions) if args.restitutions
                    else RESTITUTIONS)
    if args.quick:
        settings = MapSettings(**QUICK["settings"], ratio=args.ratio, timeout=args.timeout)
        fractions = fractions or QUICK["fractions"]
        restitutions = restitutions if args.restitutions else QUICK["restitutions"]
    # a quick map never lands where ``demstudy cost`` reads the map from
    out = args.out or (Path("results") / "engine-map-quick" if args.quick else None)
    result = engine_map(dims, fractions, restitutions, settings, out=out,
                        workers=args.workers)
    print("outputs: " + ", ".join(str(p) for p in result.written))
    return 0


def _cmd_stability(args: argparse.Namespace) -> int:
    from .stability import case_names, run_suite
    from .stability.report import format_row, format_text, write_outputs

    if args.list:
        from .stability import CASES

        for name in case_names():
            c = CASES[name]
            print(f"{name} ({c.engine or c.kind}): {c.checks}; limit: {c.limit}")
        return 0
    suite = run_suite(args.engine, args.case, quick=args.quick,
                      progress=lambda row: print(format_row(row), flush=True))
    print(format_text(suite).rsplit("\n", 1)[-1])
    command = " ".join(["demstudy", "stability", *(sys.argv[1:] if args.argv is None
                                                   else args.argv)[1:]])
    written = write_outputs(suite, args.out, command=command)
    print("written: " + ", ".join(str(p) for p in written))
    return 1 if suite.failed else 0


def build_parser() -> argparse.ArgumentParser:
    from .analysis.registry import STATISTICS
    from .engines import DEFAULT_ENGINE, backend_names, get_backend
    from .plots import KINDS

    engines = backend_names()
    parser = argparse.ArgumentParser(
        prog="demstudy",
        description="Rapid granular shear flows from one scene file (units: d = m = 1, g = 1).",
    )
    sub = parser.add_subparsers(dest="command", required=True)
    overrides = argparse.ArgumentParser(add_help=False)
    overrides.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                           help="override a scene value, e.g. --set run.production=20")
    scene_help = "a scene file, or a preset shipped with demstudy (e.g. campbell1982/chute-30)"

    p = sub.add_parser("validate", parents=[overrides], help="check scene files")
    p.add_argument("scenes", nargs="+", help=scene_help)
    p.set_defaults(func=_cmd_validate)

    with_inputs = [e for e in engines if get_backend(e).capabilities.inputs]
    p = sub.add_parser("deck", parents=[overrides],
                       help="write an engine's input files for a scene (they run without "
                            "demstudy)")
    p.add_argument("scene", help=scene_help)
    p.add_argument("--engine", default=DEFAULT_ENGINE, choices=with_inputs)
    p.add_argument("-o", "--out", default="deck", help="output folder (default: ./deck)")
    p.add_argument("--dump", help="add a custom dump of the particles to this file")
    p.set_defaults(func=_cmd_deck)

    p = sub.add_parser("run", parents=[overrides], help="run a scene")
    p.add_argument("scene", help=scene_help + "; with --engine lgd also Gutt's LGD problem "
                                              "(its control file `in` or its folder)")
    p.add_argument("--engine", default=DEFAULT_ENGINE, choices=engines)
    p.add_argument("--np", type=int, default=1, help="MPI ranks (default 1)")
    p.add_argument("--out", help="results file (default results/<scene>-<engine>.h5)")
    p.add_argument("--dump", type=Path, help="also write the engine's own dump of the samples")
    p.add_argument("--resume", action="store_true", help="continue from the last checkpoint")
    p.add_argument("--keep-frames", action="store_true", help="store every sampled frame")
    p.add_argument("--wall-limit", type=float, metavar="SECONDS",
                   help="checkpoint and stop after this much wall-clock time (then --resume)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.add_argument("--dry-run", action="store_true",
                   help="print the settings (k_n, dt, stiffness basis, the pilot's impacts) "
                        "and the wall-time forecast, then stop without running")
    owners: dict[str, list] = {}  # each engine option once, whichever engines have it
    for engine in engines:
        for name, option in get_backend(engine).options.items():
            owners.setdefault(name, []).append((engine, option))
    for name, declared in owners.items():  # checked against --engine when the run starts
        option = declared[0][1]
        p.add_argument(f"--{name.replace('_', '-')}", type=option.kind,
                       dest=f"engine_option_{name}", metavar=option.metavar,
                       help="; ".join(f"{engine} only: {o.help}" for engine, o in declared))
    p.set_defaults(func=_cmd_run)

    p = sub.add_parser("lgd-import", parents=[overrides],
                       help="write Gutt's LGD problem files (control file `in`) as a scene")
    p.add_argument("problem", help="Gutt's control file `in`, or the folder holding it")
    p.add_argument("-o", "--out", help="scene file to write (default: print it)")
    p.set_defaults(func=_cmd_lgd_import)

    p = sub.add_parser("plot", help="figures of results files: profiles, stress, statistics",
                       description="One figure per kind, in the seed theses' forms; kinds a "
                                   "file lacks are skipped with a notice (docs/plots.md).")
    p.add_argument("results", nargs="+", help="results files (overlaid in each figure)")
    p.add_argument("-o", "--out", help="figure file (one kind), or OUT-<kind>.png for each of "
                                       "several kinds (default: <kind>.png)")
    p.add_argument("--kind", action="append", metavar="KIND",
                   help=f"{', '.join(KINDS)} or all (default profiles); comma-separated or "
                        "repeated")
    p.add_argument("--scaled", action="store_true",
                   help="profiles against (y - y0)/H: H the wall gap, or the flow depth with "
                        "an open top")
    p.add_argument("--bins", metavar="B1,B2,...",
                   help="y-bins drawn by vdf, angles, freepath, gr, vcorr (1-based: bin 1 "
                        "touches the lower wall; default: first occupied, fourth, middle)")
    p.set_defaults(func=_cmd_plot)

    p = sub.add_parser("analyze", parents=[overrides],
                       help="statistics from a results file's frames or from a dump")
    p.add_argument("source", help="RUN.h5 or a LAMMPS-style custom dump")
    p.add_argument("--scene", help="the scene (needed for dumps; default for RUN.h5: its own)")
    p.add_argument("--what", default="profiles",
                   help="comma-separated, of: " + "; ".join(
                       f"{n} ({s.description}; from {s.source})" for n, s in
                       STATISTICS.items()) + " (default: profiles)")
    p.add_argument("--z-cells", type=int, default=1, metavar="N",
                   help="3D: Malik's cells, fluctuations about the means of N z-slabs of each "
                        "y-bin for " + ", ".join(n for n, s in STATISTICS.items() if s.z_cells)
                        + " (default 1: the y-bin means, Campbell's strips)")
    p.add_argument("--fixed-strips", action="store_true",
                   help="walls that move (servo): bin profiles and the structure mid-plane in "
                        "strips fixed where the walls stood at the first stored frame (dumps: "
                        "the scene's walls) and the vdf between the scene's walls, not in "
                        "strips that follow the walls (the default, Campbell's ST = HGT/FND)")
    p.add_argument("--dt", type=float, help="dump time step (default: the scene's soft-contact "
                                            "time step)")
    p.add_argument("--start", type=float, default=0.0, help="skip frames before this time")
    p.add_argument("--out", help="results file (default: RUN.h5 itself, or DUMP.h5)")
    p.add_argument("--reader", choices=["auto", "fast", "mdanalysis"], default="auto",
                   help="auto: the numpy fast path for demstudy's dumps, MDAnalysis otherwise")
    p.set_defaults(func=_cmd_analyze)

    p = sub.add_parser("compare", help="profiles and stresses of runs against a reference, "
                                       "within their statistical errors",
                       description="The first file is the reference; every other file is "
                                   "compared with it bin by bin (Δ, σ_Δ, z), one table row per "
                                   "field (relative L2 error, its noise floor, max |z|, "
                                   "whether the difference is resolved) and one figure "
                                   "(docs/compare.md). Different bins are rebinned to a "
                                   "common grid, said so. A comma-separated group "
                                   "(a1.h5,a2.h5,a3.h5) is replicas of one run with other "
                                   "seeds: their mean is compared, with the standard error "
                                   "across them (R - 1 degrees of freedom).")
    p.add_argument("results", nargs="+", metavar="RUN.h5",
                   help="the reference, then the runs compared with it; A.h5,B.h5,...: "
                        "replicas of one run, combined first")
    p.add_argument("-o", "--out", default="compare.png",
                   help="figure file (default compare.png; none: no figure)")
    p.add_argument("--fields", metavar="F1,F2,...",
                   help="fields to compare, e.g. temperature,velocity[x],stress/xy, or a "
                        "dataset for all its components (velocity, stress); default all")
    p.add_argument("--sigma", type=float, default=3.0,
                   help="significance of each field's family test, in σ (default 3)")
    p.add_argument("--min-solid-fraction", type=float, default=0.0, metavar="NU",
                   help="leave out bins more dilute than this in either run (default 0)")
    p.set_defaults(func=_cmd_compare)

    p = sub.add_parser("forecast", help="this machine's measured speed for the wall-time "
                                        "forecasts (docs/forecast.md)")
    p.add_argument("--measure", "--remeasure", action="store_true", dest="measure",
                   help="run the benchmarks again (default: show the cached rates, measuring "
                        "the missing ones)")
    p.add_argument("--engine", action="append", choices=engines,
                   help="engines to measure (default lammps and edmd; repeatable)")
    p.add_argument("--dim", type=int, action="append", choices=[2, 3],
                   help="dimensions (default 2 and 3; repeatable)")
    p.add_argument("--model", action="append", choices=["hooke", "hertz"],
                   help="soft contact models (default hooke; repeatable)")
    p.set_defaults(func=_cmd_forecast)

    soft = [e for e in engines if get_backend(e).capabilities.soft_contact]
    p = sub.add_parser("calibrate", help="measure binary soft collisions (e, beta, t_c, peak "
                                         "force) and wall motions against theory")
    p.add_argument("--engine", default=DEFAULT_ENGINE, choices=soft)
    p.add_argument("--case", choices=["impact", "rolling", "sliding"], default="impact",
                   help="impact: binary collisions; rolling: incline (--alpha); sliding: "
                        "launched at the first --speeds without spin, ends rolling at "
                        "v0/(1+K)")
    p.add_argument("--dim", type=int, choices=[2, 3], default=3)
    p.add_argument("--kind", choices=["pair", "wall"], default=None,
                   help="impact: two particles or one on a wall (default pair)")
    p.add_argument("--model", choices=["hooke", "hertz"], default=None,
                   help="normal force (hertz: kt, dt matched at the largest speed)")
    p.add_argument("--e", type=float, default=0.8)
    p.add_argument("--beta", type=float, default=None,
                   help="tangential restitution of an uncapped spring (default 0.5; not with "
                        "--mu)")
    p.add_argument("--mu", type=float, default=None, help="Coulomb friction (Walton's rule)")
    p.add_argument("--beta0", type=float, default=None,
                   help="Walton's sticking restitution (default: e, as in scenes)")
    p.add_argument("--K", type=float, default=None, help="reduced inertia (default disc/sphere)")
    p.add_argument("--kn", type=float, default=1e5)
    p.add_argument("--steps", type=float, default=200.0,
                   help="steps per contact (an uncapped spring's k_t is compensated for it)")
    p.add_argument("--phases", type=int, default=None,
                   help="impact: average each collision over this many impact phases "
                        "(default 1: first overlap half a step in)")
    p.add_argument("--speeds", type=float, nargs="+", default=[0.5, 1.0, 2.0],
                   help="impact speeds |g| (sliding: the launch speed)")
    p.add_argument("--angles", type=float, nargs="+", default=[0.0, 30.0, 60.0],
                   help="impact angles from the normal [deg]")
    p.add_argument("--spin", type=float, default=0.0,
                   help="initial angular velocity of particle 1 about the axis normal to the "
                        "plane of impact")
    p.add_argument("--sizes", type=float, nargs="+", default=None, metavar="D",
                   help="diameters of the two particles (masses ∝ d^dim); wall: one")
    p.add_argument("--alpha", type=float, default=30.0, help="incline angle [deg] (rolling)")
    p.set_defaults(func=_cmd_calibrate)

    p = sub.add_parser("cost", parents=[overrides],
                       help="accuracy vs cost: soft runs over stiffness and steps per contact "
                            "against the event-driven reference (docs/cost.md)")
    p.add_argument("scene", help=scene_help)
    p.add_argument("--kstar", metavar="K1,K2,...",
                   help="dimensionless stiffnesses k* (default 1e3,1e4,1e5,1e6; the scene's "
                        "k* definition is printed)")
    p.add_argument("--steps", metavar="S1,S2,...",
                   help="steps per contact, each >= 10 (default 10,50,200)")
    p.add_argument("--models", metavar="hooke,hertz", help="contact models (default both)")
    p.add_argument("--engine", action="append", metavar="lammps,liggghts",
                   help="soft-contact engines of the ladder (default lammps; repeat or list "
                        "several: every soft setting runs in each)")
    p.add_argument("--tolerance", type=float, default=0.02,
                   help="relative profile error to meet (default 0.02)")
    p.add_argument("--workers", type=int, help="local processes (default: the cores)")
    p.add_argument("--dask", metavar="ADDRESS",
                   help="run on this Dask scheduler instead (tcp://host:port or host:port)")
    p.add_argument("--out", help="ladder folder (default results/cost/<scene>/)")
    p.add_argument("--replicas", default="1", metavar="R",
                   help="make every run R times (seeds seed, seed+1, ...; files -r0, -r1, "
                        "...): errors from the replicas' scatter, cost the SUM of their wall "
                        "times (default 1)")
    p.add_argument("--reference-replicas", metavar="R_REF",
                   help="replicas of the event-driven reference (default: --replicas)")
    p.add_argument("--quick", action="store_true",
                   help="a tiny ladder of short runs (k* 1e2,1e3,1e4, 10 steps/contact, "
                        "hooke; not with --kstar, --steps or --models)")
    p.add_argument("--dry-run", action="store_true",
                   help="print every planned run with its forecast and the total on the "
                        "workers; run nothing, write nothing")
    p.set_defaults(func=_cmd_cost)

    p = sub.add_parser("study", help="a seed study end to end: runs, analysis, figures in the "
                       "thesis's forms and a report checking its statements (docs/studies/)")
    p.add_argument("name", help="campbell1982, gutt1989 or malik2008")
    p.add_argument("--quick", action="store_true",
                   help="a reduced study in minutes (short runs, fewer cases) into "
                        "results/studies/NAME-quick/")
    p.add_argument("--workers", type=int, help="local processes (default: the cores)")
    p.add_argument("--dask", metavar="ADDRESS",
                   help="run on this Dask scheduler instead (tcp://host:port or host:port)")
    p.add_argument("--out", help="study folder (default results/studies/NAME[-quick]/)")
    p.add_argument("--engine", action="append", metavar="edmd,lammps",
                   help="only the cases of these engines")
    p.add_argument("--only", action="append", metavar="TEXT",
                   help="only the cases whose name contains TEXT (repeatable)")
    p.add_argument("--dry-run", action="store_true",
                   help="print the runs to make and the forecast; run nothing")
    p.add_argument("--analyse-only", action="store_true",
                   help="no runs: analyse the results files (or run records) already made")
    p.add_argument("--docs", metavar="DOCS",
                   help="also publish the report and figures under DOCS (docs/studies/NAME.md,"
                        " docs/figures/studies/NAME/) and keep the runs' records in "
                        "DOCS/data/studies/NAME/records/, reused as made runs")
    p.add_argument("--records", metavar="DIR",
                   help="where the runs' records are kept and reused (default: "
                        "DOCS/data/studies/NAME/records/ with --docs, else OUT/records/); "
                        "with --analyse-only: a report from committed records, unpublished")
    p.set_defaults(func=_cmd_study)

    p = sub.add_parser("engine-map",
                       help="which engine is cheaper at 2 %% accuracy, over solid fraction "
                            "and restitution in Lees-Edwards shear (docs/accuracy-cost.md)")
    p.add_argument("--dim", default="2,3", metavar="2,3", help="dimensions (default 2,3)")
    p.add_argument("--fractions", metavar="F1,F2,...",
                   help="solid fractions (default: 0.1,0.3,0.5,0.65,0.75 for discs, "
                        "0.1,0.3,0.45,0.55,0.6 for spheres)")
    p.add_argument("--restitutions", metavar="E1,E2,...",
                   help="restitutions (default 0.5,0.7,0.9,0.99)")
    p.add_argument("--ratio", type=float, default=0.05, metavar="R",
                   help="soft contact time t_c = R x the mean free-flight time (default 0.05)")
    p.add_argument("--timeout", type=float, default=20.0, metavar="SECONDS",
                   help="event-driven runs longer than this are impractical (default 20)")
    p.add_argument("--workers", type=int, help="local processes (default: the cores)")
    p.add_argument("--out", help="folder (default results/engine-map/, with --quick "
                                 "results/engine-map-quick/)")
    p.add_argument("--quick", action="store_true",
                   help="two points per dimension (fraction 0.3, e = 0.7 and 0.9), very "
                        "short runs, one repeat")
    p.set_defaults(func=_cmd_engine_map)

    p = sub.add_parser("stability", help="hard cases in every engine where they mean "
                                         "something: a pass/fail table (docs/stability.md)",
                       description="Runs the suite of hard cases (very stiff and very soft "
                                   "contacts, energy drift, fast impacts, too large time "
                                   "steps, dense shear, servo walls, inelastic collapse, "
                                   "resting beds, t_c dependence) in every engine whose kind "
                                   "they suit, prints the table and writes it as Markdown, "
                                   "CSV and JSON. Exit 1 when a row fails.")
    p.add_argument("--engine", action="append", metavar="ENGINE",
                   help=f"engines ({', '.join(engines)}; default all; repeatable)")
    p.add_argument("--case", action="append", metavar="NAME",
                   help="cases (default all; repeatable; --list shows them)")
    p.add_argument("--quick", action="store_true",
                   help="the short version of every case (about a minute in all)")
    p.add_argument("--out", default=str(Path("results") / "stability.md"),
                   help="Markdown table (default results/stability.md; .csv and .json "
                        "next to it); the committed one is docs/stability.md")
    p.add_argument("--list", action="store_true", help="list the cases and stop")
    p.set_defaults(func=_cmd_stability)
    return parser


def main(argv: list[str] | None = None) -> int:
    from .errors import (
        BadInputFile,
        BadOption,
        EngineError,
        NotComparable,
        RunAborted,
        RunRefused,
        RunStopped,
        StatisticUnavailable,
        UnsupportedByEngine,
    )
    from .io.results import COMMAND_LINE_ENV, set_command_line

    args = build_parser().parse_args(argv)
    args.argv = argv
    previous = os.environ.get(COMMAND_LINE_ENV)
    set_command_line(["demstudy", *(sys.argv[1:] if argv is None else argv)])
    try:
        return args.func(args)
    except (SceneError, UnsupportedByEngine, EngineError, ValueError, OSError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        if isinstance(exc, RunStopped):
            return 3  # checkpoint written: run again with --resume
        if isinstance(exc, RunAborted):
            return 130  # a second Ctrl-C: as a shell reports SIGINT (128 + 2)
        refused = (SceneError | UnsupportedByEngine | RunRefused | StatisticUnavailable
                   | BadOption | NotComparable | BadInputFile)
        return 2 if isinstance(exc, refused) else 1  # 2: nothing ran or was computed
    except KeyboardInterrupt:  # outside a run loop (which checkpoints and stops by itself)
        print("error: interrupted", file=sys.stderr)
        return 130
    finally:  # the results files written by this call (and its children) record it
        if previous is None:
            os.environ.pop(COMMAND_LINE_ENV, None)
        else:
            os.environ[COMMAND_LINE_ENV] = previous


if __name__ == "__main__":
    sys.exit(main())
