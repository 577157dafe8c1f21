"""The LGD step (Gutt 1989, App. 3): hand-computed moves and collisions, exact momentum
bookkeeping, grain conservation, the time-step rule, and the native core against the numpy
reference bit for bit.

Units: the listing's integers (offsets idl/4096, velocities 1/256 cm/s, ticks 1/65536 s);
dimensionless particle units (d = 1, m = 1, g = 1) only above this core. Defaults used in the
arithmetic below: idl = 4096, idx = 2048, id2 = 4096, idy = round(4096·√3/2) = 3547,
id = 2048² = 4194304, kq = 1560, kx = 780, ky = 1351, ke = 16, so kxp = 2·16·780 = 24960,
kqp = 2·16·1560 = 49920, kxw = 16·780 = 12480, kqw = 16·1560 = 24960, ke1 = 32, ke2 = 8.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from demstudy.engines.lgd import core
from demstudy.engines.lgd import reference as ref
from demstudy.engines.lgd.lattice import MOVABLE, WALL, Lattice, LgdParams


def box(nxt: int = 12, nyt: int = 6, jx1: int = 0, jx2: int = 0) -> Lattice:
    lat = Lattice.empty(nxt, nyt)
    lat.mlp[0] = lat.mlp[-1] = WALL
    lat.ivx[0], lat.ivx[-1] = jx1, jx2
    return lat


def grain(lat, r, c, v=(0, 0), p=(0, 0), mode=MOVABLE):
    lat.mlp[r, c] = mode
    lat.ivx[r, c], lat.ivy[r, c] = v
    lat.ipx[r, c], lat.ipy[r, c] = p


def where_grains(lat):
    return {(int(r), int(c)) for r, c in zip(*np.nonzero(lat.mlp > 0), strict=True)}


# --------------------------------------------------------------------------- moves
# one step at rest without gravity: it = 1, the drift adds (0·1)/4096 = 0, no pair approaches
# (kc1 = (0 + kx)/kq = 780/1560 = 0), so only the move acts.
@pytest.mark.parametrize("r, offset, target, new_offset", [
    (2, (5000, 0), (2, 5), (5000 - 4096, 0)),  # islope 0 → d, correction (−id2, 0)
    (2, (3000, 3000), (3, 4), (3000 - 2048, 3000 - 3547)),  # islope 256 → b
    (2, (3000, -3000), (1, 5), (3000 - 2048, -3000 + 3547)),  # islope −256 → f
    (2, (-3000, 3000), (3, 3), (-3000 + 2048, 3000 - 3547)),  # 768000/−3000 = −256 → a
    (2, (-3000, -3000), (1, 4), (-3000 + 2048, -3000 + 3547)),  # +256 with ix < 0 → e
    (2, (-5000, 100), (2, 3), (-5000 + 4096, 100)),  # 25600/−5000 = −5.12 → −5 → c
    # −443904/3000 = −147.968: C truncates to −147 → d (a floor would give −148 → f)
    (2, (3000, -1734), (2, 5), (3000 - 4096, -1734)),
    # 443904/−3000 = −147.968 → −147 > −148 → c (a floor would give a)
    (2, (-3000, 1734), (2, 3), (-3000 + 4096, 1734)),
    # |ix|, |iy| < idl but 2000² + 1000² = 5e6 ≥ id: moves, islope 128 → d
    (2, (2000, 1000), (2, 5), (2000 - 4096, 1000)),
    # ix == 0: array row 2 is Gutt's odd row R = 3 → right (b up, f down)
    (2, (0, 3000), (3, 4), (-2048, 3000 - 3547)),
    (2, (0, -3000), (1, 5), (-2048, -3000 + 3547)),
    # array row 3 is the even row R = 4 → left (a up, e down)
    (3, (0, 3000), (4, 3), (2048, 3000 - 3547)),
    (3, (0, -3000), (2, 4), (2048, -3000 + 3547)),
    # offset beyond two spacings: one site per step only
    (2, (9000, 0), (2, 5), (9000 - 4096, 0)),
])
def test_single_move(r, offset, target, new_offset):
    lat, par = box(), LgdParams(nxt=12, nyt=6)
    grain(lat, r, 4, p=offset)
    lat.nlp[r, 4] = 7
    core.prepare(lat, par)
    log = core.run_steps(lat, par, 1, impl="reference")
    assert log["it"][0] == 1
    assert where_grains(lat) == {target}
    assert (lat.ipx[target], lat.ipy[target]) == new_offset
    assert lat.nlp[target] == 7 and lat.mlp[target] == MOVABLE


def test_inside_circle_stays():
    lat, par = box(), LgdParams(nxt=12, nyt=6)
    grain(lat, 2, 4, p=(1000, -1500))  # 1e6 + 2.25e6 < id = 4194304
    core.prepare(lat, par)
    core.run_steps(lat, par, 3, impl="reference")
    assert where_grains(lat) == {(2, 4)}
    assert (lat.ipx[2, 4], lat.ipy[2, 4]) == (1000, -1500)


def test_periodic_wrap_and_blocking():
    lat, par = box(), LgdParams(nxt=12, nyt=6)
    grain(lat, 2, 11, p=(5000, 0))  # d from the last column wraps to column 0
    grain(lat, 3, 4, p=(3000, 3000))  # b target (4, 4) is free
    grain(lat, 4, 7, p=(3000, 3000))  # b target is the top wall (row 5): blocked
    grain(lat, 1, 2, p=(5000, 0))  # d target (1, 3) is occupied by a grain at rest
    grain(lat, 1, 3)
    core.prepare(lat, par)
    core.run_steps(lat, par, 1, impl="reference")
    assert where_grains(lat) == {(2, 0), (4, 4), (4, 7), (1, 2), (1, 3)}
    assert (lat.ipx[4, 7], lat.ipy[4, 7]) == (3000, 3000)
    assert lat.ipx[1, 2] == 5000


def test_drift_truncates_negative_numerators():
    # v = (−1000, 0), no gravity: it = (int)(4096·4096/1000 + .5) = 16777; the drift adds
    # (−1000·16777)/4096 = −4095.947 → −4095 (a floor would give −4096); then |ix| = 4095 <
    # idl but ix² > id: the grain moves c with offset −4095 + 4096 = 1
    lat, par = box(), LgdParams(nxt=12, nyt=6)
    grain(lat, 2, 4, v=(-1000, 0))
    core.prepare(lat, par)
    log = core.run_steps(lat, par, 1, impl="reference")
    assert log["it"][0] == 16777
    assert where_grains(lat) == {(2, 3)}
    assert (lat.ipx[2, 3], lat.ipy[2, 3]) == (1, 0)


def test_gravity_kick_rounds_half_away():
    # igy = −3, it = 128 (chosen): gt = −3·128/256 = −1.5 → igt = −2, gt/2 = −0.75 → idp = −1
    c = ref.derive(LgdParams(nxt=12, nyt=6, igy=-3))
    assert ref.gravity_increments(128, c) == (0, -2, 0, -1)
    assert ref.gravity_increments(64, c) == (0, -1, 0, 0)  # −0.75 → −1, −0.375 → 0


# --------------------------------------------------------------------------- collisions
def derived(**kw) -> ref.Derived:
    return ref.derive(LgdParams(nxt=12, nyt=6, **kw))


def test_b_pair_below_cb_and_negative_projection():
    lat = box()
    grain(lat, 2, 3, v=(0, 1000), p=(-1000, 300))  # m0: G = 4 even, R = 3 odd: template 3
    grain(lat, 3, 3)  # b partner (ΔG, ΔR) = (0, +1)
    c = derived(icb=2000, iep1=12)  # e1 = .75: iep1 = 12 + 16 = 28
    ref.collide(lat, c, 3, "b")
    # kc1 = (780·0 + 1351·1000 + 780)/1560 = 1351780/1560 = 866; ikc = 28·866 = 24248
    # ikcx = (780·24248 + 24960)/49920 = 18938400/49920 = 379
    # ikcy = (1351·24248 + 24960)/49920 = 32784008/49920 = 656
    assert (lat.ivx[2, 3], lat.ivy[2, 3]) == (-379, 1000 - 656)
    assert (lat.ivx[3, 3], lat.ivy[3, 3]) == (379, 656)
    # ip = (3547·(−1000) − 2048·300)/4096 = −4161400/4096 = −1015 (truncated; floor −1016)
    # ipx = (−1015·3547)/4096 = −3600205/4096 = −878; ipy = (1015·2048)/4096 = 507
    assert (lat.ipx[2, 3], lat.ipy[2, 3]) == (-878, 507)


def test_b_pair_above_cb():
    lat = box()
    grain(lat, 2, 3, v=(0, 1000))
    grain(lat, 3, 3)
    c = derived(icb=500, iep1=12, iep2=15)
    # icp = 500·(12 − 15) = −1500 (before iep1 += ke); kc1 = 866 > 500:
    # ikc = max(−1500 + 15·866, 0) + 16·866 = 11490 + 13856 = 25346
    #     (= 16[(1 + 15/16)·866 + (12/16 − 15/16)·500] = 26846 − 1500)
    # ikcx = (780·25346 + 24960)/49920 = 19794840/49920 = 396
    # ikcy = (1351·25346 + 24960)/49920 = 34267406/49920 = 686
    ref.collide(lat, c, 3, "b")
    assert (lat.ivx[3, 3], lat.ivy[3, 3]) == (396, 686)
    assert (lat.ivx[2, 3], lat.ivy[2, 3]) == (-396, 1000 - 686)


def test_b_moving_bottom_wall():
    lat = box(jx1=1000)
    grain(lat, 1, 2, v=(0, -500))  # above the bottom wall site (0, 2): G = 3, R = 1: template 4
    c = derived(icb=2000, iew1=12)  # iew1 = 28
    ref.collide(lat, c, 4, "b")
    # kc1 = (780·(1000 − 0) + 1351·(0 + 500) + 780)/1560 = 1456280/1560 = 933
    # ikc = 28·933 = 26124; ikcx = (780·26124 + 12480)/24960 = 20389200/24960 = 816
    # ikcy = (1351·26124 + 12480)/24960 = 35306004/24960 = 1414
    assert (lat.ivx[1, 2], lat.ivy[1, 2]) == (816, -500 + 1414)
    assert (lat.ipx[0, 2], lat.ipy[0, 2]) == (-816, -1414)  # the wall gets −Δv(grain)
    assert lat.ivx[0, 2] == 1000  # infinite mass


def test_f_wall_at_m0_moving_reconstructed():
    lat = box()
    grain(lat, 3, 3, v=(500, 0), mode=WALL)  # G = 4, R = 4: template 1; f partner (2, 4)
    grain(lat, 2, 4, p=(-300, 100))
    c = derived(icb=2000, iew1=12)
    ref.collide(lat, c, 1, "f")
    # kc1 = (780·(500 − 0) + 1351·(0 − 0) + 780)/1560 = 390780/1560 = 250; ikc = 28·250
    # ikcx = (780·7000 + 12480)/24960 = 5472480/24960 = 219
    # ikcy = (1351·7000 + 12480)/24960 = 9469480/24960 = 379
    assert (lat.ivx[2, 4], lat.ivy[2, 4]) == (219, -379)  # along k = (½, −√3/2)
    assert (lat.ipx[3, 3], lat.ipy[3, 3]) == (-219, 379)
    # f projection: ip = (3547·(−300) + 2048·100)/4096 = −859300/4096 = −209 (trunc)
    # ipx = (−209·3547)/4096 = −741323/4096 = −180; ipy = (−209·2048)/4096 = −104
    assert (lat.ipx[2, 4], lat.ipy[2, 4]) == (-180, -104)


def test_f_pair_and_receding_pair():
    lat = box()
    grain(lat, 3, 3, v=(0, -1000))  # moving down towards its f partner
    grain(lat, 2, 4)
    grain(lat, 3, 7, v=(0, 1))  # receding from (2, 8): numerator 780 − 1351 = −571 → 0
    grain(lat, 2, 8)
    c = derived(icb=2000, iep1=16)  # elastic: iep1 = 32
    ref.collide(lat, c, 1, "f")
    # kc1 = (0 + 1351·(0 + 1000) + 780)/1560 = 866; ikc = 32·866 = 27712
    # ikcx = (780·27712 + 24960)/49920 = 21640320/49920 = 433
    # ikcy = (1351·27712 + 24960)/49920 = 37463872/49920 = 750
    assert (lat.ivx[3, 3], lat.ivy[3, 3]) == (-433, -1000 + 750)
    assert (lat.ivx[2, 4], lat.ivy[2, 4]) == (433, -750)
    assert (lat.ivy[3, 7], lat.ivx[2, 8], lat.ivy[2, 8]) == (1, 0, 0)


def test_c_pair_and_wall_above_cb():
    lat = box()
    grain(lat, 2, 4, v=(-200, 0), p=(700, 55))  # m0; c partner (2, 3) on its left
    grain(lat, 2, 3, v=(1000, 0), p=(-20, 9))
    grain(lat, 2, 10, v=(-3000, 10))  # m0 of the second pair, a wall on its left
    grain(lat, 2, 9, mode=WALL)
    c = derived(icb=2000, iep1=12, iew1=12, iew2=15)  # G = 5, 11 odd; R = 3 odd: template 4
    ref.collide(lat, c, 4, "c")
    # pair: kc1 = 1000 − (−200) = 1200 ≤ icb; ikc = 28·1200 = 33600;
    # ikcx = (33600 + 16)/32 = 1050 → relative rebound 850 − (−50) = 900 = .75·1200
    assert (lat.ivx[2, 4], lat.ivx[2, 3]) == (850, -50)
    assert (lat.ipx[2, 4], lat.ipy[2, 4], lat.ipx[2, 3], lat.ipy[2, 3]) == (0, 55, 0, 9)
    # wall: kc1 = 0 − (−3000) = 3000 > icb; icw = 2000·(12 − 15) = −6000;
    # ikc = (−6000 + 15·3000) + 16·3000 = 87000; ikcx = (87000 + 8)/16 = 5438
    # (rebound .75·2000 + .9375·1000 = 2437.5, rounded up by the +ke2)
    assert lat.ivx[2, 10] == -3000 + 5438
    assert lat.ipx[2, 9] == -5438


def test_walls_on_the_other_side_of_each_bond():
    """colb with the wall at m1 (moving top row), colc with the wall at m0, colf with the
    wall at m1 (bottom row): the listing's surviving branches."""
    lat = box(jx2=-1000)
    c = derived(icb=2000, iew1=12)  # iew1 = 28
    grain(lat, 4, 3, v=(0, 600), p=(-500, -700))  # G = 4, R = 5: template 3; b → top wall
    ref.collide(lat, c, 3, "b")
    # kc1 = (780·(0 + 1000) + 1351·600 + 780)/1560 = 1591380/1560 = 1020; ikc = 28·1020
    # ikcx = (780·28560 + 12480)/24960 = 22289280/24960 = 893 (exact)
    # ikcy = (1351·28560 + 12480)/24960 = 38597040/24960 = 1546
    assert (lat.ivx[4, 3], lat.ivy[4, 3]) == (-893, 600 - 1546)
    assert (lat.ipx[5, 3], lat.ipy[5, 3]) == (893, 1546)
    # ip = (3547·(−500) − 2048·(−700))/4096 = −339900/4096 = −82 (trunc)
    # ipx = (−82·3547)/4096 = −290854/4096 = −71; ipy = (82·2048)/4096 = 41
    assert (lat.ipx[4, 3], lat.ipy[4, 3]) == (-71, 41)

    grain(lat, 2, 6, mode=WALL)  # G = 7, R = 3: template 4; its c partner (2, 5)
    grain(lat, 2, 5, v=(700, 0), p=(900, 33))
    ref.collide(lat, c, 4, "c")
    # kc1 = 700 − 0; ikc = 28·700 = 19600; ikcx = (19600 + 8)/16 = 1225 (rebound .75·700)
    assert (lat.ivx[2, 5], lat.ipx[2, 5], lat.ipy[2, 5]) == (700 - 1225, 0, 33)
    assert lat.ipx[2, 6] == 1225

    grain(lat, 1, 3, v=(-200, -800))  # G = 4, R = 2: template 1; f partner: wall (0, 4)
    ref.collide(lat, c, 1, "f")
    # kc1 = (780·(−200 − 0) + 1351·(0 + 800) + 780)/1560 = 925580/1560 = 593; ikc = 16604
    # ikcx = (780·16604 + 12480)/24960 = 12963600/24960 = 519
    # ikcy = (1351·16604 + 12480)/24960 = 22444484/24960 = 899
    assert (lat.ivx[1, 3], lat.ivy[1, 3]) == (-200 - 519, -800 + 899)
    assert (lat.ipx[0, 4], lat.ipy[0, 4]) == (519, -899)


