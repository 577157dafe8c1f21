"""Soft contacts of a scene: pair and wall parameters, stiffness and time step, for every
soft-contact engine.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise the wall speed
or shear rate sets the time unit τ). k_n is a force per length, m/τ², for Hooke contacts and a
force per length^3/2 for Hertz; by default it is chosen so that an impact at the scene's
reference speed (``reference_speed``) overlaps by DEFAULT_OVERLAP.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import UnsupportedByEngine
from ..scene import Scene
from ..scene.schema import Wall
from . import mapping

#: Default hardness: at most this overlap (in d) at the reference speed.
DEFAULT_OVERLAP = 0.005


def reference_speed(scene: Scene) -> float:
    """Typical impact speed: √(g H) under gravity (H = particle-bed height or box), the wall
    speed in Couette flow, rate × Ly/2 under shear, √T for a free gas; never below 1e-3."""
    speeds = [abs(w.velocity) for w in scene.walls]
    if scene.gravity is not None:
        height = scene.box.size[1]
        if scene.initial.placement == "lattice":
            height = scene.initial.rows * scene.initial.spacing
        speeds.append(math.sqrt(scene.gravity.magnitude * min(height, 50.0)))
    if scene.shear is not None:
        speeds.append(scene.shear.rate * scene.box.size[1] / 2)
    v = scene.initial.velocity
    speeds += [abs(v.scale), math.sqrt(v.temperature)]
    return max(max(speeds), 1e-3)


@dataclass(frozen=True)
class ContactSetup:
    pair: mapping.ContactParameters
    walls: dict[str, mapping.ContactParameters]
    timestep: float
    kn: float


def _rule(rule, engine: str, e: float, model: str, where: str) -> dict:
    """make_contact's arguments for a tangential rule (smooth, beta and rough all carry β);
    refuses a Coulomb rule whose soft spring would not follow Walton's rule (``where`` names
    the scene field: 'contact' or 'walls')."""
    if rule.model == "coulomb":
        why = mapping.walton_mismatch(e, rule.beta0, model)  # type: ignore[arg-type]
        if why is not None:
            raise UnsupportedByEngine(engine, f"{where}.tangential.beta0", rule.beta0, why)
        return {"mu": rule.mu, "beta0": rule.beta0}
    if rule.model != "campbell-noslip":
        return {"beta": rule.beta}
    raise UnsupportedByEngine(engine, "walls.tangential.model", rule.model,
                              "Campbell's no-slip wall has no soft-contact equivalent")


def choose_stiffness(scene: Scene, e: float, m_eff: float,
                     engine: str = "soft contacts") -> float:
    """k_n from ``soft.stiffness``, a hardness target, or by default an overlap of
    DEFAULT_OVERLAP at the reference speed (Hooke: force/length; Hertz: force/length^3/2)."""
    soft = scene.soft
    if soft.stiffness is not None:
        return soft.stiffness
    h = soft.hardness
    overlap, speed = DEFAULT_OVERLAP, reference_speed(scene)
    if h is not None and h.overlap is not None:
        overlap, speed = h.overlap, h.impact_speed
    elif h is not None:
        if soft.model == "hertz":
            raise UnsupportedByEngine(
                engine, "soft.hardness", h.model_dump(exclude_none=True),
                "k* and κ define a Hooke stiffness; for Hertz give overlap and impact_speed",
            )
        if h.k_star is not None:
            if scene.shear is None:
                raise UnsupportedByEngine(engine, "soft.hardness.k_star", h.k_star,
                                          "k* = k/(ρ d³ γ̇²) needs a shear rate ([shear])")
            return mapping.kn_from_kstar(h.k_star, scene.shear.rate, 1.0, scene.dimension)
        return mapping.kn_from_kappa(h.kappa, h.pressure, scene.dimension)
    if soft.model == "hertz":
        return mapping.hertz_kn_for_overlap(overlap, speed, m_eff, 0.25, e)
    return mapping.hooke_kn_for_overlap(overlap, speed, m_eff, e)


def shortest_contact_time(scene: Scene, kn: float, speed: float) -> float:
    """Contact time of the lightest contacts: the two smallest particles of a polydisperse
    scene (d_min = 1 − spread/2, m ∝ d^dim), and the smallest particle on a wall."""
    d_min = 1.0 - scene.particles.diameter_spread / 2
    m_min = d_min**scene.dimension
    cases = [(scene.contact.restitution, m_min / 2, d_min / 4)]
    cases += [(w.restitution, m_min, d_min / 2) for w in scene.walls]
    if scene.soft.model == "hertz":
        return min(mapping.hertz_contact(kn, e, m, r, speed).contact_time for e, m, r in cases)
    return min(mapping.hooke_contact(kn, e, m).contact_time for e, m, _ in cases)


def contact_setup(scene: Scene, engine: str = "soft contacts") -> ContactSetup:
    """Pair (m_eff = m/2) and per-wall (m_eff = m) contacts with a common time step;
    ``engine`` names the soft-contact engine in refusals (a hardness target that defines no
    stiffness for the contact model)."""
    K, e, model = scene.inertia_k, scene.contact.restitution, scene.soft.model
    kn = choose_stiffness(scene, e, 0.5, engine)
    speed = reference_speed(scene)
    if scene.soft.hardness is not None and scene.soft.hardness.impact_speed is not None:
        speed = max(speed, scene.soft.hardness.impact_speed)  # Hertz t_c shrinks with speed
    extra = {"r_eff": 0.25, "speed": speed} if model == "hertz" else {}
    pair = mapping.make_contact(kn=kn, e=e, m_eff=0.5, K=K, model=model,
                                **_rule(scene.contact.tangential, engine, e, model, "contact"),
                                **extra)
    walls = {w.side: _wall_contact(w, kn, K, model, speed, engine) for w in scene.walls}
    dt = mapping.timestep(shortest_contact_time(scene, kn, speed), scene.soft.steps_per_contact)
    return ContactSetup(pair, walls, dt, kn)


def _wall_contact(wall: Wall, kn: float, K: float, model: str, speed: float, engine: str):
    extra = {"r_eff": 0.5, "speed": speed} if model == "hertz" else {}
    return mapping.make_contact(kn=kn, e=wall.restitution, m_eff=1.0, K=K, model=model,
                                **_rule(wall.tangential, engine, wall.restitution, model, "walls"),
                                **extra)
