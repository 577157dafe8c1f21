"""The scene: one TOML file describing a granular flow, validated before any engine starts.

Dimensionless particle units everywhere: diameter d = 1, mass m = 1, and g = 1 when gravity
acts; otherwise a wall speed or the shear rate sets the time scale. Axes: x is the flow
direction (always periodic), y the wall-normal direction (walls, if any, are planes normal to
y; profiles are taken along y), z the spanwise direction (3D only, always periodic).

Every section is optional except ``dimension``, ``box``, ``particles`` and ``run``; an effect
that is absent from the scene (gravity, walls, shear, rotation) is absent from the simulation.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import Field, model_validator

from .base import Bool, Float, Int, PosFloat, PosInt, StrictModel

Axis = Literal["x", "y", "z"]
AXES: tuple[Axis, ...] = ("x", "y", "z")

#: Densest packings (used to reject impossible solid fractions).
MAX_PACKING = {2: math.pi / (2 * math.sqrt(3)), 3: math.pi / (3 * math.sqrt(2))}
#: Reduced inertia K = 4 I / (m d^2) of the named shapes.
INERTIA_K = {"disc": 0.5, "sphere": 0.4, "shell": 2.0 / 3.0, "point": 0.0}
# Bounds that keep the decks finite (a 1e300 speed or a 5e-324 interval validated and then
# overflowed, or ran as nonsense). In particle units the time unit is √(d/g), d/U or 1/γ̇, so
# speeds are O(1)–O(100): 1e6 leaves ample room. A sample interval below 1e-9 time units is
# below any contact time; more than 1e9 samples per run would not fit in memory anyway.
#: Largest speed (walls, impacts, initial flow) and shear rate, in particle units.
MAX_SPEED = 1e6
#: Slowest design impact speed of a hardness target: k_n ∝ v², so 5e-324 gave k_n = 0 (a
#: division by zero); particle speeds are O(1), and 1e-6 still gives a finite k_n.
MIN_SPEED = 1e-6
#: Smallest normal restitution: the soft engines' damping for e is found by root search over
#: model collisions, which fails below ~1e-100 (e = 5e-324 ended in "math domain error");
#: measured restitutions are ≥ 0.1, so 1e-6 loses nothing.
MIN_RESTITUTION = 1e-6
#: Shortest sample, checkpoint and servo interval, in time units.
MIN_INTERVAL = 1e-9
#: Most samples per run ((equilibration + production) / sample_interval).
MAX_SAMPLES = 1e9


class Meta(StrictModel):
    name: str = "scene"
    description: str = ""
    reference: str = ""


class Box(StrictModel):
    """Periodic box. ``size`` = [Lx, Ly] (2D) or [Lx, Ly, Lz] (3D) in particle diameters.

    x (and z in 3D) are always periodic. y is periodic when listed in ``periodic``; otherwise
    it is bounded by the walls of the scene, and a side without a wall is open (particles may
    leave it upwards, e.g. the free surface of a chute flow; its extent grows as needed).
    """

    size: list[Annotated[Float, Field(gt=0.0, lt=1e7)]] = Field(min_length=2, max_length=3)
    periodic: list[Axis] | None = None

    @model_validator(mode="after")
    def _x_periodic(self) -> Box:
        if self.periodic is None:
            return self
        if "x" not in self.periodic:
            raise ValueError(
                f"periodic = {self.periodic}: x (the flow direction) must be periodic; "
                "walls are only supported normal to y"
            )
        if len(set(self.periodic)) != len(self.periodic):
            raise ValueError(f"periodic = {self.periodic}: an axis is listed twice")
        return self


class Smooth(StrictModel):
    """No tangential force: spins and tangential velocities are never changed (β = −1)."""

    model: Literal["smooth"]

    @property
    def beta(self) -> float:
        return -1.0


class ConstantBeta(StrictModel):
    """Constant tangential restitution β of Lun / Malik (β = 0: Campbell's fully rough rule)."""

    model: Literal["beta"]
    beta: Float = Field(ge=-1.0, le=1.0)


class Rough(StrictModel):
    """Campbell's "rough" rule: contact points stick after the collision (β = 0)."""

    model: Literal["rough"]

    @property
    def beta(self) -> float:
        return 0.0


class Coulomb(StrictModel):
    """Walton's model: Coulomb friction μ with sticking tangential restitution β₀."""

    model: Literal["coulomb"]
    mu: Float = Field(ge=0.0, le=1e3)
    beta0: Float | None = Field(
        default=None, ge=-1.0, le=1.0,
        description="sticking tangential restitution; unset = the contact's normal restitution "
                    "e (per collision for velocity-dependent e): a tangential compliance that "
                    "dissipates like the normal one, e = 1 the elastic limit, and the only β₀ a "
                    "soft Coulomb-capped spring reproduces exactly (docs/contact.md)")


class NoSlip(StrictModel):
    """Campbell's "no-slip" wall: the centre takes the wall's tangential velocity; the spin is
    unchanged."""

    model: Literal["campbell-noslip"]


Tangential = Annotated[Smooth | ConstantBeta | Rough | Coulomb, Field(discriminator="model")]
WallTangential = Annotated[
    Smooth | ConstantBeta | Rough | Coulomb | NoSlip, Field(discriminator="model")
]


class RestitutionLaw(StrictModel):
    """Normal restitution: constant, or a velocity-dependent law (declared option).

    ``campbell-exp``: e(v) = ½[1 + exp(−3 v / sqrt(g R))] (Campbell 1982, reconstructed reading);
    ``gutt-piecewise``: c_r = e1 c_b + e2 (c − c_b) above the crossover speed c_b, e1 below.
    """

    model: Literal["constant", "campbell-exp", "gutt-piecewise"] = "constant"
    e1: Float | None = Field(default=None, ge=0.0, le=1.0)
    e2: Float | None = Field(default=None, ge=0.0, le=1.0)
    crossover_speed: Float | None = Field(default=None, gt=0.0)

    @model_validator(mode="after")
    def _gutt_needs_parameters(self) -> RestitutionLaw:
        if self.model == "gutt-piecewise" and None in (self.e1, self.e2, self.crossover_speed):
            raise ValueError("model = 'gutt-piecewise' needs e1, e2 and crossover_speed")
        return self


class Contact(StrictModel):
    """Particle–particle collisions: normal restitution e and a tangential rule."""

    restitution: Float = Field(ge=MIN_RESTITUTION, le=1.0)
    law: RestitutionLaw = RestitutionLaw()
    tangential: Tangential = Smooth(model="smooth")


class Particles(StrictModel):
    """Particles of diameter d = 1 (the length unit) and mass m = 1 (the mass unit).

    Give ``count`` or ``solid_fraction`` (of the box, or of the lattice for lattice starts).
    ``inertia`` is a shape name (disc: K = 1/2, sphere: 2/5, shell: 2/3, point: 0) or the
    reduced moment of inertia K = 4 I / (m d²) itself; default: disc in 2D, sphere in 3D.
    ``diameter_spread`` > 0 makes the diameters uniform in [1 − s/2, 1 + s/2] (mass ∝ volume).
    """

    count: PosInt | None = None
    solid_fraction: Float | None = Field(default=None, gt=0.0, lt=1.0)
    inertia: (
        Literal["disc", "sphere", "shell", "point"] | Annotated[Float, Field(ge=0, le=1)] | None
    ) = None
    diameter_spread: Float = Field(default=0.0, ge=0.0, lt=0.5)

    @model_validator(mode="after")
    def _one_of_count_or_fraction(self) -> Particles:
        if self.count is not None and self.solid_fraction is not None:
            raise ValueError("give either count or solid_fraction, not both")
        return self


class Bumps(StrictModel):
    """A bumpy wall: a row (2D) or square grid (3D) of fixed particles on the wall plane."""

    spacing: PosFloat = 1.0
    diameter: PosFloat = 1.0
    pattern: Literal["regular", "random"] = "regular"


class Servo(StrictModel):
    """Campbell's normal-stress control: walls move normal to the flow so that the measured
    wall stress matches ``normal_stress`` (force per area in 3D, per length in 2D).

    Every update (``interval_collisions`` × N collisions for event-driven engines,
    ``interval_time`` for time-stepped ones) each servo wall's normal velocity becomes
    v ← ½ v ± gain · clamp(σ_measured − σ_n, −σ_n, σ_n) (outwards when pushed harder than
    σ_n), Campbell's relaxation rule; his unit gain (lengths in radii) is gain = 0.25 in
    particle units (stress in m v²/d² per unit length in 2D). ``scale_width`` keeps
    the periodic width proportional to the gap; ``hold_shear_rate`` scales the upper wall's
    speed with the gap so that (u_upper − u_lower)/gap stays constant.

    ``interval_unit``: what event-driven engines count between updates — ``collisions``
    (Campbell: every ``interval_collisions`` × N pair collisions) or ``time`` (every
    ``interval_time``, as time-stepped engines always do). Counting collisions makes the rule
    equalise the mean stress *per interval*; intervals are short when the cell is dense and
    stressed, so the time-mean wall stress differs from σ_n; with ``time`` intervals,
    ``clamp = false`` and a gain ∝ 1/σ_n (≈ 1e-3/σ_n) the time-mean wall stress converges to
    σ_n (to 0.1 % ± 2 % at 10× Campbell's stress in the event-driven engine).

    ``clamp = false`` drops Campbell's clamp (v ← ½ v ± gain · (σ_measured − σ_n)): the
    clamp cuts the high tail of the interval stress, whose distribution is skewed when an
    interval holds few wall collisions, so with it the servo settles where the *clamped*
    excess averages to zero and the mean wall stress exceeds σ_n (by 1.1–2× in Campbell's
    Couette input); without it the mean stress itself converges to σ_n.
    """

    normal_stress: PosFloat
    interval_collisions: PosFloat = 3.0
    interval_time: Float | None = Field(default=None, ge=MIN_INTERVAL, le=1e9)
    gain: PosFloat = 0.25
    scale_width: Bool = True
    hold_shear_rate: Bool = True
    clamp: Bool = True
    interval_unit: Literal["collisions", "time"] = "collisions"

    @model_validator(mode="after")
    def _time_needs_interval_time(self) -> Servo:
        if self.interval_unit == "time" and self.interval_time is None:
            raise ValueError("interval_unit = 'time' needs interval_time")
        return self


class Wall(StrictModel):
    """A flat (or bumpy) plane normal to y, at the lower or upper side of the box."""

    side: Literal["lower", "upper"]
    position: Float | None = None
    kind: Literal["flat", "bumpy"] = "flat"
    restitution: Float = Field(ge=MIN_RESTITUTION, le=1.0)
    tangential: WallTangential = Smooth(model="smooth")
    velocity: Float = Field(default=0.0, ge=-MAX_SPEED, le=MAX_SPEED)
    servo: Servo | None = None
    bumps: Bumps | None = None

    @model_validator(mode="after")
    def _bumps_iff_bumpy(self) -> Wall:
        if (self.kind == "bumpy") != (self.bumps is not None):
            raise ValueError(f"kind = {self.kind!r}: a [walls.bumps] table is needed exactly "
                             "when kind = 'bumpy'")
        return self


class Gravity(StrictModel):
    """Body force of magnitude g (= 1 in particle units when present).

    ``angle``: chute inclination α in degrees, gravity = g (sin α, −cos α[, 0]) in chute axes
    (x downslope, y normal to the base). ``direction``: an explicit vector (normalised), e.g.
    [1, 0, 0] for Poiseuille flow between vertical walls.
    """

    magnitude: Float = Field(default=1.0, gt=0.0, le=MAX_SPEED)
    angle: Float | None = Field(default=None, ge=-90.0, le=90.0)
    direction: list[Float] | None = Field(default=None, min_length=2, max_length=3)

    @model_validator(mode="after")
    def _angle_or_direction(self) -> Gravity:
        if (self.angle is None) == (self.direction is None):
            raise ValueError("give exactly one of angle (chute, degrees) or direction (vector)")
        if self.direction is not None:
            norm = math.sqrt(sum(c * c for c in self.direction))
            if not math.isfinite(norm) or norm == 0.0:
                raise ValueError(f"direction = {self.direction}: must be a non-zero vector")
        return self


class Shear(StrictModel):
    """Lees–Edwards simple shear: u = rate · y, y periodic with sliding images."""

    rate: Float = Field(gt=0.0, le=MAX_SPEED)


class VelocityInit(StrictModel):
    """Initial velocities: a mean profile along y, a relative random perturbation and/or a
    temperature (Gaussian translational and rotational velocities, T per degree of freedom).

    ``campbell-chute``: u = F(y/H)·scale (Campbell's 7th-order fit, 20 % wall slip);
    ``linear``: u from the lower wall's speed to the upper wall's (or rate·y with shear);
    ``uniform``: u = scale.
    """

    profile: Literal["none", "uniform", "linear", "campbell-chute"] = "none"
    scale: Float = Field(default=0.0, ge=-MAX_SPEED, le=MAX_SPEED)
    perturbation: Float = Field(default=0.0, ge=0.0)
    temperature: Float = Field(default=0.0, ge=0.0, le=MAX_SPEED**2)  # speed²


class Initial(StrictModel):
    """Initial configuration.

    ``lattice``: Campbell's jittered square (cubic) lattice of ``rows`` along y, ``columns``
    along x (and ``layers`` along z) with centre spacing ``spacing`` (> 1), each centre moved
    at random by at most the gap (spacing − 1)/2 (``jitter = false`` disables that).
    ``random``: random non-overlapping placement at the particles' count or solid fraction:
    random sequential addition when dilute, a fluid grown from a dilute state (Lubachevsky–
    Stillinger, :mod:`demstudy.scene.fluid_start`) when dense, never a crystal unless the
    growth jams (then a lattice subset, with a warning).
    ``file``: positions (and optionally velocities) from a text file with columns
    x y [z] [vx vy [vz]] (a relative ``path`` is relative to the working directory). The
    scene's validation checks the file (:mod:`demstudy.scene.particle_file`): it parses,
    has one row per particle (``particles.count``, if given, must match; otherwise the rows
    are the count), finite values, centres inside the periodic box and a radius from walls,
    and no overlaps (tolerance 1e-9 d).
    """

    placement: Literal["lattice", "random", "file"] = "random"
    rows: PosInt | None = None
    columns: PosInt | None = None
    layers: PosInt | None = None
    spacing: Float | None = Field(default=None, gt=1.0)
    jitter: Bool = True
    path: str | None = None
    velocity: VelocityInit = VelocityInit()

    @model_validator(mode="after")
    def _placement_fields(self) -> Initial:
        if self.placement == "lattice" and None in (self.rows, self.columns, self.spacing):
            raise ValueError("placement = 'lattice' needs rows, columns and spacing")
        if self.placement == "file" and not self.path:
            raise ValueError("placement = 'file' needs path")
        return self


class Run(StrictModel):
    """Run control, in time units (or collisions per particle with ``unit = 'collisions'``,
    or whole lattice steps with ``unit = 'steps'``: lattice scenes only, docs/lgd-engine.md)."""

    equilibration: Float = Field(ge=0.0, le=1e12)
    production: Float = Field(gt=0.0, le=1e12)
    sample_interval: Float = Field(default=1.0, ge=MIN_INTERVAL)
    seed: Int = Field(default=12345, ge=1, lt=2**31)
    unit: Literal["time", "collisions", "steps"] = "time"
    checkpoint_interval: Float | None = Field(default=None, ge=MIN_INTERVAL)



class Hardness(StrictModel):
    """Stiffness chosen by a hardness target (one of them)."""

    overlap: Float | None = Field(default=None, ge=1e-6, lt=0.5)
    impact_speed: Float | None = Field(default=None, ge=MIN_SPEED, le=MAX_SPEED)
    k_star: Float | None = Field(default=None, gt=0.0)
    kappa: Float | None = Field(default=None, gt=0.0)
    pressure: Float | None = Field(default=None, gt=0.0)

    @model_validator(mode="after")
    def _one_target(self) -> Hardness:
        targets = [self.overlap is not None, self.k_star is not None, self.kappa is not None]
        if sum(targets) != 1:
            raise ValueError("give exactly one of overlap (with impact_speed), k_star, kappa")
        if self.overlap is not None and self.impact_speed is None:
            raise ValueError("overlap needs impact_speed (the speed at which δ/d is reached)")
        if self.kappa is not None and self.pressure is None:
            raise ValueError("kappa = k/(P d) needs pressure P")
        return self


class Soft(StrictModel):
    """Soft-contact numerics (ignored by hard-particle engines)."""

    model: Literal["hooke", "hertz"] = "hooke"
    stiffness: PosFloat | None = None
    hardness: Hardness | None = None
    steps_per_contact: Float = Field(default=50.0, ge=10.0, le=1e4)

    @model_validator(mode="after")
    def _stiffness_or_hardness(self) -> Soft:
        if self.stiffness is not None and self.hardness is not None:
            raise ValueError("give stiffness or hardness, not both")
        return self


class Measure(StrictModel):
    """What to measure: profiles along ``axis`` in bins of ``bin_width`` diameters, and the
    ``statistics`` registered in :mod:`demstudy.analysis.registry` (``demstudy analyze
    --help`` lists them). Each named statistic ends in the results file: the run feeds it,
    or keeps the frames or the collision log it needs; one the scene or the engine cannot
    supply is refused before anything runs. ``keep_frames`` stores every production frame."""

    axis: Axis = "y"
    bin_width: PosFloat = 1.0
    statistics: list[str] = ["profiles"]
    keep_frames: Bool = False
