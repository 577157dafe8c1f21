"""Box, boundaries, particles (the setup stage, replaced by read_restart on resume), atom
types and groups, and the integrator.

Dimensionless particle units: d = 1, m = 1 (density 6/π for spheres, 4/π per unit area for
discs, so a particle of diameter 1 has mass 1; masses scale with volume).

Each bumpy wall owns an atom type and a group (type 2 for the first bumpy wall, 3 for the
second), so each collides with its own wall rule and moves with its own wall. Bumps are 1e6
times heavier than a particle of their size, so the pair contact sees m_eff = m to 1 part in
1e6, and ``fix move`` prescribes their motion.
"""

from __future__ import annotations

import math

import numpy as np

from ....contact.stiffness import ContactSetup
from ....effects.bumps import BumpRow, bump_padding, bumpy_walls
from ....scene import Scene
from ....scene.initial import InitialState
from .base import Block, fmt

DATA_FILE = "initial.data"
DENSITY = {2: 4 / math.pi, 3: 6 / math.pi}
MASS_FACTOR = 1e6


def bump_group(side: str) -> str:
    """LAMMPS group (and ID prefix) of one wall's bumps."""
    return f"bumps_{side}"


def bump_type(scene: Scene, side: str) -> int:
    sides = [w.side for w in bumpy_walls(scene)]
    return 2 + sides.index(side)


def n_atom_types(scene: Scene) -> int:
    return 1 + len(bumpy_walls(scene))


def boundary(scene: Scene) -> str:
    if scene.y_periodic:
        y = "p"
    elif any(w.servo is not None for w in scene.walls):
        y = "m"  # servo walls move: the box follows the particles
    elif scene.has_open_top:
        y = "fm"
    else:
        y = "f"
    return f"p {y} p"


def y_bounds(scene: Scene) -> tuple[float, float]:
    if scene.y_periodic:
        return 0.0, scene.box.size[1]
    lo = scene.wall_position("lower")
    hi = scene.wall_position("upper") if scene.wall("upper") else scene.box.size[1]
    return lo, hi


def data_file(scene: Scene, state: InitialState, bumps: list[BumpRow]) -> str:
    """LAMMPS data file (atom_style sphere) holding the initial state and any wall bumps."""
    atoms, velocities = data_rows(scene, state, bumps)
    lines = data_header(scene, len(atoms))
    lines += ["", "Atoms # sphere", "", format_rows(atoms)]
    lines += ["", "Velocities", "", format_rows(velocities)]
    return "\n".join(lines) + "\n"


def data_header(scene: Scene, n_atoms: int) -> list[str]:
    """The data file's header: atom count, atom types, box (triclinic under Lees–Edwards)."""
    lo_y, hi_y = y_bounds(scene)
    pad = 0.0 if scene.y_periodic else bump_padding(scene)  # bumps sit on the wall planes
    z = (0.0, scene.box.size[2]) if scene.dimension == 3 else (-0.5, 0.5)
    lines = [
        "demstudy initial state (dimensionless particle units: d = 1, m = 1)",
        "",
        f"{n_atoms} atoms",
        f"{n_atom_types(scene)} atom types",
        "",
        f"0 {fmt(scene.box.size[0])} xlo xhi",
        f"{fmt(lo_y - pad)} {fmt(hi_y + pad)} ylo yhi",
        f"{fmt(z[0])} {fmt(z[1])} zlo zhi",
    ]
    if scene.shear is not None:
        lines.append("0 0 0 xy xz yz")
    return lines


def data_rows(scene: Scene, state: InitialState,
              bumps: list[BumpRow]) -> tuple[np.ndarray, np.ndarray]:
    """The rows of the data file's Atoms (id type diameter density x y z) and Velocities
    (id vx vy vz wx wy wz) sections, particles then bumps, as floats."""
    dim = scene.dimension
    n = len(state.position)
    bump_xyz = [row.centres for row in bumps]
    nb = sum(len(c) for c in bump_xyz)
    # bumps: their wall's type, 1e6 times denser
    pos = np.zeros((n + nb, 3))
    pos[:n, :dim] = state.position
    if nb:
        pos[n:, :dim] = np.vstack(bump_xyz)
    diameter = np.concatenate([state.diameter] + [np.full(len(r.centres), r.diameter)
                                                  for r in bumps])
    types = np.concatenate([np.ones(n)] + [np.full(len(r.centres), bump_type(scene, r.side))
                                           for r in bumps])
    rho = DENSITY[3]  # 2D discs are re-densified with `set density/disc` after reading
    density = np.where(types > 1, rho * MASS_FACTOR, rho)
    ids = np.arange(1, n + nb + 1)
    atoms = np.column_stack([ids, types, diameter, density, pos])
    vel = np.zeros((n + nb, 6))
    vel[:n, :dim] = state.velocity
    if dim == 2:
        vel[:n, 5] = state.angular_velocity[:, 0]
    else:
        vel[:n, 3:] = state.angular_velocity
    return atoms, np.column_stack([ids, vel])


