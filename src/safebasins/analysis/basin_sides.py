"""Escape over each barrier as its own basin: safe / escape left / escape right.

A well with two barriers (the paper's quartic, ``q = -1`` and ``q = +1``) has two escapes, and
the classic three-basin picture of escape from a symmetric well (Thompson & Soliman; the Wada
basins of open Hamiltonian systems, Aguirre & Sanjuan) tells them apart.  An escape chart keeps
when each initial condition escapes, not where; :func:`side_labels` reads safe and escaped from
the chart (:func:`~safebasins.analysis.basin_labels.chart_labels`) and replays the escaped ones
with the chart's own step (:func:`safebasins.numerics.sides.barrier_sides`) for the side of
their first barrier crossing.  A one-sided well (the cubic escape equation) has one escape:
:func:`side_labels` refuses it and :func:`chart_labels` is its labelling.
"""
from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from safebasins.analysis.basin_labels import SAFE, chart_labels
from safebasins.analysis.safe import AnyCriterion
from safebasins.numerics import schemes
from safebasins.numerics.sides import LEFT, RIGHT, barrier_sides
from safebasins.wells import resolve_well
from safebasins.wells.base import WellLike

__all__ = ["side_labels", "ESCAPED_LEFT", "ESCAPED_RIGHT", "NO_CROSSING"]

#: labels of :func:`side_labels` (SAFE = 1 as chart_labels)
ESCAPED_LEFT, ESCAPED_RIGHT, NO_CROSSING = 0, 2, 3


def _integrator(chart: xr.Dataset, damping: float) -> str:
    """The scheme name whose title the chart records."""
    text = chart.attrs.get("integrator")
    for name in schemes.SCHEMES:
        if schemes.integrator_text(name, damping) == text:
            return name
    raise ValueError(f"chart: its integrator {text!r} is none of {list(schemes.SCHEMES)}")


def side_labels(chart: xr.Dataset, t_eval: float | None = None, *, well: WellLike = None,
                threshold: float | None = None, criterion: AnyCriterion = "energy",
                extra_cycles: int = 20, threads: int = 2) -> xr.DataArray:
    """The basins of a two-barrier well's escape chart: escaped over the left barrier (0), safe
    (1), escaped over the right barrier (2).

    Parameters
    ----------
    chart : an escape chart on a ``(q0, p0)`` grid (:func:`safebasins.numerics.escape_chart`) of
        a well with a barrier on each side.
    t_eval, threshold, criterion : which ICs are safe, as
        :func:`~safebasins.analysis.basin_labels.chart_labels`.
    well : the chart's well (None: the quartic); checked against the chart's ``well`` attribute.
        ValueError for a well with one barrier (one side: use chart_labels).
    extra_cycles : the replay of an escaped IC runs ``cycles + extra_cycles`` forcing cycles for
        the first barrier crossing (the energy criterion can precede it).
    threads : threads of the replay.

    Returns
    -------
    xr.DataArray ``basin`` (q0, p0), int8: 0 escaped left (first crossing ``q < q_left``),
    1 safe, 2 escaped right (``q > q_right``), 3 escaped by the criterion but no barrier crossed
    within the replay (a basin of its own, never a guessed side; counted in ``n_no_crossing``);
    CF ``flag_values``, ``flag_meanings``; attributes of chart_labels plus ``n_escaped_left``,
    ``n_escaped_right``, ``n_no_crossing``, ``extra_cycles``.
    """
    w = resolve_well(well)
    if not (np.isfinite(w.barriers[0]) and np.isfinite(w.barriers[1])):
        raise ValueError(f"well: the {w.name} well has one barrier (barriers {w.barriers}): escape has one "
                         "side, and chart_labels (escaped / safe) is its labelling")
    if chart.attrs.get("well") != w.name:
        raise ValueError(f"well: {w.name!r} is not the chart's well {chart.attrs.get('well')!r}")
    if isinstance(extra_cycles, bool) or not isinstance(extra_cycles, (int, np.integer)) or extra_cycles < 0:
        raise ValueError(f"extra_cycles must be an integer >= 0, got {extra_cycles!r}")
    missing = [k for k in ("F", "Omega", "Psi", "cycles", "steps_per_cycle") if k not in chart.attrs]
    if missing:
        raise ValueError(f"chart: attributes {missing} are missing (an escape_chart of one control point is needed)")
    base = chart_labels(chart, t_eval, threshold=threshold, criterion=criterion)
    damping = float(chart.attrs.get("damping", 0.0))
    a: dict[str, Any] = chart.attrs
    lab = base.values.astype(np.int8)
    esc = lab != SAFE
    Q, P = np.meshgrid(base["q0"].values, base["p0"].values, indexing="ij")
    side, _ = barrier_sides(Q[esc], P[esc], a["F"], a["Omega"], a["Psi"], cycles=int(a["cycles"]) + extra_cycles,
                            well=w, steps_per_cycle=int(a["steps_per_cycle"]), integrator=_integrator(chart, damping),
                            damping=damping, threads=threads)
    sub = np.full(side.shape, NO_CROSSING, np.int8)
    sub[side == LEFT] = ESCAPED_LEFT
    sub[side == RIGHT] = ESCAPED_RIGHT
    lab[esc] = sub
    out = base.copy(data=lab)
    out.attrs.update(long_name="basin label: escaped over the left barrier (0), safe (1), escaped over the right "
                               "barrier (2), escaped without crossing a barrier in the replay (3)",
                     flag_values=[ESCAPED_LEFT, SAFE, ESCAPED_RIGHT, NO_CROSSING],
                     flag_meanings="escaped_left safe escaped_right escaped_no_crossing",
                     n_escaped_left=int((sub == ESCAPED_LEFT).sum()),
                     n_escaped_right=int((sub == ESCAPED_RIGHT).sum()),
                     n_no_crossing=int((sub == NO_CROSSING).sum()), extra_cycles=int(extra_cycles),
                     side="the barrier of the first crossing, q < q_left or q > q_right, replayed with the chart's "
                          "step")
    return out
