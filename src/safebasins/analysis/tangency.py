"""Basin erosion across the homoclinic tangency of a damped well (docs/melnikov.md).

For ``q'' + beta q' + V'(q) = F sin(Omega t + Psi)`` the stable and unstable manifolds of the
forced hilltop saddle first touch at the Melnikov threshold ``F_M(Omega, beta)``
(:func:`safebasins.analysis.melnikov.melnikov_threshold`, first order in F and beta).  Below it
the safe basin's boundary is smooth (uncertainty exponent alpha = 1); past it the boundary
becomes fractal (alpha < 1) and the basin erodes (Thompson's escape equation, beta = 0.1,
Omega = 0.85).  This module puts the three measurements side by side:

* :func:`tangency_profile`: GIM / LIM / IF versus F of long-time basins from one escape chart
  per F, the Melnikov threshold ``F_melnikov`` and the safe masks at chosen F (before/after);
* :func:`fractality_profile`: the uncertainty exponent alpha(F) of the basin boundary
  (:func:`safebasins.analysis.fractality.uncertainty_exponent`) over F, with ``F_melnikov``.
"""
from __future__ import annotations

from collections.abc import Iterable

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.core import checks
from safebasins.analysis.common import as_1d, stack_charts
from safebasins.analysis.erosion import level_crossing, profile_from_charts
from safebasins.analysis.fractality import uncertainty_exponent
from safebasins.analysis.melnikov import melnikov_threshold
from safebasins.analysis.safe import chart_well, safe_stack
from safebasins.core.cf import annotate
from safebasins.wells.base import WellLike
from safebasins.wells.provenance import api_provenance

__all__ = ["tangency_profile", "fractality_profile", "melnikov_variable"]


def melnikov_variable(Omega: float, damping: float, well: WellLike) -> xr.DataArray:
    """``F_melnikov`` as a scalar DataArray (the first-order tangency threshold of the lowest
    hilltop saddle, :func:`~safebasins.analysis.melnikov.melnikov_threshold`)."""
    F_M = float(melnikov_threshold(float(Omega), float(damping), well=well))
    return xr.DataArray(F_M, attrs={"units": "1", "long_name": "Melnikov threshold of the hilltop saddle's "
                                                               "homoclinic/heteroclinic tangency (first order)"})


@api_provenance
def tangency_profile(charts: xr.Dataset | Iterable[xr.Dataset], t_eval: npt.ArrayLike | None = None, *,
                     keep_F: npt.ArrayLike = (), level: float = 0.5) -> xr.Dataset:
    """Integrity profile of damped long-time basins with the Melnikov threshold.

    Parameters
    ----------
    charts : escape charts on one (q0, p0) grid, one per F (each with attribute ``F``; from
        :func:`safebasins.numerics.escape_chart` with ``damping`` > 0), energy criterion.
    t_eval : evaluation times in cycles (default: the horizon); the basins converge as t_eval
        grows (damped transients die out), so the last one is the long-time basin.
    keep_F : F values (among the charts') whose safe masks at the last ``t_eval`` are kept
        (``safe`` over ``F_basin``, ``xi_max``, q0, p0): the basin before and after the tangency.
    level : integrity level whose first crossing in F is reported (``F_GIM``, ``F_LIM``, ``F_IF``).

    Returns
    -------
    xr.Dataset: GIM / LIM / IF over (F, xi_max, t_eval)
    (:func:`~safebasins.analysis.erosion.profile_from_charts`), their level crossings,
    ``F_melnikov`` (scalar) and ``safe``.
    """
    chart = stack_charts(charts, "F")
    beta = chart.attrs.get("damping")
    if beta is None:
        raise ValueError("charts: the charts are undamped (no damping attribute): the Melnikov threshold of an "
                         "undamped well is 0 (the manifolds always intersect); integrate them with damping > 0")
    keep = as_1d("keep_F", keep_F, checks.check_nonnegative) if np.size(keep_F) else np.zeros(0)
    F = chart["F"].values
    missing = [float(f) for f in keep if not np.isin(f, F)]
    if missing:
        raise ValueError(f"keep_F: {missing} are not among the charts' F values {F.tolist()}")
    prof = profile_from_charts(chart, t_eval)
    cross = level_crossing(prof, level)
    for m in ("GIM", "LIM", "IF"):
        prof[f"F_{m}"] = cross[m].assign_attrs(units="1", long_name=f"first F at which {m} falls below {level:g}")
    well = chart_well(chart)
    prof["F_melnikov"] = melnikov_variable(chart.attrs["Omega"], beta, well)
    if keep.size:
        safe, _ = safe_stack(chart.sel(F=keep), t_eval)
        prof["safe"] = (safe.isel(t_eval=-1, drop=True).rename(F="F_basin").astype(np.int8)
                        .assign_attrs(long_name="safe at the last t_eval (1) or escaped (0)", units="1"))
    prof.attrs.update(damping=float(beta), level=float(level),
                      method=prof.attrs["method"] + "; F_melnikov: safebasins.analysis.melnikov.melnikov_threshold")
    return annotate(prof)


