"""Compiled ensemble integrator for eq (1): q'' + q - q^3 = F sin(Omega t + Psi).

Scheme
------
Blanes & Moan (2002) symmetric symplectic Runge-Kutta-Nystrom method SRKN_6^b (order 4,
7 kicks + 6 drifts per step, kick first):

    B(b1) A(a1) B(b2) A(a2) B(b3) A(a3) B(b4) A(a3) B(b3) A(a2) B(b2) A(a1) B(b1)

with A = drift q += a h p (time drifts with q: extended phase space) and B = kick
p += b h (q^3 - q + F sin(Omega t_k + Psi)) at the current sub-time t_k.  Because
Omega * t_k = 2 pi (s + c_k) / S for sub-step s of a period of S steps, the table
sin(Omega t_k + Psi) depends only on (S, Psi): one table serves every Omega and F.

Every lane's arithmetic is written with explicit fused multiply-adds (llvm.fma), no
fast-math flags: the vector loop and the scalar replay produce bitwise identical numbers
and a trajectory's result does not depend on which lane, block or thread ran it.

Escape detection
----------------
Per step the kernel tracks, per lane, max 2*H0 and max |q| over the current quarter period
(vectorised, branch free; the period runs in SEGMENTS = 4 segments with a (q, p) snapshot
before each).  At the period boundary a lane whose segment maxima crossed its next
uncrossed threshold replays that segment from its snapshot (scalar, same arithmetic) and
records the exact step of first crossing of every threshold crossed there.
A lane whose trajectory is finished (every requested threshold crossed, or the horizon
reached) takes the next trajectory of its task at the period boundary (lane refill: the
forcing is periodic, so every lane is always at the same sub-step of the period); when
the task's queue is empty the active lanes are compacted so the vector loop only runs
over live trajectories.
"""
from __future__ import annotations

import numpy as np
from numba import njit, prange, types
from numba.extending import intrinsic

# --- Blanes & Moan 2002, SRKN_6^b (Table 3), order 4 -------------------------------------
_A1 = 0.245298957184271
_A2 = 0.604872665711080
_A3 = 0.5 - (_A1 + _A2)
_B1 = 0.0829844064174052
_B2 = 0.396309801498368
_B3 = -0.0390563049223486
_B4 = 1.0 - 2.0 * (_B1 + _B2 + _B3)
BM6_DRIFT = np.array([_A1, _A2, _A3, _A3, _A2, _A1])
BM6_KICK = np.array([_B1, _B2, _B3, _B4, _B3, _B2, _B1])
# sub-times of the 7 kicks as fractions of a step
BM6_KICK_TIMES = np.concatenate([[0.0], np.cumsum(BM6_DRIFT)])
BM6_KICK_TIMES[-1] = 1.0
DRIFT1, DRIFT2, DRIFT3 = _A1, _A2, _A3
KICK1, KICK2, KICK3, KICK4 = _B1, _B2, _B3, _B4
INTEGRATOR = "Blanes-Moan SRKN6b (symplectic RKN, order 4, 6 force evaluations/step)"
N_KICKS = 7

# q beyond the barrier |q| = 1: out of the well.  Counts as crossing every energy threshold
# (H0 no longer measures the well energy there; the particle runs away).
Q_BARRIER = 1.0
# smallest lane segment of the 4-chain vector loop (lanes run: 4 * segment)
MIN_SEGMENT = 16
# segments per period for the crossing replay (a crossing is replayed over S / SEGMENTS steps)
SEGMENTS = 4


@intrinsic
def fma(typingctx, a, b, c):
    """Correctly rounded a*b + c (llvm.fma.f64): same bits in vector and scalar code."""
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        return builder.fma(*args)

    return sig, codegen


@njit(cache=True, inline="always")
def force(q, f):
    """q^3 - q + f, with f = F sin(Omega t_k + Psi) (a product F * table value)."""
    return fma(q * q, q, f - q)


