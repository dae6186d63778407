"""Compiled ensembles of eq (1): q'' + q - q^3 = F sin(Omega t + Psi).

Public API (docs/contracts.md):
escape_chart, safe_mask, safe_area           charts.py
critical_forcing_numeric                     bisection.py
stroboscopic_map                             maps.py
random_initial_conditions                    initial_conditions.py
"""
from safebasins.numerics.charts import escape_chart, safe_area, safe_mask
from safebasins.numerics.engine import DEFAULT_STEPS_PER_CYCLE
from safebasins.numerics.kernels import INTEGRATOR

__all__ = ["escape_chart", "safe_mask", "safe_area", "DEFAULT_STEPS_PER_CYCLE", "INTEGRATOR"]

try:  # modules written after the chart engine
    from safebasins.numerics.initial_conditions import random_initial_conditions  # noqa: F401
    __all__.append("random_initial_conditions")
    from safebasins.numerics.maps import stroboscopic_map  # noqa: F401
    __all__.append("stroboscopic_map")
    from safebasins.numerics.bisection import critical_forcing_numeric  # noqa: F401
    __all__.append("critical_forcing_numeric")
except ImportError:  # pragma: no cover
    pass
