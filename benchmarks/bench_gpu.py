"""CPU engine vs CUDA engine: throughput and bitwise agreement of the escape steps.

    PYTHONPATH=src python benchmarks/bench_gpu.py                    # everything, one process
    PYTHONPATH=src python benchmarks/bench_gpu.py --cpu-sample 30    # CPU side of Fig 21 on 30 rows
    PYTHONPATH=src python benchmarks/bench_gpu.py --cpu-result fig21_cpu.npz   # reuse/store CPU steps

Runs on a machine with a CUDA GPU (numba-cuda); prints the machine (CPU model, AVX2/AVX-512
flags, cores, GPU name and SMs) and
 (0) the compiled kernel's PTX: f64 instruction counts and the number of multiplies whose
     result feeds an add/sub (contractible pairs; must be 0: see cuda_kernels), SASS DFMA/DMUL
     counts when nvdisasm is on the PATH;
 (a) a dense job: --dense-n trajectories near the well bottom with F = 0 (none escapes, every
     one runs --dense-cycles periods), trajectory-steps per second on CPU and GPU;
 (b) the paper's Fig 21 chart: 300 x 300 ICs on q0 in [-1, 1], p0 in [-0.75, 0.75], F = 0.0876,
     Omega = 0.95, Psi = pi, xi_max = 0.25, q_max = 1, 11,000 cycles of 32 steps: GPU kernel time
     (CUDA events) and wall time, CPU time (all rows, or --cpu-sample rows), and the number of
     escape steps that differ between CPU and GPU (must be 0).
--wells adds (c): the kernel per compiled well (wells/compiled.py) on the GPU: the dense job
(F = 0, nothing escapes) in the quartic (|q| tracking; signed tracking with asymmetric bounds),
the cubic V = q^2/2 - q^3/3 (degree-4 polynomial class), a degree-6 well (degree-8 class) and the
pendulum (an expression well: sin/cos from wells.elementary, the same bits on both targets; every
named well: bench_gpu_wells.py), trajectory-steps/s and the ratio to the
quartic, PTX contractible pairs of each kernel, and a --wells-n x --wells-n cubic chart
(energy + asymmetric bounds, --wells-cycles cycles) whose escape steps are compared with the CPU
engine's (must be equal).
--json PATH writes every figure as JSON as well.  Targets on one H100: >= 2e11 trajectory-steps/s
dense (FP64), Fig 21 in <= 0.2 s of kernel time.

Measured (NVIDIA H100 80GB HBM3, 132 SMs; host: 16-core Intel Xeon with AVX2 and AVX-512;
numba 0.68.0, numba-cuda 0.30.4; --integrators srkn6b,rk4 --blocks 64,256):
  PTX/SASS: srkn6b 26 DFMA, 12 DMUL, 7 DADD = the PTX fma/mul/sub counts, 0 contractible pairs;
            rk4 32 DFMA, 16 DMUL, 24 DADD, 0 contractible pairs
  (a) dense, 1e5 x 1000 cycles x 32 steps: srkn6b 2.35e11 steps/s (13.6 ms; 2.51e11 with 256-thread
      blocks), rk4 2.84e11; CPU engine (16 threads) 3.5e9 (srkn6b), 5.4e9 (rk4); 0 mismatches
  (b) Fig 21: srkn6b kernel 0.075 s, wall 0.079 s (4.4e9 trajectory-steps; the 10% that never
      escape run all 352,000 steps, a serial chain: the kernel time is that chain's latency);
      rk4 0.062 s; CPU engine 1.3 s (srkn6b); 0 of 90,000 x 2 escape steps differ, both schemes.
numba-cuda 0.30.4 overloads np.row_stack at import, which numpy 2.5 removed: on such a machine
put `numpy.row_stack = numpy.vstack` in a sitecustomize.py on PYTHONPATH (an environment fix,
not part of this project).
"""
from __future__ import annotations

import argparse
import collections
import json
import os
import platform
import re
import time

import numba
import numpy as np
from numba import cuda

from safebasins import wells
from safebasins.numerics import cuda_engine, cuda_kernels, engine
from safebasins.numerics.problem import ensemble_problem

