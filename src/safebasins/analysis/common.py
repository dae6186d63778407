"""Small helpers shared by the analysis modules (erosion, phase-invariant basins, first harmonic)."""
from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.core import checks
from safebasins.analysis.integrity import grid_spacing
from safebasins.wells.quartic import FOURIER_VARIANTS
from safebasins.wells import QuarticWell, resolve_well
from safebasins.wells.base import Well, WellLike

Array = npt.NDArray[np.float64]


def fourier_list(fourier: str | Sequence[str]) -> tuple[list[str], bool]:
    """Normalise ``fourier`` to (list_of_variants, is_scalar)."""
    scalar = isinstance(fourier, str)
    items = [fourier] if isinstance(fourier, str) else list(fourier)
    if not items:
        raise ValueError("fourier must name at least one variant")
    for f in items:
        if f not in FOURIER_VARIANTS:
            raise ValueError(f"fourier must be one of {FOURIER_VARIANTS} (or a list of them), got {f!r}")
    return items, scalar


def variant_well(well: WellLike, fourier: str | None) -> Well:
    """The well of one first-harmonic variant.

    The rule for ``fourier`` (every analysis function that takes ``well=`` and ``fourier=``):

    * the quartic (``well`` None or a QuarticWell): ``fourier`` picks G of eq (20) as printed
      ("paper") or exact ("exact"); ``None`` keeps the well's own (the paper's for ``None``);
    * any other well has only its exact first harmonic (eq 12 from its own orbit): its one
      variant is "exact", so ``fourier`` must be None or "exact" (stored as "exact"); "paper"
      (the quartic's truncated eq 20) raises ValueError.
    """
    if well is None or isinstance(well, QuarticWell):
        return resolve_well(well, fourier)
    w = resolve_well(well)      # ValueError for something that is not a Well
    if fourier not in (None, "exact"):
        raise ValueError(f"fourier {fourier!r}: the {w.name} well has only its exact first harmonic "
                         "(the paper's truncated G of eq 20 is the quartic's): leave fourier out or use 'exact'")
    return w


def well_variants(well: WellLike, fourier: str | Sequence[str] | None
                  ) -> tuple[list[str], list[Well], bool]:
    """``(names, wells, scalar)`` of a ``fourier`` argument (None, one variant or a list) for
    ``well`` (:func:`variant_well` gives the rule): ``None`` is the well's own single variant
    ("paper" for the default quartic, "exact" for any other well)."""
    if fourier is None:
        w = variant_well(well, None)
        return [w.fourier], [w], True
    names, scalar = fourier_list(fourier)
    return names, [variant_well(well, f) for f in names], scalar


def as_1d(name: str, values: npt.ArrayLike, check: checks.Check = checks.as_array) -> Array:
    """``check(name, values)`` as a 1-D float array."""
    return checks.check_1d(name, values, check)


def mesh(q0: npt.ArrayLike, p0: npt.ArrayLike) -> tuple[Array, Array, Array, Array]:
    """Validated uniform grid axes and their ``ij`` mesh: ``(q, p, Q, P)``."""
    q, p, _, _ = grid_spacing(q0, p0)
    Q, P = np.meshgrid(q, p, indexing="ij")
    return q, p, Q, P


def chart_param(ds: xr.Dataset, name: str) -> Any:
    """A parameter of an escape chart: coordinate if stacked over it, else the attribute."""
    if name in ds.coords:
        return ds[name]
    if name in ds.attrs:
        return ds.attrs[name]
    raise ValueError(f"chart has neither a coordinate nor an attribute {name!r}")


def stack_charts(charts: xr.Dataset | Iterable[xr.Dataset], dim: str) -> xr.Dataset:
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
