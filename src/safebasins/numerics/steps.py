"""The step of the CPU engine: a scheme's compiled step (scheme_code.py) around a well's force.

Equation: q'' + beta q' + V'(q) = F sin(Omega t + Psi), first order q' = p,
p' = -beta p - V'(q) + f(t).  The schemes are constants (schemes.py); their steps are generated
once (scheme_code.py) and compiled here for the CPU lanes with the well's force and energy
(wells/compiled.py), the CUDA kernels compile the same source (cuda_kernels.py).

Every operation is written with explicit fused multiply-adds (llvm.fma), no fast-math flags:
vector loop and scalar replay produce bitwise identical numbers.

Compile-time keys
-----------------
The kernels are specialised on two numba literals threaded through every call: ``scheme``, the
key of a scheme's compiled form (scheme_code.SchemeCode.key: the scheme and damped or not), and
``well``, the key of a well's compiled form (wells.compiled.WellCode.key).  Each pair is its own
compiled, cached kernel; keys hash the generated arithmetic and the engine's source, so editing
the engine invalidates the cache.

``wpar`` (float64, ``wells.compiled.N_WPAR``): [q_left, q_right, w_0 .. w_13]; the barriers (+-inf
where there is none) and the well's run-time coefficients (``wtuple``).
"""
from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any, cast

import numpy as np
import numpy.typing as npt
from numba import njit, types
from numba.core import errors
from numba.extending import overload

from safebasins.core.numba_target import package_jit
from safebasins.numerics.scheme_code import SchemeCode, code_of_scheme, scheme_code
from safebasins.wells.compiled import (LLVM_INLINE, Coefs, WellCode, cpu_functions, cpu_jit, cpu_split, energy2_from,
                                      force_from, literal_code, quartic_code, well_energy2, well_force)

#: the engine's float64 and int64 arrays
Floats = npt.NDArray[np.float64]
Ints = npt.NDArray[np.int64]
#: an integer of the compiled code: numba types a Python int and numpy's int64 alike (int64)
Int = int | np.int64
#: a scheme's coefficients (one parameter set) or forcing values (one table row), as a tuple
Row = tuple[float, ...]
#: ``step(w, q, p, c, f) -> (q, p)``: a scheme's step around a well's force (w: the well's coefficients)
Step = Callable[[Coefs, float, float, Row, Row], tuple[float, float]]
#: ``lane(l, HL, CL)``: lane l's coefficients (cpu_lane)
Lane = Callable[[int, Floats, Floats], Row]
#: ``split_step(w, q, p, c, f, d) -> (q, p, d, v)``: a scheme's split step (scheme_code) around a
#: split well (d = V'(q) at the start; V'(q), V(q) at the end)
SplitStep = Callable[[Coefs, float, float, Row, Row, float], tuple[float, float, float, float]]

#: kernel key of the paper's quartic (a global constant: numba types it as a literal)
QUARTIC_KEY = quartic_code().key


@njit(cache=True, **LLVM_INLINE)
def wtuple(wpar: Floats) -> Coefs:
    """The 14 coefficients of wpar as scalars (loaded once, before the step loops)."""
    return (wpar[2], wpar[3], wpar[4], wpar[5], wpar[6], wpar[7], wpar[8],
            wpar[9], wpar[10], wpar[11], wpar[12], wpar[13], wpar[14], wpar[15])


#: the quartic has no run-time coefficients: its w tuple (wtuple) is zeros
W0 = (0.0,) * 14


# force, energy2, energy: the quartic for plain loops (tests); not cached on disk, since their
# quartic key is a global, which numba's cache does not check (an edit of wells/compiled.py would
# reuse them)
@package_jit(inline="always")
def force(q: float, f: float) -> float:
    """q^3 - q + f (the quartic), with f = F sin(Omega t_k + Psi)."""
    return well_force(QUARTIC_KEY, W0, q, f)


