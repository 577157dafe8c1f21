"""The runs of a cost ladder: the event-driven reference (and its t_c ladder) and the soft
runs over stiffness, steps per contact and contact model, each with a file name that encodes
its settings (so a rerun finds what is done).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise the shear rate
or the wall speed sets the time unit).

Stiffness axis, per scene (``stiffness_scale``): with a shear rate γ̇, k* = k_n/(ρ d³ γ̇²)
(ρ d³ = 4m/π for discs, 6m/π for spheres: ``contact.mapping.mass_scale``); under gravity,
k* = k_n/(m g/d); otherwise k* = k_n/(m v²/d²) with v the scene's reference speed (the wall
speed of a Couette cell). k* gives the Hooke k_n; the Hertz run of the same k* has the Hertz
k_n that reaches the same largest overlap at the reference impact speed.

Replicas (``--replicas R``): every run is made R times with seeds seed, seed + 1, …, its file
name ending in ``-r0``, ``-r1``, …; the ladder then rates the settings by the replicas' mean,
with errors from their scatter (``demstudy.comparison.combine_replicas``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

from ..contact import mapping
from ..contact.stiffness import reference_speed
from ..scene import Scene, scene_to_toml
from ..scene.schema import Soft

#: t_c ladder of the event-driven reference, as factors of its default t_c (tried when the
#: TC model made collisions elastic: dense or collapsing flows)
TC_FACTORS = (1.0, 0.1, 0.01)


@dataclass(frozen=True)
class StiffnessScale:
    """k_n = value × ``unit``; ``definition`` says which dimensionless stiffness it is."""

    definition: str
    unit: float
    label: str = "$k^*$"  # for figures (mathtext)


def stiffness_scale(scene: Scene) -> StiffnessScale:
    """The dimensionless stiffness of this scene (module doc): shear rate, gravity, or the
    reference speed, in that order."""
    if scene.shear is not None:
        return StiffnessScale("k* = k_n/(rho d^3 gamma_dot^2)",
                              mapping.mass_scale(1.0, scene.dimension) * scene.shear.rate**2,
                              r"$k^* = k_n/(\rho d^3 \dot\gamma^2)$")
    if scene.gravity is not None:
        return StiffnessScale("k* = k_n/(m g/d)", float(scene.gravity.magnitude),
                              r"$k^* = k_n/(m g/d)$")
    v = reference_speed(scene)
    return StiffnessScale(f"k* = k_n/(m v^2/d^2), v = {v:.3g} (reference speed)", v * v,
                          r"$k^* = k_n/(m v^2/d^2)$")


@dataclass(frozen=True)
class RunSpec:
    """One run of the ladder: the reference (``engine = 'edmd'``, ``tc``) or a soft run
    (``engine = 'lammps'`` or another soft engine, ``model``, ``kstar``, ``steps`` per
    contact); ``replica`` i of several: the scene's seed + i (``None``: the run alone, the
    scene's seed)."""

    engine: str
    model: str | None = None
    kstar: float | None = None
    steps: float | None = None
    tc: float | None = None
    replica: int | None = None

    @property
    def soft(self) -> bool:
        return self.engine != "edmd"

    @property
    def relative_cost(self) -> float:
        """A proxy of the run's wall time for ordering (not a forecast): soft runs take
        steps ∝ steps per contact × √k (Hooke t_c ∝ k^−1/2); the event-driven ones' cost
        does not depend on a stiffness and their t_c ladder costs more as t_c shrinks."""
        if self.soft:
            return float(self.steps or 1.0) * float(self.kstar or 1.0) ** 0.5
        return 1.0 / float(self.tc or 1.0) ** 0.25

    @property
    def name(self) -> str:
        """File stem encoding the settings, e.g. ``soft-hooke-k1e+04-s50``, ``ref-edmd-tc1e-05``,
        ``soft-hooke-k100-s10-r1`` (replica 1)."""
        return self.settings + ("" if self.replica is None else f"-r{self.replica}")

    @property
    def settings(self) -> str:
        """The name without the replica suffix: one row of the ladder."""
        if self.soft:
            # LAMMPS's runs keep their names from before other soft engines existed
            engine = "" if self.engine == "lammps" else f"{self.engine}-"
            return (f"soft-{engine}{self.model}-k{self.kstar:.3g}-s{self.steps:g}"
                    .replace("+0", "+"))
        return f"ref-{self.engine}-tc{self.tc:.3g}"

    def options(self) -> dict:
        """Engine options for ``ds.run``."""
        return {} if self.soft else {"tc": float(self.tc)}


def soft_kn(scene: Scene, model: str, kstar: float) -> float:
    """k_n of a soft run at ``kstar`` (module doc: Hertz matched on the largest overlap at
    the reference speed)."""
    kn = kstar * stiffness_scale(scene).unit
    if model == "hooke":
        return kn
    e, v = scene.contact.restitution, reference_speed(scene)
    overlap = mapping.hooke_max_overlap(kn, e, 0.5, v)
    return mapping.hertz_kn_for_overlap(overlap, v, 0.5, 0.25, e)


def scene_for(base: Scene, spec: RunSpec) -> Scene:
    """The scene ``spec`` runs: ``base`` with the soft section replaced (soft runs) and the
    seed moved on by the replica's index."""
    if spec.replica:
        run = base.run.model_copy(update={"seed": base.run.seed + spec.replica})
        base = base.model_copy(update={"run": run})
    if not spec.soft:
        return base
    soft = Soft(model=spec.model, stiffness=soft_kn(base, spec.model, spec.kstar),
                steps_per_contact=spec.steps)
    return base.model_copy(update={"soft": soft})


def replicate(specs: list[RunSpec], replicas: int) -> list[RunSpec]:
    """Each run ``replicas`` times (replica 0, 1, …); one replica: the runs themselves (the
    file names of a ladder without replicas)."""
    if replicas == 1:
        return list(specs)
    return [replace(s, replica=i) for s in specs for i in range(replicas)]


def soft_ladder(kstars: list[float], steps: list[float], models: list[str],
                engines: Sequence[str] = ("lammps",)) -> list[RunSpec]:
    """Every combination, in each soft engine, cheapest first (soft stiffness and steps
    raise the cost)."""
    return [RunSpec(e, m, k, s) for k in sorted(kstars) for s in sorted(steps)
            for m in models for e in engines]


def reference_ladder(default_tc: float) -> list[RunSpec]:
    """The reference's t_c ladder, largest t_c (the default) first."""
    return [RunSpec("edmd", tc=default_tc * f) for f in TC_FACTORS]


def scene_key(scene: Scene) -> str:
    """What a finished run's ``scene_toml`` attribute must equal for it to be reused."""
    return scene_to_toml(scene)
