"""The first harmonic: the paper's truncated G (eq 20) versus the exact sn coefficient.

The paper's G(xi) keeps only the leading term of the Fourier series of the Jacobi sn
function; the exact first harmonic is G / (1 - nome) (``theory.G(..., fourier=
"exact")``).  Both variants are compared with the same numerics:

* :func:`fcr_fourier_comparison` -- critical forcing ``F_cr(Omega)`` for an IC
  ``(xi_ini, gamma_ini)`` and phase Psi: ``theory.critical_forcing`` with both variants vs
  ``numerics.critical_forcing_numeric`` (computed here or passed in, e.g. the
  pipeline's ``results/data/numeric/fcr_fig10.nc``).
* :func:`iou_fourier_comparison` -- safe basins: analytic masks with both variants vs
  a numeric escape chart (``chart_fig13-17.nc``): IoU and pixel agreement.

Both return Datasets with a ``fourier`` dimension ("paper", "exact") side by side and
summary variables telling which is closer.  The comparison is the quartic's (only its G has a
truncated variant): numerics made in another well (the ``well`` attribute of the chart or F_cr
dataset), or ``well=`` another well, raise ValueError.
"""
from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.core import checks
from safebasins.analysis.agreement import iou, pixel_agreement
from safebasins.analysis.common import as_1d, chart_param, mesh
from safebasins.analysis.integrity import integrity_measures, unforced_safe_mask
from safebasins.analysis.safe import Criterion, chart_well, safe_stack
from safebasins.core.cf import annotate
from safebasins.numerics import critical_forcing_numeric
from safebasins.theory import angle_energy, critical_forcing, initial_condition, slow_flow_escapes
from safebasins.wells.quartic import FOURIER_VARIANTS, QUARTIC, QuarticWell
from safebasins.wells.base import WellLike
from safebasins.wells.provenance import api_provenance

__all__ = ["fcr_fourier_comparison", "fcr_fourier_comparison_from_numeric", "iou_fourier_comparison"]

_FOURIER = list(FOURIER_VARIANTS)


def _check_quartic(well, what):
    """ValueError unless ``well`` is the quartic (None or a QuarticWell)."""
    if not (well is None or isinstance(well, QuarticWell)):
        raise ValueError(f"{what}: the paper/exact first-harmonic comparison is the quartic's (eq 20 as printed vs "
                         f"the exact sn coefficient); the {getattr(well, 'name', well)!r} well has only its exact "
                         "first harmonic, nothing to compare")


def _analytic_fcr(Omega, xi_max, xi_ini, gamma_ini):
    out = []
    for f in _FOURIER:
        ds = critical_forcing(Omega, xi_max, xi_ini=xi_ini, gamma_ini=gamma_ini, fourier=f)
        out.append(np.asarray(ds["F_cr"].values, float))
    return np.stack(out)


def _fcr_dataset(Omega, F_num, F_an, extra=None, attrs=None):
    fr = xr.DataArray(_FOURIER, dims="fourier")
    ds = xr.Dataset(coords={"Omega": Omega, "fourier": fr})
    ds["F_cr_numeric"] = ("Omega", F_num, {"units": "1", "long_name": "numeric critical forcing (bisection)"})
    ds["F_cr_analytic"] = (("fourier", "Omega"), F_an,
                           {"units": "1", "long_name": "analytic critical forcing (isolated resonance)"})
    err = F_an - F_num[None, :]
    ds["error"] = (("fourier", "Omega"), err, {"units": "1", "long_name": "F_cr analytic - numeric"})
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = err / F_num[None, :]
    ds["rel_error"] = (("fourier", "Omega"), rel, {"units": "1", "long_name": "(analytic - numeric) / numeric"})
    ok = np.isfinite(rel)
    n_ok = ok.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        rms = np.sqrt(np.where(ok, rel ** 2, 0).sum(axis=1) / np.maximum(n_ok, 1))
        mae = np.where(ok, np.abs(rel), 0).sum(axis=1) / np.maximum(n_ok, 1)
    rms = np.where(n_ok > 0, rms, np.nan)
    mae = np.where(n_ok > 0, mae, np.nan)
    ds["rms_rel_error"] = ("fourier", rms, {"units": "1", "long_name": "RMS relative F_cr error over Omega"})
    ds["mean_abs_rel_error"] = ("fourier", mae, {"units": "1", "long_name": "mean |relative F_cr error| over Omega"})
    closer = np.where(np.abs(err[0]) < np.abs(err[1]), 0, np.where(np.abs(err[1]) < np.abs(err[0]), 1, -1))
    closer = np.where(ok.all(axis=0), closer, -1)
    ds["closer"] = ("Omega", closer.astype(np.int8), {
        "long_name": "variant closer to numerics at this Omega", "flag_values": [-1, 0, 1],
        "flag_meanings": "undecided paper exact"})
    ds["Omega"].attrs.update(units="1", long_name="forcing frequency")
    if extra:
        for k, v in extra.items():
            ds[k] = v
    ds.attrs.update(attrs or {})
    if np.isfinite(rms).all():
        ds.attrs["closer_overall"] = _FOURIER[int(np.argmin(rms))]
    return ds