def sphere_mass(diameter: np.ndarray, density: np.ndarray) -> np.ndarray:
    """The mass ``read_data`` gives a sphere, bit for bit: LAMMPS's AtomVecSphere computes
    rmass = density * (4 pi / 3 * r * r * r), r = diameter / 2, in this order (the pinned
    LAMMPS; tests/test_lammps_engine.py compares the two set-ups)."""
    radius = 0.5 * diameter
    return density * (4.0 * math.pi / 3.0 * radius * radius * radius)


# 10**k for k = 0 … 27, exact in a long double with a 64-bit mantissa (5**27 < 2**64)
_POW10_LD = np.array([10**k for k in range(28)], dtype=np.longdouble)
_EXACT_LONGDOUBLE = np.finfo(np.longdouble).nmant >= 63
_BITS_5K = np.array([(5**k).bit_length() for k in range(28)])  # 10^k = 5^k 2^k
_E_MIN, _E_MAX = -11, 16  # decimal exponents of the vectorised path: 10^(16 - E) is exact
# the two characters of 00 … 99 as one little-endian uint16 each
_PAIRS = np.array([ord(f"{i:02d}"[0]) | ord(f"{i:02d}"[1]) << 8 for i in range(100)],
                  dtype=np.uint16)
# every field is laid out alike: sign, "0.000" (0.000ddd), each digit followed by a point,
# "e-XX", a separator; a mask per decimal exponent E and count of significant digits keeps
# the characters of %.17g's text
_LEAD, _FIRST, _EXP, _FIELD = 1, 6, 40, 45


def _masks() -> np.ndarray:
    """Characters kept for E = E_MIN … E_MAX and s = 1 … 17 significant digits (row
    (E - E_MIN) * 17 + s - 1), then for zero; the sign and the separator are set apart."""
    rows = []
    for e in range(_E_MIN, _E_MAX + 1):
        for s in range(1, 18):
            keep = np.zeros(_FIELD, dtype=bool)
            if e >= 0:  # d…d[.d…d]
                keep[_FIRST:_FIRST + 2 * max(e + 1, s):2] = True
                keep[_FIRST + 2 * e + 1] = s > e + 1
            elif e >= -4:  # 0.000d…d
                keep[_LEAD:_LEAD + 1 - e] = True
                keep[_FIRST:_FIRST + 2 * s:2] = True
            else:  # d[.d…d]e-XX
                keep[_FIRST:_FIRST + 2 * s:2] = True
                keep[_FIRST + 1] = s > 1
                keep[_EXP:_EXP + 4] = True
            rows.append(keep)
    zero = np.zeros(_FIELD, dtype=bool)
    zero[_LEAD] = True
    rows.append(zero)
    return np.array(rows)


_MASKS = _masks()


def format_rows(rows: np.ndarray, chunk: int = 4096) -> str:
    """Lines of space-separated numbers, each as ``"%.17g" % x`` writes it (so integral
    values such as IDs and types as integers), the same text as ``numpy.savetxt``; no
    newline after the last line. 17 significant digits: the text parses back to the very
    same doubles. Vectorised, in chunks of rows: ~10x faster than ``numpy.savetxt``, which
    formats row by row in Python (0.14 s for the 30 720 particles of a benchmark)."""
    rows = np.asarray(rows, dtype=np.float64)
    if rows.ndim != 2:
        raise ValueError(f"format_rows: 2D rows needed, got shape {rows.shape}")
    if not _EXACT_LONGDOUBLE:  # no 64-bit-mantissa long double here: Python's formatting
        return "\n".join(" ".join(f"{x:.17g}" for x in row) for row in rows.tolist())
    return "\n".join(_format_chunk(rows[i:i + chunk]) for i in range(0, len(rows), chunk))


