"""How the event-driven core expresses each physical effect (``TRANSLATIONS``), and what it
cannot: the scene becomes the core's constructor options (:func:`core_options`).

Dimensionless particle units: d = 1, m = 1 (mass ∝ d^dim), g = 1 with gravity. Every
translation adds its options to a dict that starts with the pair collision rule (e, β, K).
"""

from __future__ import annotations

import math

from ...effects import LATTICE_ONLY, Cannot, Translation, apply_effects
from ...errors import UnsupportedByEngine
from ...scene import Scene

__all__ = ["TRANSLATIONS", "collision_rule", "core_options"]


def collision_rule(restitution: float, rule, law=None, gravity: float | None = None) -> dict:
    """Collision-rule options of the core from a restitution, a tangential rule and a law."""
    out: dict = {"e": float(restitution)}
    if rule.model == "coulomb":
        out.update(tangential="coulomb", mu=float(rule.mu))
        if rule.beta0 is None:  # β₀ = e of each collision (default_beta0)
            out.update(beta0=float(restitution), beta0_from_e=True)
        else:
            out.update(beta0=float(rule.beta0))
    elif rule.model == "campbell-noslip":
        out.update(tangential="noslip")
    else:
        out.update(tangential="beta", beta=float(rule.beta))
    if law is not None and law.model == "campbell-exp":
        # e(v) = ½[1 + exp(−v/speed)], speed = √(g R)/3 with R = ½
        out.update(law="campbell-exp", speed=math.sqrt(gravity * 0.5) / 3.0)
    elif law is not None and law.model == "gutt-piecewise":
        out.update(law="gutt-piecewise", e1=float(law.e1), e2=float(law.e2),
                   crossover_speed=float(law.crossover_speed))
    return out


def _pair_rule(scene: Scene, params: dict) -> None:
    """The pair rule's tangential part and restitution law (``rotation``,
    ``restitution-law``): plain β stays in ``beta``, anything else goes to ``pair``."""
    g = scene.gravity.magnitude if scene.gravity is not None else None
    pair = collision_rule(scene.contact.restitution, scene.contact.tangential,
                          scene.contact.law, g)
    pair.pop("e")
    params["beta"] = float(pair.get("beta", -1.0))
    if pair != {"tangential": "beta", "beta": params["beta"]}:
        params["pair"] = pair


def _check_law(scene: Scene) -> None:
    if scene.contact.law.model == "campbell-exp" and scene.gravity is None:
        raise UnsupportedByEngine("edmd", "contact.law.model", "campbell-exp",
                                  "Campbell's e(v) = ½[1 + exp(−3v/√(gR))] needs gravity "
                                  "(its speed scale is √(gR))")


def _walls(scene: Scene, params: dict) -> None:
    walls = []
    for wall in scene.walls:
        rule = collision_rule(wall.restitution, wall.tangential)
        walls.append({"side": wall.side, "position": scene.wall_position(wall.side),
                      "velocity": float(wall.velocity), **rule})
    params.update(periodic_y=False, walls=walls)


def _check_bumps(scene: Scene) -> None:
    for wall in scene.walls:
        if wall.kind != "bumpy":
            continue
        if scene.gravity is not None and wall.bumps.pattern != "random":
            raise UnsupportedByEngine("edmd", f"walls[{wall.side}].bumps.pattern",
                                      wall.bumps.pattern,
                                      "under gravity the event-driven engine needs "
                                      "pattern = 'random': on regular bumps the bottom "
                                      "layer settles into the hollows at exactly zero "
                                      "gaps and the hard particles' collisions loop "
                                      "without time passing (a stall); use random bumps, "
                                      "a flat wall with a rough rule, or LAMMPS")
        if wall.servo is not None:
            raise UnsupportedByEngine("edmd", f"walls[{wall.side}].servo", "servo",
                                      "a bumpy wall cannot be servo-controlled")
        if wall.tangential.model == "campbell-noslip":
            raise UnsupportedByEngine("edmd", f"walls[{wall.side}].tangential.model",
                                      wall.tangential.model,
                                      "bumps collide as particles: use beta, rough or "
                                      "coulomb")


#: every effect's event-driven translation
TRANSLATIONS: dict[str, Translation | Cannot] = {
    "lattice": LATTICE_ONLY,
    "planar": Translation(how="discs: 2D positions, spins about z"),
    "rotation": Translation(_pair_rule, how="β, rough or Walton's Coulomb rule per contact"),
    "restitution-law": Translation(_pair_rule, _check_law, how="e(v) in the pair rule"),
    "walls": Translation(_walls),
    "moving-walls": Translation(how="each wall's velocity in the wall options"),
    "noslip-walls": Translation(how="the wall rule 'noslip'"),
    "servo": Translation(how="walls moved by the simulation loop (set_wall, scale_width)"),
    "bumpy-walls": Translation(check=_check_bumps,
                               how="fixed particles appended to the system (engines.edmd."
                                   "backend), colliding with their wall's rule"),
    "gravity": Translation(lambda s, p: p.update(gravity=[float(c) for c in
                                                           s.gravity_vector])),
    "lees-edwards": Translation(lambda s, p: p.update(shear_rate=float(s.shear.rate)),
                                how="sliding images along y (shear_rate)"),
}


def core_options(scene: Scene) -> dict:
    """e, β and K of a scene's pair collisions plus every other core option the scene's
    effects need (gravity, Lees–Edwards, walls); refuses what the core cannot express."""
    params: dict = {"e": float(scene.contact.restitution), "beta": -1.0,
                    "inertia_k": float(scene.inertia_k)}
    apply_effects(scene, "edmd", TRANSLATIONS, params)
    return params
