"""Serial numpy port of the step of Gutt's (1989) lattice grain dynamics (LGD), with the C
listing's integer semantics (thesis App. 3; ../shared/reference/gutt1989.md §3).

Units: the listing's integers (``lattice`` module docstring): offsets in idl/4096-cm units,
velocities in 1/256 cm/s, time in 1/65536 s ticks. The backend converts to demstudy's
dimensionless particle units (d = 1, m = 1, g = 1 when gravity acts). This module is the
bit-exact reference the native core ``demstudy._native.lgd_run`` is tested against.

One step (main's time loop, listing L2079–L2609):

1. time step ``it`` (§3.5): without gravity ``it = (int)(idl·4096/pv1 + .5)`` or 1 when every
   grain is at rest; with gravity the integer search from t_min in doubles, which uses the
   row spacing ``idy`` as "d" (as the listing does) and is capped by ``itm``;
2. gravity kick and offset drift (§3.6) on every grain with mlp == 1;
3. ``ntu`` passes of the 9 move templates in the listing's order (§3.7, ``uppo``);
4. the 12 collision sub-sweeps, odd/even order (§3.8, ``colb``, ``colc``, ``colf``);
5. wall sums is1/ip1 (row 1), is2/ip2 (row nyt), then is3/ip3 over every other wall
   particle, resetting the accumulators (L2319–L2460; not divided by nxt or nw here);
6. statistics over movable grains, the peak-speed grain for the next ``it``, mlp 2 → 1, and
   nq (grains with user column ix > nxt/2) only when extra walls exist;
7. nn += 1, itt += it.

Semantics kept from the C code:
* every division is C's truncation toward zero (negative numerators occur in the drift, the
  move sector slope ``islope``, the offset projections and ``kc1``); the rounding offsets
  ``+kx``, ``+kxp``, ``+kxw``, ``+ke``, ``+ke2`` are added, not symmetric; gravity's ``igt``
  and ``idp`` round half away from zero; the time step uses IEEE doubles as the C code does;
* the peak-speed grain is the first maximum of v² in storage order (row R, then column G),
  which is what the serial scan with the strict ``>`` keeps;
* integers are int64 (the NCUBE's ``long`` was 32 bits; results agree with the listing as
  long as no 32-bit product overflows there).

Serial replacements and reconstructions (each a documented choice, not thesis text):
* halo exchange → periodic columns (G wraps mod nxt); rows are not periodic: row 1 and row
  nyt are walls, so ``colb`` of row nyt and ``colf`` of row 1 have no partner (the listing's
  ghost rows are empty), and the parallel ghost filter of ``uppo`` has no serial analogue;
* ``colf``'s missing page (L3062–L3066): its header and guard are taken as colb's mirror
  (partner m1 = (G + 1, R − 1) inside the lattice, columns periodic); the wall-at-m0 branch
  is reconstructed as the mirror
  of ``colb``'s with the f signs (digest §3.13): wall ``ipx -= ikcx, ipy += ikcy``, grain
  ``ivx += ikcx, ivy -= ikcy``, then the f projection of the grain's offset;
* the OCR's undeclared ``kyp``/``kyw`` (colb/colf) are read as ``kxp``/``kxw``;
* ``ix == iy == 0`` with ``id == 0`` falls to the listing's "+y" branch (b on odd rows R, a on
  even rows), as the C ``else`` does;
* nw (extra wall particles) = walls outside rows 1 and nyt; walls never move or vanish, so
  it is computed from ``mlp`` rather than stored;
* nq uses the listing's user column ix = ((G + (R − 1)/2 − 1) mod nxt) + 1 > nxt/2;
* as in the listing, ``prepare`` does not clear wall accumulators (a wall's input offset is
  summed in step 1), and a grain given mlp == 2 on input skips the first drift and moves.

Within one move template the sources are ≥ 3 apart in G or R and never compete for a target,
and within one collision template and direction the pairs are disjoint, so each is one
vectorised numpy update with the sequential C loop's result.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .lattice import EMPTY, MOVABLE, MOVED, STEP_LOG_FIELDS, WALL, Lattice, LgdParams

__all__ = ["MOVE_TEMPLATES", "Derived", "cdiv", "collide", "collision_order", "derive",
           "extra_wall_count", "gravity_increments", "move_template", "prepare", "run_steps",
           "time_step"]

#: (G mod 3, R mod 3) of the 9 move templates in the listing's order (L2133–L2186)
MOVE_TEMPLATES = ((0, 0), (2, 1), (1, 2), (2, 0), (1, 1), (0, 2), (1, 0), (0, 1), (2, 2))

#: collision templates 1–4 as (G parity, R parity) of Gutt's 1-based G, R (digest §3.8)
_COLLISION_TEMPLATES = {1: (0, 0), 2: (1, 0), 3: (0, 1), 4: (1, 1)}
_ODD_ORDER = ((3, "b"), (3, "c"), (3, "f"), (2, "f"), (2, "c"), (2, "b"),
              (4, "b"), (4, "c"), (4, "f"), (1, "f"), (1, "c"), (1, "b"))

# move directions: (dc, dr, sign of idx or id2 in the offset correction, which, sign of idy)
# with the correction (icx, icy) = minus the lattice vector to the target (digest §3.7)
_D, _B, _A, _C, _E, _F = range(6)


@dataclass(frozen=True)
class Derived:
    """The listing's derived constants (L1677–L1705, L1828–L1830)."""

    idl: int
    id: int
    idx: int
    idy: int
    id2: int
    icb: int
    icp: int
    icw: int
    iep1: int  # ke·(1 + e1) after the listing's ``iep1 += ke``
    iep2: int
    iew1: int
    iew2: int
    ke: int
    ke1: int
    ke2: int
    kx: int
    ky: int
    kq: int
    kxp: int
    kxw: int
    kqp: int
    kqw: int
    igx: int
    igy: int
    jx1: int
    jx2: int
    ntu: int
    gm: float
    gm2: float
    itm: int
    dl3: float
    dy1: float
    dy3: float


