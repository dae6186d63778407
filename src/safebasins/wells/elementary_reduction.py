"""Exact reduction of huge arguments by pi/2 (Payne-Hanek), in 64-bit integer arithmetic.

For x = m 2^(e-52) (m the 53-bit integer significand, 30 <= e <= 1023), :func:`reduce_pio2`
returns n mod 4 and the fraction of x (2/pi) nearest to zero, x (2/pi) = n + F, ``|F| <= 1/2``, as
three exact doubles (F = a0 + a1 + a2 to 2^-144, 82 bits below the smallest ``|F|`` of any double,
2^-61.4).  The product m 2^(e-52) (2/pi) is formed column by column in base 2^24 from the
24-bit digits of 2/pi: every partial product is below 2^48 and every column sum below 2^51,
so no intermediate leaves int64 (and the same Python, run by numba's CUDA simulator with
Python integers, gives the same numbers).  Written once, like elementary.py, in plain
integer and float arithmetic.
"""
from __future__ import annotations

__all__ = ["reduce_pio2", "TWO_OVER_PI_DIGITS"]

#: 2/pi = sum_i D[i] 2^(-24 (i + 1)): 56 digits of 24 bits (1344 bits; e <= 1023 reads up to D[50])
TWO_OVER_PI_DIGITS = (
    10680707, 7228996, 1387004, 2578385, 16069853, 12639074, 9804092, 4427841, 16666979, 11263675,
    12935607, 2387514, 4345298, 14681673, 3074569, 13734428, 16653803, 1880361, 10960616, 8533493,
    3062596, 8710556, 7349940, 6258241, 3772886, 3769171, 3798172, 8675211, 12450088, 3874808,
    9961438, 366607, 15675153, 9132554, 7151469, 3571407, 2607881, 12013382, 4155038, 6285869,
    7677882, 13102053, 15825725, 473591, 9065106, 15363067, 6271263, 9264392, 5636912, 4652155,
    7056368, 13614112, 10155062, 1944035, 9527646, 15080200)
_MASK = 0xFFFFFF
_P48, _P96, _P144 = 2.0 ** -48, 2.0 ** -96, 2.0 ** -144


def _digit(i: int) -> int:
    """D[i], 0 for i < 0 (digits above 2^-1: none)."""
    d = TWO_OVER_PI_DIGITS[i if i > 0 else 0]
    return d if i >= 0 else 0


def _column(c: int, a: int, l0: int, l1: int, l2: int, l3: int) -> int:
    """Sum of the partial products of weight 2^(-24 (c + 1)): l_j D[c + j + a]."""
    return (l0 * _digit(c + a) + l1 * _digit(c + 1 + a)) + (l2 * _digit(c + 2 + a) + l3 * _digit(c + 3 + a))


def reduce_pio2(m: int, e: int) -> tuple[int, float, float, float]:
    """(n mod 4, a0, a1, a2): x (2/pi) = n + a0 + a1 + a2 for x = m 2^(e-52), 2^52 <= m < 2^53,
    e >= 30; ``|a0 + a1 + a2| <= 1/2``, a0 a multiple of 2^-48, ``|a1| < 2^-48``, ``|a2| < 2^-96``."""
    ex = e - 52
    a = ex // 24
    b = ex - 24 * a                                  # x = (m 2^b) 2^(24 a), 0 <= b < 24
    l0 = (m & (_MASK >> b)) << b                     # base-2^24 digits of m 2^b (< 2^77)
    l1 = (m >> (24 - b)) & _MASK
    l2 = (m >> (48 - b)) & _MASK
    l3 = (m >> 49) >> (23 - b)
    # columns of weight 2^0 (integer part: only its value mod 4 matters) to 2^-192
    ci = _column(-1, a, l0, l1, l2, l3)
    d0 = _column(0, a, l0, l1, l2, l3)
    d1 = _column(1, a, l0, l1, l2, l3)
    d2 = _column(2, a, l0, l1, l2, l3)
    d3 = _column(3, a, l0, l1, l2, l3)
    d4 = _column(4, a, l0, l1, l2, l3)
    d5 = _column(5, a, l0, l1, l2, l3)
    d6 = _column(6, a, l0, l1, l2, l3)
    d7 = _column(7, a, l0, l1, l2, l3)
    d6 += d7 >> 24
    d5 += d6 >> 24
    d6 &= _MASK
    d4 += d5 >> 24
    d5 &= _MASK
    d3 += d4 >> 24
    d4 &= _MASK
    d2 += d3 >> 24
    d3 &= _MASK
    d1 += d2 >> 24
    d2 &= _MASK
    d0 += d1 >> 24
    d1 &= _MASK
    ci += d0 >> 24
    d0 &= _MASK
    # nearest integer: a fraction >= 1/2 becomes fraction - 1 (its digits complemented; the unit
    # 2^-192 of the complement is below what the three doubles carry)
    up = d0 >= 0x800000
    q = (ci + 1) & 3 if up else ci & 3
    d0 = _MASK - d0 if up else d0
    d1 = _MASK - d1 if up else d1
    d2 = _MASK - d2 if up else d2
    d3 = _MASK - d3 if up else d3
    d4 = _MASK - d4 if up else d4
    d5 = _MASK - d5 if up else d5
    sign = -1.0 if up else 1.0
    a0 = sign * float((d0 << 24) | d1) * _P48
    a1 = sign * float((d2 << 24) | d3) * _P96
    a2 = sign * float((d4 << 24) | d5) * _P144
    return q, a0, a1, a2