@package_jit(inline="always")
def energy2(q: float, p: float) -> float:
    """2 H0 = p^2 + q^2 - q^4/2 of the quartic (eq 7, untruncated)."""
    return well_energy2(QUARTIC_KEY, W0, q, p)


@package_jit()
def energy(q: float, p: float) -> float:
    return 0.5 * energy2(q, p)


# --- a scheme's code for the CPU lanes ----------------------------------------------------------
def literal_scheme(scheme: types.Type) -> SchemeCode:
    """The scheme code of a numba literal key (typing time)."""
    if not isinstance(scheme, types.IntegerLiteral):
        raise errors.TypingError(f"scheme must be a compile-time constant scheme key (a numba literal), got {scheme}")
    return code_of_scheme(scheme.literal_value)


@functools.cache
def cpu_helpers(scheme_key: int) -> dict[str, Callable[..., Any]]:
    """The tuple helpers of a scheme's code compiled for the CPU lanes (inlined)."""
    return code_of_scheme(scheme_key).helpers(cpu_jit)


@functools.cache
def cpu_lane(scheme_key: int) -> Lane:
    """``lane(l, HL, CL)``: lane l's coefficients, formed from its step h = HL[l] for an undamped
    scheme (the IEEE products lane_coefficients precomputes), read from its column of CL (copied
    at load) for a damped one; compiled for the CPU lanes (inlined)."""
    H = cpu_helpers(scheme_key)
    if code_of_scheme(scheme_key).damped:
        column: Callable[[Floats, int], Row] = H["column"]

        def lane(l: int, HL: Floats, CL: Floats) -> Row:
            return column(CL, l)
    else:
        from_h: Callable[[float], Row] = H["from_h"]

        def lane(l: int, HL: Floats, CL: Floats) -> Row:
            return from_h(HL[l])
    return cast(Lane, cpu_jit(lane))


@functools.cache
def cpu_step(scheme_key: int, well_key: int) -> Step:
    """The step of scheme code ``scheme_key`` around the force of well code ``well_key``, compiled
    for the CPU lanes (inlined): ``step(w, q, p, c, f) -> (q, p)``."""
    return cast(Step, code_of_scheme(scheme_key).make(cpu_jit, cpu_functions(well_key)[0]))


#: a split well's force and energy from V'(q), V(q) (wells.compiled.force_from, energy2_from) for the CPU lanes
FORCE_FROM = cpu_jit(force_from)
ENERGY2_FROM = cpu_jit(energy2_from)


@functools.cache
def cpu_split_step(scheme_key: int, well_key: int) -> SplitStep | None:
    """The split step of scheme code ``scheme_key`` around well code ``well_key``
    (``split_step(w, q, p, c, f, d) -> (q, p, d, v)``, scheme_code.SchemeCode.make_split) compiled for
    the CPU lanes (inlined); None for a well without a split force (wells.compiled.WellCode.split)."""
    split = cpu_split(well_key)
    if split is None:
        return None
    return cast(SplitStep, code_of_scheme(scheme_key).make_split(cpu_jit, *split, FORCE_FROM))


def scalar_step(integrator: str = "srkn6b", damped: bool = False, well: WellCode | None = None) -> Step:
    """A step of the scheme for plain compiled loops (tests, benchmarks): ``step(w, q, p, c, f)``
    with c a tuple of lane_coefficients, f a tuple of forcing values; well: a compiled well
    (wells.compiled.WellCode; None: the quartic).  ``steps.wtuple(code.wpar)`` gives w."""
    code = scheme_code(integrator, damped)
    return cpu_step(code.key, (quartic_code() if well is None else well).key)


def step(scheme: int, well: int, w: Coefs, q: float, p: float, c: Row, f: Row) -> tuple[float, float]:
    """One step of the scheme with key `scheme` for the well with kernel key `well` (both
    compile-time constants)."""
    raise NotImplementedError("step is compiled code (numba)")


