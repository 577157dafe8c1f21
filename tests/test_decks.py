"""LAMMPS decks: each physical effect appears exactly when the scene asks for it.

Every test builds a small scene from a dict and toggles one effect, then checks the presence
AND the absence of its commands in ``build_deck(scene)``; the contact numbers are checked
against the analytic linear-spring results. Dimensionless particle units: d = 1, m = 1
(g = 1 when gravity acts).
"""

from __future__ import annotations

import copy
import math
import re
from pathlib import Path

import pytest

from demstudy.contact.discrete import DiscreteContact, mean_restitution
from demstudy.engines.lammps.deck import build_deck
from demstudy.engines.lammps.deck.system import DATA_FILE
from demstudy.errors import UnsupportedByEngine
from demstudy.scene import load_scene, validate_scene

ROOT = Path(__file__).resolve().parents[1]
LOWER = {"side": "lower", "restitution": 0.8}
UPPER = {"side": "upper", "restitution": 0.8}
ROUGH = {"model": "beta", "beta": 0.0}


def merge(target: dict, changes: dict) -> dict:
    """Recursive dict update; a value None deletes the key."""
    for key, value in changes.items():
        if value is None:
            target.pop(key, None)
        elif isinstance(value, dict) and isinstance(target.get(key), dict):
            merge(target[key], value)
        else:
            target[key] = copy.deepcopy(value)
    return target


@pytest.fixture
def make():
    """``make(dim=2, **changes)``: a small periodic scene of smooth particles, no gravity, no
    walls, no shear; ``changes`` are merged into it section by section."""

    def build(dim: int = 2, **changes):
        data = {
            "dimension": dim,
            "box": {"size": [10.0] * dim},
            "particles": {"count": 12},
            "contact": {"restitution": 0.9},
            "run": {"equilibration": 1.0, "production": 2.0, "sample_interval": 0.5},
        }
        return validate_scene(merge(data, changes))

    return build


def deck_of(scene):
    return build_deck(scene)


def fixes(deck) -> list[str]:
    return [c for c in deck.commands() if c.startswith("fix ")]


def with_prefix(deck, prefix: str) -> list[str]:
    return [c for c in deck.commands() if c.startswith(prefix)]


def data_file(deck) -> str:
    return deck.files[DATA_FILE]


# ---------------------------------------------------------------- the baseline: nothing extra
@pytest.mark.parametrize("dim", [2, 3])
def test_bare_scene_has_no_optional_effects(make, dim):
    deck = deck_of(make(dim))
    text = deck.render()
    effects = deck.effects()
    assert {"system", "contact", "integrate"} <= set(effects)
    assert not {"gravity", "lees-edwards"} & set(effects)
    assert not any(e.startswith("wall") for e in effects)
    assert ("enforce2d" in effects) == (dim == 2)
    for absent in ("fix gravity", "deform", "wall/gran", "linear_history", "nve/sphere",
                   "erotate", "group bumps", "pair_coeff 1 2", "move linear"):
        assert absent not in text, absent
    assert with_prefix(deck, "boundary") == ["boundary p p p"]
    assert "fix integrate mobile nve" in deck.commands()
    assert "1 atom types" in data_file(deck) and "xy xz yz" not in data_file(deck)


# ---------------------------------------------------------------- gravity
def test_gravity_only_when_present(make):
    assert not with_prefix(deck_of(make()), "fix gravity")
    chute = deck_of(make(gravity={"angle": 30.0}, walls=[LOWER], box={"size": [10.0, 20.0]}))
    assert with_prefix(chute, "fix gravity") == [
        "fix gravity mobile gravity 1 vector 0.5 -0.866025403784 0"]
    poiseuille = deck_of(make(3, gravity={"direction": [2.0, 0.0, 0.0], "magnitude": 0.5},
                              walls=[LOWER, UPPER]))
    assert with_prefix(poiseuille, "fix gravity") == ["fix gravity mobile gravity 0.5 vector 1 0 0"]
    assert "gravity" in poiseuille.effects()


