"""Wall time of an integrity map's numerics: every tile job of the ``integrity_map``
experiment, computed in one process exactly as the pipeline's ``chart_tile`` rule does
(``Kind.compute_tile``), on the CPU engine or the CUDA engine, plus the analytic map.

    PYTHONPATH=src python benchmarks/bench_integrity_map.py                        # config/integrity_map_fine.yaml, auto
    PYTHONPATH=src python benchmarks/bench_integrity_map.py --backend cpu --configfile config/config.yaml
    PYTHONPATH=src python benchmarks/bench_integrity_map.py --check-tasks 2        # + CPU == GPU on 2 Omega tasks
    PYTHONPATH=src python benchmarks/bench_integrity_map.py --analytic [--quick]   # analytic map: new / old

``--analytic`` times ``integrity_map_analytic`` against the pre-issue-20 loop
(``benchmarks/_integrity_reference.py``: one ``slow_flow_escapes``, ``xi_true_analytic`` and
``closed_measures`` per control point) in the same process, in alternation, on the paper
config's map (25 x 25 control points, 71 x 71 ICs; ``--quick``: 10 x 10), checks that the
arrays the map is made of are bitwise equal and prints the median ratio old / new.

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


def analytic_ratio(quick, repeat):
    """Analytic integrity map, new (``integrity_map_analytic``) vs the pre-issue-20 loop."""
    import sys

    import xarray as xr

    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from _integrity_reference import reference_arrays
    from _report import report

    from safebasins.analysis.integrity import integrity_measures
    from safebasins.analysis.integrity_map import integrity_map_analytic
    from safebasins.wells import resolve_well

    n = 10 if quick else 25
    Om, F = np.linspace(0.7, 1.1, n), np.linspace(0.0, 0.12, n)       # config/config.yaml integrity_map
    q0, p0 = np.linspace(-0.72, 0.72, 71), np.linspace(-0.63, 0.63, 71)
    args = (Om, F, np.pi, 0.18, q0, p0)
    print(machine("cpu"))
    integrity_map_analytic(Om[:2], F[:2], np.pi, 0.18, q0, p0)         # warm-up (imports, numba caches)
    reference_arrays(Om[:2], F[:2], np.pi, 0.18, q0, p0)
    t_new, t_old = [], []
    for _ in range(max(1, repeat)):
        t0 = time.perf_counter()
        ds = integrity_map_analytic(*args)
        t_new.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        safe, xt, cm = reference_arrays(*args)
        t_old.append(time.perf_counter() - t0)
    da = xr.DataArray(safe, dims=("Omega", "F", "q0", "p0"), coords={"Omega": Om, "F": F, "q0": q0, "p0": p0})
    m = integrity_measures(da, xi_max=0.18, well=resolve_well(None))
    same = all(np.asarray(a).tobytes() == np.asarray(b).tobytes() for a, b in [
        (m["GIM"].values, ds["GIM"].values), (m["LIM"].values, ds["LIM"].values), (m["IF"].values, ds["IF"].values),
        (xt, ds["xi_true"].values), (cm[..., 1], ds["LIM_true"].values), (cm[..., 2], ds["IF_true"].values)])
    ratios = [o / nw for o, nw in zip(t_old, t_new)]
    r = float(np.median(ratios))
    print(f"analytic integrity map {n} x {n} control points, 71 x 71 ICs: new {np.median(t_new):.2f} s, "
          f"old {np.median(t_old):.2f} s (medians of {len(ratios)} paired runs); old / new = {r:.1f} "
          f"(pairs {', '.join(f'{x:.1f}' for x in ratios)}); new / old = {1 / r:.3f}; bitwise equal: {same}")
    report("analytic integrity map", round(r, 1), "old / new wall time, same process",
           f"{n}x{n} control points, 71x71 ICs; new {np.median(t_new):.2f} s; bitwise equal: {same}")
    if not same:
        raise SystemExit("the new analytic map differs from the reference")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--configfile", nargs="+", default=["config/config.yaml", "config/integrity_map_fine.yaml"])
    ap.add_argument("--backend", choices=["cpu", "cuda", "auto"], default="auto")
    ap.add_argument("--threads", type=int, default=None, help="numba CPU threads (default: all)")
    ap.add_argument("--check-tasks", type=int, default=0, help="Omega tasks recomputed on the CPU and compared")
    ap.add_argument("--analytic", action="store_true", help="only the analytic map: new / old in one process")
    ap.add_argument("--quick", action="store_true", help="with --analytic: 10 x 10 control points")
    ap.add_argument("--repeat", type=int, default=3, help="with --analytic: paired runs (median ratio)")
    args = ap.parse_args()
    if args.analytic:
        return analytic_ratio(args.quick, args.repeat)

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
