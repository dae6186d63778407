"""Counter-based random numbers for the compiled engines: Philox4x32-10 and uniforms from it.

Salmon, Moraes, Dror & Shaw (2011), "Parallel random numbers: as easy as 1, 2, 3" (SC11):
``philox4x32(c0, c1, c2, c3, k0, k1)`` maps a 128-bit counter and a 64-bit key to four 32-bit
words, a bijection of the counter for each key, statistically random (BigCrush) with 10 rounds.
A random number is then a pure function of (seed, trajectory, path, step): threads, lanes, tiles,
the replay of a period and the backend (CPU lanes or CUDA) cannot change it, and no state is
carried.  Known-answer vectors of the Random123 distribution: tests/numerics/test_philox.py.

The functions are written in the well-code language (plain Python on integers that numba types
as uint64; every 32-bit word is kept masked), so the CPU lanes and the CUDA kernels compile the
same source, as a well's force (wells/compiled.py).  32 x 32 -> 64-bit products are exact in uint64.
"""
from __future__ import annotations

import numpy as np

__all__ = ["philox4x32", "uniform53", "MASK32"]

MASK32 = np.uint64(0xFFFFFFFF)
_M0 = np.uint64(0xD2511F53)
_M1 = np.uint64(0xCD9E8D57)
_W0 = np.uint64(0x9E3779B9)
_W1 = np.uint64(0xBB67AE85)
_S32 = np.uint64(32)
_S11 = np.uint64(11)
_S21 = np.uint64(21)
#: 2^-53: a 53-bit integer times it is an exact double in [0, 1)
_TWO_M53 = 2.0 ** -53


def philox4x32(c0: np.uint64, c1: np.uint64, c2: np.uint64, c3: np.uint64, k0: np.uint64,
               k1: np.uint64) -> tuple[np.uint64, np.uint64, np.uint64, np.uint64]:
    """The four 32-bit output words (uint64 values < 2^32) of Philox4x32-10 for the counter
    (c0, c1, c2, c3) and the key (k0, k1), all uint64 values < 2^32.  (One function, no calls:
    a target compiles it as it is.)"""
    for r in range(10):
        if r > 0:                         # the key is bumped between rounds
            k0 = (k0 + _W0) & MASK32
            k1 = (k1 + _W1) & MASK32
        p0 = _M0 * c0
        p1 = _M1 * c2
        c0, c1, c2, c3 = (p1 >> _S32) ^ c1 ^ k0, p1 & MASK32, (p0 >> _S32) ^ c3 ^ k1, p0 & MASK32
    return c0, c1, c2, c3


def uniform53(hi: np.uint64, lo: np.uint64) -> float:
    """A double in (0, 1] from two 32-bit words: the 53-bit integer (hi << 21) ^ (lo >> 11), plus
    one, times 2^-53 (exact; never 0, so that log(u) is finite)."""
    return float(((hi << _S21) ^ (lo >> _S11)) + np.uint64(1)) * _TWO_M53
