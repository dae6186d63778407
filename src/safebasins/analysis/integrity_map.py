"""Integrity maps: GIM, LIM and IF of the safe basin over the control plane (Omega, F).

For one threshold xi_max and forcing phase Psi, every control point (Omega, F) has a safe basin
on the same (q0, p0) grid; its integrity measures (:mod:`safebasins.analysis.integrity`,
normalised by the unforced basin) form a map over (Omega, F).

* analytic: every IC classified by the slow flow (``theory.slow_flow_escapes``) -- seconds;
  plus the phase-invariant basin of each control point in closed form, ``GIM_true =
  J(xi_true)/J(xi_max)``, ``LIM_true``, ``IF_true`` (radius ratios; both ``sqrt(xi_true/xi_max)``
  for the quartic) (:func:`safebasins.analysis.phase_invariant.xi_true_analytic`,
  :func:`~safebasins.analysis.phase_invariant.closed_measures`);
* any well of safebasins.wells (``well=``, None: the paper's quartic); ``fourier`` follows
  :func:`safebasins.analysis.common.variant_well` (another well has only "exact");
* numeric: one escape chart per control point (``numerics.escape_chart_batch``: the control
  points of a block share one ensemble), safe = ``escape_cycle > t_eval`` for every t_eval;
* :func:`erosion_front`: the F at which a measure first falls below a level, per Omega (the
  erosion front), and the numeric - analytic difference map.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.core import checks
from safebasins.analysis.common import as_1d, mesh, variant_well
from safebasins.analysis.erosion import level_crossing
from safebasins.theory.slow_flow_grid import GridSlowFlow
from safebasins.analysis.integrity import integrity_measures, unforced_radii2, unforced_safe_mask
from safebasins.analysis.safe import chart_well, safe_stack
from safebasins.core.cf import annotate
from safebasins.wells.provenance import api_provenance
from safebasins.numerics import escape_chart_batch
from safebasins.wells import well_attrs
from safebasins.wells.base import WellLike

__all__ = ["integrity_map_analytic", "integrity_map_numeric", "integrity_from_batch", "erosion_front"]

MEASURES = ("GIM", "LIM", "IF")


def _control(Omega, F):
    Om = as_1d("Omega", Omega, checks.check_positive)
    Fv = as_1d("F", F, checks.check_nonnegative)
    return Om, Fv


@api_provenance
def integrity_map_analytic(Omega: npt.ArrayLike, F: npt.ArrayLike, Psi: float, xi_max: float, q0: npt.ArrayLike,
                           p0: npt.ArrayLike, *, fourier: str | None = None, n_gamma: int = 128, n_xi: int = 64,
                           well: WellLike = None) -> xr.Dataset:
    """Analytic integrity map over (Omega, F): GIM, LIM, IF of the slow-flow basin for phase Psi,
    and ``xi_true``, ``GIM_true``, ``LIM_true``, ``IF_true`` of the basin safe for every phase.
    ``well``: any well (None: the quartic); ``fourier``: one variant (None: the well's own, "paper"
    for the default quartic; another well's only variant is "exact")."""
    Om, Fv = _control(Omega, F)
    w = variant_well(well, fourier)
    Psi = checks.check_scalar("Psi", Psi, checks.check_finite)
    xi = checks.check_scalar("xi_max", xi_max, w.check_threshold)
    q, p, Q, P = mesh(q0, p0)
    S0 = unforced_safe_mask(q, p, xi, w)
    safe = np.zeros((Om.size, Fv.size, q.size, p.size), bool)
    xt = np.zeros((Om.size, Fv.size))
    # = slow_flow_escapes and xi_true_analytic per control point, bit for bit, with the grid's and
    # the threshold's shared quantities evaluated once
    grid = GridSlowFlow(Q, P, Psi, xi, w)
    checks.check_positive_int("n_gamma", n_gamma)
    for i, om in enumerate(Om):
        for j, f in enumerate(Fv):
            prof = grid.profile(checks.check_scalar("F", f, checks.check_nonnegative),
                                checks.check_scalar("Omega", om, checks.check_positive))
            safe[i, j] = ~grid.escapes(prof) & S0
            xt[i, j] = grid.xi_true(prof, n_gamma=n_gamma, n_xi=n_xi)
    closed = _closed_measures(np.unique(xt), xi, w)
    cm = np.array([closed[x] for x in xt.ravel()]).reshape(xt.shape + (3,))
    da = xr.DataArray(safe, dims=("Omega", "F", "q0", "p0"), coords={"Omega": Om, "F": Fv, "q0": q, "p0": p})
    m = integrity_measures(da, xi_max=xi, well=w)
    ds = m[list(MEASURES)].copy()
    ds["xi_true"] = (("Omega", "F"), xt, {"units": "1", "long_name": "energy radius of the basin safe for every "
                                                                      "phase (H0 < xi_true)"})
    ds["GIM_true"] = (("Omega", "F"), np.where(xt > 0, w.J(xt) / w.J(xi), 0.0),
                      {"units": "1", "long_name": "GIM of the all-phase basin, J(xi_true)/J(xi_max)"})
    ds["LIM_true"] = (("Omega", "F"), cm[..., 1],
                      {"units": "1", "long_name": "LIM of the all-phase basin, r_local(xi_true)/r_local(xi_max) "
                                                  "(sqrt(xi_true/xi_max) for the quartic)"})
    ds["IF_true"] = (("Omega", "F"), cm[..., 2],
                     {"units": "1", "long_name": "IF of the all-phase basin, r_global(xi_true)/r_global(xi_max) "
                                                 "(sqrt(xi_true/xi_max) for the quartic)"})
    ds.attrs.update(well_attrs(w))
    ds.attrs.update(kind="analytic", Psi=Psi, xi_max=xi, fourier=w.fourier, n_gamma=int(n_gamma), n_xi=int(n_xi),
                    method="slow_flow_escapes on the grid per control point; xi_true_analytic for all phases")
    return annotate(ds)


def _closed_measures(xis, xi_max, well):
    """``{x: closed_measures(x, xi_max, well)}`` with the radii of ``xi_max`` computed once."""
    out = {}
    ref = None
    for x in xis:
        if x <= 0:
            out[x] = (0.0, 0.0, 0.0)
            continue
        if ref is None:
            ref = unforced_radii2(xi_max, well), well.J(xi_max)
        (loc_m, glob_m), J_m = ref
        loc_t, glob_t = unforced_radii2(x, well)
        out[x] = (float(well.J(x) / J_m), float(np.sqrt(loc_t / loc_m)), float(np.sqrt(glob_t / glob_m)))
    return out


@api_provenance
def integrity_from_batch(charts: xr.Dataset, t_eval: npt.ArrayLike | None = None) -> xr.Dataset:
    """GIM, LIM, IF per control point and t_eval from an ``escape_chart_batch`` Dataset (one
    energy threshold), over (control, t_eval)."""
    if charts.sizes["xi_max"] != 1:
        raise ValueError(f"an integrity map uses one energy threshold, the charts have {charts.sizes['xi_max']}")
    safe, xi_norm = safe_stack(charts, t_eval, "energy")
    m = integrity_measures(safe.isel(xi_max=0), xi_max=float(xi_norm.values[0]), well=chart_well(charts))
    return m[list(MEASURES)].transpose("control", "t_eval")


@api_provenance
def integrity_map_numeric(Omega: npt.ArrayLike, F: npt.ArrayLike, Psi: float, xi_max: float, q0: npt.ArrayLike,
                          p0: npt.ArrayLike, *, cycles: int = 1000, t_eval: npt.ArrayLike | None = None,
                          well: WellLike = None, **chart_kwargs: Any) -> xr.Dataset:
    """Numeric integrity map over (Omega, F, t_eval): one escape chart per control point (all
    control points in one ensemble), safe = escape_cycle > t_eval."""
    Om, Fv = _control(Omega, F)
    checks.check_scalar("Psi", Psi, checks.check_finite)
    checks.check_scalar("xi_max", xi_max, checks.check_positive)
    OO, FF = np.meshgrid(Om, Fv, indexing="ij")
    charts = escape_chart_batch(q0, p0, FF.ravel(), OO.ravel(), Psi, xi_max=(float(xi_max),), cycles=cycles,
                                well=well, **chart_kwargs)
    m = integrity_from_batch(charts, t_eval)
    ds = xr.Dataset({k: (("Omega", "F", "t_eval"), m[k].values.reshape(Om.size, Fv.size, -1), m[k].attrs)
                     for k in MEASURES},
                    coords={"Omega": Om, "F": Fv, "t_eval": m["t_eval"].values})
    ds.attrs.update(well_attrs(chart_well(charts)))
    ds.attrs.update(kind="numeric", Psi=float(Psi), xi_max=float(xi_max), cycles=int(cycles),
                    steps_per_cycle=charts.attrs["steps_per_cycle"], integrator=charts.attrs["integrator"],
                    **{k: charts.attrs[k] for k in ("damping",) if k in charts.attrs},
                    method="escape_chart_batch per block of control points; safe = escape_cycle > t_eval")
    return annotate(ds)


@api_provenance
def erosion_front(ds: xr.Dataset, level: float = 0.5, measures: Sequence[str] = MEASURES) -> xr.Dataset:
    """The F at which each measure first falls below ``level``, per Omega (and t_eval): variables
    ``F_<measure>`` (NaN where it never does)."""
    level = checks.check_scalar("level", level, checks.check_positive)
    out = xr.Dataset()
    for k in measures:
        out[f"F_{k}"] = level_crossing(ds[k], level, dim="F").assign_attrs(
            units="1", long_name=f"erosion front: first F at which {k} falls below {level:g}")
    return out
