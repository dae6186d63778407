"""Escape left / safe / escape right of the quartic: the sides agree with scipy's DOP853 runs of
the same initial conditions, a smooth two-sided case is not Wada, a one-sided well is refused,
and an IC escaped by the energy criterion without a barrier crossing keeps a label of its own."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from safebasins.analysis.basin_labels import SAFE
from safebasins.analysis.basin_sides import ESCAPED_LEFT, ESCAPED_RIGHT, NO_CROSSING, side_labels
from safebasins.analysis.wada import wada_test
from safebasins.numerics import escape_chart
from safebasins.wells import cubic

OMEGA, PSI = 0.9, np.pi        # Fig 14's forcing


def chart(F, damping, n=41, cycles=30, **kw):
    q, p = np.linspace(-1.0, 1.0, n), np.linspace(-0.75, 0.75, n)
    kw = kw or dict(xi_max=(), q_max=(1.0,))
    return escape_chart(q, p, F, OMEGA, PSI, cycles=cycles, damping=damping, grid=True, **kw)


def dop853_label(q0, p0, F, damping, cycles):
    """First barrier crossing of q'' + beta q' + q - q^3 = F sin(Omega t + Psi) by DOP853."""
    def rhs(t, y):
        return [y[1], -damping * y[1] - y[0] + y[0] ** 3 + F * np.sin(OMEGA * t + PSI)]
    right = lambda t, y: y[0] - 1.0
    left = lambda t, y: y[0] + 1.0
    right.terminal = left.terminal = True
    right.direction, left.direction = 1, -1
    s = solve_ivp(rhs, (0.0, 2 * np.pi / OMEGA * cycles), [q0, p0], method="DOP853", rtol=1e-11, atol=1e-12,
                  events=(left, right))
    if s.t_events[1].size:
        return ESCAPED_RIGHT
    return ESCAPED_LEFT if s.t_events[0].size else SAFE


@pytest.mark.parametrize("F, damping", [(0.2, 0.1), (0.01, 0.0)])
def test_sides_agree_with_dop853(F, damping):
    """Every IC whose four grid neighbours share its label (away from the fractal boundary, where
    one step of difference can change the side) has DOP853's label; all sampled ICs but a few."""
    lab = side_labels(chart(F, damping), criterion="displacement")
    L = lab.values
    assert lab.attrs["n_no_crossing"] == 0
    assert lab.attrs["n_escaped_left"] > 50 and lab.attrs["n_escaped_right"] > 50 and (L == SAFE).sum() > 50
    rng = np.random.default_rng(5)
    idx = rng.choice(L.size, 40, replace=False)
    agree = interior = interior_agree = 0
    for i, j in zip(*np.unravel_index(idx, L.shape)):
        ok = dop853_label(lab.q0.values[i], lab.p0.values[j], F, damping, 30) == L[i, j]
        agree += ok
        nb = L[max(i - 1, 0):i + 2, max(j - 1, 0):j + 2]
        if (nb == L[i, j]).all():
            interior += 1
            interior_agree += ok
    assert interior >= 15 and interior_agree == interior
    assert agree >= 36


def test_smooth_two_sided_case_is_not_wada():
    """Damped, F = 0.01 far below the Melnikov threshold (0.085): smooth stable manifolds of the
    two hilltop saddles, so the safe basin's merged boundary is both others' and each escape's
    boundary lies wholly far from the other escape's."""
    w = wada_test(side_labels(chart(0.01, 0.1, n=81), criterion="displacement"))
    assert not w["wada"].item() and (w["W"] > 0.9).all() and w.attrs["max_hausdorff"] > 25


def test_energy_escape_without_crossing_is_its_own_label():
    """Above xi_max at t = 0 is escape by the energy criterion; damped, such an IC can fall back
    into the well without crossing: label 3, never a guessed side."""
    lab = side_labels(chart(0.01, 0.1, xi_max=(0.25,)))
    assert lab.attrs["n_no_crossing"] > 0
    assert lab.sel(q0=0.0, p0=0.75, method="nearest").item() == NO_CROSSING
    assert sorted(np.unique(lab.values).tolist()) == [0, 1, 2, 3]


def test_one_sided_well_and_wrong_well_refused():
    q, p = np.linspace(-0.5, 0.9, 5), np.linspace(-0.3, 0.3, 5)
    ch = escape_chart(q, p, 0.01, 1.0, 0.0, xi_max=(0.15,), well=cubic(), cycles=2, grid=True)
    with pytest.raises(ValueError, match="well: the .* one barrier"):
        side_labels(ch, well=cubic())
    with pytest.raises(ValueError, match="not the chart's well"):
        side_labels(ch)
    with pytest.raises(ValueError, match="extra_cycles"):
        side_labels(chart(0.01, 0.0, n=5, cycles=2), extra_cycles=-1)
