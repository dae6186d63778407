"""Elementary functions written once in the wells' code language: the same bits on every target.

The functions are plain Python over ``+``, ``-``, ``*``, ``/``, comparisons, the wells' two primitives
(:func:`~safebasins.wells.compiled.fma`; :func:`~safebasins.wells.compiled.mul` for every
product that feeds an add, which the GPU compiler may then not contract), ``math.sqrt`` (IEEE,
correctly rounded: llvm.sqrt on the CPU, sqrt.rn.f64 on CUDA) and two bit casts,
:func:`as_bits` / :func:`from_bits`.  No libm call: glibc (CPU) and libdevice (GPU) round
differently; these functions round identically wherever they are compiled.  They are written
with selects rather than branches, so that a loop calling them vectorises on the CPU.

* sin, cos, sincos, tan (elementary_trig): x = n pi/2 + r, Cody-Waite in three parts (r = r_h + r_l,
  exact to 2^-77 for ``|x| <= 2^30``), exact Payne-Hanek reduction beyond (elementary_reduction:
  a branch that on the CPU is a vector-masked call, taken only by the lanes that need it);
  faithful minimax kernels on [-pi/4, pi/4] (double-double kernels on the huge-argument path).
* exp, expm1: x = n ln2 + r_h + r_l (r_h exact, r_l = -n LN2_LO not normalised), e^r - 1 - r_h
  by a minimax polynomial with r_h^2/2 exact, r_l added as r_l e^r_h; 2^n applied in two factors
  (no spurious overflow), one rounding in the subnormal range (exp's and pow's: a path of its
  own, on the CPU a masked call, which costs less than the path inline); faithful.  exp_expm1:
  both, with their bits, from one reduction (its subnormal path inline: in the engine's steps
  the call costs more).
* log, log1p: x = 2^E z, z in [sqrt(1/2), sqrt(2)), log z = 2 atanh(s), s = (z-1)/(z+1) as a
  double-double, minimax polynomial in s^2.
* cosh, sinh, tanh: from the double-double e^|x| and its reciprocal (sinh below 1/4 by its own
  polynomial; cosh from exp's faithful polynomial, sinh's from a double-double one: it cancels);
  tanh = (e - 1)/(e + 1) with e = e^(2|x|) as a double-double and exact sums.
* pow(x, y) = exp(y log x) with log x as a double-double to 2^-70 and y log x a double-double;
  the special cases of C99 Annex F.  powi(x, n): binary powering in double-double.
* sqrt: the IEEE square root (NaN below zero, without the exception Python would raise).

Accuracy (ulps against mpmath), special values and speed: docs/elementary.md;
tests/wells/test_elementary.py checks them.

Targets: the source is compiled per target by :func:`cpu` (numba njit, the primitives bound to
their CPU intrinsics) and :func:`cuda_device` (numba-cuda device functions); ``@njit`` code may
call this module's functions directly (CPU overloads).  Under numba's CUDA simulator the device
functions run as this Python: its integer arithmetic never leaves int64 (nothing wraps around
to differ from the compiled code) and it never divides by zero or takes a negative square root
(Python would raise).
"""
from __future__ import annotations

import functools
import hashlib
import math
import sys
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace
from typing import Any


from safebasins.core import numba_target
from safebasins.wells import elementary_dd, elementary_reduction, elementary_targets, elementary_trig
from safebasins.wells.elementary_dd import _ABS, _copysign, _dd_mul, _fast_two_sum, _pow2, _two_prod, _two_sum
from safebasins.wells.elementary_trig import SIN_COS_FAST_LIMIT, cos, sin, sincos, tan
from safebasins.wells.elementary_targets import (as_bits, as_bits_cpu, cold_call_cpu, compile_code, from_bits,
                                                    from_bits_cpu, register_cpu_overload)
from safebasins.wells.compiled import cpu_jit, fma, fma_cpu, mul, mul_cpu

__all__ = ["sin", "cos", "tan", "sincos", "exp", "expm1", "exp_expm1", "log", "log1p", "tanh", "cosh", "sinh", "sqrt",
           "pow", "powi", "cpu", "cuda_device", "for_target", "FUNCTIONS", "SIN_COS_FAST_LIMIT", "ULP_BOUNDS",
           "MODULE_HASH"]