@api_provenance
def fcr_fourier_comparison(Omega: npt.ArrayLike, xi_max: float, *, xi_ini: float = 0.0, gamma_ini: float = 0.0,
                           Psi: float = 0.0, cycles: int = 3000, tol: float = 5e-5, well: WellLike = None,
                           **numeric_kwargs: Any) -> xr.Dataset:
    """F_cr(Omega): paper vs exact first harmonic against the numeric bisection.

    The numeric IC is ``(q0, p0) = theory.initial_condition(xi_ini, gamma_ini, Psi)`` so that
    both sides describe the same trajectory (gamma_ini = theta0 - Psi).

    Returns
    -------
    xr.Dataset over (fourier, Omega): ``F_cr_analytic(fourier, Omega)``,
    ``F_cr_numeric(Omega)``, ``error``, ``rel_error``, ``closer(Omega)`` (0 paper,
    1 exact, -1 undecided); summaries ``rms_rel_error(fourier)``,
    ``mean_abs_rel_error(fourier)`` and attribute ``closer_overall``.  Numeric
    diagnostics ``non_monotone``, ``F_escape_low``, ``F_escape_all`` are carried over.
    ``well``: None or the quartic (any other well raises ValueError: it has one first harmonic).
    """
    _check_quartic(well, "well")
    Om = as_1d("Omega", Omega, checks.check_positive)
    xi_max = float(QUARTIC.check_threshold("xi_max", xi_max))
    xi_ini = float(QUARTIC.check_energy("xi_ini", xi_ini))
    gamma_ini = float(checks.check_finite("gamma_ini", gamma_ini))
    Psi = float(checks.check_finite("Psi", Psi))
    if xi_ini > 0:
        qa, pa = initial_condition(xi_ini, gamma_ini, Psi)
        q0, p0 = float(qa), float(pa)
    else:
        q0, p0 = 0.0, 0.0
    num = critical_forcing_numeric(Om, xi_max, q0=q0, p0=p0, Psi=Psi, cycles=cycles, tol=tol,
                                                   **numeric_kwargs)
    return fcr_fourier_comparison_from_numeric(num, xi_ini=xi_ini, gamma_ini=gamma_ini)


def _curve_param(ds, name, default=None):
    if name in ds.coords or name in ds.data_vars:
        return float(ds[name])
    if name in ds.attrs:
        return float(ds.attrs[name])
    if default is not None:
        return default
    raise ValueError(f"numeric F_cr dataset has no {name!r} (coordinate, variable or attribute)")


@api_provenance
def fcr_fourier_comparison_from_numeric(numeric: xr.Dataset, *, xi_ini: float | None = None,
                                        gamma_ini: float | None = None) -> xr.Dataset:
    """Paper vs exact F_cr against an existing ``critical_forcing_numeric`` Dataset.

    ``numeric`` may be stacked over ``curve`` (pipeline files ``fcr_fig10-12.nc``, with
    per-curve coordinates ``xi_max``, ``xi_ini``, ``gamma_ini``, ``Psi``); the result then has a
    ``curve`` dimension.  Without ``xi_ini``/``gamma_ini`` (coordinates or arguments) the IC
    ``(q0, p0)`` of the numeric run is converted with ``theory.angle_energy``
    (gamma_ini = theta0 - Psi).  ``numeric`` must have been made in the quartic (its ``well``
    attribute).
    """
    _check_quartic(chart_well(numeric), "numeric")
    if "curve" in numeric.dims:
        parts = [fcr_fourier_comparison_from_numeric(numeric.isel(curve=k), xi_ini=xi_ini, gamma_ini=gamma_ini)
                 for k in range(numeric.sizes["curve"])]
        out = xr.concat(parts, dim="curve", coords="different", compat="equals", combine_attrs="drop_conflicts")
        return out
    xi_max = _curve_param(numeric, "xi_max")
    Psi = _curve_param(numeric, "Psi", 0.0)
    if xi_ini is None:
        xi_ini = _curve_param(numeric, "xi_ini", np.nan)
    if gamma_ini is None:
        gamma_ini = _curve_param(numeric, "gamma_ini", np.nan)
    if not (np.isfinite(xi_ini) and np.isfinite(gamma_ini)):
        q0 = _curve_param(numeric, "q0", 0.0)
        p0 = _curve_param(numeric, "p0", 0.0)
        if q0 == 0.0 and p0 == 0.0:
            xi_ini, gamma_ini = 0.0, 0.0
        else:
            th, x = angle_energy(np.array([q0]), np.array([p0]))
            xi_ini, gamma_ini = float(x[0]), float(np.mod(th[0] - Psi, 2 * np.pi))
    Om = np.asarray(numeric["Omega"].values, float)
    F_num = np.asarray(numeric["F_cr"].values, float)
    F_an = _analytic_fcr(Om, xi_max, xi_ini, gamma_ini)
    extra = {k: ("Omega", np.asarray(numeric[k].values), dict(numeric[k].attrs))
             for k in ("non_monotone", "F_escape_low", "F_escape_all") if k in numeric}
    attrs = {"xi_max": xi_max, "xi_ini": float(xi_ini), "gamma_ini": float(gamma_ini), "Psi": Psi,
             "cycles": numeric.attrs.get("cycles", np.nan)}
    return _fcr_dataset(Om, F_num, F_an, extra, attrs)