# wells of section (c), as the config names them (safebasins.wells.resolve_well)
CUBIC = "cubic"
SEXTIC = {"polynomial": [0.0, 0.0, 0.5, 0.0, -0.25, 0.0, 0.01]}     # the degree-8 polynomial class
PENDULUM = "pendulum"                                               # an expression well (sin, cos)

FIG21 = dict(F=0.0876, Omega=0.95, Psi=np.pi, xi_max=[0.25], q_max=[1.0], cycles=11000, steps_per_cycle=32)


def machine():
    info = dict(python=platform.python_version(), numba=numba.__version__, cores=os.cpu_count(),
                numba_threads=numba.get_num_threads())
    try:
        import numba_cuda
        info["numba_cuda"] = numba_cuda.__version__
    except ImportError as exc:
        info["numba_cuda"] = f"not importable: {exc}"
    cpuinfo = open("/proc/cpuinfo").read() if os.path.exists("/proc/cpuinfo") else ""
    m = re.search(r"^model name\s*:\s*(.*)$", cpuinfo, re.M)
    info["cpu"] = m.group(1) if m else platform.processor()
    m = re.search(r"^flags\s*:\s*(.*)$", cpuinfo, re.M)
    flags = set(m.group(1).split()) if m else set()
    info["avx2"] = "avx2" in flags
    info["avx512f"] = "avx512f" in flags
    if not cuda_kernels.SIMULATOR:
        dev = cuda.get_current_device()
        name = dev.name.decode() if isinstance(dev.name, bytes) else str(dev.name)
        info.update(gpu=name, compute_capability=".".join(map(str, dev.compute_capability)),
                    sms=dev.MULTIPROCESSOR_COUNT, gpu_clock_mhz=dev.CLOCK_RATE / 1e3)
    else:
        info["gpu"] = "CUDA simulator"
    return info


def ptx_report(integrator="srkn6b", well=None):
    """f64 instruction counts of the compiled kernel and contractible mul -> add/sub pairs."""
    if cuda_kernels.SIMULATOR:
        return dict(integrator=integrator, well=well, ptx_f64_ops="simulator: no PTX", contractible_pairs=None,
                    sass=None)
    code = wells.resolve_well(well).compiled
    kernel = cuda_kernels.ensemble_kernel(integrator, True, cuda_kernels.BLOCK, cuda_kernels.WARP, code)
    asm = kernel.inspect_asm()
    ptx = next(iter(asm.values())) if isinstance(asm, dict) else asm
    ops = collections.Counter()
    mul_dst, uses = set(), []
    for line in ptx.splitlines():
        m = re.match(r"\s*((?:fma|mul|add|sub)\.[\w.]*f64)\s+(%fd\d+),\s*(.*);", line)
        if not m:
            continue
        op, dst, srcs = m.groups()
        ops[op] += 1
        if op.startswith("mul"):
            mul_dst.add(dst)
        elif op.startswith(("add", "sub")):
            uses.extend(re.findall(r"%fd\d+", srcs))
    rep = dict(integrator=integrator, well=code.name, ptx_f64_ops=dict(ops),
               contractible_pairs=sum(u in mul_dst for u in uses))
    try:
        sass = kernel.inspect_sass()
        sass = next(iter(sass.values())) if isinstance(sass, dict) else sass
        rep["sass"] = {k: len(re.findall(rf"\b{k}\b", sass)) for k in ("DFMA", "DMUL", "DADD")}
    except Exception as exc:  # diagnostic only (nvdisasm is often not installed)
        rep["sass"] = f"not available: {type(exc).__name__}: {str(exc)[:120]}"
    return rep


def compare(a, b):
    return dict(bitwise_equal=bool(np.array_equal(a, b)), mismatches=int((a != b).sum()), compared=int(a.size))


