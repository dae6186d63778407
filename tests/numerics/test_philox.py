"""Philox4x32-10 against the known-answer vectors of the Random123 distribution (kat_vectors),
in Python and compiled by numba (the same source); the uniforms from it lie in (0, 1]."""
from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from safebasins.numerics.philox import philox4x32, uniform53

KAT = [("00000000 00000000 00000000 00000000", "00000000 00000000", "6627e8d5 e169c58d bc57ac4c 9b00dbd8"),
       ("ffffffff ffffffff ffffffff ffffffff", "ffffffff ffffffff", "408f276d 41c83b0e a20bc7c6 6d5451fd"),
       ("243f6a88 85a308d3 13198a2e 03707344", "a4093822 299f31d0", "d16cfe09 94fdcceb 5001e420 24126ea1")]


def _words(text):
    return [np.uint64(int(x, 16)) for x in text.split()]


@pytest.mark.parametrize("counter,key,out", KAT)
def test_known_answers_python_and_compiled(counter, key, out):
    expected = [int(x, 16) for x in out.split()]
    assert [int(x) for x in philox4x32(*_words(counter), *_words(key))] == expected
    assert [int(x) for x in njit(philox4x32)(*_words(counter), *_words(key))] == expected


def test_uniform_in_open_closed_unit_interval_and_uniform():
    u = njit(uniform53)
    assert u(np.uint64(0), np.uint64(0)) == 2.0 ** -53
    assert u(np.uint64(0xFFFFFFFF), np.uint64(0xFFFFFFFF)) == 1.0
    ph = njit(philox4x32)
    words = [ph(np.uint64(i), np.uint64(0), np.uint64(0), np.uint64(0), np.uint64(7), np.uint64(0))
             for i in range(10000)]
    x = np.array([u(w[0], w[1]) for w in words] + [u(w[2], w[3]) for w in words])
    assert 0.0 < x.min() and x.max() <= 1.0
    # mean and variance of U(0, 1) within 5 standard errors
    assert abs(x.mean() - 0.5) < 5 * np.sqrt(1 / 12 / x.size)
    assert abs(x.var() - 1 / 12) < 5 * np.sqrt(1 / 180 / x.size)
