"""Run a simulation in a child process (on MPI ranks when asked), so that a crash in compiled
code (a segfault, an MPI abort) ends the child and reaches the caller as an ``EngineError``.

``python -m demstudy.simulation.child JOB.json`` is the child's entry point: exit 0 when
done, 2 when the engine refused the run, 3 when it stopped after a checkpoint (Ctrl-C or the
wall-clock limit), 4 when Ctrl-C came before the run loop's handler (nothing ran), 1 on an
engine error. On one rank the child is a fork of the caller when
that is safe (Linux, one thread, nothing loaded that a fork must not inherit: the backend's
``fork_safe``): it starts without a new interpreter, its imports, the job file and the
scene's validation (~0.6 s of a LAMMPS run's start). Dimensionless particle units: d = 1,
m = 1, g = 1 when gravity acts.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

from .. import UNITS_NOTE
from ..errors import (
    RESUME_ADVICE,
    EngineError,
    RunAborted,
    RunRefused,
    RunStopped,
    UnsupportedByEngine,
)
from ..scene import Scene
from .options import RunOptions, work_folder
from .schedule import stop_notice

WORKER_FLAG = "DEMSTUDY_ENGINE_WORKER"
FAILED, REFUSED, STOPPED, INTERRUPTED = 1, 2, 3, 4  # the child's exit codes

__all__ = ["in_worker", "launch_child"]


def in_worker() -> bool:
    return os.environ.get(WORKER_FLAG) == "1"


def launch_child(backend, scene: Scene, options: RunOptions) -> Path:
    """Run ``scene`` in ``backend`` (a registered backend class) in a child process, started
    by the backend's launcher (``mpirun -np N``) when np > 1.

    Ctrl-C (or a notebook's interrupt, which reaches only this process) is passed on to the
    child, which stops at the end of its current segment after a checkpoint; the caller then
    waits for it rather than killing it. The child's error message comes back in the
    ``EngineError``."""
    where = f"{backend.__module__}:{backend.__qualname__}"
    if backend.__module__ == "__main__" or "<locals>" in backend.__qualname__:
        raise UnsupportedByEngine(backend.name, "isolate", True,
                                  f"the backend {where} cannot be imported by a child process "
                                  "(defined in a script, a notebook or a function): define it "
                                  "in a module, or run with isolate=False")
    payload = {
        "units": UNITS_NOTE,
        "engine": backend.name,
        # by import path: a backend registered in this process runs in the child too, which
        # searches the same module path
        "backend": where,
        "sys_path": sys.path,
        "scene": scene.model_dump(mode="json"),
        "out": str(Path(options.out).resolve()),
        "dump": str(Path(options.dump).resolve()) if options.dump else None,
        "resume": options.resume,
        "progress": options.progress,
        "keep_frames": options.keep_frames,
        "checkpoint_interval": options.checkpoint_interval,
        "wall_limit": options.wall_limit,
        "np": options.np,
        "extra": options.extra,
        "pilot": options.pilot.to_json() if options.pilot is not None else None,
        "forecast": dataclasses.asdict(options.forecast) if options.forecast else None,
    }
    out = Path(payload["out"])
    out.parent.mkdir(parents=True, exist_ok=True)
    job = out.with_name(f".{out.name}.job.json")
    error = job.with_suffix(".error")
    error.unlink(missing_ok=True)
    proc = None
    try:
        # inside the try: a Ctrl-C once the child exists is passed on to it (the fork holds
        # SIGINT back until ``wait``), never left behind with a child running on
        proc = _start_child(backend, scene, options, payload, job, error)
        returncode = proc.wait()
    except KeyboardInterrupt:
        if proc is None:  # no child yet: nothing ran
            raise
        print(stop_notice(backend.name), file=sys.stderr, flush=True)
        proc.send_signal(signal.SIGINT)  # a terminal's Ctrl-C reached it already: harmless
        try:
            returncode = proc.wait(timeout=300)
        except KeyboardInterrupt:  # the second Ctrl-C: abort now, keeping the last checkpoint
            _end(proc)
            raise RunAborted(f"aborted by Ctrl-C: the {backend.name} run was ended; "
                             f"{_last_checkpoint(work_folder(out, backend.name))}") from None
        except subprocess.TimeoutExpired:
            _end(proc)
            raise EngineError(f"the {backend.name} run did not stop within 300 s of Ctrl-C "
                              "and was ended; "
                              f"{_last_checkpoint(work_folder(out, backend.name))}") from None
    finally:
        job.unlink(missing_ok=True)
    message = error.read_text().strip() if error.exists() else ""
    error.unlink(missing_ok=True)
    if returncode == STOPPED:
        raise RunStopped(f"the run stopped after writing a checkpoint{RESUME_ADVICE}")
    if returncode == INTERRUPTED:  # Ctrl-C while the child set up, before its loop's handler
        raise RunAborted(f"aborted by Ctrl-C while the {backend.name} run was being set up: "
                         f"it did not start; {_last_checkpoint(work_folder(out, backend.name))}")
    if returncode == REFUSED:
        raise RunRefused(message or f"the {backend.name} engine refused the run (see the "
                                    "message above)")
    if returncode != 0:
        how = ("was interrupted" if returncode == -signal.SIGINT
               else f"was killed by signal {-returncode}" if returncode < 0
               else f"failed (exit {returncode})")
        workdir = work_folder(out, backend.name)
        log_file = backend.log_file(workdir)
        log = f" and {log_file}" if log_file is not None and log_file.exists() else ""
        said = f": {message}" if message else f"; see the messages above{log}"
        # an engine that ends the process on its own errors (LIGGGHTS) left its last command
        # and its log's error in the work folder
        report = "" if message else backend.crash_report(workdir)
        raise EngineError(f"the {backend.name} run on {options.np} rank(s) {how}{said}"
                          + (f" (and {log_file})" if message and log else "")
                          + (f"\n  {report}" if report else ""))
    return out


def _start_child(backend, scene: Scene, options: RunOptions, payload: dict, job: Path,
                 error: Path):
    """The child, forked when that is safe, else a new interpreter (``mpirun`` when np > 1)."""
    if can_fork(backend, options):  # the child gets the resolved paths, as from the job file
        return _Forked(backend, scene, dataclasses.replace(
            options, out=Path(payload["out"]),
            dump=Path(payload["dump"]) if payload["dump"] else None, isolate=False), error)
    job.write_text(json.dumps(payload))
    env = dict(os.environ, **{WORKER_FLAG: "1"})
    cmd = [sys.executable, "-m", "demstudy.simulation.child", str(job)]
    if options.np > 1:
        cmd = [*backend.launcher(options.np), *cmd]
    return subprocess.Popen(cmd, env=env, stdin=subprocess.DEVNULL,
                            preexec_fn=_die_with_parent if sys.platform == "linux" else None)


def _end(proc) -> None:
    """End the child at once: SIGTERM (mpirun passes it on to its ranks), SIGKILL after
    2 s. A checkpoint is written atomically, so the last whole one stays."""
    with contextlib.suppress(ProcessLookupError):
        proc.send_signal(signal.SIGTERM)
    with contextlib.suppress(subprocess.TimeoutExpired, KeyboardInterrupt):
        proc.wait(timeout=2.0)
        return
    with contextlib.suppress(ProcessLookupError, ChildProcessError):
        proc.kill()


def _last_checkpoint(workdir: Path) -> str:
    from .checkpoint import resume_note  # noqa: PLC0415 - pickle and h5py helpers: only here

    return resume_note(workdir)


def can_fork(backend, options: RunOptions) -> bool:
    """Whether the child may be a fork of this process, as good as a new interpreter: one
    rank (the launcher starts MPI ranks), Linux, no other thread (it would be missing in the
    child, maybe holding a lock), and nothing in this process that ``backend`` must not
    inherit (``fork_safe``: LAMMPS once its MPI runtime was initialised here)."""
    return (options.np == 1 and sys.platform == "linux" and threading.active_count() == 1
            and backend.fork_safe())


class _Forked:
    """The child as a fork of this process, waited for like a ``subprocess.Popen``: it runs
    the loop as ``worker`` would, with the scene as validated here, and exits with
    ``worker``'s codes."""

    def __init__(self, backend, scene: Scene, options: RunOptions, error: Path):
        sys.stdout.flush()
        sys.stderr.flush()
        # SIGINT is held back from the fork until ``wait`` (parent) or the child's first line:
        # raised in between, the parent's KeyboardInterrupt would leave the child unknown
        self._mask: set | None = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        try:
            self.pid = os.fork()
        except BaseException:
            self._release()
            raise
        if self.pid == 0:  # the child: never returns
            code = FAILED
            try:
                self._release()  # a fork has no pending signals: none is lost here
                os.environ[WORKER_FLAG] = "1"
                _die_with_parent()
                stdin = os.open(os.devnull, os.O_RDONLY)
                os.dup2(stdin, 0)
                os.close(stdin)
                code = run_in_child(backend, scene, options, error)
            except KeyboardInterrupt:  # before the loop's own handler: the parent says so
                code = INTERRUPTED
            except BaseException as exc:  # one line, never a bare traceback
                print(f"error: {type(exc).__name__}: {exc}", file=sys.stderr)
            finally:
                try:
                    sys.stdout.flush()
                    sys.stderr.flush()
                finally:
                    os._exit(code)

    def _release(self) -> None:
        """Let SIGINT in again (one pending since the fork is handled now)."""
        if self._mask is not None:
            mask, self._mask = self._mask, None
            signal.pthread_sigmask(signal.SIG_SETMASK, mask)

    def wait(self, timeout: float | None = None) -> int:
        self._release()  # in the caller's try: a Ctrl-C from here on is passed on
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            pid, status = os.waitpid(self.pid, 0 if deadline is None else os.WNOHANG)
            if pid:
                return os.waitstatus_to_exitcode(status)
            if time.monotonic() > deadline:
                raise subprocess.TimeoutExpired(f"pid {self.pid}", timeout)
            time.sleep(0.05)

    def send_signal(self, sig: int) -> None:
        os.kill(self.pid, sig)

    def kill(self) -> None:
        os.kill(self.pid, signal.SIGKILL)
        os.waitpid(self.pid, 0)


def _die_with_parent() -> None:
    """In the child (before exec, or after fork): SIGTERM when the parent dies (killed by a
    batch system's timeout, say), so no orphaned engine keeps running (Linux prctl
    PR_SET_PDEATHSIG)."""
    import ctypes  # noqa: PLC0415

    ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)  # 1 = PR_SET_PDEATHSIG


