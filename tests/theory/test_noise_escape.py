"""The averaged theory's backward-equation solver (docs/noise-theory.md) against closed forms.

Independent routes and the measured errors (the bounds below leave a margin):

* 2-D Brownian motion in a disc (isotropic coefficients, no drift): the mean exit time
  ``(R^2 - r^2)/(4 D)`` (exact to rounding: the finite volumes are exact for functions linear in J)
  and the exit-time distribution from the Bessel series ``1 - sum 2 J_0(j_n r/R) e^{-j_n^2 D t/R^2}
  / (j_n J_1(j_n))``: max error 2.4e-4, 3.6e-5, 8e-6, 6e-6 at t = 0.1, 0.5, 1, 2 R^2/(4D) on 128 x 160 cells and
  400 steps (second order: 1.1e-3 on 64 x 80, 200 steps);
* the forced-free quartic without damping: Dynkin's formula ``E tau = 2 (xi_max - xi) / sigma^2``
  (exact also for the full equation, E dH0 = sigma^2/2 dt): relative error 4e-6;
* the damped linear oscillator, F = 0: ``E tau = (Ein(k J_max) - Ein(k J)) / beta``,
  ``k = 2 beta omega / sigma^2`` (energy diffusion in closed form): relative error 2e-5;
* the thermal, damped quartic, F = 0: the energy-diffusion quadrature of docs/noise.md
  (an integral over the energy, not over J) to xi_max = 0.2 at xi_max/T = 4: relative error 3e-5
  (32 x 400 cells; 1.7e-4 on the default 128 x 160);
* the semi-Lagrangian march (the default) against the central finite volumes where those are
  resolved (Fig 14's forcing, sigma = 0.01, default cells): max difference 0.013 within 10 cycles;
  where they are not (sigma = 0.0025, F = 0.03) the central march is refused naming ``cells`` and
  the semi-Lagrangian one stays in [0, 1].
"""

import numpy as np
import pytest
from scipy import integrate, special
from scipy.integrate import solve_ivp

from safebasins import theory
from safebasins.theory.damped import rhs_exact
from safebasins.theory.noise_averaging import AveragedDiffusion
from safebasins.theory.noise_solver import DiscGrid, generator, interpolation, march_escape, solve_first_passage
from safebasins.wells import QUARTIC, resolve_well


def _linear(J_max, omega=1.0):
    Jn = np.linspace(0.0, J_max, 50)
    c = np.full(50, 0.5 / omega)
    return AveragedDiffusion(Jn, H=omega * Jn, omega=np.full(50, omega), a=np.full(50, 0.5 / np.sqrt(omega)),
                             a_r=c, a_t=c)


def test_disc_brownian_motion():
    d = _linear(0.5)                       # R = 1; sigma = 1: covariance rate 1/2, D = 1/4
    g = DiscGrid(128, 160, 0.5)
    M, s = generator(g, d, 0.0, 1.0, 0.0, 1.0)
    gam, J = np.array([0.3, 1.0, 2.0, 0.0]), np.array([0.0, 0.05, 0.2, 0.45])
    W, wb = interpolation(g, gam, J)
    r2 = 2 * J
    assert np.allclose(solve_first_passage(M, W)[0], (1 - r2) / (4 * 0.25), rtol=1e-12, atol=1e-12)
    t, P, _ = march_escape(M, s, W, wb, 2.0, 400)
    jz = special.jn_zeros(0, 400)
    for tt, tol in ((0.1, 5e-4), (0.5, 1e-4), (1.0, 3e-5), (2.0, 3e-5)):
        k = int(round(tt / 2.0 * 400))
        S = (2 / (jz * special.j1(jz)) * special.j0(np.outer(np.sqrt(r2), jz)) * np.exp(-jz ** 2 * 0.25 * tt)).sum(1)
        assert np.max(np.abs(P[k] - (1 - S))) < tol
    # the march is monotone in time and in [0, 1] here (no advection)
    assert np.all(np.diff(P, axis=0) >= -1e-12) and P.min() >= -1e-12 and P.max() <= 1 + 1e-12


def test_undamped_quartic_dynkin():
    xi_max, sigma, Omega = 0.18, 0.02, 0.9
    xi = np.array([0.0, 0.05, 0.1, 0.17])
    q0 = np.zeros_like(xi)
    p0 = np.sqrt(2 * xi)                   # on q = 0: H0 = p^2 / 2
    ds = theory.mean_first_passage(q0, p0, 0.0, Omega, 0.0, xi_max, noise=sigma, grid=False)
    expect = 2 * (xi_max - xi) / sigma ** 2 * Omega / (2 * np.pi)
    assert ds["mean_first_passage"].dims == ("sample",)
    assert np.max(np.abs(ds["mean_first_passage"].values / expect - 1)) < 1e-4


