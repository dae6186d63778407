"""Benchmark and convergence study of safebasins.numerics (see docs/numerics.md).

    python benchmarks/bench_escape.py            # speed: engine (SRKN6b and RK4) vs numpy RK4 vs
                                                 # scipy DOP853, ceilings, equal-accuracy comparison
    python benchmarks/bench_escape.py --study    # convergence study against scipy DOP853
                                                 # (rtol 1e-10) on the 100x100 chart

Everything runs in ONE process.  The DOP853 reference of the study takes ~10-20 CPU-minutes;
it is cached in --ref (default: $TMPDIR/safebasins_dop853_chart_ref.npz) and computed with
--workers processes.
"""
from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

from _reference import ivp_escape  # noqa: E402  (benchmarks/ is on sys.path)

CHART = dict(F=0.0876, Omega=0.95, Psi=np.pi, xi_max=0.25, cycles=300, n=100)


def chart_ics(n=CHART["n"]):
    q = np.linspace(-1, 1, n)
    Q, P = np.meshgrid(q, q, indexing="ij")
    return q, Q.ravel(), P.ravel()


# ----------------------------------------------------------------------------- references
def _dop853_one(args):
    """Escape time (cycles) of one IC with scipy DOP853 (events: H0 = xi_max, |q| = 1)."""
    q0, p0, F, Om, Psi, xi_max, cycles, rtol, atol = args
    return ivp_escape((q0, p0, F, Om, Psi, xi_max, cycles, "DOP853", rtol, atol))[0]


def dop853_chart(Q, P, F, Omega, Psi, xi_max, cycles, rtol=1e-10, atol=1e-12, workers=2):
    from multiprocessing import Pool
    args = [(float(a), float(b), F, Omega, Psi, xi_max, cycles, rtol, atol) for a, b in zip(Q, P)]
    if workers > 1:
        with Pool(workers) as pool:
            return np.array(pool.map(_dop853_one, args, chunksize=16))
    return np.array([_dop853_one(a) for a in args])


def numpy_rk4_chart(Q, P, F, Omega, Psi, xi_max, cycles, steps_per_cycle):
    """Vectorised-across-trajectories classic RK4 (numpy), escape checked after every step;
    escaped trajectories are dropped from the active set at each step."""
    S = steps_per_cycle
    h = 2 * np.pi / (Omega * S)
    q = Q.astype(float).copy()
    p = P.astype(float).copy()
    out = np.full(q.size, np.inf)
    H = 0.5 * p * p + 0.5 * q * q - 0.25 * q ** 4
    start = (H > xi_max) | (np.abs(q) > 1)
    out[start] = 0.0
    idx = np.flatnonzero(~start)
    q, p = q[idx], p[idx]
    n_steps = 0
    for n in range(cycles * S):
        t = n * h
        f0 = F * math.sin(Omega * t + Psi)
        f1 = F * math.sin(Omega * (t + 0.5 * h) + Psi)
        f2 = F * math.sin(Omega * (t + h) + Psi)
        k1q = p
        k1p = q * q * q - q + f0
        qa = q + 0.5 * h * k1q
        k2q = p + 0.5 * h * k1p
        k2p = qa * qa * qa - qa + f1
        qb = q + 0.5 * h * k2q
        k3q = p + 0.5 * h * k2p
        k3p = qb * qb * qb - qb + f1
        qc = q + h * k3q
        k4q = p + h * k3p
        k4p = qc * qc * qc - qc + f2
        q = q + h / 6 * (k1q + 2 * k2q + 2 * k3q + k4q)
        p = p + h / 6 * (k1p + 2 * k2p + 2 * k3p + k4p)
        n_steps += q.size
        esc = (0.5 * p * p + 0.5 * q * q - 0.25 * q ** 4 > xi_max) | (np.abs(q) > 1)
        if esc.any():
            out[idx[esc]] = (n + 1) / S
            keep = ~esc
            idx, q, p = idx[keep], q[keep], p[keep]
            if idx.size == 0:
                break
    return out, n_steps


