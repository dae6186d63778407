"""The well's part of the lane machinery: the period loop over the lanes, the scalar replay of a
segment and the check of a state, compiled per scheme and well and called by the machinery
(kernels._run_task) through function pointers.

The machinery (the lanes' refill and compaction, the period boundary's bookkeeping) holds nothing
of the well but calls of these three functions.  It is compiled once per scheme (and shared flag
and kind of tracking), cached on disk, and takes them as first-class function values (numba's
``types.FunctionType``): each is one specialisation, on the numba literals of the scheme's and
the well's keys, of a cached dispatcher of this module (the period loop: the shared path's or the
per-lane path's), reached through its C-callable wrapper (:func:`pointer`; these are the
package's functions that keep one: ``core.numba_target.pointer_jit``).  A new well compiles its
three, not the machinery again.
The keys stay arguments of the pointer's signature, as plain integers that the specialisation
ignores (they are its compile-time constants); the scheme key, which hashes the engine's source,
keys every cache entry, so an edit of the engine never reuses one.
"""
from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numba import types
from numba.core.typing.templates import Signature

from safebasins.core.numba_target import kernel_compile, package_jit, pointer_jit
from safebasins.numerics.periods import _period_lanes_body, _period_shared_body
from safebasins.numerics.steps import Floats, Int, Ints, coefs, scaled_row, step, wtuple
from safebasins.wells.compiled import abs_tracking, well_energy2

__all__ = ["Pointer", "pointer", "finished", "period_pointer", "replay_pointer", "check_pointer", "PeriodFn",
           "ReplayFn", "CheckFn"]

#: the machinery's view of the three (what it passes; the keys as plain integers)
PeriodFn = Callable[..., None]
ReplayFn = Callable[..., tuple[Int, Int]]
CheckFn = Callable[..., tuple[Int, Int]]


# takes the scheme key, unused, for its cache entry: keyed by the well alone, the cache would not see
# an edit of steps.py
@pointer_jit(cache=True, nogil=True)
def _check_state(scheme: int, well: int, wpar: Floats, i: Int, q: float, p: float, step: Int, thrE2: Floats,
                 thrLo: Floats, thrHi: Floats, iE: Int, iQ: Int, outE: Ints, outQ: Ints) -> tuple[Int, Int]:
    """Record, at `step`, every next-uncrossed threshold the state (q, p) is beyond."""
    e = well_energy2(well, wtuple(wpar), q, p)
    nE = thrE2.shape[0]
    nQ = thrHi.shape[0]
    # comparisons are written `not x <= t`: a NaN state is beyond every threshold (escaped,
    # never safe)
    if abs_tracking(well):
        aq = abs(q)
        while iE < nE and (not e <= thrE2[iE] or not aq <= wpar[1]):
            outE[i, iE] = step
            iE += 1
        while iQ < nQ and not aq <= thrHi[iQ]:
            outQ[i, iQ] = step
            iQ += 1
    else:
        out = not q <= wpar[1] or not q >= wpar[0]
        while iE < nE and (not e <= thrE2[iE] or out):
            outE[i, iE] = step
            iE += 1
        while iQ < nQ and (not q <= thrHi[iQ] or not q >= thrLo[iQ]):
            outQ[i, iQ] = step
            iQ += 1
    return iE, iQ


@package_jit(cache=True, inline="always")
def finished(iE: Int, iQ: Int, nE: int, nQ: int, stop_any: bool) -> bool | np.bool_:
    return (iE == nE and iQ == nQ) or (stop_any and (iE > 0 or iQ > 0))


@pointer_jit(cache=True, nogil=True)
def _replay(scheme: int, well: int, wpar: Floats, i: Int, q: float, p: float, period: Int, s0: Int, s1: Int,
            sintab: Floats, c: Floats, F: float, thrE2: Floats, thrLo: Floats, thrHi: Floats, iE: Int, iQ: Int,
            outE: Ints, outQ: Ints, stop_any: bool) -> tuple[Int, Int]:
    """Scalar replay of steps [s0, s1) of a period from the state before step s0 (same
    arithmetic as the vector loop); records the step of first crossing of every threshold
    crossed there."""
    S = sintab.shape[0]
    nE = thrE2.shape[0]
    nQ = thrHi.shape[0]
    w = wtuple(wpar)
    base = period * S
    cc = coefs(scheme, c)
    for s in range(s0, s1):
        q, p = step(scheme, well, w, q, p, cc, scaled_row(scheme, sintab, s, F))
        iE, iQ = _check_state(scheme, well, wpar, i, q, p, base + s + 1, thrE2, thrLo, thrHi, iE, iQ, outE, outQ)
        if finished(iE, iQ, nE, nQ, stop_any):
            break
    return iE, iQ


