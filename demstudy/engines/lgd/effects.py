"""How the LGD engine expresses each physical effect (``TRANSLATIONS``), what it cannot, and
the scene → lattice mapping (:func:`lattice_setup`) with its unit conversion.

Units: the scene is in dimensionless particle units (d = 1 = the lattice spacing, m = 1,
g = 1 when gravity acts); the lattice in the listing's integers (offsets 1/``idl`` spacing,
velocities 1/256 "cm/s", ticks 1/65536 s, gravity "cm/s²"). One number links them, the
integer speed ``V`` of particle speed 1 (:class:`LgdUnits`):

* gravity acts: V = 4·√(|g_int|·idl / g) (so that g is the scene's gravity magnitude, 1 by
  convention, and the time unit is √(d/g)); |g_int| = ``lattice.gravity_scale`` cm/s²;
* no gravity, moving walls: V = ``lattice.speed_scale`` (required; the wall speeds are then
  given in units of it, e.g. ±1 with Gutt's Couette 4096);
* no gravity, walls at rest: V = ``lattice.speed_scale`` if given, else the grains' initial
  r.m.s. speed.

A speed v becomes round(v·V), a restitution e becomes ke·e (which must be a whole number:
the listing's coefficients are multiples of 1/ke), the crossover speed c_b becomes
icb = round(c_b·V), gravity (igx, igy) = round(gravity_scale·ĝ) (refused when rounding turns
it by more than 0.5°).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ...effects import Cannot, Translation, apply_effects
from ...errors import UnsupportedByEngine
from ...scene import Scene
from .lattice import LgdParams

__all__ = ["TRANSLATIONS", "LgdUnits", "lattice_setup"]

ENGINE = "lgd"
#: largest turn of gravity's direction by rounding (igx, igy) to integers, degrees
MAX_GRAVITY_TURN = 0.5


@dataclass(frozen=True)
class LgdUnits:
    """Particle units ↔ the listing's integers: ``speed`` V (integer velocity of particle
    speed 1), ``idl`` (offset units per spacing = length unit), and what set V."""

    speed: float
    idl: int
    basis: str

    @property
    def ticks_per_time(self) -> float:
        """Ticks (1/65536 s) per time unit d/V: 4096·idl/V (= 1024·√(idl/g) with gravity)."""
        return 4096.0 * self.idl / self.speed

    def attrs(self) -> dict:
        return {"lgd_speed_unit": self.speed, "lgd_ticks_per_time_unit": self.ticks_per_time,
                "lgd_speed_unit_basis": self.basis}


@dataclass
class Draft:
    """The lattice parameters under construction (integer fields of ``LgdParams``)."""

    values: dict
    units: LgdUnits
    notes: list[str] = field(default_factory=list)


def _refuse(field_name: str, value, reason: str) -> UnsupportedByEngine:
    return UnsupportedByEngine(ENGINE, field_name, value, reason)


def scaled_restitution(e: float, ke: int, field_name: str) -> int:
    """ke·e as the listing's integer; refused unless ke·e is whole."""
    scaled = e * ke
    if abs(scaled - round(scaled)) > 1e-9:
        raise _refuse(field_name, e, f"the listing's coefficients are multiples of 1/ke = "
                                     f"1/{ke}: {e:g}·{ke} = {scaled:g} is not whole (round e, "
                                     "or change lattice.ke)")
    return int(round(scaled))


def _pair_rule(scene: Scene, d: Draft) -> None:
    """Constant e_pp, or Gutt's piecewise law (e1 below c_b, e2 above)."""
    ke, law = d.values["ke"], scene.contact.law
    if law.model == "gutt-piecewise":
        d.values["iep1"] = scaled_restitution(law.e1, ke, "contact.law.e1")
        d.values["iep2"] = scaled_restitution(law.e2, ke, "contact.law.e2")
        d.values["icb"] = int(round(law.crossover_speed * d.units.speed))
    else:
        e = scaled_restitution(scene.contact.restitution, ke, "contact.restitution")
        d.values["iep1"] = d.values["iep2"] = e