#: the public functions
FUNCTIONS = ("sin", "cos", "tan", "sincos", "exp", "expm1", "log", "log1p", "tanh", "cosh", "sinh", "sqrt", "pow",
             "powi")
#: the largest error in ulps (against mpmath) that each function may make on its whole domain,
#: tested (tests/wells/test_elementary.py); the measured maxima: docs/elementary.md.  sin, cos,
#: exp, expm1, tanh and cosh are faithful (< 1 ulp; no double-double kernel terms: the wells' forces
#: call them); the others almost correctly rounded.  tan = sin/cos: two kernel errors of <= 0.8
#: ulp (relative 1.6 2^-52 each at a binade's bottom) and the division's rounding bound it by 3.7
ULP_BOUNDS = {"sin": 0.8, "cos": 0.8, "sincos": 0.8, "tan": 3.7, "exp": 0.65, "expm1": 0.85, "log": 0.55,
              "log1p": 0.6, "tanh": 0.75, "cosh": 0.65, "sinh": 0.55, "sqrt": 0.5, "pow": 0.55, "powi": 0.55}
#: hash of the source of the functions (this module and the four it compiles with): part of the key
#: of every compiled well that calls them (an edit never reuses a kernel cached before it)
MODULE_HASH = hashlib.blake2b(b"".join(Path(str(m.__file__)).read_bytes() for m in (
    sys.modules[__name__], elementary_dd, elementary_reduction, elementary_targets, elementary_trig)),
    digest_size=16).hexdigest()


# ------------------------------------------------------------------------------- constants
_h = float.fromhex
_SHIFT = _h("0x1.8p52")             # (x + SHIFT) - SHIFT rounds |x| < 2^51 to an integer
_SHIFT_BITS = 0x4338000000000000    # bits(SHIFT + n) - SHIFT_BITS = n
_SQRT_HALF_BITS = 0x3FE6A09E667F3BCD
_INF = math.inf
_NAN = math.nan
_P52, _P53, _P54 = 2.0 ** 52, 2.0 ** 53, 2.0 ** 54
_M1022, _M54, _M27, _M26 = 2.0 ** -1022, 2.0 ** -54, 2.0 ** -27, 2.0 ** -26

_INV_LN2 = _h("0x1.71547652b82fep+0")
_LN2_HI = _h("0x1.62e42fefa39efp-1")     # 53 bits: fma(-n, LN2_HI, x) is exact
_LN2_LO = _h("0x1.abc9e3b39803fp-56")
_LN2_42 = _h("0x1.62e42fefa3800p-1")     # 42 bits: E LN2_42 is exact for |E| < 2^11
_LN2_42M = _h("0x1.ef35793c76730p-45")
_LN2_42L = _h("0x1.f97b57a079a19p-103")


_TWO3_HI, _TWO3_LO = _h("0x1.5555555555555p-1"), _h("0x1.5555555555555p-55")
_TWO5_HI, _TWO5_LO = _h("0x1.999999999999ap-2"), _h("-0x1.999999999999ap-56")
_THIRD_HI, _THIRD_LO = _h("0x1.5555555555555p-2"), _h("0x1.5555555555555p-56")

# minimax polynomials (benchmarks/elementary_coefficients.py), relative error with these doubles:
# e^r - 1 - r - r^2/2 = r^3 (E0 + E1 r + ... + E9 r^9), |r| <= ln2/2: 2^-62.6 (relative to e^r)
_E0, _E1, _E2, _E3, _E4, _E5, _E6, _E7, _E8, _E9 = map(_h, (
    "0x1.555555555555bp-3", "0x1.555555555553cp-5", "0x1.111111110ee66p-7", "0x1.6c16c16c21b6dp-10",
    "0x1.a01a01b297f7ep-13", "0x1.a01a016b50205p-16", "0x1.71ddf279daa6ap-19", "0x1.27e55f2fdf8c6p-22",
    "0x1.af67e69d7a574p-26", "0x1.1ea0810d654fbp-29"))
