"""``V`` near the well bottom from ``V'`` when the given ``V`` loses relative accuracy there.

The action-angle data at small energies need ``V(q)`` to *relative* precision near ``q = 0``
(turning points ``V(q_pm) = E``, ``J/E``).  A potential written as ``1 - cos q`` or
``(1 - exp(-q))^2`` subtracts O(1) numbers: its error is ~``eps`` absolute, ``eps / V(q)``
relative (1e-6 at ``q = 1e-5``), and the interpolation in E cannot converge.  ``V' = sin q`` has no
such problem, so there ``V`` is evaluated as ``int_0^q V'(s) ds`` (Gauss-Legendre, ``N_NODES``
nodes on ``[0, q]``).

Detection (:func:`cancellation_fix`): at probes ``|q| = L 10^(-j/2)`` (``L`` the extent of the well
on that side, ``j = 2..17``) the relative difference ``r(q)`` of ``V`` and the quadrature.  An
absolute error grows relative to ``V ~ q^2`` as ``q -> 0``: cancellation when ``r`` at the
smallest probes exceeds ``DETECT`` and is ``>= 1e3`` times ``r`` at the largest probe.  A ``V'``
off by a constant factor (a relative mismatch, the same at every q) is not "fixed" here; the
derivative check of :class:`~safebasins.wells.numeric.NumericWell` reports it.

Where: ``|q| < q_c``, with ``q_c = L / 2`` on each side (the barrier values ``V(q_b)`` stay those
of the given V), halved until the ``N_NODES`` and ``N_CHECK`` node rules agree to ``4 eps``;
there ``V / q^2`` is tabulated as a Chebyshev series (:class:`BottomIntegralV`).
Wells whose V is accurate (polynomials by Horner's rule, ``2 sin(q/2)^2``, ``tanh(q)^2``) are left
untouched.
"""
from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt
from numpy.polynomial import chebyshev as _cheb
from numpy.polynomial import legendre as _leg
from scipy.fft import dct

__all__ = ["cancellation_fix", "BottomIntegralV"]

EPS = np.finfo(float).eps
N_NODES, N_CHECK = 12, 20
#: relative error of V at the smallest probes that counts as cancellation
DETECT = 64e3 * EPS


def _rule(n: Any) -> Any:
    x, w = _leg.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


_RULES = {n: _rule(n) for n in (N_NODES, N_CHECK)}


def bottom_integral(dV: Any, q: npt.ArrayLike, n: Any = N_NODES) -> Any:
    """``int_0^q V'(s) ds`` for a 1-D array q (Gauss-Legendre with n nodes on [0, q])."""
    t, w = _RULES[n]
    q = np.asarray(q, dtype=float)
    return q * (dV(q[:, None] * t) @ w)


class BottomIntegralV:
    """``V(q)``, but ``int_0^q V'`` for ``-q_left < q < q_right`` (``V``, ``dV`` vectorised).

    There ``V = q^2 g(q)`` with ``g`` analytic; ``g`` is tabulated once as a Chebyshev series on
    ``[-q_left, q_right]`` from the quadrature (degree doubled from 24 until the trailing
    coefficients are below ``8 eps`` of the largest), so an evaluation costs a polynomial, not
    ``N_NODES`` calls of ``V'``."""

    def __init__(self, V: Any, dV: Any, q_left: Any, q_right: Any) -> None:
        self.V, self.dV = V, dV
        self.q_left, self.q_right = float(q_left), float(q_right)
        for n in (24, 48, 96, 192):
            # coefficients by a DCT at the first-kind nodes (accurate to ~eps of the largest)
            q = self._q(np.cos(np.pi * (np.arange(n) + 0.5) / n))
            c = dct(bottom_integral(dV, q) / (q * q), type=2) / n
            c[0] *= 0.5
            if np.max(np.abs(c[-3:])) <= 8 * EPS * np.max(np.abs(c)):
                break
        else:
            raise ValueError(f"dV: int_0^q V' / q^2 is not smooth on [{-self.q_left!r}, {self.q_right!r}] "
                             "(V' not analytic at the well bottom)")
        self.coefficients = c

    def _q(self, t: Any) -> Any:
        return 0.5 * (self.q_right - self.q_left) + 0.5 * (self.q_right + self.q_left) * t

    def __call__(self, q: Any) -> Any:
        q = np.asarray(q, dtype=float)
        out = np.array(self.V(q), dtype=float)
        near = (q > -self.q_left) & (q < self.q_right)
        if near.any():
            qn = q[near]
            t = (2.0 * qn - (self.q_right - self.q_left)) / (self.q_right + self.q_left)
            out[near] = qn * qn * _cheb.chebval(t, self.coefficients)
        return out


def cancellation_fix(V: Any, dV: Any, scales: Any) -> Any:
    """A :class:`BottomIntegralV` if ``V`` loses relative accuracy at the bottom, else None.

    ``scales`` = ``(L_left, L_right)``: the extent of the well on each side (distance to the
    barrier, the closing point, or the start of an open side's tail)."""
    ratio, worst = [], 0.0
    for side, L in zip((-1.0, 1.0), scales):
        q = side * L * 10.0 ** -np.arange(1.0, 8.5, 0.5)
        ref = bottom_integral(dV, q)
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.abs(V(q) - ref) / np.abs(ref)
        r = np.where(np.isfinite(r), r, np.inf)
        small = float(np.median(r[-3:]))
        worst = max(worst, small)
        ratio.append(small / max(float(r[0]), EPS))
    if not (worst > DETECT and max(ratio) >= 1e3):
        return None
    q_c = []
    for side, L in zip((-1.0, 1.0), scales):
        x = 0.5 * L
        for _ in range(60):
            a, b = (bottom_integral(dV, np.array([side * x]), n)[0] for n in (N_NODES, N_CHECK))
            if abs(a - b) <= 4 * EPS * abs(b):
                break
            x *= 0.5
        q_c.append(x)
    return BottomIntegralV(V, dV, q_c[0], q_c[1])