def _check_law(scene: Scene) -> None:
    if scene.contact.law.model != "gutt-piecewise":
        raise _refuse("contact.law.model", scene.contact.law.model,
                      "LGD has Gutt's piecewise law only (model = 'gutt-piecewise', or a "
                      "constant restitution)")


def _walls(scene: Scene, d: Draft) -> None:
    """Rows 1 and nyt: one grain–wall restitution (iew1/iew2) for both, each its velocity."""
    lower, upper = scene.wall("lower"), scene.wall("upper")
    if lower.restitution != upper.restitution:
        raise _refuse("walls[upper].restitution", upper.restitution,
                      "the listing has one grain–wall restitution for every wall particle: "
                      f"give both walls {lower.restitution:g}")
    ke = d.values["ke"]
    d.values["iew1"] = scaled_restitution(lower.restitution, ke, "walls.restitution")
    e2 = scene.lattice.wall_e2
    d.values["iew2"] = d.values["iew1"] if e2 is None else \
        scaled_restitution(e2, ke, "lattice.wall_e2")
    if d.values["iew2"] != d.values["iew1"] and scene.contact.law.model != "gutt-piecewise":
        raise _refuse("lattice.wall_e2", e2, "a wall restitution that changes at the "
                                             "crossover speed needs contact.law 'gutt-piecewise' "
                                             "(its crossover_speed)")
    d.values["jx1"] = int(round(lower.velocity * d.units.speed))
    d.values["jx2"] = int(round(upper.velocity * d.units.speed))


def _gravity(scene: Scene, d: Draft) -> None:
    scale = scene.lattice.gravity_scale
    gx, gy = scene.gravity_vector[:2]
    norm = math.hypot(gx, gy)
    igx, igy = int(round(scale * gx / norm)), int(round(scale * gy / norm))
    if igx == igy == 0:
        raise _refuse("lattice.gravity_scale", scale, "gravity rounds to (0, 0) in the "
                                                      "listing's integers: raise it")
    turn = math.degrees(abs(math.atan2(gx * igy - gy * igx, gx * igx + gy * igy)))
    if turn > MAX_GRAVITY_TURN:
        raise _refuse("lattice.gravity_scale", scale,
                      f"gravity rounds to (igx, igy) = ({igx}, {igy}), {turn:.2f}° off the "
                      f"scene's direction; allowed: at most {MAX_GRAVITY_TURN}° (raise "
                      "gravity_scale)")
    d.values["igx"], d.values["igy"] = igx, igy
    if turn > 0:
        d.notes.append(f"gravity (igx, igy) = ({igx}, {igy}) is {turn:.3f}° off the scene's "
                       "direction (integer rounding)")


def _lattice(scene: Scene, d: Draft) -> None:
    spec = scene.lattice
    d.values.update(nxt=spec.nxt, nyt=spec.nyt, idl=spec.idl, idx=spec.idx, idy=spec.idy,
                    id=spec.id, ke=spec.ke, ntu=spec.ntu, kq=spec.kq, kx=spec.kx, ky=spec.ky)


ROUGH = ("LGD grains are smooth discs without spin: collisions exchange impulse along the "
         "lattice bond only (digest §3.8); use tangential model 'smooth'")