# e^r - 1 - r - r^2/2 - r^3/6 = r^4 (F0 + F1 r + ... + F9 r^9): 2^-66.2 (relative to e^r - 1)
_F0, _F1, _F2, _F3, _F4, _F5, _F6, _F7, _F8, _F9 = map(_h, (
    "0x1.5555555555557p-5", "0x1.111111111110ep-7", "0x1.6c16c16c157aep-10", "0x1.a01a01a01c88ap-13",
    "0x1.a01a01aaf559ap-16", "0x1.71de3a4a0def8p-19", "0x1.27e4d18dccd14p-22", "0x1.ae6479f2af7dap-26",
    "0x1.1f83858a6889ep-29", "0x1.613beb3013609p-33"))
# 2 atanh(s) = 2 s + s z (L0 + L1 z + ... + L7 z^7), z = s^2 <= (3 - 2 sqrt 2)^2: 2^-66.3
_L0, _L1, _L2, _L3, _L4, _L5, _L6, _L7 = map(_h, (
    "0x1.5555555555555p-1", "0x1.9999999999d33p-2", "0x1.2492492435cf6p-2", "0x1.c71c725057eaap-3",
    "0x1.745ce02241ff8p-3", "0x1.3b206f7ac178ep-3", "0x1.0f60813f8e27dp-3", "0x1.0f4c3f3395016p-3"))
# 2 atanh(s) = 2 s + 2 s^3/3 + 2 s^5/5 + s z^3 (M0 + ... + M6 z^6): 2^-70.3 (pow's logarithm)
_M0, _M1, _M2, _M3, _M4, _M5, _M6 = map(_h, (
    "0x1.249249249265cp-2", "0x1.c71c71c6a5341p-3", "0x1.745d17a975632p-3", "0x1.3b1385e47f1b6p-3",
    "0x1.111baba317c66p-3", "0x1.def45c9c15738p-4", "0x1.e5333184de147p-4"))
# sinh x = x + x z (H0 + H1 z + ... + H4 z^4), z = x^2, |x| <= 1/4: 2^-65.0
_H0, _H1, _H2, _H3, _H4 = map(_h, (
    "0x1.5555555555555p-3", "0x1.111111111132ap-7", "0x1.a01a019f98f55p-13", "0x1.71de34379e275p-19",
    "0x1.aec387149524dp-26"))


# ------------------------------------------------------------------------------- exp family
def _exp_reduce(xh: float, xl: float) -> tuple[int, float, float]:
    """(n, r_h, r_l): x_h + x_l = n ln2 + r_h + r_l, |r| <= ln2/2 (1 + 2^-40), for |x_h| <= 746."""
    k = fma(xh, _INV_LN2, _SHIFT)
    nf = k - _SHIFT
    t = fma(-nf, _LN2_HI, xh)                        # exact
    rh, rl = _two_sum(t, fma(-nf, _LN2_LO, xl))
    return as_bits(k) - _SHIFT_BITS, rh, rl


def _poly10(r: float, r2: float, r4: float, c0: float, c1: float, c2: float, c3: float, c4: float, c5: float, c6: float,
            c7: float, c8: float, c9: float) -> float:
    """c0 + c1 r + ... + c9 r^9 (Estrin: half Horner's chain of dependent operations)."""
    p = fma(fma(fma(c7, r, c6), r2, fma(c5, r, c4)), r4, fma(fma(c3, r, c2), r2, fma(c1, r, c0)))
    return fma(fma(c9, r, c8), mul(r4, r4), p)


def _exp_poly(rh: float, rl: float) -> tuple[float, float]:
    """e^r = b_h + b_l for r = r_h + r_l, |r| <= 0.35, to ~2^-60 relative; b_l is not normalised."""
    hr = mul(0.5, rh)
    h = mul(hr, rh)                                  # r^2/2 = h + hl exactly
    hl = fma(hr, rh, -h)
    r2 = mul(rh, rh)
    q = _poly10(rh, r2, mul(r2, r2), _E0, _E1, _E2, _E3, _E4, _E5, _E6, _E7, _E8, _E9)
    uh, e = _fast_two_sum(rh, h)
    bh, be = _fast_two_sum(1.0, uh)
    return bh, be + (e + ((hl + mul(r2, mul(rh, q))) + fma(rl, uh, rl)))      # r_l e^r


