"""The vectorised period loops of the compiled engine: steps [s0, s1) of the forcing period
for every lane of a task, with the per-lane maxima the escape detection of kernels.py reads.

Two loops, each specialised at compile time on the scheme key (scheme_code.SchemeCode.key: a
scheme and damped or not) and the well's kernel key (steps.py): _period_shared_body (every lane with the same
Omega and F: 4 dependency chains per iteration) and _period_lanes_body (per-lane Omega and F:
one chain), numba overloads whose body is picked at typing time on the literal kernel key: a
code with |q| tracking (the quartic's closed form, wells.compiled.WellCode.abs_tracking) tracks
max 2 H0 and max |q|; every other code tracks max 2 H0, max q and max -q.

A well with a split force (wells.compiled.WellCode.split) runs the scheme's split step
(scheme_code: V'(q) carried from a step's last kick to the next step's first, V(q) of the energy
test from the last kick's call): the lanes' V'(q) in the work row D, formed from Q when a loop
starts (a pure function of q: the same bits as the step's own call), the energy kept in the step
loop.  The same numbers as the plain step, fewer evaluations of the well.

The kernel keys hash this file's source (scheme_code.engine_fingerprint): an edit here never
reuses a kernel cached before it.
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numba import types
from numba.extending import overload

from safebasins.core.numba_target import JIT_OPTIONS, package_jit
from safebasins.numerics.steps import (ENERGY2_FROM, Floats, Int, Lane, SplitStep, Step, cpu_helpers, cpu_lane,
                                      cpu_split_step, cpu_step, literal_scheme, wtuple)
from safebasins.wells.compiled import Coefs, literal_code, cpu_functions, cpu_split

#: ``energy2(w, q, p)``: 2 H0 of a well (w: its coefficients)
Energy2 = Callable[[Coefs, float, float], float]


@package_jit(cache=True, inline="always")
def _keep_abs(l: Int, q: float, p: float, e: float, Q: Floats, P: Floats, ME: Floats, MQ: Floats) -> None:
    """Store lane l's new state and update its maxima of 2*H0 (e) and |q| (branch free; NaN wins,
    so that a NaN or inf state is detected as beyond every threshold at the period boundary)."""
    Q[l] = q
    P[l] = p
    x = abs(q)
    m = ME[l]
    ME[l] = e if not e <= m else m       # a NaN state propagates: it counts as a crossing
    m = MQ[l]
    MQ[l] = x if not x <= m else m


@package_jit(cache=True, inline="always")
def _maximum(l: Int, x: float, MX: Floats) -> None:
    """MX[l] = max(MX[l], x), branch free; NaN wins: a NaN state propagates, it counts as a crossing."""
    m = MX[l]
    MX[l] = x if not x <= m else m


@package_jit(cache=True, inline="always")
def _maxima_signed(l: Int, q: float, e: float, ME: Floats, MQ: Floats, MN: Floats) -> None:
    """Update lane l's maxima of 2*H0 (e), q and -q (branch free; NaN wins)."""
    _maximum(l, e, ME)
    _maximum(l, q, MQ)
    _maximum(l, -q, MN)


@package_jit(cache=True, inline="always")
def _reset(n: Int, ME: Floats, MQ: Floats, MN: Floats, signed: bool) -> None:
    for l in range(n):
        ME[l] = -np.inf
        MQ[l] = -np.inf
    if signed:
        for l in range(n):
            MN[l] = -np.inf


def _arithmetic(scheme: types.Type,
                well: types.Type) -> tuple[dict[str, Callable[..., Any]], bool, Step, Energy2, Lane]:
    """(helpers, abs_tracking, STEP, ENERGY2, LANE) of the literal scheme and kernel key: the
    scheme's tuple helpers, the code's step and energy compiled for the CPU lanes
    (wells.compiled.cpu_jit: compiled once, inlined by LLVM) and the lane's coefficients
    (``LANE(l, HL, CL)``: formed from its step h = HL[l] for an undamped scheme, the IEEE
    products lane_coefficients precomputes; read from its column of CL, copied at load, for a
    damped one).  The loop bodies below call them directly, not through the generic overloads
    of steps.py / wells/compiled.py (one wrapper fewer to type and compile)."""
    sc, code = literal_scheme(scheme), literal_code(well)
    return (cpu_helpers(sc.key), code.abs_tracking, cpu_step(sc.key, code.key), cpu_functions(code.key)[1],
            cpu_lane(sc.key))


def _split(scheme: types.Type, well: types.Type) -> tuple[SplitStep, Callable[[Coefs, float], float]] | None:
    """(SPLIT_STEP, GRADIENT) of a code with a split force (the loops' split variants), None
    without one or for a |q|-tracking code (the quartic's closed form has none)."""
    sc, code = literal_scheme(scheme), literal_code(well)
    split = cpu_split_step(sc.key, code.key)
    if split is None or code.abs_tracking:
        return None
    gradient = cpu_split(code.key)
    assert gradient is not None
    return split, gradient[0]


