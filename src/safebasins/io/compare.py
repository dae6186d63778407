"""Value-by-value comparison of datasets and of whole ``results/data`` trees.

Used to prove that a refactor keeps results (``scripts/compare_results.py``) and by the tests
(-j1 vs -j2, tiles, cluster, GPU). Provenance attributes (who/when/which commit/which
parameter text made the file) are reported but never fail a comparison; everything else must
be identical: names, dims, dtypes, values (NaN == NaN) and the attributes of every variable.
Bit for bit is right within one machine; between machines the last bits differ, and
:mod:`safebasins.io.reproduction` compares with stated tolerances instead.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from safebasins.core.provenance import PROVENANCE_ATTRS


def same_array(a: np.ndarray, b: np.ndarray) -> bool:
    """Equal shape, dtype and values (NaN == NaN; text by value, whatever its storage)."""
    if a.dtype.kind in "OUS" and b.dtype.kind in "OUS":  # text: object vs fixed-width is storage only
        return a.shape == b.shape and bool(np.array_equal(a.astype(str), b.astype(str)))
    if a.shape != b.shape or a.dtype != b.dtype:
        return False
    if a.dtype.kind in "fc":
        return bool(np.array_equal(a, b, equal_nan=True))
    return bool(np.array_equal(a, b))


def same_attr(a: Any, b: Any) -> bool:
    """Equal attribute values: numbers and arrays by value (NaN == NaN; a netCDF round trip turns
    Python scalars into numpy ones), everything else by equality."""
    numeric = (int, float, np.number, np.ndarray, list, tuple)
    if isinstance(a, numeric) and isinstance(b, numeric) and not isinstance(a, bool) and not isinstance(b, bool):
        try:
            x, y = np.asarray(a), np.asarray(b)
        except (TypeError, ValueError):
            return a == b
        if x.dtype.kind in "fciub" and y.dtype.kind in "fciub":
            nan_equal = x.dtype.kind in "fc" and y.dtype.kind in "fc"
            return x.shape == y.shape and bool(np.array_equal(x, y, equal_nan=nan_equal))
        return x.shape == y.shape and bool(np.array_equal(x, y))
    return type(a) is type(b) and a == b


def _attr_diffs(where: str, a: dict, b: dict, ignore: Any = ()) -> list[str]:
    out = []
    for k in sorted(set(a) | set(b)):
        if k in ignore:
            continue
        if k not in a or k not in b:
            out.append(f"{where}: attribute {k!r} only in {'new' if k in b else 'old'}")
        elif not same_attr(a[k], b[k]):
            out.append(f"{where}: attribute {k!r} differs: {a[k]!r} vs {b[k]!r}")
    return out


def dataset_differences(old: xr.Dataset, new: xr.Dataset, *, ignore_attrs: Any = PROVENANCE_ATTRS) -> list[str]:
    """Every difference between two datasets except the ignored global attributes."""
    out = []
    names_old, names_new = set(map(str, old.variables)), set(map(str, new.variables))
    for n in sorted(names_old - names_new):
        out.append(f"variable {n!r} only in old")
    for n in sorted(names_new - names_old):
        out.append(f"variable {n!r} only in new")
    for n in sorted(names_old & names_new):
        a, b = old[n].variable, new[n].variable
        kind_a = "coord" if n in old.coords else "data"
        kind_b = "coord" if n in new.coords else "data"
        if kind_a != kind_b:
            out.append(f"{n}: {kind_a} variable in old, {kind_b} variable in new")
        if a.dims != b.dims:
            out.append(f"{n}: dims {a.dims} vs {b.dims}")
            continue
        va, vb = np.asarray(a.values), np.asarray(b.values)
        if not same_array(va, vb):
            if va.shape != vb.shape or (va.dtype != vb.dtype
                                        and not (va.dtype.kind in "OUS" and vb.dtype.kind in "OUS")):
                out.append(f"{n}: shape/dtype {va.shape} {va.dtype} vs {vb.shape} {vb.dtype}")
            else:
                neq = ~((va == vb) | ((va != va) & (vb != vb))) if va.dtype.kind in "fc" else (va != vb)
                out.append(f"{n}: {int(np.count_nonzero(neq))} of {va.size} values differ")
        out.extend(_attr_diffs(n, dict(a.attrs), dict(b.attrs)))
    out.extend(_attr_diffs("<global>", dict(old.attrs), dict(new.attrs), ignore=ignore_attrs))
    return out


def assert_same_content(old: xr.Dataset, new: xr.Dataset, *, ignore_attrs: Any = PROVENANCE_ATTRS) -> None:
    """AssertionError listing every difference (provenance attributes aside)."""
    diffs = dataset_differences(old, new, ignore_attrs=ignore_attrs)
    if diffs:
        raise AssertionError("datasets differ:\n  " + "\n  ".join(diffs))


@dataclass
class TreeReport:
    compared: list[str] = field(default_factory=list)
    only_old: list[str] = field(default_factory=list)
    only_new: list[str] = field(default_factory=list)
    differences: dict[str, list[str]] = field(default_factory=dict)
    provenance: dict[str, list[str]] = field(default_factory=dict)

    @property
    def identical(self) -> bool:
        return not (self.only_old or self.only_new or self.differences)

    def lines(self, verbose: bool = True) -> Any:
        for f in self.only_old:
            yield f"MISSING in new: {f}"
        for f in self.only_new:
            yield f"EXTRA in new: {f}"
        for f in self.compared:
            if f in self.differences:
                yield f"DIFFERENT {f}"
                for d in self.differences[f]:
                    yield f"    {d}"
            elif verbose:
                note = f" (provenance differs: {', '.join(self.provenance[f])})" if f in self.provenance else ""
                yield f"identical {f}{note}"
        yield (f"{len(self.compared)} datasets compared: {len(self.differences)} different, "
               f"{len(self.only_old)} missing, {len(self.only_new)} extra -> "
               + ("IDENTICAL" if self.identical else "DIFFERENT"))


def dataset_files(root: Any, parts: bool = False) -> set[str]:
    """The ``*.nc`` files below ``root`` (relative paths; tile parts under ``parts/`` only with ``parts``)."""
    root = Path(root)
    return {p.relative_to(root).as_posix() for p in root.rglob("*.nc")
            if parts or "parts" not in p.relative_to(root).parts}


def compare_trees(old_root: Any, new_root: Any, *, parts: bool = False) -> TreeReport:
    """Compare every dataset of two ``results/data`` trees (see the module docstring)."""
    old_root, new_root = Path(old_root), Path(new_root)
    a, b = dataset_files(old_root, parts), dataset_files(new_root, parts)
    rep = TreeReport(only_old=sorted(a - b), only_new=sorted(b - a))
    for f in sorted(a & b):
        rep.compared.append(f)
        old, new = xr.load_dataset(old_root / f), xr.load_dataset(new_root / f)
        diffs = dataset_differences(old, new)
        if diffs:
            rep.differences[f] = diffs
        prov = [k for k in PROVENANCE_ATTRS
                if not same_attr(old.attrs.get(k), new.attrs.get(k))]
        if prov:
            rep.provenance[f] = prov
    return rep