def _expm1_poly(rh: float, rl: float) -> tuple[float, float]:
    """e^r - 1 = u_h + u_l for r = r_h + r_l, |r| <= 0.35, to ~2^-62 relative (r^2/2 and r^3/6 in
    double-double); u_l is not normalised."""
    hr = mul(0.5, rh)
    h = mul(hr, rh)                                  # r^2/2 = h + hl exactly
    hl = fma(hr, rh, -h)
    ch, cl = _two_prod(h, rh)                        # r^3/2 = ch + cl
    cl = fma(hl, rh, cl)
    th = mul(ch, _THIRD_HI)                          # r^3/6 = th + tl
    tl = fma(ch, _THIRD_HI, -th) + fma(ch, _THIRD_LO, mul(cl, _THIRD_HI))
    r2 = mul(rh, rh)
    r4 = mul(r2, r2)
    q = _poly10(rh, r2, r4, _F0, _F1, _F2, _F3, _F4, _F5, _F6, _F7, _F8, _F9)
    uh, e1 = _fast_two_sum(rh, h)
    rle = fma(rl, uh, rl)                            # r_l e^r
    uh, e2 = _fast_two_sum(uh, th)
    return uh, (e1 + e2) + ((hl + tl) + (mul(r4, q) + rle))


def _scale(n: int, y: float) -> float:
    """y 2^n for |n| <= 1100: two exact factors, so the only rounding is a subnormal result's."""
    n1 = n >> 1
    return mul(mul(y, _pow2(n1)), _pow2(n - n1))


def _exp_finish(n: int, bh: float, bl: float) -> float:
    """2^n (b_h + b_l) for b in [0.7, 1.42], rounded once also into the subnormal range."""
    b = bh + bl
    normal = _scale(n, b)
    # a subnormal result (n < -1022, or n = -1022 and b < 1): scale by 2^(n+1022) first and round
    # at 2^-52 (1.0 + y, y < 1), which the exact scaling by 2^-1022 turns into the subnormal ulp
    # 2^-1074 (other lanes scale by 1: a subnormal intermediate costs a microcode assist per
    # operation)
    tiny = (n < -1022) | ((n == -1022) & (b < 1.0))
    sc = _pow2(min(max(n, -1075), -1022) + 1022)
    y = mul(bh, sc)
    hi = 1.0 + y
    lo = ((1.0 - hi) + y) + mul(bl, sc)
    sub = mul((hi + lo) - 1.0, _M1022 if tiny else 1.0)
    return sub if tiny else normal


def _exp_fast(x: float) -> tuple[int, float, float]:
    """(n, r_h, t): e^x = 2^n (1 + r_h + t), t = e^r - 1 - r_h to ~2^-58 absolute, for
    ``|x| <= 746``: r_h exact, r_l = -n LN2_LO (not normalised) added as r_l e^r_h."""
    k = fma(x, _INV_LN2, _SHIFT)
    nf = k - _SHIFT
    rh = fma(-nf, _LN2_HI, x)                        # exact
    rl = mul(-nf, _LN2_LO)
    r2 = mul(rh, rh)
    q = _poly10(rh, r2, mul(r2, r2), _E0, _E1, _E2, _E3, _E4, _E5, _E6, _E7, _E8, _E9)
    # e^r_h - 1 - r_h = r_h^2/2 + r_h^3 q, r_h^2 = r2 + fma(r_h, r_h, -r2) exactly
    t = fma(0.5, r2, fma(mul(r2, rh), q, mul(0.5, fma(rh, rh, -r2))))
    return as_bits(k) - _SHIFT_BITS, rh, t + fma(rl, rh + t, rl)


def _exp_tiny(x: float) -> float:
    """e^x for ``-746 <= x <= 710`` with exp's rounding into the subnormal range (:func:`_exp_finish`):
    exp's path where 2^n <= 2^-1022, out of the lanes' way (its arithmetic costs more than the
    normal path's)."""
    n, rh, t = _exp_fast(x)
    bh, be = _fast_two_sum(1.0, rh)
    return _exp_finish(n, bh, be + t)


def exp(x: float) -> float:
    """e^x."""
    xc = x if x > -746.0 else -746.0                 # NaN -> -746 here, restored at the end
    xc = xc if xc < 710.0 else 710.0
    n, rh, t = _exp_fast(xc)
    bh, be = _fast_two_sum(1.0, rh)
    res = _scale(n, bh + (be + t))
    if n <= -1022:                                   # maybe subnormal: rare, on the CPU a masked cold call
        res = _exp_tiny(xc)
    return x + x if x != x else res


