"""The LAMMPS engine driven from Python: conservation laws, capture paths, errors, resume, MPI.

Dimensionless particle units: d = 1, m = 1, g = 1.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from demstudy.engines.lammps import LammpsSession
from demstudy.errors import EngineError, UnsupportedByEngine
from demstudy.io.results import read_results
from demstudy.scene import load_scene, validate_scene
from demstudy.simulation import RunOptions, Simulation, run_scene
from demstudy.simulation.checkpoint import pickle_atomically

ROOT = Path(__file__).resolve().parent.parent
CHUTE = ROOT / "inputs" / "campbell1982" / "chute-30.toml"


def chute(**run) -> object:
    settings = {"run.equilibration": 2.0, "run.production": 6.0, "run.sample_interval": 0.25}
    settings.update({f"run.{k}": v for k, v in run.items()})
    return load_scene(CHUTE, [f"{k}={v}" for k, v in settings.items()])


def run(scene, tmp_path: Path, name: str = "run.h5", **options) -> object:
    path = run_scene(scene, "lammps", RunOptions(out=tmp_path / name, progress=False, **options))
    return read_results(path)


def run_interrupted(scene, tmp_path: Path, name: str, monkeypatch, after: float,
                    **options) -> None:
    """Run until the first sample after time ``after``, then request a stop exactly as the
    SIGINT handler does (the driver stops at the end of the segment, after a checkpoint)."""
    original = Simulation._sample

    def interrupt(self, state, production):
        original(self, state, production)
        if self.backend.time > after:
            self.stop.request()

    with monkeypatch.context() as patch:
        patch.setattr(Simulation, "_sample", interrupt)
        with pytest.raises(EngineError, match="--resume"):
            run(scene, tmp_path, name, **options)
    assert not (tmp_path / name).exists()


def test_wall_forces_close_the_momentum_balance(tmp_path):
    """Σ (wall force on the particles) dt = Δp − M g T, component by component: the wall
    force record, its sign and its time averaging are exact up to O(dt) end terms."""
    scene = chute()
    res = run(scene, tmp_path)
    ts = res.timeseries
    t, p = ts["time"], ts["momentum"]
    on_wall = ts["wall_force_lower"][1:]  # force of the particles on the wall
    interval = np.diff(t)
    impulse_on_particles = -(on_wall * interval[:, None]).sum(axis=0)
    g = np.array(scene.gravity_vector)
    weight_impulse = scene.n_particles * g * (t[-1] - t[0])
    expected = p[-1] - p[0] - weight_impulse
    scale = np.abs(weight_impulse).max()
    assert np.all(np.abs(impulse_on_particles - expected) < 2e-3 * scale), (
        impulse_on_particles, expected)
    # the bed presses on the base: the mean normal force is close to the weight N g cos α
    normal = on_wall[:, 1].mean()
    assert normal == pytest.approx(-scene.n_particles * math.cos(math.radians(30)), rel=0.25)


def test_profiles_cover_every_particle(tmp_path):
    """Σ_bins ν · (bin area) = N π/4: no particle is lost or counted twice. Soft discs
    overlap the base by up to ~1e-3 d; the sliver below y = 0 lies outside the bins, so the
    tolerance is 1e-4 (one lost disc would be 2.5e-2)."""
    scene = chute()
    res = run(scene, tmp_path)
    prof = res.profiles
    total = np.sum(prof["solid_fraction"]) * res.profile_attrs["bin_width"] * scene.box.size[0]
    assert total == pytest.approx(scene.n_particles * math.pi / 4, rel=1e-4)


@pytest.mark.parametrize(("reader", "rtol"), [("read_dump_fast", 1e-12), ("read_dump", 1e-5)])
def test_in_memory_and_dump_profiles_agree(tmp_path, reader, rtol):
    """The dump holds every production sample at full precision: the numpy reader gives the
    in-memory profiles to round-off, MDAnalysis (single precision) to 1e-5."""
    from demstudy.analysis.suite import profile_analysis
    from demstudy.io import dump as dumps

    scene = chute()
    dump = tmp_path / "frames.dump"
    res = run(scene, tmp_path, dump=dump)
    analysis = profile_analysis(scene)
    analysis.run(getattr(dumps, reader)(dump, scene.dimension, dt=res.attrs["timestep"]))
    analysis.finish()
    assert analysis.attrs["samples"] == res.profile_attrs["samples"]
    for key in ("solid_fraction", "velocity", "temperature", "rotational_temperature"):
        np.testing.assert_allclose(analysis.results[key], res.profiles[key], rtol=rtol,
                                   atol=rtol, err_msg=key)


def rolling_pair(**run) -> object:
    """Two rough discs, one on the other, toppling and rolling down a 20° incline: lasting
    contacts with loaded tangential springs (pair and wall), and no chaos to amplify
    round-off."""
    return validate_scene({
        "dimension": 2, "box": {"size": [6.0, 10.0]},
        "contact": {"restitution": 0.6, "tangential": {"model": "beta", "beta": 0.5}},
        "walls": [{"side": "lower", "restitution": 0.8,
                   "tangential": {"model": "beta", "beta": 0.5}}],
        "gravity": {"angle": 20.0},
        "particles": {},
        "initial": {"placement": "lattice", "rows": 2, "columns": 1, "spacing": 1.02,
                    "jitter": False, "velocity": {"profile": "uniform", "scale": 0.3}},
        "run": {"equilibration": 0.5, "production": 2.0, "sample_interval": 0.25,
                "checkpoint_interval": 0.5, **run},
        "soft": {"stiffness": 1e5, "steps_per_contact": 50},
    })


def test_resume_after_interruption_continues_exactly(tmp_path, monkeypatch):
    """A run interrupted after a checkpoint and resumed ends where the uninterrupted run
    ends: positions, velocities, spins and contact histories all survive the restart."""
    scene = rolling_pair()
    whole = run(scene, tmp_path, "whole.h5", keep_frames=True)
    run_interrupted(scene, tmp_path, "parts.h5", monkeypatch, 1.1, keep_frames=True)
    parts = run(scene, tmp_path, "parts.h5", keep_frames=True, resume=True)

    np.testing.assert_array_equal(whole.timeseries["time"], parts.timeseries["time"])
    # Restart files are binary-exact and the forces are carried over; the neighbour lists are
    # rebuilt, so round-off differs inside the stiff contacts (k_n = 1e5). A lost tangential
    # history would show as ~1e-2 (its force, m g sin α, acting for 0.25 time units).
    for key, tol in (("position", 1e-8), ("velocity", 1e-6), ("angular_velocity", 1e-6)):
        np.testing.assert_allclose(parts.frames[key], whole.frames[key], rtol=0, atol=tol,
                                   err_msg=key)
    # the discs were rolling with loaded springs when the run was cut
    assert np.all(np.abs(whole.frames["angular_velocity"][-1]) > 0.1)
    np.testing.assert_allclose(parts.profiles["velocity"], whole.profiles["velocity"],
                               atol=1e-6)


def test_checkpoints_and_resume_leave_a_collisional_flow_as_it_was(tmp_path, monkeypatch):
    """Campbell's chute (dissipative collisions, chaotic): a run with checkpoints, and one
    interrupted and resumed, follow the run without checkpoints to round-off. Restart files
    lack the forces; set up again, LAMMPS would recompute the damping from full-step
    velocities, a one-step kick that chaos amplified to 5 % of the kinetic energy (measured
    before the forces were carried over)."""
    settings = {"equilibration": 0.5, "production": 2.0, "sample_interval": 0.25}
    plain = run(chute(**settings), tmp_path, "plain.h5")
    scene = chute(**settings, checkpoint_interval=0.5)
    whole = run(scene, tmp_path, "whole.h5")
    run_interrupted(scene, tmp_path, "parts.h5", monkeypatch, 1.1)
    parts = run(scene, tmp_path, "parts.h5", resume=True)
    ke = plain.timeseries["kinetic_energy"]
    assert ke.max() > 100.0  # a flowing bed: collisions all along
    for other in (whole, parts):
        np.testing.assert_array_equal(other.timeseries["time"], plain.timeseries["time"])
        np.testing.assert_allclose(other.timeseries["kinetic_energy"], ke, rtol=1e-8)


def test_a_checkpoint_cut_off_while_written_leaves_the_previous_pair(tmp_path, monkeypatch):
    """The second checkpoint's state pickle fails (a full disk) after its restart file was
    written: the resumed run continues from the first checkpoint, a consistent pair (the
    pickle names its restart file), and ends where the uninterrupted run ends."""
    import errno

    import demstudy.simulation.loop as driver

    scene = rolling_pair()
    whole = run(scene, tmp_path, "whole.h5")
    original, calls = driver.pickle_atomically, []

    def full_disk_on_second(path, obj):
        calls.append(obj["run"].samples)
        if len(calls) == 2:
            raise OSError(errno.ENOSPC, "No space left on device")
        original(path, obj)

    with monkeypatch.context() as patch:
        patch.setattr(driver, "pickle_atomically", full_disk_on_second)
        with pytest.raises(OSError, match="No space left"):
            run(scene, tmp_path, "parts.h5")
    workdir = tmp_path / "parts.lammps"
    assert len(list(workdir.glob("checkpoint-*.restart"))) == 2  # the orphan is not named
    parts = run(scene, tmp_path, "parts.h5", resume=True)
    np.testing.assert_array_equal(whole.timeseries["time"], parts.timeseries["time"])
    # a mismatched pair would shift every later sample by one checkpoint interval (0.5)
    np.testing.assert_allclose(parts.timeseries["kinetic_energy"],
                               whole.timeseries["kinetic_energy"], rtol=1e-4)
    assert not list(workdir.glob("checkpoint*"))


def test_resume_refuses_what_it_cannot_continue(tmp_path, monkeypatch):
    """A changed --keep-frames or --dump, an unreadable state pickle (named) and one written
    by another version are refused; the intact checkpoint then resumes."""
    import pickle

    scene = rolling_pair()
    run_interrupted(scene, tmp_path, "r.h5", monkeypatch, 0.6)
    state = tmp_path / "r.lammps" / "checkpoint.pkl"
    saved = pickle.loads(state.read_bytes())
    assert saved["units"].startswith("dimensionless particle units")
    with pytest.raises(EngineError, match="keep-frames"):
        run(scene, tmp_path, "r.h5", resume=True, keep_frames=True)
    with pytest.raises(EngineError, match="--dump"):
        run(scene, tmp_path, "r.h5", resume=True, dump=tmp_path / "new.dump")
    intact = state.read_bytes()
    state.write_bytes(intact[:200])
    with pytest.raises(EngineError, match=r"checkpoint .*checkpoint.pkl is damaged"):
        run(scene, tmp_path, "r.h5", resume=True)
    pickle_atomically(state, {**saved, "version": "demstudy 0.0"})
    with pytest.raises(EngineError, match="written by demstudy 0.0"):
        run(scene, tmp_path, "r.h5", resume=True)
    state.write_bytes(intact)
    assert run(scene, tmp_path, "r.h5", resume=True).attrs["engine"] == "lammps"


def test_resume_refuses_a_damaged_restart_file(tmp_path, monkeypatch):
    """Bytes flipped in the LAMMPS restart file the checkpoint names (read_restart then spun
    for minutes, past --wall-limit): --resume refuses it by name before LAMMPS reads it and
    writes nothing; put back, the same checkpoint resumes."""
    scene = rolling_pair()
    run_interrupted(scene, tmp_path, "r.h5", monkeypatch, 0.6)
    (restart,) = (tmp_path / "r.lammps").glob("checkpoint-*.restart")
    intact = restart.read_bytes()
    data = bytearray(intact)
    data[len(data) // 2] ^= 0x55
    restart.write_bytes(bytes(data))
    with pytest.raises(EngineError) as info:
        run(scene, tmp_path, "r.h5", resume=True)
    assert str(info.value) == (f"--resume: checkpoint {restart} is damaged (checksum "
                               "mismatch); remove the work folder to start afresh")
    assert not (tmp_path / "r.h5").exists()
    assert restart.read_bytes() == bytes(data)  # nothing rewritten
    restart.write_bytes(intact)
    assert run(scene, tmp_path, "r.h5", resume=True).attrs["engine"] == "lammps"


def test_resume_refuses_a_changed_scene(tmp_path, monkeypatch):
    scene = rolling_pair()
    run_interrupted(scene, tmp_path, "r.h5", monkeypatch, 0.6)
    with pytest.raises(EngineError, match=r"different scene \(run.seed: \d+ in the checkpoint, "
                                          r"7 now\)"):
        run(rolling_pair(seed=7), tmp_path, "r.h5", resume=True)


def test_lammps_errors_name_the_deck_line(tmp_path):
    session = LammpsSession(tmp_path)
    session.command("units lj")
    with pytest.raises(EngineError) as info:
        session.command("fix broken all no/such/style")
    assert "deck line: fix broken all no/such/style" in str(info.value)
    assert "ERROR" in str(info.value)
    session.close()


def test_unsupported_wall_rule_is_refused_before_lammps_starts(tmp_path):
    scene = load_scene(ROOT / "inputs" / "campbell1982" / "couette-noslip.toml")
    with pytest.raises(UnsupportedByEngine, match="campbell-noslip"):
        run_scene(scene, "lammps", RunOptions(out=tmp_path / "x.h5", progress=False))
    assert not (tmp_path / "x.lammps").exists()


def test_elastic_smooth_gas_conserves_energy(tmp_path):
    """e = 1, smooth, no walls, no gravity: a soft elastic gas keeps its kinetic energy up
    to the O((dt/t_c)²) error of velocity Verlet. A sample taken during a contact misses the
    elastic energy stored in it, so KE may dip there but never rise above E0."""
    scene = validate_scene({
        "dimension": 3, "box": {"size": [8.0, 8.0, 8.0]},
        "particles": {"count": 60}, "contact": {"restitution": 1.0},
        "initial": {"placement": "random", "velocity": {"temperature": 1.0}},
        "run": {"equilibration": 0.0, "production": 4.0, "sample_interval": 0.5},
        "soft": {"stiffness": 1e5, "steps_per_contact": 100},
    })
    res = run(scene, tmp_path)
    ke = res.timeseries["kinetic_energy"] / res.timeseries["kinetic_energy"][0]
    assert np.all(ke < 1 + 1e-4), ke
    assert np.mean(np.abs(ke - 1) < 1e-4) >= 0.5, ke  # dilute: most samples are contact-free
    p = res.timeseries["momentum"]
    assert np.abs(p - p[0]).max() < 1e-9 * scene.n_particles


def test_isolated_run_reports_failure_as_engine_error(tmp_path):
    scene = chute()
    bad = tmp_path / "not-a-dir"
    bad.write_text("a file where the results folder should be")
    # refused before the child starts (the output's folder is a file), or failing in it
    with pytest.raises((EngineError, OSError, UnsupportedByEngine)):
        run_scene(scene, "lammps", RunOptions(out=bad / "run.h5", progress=False, isolate=True))


def test_mpi_two_ranks_with_dump_and_a_wall_clock_stop(tmp_path):
    """On 2 ranks: the dump (a collective write) does not hang; a wall-clock limit stops
    both ranks at the same segment with a consistent checkpoint; --resume completes the run
    with every sample exactly once, in the profiles and in the dump."""
    from demstudy.io.dump import read_dump

    scene = chute()
    dump = tmp_path / "frames.dump"
    with pytest.raises(EngineError, match="--resume"):
        run(scene, tmp_path, np=2, dump=dump, wall_limit=0.0)
    res = run(scene, tmp_path, np=2, dump=dump, resume=True)
    prof = res.profiles
    total = np.sum(prof["solid_fraction"]) * res.profile_attrs["bin_width"] * scene.box.size[0]
    assert total == pytest.approx(scene.n_particles * math.pi / 4, rel=1e-4)
    assert res.profile_attrs["samples"] == 24  # 6 time units / 0.25
    times = [f.time for f in read_dump(dump, scene.dimension, dt=res.attrs["timestep"])]
    assert len(times) == 24 and np.all(np.diff(times) > 0)
    np.testing.assert_array_equal(np.diff(res.timeseries["time"]) > 0, True)


def test_lees_edwards_resume_continues_the_tilt(tmp_path, monkeypatch):
    """The box tilt is a function of time alone: after a restart it must continue exactly
    (the shear variable counts from the time the fix is defined, also after read_restart)."""
    scene = validate_scene({
        "dimension": 2, "box": {"size": [12.0, 12.0]}, "particles": {"count": 30},
        "contact": {"restitution": 0.9}, "shear": {"rate": 0.5},
        "initial": {"placement": "random", "velocity": {"profile": "linear"}},
        "run": {"equilibration": 0.0, "production": 8.0, "sample_interval": 0.5,
                "checkpoint_interval": 1.0},
        "soft": {"stiffness": 1e4, "steps_per_contact": 50},
    })
    whole = run(scene, tmp_path, "whole.h5")
    run_interrupted(scene, tmp_path, "parts.h5", monkeypatch, 3.2)
    parts = run(scene, tmp_path, "parts.h5", resume=True)
    # re-anchoring adds round-off of order 1e-9 per restart (tilt ~ 6)
    np.testing.assert_allclose(parts.timeseries["tilt"], whole.timeseries["tilt"], atol=1e-8)
    # tilt = γ̇ L_y t, flipped back by L_x past L_x/2, across checkpoints (write_restart
    # re-initialises fix deform) and the restart
    t = whole.timeseries["time"]
    # (equal modulo L_x: LAMMPS flips the box at the next neighbour-list build, so a tilt
    # may stand just past L_x/2 when it is sampled)
    offset = np.mod(whole.timeseries["tilt"] - 6.0 * t + 6.0, 12.0) - 6.0
    np.testing.assert_allclose(offset, 0.0, atol=1e-6)
    assert np.all(np.abs(whole.timeseries["tilt"]) < 6.5)


def test_paths_with_spaces_and_two_bumpy_walls(tmp_path):
    """Paths reach LAMMPS quoted; bumps sit on both wall planes, so the data file's box is
    padded to hold them (an upper bumpy wall used to make read_data fail)."""
    scene = validate_scene({
        "dimension": 2, "box": {"size": [6.0, 8.0]}, "particles": {"count": 12},
        "contact": {"restitution": 0.9},
        "walls": [
            {"side": "lower", "restitution": 0.9, "kind": "bumpy", "bumps": {}},
            {"side": "upper", "restitution": 0.9, "kind": "bumpy", "bumps": {},
             "velocity": 1.0},
        ],
        "initial": {"placement": "random", "velocity": {"temperature": 0.5}},
        "run": {"equilibration": 0.0, "production": 1.0, "sample_interval": 0.25},
        "soft": {"stiffness": 1e4},
    })
    folder = tmp_path / "my runs"
    res = run(scene, folder, dump=folder / "the frames.dump")
    assert (folder / "the frames.dump").exists()
    assert res.profile_attrs["samples"] == 4
    y = res.profiles["y"]
    assert y.min() > 0.0 and y.max() < 8.0


@pytest.mark.parametrize("dim", [2, 3])
def test_atoms_created_from_memory_are_those_of_the_data_file(tmp_path, dim):
    """A run creates its atoms through the library interface (nothing formatted and parsed);
    the state is read_data's bit for bit (positions, order, velocities, spins, radii, the
    masses of particles and bumps): the two set-ups give identical results files."""
    from demstudy.engines.lammps.backend import LammpsBackend

    class FromDataFile(LammpsBackend):
        state_from_memory = False  # the deck's data file, written and read (read_data)

    if dim == 2:
        scene = load_scene(CHUTE, ["run.equilibration=0.5", "run.production=1.0",
                                   "run.sample_interval=0.25", "walls[0].kind=bumpy",
                                   "walls.0.bumps.pattern=random", "measure.keep_frames=true"])
    else:
        scene = validate_scene({
            "dimension": 3, "box": {"size": [4.4, 10.0, 4.4]}, "particles": {"inertia": "sphere"},
            "contact": {"restitution": 0.8, "tangential": {"model": "beta", "beta": 0.0}},
            "walls": [{"side": "lower", "restitution": 0.8, "kind": "bumpy", "bumps": {}}],
            "gravity": {"angle": 25.0},
            "initial": {"placement": "lattice", "rows": 5, "columns": 4, "layers": 4,
                        "spacing": 1.1, "velocity": {"profile": "uniform", "scale": 1.0,
                                                     "perturbation": 0.1, "temperature": 0.5}},
            "run": {"equilibration": 0.0, "production": 1.0, "sample_interval": 0.25},
            "measure": {"keep_frames": True}})
    results = {}
    for how, backend in (("memory", LammpsBackend), ("data file", FromDataFile)):
        out = tmp_path / how / "run.h5"
        run_scene(scene, backend, RunOptions(out=out, progress=False))
        work = sorted(p.name for p in out.with_suffix(".lammps").iterdir())
        assert ("initial.data" in work) == (how == "data file"), work
        results[how] = read_results(out)
    a, b = results["memory"], results["data file"]
    assert a.frames and len(a.frames["time"]) == 4
    for group in ("timeseries", "profiles", "frames"):
        for key, value in getattr(a, group).items():
            other = getattr(b, group)[key]
            assert np.array_equal(np.asarray(value), np.asarray(other), equal_nan=True), key


def test_atoms_outside_the_box_are_an_engine_error(tmp_path):
    """Rows LAMMPS cannot place (outside a fixed box) are reported, not silently dropped."""
    from demstudy.engines.lammps.deck.system import data_header

    scene = chute()
    session = LammpsSession(tmp_path)
    try:
        for cmd in ("units lj", "atom_style sphere", "dimension 2", "boundary p f p"):
            session.command(cmd)
        (tmp_path / "box.data").write_text("\n".join(data_header(scene, 0)) + "\n")
        session.command(f"read_data {tmp_path / 'box.data'}")
        atoms = np.array([[1, 1, 1.0, 1.9, 1.0, 1.0, 0.0], [2, 1, 1.0, 1.9, 1.0, -5.0, 0.0]])
        with pytest.raises(EngineError, match="created 1 of 2 atoms"):
            session.create_atoms(atoms, np.zeros((2, 7)))
    finally:
        session.close()


def test_resume_keeps_the_checkpoints_automatic_contacts(tmp_path, monkeypatch):
    """Automatic stiffness (the pilot chooses k_n and dt), interrupted, then resumed where the
    pilot's cache is gone and a new measurement would differ (another node): the resume
    continues with the checkpoint's own pilot, k_n and dt unchanged; a run handed another
    pilot is refused, naming both k_n values and the remedy."""
    import dataclasses
    import pickle
    import shutil

    from demstudy.contact import pilot as pilot_mod
    from demstudy.contact.stiffness import contact_setup

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    scene = validate_scene({
        "dimension": 2, "box": {"size": [10.0, 10.0]}, "particles": {"count": 20},
        "contact": {"restitution": 0.9},
        "initial": {"placement": "random", "velocity": {"temperature": 1.0}},
        "run": {"equilibration": 0.0, "production": 1.0, "sample_interval": 0.25,
                "checkpoint_interval": 0.25, "seed": 4},
        "soft": {"steps_per_contact": 20}})
    run_interrupted(scene, tmp_path, "r.h5", monkeypatch, 0.3)
    saved = pickle.loads((tmp_path / "r.lammps" / "checkpoint.pkl").read_bytes())
    contact = saved["backend"]["contact"]
    assert contact["stiffness_basis"] == "pilot"
    expected = contact_setup(scene, "lammps", pilot_mod.run_pilot(scene))
    assert contact["kn"] == expected.kn and contact["timestep"] == expected.timestep

    shutil.rmtree(tmp_path / "cache")
    measure = pilot_mod._measure
    measured = []

    def faster(*args, **kwargs):  # another node's pilot: impacts twice as fast
        measured.append(1)
        p = measure(*args, **kwargs)
        return dataclasses.replace(p, pair={k: 2 * v for k, v in p.pair.items()},
                                   floor=2 * p.floor)

    monkeypatch.setattr(pilot_mod, "_measure", faster)
    other = pilot_mod.run_pilot(scene, cache=False)
    assert contact_setup(scene, "lammps", other).kn > 2 * expected.kn
    with pytest.raises(EngineError, match=rf"k_n = {expected.kn:.9g}.*soft\.stiffness"):
        run(scene, tmp_path, "r.h5", resume=True, pilot=other)
    measured.clear()
    res = run(scene, tmp_path, "r.h5", resume=True)
    assert not measured  # the checkpoint's pilot, not a new measurement
    assert res.attrs["kn"] == expected.kn and res.attrs["timestep"] == expected.timestep
    assert res.timeseries["time"][-1] == pytest.approx(1.0, abs=expected.timestep)
