"""Independent references for the well tests: scipy quad for the action, brentq turning points,
and one DOP853 orbit per energy (period from the upward q = 0 crossing, q_1 by FFT)."""
from __future__ import annotations

import numpy as np
from scipy import integrate, optimize


def turning_points_brentq(well, E):
    """``V(q) = E`` on each side of 0 by Brent's method inside the well's limits (an infinite
    limit, a side open at infinity, is replaced by the first ``+-2^k`` with ``V > E``)."""
    f = lambda q: float(well.V(q)) - E

    def bracket(lim, side):
        if np.isfinite(lim):
            return lim
        x = side
        while f(x) <= 0:
            x *= 2.0
        return x
    lo, hi = (bracket(lim, side) for lim, side in zip(well.limits, (-1.0, 1.0)))
    return (optimize.brentq(f, lo, 0.0, xtol=1e-16, rtol=1e-15),
            optimize.brentq(f, 0.0, hi, xtol=1e-16, rtol=1e-15))


def action_quad(well, E):
    """``J = (1/pi) int_{q-}^{q+} sqrt(2 (E - V)) dq`` with scipy quad's algebraic end weights
    ``(q - q-)^(1/2) (q+ - q)^(1/2)`` (QAWSE) and an integrand ``sqrt(2 (E - V) / ((q - q-)(q+ - q)))``."""
    qm, qp = turning_points_brentq(well, E)

    def f(q):
        den = (q - qm) * (qp - q)
        return np.sqrt(max(2.0 * (E - float(well.V(q))), 0.0) / den) if den > 0 else 0.0

    val, _ = integrate.quad(f, qm, qp, weight="alg", wvar=(0.5, 0.5), epsabs=0.0, epsrel=1e-13, limit=400)
    return val / np.pi


class Orbit:
    """DOP853 orbit of energy E from ``q = 0, p = sqrt(2E)`` (theta = 0) over one period."""

    def __init__(self, well, E, rtol=1e-13, atol=1e-15, n_fft=4096):
        p0 = np.sqrt(2.0 * E)
        T_guess = float(well.period(E))
        up = lambda t, y: y[0]
        up.direction = 1.0
        sol = integrate.solve_ivp(lambda t, y: [y[1], -float(well.dV(y[0]))], (0.0, 1.3 * T_guess),
                                  [0.0, p0], method="DOP853", rtol=rtol, atol=atol, events=up,
                                  dense_output=True)
        crossings = sol.t_events[0][sol.t_events[0] > 0.5 * T_guess]
        assert crossings.size == 1, "reference orbit did not close once"
        self.T = float(crossings[0])
        self.sol = sol
        t = np.arange(n_fft) * self.T / n_fft
        q = sol.sol(t)[0]
        self.q1 = complex(np.mean(q * np.exp(-2j * np.pi * np.arange(n_fft) / n_fft)))

    def state(self, t):
        y = self.sol.sol(t)
        return y[0], y[1]


def rel(a, b):
    """Largest relative difference."""
    return np.max(np.abs(np.asarray(a) / np.asarray(b) - 1.0))


def angle_diff(a, b):
    """Largest difference of angles (mod 2 pi)."""
    return np.max(np.abs(np.angle(np.exp(1j * (np.asarray(a) - np.asarray(b))))))


def assert_matches_orbit(well, E, n_points, tol=1e-9):
    """The well's J against scipy quad (1e-11), its period and q_1 against a DOP853 orbit (1e-10),
    and angle_energy / phase_point along that orbit (``tol``, ``n_points`` points)."""
    assert rel(well.J(E), action_quad(well, E)) <= 1e-11
    orbit = Orbit(well, E)
    assert rel(well.period(E), orbit.T) <= 1e-10
    assert abs(well.first_harmonic(E) - orbit.q1) <= 1e-10 * abs(orbit.q1)
    t = np.linspace(0, orbit.T, n_points + 1)[:-1]
    q, p = orbit.state(t)
    theta = 2 * np.pi * t / orbit.T
    assert angle_diff(well.angle_energy(q, p)[0], theta) <= tol
    qq, pp = well.phase_point(theta, E)
    assert np.max(np.abs(qq - q)) <= tol and np.max(np.abs(pp - p)) <= tol
    return orbit
