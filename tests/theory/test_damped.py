"""The damped slow flow (docs/damping.md) against the full damped equation of motion, the numeric
F_cr and chart, and its undamped limit.

Measured (quartic unless named; the bounds below leave a margin):

* envelope: F = 0.01, beta = 0.005, Omega = 0.98, zero IC, t <= 800: max |J_full - J_slow| = 0.18 F
  (Omega = 0.95 from q = 0.3: 0.26 F; cubic Omega = 0.97: 0.28 F); the phase within 0.04 rad;
* steady responses F = beta = 0.01: first harmonic of the full ODE within 0.3 F of 2 A(xi*) on
  both stable branches (relative 5e-2 on the small one, 4e-4 on the resonant one at Omega = 0.95);
  the fold Omega = 0.9599 (jump up) is crossed by the full ODE within +-0.004 of it;
* F_cr vs critical_forcing_numeric (2000 cycles), beta = 0.01 / 0.02: relative errors
  -1.5 / -1.1 % (Omega = 0.7) to -0.7 / -0.3 % (0.9), +12 / +11 % at 0.95 and +13 % at 1.0 -- the
  undamped errors there are -1.9 %, -1.0 %, +12 %, +13 %;
* beta = 1e-4: F_cr within 0.35 % of the undamped F_cr; safe-mask IoU 0.993 with the undamped one.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from safebasins import numerics as nu
from safebasins.theory import (UndecidedWarning, critical_forcing, slow_flow_escapes, slow_flow_outcomes,
                               slow_flow_rhs, slow_trajectory, steady_responses)
from safebasins.theory import damped_escape, damped_flow
from safebasins.theory.damped import from_tilde, rhs_exact, slow_tables, to_tilde
from safebasins.theory.responses import fixed_points
from safebasins.wells import QUARTIC, resolve_well

CUBIC = resolve_well("cubic")


def _full(F, Om, beta, y0, T, well, Psi=0.0):
    def f(t, y):
        return [y[1], -well.dV(y[0]) - beta * y[1] + F * np.sin(Om * t + Psi)]
    return solve_ivp(f, (0.0, T), y0, method="DOP853", rtol=1e-10, atol=1e-12, dense_output=True)


def _slow(F, Om, beta, gamma0, xi0, T, well):
    def f(t, y):
        return np.ravel(rhs_exact(well, np.asarray(y[0]), np.asarray(y[1]), F, Om, beta))
    y0 = np.array(to_tilde(well, gamma0, xi0), float)
    return solve_ivp(f, (0.0, T), y0, method="DOP853", rtol=1e-10, atol=1e-12, dense_output=True)


def _iou(a, b):
    return (a & b).sum() / (a | b).sum()


# ----------------------------------------------------------------------------- (1) the envelope
@pytest.mark.parametrize("well, Om, q0, bound", [(QUARTIC, 0.98, 0.0, 0.25), (QUARTIC, 0.95, 0.3, 0.35),
                                                 (CUBIC, 0.97, 0.0, 0.4)])
def test_envelope_against_full_ode(well, Om, q0, bound):
    """J of the full damped ODE (its energy's action) follows the slow trajectory within O(F)."""
    F, beta, T = 0.01, 0.005, 800.0
    theta0, xi0 = (0.0, 0.0) if q0 == 0 else (float(v) for v in well.angle_energy(np.array(q0), np.array(0.0)))
    full = _full(F, Om, beta, [q0, 0.0], T, well)
    slow = _slow(F, Om, beta, theta0, xi0, T, well)
    t = np.linspace(0.0, T, 4001)
    q, p = full.sol(t)
    J_full = well.J(np.clip(well.H0(q, p), 0.0, None))
    X, Y = slow.sol(t)
    J_slow = 0.5 * (X * X + Y * Y)
    assert J_slow.max() > 0.04                          # a real resonant excursion, not a small wiggle
    assert np.abs(J_full - J_slow).max() <= bound * F
    theta, _ = well.angle_energy(q, p)
    g_slow, _ = from_tilde(well, X, Y)
    dg = np.abs(np.angle(np.exp(1j * (theta - Om * t - g_slow))))
    assert dg[J_slow > 0.2 * J_slow.max()].max() < 0.06
    # the damping matters here: the undamped slow flow is off by much more
    und = _slow(F, Om, 0.0, theta0, xi0, T, well)
    Xu, Yu = und.sol(t)
    assert np.abs(J_full - 0.5 * (Xu * Xu + Yu * Yu)).max() > 2 * bound * F


# ----------------------------------------------------------------------------- (2) responses
def _first_harmonic(sol, Om, T, n=8):
    t = np.linspace(T - n * 2 * np.pi / Om, T, 256 * n, endpoint=False)
    return 2.0 * np.mean(sol.sol(t)[0] * np.exp(-1j * Om * t))


def test_steady_responses_against_full_ode():
    F, beta, Om = 0.01, 0.01, 0.95
    ds = steady_responses([Om], F, beta, xi_max=0.2)
    stable = np.nonzero(ds.stable.values[0])[0]
    assert int(ds.n_responses[0]) == 3 and stable.size == 2          # two attractors and a saddle
    assert list(ds.kind.values[0, :3]) == [2, 3, 2]
    for k in stable:
        xi, g = float(ds.xi[0, k]), float(ds.gamma[0, k])
        q0, p0 = QUARTIC.phase_point(np.array(g), np.array(xi))      # tau = 0, Psi = 0: theta = gamma
        sol = _full(F, Om, beta, [float(q0), float(p0)], 2000.0, QUARTIC)
        c1 = _first_harmonic(sol, Om, 2000.0)
        pred = -2j * float(QUARTIC.harmonic_amplitude(np.array(xi))) * np.exp(1j * g)   # q ~ 2 G sin(theta)
        assert abs(c1 - pred) < 0.3 * F, (xi, c1, pred)
    # the eigenvalues: trace -beta everywhere
    ev = ds.eig_real.values[0, :3] + 1j * ds.eig_imag.values[0, :3]
    np.testing.assert_allclose(ev.sum(axis=1).real, -beta, atol=1e-12)


def test_fold_against_full_ode():
    F, beta = 0.01, 0.01
    ds = steady_responses([0.9], F, beta)
    i = int(np.argmax(ds.Omega_fold.values))
    Of, xf, gf = float(ds.Omega_fold[i]), float(ds.xi_fold[i]), float(ds.gamma_fold[i])
    assert Of == pytest.approx(0.95992, abs=1e-4) and xf == pytest.approx(0.01715, abs=1e-4)
    # the number of responses changes across the fold (3 below, 1 above, xi < 0.2)
    n = steady_responses([Of - 1e-4, Of + 1e-4], F, beta, xi_max=0.2).n_responses.values
    assert list(n) == [3, 1]
    q0, p0 = QUARTIC.phase_point(np.array(gf), np.array(xf))
    ends = []
    for dO in (-0.004, 0.004):
        Om = Of + dO
        sol = _full(F, Om, beta, [float(q0), float(p0)], 2500.0, QUARTIC)
        t = np.linspace(2500.0 - 4 * 2 * np.pi / Om, 2500.0, 1024)
        ends.append(float(np.mean(QUARTIC.H0(*sol.sol(t)))))
    assert ends[0] < 0.012 and ends[1] > 0.04, ends          # stays low below the fold, jumps up above


def test_jacobian_determinant_formula():
    """det = F A cos(phi) dOmega/dJ along the response curve (docs/damping.md); trace = -beta."""
    from safebasins.theory.damped import coefficients
    from safebasins.theory.responses import _branches
    F, beta = 0.01, 0.01
    for well in (QUARTIC, CUBIC):
        fp = fixed_points(np.full(2, F), np.array([0.9, 0.95]), beta, well, 0.16)
        ok = fp.converged
        for x, ph, det, M in zip(fp.xi[ok], fp.phi[ok], fp.det[ok], fp.M[ok]):
            sg = 1 if np.cos(ph) > 0 else -1
            h = 1e-6 * x
            c = [{k: np.atleast_1d(v) for k, v in coefficients(well, np.array(z)).items()} for z in (x + h, x - h, x)]
            g = [_branches(ci, np.array([F]), np.zeros(1), beta)[0][sg][0, 0] for ci in c[:2]]
            dOm_dJ = (g[0] - g[1]) / (2 * h) * c[2]["omega"][0]
            assert det == pytest.approx(F * c[2]["A"][0] * np.cos(ph) * dOm_dJ, rel=1e-5)
            assert np.trace(M) == pytest.approx(-beta, abs=1e-9)
            assert np.linalg.det(M) == pytest.approx(det, rel=1e-8)


def test_tables_against_exact_flow():
    rng = np.random.default_rng(1)
    for well, top in ((QUARTIC, 0.2499), (CUBIC, 0.1666)):
        tab = slow_tables(well)
        xi = np.concatenate([rng.uniform(0.0, top, 1000), np.geomspace(1e-10, top, 100)])
        X, Y = to_tilde(well, rng.uniform(-np.pi, np.pi, xi.size), xi)
        for F, Om, beta in ((0.02, 0.9, 0.01), (0.0, 0.8, 0.05)):
            a = np.array(tab.rhs(X, Y, F, Om, beta))
            e = np.array(rhs_exact(well, X, Y, F, Om, beta))
            assert (np.abs(a - e).max(axis=0) / np.hypot(*e)).max() < 1e-5


# ----------------------------------------------------------------------------- (3) F_cr vs numerics
def test_critical_forcing_against_numeric():
    Om = np.array([0.75, 0.85, 0.9, 0.95])
    num = {b: nu.critical_forcing_numeric(Om, 0.2, cycles=1500, tol=1e-5, damping=b).F_cr.values
           for b in (0.0, 0.01)}
    err0 = critical_forcing(Om, 0.2).F_cr.values / num[0.0] - 1
    ds = critical_forcing(Om, 0.2, damping=0.01)
    err = ds.F_cr.values / num[0.01] - 1
    # measured: damped -1.4, -0.9, -0.7, +11.8 %; undamped -1.8, -1.4, -1.0, +12.1 %
    assert (np.abs(err) <= np.abs(err0) + 0.01).all(), (err, err0)
    assert (np.abs(err[:3]) < 0.03).all()
    assert (ds.F_cr.values > ds.F_cr_undamped.values).all() and not ds.undecided.values.any()
    assert (ds.F_settle.values < ds.F_cr.values).all()
    assert ((ds.F_cr - ds.F_settle) <= 1e-6 * ds.F_cr).all()


def test_critical_forcing_nonzero_ic_and_trajectory():
    """F_cr from a nonzero IC is where the slow trajectory switches from settling to escaping."""
    Om, beta, xm, x0, g0 = 0.9, 0.02, 0.2, 0.05, 1.0
    ds = critical_forcing([Om], xm, xi_ini=x0, gamma_ini=g0, damping=beta)
    F = float(ds.F_cr[0])
    assert np.isfinite(F)
    below = slow_trajectory(x0, g0, 0.999 * F, Om, xm, damping=beta)
    above = slow_trajectory(x0, g0, 1.001 * F, Om, xm, damping=beta)
    assert below.attrs["outcome"] == "settled" and above.attrs["outcome"] == "escaped"
    assert below.attrs["attractor_xi"] == pytest.approx(float(ds.xi_attractor[0]), rel=1e-3)
    assert float(above.xi[-1]) == pytest.approx(xm, rel=1e-6)


# ----------------------------------------------------------------------------- (4) beta -> 0
def test_small_damping_tends_to_undamped():
    Om = np.array([0.8, 0.9, 1.0])
    und = critical_forcing(Om, 0.2).F_cr.values
    dam = critical_forcing(Om, 0.2, damping=1e-4).F_cr.values
    np.testing.assert_allclose(dam, und, rtol=0.01)           # measured 0.03 .. 0.27 %
    assert (dam >= und).all()
    q, p = np.linspace(-0.9, 0.9, 60), np.linspace(-0.7, 0.7, 60)
    Q, P = np.meshgrid(q, p, indexing="ij")
    s0 = ~slow_flow_escapes(Q, P, 0.02, 0.9, np.pi, 0.2)
    s1 = ~slow_flow_escapes(Q, P, 0.02, 0.9, np.pi, 0.2, damping=1e-4)
    assert _iou(s0, s1) > 0.95                                  # measured 0.99


def test_damped_basin_against_numeric_chart():
    q, p = np.linspace(-0.9, 0.9, 60), np.linspace(-0.7, 0.7, 60)
    Q, P = np.meshgrid(q, p, indexing="ij")
    chart = nu.escape_chart(q, p, 0.02, 0.9, np.pi, xi_max=(0.2,), cycles=1000, damping=0.02, grid=True)
    safe_num = chart.escape_cycle_energy.squeeze().values > 1000
    safe = ~slow_flow_escapes(Q, P, 0.02, 0.9, np.pi, 0.2, damping=0.02)
    assert _iou(safe, safe_num) > 0.95                          # measured 0.98 (120 x 120, 2000 cycles)
    assert _iou(~slow_flow_escapes(Q, P, 0.02, 0.9, np.pi, 0.2), safe_num) < 0.6   # undamped theory: 0.44


# ----------------------------------------------------------------------------- decisions
def test_batch_decisions_match_per_ic_reference():
    rng = np.random.default_rng(3)
    xi = rng.uniform(0.0, 0.2, 12)
    g = rng.uniform(-np.pi, np.pi, 12)
    q0, p0 = QUARTIC.phase_point(g + np.pi, xi)                # Psi = pi: theta = gamma + Psi
    for beta, n in ((0.002, 12), (0.03, 3)):          # trapping loops, trapping ellipses
        st = slow_flow_outcomes(q0[:n], p0[:n], 0.02, 0.9, np.pi, 0.2, beta)
        trs = [slow_trajectory(x, gg, 0.02, 0.9, 0.2, damping=beta) for x, gg in zip(xi[:n], g[:n])]
        assert [damped_flow.STATUS[s] for s in st] == [tr.attrs["outcome"] for tr in trs]
        if beta == 0.002:
            assert {tr.attrs["outcome"] for tr in trs} == {"settled", "escaped"}
            assert any("loop" in tr.attrs["detection"] for tr in trs)
        else:
            assert all("ellipse" in tr.attrs["detection"] for tr in trs)


def test_undecided_is_reported_never_safe(monkeypatch):
    q, p = np.linspace(-0.5, 0.5, 7), np.linspace(-0.4, 0.4, 7)
    Q, P = np.meshgrid(q, p, indexing="ij")
    monkeypatch.setattr(damped_escape, "default_t_max", lambda pv, beta: np.full(pv.t_scale.shape, 1e-3))
    st = slow_flow_outcomes(Q, P, 0.02, 0.9, 0.0, 0.2, 0.01)
    und = st == damped_flow.UNDECIDED
    assert und.any()
    with pytest.warns(UndecidedWarning, match="undecided"):
        esc = slow_flow_escapes(Q, P, 0.02, 0.9, 0.0, 0.2, damping=0.01)
    assert esc[und].all()
    ds = critical_forcing([0.9], 0.2, damping=0.01)
    assert np.isnan(ds.F_cr.values).all() and ds.undecided.values.all()


# ----------------------------------------------------------------------------- (5), (6) API
def test_damping_zero_is_bitwise_the_undamped_code():
    Om = np.linspace(0.6, 1.2, 25)
    for kw in ({}, {"xi_ini": 0.1, "gamma_ini": 0.7}, {"well": "cubic", "xi_max": 0.15}):
        kw = {"xi_max": 0.2, **kw}
        a, b = critical_forcing(Om, **kw), critical_forcing(Om, damping=0.0, **kw)
        b.attrs["date_created"] = a.attrs["date_created"]      # the clock may pass a second between the calls
        assert a.identical(b)
        np.testing.assert_array_equal(a.F_cr.values, b.F_cr.values)
    q, p = np.linspace(-0.8, 0.8, 30), np.linspace(-0.6, 0.6, 30)
    Q, P = np.meshgrid(q, p, indexing="ij")
    for well in (None, "cubic"):
        np.testing.assert_array_equal(slow_flow_escapes(Q, P, 0.01, 0.9, np.pi, 0.15, well=well),
                                      slow_flow_escapes(Q, P, 0.01, 0.9, np.pi, 0.15, well=well, damping=0))


@pytest.mark.parametrize("bad", [-0.1, np.nan, np.inf, [0.1, 0.2], "x", 1j])
def test_bad_damping_named(bad):
    q = np.zeros(3)
    calls = [lambda: critical_forcing([0.9], 0.2, damping=bad),
             lambda: slow_flow_escapes(q, q, 0.01, 0.9, 0.0, 0.2, damping=bad),
             lambda: slow_flow_outcomes(q, q, 0.01, 0.9, 0.0, 0.2, bad),
             lambda: steady_responses([0.9], 0.01, bad),
             lambda: slow_trajectory(0.0, 0.0, 0.01, 0.9, 0.2, damping=bad)]
    for call in calls:
        with pytest.raises(ValueError, match="damping"):
            call()


def test_slow_flow_rhs_checks_its_arguments():
    X, Y = np.array([0.1, 0.2]), np.array([0.0, 0.1])
    ref = slow_flow_rhs(X, Y, 0.01, 0.9)
    for name, kw in (("F", {"F": -0.01}), ("F", {"F": np.nan}), ("Omega", {"Omega": 0.0}),
                     ("Omega", {"Omega": -1.0}), ("Omega", {"Omega": np.inf}), ("fourier", {"fourier": "exakt"}),
                     ("X", {"X": np.array([np.nan, 0.1])})):
        args = {"X": X, "Y": Y, "F": 0.01, "Omega": 0.9, **kw}
        with pytest.raises(ValueError, match=name):
            slow_flow_rhs(**args)
    with pytest.raises(ValueError, match="X, Y"):
        slow_flow_rhs(np.array([2.0]), np.array([0.0]), 0.01, 0.9)
    out = slow_flow_rhs(X, Y, 0.01, 0.9)
    np.testing.assert_array_equal(out[0], ref[0])


# ----------------------------------------------------------------------------- (7) another well
def test_cubic_well():
    Om = np.array([0.8, 0.9])
    ds = critical_forcing(Om, 0.12, well="cubic", damping=0.02)
    num = nu.critical_forcing_numeric(Om, 0.12, cycles=1000, tol=1e-5, damping=0.02, well="cubic").F_cr.values
    und_err = critical_forcing(Om, 0.12, well="cubic").F_cr.values / \
        nu.critical_forcing_numeric(Om, 0.12, cycles=1000, tol=1e-5, well="cubic").F_cr.values - 1
    err = ds.F_cr.values / num - 1
    assert (np.abs(err) <= np.abs(und_err) + 0.02).all(), (err, und_err)
    assert ds.attrs["well"] == "cubic"
    q, p = np.linspace(-0.6, 0.9, 40), np.linspace(-0.6, 0.6, 40)
    Q, P = np.meshgrid(q, p, indexing="ij")
    safe = ~slow_flow_escapes(Q, P, 0.03, 0.85, 0.0, 0.12, well="cubic", damping=0.05)
    chart = nu.escape_chart(q, p, 0.03, 0.85, 0.0, xi_max=(0.12,), cycles=1000, damping=0.05, well="cubic", grid=True)
    safe_num = chart.escape_cycle_energy.squeeze().values > 1000
    assert safe.sum() > 100 and _iou(safe, safe_num) > 0.85
    tr = slow_trajectory(0.0, 0.0, 0.5 * float(ds.F_cr[1]), 0.9, 0.12, damping=0.02, well="cubic")
    assert tr.attrs["outcome"] == "settled"
