"""Speed of the noisy ensemble (numerics.noise) against the deterministic engine and a numba
Euler-Maruyama, in one process (docs/noise.md).

    python benchmarks/bench_noise.py            # quick: 4096 paths x 200 cycles x 32 steps
    python benchmarks/bench_noise.py --full     # 16384 paths x 400 cycles
    python benchmarks/bench_noise.py --gpu      # the CUDA backend only (skipped without a CUDA GPU)

Trajectory-steps per CPU second on one thread, 15 interleaved rounds (the rates: the best round of
each; the ratios: the median of the ratios formed within each round, with quartiles), for the quartic
at F = 0.02, Omega = 0.8, ICs near the bottom of the well (nothing escapes: every trajectory runs
the whole horizon, so steps are counted exactly):

* deterministic: numerics.escape_chart (SRKN6b, the engine's vector lanes);
* noisy: noise_kernels.escape_steps at sigma = 0.002 (SRKN6b + two Gaussians a step from one
  Philox block, escape checked after every step);
* noisy, five-point variates (the law's moments equal the Gaussian's through the fifth: weak
  order 2 as well; one Philox block serves 16 steps);
* Euler-Maruyama: a hand-written numba loop (symplectic Euler drift, one numpy normal a step,
  escape checked after every step), weak order 1.

Equal accuracy: on the forced, damped harmonic oscillator (beta = 0.5, sigma = 0.5, F = 0.3,
Omega = 1.3, two cycles; closed-form Gaussian moments) the exact moments of both schemes follow
from their linear recursions; the steps per cycle Euler-Maruyama needs for the splitting's error
in Var p at 32 steps per cycle, times the per-step speed ratio, is the time ratio at equal weak
accuracy.

--gpu (numerics.cuda_noise on a CUDA GPU; numba-cuda 0.30.4 with numpy >= 2.5 needs
``numpy.row_stack = numpy.vstack`` in a sitecustomize.py, bench_gpu.py):

* bitwise: escape steps of the GPU and the CPU lanes (all threads) for every path of three
  ensembles with escapes at t = 0, later and never: the quartic at Fig 21's forcing under white
  noise; the quartic, damped, coloured noise, RK4; the pendulum, damped, white noise (its force
  and energy call wells.elementary's sin and cos);
* speed: the dense job above (nothing escapes) on the GPU, noisy kernel against the deterministic
  engine's kernel (cuda_engine) and the CPU lanes on every core;
* PTX of the quartic's kernel: f64 instruction counts and the plain (contractible) ``mul.f64``
  whose result feeds an add or subtract, except exact scalings by a power of two (must be 0;
  ``mul.rn.f64``, wells.compiled.mul, is never contracted).
"""
from __future__ import annotations

import argparse
import collections
import math
import re
import time

import numba
import numpy as np
from numba import njit

from _report import machine, report

from scipy.integrate import solve_ivp

from safebasins.numerics import engine, escape_chart, noise_kernels, schemes
from safebasins.numerics.noise import energy_shift
from safebasins.numerics.problem import ensemble_problem
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


def rounds_of(fns, rounds=15):
    """CPU times of this process (rounds, len(fns)) of each function, interleaved round by round
    (every function runs on one thread: CPU time, unlike the wall clock, does not count the time
    another process holds the core; the functions of one round run back to back, so a ratio formed
    within a round sees one load)."""
    times = np.zeros((rounds, len(fns)))
    for r in range(rounds):
        for k, fn in enumerate(fns):
            t = time.process_time()
            fn()
            times[r, k] = time.process_time() - t
    return times


def best(fns, rounds=5):
    """The best CPU time of each function over interleaved rounds."""
    return list(rounds_of(fns, rounds).min(axis=0))


def paired_ratio(times, k, base=0):
    """Median and quartiles over the rounds of time[base] / time[k] (function k's speed relative to
    the base's, formed within each round)."""
    r = times[:, base] / times[:, k]
    return np.median(r), np.percentile(r, 25), np.percentile(r, 75)


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


