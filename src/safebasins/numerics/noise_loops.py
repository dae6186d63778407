"""The well's part of the noisy lanes (noise_kernels._escape_task): one step of every active lane
with its variates and the escape checks after it, and the checks of an initial condition,
compiled per scheme and well and called by the lanes' machinery through function pointers
(:func:`numerics.well_loops.pointer`, as the deterministic engine's).

The machinery (the Philox variates, the lanes' refill and compaction, the period boundary) holds
nothing of the well but calls of these two functions, so it is compiled once per scheme, law and
colour of the noise, and a new well compiles these two only.  They are specialised on the numba
literals of the scheme's and the well's keys, the noise code's key (``rng``: noise_kernels.RNG_KEY,
which hashes this file) and whether the noise is coloured; the keys stay plain integers in the
pointer's signature.
"""
from __future__ import annotations

from typing import Any

from numba import types
from numba.extending import overload

from safebasins.core.numba_target import package_jit, pointer_jit
from safebasins.numerics.steps import Floats, Int, Ints, coefs, row, step, wtuple
from safebasins.numerics.well_loops import Pointer, pointer
from safebasins.wells.compiled import LLVM_INLINE, abs_tracking, fma, mul, well_energy2

__all__ = ["plus", "beyond", "steps_pointer", "enter_pointer"]


def plus(f: Any, x: Any) -> Any:
    """The tuple f with x added to each value (the forcing values plus the coloured noise)."""
    raise NotImplementedError("compiled code (numba)")


@overload(plus, jit_options=LLVM_INLINE)
def _ol_plus(f: Any, x: Any) -> Any:
    n = f.count
    ns: dict[str, Any] = {"Any": Any}
    # (numba compares the implementation's parameter annotations with the overload's)
    exec(f"def impl(f: Any, x: Any) -> Any:\n    return ({''.join(f'f[{j}] + x, ' for j in range(n))})", ns)
    return ns["impl"]


@package_jit(cache=True, inline="always", error_model="numpy")
def beyond(well: Any, wpar: Any, q: Any, e: Any, thrE2: Any, lo: Any, hi: Any) -> bool:
    """The engine's criteria (well_loops._check_state) for one energy threshold and one bound pair:
    written ``not x <= t`` so that a NaN state is beyond."""
    if abs_tracking(well):
        barrier = not abs(q) <= wpar[1]
    else:
        barrier = (not q <= wpar[1]) | (not q >= wpar[0])
    return (not e <= thrE2) | barrier | (not q <= hi) | (not q >= lo)


@pointer_jit(cache=True, nogil=True, error_model="numpy")
def _lane_steps(scheme: int, well: int, rng: int, coloured: bool, wpar: Floats, nact: Int, s: int, Q: Floats,
                P: Floats, E: Floats, Z1: Floats, Z2: Floats, EN: Floats, FIRST: Any, BASE: Ints, coef: Any,
                FS: Floats, thrE2: Floats, lo: float, hi: float, amp: float, shift: float, c1: float,
                c2: float) -> None:
    """Sub-step s of the period for lanes [0, nact): the step with the lanes' variates Z1, Z2
    (half kicks of the white noise around it; coloured: the Ornstein-Uhlenbeck force eta, E,
    advanced by half steps around it and added to the forcing), then the lanes' first steps
    beyond each threshold (FIRST[r]: -1 until then) and their checked energies EN."""
    w = wtuple(wpar)
    c = coefs(scheme, coef[0])
    f = row(scheme, FS, s)
    # separate lane loops for the step and the checks (one fused body spills registers: measured
    # 25% slower); the same numbers either way
    for l in range(nact):
        z1 = Z1[l]
        z2 = Z2[l]
        if coloured:
            eta = fma(c2, z1, mul(c1, E[l]))
            q, p = step(scheme, well, w, Q[l], fma(amp, z1, P[l]), c, plus(f, eta))
            E[l] = fma(c2, z2, mul(c1, eta))
        else:                    # white noise: no eta to carry or add
            q, p = step(scheme, well, w, Q[l], fma(amp, z1, P[l]), c, f)
        p = fma(amp, z2, p)
        Q[l] = q
        P[l] = p
    F0 = FIRST[0]
    t0 = thrE2[0]
    for l in range(nact):
        q = Q[l]
        p = P[l]
        e = fma(shift, abs(p), well_energy2(well, w, q, p))
        EN[l] = e
        hit = beyond(well, wpar, q, e, t0, lo, hi) & (F0[l] < 0)
        F0[l] = BASE[l] + s + 1 if hit else F0[l]
    for r in range(1, thrE2.shape[0]):        # the further thresholds: one pass each
        Fr = FIRST[r]
        t = thrE2[r]
        for l in range(nact):
            hit = beyond(well, wpar, Q[l], EN[l], t, lo, hi) & (Fr[l] < 0)
            Fr[l] = BASE[l] + s + 1 if hit else Fr[l]


@pointer_jit(cache=True, nogil=True, error_model="numpy")
def _lane_enter(scheme: int, well: int, rng: int, wpar: Floats, q: float, p: float, thrE2: Floats, lo: float,
                hi: float, FIRST: Any, k: Int) -> None:
    """FIRST[r, k] = 0 where the initial condition (q, p) is beyond threshold r, else -1."""
    e = well_energy2(well, wtuple(wpar), q, p)
    for r in range(thrE2.shape[0]):
        FIRST[r, k] = 0 if beyond(well, wpar, q, e, thrE2[r], lo, hi) else -1


def steps_pointer(scheme: int, well: int, rng: int, coloured: bool, wpar: types.Array, lane: types.Array,
                  FIRST: types.Array, BASE: types.Array, coef: types.Array, FS: types.Array,
                  thrE2: types.Array) -> Pointer:
    """:func:`_lane_steps` for the machinery's argument types (``lane``: a float lane array)."""
    i64, f64 = types.int64, types.float64
    return pointer(_lane_steps, (scheme, well, rng, coloured),
                   (wpar, i64, i64, lane, lane, lane, lane, lane, lane, FIRST, BASE, coef, FS, thrE2, f64, f64, f64,
                    f64, f64, f64))


def enter_pointer(scheme: int, well: int, rng: int, wpar: types.Array, thrE2: types.Array,
                  FIRST: types.Array) -> Pointer:
    """:func:`_lane_enter` for the machinery's argument types."""
    i64, f64 = types.int64, types.float64
    return pointer(_lane_enter, (scheme, well, rng), (wpar, f64, f64, thrE2, f64, f64, FIRST, i64))

