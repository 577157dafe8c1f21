"""Malik (2008) Ch. 5, density waves at φ ≈ 0.15: every box of the thesis's table (digest
§1.5: N = 600 … 323433, e = 0.7, β = 0.1, e_w = β_w = 0.99), the e study at L150W50H50 (e =
0.9, 0.99; Figs 5.23, 5.24) and the H/W series (Figs 5.19, 5.20), run with hard spheres in
the event-driven engine; per run the density field's Fourier modes on the xy, xz and yz
planes, their stationarity, the structure class (digest §4.11), compared with the class the
thesis reports where the digest says (§1.8), and the phase diagram over (L/W, W/d) (Fig 5.25).

Dimensionless particle units: d = 1, m = 1, g = 1 (gravity acts): times in √(d/g); time in
the thesis is collisions per particle, here c/p = 2 N_pair / N (wall collisions apart).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from ..base import Analysis, Case
from .tc import STUDY_TC
from .waves_boxes import BOXES, QUICK, Box

#: quick runs: two W = 15 boxes, past the KE's rise (≈ 100 √(d/g); 120 √(d/g) ≈ 1200-3600 c/p
#: at 10-30 c/p per √(d/g), measured) and ≈ 1000-3000 c/p of production (66 frames): ≈ 30 s
#: on one core, indicative only
QUICK_RUN = {"run": {"equilibration": 120.0, "production": 100.0, "sample_interval": 1.5}}

#: the W = 30 and W = 50 boxes run over the thesis's own span, counted in pair collisions per
#: particle (run.unit = "collisions": N_pair/N; the study's c/p is 2 N_pair/N): 1000 + 14000
#: N_pair/N = 2000 to 30000 c/p. The thesis's structures are snapshots at 4000-14000 c/p
#: (digest §1.8, [L1149]-[L1159], [L1297]-[L1305]); 30000 is its last snapshot's time even
#: if it counted N_pair/N (then our 28000). Frames every 200 N_pair/N (400 c/p): 70 in
#: production, the plug → S-wave → slug sequence of N = 50094 in ≈ 25 of them. The shipped
#: scenes' lengths (2000-3000 + 4000-5000 √(d/g)) are 10⁶-10⁷ c/p at these boxes' measured
#: 170-1300 c/p per √(d/g), ×40-300 the cost (the report's method section computes it from
#: the runs): a run of them would say what becomes of the structures long after the thesis.
THESIS_SPAN = {"run": {"unit": "collisions", "equilibration": 1000.0, "production": 14000.0,
                       "sample_interval": 200.0}}

#: the TC-model twins (not in the thesis): boxes run again at t_c = 10⁻⁶ √(d/g) (the engine's
#: default for spheres now) instead of the study's 10⁻⁵ (``tc.STUDY_TC``), over the same span, so
#: the same snapshot windows compare. At 10⁻⁵ L42W30H30's slug made 6 % of the pair collisions
#: elastic, L90W30H30's 17.7 %, L150W50H10's 15-18 %, L150W30H30's 17.7 % and L70W50H50's 12.7 %
#: (the thesis's collisions all dissipate): does the structure depend on the engine's TC model? The
#: cheapest W = 30 box, the W = 30 slugs with the largest shares, the flat W = 50 plane and the
#: thesis's featured N = 50094 box (Figs 5.6-5.10); ≈ 10-35 min each on one core here, ≈ 75 min the
#: last.
TC_TWINS = ("L42W30H30", "L90W30H30", "L150W50H10", "L150W30H30", "L70W50H50")
TC_TWIN_TC = 1e-6


def on_thesis_span(box: Box) -> bool:
    """Whether ``box`` runs over the thesis's span (W ≥ 30) rather than its shipped scene's."""
    return box.width >= 30


def twin_boxes() -> list[Box]:
    """The boxes (at the thesis's e = 0.7) that have a TC twin, in ``TC_TWINS``'s order."""
    return [next(b for b in BOXES if b.tag == tag and b.restitution == 0.7)
            for tag in TC_TWINS]


def twin_name(box: Box) -> str:
    """The TC twin's case name: the box's with ``-tc<t_c>`` before the engine."""
    return f"{box.name.removesuffix('-edmd')}-tc{TC_TWIN_TC:g}-edmd"


def cases(quick: bool) -> list[Case]:
    """Every box of the thesis's table as shipped (the e study overrides e only; W ≥ 30:
    over the thesis's span, ``THESIS_SPAN``) and the TC twins (``TC_TWINS``); ``quick``: the
    boxes of ``QUICK`` with short runs."""
    out = []
    for box in BOXES:
        sections = {} if box.restitution == 0.7 else {"contact": {"restitution":
                                                                  box.restitution}}
        if on_thesis_span(box):
            sections = {**sections, **THESIS_SPAN}
        is_quick = box.tag in QUICK and box.restitution == 0.7
        if quick and not is_quick:
            continue
        out.append(Case(box.name, box.scene, sections=sections, quick=is_quick,
                        quick_sections=QUICK_RUN if is_quick else {},
                        options={"tc": STUDY_TC}))
    if not quick:
        out += [Case(twin_name(box), box.scene, sections=THESIS_SPAN,
                     options={"tc": TC_TWIN_TC}) for box in twin_boxes()]
    return out


def derive(name: str, path: Path) -> dict[str, tuple[dict, dict]]:
    """What a study record keeps of box run ``name`` in place of its frames (the modes, the
    peak densities, the last frame: waves_measure.derive)."""
    twins = {twin_name(box) for box in twin_boxes()}
    if name not in twins and not any(box.name == name for box in BOXES):
        return {}
    from .waves_measure import derive as derive_waves

    return derive_waves(Path(path))


def analyse(runs: Mapping[str, Path], out: Path, quick: bool) -> Analysis:
    from .waves_report import analyse_waves

    return analyse_waves(runs, out, quick)