def dense(n, cycles, S=32, seed=1, run_cpu=True, integrator="srkn6b", blocks=()):
    rng = np.random.default_rng(seed)
    q = rng.uniform(-0.3, 0.3, n)
    p = rng.uniform(-0.3, 0.3, n)          # H0 < 0.09: never reaches xi_max = 0.25 with F = 0
    pidx = np.zeros(n, np.int64)
    kw = dict(xi_max=[0.25], q_max=[1.0], cycles=cycles, steps_per_cycle=S, integrator=integrator)
    steps = n * cycles * S
    cuda_engine.run_cuda(ensemble_problem(q[:256], p[:256], pidx[:256], [0.95], [0.0], np.pi, **dict(kw, cycles=2)))
    tm = {}
    gE, gQ = cuda_engine.run_cuda(ensemble_problem(q, p, pidx, [0.95], [0.0], np.pi, **kw), timing=tm)
    out = dict(integrator=integrator, n=n, cycles=cycles, steps_per_cycle=S, trajectory_steps=steps, gpu=dict(tm),
               gpu_steps_per_s=steps / tm["kernel_s"], escaped=int((gE >= 0).sum() + (gQ >= 0).sum()), block_sweep={})
    for b in blocks:                         # GPU only: threads per block (results must not change)
        cuda_engine.run_cuda(ensemble_problem(q[:256], p[:256], pidx[:256], [0.95], [0.0], np.pi, **dict(kw, cycles=2)), block=b)
        tb = {}
        bE, bQ = cuda_engine.run_cuda(ensemble_problem(q, p, pidx, [0.95], [0.0], np.pi, **kw), timing=tb, block=b)
        out["block_sweep"][b] = dict(kernel_s=tb["kernel_s"], steps_per_s=steps / tb["kernel_s"], grid=tb["grid"],
                                     regs=tb.get("regs_per_thread"),
                                     same_as_default=bool(np.array_equal(bE, gE) and np.array_equal(bQ, gQ)))
    if run_cpu:
        engine.run_cpu(ensemble_problem(q[:256], p[:256], pidx[:256], [0.95], [0.0], np.pi, **dict(kw, cycles=2)))
        t = time.perf_counter()
        cE, cQ, _ = engine.run_cpu(ensemble_problem(q, p, pidx, [0.95], [0.0], np.pi, **kw))
        dt = time.perf_counter() - t
        out.update(cpu_s=dt, cpu_steps_per_s=steps / dt, E=compare(cE, gE), Q=compare(cQ, gQ))
    return out


def work_steps(sE, sQ, cycles, S):
    """Trajectory-steps actually integrated: up to the last first-crossing when every threshold
    is crossed, else the whole horizon."""
    allc = np.concatenate([sE, sQ], axis=1)
    done = (allc >= 0).all(axis=1)
    return int(np.where(done, allc.max(axis=1), cycles * S).sum())


def fig21(n=300, cpu_sample=None, cpu_result=None, cycles=FIG21["cycles"], integrator="srkn6b"):
    qa = np.linspace(-1.0, 1.0, n)
    pa = np.linspace(-0.75, 0.75, n)
    Q, P = np.meshgrid(qa, pa, indexing="ij")
    Q, P = Q.ravel(), P.ravel()
    pidx = np.zeros(Q.size, np.int64)
    kw = dict(xi_max=FIG21["xi_max"], q_max=FIG21["q_max"], cycles=cycles, steps_per_cycle=FIG21["steps_per_cycle"],
              integrator=integrator)
    args = ([FIG21["Omega"]], [FIG21["F"]], FIG21["Psi"])
    runs = []
    for _ in range(2):                      # the first run pays for nothing but the transfers
        tm = {}
        gE, gQ = cuda_engine.run_cuda(ensemble_problem(Q, P, pidx, *args, **kw), timing=tm)
        runs.append(tm)
    S = FIG21["steps_per_cycle"]
    work = work_steps(gE, gQ, cycles, S)
    out = dict(integrator=integrator, n=n, cycles=cycles, gpu_runs=runs, kernel_s=min(r["kernel_s"] for r in runs),
               wall_s=min(r["wall_s"] for r in runs), trajectory_steps=work,
               gpu_steps_per_s=work / min(r["kernel_s"] for r in runs),
               safe_fraction={f"t{t}": dict(E=float(((gE[:, 0] < 0) | (gE[:, 0] > t * S)).mean()),
                                            Q=float(((gQ[:, 0] < 0) | (gQ[:, 0] > t * S)).mean()))
                              for t in (500, cycles)})
    rows = np.arange(n) if not cpu_sample else np.unique(np.linspace(0, n - 1, int(cpu_sample)).round().astype(int))
    sel = (rows[:, None] * n + np.arange(n)[None, :]).ravel()
    cached = None
    if cpu_result and os.path.exists(cpu_result):
        z = np.load(cpu_result)
        if (int(z["n"]) == n and int(z["cycles"]) == cycles and np.array_equal(z["rows"], rows)
                and str(z.get("integrator", "srkn6b")) == integrator):
            cached = z
        else:
            print(f"  {cpu_result}: made for other rows/n/cycles: recomputing")
    if cached is not None:
        cE, cQ, cpu_s = cached["steps_E"], cached["steps_Q"], float(cached["cpu_s"])
        out["cpu_from"] = cpu_result
    else:
        engine.run_cpu(ensemble_problem(Q[:64], P[:64], pidx[:64], *args, **dict(kw, cycles=2)))
        t = time.perf_counter()
        cE, cQ, _ = engine.run_cpu(ensemble_problem(Q[sel], P[sel], pidx[sel], *args, **kw))
        cpu_s = time.perf_counter() - t
        if cpu_result:
            np.savez(cpu_result, steps_E=cE, steps_Q=cQ, rows=rows, n=n, cycles=cycles, cpu_s=cpu_s,
                     integrator=integrator)
    out.update(cpu_rows=int(rows.size), cpu_s=cpu_s, cpu_s_full_estimate=cpu_s * n / rows.size,
               E=compare(cE, gE[sel]), Q=compare(cQ, gQ[sel]))
    return out


