"""The vectorised period loops of the compiled engine: steps [s0, s1) of the forcing period
for every lane of a task, with the per-lane maxima the escape detection of kernels.py reads.

Two loops, each specialised at compile time on the scheme flag (steps.SRKN6B, RK4 and their
damped variants) and the kernel key (steps.py): _period_shared_body (every lane with the same
Omega and F: 4 dependency chains per iteration) and _period_lanes_body (per-lane Omega and F:
one chain), numba overloads whose body is picked at typing time on the literal kernel key: a
code with |q| tracking (the quartic's closed form, wellcode.WellCode.abs_tracking) tracks
max 2 H0 and max |q|; every other code tracks max 2 H0, max q and max -q.

The kernel keys hash this file's source (wellcode.engine_fingerprint): an edit here never
reuses a kernel cached before it.
"""
from __future__ import annotations

import numpy as np
from numba import njit
from numba.extending import overload

from safebasins.numerics.steps import RK4_DAMPED, SRKN6B_DAMPED, _literal_scheme, cpu_steps, lane_coefs, row, wtuple
from safebasins.numerics.wellcode import _literal_code, cpu_functions


@njit(cache=True, inline="always")
def _keep_abs(l, q, p, e, Q, P, ME, MQ):
    """Store lane l's new state and update its maxima of 2*H0 (e) and |q| (branch free; NaN wins,
    so that a NaN or inf state is detected as beyond every threshold at the period boundary)."""
    Q[l] = q
    P[l] = p
    x = abs(q)
    m = ME[l]
    ME[l] = e if not e <= m else m       # a NaN state propagates: it counts as a crossing
    m = MQ[l]
    MQ[l] = x if not x <= m else m


@njit(cache=True, inline="always")
def _maxima_signed(l, q, e, ME, MQ, MN):
    """Update lane l's maxima of 2*H0 (e), q and -q (branch free; NaN wins)."""
    m = ME[l]
    ME[l] = e if not e <= m else m       # a NaN state propagates: it counts as a crossing
    m = MQ[l]
    MQ[l] = q if not q <= m else m
    y = -q
    m = MN[l]
    MN[l] = y if not y <= m else m


@njit(cache=True, inline="always")
def _reset(n, ME, MQ, MN, signed):
    for l in range(n):
        ME[l] = -np.inf
        MQ[l] = -np.inf
    if signed:
        for l in range(n):
            MN[l] = -np.inf


@njit(cache=True, inline="always")
def _coefs(c):
    """The 10 step coefficients of a parameter set (steps.N_COEF) as scalars."""
    return c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8], c[9]


@njit(cache=True, inline="always")
def _lane(scheme, l, HL, CL):
    """Lane l's step coefficients: formed from its step h = HL[l] for the undamped schemes (the
    IEEE products lane_coefficients precomputes), read from its column of CL (lane_coefficients
    of its parameter set, copied at load) for the damped ones."""
    if scheme == SRKN6B_DAMPED or scheme == RK4_DAMPED:
        return (CL[0, l], CL[1, l], CL[2, l], CL[3, l], CL[4, l], CL[5, l], CL[6, l], CL[7, l], CL[8, l],
                CL[9, l])
    return lane_coefs(scheme, HL[l])


def _arithmetic(scheme, well):
    """(scheme flag, abs_tracking, STEP, ENERGY2) of the literal scheme and kernel key: the code's
    step and energy compiled for the CPU lanes (njit inline="always").  The loop bodies below call
    them directly (inlined into the untyped IR, typed once with the body), not through the
    generic inline overloads steps.step / wellcode.well_energy2, which numba types anew at every
    call site and type-inference round (~30 ms each, ~0.8 s of a kernel's first compile)."""
    SCHEME, code = _literal_scheme(scheme), _literal_code(well)
    return SCHEME, code.abs_tracking, cpu_steps(code.key)[SCHEME], cpu_functions(code.key)[1]


def _period_shared_body(scheme, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1):
    """Steps [s0, s1) of the forcing period for lanes [0, 4M), all sharing one parameter set
    (coefficients c, scaled forcing table FS); ME, MQ (, MN) = the maxima over these steps.
    scheme and well are compile-time constants: one specialised loop per scheme and well.

    The lane loop (j) vectorises; its body advances 4 independent lanes j, M+j, 2M+j, 3M+j
    so that 4 dependency chains are in flight (the step is latency bound otherwise).
    |q| tracking (the quartic): max 2*H0 and max |q| kept in the step loop.  Signed tracking:
    max 2*H0, q and -q updated in a second lane loop per step.  (Fused, the 4 chains x 5 arrays
    need 190 runtime alias checks, over LLVM's limit of 128 -vectorize-memory-check-threshold,
    and the loop stays scalar: 7x slower.  Split, the step loop has 2 arrays x 4 chains and the
    maxima loop 5 arrays x 1 chain; the energy is recomputed from the stored state: the same
    numbers.)"""
    raise NotImplementedError("compiled code (numba)")


