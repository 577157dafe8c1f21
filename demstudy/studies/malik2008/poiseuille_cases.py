"""The runs of the Poiseuille part of the Malik (2008) study: Malik's Ch. 3 (φ ≈ 0.01) and
Ch. 4 (φ ≈ 0.1, 0.5) gravity-driven channel flows with the thesis's N and box (digest §1.4).

Dimensionless particle units: d = 1, m = 1, g = 1 (gravity acts): times in √(d/g), speeds in
√(gd), temperatures in g d.

What every run records (``measure``): 25 bins of 2 d across W = 50 (Malik's bins, §4.1; bin 1
at the lower wall, bin 13 the centre), the profiles, the collision log for the free paths
(Kn), the VDFs, the orientational correlation Λ(y) and the velocity correlations; the frames
are kept so that the analysis can add the in-bin g(r) and anything else afterwards. Frames are
sampled sparsely (``SAMPLE_INTERVAL``) so that a run's file stays ~100-300 MB: samples several
collision times apart are nearly independent, which the block errors need anyway.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from ..base import Case, merge
from .tc import STUDY_TC

SCENES = {0.01: "malik2008/poiseuille-phi0.01",
          0.1: "malik2008/poiseuille-phi0.1",
          0.5: "malik2008/poiseuille-phi0.5"}
#: the thesis's N and box per nominal φ (digest §1.4-1.5): the tests hold the scenes to these
THESIS_SYSTEM = {0.01: (2744, (50.0, 50.0, 50.0)), 0.1: (24400, (50.0, 50.0, 50.0)),
                 0.5: (19600, (20.0, 50.0, 20.0))}
BETAS = (-0.99, 0.0, 0.99)
RESTITUTIONS = {0.01: (0.8, 0.9, 0.95, 0.99),  # Ch. 3 appendix
                0.1: (0.7, 0.8, 0.9, 0.99)}    # "four values of e" incl. 0.7 and 0.99
DENSE = (0.9, 0.9)  # φ = 0.5: (e, β)
BIN_WIDTH = 2.0  # 25 bins across W = 50 (Malik's default, §4.1)
#: run lengths (√(d/g)) and frames (and profile samples) apart: φ = 0.01 the scene's (≈ 2500
#: collisions per particle, forecast ~100 s a run), samples ≳ 4 mean free times apart.
#: φ = 0.1 and 0.5 are shortened against the scenes (the CPU budget of this study: ~60
#: core-minutes for 13+ runs). φ = 0.5: the quick run showed the dense core's collision rate
#: rising to ≳ 250 per particle per √(d/g) by t = 12 (≈ 20 s of CPU per √(d/g)), so the scene's
#: 1300 would take hours: 40 + 10 is what fits, and the analysis says whether it is steady.
#: Measured on 2026-12-02 (2 shared cores): the φ = 0.5 run had not finished after 11.5
#: CPU-minutes, nor φ = 0.1 (e = 0.7, β = 0.99 and 0) after 6.2 and 5.1 (forecast 1.2): they
#: were stopped at the study's CPU budget; the dense collision rate is the open cost.
RUN = {0.01: {"sample_interval": 4.0},
       0.1: {"equilibration": 200.0, "production": 300.0, "sample_interval": 5.0},
       0.5: {"equilibration": 40.0, "production": 10.0, "sample_interval": 1.0}}
STATISTICS = ["profiles", "freepath", "vdf", "lambda", "vcorr"]
#: quick runs (√(d/g)): a few seconds each; no steady state is claimed from them
QUICK_RUN = {0.01: {"equilibration": 100.0, "production": 120.0, "sample_interval": 4.0},
             0.5: {"equilibration": 4.0, "production": 4.0, "sample_interval": 0.5}}


@dataclass(frozen=True)
class Flow:
    """One of Malik's flows: nominal φ, e, β and the engine."""

    phi: float
    e: float
    beta: float
    engine: str = "edmd"
    #: the event-driven engine's TC time when not the study's ``tc.STUDY_TC`` (a TC twin,
    #: :data:`TC_TWINS`)
    tc: float | None = None
    #: N in a cube of solid fraction φ when not the thesis's system (:data:`VALIDATION`)
    n: int | None = None

    @property
    def name(self) -> str:
        twin = "" if self.tc is None else f"-tc{self.tc:g}"
        box = "" if self.n is None else f"-n{self.n}"
        return (f"poiseuille-phi{self.phi:g}-b{self.beta:g}-e{self.e:g}{box}{twin}-"
                f"{self.engine}")

    @property
    def side(self) -> float | None:
        """The cube's side (d) of an N-particle validation box at exactly φ (digest §1.5:
        37.4 for N = 1000 at φ = 0.01); None for the thesis's systems."""
        return None if self.n is None else (self.n * math.pi / 6 / self.phi) ** (1 / 3)