# ---------------------------------------------------------------- tangential history
@pytest.mark.parametrize("dim", [2, 3])
def test_tangential_history_only_for_rough_contacts(make, dim):
    smooth = deck_of(make(dim))
    (pair,) = with_prefix(smooth, "pair_coeff")
    assert "linear_nohistory 0.0 0.0" in pair and "linear_history" not in smooth.render()
    rough = deck_of(make(dim, contact={"tangential": ROUGH}))
    (pair,) = with_prefix(rough, "pair_coeff")
    assert "tangential linear_history" in pair
    coulomb = deck_of(make(dim, contact={"tangential": {"model": "coulomb", "mu": 0.3}}))
    (pair,) = with_prefix(coulomb, "pair_coeff")
    # default beta0 = e: the damped copy of the normal oscillator, x_gamma_t = K / (1 + K)
    K = 0.5 if dim == 2 else 0.4
    kt, xt, mu = (float(x) for x in pair.split()[-3:])
    assert xt == pytest.approx(K / (1 + K)) and mu == 0.3
    assert kt == pytest.approx(K / (1 + K) * float(pair.split()[4]))


def test_rough_wall_alone_gives_wall_history_only(make):
    deck = deck_of(make(walls=[{**LOWER, "tangential": {"model": "rough"}}]))
    (pair,) = with_prefix(deck, "pair_coeff")
    (wall,) = with_prefix(deck, "fix wall_lower")
    assert "linear_nohistory" in pair and "linear_history" in wall
    assert "fix integrate mobile nve/sphere disc" in deck.commands(), "the wall spins discs"


# ---------------------------------------------------------------- shear
@pytest.mark.parametrize("dim", [2, 3])
def test_deform_only_with_shear(make, dim):
    assert "deform" not in deck_of(make(dim)).render()
    deck = deck_of(make(dim, shear={"rate": 0.5}))
    assert with_prefix(deck, "fix lees_edwards") == [
        "fix lees_edwards all deform 1 xy variable v_lees_edwards_tilt v_lees_edwards_rate "
        "remap v flip yes"]
    # the tilt grows at γ̇ L_y = 0.5 × 10 from the moment the fix is defined
    assert "variable lees_edwards_rate equal 5" in deck.commands()
    assert "variable lees_edwards_tilt equal 5*(time-v_lees_edwards_t0)" in deck.commands()
    assert "0 0 0 xy xz yz" in data_file(deck), "a triclinic box for Lees-Edwards"
    assert with_prefix(deck, "boundary") == ["boundary p p p"]


# ---------------------------------------------------------------- integration
@pytest.mark.parametrize(("dim", "style"), [(2, "nve/sphere disc"), (3, "nve/sphere")])
def test_rotation_integrated_only_when_it_matters(make, dim, style):
    smooth = deck_of(make(dim, initial={"velocity": {"temperature": 1.0}}))
    assert with_prefix(smooth, "fix integrate") == ["fix integrate mobile nve"]
    assert "erotate/sphere" not in smooth.render()
    rough = deck_of(make(dim, contact={"tangential": ROUGH}))
    assert with_prefix(rough, "fix integrate") == [f"fix integrate mobile {style}"]
    assert "compute erot mobile erotate/sphere" in rough.commands()
    partial = deck_of(make(dim, contact={"tangential": {"model": "beta", "beta": 0.5}}))
    assert with_prefix(partial, "fix integrate") == [f"fix integrate mobile {style}"]


@pytest.mark.parametrize("changes", [
    {},
    {"gravity": {"angle": 20.0}, "walls": [LOWER]},
    {"walls": [LOWER, {**UPPER, "velocity": 1.0}], "contact": {"tangential": ROUGH}},
    {"walls": [{**LOWER, "kind": "bumpy", "bumps": {}}], "gravity": {"angle": 30.0}},
    {"shear": {"rate": 1.0}},
])
def test_enforce2d_only_in_2d_and_last(make, changes):
    deck2 = deck_of(make(2, **changes))
    assert fixes(deck2)[-1] == "fix enforce2d all enforce2d"
    assert sum("enforce2d" in c for c in deck2.commands()) == 1
    assert "enforce2d" in deck2.effects()
    changes3 = copy.deepcopy(changes)
    if "gravity" in changes3 and "angle" in changes3["gravity"]:
        changes3["gravity"] = {"direction": [0.5, -1.0, 0.0]}
    deck3 = deck_of(make(3, **changes3))
    assert "enforce2d" not in deck3.render() and "enforce2d" not in deck3.effects()


@pytest.mark.parametrize("bumpy", [False, True])
def test_density_disc_only_in_2d(make, bumpy):
    wall = {**LOWER, "kind": "bumpy", "bumps": {}} if bumpy else LOWER
    deck2 = deck_of(make(2, walls=[wall]))
    assert "set type 1 density/disc 1.27323954473516" in deck2.commands()
    assert ("set type 2 density/disc" in deck2.render()) == bumpy
    deck3 = deck_of(make(3, walls=[wall]))
    assert "density/disc" not in deck3.render()
    assert "dimension 3" in deck3.commands() and "dimension 2" in deck2.commands()


