"""The grid classifier (one IC grid, many control points, F-independent tables shared) is the
escape criterion of the points one by one: the same booleans as ``escapes_on_manifold`` at each
IC's ``(theta - Psi, xi)``, with ICs outside the well or at/above xi_max escaping; with shared
tables (``reuse=True``) and without, for the quartic (both first harmonics), an asymmetric and a
tabulated well."""
import numpy as np
import pytest

from safebasins.theory import escapes_on_manifold, slow_flow_escapes
from safebasins.theory.slow_flow_grid import GridSlowFlow
from safebasins.wells import resolve_well


def _one_by_one(Q, P, F, Om, Psi, xi_max, w):
    out = np.ones(Q.shape, bool)
    for idx in np.ndindex(Q.shape):
        q, p = Q[idx], P[idx]
        if not (w.in_well(np.asarray(q)) and w.H0(q, p) < xi_max):
            continue
        theta, xi = w.angle_energy(np.asarray(q), np.asarray(p))
        out[idx] = bool(escapes_on_manifold(float(theta) - Psi, float(xi), F, Om, xi_max, well=w))
    return out


@pytest.mark.parametrize("well, fourier, frac, Psi", [(None, "paper", 0.72, np.pi), (None, "exact", 0.8, 0.3),
                                                      ("cubic", None, 0.7, 1.0), ("pendulum", None, 0.6, 2.0)])
def test_grid_equals_points_one_by_one(well, fourier, frac, Psi):
    w = resolve_well(well, fourier)
    xi_max = frac * w.barrier_energy
    q = np.linspace(-0.9, 0.9, 13) * float(np.max(np.abs(w.turning_points(w.barrier_energy))))
    Q, P = np.meshgrid(q, np.linspace(-0.7, 0.7, 11), indexing="ij")
    shared = GridSlowFlow(Q, P, Psi, xi_max, w)
    single = GridSlowFlow(Q, P, Psi, xi_max, w, reuse=False)
    n_safe = n_escape = 0
    for F, Om in ((0.0, 0.9), (0.01, 0.8), (0.03, 0.95), (0.06, 1.05)):
        want = _one_by_one(Q, P, F, Om, Psi, xi_max, w)
        assert np.array_equal(shared.escapes(shared.profile(F, Om)), want)
        assert np.array_equal(single.escapes(single.profile(F, Om)), want)
        assert np.array_equal(slow_flow_escapes(Q, P, F, Om, Psi, xi_max, well=w), want)
        n_safe += int((~want).sum())
        n_escape += int(want.sum())
    assert n_safe > 20 and n_escape > 20          # both classes present: the comparison can fail


def test_grid_detects_a_changed_criterion():
    """A classifier that differs in one point is told apart (the test above can fail)."""
    w = resolve_well(None)
    Q, P = np.meshgrid(np.linspace(-0.6, 0.6, 9), np.linspace(-0.5, 0.5, 7), indexing="ij")
    grid = GridSlowFlow(Q, P, np.pi, 0.18, w)
    got = grid.escapes(grid.profile(0.03, 0.9))
    want = _one_by_one(Q, P, 0.03, 0.9, np.pi, 0.18, w)
    want[4, 3] = ~want[4, 3]
    assert not np.array_equal(got, want)
