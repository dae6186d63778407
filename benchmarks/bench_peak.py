"""CPU engine's dense rate as a fraction of the machine's FP64 peak.

    .venv/bin/python benchmarks/bench_peak.py [--quick]

Job: ``engine.run_cpu`` on N ICs inside the quartic well (radius <= 0.45 of the
(q0, p0) origin), F = 0, xi_max = 0.25: nothing escapes, so every lane takes every step (the
per-step rate of the shared vector loop, all numba threads); best of ``--repeat`` runs after a
warm-up.

FLOPs per SRKN6b step of the quartic, counting an FMA as 2 (steps.scheme_steps,
wells.compiled.quartic_force / quartic_energy2, periods._keep_abs): 7 kicks x (force ``fma(q*q, q,
f - q)``: mul + sub + fma = 4; ``p = fma(c, force, p)``: 2) = 42, 6 drifts ``q = fma(c, p, q)``
= 12, the energy for the escape test ``fma(q*q, fma(-0.5, q*q, 1), p*p)`` = 6: 60 FLOP/step
(comparisons, abs and the forcing table's F*sin, formed once per period for all lanes, not
counted).  53 of them run on the FMA pipes (mul and fma); the 7 subtractions ``f - q`` go to
Zen 4's separate FADD pipes, so this code can exceed the FMA-pipe peak below by up to 60/53.

Peak: logical cores x clock x FP64 FLOP/cycle of one core's FMA pipes (2 pipes x doubles per
pipe x 2 FLOP).  Doubles per pipe from the CPU (/proc/cpuinfo): AMD family 0x1A (Zen 5) has
full 512-bit pipes: 8 (32 FLOP/cycle); AMD family 0x19 (Zen 3/4) executes a 512-bit op as two
256-bit halves: 4 (16); an AVX2-only CPU: 4 (16); another AVX-512 CPU: 8 (Intel server cores
with two 512-bit FMA units; some have one) -- ``--flop-per-cycle`` overrides.  The clock is
MEASURED in this process, on all numba threads at once: a chain of dependent FMAs advances one
FMA latency (4 cycles on Zen 3/4/5 and Intel Skylake-SP and later) per link, so links/s x 4 is
the running clock (a VM's ``cpu MHz`` gives the nominal clock, not the boost one; ``--ghz``
overrides).  Two fractions are printed: all 60 FLOP/step, and the 53 FMA-pipe FLOP/step (the
bound this loop can actually approach).

(Last stop printed 0.82 of a 16 FLOP/cycle x 2.6 GHz peak from a run on a loaded machine: this
machine is a Zen 5 at ~4.4 GHz, so that peak was 3.4x too low.)
"""
from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _report import cpu_family, cpu_info, machine, report  # noqa: E402

FLOP_PER_STEP = 7 * (4 + 2) + 6 * 2 + 6
FMA_PIPE_FLOP_PER_STEP = FLOP_PER_STEP - 7
FMA_LATENCY_CYCLES = 4


def flop_per_cycle(simd, family, vendor):
    """FP64 FLOP/cycle of one core's two FMA pipes (module docstring)."""
    if simd != "AVX-512":
        return 16
    if vendor == "AuthenticAMD" and family < 0x1A:
        return 16
    return 32


def measured_ghz(links=200_000_000):
    """Running clock on all numba threads: one chain of dependent FMAs per thread (best of 3)."""
    import numba
    from numba import njit, prange

    from safebasins.wells.compiled import fma_cpu

    @njit(parallel=True)
    def chains(x0, m, c, n):
        out = np.empty(x0.size)
        for t in prange(x0.size):
            x = x0[t]
            for _ in range(n):
                x = fma_cpu(x, m, c)
            out[t] = x
        return out

    x0 = np.full(numba.get_num_threads(), 0.5)
    chains(x0, 0.999999, 1e-7, 10)
    best = min(_timed(chains, x0, 0.999999, 1e-7, links) for _ in range(3))
    return FMA_LATENCY_CYCLES * links / best / 1e9


def _timed(fn, *args):
    t0 = time.perf_counter()
    fn(*args)
    return time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=20000, help="ICs")
    ap.add_argument("--cycles", type=int, default=300)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--ghz", type=float, default=None, help="clock (default: measured, module docstring)")
    ap.add_argument("--flop-per-cycle", type=int, default=None, help="FP64 FLOP/cycle per core (default: from the CPU)")
    ap.add_argument("--quick", action="store_true", help="--n 8192 --cycles 1000 --repeat 3")
    args = ap.parse_args()
    if args.quick:
        args.n, args.cycles, args.repeat = 8192, 1000, 3
    import numba

    from safebasins.numerics import engine
    from safebasins.numerics.problem import ensemble_problem

    _, simd, ncores, nominal = cpu_info()
    family, vendor = cpu_family()
    fpc = args.flop_per_cycle or flop_per_cycle(simd, family, vendor)
    ghz = args.ghz or measured_ghz()
    S = engine.DEFAULT_STEPS_PER_CYCLE
    rng = np.random.default_rng(0)
    r = 0.45 * np.sqrt(rng.uniform(0, 1, args.n))
    th = rng.uniform(0, 2 * np.pi, args.n)
    Q, P = r * np.cos(th), r * np.sin(th)
    pidx = np.zeros(args.n, np.int64)

    def job():
        return engine.run_cpu(ensemble_problem(Q, P, pidx, [1.0], [0.0], 0.0, xi_max=(0.25,), cycles=args.cycles,
                                   steps_per_cycle=S))[0]

    sE = job()                                   # compile / cache load, and the check
    assert (sE < 0).all(), "a dense IC escaped"
    ts = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        job()
        ts.append(time.perf_counter() - t0)
    t = min(ts)
    steps = args.n * args.cycles * S
    rate = steps / t
    gflops = rate * FLOP_PER_STEP / 1e9
    peak = ncores * ghz * fpc
    print(machine())
    print(f"dense job: {args.n} ICs x {args.cycles} cycles x {S} steps = {steps:.3g} steps, {numba.get_num_threads()} "
          f"threads, best of {args.repeat}: {t:.3f} s (median {np.median(ts):.3f} s)")
    print(f"clock {ghz:.2f} GHz ({'given' if args.ghz else 'measured'}; nominal {nominal} GHz in /proc/cpuinfo), "
          f"{fpc} FP64 FLOP/cycle per core (CPU family {family:#x}, {vendor}, {simd})")
    print(f"{rate:.3g} steps/s x {FLOP_PER_STEP} FLOP/step = {gflops:.1f} GFLOP/s; peak {ncores} cores x {ghz:.2f} GHz "
          f"x {fpc} FLOP/cycle = {peak:.1f} GFLOP/s; fraction {gflops / peak:.1%} "
          f"(FMA-pipe FLOP only, {FMA_PIPE_FLOP_PER_STEP}/step: {rate * FMA_PIPE_FLOP_PER_STEP / 1e9 / peak:.1%})")
    report("CPU dense rate / FP64 peak", round(gflops / peak, 3),
           f"GFLOP/s at {FLOP_PER_STEP} FLOP/step / ({ncores} cores x {ghz:.2f} GHz measured x {fpc} FLOP/cycle)",
           f"{rate:.3g} steps/s, {gflops:.1f} of {peak:.1f} GFLOP/s ({simd}, CPU family {family:#x}); "
           f"FMA-pipe FLOP only {rate * FMA_PIPE_FLOP_PER_STEP / 1e9 / peak:.2f}")


if __name__ == "__main__":
    main()
