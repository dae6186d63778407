"""Reference solutions for the benchmarks: scipy solve_ivp with terminal escape events."""
from __future__ import annotations

import math

import numpy as np


def H0(q, p):
    return 0.5 * p * p + 0.5 * q * q - 0.25 * q ** 4


def ivp_escape(args):
    """Escape time (cycles, inf: none) of one IC with scipy solve_ivp; terminal events
    H0 = xi_max (None: none) and |q| = 1.  Returns (escape cycle, relative H0 change at the end of the
    run for F = 0 diagnostics, number of rhs evaluations)."""
    from scipy.integrate import solve_ivp
    q0, p0, F, Om, Psi, xi_max, cycles, method, rtol, atol = args[:10]
    kw = {"max_step": args[10] * 2 * math.pi / Om} if len(args) > 10 else {}
    if (xi_max is not None and H0(q0, p0) > xi_max) or abs(q0) > 1:
        return 0.0, 0, 0
    T = 2 * math.pi / Om

    def rhs(t, y):
        q = y[0]
        return [y[1], q * q * q - q + F * math.sin(Om * t + Psi)]

    def e_energy(t, y):
        return H0(y[0], y[1]) - xi_max
    e_energy.terminal = True
    e_energy.direction = 1

    def e_barrier(t, y):
        return abs(y[0]) - 1.0
    e_barrier.terminal = True
    e_barrier.direction = 1
    sol = solve_ivp(rhs, (0, cycles * T), [q0, p0], method=method, rtol=rtol, atol=atol,
                    events=(e_energy, e_barrier) if xi_max is not None else (e_barrier,), **kw)
    hits = [ev[0] for ev in sol.t_events if len(ev)]
    return (min(hits) / T if hits else np.inf), sol.nfev, sol.y[:, -1]
