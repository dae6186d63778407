"""Python driver of the compiled ensemble kernel (argument checks, thread control, tasks)."""
from __future__ import annotations

import contextlib
import importlib.util
import math

import numba
import numpy as np

from safebasins import checks
from safebasins.numerics import kernels, steps
from safebasins.wells import resolve_well

DEFAULT_STEPS_PER_CYCLE = 32
DEFAULT_INTEGRATOR = "srkn6b"
#: where ensembles run: the CPU lanes (the reference), a CUDA GPU (cuda_engine: bitwise equal
#: escape steps) or "auto" (the GPU when one is visible, else the CPU)
BACKENDS = ("cpu", "cuda", "auto")
LANES = 128          # trajectories in flight per task (4 chains x up to 32-lane segments)


@contextlib.contextmanager
def thread_count(threads):
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


def check_threads(threads):
    if threads is None:
        return None
    n = checks.check_positive_int("threads", threads)
    if n > numba.config.NUMBA_NUM_THREADS:
        raise ValueError(f"threads must be <= {numba.config.NUMBA_NUM_THREADS} (numba's thread pool), got {n}")
    return n


def check_steps_per_cycle(steps_per_cycle):
    n = checks.check_positive_int("steps_per_cycle", steps_per_cycle)
    if n < 4:
        raise ValueError(f"steps_per_cycle must be >= 4, got {n}")
    return n


#: largest h * omega_max accepted (numerics docs): half of SRKN6b's stability limit 3.16 for
#: the harmonic oscillator and below RK4's 2.83 (|R(i x)| <= 1); phase error 1.2e-4 per step there
STEP_LIMIT = 1.5
#: above this many steps per forcing cycle the forcing is quasi-static for the well: a smaller
#: Omega is refused as such rather than answered with an astronomical steps_per_cycle
MAX_STEPS_PER_CYCLE = 10 ** 7


def check_step(Omega, steps_per_cycle, well=None):
    """Refuse a step ``h = 2 pi / (Omega steps_per_cycle)`` the schemes cannot integrate: ValueError
    (naming steps_per_cycle) when ``h * max(omega_max, Omega) > STEP_LIMIT`` for the smallest
    Omega, omega_max being the well's largest local frequency sqrt(max |V''|) (Well.omega_max).
    Beyond it the schemes lose their accuracy and, past ~3, blow up to NaN (which the kernels
    count as escape, never as safe: a chart would be all escape, not an answer)."""
    Om = np.atleast_1d(np.asarray(Omega, dtype=float))
    w = resolve_well(well)
    om_min = float(Om.min())
    h = 2.0 * math.pi / (om_min * steps_per_cycle)
    fastest = max(w.omega_max, om_min)
    x = h * fastest
    if x > STEP_LIMIT:
        need = 2.0 * math.pi * fastest / (om_min * STEP_LIMIT)
        if need > MAX_STEPS_PER_CYCLE:
            raise ValueError(
                f"steps_per_cycle: Omega = {om_min:.6g} is too small to integrate: the step limit h * {fastest:.4g} <= "
                f"{STEP_LIMIT} of the {w.name} well would need {need:.3g} steps per forcing cycle (more than "
                f"{MAX_STEPS_PER_CYCLE:.0e}); use a larger Omega")
        need = math.ceil(need)
        raise ValueError(
            f"steps_per_cycle: {steps_per_cycle} steps per forcing cycle at Omega = {om_min:.6g} give a step "
            f"h = {h:.4g}, and h * {fastest:.4g} = {x:.4g} exceeds {STEP_LIMIT} ({fastest:.4g} = the larger of Omega "
            f"and the {w.name} well's largest local frequency sqrt(max |V''|) = {w.omega_max:.4g}): the integrator "
            f"is inaccurate or unstable there; use steps_per_cycle >= {need} (or a larger Omega)")
    return steps_per_cycle


def check_damping(damping):
    """The damping beta of q'' + beta q' + V'(q) = F sin(Omega t + Psi): a finite scalar >= 0."""
    return checks.check_scalar("damping", damping, checks.check_nonnegative)


