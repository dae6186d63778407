"""The slow-flow pictures of the explorer, from theory calls only.

* :func:`ic_plane`: the safe basin on the plane of initial conditions
  (:func:`~safebasins.theory.slow_flow.slow_flow_escapes`, eq 21), its analytic boundaries
  (:func:`~safebasins.theory.basins.safe_basin_boundaries`, eqs 27-28) and the unforced orbit
  H0 = xi_max (eq 7);
* :func:`manifold`: the first integral C(gamma, xi) on the resonance manifold (eq 18,
  :func:`~safebasins.theory.slow_flow.first_integral`) with the escaping region
  (:func:`~safebasins.theory.slow_flow.escapes_on_manifold`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from safebasins import theory
from safebasins.explore.ranges import WellRanges

__all__ = ["Forcing", "ic_grid", "ic_safe", "ic_plane", "manifold", "level_values"]

#: vertices per branch of each analytic boundary curve
BOUNDARY_POINTS = 200
#: level curves of C drawn on the resonance manifold
N_LEVELS = 24


@dataclass(frozen=True)
class Forcing:
    """One point of the sliders: forcing amplitude, frequency, phase and the energy threshold."""

    F: float
    Omega: float
    Psi: float
    xi_max: float


def ic_grid(r: WellRanges, n: int):
    """The axes ``(q0, p0)`` of an ``n x n`` grid over the well's window."""
    return np.linspace(*r.q_window, n), np.linspace(*r.p_window, n)


def ic_safe(r: WellRanges, f: Forcing, n: int):
    """Slow-flow safe mask on the ``n x n`` grid, shape (q0, p0) (True = safe)."""
    q0, p0 = ic_grid(r, n)
    return ~theory.slow_flow_escapes(q0[:, None], p0[None, :], F=f.F, Omega=f.Omega, Psi=f.Psi, xi_max=f.xi_max,
                                     well=r.well)


def _polylines(boundaries):
    """Vertex lists of each boundary curve on the IC plane (NaN rows kept as breaks)."""
    index = boundaries["curve_index"].values
    q, p = boundaries["q0_vertex"].values, boundaries["p0_vertex"].values
    kinds = [str(k) for k in boundaries["kind"].values] if "kind" in boundaries else []
    xs, ys = [], []
    for k in range(len(kinds)):
        rows = index == k
        xs.append(q[rows])
        ys.append(p[rows])
    return xs, ys, kinds


def _orbit(r: WellRanges, xi):
    """The closed unforced orbit H0 = xi (eq 7) inside the well, as a polyline."""
    q_lo, q_hi = (float(v) for v in r.well.turning_points(xi))
    q = q_lo + (q_hi - q_lo) * 0.5 * (1.0 - np.cos(np.linspace(0.0, np.pi, 200)))
    p = np.sqrt(np.maximum(2.0 * (xi - r.well.V(q)), 0.0))
    return np.concatenate([q, q[::-1]]), np.concatenate([p, -p[::-1]])


def ic_plane(r: WellRanges, f: Forcing, n: int) -> dict:
    """The IC-plane picture: ``safe`` (q0, p0), ``boundaries`` (xs, ys, kinds), ``orbit`` (q, p)."""
    bounds = theory.safe_basin_boundaries(f.F, f.Omega, f.Psi, f.xi_max, well=r.well, n_points=BOUNDARY_POINTS)
    return {"safe": ic_safe(r, f, n), "boundaries": _polylines(bounds), "orbit": _orbit(r, f.xi_max)}


def level_values(C, n_levels=N_LEVELS):
    """Evenly spaced levels strictly inside the range of C (the level C = 0 of the limiting
    phase trajectory through the well bottom is drawn on its own)."""
    lo, hi = float(np.nanmin(C)), float(np.nanmax(C))
    if not hi > lo:
        return np.array([])
    return np.linspace(lo, hi, n_levels + 2)[1:-1]


def manifold(r: WellRanges, f: Forcing, n_gamma: int, n_xi: int) -> dict:
    """The resonance-manifold picture over ``gamma`` in [-pi, pi], ``xi`` in [0, xi_top]:
    ``C`` and ``escapes`` (xi, gamma), ``levels`` of C, the axes ``gamma`` and ``xi``."""
    gamma = np.linspace(-np.pi, np.pi, n_gamma)
    xi = np.linspace(0.0, r.xi_top, n_xi)
    C = theory.first_integral(gamma[None, :], xi[:, None], f.F, f.Omega, well=r.well)
    escapes = theory.escapes_on_manifold(gamma[None, :], xi[:, None], f.F, f.Omega, f.xi_max, well=r.well)
    return {"gamma": gamma, "xi": xi, "C": C, "escapes": escapes, "levels": level_values(C)}
