"""Phase-invariant ("true") safe basin: the intersection over forcing phases Psi.

An engineer rarely knows the forcing phase at the moment the disturbance starts; the
set of initial conditions that is safe *whatever* the phase is the intersection of
the safe basins over Psi.

Analytic (isolated 1:1 resonance)
---------------------------------
The slow phase is ``gamma = theta - Psi - Omega tau``, so the basin for phase Psi is
the Psi = 0 basin rotated in the slow angle: an IC ``(theta0, xi_ini)`` is safe for Psi
iff ``(gamma_ini, xi_ini) = (theta0 - Psi, xi_ini)`` is safe on the resonance manifold.  One
``angle_energy`` evaluation of the grid therefore serves every phase
(``escapes_on_manifold(theta0 - Psi, xi_ini, ...)``).

Over a *continuum* of phases the intersection is a sub-level set of the energy:
an IC is safe for every Psi iff the whole circle ``xi = xi_ini`` of the manifold is safe.
If a point of the circle ``xi1`` lies on a level curve of C that reaches xi_max,
that curve crosses every circle ``xi1 < xi < xi_max`` on its way, so the set of
all-safe circles is an interval ``[0, xi_true)``.  Hence

    true basin (all phases) = {H0(q0, p0) < xi_true(F, Omega, xi_max)}

and its integrity has a closed form: ``GIM = J(xi_true) / J(xi_max)`` (area = 2 pi J, eq 19),
``LIM = r_local(xi_true) / r_local(xi_max)`` and ``IF = r_global(xi_true) / r_global(xi_max)``
with the radii of the unforced set from its orbit curve
(:func:`safebasins.analysis.integrity.unforced_radii2`); for the quartic both radii are
``sqrt(2 xi)`` and ``LIM = IF = sqrt(xi_true / xi_max)``.  Any well of safebasins.wells
(``well=``; the slow flow of the well's own first harmonic, the quartic's "paper" or "exact"
G).  ``xi_true`` is
found by nested grid refinement of "some gamma of the circle escapes" (monotone in xi
by the same argument) with a fine gamma grid; if the LPT through the well bottom escapes,
``xi_true = 0``.  A finite set of phases gives a superset of this disk.

Numeric
-------
One escape chart per phase (eq (1) is not rotation invariant); the true basin for a
threshold and an evaluation time is the intersection of ``escape_cycle > t_eval``
over the phases.
"""
from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.core import checks
from safebasins.analysis.common import as_1d, mesh, stack_charts, variant_well, well_variants
from safebasins.analysis.integrity import MEASURE_ATTRS, integrity_measures, unforced_radii2, unforced_safe_mask
from safebasins.analysis.safe import AnyCriterion, chart_well, safe_stack
from safebasins.core.cf import annotate
from safebasins.numerics import escape_chart
from safebasins.theory import angle_energy, escapes_on_manifold
from safebasins.wells import resolve_well, well_attrs
from safebasins.wells.base import WellLike
from safebasins.wells.provenance import api_provenance
from safebasins.theory import safe_basin_boundaries

__all__ = [
    "default_phases",
    "xi_true_analytic",
    "closed_measures",
    "true_safe_basin_analytic",
    "true_safe_basin_numeric",
    "true_safe_basin_from_charts",
    "phase_boundaries",
]

_KEEP = ("GIM", "LIM", "IF", "r_local", "r_global", "area", "if_q0", "if_p0")


def default_phases(n_psi: int = 16) -> npt.NDArray[np.float64]:
    """``n_psi`` phases uniformly covering [0, 2 pi)."""
    n = checks.check_positive_int("n_psi", n_psi)
    return 2 * np.pi * np.arange(n) / n


def _first_escaping_circle(lo, hi, n_xi, F, Omega, xi_max, well, gamma):
    """Grid search on [lo, hi]: (last all-safe xi, first xi with an escaping point) or None."""
    xs = np.linspace(lo, hi, n_xi)
    e = np.asarray(escapes_on_manifold(gamma[:, None], xs[None, :], F, Omega, xi_max, well=well),
                   dtype=bool).any(axis=0)
    k = np.flatnonzero(e)
    if k.size == 0:
        return None
    k0 = int(k[0])
    return (xs[k0 - 1] if k0 > 0 else None), xs[k0]


