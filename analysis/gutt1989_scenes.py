"""Write the LGD scenes of Gutt (1989) Ch. 3 (inputs/gutt1989/*.toml) from the text's numbers.

Units: [lattice] and its md lines in the listing's integers (offsets 1/idl spacing, velocities
1/256 "cm/s"); everything else in particle units (d = 1 = lattice spacing, m = 1, g = 1 with
gravity; without gravity the wall speed or the initial r.m.s. speed, as each header says).

The thesis's initial layouts are in its figures, which are missing (digest §6): every layout
here is built from the numbers in the text and marked "assumed" in the scene's description.
Run: ``python analysis/gutt1989_scenes.py`` (rewrites the files; they are committed).
"""

from __future__ import annotations

import math
from pathlib import Path

OUT = Path(__file__).resolve().parents[1] / "inputs" / "gutt1989"
ROW = math.sqrt(3) / 2
HEADER_UNITS = {
    "gravity": "# Units: d = 1 (lattice spacing), m = 1, g = 1 (gravity acts): times in √(d/g),\n"
               "# speeds in √(g d); [lattice] and its md lines in the listing's integers.\n",
    "wall": "# Units: d = 1 (lattice spacing), m = 1, and the wall speed U = 1 (no gravity):\n"
            "# times in d/U, speeds in U; [lattice] and its md lines in the listing's "
            "integers.\n",
    "rms": "# Units: d = 1 (lattice spacing), m = 1, and {what} = 1 (no gravity, walls at\n"
           "# rest): times in d/v; [lattice] and its md lines in the listing's integers.\n",
}
GRANULAR = ('[contact]   # e1 = 0.75 below c_b = √(2 g d), e2 = 0.9375 above (L1087, L1097, '
            'L1113)\nrestitution = 0.75\nlaw = { model = "gutt-piecewise", e1 = 0.75, '
            'e2 = 0.9375, crossover_speed = 1.4142135623730951 }\n')


def line(md, x1, y1, x2=0, y2=0, vx=0, vy=0) -> str:
    return (f"  {{ md = {md}, x1 = {x1}, y1 = {y1}, x2 = {x2}, y2 = {y2}, vx = {vx}, "
            f"vy = {vy} }},")


def walls(e: float, e_name: str, velocities=(0.0, 0.0)) -> str:
    out = ""
    for side, v in zip(("lower", "upper"), velocities, strict=True):
        out += (f"\n[[walls]]   # wall row {'1' if side == 'lower' else 'nyt'}\nside = "
                f"\"{side}\"\nrestitution = {e}   # {e_name}\nvelocity = {v}\n")
    return out


def fill(x1, y1, x2, y2, density) -> str:
    """A ``[[lattice.fill]]`` table: a seeded random fill at ``density`` of the rectangle,
    at rest, seeded by run.seed (demstudy's extension of Gutt's md lines)."""
    return (f"\n[[lattice.fill]]   # seeded random fill (run.seed): density {density} of "
            f"rows {y1}-{y2}, columns {x1}-{x2}\nx1 = {x1}\ny1 = {y1}\nx2 = {x2}\ny2 = {y2}\n"
            f"density = {density}\n")


def scene(name: str, header: str, meta: str, body: str, lattice: str, lines: list[str],
          run: str, fills: str = "") -> str:
    nxt, nyt = (int(v.split("=")[1].split("#")[0]) for v in lattice.splitlines()[:2])
    box = (f"\n[box]   # the lattice: [nxt, (nyt − 1)·√3/2], wall-row centre to centre\n"
           f"size = [{float(nxt)!r}, {(nyt - 1) * ROW!r}]\n")
    return (header + "\ndimension = 2\n\n[meta]\n" + f'name = "gutt1989-{name}"\n' + meta +
            box + "\n[particles]   # the grains are the lattice's (md lines)\n\n" + body +
            "\n" + run + '\n[measure]\nbin_width = 0.8660254037844386   # one lattice row '
                         '(√3/2) per bin\n\n[lattice]\n' + lattice +
            ("initial = [\n" + "\n".join(lines) + "\n]\n" if lines else "") + fills)


