"""Labelled basins: the input of the fractal boundary measures (basin_measures, wada).

A labelled basin is an integer label per node of a uniform ``(q0, p0)`` grid (``ij`` indexing,
first axis q0): which final state each initial condition reaches (escape over a barrier, an
attractor, not escaped by t_eval).  Labels are any integers; only which nodes share a label
matters.  :func:`check_labels` validates them once for every measure; :func:`chart_labels`
reads them from an escape chart, :func:`map_labels` from the stroboscopic map of a damped well
(escape and the attractors the other initial conditions settle on).

An escape chart (:func:`safebasins.numerics.escape_chart`) records *when* an initial condition
escapes, not over which barrier: its labels are escaped (0) and safe (1), two basins.  A Wada
test needs three or more: escape and two attractors of a damped well (:func:`map_labels`), or
escape over each barrier of the quartic (an escape chart keeps the step of escape, not the side:
:func:`safebasins.analysis.basin_sides.side_labels` replays the escaped ICs for it).
"""
from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.analysis.integrity import grid_spacing
from safebasins.analysis.safe import AnyCriterion, check_t_eval, escape_variable, is_safe

__all__ = ["check_labels", "chart_labels", "map_labels", "ESCAPED", "SAFE", "LabelsLike"]

#: labels of :func:`chart_labels`
ESCAPED, SAFE = 0, 1
#: what the measures take as labels: a 2-D integer (or boolean) array or a DataArray over (q0, p0)
LabelsLike = npt.ArrayLike | xr.DataArray
#: a grid axis, or None for labels given without coordinates
Axis = npt.NDArray[np.float64] | None


def check_labels(labels: LabelsLike, name: str = "labels") -> tuple[npt.NDArray[np.int64], Axis, Axis]:
    """``(lab, q0, p0)``: the labels as a 2-D int64 array over ``(q0, p0)`` and the grid axes
    (None for a numpy array).

    ``labels``: a 2-D integer or boolean array, or a DataArray with dims ``("q0", "p0")`` (any
    order; uniform coordinates).  Floats are accepted when every value is an integer.  ValueError
    naming ``name`` for anything else (NaN, fractions, other dims, fewer than 2 nodes a side).
    """
    q0: Axis = None
    p0: Axis = None
    if isinstance(labels, xr.DataArray):
        if set(labels.dims) != {"q0", "p0"}:
            raise ValueError(f"{name} must be a 2-D DataArray with dims ('q0', 'p0'), got dims {labels.dims}: "
                             "select one basin (e.g. .isel(F=0)) first")
        labels = labels.transpose("q0", "p0")
        if "q0" in labels.coords and "p0" in labels.coords:
            q0, p0, _, _ = grid_spacing(labels["q0"].values, labels["p0"].values)
        labels = labels.values
    a = np.asarray(labels)
    if a.ndim != 2:
        raise ValueError(f"{name} must be a 2-D grid (q0, p0), got shape {a.shape}")
    if min(a.shape) < 2:
        raise ValueError(f"{name} must have at least 2 nodes along each axis, got shape {a.shape}")
    if a.dtype == bool or a.dtype.kind in "iu":
        return a.astype(np.int64), q0, p0
    if a.dtype.kind != "f":
        raise ValueError(f"{name} must hold integer labels, got dtype {a.dtype}")
    if not np.isfinite(a).all():
        raise ValueError(f"{name} must be finite integer labels (NaN or inf found): label undecided nodes with "
                         "an integer of their own")
    if (a != np.round(a)).any():
        raise ValueError(f"{name} must hold integer labels, got non-integer values")
    return a.astype(np.int64), q0, p0


