"""Engine backends, registered by name: ``lammps`` (soft contacts in LAMMPS), ``liggghts``
(soft contacts in LIGGGHTS, always in a child process), ``edmd`` (demstudy's
event-driven hard particles) and ``lgd`` (Gutt's 1989 lattice grain dynamics, lattice scenes
only).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts. A backend implements
the small protocol of :mod:`demstudy.engines.backend`; the one simulation loop
(:mod:`demstudy.simulation`) runs any of them. :func:`register_backend` adds one (a class,
or "module:Class" so that child processes can import it); docs/engines.md says how to write
one.
"""

from __future__ import annotations

import importlib
from typing import Any

__all__ = ["backend_names", "get_backend", "register_backend"]

#: name -> "module:Class" (imported on first use) or the class itself
_BACKENDS: dict[str, Any] = {
    "lammps": "demstudy.engines.lammps.backend:LammpsBackend",
    "edmd": "demstudy.engines.edmd.backend:EdmdBackend",
    "liggghts": "demstudy.engines.liggghts.backend:LiggghtsBackend",
    "lgd": "demstudy.engines.lgd.backend:LgdBackend",
}


def register_backend(backend: Any, name: str | None = None) -> None:
    """Make ``backend`` (a class, or "module:Class") available as ``--engine NAME``."""
    if name is None:
        if isinstance(backend, str):
            raise ValueError("give the name of a backend registered by its import path")
        name = backend.name
    _BACKENDS[name] = backend


def backend_names() -> list[str]:
    return list(_BACKENDS)


def get_backend(name: str) -> Any:
    """The backend class registered as ``name``."""
    entry = _BACKENDS.get(name)
    if entry is None:
        raise ValueError(f"engine = {name!r}: unknown engine (allowed: "
                         f"{', '.join(_BACKENDS)})")
    if isinstance(entry, str):
        module, _, cls = entry.partition(":")
        entry = _BACKENDS[name] = getattr(importlib.import_module(module), cls)
    return entry

#: the engine ``demstudy run`` uses when none is named
DEFAULT_ENGINE = "lammps"
