"""The CUDA backend (cuda_engine.run_ensemble_cuda) under numba's CUDA simulator: escape steps
bitwise equal to the CPU engine (engine.run_ensemble).

The simulator must be switched on before numba.cuda is first imported, so the checks run in a
SUBPROCESS with NUMBA_ENABLE_CUDASIM=1 (this file run as a script) and the rest of the test
session keeps the real CUDA target.  Cases: a 6x5 grid of initial conditions with 2 energy and
1 displacement thresholds (given unsorted) for both integrators; three parameter sets with
stop_any, the forcing table in global memory and more trajectories than threads (persistent
threads take several each; compaction runs); and knife-edge thresholds set to an energy the CPU
trajectory reaches exactly, where a one-ulp difference in the state would move the recorded
step (this is what catches a contracted multiply-add).  Simulator time: ~10 s.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

SRC = Path(__file__).resolve().parents[2] / "src"


def _grid_ics():
    q = np.linspace(-0.9, 0.9, 6)
    p = np.linspace(-0.5, 0.5, 5)
    Q, P = np.meshgrid(q, p, indexing="ij")
    return Q.ravel(), P.ravel()


def _knife_edges(integrator, ics, Omega, F, Psi, S, n_steps, per_ic=2):
    """Knife-edge thresholds: for each IC, the last `per_ic` steps where its CPU trajectory sets a
    new running maximum e* of 2 H0 (late, so earlier differences have propagated) give the
    thresholds 2 xi = e* and nextafter(e*, -inf); the lower one is crossed exactly at that step,
    and a state one ulp off there moves the step of one of the two.  Returns (xi_max, expected):
    expected[j] = (IC, step) at which the CPU must cross xi_max[2 j + 1]."""
    from safebasins.numerics import kernels
    c = kernels.lane_coefficients(Omega, S, integrator)[0]
    tab = F * kernels.sine_table(S, Psi, integrator)
    xi, expected = [], []
    for ic, (q, p) in enumerate(ics):
        emax, records = kernels.energy2(q, p), []
        for n in range(n_steps):
            row = tab[n % S]
            if integrator == "rk4":
                q, p = kernels.rk4_step(q, p, c[0], c[1], c[2], row[0], row[1], row[2])
            else:
                q, p = kernels.bm6_step(q, p, *c, *row)
            e = kernels.energy2(q, p)
            if e > emax and abs(q) <= kernels.Q_BARRIER:
                emax = e
                records.append((n + 1, e))
        for step, e in records[-per_ic:]:
            xi += [e / 2, np.nextafter(e, -np.inf) / 2]
            expected.append((ic, step))
    return xi, expected


def _cases():
    Q, P = _grid_ics()
    zero = np.zeros(Q.size, np.int64)
    yield "grid", dict(args=(Q, P, zero, [0.95], [0.0876], np.pi),
                       kw=dict(xi_max=[0.2, 0.12], q_max=[0.8], cycles=20, steps_per_cycle=16))
    yield "multi_stop_any", dict(args=(Q, P, np.arange(Q.size) % 3, [0.95, 0.8, 1.2], [0.0876, 0.05, 0.12], 0.7),
                                 kw=dict(xi_max=[0.2, 0.15], q_max=[0.75], cycles=15, steps_per_cycle=12,
                                         stop_any=True),
                                 cuda=dict(block=8, grid=2), global_table=True)
    yield "persistent", dict(args=(Q, P, zero, [0.95], [0.0876], np.pi),
                             kw=dict(xi_max=[0.22], q_max=[0.9, 0.7], cycles=15, steps_per_cycle=8),
                             cuda=dict(block=8, grid=2))


def child():
    """Run in the subprocess (NUMBA_ENABLE_CUDASIM=1): compare GPU-simulator and CPU steps."""
    from safebasins.numerics import cuda_engine, cuda_kernels, engine
    assert cuda_kernels.SIMULATOR and cuda_engine.cuda_available()
    out = []
    for integrator in ("srkn6b", "rk4"):
        cases = list(_cases())
        ics = [(0.1, 0.35), (0.3, 0.1), (-0.2, 0.2)]
        xi, expected = _knife_edges(integrator, ics, 0.95, 0.0876, np.pi, 16, 16 * 8)
        cases.append(("knife_edge", dict(args=(np.array([a for a, _ in ics]), np.array([b for _, b in ics]),
                                               np.zeros(len(ics), np.int64), [0.95], [0.0876], np.pi),
                                         kw=dict(xi_max=xi, cycles=8, steps_per_cycle=16), expect=expected)))
        for name, c in cases:
            kw = dict(c["kw"], integrator=integrator)
            cpu_E, cpu_Q, _ = engine.run_ensemble(*c["args"], threads=1, **kw)
            cuda_kernels.SHARED_TABLE_BYTES = 0 if c.get("global_table") else 16 * 1024
            t = time.perf_counter()
            gpu_E, gpu_Q = cuda_engine.run_ensemble_cuda(*c["args"], **kw, **c.get("cuda", {}))
            dt = time.perf_counter() - t
            for j, (ic, step) in enumerate(c.get("expect", ())):   # the knife edges really are ones
                assert cpu_E[ic, 2 * j + 1] == step and cpu_E[ic, 2 * j] != step, (cpu_E, c["expect"])
            out.append(dict(case=f"{integrator}/{name}", seconds=round(dt, 2),
                            equal_E=bool(np.array_equal(cpu_E, gpu_E)), equal_Q=bool(np.array_equal(cpu_Q, gpu_Q)),
                            dtype=str(gpu_E.dtype), shapes=[list(gpu_E.shape), list(gpu_Q.shape)],
                            escaped=int((cpu_E >= 0).sum() + (cpu_Q >= 0).sum()),
                            not_escaped=int((cpu_E < 0).sum() + (cpu_Q < 0).sum()),
                            at_start=int((cpu_E == 0).sum() + (cpu_Q == 0).sum()),
                            cpu=np.concatenate([cpu_E, cpu_Q], axis=1).tolist(),
                            gpu=np.concatenate([gpu_E, gpu_Q], axis=1).tolist()))
    print(json.dumps(out))


def test_cuda_simulator_matches_cpu_engine_bitwise():
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1",
               PYTHONPATH=os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")]))
    t = time.perf_counter()
    r = subprocess.run([sys.executable, __file__], env=env, capture_output=True, text=True, timeout=300)
    wall = time.perf_counter() - t
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    res = json.loads(r.stdout.strip().splitlines()[-1])
    assert len(res) == 8
    for c in res:
        assert c["equal_E"] and c["equal_Q"], (c["case"], c["cpu"], c["gpu"])
        assert c["dtype"] == "int64"
    grid = [c for c in res if c["case"].endswith("/grid")]
    # the grid case has every outcome: escape at the IC, escape later, no escape
    assert all(c["at_start"] > 0 and c["escaped"] > c["at_start"] and c["not_escaped"] > 0 for c in grid), grid
    assert wall < 120, wall


def test_missing_gpu_is_an_explicit_error():
    """Without a GPU and without the simulator, run_ensemble_cuda refuses to run."""
    from safebasins.numerics import cuda_engine, cuda_kernels
    if cuda_kernels.SIMULATOR or cuda_engine.cuda_available():
        return          # a GPU (or the simulator) is there: nothing to refuse
    import pytest
    with pytest.raises(RuntimeError, match="CUDA GPU"):
        cuda_engine.run_ensemble_cuda([0.0], [0.0], [0], [1.0], [0.0], 0.0, xi_max=[0.2], cycles=1,
                                      steps_per_cycle=8)


if __name__ == "__main__":
    child()