def xi_true_analytic(F: float, Omega: float, xi_max: float, fourier: str | None = None, *, n_gamma: int = 512,
                     n_xi: int = 400, levels: int = 3, well: WellLike = None) -> float:
    """Largest xi such that every circle ``xi' < xi`` of the resonance manifold is safe.

    The predicate "some point of the circle escapes" is monotone in xi (module
    docstring); it is tested on ``n_gamma`` equally spaced gamma (even, so the rays
    gamma = 0 and pi where the level curves turn are included) and refined ``levels``
    times on ``n_xi``-point xi grids, giving a resolution of about
    ``xi_max / (n_xi - 1)**levels``.  Returns 0 if the well bottom (the limiting phase
    trajectory) escapes and ``xi_max`` if nothing below xi_max escapes.  ``well``: any well
    (None: the quartic); ``fourier`` one variant (None: the well's own; another well's only
    variant is "exact", :func:`~safebasins.analysis.common.variant_well`).
    """
    F = float(checks.check_nonnegative("F", F))
    Omega = float(checks.check_positive("Omega", Omega))
    w = variant_well(well, fourier)
    xi_max = float(w.check_threshold("xi_max", xi_max))
    n_gamma = checks.check_positive_int("n_gamma", n_gamma)
    n_gamma += n_gamma % 2
    gamma = 2 * np.pi * np.arange(n_gamma) / n_gamma
    lo, hi = 0.0, xi_max * (1 - 1e-12)
    for _ in range(checks.check_positive_int("levels", levels)):
        r = _first_escaping_circle(lo, hi, checks.check_positive_int("n_xi", n_xi), F, Omega, xi_max, w, gamma)
        if r is None:
            return hi if hi >= xi_max * (1 - 1e-9) else lo
        if r[0] is None:
            return lo
        lo, hi = r
    return lo


def closed_measures(xi_true: float, xi_max: float, well: WellLike = None) -> tuple[float, float, float]:
    """Closed-form ``(GIM, LIM, IF)`` of the all-phase basin {H0 < xi_true} (module docstring):
    ``J(xi_true)/J(xi_max)`` (eq 19) and the ratios of the unforced radii
    (:func:`~safebasins.analysis.integrity.unforced_radii2`); ``sqrt(xi_true/xi_max)`` for both
    radii of the quartic."""
    w = resolve_well(well)
    if xi_true <= 0:
        return 0.0, 0.0, 0.0
    loc_t, glob_t = unforced_radii2(xi_true, w)
    loc_m, glob_m = unforced_radii2(xi_max, w)
    return float(w.J(xi_true) / w.J(xi_max)), float(np.sqrt(loc_t / loc_m)), float(np.sqrt(glob_t / glob_m))


def _one_analytic(F, Omega, xi_max, q, p, Psi, well, n_gamma):
    """Per-phase basins, the all-phase basin {H0 < xi_true} and its closed-form measures, for
    one well object (one first-harmonic variant)."""
    Q, P = np.meshgrid(q, p, indexing="ij")
    S0 = unforced_safe_mask(q, p, xi_max, well)
    theta = np.zeros(Q.shape)
    xi_ini = np.zeros(Q.shape)
    th, x = angle_energy(Q[S0], P[S0], well=well)
    theta[S0], xi_ini[S0] = th, x
    safe = np.zeros((Psi.size,) + Q.shape, dtype=bool)
    for k, ps in enumerate(Psi):
        gamma = np.mod(theta[S0] - ps, 2 * np.pi)
        safe[k][S0] = ~np.asarray(escapes_on_manifold(gamma, xi_ini[S0], F, Omega, xi_max, well=well), dtype=bool)
    xt = xi_true_analytic(F, Omega, xi_max, well.fourier, n_gamma=n_gamma, well=well)
    cont = S0 & (xi_ini < xt)
    return (safe, cont, xt) + closed_measures(xt, xi_max, well)


