"""Figure layout from real event-driven runs: error bars on the velocity distributions, g(r)
and the velocity correlations (the stored block-average errors), legends that cover no
panel, footers and legends inside the figure, and one colour per run.

Dimensionless particle units: d = 1, m = 1; the shear rate γ̇ = 1 sets the time unit.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from matplotlib.colors import to_rgb
from matplotlib.container import ErrorbarContainer

from demstudy.io.results import read_results
from demstudy.plots import draw
from demstudy.plots.common import Run, run_colour, save
from demstudy.scene import validate_scene
from demstudy.simulation import RunOptions, run_scene

STATISTICS = ["profiles", "vdf", "gr", "vcorr", "stress", "angles"]
KINDS = ("profiles", "vdf", "gr", "vcorr", "stress", "eos", "angles")


def _run(folder: Path, name: str, restitution: float) -> Path:
    """A 2D Lees–Edwards run of 20 × 20 at ν = 0.3 (153 discs, 20 strain units, < 1 s)."""
    scene = validate_scene({
        "dimension": 2, "meta": {"name": name}, "box": {"size": [20.0, 20.0]},
        "particles": {"solid_fraction": 0.3},
        "contact": {"restitution": restitution},
        "shear": {"rate": 1.0},
        "initial": {"placement": "random", "velocity": {"profile": "linear",
                                                          "temperature": 1.0}},
        "run": {"equilibration": 2.0, "production": 20.0, "sample_interval": 0.5},
        "measure": {"bin_width": 2.0, "statistics": STATISTICS},
    })
    return run_scene(scene, "edmd", RunOptions(out=folder / f"{name}.h5", progress=False))


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> list[Run]:
    folder = tmp_path_factory.mktemp("layout")
    return [Run.load(_run(folder, "sheared-a", 0.9)), Run.load(_run(folder, "sheared-b", 0.7))]


def _figure(kind: str, runs: list[Run], tmp_path: Path):
    fig = draw(kind, runs)
    save(fig, tmp_path / f"{kind}.png")  # drawn: the tight layout and the legends placed
    return fig


def _box(fig, artist):
    return artist.get_window_extent(fig.canvas.get_renderer())


@pytest.mark.parametrize("kind, key", [("vdf", "X"), ("vdf", "malik_P"), ("gr", "g"),
                                       ("vcorr", "C")])
def test_distributions_and_correlations_have_the_stored_error_bars(runs, kind, key, tmp_path):
    fig = _figure(kind, runs, tmp_path)
    stat = read_results(runs[0].path).groups[f"statistics/{kind}"]
    name = runs[0].path.name
    bars = {c.lines[0].get_gid(): c for ax in fig.axes for c in ax.containers
            if isinstance(c, ErrorbarContainer) and c.lines[0] is not None}
    drawn_as = "gr" if kind == "gr" else key  # g(r)'s gid names its group
    mine = [gid for gid in bars if gid.startswith(f"{name}:{drawn_as}:")]
    assert mine, f"no error bars for {key}"
    for gid in mine:
        container = bars[gid]
        assert container.has_yerr
        parts = gid.split(":")
        b = int(parts[2])
        index = (b,) if kind == "gr" else (b, int(parts[3]) if kind == "vcorr" else None)
        err = np.asarray(stat[f"{key}_err"], float)
        if kind == "vdf":  # the panel names the component: its position in the stored order
            comps = (stat["X"].shape[1] if key == "X" else stat["malik_P"].shape[1])
            panel = [ax for ax in fig.axes if container in ax.containers][0]
            col = list(fig.axes).index(panel) % max(5, comps)
            index = (b, col)
        expected = err[index]
        x = np.asarray(container.lines[0].get_xdata(), float)
        segments = [np.asarray(s, float) for s in container.lines[2][0].get_segments()]
        drawn = [s for s in segments if s.shape == (2, 2) and np.all(np.isfinite(s))]
        assert len(drawn) >= 0.5 * np.count_nonzero(np.isfinite(expected))
        for seg in drawn:  # each bar: half its length is the stored error at its abscissa
            at = int(np.argmin(np.abs(x - seg[0, 0])))
            assert abs(seg[1, 1] - seg[0, 1]) / 2 == pytest.approx(expected[at], rel=1e-6,
                                                                   abs=1e-12)


@pytest.mark.parametrize("kind", KINDS)
def test_legends_cover_no_panel_and_nothing_is_cut_off(runs, kind, tmp_path):
    fig = _figure(kind, runs, tmp_path)
    frame = fig.bbox
    panels = [_box(fig, ax) for ax in fig.axes if ax.get_visible() and ax.axison]
    assert fig.legends, "the runs' legend is below the panels"
    for legend in fig.legends:
        box = _box(fig, legend)
        assert box.x0 >= frame.x0 - 1 and box.x1 <= frame.x1 + 1, "legend cut off"
        for panel in panels:
            assert not box.overlaps(panel), f"the legend covers a panel of {kind}"
    footers = [t for t in fig.texts if t.get_text().startswith("units:")]
    assert len(footers) == 1
    box = _box(fig, footers[0])
    assert frame.x0 <= box.x0 and box.x1 <= frame.x1 and box.y0 >= frame.y0
    for panel in panels:  # the footer under the panels and their labels
        assert box.y1 <= panel.y0


@pytest.mark.parametrize("kind", ("vdf", "vcorr", "stress", "angles", "gr", "profiles"))
def test_one_colour_per_run(runs, kind, tmp_path):
    """Every data line of run r is drawn in a shade of C{r}: its own colour, darker or
    lighter for its bins (or stress parts), never another run's."""
    fig = _figure(kind, runs, tmp_path)
    for r, run in enumerate(runs):
        shades = {tuple(np.round(run_colour(r, i), 6)) for i in range(5)}
        lines = [ln for ax in fig.axes for ln in ax.get_lines()
                 if str(ln.get_gid()).startswith(f"{run.path.name}:")
                 and "reference" not in str(ln.get_gid())
                 and "gaussian" not in str(ln.get_gid())]
        assert lines
        for ln in lines:
            assert tuple(np.round(to_rgb(ln.get_color()), 6)) in shades, ln.get_gid()


def test_a_long_title_on_a_narrow_figure_is_wrapped_inside_it_above_the_panels(runs):
    """A one-panel figure whose title is wider than the figure: the title is wrapped so that
    it lies inside the figure and above the panel's own title; a short title is one line."""
    import matplotlib.pyplot as plt

    from demstudy.plots.common import finish, new_figure

    for title, lines in (("Malik Figs 3.2d/4.1c/4.15b: kinetic energy vs collisions, "
                          "φ = 0.5 (| = start of averaging)", 2), ("short", 1)):
        fig, axes = new_figure(1, 1, width=4.2, height=3.6)
        axes[0, 0].plot([0, 1], [0, 1])
        axes[0, 0].set_title("panel", fontsize=9)
        finish(fig, runs[:1], title)
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        box = fig._suptitle.get_window_extent(renderer)
        panel = axes[0, 0].title.get_window_extent(renderer)
        assert box.x0 >= 0 and box.x1 <= fig.bbox.width and box.y1 <= fig.bbox.height
        assert box.y0 > panel.y1
        assert fig._suptitle.get_text().count("\n") == lines - 1
        plt.close(fig)
