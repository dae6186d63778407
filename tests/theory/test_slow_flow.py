"""Slow flow (eqs 11, 18, 21): conservation, escape criterion vs traced slow flow and vs eq (1)."""
import numpy as np
import pytest
from scipy import integrate

from safebasins.theory import (G, H0, J, angle_energy, escapes_on_manifold, first_integral,
                               initial_condition, omega, saddles, slow_flow_escapes,
                               slow_flow_profile, slow_flow_rhs, xi_from_J)
from safebasins.theory.action_angle import dG_dxi


def _to_cartesian(gamma, xi):
    r = np.sqrt(2 * J(xi))
    return r * np.cos(gamma), r * np.sin(gamma)


def _from_cartesian(X, Y):
    return np.arctan2(Y, X), xi_from_J(0.5 * (X * X + Y * Y))


def test_first_integral_formula():
    g, x = 0.7, 0.13
    C = first_integral(g, x, 0.05, 0.9)
    assert C == pytest.approx(x - 0.9 * J(x) - 0.05 * G(x) * np.cos(g), rel=1e-14)
    Ce = first_integral(g, x, 0.05, 0.9, fourier="exact")
    assert Ce == pytest.approx(x - 0.9 * J(x) - 0.05 * G(x, "exact") * np.cos(g), rel=1e-14)
    assert first_integral(0.0, 0.0, 0.05, 0.9) == 0.0       # LPT passes through the well bottom


def test_cartesian_rhs_matches_polar_slow_flow():
    F, Om = 0.04, 0.85
    g, x = np.array([0.3, 2.0, -2.5]), np.array([0.05, 0.12, 0.2])
    X, Y = _to_cartesian(g, x)
    dX, dY = slow_flow_rhs(X, Y, F, Om)
    r = np.sqrt(2 * J(x))
    Jdot = (X * dX + Y * dY)                    # d(r^2/2)/dt
    gdot = (X * dY - Y * dX) / r ** 2
    np.testing.assert_allclose(Jdot, -F * G(x) * np.sin(g), rtol=1e-9)   # J' = -dC/dgamma
    np.testing.assert_allclose(gdot, omega(x) - Om - F * omega(x) * dG_dxi(x) * np.cos(g), rtol=1e-9)
    # regular at the well bottom
    dX0, dY0 = slow_flow_rhs(0.0, 0.0, F, Om)
    assert dX0 == 0.0 and dY0 == pytest.approx(-F / 2)
    dXs, dYs = slow_flow_rhs(1e-7, 0.0, F, Om)
    assert dXs == pytest.approx(0.0, abs=1e-6) and dYs == pytest.approx(-F / 2 + (1 - Om) * 1e-7, abs=1e-6)


@pytest.mark.parametrize("fourier", ["paper", "exact"])
def test_C_conserved_along_slow_flow(fourier):
    F, Om = 0.0478, 0.76

    def rhs(t, y):
        return np.array(slow_flow_rhs(y[0], y[1], F, Om, fourier), float)

    for g0, x0 in [(0.4, 0.02), (0.5, 0.1), (3.0, 0.22), (0.0, 0.0)]:   # safe orbits (island, saddle-type, LPT)
        y0 = _to_cartesian(g0, x0)
        sol = integrate.solve_ivp(rhs, (0, 60), y0, method="DOP853", rtol=1e-10, atol=1e-12,
                                  t_eval=np.linspace(0, 60, 61))
        g, x = _from_cartesian(sol.y[0], sol.y[1])
        C = first_integral(g, x, F, Om, fourier)
        assert np.ptp(x) > 0.005                     # it actually moved
        assert np.abs(C - C[0]).max() < 1e-9


