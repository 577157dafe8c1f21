"""Gutt's LGD problem files (demstudy.engines.lgd.problem): every md code against a lattice
drawn by hand, the user → storage column map, the readers' errors and the writer's round trip.

The listing's integer units (offsets 1/4096 cm, velocities 1/256 cm/s); no particle units here.
Pictures are in user coordinates: one text row per lattice row R (top row first), columns
ix = 1..nxt left to right; '#' wall particle, 'o' grain, '.' empty, a digit a marked grain.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from demstudy.engines.lgd.lattice import LgdParams
from demstudy.engines.lgd.problem import (
    Control,
    MdLine,
    Problem,
    ProblemError,
    build_lattice,
    c_field_problems,
    lattice_to_lines,
    read_initial_data,
    read_parameters,
    read_problem,
    storage_column,
    user_column,
    write_problem,
)

NXT, NYT = 12, 7


def picture(lat) -> list[str]:
    """The lattice in user coordinates, top row first."""
    nyt, nxt = lat.mlp.shape
    rows = []
    for r in range(nyt - 1, -1, -1):
        chars = ["?"] * nxt
        for c in range(nxt):
            ix = int(user_column(c, r, nxt))
            mark = int(lat.nlp[r, c])
            chars[ix - 1] = (str(mark) if mark and lat.mlp[r, c] > 0 else
                             {-1: "#", 0: ".", 1: "o"}[int(lat.mlp[r, c])])
        rows.append("".join(chars))
    return rows


def drawn(text: str) -> list[str]:
    return [row.strip() for row in text.strip().splitlines()]


def lattice_of(*lines: MdLine, jx1: int = 0, jx2: int = 0):
    return build_lattice(LgdParams(nxt=NXT, nyt=NYT, jx1=jx1, jx2=jx2), list(lines))


def test_user_column_is_the_physical_column_per_the_digest():
    # digest §3.2: x_phys = ix + ½[R even]; lattice.py: x = (c + 1 + r/2) mod nxt
    for iy in range(1, 9):
        for ix in range(1, NXT + 1):
            c = int(storage_column(ix, iy, NXT))
            r = iy - 1
            x_storage = (c + 1 + r / 2) % NXT
            x_user = (ix + 0.5 * (iy % 2 == 0)) % NXT
            assert x_storage == pytest.approx(x_user)
            assert user_column(c, r, NXT) == ix


def test_empty_problem_has_the_two_wall_rows_with_their_velocities():
    lat = lattice_of(jx1=-7, jx2=9)
    assert picture(lat) == drawn("""
        ############
        ............
        ............
        ............
        ............
        ............
        ############""")
    assert (lat.ivx[0] == -7).all() and (lat.ivx[-1] == 9).all()
    assert lat.ng == 0


def test_single_grain_and_wall_particle_take_offsets_and_velocity():
    lat = lattice_of(MdLine(1, 3, 2, 100, -50, 7, 8), MdLine(-1, 12, 4, 5, 6, 0, 0))
    assert picture(lat) == drawn("""
        ############
        ............
        ............
        ...........#
        ............
        ..o.........
        ############""")
    r, c = 1, int(storage_column(3, 2, NXT))
    assert (lat.ipx[r, c], lat.ipy[r, c], lat.ivx[r, c], lat.ivy[r, c]) == (100, -50, 7, 8)
    r, c = 3, int(storage_column(12, 4, NXT))
    assert (lat.mlp[r, c], lat.ipx[r, c], lat.ipy[r, c]) == (-1, 5, 6)


def test_lines_follow_c_truncation():
    # (1,2) → (12,6): npl = 11, iy = 2 + 4·l/11 truncated: rows change at l = 3, 6, 9, 11
    lat = lattice_of(MdLine(2, 1, 2, 12, 6, 1, 0), MdLine(-2, 6, 3, 6, 5))
    assert picture(lat) == drawn("""
        ############
        ...........o
        .....#...oo.
        .....#ooo...
        ...oo#......
        ooo.........
        ############""")
    # a line from a point to itself: that point (the listing would divide 0/0)
    assert picture(lattice_of(MdLine(2, 4, 4, 4, 4)))[NYT - 4] == "...o........"


def test_line_going_left_and_down_truncates_toward_zero():
    # (12,6) → (1,2): iy = 6 + (−4·l)/11, C truncation toward zero (not floor)
    lat = lattice_of(MdLine(2, 12, 6, 1, 2))
    ix = 12 + np.trunc(-11 * np.arange(12) / 11).astype(int)
    iy = 6 + np.trunc(-4 * np.arange(12) / 11).astype(int)
    got = sorted(zip(*[a.tolist() for a in np.nonzero(lat.mlp == 1)], strict=True))
    want = sorted((int(y) - 1, int(storage_column(x, y, NXT))) for x, y in zip(ix, iy,
                                                                               strict=True))
    assert got == want
    # l = 1, 2: −4/11, −8/11 truncate to 0 (floor would give −1); l = 3: −12/11 → −1
    assert picture(lat)[NYT - 6] == ".........ooo"
    assert picture(lat)[NYT - 5] == "......ooo..."


