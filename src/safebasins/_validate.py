"""One place for argument checks: every failure is a ValueError naming the argument."""
from __future__ import annotations

import numpy as np

XI_SEPARATRIX = 0.25  # energy of the hilltops q = +-1 of V(q) = q^2/2 - q^4/4


def _arr(name, value):
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be numeric, got {value!r}") from exc
    if np.isnan(a).any():
        raise ValueError(f"{name} must not contain NaN")
    return a


def check_energy(name, xi, *, allow_separatrix=False):
    """Averaged energy xi in [0, 1/4) (or [0, 1/4] with allow_separatrix)."""
    a = _arr(name, xi)
    if (a < 0).any():
        raise ValueError(f"{name} must be >= 0 (energy measured from the well bottom), got min {a.min()!r}")
    if allow_separatrix:
        if (a > XI_SEPARATRIX).any():
            raise ValueError(f"{name} must be <= 1/4 (separatrix energy), got max {a.max()!r}")
    elif (a >= XI_SEPARATRIX).any():
        raise ValueError(
            f"{name} must be < 1/4: the action-angle map is singular on the separatrix, got max {a.max()!r}")
    return a


def check_threshold(name, xi_max):
    """Truncation energy xi_max in (0, 1/4]."""
    a = _arr(name, xi_max)
    if ((a <= 0) | (a > XI_SEPARATRIX)).any():
        raise ValueError(f"{name} must lie in (0, 1/4], got {value_repr(a)}")
    return a


def check_displacement_threshold(name, q_max):
    """Displacement threshold q_max in (0, 1]."""
    a = _arr(name, q_max)
    if ((a <= 0) | (a > 1)).any():
        raise ValueError(f"{name} must lie in (0, 1], got {value_repr(a)}")
    return a


def check_nonnegative(name, value):
    a = _arr(name, value)
    if (a < 0).any():
        raise ValueError(f"{name} must be >= 0 (an amplitude), got min {a.min()!r}")
    return a


def check_positive(name, value):
    a = _arr(name, value)
    if (a <= 0).any():
        raise ValueError(f"{name} must be > 0, got min {a.min()!r}")
    return a


def check_finite(name, value):
    a = _arr(name, value)
    if not np.isfinite(a).all():
        raise ValueError(f"{name} must be finite")
    return a


def check_positive_int(name, value):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(f"{name} must be a positive integer, got {value!r}")
    return int(value)


def value_repr(a):
    a = np.asarray(a)
    return repr(a.item()) if a.ndim == 0 else repr(a.tolist() if a.size <= 6 else f"array with range [{a.min()}, {a.max()}]")
