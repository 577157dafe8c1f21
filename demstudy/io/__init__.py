"""Results files, frames and trajectory readers (dimensionless particle units: d = m = 1)."""

from .fields import field_info, time_unit
from .frames import Frame
from .results import Results, read_results, set_command_line, write_results

__all__ = ["Frame", "Results", "field_info", "read_results", "set_command_line", "time_unit",
           "write_results"]