# ----------------------------------------------------------------------------- helpers
def machine_state():
    la = os.getloadavg()
    try:
        model = [line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name")][0]
    except Exception:  # pragma: no cover
        model = "?"
    top = ""
    try:
        top = subprocess.run(["top", "-bn1", "-o", "%CPU"], capture_output=True, text=True, timeout=10).stdout
        top = "\n".join(top.splitlines()[6:12])
    except Exception:  # pragma: no cover
        pass
    return f"{model}, {os.cpu_count()} CPUs, load average {la[0]:.2f} {la[1]:.2f} {la[2]:.2f}\n{top}"


def engine_steps(chart_cycles_E, S, cycles):
    """Trajectory-steps actually integrated by the engine (to the escape step or horizon)."""
    e = np.where(np.isfinite(chart_cycles_E), chart_cycles_E, cycles)
    return float(np.round(e * S).sum())


CPU_TIMES = {}


def best_time(fn, repeat, key=None):
    """Best wall time of `repeat` runs; the process CPU time of that run goes to CPU_TIMES[key]
    (on a loaded machine, steps / CPU-seconds x threads estimates the unloaded rate)."""
    best = np.inf
    out = None
    for _ in range(repeat):
        t = time.perf_counter()
        c = time.process_time()
        out = fn()
        w = time.perf_counter() - t
        if w < best:
            best = w
            CPU_TIMES[key] = time.process_time() - c
    return best, out


# ----------------------------------------------------------------------------- benchmark
def benchmark(args):
    import numba
    from safebasins.numerics import escape_chart
    from safebasins.numerics import engine
    from safebasins.numerics.problem import ensemble_problem
    S = args.steps_per_cycle or engine.DEFAULT_STEPS_PER_CYCLE
    print("machine:", machine_state())
    print(f"numba {numba.__version__}, threads {numba.get_num_threads()}, threading layer "
          f"{numba.config.THREADING_LAYER}, steps_per_cycle {S}")
    t = time.perf_counter()
    escape_chart([0.0], [0.0], 0.01, 1.0, 0.0, cycles=1, steps_per_cycle=S)   # compile / load cache
    print(f"first call (compile or cache load): {time.perf_counter() - t:.2f} s")
    rows = []

    # (a1) dense job: F = 0, ICs well inside the well, nothing escapes
    rng = np.random.default_rng(0)
    n_dense = args.dense_n
    r = 0.45 * np.sqrt(rng.uniform(0, 1, n_dense))
    th = rng.uniform(0, 2 * np.pi, n_dense)
    qd, pd = r * np.cos(th), r * np.sin(th)
    dense_cycles = args.dense_cycles
    tdense, cd = best_time(lambda: escape_chart(qd, pd, 0.0, 1.0, 0.0, xi_max=0.25, cycles=dense_cycles,
                                                steps_per_cycle=S, grid=False), args.repeat, "dense")
    assert np.isinf(cd["escape_cycle_energy"].values).all()
    steps = n_dense * dense_cycles * S
    rows.append(("engine, dense (F=0, no escapes)", steps, tdense))

    # (a2) the 100x100 chart
    q, Q, P = chart_ics()
    c = CHART
    tchart, ch = best_time(lambda: escape_chart(q, q, c["F"], c["Omega"], c["Psi"], xi_max=c["xi_max"],
                                                cycles=c["cycles"], steps_per_cycle=S), args.repeat, "chart")
    eE = ch["escape_cycle_energy"].values[0].ravel()
    steps_chart = engine_steps(eE, S, c["cycles"])
    frac_early = float(np.mean(eE <= 10))
    rows.append((f"engine, 100x100 chart ({100 * np.mean(np.isfinite(eE)):.1f}% escape, "
                 f"{100 * frac_early:.1f}% within 10 cycles)", steps_chart, tchart))
    # the same chart, kernel only (no argument checks / meshgrid / xarray)
    tker, _ = best_time(lambda: engine.run_cpu(ensemble_problem(Q, P, np.zeros(Q.size, np.int64), [c["Omega"]], [c["F"]], c["Psi"],
                                               xi_max=(c["xi_max"],), cycles=c["cycles"], steps_per_cycle=S)),
                        args.repeat, "kernel")
    rows.append(("  same chart, engine kernel only (run_cpu)", steps_chart, tker))
    # 300x300 chart of Fig 21 at 3000 cycles (the paper-scale job)
    if args.big:
        qb = np.linspace(-1, 1, 300)
        tbig, cb = best_time(lambda: escape_chart(qb, qb, c["F"], c["Omega"], c["Psi"], xi_max=c["xi_max"],
                                                  q_max=1.0, cycles=3000, steps_per_cycle=S), 1, "big")
        eb = cb["escape_cycle_displacement"].values[0].ravel()
        rows.append((f"engine, 300x300 chart, 3000 cycles, xi_max=0.25 & q_max=1 "
                     f"({100 * np.mean(np.isinf(eb)):.1f}% safe)", engine_steps(eb, S, 3000), tbig))

    # (b) numpy RK4, vectorised across trajectories, same chart
    S_rk4 = args.rk4_steps
    t0 = time.perf_counter()
    e_rk4, n_rk4 = numpy_rk4_chart(Q, P, c["F"], c["Omega"], c["Psi"], c["xi_max"], c["cycles"], S_rk4)
    t_rk4 = time.perf_counter() - t0
    rows.append((f"numpy RK4 ({S_rk4} steps/cycle), same chart", n_rk4, t_rk4))

    # (c) scipy DOP853 on a subset, extrapolated per trajectory-cycle
    sub = rng.choice(Q.size, args.dop_subset, replace=False)
    t0 = time.perf_counter()
    e_dop = dop853_chart(Q[sub], P[sub], c["F"], c["Omega"], c["Psi"], c["xi_max"], c["cycles"],
                         rtol=1e-10, atol=1e-12, workers=1)
    t_dop = time.perf_counter() - t0
    cyc_dop = float(np.where(np.isfinite(e_dop), e_dop, c["cycles"]).sum())

    nthr = numba.get_num_threads()
    print(f"\n{'job':62s} {'traj-steps':>12s} {'time [s]':>9s} {'steps/s':>10s} {'cycles/s':>10s} "
          f"{'CPU s':>7s} {'steps/CPU-s x threads':>22s}")
    keys = ["dense", "chart", "kernel"] + (["big"] if args.big else []) + [None]
    for (name, n, t), key in zip(rows, keys):
        spc = S_rk4 if name.startswith("numpy") else S
        cpu = CPU_TIMES.get(key, t_rk4) if key else t_rk4
        est = n / cpu * (nthr if key else 1)
        print(f"{name:62s} {n:12.4g} {t:9.3f} {n / t:10.3g} {n / spc / t:10.3g} {cpu:7.3f} {est:22.3g}")
    print(f"{'scipy DOP853 rtol 1e-10, ' + str(args.dop_subset) + ' random ICs of the chart (1 process)':62s} "
          f"{'-':>12s} {t_dop:9.3f} {'-':>10s} {cyc_dop / t_dop:10.3g}")
    eng_chart = steps_chart / S / tchart            # trajectory-cycles per second
    rk4_cyc = n_rk4 / S_rk4 / t_rk4
    dop_cyc = cyc_dop / t_dop
    est_dop_chart = float(np.where(np.isfinite(eE), eE, c["cycles"]).sum()) / dop_cyc
    print(f"\nDOP853 extrapolated to the whole chart (same escape mix, per trajectory-cycle): "
          f"{est_dop_chart:.0f} s on 1 core")
    print("ratios on the chart job, per trajectory-cycle (each method at its own steps/cycle):")
    print(f"  engine / numpy RK4   = {eng_chart / rk4_cyc:8.1f}x   (RK4 at {S_rk4} steps/cycle)")
    print(f"  engine / scipy DOP853 = {eng_chart / dop_cyc:8.3g}x   (DOP853 measured on {args.dop_subset} ICs, extrapolated)")
    print("ratio per trajectory-step (engine step = 6 force evaluations, RK4 step = 4):")
    print(f"  engine / numpy RK4   = {(steps_chart / tchart) / (n_rk4 / t_rk4):8.1f}x")
    # ceiling: zmm FMA-class ops per step = 7 kicks x 3 + 6 drifts + 3 (energy) = 30 per 8 lanes
    ghz = args.ghz
    ceil_steps = 2 * ghz * 1e9 * 8 / 30 if ghz else None
    if ceil_steps:
        print(f"ceiling (2 cores x {ghz} GHz x 1 zmm FMA-class op/cycle, 30 ops per 8 lane-steps) "
              f"= {ceil_steps:.3g} steps/s: dense {steps / tdense / ceil_steps:.0%}, "
              f"chart {steps_chart / tchart / ceil_steps:.0%}")
    if not args.no_integrators:
        integrators_section(args)
    print("machine after:", machine_state().splitlines()[0])


# ----------------------------------------------------------------------------- RK4 in the engine
E_LEVELS = np.array([0.01, 0.1, 0.2, 0.24, 0.249])   # H0 of the ICs at rest (F = 0, Omega = 1)


def energy_error(integrator, S, cycles):
    """Max relative |H0(t) - H0(0)| / H0(0) over the steps of cycle `cycles` + 1 (F = 0,
    Omega = 1), ICs at rest at H0 = E_LEVELS, with the engine's own step (kernels.final_states)."""
    from safebasins.numerics import kernels, schemes, steps
    from safebasins.numerics.scheme_code import scheme_code
    q0 = np.sqrt(1 - np.sqrt(1 - 4 * E_LEVELS))
    q, p = kernels.final_states(q0, np.zeros_like(q0), np.zeros(q0.size, np.int64),
                                schemes.lane_coefficients(1.0, S, integrator), np.array([0.0]),
                                schemes.sine_table(S, 0.0, integrator), cycles, scheme=scheme_code(integrator))
    # then one more cycle step by step: the max over the steps of that cycle (a symplectic
    # scheme's error oscillates within the period; the period-end value can be far smaller)
    c = schemes.lane_coefficients(1.0, S, integrator)[0]
    worst = np.zeros(q0.size)
    for s in range(S + 1):
        H = 0.5 * p * p + 0.5 * q * q - 0.25 * q ** 4
        rel = (H - E_LEVELS) / E_LEVELS
        worst = np.where(np.abs(rel) > np.abs(worst), rel, worst)
        if s < S:
            for j in range(q0.size):
                q[j], p[j] = steps.scalar_step(integrator)(steps.W0, q[j], p[j], tuple(c),
                                                           (0.0,) * scheme_code(integrator).width)
    return float(np.abs(worst).max()), float(worst[np.argmax(np.abs(worst))])


def dense_ics(n, seed=0):
    rng = np.random.default_rng(seed)
    r = 0.45 * np.sqrt(rng.uniform(0, 1, n))
    th = rng.uniform(0, 2 * np.pi, n)
    return r * np.cos(th), r * np.sin(th)


def kernel_rate(integrator, Q, P, F, Omega, Psi, cycles, S, repeat, reps=1):
    """Best wall time of `reps` back-to-back engine.run_cpu calls (kernel only);
    returns (time, useful trajectory-steps, CPU time of the best run)."""
    from safebasins.numerics import engine
    from safebasins.numerics.problem import ensemble_problem
    def job():
        for _ in range(reps):
            sE, _, _ = engine.run_cpu(ensemble_problem(Q, P, np.zeros(Q.size, np.int64), [Omega], [F], Psi, xi_max=(0.25,),
                                      cycles=cycles, steps_per_cycle=S, integrator=integrator))
        return sE
    key = f"{integrator}-{S}-{cycles}-{reps}"
    t, sE = best_time(job, repeat, key)
    steps = float(np.where(sE[:, 0] < 0, cycles * S, sE[:, 0]).sum()) * reps
    return t, steps, CPU_TIMES[key]


def integrators_section(args):
    """RK4 vs SRKN6b in the same compiled engine: steps/s on the dense job and the 100x100 chart,
    fractions of the RK4 ceilings, and the equal-accuracy comparison (trajectory-cycles/s at the
    steps/cycle each needs for the 11,000-cycle energy bound)."""
    import numba
    from safebasins.numerics import engine
    from safebasins.numerics.problem import ensemble_problem
    nthr = numba.get_num_threads()
    c = CHART
    S0 = engine.DEFAULT_STEPS_PER_CYCLE
    qd, pd = dense_ics(args.dense_n)
    _, Q, P = chart_ics()
    for integ in ("srkn6b", "rk4"):     # compile / cache load outside the timings
        engine.run_cpu(ensemble_problem([0.1], [0.0], [0], [1.0], [0.0], 0.0, xi_max=(0.25,), cycles=1, steps_per_cycle=S0,
                       integrator=integ))
    print(f"\n=== SRKN6b vs RK4 in the same compiled engine ({nthr} threads, kernel only, best of {args.repeat}) ===")
    print(f"dense: {args.dense_n} ICs inside the well, F = 0, {args.dense_cycles_long} cycles (no escapes); "
          f"chart: 100x100, {c['cycles']} cycles, the whole chart job repeated {args.chart_reps}x back to back "
          f"(one chart is ~5 ms of work)")
    print(f"{'job':40s} {'S':>4s} {'traj-steps':>11s} {'wall [s]':>9s} {'steps/s':>9s} {'traj-cyc/s':>10s} "
          f"{'steps/CPU-s x thr':>17s}")
    rates = {}
    for integ in ("srkn6b", "rk4"):
        for job, (QQ, PP, F, Om, Psi, cyc, reps) in (
                ("dense", (qd, pd, 0.0, 1.0, 0.0, args.dense_cycles_long, 1)),
                ("chart", (Q, P, c["F"], c["Omega"], c["Psi"], c["cycles"], args.chart_reps))):
            t, n, cpu = kernel_rate(integ, QQ, PP, F, Om, Psi, cyc, S0, args.repeat, reps)
            rates[integ, job] = n / t
            print(f"{integ + ' ' + job:40s} {S0:4d} {n:11.4g} {t:9.3f} {n / t:9.3g} {n / S0 / t:10.3g} "
                  f"{n / cpu * nthr:17.3g}")
    # ceilings for RK4 (brief: 46 flops/step, 16 FP64 flops/cycle/core)
    ncores = os.cpu_count()
    ceil_brief = 2.8e9
    ceil_nom = ncores * 2.6e9 * 16 / 46
    ceil_boost = ncores * 3.65e9 * 16 / 46
    # instruction-level: 20 zmm FMA-pipe ops (mul/FMA) per 8 lane-steps (asm of the RK4 loop:
    # 14 FMA + 6 MUL per chain; the 11 add/sub/cmp go to the FADD pipes), 1 zmm FMA-pipe op per
    # cycle per core (Zen 4 double-pumps 512-bit ops over its two 256-bit FMA pipes; a Zen 5 has
    # two 512-bit pipes and this machine runs at ~4.4 GHz: benchmarks/bench_peak.py measures both)
    ceil_isa = ncores * 2.6e9 * 8 / 20
    print(f"\nRK4 ceilings ({ncores} cores): brief's 2.8e9; 46 flops/step x 16 flops/cycle/core: "
          f"{ceil_nom:.3g} at 2.6 GHz nominal, {ceil_boost:.3g} at 3.65 GHz boost; "
          f"FMA-pipe bound of this code (20 zmm mul/FMA per 8 lane-steps) {ceil_isa:.3g} at 2.6 GHz")
    for job in ("dense", "chart"):
        r = rates["rk4", job]
        print(f"  RK4 {job}: {r:.3g} steps/s = {r / ceil_brief:.0%} of 2.8e9, {r / ceil_nom:.0%} of the 2.6 GHz "
              f"46-flop ceiling ({r * 46 / 1e9:.0f} GFlop/s), {r / ceil_isa:.0%} of the FMA-pipe bound; "
              f"target {'2e9' if job == 'dense' else '1.5e9'}: "
              f"{'met' if r >= (2e9 if job == 'dense' else 1.5e9) else 'NOT met'}")
    # equal accuracy: relative energy error after 11,000 free cycles
    cyc = args.energy_cycles
    bound = 1e-5
    print(f"\nequal accuracy: max relative energy error over the steps of free cycle {cyc} + 1 (F = 0, Omega = 1, ICs at rest "
          f"at H0 = {', '.join(f'{x:g}' for x in E_LEVELS)}); requirement {bound:g}")
    err = {}
    for integ, Ss in (("srkn6b", (16, 32)), ("rk4", (64, 128, 192, 224, 256, 320))):
        for S in Ss:
            err[integ, S] = energy_error(integ, S, cyc)
            print(f"  {integ:7s} S = {S:4d}: {err[integ, S][0]:.2e} (signed {err[integ, S][1]:+.2e})")
    S_rk4 = min(S for (i, S) in err if i == "rk4" and err[i, S][0] <= bound)
    # RK4 error ~ S^-4: steps/cycle RK4 needs to match SRKN6b at its default
    e_ref = err["srkn6b", S0][0]
    S_match = 256 * (err["rk4", 256][0] / e_ref) ** 0.25
    # trajectory-cycles/s measured on the dense job at each scheme's steps/cycle
    print(f"trajectory-cycles/s on the dense job ({args.dense_n} ICs, steps/cycle as given, >= 0.5 s of work):")
    tc = {}
    for integ, S in (("srkn6b", S0), ("srkn6b", 16), ("rk4", S_rk4)):
        cyc_d = max(20, int(args.dense_cycles_long * S0 / S))
        t, n, _ = kernel_rate(integ, qd, pd, 0.0, 1.0, 0.0, cyc_d, S, args.repeat)
        tc[integ, S] = n / S / t
        print(f"  {integ:7s} S = {S:4d} ({cyc_d} cycles): {n / t:.3g} steps/s, {n / S / t:.3g} traj-cycles/s, "
              f"energy error {err[integ, S][0]:.1e}")
    print(f"=> at the requirement ({bound:g}): SRKN6b at its default {S0} steps/cycle does "
          f"{tc['srkn6b', S0] / tc['rk4', S_rk4]:.1f}x the trajectory-cycles/s of RK4 at the {S_rk4} steps/cycle "
          f"RK4 needs, with a {err['rk4', S_rk4][0] / e_ref:.0f}x smaller energy error; at 16 steps/cycle "
          f"(error {err['srkn6b', 16][0]:.1e}, still within the bound) {tc['srkn6b', 16] / tc['rk4', S_rk4]:.1f}x")
    print(f"=> RK4 would need ~{S_match:.0f} steps/cycle to match SRKN6b's {e_ref:.1e} at {S0} steps/cycle "
          f"(error ~ S^-4 from S = 256): ~{tc['rk4', S_rk4] * S_rk4 / S_match / tc['srkn6b', S0]:.3f}x SRKN6b's rate")


# ----------------------------------------------------------------------------- study
def study(args):
    from safebasins.numerics import escape_chart
    c = CHART
    q, Q, P = chart_ics()
    ref_path = args.ref or os.path.join(tempfile.gettempdir(), "safebasins_dop853_chart_ref.npz")
    if os.path.exists(ref_path):
        ref = np.load(ref_path)["escape_cycle"]
        print(f"DOP853 reference loaded from {ref_path}")
    else:
        print(f"computing the DOP853 reference (rtol 1e-10, atol 1e-12) with {args.workers} workers ...", flush=True)
        print("machine:", machine_state().splitlines()[0])
        t = time.perf_counter()
        ref = dop853_chart(Q, P, c["F"], c["Omega"], c["Psi"], c["xi_max"], c["cycles"], workers=args.workers)
        print(f"  done in {time.perf_counter() - t:.0f} s")
        np.savez(ref_path, escape_cycle=ref)
    safe_ref = np.isinf(ref)
    print(f"reference: {safe_ref.sum()} of {ref.size} ICs safe at t_eval = {c['cycles']} "
          f"({100 * np.mean(np.isfinite(ref)):.1f}% escape)")
    print("dt = engine escape cycle - DOP853 event time, over ICs escaping in both and not at t = 0")
    print(f"\n{'steps/cycle':>11s} {'disagree':>8s} {'agree %':>8s} {'|dt| med':>9s} {'|dt| 99%':>9s} "
          f"{'<=1 step %':>10s} {'dt>1 cyc':>8s} {'t [s]':>6s}")
    for S in args.steps_list:
        t = time.perf_counter()
        ch = escape_chart(q, q, c["F"], c["Omega"], c["Psi"], xi_max=c["xi_max"], cycles=c["cycles"],
                          steps_per_cycle=S)
        dt_run = time.perf_counter() - t
        e = ch["escape_cycle_energy"].values[0].ravel()
        dis = np.isinf(e) != safe_ref
        both = np.isfinite(e) & np.isfinite(ref) & (ref > 0)
        sd = e[both] - ref[both]
        d = np.abs(sd)
        one_step = np.mean((sd >= -1e-9) & (sd <= 1.0 / S + 1e-9))
        print(f"{S:11d} {dis.sum():8d} {100 * (1 - dis.mean()):8.2f} {np.median(d):9.2g} "
              f"{np.quantile(d, 0.99):9.2g} {100 * one_step:10.2f} {(d > 1).sum():8d} {dt_run:6.2f}")
    # and the t_eval-resolved agreement at the default
    from safebasins.numerics import engine
    S = engine.DEFAULT_STEPS_PER_CYCLE
    ch = escape_chart(q, q, c["F"], c["Omega"], c["Psi"], xi_max=c["xi_max"], cycles=c["cycles"], steps_per_cycle=S)
    e = ch["escape_cycle_energy"].values[0].ravel()
    print(f"\nagreement of safe(t_eval) at steps_per_cycle={S}:")
    for te in (1, 10, 50, 100, 200, 300):
        print(f"  t_eval={te:4d}: {np.sum((e > te) != (ref > te)):4d} pixels differ")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--study", action="store_true", help="convergence study instead of the speed benchmark")
    ap.add_argument("--ref", help="DOP853 reference cache (.npz)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--steps-list", type=int, nargs="+", default=[8, 12, 16, 24, 32, 48, 64, 128])
    ap.add_argument("--steps-per-cycle", type=int, default=None)
    ap.add_argument("--dense-n", type=int, default=20000)
    ap.add_argument("--dense-cycles", type=int, default=300)
    ap.add_argument("--dense-cycles-long", type=int, default=2000,
                    help="cycles of the dense job in the SRKN6b-vs-RK4 section (>= 0.5 s of work)")
    ap.add_argument("--chart-reps", type=int, default=150,
                    help="back-to-back repetitions of the 100x100 chart job in the SRKN6b-vs-RK4 section")
    ap.add_argument("--energy-cycles", type=int, default=11000)
    ap.add_argument("--no-integrators", action="store_true", help="skip the SRKN6b-vs-RK4 section")
    ap.add_argument("--only-integrators", action="store_true", help="only the SRKN6b-vs-RK4 section")
    ap.add_argument("--rk4-steps", type=int, default=64)
    ap.add_argument("--dop-subset", type=int, default=100)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--ghz", type=float, default=2.6, help="core clock for the ceiling estimate")
    ap.add_argument("--big", action="store_true", help="also the 300x300, 3000-cycle chart")
    args = ap.parse_args(argv)
    if args.study:
        study(args)
    elif args.only_integrators:
        print("machine:", machine_state())
        integrators_section(args)
        print("machine after:", machine_state().splitlines()[0])
    else:
        benchmark(args)


if __name__ == "__main__":
    sys.exit(main())
