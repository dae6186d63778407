"""CUDA kernels (numba-cuda) for the escape ensembles of q'' + V'(q) = F sin(Omega t + Psi).

The GPU twin of kernels.py: same schemes (schemes.py: each a constant, its step generated once by
scheme_code.py and compiled here as a device function), same
wells (the one compiled form of a well, wells.compiled.WellCode: the SAME Python source of its force
and energy, compiled here as device functions), same forcing tables, same escape
criteria, and the SAME SEQUENCE OF IEEE OPERATIONS per trajectory, so the recorded
first-crossing steps are bitwise equal to the CPU engine's.

Bitwise equality: fused multiply-adds and contraction
------------------------------------------------------
The CPU lanes write every fused multiply-add explicitly (llvm.fma) and keep every other product
as a separate, rounded multiply (numba's CPU target never contracts).  NVVM, in contrast,
contracts a*b + c into one fma by default (-fma=1; numba-cuda turns it off for no option but
fastmath, which would also flush denormals and relax division), and ptxas may do the same with
PTX mul/add pairs that carry no rounding modifier.  Contraction needs an add or subtract whose
operand is the result of a multiply; this module leaves no such pair:

* every product the CPU forms OUTSIDE an fma is computed on the host instead, with numpy, in
  exactly the CPU's form: the forcing values F * sin(Omega t_k + Psi) are the table
  FS[k, s, j] = F[k] * sine_table[s, j] (the CPU's shared path precomputes the same products,
  its replay and per-lane paths form the same IEEE products in the loop), and the step
  coefficients h * a_k, h * b_k are schemes.lane_coefficients (the CPU's replay uses the same
  array);
* the products that remain in the kernel, q*q in the force and q*q, p*p in the energy, feed
  only explicit fma instructions (as a multiplicand or as the addend), never an add: an fma
  cannot absorb a further product, so nothing can be fused (the polynomial force is a chain
  of fma only, its energy fma(h, q*q, p*p));
* RK4's sums (p2 + p3 etc.) contain no product.  LLVM may rewrite s + s as s * 2.0 and NVVM
  then fuse that into fma(s, 2, x): doubling is exact, so round(x + 2 s) is the same number
  either way (short of overflow, long after escape).
* a well written as an expression writes every product with wells.compiled.mul (mul.rn.f64 here:
  never contracted).
No fast-math anywhere; no division and no transcendental in the kernel (sin is in the host
table), except what a well's own formula contains: IEEE division and sqrt are correctly rounded
on both targets, but transcendental functions come from libdevice here and glibc on the CPU, so
a well with sin, exp, ... may differ from the CPU in the last bit (wells.compiled docstring).
FP64 has no flush-to-zero on the GPU.  benchmarks/bench_gpu.py counts the f64 instructions of
the compiled kernel and the multiplies that feed an add (must be none), and compares the escape
steps with the CPU engine.  On an H100 (numba-cuda 0.30.4) the SASS has exactly the PTX's DFMA
and DMUL counts (nothing fused) and the Fig 21 chart (90,000 ICs, 11,000 cycles) and a dense
1e5-trajectory job gave 0 differing escape steps for both schemes.

The simulator (NUMBA_ENABLE_CUDASIM=1) implements cuda.fma as a*b + c (two roundings); under
the simulator the wells' `fma` (wells.compiled.fma) runs its Python body, the CPU's correctly rounded
llvm.fma, so the simulator runs the same arithmetic as the GPU.

Kernel organisation (one thread = one trajectory at a time)
-----------------------------------------------------------
* Escape check after every step, as on the CPU but without the CPU's segment maxima and
  replay: the step of first crossing is recorded directly.  A branch-free filter (2 H0 > next
  uncrossed 2 xi_max, or |q| > next uncrossed q_max or the barrier) guards the exact scalar
  bookkeeping, which is well_loops._check_state line for line.
* Persistent threads: the grid holds no more blocks than the GPU keeps resident; a thread
  whose trajectory is finished (every threshold crossed, any with stop_any, or the horizon
  reached) takes the next one from a global atomic counter at the period boundary.  The
  forcing is periodic, so every thread of a block stays at the same sub-step of the period
  and reads the same table row (a broadcast from shared memory).  The counter hands
  trajectories out in a scrambled order i = c * A mod N (A coprime to N): escape times are
  spatially clustered in an initial-condition grid, and the scrambling spreads the long-lived
  ones evenly over blocks and SMs.
* Compaction: once the queue is empty, finished trajectories leave holes that would keep
  half-empty warps running at full cost (a chart where 90% escape in 10 cycles would run at
  the speed of its slowest trajectory in every warp).  At a period boundary where the live
  trajectories of a block fit in fewer warps than they occupy, the block packs them into its
  first lanes (state through shared memory); the freed warps exit.  Moving a trajectory to
  another lane does not change its arithmetic.
* Forcing table in shared memory when it fits (one parameter set: S * 7 doubles); many
  parameter sets (bisection) read it from global memory (cached).
* The well is the kernel factory's compiled well (wells.compiled.WellCode): its force -V'(q) + f and
  energy 2 H0 compiled from the one source (make_step, the coefficients w loaded from `wpar`
  once per thread; a split well's V'(q) carried in a register from step to step, as the CPU
  lanes carry it) and its escape tests (make_criteria): |q| tracking compares |q| with the
  q_max thresholds and the barrier, signed tracking compares q with the bound pairs (lo, hi)
  and the barriers (q_left, q_right), as well_loops._check_state.
"""
from __future__ import annotations