#: every effect's LGD translation, or why LGD cannot express it
TRANSLATIONS: dict[str, Translation | Cannot] = {
    "lattice": Translation(_lattice, how="nxt, nyt and the integer scales of [lattice]"),
    "planar": Translation(how="the triangular lattice is 2D"),
    "rotation": Cannot(ROUGH),
    "restitution-law": Translation(check=_check_law, how="icb, iep1/iep2 (and iew1/iew2 with "
                                                         "lattice.wall_e2)"),
    "walls": Translation(_walls, how="wall rows 1 and nyt (jx1, jx2; iew1, iew2)"),
    "moving-walls": Translation(how="the wall rows' x velocities jx1, jx2"),
    "noslip-walls": Cannot("LGD walls are rows of wall particles colliding like grains of "
                           "infinite mass (no Campbell no-slip rule); use model 'smooth'"),
    "servo": Cannot("LGD wall rows are fixed lattice rows: no normal motion, no servo; use "
                    "--engine edmd or lammps"),
    "bumpy-walls": Cannot("LGD wall rows are already rough (a row of wall particles, fig "
                          "3.13a); build rougher walls from wall particles in md lines "
                          "(md −1, −2, −3, −6) instead of [walls.bumps]"),
    "gravity": Translation(_gravity, how="igx, igy = round(gravity_scale·ĝ)"),
    "lees-edwards": Cannot("LGD's y is bounded by the wall rows: no Lees–Edwards images; "
                           "shear with moving wall rows (Couette) instead"),
}


def speed_unit(scene: Scene) -> LgdUnits:
    """The integer speed V of particle speed 1 and what sets it (module docstring)."""
    from ...scene.lattice import lattice_grains  # noqa: PLC0415

    spec = scene.lattice
    if scene.gravity is not None:
        if spec.speed_scale is not None:
            raise _refuse("lattice.speed_scale", spec.speed_scale,
                          "with gravity the speed unit is √(g d) (from lattice.gravity_scale "
                          "and idl); leave speed_scale out")
        gx, gy = scene.gravity_vector[:2]
        norm = math.hypot(gx, gy)
        igx = round(spec.gravity_scale * gx / norm)
        igy = round(spec.gravity_scale * gy / norm)
        g_int = math.hypot(igx, igy) or spec.gravity_scale
        speed = 4.0 * math.sqrt(g_int * spec.idl / scene.gravity.magnitude)
        return LgdUnits(speed, spec.idl, "gravity: time unit √(d/g)")
    moving = [w for w in scene.walls if w.velocity != 0.0]
    if spec.speed_scale is not None:
        basis = "wall speed" if moving else "lattice.speed_scale"
        return LgdUnits(float(spec.speed_scale), spec.idl, f"{basis}: time unit d/V, "
                                                            "V = lattice.speed_scale")
    if moving:
        raise _refuse("lattice.speed_scale", None,
                      "moving walls without gravity: give the listing's integer speed of "
                      "particle speed 1 (e.g. Gutt's Couette wall speed 4096), the walls' "
                      "velocities in units of it")
    rms = lattice_grains(spec, scene.run.seed)[1]
    if rms <= 0.0:
        raise _refuse("lattice.speed_scale", None,
                      "no gravity, walls at rest and every grain at rest: nothing sets a "
                      "speed unit (and nothing would move); give speed_scale or velocities")
    return LgdUnits(rms, spec.idl, "initial r.m.s. grain speed: time unit d/v_rms")


@dataclass
class LatticeSetup:
    params: LgdParams
    units: LgdUnits
    lines: list
    notes: list[str]


def lattice_setup(scene: Scene) -> LatticeSetup:
    """The LGD parameters, units and md lines of a lattice scene (effects refused per
    ``TRANSLATIONS``); absent effects leave their parameters at rest (no gravity: igx = igy
    = 0, elastic defaults replaced only by the walls' and contact's restitutions)."""
    if scene.lattice is None:
        raise _refuse("lattice", None, "the lgd engine runs lattice scenes only: add a "
                                       "[lattice] section (nxt, nyt, md lines; docs/lgd-engine.md)")
    draft = Draft(values={"igx": 0, "igy": 0, "jx1": 0, "jx2": 0, "icb": 0},
                  units=speed_unit(scene))
    draft.values["ke"] = scene.lattice.ke
    _pair_rule(scene, draft)  # the pair rule is always there (constant or piecewise)
    apply_effects(scene, ENGINE, TRANSLATIONS, draft)
    return LatticeSetup(LgdParams(**draft.values), draft.units,
                        scene.lattice.lines(scene.run.seed), draft.notes)