# ---------------------------------------------------------------- walls and boundaries
@pytest.mark.parametrize("dim", [2, 3])
def test_walls_one_fix_each_and_shear_only_when_moving(make, dim):
    none = deck_of(make(dim))
    assert "wall/gran" not in none.render() and not any(e.startswith("wall") for e in
                                                        none.effects())
    one = deck_of(make(dim, walls=[LOWER]))
    (lower,) = [c for c in fixes(one) if "wall/gran" in c]
    assert lower.startswith("fix wall_lower mobile wall/gran granular hooke")
    assert lower.endswith("yplane 0 NULL contacts") and " shear " not in lower
    assert with_prefix(one, "boundary") == ["boundary p fm p"]
    two = deck_of(make(dim, walls=[LOWER, {**UPPER, "velocity": 1.5}]))
    walls = [c for c in fixes(two) if "wall/gran" in c]
    assert len(walls) == 2 and two.effects().count("wall:lower") == 1
    lower, upper = walls
    assert lower.startswith("fix wall_lower") and " shear " not in lower
    assert upper.startswith("fix wall_upper")
    assert upper.endswith("yplane NULL 10 shear x 1.5 contacts")
    assert with_prefix(two, "boundary") == ["boundary p f p"]
    assert sum(c.startswith("compute wall_") for c in two.commands()) == 2
    moving_lower = deck_of(make(dim, walls=[{**LOWER, "velocity": -2.0}, UPPER]))
    lower, upper = [c for c in fixes(moving_lower) if "wall/gran" in c]
    assert "shear x -2 contacts" in lower and " shear " not in upper


def test_wall_positions_and_data_bounds(make):
    deck = deck_of(make(walls=[{**LOWER, "position": 1.0}, {**UPPER, "position": 9.0}]))
    lower, upper = [c for c in fixes(deck) if "wall/gran" in c]
    assert "yplane 1 NULL" in lower and "yplane NULL 9" in upper
    assert "1 9 ylo yhi" in data_file(deck)


@pytest.mark.parametrize("dim", [2, 3])
def test_bumps_only_for_bumpy_walls(make, dim):
    flat = deck_of(make(dim, walls=[LOWER]))
    text = flat.render()
    for absent in ("group bumps", "pair_coeff 1 2", "neigh_modify exclude type 2 2",
                   "fix bumps_lower", "type 2", "bumps_lower_force"):
        assert absent not in text, absent
    assert "1 atom types" in data_file(flat)
    bumpy = deck_of(make(dim, walls=[{**LOWER, "kind": "bumpy", "bumps": {"spacing": 2.0}}]))
    commands = bumpy.commands()
    assert "group bumps_lower type 2" in commands
    assert "neigh_modify exclude type 2 2" in commands
    assert len(with_prefix(bumpy, "pair_coeff 1 2")) == 1
    assert with_prefix(bumpy, "fix bumps_lower") == [
        "fix bumps_lower_move bumps_lower move linear 0 0.0 0.0"]
    # the bumps' reaction is part of the wall force
    assert "compute bumps_lower_force bumps_lower reduce sum fx fy fz" in commands
    assert "c_bumps_lower_force[*]" in with_prefix(bumpy, "fix wall_forces")[0]
    data = data_file(bumpy)
    n_bumps = 5 if dim == 2 else 25  # 10 / 2.0 per periodic direction
    assert "2 atom types" in data and f"{12 + n_bumps} atoms" in data
    atoms = data.split("Atoms # sphere")[1].split("Velocities")[0].split("\n")
    assert sum(line.split()[1:2] == ["2"] for line in atoms if line.strip()) == n_bumps


