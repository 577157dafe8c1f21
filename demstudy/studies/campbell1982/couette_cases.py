"""The runs of the Couette part of the Campbell (1982) study (cases K1-K7 of the digest).

Dimensionless particle units: d = 1, m = 1; no gravity: the upper wall's speed U_T sets the
time scale (times in d/U_T, 2D stresses in m U_T²/d²). Campbell's unit of length was R = d/2.

The cell is Campbell's: 10 rows × 4 columns of fully rough discs (β = ½), ε_p = 0.6,
ε_w = 0.8, between two walls 10 spacings apart, the upper wall sliding at U_T. Two families:

* servo runs (``K1`` rough walls, ``K2`` no-slip walls; ``K3`` the shear-rate series): the
  scenes ``campbell1982/couette-rough`` / ``couette-noslip`` as shipped, at Campbell's normal
  stress σ_n = 0.567 m (U_T/H)² (his 0.567 (R/H)² in m U_T²/R²) times a factor; the solid
  fraction ν is an output;
* fixed-gap runs (servo off, no-slip walls as K4-K6): the lattice spacing C sets
  ν = π d² / (4 C²) (gap 10 C, width 4 C), the ν = 0.35 … 0.75 series of Figs 3.18-3.40.

Run lengths are in strain units γ̇t (γ̇ = U_T/H): Campbell averaged over "many thousands of
collisions" (a few hundred per disc); the full runs here hold ~10⁴ per disc.
"""

from __future__ import annotations

import math
from typing import Any

from ..base import Case

ROUGH = "campbell1982/couette-rough"
NOSLIP = "campbell1982/couette-noslip"
#: Campbell's σ_n = 0.567 (U_T/H)² with H = 12 (the scenes' value)
SIGMA_REF = 0.567 / 144.0
#: K1/K2: the three normal stresses, in units of SIGMA_REF (the thesis does not give them)
SERVO_FACTORS = (0.5, 1.0, 2.0)
#: the fixed-gap solid fractions (Campbell's range 0.35 … 0.76)
FIXED_NU = (0.35, 0.45, 0.55, 0.65, 0.75)
#: K3: nominal shear rates γ̇ = U_T/H₀ (H₀ = 12); Campbell's R/H = γ̇/2 in his units
SHEAR_RATES = (1 / 24, 1 / 12, 1 / 6)
#: full runs: equilibration and production in strain units
EQ_STRAIN, PROD_STRAIN = 100.0, 1000.0
#: servo cells at half Campbell's stress move their walls slowly: with 100 strain units of
#: equilibration the no-slip cell's gap still grew 25 % over the production (12 → 17.6 d)
#: and the rough one's shrank 18 %; they settle for longer (measured 2026-12-03)
SERVO_EQ_STRAIN = {0.5: 4000.0}
#: quick runs
QUICK_EQ_STRAIN, QUICK_PROD_STRAIN = 40.0, 120.0
#: what every Couette case measures
STATISTICS = ["profiles", "stress", "angles", "vdf", "structure", "derived"]
#: collision-log chunks (the angles' block errors need them long): the default is fine


def spacing_for(nu: float) -> float:
    """Lattice spacing C (d) of a square lattice with solid fraction ν = π/(4 C²)."""
    if not 0.0 < nu < math.pi / 4:
        raise ValueError(f"nu = {nu}: a square lattice start allows 0 < nu < pi/4")
    return math.sqrt(math.pi / (4.0 * nu))


def _run(gap: float, speed: float, eq: float, prod: float,
         per_strain: float = 4.0) -> dict[str, Any]:
    """Run section for ``eq``/``prod`` strain units at γ̇ = speed/gap, sampled
    ``per_strain`` times per strain unit (frames are kept: 4 keeps a full run's file small;
    the quick runs take the scenes' 12)."""
    rate = speed / gap
    return {"equilibration": eq / rate, "production": prod / rate,
            "sample_interval": 1.0 / (per_strain * rate)}


def _walls(model: str, eps_w: float, speed: float, servo: dict | None) -> list[dict]:
    out = []
    for side, v in (("lower", 0.0), ("upper", speed)):
        wall: dict[str, Any] = {"side": side, "restitution": eps_w,
                                "tangential": {"model": model}, "velocity": v}
        if servo is not None:
            wall["servo"] = servo
        out.append(wall)
    return out


def servo_case(name: str, wall: str, factor: float = 1.0, rate: float = 1 / 12,
               quick: bool = False, group: str = "servo", **extra: Any) -> Case:
    """A servo run: Campbell's scene with σ_n = factor × 0.567 m γ̇² (γ̇ = U_T/12)."""
    speed = 12.0 * rate
    sigma = factor * 0.567 * rate**2
    servo = {"normal_stress": sigma, "interval_collisions": 3.0, "interval_time": 10.0 / speed,
             "scale_width": True, "hold_shear_rate": True}
    model = "rough" if wall == "rough" else "campbell-noslip"
    sections: dict[str, Any] = {
        "walls": _walls(model, 0.8, speed, servo),
        "initial": {"velocity": {"profile": "linear", "perturbation": 0.1}},
        "run": _run(12.0, speed, SERVO_EQ_STRAIN.get(factor, EQ_STRAIN), PROD_STRAIN),
        "measure": {"statistics": STATISTICS},
    }
    return Case(name, ROUGH if wall == "rough" else NOSLIP, sections=sections, quick=quick,
                quick_sections={"run": _run(12.0, speed, QUICK_EQ_STRAIN, QUICK_PROD_STRAIN,
                                                    12.0)},
                group=group, **extra)