def _noisy_args(q0, p0, paths, F, Omega, Psi, xi, cycles, sigma, *, tau=0.0, well=None, damping=0.0,
                integrator="srkn6b", seed=3):
    """(args, keywords) of noise_kernels.escape_steps / cuda_noise.escape_steps, as escape_probability forms them."""
    pb = ensemble_problem(q0, p0, np.zeros(q0.size, np.int64), [Omega], [F], Psi, xi_max=[xi], cycles=cycles,
                          steps_per_cycle=S, integrator=integrator, well=well, damping=damping)
    h = float(pb.step_sizes()[0])
    args = (pb.code, pb.scheme, q0, p0, paths, pb.coefficients(), pb.sine_table(), F, float(pb.thrE2[0]), cycles,
            noise_kernels.step_noise(sigma, h, tau), seed)
    return args, dict(shift=energy_shift(sigma, h, "shift", tau))


def _grid(qa, pa):
    Q, P = np.meshgrid(qa, pa, indexing="ij")
    return Q.ravel(), P.ravel()


def contractible_pairs(ptx):
    """(f64 instruction counts of PTX text, plain mul.f64 results feeding an add/sub, those of them
    that scale by a power-of-two immediate).  A plain mul.f64 may be contracted with the add by
    ptxas; a product by a power of two is exact (short of underflow), so contracting it cannot
    change a result (the 53-bit uniforms' 2^-53, Payne-Hanek's 2^-48 and 2^-96); any other pair
    could round differently from the CPU."""
    ops, plain, exact, uses = collections.Counter(), set(), set(), []
    for line in ptx.splitlines():
        m = re.match(r"\s*((?:fma|mul|add|sub)\.[\w.]*f64)\s+(%fd\d+),\s*(.*);", line)
        if m:
            op, dst, srcs = m.groups()
            ops[op] += 1
            if op == "mul.f64":
                plain.add(dst)
                if any(int(x, 16) & (2 ** 52 - 1) == 0 for x in re.findall(r"0d([0-9A-Fa-f]{16})", srcs)):
                    exact.add(dst)
            elif op.startswith(("add", "sub")):
                uses.extend(re.findall(r"%fd\d+", srcs))
    return dict(ops), sum(u in plain for u in uses), sum(u in exact for u in uses)