def test_two_bumpy_walls_have_their_own_types_rules_and_motion(make):
    lower = {**LOWER, "kind": "bumpy", "bumps": {}, "restitution": 0.5,
             "tangential": {"model": "smooth"}}
    upper = {**UPPER, "kind": "bumpy", "bumps": {}, "restitution": 0.95, "velocity": 1.0,
             "tangential": {"model": "rough"}}
    deck = deck_of(make(walls=[lower, upper]))
    commands = deck.commands()
    assert "group bumps_lower type 2" in commands and "group bumps_upper type 3" in commands
    (pair_lower,) = with_prefix(deck, "pair_coeff 1 2")
    (pair_upper,) = with_prefix(deck, "pair_coeff 1 3")
    # each wall's e (the damping's, compensated for the time step: +0.004 at e = 0.5)
    assert 0.5 < float(pair_lower.split()[5]) < 0.505 and "linear_nohistory" in pair_lower
    assert abs(float(pair_upper.split()[5]) - 0.95) < 1e-3 and "linear_history" in pair_upper
    assert with_prefix(deck, "neigh_modify exclude") == [
        "neigh_modify exclude type 2 2", "neigh_modify exclude type 2 3",
        "neigh_modify exclude type 3 3"]
    assert "fix bumps_lower_move bumps_lower move linear 0 0.0 0.0" in commands
    assert "fix bumps_upper_move bumps_upper move linear 1 0.0 0.0" in commands
    data = data_file(deck)
    assert "3 atom types" in data
    # the box holds the bump centres, which sit on the wall planes
    lo, hi = map(float, next(x for x in data.splitlines() if "ylo" in x).split()[:2])
    assert lo < 0.0 and hi > 10.0


def test_bumpy_wall_pair_uses_the_wall_contact(make):
    deck = deck_of(make(walls=[{**LOWER, "kind": "bumpy", "bumps": {},
                                "tangential": {"model": "rough"}}]))
    (bump_pair,) = with_prefix(deck, "pair_coeff 1 2")
    (wall,) = [c for c in fixes(deck) if "wall/gran" in c]
    args = wall.split("wall/gran granular ")[1].split(" yplane")[0]
    assert bump_pair == f"pair_coeff 1 2 {args}"


@pytest.mark.parametrize(("dim", "changes", "boundary"), [
    (2, {}, "p p p"),
    (3, {}, "p p p"),
    (2, {"walls": [LOWER]}, "p fm p"),
    (3, {"walls": [LOWER]}, "p fm p"),
    (2, {"walls": [LOWER, UPPER]}, "p f p"),
    (3, {"walls": [LOWER, UPPER]}, "p f p"),
    (2, {"shear": {"rate": 1.0}}, "p p p"),
])
def test_boundary(make, dim, changes, boundary):
    assert with_prefix(deck_of(make(dim, **changes)), "boundary") == [f"boundary {boundary}"]


# ---------------------------------------------------------------- contact numbers
def hooke_contact_time(kn: float, e: float, m_eff: float) -> float:
    """Damped linear spring: t_c = π / ω_d, damping from e (independent of the package)."""
    zeta = -math.log(e) / math.sqrt(math.pi**2 + math.log(e) ** 2)
    omega0 = math.sqrt(kn / m_eff)
    return math.pi / (omega0 * math.sqrt(1.0 - zeta**2))


def analytic_kt(beta: float, kn: float, e: float, m_eff: float, K: float) -> float:
    """β = −cos(ω_t t_c), ω_t² = k_t (1 + K)/(K m_eff)."""
    omega_t = math.acos(-beta) / hooke_contact_time(kn, e, m_eff)
    return omega_t**2 * K * m_eff / (1.0 + K)


