"""Wall time of an integrity map's numerics (issue 13): every tile job of the ``integrity_map``
experiment, computed in one process exactly as the pipeline's ``chart_tile`` rule does
(``Kind.compute_tile``), on the CPU engine or the CUDA engine, plus the analytic map.

    PYTHONPATH=src python benchmarks/bench_integrity_map.py                        # config/integrity_map_fine.yaml, auto
    PYTHONPATH=src python benchmarks/bench_integrity_map.py --backend cpu --configfile config/config.yaml
    PYTHONPATH=src python benchmarks/bench_integrity_map.py --check-tasks 2        # + CPU == GPU on 2 Omega tasks

Prints the machine, the map's size, the upper-bound trajectory-steps (cost estimate), the wall
time of all tile jobs and of the analytic map, and with --check-tasks the number of integrity
values that differ between the CUDA and the CPU engine on those tasks (0 expected: bitwise equal
escape steps).  The snakemake run adds per-job start-up (~2 s a job) and the gathering.

Measured (2026-11-23, NVIDIA H100 80GB HBM3, 132 SMs; host 16-core Intel Xeon with AVX-512;
numba-cuda; config/integrity_map_fine.yaml: 61 x 61 control points, 151 x 151 ICs, 2000 cycles,
upper bound 5.4e12 trajectory-steps, 61 tasks x 4 tiles): numerics (cuda) 52.3 s for the 244 tile
jobs (first job with compilation 3.2 s); analytic map 200.5 s on the host CPU (one process: now
the bottleneck); CPU engine recomputing one Omega task (61 control points) in 36.0 s with 16
threads: 0 of 549 integrity values differ from the GPU's.
"""
from __future__ import annotations

import argparse
import contextlib
import io
import os
import platform
import time

import numpy as np


def machine(backend):
    cpu = platform.processor() or "?"
    try:
        with open("/proc/cpuinfo") as fh:
            info = fh.read()
        cpu = next(line.split(":", 1)[1].strip() for line in info.splitlines() if line.startswith("model name"))
        flags = "AVX-512" if "avx512f" in info else "AVX2" if "avx2" in info else "no AVX2"
    except (OSError, StopIteration):
        flags = "?"
    out = f"CPU: {cpu} ({flags}), {os.cpu_count()} logical cores"
    if backend != "cpu":
        from numba import cuda

        dev = cuda.get_current_device()
        out += f"; GPU: {dev.name.decode() if isinstance(dev.name, bytes) else dev.name}, " \
               f"{dev.MULTIPROCESSOR_COUNT} SMs"
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--configfile", nargs="+", default=["config/config.yaml", "config/integrity_map_fine.yaml"])
    ap.add_argument("--backend", choices=["cpu", "cuda", "auto"], default="auto")
    ap.add_argument("--threads", type=int, default=None, help="numba CPU threads (default: all)")
    ap.add_argument("--check-tasks", type=int, default=0, help="Omega tasks recomputed on the CPU and compared")
    args = ap.parse_args()

    from safebasins.numerics.engine import resolve_backend
    from safebasins.pipeline.cost import exp_cost
    from safebasins.pipeline.kinds.maps import build_analytic
    from safebasins.pipeline.plan import plan
    from safebasins.pipeline.registry import Job

    run = plan(args.configfile)
    exp = run.experiments["integrity_map"]
    params, kind = exp.params, exp.kind
    backend = resolve_backend(args.backend)
    tiles = run.tiles
    print(machine(backend))
    nq, np_ = params["grid"]["n"]
    print(f"integrity map: {len(params['Omega'])} Omega x {len(params['F'])} F control points, {nq} x {np_} ICs, "
          f"{params['cycles']} cycles x {params['steps_per_cycle']} steps; {len(exp.tasks)} tasks x {tiles} tiles; "
          f"upper bound {exp_cost(exp):.3g} trajectory-steps")

    job = Job(threads=args.threads, backend=backend)
    t0 = time.perf_counter()
    kind.compute_tile(params, 0, 0, tiles, job)      # compile / warm up (counted separately)
    t_warm = time.perf_counter() - t0
    parts = {}
    t0 = time.perf_counter()
    with contextlib.redirect_stdout(io.StringIO()):   # (one progress line per job)
        for k in range(len(exp.tasks)):
            for t in range(tiles):
                parts[k, t] = kind.compute_tile(params, k, t, tiles, job)
    t_num = time.perf_counter() - t0
    t0 = time.perf_counter()
    build_analytic(params, {}, job)
    t_ana = time.perf_counter() - t0
    print(f"numerics ({backend}): {t_num:.1f} s for {len(parts)} tile jobs (first job with compilation: {t_warm:.1f} s); "
          f"analytic map: {t_ana:.1f} s")
    if args.check_tasks and backend != "cpu":
        cpu = Job(threads=args.threads, backend="cpu")
        diff = total = 0
        t0 = time.perf_counter()
        for k in range(min(args.check_tasks, len(exp.tasks))):
            for t in range(tiles):
                with contextlib.redirect_stdout(io.StringIO()):
                    b = kind.compute_tile(params, k, t, tiles, cpu)
                a = parts[k, t]
                for name in a.data_vars:
                    x, y = np.asarray(a[name].values), np.asarray(b[name].values)
                    diff += int(np.sum(~((x == y) | (np.isnan(x) & np.isnan(y)))))
                    total += x.size
        print(f"CPU check on {args.check_tasks} task(s) ({time.perf_counter() - t0:.1f} s): {diff} of {total} "
              f"integrity values differ between CUDA and CPU")


if __name__ == "__main__":
    main()
