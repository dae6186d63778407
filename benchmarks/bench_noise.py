"""Speed of the noisy ensemble (numerics.noise) against the deterministic engine and a numba
Euler-Maruyama, in one process (docs/noise.md).

    python benchmarks/bench_noise.py            # quick: 4096 paths x 200 cycles x 32 steps
    python benchmarks/bench_noise.py --full     # 16384 paths x 400 cycles

Trajectory-steps per second on one thread, five interleaved rounds (the best of each is kept), for the quartic
at F = 0.02, Omega = 0.8, ICs near the bottom of the well (nothing escapes: every trajectory runs
the whole horizon, so steps are counted exactly):

* deterministic: numerics.escape_chart (SRKN6b, the engine's vector lanes);
* noisy: noise_kernels.escape_steps at sigma = 0.002 (SRKN6b + two Gaussians a step from one
  Philox block, escape checked after every step);
* Euler-Maruyama: a hand-written numba loop (symplectic Euler drift, one numpy normal a step,
  escape checked after every step), weak order 1.

Equal accuracy: on the forced, damped harmonic oscillator (beta = 0.5, sigma = 0.5, F = 0.3,
Omega = 1.3, two cycles; closed-form Gaussian moments) the exact moments of both schemes follow
from their linear recursions; the steps per cycle Euler-Maruyama needs for the splitting's error
in Var p at 32 steps per cycle, times the per-step speed ratio, is the time ratio at equal weak
accuracy.
"""
from __future__ import annotations

import argparse
import math
import time

import numba
import numpy as np
from numba import njit

from _report import machine, report

from scipy.integrate import solve_ivp

from safebasins.numerics import escape_chart, noise_kernels, schemes
from safebasins.numerics.scheme_code import scheme_code
from safebasins.wells.compiled import polynomial_code, quartic_code

F, OMEGA, PSI, XI, SIGMA, S = 0.02, 0.8, 0.0, 0.25, 0.002, 32


@njit(cache=True)
def euler_maruyama(q0, p0, F, Omega, h, sigma, xi2, n_steps, seed):
    """Symplectic Euler-Maruyama for every path; first step beyond 2 H0 > xi2 or |q| > 1 (-1: none)."""
    np.random.seed(seed)  # noqa: NPY002  (numba compiles the legacy global generator, per thread)
    out = np.full(q0.size, -1, np.int64)
    sh = sigma * math.sqrt(h)
    for j in range(q0.size):
        q, p = q0[j], p0[j]
        for n in range(n_steps):
            p += h * (q * q * q - q + F * math.sin(Omega * n * h)) + sh * np.random.standard_normal()  # noqa: NPY002
            q += h * p
            if p * p + q * q - 0.5 * q ** 4 > xi2 or abs(q) > 1.0:
                out[j] = n + 1
                break
    return out


def best(fns, rounds=5):
    """The best time of each function over interleaved rounds (a load change on the shared
    machine then hits every function alike)."""
    times = [[] for _ in fns]
    for _ in range(rounds):
        for k, fn in enumerate(fns):
            t = time.perf_counter()
            fn()
            times[k].append(time.perf_counter() - t)
    return [min(t) for t in times]


# the equal-accuracy problem: q'' + beta q' + q = F sin(Omega t + Psi) + sigma dW/dt from (Q0, P0)
OU = dict(beta=0.5, sigma=0.5, F=0.3, Omega=1.3, Psi=0.4, q0=0.2, p0=-0.1, cycles=2)


def exact_var_p():
    """Var p at the end from the covariance ODE C' = A C + C A^T + diag(0, sigma^2) (DOP853)."""
    A = np.array([[0.0, 1.0], [-1.0, -OU["beta"]]])
    D = np.diag([0.0, OU["sigma"] ** 2])
    T = OU["cycles"] * 2 * math.pi / OU["Omega"]
    y = solve_ivp(lambda t, c: (A @ c.reshape(2, 2) + c.reshape(2, 2) @ A.T + D).ravel(), (0.0, T), np.zeros(4),
                  method="DOP853", rtol=1e-13, atol=1e-15).y[:, -1]
    return y[3]


def splitting_var_p(S):
    """Var p of the splitting after cycles * S steps (the kernel's one-step map, noise half kicks)."""
    code, sc = polynomial_code([0.0, 0.0, 0.5], (-math.inf, math.inf), "harmonic"), scheme_code("srkn6b", True)
    coef = schemes.lane_coefficients([OU["Omega"]], S, "srkn6b", OU["beta"])
    tab = schemes.sine_table(S, OU["Psi"])
    q, p, _ = noise_kernels.final_states(code, sc, np.array([1.0, 0.0]), np.array([0.0, 1.0]), 1, coef, tab, 0.0, 1,
                                         noise_kernels.StepNoise(0.0), 0)
    M = np.array([[q[0, 0], q[1, 0]], [p[0, 0], p[1, 0]]])
    a2 = OU["sigma"] ** 2 * math.pi / (OU["Omega"] * S)           # (sigma sqrt(h/2))^2
    E = np.diag([0.0, a2])
    C = np.zeros((2, 2))
    for _ in range(OU["cycles"] * S):
        C = M @ (C + E) @ M.T + E
    return C[1, 1]


