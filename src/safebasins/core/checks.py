"""Argument checks shared by the library: every failure is a ValueError naming the argument.

Checks that depend on the potential (energies below the barrier, thresholds, displacements)
are methods of the well (:mod:`safebasins.wells`); the ones here are well-independent.
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

#: a check of a named value (``check_finite``, ``check_positive``, ...): the value as a float array
Check = Callable[[str, Any], np.ndarray]


#: relative distance below an escape energy within which a value counts as at it: the computed
#: energy of a numeric well's barrier may lie a few ulps off its exact value (the cubic's 1/6 is
#: 0.16666666666666669), so 1/6 given as a float would pass a strict ``x < E_b``
BARRIER_RTOL = 1e-12


def as_array(name: str, value: Any) -> np.ndarray:
    """``value`` as a float ndarray; ValueError naming ``name`` if not numeric, complex or NaN."""
    try:
        raw = np.asarray(value)
        complex_ = np.iscomplexobj(raw)
        a = raw if complex_ else raw.astype(float, copy=False)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be numeric, got {value!r}") from exc
    if complex_:    # (a float conversion would drop the imaginary part with only a warning)
        raise ValueError(f"{name} must be real, got the complex value {value_repr(raw)}")
    if np.isnan(a).any():
        raise ValueError(f"{name} must not contain NaN")
    return a


def reaches(values: npt.ArrayLike, level: float) -> np.ndarray:
    """Where ``values`` lie at or above ``level`` (an escape energy), counting values within a
    relative :data:`BARRIER_RTOL` below it as at it."""
    return np.asarray(values, dtype=float) >= level - BARRIER_RTOL * abs(level)


def check_nonempty(name: str, a: np.ndarray) -> np.ndarray:
    """``a`` (an array) with at least one element."""
    if np.size(a) == 0:
        raise ValueError(f"{name} must not be empty")
    return a


def check_finite(name: str, value: Any) -> np.ndarray:
    a = as_array(name, value)
    if not np.isfinite(a).all():
        raise ValueError(f"{name} must be finite")
    return a


def check_nonnegative(name: str, value: Any) -> np.ndarray:
    """Finite and >= 0 (an amplitude, a time)."""
    a = check_finite(name, value)
    if (a < 0).any():
        raise ValueError(f"{name} must be >= 0, got min {float(a.min())!r}")
    return a


def check_positive(name: str, value: Any) -> np.ndarray:
    """Finite and > 0 (a frequency, a tolerance)."""
    a = check_finite(name, value)
    if (a <= 0).any():
        raise ValueError(f"{name} must be > 0, got min {float(a.min())!r}")
    return a


def check_positive_int(name: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(f"{name} must be a positive integer, got {value!r}")
    return int(value)


def check_damping(damping: Any) -> float:
    """The damping beta of ``q'' + beta q' + V'(q) = F sin(Omega t + Psi)``: a finite scalar >= 0
    (ValueError naming ``damping`` otherwise)."""
    return check_scalar("damping", damping, check_nonnegative)


def check_positive_damping(damping: Any, why: str) -> float:
    """check_damping, and damping > 0: ``why`` says what needs it (ValueError naming ``damping``)."""
    beta = check_damping(damping)
    if not beta > 0:
        raise ValueError(f"damping must be > 0 ({why}), got {damping!r}")
    return beta


def check_scalar(name: str, value: Any, check: Check) -> float:
    """``check(name, value)`` and a 0-d result, returned as float."""
    a = check(name, value)
    if a.ndim != 0:
        raise ValueError(f"{name} must be a scalar, got shape {a.shape}")
    return float(a)


def check_1d(name: str, value: Any, check: Check) -> np.ndarray:
    """``check(name, value)`` as a 1-D float array (a scalar becomes length 1)."""
    a = np.atleast_1d(check(name, value)).astype(float)
    if a.ndim != 1:
        raise ValueError(f"{name} must be a scalar or a 1-D sequence, got shape {a.shape}")
    return check_nonempty(name, a)


def value_repr(a: Any) -> str:
    a = np.asarray(a)
    return repr(a.item()) if a.ndim == 0 else repr(a.tolist() if a.size <= 6 else f"array with range [{a.min()}, "
                                                                                  f"{a.max()}]")


def _monotone(a: np.ndarray) -> bool:
    d = np.diff(a)
    return bool(np.all(d > 0) or np.all(d < 0))


def initial_conditions(q0: npt.ArrayLike, p0: npt.ArrayLike, grid: bool | None
                       ) -> tuple[bool, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(is_grid, q axis, p axis, Q, P)`` of the initial conditions of an ensemble: 1-D axes make
    a grid (dims q0, p0; ``grid=None``: when both are monotone) unless ``grid=False``; otherwise
    paired points of the same shape."""
    qa = check_finite("q0", q0)
    pa = check_finite("p0", p0)
    if grid is None:
        grid = qa.ndim == 1 and pa.ndim == 1 and _monotone(qa) and _monotone(pa)
    if grid:
        if qa.ndim != 1 or pa.ndim != 1:
            raise ValueError(f"q0 and p0 must be 1-D axes for grid=True, got shapes {qa.shape}, {pa.shape}")
        if qa.size == 0 or pa.size == 0:
            raise ValueError("q0 and p0 axes must not be empty")
        Q, P = np.meshgrid(qa, pa, indexing="ij")
        return True, qa, pa, Q.ravel(), P.ravel()
    if qa.shape != pa.shape:
        raise ValueError(f"q0 and p0 must have the same shape for paired initial conditions (grid=False), "
                         f"got {qa.shape} and {pa.shape}")
    return False, qa, pa, qa.ravel(), pa.ravel()
