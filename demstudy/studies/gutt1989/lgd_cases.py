"""The runs of the LGD part of the Gutt (1989) study: the thesis's Ch. 3 scenes (digest §3.15,
§4.3) on demstudy's lattice engine (``--engine lgd``, docs/lgd-engine.md), at the thesis's
step counts, from the presets in ``inputs/gutt1989/`` (their layouts are assumed: the
figures with the initial states are missing).

Dimensionless particle units: d = 1 (the lattice spacing), m = 1; g = 1 where gravity acts,
otherwise the scene's speed unit (the wall speed, or the gas's initial speed) sets the time
scale. Run lengths are whole LGD steps (``run.unit = "steps"``).

Frames are kept (``measure.keep_frames``) for the positions, row profiles, block averages and
histograms. Where only the state at the thesis's step count matters and a run is large, the
early steps are "equilibration" (their timeseries is still recorded from step 0) and only a
short final window is "production", so that the kept frames stay small.

Case names start with ``lgd-`` so that ``demstudy study gutt1989 --only lgd`` selects them.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..base import Case


def _run(total: int, interval: int, window: int | None = None) -> dict[str, Any]:
    """``total`` steps sampled every ``interval``; frames only over the last ``window``
    steps (None: every sample is a frame)."""
    window = total if window is None else window
    if total % interval or window % interval:
        raise ValueError(f"steps {total} and window {window} must be multiples of the sample "
                         f"interval {interval}")
    return {"run": {"unit": "steps", "equilibration": total - window, "production": window,
                    "sample_interval": interval},
            "measure": {"keep_frames": True}}


def _case(tag: str, scene: str, total: int, interval: int, window: int | None = None,
          quick: tuple[int, int, int | None] | None = None, group: str = "",
          extra: Mapping[str, Any] | None = None) -> Case:
    sections = _run(total, interval, window)
    if extra:
        sections = {**sections, **extra}
    quick_sections = _run(*quick)["run"] if quick else {}
    return Case(f"lgd-{tag}", f"gutt1989/{scene}", engine="lgd", sections=sections,
                quick=quick is not None, quick_sections={"run": quick_sections} if quick else {},
                group=group or tag)


#: the thesis's step counts (digest §4.3)
GAS_STEPS, EXPLOSION_STEPS, COUETTE_STEPS = 1024, 128, 1024
HOURGLASS_STEPS, OBSTACLE_STEPS, OBSTACLE_PATH_STEPS = 2048, 512, 1536
INCLINE_STEPS, POISEUILLE_STEPS = 6144, 18432
OBSTACLES = ("circle", "square", "triangle-up", "triangle-down")
#: steps between the samples of the marker-path runs (their /tracks; a grain moves at most
#: one spacing per step, so a path is resolved to 2 d)
PATH_INTERVAL = 2
#: the diagnostic Couette runs (the shape of the thermal profile): 8× longer, elastic walls
#: (e_pw = 1 instead of the thesis's 0.75), and a denser random fill (density ¾ instead of ½)
COUETTE_LONG_STEPS = 8192


def dense_couette_fill(nxt: int = 192, nyt: int = 62) -> list[dict[str, int | float]]:
    """A denser start than the preset's (a seeded random fill at density ½): the same
    random fill at density ¾ of the open rows, at rest; a diagnostic of the density's effect
    on the profiles."""
    return [{"x1": 1, "y1": 2, "x2": nxt, "y2": nyt - 1, "density": 0.75}]


def all_cases() -> list[Case]:
    elastic_walls = {"walls": [{"side": "lower", "restitution": 1.0, "velocity": -1.0},
                               {"side": "upper", "restitution": 1.0, "velocity": 1.0}]}
    out = [
        # run to 2048 steps: the thesis's statement is at 1024, the frame at 2048 says
        # whether the remaining anisotropy is a transient
        _case("gas-box", "gas-box", 2 * GAS_STEPS, 32, quick=(GAS_STEPS, 32, None)),
        _case("explosion", "explosion", EXPLOSION_STEPS, 16, quick=(EXPLOSION_STEPS, 16, None)),
        _case("couette-elastic-u4096", "couette-elastic-u4096", COUETTE_STEPS, 32,
              quick=(COUETTE_STEPS, 32, None), group="couette"),
        _case("couette-elastic-u16384", "couette-elastic-u16384", COUETTE_STEPS, 32,
              quick=(COUETTE_STEPS, 32, None), group="couette"),
        _case("couette-inelastic-u4096", "couette-inelastic-u4096", COUETTE_STEPS, 32,
              quick=(COUETTE_STEPS, 32, None), group="couette"),
        _case("couette-elastic-u4096-long", "couette-elastic-u4096", COUETTE_LONG_STEPS, 128,
              window=1024, group="couette"),
        _case("couette-elastic-u4096-ew1", "couette-elastic-u4096", COUETTE_STEPS, 32,
              group="couette", extra=elastic_walls),
        _case("couette-elastic-u4096-dense", "couette-elastic-u4096", COUETTE_STEPS, 32,
              group="couette", extra={"lattice": {"fill": dense_couette_fill()}}),
        _case("hourglass", "hourglass", HOURGLASS_STEPS, 32, quick=(HOURGLASS_STEPS, 32, None)),
    ]
    out += [_case(f"obstacle-{shape}", f"obstacle-{shape}", OBSTACLE_PATH_STEPS, 64,
                  quick=(OBSTACLE_STEPS, 64, None), group="obstacle") for shape in OBSTACLES]
    # the marked grains' paths (figs 3.29b-3.32b, 3.34b): the same scenes sampled every
    # PATH_INTERVAL steps (the thesis wrote markers every step), one frame kept at the end
    out += [_case(f"obstacle-{shape}-paths", f"obstacle-{shape}", OBSTACLE_PATH_STEPS,
                  PATH_INTERVAL, window=PATH_INTERVAL,
                  quick=(OBSTACLE_PATH_STEPS, PATH_INTERVAL, PATH_INTERVAL), group="obstacle")
            for shape in OBSTACLES]
    out += [
        _case("incline", "incline", INCLINE_STEPS, 96, window=768, quick=(1536, 96, 768)),
        _case("incline-paths", "incline", INCLINE_STEPS, PATH_INTERVAL, window=PATH_INTERVAL,
              quick=(1536, PATH_INTERVAL, PATH_INTERVAL), group="incline"),
        _case("poiseuille-small", "poiseuille-small", POISEUILLE_STEPS, 48, window=480,
              quick=(1536, 48, 480), group="poiseuille"),
        # the thesis's 508 032 grains (≈ 1.9e10 node-updates; the engine has no forecast:
        # 334 s on the 2-core VM, 2026-12-02, ≈ 5.7e7 node-updates/s); full study only
        _case("poiseuille-thesis", "poiseuille-thesis", POISEUILLE_STEPS, 96, window=192,
              group="poiseuille"),
    ]
    return out