# --------------------------------------------------------------------------- time step
def test_time_step_without_gravity():
    c = derived()
    assert ref.time_step((0, 0, 0), c) == 1
    assert ref.time_step((5000**2, 3000, 4000), c) == int(4096 * 4096 / 5000 + 0.5)  # 3355
    lat, par = box(), LgdParams(nxt=12, nyt=6)
    grain(lat, 2, 2, v=(3000, 4000))
    grain(lat, 3, 8, v=(-100, 0))
    core.prepare(lat, par)
    assert lat.pv == (25_000_000, 3000, 4000)
    assert core.run_steps(lat, par, 1, impl="reference")["it"][0] == 3355


def test_peak_speed_tie_goes_to_the_first_grain_in_storage_order():
    # the listing's scan keeps the first grain with the strictly largest v² (rows R, then
    # columns G); its velocity vector enters the gravity time step through g·v
    lat, par = box(), LgdParams(nxt=12, nyt=6, igx=5, igy=-7)
    grain(lat, 2, 0, v=(-400, -300))
    grain(lat, 1, 9, v=(300, 400))
    grain(lat, 1, 10, v=(0, 500))
    grain(lat, 3, 3, v=(0, -499))
    core.prepare(lat, par)
    assert lat.pv == (250_000, 300, 400) and lat.ng == 4


