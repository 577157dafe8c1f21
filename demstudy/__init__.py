"""demstudy: rapid granular shear flows with particle simulations.

Units everywhere are dimensionless particle units: diameter d = 1, mass m = 1,
and g = 1 when gravity acts (otherwise a wall speed or a shear rate sets the time scale).
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("demstudy")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0.0.0+local"

UNITS_NOTE = (
    "dimensionless particle units: diameter d = 1, mass m = 1, g = 1 when gravity acts "
    "(otherwise the wall speed or shear rate sets the time scale)"
)

__all__ = ["UNITS_NOTE", "__version__"]
