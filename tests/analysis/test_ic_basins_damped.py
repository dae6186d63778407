"""Damped analytic safe basins: ``analytic_basin(..., damping=beta)`` and its stack.

beta = 0 returns what the undamped call returns; beta > 0 classifies every IC by the damped slow
flow (``slow_flow_escapes(..., damping=beta)``), outlines the safe mask as the boundary curves
and agrees with the damped numerics."""
from __future__ import annotations

import numpy as np
import pytest

from safebasins.analysis.agreement import chart_agreement
from safebasins.analysis.ic_basins import MASK_OUTLINE, analytic_basin, analytic_basin_stack, mask_outline
from safebasins.io.compare import dataset_differences
from safebasins.numerics import escape_chart
from safebasins.theory import slow_flow_escapes

F, OMEGA, PSI = 0.01, 0.9, np.pi
Q = np.linspace(-0.9, 0.9, 60)
P = np.linspace(-0.7, 0.7, 48)


@pytest.fixture(scope="module")
def damped_stack():
    return analytic_basin_stack("xi_max", [0.14, 0.18], F, OMEGA, PSI, None, Q, P, damping=0.01)


def test_zero_damping_is_the_undamped_call_bitwise():
    q, p = Q[::4], P[::4]
    for kw in ({"damping": 0.0}, {"damping": 0}):
        assert dataset_differences(analytic_basin(F, OMEGA, PSI, 0.18, q, p, n_points=64),
                                   analytic_basin(F, OMEGA, PSI, 0.18, q, p, n_points=64, **kw)) == []
        assert dataset_differences(
            analytic_basin_stack("xi_max", [0.14, 0.18], F, OMEGA, PSI, None, q, p, n_points=64),
            analytic_basin_stack("xi_max", [0.14, 0.18], F, OMEGA, PSI, None, q, p, n_points=64, **kw)) == []
    assert "damping" not in analytic_basin(F, OMEGA, PSI, 0.18, q, p, n_points=64, damping=0.0).attrs


def test_damped_basin_is_the_damped_slow_flow_classification(damped_stack):
    for i, xm in enumerate((0.14, 0.18)):
        want = slow_flow_escapes(Q[:, None], P[None, :], F, OMEGA, PSI, xm, damping=0.01)
        got = damped_stack["escapes"].isel(xi_max=i).transpose("q0", "p0").values
        assert np.array_equal(got, want)
        # and not the conservative one: damping enlarges the basin here
        undamped = slow_flow_escapes(Q[:, None], P[None, :], F, OMEGA, PSI, xm)
        assert (~want).sum() > 1.2 * (~undamped).sum()
    assert damped_stack.attrs["damping"] == 0.01 and damped_stack.attrs["boundary"] == MASK_OUTLINE
    assert np.isnan(damped_stack["saddle_xi"].values).all()


def test_mask_outline_runs_between_safe_and_escaping_points(damped_stack):
    b = damped_stack.isel(xi_max=1)
    safe = ~b["escapes"].transpose("q0", "p0").values
    kinds = {str(k) for k in b["kind"].values if str(k)}
    assert kinds == {MASK_OUTLINE}
    idx = b["curve_index"].values
    qv, pv = b["q0_vertex"].values[idx >= 0], b["p0_vertex"].values[idx >= 0]
    assert qv.size > 20 and np.isfinite(qv).all()
    dq, dp = Q[1] - Q[0], P[1] - P[0]
    for x, y in zip(qv, pv):      # each vertex lies on a grid edge joining a safe and an escaping point
        i, j = np.searchsorted(Q, x - 1e-9 * dq) - 1, np.searchsorted(P, y - 1e-9 * dp) - 1
        win = safe[max(i, 0):i + 2, max(j, 0):j + 2]
        assert win.any() and not win.all()
    # the outline's slow phase and energy are those of its vertices
    g, xi = b["gamma"].values[idx >= 0], b["xi"].values[idx >= 0]
    assert np.nanmax(np.abs(g)) <= np.pi and np.nanmin(xi) > 0 and np.isfinite(xi).mean() > 0.9


def test_mask_outline_edge_cases():
    q, p = np.linspace(-0.5, 0.5, 5), np.linspace(-0.5, 0.5, 4)
    for S in (np.zeros((5, 4), bool), np.ones((5, 4), bool)):
        assert mask_outline(S, q, p, 0.0).sizes["curve"] == 0
    with pytest.raises(ValueError, match="safe must have shape"):
        mask_outline(np.zeros((4, 5), bool), q, p, 0.0)


@pytest.mark.parametrize("bad", [-0.01, np.nan, np.inf, [0.01, 0.02]])
def test_bad_damping_is_named(bad):
    with pytest.raises(ValueError, match="damping"):
        analytic_basin(F, OMEGA, PSI, 0.18, Q[:5], P[:5], damping=bad)


def test_damped_basin_agrees_with_the_damped_numerics(damped_stack):
    """Measured (60 x 48 ICs, 300 cycles, beta = 0.01): IoU 0.978 / 0.989 at xi_max = 0.14 / 0.18;
    the undamped theory against the same damped chart: 0.54 / 0.60."""
    ch = escape_chart(Q, P, F, OMEGA, PSI, xi_max=(0.14, 0.18), cycles=300, steps_per_cycle=32, damping=0.01)
    iou = chart_agreement(ch, damped_stack, 300, "xi_max")["iou"].values
    assert (iou > 0.95).all(), iou
    undamped = analytic_basin_stack("xi_max", [0.14, 0.18], F, OMEGA, PSI, None, Q, P, n_points=200)
    assert (chart_agreement(ch, undamped, 300, "xi_max")["iou"].values < 0.75).all()