def test_filled_rectangles():
    lat = lattice_of(MdLine(3, 2, 2, 5, 3, 4, 0), MdLine(-3, 10, 4, 12, 6))
    assert picture(lat) == drawn("""
        ############
        .........###
        .........###
        .........###
        .oooo.......
        .oooo.......
        ############""")
    assert (lat.ivx[lat.mlp == 1] == 4).all()


def test_density_one_third_rectangle_is_a_triangular_superlattice():
    lat = lattice_of(MdLine(6, 1, 2, 12, 6))
    assert picture(lat) == drawn("""
        ############
        o..o..o..o..
        ..o..o..o..o
        o..o..o..o..
        ..o..o..o..o
        o..o..o..o..
        ############""")
    # every grain's nearest neighbours are √3 spacings away (physical positions)
    r, c = np.nonzero(lat.mlp == 1)
    x, y = (c + 1 + r / 2) % NXT, r * math.sqrt(3) / 2
    dx = x[:, None] - x[None, :]
    dx -= NXT * np.round(dx / NXT)
    dist = np.hypot(dx, y[:, None] - y[None, :]) + 99 * np.eye(len(x))
    assert dist.min() == pytest.approx(math.sqrt(3))


def test_density_one_third_wall_rectangle_from_an_even_first_row():
    lat = lattice_of(MdLine(-6, 1, 3, 12, 4))
    # the displaced row 4 is even: it starts 1 further on (odd rows start 2 further on)
    assert picture(lat)[NYT - 4] == ".#..#..#..#."
    assert picture(lat)[NYT - 3] == "#..#..#..#.."


def test_empty_nodes_and_overwriting_in_line_order():
    lat = lattice_of(MdLine(3, 1, 2, 12, 3), MdLine(0, 5, 2), MdLine(-1, 6, 2),
                     MdLine(0, 1, 1))  # the last one opens a hole in the bottom wall row
    assert picture(lat) == drawn("""
        ############
        ............
        ............
        ............
        oooooooooooo
        oooo.#oooooo
        .###########""")


def test_marked_grains_are_numbered_by_line_placed_or_not():
    lat = lattice_of(MdLine(11, 2, 2), MdLine(15, 4, 9),  # second: row 9 > nyt, not placed
                     MdLine(12, 6, 3, 0, 0, 3, 3), MdLine(1, 8, 3))
    assert picture(lat)[NYT - 2] == ".1.........."
    assert picture(lat)[NYT - 3] == ".....3.o...."
    assert lat.ng == 3


def test_a_mark_survives_being_overwritten_as_in_the_listing():
    lat = lattice_of(MdLine(11, 2, 2), MdLine(3, 1, 2, 3, 2, 5, 0))
    r, c = 1, int(storage_column(2, 2, NXT))
    assert lat.nlp[r, c] == 1 and lat.ivx[r, c] == 5


def test_unknown_md_code_is_refused():
    with pytest.raises(ProblemError, match=r"md = 4: not a code"):
        lattice_of(MdLine(4, 1, 2))


# -- files ----------------------------------------------------------------------------------
PARAMS = """\
nam2 = init id = 1048576 icb = 0 iep1 = 16 iew1 = 12
idl = 2048   idx=1024 idy =1774 iep2= 16 iew2 = 12
igx = 0 igy = 0 jx1 = -4096 jx2 = 4096
kq = 1560 kx = 780 ky = 1351 ke = 16
mvx = 6 mvy = 5
nt = 1024 nxt = 12 nyt = 7 ntu = 3 nto = 256
"""
INIT = """  nl =     3
 6     1     2    12     6      0      0
 1     3     3    10   -20    100    -50
13     7     4     0     0      0      0
"""


def write_files(folder, params=PARAMS, init=INIT, control="2\npar\nsum\ndump\nmark\n"):
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "in").write_text(control)
    (folder / "par").write_text(params)
    (folder / "init").write_text(init)
    return folder / "in"


def test_read_problem_reads_all_three_files(tmp_path):
    problem = read_problem(write_files(tmp_path))
    par = problem.params
    assert (par.nxt, par.nyt, par.idl, par.idx, par.idy, par.id) == (12, 7, 2048, 1024, 1774,
                                                                      1048576)
    assert (par.iep1, par.iew1, par.jx1, par.jx2, par.ke) == (16, 12, -4096, 4096, 16)
    assert (problem.nt, problem.nto, problem.mvx, problem.mvy) == (1024, 256, 6, 5)
    assert problem.control == Control(2, "par", "sum", "dump", "mark")
    lat = problem.lattice()
    assert lat.ng == 20  # the singles land on nodes the rectangle filled
    r, c = 2, int(storage_column(3, 3, 12))
    assert (lat.ipx[r, c], lat.ipy[r, c], lat.ivx[r, c], lat.ivy[r, c]) == (10, -20, 100, -50)
    assert (lat.ivx[-1] == 4096).all()


