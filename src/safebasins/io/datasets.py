"""Datasets of the pipeline and the command line: CF globals and provenance, atomic netCDF writes.

Every file the pipeline writes goes through :func:`finalize` and :func:`write_netcdf`:

* :func:`safebasins.core.cf.annotate` fills ``units`` / ``long_name`` from the one CF table;
* :func:`finalize` adds the CF globals (``Conventions``, ``title``, ``source``, ``history``,
  ``references``, ``institution``, ``date_created``) and provenance (``safebasins_version``,
  ``git_commit``, ``config_hash``, ``parameters`` as JSON, ``seeds`` when the parameters have
  them; numeric datasets carry ``integrator`` and ``steps_per_cycle`` from safebasins.numerics);
* :func:`write_netcdf` writes netCDF4 with zlib compression to a temporary file in the target
  directory and renames it over the target (atomic: a killed job never leaves a half file);
  it and :func:`load` go through :mod:`safebasins.io.netcdf`, whose errors name the file and
  the likely cause (a full disk, a corrupted or truncated file).

Compare datasets by content with :mod:`safebasins.io.compare`, never by file bytes:
``date_created`` and ``git_commit`` legitimately differ between runs.
"""
from __future__ import annotations

import datetime as _dt
import json
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from safebasins.core.cf import INSTITUTION, REFERENCE, annotate
from safebasins.core.provenance import git_commit
from safebasins.core.version import __version__
from safebasins.io import netcdf
from safebasins.io.params import params_hash
from safebasins.wells import spec_attrs


def _attr_value(v: Any) -> Any:
    """A netCDF-storable attribute value."""
    if isinstance(v, (bool, np.bool_)):
        return int(v)
    if v is None:
        return "none"
    if isinstance(v, dict):
        return json.dumps(v, sort_keys=True)
    if isinstance(v, (list, tuple)):
        if all(isinstance(x, str) for x in v):
            return list(v) if v else ""
        try:
            ints = all(isinstance(x, (int, np.integer)) and not isinstance(x, bool) for x in v)
            return np.asarray(v, dtype=np.int64) if ints else np.asarray(v, dtype=float)
        except (TypeError, ValueError):
            return json.dumps(v)
    if isinstance(v, np.ndarray) and v.dtype.kind == "b":
        return v.astype(np.int8)
    return v


def _collect_seeds(params: Any) -> Any:
    seeds: list[Any] = []
    if isinstance(params, dict):
        for k, v in params.items():
            if k in ("seed", "seeds"):
                seeds.extend(v if isinstance(v, (list, tuple)) else [v])
            elif isinstance(v, dict):
                seeds.extend(_collect_seeds(v))
    return seeds


def finalize(ds: xr.Dataset, *, title: str, params: dict | None = None, config_hash: str | None = None,
             source: str | None = None, history: str | None = None, **extra: Any) -> xr.Dataset:
    """Add CF globals and provenance (returns `ds`, modified in place)."""
    annotate(ds)
    params = params or {}
    attrs = ds.attrs
    attrs["Conventions"] = "CF-1.10"
    attrs["title"] = title
    attrs["institution"] = INSTITUTION
    attrs["source"] = source or f"safebasins {__version__}"
    attrs["history"] = history or f"created by safebasins {__version__}"
    attrs["references"] = REFERENCE
    attrs["date_created"] = _dt.datetime.now(_dt.UTC).replace(microsecond=0).isoformat()
    attrs["safebasins_version"] = __version__
    attrs["git_commit"] = git_commit()
    if config_hash is None and params:
        config_hash = params_hash(params)
    attrs["config_hash"] = config_hash or "none"
    attrs["parameters"] = json.dumps(params, sort_keys=True)
    if "experiment" in params:
        attrs["experiment"] = params["experiment"]
    if "fourier" in params:
        attrs.setdefault("fourier", params["fourier"])
    if "well" in params:
        attrs.update(spec_attrs(params["well"]))
    seeds = _collect_seeds(params)
    if seeds:
        attrs["seeds"] = np.asarray(seeds, dtype=np.int64)
    for k, v in extra.items():
        attrs[k] = v
    for k in list(attrs):
        attrs[k] = _attr_value(attrs[k])
    for name in ds.variables:
        for k in list(ds[name].attrs):
            ds[name].attrs[k] = _attr_value(ds[name].attrs[k])
    return ds


def _encoding(ds: xr.Dataset) -> dict:
    enc = {}
    for name, var in ds.variables.items():
        if var.dtype.kind in "fiub" and var.ndim > 0:
            enc[name] = {"zlib": True, "complevel": 4, "shuffle": True}
    return enc


def write_netcdf(ds: xr.Dataset, path: Any) -> Path:
    """Write `ds` to netCDF4 (zlib) atomically (:func:`safebasins.io.netcdf.write`: no half file
    survives a failure; a full disk is a :class:`~safebasins.io.netcdf.NetCDFFileError` naming the file)."""
    return netcdf.write(ds, path, format="NETCDF4", engine="netcdf4", encoding=_encoding(ds))


def load(path: Any) -> xr.Dataset:
    """Read a dataset fully into memory and close the file (:func:`safebasins.io.netcdf.read`: a
    corrupted or truncated file is a :class:`~safebasins.io.netcdf.NetCDFFileError` naming it)."""
    return netcdf.read(path)
