"""Non-polynomial wells in the numerics: the pendulum 1 - cos q, the sech^2 well tanh^2 q and
the Morse well (1 - exp(-q))^2 (open at infinity), an electrostatic (MEMS-type) expression well.

* A NumericWell of the user's numpy/numba functions and the same well written as an expression
  run through the one compiled form: with the same floating-point operations their escape
  charts and numeric F_cr are bitwise equal.
* The engine's numeric F_cr from the zero IC against an independent integrator (scipy DOP853,
  rtol 1e-10, event on H0 = xi_max): DOP853 keeps the IC one scan step below the engine's F_cr
  and lets it escape one scan step above.
* A small escape chart of each well (its force through wells.elementary in the lanes) against
  DOP853 on the well's numpy V and V', pixel by pixel.
"""

from __future__ import annotations

import math
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


def _dop853_escapes(w, F, Omega, xi_max, cycles, q0=0.0, p0=0.0, Psi=0.0):
    """q'' + V'(q) = F sin(Omega t + Psi) from (q0, p0): does H0 exceed xi_max within `cycles`
    (DOP853; beyond at t = 0 counts)?"""
    def rhs(t, y):
        return [y[1], -float(w.dV(y[0])) + F * math.sin(Omega * t + Psi)]

    def above(t, y):
        return 0.5 * y[1] ** 2 + float(w.V(y[0])) - xi_max
    above.terminal, above.direction = True, 1
    if above(0.0, [q0, p0]) > 0:
        return True
    sol = solve_ivp(rhs, (0.0, cycles * 2 * np.pi / Omega), [q0, p0], method="DOP853", rtol=1e-10, atol=1e-12,
                    events=above)
    return sol.t_events[0].size > 0


ELECTROSTATIC = {"expression": "q**2/2 - 0.05/(1 - q) + 0.05 + 0.05*q"}


@pytest.mark.parametrize("spec,Omegas,xi,F_top", [
    ("pendulum", (0.7, 1.05), 1.0, 1.0), ("sech2", (1.0, 1.5), 0.5, 1.0), ("morse", (1.0, 1.3), 0.5, 1.0),
    (ELECTROSTATIC, (0.75, 0.9), 0.1, 0.1)], ids=["pendulum", "sech2", "morse", "electrostatic"])
def test_fcr_against_dop853(spec, Omegas, xi, F_top):
    w = wells.resolve_well(spec)
    name = w.name
    cycles, n_scan = 150, 301
    f = critical_forcing_numeric(list(Omegas), xi, cycles=cycles, n_scan=n_scan, tol=2e-4, F_bracket=(0.0, F_top),
                                 well=w)
    step = f.attrs["F_scan_step"]
    for k, Om in enumerate(Omegas):
        assert not bool(f["non_monotone"].values[k])
        F_cr = float(f["F_cr"].values[k])
        assert np.isfinite(F_cr)
        assert not _dop853_escapes(w, F_cr - step, Om, xi, cycles), (name, Om, F_cr)
        assert _dop853_escapes(w, F_cr + step, Om, xi, cycles), (name, Om, F_cr)


# (q range, F / E_b): forcing at 0.9 of the linear frequency; on each chart some ICs are beyond
# at t = 0, some escape later (4-22 of 36) and some not within the horizon
CHARTS = {"pendulum": ((-1.9, 1.9), 0.06), "sech2": ((-1.4, 1.4), 0.1), "morse": ((-0.5, 1.5), 0.06),
          "electrostatic": ((-0.6, 0.45), 0.03)}


@pytest.mark.parametrize("name", sorted(CHARTS))
def test_chart_against_dop853_pixel_by_pixel(name):
    """A 6 x 6 escape chart (energy criterion, xi_max = 0.9 E_b, 40 cycles, SRKN6b at the default
    steps per cycle): at most 2 of 36 pixels may differ (ICs on the edge of the basin)."""
    w = wells.resolve_well(ELECTROSTATIC if name == "electrostatic" else name)
    (qa, qb), frac = CHARTS[name]
    Eb = w.barrier_energy
    xi, F, Om = 0.9 * Eb, frac * Eb, round(0.9 * float(w.omega(0.0)), 6)
    q0, p0 = np.linspace(qa, qb, 6), np.linspace(-0.8, 0.8, 6) * math.sqrt(Eb)
    c = escape_chart(q0, p0, F, Om, np.pi, xi_max=(xi,), cycles=40, well=w)
    e = c["escape_cycle_energy"].values[0]
    numeric = np.isfinite(e)
    ref = np.array([[_dop853_escapes(w, F, Om, xi, 40, a, b, np.pi) for b in p0] for a in q0])
    assert (numeric & (e > 0)).sum() >= 4 and (~numeric).sum() >= 4, e    # not vacuous: late escapes, safe ICs
    assert (numeric != ref).sum() <= 2, (name, numeric, ref)
