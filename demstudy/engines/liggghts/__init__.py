"""The LIGGGHTS engine: the scene's deck driven through LIGGGHTS's C library (ctypes).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (``units lj``). See
docs/engines.md: ``library`` (ctypes driver, crash reports), ``deck`` (the deck and the
effect table), ``backend`` (the simulation loop's backend, always in a fresh interpreter),
``calibrate`` (binary collisions, in a child process).
"""
