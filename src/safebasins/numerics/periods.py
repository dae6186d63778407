"""The vectorised period loops of the compiled engine: steps [s0, s1) of the forcing period
for every lane of a task, with the per-lane maxima the escape detection of kernels.py reads.

Two loops, each specialised at compile time on the scheme (`rk4`) and the kernel key
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
from numba import njit, types
from numba.core import errors
from numba.extending import overload

from safebasins.numerics.steps import lane_coefs, row, step, wtuple
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


def _literal_scheme(rk4):
    """The compile-time scheme flag of an overload's argument (True: RK4)."""
    if not isinstance(rk4, types.BooleanLiteral):
        raise errors.TypingError(f"rk4 must be a compile-time constant, got {rk4}")
    return rk4.literal_value


@njit(cache=True, inline="always")
def _reset(well, n, ME, MQ, MN):
    for l in range(n):
        ME[l] = -np.inf
        MQ[l] = -np.inf
    if not abs_tracking(well):
        for l in range(n):
            MN[l] = -np.inf


@njit(cache=True, inline="always")
def _shared_fused(rk4, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1):
    """|q| tracking (the quartic): steps [s0, s1) of the forcing period for lanes [0, 4M), all sharing one
    parameter set; ME, MQ = max 2*H0 and max |q| over these steps.

    The lane loop (j) vectorises; its body advances 4 independent lanes j, M+j, 2M+j, 3M+j
    so that 4 dependency chains are in flight (the step is latency bound otherwise)."""
    c1 = c[0]; c2 = c[1]; c3 = c[2]; c4 = c[3]; c5 = c[4]; c6 = c[5]; c7 = c[6]
    w = wtuple(wpar)
    _reset(well, 4 * M, ME, MQ, MN)
    for s in range(s0, s1):
        f1, f2, f3, f4, f5, f6, f7 = row(FS, s, rk4)
        for j in range(M):
            l0 = 0 * M + j
            l1 = 1 * M + j
            l2 = 2 * M + j
            l3 = 3 * M + j
            q0, p0 = step(rk4, well, w, Q[l0], P[l0], c1, c2, c3, c4, c5, c6, c7, f1, f2, f3, f4, f5, f6, f7)
            q1, p1 = step(rk4, well, w, Q[l1], P[l1], c1, c2, c3, c4, c5, c6, c7, f1, f2, f3, f4, f5, f6, f7)
            q2, p2 = step(rk4, well, w, Q[l2], P[l2], c1, c2, c3, c4, c5, c6, c7, f1, f2, f3, f4, f5, f6, f7)
            q3, p3 = step(rk4, well, w, Q[l3], P[l3], c1, c2, c3, c4, c5, c6, c7, f1, f2, f3, f4, f5, f6, f7)
            _keep_abs(well, w, l0, q0, p0, Q, P, ME, MQ, MN)
            _keep_abs(well, w, l1, q1, p1, Q, P, ME, MQ, MN)
            _keep_abs(well, w, l2, q2, p2, Q, P, ME, MQ, MN)
            _keep_abs(well, w, l3, q3, p3, Q, P, ME, MQ, MN)


@njit(cache=True, inline="always")
def _shared_split(rk4, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1):
    """Signed tracking: as _shared_fused, with the maxima of 2*H0, q and -q updated in a
    second lane loop per step.  (Fused, the 4 chains x 5 arrays need 190 runtime alias checks,
    over LLVM's limit of 128 -vectorize-memory-check-threshold, and the loop stays scalar: 7x
    slower.  Split, the step loop has 2 arrays x 4 chains and the maxima loop 5 arrays x 1
    chain; the energy is recomputed from the stored state: the same numbers.)"""
    c1 = c[0]; c2 = c[1]; c3 = c[2]; c4 = c[3]; c5 = c[4]; c6 = c[5]; c7 = c[6]
    w = wtuple(wpar)
    n = 4 * M
    _reset(well, n, ME, MQ, MN)
    for s in range(s0, s1):
        f1, f2, f3, f4, f5, f6, f7 = row(FS, s, rk4)
        for j in range(M):
            l0 = 0 * M + j
            l1 = 1 * M + j
            l2 = 2 * M + j
            l3 = 3 * M + j
            q0, p0 = step(rk4, well, w, Q[l0], P[l0], c1, c2, c3, c4, c5, c6, c7, f1, f2, f3, f4, f5, f6, f7)
            q1, p1 = step(rk4, well, w, Q[l1], P[l1], c1, c2, c3, c4, c5, c6, c7, f1, f2, f3, f4, f5, f6, f7)
            q2, p2 = step(rk4, well, w, Q[l2], P[l2], c1, c2, c3, c4, c5, c6, c7, f1, f2, f3, f4, f5, f6, f7)
            q3, p3 = step(rk4, well, w, Q[l3], P[l3], c1, c2, c3, c4, c5, c6, c7, f1, f2, f3, f4, f5, f6, f7)
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