def granular_numbers(args: str) -> dict:
    """k_n, e, tangential style, k_t and μ of a ``granular`` model string (hooke normal)."""
    match = re.search(r"hooke (\S+) (\S+) damping coeff_restitution tangential (\S+) (.*?)"
                      r"(?: yplane|$)", args)
    assert match, args
    kn, e, style, rest = match.groups()
    values = [float(v) for v in rest.split()]
    if style == "linear_nohistory":  # x_gamma_t, mu_s
        kt, mu = 0.0, values[1]
    else:  # linear_history: k_t, x_gamma_t, mu_s
        kt, mu = values[0], values[2]
    return {"kn": float(kn), "e": float(e), "style": style, "kt": kt, "mu": mu}


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("e", [0.6, 0.9, 1.0])
@pytest.mark.parametrize(("beta", "beta_w"), [(-0.5, 0.99), (0.0, 0.0), (0.5, 1.0), (0.99, -0.9)])
def test_kt_matches_target_beta(make, dim, e, beta, beta_w):
    scene = make(dim, contact={"restitution": e, "tangential": {"model": "beta", "beta": beta}},
                 walls=[{"side": "lower", "restitution": 0.7,
                         "tangential": {"model": "beta", "beta": beta_w}}],
                 soft={"stiffness": 2e5})
    K = 0.5 if dim == 2 else 0.4
    deck = deck_of(scene)
    dt = float(with_prefix(deck, "timestep")[0].split()[1])
    (pair,) = with_prefix(deck, "pair_coeff")
    (wall,) = [c for c in fixes(deck) if "wall/gran" in c]
    for args, e_c, m_eff, target in ((pair, e, 0.5, beta), (wall, 0.7, 1.0, beta_w)):
        numbers = granular_numbers(args)
        # the deck's damping e is compensated for the time step (+0.002 at e = 0.6)
        assert numbers["kn"] == 2e5 and e_c <= numbers["e"] < e_c + 5e-3
        assert numbers["style"] == "linear_history"
        assert numbers["mu"] >= 1e19, "no Coulomb cap: β is constant"
        # the deck's k_t gives β back in LAMMPS's discrete update at this contact's own steps
        # per contact (averaged over impact phases, resolved to ~5e-4; contact.discrete
        # reproduces LAMMPS)
        tc = hooke_contact_time(2e5, e_c, m_eff)
        c = DiscreteContact(2e5, numbers["e"], m_eff, K, numbers["kt"], wall=m_eff == 1.0)
        e_got, beta_got = mean_restitution(c, tc, tc / dt)
        assert beta_got == pytest.approx(target, abs=1e-3)
        assert e_got == pytest.approx(e_c, abs=1e-3)
        # ... a first-order correction (~1/S) of the continuous −cos(ω_t t_c) = β spring
        ratio = numbers["kt"] / analytic_kt(target, 2e5, e_c, m_eff, K)
        assert 0.9 < ratio < 1.0


@pytest.mark.parametrize("steps", [10.0, 50.0, 333.0])
@pytest.mark.parametrize("e_w", [0.5, 1.0])
def test_timestep_resolves_every_contact(make, steps, e_w):
    scene = make(3, contact={"restitution": 0.8, "tangential": ROUGH},
                 walls=[{"side": "lower", "restitution": e_w}, {"side": "upper",
                                                                "restitution": 0.9}],
                 soft={"stiffness": 1e6, "steps_per_contact": steps})
    deck = deck_of(scene)
    (timestep,) = with_prefix(deck, "timestep")
    dt = float(timestep.split()[1])
    contact_times = [hooke_contact_time(1e6, 0.8, 0.5), hooke_contact_time(1e6, e_w, 1.0),
                     hooke_contact_time(1e6, 0.9, 1.0)]
    for t_c in contact_times:
        assert t_c / dt >= steps * (1 - 1e-9)
    assert min(contact_times) / dt == pytest.approx(steps, rel=1e-8), "no smaller than needed"


def test_hardness_sets_the_overlap(make):
    """k_n from hardness.overlap: the pair's maximum overlap at impact_speed is the target."""
    scene = make(contact={"restitution": 0.7}, soft={"hardness": {"overlap": 0.01,
                                                                 "impact_speed": 2.0}})
    numbers = granular_numbers(with_prefix(deck_of(scene), "pair_coeff")[0])
    kn, m_eff, v, e = numbers["kn"], 0.5, 2.0, 0.7
    zeta = -math.log(e) / math.sqrt(math.pi**2 + math.log(e) ** 2)
    omega0 = math.sqrt(kn / m_eff)
    omega_d = omega0 * math.sqrt(1 - zeta**2)
    t_max = math.atan2(omega_d, zeta * omega0) / omega_d  # velocity zero
    x_max = v / omega_d * math.exp(-zeta * omega0 * t_max) * math.sin(omega_d * t_max)
    assert x_max == pytest.approx(0.01, rel=1e-9)


def test_run_lengths_in_steps(make):
    scene = make(soft={"stiffness": 1e5}, run={"equilibration": 3.0, "production": 7.0,
                                               "sample_interval": 0.5})
    deck = deck_of(scene)
    dt = float(with_prefix(deck, "timestep")[0].split()[1])
    runs = [int(c.split()[1]) for c in with_prefix(deck, "run ")]
    assert runs == [math.ceil(3.0 / dt - 1e-9), math.ceil(7.0 / dt - 1e-9)]
    no_eq = deck_of(make(run={"equilibration": 0.0, "production": 2.0}))
    assert len(with_prefix(no_eq, "run ")) == 1 and "reset_timestep" not in no_eq.render()


# ---------------------------------------------------------------- what LAMMPS cannot do
def test_campbell_noslip_couette_validates_but_is_unsupported():
    scene = load_scene(ROOT / "inputs/campbell1982/couette-noslip.toml")
    with pytest.raises(UnsupportedByEngine) as info:
        build_deck(scene)
    field = "walls.tangential.model"
    assert field in info.value.field_name and field in str(info.value)
    assert info.value.engine == "lammps"


