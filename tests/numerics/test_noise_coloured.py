"""Coloured noise (an Ornstein-Uhlenbeck force of correlation time tau): the splitting's moments
have weak order 2 on the forced, damped harmonic oscillator (closed-form Gaussian moments of the
three-dimensional linear system), the kernel's sample moments are the scheme's, the force is
stationary with variance sigma^2 / (2 tau), and escape probabilities in the quartic agree with a
small-step Euler-Maruyama reference in plain numpy."""
from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from safebasins.numerics import noise_kernels, schemes
from safebasins.numerics.noise import escape_probability
from safebasins.numerics.scheme_code import scheme_code
from safebasins.wells.compiled import polynomial_code

BETA, SIGMA, TAU, F, OMEGA, PSI, Q0, P0, CYCLES = 0.5, 0.5, 0.7, 0.3, 1.3, 0.4, 0.2, -0.1, 2
HARMONIC = polynomial_code([0.0, 0.0, 0.5], (-math.inf, math.inf), "harmonic")
SCHEME = scheme_code("srkn6b", True)


def _exact_moments():
    """Mean and covariance of (q, p, eta) at the end from the moment ODEs (DOP853, rtol 1e-13),
    eta(0) ~ N(0, sigma^2 / (2 tau))."""
    A = np.array([[0.0, 1.0, 0.0], [-1.0, -BETA, 1.0], [0.0, 0.0, -1.0 / TAU]])
    D = np.diag([0.0, 0.0, SIGMA ** 2 / TAU ** 2])

    def rhs(t, y):
        C = y[3:].reshape(3, 3)
        dm = A @ y[:3] + np.array([0.0, F * math.sin(OMEGA * t + PSI), 0.0])
        return np.concatenate([dm, (A @ C + C @ A.T + D).ravel()])

    C0 = np.diag([0.0, 0.0, SIGMA ** 2 / (2 * TAU)])
    T = CYCLES * 2 * math.pi / OMEGA
    y = solve_ivp(rhs, (0.0, T), np.concatenate([[Q0, P0, 0.0], C0.ravel()]), method="DOP853", rtol=1e-13,
                  atol=1e-14).y[:, -1]
    return y[:3], y[3:].reshape(3, 3)


def _run(S, paths, seed, noise, q0=(Q0,), p0=(P0,), n_steps=None, F_=F, table=None):
    coef = schemes.lane_coefficients([OMEGA], S, "srkn6b", BETA)
    tab = schemes.sine_table(S, PSI) if table is None else table
    return noise_kernels.final_states(HARMONIC, SCHEME, np.array(q0, float), np.array(p0, float), paths, coef, tab,
                                      F_, CYCLES * S if n_steps is None else n_steps, noise, seed)


def _scheme_moments(S):
    """The splitting's mean and covariance of (q, p, eta): the half steps A (eta = c1 eta + c2 Z)
    around the deterministic step B = [[M, G], [0, 1]], M the kernel's one-step map of the
    unforced oscillator, G its response to a unit constant force (a forcing table of ones)."""
    h = 2 * math.pi / (OMEGA * S)
    nz = noise_kernels.step_noise(SIGMA, h, TAU)
    off = noise_kernels.StepNoise(0.0)
    qm, pm, _ = _run(S, 1, 0, off)
    qa, pa, _ = _run(S, 1, 0, off, q0=(1.0, 0.0, 0.0), p0=(0.0, 1.0, 0.0), n_steps=1, F_=0.0)
    qg, pg, _ = _run(S, 1, 0, off, q0=(0.0,), p0=(0.0,), n_steps=1, F_=1.0,
                     table=np.ones((S, len(SCHEME.scheme.times))))
    B = np.array([[qa[0, 0], qa[1, 0], qg[0, 0]], [pa[0, 0], pa[1, 0], pg[0, 0]], [0.0, 0.0, 1.0]])
    A = np.diag([1.0, 1.0, nz.c1])
    b = np.diag([0.0, 0.0, nz.c2 ** 2])
    C = np.diag([0.0, 0.0, nz.s_eta ** 2])
    for _ in range(CYCLES * S):
        C = A @ C @ A.T + b
        C = B @ C @ B.T
        C = A @ C @ A.T + b
    return np.array([qm[0, 0], pm[0, 0], 0.0]), C


