"""The explorer's numerics: the escape chart on the IC grid in blocks (for a progress bar and
to stop when the sliders move), and its agreement with the slow flow.

Numeric safe = not escaped over the energy threshold within the horizon
(:func:`~safebasins.analysis.safe.is_safe` of :func:`~safebasins.numerics.charts.escape_chart`
at ``t_eval = cycles``); the agreement is the intersection over union
(:func:`~safebasins.analysis.agreement.iou`).  With damping the chart integrates the damped equation.
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from safebasins import numerics
from safebasins.analysis.agreement import iou
from safebasins.analysis.safe import is_safe
from safebasins.explore.analytic import Forcing, ic_grid
from safebasins.explore.ranges import WellRanges

__all__ = ["numeric_safe", "agreement", "GRID_SIZES", "CYCLES"]

#: grid points per axis and horizons (forcing cycles) offered next to the button
GRID_SIZES = (41, 61, 81, 101, 151)
CYCLES = (100, 300, 1000, 3000)


def numeric_safe(r: WellRanges, f: Forcing, n: int, cycles: int, *, blocks: int = 10,
                 progress: Callable[[int, int], object] | None = None,
                 stop: Callable[[], bool] | None = None) -> NDArray[np.bool_] | None:
    """Numeric safe mask (q0, p0) on the ``n x n`` grid, integrated in ``blocks`` row blocks.

    ``progress(done, blocks)`` is called after each block; ``stop()`` is asked before each block
    and a True answer abandons the chart (returns None).
    """
    q0, p0 = ic_grid(r, n)
    safe = np.zeros((n, n), dtype=bool)
    parts = np.array_split(np.arange(n), min(blocks, n))
    for k, rows in enumerate(parts):
        if stop is not None and stop():
            return None
        chart = numerics.escape_chart(q0[rows], p0, f.F, f.Omega, f.Psi, xi_max=(f.xi_max,), cycles=cycles,
                                      well=r.well, grid=True, damping=f.damping)
        safe[rows] = is_safe(chart["escape_cycle_energy"].isel(xi_max=0).values, cycles)
        if progress is not None:
            progress(k + 1, len(parts))
    return safe


def agreement(analytic_safe: NDArray[np.bool_], numeric_safe_mask: NDArray[np.bool_]) -> float:
    """Intersection over union of the analytic and numeric safe masks."""
    return float(iou(analytic_safe, numeric_safe_mask))