def _format_chunk(rows: np.ndarray) -> str:
    n, c = rows.shape
    if n == 0:
        return ""
    x = rows.ravel()
    m = x.size
    a = np.abs(x)
    finite = np.isfinite(a) & (a > 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        exp10 = np.where(finite, np.floor(np.log10(a)), 0.0).astype(np.int64)
    # the 17 digits N = rint(|x| 10^(16 - E)) in [1e16, 1e17), from one rounding p of the
    # exact product by an exact power of ten (|p - exact| <= p 2^-64; exact when the
    # significant bits of x and of 5^(16-E) fit in 64): N is %.17g's correctly rounded
    # (half-even) integer unless the exact product may lie on the other side of a half or
    # of 1e16; those few (~1 % of inexact products) go to Python's formatting below. E is
    # that of the exact |x| (as %e's); log10 may be one off near powers of ten: corrected
    # here (a carry to 1e17 is E + 1).
    mantissa = (a.view(np.uint64) & np.uint64(2**52 - 1)) | np.uint64(2**52)
    lowest = (mantissa & (~mantissa + np.uint64(1))).astype(np.float64)  # 2^trailing zeros
    bits = 53 - np.log2(lowest).astype(np.int64)  # significant bits of x (normal numbers)
    digits = np.zeros(m, dtype=np.uint64)
    unsure = ~finite
    todo = finite.copy()
    for _ in range(3):
        todo &= (exp10 >= _E_MIN) & (exp10 <= _E_MAX)
        idx = np.flatnonzero(todo)
        if idx.size == 0:
            break
        p = a[idx].astype(np.longdouble) * _POW10_LD[16 - exp10[idx]]
        rounded = np.rint(p)
        error = p * np.longdouble(2.0**-63)
        inexact = bits[idx] + _BITS_5K[16 - exp10[idx]] > 64
        unsure[idx] = inexact & ((np.abs(np.abs(p - rounded) - 0.5) <= error)
                                 | (np.abs(p - np.longdouble(1e16)) <= error))
        digits[idx] = rounded.astype(np.uint64)
        high, low = rounded >= np.longdouble(1e17), p < np.longdouble(1e16)
        exp10[idx[high]] += 1
        exp10[idx[low]] -= 1
        todo[:] = False
        todo[idx[high | low]] = True
    unsure |= todo | (exp10 < _E_MIN) | (exp10 > _E_MAX)
    unsure &= a != 0.0
    exp10[unsure] = 0
    digits[unsure] = 10**16
    text = np.empty((n, c, _FIELD), dtype=np.uint8)
    flat = text.reshape(m, _FIELD)
    flat[:, 0] = ord("-")
    flat[:, _LEAD:_FIRST] = np.frombuffer(b"0.000", dtype=np.uint8)
    pairs = np.empty((m, 8), dtype=np.uint16)  # digits 1 … 16, two by two
    high, low = np.divmod(digits, np.uint64(10**8))
    for i, rest in ((7, low.astype(np.uint32)), (3, high.astype(np.uint32))):
        for j in range(i, i - 4, -1):
            quotient = rest // np.uint32(100)
            pairs[:, j] = _PAIRS[rest - quotient * np.uint32(100)]
            rest = quotient
    chars = pairs.view(np.uint8)
    flat[:, _FIRST] = ord("0") + rest.astype(np.uint8)  # the first digit
    flat[:, _FIRST + 2:_EXP:2] = chars
    flat[:, _FIRST + 1:_EXP:2] = ord(".")
    flat[:, _EXP:_EXP + 2] = np.frombuffer(b"e-", dtype=np.uint8)
    flat[:, _EXP + 2:_EXP + 4] = _PAIRS[np.clip(-exp10, 0, 99)].view(np.uint8).reshape(m, 2)
    flat[:, _FIELD - 1] = ord(" ")
    text[:, c - 1, _FIELD - 1] = ord("\n")
    nonzero = chars[:, ::-1] != ord("0")  # digits 16 … 1
    significant = np.where(nonzero.any(axis=1), 17 - np.argmax(nonzero, axis=1), 1)
    layout = np.where(a == 0.0, len(_MASKS) - 1, (exp10 - _E_MIN) * 17 + significant - 1)
    keep = _MASKS[layout]
    keep[:, 0] = np.signbit(x)
    keep[:, _FIELD - 1] = True
    for i in np.flatnonzero(unsure):  # near halves, outside 1e-11 … 1e17, inf, nan
        field = f"{x[i]:.17g}".encode()
        flat[i, :len(field)] = np.frombuffer(field, dtype=np.uint8)
        keep[i, :-1] = False
        keep[i, :len(field)] = True
    return flat[keep].tobytes()[:-1].decode("ascii")


def setup_block(scene: Scene, bumps: list[BumpRow]) -> Block:
    dim = scene.dimension
    cmds = [
        "units lj",
        "atom_style sphere",
        f"dimension {dim}",
        f"boundary {boundary(scene)}",
        "newton off",
        "comm_modify vel yes",
        f"read_data {DATA_FILE}",
    ]
    if dim == 2:
        # read_data gives sphere masses; discs need m = ρ π r² with ρ = 4/π
        cmds.append(f"set type 1 density/disc {DENSITY[2]:.15g}")
        cmds += [f"set type {bump_type(scene, row.side)} density/disc "
                 f"{DENSITY[2] * MASS_FACTOR:.15g}" for row in bumps]
    comment = (
        f"{'discs' if dim == 2 else 'spheres'}, {scene.n_particles} particles, "
        f"box {' x '.join(f'{s:g}' for s in scene.box.size)}, boundary {boundary(scene)}"
    )
    return Block("system", comment, cmds, stage="setup")


def groups_block(scene: Scene, bumps: list[BumpRow]) -> Block:
    cmds = ["group mobile type 1"]
    cmds += [f"group {bump_group(row.side)} type {bump_type(scene, row.side)}" for row in bumps]
    return Block("groups", "mobile particles" + (" and wall bumps" if bumps else ""), cmds)


def integrate_block(scene: Scene, setup: ContactSetup) -> Block:
    if scene.rotation_matters:
        disc = scene.dimension == 2 and abs(scene.inertia_k - 0.5) < 1e-12
        style = "nve/sphere" + (" disc" if disc else "")
        comment = "translation and rotation (velocity Verlet)"
    else:
        style = "nve"
        comment = "translation only: smooth contacts never change a spin"
    return Block("integrate", comment,
                 [f"fix integrate mobile {style}", f"timestep {setup.timestep:.10g}"])
