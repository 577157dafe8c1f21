"""The LGD step (Gutt 1989) behind one call: ``prepare`` and ``run_steps`` on a ``Lattice``,
natively (``demstudy._native.lgd_run``, the default) or by the numpy reference
(``impl="reference"``); the two agree bit for bit (tests/test_lgd_core.py).

Units: the listing's integers (``lattice`` module docstring); demstudy's dimensionless
particle units (d = 1, m = 1, g = 1 when gravity acts) apply above this module.

Inputs are validated before either implementation runs: the arrays' shapes and dtypes (the
``Lattice`` storage convention), ``nxt % 6 == 0``, ``nyt >= 4``, the wall rows (rows 1 and
nyt) made of wall particles moving at ``jx1``/``jx2``, ``mlp`` values, and the parameters the
integer arithmetic divides by.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from . import reference
from .lattice import STEP_LOG_FIELDS, WALL, Lattice, LgdParams

__all__ = ["IMPLEMENTATIONS", "prepare", "run_steps", "validate"]

IMPLEMENTATIONS = ("native", "reference")

_DTYPES = {"mlp": np.int8, "ipx": np.int64, "ipy": np.int64, "ivx": np.int64,
           "ivy": np.int64, "nlp": np.int32}


def _bad(field: str, value, allowed: str) -> ValueError:
    return ValueError(f"LGD {field} = {value!r}: {allowed}")


def _validate_params(par: LgdParams) -> LgdParams:
    p = par.resolved()
    if not (isinstance(p.nxt, int) and p.nxt >= 6 and p.nxt % 6 == 0):
        raise _bad("nxt", p.nxt, "must be a positive multiple of 6 (move templates have "
                   "period 3, collision templates period 2)")
    if not (isinstance(p.nyt, int) and p.nyt >= 4):
        raise _bad("nyt", p.nyt, "must be an integer >= 4 (two wall rows and two open rows)")
    for name in ("idl", "idx", "idy", "ke", "kq", "kx", "ky"):
        value = getattr(p, name)
        if not (isinstance(value, (int, np.integer)) and value > 0):
            raise _bad(name, value, "must be a positive integer")
    for name in ("id", "icb", "iep1", "iep2", "iew1", "iew2", "ntu"):
        value = getattr(p, name)
        if not (isinstance(value, (int, np.integer)) and value >= 0):
            raise _bad(name, value, "must be an integer >= 0")
    for name in ("igx", "igy", "jx1", "jx2"):
        value = getattr(p, name)
        if not isinstance(value, (int, np.integer)):
            raise _bad(name, value, "must be an integer")
    return p


def validate(lat: Lattice, par: LgdParams) -> LgdParams:
    """Check ``lat`` and ``par`` (ValueError naming the field, the value and what is allowed);
    returns the resolved parameters."""
    p = _validate_params(par)
    shape = (p.nyt, p.nxt)
    for name, dtype in _DTYPES.items():
        a = getattr(lat, name)
        if not isinstance(a, np.ndarray):
            raise _bad(f"lattice.{name}", type(a).__name__, "must be a numpy array")
        if a.shape != shape:
            raise _bad(f"lattice.{name}.shape", a.shape, f"must be (nyt, nxt) = {shape}")
        if a.dtype != dtype:
            raise _bad(f"lattice.{name}.dtype", str(a.dtype), f"must be {np.dtype(dtype)}")
        if not a.flags.c_contiguous or not a.flags.writeable:
            raise _bad(f"lattice.{name}", "non-contiguous or read-only",
                       "must be a writeable C-contiguous array (it is updated in place)")
    bad = ~np.isin(lat.mlp, (-1, 0, 1, 2))
    if bad.any():
        r, c = np.argwhere(bad)[0]
        raise _bad(f"lattice.mlp[{r}, {c}]", int(lat.mlp[r, c]),
                   "must be -1 (wall), 0 (empty), 1 (movable) or 2 (moved)")
    for row, name, speed in ((0, "row 1 (bottom)", p.jx1), (p.nyt - 1, "row nyt (top)", p.jx2)):
        not_wall = np.flatnonzero(lat.mlp[row] != WALL)
        if not_wall.size:
            raise _bad(f"lattice.mlp[{row}, {not_wall[0]}]", int(lat.mlp[row, not_wall[0]]),
                       f"{name} is a wall row: every site must be -1")
        off = np.flatnonzero(lat.ivx[row] != speed)
        if off.size:
            raise _bad(f"lattice.ivx[{row}, {off[0]}]", int(lat.ivx[row, off[0]]),
                       f"{name} walls move at jx{1 if row == 0 else 2} = {speed}")
    if not (isinstance(lat.nn, (int, np.integer)) and lat.nn >= 1):
        raise _bad("lattice.nn", lat.nn, "must be an integer >= 1 (the next step's number)")
    if len(tuple(lat.pv)) != 3:
        raise _bad("lattice.pv", lat.pv, "must be (v², vx, vy) of the peak-speed grain")
    return p


def prepare(lat: Lattice, par: LgdParams) -> Lattice:
    """Count the movable grains (``lat.ng``) and find the initial peak-speed grain
    (``lat.pv``), as the listing's main does before its time loop; returns ``lat``."""
    validate(lat, par)
    return reference.prepare(lat, par)


def run_steps(lat: Lattice, par: LgdParams, n_steps: int,
              impl: str = "native") -> dict[str, np.ndarray]:
    """Advance ``lat`` in place by ``n_steps`` steps; returns one int64 array of length
    ``n_steps`` per name in ``STEP_LOG_FIELDS``. ``impl``: "native" (C++) or "reference"
    (numpy). Call ``prepare`` once before the first step."""
    if impl not in IMPLEMENTATIONS:
        raise _bad("impl", impl, f"must be one of {IMPLEMENTATIONS}")
    if not (isinstance(n_steps, (int, np.integer)) and n_steps >= 0):
        raise _bad("n_steps", n_steps, "must be an integer >= 0")
    validate(lat, par)
    if impl == "reference":
        return reference.run_steps(lat, par, int(n_steps))
    from ..._native import lgd_run

    params = dataclasses.asdict(reference.derive(par))
    params["nw"] = reference.extra_wall_count(lat)
    scalars = (*(int(v) for v in lat.pv), int(lat.nn), int(lat.itt))
    table, (pv2, pvx, pvy, nn, itt) = lgd_run(lat.mlp, lat.ipx, lat.ipy, lat.ivx, lat.ivy,
                                              lat.nlp, params, scalars, int(n_steps))
    lat.pv, lat.nn, lat.itt = (pv2, pvx, pvy), nn, itt
    return {name: table[:, k].copy() for k, name in enumerate(STEP_LOG_FIELDS)}
