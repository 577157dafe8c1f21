"""The LGD step's orderings against Gutt's (1989) C listing (App. 3), hand-derived from the
listing's loops: which of two grains wins one empty site (the 9 move templates' order and
their phase in global G, R residues, main L2133–L2186 and L1777–L1786), which bond collides
first (the 12 collision sub-sweeps, reversed on even steps, L2189–L2317), and the discharge
count nq (user column ix > nxt/2, only with extra wall particles, L2406–L2434).

Units: the listing's integers (offsets in idl = 4096 per spacing, velocities 1/256 cm/s);
dimensionless particle units (d = 1, m = 1, g = 1) only above this core. Array row r = R − 1,
array column c = G − 1 (Gutt's 1-based global row R and storage column G).
"""

from __future__ import annotations

import numpy as np
import pytest

from demstudy.engines.lgd import core
from demstudy.engines.lgd.lattice import MOVABLE, WALL, Lattice, LgdParams


def box(nxt: int = 12, nyt: int = 8) -> tuple[Lattice, LgdParams]:
    lat = Lattice.empty(nxt, nyt)
    lat.mlp[0] = lat.mlp[-1] = WALL
    return lat, LgdParams(nxt=nxt, nyt=nyt)


def put(lat: Lattice, G: int, R: int, v=(0, 0), p=(0, 0)) -> None:
    lat.mlp[R - 1, G - 1] = MOVABLE
    lat.ivx[R - 1, G - 1], lat.ivy[R - 1, G - 1] = v
    lat.ipx[R - 1, G - 1], lat.ipy[R - 1, G - 1] = p


# The listing's move templates in its order (comments at L2133–L2186, phases nd0/nd1/nd2
# from L1777–L1786 with ndx1 = ndy1 = 1): (G mod 3, R mod 3) =
#   1st (0,0), 2nd (2,1), 3rd (1,2), 4th (2,0), 5th (1,1), 6th (0,2), 7th (1,0), 8th (0,1),
#   9th (2,2).
# Two grains at rest aim at the empty site T = (G, R): one from G − 1 (offset +x: move d),
# one from G + 1 (offset −x: move c). The grain whose template comes first takes T; the other
# is blocked for the rest of the step (T then holds a grain).
@pytest.mark.parametrize("G, R, winner", [
    (2, 3, "right"),  # left G=1 (1,0): 7th; right G=3 (0,0): 1st
    (3, 3, "left"),   # left G=2 (2,0): 4th; right G=4 (1,0): 7th
    (4, 4, "right"),  # left G=3 (0,1): 8th; right G=5 (2,1): 2nd
    (5, 5, "left"),   # left G=4 (1,2): 3rd; right G=6 (0,2): 6th
    (9, 4, "left"),   # left G=8 (2,1): 2nd; right G=10 (1,1): 5th
])
@pytest.mark.parametrize("impl", core.IMPLEMENTATIONS)
def test_contended_site_goes_to_the_earlier_move_template(G, R, winner, impl):
    lat, par = box()
    put(lat, G - 1, R, p=(5000, 0))  # 256·0/5000 = 0: sector d
    put(lat, G + 1, R, p=(-5000, 0))  # sector c
    core.prepare(lat, par)
    log = core.run_steps(lat, par, 1, impl=impl)
    assert log["it"][0] == 1  # every grain at rest: it = 1, no drift, no collision
    grains = {(int(c) + 1, int(r) + 1) for r, c in zip(*(lat.mlp > 0).nonzero(), strict=True)}
    stayed = (G + 1, R) if winner == "left" else (G - 1, R)
    assert grains == {(G, R), stayed}
    # the winner arrives with its offset minus one spacing; the loser keeps its offset
    assert lat.ipx[R - 1, G - 1] == (5000 - 4096 if winner == "left" else -5000 + 4096)
    assert abs(lat.ipx[R - 1, stayed[0] - 1]) == 5000


