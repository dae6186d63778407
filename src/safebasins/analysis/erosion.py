"""Erosion profiles: GIM, LIM and IF of the safe basin versus the forcing amplitude F.

Analytic profiles classify every grid IC with the isolated-resonance slow flow
(``theory.slow_flow_escapes``) for each F; numeric profiles integrate eq (1) with ONE
``numerics.escape_chart`` per F carrying all thresholds, and read the safe set
``escape_cycle > t_eval`` for every evaluation time from the same escape cycles, so
the numeric profile is a function of ``(F, xi_max, t_eval)`` at the cost of a
function of F.  :func:`profile_from_charts` does the reading for charts that
already exist (the pipeline's ``chart_fig16/17.nc``, or any stack over F).

With damping (``damping`` = beta > 0, docs/damping.md) both sides take the damped equation
``q'' + beta q' + V'(q) = F sin(Omega tau + Psi)``: the analytic profile follows each IC's damped
slow trajectory until it escapes or settles below xi_max, the numeric one integrates the damped
equation; the datasets carry the attribute ``damping``.

All results are ``xarray.Dataset`` objects with the variables of
:func:`safebasins.analysis.integrity.integrity_measures` (``GIM``, ``LIM``, ``IF`` plus raw
radii/areas), ``units``/``long_name`` attributes, and the parameters as attributes.

Monotonicity that holds exactly: for a fixed chart the safe set shrinks as t_eval
grows, so GIM, LIM and IF are non-increasing in ``t_eval`` (LIM/IF because the
distance to the unsafe set can only shrink when the unsafe set grows).  In F
neither the analytic nor the numeric profile is monotone in general (secondary
resonances, the non-monotone escape near the resonance minimum); the analytic
profile starts at 1 at F = 0 where the slow flow is xi = const (with damping xi decays: every IC
of S0 settles at the bottom).
"""
from __future__ import annotations

import warnings
from collections.abc import Iterable, Sequence
from typing import Any, overload

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.core import checks
from safebasins.core import cf
from safebasins.theory.slow_flow_grid import GridSlowFlow
from safebasins.analysis.common import as_1d, mesh, stack_charts, well_variants
from safebasins.analysis.integrity import integrity_measures, unforced_safe_mask
from safebasins.analysis.safe import AnyCriterion, chart_well, safe_stack
from safebasins.core.cf import annotate
from safebasins.numerics import escape_chart
from safebasins.numerics.engine import damping_attrs
from safebasins.theory.damped_escape import UndecidedWarning, slow_flow_outcomes
from safebasins.theory.damped_flow import SETTLED, UNDECIDED
from safebasins.wells import resolve_well, well_attrs
from safebasins.wells.base import WellLike
from safebasins.wells.provenance import api_provenance

__all__ = [
    "analytic_safe_masks",
    "erosion_profile_analytic",
    "erosion_profile_numeric",
    "profile_from_charts",
    "level_crossing",
    "compare_profiles",
]


# --------------------------------------------------------------------------- analytic
def _analytic_masks(F_values, Omega, Psi, xi_max, q0, p0, fourier, well, damping):
    """Safe masks (DataArray over fourier, F, xi_max, q0, p0), the count of undecided damped slow
    trajectories (array over fourier, F, xi_max) and whether ``fourier`` was a scalar."""
    F = as_1d("F_values", F_values, checks.check_nonnegative)
    fl, wl, scalar = well_variants(well, fourier)
    xi = as_1d("xi_max", xi_max, wl[0].check_threshold)
    Omega = checks.check_scalar("Omega", Omega, checks.check_positive)
    Psi = checks.check_scalar("Psi", Psi, checks.check_finite)
    beta = checks.check_damping(damping)
    q, p, Q, P = mesh(q0, p0)
    S0 = unforced_safe_mask(q, p, xi, wl[0])
    out = np.zeros((len(fl), F.size, xi.size, q.size, p.size), dtype=bool)
    undecided = np.zeros((len(fl), F.size, xi.size), dtype=np.int64)
    for a in range(len(fl)):
        for j, x in enumerate(xi):
            if beta > 0:
                # the damped slow flow: each IC's trajectory followed until it escapes or settles
                for i, Fi in enumerate(F):
                    status = slow_flow_outcomes(Q, P, float(Fi), Omega, Psi, float(x), beta, well=wl[a])
                    out[a, i, j] = (status == SETTLED) & S0[j]
                    undecided[a, i, j] = np.count_nonzero(status == UNDECIDED)
                continue
            # = slow_flow_escapes per F, bit for bit, the grid's and threshold's parts once
            grid = GridSlowFlow(Q, P, Psi, float(x), wl[a])
            for i, Fi in enumerate(F):
                out[a, i, j] = ~grid.escapes(grid.profile(float(Fi), Omega)) & S0[j]
    da = xr.DataArray(out, dims=("fourier", "F", "xi_max", "q0", "p0"),
                      coords={"fourier": fl, "F": F, "xi_max": xi, "q0": q, "p0": p},
                      attrs={"long_name": "analytic safe basin (isolated 1:1 resonance)", "units": "1",
                             **damping_attrs(beta)})
    n = int(undecided.sum())
    if n:
        warnings.warn(f"{n} damped slow trajectories undecided (neither settled nor escaped within the horizon): "
                      "counted as escaping; the profile's variable n_undecided says where", UndecidedWarning,
                      stacklevel=3)
    return da, undecided, scalar


