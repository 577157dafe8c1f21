"""Ctrl-C as a terminal sends it (SIGINT to the whole process group) to real ``demstudy run``
processes: the first prints the stopping notice at once, from the process the user sees; a
second aborts at once with exit 130, one line and no traceback, keeping the last
checkpoint, from which ``--resume`` continues. Dimensionless particle units: d = 1, m = 1;
the HCS's initial temperature T0 = 1 sets the time unit."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from demstudy.cli import main
from demstudy.io.results import read_results

# an elastic 3D gas of 2034 spheres (constant collision rate): 1200 τ take 3-7 s, sampled and
# checkpointed every 400 τ: each sample interval is one engine call of ~2·10⁶ events (less
# than one 10⁷-event chunk), so the first Ctrl-C's stop comes only at its end, and a second
# Ctrl-C in between must abort
SETTINGS = ["--set", "contact.restitution=1.0", "--set", "run.production=1200",
            "--set", "run.sample_interval=400", "--set", "run.checkpoint_interval=400"]
NOTICE = "edmd: stopping after the current segment and a checkpoint (Ctrl-C again aborts"
# the same run through the API with isolate=False: the loop runs in the process the user sees
IN_PROCESS = """
import sys
import demstudy
from demstudy.errors import RunAborted
from demstudy.scene import load_scene
scene = load_scene("cooling/hcs-3d", {sets!r})
try:
    demstudy.run(scene, "edmd", {out!r}, isolate=False, progress=False)
except RunAborted as exc:
    print(f"error: {{exc}}", file=sys.stderr)
    sys.exit(130)
"""


def wait_for(predicate, timeout: float, what: str) -> float:
    start = time.monotonic()
    while not predicate():
        if time.monotonic() - start > timeout:
            raise AssertionError(f"{what}: not within {timeout} s")
        time.sleep(0.02)
    return time.monotonic() - start


def checkpoint_id(workdir: Path) -> tuple[int, int]:
    """Which checkpoint file is there: a new one replaces it atomically (a new inode)."""
    st = (workdir / "checkpoint.pkl").stat()
    return st.st_ino, st.st_mtime_ns


def interrupt_twice(cmd: list[str], tmp_path: Path, workdir: Path,
                    ignored: bool = False) -> tuple[int, str]:
    """Start ``cmd`` in its own process group (with SIGINT inherited ignored, as a background
    job of a script, when ``ignored``), Ctrl-C it once a checkpoint exists, wait for the
    notice, Ctrl-C again; the exit code and stderr. The notice comes at once: before the
    segment under way ends (its checkpoint is not written yet when the notice is there), and
    the abort writes no checkpoint: the one from before the first Ctrl-C stays. Said so in
    events, not seconds, which a loaded machine stretches."""
    log = tmp_path / "stderr.txt"
    ignore = (lambda: signal.signal(signal.SIGINT, signal.SIG_IGN)) if ignored else None
    with open(log, "w") as err:
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=err, cwd=tmp_path,
                                start_new_session=True, preexec_fn=ignore)
    try:
        wait_for(lambda: (workdir / "checkpoint.pkl").exists() or proc.poll() is not None,
                 60, "a first checkpoint")
        assert proc.poll() is None, log.read_text()
        first = checkpoint_id(workdir)
        os.killpg(proc.pid, signal.SIGINT)
        wait_for(lambda: NOTICE in log.read_text() or proc.poll() is not None, 60,
                 "the stopping notice")
        assert NOTICE in log.read_text(), log.read_text()
        assert checkpoint_id(workdir) == first, "the notice came after the segment's end"
        time.sleep(0.2)
        assert proc.poll() is None, "the first Ctrl-C ended the run: no segment to abort"
        os.killpg(proc.pid, signal.SIGINT)
        code = proc.wait(timeout=60)
        assert checkpoint_id(workdir) == first, "a checkpoint was written after the abort"
        return code, log.read_text()
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()


def resumed(tmp_path: Path, out: Path) -> None:
    """--resume continues from the kept checkpoint to the end: every sample from t = 0."""
    args = ["run", "cooling/hcs-3d", "--engine", "edmd", "--out", str(out), "-q", *SETTINGS]
    assert main([*args, "--resume"]) == 0
    t = read_results(out).timeseries["time"]
    assert t[0] == 0.0 and t[-1] == pytest.approx(1200.0) and len(t) == 4


@pytest.mark.parametrize("how", ["cli", "cli-ignored", "in-process"])
def test_ctrl_c_notice_at_once_second_aborts_keeping_the_checkpoint(tmp_path, how):
    """``cli-ignored``: the command inherited SIGINT ignored (a background job of a script, a
    CI step): the caller printed no notice (the forked child alone stopped on the Ctrl-C)."""
    out = tmp_path / "r.h5"
    workdir = tmp_path / "r.edmd"
    if how.startswith("cli"):  # the engine in a forked child, as every `demstudy run`
        cmd = [sys.executable, "-m", "demstudy.cli", "run", "cooling/hcs-3d", "--engine",
               "edmd", "--out", str(out), "-q", *SETTINGS]
    else:
        sets = [s for s in SETTINGS if s != "--set"]
        cmd = [sys.executable, "-c", IN_PROCESS.format(sets=sets, out=str(out))]
    # the abort keeps the checkpoint from before the first Ctrl-C (interrupt_twice): the child
    # is ended at once, not left to finish its segment and checkpoint; in-process, the loop
    # aborts when the engine call returns, before its checkpoint
    code, err = interrupt_twice(cmd, tmp_path, workdir, ignored=how == "cli-ignored")
    assert code == 130, err
    assert err.count(NOTICE) == 1 and "Traceback" not in err
    aborted = [line for line in err.splitlines() if line.startswith("error:")]
    assert len(aborted) == 1 and "aborted by Ctrl-C" in aborted[0]
    assert f"the last checkpoint stays in {workdir}" in aborted[0]
    assert (workdir / "checkpoint.pkl").exists() and not out.exists()
    resumed(tmp_path, out)
