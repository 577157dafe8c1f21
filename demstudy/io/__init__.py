"""Results files, frames and trajectory readers (dimensionless particle units: d = m = 1)."""

from .frames import Frame
from .results import Results, read_results, write_results

__all__ = ["Frame", "Results", "read_results", "write_results"]
