"""Action-angle variables of any one-degree-of-freedom well by quadrature (Sec. 2.1 generalised).

:class:`NumericWell` takes a potential ``V(q)`` and its derivative ``V'(q)`` (vectorised numpy
callables) with the minimum at ``q = 0`` and computes everything the paper obtains in closed
form for the quartic with Jacobi elliptic functions: the action ``J(E)`` (eqs 8, 13, 19), the
frequency ``omega(E) = dE/dJ`` (eq 16), the angle ``theta(q, p)`` and its inverse
``(q, p)(theta, E)`` (eqs 14, 15, 17), and the first Fourier coefficient ``q_1(E)`` of
``q(theta)`` that enters the slow flow (eqs 12, 18, 20).

How (details in :mod:`safebasins.wells.orbit_quadrature` and
:mod:`safebasins.wells.interpolation`):

* turning points ``V(q_pm) = E`` by vectorised safeguarded Newton (near a barrier written as
  ``(V_b - E) - (q_b - q) <V'>`` so that they stay accurate at the separatrix);
* orbit integrals with ``q = m + d sin(phi)`` (square-root end singularities removed), the
  near-separatrix peak resolved by ``psi = alpha sinh(v)``; composite Clenshaw-Curtis in ``v``
  for the cumulative time along a half orbit, composite Gauss-Legendre to a single point;
* ``q_1 = exp(-i theta_plus) |q_1|`` exactly (``q(theta)`` is even about the right turning
  point ``theta_plus``), ``|q_1| = (1/pi) int sin(omega tau_plus(q)) dq``;
* period, ``J/E``, ``|q_1|/sqrt(E)``, ``theta_minus``, the turning points etc. as adaptive
  piecewise Chebyshev interpolants in ``sqrt(E)`` (well bottom) and ``log(E_b - E)``
  (separatrix), built once at construction (~0.1 s, 420 orbits for the quartic);
* ``angle_energy`` evaluates the time integral from the nearer turning point for every point
  (no interpolation in ``q``; near a turning point the position on the orbit is taken from
  ``p``, which is well conditioned there); ``phase_point`` inverts it by safeguarded Newton.

Conventions (:mod:`safebasins.wells.base`): ``theta = 0`` where the orbit crosses ``q = 0``
with ``p > 0``; ``q(theta) = sum_k q_k e^{ik theta}``.  For the quartic ``q_1 = -i G`` with
``G`` the exact first harmonic (``theory.action_angle.G(xi, fourier="exact")``), i.e.
``arg q_1 = -pi/2`` and ``C = xi - Omega J + F |q_1| sin(gamma + arg q_1)`` is eq (18).

Accuracy (measured for the quartic against the closed forms, asserted with margin in
``tests/wells``): J, omega, ``|q_1|`` within 5e-15 relative for ``E <= 0.249``, 1e-15 at 0.2499,
<= 3e-11 at ``E_b - E = 1e-12`` and ~1e-9 at the last float below ``E_b``; ``d|q_1|/dE``
within 4e-12 for ``E <= 0.249``; angles within 2e-13 (``E <= 0.249``) and 1e-13 at 0.2499.
Closer to the separatrix the angle of a given point is ill-conditioned (an error ``eps E_b``
in ``H0(q, p)`` moves theta by ~``eps E_b / (E_b - E)``).  Wells from callables need ``V``
accurate to relative precision near ``q = 0`` (write ``2 sin(q/2)^2``, not ``1 - cos q``) and
``V'`` near the barriers; the asymmetric quartic and the cubic agree with DOP853 orbits and
scipy quad to 1e-14 .. 1e-12 (limited by the references).
"""
from __future__ import annotations

from functools import partial

import numpy as np
from scipy import optimize

from safebasins.checks import as_array, value_repr
from safebasins.wells.base import Well
from safebasins.wells.bottom import cancellation_fix
from safebasins.wells.interpolation import BOTTOM, EnergyInterpolant
from safebasins.wells.open_sides import CONVERGED, TAIL_START, Tail, converged_limit, geometric_values
from safebasins.wells.orbit_quadrature import EPS, OrbitQuadrature, solve_increasing

__all__ = ["NumericWell"]

# interpolated quantities (rows of the interpolant)
_T, _JE, _H, _THM, _TL, _QM, _QP = range(7)
#: tolerance for V(0) = 0 and V'(0) = 0 (absolute)
BOTTOM_ATOL = 1e-12


