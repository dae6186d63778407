"""Shared helpers of the beyond-the-paper modules (erosion, phase_invariant, fourier_compare)."""
from __future__ import annotations

import importlib

import numpy as np
import xarray as xr

from safebasins import _validate as V
from safebasins.integrity import grid_spacing

FOURIER_CHOICES = ("paper", "exact")


_THEORY_SUBMODULES = ("slow_flow", "critical", "basins", "action_angle")
_NUMERICS_SUBMODULES = ("charts", "bisection", "maps")


def _lookup(pkg, submodules, name):
    mod = importlib.import_module(pkg)
    fn = getattr(mod, name, None)
    if fn is not None:
        return fn
    for sub in submodules:  # the contract names may not be re-exported by __init__ yet
        try:
            fn = getattr(importlib.import_module(f"{pkg}.{sub}"), name, None)
        except ImportError:
            continue
        if fn is not None:
            return fn
    raise ImportError(f"{pkg} has no {name!r} yet (see docs/contracts.md)")


def theory_fn(name):
    """A contract function of safebasins.theory (ImportError naming it if not there)."""
    return _lookup("safebasins.theory", _THEORY_SUBMODULES, name)


def numerics_fn(name):
    """A contract function of safebasins.numerics (ImportError naming it if not there)."""
    return _lookup("safebasins.numerics", _NUMERICS_SUBMODULES, name)


def fourier_list(fourier):
    """Normalise ``fourier`` to (list_of_variants, is_scalar)."""
    scalar = isinstance(fourier, str)
    items = [fourier] if scalar else list(fourier)
    if not items:
        raise ValueError("fourier must name at least one variant")
    for f in items:
        if f not in FOURIER_CHOICES:
            raise ValueError(f"fourier must be one of {FOURIER_CHOICES} (or a list of them), got {f!r}")
    return items, scalar


def as_1d(name, values, check=None):
    a = np.atleast_1d(V._arr(name, values) if check is None else check(name, values)).astype(float)
    if a.ndim != 1:
        raise ValueError(f"{name} must be a scalar or a 1-D sequence, got shape {a.shape}")
    return a


def mesh(q0, p0):
    q, p, _, _ = grid_spacing(q0, p0)
    Q, P = np.meshgrid(q, p, indexing="ij")
    return q, p, Q, P


def chart_param(ds, name):
    """A parameter of an escape chart: coordinate if stacked over it, else the attribute."""
    if name in ds.coords:
        return ds[name]
    if name in ds.attrs:
        return ds.attrs[name]
    raise ValueError(f"chart has neither a coordinate nor an attribute {name!r}")


def stack_charts(charts, dim):
    """Accept one Dataset (possibly already stacked over ``dim``) or a sequence of charts.

    A sequence is concatenated along ``dim`` using each chart's attribute ``dim``.
    """
    if isinstance(charts, xr.Dataset):
        return charts
    charts = list(charts)
    if not charts:
        raise ValueError("charts must not be empty")
    vals = []
    for c in charts:
        if dim in c.coords:
            vals.append(float(c[dim]))
        elif dim in c.attrs:
            vals.append(float(c.attrs[dim]))
        else:
            raise ValueError(f"every chart needs an attribute or scalar coordinate {dim!r} to be stacked")
    out = xr.concat([c.drop_vars(dim, errors="ignore") for c in charts], dim=dim,
                    combine_attrs="drop_conflicts")
    out = out.assign_coords({dim: vals})
    out.attrs.pop(dim, None)
    return out


def t_eval_axis(t_eval, cycles):
    """Validated 1-D t_eval (forcing cycles), each <= the integration horizon ``cycles``."""
    if t_eval is None:
        t = np.array([float(cycles)])
    else:
        t = as_1d("t_eval", t_eval, V.check_nonnegative)
    if cycles is not None and (t > float(cycles) * (1 + 1e-12)).any():
        raise ValueError(f"t_eval must be <= cycles = {cycles} (the chart knows nothing beyond its horizon), "
                         f"got max {t.max()}")
    return t


def escape_variable(chart, criterion):
    if criterion == "energy":
        return chart["escape_cycle_energy"], "xi_max"
    if criterion == "displacement":
        return chart["escape_cycle_displacement"], "q_max"
    raise ValueError(f"criterion must be 'energy' or 'displacement', got {criterion!r}")


def numeric_safe(chart, t_eval=None, criterion="energy"):
    """Safe masks ``escape_cycle > t_eval`` with a new leading dim ``t_eval``.

    Returns (safe DataArray (t_eval, ..., q0, p0), xi_norm) where xi_norm is the energy
    used for normalisation: the ``xi_max`` coordinate, or V(q_max) for the
    displacement criterion.
    """
    from safebasins.integrity import xi_from_q_max

    esc, thr = escape_variable(chart, criterion)
    cycles = chart.attrs.get("cycles")
    t = t_eval_axis(t_eval, cycles)
    tda = xr.DataArray(t, dims="t_eval", coords={"t_eval": t},
                       attrs={"units": "forcing cycles", "long_name": "evaluation time"})
    safe = (esc > tda).transpose("t_eval", ..., "q0", "p0")
    if thr == "xi_max":
        xi_norm = safe["xi_max"]
    else:
        xi_norm = xr.DataArray(xi_from_q_max(safe["q_max"].values), dims=safe["q_max"].dims,
                               coords={"q_max": safe["q_max"]})
    return safe, xi_norm
