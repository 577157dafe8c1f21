"""One LAMMPS instance driven command by command, plus the little MPI the driver needs.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (``units lj``).
"""

from __future__ import annotations

import ctypes
import sys
from pathlib import Path

import numpy as np

from ...errors import EngineError
from .deck.system import sphere_mass
from .library import open_lammps, preload_mpi

# MPICH ABI handles (the runtime is the `mpich` wheel's): MPI_COMM_WORLD, MPI_INT, MPI_MAX
_MPI_COMM_WORLD, _MPI_INT, _MPI_MAX = 0x44000000, 0x4C000405, 0x58000001
_MPI_DOUBLE, _MPI_SUM = 0x4C00080B, 0x58000003


def quoted(path: Path | str) -> str:
    """A path for a LAMMPS command line (spaces allowed)."""
    return '"' + str(path).replace('"', '\\"') + '"'


def any_rank(flag: bool, nprocs: int) -> bool:
    """True on every one of ``nprocs`` ranks if ``flag`` is true on any rank (MPI_Allreduce with
    MPI_MAX on MPI_COMM_WORLD): needs the MPI runtime, not a LAMMPS instance, so it also works
    after ``close`` (MPI outlives the instance)."""
    if nprocs == 1:
        return flag
    lib = ctypes.CDLL(str(preload_mpi()), mode=ctypes.RTLD_GLOBAL)
    send, recv = ctypes.c_int(int(flag)), ctypes.c_int(0)
    status = lib.MPI_Allreduce(ctypes.byref(send), ctypes.byref(recv), 1, _MPI_INT,
                               _MPI_MAX, _MPI_COMM_WORLD)
    if status != 0:
        raise EngineError(f"MPI_Allreduce failed with code {status}")
    return bool(recv.value)


#: why LAMMPS loses atoms in a demstudy deck (walls are flat planes at the box faces): a
#: contact overlapping by more than a radius puts the centre behind the wall, whose force then
#: pushes it out (measured: Hooke contacts made for 0.005 d at speed 1 hit a wall at 100,
#: overlap 0.71 d; ``demstudy stability --case fast-impacts``)
LOST_ATOMS_CAUSE = ("a particle left the box, most likely through a wall: an impact "
                    "overlapped the wall by more than a radius, the contacts are too soft "
                    "for the impact speeds (raise soft.stiffness, or soft.hardness's "
                    "impact_speed), or it escaped through an open boundary")