def analytic_safe_masks(F_values: npt.ArrayLike, Omega: float, Psi: float, xi_max: npt.ArrayLike, q0: npt.ArrayLike,
                        p0: npt.ArrayLike, fourier: str | Sequence[str] | None = None, well: WellLike = None, *,
                        damping: float = 0.0) -> xr.DataArray:
    """Analytic safe masks ``~slow_flow_escapes`` stacked as DataArray (fourier?, F, xi_max, q0, p0).

    ``fourier`` may be None (the well's own first harmonic: eq (20) as printed for the default
    quartic, "exact" for any other well), a string (scalar coordinate) or a list (dimension
    ``fourier``); ``well`` (None: the quartic) any well of safebasins.wells, whose only variant
    is "exact" (:func:`~safebasins.analysis.common.variant_well` states the rule).
    Points outside the unforced set S0 (eqs 4, 7; the well's ``unforced_safe``) are never safe
    (theory returns True there; the mask is intersected with S0 anyway so that GIM <= 1 exactly).
    ``damping`` (beta >= 0; 0: the paper's conservative slow flow): for beta > 0 an IC is safe iff
    its trajectory of the damped slow flow settles below xi_max
    (:func:`safebasins.theory.damped_escape.slow_flow_outcomes`, docs/damping.md); undecided
    trajectories count as escaping, with an ``UndecidedWarning``; attribute ``damping``.
    """
    da, _, scalar = _analytic_masks(F_values, Omega, Psi, xi_max, q0, p0, fourier, well, damping)
    return da.isel(fourier=0) if scalar else da


@api_provenance
def erosion_profile_analytic(F_values: npt.ArrayLike, Omega: float, Psi: float, xi_max: npt.ArrayLike,
                             q0: npt.ArrayLike, p0: npt.ArrayLike, fourier: str | Sequence[str] | None = None, *,
                             keep_masks: bool = False, well: WellLike = None, damping: float = 0.0) -> xr.Dataset:
    """Analytic erosion profile: GIM/LIM/IF versus F from the slow flow on the (q0, p0) grid.

    Parameters
    ----------
    F_values : 1-D forcing amplitudes (include 0 for the unforced reference point).
    Omega, Psi : forcing frequency and phase.
    xi_max : energy threshold(s) (dimension ``xi_max``).
    q0, p0 : 1-D uniform grid axes (cover the unforced set S0(xi_max); for the quartic
        ``|q0| <= 1``, ``|p0| <= 1/sqrt(2)``).
    fourier : None (the well's own: "paper" for the default quartic) | "paper" | "exact" |
        list of both (adds dimension ``fourier``); a well other than the quartic has only
        "exact" (:func:`~safebasins.analysis.common.variant_well`).
    well : the potential well (None: the paper's quartic).
    keep_masks : also return the masks as variable ``safe`` (..., q0, p0).
    damping : beta >= 0 of ``q'' + beta q' + V'(q) = F sin(Omega tau + Psi)`` (0: the paper's
        conservative slow flow); beta > 0 classifies every IC by its damped slow trajectory
        (:func:`analytic_safe_masks`), hundreds of times the cost of the undamped level-curve test,
        and adds the attribute ``damping`` and the variable ``n_undecided`` (fourier?, F, xi_max:
        trajectories neither settled nor escaped within the horizon, counted as escaping).

    Returns
    -------
    xr.Dataset over (fourier?, F, xi_max) with ``GIM``, ``LIM``, ``IF`` and the raw
    measures (see :func:`safebasins.analysis.integrity.integrity_measures`).
    """
    masks, undecided, scalar = _analytic_masks(F_values, Omega, Psi, xi_max, q0, p0, fourier, well, damping)
    names, wl, _ = well_variants(well, fourier)
    w = wl[0]
    beta = float(masks.attrs.get("damping", 0.0))
    if scalar:
        masks = masks.isel(fourier=0)
        undecided = undecided[0]
    ds = integrity_measures(masks, well=w)
    if keep_masks:
        ds["safe"] = masks
    if beta > 0:
        ds["n_undecided"] = (masks.dims[:-2], undecided,
                             {"units": "1", "long_name": "damped slow trajectories neither settled nor escaped within "
                                                         "the horizon (counted as escaping)"})
    method = ("safebasins.theory.damped_escape.slow_flow_outcomes (damped slow flow) on the grid" if beta > 0
              else "safebasins.theory.slow_flow_escapes on the grid")
    ds.attrs.update({"kind": "analytic", "Omega": float(Omega), "Psi": float(Psi), "method": method,
                     **damping_attrs(beta), **well_attrs(w)})
    if scalar:
        ds.attrs["fourier"] = names[0]
    return annotate(ds)


