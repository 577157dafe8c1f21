"""Every statistic demstudy computes, registered once by name (MDAnalysis's registry pattern).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.

A :class:`Statistic` says what it is computed from — ``stream``: fed frame by frame during
the run (or over stored frames afterwards); ``frames``: needs the stored frames (two passes);
``collisions``: the engine's collision log; ``results``: what the results file already holds
— what it requires (dimension, the profile axis, an engine capability, collisions logged),
which figures draw it, and how to compute it. The scene schema's allowed
``measure.statistics``, the validation of a scene's statistics, the CLI's ``--what`` choices,
the plot kinds and the suite all derive from :data:`STATISTICS`; the simulation loop honours
a scene's statistics from it (feeding the stream ones, keeping the frames or the log the
others need). Nothing here imports the analyses themselves until a statistic is computed.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any, Literal

from ..errors import StatisticUnavailable
from ..io.frames import Frame

Source = Literal["stream", "frames", "collisions", "results"]

__all__ = ["STATISTICS", "Context", "Statistic", "compute_statistics", "engine_problems",
           "scene_problems", "statistic"]


@dataclass
class Context:
    """What a statistic is computed from: the scene, frames (a callable returning a fresh
    iterable; None when none are stored), the results so far (``Results``; None for a dump),
    Malik's z cells, the wall positions when production started (servo walls move), and
    whether the y bins follow the walls (``wall_relative``; None: when the walls move, each
    frame then carrying its walls in ``frame.extra["walls"]``, :mod:`.walls`)."""

    scene: Any
    frames: Callable[[], Iterable[Frame]] | None = None
    results: Any = None
    z_cells: int = 1
    walls: tuple[float, float] | None = None
    wall_relative: bool | None = None


@dataclass(frozen=True)
class Statistic:
    name: str
    description: str
    source: Source
    build: Callable[[Context], Any]  # stream: an AnalysisBase to feed; else (data, attrs)
    plots: tuple[str, ...] = ()
    dims: tuple[int, ...] = (2, 3)
    axis_y: bool = False  # binned along y only
    capability: str | None = None  # engine capability it needs (``Capabilities`` field)
    log_every: int = 0  # collisions the engine must log (1: every one)
    z_cells: bool = False  # takes Malik's cells (``--z-cells``)
    run_group: str | None = None  # the group a run writes it to besides /statistics/<name>

    def compute(self, ctx: Context) -> tuple[dict[str, Any], dict[str, Any]]:
        """(datasets, attributes) of this statistic from ``ctx``."""
        if self.source == "stream":
            if ctx.frames is None:
                raise StatisticUnavailable(f"{self.name}: needs frames (run with "
                                           "--keep-frames or measure.keep_frames = true)")
            analysis = self.build(ctx).run(ctx.frames())
            return analysis.results, analysis.attrs
        if self.source == "frames" and ctx.frames is None:
            raise StatisticUnavailable(f"{self.name}: needs the stored frames (run with "
                                       "--keep-frames)")
        return self.build(ctx)


STATISTICS: dict[str, Statistic] = {}
#: what each engine capability a statistic can need is, in words
CAPABILITY_TEXT = {"collision_log": "a log of the collisions (event-driven engines)",
                   "stress": "the engine's interaction stress"}


def statistic(name: str, description: str, source: Source, **spec: Any):
    """Register the decorated builder as statistic ``name`` (see :class:`Statistic`)."""
    def register(build: Callable[[Context], Any]) -> Callable[[Context], Any]:
        STATISTICS[name] = Statistic(name, description, source, build, **spec)
        return build
    return register


def scene_problems(scene: Any) -> list[str]:
    """Why a scene's ``measure.statistics`` cannot be computed for any run of that scene
    (unknown names, the wrong dimension): scene validation reports these."""
    problems = []
    for name in scene.measure.statistics:
        stat = STATISTICS.get(name)
        if stat is None:
            problems.append(f"measure.statistics: unknown statistic {name!r} (allowed: "
                            f"{', '.join(STATISTICS)})")
        elif scene.dimension not in stat.dims:
            problems.append(f"measure.statistics: {name!r} ({stat.description}) needs a "
                            f"{' or '.join(f'{d}D' for d in stat.dims)} scene")
    return problems


def engine_problems(scene: Any, capabilities: Any) -> list[tuple[str, Any, str]]:
    """(field, value, reason) for each of the scene's statistics a run in an engine with
    ``capabilities`` cannot supply: the engine lacks what it needs (a collision log, an
    interaction stress), or it is binned along y and the profile axis is another."""
    out = []
    for name in scene.measure.statistics:
        stat = STATISTICS[name]
        if stat.capability and not getattr(capabilities, stat.capability):
            what = CAPABILITY_TEXT.get(stat.capability, f"the {stat.capability} capability")
            out.append(("measure.statistics", name, f"{stat.description} needs {what}, "
                                                    "which this engine does not provide"))
        if stat.axis_y and scene.measure.axis != "y":
            out.append(("measure.axis", scene.measure.axis,
                        f"{name!r} ({stat.description}) is binned along y only: use "
                        f"measure.axis = 'y' with {name!r} in measure.statistics"))
    return out


def compute_statistics(names: Iterable[str], ctx: Context) -> dict[str, tuple[dict, dict]]:
    """``{name: (datasets, attrs)}`` for each statistic in ``names``."""
    names = list(names)
    unknown = [n for n in names if n not in STATISTICS]
    if unknown:
        raise StatisticUnavailable(f"{unknown[0]!r}: unknown statistic (allowed: "
                                   f"{', '.join(STATISTICS)})")
    cells = f"--z-cells {ctx.z_cells} (z_cells)"
    if ctx.z_cells < 1:
        raise StatisticUnavailable(f"{cells}: the number of z cells per y-bin must be >= 1")
    if ctx.z_cells != 1:
        if ctx.scene.dimension != 3:
            raise StatisticUnavailable(f"{cells}: Malik's cells split the y-bins along z, so "
                                       "they need a 3D run (this one is "
                                       f"{ctx.scene.dimension}D; use 1)")
        takes = [n for n, s in STATISTICS.items() if s.z_cells]
        if not set(names) & set(takes):
            raise StatisticUnavailable(f"{cells}: applies to {', '.join(takes)}; none of them "
                                       f"is requested ({', '.join(names)})")
    for name in names:
        stat = STATISTICS[name]
        if ctx.scene.dimension not in stat.dims:
            raise StatisticUnavailable(f"{name}: {stat.description} needs a "
                             f"{' or '.join(f'{d}D' for d in stat.dims)} run")
    return {name: STATISTICS[name].compute(ctx) for name in names}


# ---------------------------------------------------------------- the statistics
# (builders import their analyses when called: importing the registry stays cheap)

@statistic("profiles", "profiles of ν, u, T and rotational T", "stream", plots=("profiles",),
           z_cells=True)
def _profiles(ctx: Context):
    from .suite import profile_analysis

    return profile_analysis(ctx.scene, ctx.walls, z_cells=ctx.z_cells,
                            wall_relative=ctx.wall_relative)


@statistic("vdf", "velocity distributions per bin", "frames", plots=("vdf",), z_cells=True)
def _vdf(ctx: Context):
    from .base import bin_edges
    from .suite import image_shift, profile_bounds, wall_relative_bins
    from .vdf import velocity_distributions

    scene = ctx.scene
    lo, hi, period = profile_bounds(scene)
    relative = wall_relative_bins(scene, ctx.wall_relative)
    ana = velocity_distributions(ctx.frames, dim=scene.dimension,
                                 edges=bin_edges(lo, hi, scene.measure.bin_width),
                                 inertia_factor=scene.inertia_k, period=period,
                                 image_velocity_shift=image_shift(scene, period),
                                 z_cells=ctx.z_cells, wall_relative=relative,
                                 bin_width=scene.measure.bin_width)
    return ana.results, ana.attrs


@statistic("gr", "the pair distribution g(r)", "stream", plots=("gr",))
def _gr(ctx: Context):
    from .pair_correlation import PairCorrelation
    from .suite import periodic_lengths

    scene = ctx.scene
    periodic = periodic_lengths(scene)
    # stay below half the shortest periodic length (no image counted twice)
    r_max = min(5.0, 0.5 * min(periodic) - 0.05) if periodic else 5.0
    return PairCorrelation(dim=scene.dimension, r_max=r_max, dr=0.05,
                           periodic_y=scene.y_periodic)


# test particles within a bin width of the mid-plane: the channel's middle (between servo
# walls: of each frame's walls), or with an open top the initial bed's
@statistic("structure", "Campbell's normal and parallel structure distributions", "stream",
           plots=("structure",))
def _structure(ctx: Context):
    from .structure import StructureDistributions
    from .suite import profile_bounds, wall_relative_bins

    scene = ctx.scene
    lo, hi, _period = profile_bounds(scene)
    # servo walls: the mid-plane of each frame's walls, or of where they stood when
    # production started (wall_relative = False)
    relative = wall_relative_bins(scene, ctx.wall_relative)
    if ctx.walls is not None:
        lo, hi = ctx.walls
    if scene.has_open_top:  # the middle of the bed, not of the empty box above it
        from ..scene.initial import build_initial_state

        lo = scene.wall_surface("lower")
        hi = float(build_initial_state(scene).position[:, 1].max())
    across = [scene.box.size[i] for i, a in enumerate("xyz"[:scene.dimension]) if a != "y"]
    return StructureDistributions(dim=scene.dimension, r_max=min(4.0, 0.5 * min(across) - 0.05),
                                  dr=0.08, half_width=scene.measure.bin_width,
                                  y_mid=0.5 * (lo + hi), wall_relative=relative)


@statistic("angles", "collision-angle distributions", "collisions", plots=("angles",),
           capability="collision_log", log_every=1)
def _angles(ctx: Context):
    from .suite import collision_angle_analysis

    ana = collision_angle_analysis(ctx.scene, ctx.results)
    return ana.results, ana.attrs


@statistic("freepath", "free paths, free times and the Knudsen number", "collisions",
           plots=("freepath",), capability="collision_log", log_every=1)
def _freepath(ctx: Context):
    from .suite import free_path_analysis

    ana = free_path_analysis(ctx.scene, ctx.results)
    return ana.results, ana.attrs


@statistic("stress", "stress profiles (kinetic, interaction, walls, momentum balance)",
           "results", plots=("stress", "eos"), axis_y=True, capability="stress",
           run_group="stress")
def _stress(ctx: Context):
    from .suite import stress_from_results

    return stress_from_results(ctx.scene, ctx.results)


@statistic("derived", "derived quantities: S, f_s, f_N, friction, χ, wall slip, Knudsen",
           "results")
def _derived(ctx: Context):
    from .derived import derived_results

    return derived_results(ctx.results, ctx.scene)


@statistic("vcorr", "spatial velocity correlations", "frames", plots=("vcorr",), z_cells=True)
def _vcorr(ctx: Context):
    from .suite import correlation_analysis

    ana = correlation_analysis(ctx.scene, ctx.frames, "vcorr", ctx.z_cells)
    return ana.results, ana.attrs


@statistic("lambda", "Malik's orientational correlation Λ", "frames", plots=("lambda",),
           dims=(3,), z_cells=True)
def _lambda(ctx: Context):
    from .suite import correlation_analysis

    ana = correlation_analysis(ctx.scene, ctx.frames, "lambda", ctx.z_cells)
    return ana.results, ana.attrs


@statistic("waves", "density-wave Fourier modes", "stream", plots=("waves",))
def _waves(ctx: Context):
    from .suite import correlation_analysis

    return correlation_analysis(ctx.scene, None, "waves")


@statistic("cgprofiles", "coarse-grained (Gaussian-kernel) profiles", "stream",
           plots=("cgprofiles",))
def _cgprofiles(ctx: Context):
    from .suite import correlation_analysis

    return correlation_analysis(ctx.scene, None, "cgprofiles")
