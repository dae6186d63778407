"""The analytic integrity map as computed before the shared slow-flow grid (one ``slow_flow_escapes`` and one
``xi_true_analytic`` per control point, ``closed_measures`` per distinct xi_true), kept as the
reference of ``bench_integrity_map.py --analytic``: same control points, same grid, the
arrays the map is made of."""
from __future__ import annotations

import numpy as np

from safebasins.analysis.common import mesh, variant_well
from safebasins.analysis.integrity import unforced_safe_mask
from safebasins.analysis.phase_invariant import xi_true_analytic
from safebasins.theory import slow_flow_escapes


def reference_arrays(Omega, F, Psi, xi_max, q0, p0, *, fourier=None, n_gamma=128, n_xi=64, well=None):
    """(safe, xi_true, closed measures) of ``integrity_map_analytic`` by the pre-issue-20 loop."""
    Om, Fv = np.atleast_1d(np.asarray(Omega, float)), np.atleast_1d(np.asarray(F, float))
    w = variant_well(well, fourier)
    xi = float(xi_max)
    q, p, Q, P = mesh(q0, p0)
    S0 = unforced_safe_mask(q, p, xi, w)
    safe = np.zeros((Om.size, Fv.size, q.size, p.size), bool)
    xt = np.zeros((Om.size, Fv.size))
    for i, om in enumerate(Om):
        for j, f in enumerate(Fv):
            safe[i, j] = ~np.asarray(slow_flow_escapes(Q, P, f, om, Psi, xi, well=w), bool) & S0
            xt[i, j] = xi_true_analytic(f, om, xi, n_gamma=n_gamma, n_xi=n_xi, well=w)
    closed = {x: _closed_measures(x, xi, w) for x in np.unique(xt)}
    cm = np.array([closed[x] for x in xt.ravel()]).reshape(xt.shape + (3,))
    return safe, xt, cm


def _unforced_radii2(xi, w, n=1001):
    """``analysis.integrity.unforced_radii2`` before the shared grid: the full (c, q) matrices."""
    lo, hi = (float(np.asarray(t)) for t in w.turning_points(xi))
    q = np.union1d(np.linspace(lo, hi, n), [0.0])
    V2 = 2.0 * np.asarray(w.V(q), float)
    r_local2 = 2.0 * xi - float(np.max(V2 - q * q))

    def worst(c):
        return np.max(V2[None, :] - (q[None, :] - c[:, None]) ** 2, axis=1)

    m = worst(q)
    k = int(np.argmin(m))
    c_fine = np.union1d(np.linspace(q[max(k - 1, 0)], q[min(k + 1, q.size - 1)], n), [q[k]])
    return r_local2, 2.0 * xi - float(min(m[k], np.min(worst(c_fine))))


def _closed_measures(xi_true, xi_max, w):
    """``analysis.phase_invariant.closed_measures`` before the shared grid."""
    if xi_true <= 0:
        return 0.0, 0.0, 0.0
    loc_t, glob_t = _unforced_radii2(xi_true, w)
    loc_m, glob_m = _unforced_radii2(xi_max, w)
    return float(w.J(xi_true) / w.J(xi_max)), float(np.sqrt(loc_t / loc_m)), float(np.sqrt(glob_t / glob_m))
