"""demstudy's cache folder (pilots, machine costs) and its locked, atomic JSON writes.

The files under it are caches, not results: they hold dimensionless particle units (d = 1,
m = 1, g = 1 when gravity acts) where they hold physics, and wall-clock seconds where they
hold costs; each says its units.
"""

from __future__ import annotations

import fcntl
import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = ["cache_dir", "locked"]


def cache_dir() -> Path:
    """demstudy's cache folder: $XDG_CACHE_HOME/demstudy (default ~/.cache/demstudy)."""
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "demstudy"


@contextmanager
def locked(path: Path) -> Iterator[None]:
    """Hold an exclusive lock (``fcntl.flock`` on ``path`` + ".lock") for a read-modify-write
    of ``path``: parallel workers updating one cache file would otherwise lose each other's
    entries (each reads the old file, the last rename wins)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path.with_name(path.name + ".lock"), "a") as fh:
        fcntl.flock(fh.fileno(), fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh.fileno(), fcntl.LOCK_UN)