@api_provenance
def iou_fourier_comparison(chart: xr.Dataset, t_eval: npt.ArrayLike | None = None, *,
                           criterion: Criterion = "energy") -> xr.Dataset:
    """Safe basins: analytic masks with both first-harmonic variants vs a numeric chart.

    ``chart`` is an ``escape_chart`` Dataset on a (q0, p0) grid, optionally stacked over
    ``F`` (or ``Psi``/``Omega``: any of these may be a coordinate; otherwise the chart
    attribute is used).  ``criterion="energy"`` compares with every ``xi_max`` threshold
    of the chart.

    Returns
    -------
    xr.Dataset over (fourier, [F,] xi_max, t_eval): ``iou``, ``pixel_agreement``,
    ``GIM_analytic``, ``GIM_numeric``; summary ``mean_iou(fourier)`` and attribute
    ``closer_overall``.
    """
    if criterion != "energy":
        raise ValueError("criterion must be 'energy': the analytic basin uses the energy threshold xi_max")
    _check_quartic(chart_well(chart), "chart")
    safe_num, _ = safe_stack(chart, t_eval, "energy")
    q, p = safe_num["q0"].values, safe_num["p0"].values
    _, _, Q, P = mesh(q, p)
    stack_dims = [d for d in ("F", "Omega", "Psi") if d in safe_num.dims]
    template = safe_num.isel(t_eval=0, drop=True)
    # analytic masks with the same leading dims as the chart (minus t_eval) plus fourier
    lead = template.transpose(*stack_dims, "xi_max", "q0", "p0")
    an = np.zeros((len(_FOURIER),) + lead.shape, dtype=bool)
    idx = np.ndindex(*lead.shape[:-2])
    for ii in idx:
        sel = {d: lead[d].values[i] for d, i in zip(lead.dims[:-2], ii)}
        F = float(sel["F"]) if "F" in sel else float(chart_param(chart, "F"))
        Om = float(sel["Omega"]) if "Omega" in sel else float(chart_param(chart, "Omega"))
        Ps = float(sel["Psi"]) if "Psi" in sel else float(chart_param(chart, "Psi"))
        x = float(sel["xi_max"])
        S0 = unforced_safe_mask(q, p, x)
        for a, f in enumerate(_FOURIER):
            an[(a,) + ii] = ~np.asarray(slow_flow_escapes(Q, P, F, Om, Ps, x, fourier=f), dtype=bool) & S0
    an_da = xr.DataArray(an, dims=("fourier",) + lead.dims,
                         coords={"fourier": _FOURIER, **{d: lead[d] for d in lead.dims}})
    num = safe_num.transpose("t_eval", *stack_dims, "xi_max", "q0", "p0")
    ds = xr.Dataset()
    ds["iou"] = iou(an_da, num).transpose("fourier", *stack_dims, "xi_max", "t_eval")
    ds["iou"].attrs.update(units="1", long_name="IoU of analytic and numeric safe basins")
    ds["pixel_agreement"] = pixel_agreement(an_da, num).transpose("fourier", *stack_dims, "xi_max", "t_eval")
    ds["pixel_agreement"].attrs.update(units="1", long_name="fraction of agreeing nodes")
    ds["GIM_analytic"] = integrity_measures(an_da, well=QUARTIC)["GIM"]
    ds["GIM_numeric"] = integrity_measures(num, well=QUARTIC)["GIM"].transpose(*stack_dims, "xi_max", "t_eval")
    ds["mean_iou"] = ds["iou"].mean([d for d in ds["iou"].dims if d != "fourier"]).assign_attrs(
        units="1", long_name="mean IoU over charts, thresholds and t_eval")
    ds.attrs.update({k: v for k, v in chart.attrs.items() if k in ("F", "Omega", "Psi", "cycles")})
    m = ds["mean_iou"].values
    if np.isfinite(m).all():
        ds.attrs["closer_overall"] = _FOURIER[int(np.argmax(m))]
    return annotate(ds)
