"""Soft contacts of a scene: pair and wall parameters, stiffness and time step, for every
soft-contact engine.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise the wall speed
or shear rate sets the time unit τ). k_n is a force per length, m/τ², for Hooke contacts and a
force per length^3/2 for Hertz. Without ``soft.stiffness`` or ``soft.hardness`` it is chosen
automatically (``stiffness_basis``):

* "pilot": from an event-driven pilot run (:mod:`demstudy.contact.pilot`, passed explicitly
  as ``contact_setup(scene, pilot=...)``; ``demstudy run`` does so): the largest overlap at
  the DESIGN_QUANTILE of the measured pair and wall impact speeds (never below the initial
  state's own approach speeds) stays below TARGET_OVERLAP, and the contact time below
  TARGET_CONTACT_RATIO × the measured free-flight time;
* "estimate": without a (usable) pilot, an impact at the guessed ``reference_speed``
  overlaps by DEFAULT_OVERLAP (``demstudy deck``, and scenes the event-driven engine cannot
  run).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..errors import UnsupportedByEngine
from ..scene import Scene
from ..scene.schema import Wall
from . import mapping
from .pilot import PilotResult

#: Default hardness: at most this overlap (in d) at the reference speed.
DEFAULT_OVERLAP = 0.005

# -- targets of the automatic ("pilot") settings, in one place (docs/contact.md), set from the
# accuracy ladders of docs/accuracy-cost.md: a softer contact is cheaper (dt ∝ t_c ∝ k_n^-1/2)
# but overlaps more
#: largest overlap δ/d allowed at the design impact speed
TARGET_OVERLAP = DEFAULT_OVERLAP
#: the design impact speed: this quantile of the pilot's normal impact speeds
DESIGN_QUANTILE = 0.999
#: largest contact time as a fraction of the free-flight time between impacts (binary,
#: instantaneous collisions: the hard-particle limit the soft run should stay near). Measured
#: (docs/accuracy-cost.md): Malik's Poiseuille error ≈ 2.1 (t_c/τ_flight)^1.26 + 0.015, i.e.
#: 8.6 % at 0.05 and 2.4 % at 0.018; ν and u_x of Campbell's Couette cell ~2 % at 0.018
TARGET_CONTACT_RATIO = 0.02


#: Largest normal impact speed in simple shear, in γ̇ d: the largest overlaps measured in 3D
#: Lees–Edwards shear at φ = 0.3 (docs/accuracy-cost.md: 0.067, 0.031, 0.0053 d at k* = 1e3,
#: 1e4, 1e5) are those of impacts at ≈ 4–5 γ̇ d, whatever the box height.
SHEAR_IMPACT_SPEED = 5.0


def reference_speed(scene: Scene) -> float:
    """Typical impact speed: √(g H) under gravity (H = particle-bed height or box), the wall
    speed in Couette flow, γ̇ min(Ly/2, SHEAR_IMPACT_SPEED d) under shear (the mean flow
    across the box grows with it, neighbours meet at a few γ̇ d: the pilot measured a q0.999
    impact speed of 6.6 γ̇ d in the 56 d 2D preset, where γ̇ Ly/2 = 28), √T for a free gas;
    never below 1e-3."""
    speeds = [abs(w.velocity) for w in scene.walls]
    if scene.gravity is not None:
        height = scene.box.size[1]
        if scene.initial.placement == "lattice":
            height = scene.initial.rows * scene.initial.spacing
        speeds.append(math.sqrt(scene.gravity.magnitude * min(height, 50.0)))
    if scene.shear is not None:
        speeds.append(scene.shear.rate * min(scene.box.size[1] / 2, SHEAR_IMPACT_SPEED))
    v = scene.initial.velocity
    speeds += [abs(v.scale), math.sqrt(v.temperature)]
    return max(max(speeds), 1e-3)


@dataclass(frozen=True)
class ContactSetup:
    """The soft contacts of a scene and how k_n was chosen: ``basis`` is "stiffness" or
    "hardness" (given), "pilot" (measured impacts) or "estimate" (guessed reference speed);
    ``speed``: the design impact speed (the largest of pair and wall; NaN when k_n was
    given); ``pilot``: the pilot's result when one was passed."""

    pair: mapping.ContactParameters
    walls: dict[str, mapping.ContactParameters]
    timestep: float
    kn: float
    basis: str = "stiffness"
    speed: float = math.nan
    pilot: PilotResult | None = field(default=None, compare=False)

    @property
    def steps_per_contact(self) -> float:
        return self.pair.contact_time / self.timestep

    def note(self) -> str:
        """One line: how k_n and dt were chosen (the deck's comment, the run's start)."""
        why = {"stiffness": "soft.stiffness", "hardness": "soft.hardness",
               "pilot": f"overlap ≤ {TARGET_OVERLAP:g} d at the q{DESIGN_QUANTILE:g} "
                        f"impact speed {self.speed:.4g}, t_c/τ_flight ≤ "
                        f"{TARGET_CONTACT_RATIO:g}",
               "estimate": f"overlap {DEFAULT_OVERLAP:g} d at the guessed "
                           f"reference speed {self.speed:.4g} (no pilot)"}[self.basis]
        return (f"k_n = {self.kn:.6g}, dt = {self.timestep:.6g}, t_c = "
                f"{self.pair.contact_time:.6g} (stiffness_basis = {self.basis}: {why})")

    def attrs(self) -> dict:
        """Root attributes of a soft run's results file."""
        out = {"stiffness_basis": self.basis, "kn": self.kn, "timestep": self.timestep,
               "contact_time": self.pair.contact_time,
               "steps_per_contact": self.steps_per_contact, "design_speed": self.speed,
               "contact_settings": self.note()}
        if self.pilot is not None:
            out["pilot"] = self.pilot.to_json()
            out["pilot_summary"] = self.pilot.summary()
        return out


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
    return _kn_for_overlap(soft.model, overlap, speed, m_eff, 0.25, e)


