"""Escape criteria of the compiled ensembles, and displacement bounds from energy levels.

Any well reaches the numerics through ``safebasins.wells.resolve_well`` (a name, a spec, a
:class:`~safebasins.wells.Well`) and its one compiled form ``well.compiled``
(:mod:`safebasins.wells.compiled`).

Escape criteria (wells.base): energy ``H0 = p^2/2 + V(q) > xi_max`` or ``q`` beyond a barrier
(``q > q_right`` or ``q < q_left``; a side without a finite barrier, ``+-inf``, never escapes
that way: a side open at infinity is left by the energy criterion below its asymptote);
displacement ``|q| > q_max`` (symmetric, ``q_max``) or ``q < lo`` or ``q > hi`` (a bound pair
``(lo, hi)`` of ``q_bounds``, e.g. the turning points ``well.turning_points(xi_max)``:
:func:`displacement_bounds`).  A NaN or inf state is beyond every threshold (escaped, never safe).
"""
from __future__ import annotations

import numpy as np
import numpy.typing as npt

from safebasins.wells import Well, resolve_well
from safebasins.wells.base import WellLike

__all__ = ["displacement_bounds", "criteria_text"]


def displacement_bounds(xi_max: npt.ArrayLike, well: WellLike = None) -> np.ndarray:
    """Displacement bound pairs from energy levels: ``(q_minus(xi), q_plus(xi))``, the turning
    points of the unforced orbit of energy xi (``well.turning_points``; eq (4) for the quartic,
    where they are ``-+q_max(xi)``), as an (n, 2) array for ``q_bounds``."""
    w = resolve_well(well)
    xi = np.atleast_1d(w.check_threshold("xi_max", xi_max)).astype(float).ravel()
    lo, hi = w.turning_points(xi)
    return np.stack([np.asarray(lo, float).ravel(), np.asarray(hi, float).ravel()], axis=-1)


def criteria_text(well: Well, displacement: str = "|q| > q_max, or q < q_lower or q > q_upper (q_bounds)") -> str:
    """The escape criteria of a numeric dataset in words."""
    return (f"energy ({well.energy_criterion()}); displacement: {displacement}; a NaN or inf state counts as "
            "escaped; checked after every step; escape_cycle = step / steps_per_cycle")