def check_options(*, tol=1e-13, n_scan=20001, asymptotes=None):
    """Validated ``(tol, n_scan, asymptotes)`` of :class:`NumericWell` (ValueError naming the argument),
    checked before anything is computed.  ``asymptotes``: None or a pair of float-or-None."""
    t = as_array("tol", tol)
    if t.ndim != 0 or not (1e-15 <= float(t) <= 1e-2):
        raise ValueError(f"tol must be a number in [1e-15, 1e-2] (relative accuracy of the energy interpolants), "
                         f"got {tol!r}")
    if isinstance(n_scan, bool) or not isinstance(n_scan, (int, np.integer)) or n_scan < 100:
        raise ValueError(f"n_scan must be an integer >= 100 (points of the barrier scan on each side), got {n_scan!r}")
    if asymptotes is None:
        return float(t), int(n_scan), None
    try:
        pair = list(asymptotes)
    except TypeError:
        pair = None
    if pair is None or len(pair) != 2:
        raise ValueError(f"asymptotes must be a pair (left, right) of limits of V at -inf / +inf, each a float or None, "
                         f"got {asymptotes!r}")
    out = []
    for side, a in zip(("left", "right"), pair):
        if a is not None:
            a = as_array("asymptotes", a)
            if a.ndim != 0 or not (np.isfinite(a) and a > 0):
                raise ValueError(f"asymptotes: the {side} limit must be a finite number > 0 (V rises from V(0) = 0 "
                                 f"towards it) or None, got {pair[0 if side == 'left' else 1]!r}")
            a = float(a)
        out.append(a)
    return float(t), int(n_scan), tuple(out)


def _call(f, q):
    """``f(q)`` as a float array of q's shape (a callable returning a constant is broadcast)."""
    with np.errstate(over="ignore", invalid="ignore"):
        out = np.asarray(f(q), dtype=float)
    return out if out.shape == np.shape(q) else np.broadcast_to(out, np.shape(q)).copy()