def estimated_overlap(scene: Scene) -> float:
    """Largest overlap (in d) of a head-on impact at the scene's impact speed
    (:func:`reference_speed`; a hardness target's ``impact_speed`` if higher), over the pair
    contact (m_eff = m/2) and every wall's (m_eff = m); NaN when the stiffness is defined only
    by a pilot or by nothing an engine accepts (hardness k* without shear, κ for Hertz)."""
    e, model = scene.contact.restitution, scene.soft.model
    speed = reference_speed(scene)
    h = scene.soft.hardness
    if h is not None and h.impact_speed is not None:
        speed = max(speed, h.impact_speed)
    try:
        kn = choose_stiffness(scene, e, 0.5)
    except UnsupportedByEngine:
        return math.nan
    cases = [(e, 0.5, 0.25)] + [(w.restitution, 1.0, 0.5) for w in scene.walls]
    if model == "hertz":
        return max(mapping.hertz_contact(kn, e_, m, r, speed).max_overlap for e_, m, r in cases)
    return max(mapping.hooke_max_overlap(kn, e_, m, speed) for e_, m, _ in cases)


#: Range of the estimated head-on overlap (in d) a given stiffness or hardness may give.
#: Above half a diameter a "collision" lets the particles pass through each other: no hard
#: particle is modelled, and the restitution compensation's model collision never ends
#: (k_n = 1e-6 and an impact_speed of 1e-6 ended in RuntimeError tracebacks). Below 1e-12 d
#: the overlap is lost in double-precision positions (1e-16 relative: 1e-13 d in a box of
#: 10³ d; the model collision never touched from 1e-15 d on, k_n = 1e30 in a unit-speed gas).
OVERLAP_RANGE = (1e-12, 0.5)


def stiffness_problem(scene: Scene) -> str | None:
    """Why the scene's given stiffness or hardness target cannot model hard particles (its
    estimated overlap, :func:`estimated_overlap`, outside ``OVERLAP_RANGE``), naming the
    field; None when it can or when nothing fixes k_n before a run (a pilot)."""
    try:
        overlap = estimated_overlap(scene)
    except (ZeroDivisionError, OverflowError):  # k_n underflowed to 0 (k* at γ̇ = 5e-324)
        overlap = math.inf
    low, high = OVERLAP_RANGE
    if math.isnan(overlap):
        return None  # the stiffness is not defined by the scene alone
    if low <= overlap < high:
        return None
    soft = scene.soft
    field, value = (("soft.stiffness", f"{soft.stiffness:g}") if soft.stiffness is not None
                    else ("soft.hardness", soft.hardness.model_dump(exclude_none=True)))
    what = ("so soft that the particles would pass through each other" if overlap >= high
            else "so stiff that the overlap is lost in double-precision positions")
    if soft.hardness is not None and soft.hardness.k_star is not None and scene.shear:
        what += f" (k_n = k* γ̇² d with shear.rate = {scene.shear.rate:g})"
    return (f"{field} = {value}: contacts {what} (estimated head-on overlap {overlap:.3g} d "
            f"at the impact speed {reference_speed(scene):.3g}); allowed: a stiffness giving "
            f"an overlap between {low:g} d and {high:g} d (hard particles: about 0.001-0.01 d)")


def overlap_warning(scene: Scene) -> str | None:
    """A warning when the scene's contacts are so soft that the overlap at its reference
    speed exceeds the health limit LIMITS['max_overlap'] (the run would be valid but far
    from hard particles, and its health group flags it); None otherwise."""
    from .health import LIMITS  # health imports this module's neighbours; keep it lazy

    overlap, limit = estimated_overlap(scene), LIMITS["max_overlap"]
    if not overlap > limit:  # NaN: nothing to estimate
        return None
    soft = scene.soft
    given = (f"soft.stiffness = {soft.stiffness:g}" if soft.stiffness is not None else
             f"soft.hardness = {soft.hardness.model_dump(exclude_none=True)}"
             if soft.hardness is not None else "the default stiffness")
    return (f"{given}: contacts this soft overlap by about {overlap:.3g} d at the estimated "
            f"impact speed {reference_speed(scene):.3g}, above the health limit {limit:g} d "
            "(results group 'health' will flag max_overlap); raise the stiffness or set "
            "soft.hardness.overlap")


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