def derive(par: LgdParams) -> Derived:
    """The listing's constants from the parameter-file fields (None fields resolved)."""
    p = par.resolved()
    gm = math.sqrt(float(p.igx * p.igx + p.igy * p.igy))
    itm = int(1024.0 * math.sqrt(2.0 * float(p.idl) / gm) + 0.5) if gm > 0.0 else 0
    return Derived(
        idl=p.idl, id=p.id, idx=p.idx, idy=p.idy, id2=2 * p.idx, icb=p.icb,
        icp=p.icb * (p.iep1 - p.iep2), icw=p.icb * (p.iew1 - p.iew2),
        iep1=p.iep1 + p.ke, iep2=p.iep2, iew1=p.iew1 + p.ke, iew2=p.iew2,
        ke=p.ke, ke1=2 * p.ke, ke2=p.ke // 2, kx=p.kx, ky=p.ky, kq=p.kq,
        kxp=2 * p.ke * p.kx, kxw=p.ke * p.kx, kqp=2 * p.ke * p.kq, kqw=p.ke * p.kq,
        igx=p.igx, igy=p.igy, jx1=p.jx1, jx2=p.jx2, ntu=p.ntu, gm=gm, gm2=gm * gm, itm=itm,
        dl3=float(p.idl) * 4096.0, dy1=float(p.idy) * 16.0, dy3=float(p.idy) * 4096.0)


def cdiv(a, b):
    """C's integer division (truncation toward zero) for int64 arrays or ints; b != 0."""
    if isinstance(a, (int, np.integer)) and isinstance(b, (int, np.integer)):
        q = abs(int(a)) // abs(int(b))
        return -q if (a < 0) != (b < 0) else q
    a = np.asarray(a, np.int64)
    q = np.abs(a) // np.abs(b)
    return np.where((a < 0) != (np.asarray(b) < 0), -q, q)


def _sqrt(x: float) -> float:
    """C's sqrt: NaN (not an exception) for a negative argument."""
    return math.sqrt(x) if x >= 0.0 else math.nan


def time_step(pv: tuple[int, int, int], c: Derived) -> int:
    """The step's ``it`` in ticks from the previous step's peak-speed grain (v², vx, vy),
    exactly as L2081–L2105 in doubles."""
    pv2 = float(pv[0])
    pv1 = math.sqrt(pv2)
    if c.gm == 0.0:
        return int(c.dl3 / pv1 + 0.5) if pv1 > 0.0 else 1
    gv = float(c.igx * pv[1] + c.igy * pv[2])
    it = int(2.0 * c.dy3 / (math.sqrt(pv2 + 2.0 * c.dy1 * c.gm) + pv1) + 0.5) - 1
    rt = float(it) / 256.0
    dp = rt * _sqrt((0.25 * c.gm2 * rt + gv) * rt + pv2) - c.dy1
    while True:
        dl = dp
        it += 1
        rt = float(it) / 256.0
        dp = rt * _sqrt((0.25 * c.gm2 * rt + gv) * rt + pv2) - c.dy1
        if not (dp < 0.0 and it < c.itm):
            break
    if dp > -dl:  # the overshoot exceeds the undershoot: the smaller it
        it -= 1
    return it


