"""Analytic safe basins on an initial-condition grid, and their numeric checks (Figs 5-9, 13-17).

Library functions taking arrays and returning Datasets; the pipeline's experiment kinds
(``basin_rm``, ``basin_chart``) and the command line (``safebasins basin|chart``) call them.

* :func:`analytic_basin` -- boundary curves of :func:`safebasins.theory.safe_basin_boundaries`
  (dims ``curve``, ``vertex``) plus the per-IC classification ``escapes(q0, p0)`` of
  :func:`safebasins.theory.slow_flow_escapes` (eqs 18-28);
* :func:`analytic_basin_stack` -- the same stacked over a scanned ``F`` or ``xi_max``;
* :func:`add_resonance_manifold` -- the first integral ``C`` and ``escapes_rm`` on a
  ``(gamma_rm, xi_rm)`` grid of the resonance manifold;
* :func:`numeric_check` -- integrate the analytic-safe ICs and store, per connected part of the
  analytic basin, the fraction the numerics keep (:func:`safebasins.analysis.confirm.confirm_regions`).
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from safebasins.io.provenance import api_provenance

__all__ = ["analytic_basin", "analytic_basin_stack", "add_resonance_manifold", "numeric_check"]


@api_provenance
def analytic_basin(F, Omega, Psi, xi_max, q0, p0, *, well=None, n_points=2000, label=None):
    """Boundaries + per-IC analytic escape mask on the (q0, p0) grid of 1-D axes ``q0``, ``p0``.

    ``well``: any form :func:`safebasins.wells.resolve_well` reads (its first harmonic included);
    ``label`` is printed in the log line."""
    from safebasins.theory import safe_basin_boundaries, slow_flow_escapes

    qa, pa = np.asarray(q0, float), np.asarray(p0, float)
    Q, P = np.meshgrid(qa, pa, indexing="ij")
    print(f"{label or 'basin'}: basin F={F} Omega={Omega} Psi={Psi} xi_max={xi_max}")
    b = safe_basin_boundaries(F, Omega, Psi, xi_max, well=well, n_points=n_points)
    esc = slow_flow_escapes(Q, P, F, Omega, Psi, xi_max, well=well)
    b["escapes"] = xr.DataArray(np.asarray(esc, dtype=bool), dims=("q0", "p0"))
    return b.assign_coords(q0=("q0", qa), p0=("p0", pa))


@api_provenance
def analytic_basin_stack(scan, values, F, Omega, Psi, xi_max, q0, p0, *, well=None, n_points=2000, label=None):
    """Analytic basins stacked over the scanned parameter ``scan`` ("F" or "xi_max", taking
    ``values``; the other one is the scalar argument).  Each basin's saddle point is a coordinate
    along ``scan`` (``saddle_gamma``, ``saddle_xi``); attribute ``scan``."""
    from safebasins.io.datasets import stack

    if scan not in ("F", "xi_max"):
        raise ValueError(f"scan must be 'F' or 'xi_max', got {scan!r}")
    parts = [analytic_basin(v if scan == "F" else F, Omega, Psi, v if scan == "xi_max" else xi_max, q0, p0,
                            well=well, n_points=n_points, label=label) for v in values]
    saddle = {k: [float(b.attrs.get(k, np.nan)) for b in parts] for k in ("saddle_gamma", "saddle_xi")}
    out = stack(parts, scan, values, coords=saddle)
    out.attrs["scan"] = scan
    return out


def add_resonance_manifold(basin, F, Omega, xi_max, *, n_gamma, n_xi, xi_top, well=None):
    """``basin`` with the first integral ``C(gamma_rm, xi_rm)`` (eq 18) and the escape
    classification ``escapes_rm`` on a gamma in [-pi, pi] x xi in [0, xi_top] grid."""
    from safebasins.theory import escapes_on_manifold, first_integral

    g = np.linspace(-np.pi, np.pi, n_gamma)
    x = np.linspace(0.0, xi_top, n_xi)
    G, X = np.meshgrid(g, x, indexing="ij")
    C = first_integral(G, X, F, Omega, well=well)
    E = escapes_on_manifold(G, X, F, Omega, xi_max, well=well)
    out = basin.assign_coords(gamma_rm=("gamma_rm", g), xi_rm=("xi_rm", x))
    out["C"] = (("gamma_rm", "xi_rm"), np.asarray(C, dtype=float))
    out["escapes_rm"] = (("gamma_rm", "xi_rm"), np.asarray(E, dtype=bool))
    return out


@api_provenance
def numeric_check(basin, F, Omega, Psi, xi_max, *, cycles, steps_per_cycle, well=None, threads=None, label=None):
    """Integrate the analytic-safe ICs of ``basin``'s grid for ``cycles`` forcing cycles (energy
    criterion) and store, per connected part of the analytic basin, the fraction the numerics
    keep: ``escape_cycle_numeric(q0, p0)``, ``region(q0, p0)``, ``region_size``,
    ``region_numeric_safe`` (dim ``region_index``), attribute ``check_cycles``."""
    from safebasins.analysis.confirm import confirm_regions
    from safebasins.numerics import escape_chart

    safe = ~np.asarray(basin["escapes"].transpose("q0", "p0").values, bool)
    Q, P = np.meshgrid(basin["q0"].values, basin["p0"].values, indexing="ij")
    ec = np.full(safe.shape, np.nan)
    if safe.any():
        ch = escape_chart(Q[safe], P[safe], F, Omega, Psi, xi_max=(xi_max,), cycles=cycles,
                          steps_per_cycle=steps_per_cycle, threads=threads, grid=False, well=well)
        ec[safe] = np.asarray(ch["escape_cycle_energy"].isel(xi_max=0).values, float)
    lab, size, frac = confirm_regions(safe, ec, cycles)
    out = basin.copy()
    out["escape_cycle_numeric"] = (("q0", "p0"), ec, {
        "units": "1", "long_name": "numeric escape time of the analytic-safe ICs in forcing cycles, energy criterion "
                                   "(inf: not within check_cycles; NaN: analytic escape, not integrated)"})
    out["region"] = (("q0", "p0"), lab, {"units": "1", "long_name": "connected part of the analytic safe basin "
                                                                   "(0: analytic escape; 1 = largest)"})
    out["region_size"] = ("region_index", size, {"units": "1", "long_name": "grid points of the region"})
    out["region_numeric_safe"] = ("region_index", frac, {
        "units": "1", "long_name": "fraction of the region's ICs that do not escape numerically within check_cycles"})
    out = out.assign_coords(region_index=("region_index", np.arange(1, size.size + 1)))
    out.attrs["check_cycles"] = int(cycles)
    print(f"{label or 'basin'}: numeric check of {int(safe.sum())} analytic-safe ICs over "
          f"{cycles} cycles: regions {size.tolist()}, kept {np.round(frac, 3).tolist()}")
    return out