def _assemble(safe, q, p, Psi, lead_dims, lead_coords, xi_norm, well):
    """Common Dataset layout: per-phase masks, true mask, integrity of both."""
    dims_psi = ("Psi",) + lead_dims + ("q0", "p0")
    coords = {"Psi": Psi, "q0": q, "p0": p, **lead_coords}
    da_safe = xr.DataArray(safe, dims=dims_psi, coords=coords,
                           attrs={"long_name": "safe basin for forcing phase Psi", "units": "1"})
    da_true = da_safe.all("Psi").assign_attrs(long_name="phase-invariant safe basin (intersection over Psi)",
                                              units="1")
    per = integrity_measures(da_safe, xi_max=xi_norm, well=well)
    tru = integrity_measures(da_true, xi_max=xi_norm, well=well)
    ds = xr.Dataset({"safe": da_safe, "true_safe": da_true})
    for k in _KEEP:
        ds[k] = per[k]
        ds[f"{k}_true"] = tru[k].assign_attrs(
            units=MEASURE_ATTRS[k]["units"], long_name=MEASURE_ATTRS[k]["long_name"] + " of the true basin")
    # energy radius of the true basin: largest E with {H0 < E} (inside S0) contained in it, the grid
    # counterpart of xi_true (compare analytic xi_true with the numeric xi_inscribed_true)
    Q, P = np.meshgrid(q, p, indexing="ij")
    Hq = xr.DataArray(well.H0(Q, P), dims=("q0", "p0"), coords={"q0": q, "p0": p})
    s0 = xr.DataArray(np.stack([well.unforced_safe(Q, P, x) for x in np.ravel(xi_norm.values)]).reshape(
        xi_norm.shape + Q.shape), dims=xi_norm.dims + ("q0", "p0"), coords={**xi_norm.coords, **Hq.coords})
    bad = s0 & ~da_true
    ds["xi_inscribed_true"] = Hq.where(bad).min(("q0", "p0")).fillna(xi_norm).assign_attrs(
        units="1", long_name="largest energy E with {H0 < E} inside the true basin (grid value, one-node accuracy)")
    # containment diagnostic: the true basin lies inside every per-phase basin
    ds["contained"] = (~(da_true & ~da_safe)).all(("q0", "p0")).all("Psi").assign_attrs(
        long_name="true basin contained in every per-phase basin", units="1")
    ds["Psi"].attrs.update(units="rad", long_name="forcing phase")
    return ds