def _rk4_escape(y, F, Om, xi_max, T, dt):
    """Vectorised RK4 of the Cartesian slow flow; True where xi reaches xi_max before T."""
    Jm = float(J(xi_max))
    X, Y = y
    esc = np.zeros(X.shape, bool)

    def f(X, Y):
        return slow_flow_rhs(X, Y, F, Om)

    for _ in range(int(T / dt)):
        live = ~esc
        if not live.any():
            break
        x, yy = X[live], Y[live]
        k1 = f(x, yy)
        k2 = f(x + 0.5 * dt * k1[0], yy + 0.5 * dt * k1[1])
        k3 = f(x + 0.5 * dt * k2[0], yy + 0.5 * dt * k2[1])
        k4 = f(x + dt * k3[0], yy + dt * k3[1])
        x = x + dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        yy = yy + dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        X[live], Y[live] = x, yy
        hit = np.zeros(X.shape, bool)
        hit[live] = 0.5 * (x * x + yy * yy) >= Jm
        esc |= hit
        X[esc], Y[esc] = 0.0, 0.0
    return esc


@pytest.mark.parametrize("F, Om, Psi, xi_max, T", [
    (0.0478, 0.76, 0.0, 0.235, 300.0),      # Fig 9: coexisting basin types
    (0.01, 0.9, np.pi, 0.08, 500.0),        # Fig 14: disjoint basins
    (0.015, 1.04, np.pi, 0.2, 400.0),       # Fig 13
])
def test_slow_flow_escapes_against_traced_slow_flow(F, Om, Psi, xi_max, T):
    rng = np.random.default_rng(7)
    q = rng.uniform(-0.95, 0.95, 400)
    p = rng.uniform(-0.7, 0.7, 400)
    inside = H0(q, p) < xi_max
    q, p = q[inside], p[inside]
    pred = slow_flow_escapes(q, p, F, Om, Psi, xi_max)
    theta, xi = angle_energy(q, p)
    gamma = theta - Psi
    # keep ICs whose level is clearly away from the critical levels (finite revolution time)
    prof = slow_flow_profile(F, Om, xi_max)
    c0 = first_integral(gamma, xi, F, Om)
    A, B = prof.suffix(xi)
    scale = F * G(xi_max)
    margin = np.minimum(np.abs(c0 - A), np.abs(c0 - B)) / scale
    keep = margin > 0.03
    keep[np.nonzero(keep)[0][30:]] = False
    assert keep.sum() >= 20 and 0 < pred[keep].sum() < keep.sum()
    X, Y = _to_cartesian(gamma[keep], xi[keep])
    traced = _rk4_escape((X.copy(), Y.copy()), F, Om, xi_max, T, dt=0.25)
    np.testing.assert_array_equal(traced, pred[keep])


def test_escapes_on_manifold_shape_and_edges():
    F, Om, xm = 0.0478, 0.76, 0.235
    g = np.linspace(-np.pi, np.pi, 7)[:, None]
    x = np.array([0.0, 0.1, 0.235, 0.24])[None, :]
    e = escapes_on_manifold(g, x, F, Om, xm)
    assert e.shape == (7, 4) and e.dtype == bool
    assert e[:, 2:].all()                                      # at / above xi_max
    assert not escapes_on_manifold(0.3, 0.1, 0.0, Om, xm)      # F = 0: energy conserved
    # symmetric in gamma
    gg = np.linspace(0, np.pi, 50)
    np.testing.assert_array_equal(escapes_on_manifold(gg, 0.12, F, Om, xm),
                                  escapes_on_manifold(-gg, 0.12, F, Om, xm))


def test_slow_flow_escapes_outside_well_and_broadcast():
    q0 = np.linspace(-1.2, 1.2, 9)[:, None]
    p0 = np.linspace(-0.8, 0.8, 5)[None, :]
    e = slow_flow_escapes(q0, p0, 0.01, 0.9, np.pi, 0.1)
    assert e.shape == (9, 5)
    assert e[0].all() and e[-1].all()                          # |q| >= 1
    assert (e[H0(q0, p0) >= 0.1]).all()
    assert not slow_flow_escapes(0.0, 0.0, 0.01, 0.9, np.pi, 0.1)


