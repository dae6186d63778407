"""Agreement of safe sets: intersection over union, pixel agreement, criteria counts.

One definition each, used by the pipeline (the IoU stored in the Figs 13-17 charts, the
Fig 19 counts), the first-harmonic comparison and the tests.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from safebasins.analysis.safe import CRITERIA, is_safe

__all__ = ["iou", "pixel_agreement", "mask_agreement", "criteria_counts"]


def _boolean(name, a):
    dtype = a.dtype if isinstance(a, xr.DataArray) else np.asarray(a).dtype
    if dtype != bool:
        raise ValueError(f"{name} must be a boolean mask (True = safe), got dtype {dtype}")


def _pair(a, b, dims):
    _boolean("a", a)
    _boolean("b", b)
    if isinstance(a, xr.DataArray) or isinstance(b, xr.DataArray):
        a, b = xr.align(a, b, join="exact")
        n = int(np.prod([a.sizes[d] for d in dims]))
    else:
        try:
            a, b = np.broadcast_arrays(np.asarray(a), np.asarray(b))
        except ValueError as exc:
            raise ValueError(f"masks must have broadcastable shapes, got {np.shape(a)} and {np.shape(b)}") from exc
        n = int(np.prod([a.shape[d] for d in dims])) if a.ndim else 0
    if n == 0:
        raise ValueError("masks must not be empty: agreement over no points is undefined")
    return a, b


def iou(a, b, dims=("q0", "p0")):
    """Intersection over union ``|A and B| / |A or B|`` of two boolean masks (1 when both are
    empty: perfect agreement).  DataArrays reduce over the named ``dims``; numpy arrays over the
    axes ``dims`` (default: the last two)."""
    if not isinstance(a, xr.DataArray) and not isinstance(b, xr.DataArray) and dims == ("q0", "p0"):
        dims = (-2, -1)
    a, b = _pair(a, b, dims)
    if isinstance(a, xr.DataArray):
        inter = (a & b).sum(dims)
        union = (a | b).sum(dims)
        return xr.where(union > 0, inter / union.where(union > 0, 1), 1.0).astype(float)
    inter = (a & b).sum(axis=dims)
    union = (a | b).sum(axis=dims)
    return np.where(union > 0, inter / np.maximum(union, 1), 1.0)


def pixel_agreement(a, b, dims=("q0", "p0")):
    """Fraction of grid points on which two boolean masks agree."""
    if not isinstance(a, xr.DataArray) and not isinstance(b, xr.DataArray) and dims == ("q0", "p0"):
        dims = (-2, -1)
    a, b = _pair(a, b, dims)
    if isinstance(a, xr.DataArray):
        return (a == b).mean(dims).astype(float)
    return (a == b).mean(axis=dims)


def mask_agreement(analytic_safe, numeric_safe, dims=("q0", "p0")):
    """``(iou, pixel_agreement)`` of two boolean safe masks (DataArrays), reduced over ``dims``."""
    return iou(analytic_safe, numeric_safe, dims), pixel_agreement(analytic_safe, numeric_safe, dims)


def criteria_counts(chart, t_eval, groups):
    """Safe counts of the energy and displacement criteria on random ICs (paper Appendix, Fig 19).

    ``chart``: an escape chart over ``sample`` with one ``xi_max`` and one ``q_max`` threshold;
    its samples are split into ``groups`` consecutive equal groups (the repetitions).  Returns
    ``(A_E, A_q)``: int64 arrays of length ``groups``, the number of ICs that have not escaped by
    ``t_eval`` under the energy (ESB) and the displacement (DSB) criterion.
    """
    n = chart.sizes["sample"]
    if groups < 1 or n % groups:
        raise ValueError(f"groups must divide the {n} samples into equal repetitions, got {groups}")
    out = []
    for crit in ("energy", "displacement"):
        var, thr = CRITERIA[crit]
        s = np.asarray(is_safe(chart[var].isel({thr: 0}).values, t_eval))
        out.append(s.reshape(groups, n // groups).sum(axis=1).astype(np.int64))
    return out[0], out[1]