# --------------------------------------------------------------------------- numeric
@api_provenance
def profile_from_charts(charts: xr.Dataset | Iterable[xr.Dataset], t_eval: npt.ArrayLike | None = None, *,
                        criterion: AnyCriterion = "energy", stack_dim: str = "F") -> xr.Dataset:
    """Integrity profile from existing escape charts (no integration).

    Parameters
    ----------
    charts : one ``escape_chart`` Dataset (optionally stacked over ``stack_dim``, e.g.
        the pipeline's ``chart_fig16.nc``) or a sequence of charts, concatenated along
        ``stack_dim`` using each chart's attribute of that name.
    t_eval : evaluation times in forcing cycles (default: the chart horizon
        ``cycles``); each <= ``cycles``.  Adds dimension ``t_eval``.
    criterion : "energy" (``escape_cycle_energy``, thresholds ``xi_max``),
        "displacement" (``escape_cycle_displacement``, thresholds ``q_max``) or "bounds"
        (``escape_cycle_bounds``, pairs ``q_bounds``); a displacement criterion is normalised by
        the unforced set of its energy in the charts' well
        (:func:`safebasins.analysis.safe.displacement_energy`: V(q_max) for the quartic).

    Returns
    -------
    xr.Dataset over (stack_dim?, threshold, t_eval) with the integrity variables.
    """
    chart = stack_charts(charts, stack_dim)
    well = chart_well(chart)    # the well the charts were integrated in (escape_chart's attributes)
    safe, xi_norm = safe_stack(chart, t_eval, criterion)
    parts = [integrity_measures(safe.isel(t_eval=k), xi_max=xi_norm, well=well) for k in range(safe.sizes["t_eval"])]
    ds = xr.concat(parts, dim="t_eval", coords="minimal", compat="override", join="override")
    thr = xi_norm.dims[0]
    lead = [d for d in (stack_dim, thr) if d in ds.dims]
    ds = ds.transpose(*lead, "t_eval", ...)
    ds["t_eval"].attrs.update(cf.attrs("t_eval"))
    ds.attrs.update({k: v for k, v in chart.attrs.items() if k in ("Omega", "Psi", "F", "cycles",
                                                                       "steps_per_cycle", "integrator", "damping")})
    ds.attrs.update(well_attrs(well))
    ds.attrs.update({"kind": "numeric", "criterion": criterion,
                     "method": "safe = escape_cycle > t_eval from safebasins.numerics.escape_chart"})
    return annotate(ds)


@api_provenance
def erosion_profile_numeric(F_values: npt.ArrayLike, Omega: float, Psi: float, xi_max: npt.ArrayLike,
                            q0: npt.ArrayLike, p0: npt.ArrayLike, t_eval: npt.ArrayLike | None = None,
                            cycles: int = 3000, *, q_max: npt.ArrayLike = (), keep_charts: bool = False,
                            well: WellLike = None, damping: float = 0.0, **chart_kwargs: Any
                            ) -> xr.Dataset | tuple[xr.Dataset, xr.Dataset]:
    """Numeric erosion profile: ONE escape chart per F, all thresholds and t_eval read from it.

    Parameters
    ----------
    F_values, Omega, Psi, xi_max, q0, p0 : as in :func:`erosion_profile_analytic`.
    t_eval : evaluation time(s) in forcing cycles, each <= ``cycles`` (default ``cycles``).
    cycles : integration horizon of each chart.
    q_max : displacement thresholds also integrated (profile variables for them are
        not returned here; use :func:`profile_from_charts` on the kept charts).
    keep_charts : return the stacked charts too: ``(profile, charts)``.
    well : the potential well (None: the paper's quartic; numerics: a polynomial well).
    damping : beta >= 0: every chart integrates ``q'' + beta q' + V'(q) = F sin(Omega tau + Psi)``
        (``numerics.escape_chart(damping=)``); the profile records ``damping`` for beta > 0.
    chart_kwargs : passed to ``numerics.escape_chart`` (``steps_per_cycle``, ``threads``).

    Returns
    -------
    xr.Dataset over (F, xi_max, t_eval) (and the charts stacked over F if ``keep_charts``).
    """
    F = as_1d("F_values", F_values, checks.check_nonnegative)
    xi = as_1d("xi_max", xi_max, resolve_well(well).check_threshold)
    checks.check_positive_int("cycles", cycles)
    checks.check_scalar("Omega", Omega, checks.check_positive)
    checks.check_scalar("Psi", Psi, checks.check_finite)
    beta = checks.check_damping(damping)
    q, p, _, _ = mesh(q0, p0)
    charts = []
    for Fi in F:
        c = escape_chart(q, p, float(Fi), float(Omega), float(Psi), xi_max=tuple(xi.tolist()),
                         q_max=tuple(np.atleast_1d(q_max).tolist()), cycles=cycles, well=well, damping=beta,
                         **chart_kwargs)
        charts.append(c.assign_attrs(F=float(Fi)))
    stacked = stack_charts(charts, "F")
    prof = profile_from_charts(stacked, t_eval)
    return (prof, stacked) if keep_charts else prof


