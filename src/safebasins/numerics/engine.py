"""The CPU backend of the ensemble engine and the one entry point of both backends.

:func:`integrate` takes an :class:`~safebasins.numerics.problem.EnsembleProblem` (built and
checked once by problem.ensemble_problem) and runs it on the CPU lanes (:func:`run_cpu`, the
reference) or the CUDA kernels (cuda_engine.run_cuda, bitwise equal); this module also holds the
engine's checks that depend on the scheme and the machine (steps per cycle, threads).
"""
from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from types import ModuleType
from typing import Any
import importlib
import importlib.util
import math

import numba
import numpy as np
import numpy.typing as npt

from safebasins.core import checks
from safebasins.numerics import kernels, schemes
from safebasins.numerics.problem import EnsembleProblem
from safebasins.wells import resolve_well
from safebasins.wells.base import WellLike

DEFAULT_STEPS_PER_CYCLE = 32
DEFAULT_INTEGRATOR = schemes.DEFAULT_SCHEME
#: where ensembles run: the CPU lanes (the reference), a CUDA GPU (cuda_engine: bitwise equal
#: escape steps) or "auto" (the GPU when one is visible, else the CPU)
BACKENDS = ("cpu", "cuda", "auto")
LANES = 128          # trajectories in flight per task (4 chains x up to 32-lane segments)


@contextlib.contextmanager
def thread_count(threads: int | None) -> Iterator[int]:
    """Temporarily run numba parallel regions on `threads` threads (None: leave as is)."""
    if threads is None:
        yield numba.get_num_threads()
        return
    old = numba.get_num_threads()
    numba.set_num_threads(int(threads))
    try:
        yield int(threads)
    finally:
        numba.set_num_threads(old)


def check_threads(threads: Any) -> int | None:
    if threads is None:
        return None
    n = checks.check_positive_int("threads", threads)
    pool: int = numba.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]  # (set at import from the environment)
    if n > pool:
        raise ValueError(f"threads must be <= {pool} (numba's thread pool), got {n}")
    return n


def check_steps_per_cycle(steps_per_cycle: Any) -> int:
    n = checks.check_positive_int("steps_per_cycle", steps_per_cycle)
    if n < 4:
        raise ValueError(f"steps_per_cycle must be >= 4, got {n}")
    return n


#: above this many steps per forcing cycle the forcing is quasi-static for the well: a smaller
#: Omega is refused as such rather than answered with an astronomical steps_per_cycle
MAX_STEPS_PER_CYCLE = 10 ** 7


def check_step(Omega: npt.ArrayLike, steps_per_cycle: int, well: WellLike = None,
               integrator: str = DEFAULT_INTEGRATOR) -> int:
    """Refuse a step ``h = 2 pi / (Omega steps_per_cycle)`` the scheme cannot integrate: ValueError
    (naming steps_per_cycle) when ``h * max(omega_max, Omega)`` exceeds the scheme's step limit
    (schemes.step_limit: half its stability limit on the harmonic oscillator; SRKN6b 1.58, RK4
    1.41) for the smallest Omega, omega_max being the well's largest local frequency
    sqrt(max |V''|) (Well.omega_max).  Beyond it the scheme loses its accuracy and, past its
    stability limit, blows up to NaN (which the kernels count as escape, never as safe: a chart
    would be all escape, not an answer)."""
    Om = np.atleast_1d(np.asarray(Omega, dtype=float))
    w = resolve_well(well)
    limit = schemes.step_limit(integrator)
    om_min = float(Om.min())
    h = 2.0 * math.pi / (om_min * steps_per_cycle)
    fastest = max(w.omega_max, om_min)
    x = h * fastest
    if x > limit:
        need = 2.0 * math.pi * fastest / (om_min * limit)
        if need > MAX_STEPS_PER_CYCLE:
            raise ValueError(
                f"steps_per_cycle: Omega = {om_min:.6g} is too small to integrate: the step limit h * {fastest:.4g} <= "
                f"{limit:.4g} of {integrator} in the {w.name} well would need {need:.3g} steps per forcing cycle (more "
                "than "
                f"{MAX_STEPS_PER_CYCLE:.0e}); use a larger Omega")
        need = math.ceil(need)
        raise ValueError(
            f"steps_per_cycle: {steps_per_cycle} steps per forcing cycle at Omega = {om_min:.6g} give a step "
            f"h = {h:.4g}, and h * {fastest:.4g} = {x:.4g} exceeds {limit:.4g}, the step limit of {integrator} "
            f"({fastest:.4g} = the larger of Omega "
            f"and the {w.name} well's largest local frequency sqrt(max |V''|) = {w.omega_max:.4g}): the integrator "
            f"is inaccurate or unstable there; use steps_per_cycle >= {need} (or a larger Omega)")
    return steps_per_cycle


