"""Erosion profiles, true basins and Fourier comparisons on the real theory / numerics.

Tiny grids and short runs (the suite must stay well under 40 s).
"""
import numpy as np
import pytest
import xarray as xr

from safebasins.analysis import erosion, fourier_compare, phase_invariant
from safebasins.numerics import escape_chart
from safebasins.theory import slow_flow_escapes


Q = np.linspace(-1, 1, 41)
P = np.linspace(-0.75, 0.75, 31)
DIAG = np.hypot(Q[1] - Q[0], P[1] - P[0])


# ----------------------------------------------------------------------------- analytic
def test_analytic_profile_is_one_at_F0_and_erodes():
    ds = erosion.erosion_profile_analytic([0.0, 0.01, 0.03, 0.3], 0.9, np.pi, [0.15, 0.22, 0.24], Q, P,
                                          fourier=["paper", "exact"])
    np.testing.assert_array_equal(ds[["GIM", "LIM", "IF"]].sel(F=0.0).to_array().values, 1.0)
    assert (ds["GIM"] <= 1).all()
    assert (ds["GIM"].sel(F=0.3) < 0.2).all()                    # far beyond the erosion
    assert (ds["GIM"].isel(F=slice(0, 3)).diff("F") <= 0).all()  # small F: nested basins


def test_analytic_true_basin_contained_rotation_and_closed_form():
    F, Om, xi_max = 0.01, 0.9, 0.18
    ds = phase_invariant.true_safe_basin_analytic(F, Om, xi_max, Q, P, n_psi=8)
    assert bool(ds["contained"])
    assert bool((ds["true_safe"] <= ds["safe"]).all())
    assert bool((ds["true_safe_continuous"] <= ds["true_safe"]).all())
    assert (ds["GIM_true"] <= ds["GIM"]).all() and (ds["IF_true"] <= ds["IF"]).all()
    # rotation in the slow angle == direct classification with the phase
    QQ, PP = np.meshgrid(Q, P, indexing="ij")
    for k in (0, 3):
        psi = float(ds["Psi"][k])
        direct = ~np.asarray(slow_flow_escapes(QQ, PP, F, Om, psi, xi_max), bool)
        mism = (ds["safe"].isel(Psi=k).squeeze().values != direct).sum()
        assert mism <= 2, f"rotation disagrees with slow_flow_escapes on {mism} nodes"
    # continuous-phase basin is {H0 < xi_true}: grid radius vs closed form within a pixel
    xt = float(ds["xi_true"].squeeze())
    assert 0 < xt < xi_max
    assert abs(float(ds["r_global_continuous"].squeeze()) - np.sqrt(2 * xt)) <= DIAG
    assert abs(float(ds["LIM_continuous"].squeeze()) - float(ds["LIM_closed"].squeeze())) <= DIAG / np.sqrt(2 * xi_max)


def test_xi_true_limits():
    assert phase_invariant.xi_true_analytic(0.0, 0.9, 0.2) == pytest.approx(0.2)
    assert phase_invariant.xi_true_analytic(0.2, 0.9, 0.2) == 0.0   # the limiting phase trajectory escapes
    a = phase_invariant.xi_true_analytic(0.005, 0.9, 0.2)
    b = phase_invariant.xi_true_analytic(0.01, 0.9, 0.2)
    assert 0 < b < a < 0.2


# ----------------------------------------------------------------------------- numeric
Qn = np.linspace(-1, 1, 17)
Pn = np.linspace(-0.75, 0.75, 13)


def test_numeric_profile_one_at_F0_and_monotone_in_t_eval():
    prof, charts = erosion.erosion_profile_numeric([0.0, 0.06], 0.9, np.pi, [0.15, 0.24], Qn, Pn,
                                                   t_eval=[2, 10, 40], cycles=40, keep_charts=True)
    np.testing.assert_array_equal(prof[["GIM", "LIM", "IF"]].sel(F=0.0).to_array().values, 1.0)
    for k in ("GIM", "LIM", "IF"):
        assert (prof[k].diff("t_eval") <= 0).all(), k
    assert float(prof["GIM"].sel(F=0.06, t_eval=40).min()) < 1
    xr.testing.assert_identical(erosion.profile_from_charts(charts, [2, 10, 40])["IF"], prof["IF"])


def test_numeric_true_basin_contained():
    ds = phase_invariant.true_safe_basin_numeric(0.05, 0.9, 0.2, Qn, Pn, Psi_values=[0, 2, 4], t_eval=[10, 30],
                                                 cycles=30)
    assert bool(ds["contained"].all())
    assert bool((ds["true_safe"] <= ds["safe"]).all())
    assert (ds["GIM_true"].diff("t_eval") <= 0).all()


def test_iou_fourier_comparison_on_a_chart():
    chart = escape_chart(Qn, Pn, 0.01, 0.9, np.pi, xi_max=(0.18, 0.22), cycles=60)
    ds = fourier_compare.iou_fourier_comparison(chart)
    assert ds["iou"].dims == ("fourier", "xi_max", "t_eval")
    assert ((ds["iou"] > 0.5) & (ds["iou"] <= 1)).all()
    assert set(ds["fourier"].values) == {"paper", "exact"}


def test_fcr_fourier_comparison_small():
    ds = fourier_compare.fcr_fourier_comparison([0.9], 0.2, cycles=150, tol=2e-3)
    assert ds["F_cr_analytic"].dims == ("fourier", "Omega")
    assert np.isfinite(ds["F_cr_numeric"]).all()
    assert (np.abs(ds["rel_error"]) < 0.5).all()