def test_damped_linear_oscillator():
    beta, sigma, J_max = 0.05, 0.1, 0.2
    k = 2 * beta / sigma ** 2
    Ein = lambda x: special.expi(x) - np.euler_gamma - np.log(x)
    d = _linear(J_max)
    g = DiscGrid(64, 200, J_max)
    M, _ = generator(g, d, 0.0, 1.0, beta, sigma)
    J = np.array([0.01, 0.05, 0.1, 0.18])
    W, _ = interpolation(g, np.zeros_like(J), J)
    T = solve_first_passage(M, W)[0]
    expect = (Ein(k * J_max) - Ein(k * J)) / beta
    assert np.max(np.abs(T / expect - 1)) < 1e-3


def test_thermal_quartic_energy_diffusion():
    beta, xi_max, Omega = 0.02, 0.2, 0.9
    temp = xi_max / 4
    sigma = np.sqrt(2 * beta * temp)
    inner = lambda y: integrate.quad(lambda z: 2 * np.pi / QUARTIC.omega(z) * np.exp(-z / temp), 0, y)[0]
    tau = integrate.quad(lambda y: np.exp(y / temp) / (beta * temp * 2 * np.pi * QUARTIC.J(y)) * inner(y), 0, xi_max,
                         limit=200)[0]
    ds = theory.mean_first_passage([0.0], [0.0], 0.0, Omega, 0.0, xi_max, noise=sigma, damping=beta, grid=False,
                                   cells=(32, 400))
    assert float(ds["mean_first_passage"][0]) * 2 * np.pi / Omega == pytest.approx(tau, rel=1e-3)


def test_escape_probability_dataset():
    q0, p0 = np.linspace(-0.9, 0.9, 5), np.linspace(-0.7, 0.7, 4)
    ds = theory.escape_probability(q0, p0, 0.01, 0.9, np.pi, 0.18, noise=0.01, t_eval=[0, 2.5, 5],
                                   cells=(32, 40))
    assert ds["P_escape"].dims == ("q0", "p0", "t_eval")
    assert ds["P_escape"].attrs["units"] == "1" and ds["t_eval"].attrs["long_name"]
    assert ds.attrs["noise"] == 0.01 and ds.attrs["cycles"] == 5
    P = ds["P_escape"].values
    assert np.all(np.isfinite(P)) and np.all(np.diff(P, axis=-1) >= -1e-9)
    assert P.min() >= -1e-12 and P.max() <= 1 + 1e-12
    H = QUARTIC.H0(*np.meshgrid(q0, p0, indexing="ij"))
    beyond = (H >= 0.18) | (np.abs(q0)[:, None] >= 1)
    assert np.all(P[beyond] == 1) and np.all(P[~beyond, 0] < 1e-9)
    # first_passage_mean is the restricted mean: 0 where escaped at once, at most the horizon
    fp = ds["first_passage_mean"].values
    assert np.all(fp[beyond] == 0) and np.all((fp >= 0) & (fp <= 5 + 1e-9))


def test_semi_lagrangian_against_central_and_in_range():
    # where the central finite volumes are resolved (sigma = 0.01) the two marches agree; where they
    # oscillate (sigma = 0.0025, F = 0.03) the central march is an error naming cells and the
    # semi-Lagrangian one stays in [0, 1]
    q0, p0 = np.linspace(-0.6, 0.6, 9), np.linspace(-0.5, 0.5, 7)
    kw = {"t_eval": [5, 10], "cells": (64, 80)}
    fine = {"t_eval": [5, 10]}
    sl = theory.escape_probability(q0, p0, 0.01, 0.9, np.pi, 0.18, noise=0.01, **fine)
    ce = theory.escape_probability(q0, p0, 0.01, 0.9, np.pi, 0.18, noise=0.01, advection="central", **fine)
    assert float(abs(sl["P_escape"] - ce["P_escape"]).max()) < 0.05
    hard = theory.escape_probability(q0, p0, 0.03, 0.9, np.pi, 0.18, noise=0.0025, **kw)
    assert float(hard["P_escape"].min()) >= -1e-12 and float(hard["P_escape"].max()) <= 1 + 1e-12
    with pytest.raises(ValueError, match="cells"):
        theory.escape_probability(q0, p0, 0.03, 0.9, np.pi, 0.18, noise=0.0025, advection="central", **kw)
    with pytest.raises(ValueError, match="cells"):
        theory.mean_first_passage(q0, p0, 0.03, 0.9, np.pi, 0.18, noise=0.0025, cells=(64, 80))


@pytest.mark.parametrize("kw, name", [({"noise": -1.0}, "noise"),
                                      ({"t_eval": [-1.0]}, "t_eval"), ({"cells": (4, 40)}, "cells"),
                                      ({"advection": "quick"}, "advection"), ({"damping": -0.1}, "damping"),
                                      ({"steps_per_cycle": 0}, "steps_per_cycle")])
def test_bad_input_named(kw, name):
    args = {"noise": 0.01, "t_eval": [1.0]} | kw
    with pytest.raises(ValueError, match=name):
        theory.escape_probability([0.1], [0.1], 0.01, 0.9, 0.0, 0.18, **args)


