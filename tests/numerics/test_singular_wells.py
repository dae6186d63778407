"""Numerics of wells with singular walls (MEMS pole beyond the barrier, Lennard-Jones core) against
DOP853: the numeric F_cr with the well's default bracket, and a small escape chart."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from safebasins import theory, wells
from safebasins.numerics import critical_forcing_numeric, escape_chart

MEMS = "q**2/2 - 0.02/(1-q) + 0.02 + 0.02*q"
LJ = "(1+q)**-12 - 2*(1+q)**-6 + 1"
CLOSED = {MEMS: (lambda q: q * q / 2 - 0.02 / (1 - q) + 0.02 + 0.02 * q, lambda q: q + 0.02 - 0.02 / (1 - q) ** 2),
          LJ: (lambda q: (1 + q) ** -12 - 2 * (1 + q) ** -6 + 1, lambda q: -12 * (1 + q) ** -13 + 12 * (1 + q) ** -7)}


def dop853_escapes(text, F, Omega, Psi, xi_max, q0, p0, cycles):
    """H0 > xi_max within `cycles` forcing cycles (DOP853, rtol 1e-10) for the closed-form well."""
    V, dV = CLOSED[text]

    def rhs(t, y):
        return [y[1], -dV(y[0]) + F * math.sin(Omega * t + Psi)]

    def above(t, y):
        return 0.5 * y[1] ** 2 + V(y[0]) - xi_max
    above.terminal, above.direction = True, 1
    if above(0.0, [q0, p0]) > 0:
        return True
    sol = solve_ivp(rhs, (0.0, cycles * 2.0 * math.pi / Omega), [q0, p0], method="DOP853", rtol=1e-10,
                    atol=1e-12, events=above)
    return sol.t_events[0].size > 0


@pytest.mark.parametrize("text,frac", [(MEMS, 0.9), (LJ, 0.8)])
def test_numeric_fcr_within_one_scan_step_of_dop853(text, frac):
    """Zero IC, xi_max = 0.8 E_b, the well's default bracket; the analytic F_cr is finite."""
    w = wells.from_spec({"expression": text})
    xi = 0.8 * w.barrier_energy
    Om = round(frac * float(w.omega(0.0)), 6)
    ds = critical_forcing_numeric(Om, xi, cycles=200, tol=1e-4, n_scan=101, well=w)
    f, step = float(ds["F_cr"][0]), ds.attrs["F_scan_step"]
    assert int(ds["F_bracket_widenings"][0]) == 0 and not bool(ds["non_monotone"][0])
    assert not dop853_escapes(text, f - step, Om, 0.0, xi, 0.0, 0.0, 200)
    assert dop853_escapes(text, f + step, Om, 0.0, xi, 0.0, 0.0, 200)
    assert np.isfinite(theory.critical_forcing(np.array([Om]), xi, well=w)["F_cr"].values).all()


def test_mems_analytic_fcr_near_the_numeric():
    """The isolated-resonance theory on the MEMS well (moderately anharmonic): within 3% of the
    numeric F_cr at 0.8-1.0 omega(0) (measured 0.6-2.6%, 200 cycles)."""
    w = wells.from_spec({"expression": MEMS})
    xi = 0.8 * w.barrier_energy
    Om = np.round(np.array([0.8, 0.9]) * float(w.omega(0.0)), 6)
    a = theory.critical_forcing(Om, xi, well=w)["F_cr"].values
    n = critical_forcing_numeric(Om, xi, cycles=200, tol=1e-4, n_scan=0, well=w)["F_cr"].values
    np.testing.assert_allclose(a, n, rtol=0.03)


def test_small_chart_agrees_with_dop853_pixel_by_pixel():
    """A 5 x 5 escape chart of the MEMS well (energy criterion, 40 cycles) against DOP853."""
    w = wells.from_spec({"expression": MEMS})
    xi = 0.9 * w.barrier_energy
    F, Om, Psi = 0.03, round(0.9 * float(w.omega(0.0)), 6), math.pi
    q0, p0 = np.linspace(-0.6, 0.7, 5), np.linspace(-0.5, 0.5, 5)
    c = escape_chart(q0, p0, F, Om, Psi, xi_max=(xi,), cycles=40, well=w)
    numeric = np.isfinite(c["escape_cycle_energy"].values[0])
    ref = np.array([[dop853_escapes(MEMS, F, Om, Psi, xi, a, b, 40) for b in p0] for a in q0])
    assert 0 < ref.sum() < ref.size                        # both outcomes on the grid
    assert (numeric == ref).mean() >= 24 / 25
