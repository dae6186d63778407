"""sin, cos, sincos, tan of wells.elementary: code in the wells' language, compiled with it for every
target (its ``_MODULES``; docs/elementary.md).

x = n pi/2 + r, Cody-Waite in three parts (r = r_h + r_l, exact to 2^-77 for ``|x| <= 2^30``),
faithful kernels on [-pi/4, pi/4] (r_h + r^3 (-1/6 + z S(z)); 1 - r^2/2 exact as two doubles,
then z^2 C(z)), both evaluated and the quadrant selected (a lane cannot branch).  Beyond 2^30 the
exact Payne-Hanek reduction (elementary_reduction) with double-double kernels: a rare branch,
on the CPU a masked cold call.
"""
from __future__ import annotations

import math

from safebasins.wells.compiled import fma, mul
from safebasins.wells.elementary_dd import _ABS, _dd_mul, _fast_two_sum, _two_prod, _two_sum
from safebasins.wells.elementary_reduction import reduce_pio2 as _payne_hanek
from safebasins.wells.elementary_targets import as_bits

__all__ = ["sin", "cos", "sincos", "tan", "SIN_COS_FAST_LIMIT"]

#: ``|x|`` up to which sin and cos reduce by Cody-Waite (beyond: Payne-Hanek)
SIN_COS_FAST_LIMIT = 2.0 ** 30

_h = float.fromhex
_SHIFT = _h("0x1.8p52")             # (x + SHIFT) - SHIFT rounds |x| < 2^51 to an integer
_INF = math.inf
_M27 = 2.0 ** -27
_TWO_OVER_PI = _h("0x1.45f306dc9c883p-1")
_PIO2_1 = _h("0x1.921fb54442d18p+0")      # pi/2 = PIO2_1 + PIO2_2 + PIO2_3 + O(2^-163)
_PIO2_2 = _h("0x1.1a62633145c07p-54")
_PIO2_3 = _h("-0x1.f1976b7ed8fbcp-110")
_SIXTH_HI, _SIXTH_LO = _h("0x1.5555555555555p-3"), _h("0x1.5555555555555p-57")
# minimax polynomials (benchmarks/elementary_coefficients.py), relative error with these doubles:
# sin r = r - r^3/6 + r^5 (S0 + S1 z + ... + S5 z^5), z = r^2, |r| <= pi/4 + 2^-20: 2^-67.4
_S0, _S1, _S2, _S3, _S4, _S5 = map(_h, (
    "0x1.111111111110fp-7", "-0x1.a01a01a0194b2p-13", "0x1.71de3a53f2fd2p-19", "-0x1.ae64537b27b3dp-26",
    "0x1.61211c7af2333p-33", "-0x1.aae6ec007d962p-41"))
# cos r = 1 - r^2/2 + z^2 (C0 + C1 z + ... + C5 z^5): 2^-63.4
_C0, _C1, _C2, _C3, _C4, _C5 = map(_h, (
    "0x1.555555555554bp-5", "-0x1.6c16c16c150c8p-10", "0x1.a01a019caf829p-16", "-0x1.27e4f81097945p-22",
    "0x1.1ee9f46249f29p-29", "-0x1.8fb46a41c8459p-37"))


def _reduce_pio2(x: float) -> tuple[int, float, float]:
    """(n mod 4, r_h, r_l): x = n pi/2 + r_h + r_l (r_l not normalised: ``|r_l| <= ulp(r_h) + 2^-77``),
    ``|r| <= pi/4 + 2^-23``, for ``|x| <= 2^30``."""
    k = fma(x, _TWO_OVER_PI, _SHIFT)
    nf = k - _SHIFT
    t = fma(-nf, _PIO2_1, x)                         # exact
    p, pe = _two_prod(nf, _PIO2_2)
    rh, te = _two_sum(t, -p)
    return as_bits(k) & 3, rh, te - fma(nf, _PIO2_3, pe)


def _sin_kernel(rh: float, rl: float) -> float:
    """sin(r_h + r_l), |r| <= pi/4 + 2^-20: r - r^3/6 in double-double, the rest a polynomial."""
    zh = mul(rh, rh)
    zl = fma(rh, rh, -zh)
    ch = mul(zh, rh)                                 # r^3 = ch + cl
    cl = fma(zh, rh, -ch) + mul(zl, rh)
    th = mul(ch, -_SIXTH_HI)                         # -r^3/6 = th + tl
    tl = fma(ch, -_SIXTH_HI, -th) - (mul(ch, _SIXTH_LO) + mul(cl, _SIXTH_HI))
    p = fma(fma(fma(fma(fma(_S5, zh, _S4), zh, _S3), zh, _S2), zh, _S1), zh, _S0)
    sh, se = _fast_two_sum(rh, th)
    return sh + (se + (tl + (fma(mul(ch, zh), p, rl) - mul(mul(0.5, zh), rl))))


