"""Analytic safe basins on an initial-condition grid, and their numeric checks (Figs 5-9, 13-17).

Library functions taking arrays and returning Datasets; the pipeline's experiment kinds
(``basin_rm``, ``basin_chart``) and the command line (``safebasins basin|chart``) call them.

* :func:`analytic_basin` -- boundary curves of :func:`safebasins.theory.safe_basin_boundaries`
  (dims ``curve``, ``vertex``) plus the per-IC classification ``escapes(q0, p0)`` of
  :func:`safebasins.theory.slow_flow_escapes` (eqs 18-28); with damping (beta > 0) the
  classification of the damped slow flow and, as its boundary, the outline of the safe mask
  (:func:`mask_outline`: the level curves of C are no trajectories there);
* :func:`analytic_basin_stack` -- the same stacked over a scanned ``F`` or ``xi_max``;
* :func:`add_resonance_manifold` -- the first integral ``C`` and ``escapes_rm`` on a
  ``(gamma_rm, xi_rm)`` grid of the resonance manifold;
* :func:`numeric_check` -- integrate the analytic-safe ICs and store, per connected part of the
  analytic basin, the fraction the numerics keep (:func:`safebasins.analysis.confirm.confirm_regions`).

They print nothing unless given a ``label`` (the pipeline's and the command line's log name): then
one progress line each, for the job's log.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Literal, cast

import numpy as np
import numpy.typing as npt
import xarray as xr
import contourpy

from safebasins.core import checks
from safebasins.wells.provenance import api_provenance
from safebasins.wells import resolve_well
from safebasins.wells.base import WellLike
from safebasins.theory import safe_basin_boundaries, slow_flow_escapes, escapes_on_manifold, first_integral
from safebasins.core.stacking import stack
from safebasins.analysis.confirm import confirm_regions
from safebasins.numerics import escape_chart

__all__ = ["analytic_basin", "analytic_basin_stack", "add_resonance_manifold", "numeric_check", "mask_outline",
           "MASK_OUTLINE"]

#: ``kind`` of the boundary curves of a damped basin (:func:`mask_outline`) and the value of its
#: attribute ``boundary``
MASK_OUTLINE = "mask_outline"


def _log(label, text):
    """One progress line for a job's log, only when the caller names the job (``label``)."""
    if label:
        print(f"{label}: {text}", flush=True)