def quartic_root_ticks(v, g, idy):
    """Smallest positive t (ticks) of d² = ¼g²t⁴ + (g·v)t³ + v²t², d = idy/4096 cm (the
    listing's gravity branch), v in 1/256 cm/s, t in 1/65536 s."""
    vx, vy = v[0] / 256, v[1] / 256
    gg = g[0] ** 2 + g[1] ** 2
    d = idy / 4096
    roots = np.roots([gg / 4, g[0] * vx + g[1] * vy, vx * vx + vy * vy, 0, -d * d])
    t = min(r.real for r in roots if abs(r.imag) < 1e-9 and r.real > 0)
    return t * 65536


@pytest.mark.parametrize("g", [(0, -8), (5, -3), (-1000, 0)])
def test_time_step_with_gravity_is_the_quartic_root(g):
    rng = np.random.default_rng(1)
    c = derived(igx=g[0], igy=g[1])
    if g == (0, -8):
        # itm = 1024·√(2·4096/8) = 32768 ticks (0.5 s); rising at 1 cm/s (256) the grain is
        # d = 0.866 cm below its start at 4t² − t = 0.866 → t = 0.607 s > itm: capped
        assert c.itm == 32768 and ref.time_step((256**2, 0, 256), c) == 32768
    vs = [(0, 0), (3000, 0), (0, 2000), (0, -2000)] + [tuple(v) for v in
                                                        rng.integers(-4000, 4000, (40, 2))]
    for vx, vy in vs:
        it = ref.time_step((vx * vx + vy * vy, vx, vy), c)
        root = quartic_root_ticks((vx, vy), g, c.idy)
        if root >= c.itm:
            assert it == c.itm  # capped by the fall time over one spacing
        else:
            assert abs(it - root) <= 1, (vx, vy, it, root)


