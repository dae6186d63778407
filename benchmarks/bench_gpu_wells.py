"""The named wells on a real GPU: cost per step against the quartic, and CPU == GPU escape steps.

    PYTHONPATH=src python benchmarks/bench_gpu_wells.py            # needs a CUDA GPU (numba-cuda)
    PYTHONPATH=src python benchmarks/bench_gpu_wells.py --json out.json

For the quartic, every named well that is not a polynomial (their forces call wells.elementary,
compiled for each target from one source) and an electrostatic (MEMS) expression well, in one
process:

* dense job: ``--dense-n`` ICs near the bottom (H0 < 0.3 E_b), F = 0, nothing escapes, every
  trajectory runs ``--dense-cycles`` periods of 32 steps: GPU kernel trajectory-steps/s (CUDA
  events) and its ratio to the quartic's (the per-step cost of the well on the GPU), and the CPU
  engine's on all host cores with its ratio to the quartic's;
* chart: ``--chart-n`` x ``--chart-n`` ICs inside the well, two forcing amplitudes, two energy
  thresholds below the barrier, ``--chart-cycles`` periods: the escape steps of every trajectory
  on the GPU and the CPU engine, and how many differ (must be 0: the same IEEE operations on both).

tests/numerics/test_cuda_simulator_wells.py checks the same equality under numba's simulator in CI.

Measured (NVIDIA H200, numba-cuda 0.30.4; host 16 cores; defaults: 65,536 x 200 cycles dense,
100 x 100 x 2 thresholds x 100 cycles chart), the quartic's steps/s over the well's:
  GPU  quartic 1.94e11 steps/s; pendulum 10.8, sech2 21.7, Morse 15.4, MEMS 3.5
  CPU  quartic 1.89e9 (16 threads); pendulum 10.7, sech2 17.8, Morse 11.4, MEMS 2.3
  chart: 0 of 20,000 escape steps differ between CPU and GPU in every well.
"""
from __future__ import annotations

import argparse
import json
import time

import numpy as np

from _report import machine
from safebasins import wells
from safebasins.numerics import cuda_engine, engine
from safebasins.numerics.problem import ensemble_problem

#: an electrostatic (MEMS) well: elastic restoring force and a Coulomb pull towards the plate at q = 1
MEMS = {"expression": "q**2/2 - 1/20/(1 - q) + 1/20 + q/20"}
S = 32


def _specs() -> list[tuple[str, object]]:
    named = [n for n in wells.NAMED_WELLS if n not in ("quartic", "cubic")]
    return [("quartic", None), *((n, n) for n in named), ("mems", MEMS)]


def _window(spec: object) -> tuple[float, float, float]:
    w = wells.resolve_well(spec)
    lo, hi = w.barriers
    span = min(hi - lo, 4.0) if np.isfinite(hi - lo) else 2.0
    return float(w.barrier_energy), max(lo, -0.45 * span), min(hi, 0.45 * span)


def dense(spec: object, n: int, cycles: int) -> dict[str, float]:
    Eb, lo, hi = _window(spec)
    rng = np.random.default_rng(1)
    r = np.sqrt(0.3 * Eb) * 0.5
    q = rng.uniform(-r, r, n)
    p = rng.uniform(-r, r, n)
    pidx = np.zeros(n, np.int64)
    kw = dict(xi_max=[0.9 * Eb], cycles=cycles, steps_per_cycle=S, well=spec)
    warm = ensemble_problem(q[:256], p[:256], pidx[:256], [0.95], [0.0], np.pi, **dict(kw, cycles=2))
    cuda_engine.run_cuda(warm)
    engine.run_cpu(warm)
    tm: dict[str, float] = {}
    gE, _ = cuda_engine.run_cuda(ensemble_problem(q, p, pidx, [0.95], [0.0], np.pi, **kw), timing=tm)
    m = max(n // 8, 256)
    t = time.perf_counter()
    cE, _, _ = engine.run_cpu(ensemble_problem(q[:m], p[:m], pidx[:m], [0.95], [0.0], np.pi, **kw))
    cpu_s = time.perf_counter() - t
    steps = n * cycles * S
    return dict(gpu_steps_per_s=steps / tm["kernel_s"], cpu_steps_per_s=m * cycles * S / cpu_s,
                escaped=int((gE >= 0).sum()), cpu_gpu_equal=bool(np.array_equal(cE, gE[:m])))


def chart(spec: object, n: int, cycles: int) -> dict[str, object]:
    Eb, lo, hi = _window(spec)
    qa = np.linspace(lo, hi, n)
    pa = np.linspace(-1.2, 1.2, n) * np.sqrt(Eb)
    Q, P = (a.ravel() for a in np.meshgrid(qa, pa, indexing="ij"))
    pidx = (np.arange(Q.size) % 2).astype(np.int64)
    args = ([0.9, 1.1], [0.05 * Eb, 0.1 * Eb], 0.3)
    kw = dict(xi_max=[0.5 * Eb, 0.8 * Eb], cycles=cycles, steps_per_cycle=S, well=spec)
    tm: dict[str, float] = {}
    gE, gQ = cuda_engine.run_cuda(ensemble_problem(Q, P, pidx, *args, **kw), timing=tm)
    t = time.perf_counter()
    cE, cQ, _ = engine.run_cpu(ensemble_problem(Q, P, pidx, *args, **kw))
    cpu_s = time.perf_counter() - t
    return dict(trajectories=int(Q.size), kernel_s=tm["kernel_s"], cpu_s=cpu_s,
                escaped_fraction=float((gE[:, -1] >= 0).mean()), escaped_later=int((gE > 0).sum()),
                differ_E=int((cE != gE).sum()), differ_Q=int((cQ != gQ).sum()), compared=int(cE.size + cQ.size))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dense-n", type=int, default=65536)
    ap.add_argument("--dense-cycles", type=int, default=200)
    ap.add_argument("--chart-n", type=int, default=100)
    ap.add_argument("--chart-cycles", type=int, default=100)
    ap.add_argument("--json", default=None)
    a = ap.parse_args()
    out: dict[str, object] = {"machine": machine()}
    dense_rates: dict[str, dict[str, float]] = {}
    charts: dict[str, dict[str, object]] = {}
    for name, spec in _specs():
        t = time.perf_counter()
        dense_rates[name] = dense(spec, a.dense_n, a.dense_cycles)
        charts[name] = chart(spec, a.chart_n, a.chart_cycles)
        d, c = dense_rates[name], charts[name]
        q = dense_rates["quartic"]
        print(f"{name:12s} GPU {d['gpu_steps_per_s']:.3e} steps/s (quartic / well = "
              f"{q['gpu_steps_per_s'] / d['gpu_steps_per_s']:5.2f}), CPU {d['cpu_steps_per_s']:.3e} "
              f"(ratio {q['cpu_steps_per_s'] / d['cpu_steps_per_s']:5.2f}); chart {c['trajectories']} x 2 thresholds: "
              f"{c['differ_E']} + {c['differ_Q']} of {c['compared']} escape steps differ, "
              f"escaped {c['escaped_fraction']:.2f}; {time.perf_counter() - t:.0f} s with compiles", flush=True)
    out.update(dense=dense_rates, charts=charts)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
