"""Energy audit of a LAMMPS run: does the contact model create energy?

Dimensionless particle units: d = 1, m = 1 (no gravity; the shear rate or the initial
velocities set the time unit).

The scene's own deck is run step by step in the library, and every ``every`` steps the audit
adds up the kinetic energy about the shear profile u = γ̇ (y − L_y/2) x̂, the rotational
energy, the normal spring energy ½ k_n δ² (Hooke) and the tangential spring energy
|F_t|²/(2 k_t) of each contact (exact for an undamped spring: F_t = −k_t ξ), and integrates
the work the shear does, W = −∫ P_xy γ̇ V dt (P_xy: LAMMPS's pressure tensor, the kinetic
part from the velocities about u). Energy balance: E(t) − E(0) = W(t) − D(t) with D the energy
dissipated so far, which a passive contact model never lets decrease.

Why it exists: near jamming the soft β rule runs much hotter than the event-driven one
(docs/stability.md, finding 2); this audit shows that the heat is shear work done against the
stiff, enduring contacts (D never decreases), not energy made by the contact model.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...contact.stiffness import contact_setup
from ...scene import Scene
from .deck import write_deck
from .library import open_lammps


@dataclass(frozen=True)
class EnergyAudit:
    """Per sample (arrays of one entry each): time, kinetic (about the shear profile),
    rotational, normal and tangential spring energy, the shear work done so far, and the
    coordination number (contacts per particle)."""

    time: np.ndarray
    kinetic: np.ndarray
    rotational: np.ndarray
    normal_spring: np.ndarray
    tangential_spring: np.ndarray
    work: np.ndarray
    coordination: np.ndarray

    @property
    def total(self) -> np.ndarray:
        return self.kinetic + self.rotational + self.normal_spring + self.tangential_spring

    @property
    def dissipated(self) -> np.ndarray:
        """D(t) = W(t) − (E(t) − E(0))."""
        return self.work - (self.total - self.total[0])

    def largest_gain(self) -> float:
        """The largest energy the model made in any stretch of the run: max over t of
        max_{t' <= t} D(t') − D(t) (0 for a passive model, up to round-off and the work's
        trapezoid rule)."""
        d = self.dissipated
        return float(np.max(np.maximum.accumulate(d) - d))


def _check(scene: Scene) -> None:
    p = contact_setup(scene, "lammps").pair
    if scene.dimension != 2 or p.model != "hooke" or p.xt != 0.0 or scene.walls:
        raise ValueError("the energy audit handles 2D periodic Hooke scenes with undamped "
                         "tangential springs only (dimension 2, soft.model hooke, no walls, "
                         f"contact.tangential smooth or beta), not {scene.meta.name!r}")


def audit(scene: Scene, folder: str | Path, duration: float, every: int = 10) -> EnergyAudit:
    """Run ``scene`` (2D, periodic, Hooke, smooth or β contacts, optional Lees–Edwards shear)
    for ``duration`` time units in LAMMPS, sampling the energies every ``every`` steps."""
    _check(scene)
    p = contact_setup(scene, "lammps").pair
    folder = Path(folder)
    deck = write_deck(scene, folder).read_text().splitlines()
    lmp = open_lammps()
    here = os.getcwd()
    try:
        os.chdir(folder)  # the deck reads its data file by a relative name
        for line in deck:
            if not line.startswith(("run ", "thermo ")):
                lmp.command(line)
        lmp.command("compute audit_f all pair/local dist p4 cutoff radius")
        lmp.command("compute audit_id all property/local patom1 patom2 cutoff radius")
        lmp.command("compute audit_p all pressure NULL virial")
        # the virial is tallied only on steps a thermo output asks for it
        lmp.command("thermo_style custom step c_audit_p[4]")
        lmp.command(f"thermo {every}")
        lmp.command("run 0")
        return _sample(lmp, scene, p.kn, p.kt, duration, every)
    finally:
        os.chdir(here)
        lmp.close()


def _sample(lmp, scene: Scene, kn: float, kt: float, duration: float,
            every: int) -> EnergyAudit:
    n = scene.n_particles
    dt = lmp.extract_global("dt")
    rate = scene.shear.rate if scene.shear is not None else 0.0
    width, height = scene.box.size[0], scene.box.size[1]
    rows: list[tuple[float, ...]] = []
    work, last_power = 0.0, None
    for step in range(0, int(round(duration / dt)) + 1, every):
        if step:
            lmp.command(f"run {every} pre no post no")
        x = np.array(lmp.numpy.extract_atom("x")[:n, :2])
        v = np.array(lmp.numpy.extract_atom("v")[:n, :2])
        omega = np.array(lmp.numpy.extract_atom("omega")[:n, 2])
        m = np.array(lmp.numpy.extract_atom("rmass")[:n])
        r = np.array(lmp.numpy.extract_atom("radius")[:n])
        ylo = lmp.extract_box()[0][1]
        v[:, 0] -= rate * (x[:, 1] - ylo - height / 2)  # about the shear profile
        kinetic = 0.5 * float(np.sum(m * (v**2).sum(1)))
        rotational = 0.25 * float(np.sum(m * r**2 * omega**2))  # discs: I = m r²/2
        p_xy = lmp.extract_compute("audit_p", 0, 1)[3] + float(np.sum(m * v[:, 0] * v[:, 1])) \
            / (width * height)
        power = -p_xy * rate * width * height
        if last_power is not None:
            work += 0.5 * (power + last_power) * every * dt
        last_power = power
        tags = np.array(lmp.numpy.extract_atom("id")[:n])
        radius = np.zeros(int(tags.max()) + 1)
        radius[tags] = r
        un, ut, contacts = _springs(lmp, kn, kt, radius)
        rows.append((step * dt, kinetic, rotational, un, ut, work, 2.0 * contacts / n))
    return EnergyAudit(*np.array(rows).T)


def _springs(lmp, kn: float, kt: float, radius: np.ndarray) -> tuple[float, float, int]:
    """(normal, tangential spring energy, contacts) of the overlapping pairs, each once
    (with ``newton off`` a pair across the periodic boundary is listed from both sides)."""
    forces = np.array(lmp.numpy.extract_compute("audit_f", 2, 2))
    ids = np.array(lmp.numpy.extract_compute("audit_id", 2, 2))
    if forces.ndim != 2 or not forces.size:
        return 0.0, 0.0, 0
    pairs, first = np.unique(np.sort(ids, axis=1).astype(int), axis=0, return_index=True)
    overlap = radius[pairs].sum(axis=1) - forces[first, 0]
    on = overlap > 0.0
    un = 0.5 * kn * float(np.sum(overlap[on] ** 2))
    ut = 0.5 * float(np.sum(forces[first, 1][on] ** 2)) / kt if kt > 0.0 else 0.0
    return un, ut, int(on.sum())