# --------------------------------------------------------------------------- whole runs
def random_scene(seed, nxt=24, nyt=12, density=0.45, g=(0, -8), jx=(0, 0), extra=0.03,
                 ntu=3, e=(12, 15, 12, 15), icb=724, speed=2000, same_speed=False):
    """Grains at random sites with random velocities and offsets; optional extra walls
    (some moving); icb = 4·√(2·8·4096) = 1024 is the digest's c_b for g = 8, 724 a variant."""
    rng = np.random.default_rng(seed)
    lat = box(nxt, nyt, *jx)
    inner = lat.mlp[1:-1]
    inner[rng.random(inner.shape) < density] = MOVABLE
    inner[rng.random(inner.shape) < extra] = WALL
    m = lat.mlp == MOVABLE
    k = int(m.sum())
    lat.ivx[m], lat.ivy[m] = rng.integers(-speed, speed + 1, (2, k))
    if same_speed:  # the thesis's gas start: one speed, half along +x, half along −x
        lat.ivx[m], lat.ivy[m] = rng.choice([-speed, speed], k), 0
    lat.ipx[m], lat.ipy[m] = rng.integers(-3000, 3001, (2, k))
    lat.nlp[m] = np.arange(1, k + 1)
    w = np.zeros_like(m)
    w[1:-1] = lat.mlp[1:-1] == WALL
    lat.ivx[w] = rng.integers(-300, 301, int(w.sum()))  # extra walls with a velocity
    par = LgdParams(nxt=nxt, nyt=nyt, igx=g[0], igy=g[1], jx1=jx[0], jx2=jx[1], ntu=ntu,
                    iep1=e[0], iep2=e[1], iew1=e[2], iew2=e[3], icb=icb)
    return lat, par