import functools
import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numba import cuda, float64, int32, int64, uint64
from numba.cuda.core import config as cuda_config

from safebasins.numerics import schemes
from safebasins.wells import compiled
from safebasins.numerics.scheme_code import SchemeCode, scheme_code
from safebasins.numerics.steps import Floats, Int, Ints, Row, Step

SIMULATOR = bool(cuda_config.ENABLE_CUDASIM)
BLOCK = 128                          # threads per block on a GPU
WARP = 32
# forcing-table and coefficient offsets are unsigned (scheme_code's flat_row / flat_coefs): numba
# wraps negative signed indices around (a compare, select and add per load, five 64-bit integer
# instructions on each of the 7 loads of a step, which made the step issue-bound); unsigned +
# unsigned stays unsigned (unsigned + signed would be float64 in numba's typing)
# forcing tables up to this size go to shared memory (48 KiB needs no opt-in; leave room for
# the compaction buffers and for several blocks per SM)
SHARED_TABLE_BYTES = 16 * 1024


def _device(fn: Callable[..., Any]) -> Any:
    return cuda.jit(device=True)(fn)


# the GPU's primitives of the wells' one source (wells.compiled.fma / mul): fma.rn.f64 and
# mul.rn.f64 (a rounded product the compiler may not contract).  Under the simulator the device
# functions run as Python and the primitives' Python bodies are the CPU's correctly rounded ones.
if not SIMULATOR:
    from numba.cuda import libdevice
    from numba.cuda.extending import overload as cuda_overload

    # an overload's implementation takes its parameters with the same annotations (numba compares them)
    @cuda_overload(compiled.fma, inline="always")
    def _ol_fma(a: Any, b: Any, c: Any) -> Callable[..., float]:
        def impl(a: Any, b: Any, c: Any) -> float:
            return cuda.fma(a, b, c)  # type: ignore[no-any-return]  # numba-cuda's fma.rn.f64 (a float)
        return impl

    @cuda_overload(compiled.mul, inline="always")
    def _ol_mul(a: Any, b: Any) -> Callable[..., float]:
        def impl(a: Any, b: Any) -> float:
            return libdevice.dmul_rn(a, b)  # type: ignore[no-any-return]  # mul.rn.f64 (a float)
        return impl

fma = compiled.fma