# the period loop: the body of the shared path (one parameter set: coef[0] and the scaled table FS)
# or of the per-lane path, called directly (every compiled function between the machinery and the
# loop is one more O3 pass over the linked loop, ~0.2-0.4 s at the first compile); one signature
@pointer_jit(cache=True, nogil=True)
def _shared_period(scheme: int, well: int, wpar: Floats, M: Int, Q: Floats, P: Floats, D: Floats, ME: Floats,
                   MQ: Floats, MN: Floats, coef: Floats, FS: Floats, HL: Floats, CL: Floats, FL: Floats,
                   sintab: Floats, s0: Int, s1: Int) -> None:
    """Steps [s0, s1) of the period, every lane with the parameter set coef[0]."""
    _period_shared_body(scheme, well, wpar, M, Q, P, D, ME, MQ, MN, coef[0], FS, s0, s1)


@pointer_jit(cache=True, nogil=True)
def _lanes_period(scheme: int, well: int, wpar: Floats, M: Int, Q: Floats, P: Floats, D: Floats, ME: Floats,
                  MQ: Floats, MN: Floats, coef: Floats, FS: Floats, HL: Floats, CL: Floats, FL: Floats,
                  sintab: Floats, s0: Int, s1: Int) -> None:
    """Steps [s0, s1) of the period, each lane with its own step, amplitude and coefficients."""
    _period_lanes_body(scheme, well, wpar, M, Q, P, D, ME, MQ, MN, HL, CL, FL, sintab, s0, s1)


class Pointer(types.CompileResultWAP):
    """A compiled specialisation as a first-class function value: its C wrapper's address, and its
    signature with the literal arguments as their plain types (what the caller passes)."""

    def __init__(self, cres: Any) -> None:      # numba's CompileResult: fields mypy cannot read
        super().__init__(cres)
        sig = cres.signature
        self._plain: Signature = sig.return_type(*(types.unliteral(a) for a in sig.args))

    def signature(self) -> Signature:
        return self._plain


def pointer(dispatcher: Any, literals: Sequence[object], args: Sequence[types.Type]) -> Pointer:
    """The specialisation of ``dispatcher`` on the numba literals ``literals`` followed by the
    argument types ``args``, compiled (or loaded from the disk cache) on first use, as a
    function pointer."""
    sig = tuple(types.literal(v) for v in literals) + tuple(args)
    ptr = _POINTERS.get((dispatcher, sig))
    if ptr is None:
        with kernel_compile():
            dispatcher.compile(sig)
        ptr = _POINTERS[(dispatcher, sig)] = Pointer(dispatcher.overloads[sig])
    return ptr


_POINTERS: dict[tuple[Any, tuple[types.Type, ...]], Pointer] = {}


def _row(t: types.Array) -> types.Array:
    """The type of ``a[i]`` for an array ``a`` of type ``t`` (numba's rule)."""
    row: types.Array = t.copy(ndim=t.ndim - 1, layout="C" if t.layout == "C" else "A")
    return row


def period_pointer(shared: bool, scheme: int, well: int, wpar: types.Array, coef: types.Array, FS: types.Array,
                   lane_f: types.Array, snap: types.Array, SMN: types.Array, CL: types.Array,
                   sintab: types.Array) -> Pointer:
    """:func:`_shared_period` (``shared``) or :func:`_lanes_period` for the machinery's argument
    types (its work arrays' rows)."""
    f = _row(lane_f)
    return pointer(_shared_period if shared else _lanes_period, (scheme, well),
                   (wpar, types.int64, f, f, f, _row(_row(snap)), _row(_row(snap)), _row(SMN), coef, FS, f, CL, f,
                    sintab, types.int64, types.int64))


def replay_pointer(scheme: int, well: int, wpar: types.Array, sintab: types.Array, coef: types.Array,
                   thrE2: types.Array, thrLo: types.Array, thrHi: types.Array, outE: types.Array,
                   outQ: types.Array) -> Pointer:
    """:func:`_replay` for the machinery's argument types."""
    i64, f64 = types.int64, types.float64
    return pointer(_replay, (scheme, well),
                   (wpar, i64, f64, f64, i64, i64, i64, sintab, _row(coef), f64, thrE2, thrLo, thrHi, i64, i64, outE,
                    outQ, types.boolean))


def check_pointer(scheme: int, well: int, wpar: types.Array, thrE2: types.Array, thrLo: types.Array,
                  thrHi: types.Array, outE: types.Array, outQ: types.Array) -> Pointer:
    """:func:`_check_state` for the machinery's argument types."""
    i64, f64 = types.int64, types.float64
    return pointer(_check_state, (scheme, well),
                   (wpar, i64, f64, f64, i64, thrE2, thrLo, thrHi, i64, i64, outE, outQ))