@api_provenance
def true_safe_basin_analytic(F: float, Omega: float, xi_max: npt.ArrayLike, q0: npt.ArrayLike, p0: npt.ArrayLike,
                             Psi_values: npt.ArrayLike | None = None, *, fourier: str | Sequence[str] | None = None,
                             n_psi: int = 16, n_gamma: int = 512, well: WellLike = None) -> xr.Dataset:
    """Analytic phase-invariant safe basin and its integrity.

    Parameters
    ----------
    F, Omega : forcing amplitude and frequency.
    xi_max : energy threshold(s) (dimension ``xi_max``).
    q0, p0 : 1-D uniform grid axes.
    Psi_values : phases to intersect over (default ``default_phases(n_psi)``).
    fourier : None (the well's own: "paper" for the default quartic) | "paper" | "exact" | list
        (dimension ``fourier``); a well other than the quartic has only "exact"
        (:func:`~safebasins.analysis.common.variant_well`).
    n_gamma : gamma resolution of the continuous-phase limit ``xi_true``.
    well : the potential well (None: the paper's quartic).

    Returns
    -------
    xr.Dataset with
      ``safe(Psi, [fourier,] xi_max, q0, p0)``     per-phase basins (rotations of Psi = 0),
      ``true_safe([fourier,] xi_max, q0, p0)``     intersection over ``Psi_values``,
      ``true_safe_continuous(...)``                 all phases: {H0 < xi_true},
      ``xi_true([fourier,] xi_max)``                energy radius of the all-phase basin,
      ``GIM, LIM, IF, r_local, r_global, area, if_q0, if_p0`` over (Psi, ...) and the
      same with suffix ``_true`` (intersection over Psi_values) and ``_continuous``
      (grid values for {H0 < xi_true}); ``GIM_closed``, ``LIM_closed``, ``IF_closed``:
      the closed forms J(xi_true)/J(xi_max) and the radius ratios (:func:`closed_measures`;
      sqrt(xi_true/xi_max) for both radii of the quartic);
      ``xi_inscribed_true`` (largest energy disk inside ``true_safe``, grid value) and
      ``contained`` (true basin inside every per-phase basin).
    """
    F = float(checks.check_nonnegative("F", F))
    Omega = float(checks.check_positive("Omega", Omega))
    fl, wl, scalar = well_variants(well, fourier)
    xi = as_1d("xi_max", xi_max, wl[0].check_threshold)
    Psi = default_phases(n_psi) if Psi_values is None else as_1d("Psi_values", Psi_values, checks.check_finite)
    q, p, _, _ = mesh(q0, p0)
    nf, nx = len(fl), xi.size
    safe = np.zeros((Psi.size, nf, nx, q.size, p.size), bool)
    cont = np.zeros((nf, nx, q.size, p.size), bool)
    xt = np.zeros((nf, nx))
    gim_c = np.zeros((nf, nx))
    lim_c = np.zeros((nf, nx))
    if_c = np.zeros((nf, nx))
    for a in range(len(fl)):
        for j, x in enumerate(xi):
            s, c, t, g, l, r = _one_analytic(F, Omega, float(x), q, p, Psi, wl[a], n_gamma)
            safe[:, a, j], cont[a, j], xt[a, j], gim_c[a, j], lim_c[a, j], if_c[a, j] = s, c, t, g, l, r
    lead_dims = ("fourier", "xi_max")
    lead_coords = {"fourier": fl, "xi_max": xi}
    xi_norm = xr.DataArray(xi, dims="xi_max", coords={"xi_max": xi})
    ds = _assemble(safe, q, p, Psi, lead_dims, lead_coords, xi_norm, wl[0])
    da_cont = xr.DataArray(cont, dims=lead_dims + ("q0", "p0"), coords={**lead_coords, "q0": q, "p0": p},
                           attrs={"long_name": "safe basin for every phase Psi in [0, 2 pi): H0 < xi_true",
                                  "units": "1"})
    ds["true_safe_continuous"] = da_cont
    cm = integrity_measures(da_cont, xi_max=xi_norm, well=wl[0])
    for k in _KEEP:
        ds[f"{k}_continuous"] = cm[k]
    ds["xi_true"] = xr.DataArray(xt, dims=lead_dims, attrs={
        "units": "1", "long_name": "largest energy whose whole manifold circle is safe (all-phase basin H0 < xi_true)"})
    ds["GIM_closed"] = xr.DataArray(gim_c, dims=lead_dims, attrs={
        "units": "1", "long_name": "closed-form GIM of the all-phase basin, J(xi_true)/J(xi_max)"})
    ds["LIM_closed"] = xr.DataArray(lim_c, dims=lead_dims, attrs={
        "units": "1", "long_name": "closed-form LIM of the all-phase basin, r_local(xi_true)/r_local(xi_max) "
                                   "(sqrt(xi_true/xi_max) for the quartic)"})
    ds["IF_closed"] = xr.DataArray(if_c, dims=lead_dims, attrs={
        "units": "1", "long_name": "closed-form IF of the all-phase basin, r_global(xi_true)/r_global(xi_max) "
                                   "(sqrt(xi_true/xi_max) for the quartic)"})
    if scalar:
        ds = ds.isel(fourier=0)
    ds.attrs.update(well_attrs(wl[0]))
    ds.attrs.update({"kind": "analytic", "F": F, "Omega": Omega, "n_gamma": int(n_gamma),
                     "method": "rotation of the Psi = 0 manifold classification: gamma_ini = theta0 - Psi"})
    return annotate(ds)


@api_provenance
def true_safe_basin_from_charts(charts: xr.Dataset | Iterable[xr.Dataset], t_eval: npt.ArrayLike | None = None, *,
                                criterion: AnyCriterion = "energy") -> xr.Dataset:
    """Numeric phase-invariant basin from escape charts stacked over ``Psi`` (or a list of charts).

    Returns a Dataset with ``safe(Psi, threshold, t_eval, q0, p0)``, ``true_safe(threshold,
    t_eval, q0, p0)``, integrity of each (``GIM``... over Psi and ``GIM_true``...),
    ``xi_inscribed_true`` (energy radius of the true basin, to compare with the analytic
    ``xi_true``) and ``contained``.
    """
    chart = stack_charts(charts, "Psi")
    well = chart_well(chart)    # the well the charts were integrated in
    safe, xi_norm = safe_stack(chart, t_eval, criterion)
    thr = xi_norm.dims[0]
    safe = safe.transpose("Psi", thr, "t_eval", "q0", "p0")
    lead_dims = (thr, "t_eval")
    lead_coords = {thr: safe[thr].values, "t_eval": safe["t_eval"].values}
    ds = _assemble(safe.values, safe["q0"].values, safe["p0"].values, safe["Psi"].values,
                   lead_dims, lead_coords, xi_norm, well)
    ds.attrs.update(well_attrs(well))
    ds.attrs.update({k: v for k, v in chart.attrs.items() if k in ("F", "Omega", "cycles", "steps_per_cycle",
                                                                       "integrator", "damping")})
    ds.attrs.update({"kind": "numeric", "criterion": criterion,
                     "method": "intersection over Psi of escape_cycle > t_eval, one escape_chart per Psi"})
    return annotate(ds)


