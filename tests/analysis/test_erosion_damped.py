"""Damped erosion profiles: the analytic profile of the damped slow flow against its independent
routes (the per-F damped classification, the damped numerics, the undamped limit beta -> 0).

Small grids (a damped slow trajectory per IC costs hundreds of level-curve tests).
"""
import numpy as np
import pytest

from safebasins.analysis import erosion
from safebasins.analysis.integrity import unforced_safe_mask
from safebasins.theory import slow_flow_escapes
from safebasins.theory.damped_escape import slow_flow_outcomes
from safebasins.theory.damped_flow import UNDECIDED
from safebasins.wells import resolve_well

Q = np.linspace(-0.85, 0.85, 25)
P = np.linspace(-0.7, 0.7, 25)
#: |analytic - numeric| safe fraction of the grid allowed at a point of the damped erosion
#: (measured 0.005 at beta = 0.05, Omega = 0.85, xi_max = 0.18; up to 0.04 at xi_max = 0.22, beta = 0.02,
#: where the undamped theory against the undamped numerics is off by 0.026 too)
FRACTION_TOL = 0.02


def test_damped_masks_are_the_damped_slow_flow_per_F():
    q, p = np.linspace(-0.85, 0.85, 13), np.linspace(-0.7, 0.7, 11)
    F, beta, xi = [0.03, 0.05], 0.05, 0.18
    ds = erosion.erosion_profile_analytic(F, 0.85, np.pi, xi, q, p, damping=beta, keep_masks=True)
    assert ds.attrs["damping"] == beta and ds["safe"].attrs["damping"] == beta
    QQ, PP = np.meshgrid(q, p, indexing="ij")
    S0 = unforced_safe_mask(q, p, np.array([xi]), resolve_well(None))[0]
    for i, f in enumerate(F):
        ref = ~np.asarray(slow_flow_escapes(QQ, PP, f, 0.85, np.pi, xi, damping=beta), bool) & S0
        np.testing.assert_array_equal(ds["safe"].isel(F=i, xi_max=0).values, ref)
        und = np.count_nonzero(slow_flow_outcomes(QQ, PP, f, 0.85, np.pi, xi, beta) == UNDECIDED)
        assert int(ds["n_undecided"].isel(F=i, xi_max=0)) == und


def test_damped_profile_follows_the_damped_numerics():
    F, beta, Om, xi, cycles = [0.0, 0.045, 0.06], 0.05, 0.85, 0.18, 300
    ana = erosion.erosion_profile_analytic(F, Om, np.pi, xi, Q, P, damping=beta, keep_masks=True)
    und = erosion.erosion_profile_analytic(F, Om, np.pi, xi, Q, P, keep_masks=True)
    num, charts = erosion.erosion_profile_numeric(F, Om, np.pi, xi, Q, P, cycles=cycles, damping=beta,
                                                  keep_charts=True)
    assert num.attrs["damping"] == charts.attrs["damping"] == beta and "damping" not in und.attrs
    f_ana = ana["safe"].mean(("q0", "p0")).values.ravel()
    f_und = und["safe"].mean(("q0", "p0")).values.ravel()
    f_num = (charts["escape_cycle_energy"] > cycles).mean(("q0", "p0")).values.ravel()
    assert f_ana[0] == f_num[0] > 0.4                      # F = 0: every IC of S0 settles at the bottom
    np.testing.assert_array_equal(ana[["GIM", "LIM", "IF"]].isel(F=0).to_array().values, 1.0)
    err, err_undamped = np.abs(f_ana - f_num), np.abs(f_und - f_num)
    assert err.max() <= FRACTION_TOL, (f_ana, f_num)
    # damping matters here: the undamped theory misses the damped numerics by far more
    assert err_undamped[1:].min() > 5 * max(err.max(), 0.01), (f_und, f_num)


def test_small_damping_recovers_the_undamped_profile():
    q, p = np.linspace(-0.85, 0.85, 21), np.linspace(-0.7, 0.7, 21)
    kw = dict(keep_masks=True)
    base = erosion.erosion_profile_analytic([0.03], 0.9, np.pi, 0.2, q, p, **kw)
    diff = {}
    for beta in (1e-2, 3e-4):
        d = erosion.erosion_profile_analytic([0.03], 0.9, np.pi, 0.2, q, p, damping=beta, **kw)
        diff[beta] = (int((d["safe"] != base["safe"]).sum()), float(np.abs(d["GIM"] - base["GIM"]).max()))
    # measured: 23 pixels / 0.10 at beta = 1e-2, 1 pixel / 0.004 at 3e-4
    assert diff[3e-4][0] <= 2 and diff[3e-4][1] <= 0.01, diff
    assert diff[3e-4][0] < diff[1e-2][0], diff


@pytest.mark.parametrize("bad", [-0.1, float("nan"), float("inf")])
def test_bad_damping_is_named(bad):
    with pytest.raises(ValueError, match="damping"):
        erosion.erosion_profile_analytic([0.01], 0.9, np.pi, 0.2, Q, P, damping=bad)
    with pytest.raises(ValueError, match="damping"):
        erosion.erosion_profile_numeric([0.01], 0.9, np.pi, 0.2, Q, P, cycles=5, damping=bad)
