"""Every named well that is not a polynomial, and an electrostatic expression well: the CUDA
backend under numba's simulator gives the CPU backend's escape steps bitwise (their forces call
wells.elementary, compiled for each target from one source).  The GPU side runs in a subprocess
with NUMBA_ENABLE_CUDASIM=1, the child of tests/numerics/test_cuda_simulator.py (cases as JSON
on stdin)."""
from __future__ import annotations

import json

import numpy as np

from safebasins import wells
from tests.numerics import test_cuda_simulator
from tests.numerics.ensemble import run_ensemble
from tests.cuda_simulator import run_simulator

#: an electrostatic (MEMS) well: elastic restoring force and a Coulomb pull towards the plate at q = 1
MEMS = {"expression": "q**2/2 - 1/20/(1 - q) + 1/20 + q/20"}
#: forcing cycles per trajectory: the simulator runs each lane's force in Python (the elementary
#: functions op by op), so the ensemble stays small; tests/wells cover the functions' domains
CYCLES = 6


def _cases() -> dict[str, dict[str, object]]:
    """(well spec -> ensemble_problem arguments): a grid of ICs inside the well, two energy
    thresholds below the barrier (some ICs escape at once, some later, some never)."""
    cases: dict[str, dict[str, object]] = {}
    # the polynomial named wells (quartic, cubic) are cases of test_cuda_simulator.py
    for spec in [*(n for n in wells.NAMED_WELLS if n not in ("quartic", "cubic")), MEMS]:
        w = wells.resolve_well(spec)
        Eb = w.barrier_energy
        lo, hi = w.barriers
        span = min(hi - lo, 4.0) if np.isfinite(hi - lo) else 4.0
        mid = 0.0
        q = mid + np.linspace(-0.35, 0.35, 4) * span * (0.5 if not np.isfinite(lo) or not np.isfinite(hi) else 1.0)
        q = q[(q > lo) & (q < hi)]
        p = np.linspace(-0.6, 0.6, 3) * np.sqrt(Eb)
        Q, P = np.meshgrid(q, p, indexing="ij")
        name = spec if isinstance(spec, str) else "mems"
        cases[f"srkn6b/{name}"] = dict(
            args=[Q.ravel().tolist(), P.ravel().tolist(), (np.arange(Q.size) % 2).tolist(), [0.9, 1.1],
                  [0.05 * Eb, 0.1 * Eb], 0.3],
            kw=dict(xi_max=[0.5 * Eb, 0.8 * Eb], cycles=CYCLES, steps_per_cycle=16, integrator="srkn6b"),
            well=spec)
    return cases


def test_named_wells_cuda_simulator_matches_cpu_bitwise() -> None:
    cases = _cases()
    r = run_simulator(test_cuda_simulator.__file__, json.dumps(cases), timeout=600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    gpu = json.loads(r.stdout.strip().splitlines()[-1])
    outcomes = set()
    for name, c in cases.items():
        args, kw = c["args"], c["kw"]
        assert isinstance(args, list) and isinstance(kw, dict)
        cpu_E, cpu_Q = run_ensemble(*args, threads=1, **kw, well=c["well"])
        g = gpu[name]
        assert np.array_equal(np.array(g["E"], np.int64).reshape(cpu_E.shape), cpu_E), (name, cpu_E, g["E"])
        assert np.array_equal(np.array(g["Q"], np.int64).reshape(cpu_Q.shape), cpu_Q), (name, cpu_Q, g["Q"])
        # a test that can fail: in every well some ICs escape after a while (the force evaluated
        # many times on the way), and some do not escape
        assert (cpu_E > 0).any(), (name, cpu_E)
        outcomes.update(np.sign(cpu_E).ravel().tolist())
    assert outcomes == {-1, 0, 1}, outcomes