def _period_shared_body(rk4, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1):
    """Steps [s0, s1) of the forcing period for lanes [0, 4M), all sharing one parameter set;
    ME, MQ (, MN) = the maxima over these steps (see _keep).  rk4 and well are compile-time
    constants at every call site (inline body): one specialised loop per scheme and well."""
    raise NotImplementedError("compiled code (numba)")


@overload(_period_shared_body)
def _ol_period_shared_body(rk4, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1):
    RK4, code = _literal_scheme(rk4), _literal_code(well)
    WELL = code.key
    if code.abs_tracking:
        def impl(rk4, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1):
            _shared_fused(RK4, WELL, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1)
    else:
        def impl(rk4, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1):
            _shared_split(RK4, WELL, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1)
    return impl


@njit(cache=True)
def _period_shared(well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1):
    """_period_shared_body for the scheme of the table FS (width 3: RK4, 7: SRKN6b)."""
    if FS.shape[1] == 3:
        _period_shared_body(True, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1)
    else:
        _period_shared_body(False, well, wpar, M, Q, P, ME, MQ, MN, c, FS, s0, s1)


@njit(cache=True, inline="always")
def _lanes_abs(rk4, well, wpar, M, Q, P, ME, MQ, MN, HL, FL, sintab, s0, s1):
    n = 4 * M
    w = wtuple(wpar)
    _reset(well, n, ME, MQ, MN)
    for s in range(s0, s1):
        t1, t2, t3, t4, t5, t6, t7 = row(sintab, s, rk4)
        for l in range(n):
            F = FL[l]
            c1, c2, c3, c4, c5, c6, c7 = lane_coefs(rk4, HL[l])
            q, p = step(rk4, well, w, Q[l], P[l], c1, c2, c3, c4, c5, c6, c7,
                        F * t1, F * t2, F * t3, F * t4, F * t5, F * t6, F * t7)
            _keep_abs(well, w, l, q, p, Q, P, ME, MQ, MN)


@njit(cache=True, inline="always")
def _lanes_signed(rk4, well, wpar, M, Q, P, ME, MQ, MN, HL, FL, sintab, s0, s1):
    n = 4 * M
    w = wtuple(wpar)
    _reset(well, n, ME, MQ, MN)
    for s in range(s0, s1):
        t1, t2, t3, t4, t5, t6, t7 = row(sintab, s, rk4)
        for l in range(n):
            F = FL[l]
            c1, c2, c3, c4, c5, c6, c7 = lane_coefs(rk4, HL[l])
            q, p = step(rk4, well, w, Q[l], P[l], c1, c2, c3, c4, c5, c6, c7,
                        F * t1, F * t2, F * t3, F * t4, F * t5, F * t6, F * t7)
            _keep_signed(well, w, l, q, p, Q, P, ME, MQ, MN)


def _period_lanes_body(rk4, well, wpar, M, Q, P, ME, MQ, MN, HL, FL, sintab, s0, s1):
    """As _period_shared for lanes [0, 4M) with per-lane parameters: step h = HL[l] and
    amplitude F = FL[l].  The coefficients h*c_k and forcing values F*sin_k are formed in the
    loop: the same IEEE products as the precomputed ones of the shared path, so both paths
    give bitwise identical trajectories.  (One chain per iteration: with 4 chains and six
    arrays LLVM's runtime alias checks exceed its budget and the loop stays scalar.)"""
    raise NotImplementedError("compiled code (numba)")


@overload(_period_lanes_body)
def _ol_period_lanes_body(rk4, well, wpar, M, Q, P, ME, MQ, MN, HL, FL, sintab, s0, s1):
    RK4, code = _literal_scheme(rk4), _literal_code(well)
    WELL = code.key
    if code.abs_tracking:
        def impl(rk4, well, wpar, M, Q, P, ME, MQ, MN, HL, FL, sintab, s0, s1):
            _lanes_abs(RK4, WELL, wpar, M, Q, P, ME, MQ, MN, HL, FL, sintab, s0, s1)
    else:
        def impl(rk4, well, wpar, M, Q, P, ME, MQ, MN, HL, FL, sintab, s0, s1):
            _lanes_signed(RK4, WELL, wpar, M, Q, P, ME, MQ, MN, HL, FL, sintab, s0, s1)
    return impl


@njit(cache=True)
def _period_lanes(well, wpar, M, Q, P, ME, MQ, MN, HL, FL, sintab, s0, s1):
    if sintab.shape[1] == 3:
        _period_lanes_body(True, well, wpar, M, Q, P, ME, MQ, MN, HL, FL, sintab, s0, s1)
    else:
        _period_lanes_body(False, well, wpar, M, Q, P, ME, MQ, MN, HL, FL, sintab, s0, s1)
