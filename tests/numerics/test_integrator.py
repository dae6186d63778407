"""Integrator of safebasins.numerics: energy drift, convergence order, DOP853 agreement,
exact escape steps, bitwise independence of threads / tasks / lanes."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from safebasins.numerics import engine
from safebasins.numerics import kernels
from safebasins.numerics import schemes
from safebasins.numerics import steps
from safebasins.numerics.scheme_code import scheme_code
from tests.numerics.ensemble import run_ensemble


def H0(q, p):
    return 0.5 * p * p + 0.5 * q * q - 0.25 * q ** 4


def run_final(q0, p0, F, Om, Psi, S, periods):
    q0 = np.atleast_1d(np.asarray(q0, float))
    p0 = np.atleast_1d(np.asarray(p0, float))
    return kernels.final_states(q0, p0, np.zeros(q0.size, np.int64), schemes.lane_coefficients(Om, S),
                          np.array([float(F)]), schemes.sine_table(S, Psi), periods)


def dop853(q0, p0, F, Om, Psi, t_end, **kw):
    def rhs(t, y):
        return [y[1], -y[0] + y[0] ** 3 + F * np.sin(Om * t + Psi)]
    return solve_ivp(rhs, (0, t_end), [q0, p0], method="DOP853", rtol=1e-12, atol=1e-13, **kw)


def test_energy_drift_free_oscillator_3000_cycles():
    """F = 0: the symplectic scheme keeps H0 bounded; at the default steps_per_cycle the
    relative error after 3000 cycles is far below the 1e-5 requirement (measured ~3e-8)."""
    E0 = np.array([0.02, 0.1, 0.18, 0.22, 0.24, 0.245])
    q0 = np.sqrt(1 - np.sqrt(1 - 4 * E0))          # turning points, p = 0
    q, p = run_final(q0, np.zeros_like(q0), 0.0, 1.0, 0.0, engine.DEFAULT_STEPS_PER_CYCLE, 3000)
    rel = np.abs(H0(q, p) - H0(q0, 0 * q0)) / E0
    assert rel.max() < 1e-6, rel


def test_observed_order_four():
    F, Om, Psi = 0.03, 0.95, 1.0
    q0, p0 = np.array([0.2, -0.35]), np.array([0.1, 0.25])
    ref = np.array(run_final(q0, p0, F, Om, Psi, 1024, 10))
    err = []
    for S in (16, 32, 64):
        err.append(np.abs(np.array(run_final(q0, p0, F, Om, Psi, S, 10)) - ref).max())
    orders = np.log2(np.array(err[:-1]) / np.array(err[1:]))
    assert np.all((orders > 3.6) & (orders < 4.6)), (err, orders)


@pytest.mark.parametrize("q0,p0,F,Om,Psi", [(0.1, 0.0, 0.05, 0.95, np.pi), (0.3, 0.2, 0.02, 1.1, 0.3),
                                            (0.2, -0.1, 0.0876, 1.5, np.pi)])
def test_single_trajectories_agree_with_dop853(q0, p0, F, Om, Psi):
    periods, S = 20, 64
    T = 2 * np.pi / Om
    sol = dop853(q0, p0, F, Om, Psi, periods * T)
    assert sol.success
    q, p = run_final(q0, p0, F, Om, Psi, S, periods)
    assert abs(q[0] - sol.y[0, -1]) < 1e-7 and abs(p[0] - sol.y[1, -1]) < 1e-7


def _steps_one_by_one(q, p, F, Om, Psi, S, n_steps):
    """Python loop over the same compiled step: the state after every step."""
    c = schemes.lane_coefficients(Om, S)[0]
    tab = F * schemes.sine_table(S, Psi)
    out = np.empty((n_steps + 1, 2))
    out[0] = q, p
    for n in range(n_steps):
        f = tab[n % S]
        q, p = steps.scalar_step("srkn6b")(steps.W0, q, p, tuple(c), tuple(f))
        out[n + 1] = q, p
    return out


def test_escape_step_exact_constructed_case():
    """Resonant forcing from rest: the recorded step is the first step whose state is beyond
    each threshold (same arithmetic, step by step), and it brackets the continuous crossing
    time from DOP853 to within one step."""
    F, Om, Psi, S = 0.05, 0.95, 0.0, 32
    xi = np.array([0.05, 0.12, 0.2])
    qm = np.array([0.3, 0.5, 0.7])
    sE, sQ = run_ensemble([0.0], [0.0], [0], [Om], [F], Psi, xi_max=xi, q_max=qm, cycles=200,
                               steps_per_cycle=S)
    assert (sE > 0).all() and (sQ > 0).all()
    traj = _steps_one_by_one(0.0, 0.0, F, Om, Psi, S, int(max(sE.max(), sQ.max())) + 2)
    e2 = np.array([steps.energy2(a, b) for a, b in traj])
    for j, x in enumerate(xi):
        first = int(np.argmax(e2 > 2 * x))
        assert sE[0, j] == first
    for j, x in enumerate(qm):
        first = int(np.argmax(np.abs(traj[:, 0]) > x))
        assert sQ[0, j] == first
    # continuous crossing times (DOP853 events) lie within one step before the recorded step
    h_cyc = 1.0 / S
    T = 2 * np.pi / Om
    for j, x in enumerate(qm):
        ev = lambda t, y, x=x: abs(y[0]) - x
        ev.terminal = True
        ev.direction = 1
        sol = dop853(0.0, 0.0, F, Om, Psi, 200 * T, events=ev)
        t_cross = sol.t_events[0][0] / T
        assert sQ[0, j] / S - h_cyc - 1e-6 <= t_cross <= sQ[0, j] / S + 1e-6


def test_initial_condition_beyond_threshold_is_zero():
    sE, sQ = run_ensemble([0.9, 0.0, 1.2], [0.0, 0.0, 0.0], [0, 0, 0], [1.0], [0.01], 0.0,
                               xi_max=[0.2, 0.25], q_max=[0.5, 1.0], cycles=5, steps_per_cycle=16)
    # H0(0.9, 0) = 0.2410: beyond 0.2, not beyond 0.25; |q| = 0.9 beyond 0.5, not beyond 1
    assert sE[0, 0] == 0 and sE[0, 1] != 0
    assert sQ[0, 0] == 0 and sQ[0, 1] != 0
    assert (sE[1] == -1).all() and (sQ[1] == -1).all()      # at rest at the bottom, tiny forcing
    assert (sE[2] == 0).all() and (sQ[2] == 0).all()        # beyond the barrier: out of the well


@pytest.mark.parametrize("integrator", ["srkn6b", "rk4"])
def test_bitwise_independent_of_threads_tasks_and_lanes(integrator):
    import numba
    from safebasins.numerics import escape_chart
    q = np.linspace(-1, 1, 40)
    kw = dict(xi_max=(0.2, 0.25), q_max=(0.8, 1.0), cycles=60, integrator=integrator)
    a = escape_chart(q, q, 0.0876, 0.95, np.pi, threads=1, **kw)
    b = escape_chart(q, q, 0.0876, 0.95, np.pi, threads=min(2, numba.config.NUMBA_NUM_THREADS), **kw)
    assert a.attrs["integrator"] == schemes.SCHEMES[integrator].title
    assert ("RK4" in a.attrs["integrator"]) == (integrator == "rk4")
    for v in ("escape_cycle_energy", "escape_cycle_displacement"):
        np.testing.assert_array_equal(a[v].values, b[v].values)
    # different task partition / lane count / per-lane parameter path
    Q, P = np.meshgrid(q, q, indexing="ij")
    Q, P = Q.ravel(), P.ravel()
    N = Q.size
    S = 32
    res = []
    for n_tasks, lanes, npar in ((1, 128, 1), (7, 64, 1), (3, 128, 2)):   # npar 2: per-lane path
        coef = np.repeat(schemes.lane_coefficients(0.95, S, integrator), npar, 0)
        oE = np.full((N, 2), -1, np.int64)
        oQ = np.full((N, 2), -1, np.int64)
        kernels.ensemble(Q, P, np.arange(N) % npar, coef, np.repeat(schemes.step_sizes(0.95, S), npar),
                         np.full(npar, 0.0876), schemes.sine_table(S, np.pi, integrator),
                         2 * np.array([0.2, 0.25]), np.array([0.8, 1.0]), 60, False, n_tasks, lanes, oE, oQ,
                         np.empty((0, 0, 2)), False, scheme=scheme_code(integrator))
        res.append((oE, oQ))
    for oE, oQ in res[1:]:
        np.testing.assert_array_equal(oE, res[0][0])
        np.testing.assert_array_equal(oQ, res[0][1])
    np.testing.assert_array_equal(engine.steps_to_cycles(res[0][0], S),
                                  a["escape_cycle_energy"].values.reshape(2, -1).T)
