"""Action-angle variables (paper eqs 4, 7, 8, 13-20) against independent computations."""
import numpy as np
import pytest
from scipy import integrate

from safebasins.theory import (G, H0, J, angle_energy, dG_dxi, dJ_dxi, initial_condition, nome,
                               omega, phase_point, q_max_from_xi)

XIS = np.array([0.001, 0.03, 0.1, 0.18, 0.22, 0.24, 0.249, 0.2499])


def _free_rhs(t, y):
    return [y[1], -y[0] + y[0] ** 3]


def _action_quadrature(xi):
    """Eq (8): I = (1/2pi) oint p dq = (2/pi) int_0^A sqrt(2 (xi - V(q))) dq, with q = A sin(s)."""
    A = np.sqrt(1.0 - np.sqrt(1.0 - 4.0 * xi))

    def f(s):
        q = A * np.sin(s)
        return np.sqrt(max(2.0 * (xi - 0.5 * q * q + 0.25 * q ** 4), 0.0)) * A * np.cos(s)

    val, _ = integrate.quad(f, 0.0, np.pi / 2, epsabs=1e-14, epsrel=1e-12, limit=200)
    return 2.0 / np.pi * val


def test_J_against_action_integral():
    got = J(XIS)
    ref = np.array([_action_quadrature(x) for x in XIS])
    np.testing.assert_allclose(got, ref, rtol=1e-9)
    assert J(0.0) == 0.0
    np.testing.assert_allclose(J(0.25), 2.0 * np.sqrt(2.0) / (3.0 * np.pi), rtol=1e-12)


def test_omega_is_inverse_derivative_of_J():
    x = XIS[1:-1]
    h = 1e-6 * np.minimum(x, 0.25 - x)
    fd = (J(x + h) - J(x - h)) / (2 * h)
    np.testing.assert_allclose(omega(x), 1.0 / fd, rtol=1e-7)
    np.testing.assert_allclose(dJ_dxi(x) * omega(x), 1.0, rtol=1e-14)
    assert omega(0.0) == pytest.approx(1.0, abs=1e-15)
    assert omega(0.25) == 0.0


def test_dG_dxi_against_finite_difference():
    x = XIS[1:-1]
    h = 1e-6 * np.minimum(x, 0.25 - x)
    for fourier in ("paper", "exact"):
        fd = (G(x + h, fourier) - G(x - h, fourier)) / (2 * h)
        np.testing.assert_allclose(dG_dxi(x, fourier), fd, rtol=1e-6)


def _first_sine_coefficient(q_samples):
    n = q_samples.size
    return 2.0 / n * np.imag(-np.fft.rfft(q_samples)[1])   # b_1 of sum b_k sin(k theta)


@pytest.mark.parametrize("xi", [0.01, 0.12, 0.2, 0.24, 0.2499])
def test_G_exact_against_fft_of_phase_point(xi):
    n = 4096
    theta = 2 * np.pi * np.arange(n) / n
    q, _ = phase_point(theta, xi)
    b1 = _first_sine_coefficient(q)
    np.testing.assert_allclose(G(xi, "exact"), b1 / 2.0, rtol=1e-10)
    # the paper's eq (20) is the leading term only: paper = exact * (1 - nome)
    np.testing.assert_allclose(G(xi, "paper"), G(xi, "exact") * (1.0 - nome(xi)), rtol=1e-13)


@pytest.mark.parametrize("xi", [0.05, 0.2, 0.24])
def test_G_exact_and_omega_against_free_ode(xi):
    """Free oscillator from (0, sqrt(2 xi)): theta = omega t, so q(t) sampled uniformly over one
    period T = 2 pi / omega is q(theta); its first sine coefficient is 2 G_exact."""
    T = 2 * np.pi / omega(xi)
    n = 1024
    t = T * np.arange(n) / n
    sol = integrate.solve_ivp(_free_rhs, (0, T), [0.0, np.sqrt(2 * xi)], t_eval=np.append(t, T),
                              rtol=1e-12, atol=1e-13, method="DOP853")
    q = sol.y[0]
    assert abs(q[-1]) < 1e-8 and sol.y[1][-1] == pytest.approx(np.sqrt(2 * xi), abs=1e-8)  # period
    b1 = _first_sine_coefficient(q[:-1])
    np.testing.assert_allclose(G(xi, "exact"), b1 / 2.0, rtol=1e-8)


def test_paper_G_is_low_by_documented_amount():
    ratio = G([0.24, 0.2499], "exact") / G([0.24, 0.2499], "paper")
    np.testing.assert_allclose(ratio - 1, [0.073, 0.239], atol=0.002)
    assert G(0.0) == 0.0 and G(0.25) == 0.0
    np.testing.assert_allclose(G(1e-8, "exact"), np.sqrt(1e-8 / 2), rtol=1e-6)  # G ~ sqrt(J/2)


