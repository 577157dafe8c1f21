"""Checkpoints: written atomically, refused when they cannot continue this run.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts. A checkpoint is one
pickle in the run's work folder (``checkpoint.pkl``): the scene, the version of the code
that wrote it, the output it belongs to, the loop's state and the engine's state, followed
by a trailer holding the SHA-256 of the pickle's bytes (``pickle.loads`` stops before it). A
resumed run continues only with the code and the scene that wrote it, and only from bytes whose
checksum matches: a damaged pickle is refused by name before it is unpickled (unpickling flipped
bytes resumed runs with temperatures of 1e178). Engines checksum their own files the same way
(:func:`demstudy.io.checksum.verify_file`, e.g. the LAMMPS restart file a checkpoint names).
"""

from __future__ import annotations

import hashlib
import pickle
from pathlib import Path
from typing import Any

from ..contact.pilot import PilotResult
from ..errors import EngineError
from ..io.checksum import DamagedCheckpoint
from ..io.results import write_atomically
from ..scene import Scene, flat_fields, scene_to_toml

CHECKPOINT = "checkpoint.pkl"
TRAILER = b"\n#sha256="  # then the 64 hex digits of the pickle's SHA-256
_TRAILER_SIZE = len(TRAILER) + 64


def pickle_atomically(path: Path, obj: Any) -> str:
    """Pickle ``obj`` to ``path`` atomically (temporary file, fsync, rename), followed by the
    SHA-256 trailer: a checkpoint is whole or absent, also when the disk is full, and damage
    done afterwards is detected by :func:`read_checkpoint`. Returns the SHA-256 (hex)."""
    data = pickle.dumps(obj)
    digest = hashlib.sha256(data).hexdigest()
    write_atomically(path, data + TRAILER + digest.encode())
    return digest


def checkpoint_digest(path: Path) -> str | None:
    """The SHA-256 a checkpoint's trailer holds (its last bytes, the pickle unread); None
    when there is no readable trailer."""
    try:
        with open(path, "rb") as fh:
            fh.seek(-_TRAILER_SIZE, 2)
            trailer = fh.read()
    except OSError:
        return None
    if not trailer.startswith(TRAILER):
        return None
    return trailer[len(TRAILER):].decode("ascii", "replace")


def stopped_run(out: Path, engine: str, scene_toml: str | None = None) -> bool:
    """Whether results file ``out`` of ``engine`` has a stopped run to resume: a checkpoint
    in its work folder (sweeps and studies continue such a run instead of restarting it),
    and (``scene_toml`` given) not one its progress file says is of another scene: a case
    whose scene changed since starts afresh, replacing that checkpoint, instead of failing
    on ``--resume``. A checkpoint without a progress file of its own (older, or damaged: the
    resume refuses it by name) is resumed, and the resume checks its scene."""
    from .options import work_folder
    from .progress import progress_record, scene_digest

    folder = work_folder(Path(out), engine)
    if not (folder / CHECKPOINT).is_file():
        return False
    record = progress_record(folder) if scene_toml is not None else None
    return record is None or record.get("scene_sha256") == scene_digest(scene_toml)


def read_checkpoint(path: Path) -> Any:
    """The object :func:`pickle_atomically` wrote to ``path``; :class:`DamagedCheckpoint` when
    the bytes do not match their checksum (flipped, truncated, no trailer), before anything is
    unpickled. ``OSError`` when it cannot be read."""
    raw = path.read_bytes()
    data, trailer = raw[:-_TRAILER_SIZE], raw[-_TRAILER_SIZE:]
    if (len(raw) <= _TRAILER_SIZE or not trailer.startswith(TRAILER)
            or hashlib.sha256(data).hexdigest().encode() != trailer[len(TRAILER):]):
        raise DamagedCheckpoint(path)
    return pickle.loads(data)


