"""The damped slow flow warns and prints nothing for valid input: the arithmetic that could
overflow (degenerate Hermite roots, huge s = beta J / (F A) outside the response curve, singular
Newton steps) is guarded where its result is discarded anyway, and Newton stays inside
(0, xi_hi) (a step past the top evaluated the well above its barrier)."""
import warnings

import numpy as np
import pytest

from safebasins import theory
from safebasins.theory.damped import slow_tables
from safebasins.theory.damped_flow import _hermite_max, pivots
from safebasins.theory.responses import fixed_points
from safebasins.wells import resolve_well


@pytest.fixture(autouse=True)
def _strict_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        yield


def _hermite(s, J0, J1, m0, m1):
    return ((2 * s ** 3 - 3 * s ** 2 + 1) * J0 + (s ** 3 - 2 * s ** 2 + s) * m0
            + (-2 * s ** 3 + 3 * s ** 2) * J1 + (s ** 3 - s ** 2) * m1)


def test_hermite_max_is_the_sampled_maximum_also_for_degenerate_cubics():
    rng = np.random.default_rng(3)
    J0, J1 = rng.uniform(0, 1, 400), rng.uniform(0, 1, 400)
    m0, m1 = rng.normal(0, 1, 400), rng.normal(0, 1, 400)
    # degenerate ones: cubic coefficient 6 J0 + 3 m0 - 6 J1 + 3 m1 exactly 0 or tiny, slopes 0,
    # everything 0, and scales far apart (roots near the float range's end)
    m1[:40] = 2 * J1[:40] - 2 * J0[:40] - m0[:40]
    m1[40:60] = 2 * J1[40:60] - 2 * J0[40:60] - m0[40:60] + 1e-300
    m0[60:80] = m1[60:80] = 0.0
    J0[80:90] = J1[80:90] = m0[80:90] = m1[80:90] = 0.0
    J0[90:100], J1[90:100], m0[90:100], m1[90:100] = 1e-200, 1e-200, 1e-305, -1e-305
    got = _hermite_max(J0, J1, m0, m1)
    s = np.linspace(0.0, 1.0, 20001)[:, None]
    dense = _hermite(s, J0, J1, m0, m1).max(axis=0)
    scale = np.maximum.reduce([np.abs(J0), np.abs(J1), np.abs(m0), np.abs(m1), np.full(400, 1e-300)])
    assert np.all(got >= dense - 1e-12 * scale)                    # never below the sampled maximum
    assert np.all(got <= dense + 1e-6 * scale)                     # and not above it (sampling error)


def test_fixed_points_stay_inside_and_quiet_near_the_separatrix():
    """Newton from seeds near the top of the tables (the pendulum at its barrier, weak damping) stays
    in (0, xi_hi): no evaluation of the well above its barrier."""
    w = resolve_well("pendulum")
    tab = slow_tables(w)
    F = np.repeat([0.0, 0.001, 0.01, 0.05, 0.2], 8)
    Om = np.tile(np.linspace(0.5, 1.3, 8), 5)
    for beta in (1e-4, 0.01, 0.5):
        pv = pivots(tab, F, Om, beta, tab.xi_top)
        x = pv.fp.xi[pv.fp.converged]
        assert np.all((x > 0) & (x < tab.xi_top) | (x == 0)), beta


def test_tiny_forcing_is_quiet():
    """s = beta J / (F A) is astronomically large for a tiny F: outside the response curve, no overflow."""
    fp = fixed_points(np.array([1e-300, 1e-200]), np.array([0.9, 0.95]), 0.5, resolve_well(None), 0.2)
    assert fp.converged.sum() == 0 or np.isfinite(fp.xi[fp.converged]).all()
    ds = theory.steady_responses([0.8, 0.9], 1e-250, 0.1)
    assert ds["n_responses"].values.tolist() == [0, 0] or np.isfinite(ds["xi"].values).any()


def test_damped_calls_warn_and_print_nothing(capsys):
    q, p = np.meshgrid(np.linspace(-0.9, 0.9, 9), np.linspace(-0.7, 0.7, 7), indexing="ij")
    for well, xm, F in (("quartic", 0.2, 0.03), ("quartic", 0.249, 0.08), ("cubic", 0.16, 0.05),
                        ("pendulum", 1.9, 0.1)):
        qq, pp = resolve_well(well).ic_window()
        Q, P = np.meshgrid(np.linspace(*qq, 7), np.linspace(*pp, 6), indexing="ij")
        for beta in (0.01, 0.3):
            theory.slow_flow_escapes(Q, P, F, 0.85, np.pi, xm, well=well, damping=beta)
        theory.steady_responses(np.linspace(0.6, 1.2, 7), F, 0.02, well=well)
    theory.critical_forcing([0.7, 0.95], 0.15, damping=0.01)
    theory.slow_trajectory(0.0, 0.0, 0.03, 0.9, 0.2, damping=0.02)
    theory.slow_flow_escapes(q, p, 0.02, 0.9, np.pi, 0.18, damping=0.05)
    out = capsys.readouterr()
    assert out.out == "" and out.err == ""