def _expm1_dd(n: int, rh: float, t: float) -> tuple[float, float]:
    """2^n (1 + r_h + t) - 1 for e^r - 1 = r_h + t (:func:`_exp_fast`), -55 <= n <= 60, as a
    double-double (exact sums)."""
    uh, ul = _fast_two_sum(rh, t)
    s = _pow2(n)
    th, tl = _two_sum(s, -1.0)                       # 2^n - 1 exactly
    sh, se = _two_sum(mul(s, uh), th)
    return _fast_two_sum(sh, se + (tl + mul(s, ul)))


def _expm1_finish(x: float, n: int, rh: float, t: float, e: float) -> float:
    """e^x - 1 from exp's reduction of x (clamped to [-746, 710]) and e = exp's rounded 2^n (1 + r_h + t)."""
    m = n if n > -55 else -55                        # x < -38: any finite value, replaced below
    dh, dl = _expm1_dd(m if m < 60 else 60, rh, t)
    res = e if n > 60 else dh + dl                   # n > 60: the -1 is below 2^-8 ulp
    res = -1.0 if x < -38.0 else res                 # e^-38 < 2^-54: expm1 = -1 rounded
    res = x if abs(x) < _M54 else res
    return x + x if x != x else res


def expm1(x: float) -> float:
    """e^x - 1."""
    xc = x if x > -746.0 else -746.0                 # as exp: NaN -> -746 here, restored at the end
    xc = xc if xc < 710.0 else 710.0
    n, rh, t = _exp_fast(xc)
    bh, be = _fast_two_sum(1.0, rh)
    return _expm1_finish(x, n, rh, t, _scale(n, bh + (be + t)))   # used for n > 60: exp's bits, never subnormal


def exp_expm1(x: float) -> tuple[float, float]:
    """(e^x, e^x - 1), the bits of exp and expm1, from one reduction and polynomial (about the
    cost of expm1 alone): the rewritten forms of the expression wells call it."""
    xc = x if x > -746.0 else -746.0
    xc = xc if xc < 710.0 else 710.0
    n, rh, t = _exp_fast(xc)
    bh, be = _fast_two_sum(1.0, rh)
    e = _exp_finish(n, bh, be + t)                 # inline: a masked call here costs the engine's steps more
    return (x + x if x != x else e), _expm1_finish(x, n, rh, t, e)


def _exp_dd(ax: float) -> tuple[int, float, float, float, float]:
    """(n, b_h, b_l, i_h, i_l): e^ax = 2^n (b_h + b_l), 1/(b_h + b_l) = i_h + i_l, 0 <= ax <= 711."""
    n, rh, rl = _exp_reduce(ax, 0.0)
    uh, ul = _expm1_poly(rh, rl)                     # sinh cancels up to 2 bits: e^r to 2^-62
    bh, be = _fast_two_sum(1.0, uh)
    bh, bl = _fast_two_sum(bh, be + ul)
    ih = 1.0 / bh
    return n, bh, bl, ih, mul(fma(-bh, ih, 1.0) - mul(bl, ih), ih)


def cosh(x: float) -> float:
    """cosh x = 2^(n-1) (b + 2^-2n / b)."""
    ax = abs(x)
    ax = ax if ax < 711.0 else 711.0                 # NaN -> 711 here, restored at the end
    n, rh, t = _exp_fast(ax)                         # no cancellation: e^r to ~2^-58 suffices
    bh, be = _fast_two_sum(1.0, rh)
    bh, bl = _fast_two_sum(bh, be + t)
    ih = 1.0 / bh
    il = mul(fma(-bh, ih, 1.0) - mul(bl, ih), ih)
    g = _pow2(-2 * (n if n < 511 else 511))
    ch, ce = _two_sum(bh, mul(g, ih))
    res = _scale(n - 1, ch + (ce + (bl + mul(g, il))))
    return x + x if x != x else res


