"""Sides of a well that are open at infinity (Morse, sech^2 / Poschl-Teller, Gaussian wells).

A side of the well bottom without a barrier has ``V'`` of one sign, so ``V`` increases
monotonically away from the bottom.  Either it grows without bound (``V -> +inf``: the side is
*closed*, no escape that way) or it tends to a finite limit ``A`` (the side is *open at
infinity*): a particle with ``H0 > A`` runs off to infinity on that side, so ``A`` is the side's
escape energy, just as ``V(q_b)`` is for a barrier.  An orbit of energy ``E < A`` turns at a
finite point, which goes to infinity as ``E -> A``; the orbit at ``E = A`` is unbounded (not a
separatrix of a saddle) and the period diverges as a power of ``A - E``, not logarithmically
(Morse: ``omega = a sqrt(2 (D - E))``).  Details: docs/wells.md.

Detection (:func:`geometric_values`, :func:`converged_limit`): ``V`` along ``|q| = x_start 2^k``
(``k = 0, 1, ...`` while finite); the side converges when ``RUN`` consecutive values agree within
``CONVERGED`` (relative), i.e. V is constant to float precision over a factor 256 in ``|q|``.

Accuracy near the limit (:class:`Tail`): far out ``V`` is within a few ulps of ``A`` and
``A - V(q)`` has lost its digits, but ``V'`` has not.  Beyond ``x0`` (where ``A - V = A/8``) the
tail function ``G(x) = A - V(side x) = int_x^inf side V'(side r) dr`` is therefore tabulated by
Gauss-Legendre quadrature of ``V'`` on adaptive panels (knots ``x_j``, ``G_j`` summed from the far
end) and evaluated as ``G_j + int_x^{x_j} side V'``: relative accuracy ~1e-15 down to
``G ~ 1e-16 A``, the smallest ``A - E`` of a float ``E < A``.
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.polynomial import legendre as _leg
from scipy import optimize

__all__ = ["geometric_values", "converged_limit", "Tail", "TAIL_START", "CONVERGED"]

EPS = np.finfo(float).eps
#: relative agreement of RUN consecutive values of V along the geometric sequence (``|q|`` growing by
#: 2^RUN) that counts as converged
CONVERGED = 4 * EPS
RUN = 8
#: ``G(x0) = TAIL_START * A``: beyond x0, ``A - V`` would lose more than 3 bits
TAIL_START = 0.125
#: a panel integral below ``NEGLIGIBLE * A`` ends the table: the rest is negligible against the
#: smallest ``A - E`` of a float ``E < A`` (~1e-16 A) even for slowly (algebraically) decaying tails
NEGLIGIBLE = 1e-34
#: panels accepted when the Gauss-Legendre rule and its two halves agree to this (relative; the
#: halves are then far more accurate, ~1e-16, for an analytic V'); a V' that is not relatively
#: accurate in the tail (noise above this) is rejected
PANEL_RTOL = 1e-12
_X, _W = _leg.leggauss(20)
_T, _W = 0.5 * (_X + 1.0), 0.5 * _W


def geometric_values(V: Any, side: Any, start: Any) -> Any:
    """``x_k = start 2^k`` (all finite ones) and ``V(side x_k)`` (``V`` vectorised, quiet)."""
    with np.errstate(over="ignore"):
        x = np.ldexp(float(start), np.arange(1100))
    x = x[np.isfinite(x)]
    return x, V(side * x)


def converged_limit(v: Any) -> Any:
    """``(A, k)``: the value ``V`` settles to along the sequence ``v``: the first run of ``RUN``
    consecutive finite values within ``CONVERGED`` of each other starts at ``k``, ``A`` its last
    value; ``(None, None)`` if there is none.  (Values beyond the run are not looked at: near
    ``|q| ~ 1e150`` a formula such as ``q^2 / (1 + q^2)`` overflows.)"""
    v = np.asarray(v, dtype=float)
    if v.size < RUN:
        return None, None
    w = np.lib.stride_tricks.sliding_window_view(v, RUN)
    with np.errstate(invalid="ignore"):
        flat = np.isfinite(w).all(axis=1) & (w[:, 0] != 0) & \
            (np.abs(w - w[:, :1]) <= CONVERGED * np.abs(w[:, :1])).all(axis=1)
    k = np.flatnonzero(flat)
    if k.size == 0:
        return None, None
    return float(w[k[0], -1]), int(k[0])


class Tail:
    """``G(x) = A - V(side x)`` for ``x >= x0`` on a side open at infinity, from ``V'``.

    ``f(x) = side V'(side x)`` (vectorised, > 0 on the side), ``A`` the limit, ``V`` the potential
    (for ``x0``: the first ``x`` with ``A - V <= TAIL_START A``), ``x_hint`` a point with ``V``
    above that level.  ``where`` names the side in error messages.  Attributes: ``A``, ``x0``,
    ``G0 = G(x0)``, ``ell0`` (decay length ``G/f`` at x0), ``knots``, ``G_knots``, ``ell_knots``
    (``G/f`` there).
    """

    def __init__(self, f: Any, V: Any, side: Any, A: Any, x_hint: Any, where: Any) -> None:
        self.f, self.side, self.A, self.where, self._V = f, float(side), float(A), where, V
        level = (1.0 - TAIL_START) * self.A
        g: Callable[[Any], Any] = lambda x: float(V(np.array([side * x]))[0]) - level
        lo = x_hint
        while lo > 1e-300 and g(lo) >= 0:
            lo *= 0.5
        hi = 2.0 * lo
        while g(hi) < 0:
            hi *= 2.0
        self.x0 = float(optimize.brentq(g, lo, hi, xtol=1e-300, rtol=1e-12, maxiter=500))
        self._table()
        self.G0 = float(self.G_knots[0])
        self.ell0 = self.G0 / float(f(np.array([self.x0]))[0])

    def _integrals(self, a: Any, b: Any) -> Any:
        """Gauss-Legendre integrals of f over the panels ``[a_i, b_i]`` and the least f at the nodes."""
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        r = a[..., None] + (b - a)[..., None] * _T
        fr = self.f(r)
        return (fr @ _W) * (b - a), fr.min(axis=-1)

    def _table(self) -> None:
        V_at: Callable[[Any], Any] = lambda x: self._V(np.array([self.side * x]))[0]
        x, h = self.x0, 0.25 * self.x0
        knots, parts = [x], []
        while True:
            a = np.array([x, x, x + 0.5 * h])
            b = np.array([x + h, x + 0.5 * h, x + h])
            I, fmin = self._integrals(a, b)
            if not (np.isfinite(I).all() and fmin.min() >= 0.0):
                raise ValueError(f"search_bound: V' changes sign or is not finite at |q| ~ {x!r} on the {self.where} "
                                 "side, beyond search_bound (a barrier there?): give a search_bound beyond it")
            whole, halves = I[0], I[1] + I[2]
            if abs(whole - halves) > PANEL_RTOL * halves:
                h *= 0.5
                if h < 1e-13 * x:
                    raise ValueError(
                        f"dV: V' has lost its relative precision at |q| ~ {x!r} on the {self.where} side, where V is "
                        f"within {self.A - float(V_at(x)):.3g} of its limit {self.A!r}: the orbits near the escape "
                        "energy "
                        "reach that far and cannot be computed.  Write V' without terms that cancel as V tends to "
                        "its limit (2 tanh(q) / cosh(q)^2, not 2 tanh(q) (1 - tanh(q)^2); 2 q / (1 + q^2)^2, not "
                        "2 q / (1 + q^2) - 2 q^3 / (1 + q^2)^2)")
                continue
            parts.append(halves)
            x += h
            knots.append(x)
            if halves <= NEGLIGIBLE * self.A:
                break
            h *= 2.0
            if not np.isfinite(x + h) or len(knots) > 4000:
                raise ValueError(f"asymptotes: V tends to its limit {self.A!r} on the {self.where} side too slowly for "
                                 f"float arithmetic (A - V still ~{float(np.sum(parts[-8:]))!r} at |q| ~ {x!r})")
        self.knots = np.array(knots)
        self.G_knots = np.append(np.cumsum(np.array(parts)[::-1])[::-1], 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            ell = self.G_knots / self.f(self.knots)
        # the last knot has G = 0 (the negligible rest): carry the previous length
        self.ell_knots = np.where(np.isfinite(ell) & (ell > 0), ell, np.append(ell[:-1], ell[-2]))

    def G(self, x: Any) -> Any:
        """``A - V(side x)`` for ``x >= x0`` (0 beyond the table, where it is below ``NEGLIGIBLE A``)."""
        x = np.asarray(x, dtype=float)
        j = np.searchsorted(self.knots, x, side="right")
        out = np.zeros(x.shape)
        inside = j < self.knots.size
        if inside.any():
            xi, ji = x[inside], j[inside]
            I, _ = self._integrals(xi, self.knots[ji])
            out[inside] = self.G_knots[ji] + I
        return out

    def bracket(self, s: Any) -> Any:
        """``(lo, hi)`` with ``G(lo) >= s > G(hi)`` for ``0 < s`` (the turning point of ``A - E = s``):
        ``(0, x0)`` where ``s >= G0`` (the turning point is not in the tail)."""
        s = np.asarray(s, dtype=float)
        n_ge = np.searchsorted(-self.G_knots, -s, side="right")
        core = n_ge == 0
        j = np.clip(n_ge, 1, self.knots.size - 1)
        lo = np.where(core, 0.0, self.knots[j - 1])
        hi = np.where(core, self.x0, self.knots[j])
        return lo, hi

    def length_at(self, x: Any) -> Any:
        """Decay length ``G / f`` at ``x0 <= x`` interpolated between the knots (a panel-count estimate)."""
        return np.interp(x, self.knots, self.ell_knots)

    def length(self, x: Any, G: Any) -> Any:
        """Decay length ``G / f`` of the tail at ``x`` (``G = G(x)``): e-folding length of ``A - V``."""
        return np.asarray(G, dtype=float) / self.f(np.asarray(x, dtype=float))