def _round_half_away(x: float) -> int:
    return int(x + (-0.5 if x < 0 else 0.5))


def gravity_increments(it: int, c: Derived) -> tuple[int, int, int, int]:
    """(igt_x, igt_y, idp_x, idp_y): the velocity kick g·it and the half kick used in the
    drift, each rounded half away from zero (L2107–L2114)."""
    gx = float(c.igx * it) / 256.0
    gy = float(c.igy * it) / 256.0
    return (_round_half_away(gx), _round_half_away(gy),
            _round_half_away(gx / 2.0), _round_half_away(gy / 2.0))


def collision_order(nn: int) -> tuple[tuple[int, str], ...]:
    """The 12 (template, bond) sub-sweeps of step nn: odd steps 3b 3c 3f 2f 2c 2b 4b 4c 4f 1f
    1c 1b, even steps the reverse (L2189–L2317)."""
    return _ODD_ORDER if nn % 2 else tuple(reversed(_ODD_ORDER))


def _peak(lat: Lattice) -> tuple[int, int, int]:
    """First grain (storage order) with the largest v² > 0 among movable grains, else 0s."""
    v2 = lat.ivx * lat.ivx + lat.ivy * lat.ivy
    v2 = np.where(lat.mlp > 0, v2, -1).ravel()
    if v2.size == 0:
        return (0, 0, 0)
    k = int(np.argmax(v2))
    if v2[k] <= 0:
        return (0, 0, 0)
    return (int(v2[k]), int(lat.ivx.ravel()[k]), int(lat.ivy.ravel()[k]))


def extra_wall_count(lat: Lattice) -> int:
    """nw: wall particles outside the wall rows 1 and nyt (the listing's nw − 2·nxt)."""
    return int(np.count_nonzero(lat.mlp[1:-1] == WALL))


def prepare(lat: Lattice, par: LgdParams) -> Lattice:
    """Count the movable grains ``ng`` and find the initial peak-speed grain ``pv`` (main
    L2008–L2046); ``nn`` and ``itt`` are left as they are. Returns ``lat``."""
    del par  # the count needs no parameter; kept for a uniform signature with the core
    lat.ng = int(np.count_nonzero(lat.mlp > 0))
    lat.pv = _peak(lat)
    return lat


def move_template(lat: Lattice, c: Derived, a: int, b: int) -> None:
    """``uppo`` on every mlp == 1 site with G ≡ a, R ≡ b (mod 3), G and R 1-based."""
    nyt, nxt = lat.mlp.shape
    rows = np.arange((b - 1) % 3, nyt, 3)
    cols = np.arange((a - 1) % 3, nxt, 3)
    rr, cc = np.meshgrid(rows, cols, indexing="ij")
    s = (rr * nxt + cc).ravel()
    mlp = lat.mlp.reshape(-1)
    s = s[mlp[s] == MOVABLE]
    if s.size == 0:
        return
    ipx, ipy = lat.ipx.reshape(-1), lat.ipy.reshape(-1)
    ix, iy = ipx[s], ipy[s]
    small = (np.abs(ix) < c.idl) & (np.abs(iy) < c.idl)
    inside = small & (np.where(small, ix * ix + iy * iy, 0) < c.id)
    mlp[s[inside]] = MOVED  # inside the circle: no move this step (mlp++)
    go = ~inside
    s, ix, iy = s[go], ix[go], iy[go]
    if s.size == 0:
        return
    r = s // nxt
    islope = cdiv(256 * iy, np.where(ix == 0, 1, ix))
    odd_row = (r % 2) == 0  # Gutt's row R = r + 1 is odd
    dirn = np.select(
        [(ix > 0) & (islope <= -148), (ix > 0) & (islope < 148), ix > 0,
         (ix < 0) & (islope >= 148), (ix < 0) & (islope > -148), ix < 0,
         iy < 0],
        [_F, _D, _B, _E, _C, _A, np.where(odd_row, _F, _E)],
        np.where(odd_row, _B, _A))
    # (dc, dr) and the offset correction per direction d, b, a, c, e, f
    dcs = np.array([1, 0, -1, -1, 0, 1])
    drs = np.array([0, 1, 1, 0, -1, -1])
    icxs = np.array([-c.id2, -c.idx, c.idx, c.id2, c.idx, -c.idx], np.int64)
    icys = np.array([0, -c.idy, -c.idy, 0, c.idy, c.idy], np.int64)
    t = (r + drs[dirn]) * nxt + (s % nxt + dcs[dirn]) % nxt
    free = mlp[t] == EMPTY
    s, t, dirn = s[free], t[free], dirn[free]
    ivx, ivy, nlp = lat.ivx.reshape(-1), lat.ivy.reshape(-1), lat.nlp.reshape(-1)
    ipx[t] = ipx[s] + icxs[dirn]
    ipy[t] = ipy[s] + icys[dirn]
    ivx[t] = ivx[s]
    ivy[t] = ivy[s]
    mlp[t] = mlp[s] + 1
    nlp[t] = nlp[s]
    ipx[s] = ipy[s] = ivx[s] = ivy[s] = 0
    mlp[s] = EMPTY
    nlp[s] = 0


