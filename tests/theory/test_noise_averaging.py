"""The averaged noise coefficients (docs/noise-theory.md) against closed forms and the true dynamics.

Independent routes:

* closed forms: ``m_JJ = <p^2>/omega^2`` against the quartic's elliptic ``J/omega`` (measured
  relative 1e-15 .. 3e-13); the noise-induced action drift ``<d^2J/dp^2>/2`` against
  ``(1/2) d(J/omega)/dJ`` by central differences of the elliptic closed forms (4e-9); the
  linear-oscillator limit ``a_t = a_r = 1/(2 omega)`` at the well bottom (2e-5 at xi = 1e-5);
* the true dynamics: an ensemble of the unforced, undamped noisy quartic, integrated exactly
  between noise kicks (the action-angle flow theta += omega h, kicks p += sigma sqrt(h/2) Z in
  (q, p): a Strang splitting of two exact flows, weak order 2), from a uniform phase on one orbit;
  the moments of the action and phase increments over four periods against sigma^2 T x the orbit
  averages (xi = 0.1, sigma = 0.01, 10,000 paths; measured over four seeds: action drift 1.001-1.003
  of the prediction (standard error 0.13%, the action's noise removed by its Ito martingale
  term), action variance 1.007-1.028 and phase variance 0.993-1.002 (standard error 1.4%), phase
  drift and J-phase covariance within 2 standard errors of 0).
"""

import numpy as np
import pytest

from safebasins.theory.damped import shift_derivative
from safebasins.theory.noise_averaging import averaged_diffusion, orbit_averages
from safebasins.wells import QUARTIC, resolve_well


def test_action_terms_match_the_closed_forms():
    xi = np.array([0.01, 0.05, 0.1, 0.15, 0.2, 0.24])
    av = orbit_averages(QUARTIC, xi)
    J, om = QUARTIC.J(xi), QUARTIC.omega(xi)
    assert np.allclose(av["J"], J, rtol=1e-14)
    assert np.max(np.abs(av["m_JJ"] / (J / om) - 1)) < 1e-10
    # (1/2) d(J/omega)/dJ = (omega/2) d(J/omega)/dxi, by differences of the closed forms
    h = 1e-5 * xi
    g = lambda x: QUARTIC.J(x) / QUARTIC.omega(x)
    expect = 0.5 * om * (g(xi + h) - g(xi - h)) / (2 * h)
    assert np.max(np.abs(av["drift_J"] / expect - 1)) < 1e-6
    # symmetric well: no J-phase covariance
    assert np.max(np.abs(av["m_gJ"]) / np.sqrt(av["m_JJ"] * av["m_gg"])) < 1e-6


def test_linear_oscillator_limit_is_isotropic():
    xi = np.array([1e-5, 1e-4])
    av = orbit_averages(QUARTIC, xi)
    a_t = 2 * av["J"] * av["m_gg"]
    a_r = 0.5 / av["omega"]
    # the quartic's orbits tend to the linear oscillator's: a_t = a_r = 1/(2 omega), corrections O(xi)
    assert np.all(np.abs(a_t - a_r) < 10 * xi)
    assert np.all(np.abs(a_r - 0.5) < 10 * xi)
    d = averaged_diffusion(QUARTIC, 0.18)
    assert d.a_t[0] == d.a_r[0] == 0.5
    assert abs(d.a_t[1] - 0.5) < 1e-3 and abs(d.a[1] - 0.5) < 1e-3    # smooth at the bottom (A ~ sqrt(J/2))
    # tables reproduce the orbit averages
    Jq = np.array([0.03, 0.1, 0.17])
    x = np.interp(Jq, d.J_nodes, d.H)
    av = orbit_averages(QUARTIC, x)
    assert np.allclose(d.m_gg(Jq), av["m_gg"], rtol=1e-3)
    assert np.allclose(d.m_JJ(Jq), av["m_JJ"], rtol=1e-3)


