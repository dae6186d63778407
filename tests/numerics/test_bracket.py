"""The numeric F bracket follows the well: its static escape force, a bounded widening, DOP853 checks."""
import math
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from safebasins import wells
from safebasins.numerics import critical_forcing_numeric
from safebasins.numerics.bisection import BracketWarning, default_bracket

CYCLES = 200
#: V' and V in closed form (independent of the wells' own code), for the DOP853 reference
CLOSED = {
    "pendulum": (math.sin, lambda q: 1.0 - math.cos(q)),
    "sech2": (lambda q: 2.0 * math.tanh(q) / math.cosh(q) ** 2, lambda q: math.tanh(q) ** 2),
    "cubic": (lambda q: q - q * q, lambda q: q * q / 2.0 - q ** 3 / 3.0),
}


def dop853_escapes(well, F, Omega, xi_max, cycles=CYCLES):
    """Whether the zero IC reaches H0 > xi_max within `cycles` forcing cycles (DOP853, rtol 1e-10)."""
    dV, V = CLOSED[well]

    def rhs(t, y):
        return [y[1], -dV(y[0]) + F * math.sin(Omega * t)]

    def above(t, y):
        return 0.5 * y[1] ** 2 + V(y[0]) - xi_max
    above.terminal, above.direction = True, 1
    sol = solve_ivp(rhs, (0.0, cycles * 2.0 * math.pi / Omega), [0.0, 0.0], method="DOP853", rtol=1e-10,
                    atol=1e-12, events=above)
    return sol.t_events[0].size > 0


@pytest.mark.parametrize("spec,expected", [
    (None, 2.0 / (3.0 * math.sqrt(3.0))),               # q - q^3 at its inflection 1/sqrt(3)
    ("cubic", 0.25),                                     # q - q^2 at q = 1/2 (right side; the left one is steeper)
    ("pendulum", 1.0),                                   # sin q at pi/2
    ("sech2", 4.0 / (3.0 * math.sqrt(3.0))),            # 2 tanh sech^2 at tanh^2 = 1/3
    ("morse", 0.5),                                      # 2 (1 - e^-q) e^-q at q = ln 2 (open side)
    ({"expression": "q**2/(1 + q**2)"}, 9.0 / (8.0 * math.sqrt(3.0))),   # an algebraic tail open to infinity
])
def test_static_escape_force_closed_forms(spec, expected):
    w = wells.resolve_well(spec)
    assert w.static_escape_force == pytest.approx(expected, rel=1e-12)


def test_default_bracket_round_numbers():
    assert default_bracket(None) == (0.0, 0.39)
    assert default_bracket("cubic") == (0.0, 0.25)          # 1/4 stays 0.25 (not 0.26) whatever its last bit
    assert default_bracket("pendulum") == (0.0, 1.0)
    assert default_bracket("sech2") == (0.0, 0.77)


@pytest.mark.parametrize("well,xi_max,Omega", [("pendulum", 1.5, 0.7), ("sech2", 0.6, 0.9)])
def test_default_bracket_finds_what_dop853_finds(well, xi_max, Omega):
    """Above the quartic's old bracket top 0.3: finite F_cr with the well's bracket, within one scan
    step of DOP853 (no escape one step below, escape one step above)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ds = critical_forcing_numeric(Omega, xi_max, cycles=CYCLES, tol=1e-4, n_scan=101, well=well)
    f = float(ds["F_cr"][0])
    step = ds.attrs["F_scan_step"]
    assert 0.3 < f < ds.attrs["F_bracket"][1]
    assert int(ds["F_bracket_widenings"][0]) == 0
    assert float(ds["F_bracket_used_high"][0]) == ds.attrs["F_bracket"][1] == default_bracket(well)[1]
    assert not dop853_escapes(well, f - step, Omega, xi_max)
    assert dop853_escapes(well, f + step, Omega, xi_max)


def test_widening_above_resonance_matches_dop853_and_the_final_bracket():
    """The cubic forced at Omega = 1.6 (above resonance) escapes only above its static escape force 1/4:
    the bracket's top is doubled once; the result equals a call with the final bracket, and DOP853
    agrees within one scan step."""
    Om = np.array([0.8, 1.6])
    ds = critical_forcing_numeric(Om, 0.16, cycles=CYCLES, tol=1e-4, n_scan=51, well="cubic")
    assert ds["F_bracket_widenings"].values.tolist() == [0, 1]
    np.testing.assert_array_equal(ds["F_bracket_used_high"], [0.25, 0.5])
    assert np.isfinite(ds["F_cr"]).all()
    wide = critical_forcing_numeric(Om[1:], 0.16, cycles=CYCLES, tol=1e-4, n_scan=51, well="cubic",
                                    F_bracket=(0.0, 0.5))
    for v in ("F_cr", "F_cr_low", "F_cr_high", "F_escape_low", "F_escape_all", "non_monotone"):
        np.testing.assert_array_equal(ds[v].values[1:], wide[v].values)
    f = float(ds["F_cr"][1])
    step = 0.5 / 50
    assert f > 0.25
    assert not dop853_escapes("cubic", f - step, 1.6, 0.16)
    assert dop853_escapes("cubic", f + step, 1.6, 0.16)


def test_no_widening_where_the_bracket_holds():
    """An explicit bracket that contains the threshold is used as given (no extra ensembles)."""
    ds = critical_forcing_numeric([0.8, 0.9], 0.2, cycles=100, tol=1e-3, n_scan=11, F_bracket=(0.0, 0.3))
    assert ds["F_bracket_widenings"].values.tolist() == [0, 0]
    np.testing.assert_array_equal(ds["F_bracket_used_high"], [0.3, 0.3])
    assert ds.attrs["F_bracket"].tolist() == [0.0, 0.3] and ds.attrs["max_widenings"] == 3
    assert ds.attrs["F_static"] == pytest.approx(2.0 / (3.0 * math.sqrt(3.0)))


def test_lower_end_escaping_is_nan_with_a_warning():
    with pytest.warns(BracketWarning, match=r"F_bracket\[0\] = 0.5 already escapes"):
        ds = critical_forcing_numeric([0.9], 0.2, cycles=100, n_scan=0, F_bracket=(0.5, 0.6))
    assert np.isnan(ds["F_cr"]).all() and int(ds["F_bracket_widenings"][0]) == 0


@pytest.mark.parametrize("bad", [-1, 1.5, True, 21])
def test_max_widenings_checked(bad):
    with pytest.raises(ValueError, match="max_widenings"):
        critical_forcing_numeric([0.9], 0.2, cycles=10, max_widenings=bad)