def _cos_kernel(rh: float, rl: float) -> float:
    """cos(r_h + r_l), |r| <= pi/4 + 2^-20: 1 - r^2/2 and C0 r^4 in double-double, the rest a
    polynomial."""
    zh = mul(rh, rh)
    zl = fma(rh, rh, -zh)
    hz = mul(0.5, zh)
    w = 1.0 - hz
    e = (1.0 - w) - hz                               # exact
    z2 = mul(zh, zh)
    z2l = fma(zh, zh, -z2)
    p = fma(fma(fma(fma(_C5, zh, _C4), zh, _C3), zh, _C2), zh, _C1)
    sr = fma(mul(zh, -_SIXTH_HI), rh, rh)             # sin r to ~r^5/120: the factor of r_l
    tail = fma(z2l, _C0, (e - mul(0.5, zl)) - mul(sr, rl))
    return w + fma(z2, _C0, fma(mul(z2, zh), p, tail))


def _sin_fast(rh: float, rl: float) -> float:
    """sin(r_h + r_l), |r| <= pi/4 + 2^-20, faithfully: r_h + r^3 (-1/6 + z S(z)), r_l cos r."""
    z = mul(rh, rh)
    p = fma(fma(fma(fma(fma(_S5, z, _S4), z, _S3), z, _S2), z, _S1), z, _S0)
    return rh + fma(mul(rh, z), fma(z, p, -_SIXTH_HI), fma(mul(-0.5, z), rl, rl))


def _cos_fast(rh: float, rl: float) -> float:
    """cos(r_h + r_l), |r| <= pi/4 + 2^-20, faithfully: 1 - r_h^2/2 exact as w + e, then
    z^2 C(z) and -r_h r_l."""
    hr = mul(0.5, rh)
    hz = mul(hr, rh)
    w = 1.0 - hz
    e = ((1.0 - w) - hz) - fma(hr, rh, -hz)          # exact
    z = mul(rh, rh)
    p = fma(fma(fma(fma(fma(_C5, z, _C4), z, _C3), z, _C2), z, _C1), z, _C0)
    return w + (e + fma(mul(z, z), p, -mul(rh, rl)))


def _quadrant(q: int, s: float, c: float) -> float:
    """sin(n pi/2 + r) from n mod 4 = q, s = sin r, c = cos r (cos: q + 1)."""
    v = c if (q & 1) == 1 else s
    return -v if (q & 2) == 2 else v


def _sincos_huge(x: float) -> tuple[float, float]:
    """(sin x, cos x) for 2^30 < |x| < inf, reduced exactly (Payne-Hanek)."""
    b = as_bits(x) & _ABS
    q, a0, a1, a2 = _payne_hanek((b & 0xFFFFFFFFFFFFF) | 0x10000000000000, (b >> 52) - 1023)
    fh, fl = _fast_two_sum(a0, a1)
    rh, rl = _dd_mul(fh, fl + a2, _PIO2_1, _PIO2_2)
    s = _sin_kernel(rh, rl)
    c = _cos_kernel(rh, rl)
    sn = _quadrant(q, s, c)
    return (-sn if x < 0.0 else sn), _quadrant(q + 1, s, c)


def _sin_huge(x: float) -> float:
    return _sincos_huge(x)[0]


def _cos_huge(x: float) -> float:
    return _sincos_huge(x)[1]


def sincos(x: float) -> tuple[float, float]:
    """(sin x, cos x)."""
    ax = abs(x)
    fast = ax <= SIN_COS_FAST_LIMIT                  # False for NaN
    q, rh, rl = _reduce_pio2(x if fast else 0.0)
    s = _sin_fast(rh, rl)
    c = _cos_fast(rh, rl)
    sn = _quadrant(q, s, c)
    cs = _quadrant(q + 1, s, c)
    if (not fast) & (ax < _INF):
        sn = _sin_huge(x)
        cs = _cos_huge(x)
    sn = x if ax < _M27 else sn                      # sin(-0) = -0
    bad = not (ax < _INF)
    return (x - x if bad else sn), (x - x if bad else cs)


def sin(x: float) -> float:
    """sin x."""
    ax = abs(x)
    fast = ax <= SIN_COS_FAST_LIMIT
    q, rh, rl = _reduce_pio2(x if fast else 0.0)
    res = _quadrant(q, _sin_fast(rh, rl), _cos_fast(rh, rl))
    if (not fast) & (ax < _INF):
        res = _sin_huge(x)
    res = x if ax < _M27 else res
    return x - x if not (ax < _INF) else res         # sin(+-inf) = NaN


def tan(x: float) -> float:
    """tan x = sin x / cos x (both from one reduction)."""
    s, c = sincos(x)
    return s / c


def cos(x: float) -> float:
    """cos x."""
    ax = abs(x)
    fast = ax <= SIN_COS_FAST_LIMIT
    q, rh, rl = _reduce_pio2(x if fast else 0.0)
    res = _quadrant(q + 1, _sin_fast(rh, rl), _cos_fast(rh, rl))
    if (not fast) & (ax < _INF):
        res = _cos_huge(x)
    return x - x if not (ax < _INF) else res