class NumericWell(Well):
    """A potential well ``V(q)`` given by callables, action-angle data by quadrature.

    Parameters
    ----------
    V, dV : callables
        Vectorised ``V(q)`` and ``V'(q)`` (numpy arrays in, same-shape float arrays out).
        Required: ``V(0) = 0`` and ``V'(0) = 0`` (to ``1e-12``), ``V''(0) > 0``.
    barriers : (q_left, q_right) or None
        Barrier positions (``-inf`` / ``+inf`` for a side without barrier).  ``None`` (default):
        found as the nearest local maxima of ``V`` on each side of 0 (first sign change of
        ``V'`` on a geometric grid of ``n_scan`` points from ``1e-9 search_bound`` to
        ``search_bound``, refined by Brent's method).  If given they are checked against that
        search and ValueError is raised on a mismatch.
    search_bound : float
        How far (in ``|q|``) the barriers are searched.  A side whose ``V'`` keeps its sign up
        to ``search_bound`` has no barrier (``+-inf``); there ``V`` must rise above the escape
        energy within ``search_bound`` (else ValueError: the well would be open).
    name : str
        Name used in datasets and configs.
    n_scan : int
        Points of the barrier scan on each side.
    tol : float
        Target relative accuracy of the energy interpolants (trailing Chebyshev coefficients).

    Attributes
    ----------
    barriers, barrier_energy, limits (bracket of all orbits of energy <= barrier_energy:
    barrier or the point where V exceeds it), omega0 (= sqrt(V''(0)), finite differences),
    interpolation_error (largest trailing-coefficient estimate of the energy interpolants,
    dominated by the panels within ~1e-12 E_b of the separatrix).

    Beyond :class:`~safebasins.wells.base.Well` (what a slow flow needs): ``period``,
    ``dJ_dE`` (= 1/omega), ``harmonic_amplitude`` (|q_1|, eq 20's G),
    ``harmonic_amplitude_derivative``, ``harmonic_phase`` (arg q_1, continuous in
    ``(-pi, 0)``), ``harmonic_phase_derivative``, ``check_energy``, ``check_point``.  Energies
    are in ``[0, E_b)`` (``turning_points``: ``[0, E_b]``; derivatives: ``(0, E_b)``); arrays
    broadcast; bad input raises ValueError naming the argument.
    """

    name = "numeric"

    def __init__(self, V, dV, *, barriers=None, search_bound=10.0, name=None, n_scan=20001, tol=1e-13,
                 asymptotes=None):
        if not callable(V):
            raise ValueError(f"V must be a callable V(q), got {V!r}")
        if not callable(dV):
            raise ValueError(f"dV must be a callable V'(q), got {dV!r}")
        tol, n_scan, declared = check_options(tol=tol, n_scan=n_scan, asymptotes=asymptotes)
        if name is not None:
            self.name = str(name)
        self._V, self._dV = V, dV
        B = float(as_array("search_bound", search_bound))
        if not (np.isfinite(B) and B > 0):
            raise ValueError(f"search_bound must be finite and > 0, got {search_bound!r}")
        self.search_bound = B
        self._check_bottom()
        found = self._locate_barriers(B, n_scan)
        if barriers is not None:
            self._check_given_barriers(barriers, found)
        self._barriers = found
        vals = [float(_call(V, np.array([b]))[0]) for b in found if np.isfinite(b)]
        limits_at_inf = self._find_asymptotes(found, declared, B)
        self._asymptotes = tuple(None if np.isfinite(b) else a for b, a in zip(found, limits_at_inf))
        levels = vals + [a for a in self._asymptotes if a is not None]
        if not levels:
            raise ValueError(f"V: the well is closed: no barrier within search_bound={B} and no finite limit of V at "
                             "either side (V' keeps its sign and V -> inf both ways, e.g. the harmonic well or an even "
                             "quartic with positive q^4): no orbit escapes, there is no escape energy")
        self._E_b = min(levels)
        self._tails = tuple(self._open_tail(side, a) for side, a in zip((-1.0, 1.0), self._asymptotes))
        self.limits = tuple(self._limit(side, b, B, n_scan) for side, b in zip((-1.0, 1.0), found))
        for side, lim in zip((-1.0, 1.0), self.limits):
            self._check_monotone(side, lim)
        self._check_derivative()
        kappa = tuple(self._curvature(b) if np.isfinite(b) else np.nan for b in found)
        for k, b in zip(kappa, found):
            if np.isfinite(b) and not k > 1e-8 * self.omega0 ** 2:
                raise ValueError(f"V: the barrier at q = {b!r} is degenerate (V''(q_b) = {-k!r}): the logarithmic "
                                 "separatrix behaviour assumed by the interpolation in E does not hold")
        self._V_bottom = cancellation_fix(partial(_call, V), partial(_call, dV), self._bottom_scales())
        V_acc = partial(_call, V) if self._V_bottom is None else self._V_bottom
        opened = {"tails": self._tails, "n_mean": 8} if self.open_at_infinity else {}
        self._quad = OrbitQuadrature(V_acc, partial(_call, dV), self.limits, found, kappa, **opened)
        self._interp = EnergyInterpolant(self._orbit_table, self._E_b, tol=tol, noise=self._noise)
        self.interpolation_error = self._interp.error_estimate

    # ------------------------------------------------------------------ construction
    def _check_bottom(self):
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
                             f"{self.search_bound!r}), must be > 0: q = 0 must be a non-degenerate minimum (a well much "
                             "smaller than search_bound needs a smaller search_bound)")
        self.omega0 = float(np.sqrt(k0))

    def _locate_barriers(self, B, n):
        """``(q_left, q_right)``: nearest local maxima of V on each side (``+-inf`` if none)."""
        return tuple(self._find_barrier(side, B, n) for side in (-1.0, 1.0))

    def _scan(self, side, B, n):
        s = np.geomspace(1e-9 * B, B, n)
        return s, side * _call(self._dV, side * s)

    def _find_barrier(self, side, B, n):
        s, f = self._scan(side, B, n)
        where = "left" if side < 0 else "right"
        stop = np.nonzero((f < 0) | ~np.isfinite(f))[0]
        self._scans = getattr(self, "_scans", {})
        self._scans[side] = (s, f)
        if stop.size == 0:
            return side * np.inf
        i = int(stop[0])
        if not np.isfinite(f[i]):
            raise ValueError(f"dV: V'({float(side * s[i])!r}) is not finite, {where} of 0 before any barrier")
        if i == 0:
            raise ValueError("dV: V' has the wrong sign next to q = 0 (q = 0 is not a minimum)")
        a, b = s[i - 1], s[i]
        if f[i - 1] == 0:
            return side * a
        g = lambda x: side * float(_call(self._dV, np.array([side * x]))[0])
        r = optimize.brentq(g, a, b, xtol=1e-300, rtol=4 * EPS, maxiter=500)
        return side * r

    def _check_monotone(self, side, lim):
        """V' must not vanish between 0 and the limit (an interior equilibrium, e.g. an
        inflection point with V' = 0, carries a non-periodic orbit): interior local minima of
        ``V'(q)/q`` on the scan are polished and rejected if they reach ~0."""
        s, f = self._scans[side]
        keep = s < abs(lim)
        s, g = s[keep], f[keep] / s[keep]
        if g.size < 3:
            return
        j = np.nonzero((g[1:-1] <= g[:-2]) & (g[1:-1] <= g[2:]) & (g[1:-1] < 1e-3 * g[0]))[0] + 1
        h = lambda x: side * float(_call(self._dV, np.array([side * x]))[0]) / x
        for k in j:
            res = optimize.minimize_scalar(h, bounds=(s[k - 1], s[k + 1]), method="bounded",
                                           options={"xatol": 1e-12 * s[k]})
            if res.fun <= 1e-9 * g[0]:
                raise ValueError(f"V: V' vanishes at q ~ {float(side * res.x)!r} inside the well (an equilibrium that is "
                                 "not a barrier): the orbit through it is not periodic")

    def _check_given_barriers(self, barriers, found):
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

    def _find_asymptotes(self, found, declared, B):
        """Per side, the finite limit of V at infinity or None (V -> inf; a barrier side without a
        declared limit).  Declared limits (``asymptotes``) are checked against V at large |q|."""
        out = []
        self._sequences = {}
        for k, side in enumerate((-1.0, 1.0)):
            where, sign = ("left", "-") if side < 0 else ("right", "+")
            given = None if declared is None else declared[k]
            if np.isfinite(found[k]) and given is None:
                out.append(None)
                continue
            x, v = geometric_values(partial(_call, self._V), side, B)
            self._sequences[side] = (x, v)
            A, i = converged_limit(v)
            if given is not None and (A is None or abs(A - given) > 1e-12 * abs(given)):
                seen = (f"tends to {A!r}" if A is not None else
                        f"does not converge (V = {float(v[np.isfinite(v)][-1])!r} at q = {float(side * x[np.isfinite(v)][-1])!r})")
                raise ValueError(f"asymptotes: the {where} limit is declared as {given!r}, but V {seen} along "
                                 f"q -> {sign}inf (|q| = search_bound 2^k)")
            if declared is not None and given is None and A is not None:
                raise ValueError(f"asymptotes: the {where} entry is None (no finite limit), but V tends to {A!r} as "
                                 f"q -> {sign}inf")
            if A is not None and np.isfinite(found[k]):
                out.append(given)
                continue
            if A is not None:
                rise = np.diff(v[:i + 1])
                if not (A > 0 and (rise >= -CONVERGED * A).all()):
                    raise ValueError(f"search_bound: V is not increasing towards its limit {A!r} on the {where} side "
                                     f"beyond search_bound = {B} (V' changes sign there: a barrier?); give a larger "
                                     "search_bound")
            out.append(given if given is not None else A)
        return tuple(out)

    def _open_tail(self, side, A):
        """The :class:`~safebasins.wells.open_sides.Tail` of a side open at infinity (its limit is
        the escape energy), else None."""
        if A is None or A > self._E_b:
            return None
        where = "left" if side < 0 else "right"
        x, v = self._sequences[side]
        hint = float(x[np.nonzero(v >= (1.0 - TAIL_START) * A)[0][0]])
        f = lambda s: side * _call(self._dV, side * s)
        tail = Tail(f, partial(_call, self._V), side, A, hint, where)
        # V(x0) + int_x0^inf V' must be the limit: a wrong declared limit, or V' not the derivative of V
        rest = A - float(_call(self._V, np.array([side * tail.x0]))[0])
        if abs(rest - tail.G0) > 1e-11 * A:
            raise ValueError(f"asymptotes: the {where} limit {A!r} is not V(q) + int_q^inf V' = "
                             f"{A - rest + tail.G0!r} (q = {side * tail.x0!r}): a wrong limit, or dV is not V'")
        return tail

    def _limit(self, side, barrier, B, n):
        if np.isfinite(barrier):
            return float(barrier)
        if self._tails[0 if side < 0 else 1] is not None:
            return side * np.inf
        s = np.geomspace(1e-9 * B, B, n)
        v = _call(self._V, side * s)
        above = np.nonzero(v > self._E_b)[0]
        if above.size:
            return float(side * s[above[0]])
        # V rises above E_b only beyond search_bound (slowly growing V, or a limit above E_b)
        x, v = self._sequences[side]
        above = np.nonzero(v > self._E_b)[0]
        if above.size == 0:
            raise ValueError(f"V: on the {'left' if side < 0 else 'right'} side V' keeps its sign up to search_bound = "
                             f"{B}, but V neither rises above the escape energy {self._E_b!r} nor converges to a finite "
                             f"limit (|q| up to {float(x[-1])!r}): the side neither closes nor is open at infinity")
        return float(side * x[above[0]])

    def _bottom_scales(self):
        """Per side the extent of the well proper: the limit, or where the tail of an open side begins."""
        return tuple(abs(lim) if t is None else t.x0 for lim, t in zip(self.limits, self._tails))

    def _check_derivative(self):
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

    def _curvature(self, qb):
        h = 1e-5 * max(1.0, abs(qb))
        return float(-(_call(self._dV, np.array([qb + h]))[0] - _call(self._dV, np.array([qb - h]))[0]) / (2 * h))

    def _noise(self, kind, a, b):
        """Relative accuracy floor of the tabulated data on a panel (conditioning near E_b)."""
        if kind == BOTTOM:
            return 0.0
        return 64 * EPS * np.sqrt(self._E_b / np.exp(a))

    def _orbit_table(self, E):
        d = self._quad.orbit_data(E)
        return np.stack([d["T"], d["J"] / E, d["q1_abs"] / np.sqrt(E), d["theta_minus"],
                         d["t_left"] / d["T"], d["q_minus"], d["q_plus"]])

    # ------------------------------------------------------------------ checks
    def check_energy(self, name, E, *, allow_separatrix=False):
        """Energy in ``[0, E_b)`` (or ``[0, E_b]`` with ``allow_separatrix``), as float array."""
        a = as_array(name, E)
        if (a < 0).any():
            raise ValueError(f"{name} must be >= 0 (energy measured from the well bottom), got min {float(a.min())!r}")
        if allow_separatrix:
            if (a > self._E_b).any():
                raise ValueError(f"{name} must be <= the barrier energy {self._E_b!r}, got max {float(a.max())!r}")
        elif (a >= self._E_b).any():
            raise ValueError(f"{name} must be < the barrier energy {self._E_b!r} (no periodic orbit on or "
                             f"above the separatrix), got max {float(a.max())!r}")
        return a

    def _check_positive_energy(self, name, E):
        a = self.check_energy(name, E)
        if (a <= 0).any():
            raise ValueError(f"{name} must be > 0 for this derivative (|q_1| ~ sqrt(E) at the well bottom)")
        return a

    def check_point(self, q, p):
        """Validated, broadcast ``(q, p)`` inside the well: between the limits, ``H0 < E_b``."""
        q, p = np.broadcast_arrays(as_array("q", q), as_array("p", p))
        lo, hi = self.limits
        if ((q <= lo) | (q >= hi)).any():
            raise ValueError(f"q must lie inside the well, {lo!r} < q < {hi!r}; got {value_repr(q)}")
        if not np.isfinite(p).all():
            raise ValueError("p must be finite")
        if (self.H0(q, p) >= self._E_b).any():
            raise ValueError(f"p: phase point has H0(q, p) >= barrier energy {self._E_b!r} (outside the well)")
        return q, p

    # ------------------------------------------------------------------ the potential
    def V(self, q):
        """``V(q)``; near the bottom ``int_0^q V'`` where the given V loses relative accuracy
        (:mod:`safebasins.wells.bottom`, e.g. ``1 - cos q``)."""
        q = as_array("q", q)
        return _call(self._V, q) if self._V_bottom is None else self._V_bottom(q)

    def dV(self, q):
        q = as_array("q", q)
        return _call(self._dV, q)

    @property
    def barriers(self):
        return self._barriers

    @property
    def barrier_energy(self):
        return self._E_b

    @property
    def asymptotes(self):
        return self._asymptotes

    def turning_points(self, E):
        E = self.check_energy("E", E, allow_separatrix=True)
        shape = E.shape
        e = E.ravel()
        guess = None
        inside = e < self._E_b
        if inside.all():
            guess = (self._interp.evaluate(e, _QM)[0], self._interp.evaluate(e, _QP)[0])
        qm, qp = self._quad.turning_points(e, guess)
        return qm.reshape(shape), qp.reshape(shape)

    # ------------------------------------------------------------------ action-angle
    def _eval(self, name, E, k):
        E = self.check_energy(name, E)
        return self._interp.evaluate(E.ravel(), k)[0].reshape(E.shape), E

    def period(self, E):
        """Period ``T(E) = 2 pi / omega`` of the free orbit."""
        return self._eval("E", E, _T)[0]

    def omega(self, E):
        """Frequency ``omega(E) = dE/dJ = 2 pi / T`` (eq 16)."""
        return 2.0 * np.pi / self.period(E)

    def dJ_dE(self, E):
        """``dJ/dE = 1/omega = T / (2 pi)`` (eq 16)."""
        return self.period(E) / (2.0 * np.pi)

    def J(self, E):
        """Action ``J(E) = (1/2pi) oint p dq`` (eqs 8, 13, 19)."""
        je, E = self._eval("E", E, _JE)
        return je * E

    def harmonic_amplitude(self, E):
        """``|q_1(E)|``, half the amplitude of the first harmonic of ``q(theta)`` (eq 20's G)."""
        h, E = self._eval("E", E, _H)
        return h * np.sqrt(E)

    def harmonic_amplitude_derivative(self, E):
        """``d|q_1|/dE`` (derivative of the interpolant), ``0 < E < E_b`` (eq 20's dG/dxi)."""
        E = self._check_positive_energy("E", E)
        e = E.ravel()
        h, dh, bottom = self._interp.evaluate_var(e, _H)
        x = np.sqrt(e)
        # bottom panels in x = sqrt(E): |q_1| = x h(x), d/dE = (h + x h_x) / (2x)
        out = np.where(bottom, (h + x * dh) / (2.0 * x),
                       h / (2.0 * x) - x * dh / np.where(bottom, 1.0, self._E_b - e))
        return out.reshape(E.shape)

    def harmonic_phase(self, E):
        """``arg q_1(E)`` in ``(-pi, 0)``, continuous: ``-theta_plus`` with ``theta_plus`` the
        angle of the right turning point (``-pi/2`` for a symmetric well)."""
        thm, _ = self._eval("E", E, _THM)
        return -(thm + np.pi)

    def harmonic_phase_derivative(self, E):
        """``d arg q_1 / dE``, ``0 < E < E_b``."""
        E = self._check_positive_energy("E", E)
        _, d = self._interp.evaluate(E.ravel(), _THM, derivative=True)
        return -d.reshape(E.shape)

    def first_harmonic(self, E):
        """Complex ``q_1(E) = |q_1| exp(i arg q_1)`` (eq 12); ``-i G_exact`` for the quartic."""
        E = self.check_energy("E", E)
        e = E.ravel()
        h, thm = self._interp.evaluate_many(e, (_H, _THM))
        phase = -(thm + np.pi)
        return ((h * np.sqrt(e)) * (np.cos(phase) + 1j * np.sin(phase))).reshape(E.shape)

    # ------------------------------------------------------------------ angles
    def _orbits(self, E):
        """Per-item orbit data for 1-D energies ``0 < E < E_b``: interpolated period, angle of
        q_minus, time to the middle, and Newton-polished turning points with geometry."""
        T, thm, tl, qm0, qp0 = self._interp.evaluate_many(E, (_T, _THM, _TL, _QM, _QP))
        tl = tl * T
        guess = (qm0, qp0)
        qm, qp = self._quad.turning_points(E, guess)
        m, d, aL, aR = self._quad.geometry(E, qm, qp)
        return {"T": T, "omega": 2.0 * np.pi / T, "theta_minus": thm, "t_left": tl,
                "q_minus": qm, "q_plus": qp, "m": m, "d": d, "alpha_left": aL, "alpha_right": aR}

    def angle_energy(self, q, p):
        """``(theta, E)`` of phase points inside the well (eqs 7, 14), ``theta in [0, 2 pi)``;
        ``theta = 0`` at the well bottom."""
        q, p = self.check_point(q, p)
        shape = q.shape
        q, p = q.ravel(), p.ravel()
        E = np.maximum(self.H0(q, p), 0.0)
        theta = np.zeros(E.shape)
        k = np.nonzero(E > 0)[0]
        if k.size:
            qk, pk, Ek = q[k], p[k], E[k]
            o = self._orbits(Ek)
            left = qk <= o["m"]
            q_end = np.where(left, o["q_minus"], o["q_plus"])
            sigma = np.where(left, -1.0, 1.0)
            # sin(psi/2) from q (h = 2 d sin^2(psi/2)); near the turning point, where that is
            # ill-conditioned in E (q_end moves with E), from p = 2 sqrt(sigma d <V'>) sin(psi/2)
            half = np.sqrt(np.clip(np.abs(qk - q_end) / (2.0 * o["d"]), 0.0, 1.0))
            near = np.nonzero(half < 0.5)[0]
            if near.size:
                mean = self._quad.mean_dV(qk[near], q_end[near])
                with np.errstate(divide="ignore", invalid="ignore"):
                    hp = np.abs(pk[near]) / (2.0 * np.sqrt(sigma[near] * o["d"][near] * mean))
                half[near] = np.where(np.isfinite(hp), np.minimum(hp, 1.0), half[near])
            psi = 2.0 * np.arcsin(half)
            alpha = np.where(left, o["alpha_left"], o["alpha_right"])
            tau = self._quad.side_time(Ek, q_end, o["d"], alpha, sigma, psi)
            wt = o["omega"] * tau
            upper = pk >= 0
            thm = o["theta_minus"]
            th = np.where(left, np.where(upper, thm + wt, thm + 2.0 * np.pi - wt),
                          np.where(upper, thm + np.pi - wt, thm + np.pi + wt))
            th = np.mod(th, 2.0 * np.pi)
            theta[k] = np.where(th >= 2.0 * np.pi, 0.0, th)
        return theta.reshape(shape), E.reshape(shape)

    def phase_point(self, theta, E):
        """``(q, p)`` at angle theta on the orbit of energy E (eqs 15, 17); inverse of
        :meth:`angle_energy`.  ``0 <= E < E_b``; theta any finite real."""
        theta = as_array("theta", theta)
        if not np.isfinite(theta).all():
            raise ValueError("theta must be finite")
        E = self.check_energy("E", E)
        theta, E = np.broadcast_arrays(theta, E)
        shape = E.shape
        theta, E = theta.ravel(), E.ravel()
        q = np.zeros(E.shape)
        p = np.zeros(E.shape)
        k = np.nonzero(E > 0)[0]
        if k.size:
            Ek = E[k]
            o = self._orbits(Ek)
            w = o["omega"]
            delta = np.mod(theta[k] - o["theta_minus"], 2.0 * np.pi)
            upper = delta <= np.pi
            tau_minus = np.where(upper, delta, 2.0 * np.pi - delta) / w
            left = tau_minus <= o["t_left"]
            target = np.where(left, tau_minus, np.abs(np.pi - delta) / w)
            total = np.where(left, o["t_left"], 0.5 * o["T"] - o["t_left"])
            q_end = np.where(left, o["q_minus"], o["q_plus"])
            alpha = np.where(left, o["alpha_left"], o["alpha_right"])
            sigma = np.where(left, -1.0, 1.0)
            d = o["d"]
            v_end = np.arcsinh(0.5 * np.pi / alpha)
            quad = self._quad

            def fdf(v, idx):
                psi = alpha[idx] * np.sinh(v)
                tau = quad.side_time(Ek[idx], q_end[idx], d[idx], alpha[idx], sigma[idx], psi)
                rate = quad.rate(Ek[idx], q_end[idx], d[idx], alpha[idx], sigma[idx], v)[0]
                return tau - target[idx], rate

            v0 = v_end * np.clip(target / total, 0.0, 1.0)
            v = solve_increasing(fdf, np.zeros(v0.shape), v_end, v0, xtol=1e-14, atol=1e-15)
            _, psi, qq, R = quad.rate(Ek, q_end, d, alpha, sigma, v)
            q[k] = qq
            p[k] = np.where(upper, 1.0, -1.0) * R * np.sin(psi)
        return q.reshape(shape), p.reshape(shape)

    # ------------------------------------------------------------------ the numerics
    def _compiled_form(self):
        from safebasins.numerics.wellcode import user_code

        return user_code(self._V, self._dV, self.barriers, self.name)

    def potential_text(self):
        return f"user function {getattr(self._V, '__qualname__', type(self._V).__name__)}"
