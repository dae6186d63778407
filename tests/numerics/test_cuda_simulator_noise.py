"""The CUDA backend of the noisy ensemble (numerics.cuda_noise) under numba's CUDA simulator: the
first steps beyond the threshold of every path equal the CPU lanes' (noise_kernels.escape_steps)
bitwise, and escape_probability(backend="cuda") returns the CPU's Dataset.

The simulator must be switched on before numba.cuda is first imported, so the GPU side runs in a
SUBPROCESS with NUMBA_ENABLE_CUDASIM=1 (this file run as a script, cases as JSON on stdin), as in
tests/numerics/test_cuda_simulator.py; the CPU side runs in the test process.  Cases: white and
coloured noise, Gaussian and five-point variates, undamped and damped, the quartic (|q| tracking)
and the pendulum (signed tracking; its force and energy call wells.elementary's sin and cos),
SRKN6b and RK4, a seed above 2^32 (both words of the Philox key), a displacement bound pair; in
every case some paths escape at the initial condition, some later and some not within the
horizon.  Few initial conditions, paths and cycles of 8 steps, few simulator threads (each takes
several trajectories): the simulator runs every operation as Python, every thread as a Python thread.
"""
from __future__ import annotations

import json
import math
import pickle
import re
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from safebasins.numerics import noise_kernels, steps
from safebasins.numerics.noise import energy_shift, escape_probability
from safebasins.numerics.problem import ensemble_problem
from safebasins.wells.compiled import fma
from tests.numerics.test_cuda_optional import INSTALL, without_numba_cuda  # noqa: F401  (a fixture)
from tests.cuda_simulator import pin_to_one_cpu, run_simulator

STEPS = 8          # steps per forcing cycle
CYCLES = 6
PATHS = 4
# the quartic, xi_max = 0.2: (0.95, 0.3) is beyond at t = 0, (0.55, 0.3) close to the threshold,
# (0, 0.05) near the bottom of the well
QUARTIC_ICS = ([0.0, 0.55, 0.95, -0.45], [0.05, 0.3, 0.3, 0.0])
# the pendulum (barriers +-pi, barrier energy 2), xi_max = 1: (2.5, 0.5) is beyond at t = 0
PENDULUM_ICS = ([0.0, 1.2, 2.5, -1.4], [0.1, 0.3, 0.5, -0.5])


def _cases() -> dict[str, dict[str, Any]]:
    """name -> the arguments of one noisy ensemble (plain values: they travel as JSON, and Python's
    float repr round-trips every double)."""
    q, p = QUARTIC_ICS
    quartic = dict(q0=q, p0=p, well=None, F=0.02, Omega=0.95, Psi=math.pi, xi_max=0.2)
    q, p = PENDULUM_ICS
    pendulum = dict(q0=q, p0=p, well="pendulum", F=0.05, Omega=0.9, Psi=0.4, xi_max=1.0)
    return {
        "quartic/white": dict(quartic, noise=0.05, seed=7),
        "quartic/white/damped": dict(quartic, noise=0.08, damping=0.1, seed=2 ** 40 + 3),
        "quartic/coloured": dict(quartic, noise=0.05, noise_time=1.5, seed=11),
        "quartic/coloured/damped/rk4": dict(quartic, noise=0.08, noise_time=1.0, damping=0.05, integrator="rk4",
                                            seed=5),
        "quartic/white/bounds": dict(quartic, noise=0.05, bounds=[-0.7, 0.6], seed=3, block=2, grid=2),
        "pendulum/white": dict(pendulum, noise=0.2, seed=1),
        "pendulum/coloured/damped": dict(pendulum, noise=0.3, noise_time=1.2, damping=0.1, seed=9),
        # the five-point law: 8 steps a period (half a Philox block), 40 (three blocks, the last one partial)
        "quartic/white/five-point": dict(quartic, noise=0.05, seed=7, variates="five-point"),
        "quartic/white/damped/five-point/40": dict(quartic, noise=0.08, damping=0.1, seed=2 ** 40 + 3,
                                                   variates="five-point", steps=40),
        "quartic/white/thresholds": dict(quartic, noise=0.05, seed=7, thrE2=[0.25, 0.4, 0.4, 0.6]),
        "quartic/white/offsets": dict(quartic, noise=0.05, seed=7, variates="five-point", ic_offset=5,
                                      path_offset=2 ** 31),
        "pendulum/coloured/damped/five-point": dict(pendulum, noise=0.3, noise_time=1.2, damping=0.1, seed=9,
                                                    variates="five-point"),
    }


