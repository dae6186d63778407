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

Classic RK4 (integrator="rk4") runs in the same engine: 4 force evaluations per step at
t, t + h/2 (twice) and t + h, table sin(Omega t + Psi) of shape (S, 3).  The scheme of a
run is the width of its forcing table (7: SRKN6b, 3: RK4); the lane machinery (escape
detection, replay, refill, compaction) is shared and only the step differs: the period
loops are inline bodies specialised at compile time on a constant `rk4` flag.

Every lane's arithmetic is written with explicit fused multiply-adds (llvm.fma), no
fast-math flags: the vector loop and the scalar replay produce bitwise identical numbers
and a trajectory's result does not depend on which lane, block or thread ran it.

Escape detection
----------------
Per step the kernel tracks, per lane, max 2*H0 and max |q| over the current quarter period
(vectorised, branch free; the period runs in SEGMENTS = 4 segments with a (q, p) snapshot
before each).  At the period boundary a lane whose segment maxima crossed its next
uncrossed threshold replays that segment from its snapshot (scalar, same arithmetic) and
records the exact step of first crossing of every threshold crossed there.  A period that
follows a boundary without any crossing runs as one segment (its crossings are replayed over
the whole period): the snapshots are only paid for while lanes are crossing thresholds.
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

# --- classic RK4 --------------------------------------------------------------------------
RK4_COEF = np.array([0.5, 1.0, 1.0 / 6.0])       # h/2, h, h/6 (as products h * c)
RK4_TIMES = np.array([0.0, 0.5, 1.0])            # force sub-times as fractions of a step
RK4_C1, RK4_C2, RK4_C3 = 0.5, 1.0, 1.0 / 6.0
INTEGRATORS = {
    "srkn6b": INTEGRATOR,
    "rk4": "classic RK4 (order 4, not symplectic, 4 force evaluations/step)",
}

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
def rk4_step(q, p, hh, h, h6, f1, f2, f3):
    """Classic RK4 for q' = p, p' = q^3 - q + f(t); hh = h/2, h6 = h/6 and f1, f2, f3 the
    forcing at t, t + h/2, t + h."""
    k1 = force(q, f1)
    q2 = fma(hh, p, q)
    p2 = fma(hh, k1, p)
    k2 = force(q2, f2)
    q3 = fma(hh, p2, q)
    p3 = fma(hh, k2, p)
    k3 = force(q3, f2)
    q4 = fma(h, p3, q)
    p4 = fma(h, k3, p)
    k4 = force(q4, f3)
    sq = p2 + p3
    sp = k2 + k3
    q = fma(h6, (p + p4) + (sq + sq), q)
    p = fma(h6, (k1 + k4) + (sp + sp), p)
    return q, p


@njit(cache=True, inline="always")
def step(rk4, q, p, c1, c2, c3, c4, c5, c6, c7, f1, f2, f3, f4, f5, f6, f7):
    """One step of the scheme selected by the (compile-time constant) flag rk4; RK4 uses
    c1..c3 = h/2, h, h/6 and f1..f3 only."""
    if rk4:
        return rk4_step(q, p, c1, c2, c3, f1, f2, f3)
    return bm6_step(q, p, c1, c2, c3, c4, c5, c6, c7, f1, f2, f3, f4, f5, f6, f7)


@njit(cache=True, inline="always")
def _row(tab, s, rk4):
    """Row s of a forcing table as 7 scalars (RK4: 3 + zeros)."""
    if rk4:
        return tab[s, 0], tab[s, 1], tab[s, 2], 0.0, 0.0, 0.0, 0.0
    return tab[s, 0], tab[s, 1], tab[s, 2], tab[s, 3], tab[s, 4], tab[s, 5], tab[s, 6]


@njit(cache=True, inline="always")
def energy2(q, p):
    """2 H0 = p^2 + q^2 - q^4/2 (eq 7, untruncated); compared with 2 xi_max (exact doubling)."""
    q2 = q * q
    return fma(q2, fma(-0.5, q2, 1.0), p * p)


