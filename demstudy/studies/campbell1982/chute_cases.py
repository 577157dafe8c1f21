"""Campbell (1982) chutes: the runs (cases C1-C8 of the digest's catalogue, §1.4, and the
flat-base, t_c and soft-contact cross-checks).

Dimensionless particle units: d = 1, m = 1, g = 1 (lengths in d = 2R, times in √(d/g), speeds
in √(gd)); Campbell's own unit of length was R = d/2.

Which base. Campbell's base is flat with sticking contacts (``chute-20/30/40``). On it the basal
discs roll and a dense bed passes at most ≈ 0.50 of its weight as shear, so a dense steady flow
exists only up to α ≈ 25° (docs/studies/campbell1982-chute30.md); at 30° the bed accelerates.
Random bumps of diameter d at spacing 1.2 d (``chute-bumpy-30``) give a steady 30° flow. So the
statements about *steady* flows (C1, C4 with the variable ε, C5 ε_p = 0.1, C6, C7, C8, width)
are tested on the bumpy base; the statements about *non-convergence* (C3 at 40°) as the thesis
ran them (the flat base) and on the bumps; ε_p = 0.8 and the constant-ε 5 × 4 bed (C4, C5) on
the bumps, where 10 × 4 at ε_p = 0.6 converges (on the flat base every 30° bed accelerates,
which would make them trivially true). The flat-base scan 24°, 26°, 30° re-measures why.
"""

from __future__ import annotations

from typing import Any

from ..base import Case

#: the thesis's chute (Campbell's rules: ε_p = 0.6, ε_w = 0.8, fully rough discs and base)
FLAT = {20: "campbell1982/chute-20", 30: "campbell1982/chute-30", 40: "campbell1982/chute-40"}
BUMPY = "campbell1982/chute-bumpy-30"
#: what every chute run measures: profiles and the stress (kinetic + collisional/contact,
#: walls, momentum balance)
MEASURE = {"statistics": ["profiles", "stress"]}
#: ... and the collision angles (Fig 3.33, case C9: the 40° chute; the 30° reference beside
#: it) where a row uses them: a collision log costs time and disc space
MEASURE_ANGLES = {"statistics": ["profiles", "stress", "angles"]}
#: run lengths in √(d/g). Steady cases: 800 to settle (the 30° bumpy bed's energy creeps up
#: from 13 to ≈ 50 per disc over the first 600-800: with 200 its production trend was +0.67),
#: then 1600, ≈ 4·10⁶ pair collisions (a thesis run held "many thousands", L813)
STEADY_RUN = {"equilibration": 800.0, "production": 1600.0}
#: soft discs (LAMMPS): settle as the hard ones, a shorter production (≈ 4 min here)
SOFT_RUN = {"equilibration": 800.0, "production": 600.0}
#: accelerating beds (40°): the history after the start, while a dense core remains (by
#: t ≈ 800 the flat-base 40° bed is a dilute gas throughout, ν max 0.36)
ACCEL_RUN = {"equilibration": 50.0, "production": 350.0}
#: the flat-base angle scan: 24° (steady and dense in docs/studies/campbell1982-chute30.md
#: with two seeds; 22° there too, but a bed that slows to rest costs the event-driven engine
#: ~1/t_c events per disc and √(d/g)), 26° (marginal) and 30° (accelerates)
FLAT_ANGLES = (24, 26, 30)
#: (as docs/studies/campbell1982-chute30.md, half its length)
FLAT_RUN = {"equilibration": 200.0, "production": 1400.0}
#: the 20° flat bed decelerates and comes to rest by t ≈ 600: the production sees the plug
#: form and stop; a resting bed costs the event-driven engine ~1/t_c events per disc and √(d/g)
REST_RUN = {"equilibration": 200.0, "production": 600.0}
REST_RUN_BUMPY = {"equilibration": 30.0, "production": 60.0}
#: --quick: a few seconds each
QUICK_RUN = {20: {"equilibration": 20.0, "production": 40.0},
             30: {"equilibration": 50.0, "production": 150.0},
             40: {"equilibration": 20.0, "production": 100.0}}
#: the TC-model times compared (1e-5 is the engine's default for discs, DEFAULT_TC_2D:
#: chute-30-bumpy)
TC_VALUES = {"tc1e-4": 1e-4, "tc1e-6": 1e-6}
SEEDS = (2, 3)  # besides the scenes' 12345
VARIABLE = {"law": {"model": "campbell-exp"}}  # e(v) = ½[1 + exp(−3v/√(gR))], pairs only


#: the soft-contact engines of the cross-check (both express the bumpy base and gravity)
SOFT_ENGINES = ("lammps", "liggghts")


