"""The weak-noise limit of the averaged diffusion (docs/noise-theory.md, "The weak-noise limit").

Independent routes (the bounds leave a margin over the measured values):

* closed forms at F = 0: Phi = 2 beta E(J) for any well (the averaged diffusion's stationary
  density exp(-2 beta E / sigma^2), Boltzmann with sigma^2 = 2 beta T), so the barrier is
  2 beta xi_max and the Hessian at the bottom 2 beta omega(0) I;
* the forced linear oscillator (constant omega and a, isotropic diffusion 1/(2 omega), linear drift):
  Phi = beta omega |x - x*|^2 exactly, barrier beta omega (R - |x*|)^2;
* the drift against the well's exact damped slow flow (damped.rhs_exact; measured 2.5e-8 of its
  largest value) and its Jacobian against central differences (1.0e-5 of its largest entry);
* the chain of two attractors against its mean first-passage time solved at small noise;
* F > 0: the slope of ln T against 1/sigma^2 from the backward-Kolmogorov solver
  (theory.mean_first_passage) at decreasing sigma approaches the barrier, and the full equation's
  SDE ensemble (numerics.escape_probability) follows the Poisson law 1 - exp(-t/T).
"""

import numpy as np
import pytest

from safebasins import numerics, theory
from safebasins.theory.damped import rhs_exact
from safebasins.theory.noise_averaging import AveragedDiffusion, averaged_diffusion
from safebasins.theory.noise_quasipotential import _Problem, _solve, attractor_barriers, coefficient_table
from safebasins.theory.damped import xi_of_J
from safebasins.wells import QUARTIC, resolve_well

CUBIC = resolve_well("cubic")


def _linear(J_max, omega):
    Jn = np.linspace(0.0, J_max, 50)
    c = np.full(50, 0.5 / omega)
    return AveragedDiffusion(Jn, H=omega * Jn, omega=np.full(50, omega), a=np.full(50, 0.5 / np.sqrt(omega)),
                             a_r=c, a_t=c)


@pytest.mark.parametrize("F", [0.0, 0.02])
def test_linear_oscillator_closed_form(F):
    omega, Omega, beta, J_max = 1.2, 1.0, 0.05, 0.1
    d = _linear(J_max, omega)
    pb = _Problem(coefficient_table(d), J_max, F, Omega, beta)
    # the attractor of X' = -(beta/2) X - g Y, Y' = g X - (beta/2) Y - F a, g = omega - Omega
    g, a = omega - Omega, 0.5 / np.sqrt(omega)
    x_star = np.linalg.solve([[-0.5 * beta, -g], [g, -0.5 * beta]], [0.0, F * a])
    qp = _solve(pb, x_star[None, :], np.zeros((0, 2)), 0.1, 64, 0.05)
    R = np.sqrt(2 * J_max)
    assert np.allclose(qp.hessian[0], 2 * beta * omega * np.eye(2), rtol=1e-9)
    assert qp.barrier[0] == pytest.approx(beta * omega * (R - np.hypot(*x_star)) ** 2, rel=1e-6)
    if F > 0:       # the nearest point of the circle
        assert np.allclose(qp.exit_point[0], R * x_star / np.hypot(*x_star), atol=1e-3 * R)


@pytest.mark.parametrize("well, xi_max", [(QUARTIC, 0.18), (CUBIC, 0.1)])
def test_thermal_well_at_zero_forcing(well, xi_max):
    beta = 0.05
    qp = theory.quasi_potential(0.0, 0.9, xi_max, damping=beta, well=well)
    assert qp.barrier[0] == pytest.approx(2 * beta * xi_max, rel=1e-6)
    assert np.allclose(qp.hessian[0], 2 * beta * well.omega(0.0) * np.eye(2), rtol=1e-4)
    assert qp.exit_set == ("circle",) and qp.saddles.shape == (0, 2)


@pytest.mark.parametrize("well, F, xi_max", [(QUARTIC, 0.01, 0.18), (CUBIC, 0.005, 0.1)])
def test_drift_and_jacobian(well, F, xi_max):
    # the cubic: the sheared frame's phase drift -beta d (measured 1.7e-8 and 1.4e-5)
    Omega, beta = 0.9, 0.02
    d = averaged_diffusion(well, xi_max)
    pb = _Problem(coefficient_table(d), d.J_max, F, Omega, beta)
    rng = np.random.default_rng(1)
    r = np.sqrt(2 * d.J_max) * np.sqrt(rng.uniform(0.01, 0.95, 40))
    g = rng.uniform(0, 2 * np.pi, 40)
    x = np.stack([r * np.cos(g), r * np.sin(g)], axis=1)
    out = pb.flow(x)
    bX, bY = rhs_exact(well, x[:, 0], x[:, 1], F, Omega, beta)
    scale = np.hypot(bX, bY).max()
    assert np.max(np.abs(out[:, 0] - bX)) < 2e-7 * scale and np.max(np.abs(out[:, 1] - bY)) < 2e-7 * scale
    h = 1e-3        # spans several table nodes (the tabulated derivatives are interpolated separately)
    for c, e in ((0, np.array([h, 0.0])), (1, np.array([0.0, h]))):
        fd = (pb.flow(x + e)[:, :2] - pb.flow(x - e)[:, :2]) / (2 * h)
        assert np.allclose(out[:, [2 + c, 4 + c]], fd, atol=5e-5 * np.abs(out[:, 2:6]).max())