@njit(cache=True)
def energy(q, p):
    return 0.5 * energy2(q, p)


def check_integrator(integrator):
    if integrator not in INTEGRATORS:
        raise ValueError(f"integrator must be one of {sorted(INTEGRATORS)}, got {integrator!r}")
    return integrator


def sine_table(steps_per_cycle, Psi, integrator="srkn6b"):
    """sin(Omega t + Psi) at the force sub-times of every step of one period: (S, 7) for
    SRKN6b (7 kicks), (S, 3) for RK4 (t, t + h/2, t + h).  The width selects the scheme."""
    times = BM6_KICK_TIMES if check_integrator(integrator) == "srkn6b" else RK4_TIMES
    s = np.arange(steps_per_cycle, dtype=float)[:, None] + times[None, :]
    return np.ascontiguousarray(np.sin(2.0 * np.pi * s / steps_per_cycle + Psi))


def lane_coefficients(Omega, steps_per_cycle, integrator="srkn6b"):
    """Per-parameter-set step coefficients (n, 7): a1 h, a2 h, a3 h, b1 h, ..., b4 h
    (SRKN6b) or h/2, h, h/6, 0, 0, 0, 0 (RK4)."""
    Omega = np.atleast_1d(np.asarray(Omega, dtype=float))
    h = 2.0 * np.pi / (Omega * steps_per_cycle)
    out = np.zeros((Omega.size, 7))
    if check_integrator(integrator) == "srkn6b":
        out[:, 0:3] = h[:, None] * BM6_DRIFT[None, :3]
        out[:, 3:7] = h[:, None] * BM6_KICK[None, :4]
    else:
        out[:, 0:3] = h[:, None] * RK4_COEF[None, :]
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
    rk4 = sintab.shape[1] == 3
    base = period * S
    for s in range(s0, s1):
        if rk4:
            q, p = rk4_step(q, p, c[0], c[1], c[2], F * sintab[s, 0], F * sintab[s, 1], F * sintab[s, 2])
        else:
            q, p = bm6_step(q, p, c[0], c[1], c[2], c[3], c[4], c[5], c[6],
                            F * sintab[s, 0], F * sintab[s, 1], F * sintab[s, 2], F * sintab[s, 3],
                            F * sintab[s, 4], F * sintab[s, 5], F * sintab[s, 6])
        iE, iQ = _check_state(i, q, p, base + s + 1, thrE2, thrQ, iE, iQ, outE, outQ)
        if _finished(iE, iQ, nE, nQ, stop_any):
            break
    return iE, iQ


@njit(cache=True, inline="always")
def _keep(l, q, p, Q, P, ME, MQ):
    """Store lane l's new state and update its maxima of 2*H0 and |q| (branch free)."""
    Q[l] = q
    P[l] = p
    e = energy2(q, p)
    x = abs(q)
    m = ME[l]
    ME[l] = e if e > m else m
    m = MQ[l]
    MQ[l] = x if x > m else m


@njit(cache=True, inline="always")
def _period_shared_body(rk4, M, Q, P, ME, MQ, c, FS, s0, s1):
    """Steps [s0, s1) of the forcing period for lanes [0, 4M), all sharing one parameter set;
    ME, MQ = max 2*H0 and max |q| over these steps.  rk4 is a compile-time constant at
    every call site (inline body): one specialised loop per scheme.

    The lane loop (j) vectorises; its body advances 4 independent lanes j, M+j, 2M+j, 3M+j
    so that 4 dependency chains are in flight (the step is latency bound otherwise)."""
    c1 = c[0]; c2 = c[1]; c3 = c[2]; c4 = c[3]; c5 = c[4]; c6 = c[5]; c7 = c[6]
    for l in range(4 * M):
        ME[l] = -np.inf
        MQ[l] = -np.inf
    for s in range(s0, s1):
        f1, f2, f3, f4, f5, f6, f7 = _row(FS, s, rk4)
        for j in range(M):
            l0 = 0 * M + j
            l1 = 1 * M + j
            l2 = 2 * M + j
            l3 = 3 * M + j
            q0, p0 = step(rk4, Q[l0], P[l0], c1, c2, c3, c4, c5, c6, c7, f1, f2, f3, f4, f5, f6, f7)
            q1, p1 = step(rk4, Q[l1], P[l1], c1, c2, c3, c4, c5, c6, c7, f1, f2, f3, f4, f5, f6, f7)
            q2, p2 = step(rk4, Q[l2], P[l2], c1, c2, c3, c4, c5, c6, c7, f1, f2, f3, f4, f5, f6, f7)
            q3, p3 = step(rk4, Q[l3], P[l3], c1, c2, c3, c4, c5, c6, c7, f1, f2, f3, f4, f5, f6, f7)
            _keep(l0, q0, p0, Q, P, ME, MQ)
            _keep(l1, q1, p1, Q, P, ME, MQ)
            _keep(l2, q2, p2, Q, P, ME, MQ)
            _keep(l3, q3, p3, Q, P, ME, MQ)