def case_of(flow: Flow, quick: bool = False) -> Case:
    """The ``Case`` of ``flow`` (``quick``: also part of ``--quick``, shortened)."""
    sections: dict[str, Any] = {
        "contact": {"restitution": flow.e,
                    "tangential": {"model": "beta", "beta": flow.beta}},
        "run": dict(RUN[flow.phi]),
        "measure": {"bin_width": BIN_WIDTH, "statistics": list(STATISTICS),
                    "keep_frames": True},
    }
    if flow.engine != "edmd":  # soft spheres: the collision log (free paths) is edmd's
        sections["measure"]["statistics"] = [s for s in STATISTICS if s != "freepath"]
        sections = merge(sections, SOFT_SECTIONS)
    if flow.side is not None:  # Malik's 25 bins across the validation box's W
        sections["box"] = {"size": [flow.side] * 3}
        sections["particles"] = {"count": flow.n}
        sections["measure"]["bin_width"] = flow.side / 25
    quick_sections = {"run": QUICK_RUN[flow.phi]} if quick else {}
    # the event-driven runs at the study's t_c, given explicitly (tc.STUDY_TC: not the
    # engine's default for spheres, 1e-6, which the twins use)
    options = {} if flow.engine != "edmd" else {
        "tc": STUDY_TC if flow.tc is None else flow.tc}
    return Case(flow.name, SCENES[flow.phi], engine=flow.engine, sections=sections,
                quick=quick, quick_sections=quick_sections, group=f"phi{flow.phi:g}",
                options=options)


def flows() -> list[Flow]:
    """Every flow of the full study, in the order the runs should be made (cheapest first:
    φ = 0.01, then φ = 0.5, then φ = 0.1 with e = 0.7 first)."""
    out = [Flow(0.01, e, b) for b in BETAS for e in RESTITUTIONS[0.01]]
    out.append(Flow(0.5, *DENSE))
    out += [Flow(0.1, e, b) for e in RESTITUTIONS[0.1] for b in BETAS]
    return out


#: the soft cross-checks (LAMMPS, LIGGGHTS): φ = 0.01, the cheapest flow, at Fig 2.11's
#: β = 0.99, e = 0.8 (β through the tangential spring), the scene's stiffness (k_n = 1.6·10⁶:
#: δ ≤ 1 % at a 20 √(gd) impact) at 10 steps per contact, which the cost study found within
#: its noise for the φ = 0.1 Poiseuille flow (k* = 10⁶: 2.4 % against a 2.3 % floor,
#: docs/accuracy-cost.md).
#: 200 + 400 √(d/g): the event-driven run plateaus by ≈ 150 √(d/g); the scene's 2500 at the
#: default 50 steps per contact would take 3.7 h (forecast), this ≈ 25 min in LAMMPS. LIGGGHTS
#: runs the same scene (hooke/stiffness: k_n, k_t and the damping set directly, the same
#: β spring), ≈ ×0.6 LAMMPS's time per step here (a 4 √(d/g) pilot of each, under load).
SOFT = Flow(0.01, 0.8, 0.99, engine="lammps")
SOFT_FLOWS = (SOFT, Flow(0.01, 0.8, 0.99, engine="liggghts"))
SOFT_SECTIONS = {"run": {"equilibration": 200.0, "production": 400.0, "sample_interval": 4.0},
                 "soft": {"steps_per_contact": 10}}
QUICK = (Flow(0.01, 0.8, 0.99), Flow(0.01, 0.8, -0.99), Flow(0.5, *DENSE))
#: TC twins (full study): the dense φ = 0.5 channel makes 16 % of its pair collisions
#: elastic at the study's t_c = 1e-5 √(d/g); the same flow at t_c = 1e-6 says whether its
#: rows depend on the TC model (the "TC model" row, :func:`poiseuille_checks.tc_twin_rows`)
TC_TWINS = (Flow(0.5, *DENSE, tc=1e-6),)
#: the code validation of §3.5 (Fig 2.11): N = 1000 at φ = 0.01 in a cube (37.4 d), e = 0.8,
#: β = 0.99 (the thesis's system for Ch. 3 is 2744 in 50³: REF in poiseuille_checks)
VALIDATION = Flow(0.01, 0.8, 0.99, n=1000)


def cases(quick: bool) -> list[Case]:
    """Full study: every flow (event-driven) and the soft cross-checks ``SOFT_FLOWS``;
    quick: ``QUICK`` only, shortened."""
    if quick:
        return [case_of(f, quick=True) for f in QUICK]
    return ([case_of(f, quick=f in QUICK) for f in flows()] + [case_of(f) for f in SOFT_FLOWS]
            + [case_of(f) for f in (*TC_TWINS, VALIDATION)])
