"""The analyses a scene asks for, configured from the scene, run over any frame source.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts. Each statistic is one
AnalysisBase class; this module only chooses their parameters from the scene (bins along the
profile axis, periodic lengths, Lees–Edwards image shifts) so that results files from every
engine and every frame source (in-memory capture, dumps, stored frames) are comparable.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any

from ..io.frames import Frame
from ..scene import Scene
from .pair_correlation import PairCorrelation
from .profiles import ProfileAnalysis
from .vdf import velocity_distributions

#: Statistics ``demstudy analyze --what`` can compute from frames.
AVAILABLE = ("profiles", "vdf", "gr")


def profile_bounds(scene: Scene) -> tuple[float, float, float]:
    """(lo, hi, period) of the profile axis: between the walls, or the periodic box."""
    axis = "xyz".index(scene.measure.axis)
    period = scene.box.size[axis] if scene.measure.axis in scene.periodic else 0.0
    if scene.measure.axis == "y" and not scene.y_periodic:
        lo = scene.wall_position("lower")
        hi = scene.wall_position("upper") if scene.wall("upper") else scene.box.size[1]
        return lo, hi, period
    return 0.0, scene.box.size[axis], period


def image_shift(scene: Scene, period: float) -> float:
    """x velocity of the periodic image above (Lees–Edwards: γ̇ L_y), 0 otherwise."""
    return scene.shear.rate * period if scene.shear is not None and scene.measure.axis == "y" \
        else 0.0


def profile_analysis(scene: Scene, walls: tuple[float, float] | None = None) -> ProfileAnalysis:
    """Profiles along the scene's axis (``walls``: current wall positions when walls move)."""
    lo, hi, period = profile_bounds(scene)
    if walls is not None and scene.measure.axis == "y":
        lo, hi = walls
    return ProfileAnalysis(axis=scene.measure.axis, bin_width=scene.measure.bin_width, lo=lo,
                           hi=hi, dim=scene.dimension, inertia_factor=scene.inertia_k,
                           period=period, image_velocity_shift=image_shift(scene, period))


def run_statistics(scene: Scene, frames: Callable[[], Iterable[Frame]],
                   what: Iterable[str]) -> dict[str, tuple[dict, dict]]:
    """``{name: (results, attrs)}`` for each requested statistic; ``frames`` returns a fresh
    iterable each call (the velocity distributions read the frames twice)."""
    out: dict[str, tuple[dict[str, Any], dict[str, Any]]] = {}
    lo, hi, period = profile_bounds(scene)
    for name in what:
        if name == "profiles":
            ana = profile_analysis(scene).run(frames()).finish()
        elif name == "vdf":
            n_bins = max(1, round((hi - lo) / scene.measure.bin_width))
            edges = [lo + (hi - lo) * i / n_bins for i in range(n_bins + 1)]
            ana = velocity_distributions(frames, dim=scene.dimension, edges=edges,
                                         inertia_factor=scene.inertia_k, period=period,
                                         image_velocity_shift=image_shift(scene, period))
        elif name == "gr":
            periodic = [scene.box.size[i] for i, a in enumerate("xyz"[: scene.dimension])
                        if a in scene.periodic]
            # stay below half the shortest periodic length (no image counted twice)
            r_max = min(5.0, 0.5 * min(periodic) - 0.05) if periodic else 5.0
            ana = PairCorrelation(dim=scene.dimension, r_max=r_max, dr=0.05,
                                  periodic_y=scene.y_periodic).run(frames()).finish()
        else:
            raise ValueError(f"--what {name!r}: unknown statistic (allowed: "
                             f"{', '.join(AVAILABLE)})")
        out[name] = (ana.results, ana.attrs)
    return out