def gpu_section():
    """The CUDA backend against the CPU lanes (module docstring)."""
    if engine.resolve_backend("auto") != "cuda":
        print("--gpu: skipped: no CUDA GPU (numba-cuda sees none)")
        return
    from numba import cuda  # noqa: PLC0415  (numba.cuda only where a GPU is there: its import costs ~1 s)

    from safebasins.numerics import cuda_engine, cuda_noise  # noqa: PLC0415  (they import numba.cuda)
    dev = cuda.get_current_device()
    name = dev.name.decode() if isinstance(dev.name, bytes) else str(dev.name)
    print(f"machine: {machine()}; GPU {name} ({dev.MULTIPROCESSOR_COUNT} SMs); numba threads "
          f"{numba.get_num_threads()}", flush=True)
    jobs = [
        ("quartic, Fig 21 forcing, white noise", _grid(np.linspace(-1, 1, 48), np.linspace(-0.75, 0.75, 48)),
         dict(paths=32, F=0.0876, Omega=0.95, Psi=math.pi, xi=0.25, cycles=30, sigma=0.02)),
        ("quartic, damped, coloured noise, RK4", _grid(np.linspace(-1, 1, 48), np.linspace(-0.75, 0.75, 48)),
         dict(paths=32, F=0.06, Omega=0.9, Psi=0.3, xi=0.2, cycles=30, sigma=0.05, tau=2.0, damping=0.05,
              integrator="rk4")),
        ("pendulum, damped, white noise", _grid(np.linspace(-3, 3, 32), np.linspace(-2, 2, 32)),
         dict(paths=32, F=0.2, Omega=0.9, Psi=0.4, xi=1.0, cycles=20, sigma=0.1, well="pendulum", damping=0.05)),
    ]
    for title, (q0, p0), kw in jobs:
        args, skw = _noisy_args(q0, p0, **kw)
        t = time.perf_counter()
        cpu = noise_kernels.escape_steps(*args, **skw, n_tasks=numba.get_num_threads())
        t_cpu = time.perf_counter() - t
        t = time.perf_counter()
        tm = {}
        gpu = cuda_noise.escape_steps(*args, **skw, timing=tm)
        t_gpu = time.perf_counter() - t
        print(f"bitwise, {title}: {q0.size} ICs x {kw['paths']} paths x {kw['cycles']} cycles: "
              f"{int((cpu != gpu).sum())} of {cpu.size} escape steps differ; escaped at t = 0 {int((cpu == 0).sum())}, "
              f"later {int((cpu > 0).sum())}, never {int((cpu < 0).sum())} (first calls, compile included: CPU "
              f"{t_cpu:.1f} s, GPU {t_gpu:.1f} s, kernel {tm['kernel_s']:.3f} s)", flush=True)

    # speed: the dense job (nothing escapes), 4096 ICs x 32 paths
    rng = np.random.default_rng(1)
    n_ic, paths, cycles = 4096, 32, 500
    q0, p0 = rng.uniform(-0.05, 0.05, n_ic), rng.uniform(-0.05, 0.05, n_ic)
    args, skw = _noisy_args(q0, p0, paths, F, OMEGA, PSI, XI, cycles, SIGMA)
    runs = []
    for _ in range(3):
        tm = {}
        out = cuda_noise.escape_steps(*args, **skw, timing=tm)
        runs.append(tm["kernel_s"])
    steps = int(np.where(out < 0, cycles * S, out).sum())      # a few paths escape over the long horizon
    det_steps = n_ic * paths * cycles * S
    qd, pd = np.repeat(q0, paths), np.repeat(p0, paths)
    det = ensemble_problem(qd, pd, np.zeros(qd.size, np.int64), [OMEGA], [F], PSI, xi_max=[XI], cycles=cycles,
                           steps_per_cycle=S)
    druns = []
    for _ in range(3):
        tm = {}
        dE, _ = cuda_engine.run_cuda(det, timing=tm)
        druns.append(tm["kernel_s"])
    assert (dE < 0).all(), "a deterministic trajectory escaped: steps not exact"
    sub = 256                                # the CPU lanes on every core, 256 of the ICs
    cargs, _ = _noisy_args(q0[:sub], p0[:sub], paths, F, OMEGA, PSI, XI, cycles, SIGMA)
    t = time.perf_counter()
    cout = noise_kernels.escape_steps(*cargs, **skw, n_tasks=numba.get_num_threads())
    r_cpu = int(np.where(cout < 0, cycles * S, cout).sum()) / (time.perf_counter() - t)
    r_gpu, r_det = steps / min(runs), det_steps / min(druns)
    print(f"speed, dense quartic job {n_ic} ICs x {paths} paths x {cycles} cycles x {S} steps: GPU noisy "
          f"{r_gpu:.3e} trajectory-steps/s (kernel {min(runs):.3f} s), GPU deterministic engine {r_det:.3e} "
          f"(kernel {min(druns):.3f} s): noisy / deterministic = {r_gpu / r_det:.3f}; CPU noisy lanes "
          f"({numba.get_num_threads()} threads) {r_cpu:.3e}: GPU / CPU = {r_gpu / r_cpu:.1f}; "
          f"{int((out >= 0).sum())} of {out.size} noisy paths escaped (steps counted to escape)", flush=True)
    report("noise_gpu_vs_deterministic_gpu", round(r_gpu / r_det, 3),
           f"noisy / deterministic trajectory-steps per second on the GPU ({name})",
           f"{n_ic} ICs x {paths} paths x {cycles} cycles x {S} steps")

    code, sc = quartic_code(), scheme_code("srkn6b")
    asm = cuda_noise.noise_kernel(code.key, sc.key).inspect_asm()
    ops, pairs, exact = contractible_pairs(next(iter(asm.values())) if isinstance(asm, dict) else asm)
    print(f"PTX of the quartic's noisy kernel: {ops}; plain mul.f64 feeding an add/sub: {pairs}, of which {exact} "
          f"exact scalings by a power of two (the others, {pairs - exact}, must be 0)")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--full", action="store_true")
    ap.add_argument("--gpu", action="store_true", help="the CUDA backend only (skipped without a CUDA GPU)")
    args = ap.parse_args()
    if args.gpu:
        gpu_section()
        return
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

    def five():
        return noise_kernels.escape_steps(code, sc, q0, p0, 1, coef, tab, F, 2 * XI, cycles,
                                          noise_kernels.step_noise(SIGMA, h, law=noise_kernels.FIVE_POINT), 7)
    assert (five() < 0).all(), "a noisy path escaped: steps not exact"

    def em():
        return euler_maruyama(q0, p0, F, OMEGA, h, SIGMA, 2 * XI, cycles * S, 7)
    assert (em() < 0).all(), "an Euler-Maruyama path escaped: steps not exact"
    times = rounds_of([deterministic, noisy, five, em])
    t_det, t_noise, t_five, t_em = times.min(axis=0)
    ratio_noise, ratio_five = paired_ratio(times, 1), paired_ratio(times, 2)

    r_det, r_noise, r_five, r_em = steps / t_det, steps / t_noise, steps / t_five, steps / t_em
    print(f"machine: {machine()}; one thread; {n} trajectories x {cycles} cycles x {S} steps")
    print(f"deterministic engine (SRKN6b)      : {r_det:.3e} trajectory-steps/s")
    print(f"noisy ensemble (SRKN6b + Philox)   : {r_noise:.3e} trajectory-steps/s")
    print(f"  five-point variates              : {r_five:.3e} trajectory-steps/s")
    print(f"numba Euler-Maruyama (weak order 1): {r_em:.3e} trajectory-steps/s")
    print(f"noisy / deterministic = {ratio_noise[0]:.3f} (quartiles {ratio_noise[1]:.3f}-{ratio_noise[2]:.3f} over "
          f"{len(times)} rounds; target >= 0.5); noisy / Euler-Maruyama = {r_noise / r_em:.3f} per step")
    print(f"five-point / deterministic = {ratio_five[0]:.3f} (quartiles {ratio_five[1]:.3f}-{ratio_five[2]:.3f}; "
          f"target >= 0.5)")
    report("noise_vs_deterministic", round(ratio_noise[0], 3),
           "noisy / deterministic trajectory-steps per CPU second (median of paired rounds)",
           f"{n} x {cycles} cycles x {S} steps, one thread")
    report("noise_five_point_vs_deterministic", round(ratio_five[0], 3),
           "noisy (five-point variates) / deterministic trajectory-steps per CPU second (median of paired rounds)",
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
    # the five-point scheme's mean and covariance are the Gaussian one's (a linear scheme: second moments only)
    speedup5 = S_em / 32 * r_five / r_em
    print(f"  with five-point variates (the same Var p error): {speedup5:.0f}x faster")
    report("noise_five_point_vs_euler_maruyama_equal_accuracy", round(speedup5, 1),
           "time of a numba Euler-Maruyama / time of the noisy ensemble with five-point variates at equal weak "
           "error (harmonic oscillator, Var p)", f"splitting 32 steps/cycle, Euler-Maruyama {S_em}")


if __name__ == "__main__":
    main()
