"""Test-suite settings. Dimensionless particle units throughout (d = 1, m = 1, g = 1 when
gravity acts)."""

import os

# runs in the tests never benchmark the machine for their forecasts (a loaded machine's
# timings; ~10 s per engine kind): forecasts come from the cache or are skipped
# (tests/test_forecast.py sets its own costs)
os.environ.setdefault("DEMSTUDY_MEASURE_RATES", "0")