def test_q_max_and_H0():
    xm = np.array([0.01, 0.15, 0.2499, 0.25])
    qm = q_max_from_xi(xm)
    np.testing.assert_allclose(qm, np.sqrt(1 - np.sqrt(1 - 4 * xm)), rtol=1e-12)
    np.testing.assert_allclose(H0(qm, 0.0), xm, rtol=1e-12)
    assert H0(0.3, -0.2) == pytest.approx(0.02 + 0.045 - 0.3 ** 4 / 4)


def test_round_trip_all_quadrants():
    rng = np.random.default_rng(42)
    q = rng.uniform(-0.999, 0.999, 20000)
    p = rng.uniform(-0.71, 0.71, 20000)
    keep = (H0(q, p) < 0.2499)
    q, p = q[keep], p[keep]
    theta, xi = angle_energy(q, p)
    assert np.all((theta >= 0) & (theta < 2 * np.pi))
    np.testing.assert_allclose(xi, H0(q, p), rtol=1e-14)
    q2, p2 = phase_point(theta, xi)
    np.testing.assert_allclose(q2, q, atol=1e-10)
    np.testing.assert_allclose(p2, p, atol=1e-10)
    # quadrant structure of q = A sn, p = B cn dn
    quad = np.floor(theta / (np.pi / 2)).astype(int)
    exp = np.where(q >= 0, np.where(p >= 0, 0, 1), np.where(p < 0, 2, 3))
    away = (np.abs(q) > 1e-6) & (np.abs(p) > 1e-6)
    np.testing.assert_array_equal(quad[away], exp[away])
    # and the other direction on a regular grid of (theta, xi)
    th = np.linspace(0, 2 * np.pi, 73)[:-1]
    for x in (1e-6, 0.1, 0.2499):
        qq, pp = phase_point(th, x)
        t2, x2 = angle_energy(qq, pp)
        d = np.angle(np.exp(1j * (t2 - th)))
        assert np.abs(d).max() < 1e-8
        np.testing.assert_allclose(x2, x, rtol=1e-9)


def test_well_bottom_is_finite():
    theta, xi = angle_energy(0.0, 0.0)
    assert theta == 0.0 and xi == 0.0
    q, p = phase_point(1.234, 0.0)
    assert q == 0.0 and p == 0.0
    th, x = angle_energy(np.zeros(3), np.zeros(3))
    assert np.isfinite(th).all() and np.isfinite(x).all()


def test_theta_advances_at_omega_along_free_motion():
    for xi in (0.05, 0.23):
        q0, p0 = phase_point(0.7, xi)
        t = np.linspace(0, 40, 801)
        sol = integrate.solve_ivp(_free_rhs, (0, 40), [q0, p0], t_eval=t, rtol=1e-11, atol=1e-12,
                                  method="DOP853")
        theta, x = angle_energy(sol.y[0], sol.y[1])
        unwrapped = np.unwrap(theta)
        np.testing.assert_allclose(unwrapped, 0.7 + omega(xi) * t, atol=1e-7)
        np.testing.assert_allclose(x, xi, atol=1e-10)


def test_initial_condition_convention():
    q0, p0 = initial_condition(0.1, 0.3, np.pi)
    q1, p1 = phase_point(0.3 + np.pi, 0.1)
    assert (q0, p0) == (q1, p1)
    th, xi = angle_energy(q0, p0)
    assert np.angle(np.exp(1j * (th - np.pi - 0.3))) == pytest.approx(0.0, abs=1e-10)


@pytest.mark.parametrize("call, name", [
    (lambda: J(-0.01), "xi"),
    (lambda: J(0.26), "xi"),
    (lambda: omega(np.array([0.1, -1.0])), "xi"),
    (lambda: G(0.3), "xi"),
    (lambda: G(0.1, fourier="fft"), "fourier"),
    (lambda: phase_point(0.0, 0.25), "xi"),
    (lambda: phase_point(np.nan, 0.1), "theta"),
    (lambda: q_max_from_xi(0.0), "xi_max"),
    (lambda: q_max_from_xi(0.3), "xi_max"),
    (lambda: angle_energy(1.2, 0.0), "q"),
    (lambda: angle_energy(0.0, 0.8), "p"),
    (lambda: initial_condition(-0.1, 0.0, 0.0), "xi_ini"),
    (lambda: dG_dxi(0.0), "xi"),
])
def test_out_of_domain_raises(call, name):
    with pytest.raises(ValueError, match=name):
        call()
