"""SHA-256 checksums of the files a resumed run reads back (checkpoints, restart files).

Dimensionless particle units do not enter here: these are bytes. A file written by a run
carries (or is named with) the SHA-256 of its bytes; a resume verifies it before reading, so
a damaged file is refused by name instead of resuming from garbage or hanging the reader.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

from ..errors import RunRefused


class DamagedCheckpoint(RunRefused):
    """A checkpoint file whose bytes do not match the checksum written with them: bad input
    given with ``--resume``, refused before the engine reads it (exit 2 on the command line,
    like every refused run; an ``EngineError`` still, for callers that catch those)."""

    def __init__(self, path: Path):
        self.path = path
        super().__init__(f"--resume: checkpoint {path} is damaged (checksum mismatch); remove "
                         "the work folder to start afresh")


def file_digest(path: Path) -> str:
    """The SHA-256 (hex) of the file at ``path``, read in chunks (restart files are large)."""
    with open(path, "rb") as fh:
        return hashlib.file_digest(fh, "sha256").hexdigest()


def verify_file(path: Path, digest: str) -> None:
    """Refuse (:class:`DamagedCheckpoint` naming ``path``) a file whose SHA-256 is not
    ``digest``: a damaged file is never handed to the code that would read it."""
    if file_digest(path) != digest:
        raise DamagedCheckpoint(path)


__all__ = ["DamagedCheckpoint", "file_digest", "verify_file"]
