"""Compiled ensemble integrator for eq (1) in any supported well: q'' + V'(q) = F sin(Omega t + Psi).

The schemes are constants (schemes.py) whose steps are generated once (scheme_code.py) and
compiled for the CPU in steps.py, the vectorised period loops over the lanes live in periods.py,
the well's force and energy in its compiled form (wells/compiled.py), the well's period loop,
replay and state check in well_loops.py; this module holds the lane machinery: escape detection,
refill, compaction, and the entry points.

Schemes and wells are compile-time constants of the inline period bodies: `scheme`, the key of a
scheme's compiled form (scheme_code.SchemeCode.key; the forcing table's width and the coefficient
table match it) and `well`, the kernel key of a compiled well (wells.compiled.WellCode.key).  The
well's three functions (well_loops.py) take both as numba literals: every pair of keys is its own
compiled code, cached on disk and compiled on first use, holding only its own scheme's and well's
code (numba @overload on the literal, resolved at typing time).  The machinery, _run_task, takes
the scheme key, the shared flag and the kind of tracking as literals (kernels.specialised) and
calls the well's three through function pointers: one cached kernel serves every well.  Keys
hash the arithmetic and the engine's source, so a cached kernel is never reused after an edit.
Parallelism: one task per thread (Python threads; the task function releases the GIL).

Every lane's arithmetic is written with explicit fused multiply-adds (llvm.fma), no
fast-math flags: the vector loop and the scalar replay produce bitwise identical numbers
and a trajectory's result does not depend on which lane, block or thread ran it.

Escape criteria
---------------
energy: 2 H0 = p^2 + 2 V(q) > 2 xi_max, or q beyond a barrier (|q| tracking, the quartic: |q| > 1; signed
tracking: q > q_right or q < q_left, a side without barrier has q_left = -inf / q_right = +inf
and never escapes that way); displacement: q outside the bound pair (lo, hi), q < lo or
q > hi (|q| tracking: |q| > q_max, lo = -hi).  A NaN or inf state is beyond every threshold.  The thresholds are sorted:
2 xi_max ascending, the bound pairs nested from the inside out (lo non-increasing, hi non-decreasing), so crossing a
threshold crosses every inner one and each lane only watches its next uncrossed one.

Escape detection
----------------
Per step the kernel tracks, per lane, max 2*H0 and max |q| (|q| tracking) or max q and max -q
(signed tracking) over the current quarter period (vectorised, branch free; the period runs
in SEGMENTS = 4 segments with a (q, p) snapshot before each).  At the period boundary a lane
whose segment maxima crossed its next uncrossed threshold replays that segment from its
snapshot (scalar, same arithmetic) and records the exact step of first crossing of every
threshold crossed there.  A period that follows a boundary without any crossing runs as one
segment (its crossings are replayed over the whole period): the snapshots are only paid for
while lanes are crossing thresholds.  A lane whose trajectory is finished (every requested
threshold crossed, or the horizon reached) takes the next trajectory of its task at the
period boundary (lane refill: the forcing is periodic, so every lane is always at the same
sub-step of the period); when the task's queue is empty the active lanes are compacted so
the vector loop only runs over live trajectories.
"""
from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
import numpy.typing as npt
from numba import typeof, types

from safebasins.core.numba_target import VECTOR_LANES, kernel_compile, package_jit
from safebasins.numerics.scheme_code import SchemeCode, scheme_code
from safebasins.numerics.steps import Floats, Int, Ints, coefs, is_damped, scaled_row, step, wtuple
from safebasins.numerics.well_loops import (CheckFn, PeriodFn, ReplayFn, finished, check_pointer, period_pointer,
                                             replay_pointer)
from safebasins.wells.compiled import WellCode, quartic_code

# smallest lane segment of the 4-chain vector loop (lanes run: 4 * segment; a multiple of
# VECTOR_LANES, so that no vector loop has a scalar remainder)
MIN_SEGMENT = VECTOR_LANES
# segments per period for the crossing replay (a crossing is replayed over S / SEGMENTS steps)
SEGMENTS = 4


