"""Gutt's (1989) lattice grain dynamics engine (``--engine lgd``; issue 15).

Dimensionless particle units outside this package's integer core: d = 1, m = 1, g = 1 when
gravity acts. ``lattice`` holds the state and parameters in the listing's integer units.
"""
