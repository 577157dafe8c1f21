"""The event-driven hard-particle engine (``--engine edmd``).

Dimensionless particle units: d = 1, m = 1 (mass ∝ d^dim). Hard discs (2D) and hard spheres
(3D) with walls, gravity, Lees–Edwards shear and Campbell's servo; the C++ core is
``demstudy._native.EventDriven`` (native/src/edmd), ``core`` its thin Python layer,
``effects`` the scene's translation into core options and ``backend`` the simulation loop's
backend. See docs/edmd-engine.md.
"""

from .backend import EdmdBackend, with_bumps, y_range
from .core import (
    DEFAULT_TC_2D,
    DEFAULT_TC_3D,
    EventDriven,
    collide_pair,
    default_tc,
    from_initial_state,
)
from .effects import core_options

__all__ = ["DEFAULT_TC_2D", "DEFAULT_TC_3D", "EdmdBackend", "EventDriven", "collide_pair",
           "core_options", "default_tc", "from_initial_state", "with_bumps", "y_range"]
