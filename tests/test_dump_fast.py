"""The numpy fast path of the dump reader gives the frames of the MDAnalysis reader.

Dumps come from the LAMMPS engine (a 2D chute with walls, and a 3D Lees-Edwards box for
the triclinic header). Dimensionless particle units: d = 1, m = 1.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from demstudy.io.dump import read_dump, read_dump_fast
from demstudy.io.frames import Frame
from demstudy.scene import load_scene
from demstudy.simulation import RunOptions, run_scene

ROOT = Path(__file__).resolve().parent.parent


def lammps_dump(tmp_path: Path, scene_file: str, **run) -> tuple[Path, float, object]:
    scene = load_scene(ROOT / "inputs" / scene_file, [f"run.{k}={v}" for k, v in run.items()])
    dump = tmp_path / "frames.dump"
    run_scene(scene, "lammps", RunOptions(out=tmp_path / "run.h5", progress=False, dump=dump))
    from demstudy.io.results import read_results

    return dump, read_results(tmp_path / "run.h5").attrs["timestep"], scene


def assert_same_frames(slow, fast, tilted: bool = False) -> None:
    assert len(slow) == len(fast) > 0
    for a, b in zip(slow, fast, strict=True):
        assert a.time == b.time
        # MDAnalysis holds positions and velocities in float32
        for key in ("position", "velocity"):
            x, y = getattr(a, key), getattr(b, key)
            assert x.shape == y.shape and y.dtype == np.float64
            np.testing.assert_allclose(x, y, rtol=2e-7, atol=2e-7 * np.abs(y).max(), err_msg=key)
        np.testing.assert_array_equal(a.angular_velocity, b.angular_velocity)
        np.testing.assert_array_equal(a.radius, b.radius)
        # both readers decode the header the same way (triclinic Lees-Edwards boxes too)
        np.testing.assert_array_equal(a.box_lo, b.box_lo)
        np.testing.assert_array_equal(a.box_hi, b.box_hi)
        assert a.tilt == b.tilt
        if not tilted:
            assert b.tilt == 0.0


def test_fast_reader_matches_mdanalysis_2d_chute(tmp_path):
    dump, dt, scene = lammps_dump(tmp_path, "campbell1982/chute-30.toml", equilibration=0.5,
                                  production=1.0, sample_interval=0.25)
    slow = list(read_dump(dump, 2, dt=dt))
    fast = list(read_dump_fast(dump, 2, dt=dt))
    assert len(fast) == 4 and fast[0].n == scene.n_particles
    assert fast[0].angular_velocity.shape == (scene.n_particles, 1)
    assert_same_frames(slow, fast)
    # start_time skips the same frames
    t1 = fast[1].time
    assert_same_frames(list(read_dump(dump, 2, dt=dt, start_time=t1)),
                       list(read_dump_fast(dump, 2, dt=dt, start_time=t1)))


def test_fast_reader_decodes_lees_edwards_box_3d(tmp_path):
    dump, dt, scene = lammps_dump(tmp_path, "shear/lees-edwards-3d.toml", equilibration=0.0,
                                  production=0.5, sample_interval=0.25)
    slow = list(read_dump(dump, 3, dt=dt))
    fast = list(read_dump_fast(dump, 3, dt=dt))
    assert_same_frames(slow, fast, tilted=True)
    size = np.asarray(scene.box.size, float)
    for frame in fast:
        # the header holds bounding-box bounds; the readers recover the box and tilt
        np.testing.assert_allclose(frame.lengths, size, rtol=1e-12)
        assert frame.tilt == pytest.approx(scene.shear.rate * size[1] * frame.time, rel=1e-6)
        assert frame.angular_velocity.shape == (scene.n_particles, 3)
    # end to end with the decoded tilt: no two sphere centres closer than ~1 d once the
    # Lees-Edwards images are shifted by the tilt (LAMMPS wraps lazily: some centres lie
    # just outside the box); with the tilt ignored, image pairs overlap
    from demstudy.analysis.pair_correlation import PairCorrelation

    def close_pairs(frames):
        ana = PairCorrelation(3, r_max=1.5, dr=0.01, periodic_y=True).run(frames)
        r = ana.results["r"]
        return ana.results["pairs_per_particle"][0][r < 0.98].sum()

    assert close_pairs(fast) == 0
    untilted = [Frame(f.time, f.box_lo, f.box_hi, f.position, f.velocity, f.angular_velocity,
                      f.radius) for f in fast]
    assert close_pairs(untilted) > 0


def test_fast_reader_rejects_foreign_columns(tmp_path):
    path = tmp_path / "other.dump"
    path.write_text("ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS pp pp pp\n"
                    "0 1\n0 1\n0 1\nITEM: ATOMS id type x y z\n1 1 0.5 0.5 0.5\n")
    with pytest.raises(ValueError, match="read_dump"):
        list(read_dump_fast(path, 3))


def test_both_readers_agree_on_a_negative_tilt(tmp_path):
    """After a flip the Lees-Edwards tilt is negative: the header's first bound is then
    xlo + xy, and MDAnalysis's shift must be undone with the true lower corner."""
    path = tmp_path / "tilted.dump"
    path.write_text(
        "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n2\n"
        "ITEM: BOX BOUNDS xy xz yz pp pp pp\n-3.0 10.0 -3.0\n0.0 10.0 0.0\n0.0 10.0 0.0\n"
        "ITEM: ATOMS id type radius x y z vx vy vz omegax omegay omegaz\n"
        "1 1 0.5 1.0 2.0 3.0 0 0 0 0 0 0\n2 1 0.5 4.0 5.0 6.0 0 0 0 0 0 0\n")
    (slow,), (fast,) = list(read_dump(path, 3)), list(read_dump_fast(path, 3))
    np.testing.assert_allclose(fast.position[:, 0], [1.0, 4.0])
    np.testing.assert_allclose(slow.position, fast.position, atol=1e-6)
    assert slow.tilt == fast.tilt == -3.0
    np.testing.assert_array_equal(slow.box_lo, [0.0, 0.0, 0.0])