def chart_labels(chart: xr.Dataset, t_eval: float | None = None, *, threshold: float | None = None,
                 criterion: AnyCriterion = "energy") -> xr.DataArray:
    """The basins of an escape chart on a grid: 0 = escaped by ``t_eval``, 1 = safe.

    Parameters
    ----------
    chart : an escape chart on a ``(q0, p0)`` grid (:func:`safebasins.numerics.escape_chart`).
    t_eval : evaluation time in cycles (default: the chart's horizon); safe = escape_cycle > t_eval
        (:func:`safebasins.analysis.safe.is_safe`).
    threshold : the chart's threshold to read (an ``xi_max``, ``q_max`` or ``q_bounds`` value of
        the criterion); may be left out when the chart has only one.
    criterion : "energy" (default), "displacement" or "bounds" (as
        :func:`safebasins.analysis.safe.escape_variable`).

    Returns
    -------
    xr.DataArray
        ``basin`` (q0, p0), int8, CF flags ``flag_values = [0, 1]``,
        ``flag_meanings = "escaped safe"``; attributes ``t_eval``, ``criterion``, the threshold
        and the chart's F, Omega, Psi, cycles, damping and well.  The chart does not record the
        barrier an IC escaped over, so every escaped IC has one label.
    """
    esc, thr = escape_variable(chart, criterion)
    if not {"q0", "p0"} <= set(esc.dims):
        raise ValueError(f"chart must be an escape chart on a (q0, p0) grid (labels need a grid), got dims {esc.dims}")
    extra = [d for d in esc.dims if d not in ("q0", "p0", thr)]
    if extra:
        raise ValueError(f"chart has the extra dimensions {extra}: select one chart (e.g. .isel({extra[0]}=0)) first")
    values = esc[thr].values
    if threshold is None:
        if values.size != 1:
            raise ValueError(f"threshold is required: the chart has {values.size} values of {thr!r} "
                             f"({values.tolist()})")
        k = 0
    else:
        hit = np.flatnonzero(np.isclose(values, float(threshold), rtol=1e-12, atol=0))
        if hit.size != 1:
            raise ValueError(f"threshold {threshold!r} is not one of the chart's {thr!r} values {values.tolist()}")
        k = int(hit[0])
    cycles: Any = chart.attrs.get("cycles")
    if t_eval is None and cycles is None:
        raise ValueError("t_eval is required: the chart records no horizon (attribute 'cycles')")
    t = float(check_t_eval(cycles if t_eval is None else t_eval, cycles))
    safe = is_safe(esc.isel({thr: k}), t).transpose("q0", "p0")
    out = safe.astype(np.int8).rename("basin")
    out.attrs = {"long_name": "basin label: escaped (0) or safe (1) at t_eval", "flag_values": [ESCAPED, SAFE],
                 "flag_meanings": "escaped safe", "t_eval": t, "criterion": criterion,
                 thr: float(values[k]) if thr != "q_bounds" else int(values[k])}
    out.attrs.update({key: chart.attrs[key] for key in ("F", "Omega", "Psi", "cycles", "damping")
                      if key in chart.attrs})
    out.attrs.update({key: v for key, v in chart.attrs.items() if key.startswith("well")})
    result: xr.DataArray = out
    return result


def _grid_axes(strobe: xr.Dataset) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """The ``ij`` grid axes of a map's samples (C-order ``meshgrid(q0, p0, indexing="ij")``)."""
    Q, P = strobe["q0"].values, strobe["p0"].values
    q0, p0 = np.unique(Q), np.unique(P)
    if q0.size * p0.size != Q.size or not (np.array_equal(Q, np.repeat(q0, p0.size))
                                          and np.array_equal(P, np.tile(p0, q0.size))):
        raise ValueError("strobe: its initial conditions are not a grid; make the map of "
                         "np.meshgrid(q0, p0, indexing='ij') (flattened in C order)")
    grid_spacing(q0, p0)
    return q0, p0


