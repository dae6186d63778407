"""Reading datasets for figures: exact names only (docs/contracts.md).

A figure reads what the pipeline (or the API) wrote and never recomputes physics.  Every read
names the variable or parameter exactly; a missing one is a :class:`MissingData` naming the
dataset (its file) and the name, never a silent fallback to another spelling.  ``MissingData``
is both a ``KeyError`` (a lookup that failed) and a ``ValueError`` (a dataset unfit for the
figure: what the public plotting functions document).
"""
from __future__ import annotations

import os
from collections.abc import Iterable, Iterator
from typing import TYPE_CHECKING, Any, TypeAlias, TypeGuard, overload

import numpy as np
import xarray as xr
import yaml

from safebasins.io.netcdf import read
from safebasins.wells import NAMED_WELLS, from_attrs

if TYPE_CHECKING:
    from collections.abc import Mapping

    from matplotlib.figure import Figure

    from safebasins.wells.base import Well

#: what the figure functions read: a dataset, or the path of its netCDF file
DataSource: TypeAlias = "xr.Dataset | str | os.PathLike[str]"
#: what a figure is drawn from, for its provenance: a Dataset or DataArray, the path of a netCDF
#: file or of a parameter file (.yaml, skipped: the datasets hold the parameters), or None
DataItem: TypeAlias = "xr.Dataset | xr.DataArray | str | os.PathLike[str] | None"
#: one :data:`DataItem` or a list (tuple) of them (a figure reading several files for one input)
DataItems: TypeAlias = "DataItem | list[DataItem] | tuple[DataItem, ...]"


@overload
def open_dataset(src: None) -> None: ...
@overload
def open_dataset(src: xr.DataArray) -> xr.DataArray: ...
@overload
def open_dataset(src: DataSource) -> xr.Dataset: ...
@overload
def open_dataset(src: DataSource | None) -> xr.Dataset | None: ...
def open_dataset(src: DataSource | xr.DataArray | None) -> xr.Dataset | xr.DataArray | None:
    """Path -> fully loaded Dataset (file closed again; its path kept in ``encoding["source"]``);
    a Dataset passes through; None stays None.  A corrupted or truncated file is a
    :class:`~safebasins.io.netcdf.NetCDFFileError` naming it."""
    if src is None or isinstance(src, (xr.Dataset, xr.DataArray)):
        return src
    out = read(src)
    out.encoding["source"] = os.fspath(src)
    return out


class MissingData(KeyError, ValueError):
    """A dataset lacks a variable, coordinate or attribute a figure needs (the message names it)."""

    def __str__(self) -> str:  # KeyError would print the message quoted
        return str(self.args[0]) if self.args else ""


def source(ds: xr.Dataset | xr.DataArray) -> str:
    return ds.encoding.get("source", "<dataset>")


def var(ds: xr.Dataset, name: str) -> xr.DataArray:
    """Data variable or coordinate ``name``; MissingData naming the dataset if absent."""
    if name not in ds.variables:
        raise MissingData(f"{source(ds)}: no variable {name!r} (it has {sorted(map(str, ds.variables))})")
    return ds[name]


def param(ds: xr.Dataset, name: str) -> Any:
    """A parameter of a dataset: its global attribute, or its coordinate when the dataset is
    stacked over it with a single value (docs/contracts.md).  MissingData naming both if absent."""
    if name in ds.attrs:
        v = ds.attrs[name]
        return v.item() if isinstance(v, np.ndarray) and v.size == 1 else v
    if name in ds.coords and ds[name].size == 1:
        return ds[name].item()
    raise MissingData(f"{source(ds)}: no attribute or single-valued coordinate {name!r}")


def well(ds: xr.Dataset) -> Well:
    """The potential well of a dataset (its ``well`` attributes, safebasins.wells.spec_attrs)."""
    if "well" not in ds.attrs:
        raise MissingData(f"{source(ds)}: no attribute 'well' (datasets name their potential well)")
    return from_attrs(ds.attrs)


#: dataset attributes written into saved figures (io.datasets.finalize: provenance; wells.spec_attrs)
PROVENANCE = ("title", "safebasins_version", "git_commit", "config_hash", "well", "well_coefficients",
              "well_expression", "parameters")
_PROVENANCE_ATTR = "_safebasins_datasets"


def attach(fig: Figure, *datasets: DataItem) -> Figure:
    """Remember the datasets a Figure was drawn from (their provenance goes into the saved file,
    :func:`safebasins.plotting.style.save_figure`)."""
    have = getattr(fig, _PROVENANCE_ATTR, None)
    if have is None:
        have = []
        setattr(fig, _PROVENANCE_ATTR, have)
    have += [d for d in datasets if d is not None and not any(d is h for h in have)]
    return fig


def _is_params_file(d: DataItem) -> TypeGuard[str | os.PathLike[str]]:
    """Whether ``d`` names a parameter file (results/params/<experiment>.yaml), not a dataset."""
    return isinstance(d, (str, os.PathLike)) and os.fspath(d).endswith((".yaml", ".yml"))


def _flat(datasets: Iterable[DataItems]) -> Iterator[xr.Dataset | xr.DataArray | str | os.PathLike[str]]:
    for d in datasets:
        if isinstance(d, (list, tuple)):
            yield from _flat(d)
        elif d is not None and not _is_params_file(d):  # parameter files: the datasets hold them
            yield d