def load_checkpoint(path: Path, scene: Scene, keys: set[str], version: str,
                    engine: str) -> dict:
    """The pickled checkpoint dict at ``path`` for ``--resume``, refused (``EngineError``
    naming the file) when missing, unreadable, without the ``keys`` the engine needs (besides
    ``scene``), written by another ``version`` (a checkpoint continues only with the code that
    wrote it) or for a scene other than ``scene`` (naming the keys that differ); damaged
    (checksum mismatch): :class:`DamagedCheckpoint`."""
    if not path.exists():
        raise EngineError(f"--resume: no checkpoint in {path.parent}")
    try:
        saved = read_checkpoint(path)
    except DamagedCheckpoint:
        raise
    except Exception as exc:  # truncated, corrupt or written by other code
        raise EngineError(f"--resume: {path} is not readable ({type(exc).__name__}: {exc}); "
                          "remove it to start afresh") from exc
    if not isinstance(saved, dict):
        raise EngineError(f"--resume: {path} is not a checkpoint of the {engine} engine")
    written = saved.get("version", "an earlier version")
    if written != version:
        raise EngineError(f"--resume: {path} was written by {written}, this is {version}: a "
                          "checkpoint continues only with the code that wrote it (remove it "
                          "to start afresh)")
    if not keys | {"scene"} <= saved.keys():
        raise EngineError(f"--resume: {path} is not a checkpoint of the {engine} engine")
    if saved["scene"] != scene_to_toml(scene):
        raise EngineError("--resume: the checkpoint belongs to a different scene ("
                          f"{scene_difference(saved['scene'], scene)})")
    return saved


def saved_pilot(path: Path) -> PilotResult | None:
    """The pilot a soft-contact run's checkpoint at ``path`` chose its k_n and dt with
    (``get_state()["contact"]["pilot"]``), for ``--resume`` to continue with the same
    contacts even where the pilot's cache is gone; None when there is none (or no readable
    checkpoint: :func:`load_checkpoint` then says why)."""
    try:
        text = read_checkpoint(path)["backend"]["contact"]["pilot"]
        return PilotResult.from_json(text)
    except Exception:  # noqa: BLE001 - no checkpoint, no pilot, another format
        return None


def scene_difference(saved_toml: str, scene: Scene, most: int = 3) -> str:
    """The scene a checkpoint was run with against ``scene``: the first ``most`` dotted keys
    whose values differ, e.g. "run.production: 4.0 in the checkpoint, 1.0 now"."""
    import tomllib  # noqa: PLC0415

    old = flat_fields(tomllib.loads(saved_toml))
    new = flat_fields(tomllib.loads(scene_to_toml(scene)))
    missing = object()
    diffs = [f"{k}: {old.get(k, 'unset')!r} in the checkpoint, {new.get(k, 'unset')!r} now"
             for k in sorted(old.keys() | new.keys())
             if old.get(k, missing) != new.get(k, missing)]
    more = f" and {len(diffs) - most} more" if len(diffs) > most else ""
    return "; ".join(diffs[:most]) + more


def resume_note(workdir: Path) -> str:
    """What an aborted run leaves: the last checkpoint in ``workdir`` to ``--resume`` from,
    or none."""
    if (workdir / CHECKPOINT).exists():
        return (f"the last checkpoint stays in {workdir}: run the same command again with "
                "--resume to continue from it")
    return "no checkpoint was written yet, so the run starts afresh next time"


def refuse_foreign_checkpoint(path: Path, out: Path) -> None:
    """Outputs that differ only in their suffix share a work folder: a fresh run must not
    delete the checkpoint another output's interrupted run left there."""
    if not path.exists():
        return
    try:
        other = read_checkpoint(path).get("out")
    except Exception:  # unreadable: a fresh run replaces it
        return
    if other is not None and other != str(out):
        raise EngineError(f"{path.parent} holds the checkpoint of the interrupted run "
                          f"writing {other}: resume that run first, or remove the folder")
