"""The vectorised period loops of the compiled engine: steps [s0, s1) of the forcing period
for every lane of a task, with the per-lane maxima the escape detection of kernels.py reads.

Two loops, each specialised at compile time on the scheme flag (steps.SRKN6B, RK4 and their
damped variants) and the kernel key
(steps.py): _period_shared (every lane with the same Omega and F: 4 dependency chains per
iteration) and _period_lanes (per-lane Omega and F: one chain).  The body of a key is picked at
typing time (@overload on the literal kernel key): a code with |q| tracking (the quartic's
closed form, wellcode.WellCode.abs_tracking) tracks max 2 H0 and max |q| (_shared_fused,
_lanes_abs); every other code tracks max 2 H0, max q and max -q (_shared_split, _lanes_signed).

The kernel keys hash this file's source (wellcode.engine_fingerprint): an edit here never
reuses a kernel cached before it.
"""
from __future__ import annotations

import numpy as np
from numba import njit
from numba.extending import overload

from safebasins.numerics.steps import RK4_DAMPED, SRKN6B_DAMPED, _literal_scheme, lane_coefs, row, step, wtuple
from safebasins.numerics.wellcode import _literal_code, abs_tracking, well_energy2


@njit(cache=True, inline="always")
def _keep_abs(well, w, l, q, p, Q, P, ME, MQ, MN):
    """Store lane l's new state and update its maxima of 2*H0 and |q| (branch free; NaN wins, so that
    a NaN or inf state is detected as beyond every threshold at the period boundary)."""
    Q[l] = q
    P[l] = p
    e = well_energy2(well, w, q, p)
    x = abs(q)
    m = ME[l]
    ME[l] = e if not e <= m else m       # a NaN state propagates: it counts as a crossing
    m = MQ[l]
    MQ[l] = x if not x <= m else m


@njit(cache=True, inline="always")
def _keep_signed(well, w, l, q, p, Q, P, ME, MQ, MN):
    """Store lane l's new state and update its maxima of 2*H0, q and -q (branch free)."""
    Q[l] = q
    P[l] = p
    _maxima_signed(well, w, l, q, p, ME, MQ, MN)


@njit(cache=True, inline="always")
def _maxima_signed(well, w, l, q, p, ME, MQ, MN):
    e = well_energy2(well, w, q, p)
    m = ME[l]
    ME[l] = e if not e <= m else m       # a NaN state propagates: it counts as a crossing
    m = MQ[l]
    MQ[l] = q if not q <= m else m
    y = -q
    m = MN[l]
    MN[l] = y if not y <= m else m


@njit(cache=True, inline="always")
def _reset(well, n, ME, MQ, MN):
    for l in range(n):
        ME[l] = -np.inf
        MQ[l] = -np.inf
    if not abs_tracking(well):
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


@njit(cache=True, inline="always")
def _shared_fused(scheme, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1):
    """|q| tracking (the quartic): steps [s0, s1) of the forcing period for lanes [0, 4M), all
    sharing one parameter set; ME, MQ = max 2*H0 and max |q| over these steps.

    The lane loop (j) vectorises; its body advances 4 independent lanes j, M+j, 2M+j, 3M+j
    so that 4 dependency chains are in flight (the step is latency bound otherwise)."""
    c1, c2, c3, c4, c5, c6, c7, c8, c9, c10 = _coefs(c)
    w = wtuple(wpar)
    _reset(well, 4 * M, ME, MQ, MN)
    for s in range(s0, s1):
        f1, f2, f3, f4, f5, f6, f7 = row(FS, s, scheme)
        for j in range(M):
            l0 = 0 * M + j
            l1 = 1 * M + j
            l2 = 2 * M + j
            l3 = 3 * M + j
            q0, p0 = step(scheme, well, w, Q[l0], P[l0], c1, c2, c3, c4, c5, c6, c7, c8, c9, c10,
                              f1, f2, f3, f4, f5, f6, f7)
            q1, p1 = step(scheme, well, w, Q[l1], P[l1], c1, c2, c3, c4, c5, c6, c7, c8, c9, c10,
                              f1, f2, f3, f4, f5, f6, f7)
            q2, p2 = step(scheme, well, w, Q[l2], P[l2], c1, c2, c3, c4, c5, c6, c7, c8, c9, c10,
                              f1, f2, f3, f4, f5, f6, f7)
            q3, p3 = step(scheme, well, w, Q[l3], P[l3], c1, c2, c3, c4, c5, c6, c7, c8, c9, c10,
                              f1, f2, f3, f4, f5, f6, f7)
            _keep_abs(well, w, l0, q0, p0, Q, P, ME, MQ, MN)
            _keep_abs(well, w, l1, q1, p1, Q, P, ME, MQ, MN)
            _keep_abs(well, w, l2, q2, p2, Q, P, ME, MQ, MN)
            _keep_abs(well, w, l3, q3, p3, Q, P, ME, MQ, MN)


