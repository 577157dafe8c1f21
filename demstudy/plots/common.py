"""Shared plumbing of the figures: loading results files, run labels, bin choice, the units /
engine footer, saving. Dimensionless particle units: d = 1, m = 1, g = 1 with gravity.

Figures are built on :class:`matplotlib.figure.Figure` with the Agg canvas (no pyplot state,
nothing to close); every drawing function returns its Figure so that tests can read back the
plotted data.
"""

from __future__ import annotations

import textwrap
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure
from matplotlib.text import Text

from ..io.results import Results, read_results
from .kinds import HOW_PLOT_ONLY

#: a dataset that must be present for the kind to be drawable
REQUIRED = {"stress": "total", "eos": "total", "vdf": "X", "angles": "p_text",
            "freepath": "p_lambda", "gr": "g",
            "vcorr": "C", "lambda": "lambda", "waves": "series_time",
            "structure": "normal", "cgprofiles": "solid_fraction"}


def statistic_of(kind: str) -> str:
    """The registered statistic whose group a plot kind draws."""
    from ..analysis.registry import STATISTICS

    return next(name for name, stat in STATISTICS.items() if kind in stat.plots)


def groups_of(kind: str) -> tuple[str, ...]:
    """Results-file groups holding ``kind`` (first present wins): the statistic's group, and
    the run's own top-level group of that name (``/stress``)."""
    from ..analysis.registry import STATISTICS

    name = statistic_of(kind)
    run_group = STATISTICS[name].run_group
    return (f"statistics/{name}",) + ((run_group,) if run_group else ())


def how_to_get(kind: str) -> str:
    """How to obtain a missing kind ({file}: the results file's name), from the registry."""
    if kind in HOW_PLOT_ONLY:
        return HOW_PLOT_ONLY[kind]
    from ..analysis.registry import STATISTICS

    name = statistic_of(kind)
    stat = STATISTICS[name]
    how = (f"add it with measure.statistics = [\"{name}\"] or "
           f"`demstudy analyze {{file}} --what {name}`")
    if stat.capability == "collision_log":
        every = " of every collision (log_every = 1)" if name == "freepath" else ""
        how += f", which needs an event-driven run's /collisions log{every}"
    if stat.dims == (3,):
        how += ", 3D only"
    if stat.source == "frames":
        how += " (from stored frames: --keep-frames)"
    return how


LINESTYLES = ("-", "--", ":", "-.")
MARKERS = ("o", "s", "^", "v", "D", "P")
#: the resolution of the saved figures (dots per inch)
DPI = 110
#: the shades of a run's colour for its bins (1: the colour itself; < 1 darker, > 1 lighter)
SHADES = (1.0, 0.55, 1.55, 0.3, 1.8)


def run_colour(r: int, shade: int = 0) -> tuple[float, float, float]:
    """Run ``r``'s colour (``C{r}``: one colour per run, in every figure), darkened or
    lightened for its ``shade``-th bin so that the bins of one run stay apart (they also
    differ in line style and marker)."""
    base = np.array(to_rgb(f"C{r % 10}"))
    f = SHADES[shade % len(SHADES)]
    rgb = base * f if f <= 1 else base + (1 - base) * (f - 1)
    return tuple(float(c) for c in np.clip(rgb, 0.0, 1.0))


def homogeneous_cooling(scene: Any) -> bool:
    """A free-cooling scene, where Haff's law applies: every axis periodic, no walls, gravity
    or shear, equal particles (the theory is for d = m = 1) and a constant normal restitution
    e < 1."""
    return (scene is not None and len(scene.periodic) == scene.dimension and not scene.walls
            and scene.gravity is None and scene.shear is None
            and scene.particles.diameter_spread == 0
            and scene.contact.law.model == "constant" and scene.contact.restitution < 1)


def load_results(path: str | Path) -> Results:
    """A results file without its (possibly huge) ``/frames`` and ``/collisions``: what the
    figures need."""
    return read_results(path, skip=("frames", "collisions"))


