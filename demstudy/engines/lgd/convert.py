"""Gutt's problem files ↔ demstudy lattice scenes.

Units: a problem holds the listing's integers; the scene it becomes is in demstudy's particle
units (d = 1 = the lattice spacing, m = 1, g = 1 when gravity acts, otherwise the wall speed
or the grains' initial r.m.s. speed is the speed unit V: :mod:`demstudy.engines.lgd.effects`).
The md lines keep their integers (``[lattice]`` holds the listing's units).

* :func:`problem_scene_data`: a problem as scene data (``demstudy lgd-import`` writes it as
  TOML; ``demstudy run PATH --engine lgd`` runs a problem directly when PATH is Gutt's control
  file ``in`` or the folder holding it). g = (igx, igy) becomes ``gravity.direction`` with
  ``lattice.gravity_scale`` = |g|; without gravity, moving walls set ``speed_scale`` =
  max(|jx1|, |jx2|) (wall speeds ±1 or 0/1); e = iep/ke; iep1 ≠ iep2 or iew1 ≠ iew2 become
  Gutt's piecewise law with c_b = icb/V (``lattice.wall_e2`` = iew2/ke); icb = 0 means the
  "above c_b" coefficients always apply, so e2 is then the constant; nt, nto become
  ``run.unit = 'steps'``, production nt, samples every gcd(nt, nto) steps.
* :func:`scene_problem`: a lattice scene as a problem (``write_problem`` writes the files).

What a scene does not keep: ``ist`` (output modes), ``mvx``/``mvy`` (block sizes of the
averaged-velocity output) and the output file names; they are in the scene's description.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

from ...scene import Scene, apply_overrides, load_scene, validate_scene
from ...scene.lattice import ROW_HEIGHT
from .effects import lattice_setup
from .problem import Control, Problem, read_problem

__all__ = ["is_problem", "load_scene_or_problem", "problem_scene_data", "scene_problem"]


def is_problem(source: str | os.PathLike) -> bool:
    """Whether ``source`` names Gutt's control file (a file called ``in``, or a folder
    holding one)."""
    path = Path(source)
    return (path.is_dir() and (path / "in").is_file()) or (path.is_file() and path.name == "in")


def _speed(problem: Problem) -> tuple[float, float | None]:
    """(V, speed_scale for the scene) of a problem (effects module docstring)."""
    par = problem.params
    if par.igx or par.igy:
        return 4.0 * math.sqrt(math.hypot(par.igx, par.igy) * par.idl), None
    if par.jx1 or par.jx2:
        scale = float(max(abs(par.jx1), abs(par.jx2)))
        return scale, scale
    from .problem import speed_rms  # noqa: PLC0415

    return speed_rms(problem.lattice()), None


def problem_scene_data(problem: Problem, source: str = "") -> dict[str, Any]:
    """Scene data (a TOML-ready dict) of ``problem`` (module docstring)."""
    par = problem.params.resolved()
    ke = par.ke
    speed, speed_scale = _speed(problem)
    iep1, iew1 = (par.iep1, par.iew1) if par.icb > 0 else (par.iep2, par.iew2)
    piecewise = par.icb > 0 and (par.iep1 != par.iep2 or par.iew1 != par.iew2)
    contact: dict[str, Any] = {"restitution": iep1 / ke}
    if piecewise:
        contact["law"] = {"model": "gutt-piecewise", "e1": iep1 / ke, "e2": par.iep2 / ke,
                          "crossover_speed": par.icb / speed}
    walls = [{"side": side, "restitution": iew1 / ke, "velocity": jx / speed}
             for side, jx in (("lower", par.jx1), ("upper", par.jx2))]
    lattice: dict[str, Any] = {
        k: getattr(par, k) for k in ("nxt", "nyt", "idl", "idx", "idy", "id", "ke", "ntu",
                                     "kq", "kx", "ky")}
    if piecewise and par.iew2 != iew1:
        lattice["wall_e2"] = par.iew2 / ke
    if speed_scale is not None:
        lattice["speed_scale"] = speed_scale
    data: dict[str, Any] = {"dimension": 2, "contact": contact, "walls": walls,
                            "particles": {}}
    if par.igx or par.igy:
        data["gravity"] = {"direction": [float(par.igx), float(par.igy)]}
        lattice["gravity_scale"] = math.hypot(par.igx, par.igy)
    lattice["initial"] = [dict(zip(("md", "x1", "y1", "x2", "y2", "vx", "vy"), ln.values(),
                                   strict=True)) for ln in problem.lines]
    data["lattice"] = lattice
    nto = problem.nto if 0 < problem.nto <= problem.nt else problem.nt
    data["run"] = {"unit": "steps", "equilibration": 0.0, "production": float(problem.nt),
                   "sample_interval": float(math.gcd(problem.nt, nto) or 1)}
    data["measure"] = {"bin_width": ROW_HEIGHT}
    ctl = problem.control
    data["meta"] = {
        "name": Path(source).parent.name if Path(source).name == "in" else
        (Path(source).name or "gutt-problem"),
        "description": f"Gutt's LGD problem {source} converted (ist = {ctl.ist}, mvx = "
                       f"{problem.mvx}, mvy = {problem.mvy}, nto = {problem.nto}; outputs "
                       f"{ctl.nam3}, {ctl.nam4}{', ' + ctl.nam5 if ctl.nam5 else ''} not "
                       "written: the results file holds them)",
        "reference": "Gutt (1989), App. 3 problem-file format (main L1584–L2006)"}
    return data


def load_scene_or_problem(source: str | os.PathLike, overrides=()) -> Scene:
    """A scene file or preset, or Gutt's problem (control file ``in`` or its folder)."""
    if not is_problem(source):
        return load_scene(source, overrides)
    data = problem_scene_data(read_problem(Path(source)), str(source))
    return validate_scene(apply_overrides(data, overrides), str(source))


def scene_problem(scene: Scene) -> Problem:
    """Gutt's problem of a lattice scene (its integers as ``lgd`` runs them)."""
    setup = lattice_setup(scene)
    run = scene.run
    if run.unit == "steps":
        nt, nto = int(run.equilibration + run.production), int(run.sample_interval)
    else:  # the listing counts steps only: say so rather than guess a step count
        raise ValueError(f"run.unit = {run.unit!r}: Gutt's problem files count steps (nt); "
                         "give the scene run.unit = 'steps'")
    return Problem(params=setup.params.resolved(), lines=setup.lines, nt=nt, nto=nto,
                   control=Control(0, "par", "sum", "dump"), nam2="init")
