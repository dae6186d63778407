"""Double-double arithmetic for the elementary functions (wells.elementary): exact sums and
products (Knuth, Dekker), powers of two and copysign by bit casts.  Code in the wells' language,
compiled with wells.elementary for every target (its ``_MODULES``)."""
from __future__ import annotations

from safebasins.wells.compiled import fma, mul
from safebasins.wells.elementary_targets import as_bits, from_bits

_SIGN = -0x8000000000000000         # the sign bit (int64)
_ABS = 0x7FFFFFFFFFFFFFFF


def _two_sum(a: float, b: float) -> tuple[float, float]:
    """(s, e): s = a + b rounded, e its exact error (Knuth)."""
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


def _fast_two_sum(a: float, b: float) -> tuple[float, float]:
    """(s, e) as _two_sum, for |a| >= |b| or a = 0 (Dekker)."""
    s = a + b
    return s, b - (s - a)


def _two_prod(a: float, b: float) -> tuple[float, float]:
    """(p, e): p = a b rounded, e = fma(a, b, -p) its exact error."""
    p = mul(a, b)
    return p, fma(a, b, -p)


def _dd_mul(ah: float, al: float, bh: float, bl: float) -> tuple[float, float]:
    """(a_h + a_l)(b_h + b_l), normalised (relative error ~2^-104)."""
    p = mul(ah, bh)
    return _fast_two_sum(p, fma(ah, bh, -p) + (mul(ah, bl) + mul(al, bh)))


def _pow2(k: int) -> float:
    """2^k for an integer -1022 <= k <= 1023."""
    return from_bits((k + 1023) << 52)


def _copysign(a: float, x: float) -> float:
    return from_bits((as_bits(a) & _ABS) | (as_bits(x) & _SIGN))
