"""Compiled ensembles of q'' + V'(q) = F sin(Omega t + Psi) (eq (1) for the paper's quartic well).

Public API (docs/contracts.md):
escape_chart, escape_chart_batch charts.py  (safe masks and areas from a chart: safebasins.analysis.safe)
critical_forcing_numeric         bisection.py
stroboscopic_map                 maps.py
random_initial_conditions        initial_conditions.py
displacement_bounds              criteria.py  (asymmetric displacement bounds from energy levels)
SCHEMES                          schemes.py   (the integrators by name: each a constant)
escape_probability               noise.py     (escape under white noise: ensembles of paths)
Every function takes ``well=``: any form safebasins.wells.resolve_well reads (None: the quartic),
integrated in its one compiled form (``Well.compiled``, wells.compiled).
"""
from safebasins.numerics.bisection import critical_forcing_numeric
from safebasins.numerics.charts import escape_chart, escape_chart_batch
from safebasins.numerics.criteria import displacement_bounds
from safebasins.numerics.engine import DEFAULT_STEPS_PER_CYCLE
from safebasins.numerics.initial_conditions import random_initial_conditions
from safebasins.numerics.noise import escape_probability
from safebasins.numerics.maps import stroboscopic_map
from safebasins.numerics.schemes import SCHEMES

__all__ = ["escape_chart", "escape_chart_batch", "critical_forcing_numeric", "stroboscopic_map",
           "random_initial_conditions", "displacement_bounds", "DEFAULT_STEPS_PER_CYCLE", "SCHEMES",
           "escape_probability"]
