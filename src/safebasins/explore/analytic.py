"""The slow-flow pictures of the explorer, from theory calls only.

* :func:`ic_plane`: the safe basin on the plane of initial conditions
  (:func:`~safebasins.theory.slow_flow.slow_flow_escapes`, eq 21), its analytic boundaries
  (:func:`~safebasins.theory.basins.safe_basin_boundaries`, eqs 27-28) and the unforced orbit
  H0 = xi_max (eq 7);
* :func:`manifold`: the first integral C(gamma, xi) on the resonance manifold (eq 18,
  :func:`~safebasins.theory.slow_flow.first_integral`) with the escaping region
  (:func:`~safebasins.theory.slow_flow.escapes_on_manifold`).

With damping (beta > 0) C is not conserved and its level curves bound nothing: the IC
plane shows the damped slow flow's classification
(:func:`~safebasins.theory.slow_flow.slow_flow_escapes` with ``damping``) on a coarser grid
(``DAMPED_IC_GRID``: each IC's slow trajectory is integrated) with the outline of its mask
(:func:`~safebasins.analysis.ic_basins.mask_outline`) as the boundary, and the resonance manifold
classifies each point (gamma, xi) by its damped slow trajectory (the IC at tau = 0 with
theta0 = gamma + Psi) on ``DAMPED_MANIFOLD_GRID``, without level curves.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from safebasins import theory
from safebasins.explore.ranges import WellRanges
from safebasins.analysis.ic_basins import mask_outline

if TYPE_CHECKING:
    import xarray as xr

#: polylines ``(xs, ys, kinds)``: vertex arrays of each boundary curve and its kind
Polylines = tuple[list[NDArray[np.float64]], list[NDArray[np.float64]], list[str]]

__all__ = ["Forcing", "ic_grid", "ic_safe", "ic_plane", "manifold", "pictures", "level_values", "IC_GRID",
           "MANIFOLD_GRID", "DAMPED_IC_GRID", "DAMPED_MANIFOLD_GRID"]

#: grid of the IC-plane picture, and (gamma, xi) points of the manifold picture
IC_GRID = 161
MANIFOLD_GRID = (241, 161)
#: vertices per branch of each analytic boundary curve
BOUNDARY_POINTS = 200
#: level curves of C drawn on the resonance manifold
N_LEVELS = 24
#: largest IC grid and (gamma, xi) grid of the damped pictures (one slow trajectory per point:
#: about 1e4 points per second on one core)
DAMPED_IC_GRID = 81
DAMPED_MANIFOLD_GRID = (97, 65)


@dataclass(frozen=True)
class Forcing:
    """One point of the sliders: forcing amplitude, frequency, phase and the energy threshold."""

    F: float
    Omega: float
    Psi: float
    xi_max: float
    damping: float = 0.0


def ic_grid(r: WellRanges, n: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The axes ``(q0, p0)`` of an ``n x n`` grid over the well's window."""
    return np.linspace(*r.q_window, n), np.linspace(*r.p_window, n)


def ic_safe(r: WellRanges, f: Forcing, n: int) -> NDArray[np.bool_]:
    """Slow-flow safe mask on the ``n x n`` grid, shape (q0, p0) (True = safe)."""
    q0, p0 = ic_grid(r, n)
    return ~theory.slow_flow_escapes(q0[:, None], p0[None, :], F=f.F, Omega=f.Omega, Psi=f.Psi, xi_max=f.xi_max,
                                     well=r.well, damping=f.damping)


def _polylines(boundaries: xr.Dataset) -> Polylines:
    """Vertex lists of each boundary curve on the IC plane (NaN rows kept as breaks)."""
    index = boundaries["curve_index"].values
    q, p = boundaries["q0_vertex"].values, boundaries["p0_vertex"].values
    kinds = [str(k) for k in boundaries["kind"].values] if "kind" in boundaries else []
    xs: list[NDArray[np.float64]] = []
    ys: list[NDArray[np.float64]] = []
    for k in range(len(kinds)):
        rows = index == k
        xs.append(q[rows])
        ys.append(p[rows])
    return xs, ys, kinds