def _period_shared_body(scheme: int, well: int, wpar: Floats, M: Int, Q: Floats, P: Floats, D: Floats, ME: Floats,
                        MQ: Floats, MN: Floats, c: Floats, FS: Floats, s0: Int, s1: Int) -> None:
    """Steps [s0, s1) of the forcing period for lanes [0, 4M), all sharing one parameter set
    (coefficients c, scaled forcing table FS); ME, MQ (, MN) = the maxima over these steps.
    scheme and well are compile-time constants: one specialised loop per scheme and well.

    The lane loop (j) vectorises; its body advances 4 independent lanes j, M+j, 2M+j, 3M+j
    so that 4 dependency chains are in flight (the step is latency bound otherwise); the
    vectoriser also interleaves two vector bodies instruction by instruction
    (core.numba_target.INTERLEAVE), which a well with elementary functions needs: its chains are
    too long for the CPU to overlap them as written.
    |q| tracking (the quartic): max 2*H0 and max |q| kept in the step loop.  Signed tracking:
    max 2*H0, q and -q updated in a second lane loop per step.  (Fused, the 4 chains x 5 arrays
    need 190 runtime alias checks, over LLVM's limit of 128 -vectorize-memory-check-threshold,
    and the loop stays scalar: 7x slower.  Split, the step loop has 2 arrays x 4 chains and the
    maxima loop 5 arrays x 1 chain; the energy is recomputed from the stored state: the same
    numbers.)  D: the lanes' V'(q) (a split code, module docstring; else unused); a split code
    keeps the energy's maximum in the step loop (3 arrays x 4 chains there), q's in the second."""
    raise NotImplementedError("compiled code (numba)")


# Any on an overload's typing function and its implementation alike (see steps._ol_step)
@overload(_period_shared_body, jit_options=JIT_OPTIONS)
def _ol_period_shared_body(scheme: Any, well: Any, wpar: Any, M: Any, Q: Any, P: Any, D: Any, ME: Any, MQ: Any,
                           MN: Any, c: Any, FS: Any, s0: Any, s1: Any) -> Callable[..., None]:
    H, ABS, STEP, ENERGY2, _ = _arithmetic(scheme, well)
    COEFS, ROW = H["coefs"], H["row"]
    split = _split(scheme, well)
    if split is not None:
        SPLIT, GRADIENT = split

        def impl(scheme: Any, well: Any, wpar: Any, M: Any, Q: Any, P: Any, D: Any, ME: Any, MQ: Any, MN: Any,
                 c: Any, FS: Any, s0: Any, s1: Any) -> None:
            cc = COEFS(c)
            w = wtuple(wpar)
            n = 4 * M
            _reset(n, ME, MQ, MN, True)
            for l in range(n):
                D[l] = GRADIENT(w, Q[l])            # the split step's carried V'(q)
            for s in range(s0, s1):
                f = ROW(FS, s)
                for j in range(M):
                    l0 = 0 * M + j
                    l1 = 1 * M + j
                    l2 = 2 * M + j
                    l3 = 3 * M + j
                    q0, p0, d0, v0 = SPLIT(w, Q[l0], P[l0], cc, f, D[l0])
                    q1, p1, d1, v1 = SPLIT(w, Q[l1], P[l1], cc, f, D[l1])
                    q2, p2, d2, v2 = SPLIT(w, Q[l2], P[l2], cc, f, D[l2])
                    q3, p3, d3, v3 = SPLIT(w, Q[l3], P[l3], cc, f, D[l3])
                    Q[l0] = q0
                    P[l0] = p0
                    D[l0] = d0
                    Q[l1] = q1
                    P[l1] = p1
                    D[l1] = d1
                    Q[l2] = q2
                    P[l2] = p2
                    D[l2] = d2
                    Q[l3] = q3
                    P[l3] = p3
                    D[l3] = d3
                    _maximum(l0, ENERGY2_FROM(w, v0, p0), ME)
                    _maximum(l1, ENERGY2_FROM(w, v1, p1), ME)
                    _maximum(l2, ENERGY2_FROM(w, v2, p2), ME)
                    _maximum(l3, ENERGY2_FROM(w, v3, p3), ME)
                for l in range(n):
                    q = Q[l]
                    _maximum(l, q, MQ)
                    _maximum(l, -q, MN)
    elif ABS:
        def impl(scheme: Any, well: Any, wpar: Any, M: Any, Q: Any, P: Any, D: Any, ME: Any, MQ: Any, MN: Any,
                 c: Any, FS: Any, s0: Any, s1: Any) -> None:
            cc = COEFS(c)
            w = wtuple(wpar)
            _reset(4 * M, ME, MQ, MN, False)
            for s in range(s0, s1):
                f = ROW(FS, s)
                for j in range(M):
                    l0 = 0 * M + j
                    l1 = 1 * M + j
                    l2 = 2 * M + j
                    l3 = 3 * M + j
                    q0, p0 = STEP(w, Q[l0], P[l0], cc, f)
                    q1, p1 = STEP(w, Q[l1], P[l1], cc, f)
                    q2, p2 = STEP(w, Q[l2], P[l2], cc, f)
                    q3, p3 = STEP(w, Q[l3], P[l3], cc, f)
                    _keep_abs(l0, q0, p0, ENERGY2(w, q0, p0), Q, P, ME, MQ)
                    _keep_abs(l1, q1, p1, ENERGY2(w, q1, p1), Q, P, ME, MQ)
                    _keep_abs(l2, q2, p2, ENERGY2(w, q2, p2), Q, P, ME, MQ)
                    _keep_abs(l3, q3, p3, ENERGY2(w, q3, p3), Q, P, ME, MQ)
    else:
        def impl(scheme: Any, well: Any, wpar: Any, M: Any, Q: Any, P: Any, D: Any, ME: Any, MQ: Any, MN: Any,
                 c: Any, FS: Any, s0: Any, s1: Any) -> None:
            cc = COEFS(c)
            w = wtuple(wpar)
            n = 4 * M
            _reset(n, ME, MQ, MN, True)
            for s in range(s0, s1):
                f = ROW(FS, s)
                for j in range(M):
                    l0 = 0 * M + j
                    l1 = 1 * M + j
                    l2 = 2 * M + j
                    l3 = 3 * M + j
                    q0, p0 = STEP(w, Q[l0], P[l0], cc, f)
                    q1, p1 = STEP(w, Q[l1], P[l1], cc, f)
                    q2, p2 = STEP(w, Q[l2], P[l2], cc, f)
                    q3, p3 = STEP(w, Q[l3], P[l3], cc, f)
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


