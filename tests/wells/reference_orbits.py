"""Independent references for the well tests: scipy quad for the action, brentq turning points,
and one DOP853 orbit per energy (period from the upward q = 0 crossing, q_1 by FFT)."""
from __future__ import annotations

import numpy as np
from scipy import integrate, optimize


def turning_points_brentq(well, E):
    """``V(q) = E`` on each side of 0 by Brent's method inside the well's limits."""
    f = lambda q: float(well.V(q)) - E
    lo, hi = well.limits
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
