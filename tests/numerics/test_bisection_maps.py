"""critical_forcing_numeric and stroboscopic_map."""
import numpy as np
import pytest

from safebasins.numerics import (critical_forcing_numeric, escape_chart, random_initial_conditions,
                                 stroboscopic_map)
from safebasins.numerics import kernels
from safebasins.numerics import schemes


@pytest.fixture(scope="module")
def fcr():
    return critical_forcing_numeric([0.8, 0.9, 1.0], 0.25, cycles=3000, n_scan=121, F_bracket=(0.0, 0.12))


def test_bisection_structure(fcr):
    assert fcr["F_cr"].dims == ("Omega",)
    for v in ("F_cr", "F_escape_low", "F_escape_all", "non_monotone"):
        assert v in fcr
    for k in ("xi_max", "q0", "p0", "Psi", "cycles", "tol", "criterion"):
        assert k in fcr.attrs
    assert np.all(fcr["F_cr_high"] - fcr["F_cr_low"] <= fcr.attrs["tol"])
    assert np.all((fcr["F_cr"] > 0) & (fcr["F_cr"] < 0.12))


def test_bisection_bracket_is_real(fcr):
    """F_cr_low does not escape, F_cr_high does (zero IC), each checked with escape_chart."""
    for Om, lo, hi in zip(fcr["Omega"].values, fcr["F_cr_low"].values, fcr["F_cr_high"].values):
        for F, esc in ((lo, False), (hi, True)):
            c = escape_chart([0.0], [0.0], F, Om, 0.0, xi_max=0.25, cycles=3000)
            assert np.isfinite(c["escape_cycle_energy"].values[0, 0, 0]) == esc


def test_scan_flags_non_monotone_near_0_9(fcr):
    f = fcr.sel(Omega=0.9)
    assert bool(f["non_monotone"])
    step = fcr.attrs["F_scan_step"]
    assert f["F_escape_low"] < f["F_escape_all"]
    assert 0.02 < f["F_escape_low"] < 0.035 and 0.02 < f["F_escape_all"] < 0.035
    # the bisection result lies inside the flickering band (up to one scan step)
    assert f["F_escape_low"] - step <= f["F_cr"] <= f["F_escape_all"]
    g = fcr.sel(Omega=0.8)
    assert not bool(g["non_monotone"])
    assert abs(g["F_cr"] - g["F_escape_low"]) <= step


def test_displacement_criterion_not_below_energy():
    e = critical_forcing_numeric([0.85, 1.0], 0.2, cycles=300, n_scan=0, F_bracket=(0, 0.2))
    d = critical_forcing_numeric([0.85, 1.0], 0.2, cycles=300, n_scan=0, F_bracket=(0, 0.2), criterion="displacement")
    assert np.all(d["F_cr_high"] >= e["F_cr_low"])
    assert d.attrs["criterion"] == "displacement"


def test_bracket_too_small_warns_naming_F_bracket():
    """A bracket whose upper end does not escape gives NaN with a warning, never silently."""
    from safebasins.numerics.bisection import BracketWarning

    with pytest.warns(BracketWarning, match=r"F_bracket = \(0, 0.001\) did not contain the escape threshold.*"
                                            r"F_bracket\[1\] = 0.001 does not escape within 100 cycles at "
                                            r"Omega = 0.9, 1 \(2 of 2\).*F_bracket=\(0, 0.004\)"):
        ds = critical_forcing_numeric([0.9, 1.0], 0.2, cycles=100, n_scan=0, F_bracket=(0.0, 0.001), max_widenings=0)
    assert np.isnan(ds["F_cr"]).all()
    # the widening is bounded: three doublings (0.008) still miss it, and the warning says so
    with pytest.warns(BracketWarning, match=r"F_bracket = \(0, 0.001\) did not contain the escape threshold.*"
                                            r"F_bracket\[1\] doubled 3 times, F = 0.008, does not escape within 100 "
                                            r"cycles at Omega = 0.9, 1 \(2 of 2\).*F_bracket=\(0, 0.032\)"):
        ds = critical_forcing_numeric([0.9, 1.0], 0.2, cycles=100, n_scan=0, F_bracket=(0.0, 0.001))
    assert np.isnan(ds["F_cr"]).all()
    assert ds["F_bracket_widenings"].values.tolist() == [3, 3]
    np.testing.assert_array_equal(ds["F_bracket_used_high"], [0.008, 0.008])
    with pytest.warns(BracketWarning, match=r"F_bracket\[0\] = 0.5 already escapes at Omega = 0.9 .*"
                                            r"F_bracket=\(0, 0.6\)"):
        critical_forcing_numeric([0.9], 0.2, cycles=100, n_scan=0, F_bracket=(0.5, 0.6))