# ------------------------------------------------------------------------------- the well and the scheme
def make_step(code: compiled.WellCode, sc: SchemeCode) -> tuple[Any, Any, Any, Any]:
    """(step, energy2, flat_coefs, first) device functions of a compiled well
    (wells.compiled.WellCode) and a scheme code (scheme_code.SchemeCode): the well's one source and
    the scheme's one generated source, compiled for the GPU.

    step(q, p, c, tab, o, w, d) -> (q, p, d, e) reads the forcing values tab[o], tab[o+1], ...
    (already multiplied by F; o unsigned) and calls the scheme's step with them; c the coefficient
    tuple (flat_coefs(coef, o): schemes.lane_coefficients of one parameter set), w the well's 14
    coefficients (steps.wtuple); e = 2 H0 after the step.  A well with a split force
    (WellCode.split) runs the scheme's split step: d = V'(q) carried from step to step
    (``first(q, w)`` where a trajectory starts or moves), V(q) of e from the last kick's call (the
    same bits, fewer evaluations: scheme_code); any other well ignores d (``first`` is 0).
    energy2(q, p, w) = 2 H0 of the well."""
    energy_w: Callable[[compiled.Coefs, float, float], float]
    force, energy_w = code.make(_device)
    H = sc.helpers(_device)
    flat_row = H["flat_row"]

    @_device
    def energy2w(q: float, p: float, w: compiled.Coefs) -> float:
        return energy_w(w, q, p)

    if code.split is None:
        inner: Step = sc.make(_device, force)

        @_device
        def step(q: float, p: float, c: Row, tab: Floats, o: np.uint64, w: compiled.Coefs,
                 d: float) -> tuple[float, float, float, float]:
            q, p = inner(w, q, p, c, flat_row(tab, o))
            return q, p, d, energy_w(w, q, p)

        @_device
        def first(q: float, w: compiled.Coefs) -> float:
            return 0.0
    else:
        gradient, gradient_potential = code.split(_device)
        split = sc.make_split(_device, gradient, gradient_potential, _device(compiled.force_from))
        energy2_from = _device(compiled.energy2_from)

        @_device
        def step(q: float, p: float, c: Row, tab: Floats, o: np.uint64, w: compiled.Coefs,
                 d: float) -> tuple[float, float, float, float]:
            q, p, d, v = split(w, q, p, c, flat_row(tab, o), d)
            return q, p, d, energy2_from(w, v, p)

        @_device
        def first(q: float, w: compiled.Coefs) -> float:
            return gradient(w, q)  # type: ignore[no-any-return]  # a device function (numba-cuda dispatcher)

    return step, energy2w, H["flat_coefs"], first


# ------------------------------------------------------------------------------- escape bookkeeping
def make_criteria(abs_q: bool) -> tuple[Any, Any, Any]:
    """(crossed, check_state, next_filters) for |q| tracking (abs_q, the quartic) or signed tracking:

    crossed(e, q, tE, tQ, tN): the branch-free filter (2 H0 above the next uncrossed 2 xi_max, q
    beyond the next uncrossed bound or, while an energy threshold is uncrossed, a barrier);
    check_state(i, e, q, step, thrE2, nE, thrLo, thrHi, nQ, iE, iQ, outE, outQ, qL, qR):
    well_loops._check_state with e = energy2(q, p): record `step` for every next uncrossed threshold
    the state is beyond (outE, outQ flat, row i);
    next_filters(iE, iQ, thrE2, nE, thrLo, thrHi, nQ, qL, qR) -> (tE, tQ, tN) as kernels._filters.
    |q| tracking compares |q| with thrHi (the q_max) and the barrier qR; signed tracking compares
    q with (thrLo, thrHi) and the barriers (qL, qR).  Every comparison is `not x <= t`, as on the
    CPU: a NaN state is beyond every threshold."""
    if abs_q:
        @_device
        def crossed(e: float, q: float, tE: float, tQ: float, tN: float) -> bool:
            return not e <= tE or not abs(q) <= tQ

        @_device
        def check_state(i: Int, e: float, q: float, step: Int, thrE2: Floats, nE: Int, thrLo: Floats, thrHi: Floats,
                        nQ: Int, iE: Int, iQ: Int, outE: Ints, outQ: Ints, qL: float, qR: float) -> tuple[Int, Int]:
            aq = abs(q)
            while iE < nE and (not e <= thrE2[iE] or not aq <= qR):
                outE[i * nE + iE] = step
                iE += 1
            while iQ < nQ and not aq <= thrHi[iQ]:
                outQ[i * nQ + iQ] = step
                iQ += 1
            return iE, iQ

        @_device
        def next_filters(iE: Int, iQ: Int, thrE2: Floats, nE: Int, thrLo: Floats, thrHi: Floats, nQ: Int, qL: float,
                         qR: float) -> tuple[float, float, float]:
            tE = math.inf
            tQ = math.inf
            if iQ < nQ:
                tQ = thrHi[iQ]
            if iE < nE:
                tE = thrE2[iE]
                if qR < tQ:
                    tQ = qR
            return tE, tQ, math.inf
    else:
        @_device
        def crossed(e: float, q: float, tE: float, tQ: float, tN: float) -> bool:
            return not e <= tE or not q <= tQ or not -q <= tN

        @_device
        def check_state(i: Int, e: float, q: float, step: Int, thrE2: Floats, nE: Int, thrLo: Floats, thrHi: Floats,
                        nQ: Int, iE: Int, iQ: Int, outE: Ints, outQ: Ints, qL: float, qR: float) -> tuple[Int, Int]:
            out = not q <= qR or not q >= qL
            while iE < nE and (not e <= thrE2[iE] or out):
                outE[i * nE + iE] = step
                iE += 1
            while iQ < nQ and (not q <= thrHi[iQ] or not q >= thrLo[iQ]):
                outQ[i * nQ + iQ] = step
                iQ += 1
            return iE, iQ

        @_device
        def next_filters(iE: Int, iQ: Int, thrE2: Floats, nE: Int, thrLo: Floats, thrHi: Floats, nQ: Int, qL: float,
                         qR: float) -> tuple[float, float, float]:
            tE = math.inf
            tQ = math.inf
            tN = math.inf
            if iQ < nQ:
                tQ = thrHi[iQ]
                tN = -thrLo[iQ]
            if iE < nE:
                tE = thrE2[iE]
                if qR < tQ:
                    tQ = qR
                if -qL < tN:
                    tN = -qL
            return tE, tQ, tN
    return crossed, check_state, next_filters