def _tell_parent(path: Path, message: str) -> None:
    """The child's error, for the parent's exception, which prints it (rank 0 writes it; best
    effort: where it could not, the child prints it itself, so it is said once)."""
    if os.environ.get("PMI_RANK", "0") == "0":
        try:
            path.write_text(message)
            return
        except OSError:
            pass
    print(f"error: {message}", file=sys.stderr)


def worker(job: str) -> int:
    from ..engines import get_backend, register_backend
    from ..scene import validate_scene

    payload = json.loads(Path(job).read_text())
    sys.path[:0] = [p for p in payload["sys_path"] if p not in sys.path]
    register_backend(payload["backend"], payload["engine"])
    error = Path(job).with_suffix(".error")
    from ..contact.pilot import PilotResult
    from .forecast import Forecast

    scene = validate_scene(payload["scene"], source=job)
    pilot, forecast = payload.get("pilot"), payload.get("forecast")
    options = RunOptions(out=Path(payload["out"]), np=payload["np"],
                         dump=Path(payload["dump"]) if payload["dump"] else None,
                         resume=payload["resume"], progress=payload["progress"],
                         keep_frames=payload["keep_frames"],
                         checkpoint_interval=payload["checkpoint_interval"],
                         wall_limit=payload["wall_limit"], extra=payload["extra"],
                         plan=False, pilot=PilotResult.from_json(pilot) if pilot else None,
                         forecast=Forecast(**forecast) if forecast else None)
    return run_in_child(get_backend(payload["engine"]), scene, options, error)


def run_in_child(backend, scene: Scene, options: RunOptions, error: Path) -> int:
    """Run the loop here, in the child; the child's exit code (its message, if any, in the
    file ``error`` for the parent)."""
    from ..io.checksum import DamagedCheckpoint
    from ..scene.load import SceneError
    from .loop import Simulation

    try:
        Simulation(scene, backend, options).run()
    except RunStopped:
        return STOPPED  # the parent says so, once
    except (UnsupportedByEngine, SceneError, DamagedCheckpoint) as exc:  # nothing ran
        _tell_parent(error, str(exc))
        return REFUSED
    except Exception as exc:  # one line, never a bare traceback
        _tell_parent(error, f"{type(exc).__name__}: {exc}")
        return FAILED
    return 0