@njit(cache=True, inline="always")
def bm6_step(q, p, a1, a2, a3, b1, b2, b3, b4, f1, f2, f3, f4, f5, f6, f7):
    p = fma(b1, force(q, f1), p)
    q = fma(a1, p, q)
    p = fma(b2, force(q, f2), p)
    q = fma(a2, p, q)
    p = fma(b3, force(q, f3), p)
    q = fma(a3, p, q)
    p = fma(b4, force(q, f4), p)
    q = fma(a3, p, q)
    p = fma(b3, force(q, f5), p)
    q = fma(a2, p, q)
    p = fma(b2, force(q, f6), p)
    q = fma(a1, p, q)
    p = fma(b1, force(q, f7), p)
    return q, p


@njit(cache=True, inline="always")
def energy2(q, p):
    """2 H0 = p^2 + q^2 - q^4/2 (eq 7, untruncated); compared with 2 xi_max (exact doubling)."""
    q2 = q * q
    return fma(q2, fma(-0.5, q2, 1.0), p * p)


@njit(cache=True)
def energy(q, p):
    return 0.5 * energy2(q, p)


def sine_table(steps_per_cycle, Psi):
    """sin(Omega t + Psi) at the 7 kick sub-times of every step of one period, (S, 7)."""
    s = np.arange(steps_per_cycle, dtype=float)[:, None] + BM6_KICK_TIMES[None, :]
    return np.ascontiguousarray(np.sin(2.0 * np.pi * s / steps_per_cycle + Psi))


def lane_coefficients(Omega, steps_per_cycle):
    """Per-parameter-set step coefficients (n, 7): a1 h, a2 h, a3 h, b1 h, ..., b4 h."""
    Omega = np.atleast_1d(np.asarray(Omega, dtype=float))
    h = 2.0 * np.pi / (Omega * steps_per_cycle)
    out = np.empty((Omega.size, 7))
    out[:, 0:3] = h[:, None] * BM6_DRIFT[None, :3]
    out[:, 3:7] = h[:, None] * BM6_KICK[None, :4]
    return out


def step_sizes(Omega, steps_per_cycle):
    """h = T / S per parameter set (the per-lane path forms h * a_k in the loop)."""
    Omega = np.atleast_1d(np.asarray(Omega, dtype=float))
    return 2.0 * np.pi / (Omega * steps_per_cycle)


@njit(cache=True)
def _check_state(i, q, p, step, thrE2, thrQ, iE, iQ, outE, outQ):
    """Record, at `step`, every next-uncrossed threshold the state (q, p) is beyond."""
    e = energy2(q, p)
    aq = abs(q)
    nE = thrE2.shape[0]
    nQ = thrQ.shape[0]
    while iE < nE and (e > thrE2[iE] or aq > Q_BARRIER):
        outE[i, iE] = step
        iE += 1
    while iQ < nQ and aq > thrQ[iQ]:
        outQ[i, iQ] = step
        iQ += 1
    return iE, iQ


@njit(cache=True, inline="always")
def _finished(iE, iQ, nE, nQ, stop_any):
    return (iE == nE and iQ == nQ) or (stop_any and (iE > 0 or iQ > 0))


@njit(cache=True)
def _replay(i, q, p, period, s0, s1, sintab, c, F, thrE2, thrQ, iE, iQ, outE, outQ, stop_any):
    """Scalar replay of steps [s0, s1) of a period from the state before step s0 (same
    arithmetic as the vector loop); records the step of first crossing of every threshold
    crossed there."""
    S = sintab.shape[0]
    nE = thrE2.shape[0]
    nQ = thrQ.shape[0]
    base = period * S
    for s in range(s0, s1):
        q, p = bm6_step(q, p, c[0], c[1], c[2], c[3], c[4], c[5], c[6],
                        F * sintab[s, 0], F * sintab[s, 1], F * sintab[s, 2], F * sintab[s, 3],
                        F * sintab[s, 4], F * sintab[s, 5], F * sintab[s, 6])
        iE, iQ = _check_state(i, q, p, base + s + 1, thrE2, thrQ, iE, iQ, outE, outQ)
        if _finished(iE, iQ, nE, nQ, stop_any):
            break
    return iE, iQ