def fixed_case(name: str, nu: float, wall: str = "noslip", eps: tuple[float, float] = (0.8, 0.6),
               rows: int = 10, columns: int = 4, quick: bool = False, group: str = "fixed",
               options: dict | None = None) -> Case:
    """A fixed-gap run at solid fraction ``nu`` (walls ``rough`` or ``noslip``; ``eps`` =
    (ε_w, ε_p)); gap rows·C, width columns·C, U_T = 1."""
    c = spacing_for(nu)
    gap = rows * c
    model = "rough" if wall == "rough" else "campbell-noslip"
    sections: dict[str, Any] = {
        "box": {"size": [columns * c, gap]},
        "contact": {"restitution": eps[1]},
        "walls": _walls(model, eps[0], 1.0, None),
        "initial": {"rows": rows, "columns": columns, "spacing": c},
        "run": _run(gap, 1.0, EQ_STRAIN, PROD_STRAIN),
        "measure": {"statistics": STATISTICS},
    }
    return Case(name, NOSLIP, sections=sections, quick=quick,
                quick_sections={"run": _run(gap, 1.0, QUICK_EQ_STRAIN, QUICK_PROD_STRAIN, 12.0)},
                group=group, options=options or {})


def nu_tag(nu: float) -> str:
    return f"{nu:.2f}".replace("0.", "")


def all_cases() -> list[Case]:
    """Every Couette case (quick ones flagged)."""
    cases = []
    for wall, key in (("rough", "k1"), ("noslip", "k2")):
        for f in SERVO_FACTORS:
            cases.append(servo_case(f"couette-{key}-{wall}-servo-s{f:g}", wall, f,
                                    quick=(wall == "rough" and f == 1.0), group=key))
    for rate in SHEAR_RATES:
        if rate == 1 / 12:
            continue  # the K2 run at factor 1
        cases.append(servo_case(f"couette-k3-noslip-rate{12 * rate:g}", "noslip", 1.0, rate,
                                group="k3"))
    for nu in FIXED_NU:
        cases.append(fixed_case(f"couette-fixed-nu{nu_tag(nu)}", nu,
                                quick=nu in (0.45, 0.65)))
    cases.append(fixed_case("couette-k6-nu45-elastic", 0.45, eps=(1.0, 1.0), group="k6"))
    cases += candidate_cases()
    soft = servo_case("couette-k1-rough-servo-s1-lammps", "rough", 1.0, group="lammps",
                      engine="lammps")
    # no collision log in a soft engine: no angles
    sections = {**soft.sections, "measure": {"statistics": [s for s in STATISTICS
                                                             if s != "angles"]}}
    cases.append(Case(soft.name, soft.scene, "lammps", sections=sections, group="lammps"))
    return cases


def candidate_cases() -> list[Case]:
    """Runs that test candidate causes of differences (wall rule, system size, t_c)."""
    out = []
    for nu in (0.55, 0.75):
        out.append(fixed_case(f"couette-cause-rough-nu{nu_tag(nu)}", nu, wall="rough",
                              group="cause-wall"))
        # at ν = 0.75 the larger lattices stall at t_c = 1e-5 (a crystalline row colliding
        # in a loop that takes no time): they run at t_c = 1e-4, beside the 10 × 4 cell's
        # t_c = 1e-4 run
        tc = {"tc": 1e-4} if nu > 0.7 else {}
        out.append(fixed_case(f"couette-cause-10x8-nu{nu_tag(nu)}", nu, columns=8,
                              group="cause-size", options=tc))
        out.append(fixed_case(f"couette-cause-20x8-nu{nu_tag(nu)}", nu, rows=20, columns=8,
                              group="cause-size", options=tc))
    for tc in (1e-4, 1e-6):
        out.append(fixed_case(f"couette-cause-tc{tc:g}-nu75", 0.75, group="cause-tc",
                              options={"tc": tc}))
        if tc < 1e-5:  # the ν = 0.65 cell makes 6 % elastic at 1e-5: its small-share twin
            out.append(fixed_case(f"couette-cause-tc{tc:g}-nu65", 0.65, group="cause-tc",
                                  options={"tc": tc}))
        # the rough-wall servo cells make 13-56 % of their collisions elastic at t_c = 1e-5
        out.append(servo_case(f"couette-cause-tc{tc:g}-rough-servo-s1", "rough", 1.0,
                              group="cause-tc", options={"tc": tc}))
    return out