@overload(_period_shared_body)
def _ol_period_shared_body(scheme, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1):
    SCHEME, ABS, STEP, ENERGY2 = _arithmetic(scheme, well)
    if ABS:
        def impl(scheme, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1):
            c1, c2, c3, c4, c5, c6, c7, c8, c9, c10 = _coefs(c)
            w = wtuple(wpar)
            _reset(4 * M, ME, MQ, MN, False)
            for s in range(s0, s1):
                f1, f2, f3, f4, f5, f6, f7 = row(FS, s, SCHEME)
                for j in range(M):
                    l0 = 0 * M + j
                    l1 = 1 * M + j
                    l2 = 2 * M + j
                    l3 = 3 * M + j
                    q0, p0 = STEP(w, Q[l0], P[l0], c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, f1, f2, f3, f4, f5, f6, f7)
                    q1, p1 = STEP(w, Q[l1], P[l1], c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, f1, f2, f3, f4, f5, f6, f7)
                    q2, p2 = STEP(w, Q[l2], P[l2], c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, f1, f2, f3, f4, f5, f6, f7)
                    q3, p3 = STEP(w, Q[l3], P[l3], c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, f1, f2, f3, f4, f5, f6, f7)
                    _keep_abs(l0, q0, p0, ENERGY2(w, q0, p0), Q, P, ME, MQ)
                    _keep_abs(l1, q1, p1, ENERGY2(w, q1, p1), Q, P, ME, MQ)
                    _keep_abs(l2, q2, p2, ENERGY2(w, q2, p2), Q, P, ME, MQ)
                    _keep_abs(l3, q3, p3, ENERGY2(w, q3, p3), Q, P, ME, MQ)
    else:
        def impl(scheme, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1):
            c1, c2, c3, c4, c5, c6, c7, c8, c9, c10 = _coefs(c)
            w = wtuple(wpar)
            n = 4 * M
            _reset(n, ME, MQ, MN, True)
            for s in range(s0, s1):
                f1, f2, f3, f4, f5, f6, f7 = row(FS, s, SCHEME)
                for j in range(M):
                    l0 = 0 * M + j
                    l1 = 1 * M + j
                    l2 = 2 * M + j
                    l3 = 3 * M + j
                    q0, p0 = STEP(w, Q[l0], P[l0], c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, f1, f2, f3, f4, f5, f6, f7)
                    q1, p1 = STEP(w, Q[l1], P[l1], c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, f1, f2, f3, f4, f5, f6, f7)
                    q2, p2 = STEP(w, Q[l2], P[l2], c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, f1, f2, f3, f4, f5, f6, f7)
                    q3, p3 = STEP(w, Q[l3], P[l3], c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, f1, f2, f3, f4, f5, f6, f7)
                    Q[l0] = q0
                    P[l0] = p0
                    Q[l1] = q1
                    P[l1] = p1
                    Q[l2] = q2
                    P[l2] = p2
                    Q[l3] = q3
                    P[l3] = p3
                for l in range(n):
                    q = Q[l]
                    _maxima_signed(l, q, ENERGY2(w, q, P[l]), ME, MQ, MN)
    return impl


def _period_lanes_body(scheme, well, wpar, M, Q, P, ME, MQ, MN, HL, CL, FL, sintab, s0, s1):
    """As _period_shared_body for lanes [0, 4M) with per-lane parameters: step h = HL[l] (damped
    schemes: the coefficient column CL[:, l]) and amplitude F = FL[l].  The undamped
    coefficients h*c_k and the forcing values F*sin_k are formed in the loop: the same IEEE
    products as the precomputed ones of the shared path, so both paths give bitwise identical
    trajectories.  (One chain per iteration: with 4 chains and six arrays LLVM's runtime alias
    checks exceed its budget and the loop stays scalar.)"""
    raise NotImplementedError("compiled code (numba)")


@overload(_period_lanes_body)
def _ol_period_lanes_body(scheme, well, wpar, M, Q, P, ME, MQ, MN, HL, CL, FL, sintab, s0, s1):
    SCHEME, ABS, STEP, ENERGY2 = _arithmetic(scheme, well)
    SIGNED = not ABS

    def impl(scheme, well, wpar, M, Q, P, ME, MQ, MN, HL, CL, FL, sintab, s0, s1):
        n = 4 * M
        w = wtuple(wpar)
        _reset(n, ME, MQ, MN, SIGNED)
        for s in range(s0, s1):
            t1, t2, t3, t4, t5, t6, t7 = row(sintab, s, SCHEME)
            for l in range(n):
                F = FL[l]
                c1, c2, c3, c4, c5, c6, c7, c8, c9, c10 = _lane(SCHEME, l, HL, CL)
                q, p = STEP(w, Q[l], P[l], c1, c2, c3, c4, c5, c6, c7, c8, c9, c10,
                            F * t1, F * t2, F * t3, F * t4, F * t5, F * t6, F * t7)
                e = ENERGY2(w, q, p)
                if SIGNED:
                    Q[l] = q
                    P[l] = p
                    _maxima_signed(l, q, e, ME, MQ, MN)
                else:
                    _keep_abs(l, q, p, e, Q, P, ME, MQ)
    return impl