@api_provenance
def mask_outline(safe: npt.ArrayLike, q0: npt.ArrayLike, p0: npt.ArrayLike, Psi: float, *,
                 well: WellLike = None) -> xr.Dataset:
    """The outline of a safe mask on the IC grid as boundary curves in the layout of
    :func:`safebasins.theory.safe_basin_boundaries` (dims ``curve``, ``vertex``).

    ``safe``: bool array over (q0, p0) (1-D axes ``q0``, ``p0``).  The curves are the 1/2 level
    of the mask (marching squares: vertices half-way between a safe and an escaping grid point;
    a curve ends where it meets the grid's edge), ``kind`` ``"mask_outline"``; ``C_level``,
    ``ray``, ``xi_top`` are NaN and ``safe_sign`` 0 (no level of C bounds a damped basin);
    ``gamma`` (slow phase ``theta - Psi`` wrapped to [-pi, pi], NaN at a wrap so that a curve on
    the resonance manifold is split there) and ``xi`` of each vertex from the well's action-angle
    map (NaN outside the well).  The outline is as fine as the grid: within half a grid step of
    the true boundary of the classification."""
    w = resolve_well(well)
    qa, pa = np.asarray(q0, float), np.asarray(p0, float)
    S = np.asarray(safe, bool)
    if S.shape != (qa.size, pa.size):
        raise ValueError(f"safe must have shape (len(q0), len(p0)) = {(qa.size, pa.size)}, got {S.shape}")
    lines: list[npt.NDArray[np.float64]] = []
    if S.any() and not S.all() and qa.size > 1 and pa.size > 1:
        gen = contourpy.contour_generator(qa, pa, S.T.astype(float), line_type="Separate")
        # line_type Separate: a list of (n, 2) point arrays (lines() is typed as every line type's return)
        lines = [ln for ln in cast(list[npt.NDArray[np.float64]], gen.lines(0.5)) if len(ln) > 1]
    qv = np.concatenate([ln[:, 0] for ln in lines]) if lines else np.empty(0)
    pv = np.concatenate([ln[:, 1] for ln in lines]) if lines else np.empty(0)
    idx = np.concatenate([np.full(len(ln), k, np.int64) for k, ln in enumerate(lines)]) if lines else \
        np.empty(0, np.int64)
    gam, xi = np.full(qv.shape, np.nan), np.full(qv.shape, np.nan)
    inside = w.in_well(qv) & (w.H0(qv, pv) < w.barrier_energy) if qv.size else np.zeros(0, bool)
    if inside.any():
        th, x = w.angle_energy(qv[inside], pv[inside])
        gam[inside] = np.angle(np.exp(1j * (np.asarray(th, float) - float(Psi))))
        xi[inside] = x
    wrap = np.r_[False, (np.abs(np.diff(gam)) > np.pi) & (idx[1:] == idx[:-1])] if gam.size else np.zeros(0, bool)
    gam[wrap] = xi[wrap] = np.nan
    n = len(lines)
    return xr.Dataset(
        {
            "kind": ("curve", np.full(n, MASK_OUTLINE), {"long_name": "safe-basin boundary type (mask_outline: "
                                                                      "outline of the analytic safe mask)"}),
            "C_level": ("curve", np.full(n, np.nan), {"units": "1", "long_name": "value of the first integral C "
                                                                             "(eq 18) on the boundary (none here)"}),
            "ray": ("curve", np.full(n, np.nan), {"units": "rad", "long_name": "slow phase of the tangency or "
                                                                               "saddle point (none here)"}),
            "xi_top": ("curve", np.full(n, np.nan), {"units": "1", "long_name": "energy of the tangency or saddle "
                                                                               "point (none here)"}),
            "safe_sign": ("curve", np.zeros(n, np.int8), {"long_name": "safe side (0: not a level curve of C)"}),
            "gamma": ("vertex", gam, {"units": "rad", "long_name": "slow phase gamma = theta - Psi - Omega tau"}),
            "xi": ("vertex", xi, {"units": "1", "long_name": "averaged energy"}),
            "q0_vertex": ("vertex", qv, {"units": "1", "long_name": "initial displacement"}),
            "p0_vertex": ("vertex", pv, {"units": "1", "long_name": "initial momentum"}),
            "curve_index": ("vertex", idx, {"long_name": "index of the curve a vertex belongs to"}),
        },
        attrs={"boundary": MASK_OUTLINE})


@api_provenance
def analytic_basin(F: float, Omega: float, Psi: float, xi_max: float, q0: npt.ArrayLike, p0: npt.ArrayLike, *,
                   well: WellLike = None, n_points: int = 2000, label: str | None = None,
                   damping: float = 0.0) -> xr.Dataset:
    """Boundaries + per-IC analytic escape mask on the (q0, p0) grid of 1-D axes ``q0``, ``p0``.

    ``well``: any form :func:`safebasins.wells.resolve_well` reads (its first harmonic included);
    ``label``: the name of a progress line printed for a job's log (None: nothing printed).  ``damping`` (beta >= 0,
    default 0: the paper's conservative slow flow, output as before damping existed): for beta > 0 ``escapes`` is the
    classification of the damped slow flow (``slow_flow_escapes(..., damping=beta)``,
    docs/damping.md; undecided trajectories count as escaping) and the boundary curves are the
    outline of its safe mask (:func:`mask_outline`, attribute ``boundary = "mask_outline"``;
    ``n_points`` unused), attribute ``damping``."""
    beta = checks.check_damping(damping)
    qa, pa = np.asarray(q0, float), np.asarray(p0, float)
    Q, P = np.meshgrid(qa, pa, indexing="ij")
    if beta > 0:
        _log(label, f"damped basin F={F} Omega={Omega} Psi={Psi} xi_max={xi_max} beta={beta}")
        esc = np.asarray(slow_flow_escapes(Q, P, F, Omega, Psi, xi_max, well=well, damping=beta), dtype=bool)
        b = mask_outline(~esc, qa, pa, Psi, well=well)
        b.attrs.update(F=float(F), Omega=float(Omega), Psi=float(Psi), xi_max=float(xi_max), damping=beta,
                       saddle_gamma=np.nan, saddle_xi=np.nan)
        b["escapes"] = xr.DataArray(esc, dims=("q0", "p0"))
        return b.assign_coords(q0=("q0", qa), p0=("p0", pa))
    _log(label, f"basin F={F} Omega={Omega} Psi={Psi} xi_max={xi_max}")
    b = safe_basin_boundaries(F, Omega, Psi, xi_max, well=well, n_points=n_points)
    esc = slow_flow_escapes(Q, P, F, Omega, Psi, xi_max, well=well)
    b["escapes"] = xr.DataArray(np.asarray(esc, dtype=bool), dims=("q0", "p0"))
    return b.assign_coords(q0=("q0", qa), p0=("p0", pa))