def test_pendulum_action_diffusion():
    pend = resolve_well("pendulum")
    xi = np.array([0.2, 1.0, 1.8])
    av = orbit_averages(pend, xi)
    assert np.max(np.abs(av["m_JJ"] / (av["J"] / av["omega"]) - 1)) < 1e-6
    assert np.max(np.abs(av["m_gJ"]) / np.sqrt(av["m_JJ"] * av["m_gg"])) < 1e-6


def test_numeric_symmetric_well_accepted():
    # the pendulum's first-harmonic phase is rounding (1e-16), not an asymmetry
    d = averaged_diffusion(resolve_well("pendulum"), 0.8, n=40, n_theta=64)
    assert d.a_t[0] == d.a_r[0] == pytest.approx(0.5, abs=1e-12) and np.all(d.a_t[1:] > d.a_r[1:])


def test_asymmetric_well_in_the_sheared_phase():
    cub = resolve_well("cubic")
    xi = np.array([1e-3, 0.02, 0.06, 0.1, 0.14])
    g = orbit_averages(cub, xi)
    s = orbit_averages(cub, xi, sheared=True)
    # in the angle theta the J-phase covariance is of the size of the diffusions ...
    assert np.all(np.abs(g["m_gJ"]) / np.sqrt(g["m_JJ"] * g["m_gg"]) > 0.02)
    # ... in phi = theta + delta(J) it vanishes (time reversal about the turning point)
    assert np.max(np.abs(s["m_gJ"]) / np.sqrt(s["m_JJ"] * s["m_gg"])) < 1e-6
    # the sheared averages by the chain rule from theta's: dphi/dp = dtheta/dp + delta_J dJ/dp
    dJ = shift_derivative(cub, xi) * cub.omega(xi)
    assert np.allclose(s["m_gg"], g["m_gg"] + 2 * dJ * g["m_gJ"] + dJ ** 2 * g["m_JJ"], rtol=1e-6)
    assert np.allclose(s["m_gJ"] + 1.0, 1.0 + g["m_gJ"] + dJ * g["m_JJ"], atol=1e-8)
    for k in ("m_JJ", "drift_J"):
        assert np.array_equal(s[k], g[k])
    d = averaged_diffusion(cub, 0.12)
    assert not d.symmetric and averaged_diffusion(QUARTIC, 0.12).symmetric
    # isotropic at the bottom, smooth there: a_t -> a_r, d ~ sqrt(2J) (d_r finite), d = J ddelta/dJ
    assert d.a_t[0] == d.a_r[0] and abs(d.a_t[1] - d.a_r[1]) < 1e-3 and np.all(np.isfinite(d.d_r))
    Jq = np.array([0.02, 0.06, 0.1])
    x = np.interp(Jq, d.J_nodes, d.H)
    assert np.allclose(d.d(Jq), Jq * cub.omega(x) * shift_derivative(cub, x), rtol=1e-3)
    assert np.allclose(d.m_gg(Jq), orbit_averages(cub, x, sheared=True)["m_gg"], rtol=1e-3)


def _kicked(well, xi0, sigma, n_paths, steps, seed, periods=4):
    """The unforced, undamped noisy well integrated exactly between noise kicks, from a uniform
    phase on the orbit xi0: ``(T, J, martingale, dtheta, dphi)`` over ``periods`` periods, with
    the kicks' phase jumps in theta and in the sheared phi = theta + delta(xi)."""
    T = periods * 2 * np.pi / float(well.omega(xi0))
    h = T / steps
    a = sigma * np.sqrt(h / 2)
    rng = np.random.default_rng(seed)
    theta = rng.uniform(0, 2 * np.pi, n_paths)
    xi = np.full(n_paths, xi0)
    dtheta_kick = np.zeros(n_paths)
    dphi_kick = np.zeros(n_paths)
    martingale = np.zeros(n_paths)        # sum of (dJ/dp) a Z = (p/omega) a Z: mean 0, removes the noise of dJ

    def kick(theta, xi):
        q, p = well.phase_point(theta, xi)
        dp = a * rng.standard_normal(n_paths)
        th1, xi1 = well.angle_energy(q, p + dp)
        jump = np.angle(np.exp(1j * (th1 - theta)))
        return th1, xi1, jump, jump + well.harmonic_shift(xi1) - well.harmonic_shift(xi), p / well.omega(xi) * dp

    for _ in range(steps):
        theta, xi, d1, s1, m1 = kick(theta, xi)
        theta = theta + well.omega(xi) * h
        theta, xi, d2, s2, m2 = kick(theta, xi)
        dtheta_kick += d1 + d2
        dphi_kick += s1 + s2
        martingale += m1 + m2
    return T, well.J(xi) - well.J(xi0), martingale, dtheta_kick, dphi_kick