@njit(cache=True)
def _period_shared(M, Q, P, ME, MQ, c, FS, s0, s1):
    """_period_shared_body for the scheme of the table FS (width 3: RK4, 7: SRKN6b)."""
    if FS.shape[1] == 3:
        _period_shared_body(True, M, Q, P, ME, MQ, c, FS, s0, s1)
    else:
        _period_shared_body(False, M, Q, P, ME, MQ, c, FS, s0, s1)


@njit(cache=True, inline="always")
def _lane_coefs(rk4, h):
    if rk4:
        return h * RK4_C1, h * RK4_C2, h * RK4_C3, 0.0, 0.0, 0.0, 0.0
    return h * DRIFT1, h * DRIFT2, h * DRIFT3, h * KICK1, h * KICK2, h * KICK3, h * KICK4


@njit(cache=True, inline="always")
def _period_lanes_body(rk4, M, Q, P, ME, MQ, HL, FL, sintab, s0, s1):
    """As _period_shared for lanes [0, 4M) with per-lane parameters: step h = HL[l] and
    amplitude F = FL[l].  The coefficients h*c_k and forcing values F*sin_k are formed in the
    loop: the same IEEE products as the precomputed ones of the shared path, so both paths
    give bitwise identical trajectories.  (One chain per iteration: with 4 chains and six
    arrays LLVM's runtime alias checks exceed its budget and the loop stays scalar.)"""
    n = 4 * M
    for l in range(n):
        ME[l] = -np.inf
        MQ[l] = -np.inf
    for s in range(s0, s1):
        t1, t2, t3, t4, t5, t6, t7 = _row(sintab, s, rk4)
        for l in range(n):
            F = FL[l]
            c1, c2, c3, c4, c5, c6, c7 = _lane_coefs(rk4, HL[l])
            q, p = step(rk4, Q[l], P[l], c1, c2, c3, c4, c5, c6, c7,
                        F * t1, F * t2, F * t3, F * t4, F * t5, F * t6, F * t7)
            _keep(l, q, p, Q, P, ME, MQ)