def test_chain_of_two_attractors():
    # W(A->R), W(A->circle), W(R->A), W(R->circle) through one saddle whose branches go to A and R
    w_ar, w_ac, w_ra, w_rc = 1.0, 1.3, 2.7, 0.36
    to_saddle = np.array([[w_ar], [w_ra]])
    barrier, sets = attractor_barriers(np.array([w_ac, w_rc]), to_saddle, np.array([[1, 0]]))
    # the chain's mean first-passage time from A solved at small eps: eps ln T -> barrier
    eps = 0.004
    a, c, r, d = np.exp(-np.array([w_ar, w_ac, w_ra, w_rc]) / eps)
    M = np.array([[-(a + c), a], [r, -(r + d)]])
    T = np.linalg.solve(M, -np.ones(2))
    assert eps * np.log(T) == pytest.approx(barrier, abs=10 * eps)
    assert barrier[0] == pytest.approx(w_ar) and sets == ("chain", "chain")
    # a saddle whose other branch escapes joins the circle
    b1, s1 = attractor_barriers(np.array([w_ac]), np.array([[w_ar]]), np.array([[-1, 0]]))
    assert b1[0] == w_ar and s1 == ("saddle 0",)


FORCED = dict(F=0.01, Omega=0.9, xi_max=0.09, damping=0.02)       # one attractor, no saddle inside


@pytest.fixture(scope="module")
def forced():
    """The quasi-potential at FORCED and the IC (q0, p0) at tau = 0 on its attractor (Psi = 0)."""
    k = FORCED
    qp = theory.quasi_potential(k["F"], k["Omega"], k["xi_max"], damping=k["damping"])
    X, Y = qp.attractors[0]
    xi = float(theory.xi_from_J(0.5 * (X * X + Y * Y)))
    q0, p0 = QUARTIC.phase_point(np.arctan2(Y, X), xi)       # gamma = theta - Psi
    return qp, float(q0), float(p0)


def _mfpt(q0, p0, sigma):
    k = FORCED
    ds = theory.mean_first_passage([q0], [p0], k["F"], k["Omega"], 0.0, k["xi_max"], noise=sigma,
                                   damping=k["damping"], grid=False)
    return float(ds["mean_first_passage"][0])


def test_arrhenius_slope_of_the_backward_equation(forced):
    """F > 0: d ln T / d(1/sigma^2) from the solver approaches the barrier (measured 0.935, 0.965,
    0.985, 1.008 of it between sigma = 0.02, 0.016, 0.013, 0.011, 0.009)."""
    qp, q0, p0 = forced
    assert qp.attractors.shape == (1, 2) and qp.exit_set == ("circle",)
    sig = np.array([0.02, 0.016, 0.011, 0.009])
    T = [_mfpt(q0, p0, s) for s in sig]
    slope = np.diff(np.log(T)) / np.diff(1 / sig ** 2) / qp.barrier[0]
    assert abs(slope[-1] - 1) < 0.03
    assert abs(slope[-1] - 1) < abs(slope[0] - 1)


def test_arrhenius_slope_asymmetric_well():
    """The escape equation's cubic in its sheared phase: the slope of ln T from the solver against
    1/sigma^2 approaches the barrier (measured 0.948, 0.968, 0.982 of it between sigma = 0.02, 0.016,
    0.013, 0.011)."""
    k = dict(F=0.005, Omega=0.9, xi_max=0.1, damping=0.02)
    qp = theory.quasi_potential(k["F"], k["Omega"], k["xi_max"], damping=k["damping"], well=CUBIC)
    assert qp.attractors.shape == (1, 2) and qp.exit_set == ("circle",)
    X, Y = qp.attractors[0]
    xi = float(xi_of_J(CUBIC, 0.5 * (X * X + Y * Y)))
    q0, p0 = CUBIC.phase_point(np.arctan2(Y, X) - float(CUBIC.harmonic_shift(xi)), xi)     # theta = phi - delta
    sig = np.array([0.02, 0.016, 0.013, 0.011])
    T = [float(theory.mean_first_passage([float(q0)], [float(p0)], k["F"], k["Omega"], 0.0, k["xi_max"], noise=s,
                                         damping=k["damping"], grid=False, well=CUBIC)["mean_first_passage"][0])
         for s in sig]
    slope = np.diff(np.log(T)) / np.diff(1 / sig ** 2) / qp.barrier[0]
    assert abs(slope[-1] - 1) < 0.03 and abs(slope[-1] - 1) < abs(slope[0] - 1)