@njit(cache=True)
def _period_shared(M, Q, P, ME, MQ, c, FS, s0, s1):
    """Steps [s0, s1) of the forcing period for lanes [0, 4M), all sharing one parameter set;
    ME, MQ = max 2*H0 and max |q| over these steps.

    The lane loop (j) vectorises; its body advances 4 independent lanes j, M+j, 2M+j, 3M+j
    so that 4 dependency chains are in flight (the step is latency bound otherwise).
    (Generated code: 4 explicit chains.)"""
    a1 = c[0]; a2 = c[1]; a3 = c[2]; b1 = c[3]; b2 = c[4]; b3 = c[5]; b4 = c[6]
    for l in range(4 * M):
        ME[l] = -np.inf
        MQ[l] = -np.inf
    for s in range(s0, s1):
        f1 = FS[s, 0]; f2 = FS[s, 1]; f3 = FS[s, 2]; f4 = FS[s, 3]
        f5 = FS[s, 4]; f6 = FS[s, 5]; f7 = FS[s, 6]
        for j in range(M):
            l0 = 0 * M + j
            l1 = 1 * M + j
            l2 = 2 * M + j
            l3 = 3 * M + j
            q0, p0 = bm6_step(Q[l0], P[l0], a1, a2, a3, b1, b2, b3, b4,
                                  f1, f2, f3, f4, f5, f6, f7)
            q1, p1 = bm6_step(Q[l1], P[l1], a1, a2, a3, b1, b2, b3, b4,
                                  f1, f2, f3, f4, f5, f6, f7)
            q2, p2 = bm6_step(Q[l2], P[l2], a1, a2, a3, b1, b2, b3, b4,
                                  f1, f2, f3, f4, f5, f6, f7)
            q3, p3 = bm6_step(Q[l3], P[l3], a1, a2, a3, b1, b2, b3, b4,
                                  f1, f2, f3, f4, f5, f6, f7)
            Q[l0] = q0
            P[l0] = p0
            e0 = energy2(q0, p0)
            x0 = abs(q0)
            m = ME[l0]
            ME[l0] = e0 if e0 > m else m
            m = MQ[l0]
            MQ[l0] = x0 if x0 > m else m
            Q[l1] = q1
            P[l1] = p1
            e1 = energy2(q1, p1)
            x1 = abs(q1)
            m = ME[l1]
            ME[l1] = e1 if e1 > m else m
            m = MQ[l1]
            MQ[l1] = x1 if x1 > m else m
            Q[l2] = q2
            P[l2] = p2
            e2 = energy2(q2, p2)
            x2 = abs(q2)
            m = ME[l2]
            ME[l2] = e2 if e2 > m else m
            m = MQ[l2]
            MQ[l2] = x2 if x2 > m else m
            Q[l3] = q3
            P[l3] = p3
            e3 = energy2(q3, p3)
            x3 = abs(q3)
            m = ME[l3]
            ME[l3] = e3 if e3 > m else m
            m = MQ[l3]
            MQ[l3] = x3 if x3 > m else m


@njit(cache=True)
def _period_lanes(M, Q, P, ME, MQ, HL, FL, sintab, s0, s1):
    """As _period_shared for lanes [0, 4M) with per-lane parameters: step h = HL[l] and
    amplitude F = FL[l].  The coefficients h*a_k, h*b_k and forcing values F*sin_k are formed
    in the loop: the same IEEE products as the precomputed ones of the shared path, so both
    paths give bitwise identical trajectories.  (One chain per iteration: with 4 chains and
    six arrays LLVM's runtime alias checks exceed its budget and the loop stays scalar.)"""
    A1 = DRIFT1; A2 = DRIFT2; A3 = DRIFT3; B1 = KICK1; B2 = KICK2; B3 = KICK3; B4 = KICK4
    n = 4 * M
    for l in range(n):
        ME[l] = -np.inf
        MQ[l] = -np.inf
    for s in range(s0, s1):
        t1 = sintab[s, 0]; t2 = sintab[s, 1]; t3 = sintab[s, 2]; t4 = sintab[s, 3]
        t5 = sintab[s, 4]; t6 = sintab[s, 5]; t7 = sintab[s, 6]
        for l in range(n):
            h = HL[l]
            F = FL[l]
            q, p = bm6_step(Q[l], P[l], h * A1, h * A2, h * A3, h * B1, h * B2, h * B3, h * B4,
                            F * t1, F * t2, F * t3, F * t4, F * t5, F * t6, F * t7)
            Q[l] = q
            P[l] = p
            e = energy2(q, p)
            x = abs(q)
            m = ME[l]
            ME[l] = e if e > m else m
            m = MQ[l]
            MQ[l] = x if x > m else m


