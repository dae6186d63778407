"""The CUDA backend (engine.integrate(problem, "cuda"): cuda_engine.run_cuda) under numba's CUDA
simulator: escape steps bitwise equal to the CPU backend (engine.integrate(problem, "cpu")).

The simulator must be switched on before numba.cuda is first imported, so the GPU side runs in a
SUBPROCESS with NUMBA_ENABLE_CUDASIM=1 (this file run as a script, cases as JSON on stdin) and
the rest of the test session keeps the real CUDA target; the CPU side runs in the test process
(whose compiled engine the other numerics tests share).  Cases, for both integrators: a 6x5 grid
of initial conditions with 2 energy and 1 displacement thresholds (given unsorted); three parameter sets with
stop_any, the forcing table in global memory and more trajectories than threads (persistent
threads take several each; compaction runs); and knife-edge thresholds set to an energy the CPU
trajectory reaches exactly, where a one-ulp difference in the state would move the recorded
step (this is what catches a multiply-add rounded twice).  Other wells: the cubic (kernel flag
code: Horner from run-time coefficients, one barrier) with asymmetric displacement bounds, the
quartic with asymmetric bounds (signed tracking), several parameter sets, and a rational well
written as an expression (generated V, dV); the damped schemes (beta = 0.1, three parameter sets).  Subprocess:
~10-15 s.
"""
from __future__ import annotations

import json
import math
import sys
import time

import numpy as np

from safebasins.numerics import schemes
from tests.cuda_simulator import pin_to_one_cpu, run_simulator

# wells travel to the subprocess as specs (safebasins.wells.resolve_well): the cubic
# V = q^2/2 - q^3/3 (a polynomial code, Horner from run-time coefficients) and a well written as
# an expression (the generic V, dV code; sqrt and division: correctly rounded on every target)
CUBIC = "cubic"
RATIONAL = {"expression": "q**2/2 - q**4/(4 + q**2)"}


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
    from safebasins.numerics import steps
    c = schemes.lane_coefficients(Omega, S, integrator)[0]
    tab = F * schemes.sine_table(S, Psi, integrator)
    xi, expected = [], []
    for ic, (q, p) in enumerate(ics):
        emax, records = steps.energy2(q, p), []
        for n in range(n_steps):
            row = tab[n % S]
            q, p = steps.scalar_step(integrator)(steps.W0, q, p, tuple(c), tuple(row))
            e = steps.energy2(q, p)
            if e > emax and abs(q) <= 1.0:
                emax = e
                records.append((n + 1, e))
        for step, e in records[-per_ic:]:
            xi += [e / 2, np.nextafter(e, -np.inf) / 2]
            expected.append((ic, step))
    return xi, expected


#: schemes run through every case; any other scheme (each generated from its constant by the same
#: code) through the knife edges and the damped case only, to keep the simulator's time bounded
FULL = ("srkn6b", "rk4")


def _cases():
    """(name, spec) pairs; spec: args and kw of ensemble_problem, optional cuda (block, grid),
    global_table, expect (knife edges).  Plain lists: the spec travels to the subprocess as JSON
    (Python's float repr round-trips every double exactly)."""
    for name, spec in _all_cases():
        if name.split("/")[0] in FULL or name.endswith(("/knife_edge", "/damped")):
            yield name, spec


def _all_cases():
    Q, P = _grid_ics()
    zero = [0] * Q.size
    for integrator in schemes.SCHEMES:
        yield f"{integrator}/grid", dict(
            args=[Q.tolist(), P.tolist(), zero, [0.95], [0.0876], np.pi],
            kw=dict(xi_max=[0.2, 0.12], q_max=[0.8], cycles=20, steps_per_cycle=16, integrator=integrator))
        yield f"{integrator}/multi_stop_any", dict(
            args=[Q.tolist(), P.tolist(), (np.arange(Q.size) % 3).tolist(), [0.95, 0.8, 1.2], [0.0876, 0.05, 0.12],
                  0.7],
            kw=dict(xi_max=[0.2, 0.15], q_max=[0.75], cycles=15, steps_per_cycle=12, stop_any=True,
                    integrator=integrator),
            cuda=dict(block=8, grid=2), global_table=True)
        yield f"{integrator}/persistent", dict(
            args=[Q.tolist(), P.tolist(), zero, [0.95], [0.0876], np.pi],
            kw=dict(xi_max=[0.22], q_max=[0.9, 0.7], cycles=15, steps_per_cycle=8, integrator=integrator),
            cuda=dict(block=8, grid=2))
        ics = [(0.1, 0.35), (0.3, 0.1), (-0.2, 0.2)]
        xi, expected = _knife_edges(integrator, ics, 0.95, 0.0876, np.pi, 16, 16 * 8)
        yield f"{integrator}/knife_edge", dict(
            args=[[a for a, _ in ics], [b for _, b in ics], [0] * len(ics), [0.95], [0.0876], np.pi],
            kw=dict(xi_max=[float(x) for x in xi], cycles=8, steps_per_cycle=16, integrator=integrator),
            expect=expected)
        Qc, Pc = 0.55 * Q + 0.1, 0.7 * P
        yield f"{integrator}/cubic", dict(
            args=[Qc.tolist(), Pc.tolist(), (np.arange(Q.size) % 2).tolist(), [0.85, 0.9], [0.02, 0.03], 0.3],
            kw=dict(xi_max=[0.12, 1.0 / 6.0], q_bounds=[[-0.43, 0.65], [-math.inf, 0.9]], cycles=20,
                    steps_per_cycle=16, integrator=integrator),
            well=CUBIC)
        yield f"{integrator}/damped", dict(     # several parameter sets: the per-lane coefficient columns
            args=[Qc.tolist(), Pc.tolist(), (np.arange(Q.size) % 3).tolist(), [0.85, 0.9, 0.8], [0.05, 0.06, 0.04],
                  0.3],
            kw=dict(xi_max=[0.12, 1.0 / 6.0], q_bounds=[[-0.43, 0.65]], cycles=25, steps_per_cycle=16,
                    integrator=integrator, damping=0.1),
            well=CUBIC)
        yield f"{integrator}/expression", dict(
            args=[(0.9 * Q).tolist(), (0.9 * P).tolist(), zero, [0.8], [0.05], 1.0],
            kw=dict(xi_max=[0.2, 0.3], q_bounds=[[-0.9, 1.0]], cycles=20, steps_per_cycle=16, integrator=integrator),
            well=RATIONAL)
    yield "srkn6b/quartic_signed", dict(
        args=[Q.tolist(), P.tolist(), zero, [0.95], [0.0876], np.pi],
        kw=dict(xi_max=[0.2], q_max=[0.7], q_bounds=[[-0.75, 0.8]], cycles=15, steps_per_cycle=8, stop_any=False),
        cuda=dict(block=8, grid=2))