def test_mean_first_passage_needs_noise():
    with pytest.raises(ValueError, match="noise must be > 0"):
        theory.mean_first_passage([0.1], [0.1], 0.01, 0.9, 0.0, 0.18, noise=0.0)


@pytest.mark.parametrize("well, F, xi_max, beta, window", [
    ("quartic", 0.01, 0.18, 0.0, (0.95, 0.75)),
    ("cubic", 0.005, 0.12, 0.0, (0.46, 0.52)),
    ("cubic", 0.005, 0.12, 0.05, (0.46, 0.52)),       # the sheared frame's damping drift -beta d
])
def test_noise_free_limit_is_the_slow_flow(well, F, xi_max, beta, window):
    # noise 0: each IC's slow trajectory; at a long horizon its escape is the slow flow's own
    # classification (level curves of C, or the damped flow's attractors: an independent route)
    q = np.linspace(-window[0], 1.5 * window[0] if well == "cubic" else window[0], 25)
    p = np.linspace(-window[1], window[1], 21)
    ds = theory.escape_probability(q, p, F, 0.9, np.pi, xi_max, noise=0.0, t_eval=[5, 300], well=well,
                                   damping=beta, cells=(16, 20), steps_per_cycle=4)
    P = ds["P_escape"].values
    assert set(np.unique(P)) <= {0.0, 1.0} and (P[..., 0] <= P[..., 1]).all()
    det = theory.slow_flow_escapes(q[:, None], p[None, :], F, 0.9, np.pi, xi_max, well=well, damping=beta)
    assert 0 < det.mean() < 1 and np.array_equal(P[..., 1].astype(bool), det)
    fp = ds["first_passage_mean"].values
    assert np.all(fp[P[..., 1] == 0] == 300) and np.all(fp[P[..., 1] == 1] <= 300)


@pytest.mark.parametrize("well, F, beta, ics", [
    ("quartic", 0.01, 0.0, [(-0.65, 0.0), (-0.6, 0.25), (-0.3, 0.0)]),
    ("cubic", 0.005, 0.005, [(-0.36, 0.173), (-0.11, -0.47), (0.44, -0.025), (0.0, 0.0)]),
])
def test_noise_free_first_passage_times_against_dop853(well, F, beta, ics):
    # the slow trajectory's first passage of xi_max against scipy's DOP853 on the well's exact slow
    # flow (damped.rhs_exact, in the sheared frame: phase theta - Psi + delta(xi)); the march's times
    # are the first RK4 substep at or past the threshold (1/64 cycle at 8 steps per cycle)
    w = resolve_well(well)
    xi_max = 0.18 if well == "quartic" else 0.12
    q, p = np.array([c[0] for c in ics]), np.array([c[1] for c in ics])
    ds = theory.escape_probability(q, p, F, 0.9, np.pi, xi_max, noise=0.0, t_eval=[200], well=w, damping=beta,
                                   grid=False, cells=(16, 20))
    period = 2 * np.pi / 0.9
    J_max = float(w.J(xi_max))
    hit = 0
    for k, (q0, p0) in enumerate(ics):
        theta, xi = w.angle_energy(np.array(q0), np.array(p0))
        phi = float(theta) - np.pi + float(w.harmonic_shift(xi))
        r = np.sqrt(2 * float(w.J(xi)))
        event = lambda t, y: 0.5 * (y[0] ** 2 + y[1] ** 2) - J_max
        event.terminal = True
        sol = solve_ivp(lambda t, y: rhs_exact(w, np.array(y[0]), np.array(y[1]), F, 0.9, beta), (0, 200 * period),
                        [r * np.cos(phi), r * np.sin(phi)], method="DOP853", rtol=1e-9, atol=1e-12, events=event)
        got = float(ds["first_passage_mean"][k])
        if sol.t_events[0].size:
            hit += 1
            assert 0 <= got - sol.t_events[0][0] / period <= 1 / 64 + 0.01, (q0, p0)
        else:
            assert got == 200 and float(ds["P_escape"][k, 0]) == 0
    assert hit >= 2


def test_small_noise_tends_to_the_noise_free_limit():
    q, p = np.linspace(-0.95, 0.95, 21), np.linspace(-0.75, 0.75, 17)
    kw = dict(t_eval=[20], cells=(64, 80))
    P0 = theory.escape_probability(q, p, 0.01, 0.9, np.pi, 0.18, noise=0.0, **kw)["P_escape"].values
    d = [np.abs(theory.escape_probability(q, p, 0.01, 0.9, np.pi, 0.18, noise=s, **kw)["P_escape"].values - P0).mean()
         for s in (0.004, 0.002, 0.001)]
    print(d)
    assert d[0] > d[1] > d[2]


def test_bad_threshold_named():
    with pytest.raises(ValueError, match="xi_max"):
        theory.mean_first_passage([0.1], [0.1], 0.01, 0.9, 0.0, 0.25, noise=0.01)