@api_provenance
def analytic_basin_stack(scan: Literal["F", "xi_max"], values: Sequence[float], F: float | None, Omega: float,
                         Psi: float, xi_max: float | None, q0: npt.ArrayLike, p0: npt.ArrayLike, *,
                         well: WellLike = None, n_points: int = 2000, label: str | None = None,
                         damping: float = 0.0) -> xr.Dataset:
    """Analytic basins stacked over the scanned parameter ``scan`` ("F" or "xi_max", taking
    ``values``; the other one is the scalar argument).  Each basin's saddle point is a coordinate
    along ``scan`` (``saddle_gamma``, ``saddle_xi``; NaN for a damped basin); attribute ``scan``.
    ``damping``: as :func:`analytic_basin`."""
    if scan not in ("F", "xi_max"):
        raise ValueError(f"scan must be 'F' or 'xi_max', got {scan!r}")
    # the scanned one of F, xi_max may be None (unused): the other one is a float
    parts = [analytic_basin(v if scan == "F" else cast(float, F), Omega, Psi,
                            v if scan == "xi_max" else cast(float, xi_max), q0, p0,
                            well=well, n_points=n_points, label=label, damping=damping) for v in values]
    saddle = {k: [float(b.attrs.get(k, np.nan)) for b in parts] for k in ("saddle_gamma", "saddle_xi")}
    out = stack(parts, scan, values, coords=saddle)
    out.attrs["scan"] = scan
    return out


def add_resonance_manifold(basin: xr.Dataset, F: float, Omega: float, xi_max: float, *, n_gamma: int, n_xi: int,
                           xi_top: float, well: WellLike = None) -> xr.Dataset:
    """``basin`` with the first integral ``C(gamma_rm, xi_rm)`` (eq 18) and the escape
    classification ``escapes_rm`` on a gamma in [-pi, pi] x xi in [0, xi_top] grid."""
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
def numeric_check(basin: xr.Dataset, F: float, Omega: float, Psi: float, xi_max: float, *, cycles: int,
                  steps_per_cycle: int, well: WellLike = None, threads: int | None = None,
                  label: str | None = None) -> xr.Dataset:
    """Integrate the analytic-safe ICs of ``basin``'s grid for ``cycles`` forcing cycles (energy
    criterion) and store, per connected part of the analytic basin, the fraction the numerics
    keep: ``escape_cycle_numeric(q0, p0)``, ``region(q0, p0)``, ``region_size``,
    ``region_numeric_safe`` (dim ``region_index``), attribute ``check_cycles``.  The numerics
    integrate the equation of the basin: with its ``damping`` attribute (a damped basin of
    :func:`analytic_basin`) the damped one.  ``label``: as :func:`analytic_basin`."""
    beta = checks.check_damping(basin.attrs.get("damping", 0.0))
    safe = ~np.asarray(basin["escapes"].transpose("q0", "p0").values, bool)
    Q, P = np.meshgrid(basin["q0"].values, basin["p0"].values, indexing="ij")
    ec = np.full(safe.shape, np.nan)
    if safe.any():
        ch = escape_chart(Q[safe], P[safe], F, Omega, Psi, xi_max=(xi_max,), cycles=cycles,
                          steps_per_cycle=steps_per_cycle, threads=threads, grid=False, well=well, damping=beta)
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
    _log(label, f"numeric check of {int(safe.sum())} analytic-safe ICs over {cycles} cycles: regions "
                f"{size.tolist()}, kept {np.round(frac, 3).tolist()}")
    return out
