"""``--engine lgd``: Gutt's (1989) lattice grain dynamics as a backend of the simulation loop.

Units: everything it hands the loop is in demstudy's dimensionless particle units: d = 1 =
the lattice spacing, m = 1, and g = 1 when gravity acts (time unit √(d/g)); without gravity
the wall speed (``lattice.speed_scale``) or, with walls at rest, the grains' initial r.m.s.
speed is the speed unit V and d/V the time unit (:mod:`demstudy.engines.lgd.effects`; the
results file's attributes ``lgd_speed_unit``, ``lgd_ticks_per_time_unit`` and
``lgd_speed_unit_basis`` say which). The lattice itself runs in the listing's integers
(:mod:`demstudy.engines.lgd.lattice`).

Steps: each LGD step is as long as the fastest grain needs to cross one spacing (digest §3.5),
so steps have different lengths. ``run.unit = 'steps'`` counts whole steps (Gutt's results
are at step counts: 1024, 2048, 18432); with ``run.unit = 'time'`` a sample is taken at the
end of the first step that reaches the sample's time (at most one step late; the recorded
``time`` is the step's).

Per sample (``observe``): ``kinetic_energy`` ½ Σ v², ``momentum`` and ``mean_velocity``
(Σ v / N), ``thermal_velocity`` √(⟨v²⟩ − ⟨v⟩²) (the listing's av3), ``steps`` done,
``discharged`` (grains right of x = nxt/2, counted only when extra wall particles exist:
the hourglass count nq), and for the wall rows ``lower``, ``upper`` and the extra wall
particles ``extra``: ``wall_shear_<w>`` and ``wall_normal_<w>``, the x and y force of the
grains on one wall particle (its impulse per unit time, the thesis's plot: the listing sums
the impulse per step and divides by nxt or nw; here it is also divided by the interval's
duration), averaged over the interval that ends at the sample (NaN at t = 0). For the lower
wall the pressure is −wall_normal_lower, for the upper +wall_normal_upper.
``wall_impulse()`` gives the walls' cumulative impulse on the grains (the loop's
``wall_force_<side>``: the total force, not per wall particle).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ...errors import UnsupportedByEngine
from ...io.frames import Frame
from ...scene.lattice import ROW_HEIGHT
from ..backend import BackendBase, Capabilities, EngineOption, Needs
from . import core
from .effects import TRANSLATIONS, lattice_setup
from .lattice import Lattice
from .problem import build_lattice

__all__ = ["LgdBackend"]

#: steps per native call between two stop checks (one call validates the whole lattice)
CHUNK = 256
#: the sums of one wall group in the step log: (x, y)
WALL_SUMS = {"lower": ("is1", "ip1"), "upper": ("is2", "ip2"), "extra": ("is3", "ip3")}
ARRAYS = ("mlp", "ipx", "ipy", "ivx", "ivy", "nlp")
#: LgdParams fields whose defaults the thesis does not give (digest §8)
ASSUMED = ("idl", "id", "ke", "ntu")


def _impl_problem(value) -> str | None:
    return None if value in core.IMPLEMENTATIONS else \
        f"one of {', '.join(core.IMPLEMENTATIONS)} is allowed"


class LgdBackend(BackendBase):
    """Gutt's LGD on the scene's lattice; ``--impl reference`` runs the numpy step."""

    name = "lgd"
    kind = "lattice grain dynamics"
    capabilities = Capabilities(time_step=True, step_count=True)
    translations = TRANSLATIONS
    options = {"impl": EngineOption("impl", str, "the LGD step: native (C++, default) or "
                                                 "reference (numpy, bit-identical, slower)",
                                    _impl_problem, "native|reference")}
    version = "lgd 1 (Gutt 1989 listing of 27 Sep 88)"

    @classmethod
    def check(cls, scene, options) -> None:
        if scene.lattice is None:
            raise UnsupportedByEngine(cls.name, "lattice", None,
                                      "the lgd engine runs lattice scenes only: add a "
                                      "[lattice] section (nxt, nyt, Gutt's md lines; "
                                      "docs/lgd-engine.md)")
        super().check(scene, options)
        lattice_setup(scene)  # refuses what the integers cannot express, before any run

    # -- set-up ---------------------------------------------------------------------------
    def setup(self, needs: Needs, saved: dict | None, servo) -> None:
        scene = self.scene
        self.impl = str(self.run_options.extra.get("impl", "native"))
        setup = lattice_setup(scene)
        self.params, self.units, self.notes = setup.params, setup.units, setup.notes
        if saved is None:
            self.lat = build_lattice(self.params, setup.lines, self.notes)
            core.prepare(self.lat, self.params)
            self.total = {k: 0 for k in ("is1", "ip1", "is2", "ip2", "is3", "ip3")}
            self.nq = 0
        else:
            self.lat = Lattice(**{k: np.array(saved["lattice"][k]) for k in ARRAYS},
                               pv=tuple(saved["pv"]), nn=int(saved["nn"]),
                               itt=int(saved["itt"]), ng=int(saved["ng"]))
            self.total, self.nq = dict(saved["total"]), int(saved["nq"])
            # a stop inside a sample interval: its sums so far carry over
            self.last = (dict(saved["last_total"]), float(saved["last_time"]))
        self.n_particles = self.lat.ng
        # fixed when the run starts (a resumed run's lattice still holds them)
        self.has_marks = bool(np.any((self.lat.mlp > 0) & (self.lat.nlp > 0)))
        # wall particles per group (the listing's nxt, nxt and nw)
        nyt, nxt = self.lat.mlp.shape
        self.n_wall = {"lower": nxt, "upper": nxt,
                       "extra": int(np.count_nonzero(self.lat.mlp[1:-1] < 0))}
        if saved is None:
            self.last = (dict(self.total), self.time)  # the previous sample's sums, time
        self.last_step_ticks = 0  # the latest step's length (sizes the chunks of advance)
        self.first = saved is None

    # -- advancing ------------------------------------------------------------------------
    @property
    def time(self) -> float:
        return self.lat.itt / self.units.ticks_per_time

    @property
    def steps(self) -> int:
        return self.lat.nn - 1

    def _run(self, n: int) -> None:
        log = core.run_steps(self.lat, self.params, int(n), impl=self.impl)
        for key in self.total:
            self.total[key] += int(log[key].sum())
        if n:
            self.nq = int(log["nq"][-1])
            self.last_step_ticks = int(log["it"][-1])

    def advance_steps(self, steps: int, stop: Callable[[], bool] | None = None) -> bool:
        while self.steps < steps:
            self._run(min(CHUNK, steps - self.steps))
            if self.steps < steps and stop is not None and stop():
                return False
        return True

    def advance(self, t: float, collisions: int = 0, stop=None) -> bool:
        """Whole steps until the first step end at or after ``t``: chunks sized by the last
        step's length (steps shrink as grains speed up), then single steps."""
        ticks = t * self.units.ticks_per_time
        while self.lat.itt < ticks - 1e-9 * max(1.0, ticks):
            last = self.last_step_ticks  # 0: no step yet, so no estimate: one step
            ahead = int(0.8 * (ticks - self.lat.itt) / last) if last else 1
            self._run(max(1, min(CHUNK, ahead)))
            if self.lat.itt < ticks and stop is not None and stop():
                return False
        return True

    # -- sampling -------------------------------------------------------------------------
    def _grains(self) -> tuple[np.ndarray, np.ndarray]:
        return np.nonzero(self.lat.mlp > 0)

    def frame(self) -> Frame:
        """Grain centres x = (c + 1 + r/2 + ipx/idl) mod nxt, y = r·√3/2 + ipy/idl (row r and
        storage column c from 0; offsets included), velocities in particle units, the
        marked-grain numbers in ``extra['mark']`` (0: unmarked)."""
        lat = self.lat
        nyt, nxt = lat.mlp.shape
        r, c = self._grains()
        position, v = self._place(r, c)
        n = len(r)
        return Frame(time=self.time, box_lo=np.zeros(2),
                     box_hi=np.array([float(nxt), (nyt - 1) * ROW_HEIGHT]),
                     position=position, velocity=v,
                     angular_velocity=np.zeros((n, 1)), radius=np.full(n, 0.5),
                     extra={"mark": lat.nlp[r, c].copy()})

    def _place(self, r: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Positions and velocities (particle units) of the grains at rows ``r``, storage
        columns ``c``."""
        lat, idl, nxt = self.lat, self.params.idl, self.lat.mlp.shape[1]
        x = np.mod(c + 1 + r / 2 + lat.ipx[r, c] / idl, nxt)
        y = r * ROW_HEIGHT + lat.ipy[r, c] / idl
        v = np.column_stack([lat.ivx[r, c], lat.ivy[r, c]]) / self.units.speed
        return np.column_stack([x, y]), v

    def marked(self) -> dict | None:
        """The marked grains (``nlp`` > 0) as :meth:`frame` places them; None without any."""
        if not self.has_marks:
            return None
        lat = self.lat
        r, c = np.nonzero((lat.mlp > 0) & (lat.nlp > 0))
        position, velocity = self._place(r, c)
        return {"mark": lat.nlp[r, c].astype(np.int64), "position": position,
                "velocity": velocity, "period": float(lat.mlp.shape[1])}

    def observe(self, production: bool) -> dict:
        lat = self.lat
        r, c = self._grains()
        v = np.column_stack([lat.ivx[r, c], lat.ivy[r, c]]) / self.units.speed
        n = max(len(r), 1)
        mean = v.sum(axis=0) / n
        v2 = float((v * v).sum()) / n
        values = {"kinetic_energy": 0.5 * float((v * v).sum()),
                  "momentum": v.sum(axis=0), "mean_velocity": mean,
                  "thermal_velocity": math.sqrt(max(v2 - float(mean @ mean), 0.0)),
                  "steps": self.steps, "discharged": self.nq}
        previous, t0 = self.last
        span = self.time - t0
        for wall, (sx, sy) in WALL_SUMS.items():
            per = self.n_wall[wall] * span * self.units.speed
            ok = not self.first and span > 0 and self.n_wall[wall] > 0
            values[f"wall_shear_{wall}"] = (self.total[sx] - previous[sx]) / per if ok \
                else float("nan")
            values[f"wall_normal_{wall}"] = (self.total[sy] - previous[sy]) / per if ok \
                else float("nan")
        self.last, self.first = (dict(self.total), self.time), False
        return values

    def wall_impulse(self) -> dict[str, np.ndarray]:
        """Cumulative impulse of each wall row on the grains (the accumulators hold the
        grains' impulse on the walls), (3,) per side."""
        out = {}
        for side in ("lower", "upper"):
            sx, sy = WALL_SUMS[side]
            out[side] = -np.array([self.total[sx], self.total[sy], 0.0]) / self.units.speed
        return out

    def get_state(self) -> dict:
        lat = self.lat
        return {"lattice": {k: getattr(lat, k).copy() for k in ARRAYS},
                "pv": tuple(int(v) for v in lat.pv), "nn": lat.nn, "itt": lat.itt,
                "ng": lat.ng, "total": dict(self.total), "nq": self.nq,
                "last_total": dict(self.last[0]), "last_time": self.last[1]}

    def result_attrs(self) -> dict:
        par = self.params.resolved()
        attrs = {f"lgd_{k}": int(v) for k, v in par.__dict__.items()}
        attrs.update(self.units.attrs())
        attrs.update(lgd_impl=self.impl, lgd_steps=self.steps, lgd_ticks=self.lat.itt,
                     lgd_extra_wall_particles=self.n_wall["extra"],
                     lgd_assumed=", ".join(f"{k} = {getattr(par, k)}" for k in ASSUMED) +
                     " (not given in the thesis; docs/lgd-engine.md)",
                     lgd_units="d = 1 (lattice spacing), m = 1; speeds in lgd_speed_unit "
                               "integer units (1/256 cm/s of the listing); time unit = "
                               "lgd_ticks_per_time_unit ticks (1/65536 s); g = 1 with gravity",
                     lgd_wall_stress="wall_shear_<w>, wall_normal_<w>: x, y force of the "
                                     "grains on one wall particle, averaged over each sample "
                                     "interval (impulse per wall particle per unit time)")
        if self.notes:
            attrs["lgd_notes"] = "; ".join(self.notes)
        return attrs