def test_momentum_balance_with_walls_step_by_step():
    """Per step: Δ Σ grain velocity = ng·(gravity kick) − Σ wall accumulators (is1+is2+is3,
    ip1+ip2+ip3), exactly; the walls here move and the restitution is piecewise."""
    lat, par = random_scene(3, g=(2, -8), jx=(400, -400))
    core.prepare(lat, par)
    c = ref.derive(par)
    p = (int(lat.ivx[lat.mlp > 0].sum()), int(lat.ivy[lat.mlp > 0].sum()))
    log = core.run_steps(lat, par, 300, impl="reference")
    assert (log["is3"] != 0).any() and (log["is1"] != 0).any() and (log["ip2"] != 0).any()
    for k in range(300):
        kick = ref.gravity_increments(int(log["it"][k]), c)
        wall = (log["is1"][k] + log["is2"][k] + log["is3"][k],
                log["ip1"][k] + log["ip2"][k] + log["ip3"][k])
        now = (log["sum_vx"][k], log["sum_vy"][k])
        assert now[0] - p[0] == lat.ng * kick[0] - wall[0]
        assert now[1] - p[1] == lat.ng * kick[1] - wall[1]
        p = now


def test_momentum_constant_away_from_walls():
    lat, par = box(48, 40), LgdParams(nxt=48, nyt=40, iep1=12, iep2=15, icb=300)
    rng = np.random.default_rng(5)
    for r in range(16, 24):
        for c in range(20, 28):
            grain(lat, r, c, v=tuple(rng.integers(-400, 401, 2)), p=(0, 0))
    core.prepare(lat, par)
    px, py = lat.ivx[1:-1].sum(), lat.ivy[1:-1].sum()
    # a grain moves at most one site per step: from rows 16..23 it needs 15 steps to reach
    # row 1 or 38, next to a wall row
    log = core.run_steps(lat, par, 14, impl="reference")
    walls = np.stack([log[k] for k in ("is1", "ip1", "is2", "ip2", "is3", "ip3")])
    assert not walls.any()
    assert (log["sum_v2"][-1] < log["sum_v2"][0])  # inelastic: collisions happened
    assert (log["sum_vx"] == px).all() and (log["sum_vy"] == py).all()


