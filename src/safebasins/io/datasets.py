"""Datasets: provenance, atomic netCDF writes, stacking of variable-length results.

Every file the pipeline writes goes through :func:`finalize` and :func:`write_netcdf`:

* :func:`safebasins.io.cf.annotate` fills ``units`` / ``long_name`` from the one CF table;
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
import hashlib
import json
import subprocess
from functools import lru_cache
from pathlib import Path

import numpy as np
import xarray as xr

from safebasins import __version__
from safebasins.io.cf import INSTITUTION, REFERENCE, annotate
from safebasins.io import netcdf

@lru_cache(maxsize=1)
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
    except Exception:
        return "unknown"


def _attr_value(v):
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
            return np.asarray(v, dtype=float) if not all(isinstance(x, (int, np.integer)) and
                                                      not isinstance(x, bool) for x in v) else np.asarray(v, dtype=np.int64)
        except (TypeError, ValueError):
            return json.dumps(v)
    if isinstance(v, np.ndarray) and v.dtype.kind == "b":
        return v.astype(np.int8)
    return v


def _collect_seeds(params):
    seeds = []
    if isinstance(params, dict):
        for k, v in params.items():
            if k in ("seed", "seeds"):
                seeds.extend(v if isinstance(v, (list, tuple)) else [v])
            elif isinstance(v, dict):
                seeds.extend(_collect_seeds(v))
    return seeds


def finalize(ds: xr.Dataset, *, title: str, params: dict | None = None, config_hash: str | None = None,
             source: str | None = None, history: str | None = None, **extra) -> xr.Dataset:
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
    attrs["date_created"] = _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0).isoformat()
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
        from safebasins.wells import spec_attrs

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


def write_netcdf(ds: xr.Dataset, path) -> Path:
    """Write `ds` to netCDF4 (zlib) atomically (:func:`safebasins.io.netcdf.write`: no half file
    survives a failure; a full disk is a :class:`~safebasins.io.netcdf.NetCDFFileError` naming the file)."""
    return netcdf.write(ds, path, format="NETCDF4", engine="netcdf4", encoding=_encoding(ds))


def params_hash(params: dict) -> str:
    """SHA-256 of the canonical JSON of one experiment's resolved parameters."""
    return hashlib.sha256(json.dumps(params, sort_keys=True, separators=(",", ":")).encode()).hexdigest()


def load(path) -> xr.Dataset:
    """Read a dataset fully into memory and close the file (:func:`safebasins.io.netcdf.read`: a
    corrupted or truncated file is a :class:`~safebasins.io.netcdf.NetCDFFileError` naming it)."""
    return netcdf.read(path)


# --------------------------------------------------------------------------------------
# stacking variable-length results
# --------------------------------------------------------------------------------------
def _fill_value(dtype):
    k = np.dtype(dtype).kind
    if k == "f":
        return np.nan
    if k == "c":
        return np.nan + 0j
    if k == "i":
        return -1
    if k == "u":
        return 0
    if k == "b":
        return False
    if k in "US":
        return ""
    return ""


def pad_dim(ds: xr.Dataset, dim: str, n: int) -> xr.Dataset:
    """Pad every variable along `dim` to length `n` (float NaN, int -1, bool False, str "")."""
    m = ds.sizes.get(dim, 0)
    if m >= n:
        return ds
    if dim in ds.indexes:
        ds = ds.drop_vars(dim)
    out = ds.copy()
    new_vars = {}
    for name, var in ds.variables.items():
        if dim not in var.dims:
            continue
        axis = var.dims.index(dim)
        shape = list(var.shape)
        shape[axis] = n
        vals = np.asarray(var.values)
        fill = _fill_value(vals.dtype)
        dtype = vals.dtype if vals.dtype.kind not in "US" else object
        arr = np.full(shape, fill, dtype=dtype)
        idx = [slice(None)] * len(shape)
        idx[axis] = slice(0, m)
        arr[tuple(idx)] = vals
        new_vars[name] = xr.Variable(var.dims, arr, var.attrs)
    for name in new_vars:
        out = out.drop_vars(name)
    for name, v in new_vars.items():
        if name in ds.coords:
            out = out.assign_coords({name: v})
        else:
            out[name] = v
    return out


def _same(a, b):
    try:
        a, b = np.asarray(a), np.asarray(b)
        if a.dtype.kind in "fc" and b.dtype.kind in "fc":
            return np.array_equal(a, b, equal_nan=True)
        return np.array_equal(a, b)
    except Exception:
        return a == b


def stack(datasets, dim: str, values=None, *, coords: dict | None = None,
          pad: tuple[str, ...] = ("vertex", "curve")) -> xr.Dataset:
    """Concatenate datasets along a new dimension `dim`.

    `values` become the coordinate of `dim` (default: 0..n-1); `coords` maps extra coordinate
    names to per-dataset values (e.g. ``{"label": [...]}``). Attributes that differ between the
    datasets become coordinates along `dim`; equal ones stay attributes. Dimensions in `pad`
    are padded (NaN / -1 / "" / False) to their largest length first.
    """
    from safebasins.io.compare import PROVENANCE_ATTRS

    datasets = [d.copy() for d in datasets]
    n = len(datasets)
    if n == 0:
        raise ValueError("datasets must not be empty")
    for d in datasets:          # each part's provenance (API calls) is not a coordinate of the stack
        d.attrs = {k: v for k, v in d.attrs.items() if k not in PROVENANCE_ATTRS}
    keys = set().union(*(d.attrs.keys() for d in datasets))
    varying = sorted(k for k in keys if k != dim and not all(
        k in d.attrs and _same(d.attrs[k], datasets[0].attrs.get(k)) for d in datasets))
    extra = dict(coords or {})
    common = {k: datasets[0].attrs[k] for k in keys
              if k not in varying and k not in extra and k != dim and k in datasets[0].attrs}
    for k in varying:
        if k in extra:
            continue
        vals = [d.attrs.get(k, np.nan) for d in datasets]
        extra[k] = vals
    for d in datasets:
        d.attrs = {}
    for pdim in pad:
        longest = max(max(d.sizes.get(pdim, 0) for d in datasets), 1)
        datasets = [pad_dim(d, pdim, longest) if pdim in d.dims else d for d in datasets]
    index = np.arange(n) if values is None else np.asarray(values)
    out = xr.concat(datasets, dim=dim, data_vars="all", coords="different", compat="equals",
                    join="outer", combine_attrs="drop")
    out = out.assign_coords({dim: index})
    for k, vals in extra.items():
        arr = np.asarray(vals)
        if arr.dtype.kind == "U":
            arr = arr.astype(object)
        if k == dim:
            continue
        out = out.assign_coords({k: (dim, arr)})
    out.attrs = common
    return out