def run_table(steps: int, every: int) -> str:
    return (f"[run]   # whole LGD steps (the thesis reports step counts)\nunit = \"steps\"\n"
            f"equilibration = 0\nproduction = {steps}\nsample_interval = {every}\n")


def rows_of(shape, rows: range, nxt: int) -> list[tuple[int, int, int]]:
    """(iy, ix1, ix2) of the nodes whose centres (x_phys = ix + ½[iy even], y = (iy−1)√3/2)
    ``shape(x, y)`` holds, as row runs."""
    out = []
    for iy in rows:
        xs = [ix for ix in range(1, nxt + 1) if shape(ix + 0.5 * (iy % 2 == 0),
                                                        (iy - 1) * ROW)]
        if xs:
            out.append((iy, xs[0], xs[-1]))
    return out


def gas_box() -> str:
    lines = [line(6, 1, 2, 96, 65, 4096, 0), line(6, 1, 66, 96, 129, -4096, 0)]
    return scene(
        "gas-box",
        "# Gutt (1989) §3 (L1035–L1059, figs 3.16–3.17): an elastic 2D gas in a box relaxes to "
        "a\n# Maxwellian: 4096 grains, 128 open rows × 258 columns (nyt = 130: the 128 rows are "
        "open,\n# plus the two wall rows; nxt = 258 = 6·43 passes the listing's multiple-of-6 "
        "check), 1024 steps.\n" + HEADER_UNITS["rms"].format(what="the initial speed v"),
        'description = "Elastic gas, 4096 grains, all at one speed, half +x, half -x; '
        'ASSUMED layout: a density-1/3 block of 96 columns x 128 rows, lower half +x, upper '
        'half -x, speed 4096 (figure 3.16a missing); wall restitution 1 assumed (not stated)"\n'
        'reference = "Gutt (1989), The Physics of Granular Systems, Ch. 3, L1035-L1059, '
        'figs 3.16-3.17"\n',
        "[contact]   # elastic (L1037)\nrestitution = 1.0\n" + walls(1.0, "assumed: not "
                                                                       "stated for the box"),
        "nxt = 258\nnyt = 130\n", lines, run_table(1024, 32))


def explosion() -> str:
    lines = [line(6, 1, 2, 288, 289)]  # background at rest, density 1/3
    x1, x2, y1, y2 = 128, 160, 128, 162  # 33 × 35 block around (144, 145)
    xc, yc = 144, 145
    v = 4096
    for iy in range(y1, y2 + 1):
        dy = iy - yc
        # outward along the axis of the nearest face: |dx| > |dy| → ±x, else ±y
        left_end = xc - abs(dy) - 1  # columns with dx < −|dy|
        right_start = xc + abs(dy) + 1
        if left_end >= x1:
            lines.append(line(2, x1, iy, left_end, iy, -v, 0))
        mid1, mid2 = max(x1, left_end + 1), min(x2, right_start - 1)
        vy = v if dy > 0 else -v if dy < 0 else 0
        lines.append(line(2, mid1, iy, mid2, iy, 0, vy) if mid2 > mid1 else
                     line(1, mid1, iy, 0, 0, 0, vy))  # one node: md 1 (its offset 0, 0)
        if right_start <= x2:
            lines.append(line(2, right_start, iy, x2, iy, v, 0))
    return scene(
        "explosion",
        "# Gutt (1989) §3 (L1061–L1067, figs 3.18–3.19): an explosion in a gas at rest tests "
        "the\n# lattice's isotropy: 288 × 288 at density 1/3, a central 33 × 35 block with "
        "velocities along\n# ±x or ±y, 128 steps: the front stays circular. nyt = 290 "
        "(derived: (nyt − 2) % 8 = 0 for\n# the 8 × 8 averages).\n" +
        HEADER_UNITS["rms"].format(what="the block's speed v (lattice.speed_scale)"),
        'description = "Explosion, 288 x 288 background at density 1/3 at rest; ASSUMED '
        'block: density 1, speed 4096, each grain moving outwards along the axis of the '
        'block face nearest to it (the block centre row moves along +-x; figure 3.18b '
        'missing, density and speed not stated)"\n'
        'reference = "Gutt (1989), Ch. 3, L1061-L1067, figs 3.18-3.19"\n',
        "[contact]   # elastic (L1065)\nrestitution = 1.0\n" + walls(1.0, "assumed"),
        "nxt = 288\nnyt = 290\nspeed_scale = 4096.0   # the block's speed (assumed) is the "
        "speed unit\n", lines, run_table(128, 16))