def damping_attrs(damping):
    """``{"damping": beta}`` for a damped run; nothing for the undamped equation (datasets of the
    paper's equation keep their attributes: no damping attribute means beta = 0)."""
    return {"damping": damping} if damping > 0 else {}


def integrator_text(integrator, damping):
    """The integrator of a dataset in words (its damped variant for damping > 0)."""
    return steps.DAMPED_INTEGRATORS[integrator] if damping > 0 else steps.INTEGRATORS[integrator]


def check_cycles(name, cycles):
    if isinstance(cycles, (float, np.floating)) and float(cycles).is_integer() and cycles >= 1:
        cycles = int(cycles)
    return checks.check_positive_int(name, cycles)


def thresholds(name, values, check):
    a = np.atleast_1d(check(name, values) if np.size(values) else np.asarray(values, dtype=float)).astype(float)
    if a.ndim != 1:
        raise ValueError(f"{name} must be a scalar or a 1-D sequence, got shape {a.shape}")
    return a


def displacement_pairs(q_max=(), q_bounds=()):
    """The displacement thresholds as bound pairs (lo, hi): q_max -> (-q_max, q_max), then the
    q_bounds pairs; returns (lo, hi, order, signed): `order` sorts them nested from the inside
    out (hi ascending, lo descending; stable), `signed` = some pair is not symmetric.
    ValueError naming q_max / q_bounds when two pairs are not nested (neither contains the
    other: the engine watches only the next uncrossed bound of each trajectory)."""
    qm = np.asarray(q_max, dtype=float).ravel()
    qb = np.asarray(q_bounds, dtype=float).reshape(-1, 2) if np.size(q_bounds) else np.zeros((0, 2))
    lo = np.concatenate([-qm, qb[:, 0]])
    hi = np.concatenate([qm, qb[:, 1]])
    order = np.lexsort((-lo, hi))
    if lo.size and not (np.diff(lo[order]) <= 0).all():
        name = "q_bounds" if qb.shape[0] else "q_max"
        pairs = [(float(a), float(b)) for a, b in zip(lo[order], hi[order])]
        raise ValueError(f"{name}: the displacement bounds (q_max as (-q_max, q_max) and q_bounds) must be nested, "
                         f"each pair inside the next; got {pairs}")
    return lo, hi, order, bool((lo != -hi).any())


def engine_code(well, q_max=(), q_bounds=()):
    """The compiled form the engines integrate ``well`` in: its |q|-tracking form only when every
    displacement bound is symmetric (displacement_pairs)."""
    code = resolve_well(well).compiled
    return code.signed() if displacement_pairs(q_max, q_bounds)[3] else code


