"""Argument checks shared by the library: every failure is a ValueError naming the argument.

Checks that depend on the potential (energies below the barrier, thresholds, displacements)
are methods of the well (:mod:`safebasins.wells`); the ones here are well-independent.
"""
from __future__ import annotations

import numpy as np


def as_array(name, value):
    """``value`` as a float ndarray; ValueError naming ``name`` if not numeric or NaN."""
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be numeric, got {value!r}") from exc
    if np.isnan(a).any():
        raise ValueError(f"{name} must not contain NaN")
    return a


def check_finite(name, value):
    a = as_array(name, value)
    if not np.isfinite(a).all():
        raise ValueError(f"{name} must be finite")
    return a


def check_nonnegative(name, value):
    """Finite and >= 0 (an amplitude, a time)."""
    a = check_finite(name, value)
    if (a < 0).any():
        raise ValueError(f"{name} must be >= 0, got min {float(a.min())!r}")
    return a


def check_positive(name, value):
    """Finite and > 0 (a frequency, a tolerance)."""
    a = check_finite(name, value)
    if (a <= 0).any():
        raise ValueError(f"{name} must be > 0, got min {float(a.min())!r}")
    return a


def check_positive_int(name, value):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(f"{name} must be a positive integer, got {value!r}")
    return int(value)


def check_scalar(name, value, check):
    """``check(name, value)`` and a 0-d result, returned as float."""
    a = check(name, value)
    if a.ndim != 0:
        raise ValueError(f"{name} must be a scalar, got shape {a.shape}")
    return float(a)


def check_1d(name, value, check):
    """``check(name, value)`` as a 1-D float array (a scalar becomes length 1)."""
    a = np.atleast_1d(check(name, value)).astype(float)
    if a.ndim != 1:
        raise ValueError(f"{name} must be a scalar or a 1-D sequence, got shape {a.shape}")
    return a


def value_repr(a):
    a = np.asarray(a)
    return repr(a.item()) if a.ndim == 0 else repr(a.tolist() if a.size <= 6 else f"array with range [{a.min()}, {a.max()}]")
