"""Provenance of the Datasets the public API returns.

:func:`api_provenance` decorates a public function: the Dataset it returns carries the package
version, the git commit (:func:`git_commit`), the creation date, the call's parameters (JSON:
scalars as given, arrays up to 16 values in full, larger ones as shape and range) and
``history`` (the function), and, when the call names a well, the well's attributes — the same
attributes the pipeline's datasets carry (:func:`safebasins.io.datasets.finalize` overwrites them
with the experiment's).  The core knows no wells: the decorator is given the function that turns
a ``well`` argument into attributes (``well_attrs=``; :data:`safebasins.wells.provenance.api_provenance`
is this decorator with the wells' one).  Only provenance attributes (:data:`PROVENANCE_ATTRS`)
and the well's are added, so results compare as before; :func:`safebasins.core.stacking.stack`
drops the per-part provenance.
"""
from __future__ import annotations

import datetime as _dt
import functools
import inspect
import json
import subprocess
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar, overload

import numpy as np
import xarray as xr

from safebasins.core.version import __version__

F = TypeVar("F", bound=Callable[..., Any])

__all__ = ["api_provenance", "call_parameters", "git_commit", "PROVENANCE_ATTRS"]

#: global attributes that describe how a file was made, not what it holds (never compared)
PROVENANCE_ATTRS = ("date_created", "git_commit", "safebasins_version", "config_hash", "parameters",
                    "history", "source", "seeds")


@functools.lru_cache(maxsize=1)
def git_commit() -> str:
    """Commit of the source tree the library was imported from ('unknown' outside git, and for an
    installed copy inside another repository's work tree, e.g. a project's ignored .venv)."""
    here = Path(__file__).resolve().parent
    try:
        subprocess.run(["git", "-C", str(here), "ls-files", "--error-unmatch", Path(__file__).name],
                       capture_output=True, timeout=10, check=True)
        out = subprocess.run(["git", "-C", str(here), "rev-parse", "HEAD"], capture_output=True,
                             text=True, timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(here), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=20).stdout.strip()
        return out + ("-dirty" if dirty else "")
    except Exception:  # noqa: BLE001  (no git, not a work tree, a timeout: the commit is unknown)
        return "unknown"


#: arrays with at most this many values are recorded in full
FULL_ARRAY = 16


def _value(v: Any) -> Any:
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
    except Exception:  # noqa: BLE001  (an object numpy cannot hold: its repr names it)
        return repr(v)
    if a.dtype.kind in "fiub":
        if a.size <= FULL_ARRAY:
            return a.tolist()
        return {"shape": list(a.shape), "min": float(np.nanmin(a)), "max": float(np.nanmax(a))}
    return repr(v)


def call_parameters(fn: Any, args: Any, kwargs: Any) -> dict:
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


@overload
def api_provenance(fn: F, *, well_attrs: Callable[[Any], dict[str, Any]] | None = None) -> F: ...


@overload
def api_provenance(fn: None = None, *, well_attrs: Callable[[Any], dict[str, Any]] | None = None
                   ) -> Callable[[F], F]: ...


def api_provenance(fn: Callable[..., Any] | None = None, *,
                   well_attrs: Callable[[Any], dict[str, Any]] | None = None) -> Any:
    """Decorator: the returned Dataset carries version, commit, date, parameters, history and,
    where the call has a ``well`` argument and ``well_attrs`` is given, ``well_attrs(well)`` (see
    the module docstring); anything else is returned as it is.  ``@api_provenance`` or
    ``@api_provenance(well_attrs=...)``."""
    if fn is None:
        return functools.partial(api_provenance, well_attrs=well_attrs)

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        out = fn(*args, **kwargs)
        if not isinstance(out, xr.Dataset):
            return out
        params = call_parameters(fn, args, kwargs)
        if well_attrs is not None and "well" in params and "well" not in out.attrs:
            out.attrs.update(well_attrs(inspect.signature(fn).bind(*args, **kwargs).arguments.get("well")))
        out.attrs.update(
            safebasins_version=__version__, git_commit=git_commit(),
            date_created=_dt.datetime.now(_dt.UTC).replace(microsecond=0).isoformat(),
            parameters=json.dumps(params, sort_keys=True, default=repr),
            history=f"{fn.__module__}.{fn.__qualname__} (safebasins {__version__} API)")
        return out

    return wrapper