def run_ensemble(q0, p0, pidx, Omega, F, Psi, *, xi_max=(), q_max=(), q_bounds=(), cycles, steps_per_cycle,
                 threads=None, stop_any=False, store=False, integrator=DEFAULT_INTEGRATOR, well=None, damping=0.0):
    """Integrate trajectories i from (q0[i], p0[i]) with Omega[pidx[i]], F[pidx[i]] in `well`.

    Returns (steps_E (N, nE), steps_Q (N, nQ), store or None): int64 first-crossing steps in the
    order of the given thresholds (-1: not within `cycles`), and period-map iterates.  The
    displacement columns are the q_max thresholds (|q| > q_max) followed by the q_bounds pairs
    (q < lo or q > hi); all of them must be nested (displacement_pairs).
    integrator: "srkn6b" (default) or "rk4" (kernels.INTEGRATORS), with ``damping`` beta > 0 of
    q'' + beta q' + V'(q) = F sin(...) their damped variants (steps.DAMPED_INTEGRATORS; 0: the
    undamped schemes, bitwise as before damping existed); well: any form
    safebasins.wells.resolve_well reads (None: the quartic), integrated in its compiled form.
    Thresholds are not checked against the well here (the public functions do that).
    """
    kernels.check_integrator(integrator)
    code = engine_code(well, q_max, q_bounds)
    q0 = np.ascontiguousarray(q0, dtype=float).ravel()
    p0 = np.ascontiguousarray(p0, dtype=float).ravel()
    pidx = np.ascontiguousarray(pidx, dtype=np.int64).ravel()
    Omega = np.atleast_1d(np.asarray(Omega, dtype=float))
    F = np.atleast_1d(np.asarray(F, dtype=float))
    xi = np.asarray(xi_max, dtype=float).ravel()
    lo, hi, oQ_sorted, _ = displacement_pairs(q_max, q_bounds)
    N = q0.size
    oE_sorted = np.argsort(xi, kind="stable")
    outE = np.full((N, xi.size), -1, dtype=np.int64)
    outQ = np.full((N, hi.size), -1, dtype=np.int64)
    st = np.full((N, cycles + 1, 2), np.nan) if store else np.empty((0, 0, 2))
    if N:
        coef = np.ascontiguousarray(kernels.lane_coefficients(Omega, steps_per_cycle, integrator, damping))
        sintab = kernels.sine_table(steps_per_cycle, Psi, integrator)
        with thread_count(threads) as nthreads:
            # one task per thread: trajectories are interleaved over tasks (i % n_tasks), so each
            # task gets a statistically equal share of long-lived ones and its lanes stay full
            n_tasks = max(1, min(math.ceil(N / LANES), nthreads))
            kernels.ensemble(q0, p0, pidx, coef, kernels.step_sizes(Omega, steps_per_cycle), np.ascontiguousarray(F), sintab,
                       np.ascontiguousarray(2.0 * xi[oE_sorted]), np.ascontiguousarray(hi[oQ_sorted]),
                       int(cycles), bool(stop_any), int(n_tasks), LANES, outE, outQ, st, bool(store),
                       scheme=kernels.scheme_of(integrator, damping),
                       well=code, thrQlo=np.ascontiguousarray(lo[oQ_sorted]))
    # back to the caller's threshold order
    steps_E = np.empty_like(outE)
    steps_E[:, oE_sorted] = outE
    steps_Q = np.empty_like(outQ)
    steps_Q[:, oQ_sorted] = outQ
    return steps_E, steps_Q, (st if store else None)


def steps_to_cycles(steps, steps_per_cycle):
    """int64 step counts (-1: none) -> float64 forcing cycles (+inf: none)."""
    out = steps.astype(float) / steps_per_cycle
    out[steps < 0] = np.inf
    return out


def resolve_backend(backend):
    """"cpu" or "cuda" for a requested backend ("auto": the GPU when numba-cuda sees one)."""
    if backend not in BACKENDS:
        raise ValueError(f"backend must be one of {BACKENDS}, got {backend!r}")
    if backend == "auto":
        return "cuda" if importlib.util.find_spec("numba_cuda") and cuda_engine().cuda_available() else "cpu"
    return backend


def cuda_engine():
    """The CUDA engine module (safebasins.numerics.cuda_engine); ImportError naming the extra to
    install when numba-cuda, the numba CUDA target it is written for, is missing."""
    if importlib.util.find_spec("numba_cuda") is None:
        raise ImportError("the CUDA backend needs numba-cuda (numba's CUDA target), which is not installed: "
                          "pip install 'safebasins[cuda]'", name="numba_cuda")
    from safebasins.numerics import cuda_engine as module

    return module


def integrate(q0, p0, pidx, Omega, F, Psi, *, backend="cpu", threads=None, **kwargs):
    """:func:`run_ensemble` on the chosen backend; returns (steps_E, steps_Q), bitwise the same
    on either (the CUDA kernels repeat the CPU lanes' operations; tests/numerics/test_cuda_simulator.py)."""
    if resolve_backend(backend) == "cuda":
        return cuda_engine().run_ensemble_cuda(q0, p0, pidx, Omega, F, Psi, **kwargs)
    steps_E, steps_Q, _ = run_ensemble(q0, p0, pidx, Omega, F, Psi, threads=threads, **kwargs)
    return steps_E, steps_Q
