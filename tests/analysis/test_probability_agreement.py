"""probability_agreement: the averaged theory's escape-probability maps against SDE ensembles.

The main measure (docs/noise-theory.md): the paper's quartic at Fig 14's forcing (F = 0.01,
Omega = 0.9, Psi = pi, xi_max = 0.18), white noise sigma = 0.01, a 21 x 16 grid over
|q0| <= 0.95, |p0| <= 0.75, 400 paths: mean |P_theory - P_SDE| 0.0062 / 0.0075 over the plane at
10 / 25 cycles (0.017 over the ICs not escaping at once), maximum 0.098 / 0.091; the theory lies in
the ensembles' 95% Wilson interval at 94% of the (IC, t_eval).  The bound is the target 0.05 of the
mean.
"""

import numpy as np
import pytest
import xarray as xr

from safebasins import numerics, theory
from safebasins.analysis.agreement import probability_agreement


def _ds(P, low=None, high=None):
    q0, p0 = np.linspace(-1, 1, P.shape[0]), np.linspace(-1, 1, P.shape[1])
    data = {"P_escape": (("q0", "p0", "t_eval"), P)}
    if low is not None:
        data |= {"P_escape_low": (("q0", "p0", "t_eval"), low), "P_escape_high": (("q0", "p0", "t_eval"), high)}
    return xr.Dataset(data, coords={"q0": q0, "p0": p0, "t_eval": [1.0, 2.0]})


def test_known_differences():
    rng = np.random.default_rng(3)
    Pn = rng.uniform(size=(4, 3, 2))
    Pt = np.clip(Pn + rng.normal(0, 0.1, Pn.shape), 0, 1)
    Pn[0, 0], Pt[0, 0] = 1.0, 1.0                            # certain escape in both
    out = probability_agreement(_ds(Pt), _ds(Pn, Pn - 0.05, Pn + 0.05))
    d = np.abs(Pt - Pn)
    assert np.allclose(out["P_escape_mean_abs_difference"].values, d.mean(axis=(0, 1)), rtol=1e-14)
    assert np.allclose(out["P_escape_max_abs_difference"].values, d.max(axis=(0, 1)), rtol=1e-14)
    assert out.attrs["P_escape_mean_abs_difference"] == pytest.approx(d.mean(), rel=1e-14)
    keep = np.ones((4, 3), bool)
    keep[0, 0] = False
    assert out.attrs["P_escape_mean_abs_difference_uncertain"] == pytest.approx(d[keep].mean(), rel=1e-14)
    assert out.attrs["P_escape_theory_within_wilson"] == pytest.approx(np.mean(d <= 0.05), abs=1e-12)
    assert out["P_escape_mean_abs_difference"].attrs["long_name"]
    assert np.array_equal(out["P_escape_theory"].values, Pt)


def test_mismatch_named():
    a, b = _ds(np.zeros((4, 3, 2))), _ds(np.zeros((4, 3, 2)))
    with pytest.raises(ValueError, match="q0"):
        probability_agreement(a, b.assign_coords(q0=b.q0 + 0.1))
    with pytest.raises(ValueError, match="theory"):
        probability_agreement(a.drop_vars("P_escape"), b)


def test_theory_against_sde_ensembles_fig14():
    q0, p0 = np.linspace(-0.95, 0.95, 21), np.linspace(-0.75, 0.75, 16)
    args = (q0, p0, 0.01, 0.9, np.pi)
    kw = {"noise": 0.01, "t_eval": [10, 25]}
    th = theory.escape_probability(*args, 0.18, **kw)
    nu = numerics.escape_probability(*args, xi_max=0.18, paths=400, seed=1, threads=1, **kw)
    out = probability_agreement(th, nu)
    mean = out["P_escape_mean_abs_difference"].values
    assert np.all(mean <= 0.05)
    assert out.attrs["P_escape_mean_abs_difference_uncertain"] <= 0.05
    assert out.attrs["P_escape_max_abs_difference"] < 0.3
    assert out.attrs["P_escape_theory_within_wilson"] > 0.8