@_device
def finished(iE: Int, iQ: Int, nE: Int, nQ: Int, stop_any: bool) -> bool | np.bool_:
    return (iE == nE and iQ == nQ) or (stop_any and (iE > 0 or iQ > 0))


# ------------------------------------------------------------------------------- the kernel
@functools.cache
def ensemble_kernel(integrator: str = "srkn6b", shared_table: bool = True, block: int = BLOCK, warp: int = WARP,
                    well: compiled.WellCode | None = None, damped: bool = False) -> Any:
    """The compiled ensemble kernel for one scheme and well (cached per argument set).

    integrator: a name of schemes.SCHEMES; shared_table: copy the forcing table into dynamic shared
    memory (launch with its size in bytes); block: threads per block (static shared buffers);
    warp: compaction granularity (32 on a GPU; smaller values exercise compaction in the
    simulator); well: the compiled well (wells.compiled.WellCode; None: the quartic); damped: the
    scheme's damped variant (coefficients from schemes.lane_coefficients with the damping).

    Launch: kernel[grid, block, 0, table_bytes if shared_table else 0](
        q0, p0, pidx, coef, FS, thrE2, nE, thrLo, thrHi, nQ, N, S, cycles, stop_any, A, counter,
        outE, outQ, wpar)
    q0, p0 (N,) float64; pidx (N,) int64; coef (P*NC,) lane_coefficients (NC per parameter set);
    FS (P*S*W,) the forcing products F[k] * sine_table (W the scheme's width); thrE2 (>= max(nE, 1),) sorted 2*xi_max;
    thrLo, thrHi (>= max(nQ, 1),) the nested displacement bounds, inside out (|q| tracking: thrHi
    = sorted q_max, thrLo unused); A: scrambling multiplier (coprime to N); counter (1,) int64
    = 0; outE (N*nE,), outQ (N*nQ,) int64 pre-filled with -1; wpar (steps.N_WPAR,) the well's
    barriers and coefficients (wells.compiled.WellCode.wpar).
    """
    sc = scheme_code(schemes.check_integrator(integrator), bool(damped))
    UW = np.uint64(sc.width)
    code = compiled.quartic_code() if well is None else well
    if not isinstance(code, compiled.WellCode):
        raise ValueError(f"well must be a compiled well (wells.compiled.WellCode), got {well!r}")
    step, energy2w, flat_coefs, first = make_step(code, sc)
    crossed, check_state, next_filters = make_criteria(code.abs_tracking)
    NC = np.uint64(sc.n_coef)
    SHARED = bool(shared_table)
    BLK = int(block)
    WRP = int(warp)
    if BLK % WRP:
        raise ValueError(f"block ({BLK}) must be a multiple of warp ({WRP})")

    def ensemble(q0: Floats, p0: Floats, pidx: Ints, coef: Floats, FS: Floats, thrE2: Floats, nE: Int, thrLo: Floats,
                 thrHi: Floats, nQ: Int, N: Int, S: Int, cycles: Int, stop_any: bool, A: Int, counter: Ints,
                 outE: Ints, outQ: Ints, wpar: Floats) -> None:
        tid = cuda.threadIdx.x
        qL = wpar[0]
        qR = wpar[1]
        w = (wpar[2], wpar[3], wpar[4], wpar[5], wpar[6], wpar[7], wpar[8],
             wpar[9], wpar[10], wpar[11], wpar[12], wpar[13], wpar[14], wpar[15])
        # compaction buffers (one slot per lane) and the slot counter
        bq = cuda.shared.array(BLK, float64)
        bp = cuda.shared.array(BLK, float64)
        bi = cuda.shared.array(BLK, int64)
        bk = cuda.shared.array(BLK, int64)
        bper = cuda.shared.array(BLK, int64)
        bE = cuda.shared.array(BLK, int32)
        bQ = cuda.shared.array(BLK, int32)
        cnt = cuda.shared.array(1, int32)
        if SHARED:
            tab = cuda.shared.array(0, float64)
            for j in range(tid, FS.shape[0], BLK):
                tab[j] = FS[j]
        else:
            tab = FS
        if tid == 0:
            cnt[0] = 0
        cuda.syncthreads()

        uSW = uint64(S) * UW
        live = False
        empty = False
        nlive_c = BLK             # live lanes lie in [0, nlive_c) (after the last compaction)
        i = int64(0)
        k = int64(0)
        per: Int = int64(0)
        iE = int64(0)
        iQ = int64(0)
        q = 0.0
        p = 0.0
        tE = math.inf
        tQ = math.inf
        tN = math.inf
        cf = flat_coefs(coef, uint64(0))
        d = 0.0
        reload = False
        while True:
            # ---------------------------------------------- take the next trajectory
            if not live and not empty:
                while True:
                    c = cuda.atomic.add(counter, 0, 1)
                    if c >= N:
                        empty = True
                        break
                    i = (c * A) % N
                    q = q0[i]
                    p = p0[i]
                    iE, iQ = check_state(i, energy2w(q, p, w), q, 0, thrE2, nE, thrLo, thrHi, nQ, 0, 0,
                                         outE, outQ, qL, qR)
                    if finished(iE, iQ, nE, nQ, stop_any):
                        continue
                    k = pidx[i]
                    per = 0
                    live = True
                    reload = True
                    break
            nlive = cuda.syncthreads_count(1 if live else 0)
            if nlive == 0:
                break             # every lane idle and the queue empty: uniform exit
            # ---------------------------------------------- compaction (queue exhausted)
            if cuda.syncthreads_or(1 if empty else 0) and (nlive + WRP - 1) // WRP < (nlive_c + WRP - 1) // WRP:
                if live:
                    slot = cuda.atomic.add(cnt, 0, 1)
                    bq[slot] = q
                    bp[slot] = p
                    bi[slot] = i
                    bk[slot] = k
                    bper[slot] = per
                    bE[slot] = iE
                    bQ[slot] = iQ
                cuda.syncthreads()
                live = tid < nlive
                if live:
                    q = bq[tid]
                    p = bp[tid]
                    i = bi[tid]
                    k = bk[tid]
                    per = bper[tid]
                    iE = int64(bE[tid])
                    iQ = int64(bQ[tid])
                    reload = True
                if tid == 0:
                    cnt[0] = 0
                nlive_c = nlive
                cuda.syncthreads()
            if not live:
                # idle lanes stay in the loop (every lane must reach the block barriers); a warp
                # of idle lanes issues no arithmetic and only waits at the barriers
                continue
            if reload:
                cf = flat_coefs(coef, uint64(k) * NC)
                tE, tQ, tN = next_filters(iE, iQ, thrE2, nE, thrLo, thrHi, nQ, qL, qR)
                d = first(q, w)
                reload = False
            # ---------------------------------------------- one forcing period
            o = uint64(k) * uSW
            base = per * S
            for s in range(S):
                q, p, d, e = step(q, p, cf, tab, o, w, d)
                o += UW
                if crossed(e, q, tE, tQ, tN):
                    iE, iQ = check_state(i, e, q, base + s + 1, thrE2, nE, thrLo, thrHi, nQ, iE, iQ, outE, outQ,
                                         qL, qR)
                    if finished(iE, iQ, nE, nQ, stop_any):
                        live = False
                        break
                    tE, tQ, tN = next_filters(iE, iQ, thrE2, nE, thrLo, thrHi, nQ, qL, qR)
            if live:
                per += 1
                if per >= cycles:
                    live = False

    sig = ("void(float64[::1], float64[::1], int64[::1], float64[::1], float64[::1], float64[::1], int64, "
           "float64[::1], float64[::1], int64, int64, int64, int64, boolean, int64, int64[::1], int64[::1], "
           "int64[::1], float64[::1])")
    return cuda.jit(sig)(ensemble)