def test_no_grain_lost_or_duplicated_with_gravity():
    lat, par = random_scene(11, nxt=30, nyt=16, density=0.5, g=(3, -8))
    core.prepare(lat, par)
    marks = np.sort(lat.nlp[lat.mlp > 0])
    for _ in range(4):
        core.run_steps(lat, par, 100, impl="reference")
        assert np.count_nonzero(lat.mlp > 0) == lat.ng
        assert (np.sort(lat.nlp[lat.mlp > 0]) == marks).all()
        assert (lat.mlp[lat.mlp > 0] == MOVABLE).all()  # re-armed at the end of each step
        assert not lat.ivx[lat.mlp == 0].any() and not lat.ipx[lat.mlp == 0].any()


SCENES = [
    dict(seed=1),  # gravity down, extra walls, piecewise restitution
    dict(seed=2, g=(5, -7), jx=(800, -600), ntu=2),  # tilted gravity, moving wall rows
    dict(seed=3, g=(0, 0), e=(16, 16, 12, 12), icb=0, extra=0.0),  # elastic gas, no gravity
    dict(seed=4, g=(-8, 0), e=(12, 15, 16, 4), ntu=1, nxt=36, nyt=10),
    dict(seed=5, density=0.8, speed=6000, icb=3000),  # dense and fast
    dict(seed=6, speed=400_000, icb=100_000, nxt=18),  # products beyond 2^32
    dict(seed=7, g=(5, -7), same_speed=True, extra=0.0),  # ties for the peak-speed grain
]


