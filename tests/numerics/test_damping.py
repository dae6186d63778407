"""The damped equation q'' + beta q' + V'(q) = F sin(Omega t + Psi) in the engines:
damping = 0 is the undamped code bitwise; the damped schemes (conformal symplectic SRKN6b, RK4
with -beta p) have order 4 and agree with scipy's DOP853 pixel for pixel on a damped chart of the
escape equation below the Melnikov tangency."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from safebasins import wells
from safebasins.numerics import critical_forcing_numeric, escape_chart, kernels, stroboscopic_map
from safebasins.numerics import schemes
from safebasins.numerics.scheme_code import scheme_code


def test_zero_damping_is_the_undamped_code():
    q = np.linspace(-0.9, 0.9, 9)
    a = escape_chart(q, q, 0.0876, 0.95, np.pi, xi_max=(0.2,), q_max=(0.8,), cycles=30, steps_per_cycle=16)
    b = escape_chart(q, q, 0.0876, 0.95, np.pi, xi_max=(0.2,), q_max=(0.8,), cycles=30, steps_per_cycle=16,
                     damping=0.0)
    for v in ("escape_cycle_energy", "escape_cycle_displacement"):
        np.testing.assert_array_equal(a[v].values, b[v].values)
    assert "damping" not in b.attrs and b.attrs["integrator"] == a.attrs["integrator"]
    c = escape_chart(q, q, 0.0876, 0.95, np.pi, xi_max=(0.2,), cycles=30, steps_per_cycle=16, damping=0.05)
    assert c.attrs["damping"] == 0.05 and "conformal" in c.attrs["integrator"]


def _reference(q0, p0, F, Omega, beta, t_end, well):
    def rhs(t, y):
        return [y[1], -float(well.dV(y[0])) - beta * y[1] + F * np.sin(Omega * t)]
    sol = solve_ivp(rhs, (0.0, t_end), [q0, p0], method="DOP853", rtol=1e-13, atol=1e-14)
    return sol.y[:, -1]


@pytest.mark.parametrize("integrator", ["srkn6b", "rk4"])
def test_damped_schemes_have_order_four(integrator):
    """Final states after 3 forcing periods of the cubic with beta = 0.3 against DOP853: the error
    falls by ~2^4 per halving of the step."""
    w = wells.cubic()
    code = w.compiled
    F, Omega, beta, n = 0.05, 0.85, 0.3, 3
    q0, p0 = np.array([0.3, -0.2]), np.array([0.1, 0.25])
    ref = np.array([_reference(a, b, F, Omega, beta, n * 2 * np.pi / Omega, w) for a, b in zip(q0, p0)])
    err = []
    for S in (16, 32, 64):
        q, p = kernels.final_states(q0, p0, np.zeros(2, np.int64),
                                    schemes.lane_coefficients(Omega, S, integrator, beta),
                                    np.array([F]), schemes.sine_table(S, 0.0, integrator), n, well=code,
                                    scheme=scheme_code(integrator, beta > 0))
        err.append(np.max(np.abs(np.stack([q, p], 1) - ref)))
    rates = np.log2(np.array(err[:-1]) / np.array(err[1:]))
    assert (rates > 3.6).all() and (rates < 4.6).all(), (err, rates)


def test_damped_chart_matches_dop853_pixel_for_pixel():
    """Thompson's escape equation (the cubic) at beta = 0.1, Omega = 0.85, F = 0.05 (below the
    Melnikov tangency F_M = beta sinh(pi Omega) / (5 pi Omega^2) = 0.063): escape (H0 > 1/6 or
    q > 1) within 60 cycles, engine (SRKN6b damped, 64 steps per cycle) vs DOP853 (rtol 1e-11)."""
    w = wells.cubic()
    F, Omega, beta, cycles = 0.05, 0.85, 0.1, 60
    q0, p0 = np.linspace(-0.6, 0.95, 12), np.linspace(-0.6, 0.6, 10)
    ch = escape_chart(q0, p0, F, Omega, 0.0, xi_max=(1.0 / 6.0,), cycles=cycles, steps_per_cycle=64, well=w,
                      damping=beta)
    engine_escape = np.isfinite(ch["escape_cycle_energy"].isel(xi_max=0).values)

    def rhs(t, y):
        return [y[1], -y[0] + y[0] ** 2 - beta * y[1] + F * np.sin(Omega * t)]

    def out(t, y):
        return min(1.0 / 6.0 - (0.5 * y[1] ** 2 + 0.5 * y[0] ** 2 - y[0] ** 3 / 3.0), 1.0 - y[0])
    out.terminal, out.direction = True, -1
    ref = np.zeros_like(engine_escape)
    for i, a in enumerate(q0):
        for j, b in enumerate(p0):
            if out(0.0, [a, b]) <= 0:
                ref[i, j] = True
                continue
            sol = solve_ivp(rhs, (0.0, cycles * 2 * np.pi / Omega), [a, b], method="DOP853", rtol=1e-11,
                            atol=1e-12, events=out)
            ref[i, j] = sol.t_events[0].size > 0
    assert 0.2 < engine_escape.mean() < 0.9
    np.testing.assert_array_equal(engine_escape, ref)


def test_damped_map_and_bisection():
    """With damping a trajectory inside the basin settles: the stroboscopic map converges to the
    attracting periodic orbit (period-1 fixed point); the numeric F_cr takes damping and grows
    with it."""
    m = stroboscopic_map([0.1, -0.05], [0.0, 0.1], 0.02, 0.85, 0.0, n_iter=400, xi_max=1.0 / 6.0, well="cubic",
                         damping=0.1)
    q = m["q"].values
    assert not m["escaped"].values.any()
    np.testing.assert_allclose(q[0, -1], q[1, -1], atol=1e-9)
    np.testing.assert_allclose(q[:, -1], q[:, -2], atol=1e-9)
    f0 = critical_forcing_numeric([0.85], 0.12, cycles=200, n_scan=0, tol=1e-3, F_bracket=(0.0, 0.3), well="cubic")
    f1 = critical_forcing_numeric([0.85], 0.12, cycles=200, n_scan=0, tol=1e-3, F_bracket=(0.0, 0.3), well="cubic",
                                  damping=0.05)
    assert f1["F_cr"].values[0] > f0["F_cr"].values[0] and f1.attrs["damping"] == 0.05


@pytest.mark.parametrize("bad", [-0.1, np.nan, np.inf, [0.1, 0.2], "x"])
def test_bad_damping_is_named(bad):
    with pytest.raises(ValueError, match="damping"):
        escape_chart([0.1], [0.0], 0.01, 0.9, 0.0, cycles=2, damping=bad, grid=False)