# --------------------------------------------------------------------------- summaries
@overload
def level_crossing(profile: xr.DataArray, level: float = 0.5, dim: str = "F") -> xr.DataArray: ...


@overload
def level_crossing(profile: xr.Dataset, level: float = 0.5, dim: str = "F") -> xr.Dataset: ...


@api_provenance
def level_crossing(profile: xr.DataArray | xr.Dataset, level: float = 0.5, dim: str = "F"
                   ) -> xr.DataArray | xr.Dataset:
    """First value of ``dim`` at which a profile falls below ``level`` (linear interpolation).

    ``profile`` is a DataArray (e.g. ``ds["GIM"]``) or a Dataset (applied to GIM, LIM,
    IF).  NaN where the profile never drops below ``level``; the first coordinate if it
    starts below.  Vectorised over all other dims.
    """
    if isinstance(profile, xr.Dataset):
        if not any(k in profile for k in ("GIM", "LIM", "IF")):
            raise ValueError(f"profile has none of GIM, LIM, IF (variables: {sorted(map(str, profile.data_vars))})")
        out = xr.Dataset({k: level_crossing(profile[k], level, dim) for k in ("GIM", "LIM", "IF")
                          if k in profile})
        return out.assign_attrs(level=float(level), dim=dim)
    if not isinstance(profile, xr.DataArray):
        raise ValueError(f"profile must be a DataArray or Dataset of measures over {dim!r}, got "
                         f"{type(profile).__name__}")
    if dim not in profile.dims:
        raise ValueError(f"dim {dim!r} is not a dimension of the profile (dims: {profile.dims})")
    if profile.sizes[dim] == 0:
        raise ValueError(f"the profile is empty along dim {dim!r}")
    checks.check_scalar("level", level, checks.check_finite)
    x = profile[dim].values.astype(float)
    if x.size > 1 and (np.diff(x) <= 0).any():
        raise ValueError(f"{dim} must be increasing along the profile")

    def _first(y):
        y = np.asarray(y, float)
        below = np.flatnonzero(y < level)
        if below.size == 0:
            return np.nan
        k = below[0]
        if k == 0:
            return x[0]
        y0, y1 = y[k - 1], y[k]
        if not np.isfinite(y0) or y0 == y1:
            return x[k]
        return x[k - 1] + (y0 - level) / (y0 - y1) * (x[k] - x[k - 1])

    res = xr.apply_ufunc(lambda a: np.apply_along_axis(_first, -1, a), profile,
                         input_core_dims=[[dim]], output_core_dims=[[]])
    return res.assign_attrs(units=profile[dim].attrs.get("units", "1"),
                            long_name=f"first {dim} at which {profile.name or 'the measure'} < {level}")


@api_provenance
def compare_profiles(analytic: xr.Dataset, numeric: xr.Dataset, level: float = 0.5) -> xr.Dataset:
    """Side-by-side Dataset: ``<measure>_analytic``, ``<measure>_numeric`` and the F at which
    each falls below ``level`` (``F_<measure>_analytic``, ``F_<measure>_numeric``).

    The two profiles must share the F and xi_max coordinates (as produced by
    :func:`erosion_profile_analytic` and :func:`erosion_profile_numeric` with the same
    arguments).
    """
    out = xr.Dataset()
    for k in ("GIM", "LIM", "IF"):
        out[f"{k}_analytic"] = analytic[k]
        out[f"{k}_numeric"] = numeric[k]
        out[f"F_{k}_analytic"] = level_crossing(analytic[k], level)
        out[f"F_{k}_numeric"] = level_crossing(numeric[k], level)
    out.attrs.update(level=float(level), Omega=analytic.attrs.get("Omega"), Psi=analytic.attrs.get("Psi"))
    return out