def test_two_attractors_and_a_saddle_asymmetric_well():
    """The cubic at F = 0.01, beta = 0.02, xi_max = 0.1: the bottom's attractor, a resonant one just
    inside the circle (barrier 1.2e-6) and a saddle between them whose other branch escapes.  The
    rays reach the saddle only after extra refinement passes; the bottom attractor's barrier (via the
    saddle, 2.021e-3) against the backward equation's Arrhenius slope: measured 0.983, 1.006, 1.021,
    1.036 of it between sigma = 0.02, 0.016, 0.013, 0.011, 0.0095."""
    k = dict(F=0.01, Omega=0.9, xi_max=0.1, damping=0.02)
    qp = theory.quasi_potential(k["F"], k["Omega"], k["xi_max"], damping=k["damping"], well=CUBIC)
    assert qp.attractors.shape == (2, 2) and qp.saddles.shape == (1, 2) and qp.exit_set == ("chain", "chain")
    assert np.isfinite(qp.to_saddle[0, 0]) and qp.barrier[0] == pytest.approx(qp.to_saddle[0, 0])
    assert qp.barrier[1] < 1e-3 * qp.barrier[0]
    X, Y = qp.attractors[0]
    xi = float(xi_of_J(CUBIC, 0.5 * (X * X + Y * Y)))
    q0, p0 = CUBIC.phase_point(np.arctan2(Y, X) - float(CUBIC.harmonic_shift(xi)), xi)
    sig = np.array([0.02, 0.016, 0.013])
    T = [float(theory.mean_first_passage([float(q0)], [float(p0)], k["F"], k["Omega"], 0.0, k["xi_max"], noise=s,
                                         damping=k["damping"], grid=False, well=CUBIC)["mean_first_passage"][0])
         for s in sig]
    slope = np.diff(np.log(T)) / np.diff(1 / sig ** 2) / qp.barrier[0]
    assert abs(slope[-1] - 1) < 0.03


def test_poisson_law_against_the_sde_ensemble(forced):
    """Once relaxed, escape is a Poisson event: the full equation's ensemble (2000 paths) at
    sigma = 0.025 (barrier / sigma^2 = 3.5) against 1 - exp(-t/T), T from the backward equation
    (194 cycles): measured 0.6245 [0.603, 0.645] and 0.7645 [0.745, 0.783] (Wilson) at t = T, 1.5 T
    against 0.632 and 0.777 (at T/2: 0.3725 [0.352, 0.394] against 0.393, the relaxation's lag)."""
    _, q0, p0 = forced
    k, sigma = FORCED, 0.025
    T = _mfpt(q0, p0, sigma)
    te = np.array([1.0, 1.5]) * T
    ds = numerics.escape_probability([q0], [p0], k["F"], k["Omega"], 0.0, noise=sigma, paths=2000,
                                     xi_max=k["xi_max"], t_eval=te, damping=k["damping"], grid=False)
    law = 1 - np.exp(-te / T)
    assert np.all(ds["P_escape_low"].values.ravel() <= law) and np.all(law <= ds["P_escape_high"].values.ravel())


@pytest.mark.parametrize("kw, name", [(dict(damping=0.0), "damping"), (dict(F=-1.0), "F"),
                                      (dict(F=0.2), "F"), (dict(n_rays=4), "n_rays"), (dict(step=2.0), "step"),
                                      (dict(xi_max=0.3), "xi_max")])
def test_bad_input_named(kw, name):
    args = dict(F=0.01, Omega=0.9, xi_max=0.09, damping=0.02) | kw
    with pytest.raises(ValueError, match=name):
        theory.quasi_potential(args.pop("F"), args.pop("Omega"), args.pop("xi_max"), **args)


def test_saddle_whose_branch_escapes_sets_the_barrier():
    """xi_max between the saddle and the resonant attractor: the saddle's outer branch leaves the
    disc, so the barrier is Phi at the saddle, just below the rays' least Phi on the circle (measured
    0.0010469 and 0.0010496; the backward solver's slope of ln T on 256 x 320 cells: 1.002 and 1.007
    of the barrier between sigma = 0.01, 0.009, 0.008)."""
    qp = theory.quasi_potential(0.01, 0.9, 0.11, damping=0.01)
    assert qp.exit_set == ("saddle 0",) and qp.saddle_targets.tolist() == [[-1, 0]]
    assert qp.barrier[0] == qp.to_saddle[0, 0] < qp.to_circle[0] < 1.01 * qp.barrier[0]