@pytest.mark.parametrize(("text", "message"), [
    (PARAMS.replace("icb = 0", "icx = 0"), r"line 1: fields .*'icx'.*expected .*'icb'"),
    (PARAMS.replace("ke = 16", "ke = 1.5"), r"line 4: ke = '1.5' is not an integer"),
    (PARAMS.replace("nxt = 12", "nxt = 16"), r"line 6: nxt = 16; allowed: a multiple of 6"),
    (PARAMS.replace("mvx = 6", "mvx = 5"), r"line 5: mvx = 5; allowed: a divisor of nxt"),
    (PARAMS.replace("idl = 2048", "idl = 0"), r"line 2: idl = 0; allowed: > 0"),
    (PARAMS.replace("jx1 = -4096", "jx1 -4096"), r"line 3: .* not a sequence of 'name = val"),
    ("\n".join(PARAMS.splitlines()[:5]), r"5 non-empty lines; the parameter file has 6"),
])
def test_parameter_errors_name_file_line_and_field(tmp_path, text, message):
    (tmp_path / "par").write_text(text)
    with pytest.raises(ProblemError, match=message) as info:
        read_parameters(tmp_path / "par")
    assert str(tmp_path / "par") in str(info.value)


def test_blank_lines_do_not_shift_the_line_numbers(tmp_path):
    text = "\n" + PARAMS.replace("nxt = 12", "nxt = 13")
    (tmp_path / "par").write_text(text)
    with pytest.raises(ProblemError, match=r"line 7: nxt = 13"):
        read_parameters(tmp_path / "par")


@pytest.mark.parametrize(("text", "message"), [
    (INIT.replace("nl =     3", "nl =     4"), r"nl = 4 but 3 md lines follow"),
    (INIT.replace("13     7", " 5     7"), r"line 4: md = 5: not a code"),
    (INIT.replace("   -50", ""), r"line 3: 6 values .* expected 7"),
    (INIT.replace("   100", "   1e2"), r"line 3: vx = '1e2' is not an integer"),
    ("n = 3\n", r"line 1: 'n = 3'; expected 'nl = N'"),
])
def test_initial_data_errors_name_file_and_line(tmp_path, text, message):
    (tmp_path / "init").write_text(text)
    with pytest.raises(ProblemError, match=message):
        read_initial_data(tmp_path / "init")


def test_missing_file_is_named(tmp_path):
    write_files(tmp_path)
    (tmp_path / "init").unlink()
    with pytest.raises(ProblemError, match=r"init: cannot be read"):
        read_problem(tmp_path)


def round_trip(problem: Problem, folder):
    again = read_problem(write_problem(folder, problem))
    a, b = problem.lattice(), again.lattice()
    for name in ("mlp", "ipx", "ipy", "ivx", "ivy", "nlp"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert again.params == problem.params.resolved()
    assert (again.nt, again.nto, again.mvx, again.mvy) == (problem.nt, problem.nto,
                                                          problem.mvx, problem.mvy)
    return again


def test_written_problem_reads_back_the_same(tmp_path):
    round_trip(read_problem(write_files(tmp_path / "a")), tmp_path / "b")


def test_lattice_written_as_lines_rebuilds_every_node(tmp_path):
    rng = np.random.default_rng(3)
    par = LgdParams(nxt=12, nyt=9, jx1=5, jx2=-5)
    lines = [MdLine(3, 1, 2, 12, 5, 2, -1), MdLine(6, 1, 6, 12, 8, 0, 3)]
    for _ in range(25):  # scattered singles with offsets, walls, holes and marks
        md = int(rng.choice([1, -1, 0, 11]))
        lines.append(MdLine(md, int(rng.integers(1, 13)), int(rng.integers(1, 10)),
                            int(rng.integers(-900, 900)), int(rng.integers(-900, 900)),
                            int(rng.integers(-50, 50)), int(rng.integers(-50, 50))))
    lat = build_lattice(par, lines)
    rebuilt = build_lattice(par, lattice_to_lines(lat, par))
    for name in ("mlp", "ipx", "ipy", "ivx", "ivy", "nlp"):
        np.testing.assert_array_equal(getattr(lat, name), getattr(rebuilt, name),
                                      err_msg=name)
    again = round_trip(Problem(par, lattice_to_lines(lat, par), nt=10), tmp_path)
    assert len(again.lines) < lat.mlp.size / 2  # rows of equal grains became ±2 lines


def test_c_field_width_problems_are_reported():
    problem = Problem(LgdParams(nxt=12, nyt=7), [], nt=5)  # id = (4096/2)² = 4194304
    assert c_field_problems(problem) == ["id = 4194304: more than the 6 characters of %6d"]