@pytest.mark.parametrize("scene", SCENES)
@pytest.mark.parametrize("first_step", [1, 2])
def test_native_equals_reference(scene, first_step):
    runs = []
    for impl in core.IMPLEMENTATIONS:
        lat, par = random_scene(**scene)
        lat.nn = first_step
        core.prepare(lat, par)
        log = {}
        for chunk in (150, 1, 99):  # restarts carry pv, nn, itt
            part = core.run_steps(lat, par, chunk, impl=impl)
            log = {k: np.concatenate([log.get(k, []), v]) for k, v in part.items()}
        runs.append((lat, log))
    (a, la), (b, lb) = runs
    for name in ("mlp", "ipx", "ipy", "ivx", "ivy", "nlp"):
        assert (getattr(a, name) == getattr(b, name)).all(), name
    assert (a.pv, a.nn, a.itt) == (b.pv, b.nn, b.itt)
    for name in la:
        assert (la[name] == lb[name]).all(), name
    assert len(set(la["it"].tolist())) > 10  # the time step varied


def test_native_time_step_equals_reference():
    from demstudy._native import lgd_time_step
    rng = np.random.default_rng(2)
    for g in ((0, 0), (0, -8), (7, -3)):
        c = ref.derive(LgdParams(nxt=12, nyt=6, igx=g[0], igy=g[1]))
        params = {**dataclasses.asdict(c), "nw": 0}
        for vx, vy in rng.integers(-9000, 9000, (200, 2)):
            pv = (int(vx * vx + vy * vy), int(vx), int(vy))
            assert lgd_time_step(params, *pv) == ref.time_step(pv, c)


@pytest.mark.parametrize("change, message", [
    (lambda lat, par: setattr(par, "nxt", 16), "nxt = 16"),
    (lambda lat, par: setattr(par, "nyt", 3), "nyt = 3"),
    (lambda lat, par: lat.mlp.__setitem__((0, 5), 0), "lattice.mlp[0, 5] = 0"),
    (lambda lat, par: lat.mlp.__setitem__((2, 5), 3), "lattice.mlp[2, 5] = 3"),
    (lambda lat, par: setattr(lat, "ipx", lat.ipx.astype(np.int32)), "lattice.ipx.dtype"),
    (lambda lat, par: setattr(lat, "ivy", lat.ivy[:, :6].copy()), "lattice.ivy.shape"),
    (lambda lat, par: setattr(par, "jx2", 5), "lattice.ivx[5, 0] = 0"),
    (lambda lat, par: setattr(par, "ke", 0), "ke = 0"),
])
def test_bad_input_names_field_and_value(change, message):
    lat, par = box(), LgdParams(nxt=12, nyt=6)
    change(lat, par)
    with pytest.raises(ValueError) as err:
        core.run_steps(lat, par, 1)
    assert message in str(err.value)


def test_bad_impl():
    lat, par = box(), LgdParams(nxt=12, nyt=6)
    with pytest.raises(ValueError, match="impl = 'fortran'"):
        core.run_steps(lat, par, 1, impl="fortran")
