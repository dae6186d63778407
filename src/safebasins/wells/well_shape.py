"""The shape of a well given by callables ``V``, ``V'``: construction-time analysis for
:class:`~safebasins.wells.numeric.NumericWell` (a mixin: the checks of the bottom, the barrier
search, the three kinds of side, the limits).

* bottom: ``V(0) = V'(0) = 0``, ``V''(0) > 0`` (``V'(h)/h`` at ``h = 1e-8, 1e-7 search_bound``);
* barriers: the nearest sign changes of ``V'`` on a geometric scan up to ``search_bound``;
* a side without a barrier is *closed* (``V -> inf``) or *open at infinity* (``V -> A`` finite,
  :mod:`safebasins.wells.open_sides`); the escape energy is the lowest of the barriers' ``V(q_b)``
  and the limits ``A``;
* ``limits``: the barrier, the first scan point where ``V`` exceeds the escape energy (closed
  side), or ``+-inf`` (open side whose limit is the escape energy).
"""
from __future__ import annotations

from functools import partial

from collections.abc import Callable
from typing import Any

import numpy as np
from scipy import optimize

from safebasins.core.checks import as_array
from safebasins.wells.interpolation import DEFAULT_TOL, TOL_RANGE
from safebasins.wells.open_sides import CONVERGED, TAIL_START, Tail, converged_limit, geometric_values

__all__ = ["WellShape", "check_options"]

EPS = np.finfo(float).eps
#: tolerance for V(0) = 0 and V'(0) = 0 (absolute)
BOTTOM_ATOL = 1e-12


def check_options(*, tol: Any = DEFAULT_TOL, n_scan: int = 20001, asymptotes: Any = None) -> Any:
    """Validated ``(tol, n_scan, asymptotes)`` of :class:`NumericWell` (ValueError naming the argument),
    checked before anything is computed.  ``asymptotes``: None or a pair of float-or-None."""
    t = as_array("tol", tol)
    if t.ndim != 0 or not (TOL_RANGE[0] <= float(t) <= TOL_RANGE[1]):
        raise ValueError(f"tol must be a number in [{TOL_RANGE[0]:g}, {TOL_RANGE[1]:g}] (relative accuracy of the "
                         f"energy interpolants), got {tol!r}")
    if isinstance(n_scan, bool) or not isinstance(n_scan, (int, np.integer)) or n_scan < 100:
        raise ValueError(f"n_scan must be an integer >= 100 (points of the barrier scan on each side), got {n_scan!r}")
    if asymptotes is None:
        return float(t), int(n_scan), None
    try:
        pair = list(asymptotes)
    except TypeError:
        pair = None
    if pair is None or len(pair) != 2:
        raise ValueError("asymptotes must be a pair (left, right) of limits of V at -inf / +inf, each a float or "
                         "None, "
                         f"got {asymptotes!r}")
    out = []
    for side, a in zip(("left", "right"), pair):
        if a is not None:
            a = as_array("asymptotes", a)
            if a.ndim != 0 or not np.isfinite(a):
                raise ValueError(f"asymptotes: the {side} limit must be a finite number or None, got "
                                 f"{pair[0 if side == 'left' else 1]!r}")
            a = float(a)
        out.append(a)
    return float(t), int(n_scan), tuple(out)


def _call(f: Any, q: Any) -> Any:
    """``f(q)`` as a float array of q's shape (a callable returning a constant is broadcast)."""
    with np.errstate(over="ignore", invalid="ignore"):
        out = np.asarray(f(q), dtype=float)
    return out if out.shape == np.shape(q) else np.broadcast_to(out, np.shape(q)).copy()