API_CHART = dict(q0=np.linspace(-0.8, 0.8, 5).tolist(), p0=np.linspace(-0.4, 0.6, 4).tolist(), F=0.0876,
                 Omega=0.95, Psi=float(np.pi), xi_max=[0.2, 0.25], q_max=[0.8], cycles=12, steps_per_cycle=16)


def child():
    """In the subprocess (NUMBA_ENABLE_CUDASIM=1): run every case (JSON on stdin) with
    the CUDA backend under the simulator, and one escape_chart(backend="cuda"); print as JSON."""
    from safebasins.numerics import cuda_engine, cuda_kernels, engine, escape_chart
    from safebasins.numerics.problem import ensemble_problem
    assert cuda_kernels.SIMULATOR and cuda_engine.cuda_available()
    a = dict(API_CHART)
    ch = escape_chart(a.pop("q0"), a.pop("p0"), a.pop("F"), a.pop("Omega"), a.pop("Psi"), backend="cuda", **a)
    out = {"api/escape_chart": dict(E=ch["escape_cycle_energy"].values.tolist(),
                                    Q=ch["escape_cycle_displacement"].values.tolist())}
    for name, c in json.load(sys.stdin).items():
        cuda_kernels.SHARED_TABLE_BYTES = 0 if c.get("global_table") else 16 * 1024
        t = time.perf_counter()
        E, Q = engine.integrate(ensemble_problem(*c["args"], **c["kw"], well=c.get("well")), "cuda",
                                **c.get("cuda", {}))
        out[name] = dict(E=E.tolist(), Q=Q.tolist(), dtype=[str(E.dtype), str(Q.dtype)],
                         seconds=round(time.perf_counter() - t, 2))
    print(json.dumps(out))


def test_cuda_simulator_matches_cpu_engine_bitwise():
    from tests.numerics.ensemble import run_ensemble
    cases = dict(_cases())
    t = time.perf_counter()
    r = run_simulator(__file__, json.dumps(cases), timeout=300)
    wall = time.perf_counter() - t
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    gpu = json.loads(r.stdout.strip().splitlines()[-1])
    # the public API: escape_chart(backend="cuda") equals the CPU chart value for value
    from safebasins.numerics import escape_chart
    a = dict(API_CHART)
    ch = escape_chart(a.pop("q0"), a.pop("p0"), a.pop("F"), a.pop("Omega"), a.pop("Psi"), backend="cpu", **a)
    api = gpu.pop("api/escape_chart")
    assert np.array_equal(np.array(api["E"]), ch["escape_cycle_energy"].values)
    assert np.array_equal(np.array(api["Q"]), ch["escape_cycle_displacement"].values)
    assert sorted(gpu) == sorted(cases)
    for name, c in cases.items():
        cpu_E, cpu_Q = run_ensemble(*c["args"], threads=1, **c["kw"], well=c.get("well"))
        for j, (ic, step) in enumerate(c.get("expect", ())):   # the knife edges really are ones
            assert cpu_E[ic, 2 * j + 1] == step and cpu_E[ic, 2 * j] != step, (name, cpu_E, c["expect"])
        g = gpu[name]
        assert g["dtype"] == ["int64", "int64"]
        assert np.array_equal(np.array(g["E"], np.int64).reshape(cpu_E.shape), cpu_E), (name, cpu_E, g["E"])
        assert np.array_equal(np.array(g["Q"], np.int64).reshape(cpu_Q.shape), cpu_Q), (name, cpu_Q, g["Q"])
        if name.endswith(("/grid", "/cubic")):   # every outcome: escape at the IC, escape later, no escape
            both = np.concatenate([cpu_E, cpu_Q], axis=1)
            assert (both == 0).any() and (both > 0).any() and (both < 0).any(), both
    print(f"simulator subprocess: {wall:.1f} s")


def test_missing_gpu_is_an_explicit_error():
    """Without a GPU and without the simulator, the CUDA backend refuses to run."""
    from safebasins.numerics import cuda_engine, cuda_kernels
    from safebasins.numerics.problem import ensemble_problem
    if cuda_kernels.SIMULATOR or cuda_engine.cuda_available():
        return          # a GPU (or the simulator) is there: nothing to refuse
    import pytest
    with pytest.raises(RuntimeError, match="CUDA GPU"):
        cuda_engine.run_cuda(ensemble_problem([0.0], [0.0], [0], [1.0], [0.0], 0.0, xi_max=[0.2], cycles=1,
                                              steps_per_cycle=8))


if __name__ == "__main__":
    pin_to_one_cpu()
    child()