# an overload's typing function sees numba types, its implementation values, and numba compares
# their signatures, annotations included: Any is the annotation true of both
@overload(step, jit_options=LLVM_INLINE)
def _ol_step(scheme: Any, well: Any, w: Any, q: Any, p: Any, c: Any, f: Any) -> Callable[..., tuple[float, float]]:
    STEP = cpu_step(literal_scheme(scheme).key, literal_code(well).key)

    def impl(scheme: Any, well: Any, w: Any, q: Any, p: Any, c: Any, f: Any) -> tuple[float, float]:
        return STEP(w, q, p, c, f)
    return impl


def row(scheme: int, tab: Floats, s: int) -> Row:
    """The forcing values of row s of a table (a tuple of the scheme's width)."""
    raise NotImplementedError("compiled code (numba)")


def scaled(scheme: int, F: float, t: Row) -> Row:
    """F times the forcing values t (the products the shared loop precomputes)."""
    raise NotImplementedError("compiled code (numba)")


def coefs(scheme: int, c: Floats) -> Row:
    """A coefficient row (lane_coefficients of one parameter set) as a tuple."""
    raise NotImplementedError("compiled code (numba)")


def column(scheme: int, CL: Floats, l: int) -> Row:
    """Lane l's coefficients from its column of CL, as a tuple."""
    raise NotImplementedError("compiled code (numba)")


def from_h(scheme: int, h: float) -> Row:
    """The undamped coefficients formed from the step h (the IEEE products lane_coefficients forms)."""
    raise NotImplementedError("compiled code (numba)")


def _H(scheme: types.Type, name: str) -> Callable[..., Row]:
    return cpu_helpers(literal_scheme(scheme).key)[name]


@overload(row, jit_options=LLVM_INLINE)
def _ol_row(scheme: Any, tab: Any, s: Any) -> Callable[..., Row]:
    H = _H(scheme, "row")

    def impl(scheme: Any, tab: Any, s: Any) -> Row:
        return H(tab, s)
    return impl


@overload(scaled, jit_options=LLVM_INLINE)
def _ol_scaled(scheme: Any, F: Any, t: Any) -> Callable[..., Row]:
    H = _H(scheme, "scaled")

    def impl(scheme: Any, F: Any, t: Any) -> Row:
        return H(F, t)
    return impl


@overload(coefs, jit_options=LLVM_INLINE)
def _ol_coefs(scheme: Any, c: Any) -> Callable[..., Row]:
    H = _H(scheme, "coefs")

    def impl(scheme: Any, c: Any) -> Row:
        return H(c)
    return impl


@overload(column, jit_options=LLVM_INLINE)
def _ol_column(scheme: Any, CL: Any, l: Any) -> Callable[..., Row]:
    H = _H(scheme, "column")

    def impl(scheme: Any, CL: Any, l: Any) -> Row:
        return H(CL, l)
    return impl


@overload(from_h, jit_options=LLVM_INLINE)
def _ol_from_h(scheme: Any, h: Any) -> Callable[..., Row]:
    H = _H(scheme, "from_h")

    def impl(scheme: Any, h: Any) -> Row:
        return H(h)
    return impl


def is_damped(scheme: int) -> bool:
    """True when the scheme code of key `scheme` is a damped variant (a compile-time constant)."""
    raise NotImplementedError("compiled code (numba)")


@overload(is_damped, jit_options=LLVM_INLINE)
def _ol_is_damped(scheme: Any) -> Callable[..., bool]:
    def yes(scheme: Any) -> bool:
        return True

    def no(scheme: Any) -> bool:
        return False
    return yes if literal_scheme(scheme).damped else no


@njit(cache=True, **LLVM_INLINE)
def scaled_row(scheme: int, tab: Floats, s: int, F: float) -> Row:
    """F times row s of a forcing table (the products the shared loop precomputes)."""
    return scaled(scheme, F, row(scheme, tab, s))
