"""The root scene model and its cross-field rules.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.
"""

from __future__ import annotations

import math
from typing import Literal

from pydantic import model_validator

from .base import StrictModel
from .lattice import ROW_HEIGHT, LatticeSpec, lattice_box, lattice_grains
from .schema import (
    INERTIA_K,
    MAX_PACKING,
    MAX_SAMPLES,
    Box,
    Contact,
    Gravity,
    Initial,
    Measure,
    Meta,
    Particles,
    Run,
    Shear,
    Soft,
    Wall,
)

#: Densest 'random' starts: above RSA's range they are grown as a fluid (Lubachevsky–
#: Stillinger, demstudy.scene.fluid_start), which jams not far above these fractions (and only
#: if it jams, a shuffled lattice is used; see demstudy.scene.initial).
RANDOM_PLACEMENT_LIMIT = {2: 0.80, 3: 0.60}


class Scene(StrictModel):
    """A complete, validated scene (see demstudy.scene.schema for every section)."""

    meta: Meta = Meta()
    dimension: Literal[2, 3]
    box: Box
    particles: Particles
    contact: Contact
    walls: list[Wall] = []
    gravity: Gravity | None = None
    shear: Shear | None = None
    initial: Initial = Initial()
    run: Run
    soft: Soft = Soft()
    measure: Measure = Measure()
    lattice: LatticeSpec | None = None

    @model_validator(mode="before")
    @classmethod
    def _lattice_box(cls, data):
        """A lattice scene's box is its lattice: filled in when [box] is left out."""
        if isinstance(data, dict) and isinstance(data.get("lattice"), dict) \
                and "box" not in data:
            spec = data["lattice"]
            nxt, nyt = spec.get("nxt"), spec.get("nyt")
            if isinstance(nxt, int) and isinstance(nyt, int) and nxt > 0 and nyt > 1:
                data = {**data, "box": {"size": [float(nxt), (nyt - 1) * ROW_HEIGHT]}}
        return data

    # ---- derived quantities -------------------------------------------------------------
    @property
    def periodic(self) -> tuple[str, ...]:
        if self.box.periodic is not None:
            return tuple(self.box.periodic)
        axes = ["x"] if self.walls else ["x", "y"]
        return tuple(axes + (["z"] if self.dimension == 3 else []))

    @property
    def has_open_top(self) -> bool:
        """y is bounded but has no upper wall (a free surface)."""
        return bool(self.walls) and self.wall("upper") is None

    @property
    def y_periodic(self) -> bool:
        return "y" in self.periodic

    @property
    def inertia_k(self) -> float:
        """Reduced moment of inertia K = 4 I / (m d²)."""
        inertia = self.particles.inertia
        if inertia is None:
            return INERTIA_K["disc" if self.dimension == 2 else "sphere"]
        return INERTIA_K[inertia] if isinstance(inertia, str) else float(inertia)

    @property
    def box_volume(self) -> float:
        return math.prod(self.box.size)

    @property
    def particle_volume(self) -> float:
        """Volume (area in 2D) of one particle of diameter 1."""
        return math.pi / 4 if self.dimension == 2 else math.pi / 6

    @property
    def n_particles(self) -> int:
        p, init = self.particles, self.initial
        if self.lattice is not None:  # the movable grains of the initial lattice
            return lattice_grains(self.lattice, self.run.seed)[0]
        if init.placement == "lattice":
            layers = (init.layers or 1) if self.dimension == 3 else 1
            return init.rows * init.columns * layers
        if p.count is not None:
            return p.count
        if init.placement == "file":  # the file's rows (0 if it cannot be read: a problem)
            from .particle_file import file_count  # noqa: PLC0415 - it imports numpy

            return file_count(self)
        if p.solid_fraction is not None:
            return max(1, round(p.solid_fraction * self.box_volume / self.particle_volume))
        return 0

    @property
    def solid_fraction(self) -> float:
        return self.n_particles * self.particle_volume / self.box_volume

    def wall(self, side: str) -> Wall | None:
        for wall in self.walls:
            if wall.side == side:
                return wall
        return None

    def wall_position(self, side: str) -> float:
        wall = self.wall(side)
        if wall is not None and wall.position is not None:
            return wall.position
        return 0.0 if side == "lower" else self.box.size[1]

    def wall_surface(self, side: str) -> float:
        """Where particles meet the wall: its plane, or the tops of its bumps (random bumps
        stand up to a quarter diameter proud of the plane)."""
        wall = self.wall(side)
        y = self.wall_position(side)
        if wall is None or wall.bumps is None:
            return y
        reach = wall.bumps.diameter * (0.75 if wall.bumps.pattern == "random" else 0.5)
        return y + reach if side == "lower" else y - reach

    @property
    def gravity_vector(self) -> tuple[float, ...] | None:
        g = self.gravity
        if g is None:
            return None
        if g.angle is not None:
            a = math.radians(g.angle)
            vec = [math.sin(a), -math.cos(a)] + ([0.0] if self.dimension == 3 else [])
        else:
            norm = math.sqrt(sum(c * c for c in g.direction))
            vec = [c / norm for c in g.direction]
        return tuple(g.magnitude * c for c in vec)

    @property
    def rotation_matters(self) -> bool:
        """True when any contact can change a spin (a tangential rule other than smooth)."""
        rules = [self.contact.tangential] + [w.tangential for w in self.walls]
        return any(rule.model not in ("smooth", "campbell-noslip") for rule in rules)

    # ---- cross-field rules --------------------------------------------------------------
    @model_validator(mode="after")
    def _consistent(self) -> Scene:
        dim = self.dimension
        problems: list[str] = []
        if len(self.box.size) != dim:
            problems.append(
                f"box.size = {self.box.size}: needs {dim} lengths for dimension = {dim}"
            )
        periodic = self.box.periodic
        if periodic is not None:
            if dim == 2 and "z" in periodic:
                problems.append(f"box.periodic = {periodic}: 2D scenes have no z axis")
            if dim == 3 and "z" not in periodic:
                problems.append(f"box.periodic = {periodic}: z must be periodic in 3D")
            if "y" in periodic and self.walls:
                problems.append(f"box.periodic = {periodic}: y cannot be periodic with walls")
            if "y" not in periodic and not self.walls:
                problems.append(f"box.periodic = {periodic}: y is bounded but no wall is given")
        problems += self._wall_problems()
        if self.lattice is not None:
            problems += self._lattice_problems()
            if problems:
                raise ValueError("; ".join(problems))
        else:
            problems += self._particle_problems()
            if self.run.unit == "steps":
                problems.append("run.unit = 'steps': whole lattice steps exist only in "
                                "lattice scenes ([lattice], --engine lgd); allowed here: "
                                "'time' or 'collisions'")
        if self.shear is not None and (self.walls or not self.y_periodic):
            problems.append("shear: Lees–Edwards shear needs a y-periodic box without walls")
        g = self.gravity
        if g is not None and g.direction is not None and len(g.direction) != dim:
            problems.append(f"gravity.direction = {g.direction}: needs {dim} components")
        elif self.shear is not None and g is not None:
            problems += self._sheared_gravity_problems()
        if self.lattice is None:
            problems += self._initial_problems()
        from ..analysis.registry import scene_problems  # the statistics' own registry

        problems += scene_problems(self)
        if self.run.sample_interval > self.run.production:
            problems.append(
                f"run.sample_interval = {self.run.sample_interval}: longer than "
                f"run.production = {self.run.production}"
            )
        run = self.run
        samples = (run.equilibration + run.production) / run.sample_interval
        if samples > MAX_SAMPLES:  # the decks count steps and samples in machine integers
            problems.append(
                f"run.sample_interval = {run.sample_interval:g}: {samples:.3g} samples in "
                f"equilibration + production = {run.equilibration + run.production:g}; "
                f"allowed: at most {MAX_SAMPLES:g} samples per run"
            )
        if problems:
            raise ValueError("; ".join(problems))
        return self

    def _lattice_problems(self) -> list[str]:
        """A lattice scene: 2D, its box the lattice, both wall rows declared as walls at
        their places, grains from md lines only, whole steps with ``run.unit = 'steps'``."""
        spec, problems = self.lattice, []
        if self.dimension != 2:
            problems.append(f"dimension = {self.dimension}: a lattice scene is 2D (Gutt's "
                            "triangular lattice); allowed: 2")
        box = lattice_box(spec)
        if len(self.box.size) != 2 or any(abs(a - b) > 1e-9 * max(1.0, b)
                                          for a, b in zip(self.box.size, box, strict=False)):
            problems.append(f"box.size = {self.box.size}: a lattice scene's box is its lattice, "
                            f"[nxt, (nyt − 1)·√3/2] = [{box[0]:g}, {box[1]:.10g}]; leave [box] "
                            "out to have it filled in")
        sides = sorted(w.side for w in self.walls)
        if sides != ["lower", "upper"]:
            problems.append(f"walls: {sides}; a lattice scene needs both walls, lower and "
                            "upper: rows 1 and nyt are always wall rows (listing L1831–L1856)")
        for i, wall in enumerate(self.walls):
            want = 0.0 if wall.side == "lower" else box[1]
            if wall.position is not None and abs(wall.position - want) > 1e-9 * max(1, want):
                problems.append(f"walls[{i}].position = {wall.position:g}: the {wall.side} "
                                f"wall row of the lattice is at y = {want:.10g}; leave "
                                "position out")
        if self.initial != Initial():
            problems.append("initial: a lattice scene's grains come from lattice.initial / "
                            "lattice.initial_file (Gutt's md lines) / lattice.fill; leave "
                            "[initial] out")
        if self.particles.solid_fraction is not None:
            problems.append(f"particles.solid_fraction = {self.particles.solid_fraction:g}: "
                            "a lattice scene's grains come from its md lines; leave it out")
        try:
            count = lattice_grains(spec, self.run.seed)[0]
        except (ValueError, OSError) as exc:  # the initial-data file, or a fill
            if str(exc).startswith("lattice.fill["):
                return problems + [str(exc)]
            return problems + [f"lattice.initial_file = {spec.initial_file!r}: {exc}"]
        if count == 0:
            problems.append("lattice: the md lines place no movable grain")
        if self.particles.count is not None and self.particles.count != count:
            problems.append(f"particles.count = {self.particles.count}: the lattice's md "
                            f"lines place {count} movable grains")
        if self.run.unit == "steps":
            run = self.run
            for name in ("equilibration", "production", "sample_interval",
                         "checkpoint_interval"):
                value = getattr(run, name)
                if value is not None and value != int(value):
                    problems.append(f"run.{name} = {value:g}: with unit = 'steps' a whole "
                                    "number of steps is allowed")
            if run.sample_interval < 1:
                problems.append(f"run.sample_interval = {run.sample_interval:g}: with unit = "
                                "'steps' at least 1 step is allowed")
            elif not problems:
                # samples fall on whole intervals: a phase that is no multiple of the
                # interval would silently run a different number of steps
                for name in ("equilibration", "production"):
                    value = getattr(run, name)
                    if value % run.sample_interval:
                        problems.append(
                            f"run.{name} = {value:g}: with unit = 'steps' a multiple of "
                            f"run.sample_interval = {run.sample_interval:g} is allowed")
        return problems

    def _sheared_gravity_problems(self) -> list[str]:
        """Gravity with a y component under Lees–Edwards shear has no support: y is periodic
        with sliding images and there are no walls, so the bed falls through the images for
        ever; each net crossing shifts its x velocity by γ̇ Ly and the energy grows without
        bound. Gravity along x (or z) only accelerates the centre of mass, as in any
        wall-free periodic box, and is left alone."""
        g_y = self.gravity_vector[1]
        if abs(g_y) <= 1e-9 * self.gravity.magnitude:  # cos(90°) is 6e-17, not 0
            return []
        given = (f"gravity.angle = {self.gravity.angle:g}" if self.gravity.angle is not None
                 else f"gravity.direction = {list(self.gravity.direction)}")
        along_x = "[1, 0]" if self.dimension == 2 else "[1, 0, 0]"
        return [f"{given}: gravity has a y component ({g_y:.3g}) but Lees–Edwards shear makes "
                "y periodic with sliding images and allows no walls, so nothing supports the "
                "weight and the energy grows without bound; allowed with [shear]: gravity "
                f"along x (direction = {along_x}, or angle = ±90), or drop [shear] and bound y "
                "with walls"]

    def _wall_problems(self) -> list[str]:
        problems = []
        sides = [w.side for w in self.walls]
        for side in ("lower", "upper"):
            if sides.count(side) > 1:
                problems.append(f"walls: {sides.count(side)} walls with side = {side!r}; at most 1")
        if self.walls and self.wall("lower") is None:
            problems.append("walls: an upper wall needs a lower wall (the open side is the top)")
        if self.walls and len(self.box.size) > 1:
            ly = self.box.size[1]
            for i, wall in enumerate(self.walls):
                if wall.position is not None and not 0.0 <= wall.position <= ly:
                    problems.append(
                        f"walls[{i}].position = {wall.position:g}: outside the box; allowed "
                        f"0 <= position <= box.size[1] = {ly:g}"
                    )
            lo, hi = self.wall_position("lower"), self.wall_position("upper")
            if self.wall("upper") is not None and hi - lo < 2.0:
                problems.append(f"walls: gap {hi - lo:g} between lower and upper wall is < 2 d")
            elif self.wall("upper") is None and hi - lo < 2.0:
                problems.append(
                    f"walls: the lower wall at y = {lo:g} leaves {hi - lo:g} < 2 d below the "
                    f"top of the box (box.size[1] = {ly:g})"
                )
        for wall in self.walls:
            if wall.servo is not None and self.wall("upper") is None:
                problems.append("walls.servo: normal-stress control needs two walls")
        servos = [w.servo for w in self.walls if w.servo is not None]
        shared = ("interval_collisions", "interval_time", "scale_width", "hold_shear_rate")
        for key in shared:
            values = {getattr(s, key) for s in servos}
            if len(values) > 1:
                problems.append(f"walls.servo.{key}: servo walls update together and must "
                                f"share it (got {sorted(values, key=str)})")
        return problems

    def _particle_problems(self) -> list[str]:
        p, init, dim = self.particles, self.initial, self.dimension
        d_max = 1.0 + p.diameter_spread / 2
        problems = []
        if init.placement == "lattice" and init.spacing is not None and init.spacing <= d_max:
            problems.append(
                f"initial.spacing = {init.spacing:g}: must exceed the largest diameter "
                f"1 + particles.diameter_spread/2 = {d_max:g}"
            )
        if init.placement == "random" and p.count is None and p.solid_fraction is None:
            problems.append("particles: give count or solid_fraction for placement = 'random'")
        if init.placement == "lattice" and p.count is not None and p.count != self.n_particles:
            problems.append(
                f"particles.count = {p.count}: the lattice holds {self.n_particles} particles"
            )
        if len(self.box.size) == dim and self.n_particles > 0:
            phi = self.solid_fraction
            if phi >= MAX_PACKING[dim]:
                problems.append(
                    f"particles: solid fraction {phi:.4g} exceeds the densest packing "
                    f"{MAX_PACKING[dim]:.4f} in {dim}D"
                )
            elif init.placement == "random" and phi * d_max**dim > RANDOM_PLACEMENT_LIMIT[dim]:
                spread = (
                    f" (as if all had the largest diameter {d_max:g}: {phi * d_max**dim:.4g})"
                    if d_max > 1.0 else ""
                )
                problems.append(
                    f"particles: solid fraction {phi:.4g}{spread} is above "
                    f"{RANDOM_PLACEMENT_LIMIT[dim]} for placement = 'random'; use placement = "
                    "'lattice'" + (" or a smaller diameter_spread" if spread else "")
                )
            if self.n_particles > 50_000_000:
                problems.append(f"particles: {self.n_particles} particles is more than 5e7")
        return problems

    def _initial_problems(self) -> list[str]:
        init, dim = self.initial, self.dimension
        problems = []
        if init.placement == "lattice" and len(self.box.size) == dim:
            s = init.spacing
            if init.columns * s > self.box.size[0] + 1e-9:
                problems.append(
                    f"initial: columns × spacing = {init.columns * s:g} exceeds box.size[0] = "
                    f"{self.box.size[0]:g}"
                )
            if dim == 3 and (init.layers or 1) * s > self.box.size[2] + 1e-9:
                problems.append(
                    f"initial: layers × spacing = {(init.layers or 1) * s:g} exceeds "
                    f"box.size[2] = {self.box.size[2]:g}"
                )
            if dim == 2 and init.layers is not None:
                problems.append("initial.layers: 2D lattices have rows and columns only")
            top = self.wall_surface("lower") + init.rows * s
            if self.wall("upper") is not None and top > self.wall_surface("upper") + 1e-9:
                problems.append(f"initial: rows × spacing = {init.rows * s:g} exceeds the wall gap")
            if not self.walls and init.rows * s > self.box.size[1] + 1e-9:
                problems.append(
                    f"initial: rows × spacing = {init.rows * s:g} exceeds box.size[1] = "
                    f"{self.box.size[1]:g}"
                )
        if init.placement == "file" and init.path and len(self.box.size) == dim:
            from .particle_file import particle_file_problems  # noqa: PLC0415

            problems += particle_file_problems(self)
        v = init.velocity
        if v.profile == "campbell-chute" and (self.gravity is None or self.gravity.angle is None):
            problems.append("initial.velocity.profile = 'campbell-chute' needs gravity.angle")
        if v.profile == "linear" and self.shear is None and self.wall("upper") is None:
            problems.append("initial.velocity.profile = 'linear' needs two walls or shear")
        return problems