@api_provenance
def true_safe_basin_numeric(F: float, Omega: float, xi_max: npt.ArrayLike, q0: npt.ArrayLike, p0: npt.ArrayLike,
                            Psi_values: npt.ArrayLike | None = None, t_eval: npt.ArrayLike | None = None,
                            cycles: int = 3000, *, n_psi: int = 16, keep_charts: bool = False, well: WellLike = None,
                            **chart_kwargs: Any) -> xr.Dataset | tuple[xr.Dataset, xr.Dataset]:
    """Numeric phase-invariant safe basin: one ``numerics.escape_chart`` per phase.

    Parameters as in :func:`true_safe_basin_analytic`, plus ``t_eval`` (cycles, each <=
    ``cycles``; dimension ``t_eval``), ``cycles`` and ``chart_kwargs`` for escape_chart.
    Returns the Dataset of :func:`true_safe_basin_from_charts` (and the charts if
    ``keep_charts``).
    """
    F = float(checks.check_nonnegative("F", F))
    Omega = float(checks.check_positive("Omega", Omega))
    xi = as_1d("xi_max", xi_max, resolve_well(well).check_threshold)
    Psi = default_phases(n_psi) if Psi_values is None else as_1d("Psi_values", Psi_values, checks.check_finite)
    checks.check_positive_int("cycles", cycles)
    q, p, _, _ = mesh(q0, p0)
    charts = [escape_chart(q, p, F, Omega, float(ps), xi_max=tuple(xi.tolist()), cycles=cycles, well=well,
                           **chart_kwargs).assign_attrs(Psi=float(ps)) for ps in Psi]
    stacked = stack_charts(charts, "Psi")
    ds = true_safe_basin_from_charts(stacked, t_eval)
    return (ds, stacked) if keep_charts else ds


@api_provenance
def phase_boundaries(F: float, Omega: float, xi_max: npt.ArrayLike, Psi_values: npt.ArrayLike, *,
                     fourier: str | Sequence[str] | None = None, n_points: int = 400,
                     well: WellLike = None) -> xr.Dataset:
    """Boundary curves of the analytic per-phase basins on the IC plane, from the slow flow
    itself (:func:`safebasins.theory.safe_basin_boundaries` for every phase), not from a grid.
    ``well``, ``fourier`` as in :func:`true_safe_basin_analytic`.

    Returns an xr.Dataset over (``Psi``, [``fourier``,] ``xi_max``, ``vertex``) with
    ``boundary_q0``, ``boundary_p0`` (NaN-padded; NaN rows also split a curve) and
    ``boundary_curve`` (curve index of the vertex, -1 = padding).
    """
    fl, wl, scalar = well_variants(well, fourier)
    xi = as_1d("xi_max", xi_max, wl[0].check_threshold)
    Psi = as_1d("Psi_values", Psi_values, checks.check_finite)
    parts = {}
    for k, ps in enumerate(Psi):
        for a in range(len(fl)):
            for j, x in enumerate(xi):
                b = safe_basin_boundaries(F, Omega, float(ps), float(x), well=wl[a], n_points=n_points)
                parts[k, a, j] = (np.asarray(b["q0_vertex"], float), np.asarray(b["p0_vertex"], float),
                                  np.asarray(b["curve_index"], float))
    nv = max(v[0].size for v in parts.values())
    shape = (Psi.size, len(fl), xi.size, nv)
    bq, bp, bc = np.full(shape, np.nan), np.full(shape, np.nan), np.full(shape, -1, np.int64)
    for (k, a, j), (qv, pv, cv) in parts.items():
        bq[k, a, j, :qv.size], bp[k, a, j, :pv.size] = qv, pv
        bc[k, a, j, :cv.size] = np.where(np.isfinite(cv), cv, -1).astype(np.int64)
    dims = ("Psi", "fourier", "xi_max", "vertex")
    ds = xr.Dataset({
        "boundary_q0": (dims, bq, {"units": "1", "long_name": "q0 of the per-phase analytic basin boundary"}),
        "boundary_p0": (dims, bp, {"units": "1", "long_name": "p0 of the per-phase analytic basin boundary"}),
        "boundary_curve": (dims, bc, {"units": "1", "long_name": "boundary curve of the vertex (-1: padding)"}),
    }, coords={"Psi": Psi, "fourier": fl, "xi_max": xi})
    return ds.isel(fourier=0, drop=True) if scalar else ds
