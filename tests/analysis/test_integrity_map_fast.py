"""The analytic integrity map's shared-grid path gives, bit for bit, what the public
per-control-point functions give: ``slow_flow_escapes``, ``xi_true_analytic``,
``closed_measures`` and the plain-matrix ``unforced_radii2``."""
import numpy as np
import pytest

from safebasins.analysis import integrity
from safebasins.theory.slow_flow_grid import GridSlowFlow
from safebasins.analysis.common import mesh, variant_well
from safebasins.analysis.integrity_map import _closed_measures
from safebasins.analysis.phase_invariant import closed_measures, xi_true_analytic
from safebasins.theory import slow_flow_escapes
from safebasins.wells import resolve_well


def _bits(a):
    return np.asarray(a, float).tobytes()


@pytest.mark.parametrize("well, fourier, xi, Psi", [(None, "paper", 0.18, np.pi), (None, "exact", 0.2, 0.3),
                                                     ("cubic", None, 0.12, 1.0)])
def test_grid_slow_flow_equals_public_functions(well, fourier, xi, Psi):
    w = variant_well(resolve_well(well) if well else None, fourier)
    q, p, Q, P = mesh(np.linspace(-0.7, 0.7, 23), np.linspace(-0.6, 0.6, 19))
    grid = GridSlowFlow(Q, P, Psi, xi, w)
    for om in (0.75, 0.9, 1.05):
        for f in (0.0, 0.01, 0.03, 0.08):
            prof = grid.profile(f, om)
            assert np.array_equal(grid.escapes(prof), slow_flow_escapes(Q, P, f, om, Psi, xi, well=w))
            assert _bits(grid.xi_true(prof, n_gamma=32, n_xi=16)) == \
                _bits(xi_true_analytic(f, om, xi, n_gamma=32, n_xi=16, well=w))


def _radii_plain(xi, w, n=1001):
    lo, hi = (float(np.asarray(t)) for t in w.turning_points(xi))
    q = np.union1d(np.linspace(lo, hi, n), [0.0])
    V2 = 2.0 * np.asarray(w.V(q), float)

    def worst(c):
        return np.max(V2[None, :] - (q[None, :] - c[:, None]) ** 2, axis=1)

    m = worst(q)
    k = int(np.argmin(m))
    c_fine = np.union1d(np.linspace(q[max(k - 1, 0)], q[min(k + 1, q.size - 1)], n), [q[k]])
    return 2.0 * xi - float(np.max(V2 - q * q)), 2.0 * xi - float(min(m[k], np.min(worst(c_fine))))


@pytest.mark.parametrize("name", [None, "cubic", "pendulum"])
def test_unforced_radii2_pruned_equals_plain_matrix(name):
    w = resolve_well(name)
    for xi in np.linspace(1e-4, 0.9 * w.barrier_energy, 7):
        assert _bits(integrity.unforced_radii2(xi, w)) == _bits(_radii_plain(xi, w))


def test_closed_measures_cached_equal():
    w = resolve_well(None)
    xs = np.array([0.0, 0.01, 0.07, 0.15])
    got = _closed_measures(xs, 0.18, w)
    for x in xs:
        assert _bits(got[x]) == _bits(closed_measures(x, 0.18, w))


@pytest.mark.parametrize("well, fourier, xi, Psi, Omega", [(None, ["paper", "exact"], [0.15, 0.2], 0.0, 0.9),
                                                            ("cubic", None, [0.1], 1.0, 0.95)])
def test_erosion_masks_equal_slow_flow_escapes_per_F(well, fourier, xi, Psi, Omega):
    """analytic_safe_masks (shared grid) = ~slow_flow_escapes & S0 per F, xi_max, variant."""
    from safebasins.analysis.common import well_variants
    from safebasins.analysis.erosion import analytic_safe_masks
    from safebasins.analysis.integrity import unforced_safe_mask

    F = [0.0, 0.01, 0.03, 0.06]
    q, p, Q, P = mesh(np.linspace(-1.0, 1.0, 25), np.linspace(-0.72, 0.72, 21))
    masks = analytic_safe_masks(F, Omega, Psi, xi, q, p, fourier=fourier, well=well)
    names, wl, scalar = well_variants(resolve_well(well) if well else None, fourier)
    got = masks.values[None] if scalar else masks.values
    assert got.any() and not got.all()
    for a, w in enumerate(wl):
        for i, f in enumerate(F):
            for j, x in enumerate(xi):
                S0 = unforced_safe_mask(q, p, np.array([x]), wl[0])[0]
                assert np.array_equal(got[a, i, j], ~np.asarray(slow_flow_escapes(Q, P, f, Omega, Psi, x, well=w)) & S0)