def sinh(x: float) -> float:
    """sinh x: 2^(n-1) (b - 2^-2n / b), below 1/4 a polynomial."""
    ax = abs(x)
    n, bh, bl, ih, il = _exp_dd(ax if ax < 711.0 else 711.0)
    g = _pow2(-2 * (n if n < 511 else 511))
    ch, ce = _two_sum(bh, -mul(g, ih))
    res = _scale(n - 1, ch + (ce + (bl - mul(g, il))))
    z = mul(ax, ax)
    p = fma(fma(fma(fma(_H4, z, _H3), z, _H2), z, _H1), z, _H0)
    res = fma(mul(ax, z), p, ax) if ax < 0.25 else res
    res = _copysign(res, x)
    res = x if ax < _M26 else res
    return x + x if x != x else res


def tanh(x: float) -> float:
    """tanh x = sign(x) (e - 1)/(e + 1), e = e^(2|x|) = 2^n (1 + r_h + t) as a double-double, e - 1 and
    e + 1 by exact sums."""
    ax = abs(x)
    ax2 = ax + ax if ax < 20.0 else 40.0             # tanh(20) = 1 - 2^-56.7: 1 rounded
    n, rh, t = _exp_fast(ax2)
    s = _pow2(n)
    bh, be = _fast_two_sum(1.0, rh)
    eh, el = _fast_two_sum(mul(s, bh), mul(s, be + t))
    nh, ne = _two_sum(eh, -1.0)
    sh, se = _two_sum(eh, 1.0)
    inv = 1.0 / sh
    qh = mul(nh, inv)
    ql = mul((fma(-qh, sh, nh) + (ne + el)) - mul(qh, se + el), inv)
    res = _copysign(qh + ql, x)
    res = x if ax < _M27 else res
    return x + x if x != x else res


# ------------------------------------------------------------------------------- log family
def _log_reduce(x: float) -> tuple[int, float, float]:
    """(E, e, z): x = 2^E z, z in [sqrt(1/2), sqrt(2)), E as an int and a float, 0 < x < inf."""
    sub = x < _M1022
    ix = as_bits(mul(x, _P54) if sub else x) & _ABS
    k = (ix - _SQRT_HALF_BITS) >> 52
    z = from_bits(ix - (k << 52))
    k = k - 54 if sub else k
    return k, from_bits(k + _SHIFT_BITS) - _SHIFT, z


def _atanh_arg(fh: float, fl: float) -> tuple[float, float]:
    """s = f/(2 + f) as a double-double, f = f_h + f_l, |f| <= 0.42."""
    dh, de = _fast_two_sum(2.0, fh)
    inv = 1.0 / dh
    sh = mul(fh, inv)
    return sh, mul((fma(-sh, dh, fh) + fl) - mul(sh, de + fl), inv)


def _log_core(e: float, fh: float, fl: float) -> float:
    """e ln2 + log1p(f_h + f_l), rounded."""
    sh, sl = _atanh_arg(fh, fl)
    z = mul(sh, sh)
    v = fma(fma(fma(fma(fma(fma(fma(_L7, z, _L6), z, _L5), z, _L4), z, _L3), z, _L2), z, _L1), z, _L0)
    hi, he = _fast_two_sum(mul(e, _LN2_42), sh + sh)
    return hi + (he + (mul(e, _LN2_42M) + ((sl + sl) + mul(mul(sh, z), v))))


def log(x: float) -> float:
    """Natural logarithm."""
    k, e, z = _log_reduce(x)
    res = _log_core(e, z - 1.0, 0.0)
    res = -_INF if x == 0.0 else res
    res = x + x if not (x < _INF) else res           # +inf, NaN
    return _NAN if x < 0.0 else res


def log1p(x: float) -> float:
    """log(1 + x): for x in [sqrt(1/2) - 1, sqrt(2) - 1] log1p(x) itself, beyond the log of
    1 + x as the double-double u_h + u_l."""
    xc = x if x > -1.0 else 0.0                      # x <= -1, NaN: special values below
    uh, ul = _two_sum(1.0, xc if xc < _INF else 0.0)
    k, e, z = _log_reduce(uh)
    near = (x > -0.2928) & (x < 0.4142)
    fh = x if near else z - 1.0
    fl = 0.0 if near else mul(ul, _pow2(-(k if k < 1000 else 1000)))
    res = _log_core(0.0 if near else e, fh, fl)
    res = x if abs(x) < _M54 else res
    res = -_INF if x == -1.0 else res
    res = x + x if not (x < _INF) else res           # +inf, NaN
    return _NAN if x < -1.0 else res


