"""CPU engine's dense rate as a fraction of the machine's FP64 peak (issue 20).

    .venv/bin/python benchmarks/bench_peak.py [--quick]

Job: ``engine.run_ensemble`` on N ICs inside the quartic well (radius <= 0.45 of the
(q0, p0) origin), F = 0, xi_max = 0.25: nothing escapes, so every lane takes every step (the
per-step rate of the shared vector loop, all numba threads); best of ``--repeat`` runs after a
warm-up.

FLOPs per SRKN6b step of the quartic, counting an FMA as 2 (steps.scheme_steps,
wellcode.quartic_force / quartic_energy2, periods._keep_abs): 7 kicks x (force ``fma(q*q, q,
f - q)``: mul + sub + fma = 4; ``p = fma(c, force, p)``: 2) = 42, 6 drifts ``q = fma(c, p, q)``
= 12, the energy for the escape test ``fma(q*q, fma(-0.5, q*q, 1), p*p)`` = 6: 60 FLOP/step
(comparisons, abs and the forcing table's F*sin, formed once per period for all lanes, not
counted).  53 of them run on the FMA pipes (mul and fma); the 7 subtractions ``f - q`` go to
Zen 4's separate FADD pipes, so this code can exceed the FMA-pipe peak below by up to 60/53.

Peak: logical cores x clock x 16 FP64 FLOP/cycle.  16 = 2 FMA pipes x 4 doubles x 2 FLOP:
AMD Zen 4 executes a 512-bit AVX-512 op as two 256-bit halves on its two 256-bit FMA pipes, so
AVX-512 doubles the width of an instruction but not the FLOP/cycle (on a core with two full
512-bit FMA units it would be 32).  The clock is the largest ``cpu MHz`` of /proc/cpuinfo (the
nominal clock on a VM, 2.6 GHz here; the cores boost above it, up to ~3.7 GHz on a Zen 4 EPYC, which
would make the fraction ~30 % smaller); ``--ghz`` overrides it.  Two fractions are printed: all
60 FLOP/step, and the 53 FMA-pipe FLOP/step (the bound this loop can actually approach).
"""
from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _report import cpu_info, machine, report  # noqa: E402

FLOP_PER_STEP = 7 * (4 + 2) + 6 * 2 + 6
FMA_PIPE_FLOP_PER_STEP = FLOP_PER_STEP - 7
FLOP_PER_CYCLE_CORE = 16


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=20000, help="ICs")
    ap.add_argument("--cycles", type=int, default=300)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--ghz", type=float, default=None)
    ap.add_argument("--quick", action="store_true", help="--n 8192 --cycles 1000 --repeat 3")
    args = ap.parse_args()
    if args.quick:
        args.n, args.cycles, args.repeat = 8192, 1000, 3
    import numba

    from safebasins.numerics import engine

    _, simd, ncores, ghz = cpu_info()
    ghz = args.ghz or ghz or 2.6
    S = engine.DEFAULT_STEPS_PER_CYCLE
    rng = np.random.default_rng(0)
    r = 0.45 * np.sqrt(rng.uniform(0, 1, args.n))
    th = rng.uniform(0, 2 * np.pi, args.n)
    Q, P = r * np.cos(th), r * np.sin(th)
    pidx = np.zeros(args.n, np.int64)

    def job():
        return engine.run_ensemble(Q, P, pidx, [1.0], [0.0], 0.0, xi_max=(0.25,), cycles=args.cycles,
                                   steps_per_cycle=S)[0]

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
    peak = ncores * ghz * FLOP_PER_CYCLE_CORE
    print(machine())
    print(f"dense job: {args.n} ICs x {args.cycles} cycles x {S} steps = {steps:.3g} steps, {numba.get_num_threads()} "
          f"threads, best of {args.repeat}: {t:.3f} s (median {np.median(ts):.3f} s)")
    print(f"{rate:.3g} steps/s x {FLOP_PER_STEP} FLOP/step = {gflops:.1f} GFLOP/s; peak {ncores} cores x {ghz:.2f} GHz "
          f"x {FLOP_PER_CYCLE_CORE} FLOP/cycle = {peak:.1f} GFLOP/s; fraction {gflops / peak:.1%} "
          f"(FMA-pipe FLOP only, {FMA_PIPE_FLOP_PER_STEP}/step: {rate * FMA_PIPE_FLOP_PER_STEP / 1e9 / peak:.1%})")
    report("CPU dense rate / FP64 peak", round(gflops / peak, 3),
           f"GFLOP/s at {FLOP_PER_STEP} FLOP/step / ({ncores} cores x {ghz:.2f} GHz x 16 FLOP/cycle)",
           f"{rate:.3g} steps/s, {gflops:.1f} of {peak:.1f} GFLOP/s ({simd}); FMA-pipe FLOP only "
           f"{rate * FMA_PIPE_FLOP_PER_STEP / 1e9 / peak:.2f}; > 1 possible: FADD pipes, boost clock")


if __name__ == "__main__":
    main()
