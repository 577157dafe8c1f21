"""``python -m demstudy.simulation.child JOB.json``: the entry point of an engine's child
process (:mod:`demstudy.simulation.isolation` says what it does and its exit codes).

A module of its own, imported by nothing: running ``isolation`` itself with ``-m`` made Python
warn that it was already imported (by the package) before it ran as ``__main__``.
Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.
"""

from __future__ import annotations

import sys

if __name__ == "__main__":
    from .isolation import INTERRUPTED, worker

    try:
        sys.exit(worker(sys.argv[1]))
    except KeyboardInterrupt:  # before the engine's own handler (while importing, say)
        sys.exit(INTERRUPTED)  # the parent says so