# Why random fills (Couette, Poiseuille): a layout uniform along x (e.g. every other row
# full) stays 6-column periodic for ever under the deterministic integer step (the templates
# repeat every 6 columns: tests/test_lgd_listing_order.py), so a long lattice would only be
# copies of a 6-column one; a seeded random fill at the same density breaks that.
def couette(name: str, e_pp: float, e_pw: float, speed: int, what: str) -> str:
    return scene(
        name,
        "# Gutt (1989) §3 (L1069–L1079, figs 3.20–3.23): gravity-free Couette flow between "
        "wall rows\n# moving at ±U: 5760 grains in a channel 60 rows wide and 192 long "
        "(5760 = ½·60·192, so\n# nyt = 62: 60 open rows + 2 wall rows, derived), 1024 "
        "steps.\n# " + what + "\n" + HEADER_UNITS["wall"],
        f'description = "Couette flow, e_pp = {e_pp}, e_pw = {e_pw}, walls at -+{speed} '
        '(the listing\'s integers; +-1 in particle units); ASSUMED layout: seeded random fill '
        '(figure missing): 5760 grains at rest on half the nodes of the 60 open rows '
        '(density 1/2, figure 3.20), drawn with run.seed"\n'
        'reference = "Gutt (1989), Ch. 3, L1069-L1079, figs 3.20-3.23"\n',
        f"[contact]\nrestitution = {e_pp}\n" +
        walls(e_pw, "e_pw", (-1.0, 1.0)),
        f"nxt = 192\nnyt = 62\nspeed_scale = {float(speed)}   # the wall speed in the "
        "listing's integers\n", [], run_table(1024, 32), fill(1, 2, 192, 61, 0.5))


def hourglass() -> str:
    # gravity along +x; funnel walls at 40.9° to it (user lines Δix = Δiy) end at ix = 120
    # leaving rows 56..67 open (12 nodes); an extra wall at ix = 240 closes the catch bin
    # the bin: 66 full columns plus a 10 × 39 block inside the funnel = 8310 grains; the
    # funnel walls are at ix = 65 + iy (rows 2..55) and ix = 188 − iy (rows 68..121)
    lines = [line(3, 1, 2, 66, 121), line(3, 67, 40, 76, 78)]
    lines += [line(-2, 120 - 53, 2, 120, 55), line(-2, 120, 68, 120 - 53, 121),
              line(-2, 240, 2, 240, 121)]
    return scene(
        "hourglass",
        "# Gutt (1989) §3 (L1081–L1091, figs 3.24–3.26): a hopper draining through a 12-node "
        "orifice:\n# 8310 grains, lattice 240 long × 122 wide, gravity along the long (x) "
        "axis (derived from the\n# periodic closure), bin walls at 41° to the vertical, "
        "bottom closed by an extra wall;\n# 2048 steps; the discharge count (grains past "
        "x = nxt/2) grows linearly.\n" + HEADER_UNITS["gravity"],
        'description = "Hourglass, 8310 grains; ASSUMED layout: a dense bin of 66 columns '
        'across the channel plus a 10 x 39 block in the funnel, funnel walls as '
        'user-diagonal lines (40.9 deg to gravity) from the side walls to x = 120, '
        'orifice rows 56-67, catch wall at '
        'x = 240 (figure 3.24a missing); grain-wall e assumed equal to grain-grain e"\n'
        'reference = "Gutt (1989), Ch. 3, L1081-L1091, figs 3.24-3.26"\n',
        GRANULAR + walls(0.75, "e_pw below c_b (assumed = e_pp)") +
        "\n[gravity]   # along +x: the channel axis\ndirection = [1.0, 0.0]\n",
        "nxt = 240\nnyt = 122\nwall_e2 = 0.9375   # e_pw above c_b (assumed = e_pp)\n",
        lines, run_table(2048, 32))