def test_saddle_is_a_critical_point_of_C():
    F, Om = 0.0478, 0.76
    (gs, xs), = saddles(F, Om, 0.235)
    h = 1e-6
    dCdx = (first_integral(gs, xs + h, F, Om) - first_integral(gs, xs - h, F, Om)) / (2 * h)
    dCdg = (first_integral(gs + h, xs, F, Om) - first_integral(gs - h, xs, F, Om)) / (2 * h)
    assert abs(dCdx) < 1e-8 and abs(dCdg) < 1e-8
    Cxx = (first_integral(gs, xs + 1e-4, F, Om) - 2 * first_integral(gs, xs, F, Om)
           + first_integral(gs, xs - 1e-4, F, Om)) / 1e-8
    Cgg = F * G(xs) * np.cos(gs)
    assert Cxx * Cgg < 0                                       # det H < 0, eq (25)


def test_against_real_dynamics_eq1():
    """Eq (1), q'' + q - q^3 = F sin(Omega tau + Psi), integrated directly for a few ICs well away
    from the predicted boundary (F = 0.015, Omega = 1.04, Psi = pi, xi_max = 0.2; Fig 13).

    At xi_ini = 0.185 the prediction depends on the phase: gamma_ini = 0 escapes, gamma_ini = pi is safe.
    A wrong sign/phase convention swaps them."""
    F, Om, Psi, xm = 0.015, 1.04, np.pi, 0.2

    def rhs(t, y):
        return [y[1], -y[0] + y[0] ** 3 + F * np.sin(Om * t + Psi)]

    def crossed(t, y):
        return 0.5 * y[1] ** 2 + 0.5 * y[0] ** 2 - 0.25 * y[0] ** 4 - xm
    crossed.terminal = True

    cases = [(0.185, 0.0), (0.185, 0.4), (0.185, np.pi), (0.18, np.pi - 0.6), (0.185, -0.3),
             (0.15, 1.0), (0.1, 0.4)]
    ring = 0.02 * np.exp(1j * np.linspace(0, 2 * np.pi, 12, endpoint=False))
    results = []
    for xi_ini, g0 in cases:
        q0, p0 = initial_condition(xi_ini, g0, Psi)
        pred = bool(slow_flow_escapes(q0, p0, F, Om, Psi, xm))
        # "well away from the boundary": every IC within 0.02 has the same prediction
        assert (slow_flow_escapes(q0 + ring.real, p0 + ring.imag, F, Om, Psi, xm) == pred).all()
        sol = integrate.solve_ivp(rhs, (0, 250 * 2 * np.pi / Om), [q0, p0], method="DOP853",
                                  rtol=1e-9, atol=1e-11, events=crossed)
        results.append((pred, sol.t_events[0].size > 0))
    preds = [r[0] for r in results]
    assert preds[0] and not preds[2]            # the phase matters for this set
    assert [r[0] for r in results] == [r[1] for r in results]


@pytest.mark.parametrize("call, name", [
    (lambda: first_integral(0.0, -0.1, 0.01, 0.9), "xi"),
    (lambda: first_integral(0.0, 0.26, 0.01, 0.9), "xi"),
    (lambda: first_integral(0.0, 0.1, -0.01, 0.9), "F"),
    (lambda: first_integral(0.0, 0.1, 0.01, 0.0), "Omega"),
    (lambda: first_integral(0.0, 0.1, 0.01, 0.9, fourier="x"), "fourier"),
    (lambda: escapes_on_manifold(0.0, 0.1, 0.01, -1.0, 0.2), "Omega"),
    (lambda: escapes_on_manifold(0.0, 0.1, 0.01, 0.9, 0.0), "xi_max"),
    (lambda: escapes_on_manifold(0.0, 0.1, 0.01, 0.9, 0.3), "xi_max"),
    (lambda: escapes_on_manifold(0.0, -0.1, 0.01, 0.9, 0.2), "xi"),
    (lambda: slow_flow_escapes(0.0, 0.0, -0.01, 0.9, 0.0, 0.2), "F"),
    (lambda: slow_flow_escapes(0.0, 0.0, 0.01, 0.9, np.nan, 0.2), "Psi"),
    (lambda: slow_flow_escapes(0.0, 0.0, 0.01, 0.9, 0.0, 0.26), "xi_max"),
    (lambda: slow_flow_escapes(0.0, np.nan, 0.01, 0.9, 0.0, 0.2), "p0"),
])
def test_out_of_domain_raises(call, name):
    with pytest.raises(ValueError, match=name):
        call()
