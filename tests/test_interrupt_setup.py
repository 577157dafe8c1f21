"""Ctrl-C during a run's set-up is never lost: delivered at controlled points (marker files
and patched hooks, never a guessed delay), it aborts the set-up with ``RunAborted`` or stops
the run after a checkpoint. Dimensionless particle units: d = 1, m = 1; the shear rate sets
the time unit τ.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest

from demstudy.engines import get_backend
from demstudy.errors import RunAborted, RunStopped
from demstudy.scene import load_scene
from demstudy.simulation import RunOptions, plan_run
from demstudy.simulation.schedule import interrupts_honoured

# the child, still setting up (before its run loop's handler), interrupts its caller alone
# once the caller waits for it (a marker file: no delay), then idles until the caller's
# forwarded SIGINT ends its set-up
SETUP_INTERRUPTED = """
import os, signal, time
from pathlib import Path
import demstudy as ds
import demstudy.simulation.isolation as iso
import demstudy.simulation.loop as loop
from demstudy.errors import RunAborted, RunStopped

wait = iso._Forked.wait

def waiting(self, timeout=None):
    Path("caller-waits").touch()
    return wait(self, timeout)

def setting_up(self, *args, **kwargs):
    while not Path("caller-waits").exists():
        time.sleep(0.01)
    os.kill(os.getppid(), signal.SIGINT)
    while True:
        time.sleep(0.05)

iso._Forked.wait, loop.Simulation.__init__ = waiting, setting_up
try:
    ds.run('shear/lees-edwards-3d', engine='edmd', out='s.h5', progress=False)
    print('completed')
except RunStopped:
    print('stopped')
except RunAborted as exc:
    print(f'aborted: {exc}')
"""


@pytest.mark.parametrize("inherited", ["default", "ignored"])
def test_an_interrupt_while_the_child_sets_up_aborts_the_run_before_it_starts(tmp_path,
                                                                             inherited):
    """Before the child's loop installs its handler, the forwarded SIGINT is a
    KeyboardInterrupt there: the caller reports an aborted set-up (it was an engine failure,
    "exit 1"), and nothing is written."""
    ignore = (lambda: signal.signal(signal.SIGINT, signal.SIG_IGN)) \
        if inherited == "ignored" else None
    proc = subprocess.Popen([sys.executable, "-c", SETUP_INTERRUPTED], cwd=tmp_path,
                            text=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True, preexec_fn=ignore)
    try:
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:  # the interrupt was lost: the child idles for ever
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()
    assert out.startswith("aborted: aborted by Ctrl-C while the edmd run was being set up"), \
        err[-2000:]
    assert "no checkpoint was written" in out and "Traceback" not in err
    assert not (tmp_path / "s.h5").exists() and not (tmp_path / "s.edmd").exists()


def test_an_interrupt_of_the_forecast_benchmark_aborts_instead_of_running_on(tmp_path,
                                                                             monkeypatch):
    """The first run on a machine measures its speed with benchmark runs in child processes;
    Ctrl-C stops such a run (RunStopped), which the forecast took for a failed benchmark and
    warned about ("no forecast"), and the real run then started and went to its end."""
    import demstudy.simulation as simulation

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))  # nothing measured yet
    monkeypatch.setenv("DEMSTUDY_MEASURE_RATES", "1")
    calls = []

    def interrupted_benchmark(scene, backend, options):
        calls.append(options.out)
        raise RunStopped("the run stopped after writing a checkpoint")  # as after Ctrl-C

    monkeypatch.setattr(simulation, "run_scene", interrupted_benchmark)
    scene = load_scene("shear/lees-edwards-3d")
    with pytest.raises(RunAborted, match="measuring this machine's speed.*did not start"):
        plan_run(scene, get_backend("edmd"), RunOptions(out=tmp_path / "s.h5"))
    assert len(calls) == 1  # the first benchmark case, then no more
    assert not (tmp_path / "cache" / "demstudy" / "machine-rates.json").exists()


def _custom(signum, frame):  # a handler the caller installed itself
    raise RuntimeError("the caller's own")


@pytest.mark.parametrize("inherited", [signal.SIG_IGN, signal.SIG_DFL, _custom,
                                       signal.default_int_handler])
def test_interrupts_are_honoured_inside_whatever_was_inherited(inherited):
    """Inside: SIGINT is a KeyboardInterrupt where it was ignored or at its default action;
    a caller's own handler is kept; on the way out the previous one comes back."""
    previous = signal.signal(signal.SIGINT, inherited)
    try:
        with interrupts_honoured():
            inside = signal.getsignal(signal.SIGINT)
            expected = KeyboardInterrupt if inherited in (signal.SIG_IGN, signal.SIG_DFL,
                                                          signal.default_int_handler) \
                else RuntimeError
            with pytest.raises(expected):
                signal.raise_signal(signal.SIGINT)
                time.sleep(0.01)  # the Python handler runs at the next bytecode
        assert signal.getsignal(signal.SIGINT) is inherited
    finally:
        signal.signal(signal.SIGINT, previous)
    assert inside in (signal.default_int_handler, _custom)

