"""Run a simulation in a child process (on MPI ranks when asked), so that a crash in compiled
code (a segfault, an MPI abort) ends the child and reaches the caller as an ``EngineError``.

``python -m demstudy.simulation.isolation JOB.json`` is the child's entry point: exit 0 when
done, 2 when the engine refused the run, 3 when it stopped after a checkpoint (Ctrl-C or the
wall-clock limit), 1 on an engine error. Dimensionless particle units: d = 1, m = 1, g = 1
when gravity acts.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

from .. import UNITS_NOTE
from ..errors import EngineError, RunRefused, RunStopped, UnsupportedByEngine
from ..scene import Scene
from .options import RunOptions, work_folder

WORKER_FLAG = "DEMSTUDY_ENGINE_WORKER"
FAILED, REFUSED, STOPPED = 1, 2, 3  # the child's exit codes

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
    }
    out = Path(payload["out"])
    out.parent.mkdir(parents=True, exist_ok=True)
    job = out.with_name(f".{out.name}.job.json")
    job.write_text(json.dumps(payload))
    error = job.with_suffix(".error")
    error.unlink(missing_ok=True)
    env = dict(os.environ, **{WORKER_FLAG: "1"})
    cmd = [sys.executable, "-m", "demstudy.simulation.isolation", str(job)]
    if options.np > 1:
        cmd = [*backend.launcher(options.np), *cmd]
    proc = subprocess.Popen(cmd, env=env, stdin=subprocess.DEVNULL,
                            preexec_fn=_die_with_parent if sys.platform == "linux" else None)
    try:
        returncode = proc.wait()
    except KeyboardInterrupt:
        print(f"\n{backend.name}: stopping after the current segment and a checkpoint "
              "(Ctrl-C again aborts without one)", file=sys.stderr, flush=True)
        proc.send_signal(signal.SIGINT)  # a terminal's Ctrl-C reached it already: harmless
        try:
            returncode = proc.wait(timeout=300)
        except (subprocess.TimeoutExpired, KeyboardInterrupt):
            proc.kill()
            returncode = -9
    finally:
        job.unlink(missing_ok=True)
    message = error.read_text().strip() if error.exists() else ""
    error.unlink(missing_ok=True)
    if returncode == STOPPED:
        raise RunStopped("the run stopped after writing a checkpoint: run the same command "
                         "again with --resume to continue")
    if returncode == REFUSED:
        raise RunRefused(message or f"the {backend.name} engine refused the run (see the "
                                    "message above)")
    if returncode != 0:
        how = ("was interrupted" if returncode == -signal.SIGINT
               else f"was killed by signal {-returncode}" if returncode < 0
               else f"failed (exit {returncode})")
        log_file = backend.log_file(work_folder(out, backend.name))
        log = f" and {log_file}" if log_file is not None and log_file.exists() else ""
        said = f": {message}" if message else f"; see the messages above{log}"
        raise EngineError(f"the {backend.name} run on {options.np} rank(s) {how}{said}"
                          + (f" (and {log_file})" if message and log else ""))
    return out


def _die_with_parent() -> None:
    """In the child before exec: SIGTERM when the parent dies (killed by a batch system's
    timeout, say), so no orphaned engine keeps running (Linux prctl PR_SET_PDEATHSIG)."""
    import ctypes  # noqa: PLC0415

    ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)  # 1 = PR_SET_PDEATHSIG


def _tell_parent(path: Path, message: str) -> None:
    """The child's error, for the parent's exception (rank 0 writes it; best effort)."""
    if os.environ.get("PMI_RANK", "0") == "0":
        try:
            path.write_text(message)
        except OSError:
            pass


def worker(job: str) -> int:
    from ..engines import get_backend, register_backend
    from ..scene import validate_scene
    from ..scene.load import SceneError
    from .loop import Simulation

    payload = json.loads(Path(job).read_text())
    sys.path[:0] = [p for p in payload["sys_path"] if p not in sys.path]
    register_backend(payload["backend"], payload["engine"])
    error = Path(job).with_suffix(".error")
    scene = validate_scene(payload["scene"], source=job)
    options = RunOptions(out=Path(payload["out"]), np=payload["np"],
                         dump=Path(payload["dump"]) if payload["dump"] else None,
                         resume=payload["resume"], progress=payload["progress"],
                         keep_frames=payload["keep_frames"],
                         checkpoint_interval=payload["checkpoint_interval"],
                         wall_limit=payload["wall_limit"], extra=payload["extra"])
    try:
        Simulation(scene, get_backend(payload["engine"]), options).run()
    except RunStopped:
        return STOPPED  # the parent says so, once
    except (UnsupportedByEngine, SceneError) as exc:  # refused before anything ran
        print(f"error: {exc}", file=sys.stderr)
        _tell_parent(error, str(exc))
        return REFUSED
    except Exception as exc:  # one line, never a bare traceback
        print(f"error: {type(exc).__name__}: {exc}", file=sys.stderr)
        _tell_parent(error, f"{type(exc).__name__}: {exc}")
        return FAILED
    return 0


if __name__ == "__main__":
    try:
        sys.exit(worker(sys.argv[1]))
    except KeyboardInterrupt:  # before the engine's own handler (while importing, say)
        print("error: interrupted before the run started", file=sys.stderr)
        sys.exit(FAILED)
