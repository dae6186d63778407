"""analysis.tangency: the escape equation's basin across the Melnikov tangency (beta = 0.1,
Omega = 0.85, F_M = 0.063335, docs/melnikov.md): the local integrity collapses within a few percent
of F_M, the boundary is smooth (alpha = 1) well below it and fractal (alpha < 1) past it."""
from __future__ import annotations

import numpy as np
import pytest

from safebasins import wells
from safebasins.analysis.melnikov import melnikov_threshold
from safebasins.analysis.tangency import fractality_profile, tangency_profile
from safebasins.numerics import escape_chart

CUBIC = wells.resolve_well("cubic")
BOX = ((-0.8, 1.2), (-0.8, 0.8))


@pytest.fixture(scope="module")
def charts():
    q0, p0 = np.linspace(-0.8, 1.2, 81), np.linspace(-0.8, 0.8, 65)
    return [escape_chart(q0, p0, F, 0.85, 0.0, xi_max=(1 / 6,), cycles=300, well=CUBIC, damping=0.1).assign_attrs(F=F)
            for F in (0.04, 0.05, 0.055, 0.06, 0.0625, 0.065, 0.0675, 0.07, 0.08)]


def test_profile_marks_melnikov_and_lim_collapses_there(charts):
    prof = tangency_profile(charts, [50, 300], keep_F=[0.055, 0.07])
    F_M = float(prof["F_melnikov"])
    assert F_M == melnikov_threshold(0.85, 0.1, well=CUBIC)
    F_lim = float(prof["F_LIM"].sel(t_eval=300).squeeze())
    assert abs(F_lim / F_M - 1) < 0.05, F_lim                       # measured 1.01 on a 201^2 grid
    lim = prof["LIM"].sel(t_eval=300).squeeze()
    assert (lim.sel(F=[0.04, 0.05, 0.055]) > 0.9).all() and (lim.sel(F=[0.07, 0.08]) < 0.05).all()
    safe = prof["safe"].squeeze("xi_max")
    assert safe.sel(F_basin=0.055).mean() > 5 * safe.sel(F_basin=0.07).mean()
    assert prof.attrs["damping"] == 0.1


def test_profile_refuses_undamped_charts_and_unknown_basin_F(charts):
    q0 = p0 = np.linspace(-0.5, 0.5, 5)
    undamped = [escape_chart(q0, p0, F, 0.85, 0.0, xi_max=(1 / 6,), cycles=10, well=CUBIC).assign_attrs(F=F)
                for F in (0.01, 0.02)]
    with pytest.raises(ValueError, match="charts: the charts are undamped"):
        tangency_profile(undamped)
    with pytest.raises(ValueError, match="keep_F"):
        tangency_profile(charts, keep_F=[0.0551])


def test_uncertainty_exponent_drops_past_the_tangency():
    fr = fractality_profile([0.055, 0.0675], 0.85, 0.0, 1 / 6, BOX, damping=0.1, n=8000, cycles=300, seed=3,
                            well=CUBIC)
    a, e = fr["alpha"].values, fr["alpha_err"].values
    assert abs(a[0] - 1) < 3 * e[0] + 0.05, (a, e)                  # smooth below F_M
    assert a[1] < 0.8 and a[1] + 3 * e[1] < a[0], (a, e)            # fractal past it (measured 0.57 +- 0.01)
    assert float(fr["F_melnikov"]) == melnikov_threshold(0.85, 0.1, well=CUBIC)
    with pytest.raises(ValueError, match="damping"):
        fractality_profile([0.05], 0.85, 0.0, 1 / 6, BOX, damping=0.0, well=CUBIC)