def test_servo_without_interval_time_is_unsupported():
    data = load_scene(ROOT / "inputs/campbell1982/couette-rough.toml").model_dump(mode="json")
    for wall in data["walls"]:
        wall["servo"].pop("interval_time")
    scene = validate_scene(data)
    with pytest.raises(UnsupportedByEngine) as info:
        build_deck(scene)
    assert "servo.interval_time" in info.value.field_name


def test_collision_counted_runs_are_unsupported(make):
    with pytest.raises(UnsupportedByEngine, match="run.unit"):
        build_deck(make(run={"equilibration": 1.0, "production": 2.0, "unit": "collisions"}))


def test_campbell_rough_couette_runs_on_servo_walls():
    deck = build_deck(load_scene(ROOT / "inputs/campbell1982/couette-rough.toml"))
    assert deck.effects().count("wall:lower") == 1 and deck.effects().count("wall:upper") == 1
    assert "wall/gran/region" in deck.render()


def _savetxt(rows) -> str:
    """The data file's tables as numpy.savetxt wrote them before format_rows."""
    import io

    import numpy as np

    buffer = io.StringIO()
    np.savetxt(buffer, rows, fmt="%.17g")
    return buffer.getvalue().rstrip("\n")


@pytest.mark.parametrize("dim", [2, 3])
def test_data_file_tables_are_savetxt_text_and_round_trip(make, dim):
    """format_rows writes what numpy.savetxt wrote with %.17g, character for character, and
    that text parses back to the very same doubles: positions, velocities, spins, the bumps'
    rows and types, and values chosen to be hard (near powers of ten and ties, tiny, huge,
    negative zero, inf, nan)."""
    import numpy as np

    from demstudy.effects.bumps import bump_rows
    from demstudy.engines.lammps.deck.system import data_rows, format_rows
    from demstudy.scene.initial import build_initial_state

    scene = make(dim, particles={"count": 40},
                 walls=[{**LOWER, "kind": "bumpy", "bumps": {"pattern": "random"}},
                        {**UPPER, "kind": "bumpy", "bumps": {}}],
                 initial={"velocity": {"temperature": 1.0}})
    atoms, velocities = data_rows(scene, build_initial_state(scene), bump_rows(scene))
    assert {2, 3} <= set(atoms[:, 1])  # both walls' bumps are in the tables
    rng = np.random.default_rng(7)
    near_ten = [np.nextafter(10.0**k, t) for k in range(-13, 19) for t in (0.0, np.inf)]
    hard = np.array(near_ten + [10.0**k for k in range(-13, 19)] + [
        0.5, 2.5, 1e-5, 1e-11, 9.999999999999999e-12, 1.5e-300, 5e-324, 1.7976931348623157e308,
        1e17, 12345678901234567.0, 0.0, -0.0, np.inf, -np.inf, np.nan, 6 / math.pi, 1e6])
    tables = [atoms, velocities, np.concatenate([hard, -hard]).reshape(-1, 2),
              rng.normal(size=(3000, 3)) * 10.0 ** rng.integers(-15, 18, (3000, 3)),
              rng.integers(0, 2**63, (3000, 2)).view(np.float64)]  # any bit pattern
    for rows in tables:
        text = format_rows(rows)
        assert text == _savetxt(rows)
        back = np.array([[float(v) for v in line.split()] for line in text.split("\n")])
        finite = ~np.isnan(rows)
        assert np.array_equal(np.isnan(back), ~finite)
        assert np.array_equal(back[finite].view(np.int64), rows[finite].view(np.int64))
    assert format_rows(np.zeros((0, 3))) == ""


def test_deck_without_data_file_builds_no_initial_state(make, monkeypatch):
    """``build_deck(data=False)``, as a run builds it (its atoms come from memory): the same
    commands, no data file, and no initial state built for it."""
    import demstudy.engines.lammps.deck as deck_module

    scene = make(2, walls=[LOWER, UPPER])
    full = build_deck(scene)

    def refuse(*args, **kwargs):
        raise AssertionError("an initial state was built")

    monkeypatch.setattr(deck_module, "build_initial_state", refuse)
    bare = build_deck(scene, data=False)
    assert DATA_FILE not in bare.files and DATA_FILE in full.files
    assert bare.render() == full.render()
