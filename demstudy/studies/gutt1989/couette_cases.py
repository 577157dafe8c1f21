"""The runs of the Couette part of the Gutt (1989) study: Gutt's Ch. 2 channel (digest §2.4,
S5) as event-driven hard discs (2D) and spheres (3D).

Dimensionless particle units: d = 1, m = 1; no gravity: the wall speed u_w = 1 sets the time
scale (times in d/u_w; stresses in m u_w²/d² in 2D, m u_w²/d³ in 3D).

Gutt's walls (L581-L611) are microscopically smooth and frictionless, with undulations whose
local normals k set the roughness ⟨k_τ²⟩; his grains are smooth, non-spinning and
inelastic. The event-driven engine's bumpy walls are that wall: fixed discs/spheres on the
wall plane (``effects.bumps``) that move with the wall, every contact smooth (no tangential
impulse), the plane between them a flat backstop. Each case is the scene
``gutt1989/couette-2d`` or ``-3d`` (h = 10 d between the planes, the inventory of Δh =
3.25 d, e = 0.9 assumed, walls at ±u_w) with one bump geometry and one e_w:

* ``GEOMETRIES``: flat (⟨k_τ²⟩ = 0) and four bump layouts from small undulations to bumps as
  large as a grain; their ⟨k_τ²⟩ is measured from the collision log (couette_measure), not
  set: the layout → roughness map is not monotonic (touching bumps hold the grains in the
  hollows, where they meet the bumps' upper flanks);
* ``E_WALLS``: the thesis's curves a, b, c (e_w = 0.96, 0.92, 0.84, fig 2.4 caption).
"""

from __future__ import annotations

from typing import Any

from ..base import Case

#: the grain restitution (assumed: Gutt's Ch. 2 gives only γ = 0.16, with γ ∝ 1 − e²)
E_GRAIN = 0.9
#: e_w of the thesis's curves a, b, c (fig 2.4 caption, L795)
E_WALLS = (0.96, 0.92, 0.84)
#: bump geometries: tag → (diameter, spacing) in d; None = flat wall
GEOMETRIES: dict[str, tuple[float, float] | None] = {
    "flat": None,
    "b025s1": (0.25, 1.0),
    "b05s1": (0.5, 1.0),
    "b1s2": (1.0, 2.0),
    "b1s15": (1.0, 1.5),
}
#: what the quick study runs (2D and 3D, e_w = 0.84)
QUICK_GEOMETRIES = ("flat", "b05s1", "b1s15")
SCENES = {2: "gutt1989/couette-2d", 3: "gutt1989/couette-3d"}
#: equilibration and production (d/u_w): the thermal diffusion time across the gap is
#: h²/K ≈ 60 d/u_w (K = r d² v/s with v ≈ 0.2 u_w, s ≈ 0.1 d). The smoothest 3D wall
#: (b025s1) heats the grains in bursts: its kinetic energy swings by a factor ~3 over hundreds
#: of d/u_w (the report lists the runs whose production halves differ by > 10 %), so the 3D
#: runs are long enough to hold several bursts
EQUILIBRATION, PRODUCTION = {2: 300.0, 3: 600.0}, {2: 1500.0, 3: 1000.0}
QUICK_EQUILIBRATION, QUICK_PRODUCTION = 60.0, 100.0
#: log every k-th collision so that the log's 200 000 records span the production
LOG_EVERY = {2: 4, 3: 30}


def case_name(dim: int, geometry: str, e_w: float) -> str:
    return f"couette-{dim}d-{geometry}-ew{round(100 * e_w)}"


def walls(geometry: str, e_w: float, u_w: float = 1.0) -> list[dict[str, Any]]:
    """Both walls at ±u_w with restitution e_w, smooth contacts, the geometry's bumps."""
    bumps = GEOMETRIES[geometry]
    out = []
    for side, speed in (("lower", -u_w), ("upper", u_w)):
        wall: dict[str, Any] = {"side": side, "restitution": e_w, "velocity": speed,
                                "tangential": {"model": "smooth"}}
        if bumps is not None:
            wall["kind"] = "bumpy"
            wall["bumps"] = {"diameter": bumps[0], "spacing": bumps[1], "pattern": "regular"}
        out.append(wall)
    return out


#: the event-driven TC time of Gutt's Couette runs (docs/studies/gutt1989.md was made at it)
GUTT_TC = 1e-5


def couette_case(dim: int, geometry: str, e_w: float) -> Case:
    if geometry not in GEOMETRIES:
        raise ValueError(f"geometry = {geometry!r}: allowed are {', '.join(GEOMETRIES)}")
    quick = e_w == 0.84 and geometry in QUICK_GEOMETRIES
    sections = {"walls": walls(geometry, e_w),
                "contact": {"restitution": E_GRAIN, "tangential": {"model": "smooth"}},
                "run": {"equilibration": EQUILIBRATION[dim], "production": PRODUCTION[dim],
                        "sample_interval": 1.0},
                "measure": {"axis": "y", "bin_width": 0.5, "statistics": ["profiles", "stress"]}}
    return Case(case_name(dim, geometry, e_w), SCENES[dim], sections=sections,
                # t_c = 1e-5 explicitly: the report was made there, the default then for both
                # dimensions (spheres default to 1e-6 since; docs/edmd-engine.md)
                options={"log_every": LOG_EVERY[dim], "tc": GUTT_TC}, quick=quick,
                quick_sections={"run": {"equilibration": QUICK_EQUILIBRATION,
                                        "production": QUICK_PRODUCTION}},
                group=f"{dim}d")


def all_cases() -> list[Case]:
    return [couette_case(dim, g, e_w) for dim in (2, 3) for g in GEOMETRIES for e_w in E_WALLS]