class WellShape:
    """Construction-time analysis of ``V``, ``V'`` (``self._V``, ``self._dV``, ``self.search_bound``)."""

    # set by the well that uses this analysis (NumericWell.__init__)
    _V: Callable[[Any], Any]
    _dV: Callable[[Any], Any]
    search_bound: float
    walls: dict[float, float]
    _E_b: float
    _tails: tuple[Any, Any]
    limits: tuple[float, float]

    def _check_bottom(self) -> None:
        z = np.zeros(1)
        v0, d0 = float(_call(self._V, z)[0]), float(_call(self._dV, z)[0])
        if not (np.isfinite(v0) and abs(v0) <= BOTTOM_ATOL):
            raise ValueError(f"V: V(0) = {v0!r}, must be 0 (energies are measured from the well bottom q = 0)")
        if not (np.isfinite(d0) and abs(d0) <= BOTTOM_ATOL):
            raise ValueError(f"dV: V'(0) = {d0!r}, must be 0 (the minimum of the well must be at q = 0)")
        # V''(0) from V'(h)/h on both sides at h = 1e-7 and 1e-8 search_bound: they must agree
        # (a degenerate minimum, V''(0) = 0, has V'(h)/h ~ h^2 and fails the comparison)
        h = self.search_bound * np.array([-1e-7, -1e-8, 1e-8, 1e-7])
        g = _call(self._dV, h) / h
        k0 = float(np.mean(g))
        if not (np.isfinite(g).all() and (g > 0).all() and g.min() > 0.5 * g.max()):
            raise ValueError(f"V: V''(0) = {float(g.min())!r} (V'(q)/q at |q| = 1e-8 and 1e-7 search_bound = "
                             f"{self.search_bound!r}), must be > 0: q = 0 must be a non-degenerate minimum (a well "
                             "much "
                             "smaller than search_bound needs a smaller search_bound)")
        self.omega0 = float(np.sqrt(k0))

    def _locate_barriers(self, B: Any, n: Any) -> Any:
        """``(q_left, q_right)``: nearest local maxima of V on each side (``+-inf`` if none)."""
        return tuple(self._find_barrier(side, B, n) for side in (-1.0, 1.0))

    def _scan(self, side: Any, B: Any, n: Any) -> Any:
        s = np.geomspace(1e-9 * B, B, n)
        return s, side * _call(self._dV, side * s)

    def _find_barrier(self, side: Any, B: Any, n: Any) -> Any:
        """The barrier on one side: the first sign change of V' on the scan, polished by Brent's
        method; ``side * inf`` where there is none, or where the sign changes through a pole of V'
        at which V rises without bound (a wall, e.g. the repulsive core of a Lennard-Jones well:
        the side is closed there, :attr:`walls`)."""
        s, f = self._scan(side, B, n)
        where = "left" if side < 0 else "right"
        stop = np.nonzero((f < 0) | ~np.isfinite(f))[0]
        self._scans = getattr(self, "_scans", {})
        self._scans[side] = (s, f)
        if stop.size == 0:
            return side * np.inf
        i = int(stop[0])
        if i == 0:
            raise ValueError("dV: V' has the wrong sign next to q = 0 (q = 0 is not a minimum)")
        a, b = s[i - 1], s[i]
        if not np.isfinite(f[i]):
            if self._rises_to_wall(side, s[:i]):
                self.walls[side] = float(side * b)
                return side * np.inf
            raise ValueError(f"dV: V'({float(side * s[i])!r}) is not finite, {where} of 0 before any barrier")
        if f[i - 1] == 0:
            return side * a
        g: Callable[[Any], Any] = lambda x: side * float(_call(self._dV, np.array([side * x]))[0])
        r = optimize.brentq(g, a, b, xtol=1e-300, rtol=4 * EPS, maxiter=500)
        # a root of V' has |V'| at rounding level there; a pole (V' -> +inf, then -inf beyond) does not
        if not abs(g(r)) <= 1e-6 * max(abs(f[i - 1]), abs(f[i])):
            if self._rises_to_wall(side, s[:i]):
                self.walls[side] = float(side * r)
                return side * np.inf
            raise ValueError(f"dV: V' changes sign at q ~ {float(side * r)!r} through a singularity, not a zero, "
                             "and V does not rise without bound towards it: neither a barrier nor a wall")
        return side * r

    def _rises_to_wall(self, side: Any, s: Any) -> Any:
        """Whether V grows without bound along the scan points ``s`` (towards a pole of V'): its last
        values exceed 1e6 times its largest value over the first half of the scan's extent."""
        v = _call(self._V, side * s)
        inner = v[s <= 0.5 * s[-1]]
        return bool(np.isfinite(v[-1]) and inner.size and v[-1] > 1e6 * max(float(np.max(np.abs(inner))), EPS))

    def _check_monotone(self, side: Any, lim: Any) -> None:
        """V' must not vanish between 0 and the limit (an interior equilibrium, e.g. an
        inflection point with V' = 0, carries a non-periodic orbit): interior local minima of
        ``V'(q)/q`` on the scan are polished and rejected if they reach ~0."""
        s, f = self._scans[side]
        keep = s < abs(lim)
        s, g = s[keep], f[keep] / s[keep]
        if g.size < 3:
            return
        j = np.nonzero((g[1:-1] <= g[:-2]) & (g[1:-1] <= g[2:]) & (g[1:-1] < 1e-3 * g[0]))[0] + 1
        h: Callable[[Any], Any] = lambda x: side * float(_call(self._dV, np.array([side * x]))[0]) / x
        for k in j:
            res = optimize.minimize_scalar(h, bounds=(s[k - 1], s[k + 1]), method="bounded",
                                           options={"xatol": 1e-12 * s[k]})
            if res.fun <= 1e-9 * g[0]:
                raise ValueError(f"V: V' vanishes at q ~ {float(side * res.x)!r} inside the well (an equilibrium that "
                                 "is "
                                 "not a barrier): the orbit through it is not periodic")

    def _check_given_barriers(self, barriers: Any, found: Any) -> None:
        try:
            given = tuple(float(b) for b in barriers)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"barriers must be a pair (q_left, q_right), got {barriers!r}") from exc
        if len(given) != 2 or np.isnan(given).any():
            raise ValueError(f"barriers must be a pair (q_left, q_right) without NaN, got {barriers!r}")
        if not (given[0] < 0 < given[1]):
            raise ValueError(f"barriers must satisfy q_left < 0 < q_right, got {given!r}")
        for g, f, side in zip(given, found, ("left", "right")):
            same = (g == f) if not (np.isfinite(g) and np.isfinite(f)) else abs(g - f) <= 1e-9 * max(1.0, abs(f))
            if not same:
                raise ValueError(f"barriers: the {side} barrier is given as {g!r} but the nearest local maximum "
                                 f"of V on that side (within search_bound) is at {f!r}")

    def _find_asymptotes(self, found: Any, declared: Any, B: Any) -> Any:
        """Per side without a barrier, the finite limit of V at infinity or None (V -> inf); None on a
        side with a barrier.  Declared limits (``asymptotes``) are checked against V at large |q|."""
        out: list[float | None] = []
        self._sequences = {}
        for k, side in enumerate((-1.0, 1.0)):
            where, sign = ("left", "-") if side < 0 else ("right", "+")
            given = None if declared is None else declared[k]
            if np.isfinite(found[k]) or side in self.walls:
                out.append(None)               # escape over the barrier (or closed by a wall): a declared
                continue                       # limit (beyond the wall: unreachable) is not used
            x, v = geometric_values(partial(_call, self._V), side, B)
            self._sequences[side] = (x, v)
            A, i = converged_limit(v)
            if given is not None and (A is None or abs(A - given) > 1e-12 * abs(given)):
                fin = np.flatnonzero(np.isfinite(v))
                seen = (f"tends to {A!r}" if A is not None else "is not finite" if fin.size == 0 else
                        f"does not converge (V = {float(v[fin[-1]])!r} at q = {float(side * x[fin[-1]])!r})")
                raise ValueError(f"asymptotes: the {where} limit is declared as {given!r}, but V {seen} along "
                                 f"q -> {sign}inf (|q| = search_bound 2^k)")
            if declared is not None and given is None and A is not None:
                raise ValueError(f"asymptotes: the {where} entry is None (no finite limit), but V tends to {A!r} as "
                                 f"q -> {sign}inf")
            if A is not None:
                rise = np.diff(v[:i + 1])
                if not (A > 0 and (rise >= -CONVERGED * A).all()):
                    raise ValueError(f"search_bound: V is not increasing towards its limit {A!r} on the {where} side "
                                     f"beyond search_bound = {B} (V' changes sign there: a barrier?); give a larger "
                                     "search_bound")
            out.append(given if given is not None else A)
        return tuple(out)

    def _open_tail(self, side: Any, A: Any) -> Any:
        """The :class:`~safebasins.wells.open_sides.Tail` of a side open at infinity (its limit is
        the escape energy), else None."""
        if A is None or A > self._E_b:
            return None
        where = "left" if side < 0 else "right"
        x, v = self._sequences[side]
        hint = float(x[np.nonzero(v >= (1.0 - TAIL_START) * A)[0][0]])
        f: Callable[[Any], Any] = lambda s: side * _call(self._dV, side * s)
        tail = Tail(f, partial(_call, self._V), side, A, hint, where)
        # V(x0) + int_x0^inf V' must be the limit: a wrong declared limit, or V' not the derivative of V
        rest = A - float(_call(self._V, np.array([side * tail.x0]))[0])
        if abs(rest - tail.G0) > 1e-11 * A:
            raise ValueError(f"asymptotes: the {where} limit {A!r} is not V(q) + int_q^inf V' = "
                             f"{A - rest + tail.G0!r} (q = {side * tail.x0!r}): a wrong limit, or dV is not V'")
        return tail

    def _limit(self, side: Any, barrier: Any, B: Any, n: Any) -> Any:
        if np.isfinite(barrier):
            return float(barrier)
        if self._tails[0 if side < 0 else 1] is not None:
            return side * np.inf
        s = np.geomspace(1e-9 * B, B, n)
        if side in self.walls:                 # only inside the wall
            s = s[s < abs(self.walls[side])]
        v = _call(self._V, side * s)
        above = np.nonzero(v > self._E_b)[0]
        if above.size:
            return float(side * s[above[0]])
        if side in self.walls:
            raise ValueError(f"V: on the {'left' if side < 0 else 'right'} side V rises towards the wall at "
                             f"q = {self.walls[side]!r} but not above the escape energy {self._E_b!r} before it")
        # V rises above E_b only beyond search_bound (slowly growing V, or a limit above E_b)
        x, v = self._sequences[side]
        above = np.nonzero(v > self._E_b)[0]
        if above.size == 0:
            raise ValueError(f"V: on the {'left' if side < 0 else 'right'} side V' keeps its sign up to search_bound = "
                             f"{B}, but V neither rises above the escape energy {self._E_b!r} nor converges to a "
                             "finite "
                             f"limit (|q| up to {float(x[-1])!r}): the side neither closes nor is open at infinity")
        return float(side * x[above[0]])

    def _bottom_scales(self) -> Any:
        """Per side the extent of the well proper: the limit, where the tail of an open side begins, or
        on a side closed by a wall the distance to the wall (V' is analytic up to it)."""
        return tuple(abs(self.walls[side]) if side in self.walls else abs(lim) if t is None else t.x0
                     for side, lim, t in zip((-1.0, 1.0), self.limits, self._tails))

    def _check_derivative(self) -> None:
        lo, hi = (side * s for side, s in zip((-1.0, 1.0), self._bottom_scales()))
        q = np.linspace(lo, hi, 13)[1:-1]
        q = q[q != 0]
        h = 1e-5 * max(abs(lo), abs(hi))
        fd = (_call(self._V, q + h) - _call(self._V, q - h)) / (2 * h)
        d = _call(self._dV, q)
        scale = np.max(np.abs(d))
        if not np.allclose(fd, d, rtol=0, atol=1e-6 * scale):
            raise ValueError(f"dV does not match the derivative of V (max |dV - dV_fd| = {np.max(np.abs(fd - d))!r} "
                             f"relative to max |dV| = {scale!r})")

    def _curvature(self, qb: Any) -> Any:
        h = 1e-5 * max(1.0, abs(qb))
        return float(-(_call(self._dV, np.array([qb + h]))[0] - _call(self._dV, np.array([qb - h]))[0]) / (2 * h))
