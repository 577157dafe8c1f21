"""Command line: ``demstudy validate | deck | run | plot | calibrate``.

All quantities are in dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts
(otherwise a wall speed or the shear rate sets the time scale).
"""

from __future__ import annotations

import argparse
import math
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
    return 1 if failed else 0


def _cmd_deck(args: argparse.Namespace) -> int:
    from .decks import write_deck

    scene = load_scene(args.scene, args.set)
    path = write_deck(scene, args.out, dump=args.dump)
    print(f"wrote {path} (run it with: cd {path.parent} && lmp -in {path.name})")
    return 0


def _cmd_run(args: argparse.Namespace) -> int:
    from .decks.base import UnsupportedByEngine
    from .engines.base import RunOptions, check_run_options, get_engine

    scene = load_scene(args.scene, args.set)
    extra = {}
    if args.tc is not None:  # checked before any engine starts
        if args.engine != "edmd":
            raise UnsupportedByEngine(args.engine, "--tc", args.tc,
                                      "the TC-model time is an event-driven option (--engine edmd)")
        if not (math.isfinite(args.tc) and args.tc >= 0.0):
            raise UnsupportedByEngine(args.engine, "--tc", args.tc,
                                      "a finite time >= 0 is allowed (0 switches the model off)")
        extra["tc"] = args.tc
    out = Path(args.out or Path("results") / f"{Path(args.scene).stem}-{args.engine}.h5")
    options = RunOptions(out=out, np=args.np, dump=args.dump, resume=args.resume,
                         progress=not args.quiet, keep_frames=args.keep_frames or None,
                         isolate=True, wall_limit=args.wall_limit, extra=extra)
    check_run_options(args.engine, options)
    path = get_engine(args.engine).run(scene, options)
    print(f"results: {path}")
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
    from .analysis.suite import run_statistics
    from .io.dump import has_fast_columns, read_dump, read_dump_fast
    from .io.results import Results, frames_of, read_results, write_results
    from .scene import apply_overrides, parse_scene_text, scene_to_toml, validate_scene

    what = [w.strip() for w in args.what.split(",") if w.strip()]
    source = Path(args.source)
    if source.suffix in (".h5", ".hdf5"):
        results = read_results(source)
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
    else:
        if not args.scene:
            raise ValueError("analyzing a dump needs --scene SCENE.toml (the scene it ran)")
        from .decks.contact import contact_setup

        scene = load_scene(args.scene, args.set)
        dt = args.dt if args.dt is not None else contact_setup(scene).timestep
        fast = args.reader == "fast" or (args.reader == "auto" and has_fast_columns(source))
        reader = read_dump_fast if fast else read_dump
        results = Results({"engine": "lammps-dump",
                           "engine_version": "numpy fast reader" if fast else "MDAnalysis",
                           "scene_toml": scene_to_toml(scene), "scene_name": scene.meta.name,
                           "seed": scene.run.seed, "wall_seconds": 0.0, "source": str(source)})
        out = Path(args.out or source.with_suffix(".h5"))

        def frames():
            return reader(source, scene.dimension, dt=dt, start_time=args.start)

    for name, (data, attrs) in run_statistics(scene, frames, what, results,
                                              args.z_cells).items():
        if name == "profiles":
            results.profiles, results.profile_attrs = data, attrs
        else:
            results.groups[f"statistics/{name}"] = data
            results.group_attrs[f"statistics/{name}"] = attrs
    write_results(out, results)
    print(f"results: {out} ({', '.join(what)})")
    return 0