def provenance(*datasets: DataItems, fig: Figure | None = None) -> dict[str, str]:
    """Text metadata of a saved figure: ``Source`` (the dataset files) and every attribute of
    :data:`PROVENANCE` the datasets carry (paths, Datasets or lists of them; those attached to
    ``fig`` with :func:`attach` too).  A value the datasets disagree on lists each one, one a line."""
    items = list(_flat([*datasets, *(getattr(fig, _PROVENANCE_ATTR, None) or [])]))
    out: dict[str, list[str]] = {}
    sources: list[str] = []
    for d in items:
        attrs = _attrs_of(d)
        src = (source(d) if isinstance(d, xr.Dataset) else "<data array>" if isinstance(d, xr.DataArray)
               else os.fspath(d))
        if src not in sources:
            sources.append(src)
        for k in PROVENANCE:
            if k in attrs:
                v = attrs[k]
                v = " ".join(map(str, np.ravel(v))) if isinstance(v, np.ndarray) else str(v)
                out.setdefault(k, [])
                if v not in out[k]:
                    out[k].append(v)
    meta = {"Source": "\n".join(sources)} if sources else {}
    meta.update({("Title" if k == "title" else k): "\n".join(v) for k, v in out.items()})
    return meta


def _attrs_of(d: xr.Dataset | xr.DataArray | str | os.PathLike[str]) -> dict[Any, Any]:
    if isinstance(d, (xr.Dataset, xr.DataArray)):
        return d.attrs
    with xr.open_dataset(d) as ds:
        return dict(ds.attrs)


def well_text(attrs: Mapping[Any, Any]) -> str | None:
    """How a figure names the potential well of a dataset (its ``well`` attributes): a named well by
    its description (``well: pendulum, the pendulum / ship roll V = 1 - cos q, ...``), an expression
    well by its formula, a polynomial by V(q); None for the paper's quartic (every figure's default)
    and a dataset that names no well."""
    name = attrs.get("well")
    if not isinstance(name, str) or name == "quartic":
        return None
    if name == "expression" and "well_expression" in attrs:      # the formula the dataset defines it by
        return f"well: V(q) = {attrs['well_expression']}"

    if name in NAMED_WELLS:                                      # the named well's own description
        return f"well: {name}, {NAMED_WELLS[name][1]}"
    try:
        return f"well: {name}, V(q) = {from_attrs(attrs).potential_text()}"
    except ValueError:                                           # a well the attributes cannot rebuild
        return f"well: {name}"


def well_texts(*datasets: DataItems, fig: Figure | None = None) -> list[str]:
    """:func:`well_text` of every distinct well among the datasets (and those attached to ``fig``)."""
    out: list[str] = []
    for d in _flat([*datasets, *(getattr(fig, _PROVENANCE_ATTR, None) or [])]):
        t = well_text(_attrs_of(d))
        if t and t not in out:
            out.append(t)
    return out


def load_params(src: str | os.PathLike[str]) -> dict[str, Any]:
    """Resolved parameter file (results/params/<experiment>.yaml) -> dict."""
    with open(src) as fh:
        return yaml.safe_load(fh)


#: attributes and headline variables printed by :func:`describe` when a dataset has them
SUMMARY_ATTRS = ("title", "F", "Omega", "Psi", "xi_max", "q_max", "xi_ini", "gamma_ini", "cycles",
                 "steps_per_cycle", "integrator", "tol", "criterion", "fourier", "seed", "level",
                 "saddle_gamma", "saddle_xi", "source_experiment", "git_commit", "config_hash",
                 "safebasins_version")
HEADLINE = ("iou", "pixel_agreement", "F_GIM", "F_LIM", "F_IF", "xi_true", "GIM_true", "LIM_true", "IF_true",
            "GIM_continuous", "GIM_closed", "LIM_closed", "rms_rel_error", "mean_abs_rel_error", "mean_iou")


def describe(**datasets: DataSource | list[DataSource] | tuple[DataSource, ...] | None) -> str:
    """Text summary of the datasets a figure reads (paths, lists of paths, Datasets or parameter
    files): dims, variables, parameters, provenance and headline numbers."""
    lines: list[str] = []
    for name, src in datasets.items():
        for s in (src if isinstance(src, (list, tuple)) else [src]):
            if s is None:
                continue
            if _is_params_file(s):
                lines.append(f"[{name}] {s}")
                for k, v in load_params(s).items():
                    if k != "tasks":
                        txt = repr(v)
                        lines.append(f"  {k}: {txt if len(txt) < 120 else txt[:117] + '...'}")
                continue
            ds = open_dataset(s)
            lines.append(f"[{name}] {source(ds)}")
            lines.append("  dims: " + ", ".join(f"{k}={v}" for k, v in ds.sizes.items()))
            lines.append(f"  variables: {', '.join(map(str, ds.data_vars))}")
            lines += [f"  {k}: {ds.attrs[k]}" for k in SUMMARY_ATTRS if k in ds.attrs]
            for v in HEADLINE:
                if v in ds:
                    da = ds[v]
                    dims = ", ".join(f"{d}={np.array2string(np.asarray(da[d].values), precision=4)}" for d in da.dims)
                    vals = np.array2string(np.asarray(da.values), precision=4, suppress_small=True)
                    lines.append(f"  {v}" + (f" over ({dims})" if dims else "") + ":\n    "
                                 + vals.replace("\n", "\n    "))
    text = "\n".join(lines)
    print(text)
    return text
