"""The smallest engine backend: ballistic particles without contacts, in a periodic box.

Dimensionless particle units: d = 1, m = 1 (mass ∝ d^dim). It shows what a backend must
implement for the simulation loop (docs/engines.md) and checks that adding one touches
nothing else: tests/test_simulation.py registers it and runs scenes through the loop.
"""

from __future__ import annotations

import numpy as np

from demstudy.effects import EFFECTS, LATTICE_ONLY, Cannot, Translation
from demstudy.engines.backend import BackendBase, Capabilities, EngineOption
from demstudy.io.frames import Frame
from demstudy.scene.initial import build_initial_state

NO_FORCES = Cannot("ballistic particles feel no contacts, walls or forces")


class BallisticBackend(BackendBase):
    """x(t) = x0 + v t, wrapped into the box; nothing else ever happens."""

    name = "ballistic"
    kind = "ballistic"
    capabilities = Capabilities()
    translations = {name: NO_FORCES for name in EFFECTS} | {
        "lattice": LATTICE_ONLY,
        "planar": Translation(how="2D positions"),
        "rotation": Translation(how="spins never change: there are no contacts"),
    }
    version = "ballistic 1"

    def setup(self, needs, saved, servo) -> None:
        state = build_initial_state(self.scene)
        self.radius = state.diameter / 2
        self.mass = state.mass
        self.n_particles = len(self.mass)
        self.box = np.asarray(self.scene.box.size, float)
        self.x, self.v = state.position.copy(), state.velocity.copy()
        self.omega = state.angular_velocity.copy()
        self.t = 0.0
        if saved is not None:
            self.x, self.v, self.omega, self.t = (saved[k] for k in ("x", "v", "omega", "t"))

    @property
    def time(self) -> float:
        return self.t

    def advance(self, t: float, collisions: int = 0, stop=None) -> bool:
        self.x = np.mod(self.x + self.v * (t - self.t), self.box)
        self.t = t
        return True

    def frame(self) -> Frame:
        return Frame(time=self.t, box_lo=np.zeros(len(self.box)), box_hi=self.box.copy(),
                     position=self.x.copy(), velocity=self.v.copy(),
                     angular_velocity=self.omega.copy(), radius=self.radius)

    def observe(self, production: bool) -> dict:
        inertia = self.scene.inertia_k * self.mass * self.radius**2
        return {"momentum": (self.mass[:, None] * self.v).sum(axis=0),
                "kinetic_energy": 0.5 * float((self.mass[:, None] * self.v**2).sum()),
                "rotational_energy": 0.5 * float((inertia[:, None] * self.omega**2).sum())}

    def get_state(self) -> dict:
        return {"x": self.x.copy(), "v": self.v, "omega": self.omega, "t": self.t}


class CrashingBackend(BallisticBackend):
    """Segfaults on its first advance, as a bug in compiled code would (``crash=False``:
    it does not)."""

    name = "crashing"
    options = {"crash": EngineOption("crash", bool, "segfault on the first advance")}

    def advance(self, t: float, collisions: int = 0, stop=None) -> bool:
        if self.run_options.extra.get("crash", True):
            import ctypes

            ctypes.string_at(0)  # reads address 0: SIGSEGV
        return super().advance(t, collisions, stop)