class LammpsSession:
    """One LAMMPS instance; errors come back as ``EngineError`` naming the deck line."""

    def __init__(self, workdir: Path, screen: bool = False):
        self.workdir = workdir
        self.lmp = open_lammps(screen=screen, log=workdir / "log.lammps")
        self.rank = int(self.lmp.extract_setting("world_rank"))
        self.nprocs = int(self.lmp.extract_setting("world_size"))
        self._lam = sys.modules[type(self.lmp).__module__.split(".")[0]]

    def command(self, cmd: str) -> None:
        try:
            self.lmp.command(cmd)
        except Exception as exc:  # LAMMPS raises a bare Exception with its error message
            message = str(exc).strip() or type(exc).__name__
            if "Lost atoms" in message:
                message += f"\n  cause: {LOST_ATOMS_CAUSE}"
            raise EngineError(f"LAMMPS error: {message}\n  deck line: {cmd}") from None

    def gather(self, name: str, count: int, integer: bool = False) -> np.ndarray:
        """A per-atom property of all atoms, ordered by atom ID, on every rank."""
        data = self.lmp.gather_atoms(name, 0 if integer else 1, count)
        if data is None:
            raise EngineError(f"LAMMPS could not gather per-atom {name!r}")
        arr = np.ctypeslib.as_array(data)
        return arr.reshape(-1, count) if count > 1 else arr.copy()

    def scatter(self, name: str, values: np.ndarray) -> None:
        """Set a per-atom float property from rows ordered by atom ID (the inverse of
        ``gather``; every rank passes the same array and sets its owned atoms, so no atom
        map is needed)."""
        nlocal = int(self.lmp.extract_setting("nlocal"))
        ids = np.array(self.lmp.numpy.extract_atom("id")[:nlocal], dtype=np.int64)
        target = self.lmp.numpy.extract_atom(name)
        target[:nlocal] = values[ids - 1]

    def create_atoms(self, atoms: np.ndarray, velocities: np.ndarray) -> None:
        """Add the atoms of a data file's Atoms and Velocities rows (``deck.system.data_rows``)
        through the library interface, as ``read_data`` would: the same positions, order,
        velocities, radii, masses (``sphere_mass``) and spins, without formatting and parsing
        text. Every rank passes every row; each keeps those it owns."""
        n = len(atoms)
        tagint = np.int64 if self.lmp.extract_setting("tagint") == 8 else np.int32
        ids = np.ascontiguousarray(atoms[:, 0], dtype=tagint)
        types = np.ascontiguousarray(atoms[:, 1], dtype=np.int32)
        x = np.ascontiguousarray(atoms[:, 4:7], dtype=np.float64)
        v = np.ascontiguousarray(velocities[:, 1:4], dtype=np.float64)
        create = self.lmp.lib.lammps_create_atoms
        create.argtypes = [ctypes.c_void_p, ctypes.c_int] + [ctypes.c_void_p] * 5 + [ctypes.c_int]
        create.restype = ctypes.c_int
        try:
            with self._lam.core.ExceptionCheck(self.lmp):  # LAMMPS's error, as a command's
                made = create(self.lmp.lmp, n, ids.ctypes.data, types.ctypes.data,
                              x.ctypes.data, v.ctypes.data, None, 0)
        except Exception as exc:
            message = str(exc).strip() or type(exc).__name__
            raise EngineError(f"LAMMPS error: {message}\n  creating the initial atoms") from None
        total = int(self.lmp.get_natoms())
        if made != n or total != n:
            raise EngineError(f"LAMMPS created {total} of {n} atoms (some outside the box?)")
        self.scatter("radius", 0.5 * atoms[:, 2])
        self.scatter("rmass", sphere_mass(atoms[:, 2], atoms[:, 3]))
        self.scatter("omega", np.ascontiguousarray(velocities[:, 4:7]))

    def fix_vector(self, fix_id: str, length: int) -> np.ndarray:
        """Global vector of a fix (e.g. ``fix ave/time``), identical on every rank."""
        style, kind = self._lam.LMP_STYLE_GLOBAL, self._lam.LMP_TYPE_VECTOR
        if length == 1:  # a fix averaging one value has a global scalar, not a vector
            return np.array([self.lmp.extract_fix(fix_id, style, self._lam.LMP_TYPE_SCALAR)])
        return np.array([self.lmp.extract_fix(fix_id, style, kind, i) for i in range(length)])

    def compute_scalar(self, compute_id: str) -> float:
        """Global scalar of a compute (e.g. ``compute pressure``), identical on every rank."""
        return float(self.lmp.extract_compute(compute_id, self._lam.LMP_STYLE_GLOBAL,
                                              self._lam.LMP_TYPE_SCALAR))

    def box_lengths(self) -> np.ndarray:
        boxlo, boxhi, *_ = self.lmp.extract_box()
        return np.asarray(boxhi) - np.asarray(boxlo)

    def any_rank(self, flag: bool) -> bool:
        """True on every rank if ``flag`` is true on any rank (MPI_Allreduce with MPI_MAX)."""
        return any_rank(flag, self.nprocs)

    def local_array(self, compute_id: str, columns: int) -> np.ndarray:
        """This rank's rows of a local compute's array (e.g. ``compute pair/local``)."""
        data = self.lmp.numpy.extract_compute(compute_id, self._lam.LMP_STYLE_LOCAL,
                                              self._lam.LMP_TYPE_ARRAY)
        if data is None:
            return np.zeros((0, columns))
        return np.array(data, dtype=np.float64).reshape(-1, columns)

    def fix_atom_array(self, fix_id: str) -> np.ndarray:
        """This rank's rows (owned atoms) of a fix's per-atom array."""
        data = self.lmp.numpy.extract_fix(fix_id, self._lam.LMP_STYLE_ATOM,
                                          self._lam.LMP_TYPE_ARRAY)
        return np.zeros((0, 0)) if data is None else np.array(data, dtype=np.float64)

    def local_positions(self) -> np.ndarray:
        """Positions of this rank's owned atoms (the rows of per-atom fix arrays)."""
        nlocal = int(self.lmp.extract_setting("nlocal"))
        return np.array(self.lmp.numpy.extract_atom("x"), dtype=np.float64)[:nlocal]

    def sum_ranks(self, values: np.ndarray) -> np.ndarray:
        """Element-wise sum of a float array over the ranks (MPI_Allreduce, MPI_SUM)."""
        send = np.ascontiguousarray(values, dtype=np.float64)
        if self.nprocs == 1:
            return send.copy()
        recv = np.empty_like(send)
        lib = ctypes.CDLL(str(preload_mpi()), mode=ctypes.RTLD_GLOBAL)
        status = lib.MPI_Allreduce(send.ctypes.data_as(ctypes.c_void_p),
                                   recv.ctypes.data_as(ctypes.c_void_p), send.size,
                                   _MPI_DOUBLE, _MPI_SUM, _MPI_COMM_WORLD)
        if status != 0:
            raise EngineError(f"MPI_Allreduce failed with code {status}")
        return recv

    def gather_rows(self, rows: np.ndarray) -> np.ndarray:
        """Every rank's rows of a local array, stacked in rank order, on every rank (an
        allgather built from two element-wise sums: counts, then a zero-padded buffer in
        which each rank fills its own slice; meant for the few rows of a sample)."""
        rows = np.ascontiguousarray(rows, dtype=np.float64)
        if self.nprocs == 1:
            return rows.copy()
        counts = np.zeros(self.nprocs)
        counts[self.rank] = rows.shape[0]
        counts = self.sum_ranks(counts).astype(np.int64)
        start = int(counts[:self.rank].sum())
        buffer = np.zeros((int(counts.sum()), rows.shape[1]))
        buffer[start:start + rows.shape[0]] = rows
        return self.sum_ranks(buffer)

    def close(self) -> None:
        self.lmp.close()