def _impulse(kc1: np.ndarray, wall: np.ndarray, c: Derived) -> np.ndarray:
    """ikc = ke·(1+e)·kc with the piecewise restitution (pair or wall coefficients)."""
    e1 = np.where(wall, c.iew1, c.iep1)
    e2 = np.where(wall, c.iew2, c.iep2)
    icx = np.where(wall, c.icw, c.icp)
    above = np.maximum(icx + e2 * kc1, 0) + c.ke * kc1
    return np.where(kc1 <= c.icb, e1 * kc1, above)


def collide(lat: Lattice, c: Derived, template: int, bond: str) -> None:
    """``colb``/``colc``/``colf`` on every non-empty site of one collision template."""
    nyt, nxt = lat.mlp.shape
    gpar, rpar = _COLLISION_TEMPLATES[template]
    # G = c + 1 has parity gpar ⇔ c ≡ 1 − gpar (mod 2); likewise for rows
    r_lo, r_hi = (0, nyt - 1) if bond == "b" else (1, nyt) if bond == "f" else (0, nyt)
    rows = np.arange((1 - rpar) % 2, nyt, 2)
    rows = rows[(rows >= r_lo) & (rows < r_hi)]
    cols = np.arange((1 - gpar) % 2, nxt, 2)
    rr, cc = np.meshgrid(rows, cols, indexing="ij")
    dr, dc = {"b": (1, 0), "c": (0, -1), "f": (-1, 1)}[bond]
    m0 = (rr * nxt + cc).ravel()
    m1 = ((rr + dr) * nxt + (cc + dc) % nxt).ravel()
    mlp = lat.mlp.reshape(-1)
    a0, a1 = mlp[m0], mlp[m1]
    keep = (a0 != EMPTY) & (a1 != EMPTY) & ((a0 > 0) | (a1 > 0))
    m0, m1, a0, a1 = m0[keep], m1[keep], a0[keep], a1[keep]
    if m0.size == 0:
        return
    ipx, ipy = lat.ipx.reshape(-1), lat.ipy.reshape(-1)
    ivx, ivy = lat.ivx.reshape(-1), lat.ivy.reshape(-1)
    w0, w1 = a0 == WALL, a1 == WALL
    wall = w0 | w1
    if bond == "c":
        kc1 = ivx[m1] - ivx[m0]
        hit = kc1 > 0
        m0, m1, w0, w1, wall, kc1 = m0[hit], m1[hit], w0[hit], w1[hit], wall[hit], kc1[hit]
        ikc = _impulse(kc1, wall, c)
        ikcx = np.where(wall, cdiv(ikc + c.ke2, c.ke), cdiv(ikc + c.ke, c.ke1))
        # k = (−1, 0) from m0 to m1: Δv0 = +ikcx, Δv1 = −ikcx; a wall gets −Δv(partner)
        ivx[m0[~w0]] += ikcx[~w0]
        ivx[m1[~w1]] -= ikcx[~w1]
        ipx[m0[w0]] += ikcx[w0]
        ipx[m1[w1]] -= ikcx[w1]
        ipx[m0[~w0]] = 0  # offset projection: drop the component along k
        ipx[m1[~w1]] = 0
        return
    sy = 1 if bond == "b" else -1  # k = (½, sy·√3/2)
    kc1 = cdiv(c.kx * (ivx[m0] - ivx[m1]) + sy * c.ky * (ivy[m0] - ivy[m1]) + c.kx, c.kq)
    hit = kc1 > 0
    m0, m1, w0, w1, wall, kc1 = m0[hit], m1[hit], w0[hit], w1[hit], wall[hit], kc1[hit]
    ikc = _impulse(kc1, wall, c)
    add = np.where(wall, c.kxw, c.kxp)
    den = np.where(wall, c.kqw, c.kqp)
    dvx = cdiv(c.kx * ikc + add, den)  # Δv of m1 = (ikcx, sy·ikcy); Δv of m0 = −that
    dvy = sy * cdiv(c.ky * ikc + add, den)
    g0, g1 = ~w0, ~w1
    ivx[m0[g0]] -= dvx[g0]
    ivy[m0[g0]] -= dvy[g0]
    ivx[m1[g1]] += dvx[g1]
    ivy[m1[g1]] += dvy[g1]
    ipx[m0[w0]] -= dvx[w0]  # wall accumulators: minus the grain's Δv
    ipy[m0[w0]] -= dvy[w0]
    ipx[m1[w1]] += dvx[w1]
    ipy[m1[w1]] += dvy[w1]
    for m in (m0[g0], m1[g1]):  # keep the offset component perpendicular to k
        ip = cdiv(c.idy * ipx[m] - sy * c.idx * ipy[m], c.id2)
        ipx[m] = cdiv(ip * c.idy, c.id2)
        ipy[m] = cdiv(-sy * ip * c.idx, c.id2)


