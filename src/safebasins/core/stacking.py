"""Datasets stacked along a new dimension: parts of different lengths padded, attributes that
differ between the parts turned into coordinates, the parts' provenance dropped."""
from __future__ import annotations

import numpy as np
import xarray as xr
from typing import Any

from safebasins.core.provenance import PROVENANCE_ATTRS

__all__ = ["stack", "pad_dim"]


def _fill_value(dtype: Any) -> Any:
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
    new_vars: dict[Any, xr.Variable] = {}
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


def _same(a: Any, b: Any) -> Any:
    try:
        a, b = np.asarray(a), np.asarray(b)
        if a.dtype.kind in "fc" and b.dtype.kind in "fc":
            return np.array_equal(a, b, equal_nan=True)
        return np.array_equal(a, b)
    except Exception:  # noqa: BLE001  (values numpy cannot compare: compared as Python objects)
        return a == b


def stack(datasets: Any, dim: str, values: Any = None, *, coords: dict | None = None,
          pad: tuple[str, ...] = ("vertex", "curve")) -> xr.Dataset:
    """Concatenate datasets along a new dimension `dim`.

    `values` become the coordinate of `dim` (default: 0..n-1); `coords` maps extra coordinate
    names to per-dataset values (e.g. ``{"label": [...]}``). Attributes that differ between the
    datasets become coordinates along `dim`; equal ones stay attributes. Dimensions in `pad`
    are padded (NaN / -1 / "" / False) to their largest length first.
    """
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