def _orbit(r: WellRanges, xi: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The closed unforced orbit H0 = xi (eq 7) inside the well, as a polyline."""
    q_lo, q_hi = (float(v) for v in r.well.turning_points(xi))
    q = q_lo + (q_hi - q_lo) * 0.5 * (1.0 - np.cos(np.linspace(0.0, np.pi, 200)))
    p = np.sqrt(np.maximum(2.0 * (xi - r.well.V(q)), 0.0))
    return np.concatenate([q, q[::-1]]), np.concatenate([p, -p[::-1]])


def ic_plane(r: WellRanges, f: Forcing, n: int) -> dict[str, Any]:
    """The IC-plane picture: ``safe`` (q0, p0), ``boundaries`` (xs, ys, kinds), ``orbit`` (q, p).
    Damped (``f.damping > 0``): on at most ``DAMPED_IC_GRID`` points per axis, the boundaries the
    outline of the safe mask."""
    if f.damping > 0:
        n = min(n, DAMPED_IC_GRID)
        safe = ic_safe(r, f, n)
        bounds = mask_outline(safe, *ic_grid(r, n), f.Psi, well=r.well)
    else:
        bounds = theory.safe_basin_boundaries(f.F, f.Omega, f.Psi, f.xi_max, well=r.well, n_points=BOUNDARY_POINTS)
        safe = ic_safe(r, f, n)
    return {"safe": safe, "boundaries": _polylines(bounds), "orbit": _orbit(r, f.xi_max)}


def level_values(C: ArrayLike, n_levels: int = N_LEVELS) -> NDArray[np.float64]:
    """Evenly spaced levels strictly inside the range of C (the level C = 0 of the limiting
    phase trajectory through the well bottom is drawn on its own)."""
    lo, hi = float(np.nanmin(C)), float(np.nanmax(C))
    if not hi > lo:
        return np.array([])
    return np.linspace(lo, hi, n_levels + 2)[1:-1]


def manifold(r: WellRanges, f: Forcing, n_gamma: int, n_xi: int) -> dict[str, Any]:
    """The resonance-manifold picture over ``gamma`` in [-pi, pi], ``xi`` in [0, xi_top]:
    ``C`` and ``escapes`` (xi, gamma), ``levels`` of C, the axes ``gamma`` and ``xi``.  Damped
    (``f.damping > 0``): ``escapes`` of each point's damped slow trajectory on at most
    ``DAMPED_MANIFOLD_GRID`` points, no levels (C is not conserved)."""
    if f.damping > 0:
        n_gamma, n_xi = min(n_gamma, DAMPED_MANIFOLD_GRID[0]), min(n_xi, DAMPED_MANIFOLD_GRID[1])
    gamma = np.linspace(-np.pi, np.pi, n_gamma)
    xi = np.linspace(0.0, r.xi_top, n_xi)
    C = theory.first_integral(gamma[None, :], xi[:, None], f.F, f.Omega, well=r.well)
    if f.damping > 0:
        G, X = np.meshgrid(gamma, xi)
        escapes = np.ones(G.shape, bool)
        below = X < f.xi_max           # at or above xi_max: escaped at once
        q0, p0 = r.well.phase_point(G[below] + f.Psi, X[below])
        escapes[below] = theory.slow_flow_escapes(q0, p0, F=f.F, Omega=f.Omega, Psi=f.Psi, xi_max=f.xi_max,
                                                  well=r.well, damping=f.damping)
        return {"gamma": gamma, "xi": xi, "C": C, "escapes": escapes, "levels": np.array([])}
    escapes = theory.escapes_on_manifold(gamma[None, :], xi[:, None], f.F, f.Omega, f.xi_max, well=r.well)
    return {"gamma": gamma, "xi": xi, "C": C, "escapes": escapes, "levels": level_values(C)}


def pictures(r: WellRanges, f: Forcing) -> tuple[dict[str, Any], dict[str, Any]]:
    """Both pictures of one point of the sliders, at the explorer's resolution: ``(ic_plane, manifold)``."""
    return ic_plane(r, f, IC_GRID), manifold(r, f, *MANIFOLD_GRID)