# ---- foreign dumps: other columns than demstudy writes -------------------------------------

GAS_TOML = """dimension = 3
[box]
size = [6.0, 6.0, 6.0]
[contact]
restitution = 0.9
[particles]
count = 3
[initial.velocity]
temperature = 1.0
[run]
equilibration = 0.0
production = 1.0
sample_interval = 0.5
"""
FULL = ("id", "type", "radius", "x", "y", "z", "vx", "vy", "vz", "omegax", "omegay", "omegaz")


def write_dump(path: Path, columns: tuple[str, ...], seed: int = 3) -> Path:
    """Two frames of three spheres in a 6³ box, random state, only ``columns`` (from FULL,
    or scaled xs ys zs = x / 6) written; ids shuffled as LAMMPS writes them on MPI ranks."""
    rng = np.random.default_rng(seed)
    text = ""
    for step in (0, 50):
        data = {"id": np.array([3, 1, 2]), "type": np.ones(3, int), "radius": np.full(3, 0.5)}
        for axis in "xyz":
            data[axis] = rng.uniform(0.5, 5.5, 3)
            data[f"{axis}s"] = data[axis] / 6.0
            data[f"v{axis}"] = rng.normal(size=3)
            data[f"omega{axis}"] = rng.normal(size=3)
        text += (f"ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n3\nITEM: BOX BOUNDS pp pp pp\n"
                 + "0 6\n" * 3 + f"ITEM: ATOMS {' '.join(columns)}\n")
        text += "".join(" ".join(repr(data[c][i].item()) for c in columns) + "\n"
                        for i in range(3))
    path.write_text(text)
    return path


def test_a_dump_without_omega_columns_gives_frames_without_rotation(tmp_path, capsys):
    """Without omegax omegay omegaz both readers give the same translational frames as the
    full dump and NaN angular velocities; `analyze` says so, computes the translational
    profiles of the full dump exactly and leaves the rotational ones NaN."""
    from demstudy.cli import main
    from demstudy.io.results import read_results

    full = write_dump(tmp_path / "full.dump", FULL)
    bare = write_dump(tmp_path / "bare.dump", FULL[:9])
    for read in (read_dump, read_dump_fast):
        a, b = list(read(full, 3, dt=0.01)), list(read(bare, 3, dt=0.01))
        assert len(a) == len(b) == 2
        for x, y in zip(a, b, strict=True):
            np.testing.assert_array_equal(x.position, y.position)
            np.testing.assert_array_equal(x.velocity, y.velocity)
            assert np.isfinite(x.angular_velocity).all() and np.isnan(y.angular_velocity).all()
    scene = tmp_path / "gas.toml"
    scene.write_text(GAS_TOML)
    for dump in (full, bare):
        assert main(["analyze", str(dump), "--scene", str(scene), "--what", "profiles",
                     "--dt", "0.01"]) == 0
    assert f"note: {bare}: angular velocity absent" in capsys.readouterr().err
    a, b = (read_results(tmp_path / f"{n}.h5") for n in ("full", "bare"))
    assert "angular_velocity" in b.attrs and "angular_velocity" not in a.attrs
    for key in ("solid_fraction", "velocity", "temperature"):
        np.testing.assert_array_equal(a.profiles[key], b.profiles[key], err_msg=key)
    occupied = a.profiles["solid_fraction"] > 0
    assert np.isfinite(a.profiles["rotational_temperature"][occupied]).all()
    assert np.isnan(b.profiles["rotational_temperature"]).all()


@pytest.mark.parametrize("columns, said", [
    (tuple(c for c in FULL if c != "z"), "lacks the columns z:"),
    (tuple({"x": "xs", "y": "ys", "z": "zs"}.get(c, c) for c in FULL),
     "lacks the columns x y z; it has scaled (xs ys zs) coordinates instead"),
    (FULL[3:], "lacks the columns id type radius:"),
])
def test_a_dump_without_z_or_with_scaled_coordinates_is_refused_by_name(tmp_path, capsys,
                                                                        columns, said):
    """A dump lacking a column both readers need, or with positions in box fractions, is
    refused before any frame is read: BadInputFile naming the file and the columns (both
    readers), `analyze` exit 2 with that message and no results file."""
    from demstudy.cli import main
    from demstudy.errors import BadInputFile

    dump = write_dump(tmp_path / "foreign.dump", columns)
    with pytest.raises(BadInputFile, match=re.escape(f"dump {dump} {said}")):
        list(read_dump(dump, 3))
    scene = tmp_path / "gas.toml"
    scene.write_text(GAS_TOML)
    for reader in ("auto", "mdanalysis"):
        assert main(["analyze", str(dump), "--scene", str(scene), "--what", "profiles",
                     "--dt", "0.01", "--reader", reader]) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"error: dump {dump} {said}") and "Traceback" not in err
    assert not (tmp_path / "foreign.h5").exists()