def test_asymmetric_coefficients_against_the_noisy_dynamics():
    # the escape equation's well: in theta the J-phase covariance is sigma^2 m_gJ (nonzero), in the
    # sheared phi it vanishes, and phi's diffusion is the sheared m_gg
    cub = resolve_well("cubic")
    xi0, sigma, n = 0.08, 0.01, 10000
    T, dJ, _, dth, dphi = _kicked(cub, xi0, sigma, n, 16, 11)
    g = orbit_averages(cub, np.array([xi0]))
    s = orbit_averages(cub, np.array([xi0]), sheared=True)
    cov = lambda x, y: np.mean((x - x.mean()) * (y - y.mean()))
    se_cov = lambda x, y: np.sqrt(x.var() * y.var() / n)
    # over 12 seeds (mean +- sd of one seed): action variance 1.014 +- 0.018, theta covariance
    # 1.036 +- 0.042, phi variance 1.018 +- 0.016 of the averages, the phi covariance -0.1 +- 1.2 of its
    # standard error; the bounds are about 5 sd of one seed
    assert abs(dJ.var() / (sigma ** 2 * g["m_JJ"][0] * T) - 1) < 0.1
    assert abs(cov(dJ, dth) / (sigma ** 2 * g["m_gJ"][0] * T) - 1) < 0.2
    assert abs(cov(dJ, dth)) > 10 * se_cov(dJ, dth)
    assert abs(dphi.var() / (sigma ** 2 * s["m_gg"][0] * T) - 1) < 0.1
    assert abs(cov(dJ, dphi)) < 3 * se_cov(dJ, dphi)


def test_coefficients_against_the_noisy_dynamics():
    xi0, sigma, n_paths = 0.1, 0.01, 10000
    T, dJ, martingale, dtheta_kick, _ = _kicked(QUARTIC, xi0, sigma, n_paths, 64, 7)
    av = orbit_averages(QUARTIC, np.array([xi0]))
    se = lambda x: x.std(ddof=1) / np.sqrt(n_paths)
    drift = dJ - martingale
    ratios = (drift.mean() / (sigma ** 2 * av["drift_J"][0] * T), dJ.var() / (sigma ** 2 * av["m_JJ"][0] * T),
              dtheta_kick.var() / (sigma ** 2 * av["m_gg"][0] * T))
    # action drift (sigma^2/2) d(J/omega)/dJ: within 1% (standard error 0.13%)
    assert abs(ratios[0] - 1) < 0.01 and se(drift) < 2e-3 * abs(drift.mean())
    # action diffusion sigma^2 J/omega and phase diffusion sigma^2 <q_J^2>: variances within 5%
    # (standard error 1.4%)
    assert abs(ratios[1] - 1) < 0.05 and abs(ratios[2] - 1) < 0.05
    # no phase drift and no J-phase covariance for the symmetric well (the phase drift's scale, if
    # <d^2 theta/dp^2> did not vanish, would be of order sigma^2 <q_J^2> T: 9.5 standard errors)
    assert abs(dtheta_kick.mean()) < 3 * se(dtheta_kick)
    cov = np.mean((dJ - dJ.mean()) * (dtheta_kick - dtheta_kick.mean()))
    assert abs(cov) < 3 * np.sqrt(dJ.var() * dtheta_kick.var() / n_paths)
    print(ratios, se(drift) / drift.mean(), dtheta_kick.mean() / se(dtheta_kick),
          sigma ** 2 * av["m_gg"][0] * T / se(dtheta_kick), cov / np.sqrt(dJ.var() * dtheta_kick.var() / n_paths))


