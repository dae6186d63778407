"""Schemes as data (numerics.schemes, numerics.scheme_code): every scheme of SCHEMES and a scheme
added as one constant integrate the forced quartic with their order against DOP853 (undamped and
damped), keep the free oscillator's energy bounded when symplectic, and have the stability limit
their constants imply; the generated step is the scheme's one-step map on a linear force."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from safebasins import wells
from safebasins.numerics import escape_chart, kernels, schemes, steps
from safebasins.wells import compiled
from safebasins.numerics.engine import check_step
from safebasins.numerics.scheme_code import scheme_code

#: a scheme added as one constant: Stoermer-Verlet (velocity form), order 2
VERLET = schemes.Splitting(name="verlet", title="Stoermer-Verlet (order 2)", order=2, drift=(1.0,), kick=(0.5, 0.5))


@pytest.fixture
def with_verlet(monkeypatch):
    monkeypatch.setitem(schemes.SCHEMES, VERLET.name, VERLET)
    return VERLET.name


#: the free oscillator V = q^2/2 as a compiled code (no Well: it has no barrier)
HARMONIC = compiled.polynomial_code([0.0, 0.0, 0.5], (-np.inf, np.inf), name="harmonic")


def _final(integrator, q0, p0, F, Omega, beta, S, n, code=None):
    code = code or wells.QUARTIC.compiled
    return np.stack(kernels.final_states(
        q0, p0, np.zeros(q0.size, np.int64), schemes.lane_coefficients(Omega, S, integrator, beta), np.array([F]),
        schemes.sine_table(S, 0.4, integrator), n, well=code, scheme=scheme_code(integrator, beta > 0)), 1)


def _dop853(q0, p0, F, Omega, beta, t_end):
    def rhs(t, y):
        return [y[1], -y[0] + y[0] ** 3 - beta * y[1] + F * math.sin(Omega * t + 0.4)]
    return np.array([solve_ivp(rhs, (0.0, t_end), [a, b], method="DOP853", rtol=1e-13, atol=1e-14).y[:, -1]
                     for a, b in zip(q0, p0)])


@pytest.mark.parametrize("beta", [0.0, 0.1])
@pytest.mark.parametrize("integrator", [*schemes.SCHEMES, "verlet"])
def test_measured_order_of_convergence(integrator, beta, with_verlet):
    """Error of the final state after 4 periods against DOP853 (rtol 1e-13) falls by 2^order per
    halving of the step (measured: SRKN6b 4.0, RK4 4.0, Forest-Ruth 4.0, Verlet 2.0; damped alike)."""
    order = schemes.scheme_of(integrator).order
    F, Omega, n = 0.04, 0.9, 4
    q0, p0 = np.array([0.3, -0.2]), np.array([0.1, 0.25])
    ref = _dop853(q0, p0, F, Omega, beta, n * 2 * np.pi / Omega)
    err = [np.abs(_final(integrator, q0, p0, F, Omega, beta, S, n) - ref).max() for S in (32, 64, 128, 256)]
    rates = np.log2(np.array(err[:-1]) / np.array(err[1:]))
    # pre-asymptotic at the coarsest step (RK4: 4.4, 4.3, 4.1): the finest rate within 0.3
    assert np.all(np.abs(rates - order) < 0.6) and abs(rates[-1] - order) < 0.3, (integrator, beta, err, rates)


def _energy_error(integrator, S, cycles):
    """Max relative |H0 - E| over `cycles` periods of the free quartic oscillator (F = 0, Omega = 1)
    from rest at E = 0.2, sampled once per period."""
    q, p = np.array([np.sqrt(1 - np.sqrt(1 - 0.8))]), np.zeros(1)
    worst = 0.0
    for _ in range(cycles // 50):
        q, p = _final(integrator, q, p, 0.0, 1.0, 0.0, S, 50).T
        worst = max(worst, abs(float(wells.QUARTIC.H0(q[0], p[0])) - 0.2) / 0.2)
    return worst


def test_energy_error_bounded_for_symplectic_schemes():
    """F = 0, 32 steps per period, from rest at H0 = 0.2: the symplectic schemes' energy error
    stays bounded (no drift between 500 and 2000 periods) while RK4's grows; measured max relative
    error over 500 / 2000 periods: SRKN6b 3.06e-8 / 3.09e-8, Forest-Ruth 1.24e-4 / 1.28e-4 (its
    error constant is ~4000 times SRKN6b's), RK4 7.0e-3 / 2.8e-2 (drains energy)."""
    err = {s: (_energy_error(s, 32, 500), _energy_error(s, 32, 2000)) for s in schemes.SCHEMES}
    for name, s in schemes.SCHEMES.items():
        short, long = err[name]
        if isinstance(s, schemes.Splitting):
            assert long < 1e-3 and long < 1.5 * short + 1e-12, (name, err)
        else:
            assert long > 3 * short, (name, err)
    assert err["srkn6b"][1] < err["forest-ruth"][1] < err["rk4"][1], err


def test_stability_limits_from_the_constants():
    """RK4's limit on the imaginary axis is 2 sqrt 2 (closed form); every limit is where the free
    oscillator's one-step map stops being bounded: 1e4 steps just below stay bounded, just above
    grow (the compiled step of a harmonic well, V = q^2/2)."""
    assert schemes.stability_limit("rk4") == pytest.approx(2 * math.sqrt(2), abs=1e-9)
    assert schemes.stability_limit("srkn6b") == pytest.approx(3.1635, abs=1e-3)
    for name in schemes.SCHEMES:
        x = schemes.stability_limit(name)
        grows = []
        for xh in (0.999 * x, 1.001 * x):
            S = 64
            Omega = 2 * np.pi / (S * xh)          # h = 2 pi / (Omega S) = xh, omega = 1
            q = _final(name, np.array([1.0]), np.array([0.0]), 0.0, Omega, 0.0, S, 160, HARMONIC)
            grows.append(float(np.hypot(*q[0])))
        assert grows[0] < 100.0 and not grows[1] < 1e6, (name, x, grows)
        assert schemes.step_limit(name) == schemes.STABILITY_FRACTION * x


def test_stability_scan_is_the_pointwise_test():
    """The vectorised scan that finds the limit decides every h as the one-point test does (the
    harmonic one-step matrix, RK's stability function), on both sides of each limit and for a
    scheme added as one constant."""
    xs = np.linspace(1e-3, 6.0, 3001)
    for s in (*schemes.SCHEMES.values(), VERLET):
        lim = schemes.stability_limit(s)
        keep = np.abs(xs - lim) > 1e-9
        many = schemes._stable_many(s, xs)
        one = np.array([schemes._stable(s, float(x)) for x in xs])
        assert np.array_equal(many[keep], one[keep]), s.name
        assert many[xs < lim].all() and not many[xs > lim + 1e-9].all(), s.name
    assert schemes.stability_limit(VERLET) == pytest.approx(2.0, abs=1e-9)      # h omega < 2, closed form


def test_step_check_uses_the_scheme_limit():
    """The engine refuses a step beyond the scheme's own limit: RK4 (1.41) refuses a step SRKN6b
    (1.58) accepts."""
    h = 1.5                       # h * omega_max for the quartic (omega_max = sqrt(2)): S below
    S = math.ceil(2 * np.pi * math.sqrt(2) / (0.5 * h))
    Omega = 2 * np.pi * math.sqrt(2) / (S * 1.5)
    check_step(Omega, S, None, "srkn6b")
    with pytest.raises(ValueError, match="steps_per_cycle"):
        check_step(Omega, S, None, "rk4")


@pytest.mark.parametrize("integrator", [*schemes.SCHEMES, "verlet"])
def test_generated_step_is_the_schemes_map(integrator, with_verlet):
    """On a linear force (V = q^2/2, F = 0) one compiled step is the scheme's one-step matrix
    (Splitting.harmonic_matrix; RK: the stability function's real form) to 1e-15."""
    s = schemes.scheme_of(integrator)
    h = 0.3
    code = scheme_code(integrator)
    step = steps.scalar_step(integrator, well=HARMONIC)
    c = schemes.lane_coefficients(2 * np.pi / h, 1, integrator)[0]     # S = 1: h = 2 pi / Omega
    w = steps.wtuple(HARMONIC.wpar)
    for y in ((1.0, 0.0), (0.0, 1.0)):
        q, p = step(w, y[0], y[1], tuple(c), (0.0,) * code.width)
        if isinstance(s, schemes.Splitting):
            expect = s.harmonic_matrix(h) @ np.array(y)
        else:
            R = s.amplification(1j * h)          # q - i p obeys w' = i w: one step multiplies it by R(i h)
            z = complex(y[0], -y[1]) * R
            expect = np.array([z.real, -z.imag])
        assert np.allclose([q, p], expect, rtol=0, atol=1e-15), (integrator, y, (q, p), expect)


def test_added_scheme_runs_in_the_engine(with_verlet):
    """One constant is enough: the Verlet scheme integrates an escape chart (shared and per-lane
    loops, replay) and agrees with SRKN6b on most pixels at a fine step."""
    q = np.linspace(-0.8, 0.8, 9)
    a = escape_chart(q, q, 0.05, 0.9, 0.0, xi_max=(0.2,), cycles=30, steps_per_cycle=256, integrator="verlet")
    b = escape_chart(q, q, 0.05, 0.9, 0.0, xi_max=(0.2,), cycles=30, steps_per_cycle=256)
    assert a.attrs["integrator"] == VERLET.title
    ea, eb = a.escape_cycle_energy.values, b.escape_cycle_energy.values
    assert np.mean(np.isfinite(ea) == np.isfinite(eb)) > 0.95


def test_schemes_are_checked():
    with pytest.raises(ValueError, match="integrator"):
        schemes.scheme_of("leapfrog")
    with pytest.raises(ValueError, match="one kick more"):
        schemes.Splitting(name="x", title="x", order=2, drift=(0.5, 0.5), kick=(1.0,))
    with pytest.raises(ValueError, match="sum to 1"):
        schemes.Splitting(name="x", title="x", order=2, drift=(0.9,), kick=(0.5, 0.5))
