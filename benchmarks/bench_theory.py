"""Timings of the analytic theory (targets: slow_flow_escapes 300x300 <= 1 s, critical_forcing
400 Omega <= 2 s, one core, after warm-up).  Run: .venv/bin/python benchmarks/bench_theory.py"""
import time

import numpy as np

from safebasins.theory import critical_forcing, safe_basin_boundaries, slow_flow_escapes


def best_of(fun, n=5):
    fun()                                   # warm-up
    ts = []
    for _ in range(n):
        t = time.perf_counter()
        fun()
        ts.append(time.perf_counter() - t)
    return min(ts), float(np.median(ts))


def main():
    q = np.linspace(-1, 1, 300)
    Q, P = np.meshgrid(q, q, indexing="ij")
    Om = np.linspace(0.4, 1.4, 400)
    cases = [
        ("slow_flow_escapes 300x300 (F=0.015, Om=1.04, Psi=pi, xi_max=0.2)",
         lambda: slow_flow_escapes(Q, P, 0.015, 1.04, np.pi, 0.2), 1.0),
        ("slow_flow_escapes 300x300 (F=0.0876, Om=0.57, xi_max=0.2499, exact)",
         lambda: slow_flow_escapes(Q, P, 0.0876, 0.57, 0.0, 0.2499, fourier="exact"), 1.0),
        ("critical_forcing 400 Omega (zero IC, xi_max=0.15)",
         lambda: critical_forcing(Om, 0.15), 2.0),
        ("critical_forcing 400 Omega (xi_ini=0.15, gamma_ini=0.25, xi_max=0.242)",
         lambda: critical_forcing(Om, 0.242, 0.15, 0.25), 2.0),
        ("safe_basin_boundaries Fig 9 (n_points=400)",
         lambda: safe_basin_boundaries(0.0478, 0.76, 0.0, 0.235), None),
    ]
    for name, fun, target in cases:
        best, med = best_of(fun)
        flag = "" if target is None else (" OK" if best <= target else " SLOW") + f" (target {target} s)"
        print(f"{name:72s} best {best:7.3f} s  median {med:7.3f} s{flag}")


if __name__ == "__main__":
    main()