@package_jit(cache=True, inline="always")
def _filters(abs_q: bool, wpar: Floats, iE: Int, iQ: Int, thrE2: Floats, thrLo: Floats,
             thrHi: Floats) -> tuple[float, float, float]:
    """(tE, tQ, tN): the lane's next uncrossed 2 xi_max, and the levels its max q (|q| tracking:
    max |q|) and max -q must exceed to cross its next uncrossed bound or, while an energy
    threshold is uncrossed, a barrier (inf: none)."""
    inf = np.inf
    nE = thrE2.shape[0]
    nQ = thrHi.shape[0]
    tE = thrE2[iE] if iE < nE else inf
    tQ = thrHi[iQ] if iQ < nQ else inf
    tN = inf
    if abs_q:
        if iE < nE:
            tQ = min(tQ, wpar[1])
    else:
        tN = -thrLo[iQ] if iQ < nQ else inf
        if iE < nE:
            tQ = min(tQ, wpar[1])
            tN = min(tN, -wpar[0])
    return tE, tQ, tN


@package_jit(cache=True, nogil=True)
def _run_task(scheme: int, shared: bool, abs_q: bool, well: int, period_fn: PeriodFn, replay_fn: ReplayFn,
              check_fn: CheckFn, wpar: Floats, task: int, n_tasks: int, lanes: int, q0: Floats, p0: Floats,
              pidx: Ints, coef: Floats, hpar: Floats, Fpar: Floats, sintab: Floats, thrE2: Floats, thrLo: Floats,
              thrHi: Floats, cycles: int, stop_any: bool, outE: Ints, outQ: Ints, store: Floats, do_store: bool,
              FS: Floats, segs: Ints, lane_f: Floats, snap: Floats, SMN: Floats, lane_i: Ints,
              lane_b: npt.NDArray[np.bool_], lane_t: Floats, CL: Floats) -> None:
    """Trajectories task, task + n_tasks, ... (one thread): the lane machinery of the module
    docstring.  `scheme` is the key of a scheme code, `shared` whether all trajectories share one
    parameter set (``coef.shape[0] == 1``: the shared loop, else the per-lane loop), `abs_q`
    whether the well tracks |q| (else q and -q); numba literals (:func:`specialised`): one cached
    kernel per triple, compiled on first use.  The well (its kernel key `well`) enters only
    through the function pointers of its period loop, replay and state check
    (numerics.well_loops), compiled for this scheme and shared flag.
    FS .. CL: the task's work arrays (:func:`_workspace`), allocated by the caller: numpy's
    allocation overloads would be compiled anew with every kernel."""
    damped = is_damped(scheme)
    N = q0.shape[0]
    nE = thrE2.shape[0]
    nQ = thrHi.shape[0]
    L: Int = np.int64(lanes)
    # lane state: (q, p), the per-lane path's step and amplitude; V'(q) of a split well's loops
    Q, P, HL, FL, D = lane_f[0], lane_f[1], lane_f[2], lane_f[3], lane_f[4]
    # the period is run in G segments; snapshots of (q, p) before each segment and the
    # segment maxima let a crossing be replayed over one segment only.  Segments cost a
    # snapshot per lane each; they pay off only while lanes cross thresholds, so a period
    # after one without any crossing runs as ONE segment (a crossing there is replayed over
    # the whole period; the recorded steps are the same either way)
    Gmax = segs.shape[1] - 1
    SQ, SP, SME, SMQ = snap[0], snap[1], snap[2], snap[3]
    nhit = np.int64(1)         # crossings at the last period boundary (first period: segmented)
    traj, per, lE, lQ = lane_i[0], lane_i[1], lane_i[2], lane_i[3]
    done, hit = lane_b[0], lane_b[1]
    # next uncrossed 2*xi threshold of the lane (inf: none); next uncrossed |q| (|q| tracking) or
    # upper bound, or the barrier; signed tracking: next uncrossed -lower bound, or -q_left
    tE, tQ, tN = lane_t[0], lane_t[1], lane_t[2]
    NC = coef.shape[1]

    zero = np.int64(0)
    nxt = np.int64(task)
    nact: Int = np.int64(0)
    ndone = np.int64(0)        # lanes finished at the last period boundary
    while True:
        # ---------------------------------------------------- fill empty / finished lanes
        l: Int = np.int64(0)
        if ndone == 0 and (nact == L or nxt >= N):
            l = nact           # nothing to refill or compact: skip the scan
        while l < nact or (l == nact and nact < L and nxt < N):
            if l < nact and not done[l]:
                l += 1
                continue
            loaded = False
            while nxt < N:
                i = nxt
                nxt += n_tasks
                # int64 zeros, not literals: the same _check_state as the replay's (one compile)
                iE, iQ = check_fn(scheme, well, wpar, i, q0[i], p0[i], zero, thrE2, thrLo, thrHi, zero, zero, outE,
                                  outQ)
                if do_store and iE == 0 and iQ == 0:
                    store[i, 0, 0] = q0[i]
                    store[i, 0, 1] = p0[i]
                if finished(iE, iQ, nE, nQ, stop_any) or cycles == 0:
                    continue
                k = pidx[i]
                Q[l] = q0[i]; P[l] = p0[i]
                HL[l] = hpar[k]
                FL[l] = Fpar[k]
                if damped:
                    for j in range(NC):
                        CL[j, l] = coef[k, j]
                traj[l] = i; per[l] = 0; lE[l] = iE; lQ[l] = iQ
                tE[l], tQ[l], tN[l] = _filters(abs_q, wpar, iE, iQ, thrE2, thrLo, thrHi)
                done[l] = False
                loaded = True
                break
            if loaded:
                if l == nact:
                    nact += 1
                l += 1
                continue
            if l == nact:
                break
            # queue empty: move the last active lane into the hole
            last = nact - 1
            if last != l:
                Q[l] = Q[last]; P[l] = P[last]
                HL[l] = HL[last]
                FL[l] = FL[last]
                if damped:
                    for j in range(NC):
                        CL[j, l] = CL[j, last]
                traj[l] = traj[last]; per[l] = per[last]; lE[l] = lE[last]; lQ[l] = lQ[last]
                tE[l] = tE[last]; tQ[l] = tQ[last]; tN[l] = tN[last]; done[l] = done[last]
            nact -= 1
        if nact == 0:
            break
        # ---------------------------------------------------- one period, vectorised
        # lanes [0, 4M) with M a multiple of VECTOR_LANES (no scalar remainder in the vector
        # loops); idle lanes hold q = p = 0
        M = max(MIN_SEGMENT, ((nact + 3) // 4 + VECTOR_LANES - 1) // VECTOR_LANES * VECTOR_LANES)
        for l in range(nact, 4 * M):
            Q[l] = 0.0
            P[l] = 0.0
        G = Gmax if nhit > 0 else 1
        seg = segs[0] if nhit > 0 else segs[1]
        for g in range(G):
            for l in range(nact):
                SQ[g, l] = Q[l]
                SP[g, l] = P[l]
            # segment maxima go straight into the rows SME[g], SMQ[g] (, SMN[g])
            period_fn(scheme, well, wpar, M, Q, P, D, SME[g], SMQ[g], SMN[g], coef, FS, HL, CL, FL, sintab, seg[g],
                      seg[g + 1])
        # ---------------------------------------------------- period boundary
        # vectorised test first: only lanes whose maxima crossed a threshold (or, for the
        # map, every lane) need the scalar bookkeeping below
        for l in range(nact):
            hit[l] = False
        if abs_q:
            for g in range(G):
                for l in range(nact):
                    hit[l] = hit[l] | (not SME[g, l] <= tE[l]) | (not SMQ[g, l] <= tQ[l])
        else:
            for g in range(G):
                for l in range(nact):
                    hit[l] = hit[l] | (not SME[g, l] <= tE[l]) | (not SMQ[g, l] <= tQ[l]) | (not SMN[g, l] <= tN[l])
        nhit = np.int64(0)
        for l in range(nact):
            nhit += hit[l]
        ndone = np.int64(0)
        for l in range(nact):
            per[l] += 1
            d = per[l] >= cycles
            done[l] = d
            ndone += d
        for l in range(nact):
            if nhit == 0 and not do_store:
                break
            if not (hit[l] or do_store):
                continue
            i = traj[l]
            iE = lE[l]
            iQ = lQ[l]
            if hit[l]:
                for g in range(G):
                    if (not SME[g, l] <= tE[l] or not SMQ[g, l] <= tQ[l]
                            or (not abs_q and not SMN[g, l] <= tN[l])):
                        k = pidx[i]
                        iE, iQ = replay_fn(scheme, well, wpar, i, SQ[g, l], SP[g, l], per[l] - 1, seg[g],
                                           seg[g + 1], sintab, coef[k], Fpar[k], thrE2, thrLo, thrHi, iE, iQ, outE,
                                           outQ, stop_any)
                        lE[l] = iE
                        lQ[l] = iQ
                        tE[l], tQ[l], tN[l] = _filters(abs_q, wpar, iE, iQ, thrE2, thrLo, thrHi)
                        if finished(iE, iQ, nE, nQ, stop_any):
                            break
            fin = finished(iE, iQ, nE, nQ, stop_any)
            if do_store and not fin and iE == 0 and iQ == 0:
                store[i, per[l], 0] = Q[l]
                store[i, per[l], 1] = P[l]
            d = fin or per[l] >= cycles
            ndone += d and not done[l]
            done[l] = d




def specialised(dispatcher: Any, args: Sequence[Any], n_literal: int = 2) -> Callable[..., Any]:
    """The compiled entry point of ``dispatcher`` for ``args``, whose first ``n_literal`` arguments
    (the kernel key, the scheme key; for _run_task also the shared flag) are taken as numba
    literals (compiled, or loaded from the on-disk cache, on first use; compiled with
    core.numba_target's interleave count).  Calling it skips numba's dispatch, which would
    first try the non-literal signature at every call."""
    sig = tuple(types.literal(a) for a in args[:n_literal]) + tuple(typeof(a) for a in args[n_literal:])
    entry = _ENTRIES.get((dispatcher, sig))
    if entry is None:
        with kernel_compile():
            dispatcher.compile(sig)
        entry = _ENTRIES[(dispatcher, sig)] = dispatcher.overloads[sig].entry_point
    return entry


_ENTRIES: dict[tuple[Any, tuple[Any, ...]], Callable[..., Any]] = {}


def _zeros(shape: tuple[int, ...], dtype: type = np.float64) -> np.ndarray:
    """Zeros with rows aligned to 64 bytes (the vector loop's arrays; a row length the callers
    round to 8 elements)."""
    size = int(np.prod(shape)) * np.dtype(dtype).itemsize
    buf = np.zeros(size + 64, np.uint8)
    start = -buf.ctypes.data % 64
    return buf[start:start + size].view(dtype).reshape(shape)


def _workspace(lanes: int, shared: bool, damped: bool, abs_q: bool, coef: np.ndarray, Fpar: np.ndarray,
               sintab: np.ndarray) -> list[np.ndarray]:
    """The work arrays of one task of :func:`_run_task` (its arguments FS .. CL)."""
    S = sintab.shape[0]
    Lmem = (max(lanes, 4 * MIN_SEGMENT) + 4 * VECTOR_LANES + 7) // 8 * 8     # room for the padded segments
    Lr = (lanes + 7) // 8 * 8
    Gmax = SEGMENTS if S >= 4 * SEGMENTS else 1
    segs = np.zeros((2, Gmax + 1), np.int64)
    for g in range(Gmax + 1):
        segs[0, g] = g * S // Gmax
        segs[1, g] = S if g > 0 else 0
    FS = Fpar[0] * sintab if shared else np.zeros((1, sintab.shape[1]))      # the shared path's forcing
    return [FS, segs, _zeros((5, Lmem)), _zeros((4, Gmax, Lmem)), _zeros((Gmax, 1 if abs_q else Lmem)),
            _zeros((4, Lr), np.int64), _zeros((2, Lr), np.bool_), _zeros((3, Lr)),
            _zeros((coef.shape[1], Lmem if damped else 1))]


def run_tasks(fn: Callable[[int], object], n_tasks: int) -> None:
    """fn(task) for task in range(n_tasks), on n_tasks threads (the compiled task functions release
    the GIL); exceptions propagate."""
    if n_tasks == 1:
        fn(0)
        return
    with ThreadPoolExecutor(max_workers=n_tasks) as pool:
        for f in [pool.submit(fn, t) for t in range(n_tasks)]:
            f.result()


def _check_code(well: object) -> WellCode:
    if not isinstance(well, WellCode):
        raise ValueError(f"well must be a compiled well (safebasins.wells.compiled.WellCode: Well.compiled), "
                         f"got {well!r}")
    return well


def ensemble(q0: np.ndarray, p0: np.ndarray, pidx: np.ndarray, coef: np.ndarray, hpar: np.ndarray, Fpar: np.ndarray,
             sintab: np.ndarray, thrE2: np.ndarray, thrQ: npt.ArrayLike, cycles: int, stop_any: bool, n_tasks: int,
             lanes: int, outE: np.ndarray, outQ: np.ndarray, store: np.ndarray, do_store: bool,
             well: WellCode | None = None, thrQlo: npt.ArrayLike | None = None,
             scheme: SchemeCode | None = None) -> None:
    """Integrate every trajectory i from (q0[i], p0[i]) with parameter set pidx[i]
    (coef[pidx[i]] = step coefficients from schemes.lane_coefficients, hpar[pidx[i]] = the step h
    from schemes.step_sizes, Fpar[pidx[i]] = F) for at most
    `cycles` forcing periods of S = sintab.shape[0] steps.

    thrE2: sorted ascending 2*xi_max thresholds; thrQ: the upper displacement bounds, sorted
    ascending (|q| tracking: the q_max of |q| > q_max), thrQlo: the lower bounds (signed
    tracking; None: -thrQ), nested with thrQ (non-increasing); either threshold list may be empty.
    outE (N, nE), outQ (N, nQ): int64 step after which the threshold is first
    exceeded (0 = the initial condition), pre-filled with -1 (= not within the horizon).
    A trajectory stops when every threshold is crossed (stop_any: when any is crossed); a NaN
    or inf state is beyond every threshold.
    store (N, cycles+1, 2): period-map iterates when do_store (pre-filled with NaN).
    scheme: the scheme's compiled form (scheme_code.scheme_code(integrator, damped); None: SRKN6b
    undamped), with schemes.sine_table / lane_coefficients of the same scheme and damping; the
    well is its compiled form `well` (wells.compiled.WellCode; None: the quartic).
    Trajectory i is run by task i % n_tasks (one thread each); the results do not depend on
    n_tasks, lanes or the thread count (each trajectory is the same sequence of IEEE operations).
    """
    code = quartic_code() if well is None else _check_code(well)
    hi = np.ascontiguousarray(thrQ, dtype=float)
    lo = -hi if thrQlo is None else np.ascontiguousarray(thrQlo, dtype=float)
    sc = _scheme(scheme, sintab, coef)
    shared = bool(coef.shape[0] == 1)
    work = [_workspace(int(lanes), shared, sc.damped, code.abs_tracking, coef, Fpar, sintab) for _ in range(n_tasks)]
    wpar_t, coef_t, sintab_t = typeof(code.wpar), typeof(coef), typeof(sintab)
    thr_t = [typeof(a) for a in (thrE2, lo, hi)]
    out_t = [typeof(outE), typeof(outQ)]
    FS, _, lane_f, snap, SMN, _, _, _, CL = (typeof(a) for a in work[0])
    calls = [period_pointer(shared, sc.key, code.key, wpar_t, coef_t, FS, lane_f, snap, SMN, CL, sintab_t),
             replay_pointer(sc.key, code.key, wpar_t, sintab_t, coef_t, *thr_t, *out_t),
             check_pointer(sc.key, code.key, wpar_t, *thr_t, *out_t)]
    args = [sc.key, shared, code.abs_tracking, code.key, *calls, code.wpar, 0, int(n_tasks), int(lanes), q0, p0,
            pidx, coef, hpar, Fpar, sintab, thrE2, lo, hi, int(cycles), bool(stop_any), outE, outQ, store,
            bool(do_store)]
    entry = specialised(_run_task, args + work[0], n_literal=3)
    run_tasks(lambda task: entry(*args[:8], task, *args[9:], *work[task]), n_tasks)


def _scheme(scheme: SchemeCode | None, sintab: np.ndarray, coef: np.ndarray) -> SchemeCode:
    """The scheme code (None: SRKN6b), checked against the forcing table and the coefficient table."""
    sc = scheme_code("srkn6b") if scheme is None else scheme
    if not isinstance(sc, SchemeCode):
        raise ValueError(f"scheme must be a scheme code (scheme_code.scheme_code), got {scheme!r}")
    if sintab.ndim != 2 or sintab.shape[1] != sc.width:
        raise ValueError(f"the forcing table of {sc.name} has {sc.width} columns (schemes.sine_table), "
                         f"got shape {sintab.shape}")
    if coef.ndim != 2 or coef.shape[1] != sc.n_coef:
        raise ValueError(f"coef must be lane_coefficients of {sc.name}, shape (n, {sc.n_coef}), got {coef.shape}")
    return sc


@package_jit(cache=True, nogil=True)
def _final_states(well: int, scheme: int, wpar: Floats, q0: Floats, p0: Floats, pidx: Ints, coef: Floats,
                  Fpar: Floats, sintab: Floats, n_periods: int, task: int, n_tasks: int, qo: Floats,
                  po: Floats) -> None:
    N = q0.shape[0]
    S = sintab.shape[0]
    w = wtuple(wpar)
    for i in range(task, N, n_tasks):
        k = pidx[i]
        F = Fpar[k]
        cc = coefs(scheme, coef[k])
        q = q0[i]
        p = p0[i]
        for _ in range(n_periods):
            for s in range(S):
                q, p = step(scheme, well, w, q, p, cc, scaled_row(scheme, sintab, s, F))
        qo[i] = q
        po[i] = p


def final_states(q0: npt.ArrayLike, p0: npt.ArrayLike, pidx: np.ndarray, coef: np.ndarray, Fpar: np.ndarray,
                 sintab: np.ndarray, n_periods: int, well: WellCode | None = None, n_tasks: int = 2,
                 scheme: SchemeCode | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Plain integration (no escape checks) for n_periods periods; returns (q, p).
    Scalar per trajectory; used by tests (convergence order, energy drift).  well: a compiled
    well (None: the quartic); scheme: as ensemble."""
    code = quartic_code() if well is None else _check_code(well)
    q = np.ascontiguousarray(q0, dtype=float)
    qo, po = np.empty(q.shape), np.empty(q.shape)
    n_tasks = max(1, min(int(n_tasks), q.size))
    sc = _scheme(scheme, sintab, coef)
    args = [code.key, sc.key, code.wpar, q, np.ascontiguousarray(p0, dtype=float), pidx, coef, Fpar, sintab,
            int(n_periods), 0, n_tasks, qo, po]
    entry = specialised(_final_states, args)
    run_tasks(lambda t: entry(*args[:10], t, *args[11:]), n_tasks)
    return qo, po
