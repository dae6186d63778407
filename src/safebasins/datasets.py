"""Datasets: xarray construction helpers, CF attributes, provenance, atomic netCDF writes.

Every file the pipeline writes goes through :func:`finalize` and :func:`write_netcdf`:

* :func:`annotate` fills ``units`` / ``long_name`` of coordinates and variables from one table;
* :func:`finalize` adds the CF globals (``Conventions``, ``title``, ``source``, ``history``,
  ``references``, ``institution``, ``date_created``) and provenance (``safebasins_version``,
  ``git_commit``, ``config_hash``, ``parameters`` as JSON, ``seeds`` when the parameters have
  them; numeric datasets carry ``integrator`` and ``steps_per_cycle`` from safebasins.numerics);
* :func:`write_netcdf` writes netCDF4 with zlib compression to a temporary file in the target
  directory and renames it over the target (atomic: a killed job never leaves a half file).

Compare datasets by content with :func:`assert_same_content` (``xarray.testing``), never by
file bytes: ``date_created`` and ``git_commit`` legitimately differ between runs.
"""
from __future__ import annotations

import datetime as _dt
import json
import os
import subprocess
import tempfile
from functools import lru_cache
from pathlib import Path

import numpy as np
import xarray as xr

from . import __version__

REFERENCE = ("G. Karmi, P. Kravetc, O. Gendelman, Analytic exploration of safe basins in a "
             "benchmark problem of forced escape")
INSTITUTION = "safebasins reproduction"
# attributes that legitimately differ between two runs of the same computation
VOLATILE_ATTRS = ("date_created", "git_commit")

# name -> (units, long_name). Dimensionless units are "1"; time in forcing cycles.
VARIABLES = {
    "q0": ("1", "initial displacement q(0)"),
    "p0": ("1", "initial momentum p(0)"),
    "q": ("1", "displacement at the stroboscopic instants"),
    "p": ("1", "momentum at the stroboscopic instants"),
    "sample": ("1", "initial-condition index"),
    "iteration": ("1", "stroboscopic-map iteration (forcing cycles)"),
    "Omega": ("1", "forcing frequency Omega"),
    "F": ("1", "forcing amplitude F"),
    "Psi": ("rad", "forcing phase Psi"),
    "xi_max": ("1", "energy truncation level xi_max (escape threshold on H0)"),
    "q_max": ("1", "displacement escape threshold q_max"),
    "t_eval": ("forcing cycles", "evaluation time"),
    "gamma": ("rad", "slow phase gamma = theta - Psi - Omega tau"),
    "xi": ("1", "averaged energy xi"),
    "gamma_rm": ("rad", "slow phase gamma on the resonance-manifold grid"),
    "xi_rm": ("1", "averaged energy xi on the resonance-manifold grid"),
    "repeat": ("1", "random repetition index"),
    "seed": ("1", "random seed of the repetition"),
    "xi_ini": ("1", "initial averaged energy xi_ini"),
    "gamma_ini": ("rad", "initial slow phase gamma_ini"),
    "xi0": ("1", "initial averaged energy xi_ini"),
    "gamma0": ("rad", "initial slow phase gamma_ini"),
    "curve": ("1", "curve index"),
    "label": ("", "curve label"),
    "vertex": ("1", "boundary vertex index"),
    "curve_index": ("1", "index of the boundary curve a vertex belongs to (-1 = padding)"),
    "kind": ("", "boundary kind (island | peninsula | saddle)"),
    "C_level": ("1", "level of the first integral C on the boundary curve"),
    "C": ("1", "first integral C(gamma, xi) of the slow flow, eq (18)"),
    "escapes": ("1", "analytic (slow-flow) escape: True = the IC escapes"),
    "escapes_rm": ("1", "analytic escape of the resonance-manifold point: True = escapes"),
    "escape_cycle_energy": ("forcing cycles", "first cycle with H0 > xi_max (+inf = none within the horizon)"),
    "escape_cycle_displacement": ("forcing cycles", "first cycle with |q| > q_max (+inf = none within the horizon)"),
    "escape_cycle": ("forcing cycles", "escape time (+inf = none within the horizon)"),
    "escaped": ("1", "trajectory escaped within the horizon"),
    "F_cr": ("1", "critical forcing amplitude"),
    "F_MM_0": ("1", "critical forcing, maximum mechanism through gamma* = 0"),
    "F_MM_pi": ("1", "critical forcing, maximum mechanism through gamma* = pi"),
    "F_SM": ("1", "critical forcing, saddle mechanism"),
    "F_SMM": ("1", "critical forcing, saddle maximum mechanism"),
    "F_escape_low": ("1", "lowest escaping F on the scan"),
    "F_escape_all": ("1", "F above which every scanned F escapes"),
    "non_monotone": ("1", "escape is not monotone in F on the scan"),
    "mechanism": ("1", "escape mechanism of the overall F_cr"),
    "xi_saddle": ("1", "averaged energy of the saddle point"),
    "gamma_saddle": ("rad", "slow phase of the saddle point"),
    "saddle_gamma": ("rad", "slow phase of the saddle point"),
    "saddle_xi": ("1", "averaged energy of the saddle point"),
    "iou": ("1", "intersection over union of the analytic and numeric safe basins"),
    "pixel_agreement": ("1", "fraction of grid points where the analytic and numeric safe/escape labels agree"),
    "safe_analytic": ("1", "number of grid points in the analytic safe basin"),
    "safe_numeric": ("1", "number of grid points in the numeric safe basin"),
    "A_E": ("1", "number of ICs in the energy-criterion safe basin (ESB)"),
    "A_q": ("1", "number of ICs in the displacement-criterion safe basin (DSB)"),
    "rel_diff": ("1", "(A_q - A_E) / A_E"),
}


