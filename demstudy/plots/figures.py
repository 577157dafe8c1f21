"""The drawing of every plot kind (matplotlib): :func:`draw`, :func:`plot_files` and the
table of drawing functions; :mod:`demstudy.plots` loads this module on first use.
Dimensionless particle units: d = 1, m = 1, g = 1 with gravity.
"""


from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from matplotlib.figure import Figure

from .common import Run, missing_notice, save
from .correlations import draw_gr, draw_lambda, draw_structure, draw_vcorr
from .distributions import draw_angles, draw_freepath, draw_vdf
from .health import draw_health
from .kinds import KINDS, SCALED
from .profiles import (
    draw_cgprofiles,
    draw_cooling,
    draw_eos,
    draw_profiles,
    draw_stress,
    reference_height,
)
from .waves import draw_waves

#: the drawing function of every kind; ``bins``: it takes the bins to draw
DRAW: dict[str, tuple[Callable[..., Figure], bool]] = {
    "profiles": (draw_profiles, False), "stress": (draw_stress, False),
    "eos": (draw_eos, False), "vdf": (draw_vdf, True), "angles": (draw_angles, True),
    "freepath": (draw_freepath, True), "gr": (draw_gr, True), "vcorr": (draw_vcorr, True),
    "lambda": (draw_lambda, False), "waves": (draw_waves, False),
    "cooling": (draw_cooling, False), "structure": (draw_structure, False),
    "cgprofiles": (draw_cgprofiles, False), "health": (draw_health, False),
}
if set(KINDS) != set(DRAW):  # a statistic declares a figure nobody draws, or vice versa
    raise ImportError(f"plot kinds out of step: registered {sorted(KINDS)}, drawn "
                      f"{sorted(DRAW)}")

__all__ = ["DRAW", "Run", "draw", "draw_angles", "draw_cgprofiles", "draw_cooling", "draw_eos",
           "draw_freepath", "draw_gr", "draw_health", "draw_lambda", "draw_profiles", "draw_stress",
           "draw_structure", "draw_vcorr", "draw_vdf", "draw_waves",
           "output_path", "plot_files", "plot_profiles", "reference_height"]




def draw(kind: str, runs: Sequence[Run], *, scaled: bool = False,
         bins: Sequence[int] | None = None) -> Figure:
    """The Figure of ``kind`` for ``runs`` (each must hold the kind)."""
    if kind not in KINDS:
        raise ValueError(f"unknown plot kind {kind!r} (allowed: {', '.join(KINDS)})")
    fn, takes_bins = DRAW[kind]
    if kind in SCALED:
        return fn(runs, scaled=scaled)
    return fn(runs, bins=bins) if takes_bins else fn(runs)


def output_path(out: str | Path | None, kind: str, several: bool) -> Path:
    """OUT for one kind, OUT-<kind>.png for several (default: <kind>.png)."""
    if out is None:
        return Path(f"{kind}.png")
    out = Path(out)
    if not several:
        return out
    suffix = out.suffix or ".png"
    return out.with_name(f"{out.stem if out.suffix else out.name}-{kind}{suffix}")


def plot_files(paths: Sequence[str | Path], kinds: Sequence[str], out: str | Path | None,
               *, scaled: bool = False, bins: Sequence[int] | None = None,
               notice: Callable[[str], Any] | None = None) -> list[Path]:
    """Write one PNG per kind present in at least one of ``paths`` (files lacking a kind are
    left out of its figure, with a one-line ``notice``); returns the paths written."""
    notice = notice or (lambda text: print(text, file=sys.stderr))
    runs = [Run.load(p) for p in paths]
    several = len(kinds) > 1
    written = []
    for kind in kinds:
        have = []
        for run in runs:
            if run.group(kind) is None:
                notice(missing_notice(run, kind))
            else:
                have.append(run)
        if have:
            written.append(save(draw(kind, have, scaled=scaled, bins=bins),
                                output_path(out, kind, several)))
    return written


def plot_profiles(paths: Sequence[str | Path], out: str | Path, scaled: bool = False) -> Path:
    """ν, u and T (translational and rotational) against y, one curve per results file,
    written to ``out`` (returns the path; :func:`draw_profiles` returns the Figure)."""
    runs = [Run.load(p) for p in paths]
    for run in runs:
        if run.group("profiles") is None:
            raise ValueError(f"{run.path}: the results file holds no profiles")
    return save(draw_profiles(runs, scaled=scaled), out)
