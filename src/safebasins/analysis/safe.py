"""Safe basins read from escape charts: the one definition ``safe = escape_cycle > t_eval``.

An escape chart (:func:`safebasins.numerics.escape_chart`) stores the first escape time of
every initial condition for every threshold (``+inf`` = no escape within the horizon); the
safe basin for a threshold and an evaluation time ``t_eval <= cycles`` is the set of ICs that
have not escaped by then.  Every reader of charts (agreement, integrity, erosion, phase-invariant
basins, criteria counts, figures) goes through :func:`is_safe`.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from safebasins import checks
from safebasins.io import cf

__all__ = ["is_safe", "check_t_eval", "safe_mask", "safe_area", "safe_stack", "escape_variable"]

#: escape-time variable and threshold dimension of each criterion
CRITERIA = {"energy": ("escape_cycle_energy", "xi_max"),
            "displacement": ("escape_cycle_displacement", "q_max")}


def is_safe(escape_cycle, t_eval):
    """``escape_cycle > t_eval``: not escaped by ``t_eval`` (numpy arrays or DataArrays)."""
    return escape_cycle > t_eval


def escape_variable(chart, criterion):
    """(escape-time DataArray, threshold dimension) of ``criterion`` ("energy" | "displacement")."""
    if criterion not in CRITERIA:
        raise ValueError(f"criterion must be one of {sorted(CRITERIA)}, got {criterion!r}")
    var, thr = CRITERIA[criterion]
    return chart[var], thr


def check_t_eval(t_eval, cycles):
    """Validated evaluation times (scalar or 1-D, forcing cycles), each <= the horizon ``cycles``."""
    t = checks.check_nonnegative("t_eval", t_eval)
    if t.ndim > 1:
        raise ValueError(f"t_eval must be a scalar or 1-D, got shape {t.shape}")
    if cycles is not None and (t > float(cycles) * (1 + 1e-12)).any():
        raise ValueError(f"t_eval must be <= the chart's horizon cycles = {cycles} (the chart knows nothing "
                         f"beyond it), got max {t.max()!r}")
    return t


def _t_eval_array(t, name="t_eval"):
    return xr.DataArray(t, dims=(name,) if t.ndim else (), name=name, attrs=cf.attrs("t_eval"))


def safe_mask(chart, t_eval):
    """Safe basins of an escape chart at evaluation time(s) ``t_eval`` (cycles, <= chart cycles).

    Returns a Dataset with bool ``safe_energy`` (xi_max, ...) and ``safe_displacement``
    (q_max, ...).  A 1-D t_eval adds a leading dim ``t_eval``; a scalar gives a scalar coordinate.
    """
    t = check_t_eval(t_eval, chart.attrs.get("cycles"))
    tda = _t_eval_array(t)
    out = xr.Dataset({f"safe_{c}": is_safe(chart[CRITERIA[c][0]], tda) for c in CRITERIA})
    out = out.assign_coords(t_eval=tda)
    if "t_eval" in out.dims:
        out = out.transpose("t_eval", ...)
    for c in CRITERIA:
        out[f"safe_{c}"].attrs = {"long_name": f"safe (no {c} escape up to t_eval)"}
    out.attrs.update({k: chart.attrs[k] for k in ("F", "Omega", "Psi", "cycles", "steps_per_cycle") if k in chart.attrs})
    return out


def _cell_widths(name, x):
    x = np.asarray(x, dtype=float)
    if x.size < 2:
        raise ValueError(f"{name} must have at least 2 grid points to define a cell area, got {x.size}")
    w = np.empty_like(x)
    w[1:-1] = 0.5 * (x[2:] - x[:-2])
    w[0] = x[1] - x[0]
    w[-1] = x[-1] - x[-2]
    return np.abs(w)


def safe_area(chart, t_eval):
    """Safe-basin size versus evaluation time, vectorised over t_eval.

    Returns a Dataset with ``pixels_energy`` (t_eval?, xi_max) and ``pixels_displacement``
    (t_eval?, q_max): number of safe ICs; ``area_*``: phase-space area (sum of the cells
    dq0 * dp0 of the safe grid points), NaN for paired ICs; ``fraction_*``: pixels / ICs.
    A grid axis with a single point has no cell size: ValueError.
    """
    m = safe_mask(chart, t_eval)
    is_grid = "q0" in chart.dims and "p0" in chart.dims
    dims = ("q0", "p0") if is_grid else ("sample",)
    n = int(np.prod([chart.sizes[d] for d in dims]))
    out = xr.Dataset(coords={"t_eval": m["t_eval"]})
    if is_grid:
        w = xr.DataArray(np.outer(_cell_widths("q0", chart["q0"].values), _cell_widths("p0", chart["p0"].values)),
                         dims=dims)
    for kind in CRITERIA:
        s = m[f"safe_{kind}"]
        pix = s.sum(dims)
        out[f"pixels_{kind}"] = pix.astype(np.int64)
        out[f"pixels_{kind}"].attrs = {"units": "1", "long_name": f"number of safe ICs ({kind} criterion)"}
        out[f"fraction_{kind}"] = pix / n
        out[f"fraction_{kind}"].attrs = {"units": "1", "long_name": f"safe fraction of the ICs ({kind} criterion)"}
        area = (s * w).sum(dims) if is_grid else pix * np.nan
        out[f"area_{kind}"] = area
        out[f"area_{kind}"].attrs = {"units": "1", "long_name": f"safe area in the (q0, p0) plane ({kind} criterion)"}
    if "t_eval" in out.dims:
        out = out.transpose("t_eval", ...)
    out.attrs.update(m.attrs)
    return out


def safe_stack(chart, t_eval=None, criterion="energy"):
    """Safe masks with a leading dimension ``t_eval`` (default: the chart horizon).

    Returns ``(safe (t_eval, ..., q0, p0), xi_norm)`` where ``xi_norm`` is the energy that
    normalises integrity measures: the ``xi_max`` coordinate, or the energy ``V(q_max)`` of the
    displacement thresholds (the unforced set {max |q(t)| < q_max} is S0(V(q_max))).
    """
    from safebasins.wells.quartic import QUARTIC

    esc, thr = escape_variable(chart, criterion)
    cycles = chart.attrs.get("cycles")
    t = np.atleast_1d(check_t_eval(float(cycles) if t_eval is None else t_eval, cycles)).astype(float)
    tda = xr.DataArray(t, dims="t_eval", coords={"t_eval": t},
                       attrs=cf.attrs("t_eval"))
    safe = is_safe(esc, tda).transpose("t_eval", ..., "q0", "p0")
    if thr == "xi_max":
        xi_norm = safe["xi_max"]
    else:
        qm = QUARTIC.check_displacement("q_max", safe["q_max"].values)
        xi_norm = xr.DataArray(QUARTIC.xi_from_q_max(qm), dims=safe["q_max"].dims, coords={"q_max": safe["q_max"]})
    return safe, xi_norm