def _period_lanes_body(scheme: int, well: int, wpar: Floats, M: Int, Q: Floats, P: Floats, D: Floats, ME: Floats,
                       MQ: Floats, MN: Floats, HL: Floats, CL: Floats, FL: Floats, sintab: Floats, s0: Int,
                       s1: Int) -> None:
    """As _period_shared_body for lanes [0, 4M) with per-lane parameters: step h = HL[l] (damped
    schemes: the coefficient column CL[:, l]) and amplitude F = FL[l].  The undamped
    coefficients h*c_k and the forcing values F*sin_k are formed in the loop: the same IEEE
    products as the precomputed ones of the shared path, so both paths give bitwise identical
    trajectories.  (One chain per iteration: with 4 chains and six arrays LLVM's runtime alias
    checks exceed its budget and the loop stays scalar.)"""
    raise NotImplementedError("compiled code (numba)")


@overload(_period_lanes_body, jit_options=JIT_OPTIONS)
def _ol_period_lanes_body(scheme: Any, well: Any, wpar: Any, M: Any, Q: Any, P: Any, D: Any, ME: Any, MQ: Any,
                          MN: Any, HL: Any, CL: Any, FL: Any, sintab: Any, s0: Any, s1: Any) -> Callable[..., None]:
    H, ABS, STEP, ENERGY2, LANE = _arithmetic(scheme, well)
    ROW, SCALED = H["row"], H["scaled"]
    SIGNED = not ABS
    split = _split(scheme, well)
    if split is not None:
        SPLIT, GRADIENT = split

        def split_impl(scheme: Any, well: Any, wpar: Any, M: Any, Q: Any, P: Any, D: Any, ME: Any, MQ: Any,
                       MN: Any, HL: Any, CL: Any, FL: Any, sintab: Any, s0: Any, s1: Any) -> None:
            n = 4 * M
            w = wtuple(wpar)
            _reset(n, ME, MQ, MN, True)
            for l in range(n):
                D[l] = GRADIENT(w, Q[l])            # the split step's carried V'(q)
            for s in range(s0, s1):
                t = ROW(sintab, s)
                for l in range(n):
                    q, p, d, v = SPLIT(w, Q[l], P[l], LANE(l, HL, CL), SCALED(FL[l], t), D[l])
                    Q[l] = q
                    P[l] = p
                    D[l] = d
                    _maxima_signed(l, q, ENERGY2_FROM(w, v, p), ME, MQ, MN)
        return split_impl

    def impl(scheme: Any, well: Any, wpar: Any, M: Any, Q: Any, P: Any, D: Any, ME: Any, MQ: Any, MN: Any,
             HL: Any, CL: Any, FL: Any, sintab: Any, s0: Any, s1: Any) -> None:
        n = 4 * M
        w = wtuple(wpar)
        _reset(n, ME, MQ, MN, SIGNED)
        for s in range(s0, s1):
            t = ROW(sintab, s)
            for l in range(n):
                q, p = STEP(w, Q[l], P[l], LANE(l, HL, CL), SCALED(FL[l], t))
                e = ENERGY2(w, q, p)
                if SIGNED:
                    Q[l] = q
                    P[l] = p
                    _maxima_signed(l, q, e, ME, MQ, MN)
                else:
                    _keep_abs(l, q, p, e, Q, P, ME, MQ)
    return impl