# Collision sub-sweeps (listing L2189–L2317); templates as (G parity, R parity):
#   odd steps:  (0,1) b c f, (1,0) f c b, (1,1) b c f, (0,0) f c b
#   even steps: (0,0) b c f, (1,1) f c b, (1,0) b c f, (0,1) f c b
# A row of three grains A, B, C at G−1, G, G+1: C moves left at 1000, A and B at rest
# (elastic, icb = 0). colc pairs a site with its left neighbour, so pair (C, B) is swept in
# C's template and pair (B, A) in B's. If (C, B) goes first, Newton's cradle: C stops, B
# takes −1000 and passes it on to A in the same step. Otherwise (B, A) meets two grains at
# rest (no collision) and B ends with −1000.
@pytest.mark.parametrize("nn, G, R, cradle", [
    (1, 4, 4, True),   # C at G=5, R=4: (1,0) c is 5th; B (0,0) c is 11th
    (2, 4, 4, False),  # even: B (0,0) c 2nd, C (1,0) c 8th
    (1, 5, 4, False),  # C at G=6 (0,0) c 11th; B (1,0) c 5th
    (2, 5, 4, True),   # even: C (0,0) c 2nd
    (1, 5, 3, True),   # R = 3 odd: C at G=6 (0,1) c 2nd; B (1,1) c 8th
    (2, 5, 3, False),  # even: B (1,1) c 5th, C (0,1) c 11th
])
@pytest.mark.parametrize("impl", core.IMPLEMENTATIONS)
def test_collision_sweep_order_alternates_between_odd_and_even_steps(nn, G, R, cradle, impl):
    lat, par = box()
    put(lat, G - 1, R)
    put(lat, G, R)
    put(lat, G + 1, R, v=(-1000, 0))  # its drift offset −4095 aims c at B: blocked
    lat.nn = nn
    core.prepare(lat, par)
    core.run_steps(lat, par, 1, impl=impl)
    # elastic c bond: ikc = (16 + 16)·1000, ikcx = (32000 + 16)/32 = 1000: full exchange
    expected = (-1000, 0, 0) if cradle else (0, -1000, 0)
    assert tuple(int(lat.ivx[R - 1, g - 1]) for g in (G - 1, G, G + 1)) == expected
    assert (lat.mlp[R - 1, G - 2:G + 1] == MOVABLE).all()  # nobody moved


@pytest.mark.parametrize("impl", core.IMPLEMENTATIONS)
def test_discharge_count_uses_the_user_column_and_needs_extra_walls(impl):
    # user column ix = ((G + (R − 1)/2 − 1) mod nxt) + 1 (L2406); nq counts ix > nxt/2 = 6
    lat, par = box()
    counted = [(7, 2), (6, 5), (5, 7)]  # ix = 7, (6 + 2 − 1) mod 12 + 1 = 8, 8
    not_counted = [(6, 2), (4, 5), (12, 7)]  # ix = 6, 6, (12 + 3 − 1) mod 12 + 1 = 3
    for G, R in counted + not_counted:
        put(lat, G, R)
    no_walls = core.run_steps(core.prepare(lat, par), par, 1, impl=impl)
    assert no_walls["nq"][0] == 0  # no extra wall particles: the listing skips the count
    lat.mlp[3, 0] = WALL  # one extra wall particle at (G, R) = (1, 4), touching no grain
    log = core.run_steps(lat, par, 1, impl=impl)
    assert log["nq"][0] == len(counted)


@pytest.mark.parametrize("impl", core.IMPLEMENTATIONS)
def test_step_commutes_with_a_shift_by_six_columns_only(impl):
    """Move templates repeat every 3 columns and collision templates every 2, and columns
    are periodic: shifting a state by 6 columns shifts its whole future by 6 (so a layout
    uniform along x stays 6-column periodic for ever: docs/lgd-review.md). A shift by 2 or 3
    changes which template a grain is in, and the future with it."""
    rng = np.random.default_rng(3)
    lat, _ = box(24, 10)
    inner = lat.mlp[1:-1]
    inner[rng.random(inner.shape) < 0.45] = MOVABLE
    inner[rng.random(inner.shape) < 0.03] = WALL
    m = lat.mlp == MOVABLE
    lat.ivx[m], lat.ivy[m] = rng.integers(-2000, 2001, (2, int(m.sum())))
    lat.ipx[m], lat.ipy[m] = rng.integers(-3000, 3001, (2, int(m.sum())))
    lat.ivx[0], lat.ivx[-1] = -500, 700
    par = LgdParams(nxt=24, nyt=10, jx1=-500, jx2=700, iep1=12, iep2=15, iew1=12, iew2=15,
                    icb=724)
    fields = ("mlp", "ipx", "ipy", "ivx", "ivy")

    def run(shift: int) -> tuple[Lattice, dict]:
        moved = Lattice(**{k: np.roll(getattr(lat, k), shift, axis=1) for k in
                           (*fields, "nlp")})
        return moved, core.run_steps(core.prepare(moved, par), par, 200, impl=impl)

    (a, la), (b, lb) = run(0), run(6)
    for k in fields:
        assert (np.roll(getattr(a, k), 6, axis=1) == getattr(b, k)).all(), k
    assert all((la[k] == lb[k]).all() for k in la if k != "nq")  # nq: user columns move
    for shift in (2, 3):
        c, _ = run(shift)
        assert not (np.roll(a.ivx, shift, axis=1) == c.ivx).all()