def _step(lat: Lattice, c: Derived, nw: int) -> list[int]:
    it = time_step(lat.pv, c)
    igtx, igty, idpx, idpy = gravity_increments(it, c)
    mov = lat.mlp == MOVABLE
    lat.ipx[mov] += cdiv((lat.ivx[mov] + idpx) * it, 4096)
    lat.ipy[mov] += cdiv((lat.ivy[mov] + idpy) * it, 4096)
    lat.ivx[mov] += igtx
    lat.ivy[mov] += igty
    for _ in range(c.ntu):
        for a, b in MOVE_TEMPLATES:
            move_template(lat, c, a, b)
    for template, bond in collision_order(lat.nn):
        collide(lat, c, template, bond)
    sums = []
    for row in (0, -1):  # is1, ip1 (row 1) then is2, ip2 (row nyt)
        sums += [int(lat.ipx[row].sum()), int(lat.ipy[row].sum())]
        lat.ipx[row] = 0
        lat.ipy[row] = 0
    walls = lat.mlp == WALL
    sums += [int(lat.ipx[walls].sum()), int(lat.ipy[walls].sum())]  # is3, ip3
    lat.ipx[walls] = 0
    lat.ipy[walls] = 0
    grains = lat.mlp > 0
    nq = 0
    if nw > 0:
        nyt, nxt = lat.mlp.shape
        r, col = np.nonzero(grains)
        nq = int(np.count_nonzero((col + r // 2) % nxt + 1 > nxt // 2))
    lat.mlp[lat.mlp == MOVED] = MOVABLE
    vx, vy = lat.ivx[grains], lat.ivy[grains]
    lat.pv = _peak(lat)
    lat.itt += it
    out = [lat.nn, it, lat.itt, int(vx.sum()), int(vy.sum()), int((vx * vx + vy * vy).sum()),
           lat.pv[0], *sums, nq]
    lat.nn += 1
    return out


def run_steps(lat: Lattice, par: LgdParams, n_steps: int) -> dict[str, np.ndarray]:
    """Advance ``lat`` (mutated in place) by ``n_steps`` steps; returns the step log, one
    int64 array of length n_steps per name in ``STEP_LOG_FIELDS``. Call ``prepare`` first
    (it sets the initial ``pv``)."""
    c = derive(par)
    nw = extra_wall_count(lat)
    rows = [_step(lat, c, nw) for _ in range(int(n_steps))]
    table = np.array(rows, np.int64).reshape(-1, len(STEP_LOG_FIELDS))
    return {name: table[:, k].copy() for k, name in enumerate(STEP_LOG_FIELDS)}
