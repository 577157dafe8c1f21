"""``python -m demstudy.engines.lammps JOB.json``: the child-process / MPI-rank entry point."""

import sys

from .launch import worker

sys.exit(worker(sys.argv[1]))