def bumpy_wall(restitution: float = 0.8) -> list[dict[str, Any]]:
    """The lower wall of chute-bumpy-30 (the whole walls list: overrides replace lists)."""
    return [{"side": "lower", "kind": "bumpy", "restitution": restitution,
             "tangential": {"model": "rough"},
             "bumps": {"spacing": 1.2, "diameter": 1.0, "pattern": "random"}}]


def _sections(run: dict, angles: bool = False, **extra: Any) -> dict[str, Any]:
    return {"run": dict(run), "measure": dict(MEASURE_ANGLES if angles else MEASURE), **extra}


def _bed(rows: int, columns: int = 4) -> dict[str, Any]:
    """A bed of rows × columns discs on Campbell's lattice (spacing 1.2 d: width 1.2 columns)."""
    return {"initial": {"rows": rows, "columns": columns}, "box": {"size": [1.2 * columns, 40.0]}}


def cases(quick: bool) -> list[Case]:
    """The chute runs; ``quick``: 20° (flat), 30° (bumps) and 40° (flat), a few seconds each."""
    angle = [
        Case("chute-30-bumpy", BUMPY, sections=_sections(STEADY_RUN, angles=True), quick=True,
             quick_sections={"run": QUICK_RUN[30]}, group="C1"),
        Case("chute-20-flat", FLAT[20], sections=_sections(REST_RUN), quick=True,
             quick_sections={"run": QUICK_RUN[20]}, group="C2"),
        Case("chute-40-flat", FLAT[40], sections=_sections(ACCEL_RUN, angles=True), quick=True,
             quick_sections={"run": QUICK_RUN[40]}, group="C3"),
    ]
    if quick:
        return [c for c in angle if c.quick]
    flat = [Case(f"chute-{a}-flat", FLAT[30],
                 sections=_sections(FLAT_RUN, gravity={"angle": float(a)}), group="flat")
            for a in FLAT_ANGLES]
    more_angles = [
        Case("chute-20-bumpy", FLAT[20], sections=_sections(REST_RUN_BUMPY, walls=bumpy_wall()),
             group="C2"),
        Case("chute-40-bumpy", FLAT[40],
             sections=_sections(ACCEL_RUN, angles=True, walls=bumpy_wall()),
             group="C3"),
    ]
    depth = [Case(f"chute-30-bumpy-{r}x4-var", BUMPY,
                  sections=_sections(STEADY_RUN, contact=VARIABLE, **_bed(r)), group="C4")
             for r in (5, 10, 13)]
    depth.append(Case("chute-30-bumpy-5x4", BUMPY, sections=_sections(STEADY_RUN, **_bed(5)),
                      group="C4"))
    resti = [Case(f"chute-30-bumpy-ep{e:g}", BUMPY,
                  sections=_sections(STEADY_RUN, contact={"restitution": e}), group="C5")
             for e in (0.1, 0.8)]
    resti += [Case(f"chute-30-bumpy-ew{e:g}", BUMPY,
                   sections=_sections(STEADY_RUN, walls=bumpy_wall(e)), group="C6")
              for e in (0.6, 1.0)]
    steep = [
        Case("chute-40-bumpy-5x4", FLAT[40],
             sections=_sections(STEADY_RUN, walls=bumpy_wall(), **_bed(5)), group="C7"),
        Case("chute-40-bumpy-4x4-var", FLAT[40],
             sections=_sections(STEADY_RUN, walls=bumpy_wall(), contact=VARIABLE, **_bed(4)),
             group="C8"),
        Case("chute-30-bumpy-10x8", BUMPY, sections=_sections(STEADY_RUN, **_bed(10, 8)),
             group="width"),
    ]
    # other seeds (initial jitter, velocities and the random bump heights): the spread of the
    # 40-disc flow between realisations, against which "little effect" is judged
    seeds = [Case(f"chute-30-bumpy-seed{k}", BUMPY,
                  sections=_sections(STEADY_RUN | {"seed": k}), group="seed") for k in SEEDS]
    tc = [Case(f"chute-30-bumpy-{name}", BUMPY, sections=_sections(STEADY_RUN),
               options={"tc": t}, group="tc") for name, t in TC_VALUES.items()]
    # soft discs: k_n = 1e6 (the scene's; at 1e5 the soft bed creeps), ≈ 4 min here
    soft = [Case(f"chute-30-bumpy-{engine}", BUMPY, engine=engine,
                 sections=_sections(SOFT_RUN), group="soft")
            for engine in SOFT_ENGINES]
    return angle + flat + more_angles + depth + resti + steep + seeds + tc + soft
