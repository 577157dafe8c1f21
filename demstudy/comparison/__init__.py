"""Runs compared with a reference, bin by bin within their statistical errors
(``demstudy compare``, ``ds.compare``). Dimensionless particle units: d = 1, m = 1, g = 1 when
gravity acts (otherwise a wall speed or the shear rate sets the time scale).

:func:`compare` gives one :class:`Comparison` per other run (a :class:`FieldComparison` per
field, ``table()`` for the terminal), :func:`plot_comparison` the overlay and difference
figure; :mod:`.stats` holds the significance test shared with :mod:`demstudy.testing` and
:mod:`.rebin` the move to a common bin grid; :func:`combine_replicas` makes one run of
independent replicas (other seeds), with errors from their scatter.
"""

from .core import Comparison, FieldComparison, compare, compare_pair, field_names
from .figure import plot_comparison
from .replicas import combine_replicas

__all__ = ["Comparison", "FieldComparison", "combine_replicas", "compare", "compare_pair",
           "field_names", "plot_comparison"]