def annotate(ds: xr.Dataset) -> xr.Dataset:
    """Fill missing `units` / `long_name` of coordinates and data variables (in place, returned)."""
    for name in list(ds.variables):
        entry = VARIABLES.get(str(name))
        if entry is None:
            continue
        units, long_name = entry
        attrs = ds[name].attrs
        if units and "units" not in attrs and ds[name].dtype.kind in "fiub":
            attrs["units"] = units
        attrs.setdefault("long_name", long_name)
    return ds


@lru_cache(maxsize=1)
def git_commit() -> str:
    """Commit of the source tree the library was imported from ('unknown' outside git)."""
    here = Path(__file__).resolve().parent
    try:
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
        from .config import params_hash

        config_hash = params_hash(params)
    attrs["config_hash"] = config_hash or "none"
    attrs["parameters"] = json.dumps(params, sort_keys=True)
    if "experiment" in params:
        attrs["experiment"] = params["experiment"]
    if "fourier" in params:
        attrs.setdefault("fourier", params["fourier"])
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
    """Write `ds` to netCDF4 (zlib) atomically: temporary file in the same directory + rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        ds.to_netcdf(tmp, format="NETCDF4", engine="netcdf4", encoding=_encoding(ds))
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    return path


def load(path) -> xr.Dataset:
    """Read a dataset fully into memory and close the file."""
    return xr.load_dataset(path, engine="netcdf4")


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
    datasets = [d.copy() for d in datasets]
    n = len(datasets)
    if n == 0:
        raise ValueError("datasets must not be empty")
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


# --------------------------------------------------------------------------------------
# agreement between analytic and numeric safe basins
# --------------------------------------------------------------------------------------
def gather_tiles(paths) -> xr.Dataset:
    """Concatenate the tile files of one chart task (rule `chart_tile`) in order.

    Grid tiles are blocks of q0 rows; random-IC tiles are blocks of ``sample``. The tile
    bookkeeping attributes (``task``, ``tile``, ``tiles``) are dropped.
    """
    parts = [load(f) for f in paths]
    dim = "sample" if "sample" in parts[0].dims else "q0"
    ds = xr.concat(parts, dim=dim, data_vars="minimal", coords="minimal", compat="override",
                   join="exact" if dim == "sample" else "outer", combine_attrs="override")
    for k in ("task", "tile", "tiles"):
        ds.attrs.pop(k, None)
    return ds


def task_charts(paths, ntasks: int) -> list[xr.Dataset]:
    """The gathered chart of every task from the flat tile list (tasks x tiles, task-major)."""
    paths = list(paths)
    per_task = len(paths) // ntasks
    return [gather_tiles(paths[i * per_task:(i + 1) * per_task]) for i in range(ntasks)]


def mask_agreement(analytic_safe: xr.DataArray, numeric_safe: xr.DataArray, dims=("q0", "p0")):
    """(iou, pixel_agreement) of two boolean safe masks, reduced over `dims`.

    iou = |A and N| / |A or N| (1 when both are empty); pixel_agreement = mean(A == N).
    """
    a, b = xr.align(analytic_safe.astype(bool), numeric_safe.astype(bool), join="exact")
    inter = (a & b).sum(dims)
    union = (a | b).sum(dims)
    iou = xr.where(union > 0, inter / union.where(union > 0, 1), 1.0).astype(float)
    pixel = (a == b).mean(dims).astype(float)
    return iou, pixel


def assert_same_content(a: xr.Dataset, b: xr.Dataset, ignore_attrs=VOLATILE_ATTRS):
    """xarray.testing.assert_identical, ignoring the run-dependent global attributes."""
    a, b = a.copy(), b.copy()
    for d in (a, b):
        for k in ignore_attrs:
            d.attrs.pop(k, None)
    xr.testing.assert_identical(a, b)
