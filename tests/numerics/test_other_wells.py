"""Non-polynomial wells in the numerics: the pendulum 1 - cos q and the sech^2 well
tanh^2 q (open at infinity).

* A NumericWell of the user's numpy/numba functions and the same well written as an expression
  run through the one compiled form: with the same floating-point operations their escape
  charts and numeric F_cr are bitwise equal.
* The engine's numeric F_cr from the zero IC against an independent integrator (scipy DOP853,
  rtol 1e-10, event on H0 = xi_max): DOP853 keeps the IC one scan step below the engine's F_cr
  and lets it escape one scan step above.
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from safebasins import wells
from safebasins.numerics import critical_forcing_numeric, escape_chart
from safebasins.wells.numeric import NumericWell

# the user's functions, written with the operations the expression wells print (wells.expression)
USER = {
    "pendulum": (lambda q: 1.0 - np.cos(q), lambda q: np.sin(q)),
    "sech2": (lambda q: np.tanh(q) * np.tanh(q), lambda q: 2.0 * np.tanh(q) / (np.cosh(q) * np.cosh(q))),
}
EXPRESSION = {"pendulum": "1 - cos(q)", "sech2": "tanh(q)**2"}
CASES = {"pendulum": dict(Omega=0.9, xi=(1.0, 1.5), box=2.6), "sech2": dict(Omega=1.27, xi=(0.5, 0.75), box=1.8)}


@pytest.mark.parametrize("name", ["pendulum", "sech2"])
def test_numeric_well_equals_expression_bitwise(name):
    V, dV = USER[name]
    user = NumericWell(V, dV, name=f"user {name}")
    expr = wells.resolve_well({"expression": EXPRESSION[name]})
    assert user.barrier_energy == expr.barrier_energy
    c = CASES[name]
    q = np.linspace(-c["box"], c["box"], 18)
    p = np.linspace(-0.8 * c["box"], 0.8 * c["box"], 15)
    kw = dict(xi_max=c["xi"], cycles=60, steps_per_cycle=32)
    a = escape_chart(q, p, 0.02, c["Omega"], np.pi, well=user, **kw)
    b = escape_chart(q, p, 0.02, c["Omega"], np.pi, well=expr, **kw)
    np.testing.assert_array_equal(a["escape_cycle_energy"].values, b["escape_cycle_energy"].values)
    e = a["escape_cycle_energy"].values
    assert 0.2 < np.isfinite(e).mean() < 0.95            # both outcomes: the comparison is not vacuous
    fa = critical_forcing_numeric([c["Omega"], 1.1 * c["Omega"]], c["xi"][0], cycles=60, n_scan=11, tol=1e-3,
                                  F_bracket=(0.0, 1.0), well=user)
    fb = critical_forcing_numeric([c["Omega"], 1.1 * c["Omega"]], c["xi"][0], cycles=60, n_scan=11, tol=1e-3,
                                  F_bracket=(0.0, 1.0), well=expr)
    np.testing.assert_array_equal(fa["F_cr"].values, fb["F_cr"].values)


def _dop853_escapes(w, F, Omega, xi_max, cycles):
    """Zero IC, q'' + V'(q) = F sin(Omega t): does H0 exceed xi_max within `cycles` (DOP853)?"""
    def rhs(t, y):
        return [y[1], -float(w.dV(y[0])) + F * np.sin(Omega * t)]

    def above(t, y):
        return 0.5 * y[1] ** 2 + float(w.V(y[0])) - xi_max
    above.terminal, above.direction = True, 1
    sol = solve_ivp(rhs, (0.0, cycles * 2 * np.pi / Omega), [0.0, 0.0], method="DOP853", rtol=1e-10, atol=1e-12,
                    events=above)
    return sol.t_events[0].size > 0


@pytest.mark.parametrize("name,Omegas,xi", [("pendulum", (0.7, 1.05), 1.0), ("sech2", (1.0, 1.5), 0.5)])
def test_fcr_against_dop853(name, Omegas, xi):
    w = wells.resolve_well(name)
    cycles, n_scan = 150, 301
    f = critical_forcing_numeric(list(Omegas), xi, cycles=cycles, n_scan=n_scan, tol=2e-4, F_bracket=(0.0, 1.0),
                                 well=w)
    step = f.attrs["F_scan_step"]
    for k, Om in enumerate(Omegas):
        assert not bool(f["non_monotone"].values[k])
        F_cr = float(f["F_cr"].values[k])
        assert np.isfinite(F_cr)
        assert not _dop853_escapes(w, F_cr - step, Om, xi, cycles), (name, Om, F_cr)
        assert _dop853_escapes(w, F_cr + step, Om, xi, cycles), (name, Om, F_cr)
