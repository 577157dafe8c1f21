"""The LAMMPS engine's entry point, and running it in a child process or on MPI ranks.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (``units lj``).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from ..._lammps import mpirun_executable
from ...decks import build_deck
from ...decks.contact import contact_setup
from ...scene import Scene, validate_scene
from ..base import EngineError, RunOptions
from .driver import Driver

WORKER_FLAG = "DEMSTUDY_LAMMPS_WORKER"


class LammpsEngine:
    """``run(scene, options)``: the scene's deck, driven through LAMMPS's Python interface."""

    name = "lammps"

    def run(self, scene: Scene, options: RunOptions) -> Path:
        if (options.np > 1 or options.isolate) and os.environ.get(WORKER_FLAG) != "1":
            return launch_child(scene, options)
        setup = contact_setup(scene)  # raises UnsupportedByEngine before LAMMPS starts
        deck = build_deck(scene, setup=setup)  # so does every effect LAMMPS cannot express
        out = Path(options.out).resolve()
        workdir = out.with_suffix(".lammps")
        workdir.mkdir(parents=True, exist_ok=True)
        for name, content in deck.files.items():
            (workdir / name).write_text(content)
        (workdir / "deck.in").write_text(deck.render(scene.meta.name))
        return Driver(scene, deck, setup.timestep, workdir, out, options).run()


def launch_child(scene: Scene, options: RunOptions) -> Path:
    """Run the engine in a child process (on ``options.np`` MPI ranks when np > 1).

    A crash inside LAMMPS (a segfault, an MPI abort) then ends the child, not the caller, and
    is reported as an ``EngineError``; the checkpoint written so far remains usable. Ctrl-C
    reaches the child too, which stops at the end of its segment after a checkpoint.
    """
    build_deck(scene)  # refuse unsupported scenes before launching anything
    payload = {
        "scene": scene.model_dump(mode="json"),
        "out": str(Path(options.out).resolve()),
        "dump": str(Path(options.dump).resolve()) if options.dump else None,
        "resume": options.resume,
        "progress": options.progress,
        "keep_frames": options.keep_frames,
        "checkpoint_interval": options.checkpoint_interval,
        "wall_limit": options.wall_limit,
        "np": options.np,
    }
    out = Path(payload["out"])
    out.parent.mkdir(parents=True, exist_ok=True)
    job = out.with_name(f".{out.name}.job.json")
    job.write_text(json.dumps(payload))
    env = dict(os.environ, **{WORKER_FLAG: "1"})
    cmd = [sys.executable, "-m", "demstudy.engines.lammps", str(job)]
    if options.np > 1:
        cmd = [mpirun_executable(), "-np", str(options.np), *cmd]
    proc = subprocess.Popen(cmd, env=env, stdin=subprocess.DEVNULL)
    try:
        returncode = proc.wait()
    except KeyboardInterrupt:
        # the child got the same SIGINT: let it finish its segment and write a checkpoint
        try:
            returncode = proc.wait(timeout=300)
        except (subprocess.TimeoutExpired, KeyboardInterrupt):
            proc.kill()
            returncode = -9
    finally:
        job.unlink(missing_ok=True)
    if returncode == 3:
        raise EngineError("the run stopped after writing a checkpoint: run the same command "
                          "again with --resume to continue")
    if returncode != 0:
        how = (f"was killed by signal {-returncode}" if returncode < 0
               else f"failed (exit {returncode})")
        where = out.with_suffix(".lammps") / "log.lammps"
        raise EngineError(f"the LAMMPS run on {options.np} rank(s) {how}; see the messages "
                          f"above and {where}")
    return out


def worker(job: str) -> int:
    """``python -m demstudy.engines.lammps JOB.json``: exit 0 done, 3 stopped, 1 failed."""
    payload = json.loads(Path(job).read_text())
    scene = validate_scene(payload["scene"], source=job)
    options = RunOptions(out=Path(payload["out"]), np=payload["np"],
                         dump=Path(payload["dump"]) if payload["dump"] else None,
                         resume=payload["resume"], progress=payload["progress"],
                         keep_frames=payload["keep_frames"],
                         checkpoint_interval=payload["checkpoint_interval"],
                         wall_limit=payload["wall_limit"])
    try:
        LammpsEngine().run(scene, options)
    except EngineError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 3 if str(exc).startswith("stopped") else 1
    return 0