@dataclass
class Run:
    """One results file: its content, its scene (None if it cannot be rebuilt) and label."""

    path: Path
    results: Results
    scene: Any = None

    @classmethod
    def load(cls, path: str | Path) -> Run:
        return cls.of(load_results(path))

    @classmethod
    def of(cls, res: Results) -> Run:
        """A run from results in memory (its scene None if it cannot be rebuilt)."""
        path = res.path or Path(f"{res.attrs.get('scene_name', 'run')}.h5")
        try:
            scene = res.scene
        except Exception:  # an older or foreign scene: the figures do without it
            scene = None
        return cls(Path(path), res, scene)

    @property
    def attrs(self) -> dict[str, Any]:
        return self.results.attrs

    @property
    def engine(self) -> str:
        """The engine and its version, without the version's feature list (the footer must
        fit; the whole string is in the file's ``engine_version``)."""
        name = str(self.attrs.get("engine", "unknown engine"))
        version = str(self.attrs.get("engine_version") or "").split(" (")[0]
        return f"{name} ({version})" if version else name

    @property
    def label(self) -> str:
        name = self.attrs.get("scene_name") or self.path.stem
        return f"{name} ({self.attrs.get('engine', '?')})"

    @property
    def gravity(self) -> bool | None:
        return None if self.scene is None else self.scene.gravity is not None

    def group(self, kind: str) -> tuple[dict[str, np.ndarray], dict[str, Any]] | None:
        """(datasets, attrs) of ``kind`` in this file, or None when absent."""
        if kind == "profiles":
            prof = self.results.profiles
            return (prof, self.results.profile_attrs) if prof and "y" in prof else None
        if kind == "cooling":  # a property of the run (its scene), not of a stored group
            ts = self.results.timeseries
            ok = homogeneous_cooling(self.scene) and "kinetic_energy" in ts and "time" in ts
            return (ts, {}) if ok else None
        if kind == "health":  # the run's own group (soft-contact engines)
            data = self.results.groups.get("health")
            return (data, self.results.group_attrs.get("health", {})) if data else None
        for name in groups_of(kind):
            data = self.results.groups.get(name)
            if data and REQUIRED.get(kind, next(iter(data), "")) in data:
                return data, self.results.group_attrs.get(name, {})
        return None

    def where(self, kind: str) -> str:
        if kind == "cooling":
            return "homogeneous cooling scene with /timeseries/kinetic_energy"
        if kind == "health":
            return "/health"
        return "/profiles" if kind == "profiles" else " or ".join(f"/{g}" for g in groups_of(kind))


def missing_notice(run: Run, kind: str) -> str:
    how = how_to_get(kind)
    return (f"notice: {run.path}: no {run.where(kind)}: {kind} skipped "
            f"({how.format(file=run.path.name)})")


def units_text(runs: Sequence[Run]) -> str:
    """The units statement of a figure, with whether gravity acts in these runs."""
    gravity = {run.gravity for run in runs}
    text = "units: d = 1, m = 1, g = 1 with gravity"
    if all(homogeneous_cooling(run.scene) for run in runs):  # no wall speed, no shear rate
        return text + " (no gravity here: the initial temperature sets the time scale)"
    if gravity == {True}:
        return text + " (gravity acts here)"
    if gravity == {False}:
        return text + " (no gravity here: the wall speed or shear rate sets the time scale)"
    return text + " (otherwise the wall speed or shear rate sets the time scale)"


def new_figure(n_rows: int, n_cols: int, width: float = 4.0, height: float = 3.6,
               **kwargs: Any) -> tuple[Figure, np.ndarray]:
    """A Figure on the Agg canvas and its axes as a 2D array."""
    # made at the resolution it is saved at: text widths are measured at this resolution
    # (hinted glyphs are not proportional to the resolution) to keep footers and legends in
    fig = Figure(figsize=(width * n_cols, height * n_rows + 0.6), dpi=DPI)
    FigureCanvasAgg(fig)
    axes = fig.subplots(n_rows, n_cols, squeeze=False, **kwargs)
    return fig, axes


def _extent(fig: Figure, artist: Any) -> tuple[float, float]:
    """An artist's drawn width and height as figure fractions."""
    box = artist.get_window_extent(fig.canvas.get_renderer())
    return box.width / fig.bbox.width, box.height / fig.bbox.height