OBSTACLES = {
    "circle": "a disc of diameter 64 (½ the channel width)",
    "square": "a square of side 64",
    "triangle-up": "an equilateral triangle of side 64, apex upstream (against gravity)",
    "triangle-down": "an equilateral triangle of side 64, apex downstream",
}


def obstacle(kind: str) -> str:
    xc, yc, s = 100.0, 64 * ROW, 64.0  # centre: x = 100, mid-channel (rows 2..129)
    h = s * ROW
    shapes = {
        "circle": lambda x, y: (x - xc) ** 2 + (y - yc) ** 2 <= (s / 2) ** 2,
        "square": lambda x, y: abs(x - xc) <= s / 2 and abs(y - yc) <= s / 2,
        "triangle-up": lambda x, y: abs(y - yc) <= s / 2 and
        xc - h / 2 + abs(y - yc) * math.sqrt(3) <= x <= xc + h / 2,
        "triangle-down": lambda x, y: abs(y - yc) <= s / 2 and
        xc - h / 2 <= x <= xc + h / 2 - abs(y - yc) * math.sqrt(3),
    }
    body = rows_of(shapes[kind], range(2, 130), 288)
    inside = sum(x2 - x1 + 1 for _, x1, x2 in body)
    # the bed: dense, from x = 1 on, long enough for 16384 grains besides the obstacle
    columns, extra = divmod(16384 + inside, 128)
    lines = [line(3, 1, 2, columns, 129)]
    if extra:
        lines.append(line(2, columns + 1, 2, columns + 1, 1 + extra))
    lines += [line(-2, x1, iy, x2, iy) for iy, x1, x2 in body]
    lines += [line(-2, 200, 2, 200, 56), line(-2, 200, 75, 200, 129),  # restrictor, gap 18
              line(-2, 288, 2, 288, 129)]  # the catch box's end
    lines += [line(11 + k, 20, 8 + 14 * k) for k in range(9)]  # kale-seed markers
    return scene(
        f"obstacle-{kind}",
        "# Gutt (1989) §3 (L1093–L1107, figs 3.27–3.32): flow around an obstacle above a "
        "restrictor,\n# after Nedderman et al. (1980): 16384 grains, 288 × 130, an 18-node "
        "central gap in the\n# restrictor wall and a catch box below; obstacle: "
        f"{OBSTACLES[kind]};\n# positions at 512 steps, marker paths at 1536.\n" +
        HEADER_UNITS["gravity"],
        f'description = "Obstacle ({kind}), 16384 grains; ASSUMED layout: a dense bed from '
        f'x = 1 holding the obstacle (centre x = 100, mid-channel), restrictor wall at '
        f'x = 200 with rows 57-74 open, catch box closed at x = 288, 9 marked grains at '
        f'x = 20 (figure 3.28 missing); grain-wall e assumed equal to grain-grain e"\n'
        'reference = "Gutt (1989), Ch. 3, L1093-L1107, figs 3.27-3.32; Nedderman, Davies '
        '& Horton (1980)"\n',
        GRANULAR + walls(0.75, "e_pw below c_b (assumed = e_pp)") +
        "\n[gravity]   # along +x: down the channel\ndirection = [1.0, 0.0]\n",
        "nxt = 288\nnyt = 130\nwall_e2 = 0.9375   # e_pw above c_b (assumed = e_pp)\n",
        lines, run_table(1536, 32))


