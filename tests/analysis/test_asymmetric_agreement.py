"""The averaged theory of an asymmetric well (the escape equation's cubic, solved in its sheared
phase gamma + delta(J), docs/noise-theory.md) against the SDE ensembles: the escape-probability maps
agree within the issue's target (mean |Delta P| <= 0.05 over the IC plane).

Measured (24 x 22 ICs over the study's window, Omega = 0.9, Psi = pi, xi_max = 0.12, 400 paths):
mean |Delta P| at 10 / 50 cycles 0.0038 / 0.0067 (F = 0.005, sigma = 0.005), 0.0082 / 0.0062
(F = 0.01, sigma = 0.01), 0.0049 / 0.0049 (F = 0.005, sigma = 0.01, beta = 0.05); here (16 x 14 ICs,
300 paths, 64 x 80 cells) 0.0041 / 0.0071 and 0.0075 / 0.0075.
"""
import numpy as np
import pytest

from safebasins import numerics, theory
from safebasins.analysis.agreement import probability_agreement

Q = np.linspace(-0.46, 0.69, 16)
P = np.linspace(-0.52, 0.52, 14)


@pytest.mark.parametrize("F, sigma, beta", [(0.005, 0.005, 0.0), (0.005, 0.01, 0.05)])
def test_cubic_maps_agree(F, sigma, beta):
    kw = dict(noise=sigma, t_eval=[10, 50], damping=beta, well="cubic")
    th = theory.escape_probability(Q, P, F, 0.9, np.pi, 0.12, cells=(64, 80), **kw)
    nu = numerics.escape_probability(Q, P, F, 0.9, np.pi, xi_max=0.12, paths=300, cycles=50, seed=3, **kw)
    ag = probability_agreement(th, nu)
    mean = ag["P_escape_mean_abs_difference"].values
    # the target is 0.05; 0.02 also rejects the ICs mapped without the shear delta(xi)
    # (measured 0.032 / 0.028 at the first case's 10 / 50 cycles)
    assert np.all(mean <= 0.02), mean
    # neither map is trivial: the basin is partly eroded
    assert 0.1 < float(nu["P_escape"].mean()) < 0.9 and 0.1 < float(th["P_escape"].mean()) < 0.9