def test_coloured_splitting_has_weak_order_two():
    """Errors of Var q, Var p and Cov(q, p) fall 4x per halving of h (log2 ratios in
    [1.8, 2.2] from 8 to 32 steps per cycle); eta's variance is exact (the OU steps are)."""
    _, C = _exact_moments()
    errs = []
    for S in (8, 16, 32):
        _, Cs = _scheme_moments(S)
        assert math.isclose(Cs[2, 2], C[2, 2], rel_tol=1e-12)
        errs.append(np.abs(Cs - C)[[0, 0, 1], [0, 1, 1]])
    errs = np.array(errs)
    orders = np.log2(errs[:-1] / errs[1:])
    assert ((orders > 1.8) & (orders < 2.2)).all(), (errs, orders)


def test_coloured_kernel_moments_are_the_scheme_moments():
    """200000 paths at 4 and 8 steps per cycle: sample mean and covariance of (q, p, eta) equal
    the splitting's within 5 standard errors; eta keeps its stationary variance sigma^2 / (2 tau)."""
    n = 200_000
    _, C = _exact_moments()
    for S in (4, 8):
        ms, Cs = _scheme_moments(S)
        h = 2 * math.pi / (OMEGA * S)
        q, p, e = _run(S, n, seed=S, noise=noise_kernels.step_noise(SIGMA, h, TAU))
        X = np.stack([q[0], p[0], e[0]])
        assert (np.abs(X.mean(axis=1) - ms) < 5 * np.sqrt(np.diag(Cs) / n)).all()
        se = np.sqrt((np.outer(np.diag(Cs), np.diag(Cs)) + Cs ** 2) / n)
        assert (np.abs(np.cov(X) - Cs) < 5 * se).all(), (np.cov(X) - Cs) / se
        assert abs(np.var(e[0]) - SIGMA ** 2 / (2 * TAU)) < 5 * se[2, 2]


ESC = dict(F=0.05, Omega=0.9, Psi=0.0, noise=0.06, noise_time=1.0, xi_max=0.2, t_eval=[3.0, 5.0], damping=0.05)
N_PATHS = 20_000


def _euler_maruyama(S, seed=0):
    """Escape probabilities at ESC's t_eval: Euler-Maruyama of (q, p, eta) in numpy (eta by its
    exact OU step, p then q semi-implicit), eta(0) stationary; escape checked after every step."""
    rng = np.random.default_rng(seed)
    F_, Om, Psi, beta, sigma, tau, xi = (ESC[k] for k in ("F", "Omega", "Psi", "damping", "noise", "noise_time",
                                                          "xi_max"))
    h = 2 * math.pi / (Om * S)
    q, p = np.zeros(N_PATHS), np.zeros(N_PATHS)
    eta = sigma / math.sqrt(2 * tau) * rng.standard_normal(N_PATHS)
    t_esc = np.full(N_PATHS, np.inf)
    live = np.arange(N_PATHS)
    c1, c2 = math.exp(-h / tau), sigma * math.sqrt(-math.expm1(-2 * h / tau) / (2 * tau))
    for n in range(int(max(ESC["t_eval"]) * S)):
        p = p + h * (q ** 3 - q - beta * p + F_ * math.sin(Om * n * h + Psi) + eta)
        q = q + h * p
        eta = c1 * eta + c2 * rng.standard_normal(live.size)
        out = (p * p + q * q - 0.5 * q ** 4 > 2 * xi) | (np.abs(q) > 1)
        t_esc[live[out]] = (n + 1) / S
        live, q, p, eta = live[~out], q[~out], p[~out], eta[~out]
    return np.array([(t_esc <= t).mean() for t in ESC["t_eval"]])


def test_coloured_escape_probability_matches_euler_maruyama():
    """The quartic near resonance under an OU force of correlation time 1: P_escape at 3 and 5
    cycles (16 steps per cycle) within 4 standard errors of the difference of a 512-steps-per-cycle
    Euler-Maruyama; and not the white-noise answer (coloured noise of the same intensity escapes
    less at this tau: its spectrum is cut off above 1/tau)."""
    ref = _euler_maruyama(512)
    kw = dict(paths=N_PATHS, steps_per_cycle=16, grid=False, seed=16)
    ds = escape_probability([0.0], [0.0], **ESC, **kw)
    got = ds.P_escape.values[0]
    se = np.sqrt(2 * ref * (1 - ref) / N_PATHS)
    assert (np.abs(got - ref) < 4 * se).all(), (got, ref, se)
    assert ds.attrs["noise_time"] == 1.0 and "Ornstein-Uhlenbeck" in ds.attrs["noise_model"]
    white = escape_probability([0.0], [0.0], **{**ESC, "noise_time": 0.0}, **kw).P_escape.values[0]
    assert abs(white[1] - got[1]) > 10 * se[1], (white, got)
