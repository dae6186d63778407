"""The five-point variates of the noisy ensemble (numerics.noise_kernels, law FIVE_POINT): the
documented map from the Philox blocks, the law, weak order 2 on the forced, damped harmonic
oscillator (the scheme's characteristic function in closed form: exact for a linear scheme
driven by independent discrete variates), the kernel's one-step law, the boundary shift constant
(Spitzer-Siegmund integral, against the Gaussian's closed form) and the escape probability
against an Euler-Maruyama reference."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from safebasins.numerics import noise_kernels, philox
from safebasins.numerics.noise import BOUNDARY_SHIFTS, GOBET_SHIFT, escape_probability
from tests.numerics.test_noise_weak import (CYCLES, ESC, HARMONIC, N_PATHS, SCHEME, _euler_maruyama,
                                            _exact_moments, _setup)

FIVE = noise_kernels.FIVE_POINT
#: the five-point law: values and probabilities (the module docstring's)
VALUES = np.array([0.0, math.sqrt(2), -math.sqrt(2), 2.0, -2.0])
PROBS = np.array([10, 2, 2, 1, 1]) / 16


def _nibble_law(t: np.ndarray) -> np.ndarray:
    """The documented nibble -> variate map, in numpy."""
    return np.select([t < 2, t < 4, t == 4, t == 5], [math.sqrt(2), -math.sqrt(2), 2.0, -2.0], 0.0)


def test_variates_follow_the_documented_blocks():
    """Step k = n S + s of path m from IC i: byte s mod 16 of Philox block (n ceil(S/16) + s div 16,
    m, i, 2) (the words w_0..w_3 as one little-endian string), Z_1 its low nibble and Z_2 its high
    one, for S = 8, 16 and 37 (a partial block ends each period); recomputed with the pure-Python
    Philox (numerics.philox, the Random123 known answers in test_philox.py)."""
    rng = np.random.default_rng(4)
    seed = 2 ** 40 + 17
    k0, k1 = np.uint64(seed & 0xFFFFFFFF), np.uint64(seed >> 32)
    for S in (8, 16, 37):
        k = rng.integers(0, 5000, 60)
        m = rng.integers(0, 2 ** 32, 60)
        i = rng.integers(0, 2 ** 32, 60)
        got = noise_kernels.step_variates(seed, k, m, i, FIVE, S)
        H = -(-S // 16)
        for j in range(k.size):
            n, s = divmod(int(k[j]), S)
            words = philox.philox4x32(np.uint64(n * H + s // 16), np.uint64(m[j]), np.uint64(i[j]), np.uint64(2),
                                      k0, k1)
            byte = (int(words[(s % 16) // 4]) >> (8 * (s % 4))) & 0xFF
            want = _nibble_law(np.array([byte & 15, byte >> 4]))
            np.testing.assert_array_equal(got[j], want)


def test_five_point_law_moments_and_independence():
    """400,000 pairs: the five values at 10/16, 2/16, 2/16, 1/16, 1/16 (chi-square, 4 degrees of
    freedom, below its 0.999 quantile 18.5); the law itself has E Z^2 = 1, E Z^4 = 3 and zero odd
    moments exactly (the Gaussian's through the fifth); Z_1 and Z_2 uncorrelated, and so are
    consecutive steps (5 standard errors)."""
    assert PROBS @ VALUES ** 2 == pytest.approx(1.0, abs=1e-15)
    assert PROBS @ VALUES ** 4 == pytest.approx(3.0, abs=1e-14)
    assert PROBS @ VALUES ** 3 == PROBS @ VALUES ** 5 == 0.0
    n = 200_000
    k = np.arange(n)
    z = noise_kernels.step_variates(2026, k % 1000, k // 1000, np.full(n, 3), FIVE, 32)
    counts = np.array([(np.abs(z - v) < 1e-12).sum() for v in VALUES])
    assert counts.sum() == z.size
    expected = PROBS * z.size
    assert ((counts - expected) ** 2 / expected).sum() < 18.5, counts / z.size
    se = 1 / math.sqrt(n)
    assert abs(np.corrcoef(z[:, 0], z[:, 1])[0, 1]) < 5 * se
    zz = z[:, 0].reshape(200, 1000)       # path-major: steps 0..999 of 200 paths
    assert abs(np.corrcoef(zz[:, :-1].ravel(), zz[:, 1:].ravel())[0, 1]) < 5 * se


def _contributions(S: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(mean, b_1, b_2) of the splitting after CYCLES * S steps on the forced, damped oscillator:
    X_N = mean + sum_n (b_1[n] Z_1,n + b_2[n] Z_2,n), b_1[n] = M^(N-n) a e_p and b_2[n] = M^(N-1-n) a e_p
    (p += a Z_1, step, p += a Z_2), M the kernel's one-step map."""
    coef, tab, a = _setup(S)
    z = noise_kernels.StepNoise(0.0)
    qm, pm, _ = noise_kernels.final_states(HARMONIC, SCHEME, np.array([0.2]), np.array([-0.1]), 1, coef, tab, 0.3,
                                           CYCLES * S, z, 0)
    qa, pa, _ = noise_kernels.final_states(HARMONIC, SCHEME, np.array([1.0, 0.0]), np.array([0.0, 1.0]), 1, coef,
                                           tab, 0.0, 1, z, 0)
    M = np.array([[qa[0, 0], qa[1, 0]], [pa[0, 0], pa[1, 0]]])
    N = CYCLES * S
    powers = [np.array([0.0, a])]
    for _ in range(N):
        powers.append(M @ powers[-1])
    b1 = np.array([powers[N - n] for n in range(N)])
    b2 = np.array([powers[N - 1 - n] for n in range(N)])
    return np.array([qm[0, 0], pm[0, 0]]), b1, b2


def _phi_five(t: np.ndarray) -> np.ndarray:
    return (10 + 4 * np.cos(math.sqrt(2) * t) + 2 * np.cos(2 * t)) / 16


def _cos_expectation(S: int, kappa: float, law: str) -> float:
    """E cos(kappa p_N) of the scheme with variates of ``law``: cos(kappa mean_p) times the product of
    the variates' characteristic functions at kappa (b_j)_p (exact: independent variates, linear scheme)."""
    mean, b1, b2 = _contributions(S)
    t = kappa * np.concatenate([b1[:, 1], b2[:, 1]])
    phi = _phi_five(t) if law == "five-point" else np.exp(-t * t / 2)
    return math.cos(kappa * mean[1]) * float(np.prod(phi))


def test_five_point_scheme_has_weak_order_two():
    """E cos(kappa p) at the end (kappa = 2 / sd(p), where the characteristic function feels the law's
    higher moments) of the splitting with five-point variates against the exact Gaussian value:
    log2 of the error ratios 1.9-2.1 from 16 to 64 steps per cycle (measured 1.96, 1.99); the
    five-point scheme's distance from the Gaussian-variate scheme (the law's own weak error) falls
    as h^2 too (2.06, 2.03 from 32 to 128)."""
    m, C = _exact_moments()
    kappa = 2.0 / math.sqrt(C[1, 1])
    exact = math.cos(kappa * m[1]) * math.exp(-kappa ** 2 * C[1, 1] / 2)
    five = {S: _cos_expectation(S, kappa, "five-point") for S in (16, 32, 64, 128)}
    errs = np.array([abs(five[S] - exact) for S in (16, 32, 64)])
    gaps = np.array([abs(five[S] - _cos_expectation(S, kappa, "gaussian")) for S in (32, 64, 128)])
    orders = np.log2(errs[:-1] / errs[1:])
    gap_orders = np.log2(gaps[:-1] / gaps[1:])
    assert ((orders > 1.9) & (orders < 2.1)).all(), orders
    assert ((gap_orders > 1.95) & (gap_orders < 2.1)).all(), gap_orders


def test_kernel_one_step_law_is_the_five_point_law():
    """100,000 paths, one step of 8 per cycle from one state: the kernel's (q, p) minus the
    noise-free step is a (M e_p Z_1 + e_p Z_2) exactly (rounding aside); decoded, every pair
    (Z_1, Z_2) is one of the law's 25 and their frequencies are the product law's (chi-square, 24
    degrees of freedom, below its 0.999 quantile 51.2)."""
    S, n = 8, 100_000
    coef, tab, a = _setup(S)
    q0, p0 = np.array([0.2]), np.array([-0.1])
    noisy = noise_kernels.StepNoise(a, law=FIVE)
    q, p, _ = noise_kernels.final_states(HARMONIC, SCHEME, q0, p0, n, coef, tab, 0.3, 1, noisy, 5)
    q_, p_, _ = noise_kernels.final_states(HARMONIC, SCHEME, q0, p0, 1, coef, tab, 0.3, 1,
                                           noise_kernels.StepNoise(0.0), 5)
    qa, pa, _ = noise_kernels.final_states(HARMONIC, SCHEME, np.array([0.0]), np.array([1.0]), 1, coef, tab, 0.0, 1,
                                           noise_kernels.StepNoise(0.0), 0)
    z1 = (q[0] - q_[0, 0]) / (a * qa[0, 0])
    z2 = (p[0] - p_[0, 0] - a * pa[0, 0] * z1) / a
    idx = [np.abs(z[:, None] - VALUES[None, :]).argmin(axis=1) for z in (z1, z2)]
    assert max(np.abs(z1 - VALUES[idx[0]]).max(), np.abs(z2 - VALUES[idx[1]]).max()) < 1e-9
    counts = np.bincount(idx[0] * 5 + idx[1], minlength=25)
    expected = np.outer(PROBS, PROBS).ravel() * n
    assert ((counts - expected) ** 2 / expected).sum() < 51.2, counts.reshape(5, 5)


def _overshoot_constant(one_minus_phi, T: float, per_unit: int) -> float:
    """-(1/pi) int_0^inf t^-2 log(2 (1 - phi(t)) / t^2) dt (Siegmund 1985, the mean overshoot of a
    random walk with symmetric, non-lattice, unit-variance steps of characteristic function phi, in
    units of the step's standard deviation): Simpson on (0, T], the tail beyond T with log(2 (1 - phi))
    replaced by its mean over (T/2, T] (an almost periodic function) and log t^2 integrated exactly."""
    t = np.linspace(0.0, T, int(T * per_unit) + 1)[1:]
    f = np.log(2 * one_minus_phi(t) / t ** 2) / t ** 2
    total = integrate.simpson(f, x=t) + f[0] * t[0]
    total += np.mean(np.log(2 * one_minus_phi(t[t > T / 2]))) / T - 2 * (math.log(T) + 1) / T
    return float(-total / math.pi)


def test_boundary_shift_constants():
    """beta_1 of each law is the mean overshoot of the walk of a step's two kicks, (Z_1 + Z_2)/sqrt 2:
    the integral gives the Gaussian's closed form -zeta(1/2)/sqrt(2 pi) within 1e-9 (the check of the
    quadrature) and the five-point value stored in BOUNDARY_SHIFTS within 1e-6."""
    assert _overshoot_constant(lambda t: -np.expm1(-t * t / 2), 40.0, 20_000) == pytest.approx(GOBET_SHIFT, abs=1e-9)
    assert BOUNDARY_SHIFTS["gaussian"] == GOBET_SHIFT

    def one_minus_phi(t: np.ndarray) -> np.ndarray:
        u = t / math.sqrt(2)                    # each kick: Z / sqrt 2
        one = 2 * (PROBS[1:, None] * np.sin(np.outer(VALUES[1:], u) / 2) ** 2).sum(axis=0)   # 1 - phi_Z(u)
        return one * (2 - one)                  # 1 - phi_Z(u)^2: two kicks
    assert _overshoot_constant(one_minus_phi, 1600.0, 2000) == pytest.approx(BOUNDARY_SHIFTS["five-point"], abs=1e-6)


def test_five_point_escape_probability_and_its_shift():
    """The escape check of test_noise_weak with five-point variates: at 8 steps per cycle the
    shifted threshold (BOUNDARY_SHIFTS["five-point"]) agrees with the 256-steps-per-cycle
    Euler-Maruyama reference within 4 standard errors of the difference at both times, and the
    unshifted check is biased low by more than 5."""
    ref = _euler_maruyama(256)
    kw = dict(paths=N_PATHS, steps_per_cycle=8, grid=False, seed=8, variates="five-point")
    shifted = escape_probability([0.0], [0.0], **ESC, correction="shift", **kw)
    plain = escape_probability([0.0], [0.0], **ESC, correction="none", **kw).P_escape.values[0]
    se = np.sqrt(2 * ref * (1 - ref) / N_PATHS)
    assert (np.abs(shifted.P_escape.values[0] - ref) < 4 * se).all(), (shifted.P_escape.values[0], ref, se)
    assert ref[1] - plain[1] > 5 * se[1], (plain, ref, se)
    assert shifted.attrs["variates"] == "five-point"
    assert str(BOUNDARY_SHIFTS["five-point"]) in shifted.attrs["boundary_correction"]