def _arguments(case: dict[str, Any]) -> tuple[tuple[Any, ...], dict[str, Any]]:
    """(args, keywords) of noise_kernels.escape_steps / cuda_noise.escape_steps for a case, formed as
    escape_probability forms them."""
    q0, p0 = np.array(case["q0"]), np.array(case["p0"])
    pb = ensemble_problem(q0, p0, np.zeros(q0.size, np.int64), [case["Omega"]], [case["F"]], case["Psi"],
                          xi_max=[case["xi_max"]], cycles=CYCLES, steps_per_cycle=case.get("steps", STEPS),
                          integrator=case.get("integrator", "srkn6b"), well=case["well"],
                          damping=case.get("damping", 0.0))
    h = float(pb.step_sizes()[0])
    tau = case.get("noise_time", 0.0)
    thrE2 = np.array(case["thrE2"]) if isinstance(case.get("thrE2"), list) else case.get("thrE2", float(pb.thrE2[0]))
    variates = case.get("variates", "gaussian")
    args = (pb.code, pb.scheme, q0, p0, PATHS, pb.coefficients(), pb.sine_table(), case["F"], thrE2, CYCLES,
            noise_kernels.step_noise(case["noise"], h, tau, noise_kernels.LAWS[variates]), case["seed"])
    bounds = tuple(case.get("bounds", (-math.inf, math.inf)))
    kw = dict(shift=energy_shift(case["noise"], h, "shift", tau, variates), bounds=bounds,
              ic_offset=case.get("ic_offset", 0), path_offset=case.get("path_offset", 0))
    return args, kw


def _knife_edges(case: dict[str, Any]) -> tuple[float, int]:
    """(e*, n*): the largest 2 H0 + shift |p| of path 0 from the first (quartic) initial condition
    within the horizon, reached first after step n* (the CPU's states, noise_kernels.final_states).
    With 2 xi_max = e* that path does not escape; one ulp below, it escapes at step n* exactly: a
    state one ulp off at step n* moves the recorded step (what an operation rounded differently,
    a multiply-add rounded twice, would do)."""
    args, kw = _arguments(case)
    code, sc, q0, p0, _, coef, sintab, F, _, cycles, noise, seed = args
    e_star, n_star = -math.inf, -1
    for n in range(1, cycles * sintab.shape[0] + 1):
        q, p, _ = noise_kernels.final_states(code, sc, q0[:1], p0[:1], 1, coef, sintab, F, n, noise, seed)
        e = fma(kw["shift"], abs(float(p[0, 0])), steps.energy2(float(q[0, 0]), float(p[0, 0])))
        assert abs(q[0, 0]) < 1.0
        if e > e_star:
            e_star, n_star = e, n
    return e_star, n_star


#: the public call compared as a whole Dataset (a grid of ICs, white noise, damped)
API = dict(q0=[-0.3, 0.2, 0.9], p0=[0.0, 0.35], F=0.0876, Omega=0.95, Psi=float(np.pi), noise=0.06, paths=3,
           xi_max=0.2, t_eval=[1.0, 2.5, 4.0], cycles=4, damping=0.05, steps_per_cycle=STEPS, seed=21)
#: attributes that are not results: the call's own arguments (backend) and its time
CALL_ATTRS = ("parameters", "date_created")