def _cmd_calibrate(args: argparse.Namespace) -> int:
    from .contact import calibrate as cal

    rows = cal.calibrate(dim=args.dim, kind=args.kind, e=args.e, beta=args.beta,
                         K=args.K if args.K is not None else (0.5 if args.dim == 2 else 0.4),
                         kn=args.kn, steps_per_contact=args.steps,
                         speeds=args.speeds, angles=args.angles)
    print(cal.format_table(rows))
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="demstudy",
        description="Rapid granular shear flows from one scene file (units: d = m = 1, g = 1).",
    )
    sub = parser.add_subparsers(dest="command", required=True)
    overrides = argparse.ArgumentParser(add_help=False)
    overrides.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                           help="override a scene value, e.g. --set run.production=20")

    p = sub.add_parser("validate", parents=[overrides], help="check scene files")
    p.add_argument("scenes", nargs="+")
    p.set_defaults(func=_cmd_validate)

    p = sub.add_parser("deck", parents=[overrides], help="write the LAMMPS deck of a scene")
    p.add_argument("scene")
    p.add_argument("-o", "--out", default="deck", help="output folder (default: ./deck)")
    p.add_argument("--dump", help="add a custom dump of the particles to this file")
    p.set_defaults(func=_cmd_deck)

    p = sub.add_parser("run", parents=[overrides], help="run a scene")
    p.add_argument("scene")
    p.add_argument("--engine", default="lammps", choices=["lammps", "edmd"])
    p.add_argument("--np", type=int, default=1, help="MPI ranks (default 1)")
    p.add_argument("--out", help="results file (default results/<scene>-<engine>.h5)")
    p.add_argument("--dump", type=Path, help="also write a LAMMPS custom dump of the samples")
    p.add_argument("--resume", action="store_true", help="continue from the last checkpoint")
    p.add_argument("--keep-frames", action="store_true", help="store every sampled frame")
    p.add_argument("--wall-limit", type=float, metavar="SECONDS",
                   help="checkpoint and stop after this much wall-clock time (then --resume)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.add_argument("--tc", type=float, metavar="TIME",
                   help="edmd: TC-model time t_c (default 1e-5; 0 = off). A collision within t_c "
                        "of a partner's previous one is elastic, and a particle resting on a "
                        "wall hops with period t_c: a resting bed costs ~1/t_c events per "
                        "particle and time unit (docs/edmd-engine.md)")
    p.set_defaults(func=_cmd_run)

    p = sub.add_parser("plot", help="figures of results files: profiles, stress, statistics",
                       description="One figure per kind, in the seed theses' forms; kinds a "
                                   "file lacks are skipped with a notice (docs/plots.md).")
    p.add_argument("results", nargs="+", help="results files (overlaid in each figure)")
    p.add_argument("-o", "--out", help="figure file (one kind), or OUT-<kind>.png for each of "
                                       "several kinds (default: <kind>.png)")
    p.add_argument("--kind", action="append", metavar="KIND",
                   help="profiles (default), stress, eos, vdf, angles, freepath, gr, vcorr, "
                        "lambda, waves, cooling or all; comma-separated or repeated")
    p.add_argument("--scaled", action="store_true",
                   help="profiles against (y - y0)/H: H the wall gap, or the flow depth with "
                        "an open top")
    p.add_argument("--bins", metavar="B1,B2,...",
                   help="y-bins drawn by vdf, angles, freepath, gr, vcorr (1-based: bin 1 "
                        "touches the lower wall; default: first occupied, fourth, middle)")
    p.set_defaults(func=_cmd_plot)

    p = sub.add_parser("analyze", parents=[overrides],
                       help="statistics from a results file's frames or from a LAMMPS dump")
    p.add_argument("source", help="RUN.h5 (run with --keep-frames) or a LAMMPS dump")
    p.add_argument("--scene", help="the scene (needed for dumps; default for RUN.h5: its own)")
    p.add_argument("--what", default="profiles",
                   help="comma-separated: profiles, vdf, gr, angles, freepath, stress, vcorr, "
                        "lambda, waves, cgprofiles (default: profiles)")
    p.add_argument("--z-cells", type=int, default=1, metavar="N",
                   help="3D: Malik's cells, fluctuations about the means of N z-slabs of each "
                        "y-bin for profiles (added cell_temperature*), vdf, vcorr, lambda "
                        "(default 1: the y-bin means, Campbell's strips)")
    p.add_argument("--dt", type=float, help="dump time step (default: the scene's LAMMPS one)")
    p.add_argument("--start", type=float, default=0.0, help="skip frames before this time")
    p.add_argument("--out", help="results file (default: RUN.h5 itself, or DUMP.h5)")
    p.add_argument("--reader", choices=["auto", "fast", "mdanalysis"], default="auto",
                   help="auto: the numpy fast path for demstudy's dumps, MDAnalysis otherwise")
    p.set_defaults(func=_cmd_analyze)

    p = sub.add_parser("calibrate", help="measure e, beta, t_c of binary collisions in LAMMPS")
    p.add_argument("--dim", type=int, choices=[2, 3], default=3)
    p.add_argument("--kind", choices=["pair", "wall"], default="pair")
    p.add_argument("--e", type=float, default=0.8)
    p.add_argument("--beta", type=float, default=0.5)
    p.add_argument("--K", type=float, default=None, help="reduced inertia (default disc/sphere)")
    p.add_argument("--kn", type=float, default=1e5)
    p.add_argument("--steps", type=float, default=200.0, help="steps per contact")
    p.add_argument("--speeds", type=float, nargs="+", default=[0.5, 1.0, 2.0])
    p.add_argument("--angles", type=float, nargs="+", default=[0.0, 30.0, 60.0])
    p.set_defaults(func=_cmd_calibrate)
    return parser


def main(argv: list[str] | None = None) -> int:
    from .decks.base import UnsupportedByEngine
    from .engines.base import EngineError, RunRefused, RunStopped

    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except (SceneError, UnsupportedByEngine, EngineError, ValueError, OSError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        if isinstance(exc, RunStopped):
            return 3  # checkpoint written: run again with --resume
        return 2 if isinstance(exc, SceneError | UnsupportedByEngine | RunRefused) else 1
    except KeyboardInterrupt:  # outside a run loop (which checkpoints and stops by itself)
        print("error: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