@njit(cache=True)
def _run_task(task, n_tasks, lanes, q0, p0, pidx, coef, hpar, Fpar, sintab, thrE2, thrQ, cycles,
              stop_any, outE, outQ, store, do_store):
    N = q0.shape[0]
    S = sintab.shape[0]
    nE = thrE2.shape[0]
    nQ = thrQ.shape[0]
    shared = coef.shape[0] == 1
    L = np.int64(lanes)
    Lmem = max(L, 4 * MIN_SEGMENT) + 32       # room for the padded segments
    Q = np.zeros(Lmem)
    P = np.zeros(Lmem)
    ME = np.empty(Lmem)
    MQ = np.empty(Lmem)
    # the period is run in G segments; snapshots of (q, p) before each segment and the
    # segment maxima let a crossing be replayed over one segment only
    G = SEGMENTS if S >= 4 * SEGMENTS else 1
    seg = np.empty(G + 1, np.int64)
    for g in range(G + 1):
        seg[g] = g * S // G
    SQ = np.zeros((G, Lmem))
    SP = np.zeros((G, Lmem))
    SME = np.empty((G, Lmem))
    SMQ = np.empty((G, Lmem))
    traj = np.empty(L, np.int64)
    per = np.empty(L, np.int64)
    lE = np.empty(L, np.int64)
    lQ = np.empty(L, np.int64)
    done = np.zeros(L, np.bool_)
    tE = np.empty(L)      # next uncrossed 2*xi threshold of the lane (inf: none)
    tQ = np.empty(L)      # next uncrossed |q| threshold (or the barrier)
    inf = np.inf
    FS = Fpar[0] * sintab        # (S, 7), shared path
    HL = np.zeros(Lmem)          # per-lane path
    FL = np.zeros(Lmem)

    nxt = np.int64(task)
    nact = np.int64(0)
    while True:
        # ---------------------------------------------------- fill empty / finished lanes
        l = np.int64(0)
        while l < nact or (l == nact and nact < L and nxt < N):
            if l < nact and not done[l]:
                l += 1
                continue
            loaded = False
            while nxt < N:
                i = nxt
                nxt += n_tasks
                iE, iQ = _check_state(i, q0[i], p0[i], 0, thrE2, thrQ, 0, 0, outE, outQ)
                if do_store and iE == 0 and iQ == 0:
                    store[i, 0, 0] = q0[i]
                    store[i, 0, 1] = p0[i]
                if _finished(iE, iQ, nE, nQ, stop_any) or cycles == 0:
                    continue
                k = pidx[i]
                Q[l] = q0[i]; P[l] = p0[i]
                HL[l] = hpar[k]
                FL[l] = Fpar[k]
                traj[l] = i; per[l] = 0; lE[l] = iE; lQ[l] = iQ
                tE[l] = thrE2[iE] if iE < nE else inf
                tQ[l] = thrQ[iQ] if iQ < nQ else inf
                if iE < nE:
                    tQ[l] = min(tQ[l], Q_BARRIER)
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
                traj[l] = traj[last]; per[l] = per[last]; lE[l] = lE[last]; lQ[l] = lQ[last]
                tE[l] = tE[last]; tQ[l] = tQ[last]; done[l] = done[last]
            nact -= 1
        if nact == 0:
            break
        # ---------------------------------------------------- one period, vectorised
        # lanes [0, 4M) with M a multiple of 8 (vector width); idle lanes hold q = p = 0
        M = max(MIN_SEGMENT, ((nact + 3) // 4 + 7) // 8 * 8)
        for l in range(nact, 4 * M):
            Q[l] = 0.0
            P[l] = 0.0
        for g in range(G):
            for l in range(nact):
                SQ[g, l] = Q[l]
                SP[g, l] = P[l]
            if shared:
                _period_shared(M, Q, P, ME, MQ, coef[0], FS, seg[g], seg[g + 1])
            else:
                _period_lanes(M, Q, P, ME, MQ, HL, FL, sintab, seg[g], seg[g + 1])
            for l in range(nact):
                SME[g, l] = ME[l]
                SMQ[g, l] = MQ[l]
        # ---------------------------------------------------- period boundary
        for l in range(nact):
            i = traj[l]
            iE = lE[l]
            iQ = lQ[l]
            for g in range(G):
                if SME[g, l] > tE[l] or SMQ[g, l] > tQ[l]:
                    k = pidx[i]
                    iE, iQ = _replay(i, SQ[g, l], SP[g, l], per[l], seg[g], seg[g + 1], sintab, coef[k],
                                     Fpar[k], thrE2, thrQ, iE, iQ, outE, outQ, stop_any)
                    lE[l] = iE
                    lQ[l] = iQ
                    tE[l] = thrE2[iE] if iE < nE else inf
                    tQ[l] = thrQ[iQ] if iQ < nQ else inf
                    if iE < nE:
                        tQ[l] = min(tQ[l], Q_BARRIER)
                    if _finished(iE, iQ, nE, nQ, stop_any):
                        break
            per[l] += 1
            fin = _finished(iE, iQ, nE, nQ, stop_any)
            if do_store and not fin and iE == 0 and iQ == 0:
                store[i, per[l], 0] = Q[l]
                store[i, per[l], 1] = P[l]
            done[l] = fin or per[l] >= cycles


@njit(cache=True, parallel=True)
def ensemble(q0, p0, pidx, coef, hpar, Fpar, sintab, thrE2, thrQ, cycles, stop_any, n_tasks, lanes,
             outE, outQ, store, do_store):
    """Integrate every trajectory i from (q0[i], p0[i]) with parameter set pidx[i]
    (coef[pidx[i]] = step coefficients from lane_coefficients, hpar[pidx[i]] = the step h
    from step_sizes, Fpar[pidx[i]] = F) for at most
    `cycles` forcing periods of S = sintab.shape[0] steps.

    thrE2: sorted ascending 2*xi_max thresholds; thrQ: sorted ascending q_max (either may be
    empty).  outE (N, nE), outQ (N, nQ): int64 step after which the threshold is first
    exceeded (0 = the initial condition), pre-filled with -1 (= not within the horizon).
    A trajectory stops when every threshold is crossed (stop_any: when any is crossed).
    store (N, cycles+1, 2): period-map iterates when do_store (pre-filled with NaN).
    Trajectory i is run by task i % n_tasks; the results do not depend on n_tasks, lanes or
    the thread count (each trajectory is the same sequence of IEEE operations).
    """
    for task in prange(n_tasks):
        _run_task(task, n_tasks, lanes, q0, p0, pidx, coef, hpar, Fpar, sintab, thrE2, thrQ, cycles,
                  stop_any, outE, outQ, store, do_store)


@njit(cache=True, parallel=True)
def final_states(q0, p0, pidx, coef, Fpar, sintab, n_periods):
    """Plain integration (no escape checks) for n_periods periods; returns (q, p).
    Scalar per trajectory; used by tests (convergence order, energy drift)."""
    N = q0.shape[0]
    S = sintab.shape[0]
    qo = np.empty(N)
    po = np.empty(N)
    for i in prange(N):
        k = pidx[i]
        F = Fpar[k]
        c = coef[k]
        q = q0[i]
        p = p0[i]
        for n in range(n_periods):
            for s in range(S):
                q, p = bm6_step(q, p, c[0], c[1], c[2], c[3], c[4], c[5], c[6],
                                F * sintab[s, 0], F * sintab[s, 1], F * sintab[s, 2],
                                F * sintab[s, 3], F * sintab[s, 4], F * sintab[s, 5],
                                F * sintab[s, 6])
        qo[i] = q
        po[i] = p
    return qo, po
