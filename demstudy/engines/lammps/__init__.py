"""The LAMMPS engine: the scene's deck driven through LAMMPS's Python interface.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (``units lj``). See
docs/lammps-engine.md: ``launch`` (entry point, child process, MPI), ``driver`` (the run loop,
sampling, servo, checkpoints), ``session`` (one LAMMPS instance, errors, gathers).
"""

from .driver import Driver, RunState, profile_analysis
from .launch import LammpsEngine
from .session import LammpsSession

__all__ = ["Driver", "LammpsEngine", "LammpsSession", "RunState", "profile_analysis"]