# --------------------------------------------------------------------------- tables kept per well
# the tables depend on the well and (xi_max, n, n_theta) only, not on sigma, F, Omega or beta:
# computed once per well and kept; a fresh QuarticWell object starts with none
def _counting(monkeypatch):
    from safebasins.theory import noise_averaging

    calls = []
    real = noise_averaging.orbit_averages
    monkeypatch.setattr(noise_averaging, "orbit_averages", lambda *a, **k: calls.append(a[1].size) or real(*a, **k))
    return calls


def test_tables_computed_once_per_well_and_threshold(monkeypatch):
    from safebasins import theory
    from safebasins.wells import QuarticWell

    calls = _counting(monkeypatch)
    w = QuarticWell()
    kw = dict(t_eval=[1.0], well=w, cells=(16, 20), steps_per_cycle=4)
    for s in (0.02, 0.04, 0.06):
        theory.escape_probability([0.1], [0.0], 0.05, 0.9, 0.0, 0.2, noise=s, damping=0.05, **kw)
    theory.escape_probability([0.1], [0.0], 0.03, 0.8, 1.0, 0.2, noise=0.02, **kw)       # other F, Omega, Psi, beta
    theory.mean_first_passage([0.1], [0.0], 0.05, 0.9, 0.0, 0.2, noise=0.05, well=w, cells=(16, 20))
    assert len(calls) == 1
    assert averaged_diffusion(w, 0.2) is averaged_diffusion(w, 0.2)
    averaged_diffusion(w, 0.18)                                             # another threshold: its own tables
    averaged_diffusion(w, 0.2, n=40)                                         # another resolution too
    assert len(calls) == 3
    averaged_diffusion(QuarticWell(), 0.2)                                   # another well object: its own
    assert len(calls) == 4


def test_kept_tables_are_read_only_and_the_first_calls_bits():
    from safebasins.wells import QuarticWell

    kept = averaged_diffusion(QuarticWell(), 0.2, n=50, n_theta=64)
    fresh = averaged_diffusion(QuarticWell(), 0.2, n=50, n_theta=64)
    for name in ("J_nodes", "H", "omega", "a", "a_r", "a_t"):
        np.testing.assert_array_equal(getattr(kept, name), getattr(fresh, name), err_msg=name)
        with pytest.raises(ValueError, match="read-only"):
            getattr(kept, name)[0] = 1.0


def test_escape_probability_with_kept_tables_is_bitwise_a_cold_solve():
    # a sweep's later levels reuse the first level's tables: the same bits as a solve from scratch
    from safebasins import theory
    from safebasins.wells import QuarticWell

    q0, p0 = np.linspace(-0.8, 0.8, 7), np.linspace(-0.6, 0.6, 5)
    kw = dict(t_eval=[1.0, 3.0], damping=0.05, grid=True, cells=(24, 30), steps_per_cycle=6)
    warm = QuarticWell()
    theory.escape_probability(q0, p0, 0.05, 0.9, 0.0, 0.2, noise=0.02, well=warm, **kw)
    again = theory.escape_probability(q0, p0, 0.05, 0.9, 0.0, 0.2, noise=0.06, well=warm, **kw)
    cold = theory.escape_probability(q0, p0, 0.05, 0.9, 0.0, 0.2, noise=0.06, well=QuarticWell(), **kw)
    np.testing.assert_array_equal(again["P_escape"].values, cold["P_escape"].values)
    np.testing.assert_array_equal(again["first_passage_mean"].values, cold["first_passage_mean"].values)
    assert 0.05 < float(cold["P_escape"].mean()) < 0.95          # some escape, some stay: the test can fail


def test_unhashable_well_computes_its_tables_every_call(monkeypatch):
    from safebasins.wells import QuarticWell

    class Unhashable(QuarticWell):
        __hash__ = None  # type: ignore[assignment]

    calls = _counting(monkeypatch)
    w = Unhashable()
    a, b = averaged_diffusion(w, 0.2, n=30, n_theta=32), averaged_diffusion(w, 0.2, n=30, n_theta=32)
    assert len(calls) == 2 and a is not b
    np.testing.assert_array_equal(a.a_t, b.a_t)