def child() -> None:
    """In the subprocess (NUMBA_ENABLE_CUDASIM=1): every case on the CUDA backend, and the API
    Dataset pickled to the given path; the escape steps printed as JSON."""
    from safebasins.numerics import cuda_kernels, cuda_noise
    assert cuda_kernels.SIMULATOR
    job = json.load(sys.stdin)
    out: dict[str, Any] = {}
    for name, case in job["cases"].items():
        args, kw = _arguments(case)
        t = time.perf_counter()
        steps = cuda_noise.escape_steps(*args, **kw, block=case.get("block", 4), grid=case.get("grid", 1))
        out[name] = dict(steps=steps.tolist(), dtype=str(steps.dtype), seconds=round(time.perf_counter() - t, 2))
    ds = [escape_probability(**API, backend="cuda", variates=v) for v in ("gaussian", "five-point")]
    Path(job["api"]).write_bytes(pickle.dumps(ds))
    print(json.dumps(out))


def _without_call(ds: xr.Dataset) -> xr.Dataset:
    ds = ds.copy()
    for k in CALL_ATTRS:
        ds.attrs.pop(k)
    return ds


def test_cuda_simulator_noise_matches_cpu_bitwise(tmp_path: Path) -> None:
    cases = _cases()
    knife = dict(cases["quartic/white/damped"], noise=0.04)
    e_star, n_star = _knife_edges(knife)
    assert n_star > STEPS, n_star              # late: earlier differences have propagated
    cases["knife_edge/at"] = dict(knife, thrE2=e_star)
    cases["knife_edge/below"] = dict(knife, thrE2=float(np.nextafter(e_star, -math.inf)))
    api_path = tmp_path / "api.pickle"
    t = time.perf_counter()
    r = run_simulator(__file__, json.dumps(dict(cases=cases, api=str(api_path))), timeout=600)
    wall = time.perf_counter() - t
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    gpu = json.loads(r.stdout.strip().splitlines()[-1])
    assert sorted(gpu) == sorted(cases)
    for name, case in cases.items():
        args, kw = _arguments(case)
        cpu = noise_kernels.escape_steps(*args, **kw)
        g = gpu[name]
        assert g["dtype"] == "int64"
        np.testing.assert_array_equal(np.array(g["steps"], np.int64), cpu, err_msg=name)
        if name.startswith("knife_edge"):       # the knife edge is one: path 0 of IC 0 crosses it at n* exactly
            assert cpu[0, 0] == (n_star if name.endswith("below") else -1), (name, cpu, n_star)
            continue
        # a test that can fail: escapes at the initial condition, later, and none within the horizon
        assert (cpu == 0).any() and (cpu > 0).any() and (cpu < 0).any(), (name, cpu)
        # and the noise acts: some initial condition's paths differ
        assert (cpu.min(axis=1) != cpu.max(axis=1)).any(), (name, cpu)
    for cuda_ds, variates in zip(pickle.loads(api_path.read_bytes()), ("gaussian", "five-point")):
        cpu_ds = escape_probability(**API, backend="cpu", variates=variates)
        xr.testing.assert_identical(_without_call(cuda_ds), _without_call(cpu_ds))
        p = cpu_ds.P_escape.values
        assert ((p > 0) & (p < 1)).any() and (p == 0).any(), p
        assert json.loads(cuda_ds.attrs["parameters"])["backend"] == "cuda"
        assert cpu_ds.attrs["variates"] == variates
    print(f"simulator subprocess: {wall:.1f} s; per case {[gpu[n]['seconds'] for n in cases]}")


def test_cuda_backend_without_a_gpu_is_an_explicit_error() -> None:
    """Without a GPU and without the simulator, backend="cuda" refuses to run (RuntimeError naming
    the GPU); "auto" then runs on the CPU, with the CPU's result."""
    import pytest

    from safebasins.numerics import cuda_engine, cuda_kernels
    if cuda_kernels.SIMULATOR or cuda_engine.cuda_available():
        pytest.skip("a GPU (or the simulator) is there: nothing to refuse")
    with pytest.raises(RuntimeError, match="CUDA GPU"):
        escape_probability(**API, backend="cuda")
    xr.testing.assert_identical(_without_call(escape_probability(**API, backend="auto")),
                                _without_call(escape_probability(**API, backend="cpu")))


def test_cuda_without_numba_cuda_names_the_extra(without_numba_cuda: None) -> None:
    import pytest

    with pytest.raises(ImportError, match=re.escape(INSTALL)):
        escape_probability(**API, backend="cuda")


if __name__ == "__main__":
    pin_to_one_cpu()
    child()
