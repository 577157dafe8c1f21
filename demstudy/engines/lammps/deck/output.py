"""Sampling computes and the bare deck's run commands (time in the scene's units)."""

from __future__ import annotations

import math

from ....contact.stiffness import ContactSetup
from ....scene import Scene
from .base import Block
from .effects import wall_force_sources

WALL_FORCES = "wall_forces"
#: local computes read by the driver for the contact stress (measure.statistics "stress"):
#: normal force on i (fx fy fz), tangential force on i (p1-p3), x_i - x_j (p10-p12)
STRESS_PAIRS, STRESS_IDS = "stress_pairs", "stress_ids"
STRESS_COLUMNS = 9
#: local computes read by the driver for the contact health (demstudy.contact.health): the
#: distance and x_i - x_j (p10-p12) of every touching pair, and their atom IDs
HEALTH_PAIRS, HEALTH_IDS = "health_pairs", "health_ids"
HEALTH_COLUMNS = 4
#: y-periodic boxes: the contact part of the pressure, tr(Σ r_ij f_ij)/(dim V), read by the
#: driver at each sample (the virial is tallied on thermo steps only: it is a thermo column)
VIRIAL_PRESSURE = "virial_pressure"


def sample_steps(scene: Scene, dt: float) -> int:
    """Steps between samples (the sampling interval rounded to whole steps)."""
    return max(1, round(scene.run.sample_interval / dt))


def sampling_block(scene: Scene, setup: ContactSetup) -> Block:
    n = sample_steps(scene, setup.timestep)  # the Python driver's segment
    cmds = ["compute ke mobile ke"]
    columns = ["step", "time", "c_ke"]
    if scene.rotation_matters:
        cmds.append("compute erot mobile erotate/sphere")
        columns.append("c_erot")
    sources = wall_force_sources(scene)
    if sources:
        # wall forces averaged over every step of each run segment (contacts are brief);
        # one fix for all walls: each ave/time fix costs a few microseconds per step
        forces = " ".join(f"c_{compute}[*]" for _side, compute, _sign in sources)
        cmds.append(f"fix {WALL_FORCES} all ave/time 1 {n} {n} {forces}")
        columns += [f"f_{WALL_FORCES}[{i}]" for i in range(1, 3 * len(sources) + 1)]
    if "stress" in scene.measure.statistics:
        # contact forces and atom IDs of every touching pair, evaluated only when the
        # driver reads them (same neighbour loop and cutoff: the rows correspond)
        cmds.append(f"compute {STRESS_PAIRS} all pair/local fx fy fz p1 p2 p3 p10 p11 p12 "
                    "cutoff radius")
        cmds.append(f"compute {STRESS_IDS} all property/local patom1 patom2 cutoff radius")
    # the touching pairs for the contact health, read at the samples only (a local compute
    # costs nothing between reads)
    cmds.append(f"compute {HEALTH_PAIRS} all pair/local dist p10 p11 p12 cutoff radius")
    cmds.append(f"compute {HEALTH_IDS} all property/local patom1 patom2 cutoff radius")
    if scene.y_periodic:
        # virial only: LAMMPS's kinetic part would count the Lees–Edwards mean flow as heat
        # (the driver adds the peculiar kinetic part, demstudy.engines.peculiar)
        cmds.append(f"compute {VIRIAL_PRESSURE} all pressure NULL virial")
        columns.append(f"c_{VIRIAL_PRESSURE}")
    if scene.shear is not None:
        columns.append("xy")  # the Lees–Edwards tilt
    cmds.append("thermo_style custom " + " ".join(columns))
    cmds.append("thermo_modify norm no lost error")
    return Block("sampling", "energies (translational; rotational with sphere inertia) and "
                 f"wall forces averaged over segments of {n} steps", cmds)


def steps(duration: float, dt: float) -> int:
    return max(0, math.ceil(duration / dt - 1e-9))


def run_block(scene: Scene, setup: ContactSetup, dump: str | None = None) -> Block:
    """Commands that make the deck runnable with ``lmp -in deck.in`` (no Python needed)."""
    dt = setup.timestep
    n_sample = sample_steps(scene, dt)
    cmds = [f"thermo {n_sample}"]
    if dump:
        cmds.append(
            f"dump frames mobile custom {n_sample} {dump} id type radius x y z vx vy vz "
            "omegax omegay omegaz"
        )
        cmds.append("dump_modify frames sort id")
    eq, prod = steps(scene.run.equilibration, dt), steps(scene.run.production, dt)
    if eq:
        cmds.append(f"run {eq}  # equilibration: {scene.run.equilibration:g} time units")
        if scene.shear is not None:
            # the next run re-initialises fix deform: count the tilt from now again
            cmds.append("variable lees_edwards_t0 equal $(time)")
    cmds.append(f"run {prod}  # production: {scene.run.production:g} time units")
    return Block("run", f"bare-deck runs, dt = {dt:.6g}, thermo every {n_sample} steps",
                 cmds, stage="run")