def wells_section(n_dense, cycles, chart_n, chart_cycles, cpu_rows, integrator="srkn6b"):
    """(c): dense steps/s per compiled well on the GPU (and the CPU engine), a cubic chart CPU vs GPU."""
    S = 32
    rng = np.random.default_rng(3)
    q = rng.uniform(-0.25, 0.25, n_dense)
    p = rng.uniform(-0.25, 0.25, n_dense)      # H0 < 0.07 in all three wells: nothing escapes with F = 0
    pidx = np.zeros(n_dense, np.int64)
    jobs = [("quartic", None, dict(xi_max=[0.25], q_max=[1.0])),
            ("quartic, asymmetric bounds (signed tracking)", None, dict(xi_max=[0.25], q_bounds=[[-0.9, 1.0]])),
            ("cubic (degree-4 class)", CUBIC, dict(xi_max=[1.0 / 6.0], q_bounds=[[-0.5, 1.0]])),
            ("sextic (degree-8 class)", SEXTIC, dict(xi_max=[0.2], q_max=[1.0])),
            ("pendulum (expression, wells.elementary sin/cos)", PENDULUM, dict(xi_max=[1.9], q_max=[3.0]))]
    out = dict(integrator=integrator, n=n_dense, cycles=cycles, steps_per_cycle=S, dense={}, ptx=[])
    steps_n = n_dense * cycles * S
    for name, well, thr in jobs:
        kw = dict(cycles=cycles, steps_per_cycle=S, integrator=integrator, well=well, **thr)
        cuda_engine.run_cuda(ensemble_problem(q[:256], p[:256], pidx[:256], [0.95], [0.0], np.pi, **dict(kw, cycles=2)))
        tm = {}
        gE, gQ = cuda_engine.run_cuda(ensemble_problem(q, p, pidx, [0.95], [0.0], np.pi, **kw), timing=tm)
        engine.run_cpu(ensemble_problem(q[:256], p[:256], pidx[:256], [0.95], [0.0], np.pi, **dict(kw, cycles=2)))
        t = time.perf_counter()
        cE, cQ, _ = engine.run_cpu(ensemble_problem(q, p, pidx, [0.95], [0.0], np.pi, **kw))
        cpu_s = time.perf_counter() - t
        out["dense"][name] = dict(kernel_s=tm["kernel_s"], gpu_steps_per_s=steps_n / tm["kernel_s"],
                                  regs=tm.get("regs_per_thread"), cpu_s=cpu_s, cpu_steps_per_s=steps_n / cpu_s,
                                  escaped=int((gE >= 0).sum() + (gQ >= 0).sum()), E=compare(cE, gE), Q=compare(cQ, gQ))
    for well in (None, CUBIC, SEXTIC, PENDULUM):
        out["ptx"].append(ptx_report(integrator, well))
    # the cubic chart: energy thresholds and asymmetric bounds, CPU vs GPU escape steps
    qa = np.linspace(-0.6, 1.0, chart_n)
    pa = np.linspace(-0.6, 0.6, chart_n)
    Q, P = (a.ravel() for a in np.meshgrid(qa, pa, indexing="ij"))
    kw = dict(xi_max=[0.12, 1.0 / 6.0], q_bounds=[[-0.43, 0.65], [-np.inf, 0.9]], cycles=chart_cycles,
              steps_per_cycle=S, integrator=integrator, well=CUBIC)
    args = ([0.85], [0.02], 0.3)
    runs = []
    for _ in range(2):
        tm = {}
        gE, gQ = cuda_engine.run_cuda(ensemble_problem(Q, P, np.zeros(Q.size, np.int64), *args, **kw), timing=tm)
        runs.append(tm["kernel_s"])
    rows = np.unique(np.linspace(0, chart_n - 1, min(cpu_rows, chart_n)).round().astype(int))
    sel = (rows[:, None] * chart_n + np.arange(chart_n)[None, :]).ravel()
    t = time.perf_counter()
    cE, cQ, _ = engine.run_cpu(ensemble_problem(Q[sel], P[sel], np.zeros(sel.size, np.int64), *args, **kw))
    cpu_s = time.perf_counter() - t
    out["cubic_chart"] = dict(n=chart_n, cycles=chart_cycles, kernel_s=min(runs), cpu_rows=int(rows.size), cpu_s=cpu_s,
                              escaped_fraction=float((gE[:, 1] >= 0).mean()), E=compare(cE, gE[sel]),
                              Q=compare(cQ, gQ[sel]))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dense-n", type=int, default=100_000)
    ap.add_argument("--dense-cycles", type=int, default=1000)
    ap.add_argument("--dense-cpu", type=int, default=1, help="0: skip the CPU side of the dense job")
    ap.add_argument("--chart-n", type=int, default=300)
    ap.add_argument("--chart-cycles", type=int, default=FIG21["cycles"])
    ap.add_argument("--cpu-sample", type=int, default=None, help="compare Fig 21 on this many rows of q0")
    ap.add_argument("--cpu-result", default=None, help="npz of CPU Fig 21 steps: reused if it fits, else written "
                    "(srkn6b; other integrators get the suffix _<integrator>)")
    ap.add_argument("--integrators", default="srkn6b", help="comma-separated: srkn6b,rk4")
    ap.add_argument("--blocks", default="", help="comma-separated threads per block to sweep on the dense job (GPU)")
    ap.add_argument("--wells", action="store_true", help="section (c): the kernel per compiled well")
    ap.add_argument("--wells-only", action="store_true", help="only section (c)")
    ap.add_argument("--wells-n", type=int, default=200, help="cubic chart of (c): n x n ICs")
    ap.add_argument("--wells-cycles", type=int, default=2000)
    ap.add_argument("--wells-cpu-rows", type=int, default=40)
    ap.add_argument("--json", default=None)
    a = ap.parse_args()
    if not cuda_engine.cuda_available():
        raise SystemExit("bench_gpu: no CUDA GPU (numba-cuda) on this machine")
    res = dict(machine=machine())
    m = res["machine"]
    print(f"machine: CPU {m['cpu']} ({m['cores']} cores, numba threads {m['numba_threads']}, AVX2 {m['avx2']}, "
          f"AVX-512 {m['avx512f']}); GPU {m['gpu']} (cc {m.get('compute_capability')}, {m.get('sms')} SMs, "
          f"{m.get('gpu_clock_mhz')} MHz); numba {m['numba']}, numba-cuda {m['numba_cuda']}")
    if a.wells or a.wells_only:
        res["wells"] = []
        for integrator in a.integrators.split(","):
            w = wells_section(a.dense_n, a.dense_cycles, a.wells_n, a.wells_cycles, a.wells_cpu_rows, integrator)
            res["wells"].append(w)
            print(f"(c) wells [{integrator}], dense {w['n']} x {w['cycles']} cycles x {w['steps_per_cycle']} steps, F = 0:")
            ref = w["dense"]["quartic (QUARTIC)"]["gpu_steps_per_s"]
            for name, d in w["dense"].items():
                print(f"    {name:44s} GPU {d['gpu_steps_per_s']:.3g} steps/s ({ref / d['gpu_steps_per_s']:.2f}x the "
                      f"quartic's time per step, {d['regs']} regs); CPU {d['cpu_steps_per_s']:.3g} steps/s; "
                      f"crossings {d['escaped']}; CPU == GPU: E {d['E']['bitwise_equal']}, Q {d['Q']['bitwise_equal']}")
            for r in w["ptx"]:
                print(f"    PTX well {r['well']}: f64 ops {r['ptx_f64_ops']}; contractible pairs "
                      f"{r['contractible_pairs']}; SASS {r['sass']}")
            c = w["cubic_chart"]
            print(f"    cubic chart {c['n']}x{c['n']}, {c['cycles']} cycles: GPU kernel {c['kernel_s']:.4f} s, "
                  f"{100 * c['escaped_fraction']:.1f}% escape (barrier energy); CPU {c['cpu_s']:.2f} s on "
                  f"{c['cpu_rows']} rows; CPU vs GPU steps: E {c['E']}, Q {c['Q']}")
        if a.wells_only:
            if a.json:
                with open(a.json, "w") as fh:
                    json.dump(res, fh, indent=1, default=str)
            return
    res["ptx"] = [ptx_report(i) for i in ("srkn6b", "rk4")]
    for r in res["ptx"]:
        print(f"kernel {r['integrator']}: PTX f64 ops {r['ptx_f64_ops']}; contractible mul->add/sub pairs: "
              f"{r['contractible_pairs']}; SASS {r['sass']}")
    blocks = [int(b) for b in a.blocks.split(",") if b]
    res["dense"], res["fig21"] = [], []
    for integrator in a.integrators.split(","):
        d = dense(a.dense_n, a.dense_cycles, run_cpu=bool(a.dense_cpu), integrator=integrator, blocks=blocks)
        res["dense"].append(d)
        print(f"(a) dense [{integrator}]: {d['n']} trajectories x {d['cycles']} cycles x {d['steps_per_cycle']} steps = "
              f"{d['trajectory_steps']:.3g} trajectory-steps, none escapes ({d['escaped']} crossings)")
        print(f"    GPU kernel {d['gpu']['kernel_s']:.4f} s -> {d['gpu_steps_per_s']:.3g} steps/s "
              f"(grid {d['gpu']['grid']} x {d['gpu']['block']}, {d['gpu'].get('regs_per_thread')} regs, "
              f"wall {d['gpu']['wall_s']:.3f} s)")
        for b, r in d["block_sweep"].items():
            print(f"    block {b}: grid {r['grid']}, {r['regs']} regs, kernel {r['kernel_s']:.4f} s -> "
                  f"{r['steps_per_s']:.3g} steps/s, steps identical to block {d['gpu']['block']}: {r['same_as_default']}")
        if "cpu_s" in d:
            print(f"    CPU {d['cpu_s']:.3f} s -> {d['cpu_steps_per_s']:.3g} steps/s; GPU/CPU "
                  f"{d['gpu_steps_per_s'] / d['cpu_steps_per_s']:.1f}x; steps E {d['E']}, Q {d['Q']}")
        cpu_result = a.cpu_result
        if cpu_result and integrator != "srkn6b":
            root, ext = os.path.splitext(cpu_result)
            cpu_result = f"{root}_{integrator}{ext}"
        f = fig21(a.chart_n, a.cpu_sample, cpu_result, a.chart_cycles, integrator)
        res["fig21"].append(f)
        print(f"(b) Fig 21 chart [{integrator}] {f['n']}x{f['n']}, {f['cycles']} cycles: GPU kernel {f['kernel_s']:.4f} s, "
              f"wall {f['wall_s']:.4f} s (runs: {[round(r['kernel_s'], 4) for r in f['gpu_runs']]} s kernel); "
              f"{f['trajectory_steps']:.3g} trajectory-steps -> {f['gpu_steps_per_s']:.3g} steps/s")
        print(f"    safe fractions {f['safe_fraction']}")
        print(f"    CPU {f['cpu_s']:.2f} s on {f['cpu_rows']} of {f['n']} rows (full chart ~{f['cpu_s_full_estimate']:.1f} s)"
              f"{' [from ' + f['cpu_from'] + ']' if 'cpu_from' in f else ''}; "
              f"CPU vs GPU steps: E {f['E']}, Q {f['Q']}")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(res, fh, indent=1, default=str)


if __name__ == "__main__":
    main()