@api_provenance
def fractality_profile(F_values: npt.ArrayLike, Omega: float, Psi: float, xi_max: float, box: npt.ArrayLike, *,
                       damping: float, eps: npt.ArrayLike = (1e-2, 3e-3, 1e-3, 3e-4, 1e-4), n: int = 4000,
                       cycles: int = 500, t_eval: float | None = None, seed: int = 0, well: WellLike = None,
                       steps_per_cycle: int = 32, threads: int | None = None, backend: str = "cpu") -> xr.Dataset:
    """Uncertainty exponent alpha(F) of the safe basin's boundary, with the Melnikov threshold.

    One :func:`~safebasins.analysis.fractality.uncertainty_exponent` per F (the same seeded base
    points ``seed`` for every F, so the F dependence is not sampling noise).  alpha = 1: a smooth
    boundary; alpha < 1: fractal (boundary dimension 2 - alpha), expected past ``F_melnikov``.

    Returns
    -------
    xr.Dataset over F (and eps): ``alpha``, ``alpha_err``, ``boundary_dimension``,
    ``safe_fraction``, ``fraction`` / ``fraction_err`` / ``n_uncertain`` (F, eps) and the scalar
    ``F_melnikov``.
    """
    F = as_1d("F_values", F_values, checks.check_nonnegative)
    beta = checks.check_scalar("damping", damping, checks.check_positive)
    parts = [uncertainty_exponent(float(f), Omega, Psi, xi_max, box, eps=eps, n=n, cycles=cycles, t_eval=t_eval,
                                  seed=seed, well=well, damping=beta, steps_per_cycle=steps_per_cycle,
                                  threads=threads, backend=backend) for f in F]
    ds = xr.concat([p[["n_uncertain", "fraction", "fraction_err", "used"]] for p in parts],
                   dim=xr.DataArray(F, dims="F", attrs={"units": "1", "long_name": "forcing amplitude F"}))
    for k, text in (("alpha", "uncertainty exponent alpha (f(eps) ~ eps^alpha)"),
                    ("alpha_err", "standard error of alpha (weighted fit)"),
                    ("boundary_dimension", "box-counting dimension of the basin boundary, 2 - alpha"),
                    ("safe_fraction", "safe fraction of the base points")):
        ds[k] = xr.DataArray([p.attrs[k] for p in parts], dims="F", attrs={"units": "1", "long_name": text})
    ds["F_melnikov"] = melnikov_variable(Omega, beta, well)
    keep = ("Omega", "Psi", "xi_max", "n", "seed", "cycles", "t_eval", "method")
    ds.attrs.update({k: v for k, v in parts[0].attrs.items() if k in keep})
    ds.attrs.update(damping=beta, steps_per_cycle=int(steps_per_cycle), box=np.asarray(box, float).ravel())
    return annotate(ds)
