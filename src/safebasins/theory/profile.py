"""The tables of the conservative slow flow's escape criterion (paper eqs 18, 21, 25).

``a(xi) = h - F A(xi)`` and ``b(xi) = h + F A(xi)`` with ``h = xi - Omega J(xi)`` are the first
integral C on the rays gamma' = 0 and pi (gamma' = gamma + delta(xi); delta = 0 for a symmetric
well).  A point ``(gamma, xi)`` escapes iff ``max a <= C(gamma, xi) <= min b`` over
``[xi, xi_max]`` (:mod:`safebasins.theory.slow_flow`).  :class:`SlowFlowProfile` tabulates a and
b with their critical points (Brent's method) as nodes and their suffix extrema;
:func:`level_escapes` is the criterion itself.  The damped slow flow shares :func:`unshear`.
"""
from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import optimize

from safebasins.theory.types import BoolArray, FloatArray
from safebasins.wells.base import Well

__all__ = ["SHIFT_RESOLUTION", "SlowFlowProfile", "level_escapes", "resolved_shift", "unshear", "xi_grid"]


def unshear(g: ArrayLike, shift: ArrayLike) -> Any:
    """The slow phase gamma (in (-pi, pi]) of a point at gamma' = g on the sheared rays
    gamma' = gamma + delta(xi) (``shift`` = delta; 0 for a symmetric well: g itself)."""
    return np.pi - np.mod(np.pi - (np.asarray(g) - shift), 2.0 * np.pi)


#: a shift delta smaller than this in magnitude (rad) is noise of a well's tables (a symmetric
#: well's delta is 0, its tables give a few 1e-16 of either sign, which would put a point of the
#: ray gamma' = pi at +pi or -pi)
SHIFT_RESOLUTION = 1e-12


def resolved_shift(well: Well, xi: ArrayLike) -> FloatArray:
    """``well.harmonic_shift(xi)`` with values below :data:`SHIFT_RESOLUTION` set to exactly 0."""
    d = np.asarray(well.harmonic_shift(xi), dtype=float)
    out: FloatArray = np.where(np.abs(d) < SHIFT_RESOLUTION, 0.0, d)
    return out


def xi_grid(lo: float, hi: float, n: int) -> FloatArray:
    """Grid on [lo, hi] clustered at both ends (Chebyshev-Lobatto spacing)."""
    t = np.linspace(0.0, 1.0, n)
    x: FloatArray = lo + (hi - lo) * 0.5 * (1.0 - np.cos(np.pi * t))
    x[0], x[-1] = lo, hi
    return x


def _h_prime(xi: FloatArray, Omega: float, well: Well) -> FloatArray:
    with np.errstate(divide="ignore"):
        out: FloatArray = 1.0 - Omega / well.omega(xi)
    return out


def _ab_prime(xi: FloatArray, F: float, Omega: float, well: Well) -> tuple[FloatArray, FloatArray]:
    hp = _h_prime(xi, Omega, well)
    gp = well.harmonic_amplitude_derivative(xi)
    return hp - F * gp, hp + F * gp


def _critical_points(xi: FloatArray, F: float, Omega: float, well: Well,
                     which: int) -> tuple[FloatArray, NDArray[np.int_]]:
    """Roots of a'(xi) (which=0) or b'(xi) (which=1) on the open interval of the grid.

    Returns (roots, kinds) with kind +1 for a local max, -1 for a local min.
    """
    inner = xi[1:-1] if xi[-1] >= well.barrier_energy else xi[1:]
    if inner.size < 2:
        return np.empty(0), np.empty(0, int)
    d = _ab_prime(inner, F, Omega, well)[which]
    s = np.sign(d)
    idx = np.nonzero(s[:-1] * s[1:] < 0)[0]
    roots, kinds = [], []

    def f(x: float) -> float:
        return float(_ab_prime(np.asarray(x), F, Omega, well)[which])

    for i in idx:
        r = optimize.brentq(f, inner[i], inner[i + 1], xtol=1e-15, rtol=1e-15, maxiter=200)
        roots.append(r)
        kinds.append(1 if s[i] > 0 else -1)
    return np.asarray(roots, float), np.asarray(kinds, int)


class SlowFlowProfile:
    """Tabulated ``a(xi)``, ``b(xi)`` on [0, xi_max] with critical points as nodes.

    Attributes: ``xi``, ``h``, ``a``, ``b``, ``A`` (suffix max of a), ``B`` (suffix min of b),
    ``a_max``/``b_min`` (xi of interior local maxima of a / minima of b: saddles on
    gamma = 0 / pi), ``a_min``/``b_max`` (centres).  For a well whose first harmonic has a
    phase delta(xi), a and b are C on the sheared rays gamma + delta(xi) = 0, pi.  ``F``,
    ``Omega``, ``xi_max`` validated floats, ``well`` a resolved well.
    """

    def __init__(self, F: float, Omega: float, xi_max: float, well: Well, n: int = 1500,
                 lo: float = 0.0) -> None:
        self.F, self.Omega, self.xi_max, self.well = F, Omega, xi_max, well
        base = xi_grid(lo, xi_max, n)
        ra, ka = _critical_points(base, F, Omega, well, 0)
        rb, kb = _critical_points(base, F, Omega, well, 1)
        self.a_max, self.a_min = ra[ka > 0], ra[ka < 0]
        self.b_min, self.b_max = rb[kb < 0], rb[kb > 0]
        xi = np.unique(np.concatenate([base, ra, rb]))
        self.xi = xi
        self.J = well.J(xi)
        self.Gv = well.harmonic_amplitude(xi)
        self.h = xi - Omega * self.J
        self.a = self.h - F * self.Gv
        self.b = self.h + F * self.Gv
        self.A: FloatArray = np.maximum.accumulate(self.a[::-1])[::-1]
        self.B: FloatArray = np.minimum.accumulate(self.b[::-1])[::-1]

    def suffix(self, xi_ini: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """(max a, min b) over [xi_ini, xi_max] for xi_ini < xi_max, excluding a(xi_ini), b(xi_ini)."""
        j = np.searchsorted(self.xi, xi_ini, side="right")
        j = np.minimum(j, self.xi.size - 1)
        return self.A[j], self.B[j]


def level_escapes(prof: SlowFlowProfile, x: FloatArray, Jx: FloatArray, Gx: FloatArray,
                  cos: FloatArray) -> BoolArray:
    """The escape criterion (eq 21) of points below ``prof.xi_max``: ``max a <= C <= min b``
    over ``[x, xi_max]``, with ``C = x - Omega J - F A cos(gamma + delta)`` from the energies
    ``x``, ``Jx = J(x)``, ``Gx = A(x)`` and ``cos = cos(gamma + delta(x))`` (broadcast: ``cos``
    may carry a leading axis of phases).  True = escapes; nothing escapes at F = 0."""
    if prof.F == 0.0:
        return np.zeros(np.broadcast_shapes(np.shape(x), np.shape(cos)), dtype=bool)
    c0 = x - prof.Omega * Jx - prof.F * Gx * cos
    A, B = prof.suffix(x)
    out: BoolArray = (A <= c0) & (c0 <= B)
    return out