@njit(cache=True, inline="always")
def _shared_split(scheme, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1):
    """Signed tracking: as _shared_fused, with the maxima of 2*H0, q and -q updated in a
    second lane loop per step.  (Fused, the 4 chains x 5 arrays need 190 runtime alias checks,
    over LLVM's limit of 128 -vectorize-memory-check-threshold, and the loop stays scalar: 7x
    slower.  Split, the step loop has 2 arrays x 4 chains and the maxima loop 5 arrays x 1
    chain; the energy is recomputed from the stored state: the same numbers.)"""
    c1, c2, c3, c4, c5, c6, c7, c8, c9, c10 = _coefs(c)
    w = wtuple(wpar)
    n = 4 * M
    _reset(well, n, ME, MQ, MN)
    for s in range(s0, s1):
        f1, f2, f3, f4, f5, f6, f7 = row(FS, s, scheme)
        for j in range(M):
            l0 = 0 * M + j
            l1 = 1 * M + j
            l2 = 2 * M + j
            l3 = 3 * M + j
            q0, p0 = step(scheme, well, w, Q[l0], P[l0], c1, c2, c3, c4, c5, c6, c7, c8, c9, c10,
                              f1, f2, f3, f4, f5, f6, f7)
            q1, p1 = step(scheme, well, w, Q[l1], P[l1], c1, c2, c3, c4, c5, c6, c7, c8, c9, c10,
                              f1, f2, f3, f4, f5, f6, f7)
            q2, p2 = step(scheme, well, w, Q[l2], P[l2], c1, c2, c3, c4, c5, c6, c7, c8, c9, c10,
                              f1, f2, f3, f4, f5, f6, f7)
            q3, p3 = step(scheme, well, w, Q[l3], P[l3], c1, c2, c3, c4, c5, c6, c7, c8, c9, c10,
                              f1, f2, f3, f4, f5, f6, f7)
            Q[l0] = q0
            P[l0] = p0
            Q[l1] = q1
            P[l1] = p1
            Q[l2] = q2
            P[l2] = p2
            Q[l3] = q3
            P[l3] = p3
        for l in range(n):
            _maxima_signed(well, w, l, Q[l], P[l], ME, MQ, MN)


def _period_shared_body(scheme, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1):
    """Steps [s0, s1) of the forcing period for lanes [0, 4M), all sharing one parameter set;
    ME, MQ (, MN) = the maxima over these steps (see _keep).  scheme and well are compile-time
    constants at every call site (inline body): one specialised loop per scheme and well."""
    raise NotImplementedError("compiled code (numba)")


@overload(_period_shared_body)
def _ol_period_shared_body(scheme, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1):
    SCHEME, code = _literal_scheme(scheme), _literal_code(well)
    WELL = code.key
    if code.abs_tracking:
        def impl(scheme, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1):
            _shared_fused(SCHEME, WELL, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1)
    else:
        def impl(scheme, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1):
            _shared_split(SCHEME, WELL, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1)
    return impl