def _log_dd(x: float) -> tuple[float, float]:
    """log x as a double-double of relative error ~2^-70 (pow), 0 < x < inf."""
    k, e, z = _log_reduce(x)
    sh, sl = _atanh_arg(z - 1.0, 0.0)
    zh, zl = _two_prod(sh, sh)
    zl = zl + mul(sh + sh, sl)
    v = fma(fma(fma(fma(fma(fma(_M6, zh, _M5), zh, _M4), zh, _M3), zh, _M2), zh, _M1), zh, _M0)
    t = mul(zh, v)                                   # w = 2/5 + z v
    wh, we = _fast_two_sum(_TWO5_HI, t)
    wl = we + (_TWO5_LO + (fma(zh, v, -t) + mul(zl, v)))
    ph, pl = _dd_mul(zh, zl, wh, wl)                 # u = 2/3 + z w
    uh, ue = _fast_two_sum(_TWO3_HI, ph)
    yh, yl = _dd_mul(zh, zl, uh, ue + (_TWO3_LO + pl))
    qh, ql = _dd_mul(sh, sl, yh, yl)                 # 2 atanh s = 2 s + s z u
    th, te = _fast_two_sum(sh + sh, qh)
    lh, le = _fast_two_sum(mul(e, _LN2_42), th)
    mh, ml = _two_prod(e, _LN2_42M)
    return _fast_two_sum(lh, le + ((te + ((sl + sl) + ql)) + (mh + (ml + mul(e, _LN2_42L)))))


# ------------------------------------------------------------------------------- powers
def _parity(y: float) -> tuple[bool, bool]:
    """(y is an integer, y is an odd integer); neither for inf or NaN."""
    ay = abs(y)
    small = ay < _P52
    k = ay + _P52 if small else ay                   # |y| < 2^52: rounds to an integer
    integer = (k - _P52 == ay) if small else (ay < _INF)
    return integer, integer & ((as_bits(k) & 1) == 1) & (ay < _P53)


def _pow_tiny(eh: float, el: float) -> float:
    """e^(e_h + e_l) for ``-746 <= e_h <= 710`` with exp's rounding into the subnormal range: pow's
    path where 2^n <= 2^-1022, out of the lanes' way (as :func:`_exp_tiny`)."""
    n, rh, rl = _exp_reduce(eh, el)
    bh, bl = _exp_poly(rh, rl)
    return _exp_finish(n, bh, bl)


def pow(x: float, y: float) -> float:
    """x^y (C99 Annex F special cases: pow(x, 0) = pow(1, y) = 1 even for NaN, ...)."""
    ax = abs(x)
    lh, ll = _log_dd(ax)
    th = mul(y, lh)
    tl = fma(y, lh, -th) + mul(y, ll)
    big = th > 710.0
    small = not (th > -746.0)                        # NaN too: a finite path, replaced below
    eh, el = (710.0 if big else (-746.0 if small else th)), (0.0 if big | small else tl)
    n, rh, rl = _exp_reduce(eh, el)
    bh, bl = _exp_poly(rh, rl)
    res = _scale(n, bh + bl)
    if n <= -1022:                                   # maybe subnormal: rare, on the CPU a masked cold call
        res = _pow_tiny(eh, el)
    integer, odd = _parity(y)
    negative = as_bits(x) < 0
    res = -res if negative & odd else res
    res = _NAN if (x < 0.0) & (x > -_INF) & (not integer) & (abs(y) < _INF) else res
    # x = +-0 and x = +-inf: 0 or inf, with the sign of x for an odd integer y
    tiny = (y > 0.0) == (ax == 0.0)
    edge = 0.0 if tiny else _INF
    res = (_copysign(edge, x) if odd else edge) if (ax == 0.0) | (ax == _INF) else res
    res = ((1.0 if ax == 1.0 else (_INF if (ax < 1.0) == (y < 0.0) else 0.0)) if abs(y) == _INF else res)
    res = x + y if (x != x) | (y != y) else res
    return 1.0 if (x == 1.0) | (y == 0.0) else res


