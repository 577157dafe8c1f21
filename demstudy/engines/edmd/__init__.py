"""The event-driven hard-particle engine (``--engine edmd``), milestone 1.

Dimensionless particle units: d = 1, m = 1 (mass ∝ d^dim). Hard discs (2D) and hard spheres
(3D) in a fully periodic box, constant normal restitution e, smooth or constant tangential
restitution β with the reduced inertia K. The C++ core is ``demstudy._native.EventDriven``
(native/src/edmd); ``engine`` runs scenes and writes the common results file.
See docs/edmd-engine.md.
"""

from .core import DEFAULT_TC, EventDriven, collide_pair, from_initial_state, scene_parameters
from .engine import EdmdEngine, check_supported

__all__ = ["DEFAULT_TC", "EdmdEngine", "EventDriven", "check_supported", "collide_pair",
           "from_initial_state", "scene_parameters"]