def map_labels(strobe: xr.Dataset, *, tol: float = 1e-4, period_max: int = 4) -> xr.DataArray:
    """The basins of escape and of each attractor from the stroboscopic map of a grid of ICs.

    Parameters
    ----------
    strobe : xr.Dataset
        :func:`safebasins.numerics.stroboscopic_map` of ``np.meshgrid(q0, p0, indexing="ij")``
        (damped, ``n_iter`` long enough for transients to die out).
    tol : an IC has settled on a period-k orbit (k <= ``period_max``) when its last iterate lies
        within ``tol`` (max norm) of the iterate k periods before.  Orbits whose smallest-q
        points lie within ``10 tol`` of each other are one attractor.
    period_max : longest period looked for.

    Returns
    -------
    xr.DataArray ``basin`` (q0, p0), int64: 0 = escaped within ``n_iter`` cycles, k = 1, 2, ... the
    attractors ordered by period, then by the q of their smallest-q point; CF ``flag_values``,
    ``flag_meanings``; attributes ``attractor_q``, ``attractor_p`` (that point of each),
    ``attractor_period``, ``n_unsettled``: ICs not settled after ``n_iter`` cycles (long
    transients near a basin boundary), given the attractor nearest to their last iterate.
    """
    q0, p0 = _grid_axes(strobe)
    tol = float(np.asarray(tol)) if np.ndim(tol) == 0 else np.nan
    if not np.isfinite(tol) or tol <= 0:
        raise ValueError(f"tol must be a positive number, got {tol!r}")
    if isinstance(period_max, bool) or not isinstance(period_max, (int, np.integer)) or period_max < 1:
        raise ValueError(f"period_max must be a positive integer, got {period_max!r}")
    n_it = strobe.sizes["iteration"] - 1
    if n_it < 2 * period_max:
        raise ValueError(f"strobe: {n_it} iterations are too few to find periods up to period_max = {period_max}")
    esc = strobe["escaped"].values
    q, p = strobe["q"].values[~esc, -period_max - 1:], strobe["p"].values[~esc, -period_max - 1:]
    period = np.zeros(q.shape[0], np.int64)
    for k in range(period_max, 0, -1):          # the smallest period wins
        near = np.maximum(np.abs(q[:, -1] - q[:, -1 - k]), np.abs(p[:, -1] - p[:, -1 - k])) < tol
        period[near] = k
    settled = period > 0
    # the smallest-q point of each settled orbit (its last `period` iterates)
    cols = np.arange(period_max)[None, :] >= period_max - period[:, None]
    qq = np.where(cols, q[:, 1:], np.inf)
    j = np.argmin(qq, axis=1)
    cq, cp = q[np.arange(q.shape[0]), 1 + j], p[np.arange(q.shape[0]), 1 + j]
    centres: list[tuple[int, float, float, Any]] = []   # (period, q, p, members) of each attractor
    free = settled.copy()
    while free.any():
        i = int(np.flatnonzero(free)[0])
        same = free & (period == period[i]) & (np.maximum(np.abs(cq - cq[i]), np.abs(cp - cp[i])) < 10 * tol)
        centres.append((int(period[i]), float(cq[i]), float(cp[i]), same))
        free &= ~same
    if not centres:
        raise ValueError(f"strobe: no IC settled on an orbit of period <= {period_max} within tol = {tol:g} "
                         "(every IC escaped, or n_iter is too short for the transients)")
    order = sorted(range(len(centres)), key=lambda a: centres[a][:2])
    lab = np.zeros(q.shape[0], np.int64)
    for new, a in enumerate(order, start=1):
        lab[centres[a][3]] = new
    if (~settled).any():                        # nearest attractor point to the last iterate
        aq = np.array([centres[a][1] for a in order])
        ap = np.array([centres[a][2] for a in order])
        d = np.hypot(q[~settled, -1, None] - aq[None, :], p[~settled, -1, None] - ap[None, :])
        lab[~settled] = 1 + np.argmin(d, axis=1)
    out = np.zeros(esc.size, np.int64)
    out[~esc] = lab
    n = len(order)
    da = xr.DataArray(out.reshape(q0.size, p0.size), dims=("q0", "p0"), name="basin",
                      coords={"q0": ("q0", q0, strobe["q0"].attrs), "p0": ("p0", p0, strobe["p0"].attrs)})
    da.attrs = {"long_name": "basin label: escaped (0) or the attractor settled on (1, 2, ...)",
                "flag_values": list(range(n + 1)),
                "flag_meanings": " ".join(["escaped"] + [f"attractor_{k}" for k in range(1, n + 1)]),
                "attractor_q": [centres[a][1] for a in order], "attractor_p": [centres[a][2] for a in order],
                "attractor_period": [centres[a][0] for a in order], "n_unsettled": int((~settled).sum()),
                "n_iter": int(n_it), "tol": tol}
    da.attrs.update({key: strobe.attrs[key] for key in ("F", "Omega", "Psi", "damping", "xi_max")
                     if key in strobe.attrs})
    da.attrs.update({key: v for key, v in strobe.attrs.items() if key.startswith("well")})
    return da