def euler_maruyama_var_p(S):
    """Var p of the symplectic Euler-Maruyama (p += h (-q - beta p + f) + sigma sqrt(h) Z; q += h p)."""
    h = 2 * math.pi / (OU["Omega"] * S)
    b = OU["beta"]
    A = np.array([[1.0 - h * h, h * (1.0 - b * h)], [-h, 1.0 - b * h]])
    v = OU["sigma"] * math.sqrt(h) * np.array([h, 1.0])
    C = np.zeros((2, 2))
    for _ in range(OU["cycles"] * S):
        C = A @ C @ A.T + np.outer(v, v)
    return C[1, 1]


def equal_accuracy_steps(S_split=32):
    """(splitting's error at S_split, Euler-Maruyama's steps per cycle for the same error)."""
    exact = exact_var_p()
    target = abs(splitting_var_p(S_split) - exact)
    S = S_split
    while abs(euler_maruyama_var_p(S) - exact) > target:
        S *= 2
    lo, hi = S // 2, S
    while hi - lo > max(1, lo // 100):              # bisect to 1%: the error is monotone in S here
        mid = (lo + hi) // 2
        lo, hi = (mid, hi) if abs(euler_maruyama_var_p(mid) - exact) > target else (lo, mid)
    return target, hi


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--full", action="store_true")
    args = ap.parse_args()
    n, cycles = (16384, 400) if args.full else (4096, 200)
    numba.set_num_threads(1)
    rng = np.random.default_rng(1)
    q0 = rng.uniform(-0.05, 0.05, n)
    p0 = rng.uniform(-0.05, 0.05, n)
    steps = n * cycles * S
    h = 2 * math.pi / (OMEGA * S)

    det = escape_chart(q0, p0, F, OMEGA, PSI, xi_max=XI, cycles=cycles, grid=False, threads=1)
    assert np.isinf(det.escape_cycle_energy).all(), "a deterministic trajectory escaped: steps not exact"

    def deterministic():
        return escape_chart(q0, p0, F, OMEGA, PSI, xi_max=XI, cycles=cycles, grid=False, threads=1)

    code, sc = quartic_code(), scheme_code("srkn6b")
    coef, tab = schemes.lane_coefficients([OMEGA], S), schemes.sine_table(S, PSI)

    def noisy():
        return noise_kernels.escape_steps(code, sc, q0, p0, 1, coef, tab, F, 2 * XI, cycles,
                                          noise_kernels.step_noise(SIGMA, h), 7)
    assert (noisy() < 0).all(), "a noisy path escaped: steps not exact"

    def em():
        return euler_maruyama(q0, p0, F, OMEGA, h, SIGMA, 2 * XI, cycles * S, 7)
    assert (em() < 0).all(), "an Euler-Maruyama path escaped: steps not exact"
    t_det, t_noise, t_em = best([deterministic, noisy, em])

    r_det, r_noise, r_em = steps / t_det, steps / t_noise, steps / t_em
    print(f"machine: {machine()}; one thread; {n} trajectories x {cycles} cycles x {S} steps")
    print(f"deterministic engine (SRKN6b)      : {r_det:.3e} trajectory-steps/s")
    print(f"noisy ensemble (SRKN6b + Philox)   : {r_noise:.3e} trajectory-steps/s")
    print(f"numba Euler-Maruyama (weak order 1): {r_em:.3e} trajectory-steps/s")
    print(f"noisy / deterministic = {r_noise / r_det:.3f} (target >= 0.5); noisy / Euler-Maruyama = "
          f"{r_noise / r_em:.3f} per step")
    report("noise_vs_deterministic", round(r_noise / r_det, 3), "noisy / deterministic trajectory-steps per second",
           f"{n} x {cycles} cycles x {S} steps, one thread")
    report("noise_vs_euler_maruyama_per_step", round(r_noise / r_em, 3),
           "noisy ensemble / numba Euler-Maruyama trajectory-steps per second (per step, not at equal accuracy)",
           f"{n} x {cycles} cycles x {S} steps, one thread")
    err, S_em = equal_accuracy_steps(32)
    speedup = S_em / 32 * r_noise / r_em
    print(f"equal weak accuracy (Var p error {err:.2e} of the splitting at 32 steps/cycle): Euler-Maruyama needs "
          f"{S_em} steps/cycle ({S_em / 32:.0f}x the steps): the splitting is {speedup:.0f}x faster")
    report("noise_vs_euler_maruyama_equal_accuracy", round(speedup, 1),
           "time of a numba Euler-Maruyama / time of the noisy ensemble at equal weak error (harmonic oscillator, "
           "Var p)", f"splitting 32 steps/cycle, Euler-Maruyama {S_em}")


if __name__ == "__main__":
    main()