@pytest.mark.parametrize("kw,name", [(dict(Omega=-1), "Omega"), (dict(xi_max=0.3), "xi_max"),
                                     (dict(tol=0), "tol"), (dict(F_bracket=(0.2, 0.1)), "F_bracket"),
                                     (dict(criterion="foo"), "criterion"), (dict(n_scan=1), "n_scan"),
                                     (dict(cycles=-3), "cycles"), (dict(q0=np.nan), "q0")])
def test_bisection_bad_arguments(kw, name):
    args = dict(Omega=[0.9], xi_max=0.25)
    args.update(kw)
    with pytest.raises(ValueError, match=name):
        critical_forcing_numeric(args.pop("Omega"), args.pop("xi_max"), **args)


def test_stroboscopic_map():
    q0, p0 = random_initial_conditions(40, 7, box=((-0.8, 0.8), (-0.6, 0.6)))
    m = stroboscopic_map(q0, p0, 0.0876, 0.99, np.pi, n_iter=200, xi_max=0.24)
    assert m["q"].dims == ("sample", "iteration") and m.sizes["iteration"] == 201
    np.testing.assert_array_equal(m["q"].values[:, 0][~np.isnan(m["q"].values[:, 0])],
                                  q0[~np.isnan(m["q"].values[:, 0])])
    esc = m["escaped"].values
    assert esc.any() and (~esc).any()
    assert np.array_equal(esc, np.isfinite(m["escape_cycle"].values))
    # non-escaping: every iterate finite and below the threshold; escaping: NaN from the escape period on
    H = 0.5 * m["p"] ** 2 + 0.5 * m["q"] ** 2 - 0.25 * m["q"] ** 4
    assert np.all(np.isfinite(m["q"].values[~esc])) and float(H.max()) <= 0.24
    for i in np.flatnonzero(esc):
        k = int(np.ceil(m["escape_cycle"].values[i]))
        assert np.all(np.isnan(m["q"].values[i, max(k, 1):])) or k == 0
        if k >= 1:
            assert np.all(np.isfinite(m["q"].values[i, :k]))
    # iterates equal the plain integrator's state after n periods (bitwise)
    safe = np.flatnonzero(~esc)[:3]
    S = m.attrs["steps_per_cycle"]
    for n in (1, 37, 200):
        q, p = kernels.final_states(q0[safe], p0[safe], np.zeros(safe.size, np.int64),
                                    schemes.lane_coefficients(0.99, S),
                              np.array([0.0876]), schemes.sine_table(S, np.pi), n)
        np.testing.assert_array_equal(q, m["q"].values[safe, n])
        np.testing.assert_array_equal(p, m["p"].values[safe, n])
    # escape times agree with escape_chart on the same ICs
    c = escape_chart(q0, p0, 0.0876, 0.99, np.pi, xi_max=0.24, cycles=200, grid=False)
    np.testing.assert_array_equal(c["escape_cycle_energy"].values[0], m["escape_cycle"].values)
    with pytest.raises(ValueError, match="n_iter"):
        stroboscopic_map(q0, p0, 0.01, 1.0, 0.0, n_iter=0)
    with pytest.raises(ValueError, match="q_max"):
        stroboscopic_map(q0, p0, 0.01, 1.0, 0.0, q_max=2.0)
    with pytest.raises(ValueError, match="xi_max"):
        stroboscopic_map(q0, p0, 0.01, 1.0, 0.0, xi_max=None, q_max=None)