def _wrapped(fig: Figure, text: Text, parts: Sequence[str], room: float) -> None:
    """Set ``text`` to ``parts`` (units, engines), each wrapped at the most characters that
    keep the drawn text within ``room`` (a figure fraction), measured with the renderer:
    footers are never cut off at the right edge, whatever the characters."""
    chars = max(len(p) for p in parts)
    while True:
        text.set_text("\n".join(line for p in parts
                                for line in textwrap.wrap(p, chars, break_on_hyphens=False)))
        if chars <= 20 or _extent(fig, text)[0] <= room:
            return
        chars = int(chars * 0.92)


def finish(fig: Figure, runs: Sequence[Run], title: str, bottom: float = 0.03,
           legend: tuple[Sequence[Any], Sequence[str]] | None = None, max_cols: int = 4,
           legend_size: float = 7) -> Figure:
    """Title, the units and engine footer, tight layout (applied when the figure is drawn)
    above ``bottom`` (a figure fraction). ``legend``: (handles, labels) drawn below the
    panels, above the footer, with the most columns (≤ ``max_cols``) whose drawn width fits
    the figure, so that it covers no data and is not cut off; the panels make room for it."""
    engines = ", ".join(dict.fromkeys(run.engine for run in runs))
    heading = fig.suptitle(title, fontsize=10)
    top = 0.96
    if _extent(fig, heading)[0] > 0.98:  # a long title on a narrow figure: wrapped to fit
        _wrapped(fig, heading, (title,), 0.98)
        top = min(top, 0.99 - _extent(fig, heading)[1])
    text = fig.text(0.005, 0.005, "", fontsize=7, ha="left", va="bottom")
    units, engine = units_text(runs), f"engine: {engines}"
    one_line = f"{units}  |  {engine}"
    text.set_text(one_line)
    if _extent(fig, text)[0] > 0.98:  # the units, then the engines, each wrapped to fit
        _wrapped(fig, text, (units, engine), 0.98)
    height = _extent(fig, text)[1] + 0.01
    if legend is not None and len(legend[1]):
        handles, labels = legend
        for ncol in range(min(max_cols, len(labels)), 0, -1):
            box = fig.legend(handles, labels, fontsize=legend_size, loc="lower center",
                             ncol=ncol, bbox_to_anchor=(0.5, height), frameon=False)
            if ncol == 1 or _extent(fig, box)[0] <= 0.98:
                break
            box.remove()
        height += _extent(fig, box)[1] + 0.01
    bottom = max(bottom, height + 0.01)
    fig.set_layout_engine("tight", rect=(0, bottom, 1, top))  # applied when drawn (saved)
    return fig


def save_with_note(fig: Figure, path: str | Path, note: str, *, bottom: float = 0.04,
                   dpi: int = 110, fontsize: float = 7, wrap: bool = False) -> Path:
    """Write ``fig`` to ``path`` with ``note`` (units, constants) centred at the bottom, the
    panels laid out above ``bottom`` (a figure fraction), and close it."""
    import matplotlib.pyplot as plt

    fig.text(0.5, 0.005, note, ha="center", va="bottom", fontsize=fontsize, wrap=wrap)
    fig.tight_layout(rect=(0, bottom, 1, 1))
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def save(fig: Figure, out: str | Path) -> Path:
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=DPI)
    return out


def pick_bins(valid: np.ndarray, requested: Sequence[int] | None = None) -> list[int]:
    """Bins (0-based) to draw: ``requested`` (1-based bin numbers, Malik's "bin 1" touches
    the lower wall) that exist, else Malik's choice generalised: the first occupied bin, the
    fourth and the middle of the occupied range."""
    valid = np.asarray(valid, bool)
    if requested:
        return [b - 1 for b in requested if 1 <= b <= valid.size]
    occupied = np.flatnonzero(valid)
    if occupied.size == 0:
        return []
    first, last = int(occupied[0]), int(occupied[-1])
    picks = [first, min(first + 3, last), (first + last + 1) // 2]
    return [b for b in dict.fromkeys(picks) if valid[b]]


def bin_label(y: np.ndarray, b: int) -> str:
    return f"bin {b + 1} (y = {float(y[b]):.3g})"