def damping_attrs(damping: float) -> dict[str, float]:
    """``{"damping": beta}`` for a damped run; nothing for the undamped equation (datasets of the
    paper's equation keep their attributes: no damping attribute means beta = 0)."""
    return {"damping": damping} if damping > 0 else {}


integrator_text = schemes.integrator_text


def thresholds(name: str, values: npt.ArrayLike, check: Callable[[str, Any], np.ndarray]) -> np.ndarray:
    a = np.atleast_1d(check(name, values) if np.size(values) else np.asarray(values, dtype=float)).astype(float)
    if a.ndim != 1:
        raise ValueError(f"{name} must be a scalar or a 1-D sequence, got shape {a.shape}")
    return a


def run_cpu(problem: EnsembleProblem, *, threads: int | None = None, store: bool = False
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """Integrate a problem on the CPU lanes (kernels.ensemble).

    Returns (steps_E (N, nE), steps_Q (N, nQ), store or None): int64 first-crossing steps in the
    problem's sorted threshold order (-1: not within `cycles`), and with ``store`` the period-map
    iterates (N, cycles + 1, 2) (NaN after escape)."""
    pb = problem
    N = pb.n
    outE = np.full((N, pb.thrE2.size), -1, dtype=np.int64)
    outQ = np.full((N, pb.hi.size), -1, dtype=np.int64)
    st = np.full((N, pb.cycles + 1, 2), np.nan) if store else np.empty((0, 0, 2))
    if N:
        with thread_count(threads) as nthreads:
            # one task per thread: trajectories are interleaved over tasks (i % n_tasks), so each
            # task gets a statistically equal share of long-lived ones and its lanes stay full
            n_tasks = max(1, min(math.ceil(N / LANES), nthreads))
            kernels.ensemble(pb.q0, pb.p0, pb.pidx, pb.coefficients(), pb.step_sizes(), pb.F, pb.sine_table(),
                             pb.thrE2, pb.hi, pb.cycles, pb.stop_any, int(n_tasks), LANES, outE, outQ, st,
                             bool(store), scheme=pb.scheme, well=pb.code, thrQlo=pb.lo)
    return outE, outQ, (st if store else None)


def steps_to_cycles(steps: np.ndarray, steps_per_cycle: int) -> np.ndarray:
    """int64 step counts (-1: none) -> float64 forcing cycles (+inf: none)."""
    out = steps.astype(float) / steps_per_cycle
    out[steps < 0] = np.inf
    return out


def resolve_backend(backend: str) -> str:
    """"cpu" or "cuda" for a requested backend ("auto": the GPU when numba-cuda sees one)."""
    if backend not in BACKENDS:
        raise ValueError(f"backend must be one of {BACKENDS}, got {backend!r}")
    if backend == "auto":
        return "cuda" if importlib.util.find_spec("numba_cuda") and cuda_engine().cuda_available() else "cpu"
    return backend


def cuda_engine() -> ModuleType:
    """The CUDA backend's module (safebasins.numerics.cuda_engine), imported on first use: importing
    numba.cuda costs ~1 s and the simulator must be chosen (NUMBA_ENABLE_CUDASIM) before it;
    ImportError naming the extra to install when numba-cuda, the numba CUDA target it is written
    for, is missing."""
    if importlib.util.find_spec("numba_cuda") is None:
        raise ImportError("the CUDA backend needs numba-cuda (numba's CUDA target), which is not installed: "
                          "pip install 'safebasins[cuda]'", name="numba_cuda")
    return importlib.import_module("safebasins.numerics.cuda_engine")


def integrate(problem: EnsembleProblem, backend: str = "cpu", *, threads: int | None = None,
              **options: Any) -> tuple[np.ndarray, np.ndarray]:
    """Integrate an ensemble problem (problem.ensemble_problem) on a backend: "cpu" (the CPU lanes,
    the reference; ``threads``), "cuda" (cuda_engine.run_cuda; ``block``, ``grid``, ``timing``) or
    "auto" (the GPU when one is visible).  Returns (steps_E, steps_Q) in the caller's threshold
    order, bitwise the same on either backend (the CUDA kernels repeat the CPU lanes' operations;
    tests/numerics/test_cuda_simulator.py)."""
    if resolve_backend(backend) == "cuda":
        steps_E, steps_Q = cuda_engine().run_cuda(problem, **options)
    else:
        steps_E, steps_Q, _ = run_cpu(problem, threads=threads, **options)
    return problem.caller_order(steps_E, steps_Q)