@njit(cache=True)
def _period_shared(scheme, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1):
    """_period_shared_body of the scheme and well (compile-time constants: one cached loop each)."""
    _period_shared_body(scheme, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1)


@njit(cache=True, inline="always")
def _lanes_abs(scheme, well, wpar, M, Q, P, ME, MQ, MN, HL, CL, FL, sintab, s0, s1):
    n = 4 * M
    w = wtuple(wpar)
    _reset(well, n, ME, MQ, MN)
    for s in range(s0, s1):
        t1, t2, t3, t4, t5, t6, t7 = row(sintab, s, scheme)
        for l in range(n):
            F = FL[l]
            c1, c2, c3, c4, c5, c6, c7, c8, c9, c10 = _lane(scheme, l, HL, CL)
            q, p = step(scheme, well, w, Q[l], P[l], c1, c2, c3, c4, c5, c6, c7, c8, c9, c10,
                        F * t1, F * t2, F * t3, F * t4, F * t5, F * t6, F * t7)
            _keep_abs(well, w, l, q, p, Q, P, ME, MQ, MN)


@njit(cache=True, inline="always")
def _lanes_signed(scheme, well, wpar, M, Q, P, ME, MQ, MN, HL, CL, FL, sintab, s0, s1):
    n = 4 * M
    w = wtuple(wpar)
    _reset(well, n, ME, MQ, MN)
    for s in range(s0, s1):
        t1, t2, t3, t4, t5, t6, t7 = row(sintab, s, scheme)
        for l in range(n):
            F = FL[l]
            c1, c2, c3, c4, c5, c6, c7, c8, c9, c10 = _lane(scheme, l, HL, CL)
            q, p = step(scheme, well, w, Q[l], P[l], c1, c2, c3, c4, c5, c6, c7, c8, c9, c10,
                        F * t1, F * t2, F * t3, F * t4, F * t5, F * t6, F * t7)
            _keep_signed(well, w, l, q, p, Q, P, ME, MQ, MN)


def _period_lanes_body(scheme, well, wpar, M, Q, P, ME, MQ, MN, HL, CL, FL, sintab, s0, s1):
    """As _period_shared for lanes [0, 4M) with per-lane parameters: step h = HL[l] (damped
    schemes: the coefficient column CL[:, l]) and amplitude F = FL[l].  The undamped
    coefficients h*c_k and the forcing values F*sin_k are formed in the loop: the same IEEE
    products as the precomputed ones of the shared path, so both paths give bitwise identical
    trajectories.  (One chain per iteration: with 4 chains and six arrays LLVM's runtime alias
    checks exceed its budget and the loop stays scalar.)"""
    raise NotImplementedError("compiled code (numba)")


@overload(_period_lanes_body)
def _ol_period_lanes_body(scheme, well, wpar, M, Q, P, ME, MQ, MN, HL, CL, FL, sintab, s0, s1):
    SCHEME, code = _literal_scheme(scheme), _literal_code(well)
    WELL = code.key
    if code.abs_tracking:
        def impl(scheme, well, wpar, M, Q, P, ME, MQ, MN, HL, CL, FL, sintab, s0, s1):
            _lanes_abs(SCHEME, WELL, wpar, M, Q, P, ME, MQ, MN, HL, CL, FL, sintab, s0, s1)
    else:
        def impl(scheme, well, wpar, M, Q, P, ME, MQ, MN, HL, CL, FL, sintab, s0, s1):
            _lanes_signed(SCHEME, WELL, wpar, M, Q, P, ME, MQ, MN, HL, CL, FL, sintab, s0, s1)
    return impl


@njit(cache=True)
def _period_lanes(scheme, well, wpar, M, Q, P, ME, MQ, MN, HL, CL, FL, sintab, s0, s1):
    _period_lanes_body(scheme, well, wpar, M, Q, P, ME, MQ, MN, HL, CL, FL, sintab, s0, s1)