def incline() -> str:
    alpha = math.atan(math.sqrt(3) / 4)  # the user diagonal Δiy/Δix = ½ is level
    lines = [line(3, 1, 2, 144, 109), line(-2, 217, 2, 217 + 2 * 215, 217),
             line(11, 144, 109)]
    return scene(
        "incline",
        "# Gutt (1989) §3 (L1109–L1115, figs 3.33–3.34): a block of 144 × 108 grains (15552) "
        "slides\n# down a 23.4° slope onto a level run-out: lattice 432 × 218 (the periodic "
        "wrap replaces 720 × 218);\n# gravity is normal to a user-diagonal wall line "
        "(Δiy/Δix = ½: atan(√3/4) = 23.41° to the rows),\n# so the bottom wall row is the "
        "slope and the diagonal the run-out; 6144 steps.\n" + HEADER_UNITS["gravity"],
        'description = "Incline with run-out, 15552 grains; ASSUMED layout: the block at '
        'x = 1-144, rows 2-109, at rest; the run-out a diagonal wall from (217, 2) wrapping '
        'once round x to row 217; one marked grain at the block\'s top front corner '
        '(x = 144, row 109: a surface grain, the thesis\'s marker saltates; figure 3.33 '
        'missing); grain-wall e assumed equal to grain-grain e"\n'
        'reference = "Gutt (1989), Ch. 3, L1109-L1115, figs 3.33-3.34"\n',
        GRANULAR + walls(0.75, "e_pw below c_b (assumed = e_pp)") +
        f"\n[gravity]   # normal to the diagonal: 23.41° from −y towards +x\n"
        f"direction = [{math.sin(alpha)!r}, {-math.cos(alpha)!r}]\n",
        "nxt = 432\nnyt = 218\nwall_e2 = 0.9375   # e_pw above c_b (assumed = e_pp)\n",
        lines, run_table(6144, 48))


def poiseuille(nxt: int, name: str, note: str) -> str:
    grains = 63 * nxt  # density ½ of the 126 open rows
    return scene(
        name,
        "# Gutt (1989) §3 (L1117–L1127, figs 3.35–3.36): gravity-driven Poiseuille flow "
        "between the\n# wall rows, from rest: 508032 grains in 8064 × 128 (nyt = 128 with "
        "the walls: ½·8064·126,\n# derived), g = 8 along +x, e_pp = 0.9375, e_pw = 0.75 "
        "(constant), 18432 steps on 512 NCUBE\n# nodes in 27 h; expected steady wall shear "
        "g·N/N_wall (= 252 for the full run), ≈150 reached.\n" + note +
        HEADER_UNITS["gravity"],
        f'description = "Poiseuille flow, nxt = {nxt}, {grains} grains; ASSUMED layout: '
        'seeded random fill (figure missing): half the nodes of the 126 open rows '
        '(density 1/2), at rest, drawn with run.seed"\n'
        'reference = "Gutt (1989), Ch. 3, L1117-L1127, figs 3.35-3.36"\n',
        "[contact]   # velocity-independent (L1119)\nrestitution = 0.9375\n" +
        walls(0.75, "e_pw") + "\n[gravity]   # g = 8 along +x (L1119): gravity_scale\n"
                              "direction = [1.0, 0.0]\n",
        f"nxt = {nxt}\nnyt = 128\ngravity_scale = 8.0   # the thesis's g = 8 (L1119)\n",
        [], run_table(18432, 48), fill(1, 2, nxt, 127, 0.5))


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    files = {
        "gas-box": gas_box(), "explosion": explosion(),
        "couette-elastic-u4096": couette("couette-elastic-u4096", 1.0, 0.75, 4096,
                                   "Elastic grains (e_pp = 1, e_pw = 0.75), wall speed "
                                   "4096."),
        "couette-elastic-u16384": couette("couette-elastic-u16384", 1.0, 0.75, 16384,
                                      "As couette-elastic-u4096 with 4× the wall speed (16384): "
                                      "the thesis finds p, σ × 16;\n# in particle units "
                                      "(speed unit U) the two runs should coincide."),
        "couette-inelastic-u4096": couette("couette-inelastic-u4096", 0.75, 0.75, 4096,
                                     "Inelastic grains and walls (0.75/0.75), wall speed "
                                     "4096."),
        "hourglass": hourglass(),
        "incline": incline(),
        "poiseuille-small": poiseuille(504, "poiseuille-small",
                                 "# SCALED DOWN: nxt = 504 (1/16 of the length, the same "
                                 "width and steps); the full run is\n# the preset "
                                 "gutt1989/poiseuille-thesis.\n"),
        "poiseuille-thesis": poiseuille(8064, "poiseuille-thesis",
                                      "# The thesis's full size: 508032 grains (hours of "
                                      "native LGD here).\n"),
    }
    for kind in OBSTACLES:
        files[f"obstacle-{kind}"] = obstacle(kind)
    for name, text in files.items():
        (OUT / f"{name}.toml").write_text(text)
        print(f"wrote {OUT / name}.toml")


if __name__ == "__main__":
    main()