def _kn_for_overlap(model: str, overlap: float, speed: float, m_eff: float, r_eff: float,
                    e: float) -> float:
    """k_n whose largest overlap at the impact ``speed`` is ``overlap`` (Hertz: for contact
    radius ``r_eff``; Hooke needs none)."""
    if model == "hertz":
        return mapping.hertz_kn_for_overlap(overlap, speed, m_eff, r_eff, e)
    return mapping.hooke_kn_for_overlap(overlap, speed, m_eff, e)


def pilot_stiffness(scene: Scene, pilot: PilotResult) -> tuple[float, float]:
    """(k_n, design speed) from a usable pilot: the stiffest of (a) the pair contact
    (m_eff = m/2) and every wall's (m_eff = m) overlapping TARGET_OVERLAP at their
    DESIGN_QUANTILE impact speed, (b) the contact time TARGET_CONTACT_RATIO × τ_flight."""
    model = scene.soft.model
    v_pair = pilot.speed("pair", DESIGN_QUANTILE)
    v_wall = pilot.speed("wall", DESIGN_QUANTILE)
    speed = max(v_pair, v_wall if scene.walls else 0.0)
    kn = _kn_for_overlap(model, TARGET_OVERLAP, v_pair, 0.5, 0.25, scene.contact.restitution)
    for w in scene.walls:
        kn = max(kn, _kn_for_overlap(model, TARGET_OVERLAP, v_wall, 1.0, 0.5, w.restitution))
    if math.isfinite(pilot.tau_flight):
        # t_c ∝ k_n^(-1/2) (Hooke) or k_n^(-2/5) (Hertz, at fixed speed): scale up to the target
        tc = shortest_contact_time(scene, kn, speed)
        target = TARGET_CONTACT_RATIO * pilot.tau_flight
        if tc > target:
            kn *= (tc / target) ** (2.0 if model == "hooke" else 2.5)
    return kn, speed


def contact_setup(scene: Scene, engine: str = "soft contacts",
                  pilot: PilotResult | None = None) -> ContactSetup:
    """Pair (m_eff = m/2) and per-wall (m_eff = m) contacts with a common time step;
    ``engine`` names the soft-contact engine in refusals (a hardness target that defines no
    stiffness for the contact model). Deterministic and cheap: a pilot is used only when
    passed (``pilot``) and k_n is not given; without one an automatic k_n is an estimate."""
    K, e, model = scene.inertia_k, scene.contact.restitution, scene.soft.model
    soft = scene.soft
    speed = reference_speed(scene)
    basis = "stiffness" if soft.stiffness is not None else \
        "hardness" if soft.hardness is not None else "estimate"
    if basis == "estimate" and pilot is not None and pilot.usable and \
            max(pilot.speed("pair", DESIGN_QUANTILE), pilot.speed("wall", DESIGN_QUANTILE)) > 0:
        basis = "pilot"
        kn, speed = pilot_stiffness(scene, pilot)
    else:
        kn = choose_stiffness(scene, e, 0.5, engine)
    if soft.hardness is not None and soft.hardness.impact_speed is not None:
        speed = max(speed, soft.hardness.impact_speed)  # Hertz t_c shrinks with speed
    dt = mapping.timestep(shortest_contact_time(scene, kn, speed), scene.soft.steps_per_contact)
    extra = {"r_eff": 0.25, "speed": speed} if model == "hertz" else {}
    # each contact's k_t is compensated for its own steps per contact (t_c / dt: a wall's
    # contact, m_eff = m, lasts √2 × longer than a pair's)
    pair = mapping.make_contact(kn=kn, e=e, m_eff=0.5, K=K, model=model,
                                **_rule(scene.contact.tangential, engine, e, model, "contact"),
                                steps_per_contact=_steps(model, kn, e, 0.5, 0.25, speed, dt),
                                **extra)
    walls = {w.side: _wall_contact(w, kn, K, model, speed, engine, dt) for w in scene.walls}
    shown = speed if basis in ("pilot", "estimate") else math.nan
    return ContactSetup(pair, walls, dt, kn, basis, shown, pilot)


def _steps(model: str, kn: float, e: float, m_eff: float, r_eff: float, speed: float,
           dt: float) -> float:
    """Steps per contact t_c / dt of one contact (Hertz: at the design speed)."""
    if model == "hertz":
        return mapping.hertz_contact(kn, e, m_eff, r_eff, speed).contact_time / dt
    return mapping.hooke_contact(kn, e, m_eff).contact_time / dt


def _wall_contact(wall: Wall, kn: float, K: float, model: str, speed: float, engine: str,
                  dt: float):
    extra = {"r_eff": 0.5, "speed": speed} if model == "hertz" else {}
    return mapping.make_contact(kn=kn, e=wall.restitution, m_eff=1.0, K=K, model=model,
                                **_rule(wall.tangential, engine, wall.restitution, model, "walls"),
                                steps_per_contact=_steps(model, kn, wall.restitution, 1.0, 0.5,
                                                         speed, dt),
                                wall=True, **extra)
