"""Classic RK4 in the compiled lane engine (integrator="rk4"): order, DOP853 agreement, known
energy loss, bitwise thread/lane/path independence, chart agreement with SRKN6b."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from safebasins.numerics import escape_chart
from safebasins.numerics import kernels
from safebasins.numerics import schemes
from safebasins.numerics import steps
from safebasins.numerics.scheme_code import scheme_code
from tests.numerics.ensemble import run_ensemble


def H0(q, p):
    return 0.5 * p * p + 0.5 * q * q - 0.25 * q ** 4


def run_rk4(q0, p0, F, Om, Psi, S, periods):
    q0 = np.atleast_1d(np.asarray(q0, float))
    p0 = np.atleast_1d(np.asarray(p0, float))
    return kernels.final_states(q0, p0, np.zeros(q0.size, np.int64), schemes.lane_coefficients(Om, S, "rk4"),
                                np.array([float(F)]), schemes.sine_table(S, Psi, "rk4"), periods,
                                scheme=scheme_code("rk4"))


def test_tables_select_the_scheme():
    assert schemes.sine_table(16, 0.3, "rk4").shape == (16, 3)
    assert schemes.sine_table(16, 0.3).shape == (16, 7)
    c = schemes.lane_coefficients(0.95, 16, "rk4")[0]
    h = 2 * np.pi / (0.95 * 16)
    assert c[0] == h * 0.5 and c[1] == h and c[2] == h * (1.0 / 6.0) and not c[3:].any()
    with pytest.raises(ValueError, match="integrator"):
        escape_chart([0.0], [0.0], 0.01, 1.0, 0.0, cycles=1, integrator="euler")


def test_rk4_observed_order_four():
    F, Om, Psi = 0.03, 0.95, 1.0
    q0, p0 = np.array([0.2, -0.35]), np.array([0.1, 0.25])
    ref = np.array(run_rk4(q0, p0, F, Om, Psi, 2048, 10))
    err = np.array([np.abs(np.array(run_rk4(q0, p0, F, Om, Psi, S, 10)) - ref).max() for S in (32, 64, 128, 256)])
    orders = np.log2(err[:-1] / err[1:])          # measured 4.85, 4.09, 3.63
    overall = np.log2(err[0] / err[-1]) / 3       # measured 4.19
    assert np.all((orders > 3.5) & (orders < 5.0)) and 3.8 < overall < 4.3, (err, orders)


@pytest.mark.parametrize("q0,p0,F,Om,Psi", [(0.1, 0.0, 0.05, 0.95, np.pi), (0.3, 0.2, 0.02, 1.1, 0.3),
                                            (0.2, -0.1, 0.0876, 1.5, np.pi)])
def test_rk4_single_trajectories_agree_with_dop853(q0, p0, F, Om, Psi):
    periods, S = 20, 256
    T = 2 * np.pi / Om

    def rhs(t, y):
        return [y[1], -y[0] + y[0] ** 3 + F * np.sin(Om * t + Psi)]
    sol = solve_ivp(rhs, (0, periods * T), [q0, p0], method="DOP853", rtol=1e-12, atol=1e-13)
    q, p = run_rk4(q0, p0, F, Om, Psi, S, periods)
    assert abs(q[0] - sol.y[0, -1]) < 1e-7 and abs(p[0] - sol.y[1, -1]) < 1e-7


def test_rk4_energy_loss_known_figures():
    """F = 0, Omega = 1, ICs at rest at H0 = 0.01 ... 0.249: RK4 drains energy; relative loss
    after 3000 cycles ~1.6e-3 (max over the ICs) at 64 steps/cycle, ~4.9e-5 at 128."""
    E0 = np.array([0.01, 0.1, 0.2, 0.24, 0.249])
    q0 = np.sqrt(1 - np.sqrt(1 - 4 * E0))
    for S, lo, hi in ((64, 1.0e-3, 2.5e-3), (128, 3e-5, 8e-5)):
        q, p = run_rk4(q0, np.zeros_like(q0), 0.0, 1.0, 0.0, S, 3000)
        rel = (H0(q, p) - E0) / E0
        assert (rel < 0).all(), rel                      # loss, not gain
        assert lo < -rel.min() < hi, (S, rel)


def test_rk4_escape_step_is_first_step_beyond_threshold():
    """The engine's recorded step is the first RK4 step whose state is beyond the threshold
    (replay of the same arithmetic as the vector loop)."""
    F, Om, Psi, S = 0.05, 0.95, 0.0, 32
    sE, _ = run_ensemble([0.0], [0.0], [0], [Om], [F], Psi, xi_max=[0.05, 0.2], cycles=200,
                              steps_per_cycle=S, integrator="rk4")
    c = schemes.lane_coefficients(Om, S, "rk4")[0]
    tab = F * schemes.sine_table(S, Psi, "rk4")
    q = p = 0.0
    e2 = [0.0]
    for n in range(int(sE.max()) + 2):
        q, p = steps.scalar_step("rk4")(steps.W0, q, p, tuple(c), tuple(tab[n % S]))
        e2.append(steps.energy2(q, p))
    e2 = np.array(e2)
    for j, x in enumerate((0.05, 0.2)):
        assert sE[0, j] == int(np.argmax(e2 > 2 * x))


def test_rk4_and_srkn_charts_agree_away_from_grazing():
    """Escape / no-escape at xi_max = 0.24 within 100 cycles: RK4 (64 steps/cycle) equals SRKN6b
    on every IC whose SRKN verdict is robust (safe also at xi_max = 0.23, or escaping within 90
    cycles also at xi_max = 0.25)."""
    q = np.linspace(-1, 1, 60)
    s = escape_chart(q, q, 0.0876, 0.95, np.pi, xi_max=(0.23, 0.24, 0.25), cycles=100)
    r = escape_chart(q, q, 0.0876, 0.95, np.pi, xi_max=0.24, cycles=100, steps_per_cycle=64, integrator="rk4")
    es = s["escape_cycle_energy"].values
    er = r["escape_cycle_energy"].values[0]
    robust_safe = np.isinf(es[0])
    robust_esc = es[2] <= 90
    assert robust_safe.sum() > 100 and robust_esc.sum() > 2000
    assert np.isinf(er[robust_safe]).all()
    assert np.isfinite(er[robust_esc]).all()
    assert np.mean(np.isinf(er) == np.isinf(es[1])) > 0.995
