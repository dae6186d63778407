"""Provenance of the Datasets the public API returns.

:func:`api_provenance` decorates a public function: the Dataset it returns carries the package
version, the git commit, the creation date, the call's parameters (JSON: scalars as given,
arrays up to 16 values in full, larger ones as shape and range) and ``history`` (the function),
and, when the call names a well, the well's attributes (:func:`safebasins.wells.well_attrs`) —
the same attributes the pipeline's datasets carry (:func:`safebasins.io.datasets.finalize`
overwrites them with the experiment's).  Only provenance attributes
(:data:`safebasins.io.compare.PROVENANCE_ATTRS`) and the well's are added, so results compare
as before; :func:`safebasins.io.datasets.stack` drops the per-part provenance.
"""
from __future__ import annotations

import datetime as _dt
import functools
import inspect
import json

import numpy as np
import xarray as xr

from safebasins import __version__

__all__ = ["api_provenance", "call_parameters"]

#: arrays with at most this many values are recorded in full
FULL_ARRAY = 16


def _value(v):
    if isinstance(v, (str, bool, int, float, type(None))):
        return v
    if isinstance(v, (np.integer, np.floating, np.bool_)):
        return v.item()
    if isinstance(v, (xr.Dataset, xr.DataArray)):
        return f"<{type(v).__name__} {dict(v.sizes)}>"
    if isinstance(v, dict):
        return {str(k): _value(x) for k, x in v.items()}
    try:
        a = np.asarray(v)
    except Exception:                   # an object numpy cannot hold: its repr names it
        return repr(v)
    if a.dtype.kind in "fiub":
        if a.size <= FULL_ARRAY:
            return a.tolist()
        return {"shape": list(a.shape), "min": float(np.nanmin(a)), "max": float(np.nanmax(a))}
    return repr(v)


def call_parameters(fn, args, kwargs) -> dict:
    """The bound arguments of a call (defaults applied) as JSON-ready values; a well object by
    its spec."""
    bound = inspect.signature(fn).bind(*args, **kwargs)
    bound.apply_defaults()
    out = {}
    for k, v in bound.arguments.items():
        if k == "well" and v is not None and hasattr(v, "spec"):
            out[k] = v.spec()
        else:
            out[k] = _value(v)
    return out


def api_provenance(fn):
    """Decorator: the returned Dataset carries version, commit, date, parameters, history and
    the well (see the module docstring); anything else is returned as it is."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        out = fn(*args, **kwargs)
        if not isinstance(out, xr.Dataset):
            return out
        from safebasins.io.datasets import git_commit
        from safebasins.wells import resolve_well, well_attrs

        params = call_parameters(fn, args, kwargs)
        if "well" in params and "well" not in out.attrs:
            out.attrs.update(well_attrs(resolve_well(inspect.signature(fn).bind(*args, **kwargs).arguments.get("well"))))
        out.attrs.update(
            safebasins_version=__version__, git_commit=git_commit(),
            date_created=_dt.datetime.now(_dt.timezone.utc).replace(microsecond=0).isoformat(),
            parameters=json.dumps(params, sort_keys=True, default=repr),
            history=f"{fn.__module__}.{fn.__qualname__} (safebasins {__version__} API)")
        return out

    return wrapper