def powi(x: float, n: int) -> float:
    """x^n for an integer n (C23 pown special cases), by binary powering in double-double."""
    m = -n if n < 0 else n
    xi = x if x != 0.0 else 1.0                      # no division by zero (x = 0: below)
    ih = 1.0 / xi
    bh = ih if n < 0 else x
    bl = mul(fma(-xi, ih, 1.0), ih) if n < 0 else 0.0
    rh, rl = 1.0, 0.0
    while m > 0:
        if m & 1:
            rh, rl = _dd_mul(rh, rl, bh, bl)
        bh, bl = _dd_mul(bh, bl, bh, bl)
        m >>= 1
    res = rh + rl
    odd = (n & 1) == 1
    res = (_copysign(_INF, x if odd else 1.0)) if (res != res) & (x == x) else res   # overflow
    tiny = (n > 0) == (x == 0.0)
    special = _copysign(0.0 if tiny else _INF, x) if odd else (0.0 if tiny else _INF)
    res = special if (x == 0.0) | (abs(x) == _INF) else res
    return 1.0 if n == 0 else res


def sqrt(x: float) -> float:
    """The IEEE square root; NaN below zero (sqrt(-0) = -0)."""
    return math.sqrt(x) if x >= 0.0 else _NAN


# ------------------------------------------------------------------------------- targets
#: functions here that are not code (compile_code compiles the others)
NOT_CODE = ("cpu", "cuda_device", "for_target", "_cold", "_cpu_function")
_MODULES = (sys.modules[__name__], elementary_dd, elementary_reduction, elementary_trig)
#: the rare paths the CPU compilation calls out of the lanes (masked cold calls)
COLD_PATHS = ("_sin_huge", "_cos_huge", "_exp_tiny", "_pow_tiny")


def _cold(ns: SimpleNamespace, name: str) -> Any:
    """The masked cold call (CPU) of the compiled function ``name`` of ``ns``."""
    return cold_call_cpu(getattr(ns, name), name)


@functools.cache
def cpu() -> SimpleNamespace:
    """The functions compiled for the CPU (njit, numpy error model: a division never raises), fma,
    mul and the bit casts bound to their CPU intrinsics; the rare paths (sin/cos of huge arguments,
    exp's and pow's results near the subnormal range) as masked cold calls.  A namespace of
    dispatchers: ``cpu().sin`` etc."""
    prims = {"fma": fma_cpu, "mul": mul_cpu, "as_bits": as_bits_cpu, "from_bits": from_bits_cpu}
    cold = {k: functools.partial(_cold, name=k) for k in COLD_PATHS}
    return compile_code(_MODULES, numba_target.package_jit(error_model="numpy", forceinline=True), prims, cold)


@functools.cache
def cuda_device() -> SimpleNamespace:
    """The functions as numba-cuda device functions: fma.rn.f64, mul.rn.f64 (never contracted) and
    libdevice's bit casts; under the simulator (NUMBA_ENABLE_CUDASIM=1) the Python primitives (the
    CPU's correctly rounded fma), as cuda_kernels does for the wells."""
    from numba import cuda  # noqa: PLC0415  (lazy: numba.cuda reads the simulator switch when first imported)
    from numba.cuda.core import config as cuda_config  # noqa: PLC0415  (as numba.cuda)

    prims: dict[str, Any] = {}
    if not cuda_config.ENABLE_CUDASIM:
        from numba.cuda import libdevice  # noqa: PLC0415  (as numba.cuda; not there under the simulator)

        # libdevice's fma (fma.rn.f64): numba-cuda's cuda.fma is a stub, typed only as numba.cuda.fma
        prims = {"fma": libdevice.fma, "mul": libdevice.dmul_rn, "as_bits": libdevice.double_as_longlong,
                 "from_bits": libdevice.longlong_as_double}
    return compile_code(_MODULES, cuda.jit(device=True), prims)


def for_target(jit: Callable[..., Any]) -> SimpleNamespace:
    """The functions compiled for the target whose decorator is ``jit``: the CPU lanes'
    (:func:`~safebasins.wells.compiled.cpu_jit`) or, for any other, CUDA's device functions."""
    return cpu() if jit is cpu_jit else cuda_device()


def _cpu_function(name: str) -> Any:
    return getattr(cpu(), name)


for _name in FUNCTIONS:
    register_cpu_overload(globals()[_name], functools.partial(_cpu_function, _name))