@njit(cache=True)
def _period_lanes(M, Q, P, ME, MQ, HL, FL, sintab, s0, s1):
    if sintab.shape[1] == 3:
        _period_lanes_body(True, M, Q, P, ME, MQ, HL, FL, sintab, s0, s1)
    else:
        _period_lanes_body(False, M, Q, P, ME, MQ, HL, FL, sintab, s0, s1)


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
    # the period is run in G segments; snapshots of (q, p) before each segment and the
    # segment maxima let a crossing be replayed over one segment only.  Segments cost a
    # snapshot per lane each; they pay off only while lanes cross thresholds, so a period
    # after one without any crossing runs as ONE segment (a crossing there is replayed over
    # the whole period; the recorded steps are the same either way)
    Gmax = SEGMENTS if S >= 4 * SEGMENTS else 1
    segs = np.empty((2, Gmax + 1), np.int64)
    for g in range(Gmax + 1):
        segs[0, g] = g * S // Gmax
        segs[1, g] = S if g > 0 else 0
    SQ = np.zeros((Gmax, Lmem))
    SP = np.zeros((Gmax, Lmem))
    SME = np.empty((Gmax, Lmem))
    SMQ = np.empty((Gmax, Lmem))
    nhit = np.int64(1)         # crossings at the last period boundary (first period: segmented)
    traj = np.empty(L, np.int64)
    per = np.empty(L, np.int64)
    lE = np.empty(L, np.int64)
    lQ = np.empty(L, np.int64)
    done = np.zeros(L, np.bool_)
    hit = np.zeros(L, np.bool_)
    tE = np.empty(L)      # next uncrossed 2*xi threshold of the lane (inf: none)
    tQ = np.empty(L)      # next uncrossed |q| threshold (or the barrier)
    inf = np.inf
    FS = Fpar[0] * sintab        # (S, 7) or (S, 3), shared path
    HL = np.zeros(Lmem)          # per-lane path
    FL = np.zeros(Lmem)

    nxt = np.int64(task)
    nact = np.int64(0)
    ndone = np.int64(0)        # lanes finished at the last period boundary
    while True:
        # ---------------------------------------------------- fill empty / finished lanes
        l = np.int64(0)
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
        G = Gmax if nhit > 0 else 1
        seg = segs[0] if nhit > 0 else segs[1]
        for g in range(G):
            for l in range(nact):
                SQ[g, l] = Q[l]
                SP[g, l] = P[l]
            # segment maxima go straight into the rows SME[g], SMQ[g]
            if shared:
                _period_shared(M, Q, P, SME[g], SMQ[g], coef[0], FS, seg[g], seg[g + 1])
            else:
                _period_lanes(M, Q, P, SME[g], SMQ[g], HL, FL, sintab, seg[g], seg[g + 1])
        # ---------------------------------------------------- period boundary
        # vectorised test first: only lanes whose maxima crossed a threshold (or, for the
        # map, every lane) need the scalar bookkeeping below
        for l in range(nact):
            hit[l] = False
        for g in range(G):
            for l in range(nact):
                hit[l] = hit[l] | (SME[g, l] > tE[l]) | (SMQ[g, l] > tQ[l])
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
                    if SME[g, l] > tE[l] or SMQ[g, l] > tQ[l]:
                        k = pidx[i]
                        iE, iQ = _replay(i, SQ[g, l], SP[g, l], per[l] - 1, seg[g], seg[g + 1], sintab,
                                         coef[k], Fpar[k], thrE2, thrQ, iE, iQ, outE, outQ, stop_any)
                        lE[l] = iE
                        lQ[l] = iQ
                        tE[l] = thrE2[iE] if iE < nE else inf
                        tQ[l] = thrQ[iQ] if iQ < nQ else inf
                        if iE < nE:
                            tQ[l] = min(tQ[l], Q_BARRIER)
                        if _finished(iE, iQ, nE, nQ, stop_any):
                            break
            fin = _finished(iE, iQ, nE, nQ, stop_any)
            if do_store and not fin and iE == 0 and iQ == 0:
                store[i, per[l], 0] = Q[l]
                store[i, per[l], 1] = P[l]
            d = fin or per[l] >= cycles
            ndone += d and not done[l]
            done[l] = d


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
    The scheme is the width of sintab (sine_table / lane_coefficients of the same integrator).
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
    rk4 = sintab.shape[1] == 3
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
                if rk4:
                    q, p = rk4_step(q, p, c[0], c[1], c[2], F * sintab[s, 0], F * sintab[s, 1],
                                    F * sintab[s, 2])
                else:
                    q, p = bm6_step(q, p, c[0], c[1], c[2], c[3], c[4], c[5], c[6],
                                    F * sintab[s, 0], F * sintab[s, 1], F * sintab[s, 2],
                                    F * sintab[s, 3], F * sintab[s, 4], F * sintab[s, 5],
                                    F * sintab[s, 6])
        qo[i] = q
        po[i] = p
    return qo, po
