"""A cost floor for the wells' elementary functions: the cheapest polynomial forms, NOT faithful.

bench_wells.py --floor compiles each transcendental expression well also with these in place of
wells.elementary's sin, cos, sincos, exp, expm1, exp_expm1 and tanh, in the same process and
lanes: the per-step ratio it prints is below what any faithful (< 1 ulp) version could reach, so
it says whether the per-step target is reachable at all.  Each form keeps only what no version can
drop: a Cody-Waite reduction in two parts (no double-word remainder, no huge-argument path, no
special values) and one Taylor polynomial in Horner form, long enough for about 1e-16 absolute
error on the benchmark's arguments; no tail terms, no second polynomial.

* sin, cos: x = n pi + r, |r| <= pi/2, sin r = r + r^3 P(r^2) (to r^21), the sign of (-1)^n;
  cos x = sin(x + pi/2) (one rounding more); sincos: both, from two reductions.
* exp, expm1, exp_expm1: x = n ln2 + r, |r| <= ln2/2, e^r - 1 = r + r^2 P(r) (to r^12), then
  2^n (1 + (e^r - 1)) and 2^n (e^r - 1) + (2^n - 1).
* tanh x = -expm1(-2|x|) / (2 + expm1(-2|x|)) with the sign of x (one division).
"""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from safebasins.core.numba_target import package_jit
from safebasins.wells import elementary
from safebasins.wells.compiled import fma, mul

_SHIFT = float.fromhex("0x1.8p52")
_INV_PI = 1.0 / math.pi
_PI_1 = float.fromhex("0x1.921fb54442d18p+1")
_PI_2 = float.fromhex("0x1.1a62633145c07p-53")
_HALF_PI = math.pi / 2.0
_INV_LN2 = 1.0 / math.log(2.0)
_LN2_1 = float.fromhex("0x1.62e42fefa39efp-1")
_LN2_2 = float.fromhex("0x1.abc9e3b39803fp-56")
_S3, _S5, _S7, _S9, _S11, _S13, _S15, _S17, _S19, _S21 = ((-1.0) ** k / math.factorial(2 * k + 1) for k in range(1, 11))
_E2, _E3, _E4, _E5, _E6, _E7, _E8, _E9, _E10, _E11, _E12 = (1.0 / math.factorial(k) for k in range(2, 13))

_jit = package_jit(error_model="numpy", forceinline=True)
_pow2 = elementary.cpu()._pow2


@_jit
def sin(x: float) -> float:
    n = fma(x, _INV_PI, _SHIFT) - _SHIFT
    r = fma(-n, _PI_2, fma(-n, _PI_1, x))
    z = mul(r, r)
    p = fma(fma(fma(fma(fma(fma(fma(fma(fma(_S21, z, _S19), z, _S17), z, _S15), z, _S13), z, _S11), z, _S9), z, _S7),
                    z, _S5), z, _S3)
    h = mul(n, 0.5)
    return mul(fma(mul(r, z), p, r), fma(-4.0, h - np.floor(h), 1.0))


@_jit
def cos(x: float) -> float:
    return sin(x + _HALF_PI)


@_jit
def sincos(x: float) -> tuple[float, float]:
    return sin(x), cos(x)


@_jit
def _expm1_parts(x: float) -> tuple[float, float]:
    """(2^n, e^r - 1), x = n ln2 + r."""
    n = fma(x, _INV_LN2, _SHIFT) - _SHIFT
    r = fma(-n, _LN2_2, fma(-n, _LN2_1, x))
    p = fma(fma(fma(fma(fma(fma(fma(fma(fma(fma(_E12, r, _E11), r, _E10), r, _E9), r, _E8), r, _E7), r, _E6), r,
                        _E5), r, _E4), r, _E3), r, _E2)
    return _pow2(np.int64(n)), fma(mul(r, r), p, r)


@_jit
def exp_expm1(x: float) -> tuple[float, float]:
    s, u = _expm1_parts(x)
    return fma(s, u, s), fma(s, u, s - 1.0)


@_jit
def exp(x: float) -> float:
    s, u = _expm1_parts(x)
    return fma(s, u, s)


@_jit
def expm1(x: float) -> float:
    s, u = _expm1_parts(x)
    return fma(s, u, s - 1.0)


@_jit
def tanh(x: float) -> float:
    e = expm1(mul(-2.0, abs(x)))
    t = -e / (2.0 + e)
    return t if x >= 0.0 else -t


FLOOR = ("sin", "cos", "sincos", "exp", "expm1", "exp_expm1", "tanh")


def floor_namespace() -> SimpleNamespace:
    """wells.elementary's CPU namespace with the functions of FLOOR replaced by the forms above."""
    ns = SimpleNamespace(**vars(elementary.cpu()))
    for k in FLOOR:
        setattr(ns, k, globals()[k])
    return ns
