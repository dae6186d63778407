"""Periodic orbits of the forced equation by multiple shooting (safebasins.analysis.floquet).

Independent routes: the forced hilltop saddle's orbit against the linear saddle's response (its
deviation is O(F^2): it quarters when F halves), its multipliers against exp(lambda T) of the
linear saddle and their product against Liouville's exp(-beta T), its fixed point against a
separate scipy DOP853 integration of one trajectory over one period, and a well bottom's orbit
against the linear oscillator's response with multipliers of modulus exp(-beta T / 2).
"""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from safebasins.analysis.floquet import linear_response, periodic_orbit, saddle_orbit, stiffness
from safebasins.wells import resolve_well

CUBIC = resolve_well("cubic")          # V = q^2/2 - q^3/3: hilltop q_b = 1, V''(1) = -1, V''' = -2
OMEGA = 0.85


def _period_map(well, F, Omega, beta, Psi, x):
    """One trajectory over one period, scipy DOP853 at rtol 1e-12 (not floquet.forced_flow)."""
    def f(t, y):
        return [y[1], -float(np.asarray(well.dV(np.array([y[0]])))[0]) - beta * y[1] + F * np.sin(Omega * t + Psi)]
    sol = solve_ivp(f, (0.0, 2 * np.pi / Omega), x, method="DOP853", rtol=1e-12, atol=1e-14)
    return sol.y[:, -1]


@pytest.mark.parametrize("beta", [0.0, 0.1])
def test_saddle_orbit_is_the_linear_response_to_first_order(beta):
    dev = []
    for F in (2e-3, 1e-3):
        orb = saddle_orbit(CUBIC, F, OMEGA, beta, 0.3, 1.0, 1e-12)
        lin = linear_response(F, OMEGA, beta, 0.3, -1.0, orb.times, q_e=1.0)
        dev.append(np.max(np.abs(orb.nodes - lin)))
        assert dev[-1] < 0.3 * F ** 2                    # V''' xi^2 / 2 with |xi| <= F / 1.72
    assert 3.6 < dev[0] / dev[1] < 4.4                   # O(F^2)


@pytest.mark.parametrize("beta", [0.0, 0.1])
def test_multipliers_are_those_of_the_linear_saddle(beta):
    T = 2 * np.pi / OMEGA
    lam = -beta / 2 + np.array([1.0, -1.0]) * np.sqrt(beta ** 2 / 4 + 1.0)
    orb = saddle_orbit(CUBIC, 0.0, OMEGA, beta, 0.0, 1.0, 1e-12)
    np.testing.assert_allclose(orb.nodes, [[1.0] * orb.nodes.shape[1], [0.0] * orb.nodes.shape[1]], atol=1e-12)
    (mu_u, e_u), (mu_s, e_s) = orb.saddle_directions()
    np.testing.assert_allclose([mu_u, mu_s], np.exp(lam * T), rtol=1e-6)
    np.testing.assert_allclose(abs(e_u[1] / e_u[0]), lam[0], rtol=1e-6)      # eigenvectors (1, lambda)
    np.testing.assert_allclose(abs(e_s[1] / e_s[0]), -lam[1], rtol=1e-6)
    forced = saddle_orbit(CUBIC, 0.02, OMEGA, beta, 0.0, 1.0, 1e-12)
    np.testing.assert_allclose(np.prod(np.real(forced.multipliers)), np.exp(-beta * T), rtol=1e-6)   # Liouville
    assert abs(np.real(forced.multipliers[0]) / mu_u - 1) < 1e-2


@pytest.mark.parametrize("well, q_b", [("cubic", 1.0), ("quartic", -1.0), ("quartic", 1.0)])
def test_fixed_point_of_an_independent_period_map(well, q_b):
    w = resolve_well(well)
    orb = saddle_orbit(w, 0.04, 0.9, 0.05, 1.0, q_b, 1e-12)
    assert orb.converged and orb.residual < 1e-10
    x = orb.point
    y = _period_map(w, 0.04, 0.9, 0.05, 1.0, x)
    # an error e of the fixed point shows as (mu_u - 1) e: 1e-8 here is e < 1e-11
    assert np.max(np.abs(y - x)) < 1e-8
    assert abs(x[0] - q_b) > 1e-3                          # the forcing moved it


def test_well_bottom_orbit_is_an_attractor():
    beta, F, Om = 0.05, 1e-3, 0.6                        # (2 Omega away from the linear frequency 1)
    guess = linear_response(F, Om, beta, 0.0, 1.0, [0.0])
    orb = periodic_orbit(CUBIC, F, Om, beta, 0.0, guess, rtol=1e-12)
    assert orb.converged and orb.stable
    np.testing.assert_allclose(np.abs(orb.multipliers), np.exp(-beta * np.pi / Om), rtol=1e-4)
    # second order: the mean |a|^2 / 2 and the 2 Omega harmonic |a|^2 / (2 |1 - 4 Omega^2|), 4 F^2 together
    np.testing.assert_allclose(orb.point, guess[:, 0], atol=5 * F ** 2)
    assert orb.saddle_directions() is None


def test_stiffness_and_bad_input():
    assert stiffness(CUBIC, 1.0) == pytest.approx(-1.0, abs=1e-8)
    with pytest.raises(ValueError, match="well"):
        saddle_orbit(CUBIC, 0.01, OMEGA, 0.1, 0.0, 0.0, 1e-10)          # the well bottom: no saddle
    with pytest.raises(ValueError, match="F = "):
        saddle_orbit(CUBIC, 2.0, OMEGA, 0.1, 0.0, 1.0, 1e-10)           # far beyond the hilltop's continuation
