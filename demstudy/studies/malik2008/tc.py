"""The event-driven engine's TC time of Malik's study runs.

Dimensionless particle units: d = 1, m = 1, g = 1 (t_c in √(d/g)).

The study's runs are made at ``STUDY_TC`` = 1e-5, given as an explicit option: that was the
engine's default for spheres when the committed records (docs/data/studies/malik2008) were
made, and the default for spheres is now 1e-6 (``engines.edmd.core.DEFAULT_TC_3D``), the t_c of
the study's TC twins. Remaking every run at 1e-6 would take about 30 h of one core (the
W = 50 boxes, ×1.0-2.1 their time); the twins say where t_c matters (the "TC model" rows).
"""

STUDY_TC = 1e-5
