"""Action-angle variables of any one-degree-of-freedom well by quadrature (Sec. 2.1 generalised).

:class:`NumericWell` takes a potential ``V(q)`` and its derivative ``V'(q)`` (vectorised numpy
callables) with the minimum at ``q = 0`` and computes everything the paper obtains in closed
form for the quartic with Jacobi elliptic functions: the action ``J(E)`` (eqs 8, 13, 19), the
frequency ``omega(E) = dE/dJ`` (eq 16), the angle ``theta(q, p)`` and its inverse
``(q, p)(theta, E)`` (eqs 14, 15, 17), and the first Fourier coefficient ``q_1(E)`` of
``q(theta)`` that enters the slow flow (eqs 12, 18, 20).

How (details in :mod:`safebasins.wells.orbit_quadrature` and
:mod:`safebasins.wells.interpolation`; the shape of the well in
:mod:`safebasins.wells.well_shape`, sides open at infinity in :mod:`safebasins.wells.open_sides`):

* turning points ``V(q_pm) = E`` by vectorised safeguarded Newton (near a barrier written as
  ``(V_b - E) - (q_b - q) <V'>`` so that they stay accurate at the separatrix; far out on a side
  open at infinity as ``(A - E) - int_q^inf V'``);
* orbit integrals with ``q = m + d sin(phi)`` (square-root end singularities removed), the
  near-separatrix peak resolved by ``psi = alpha sinh(v)``; composite Clenshaw-Curtis in ``v``
  for the cumulative time along a half orbit, composite Gauss-Legendre to a single point;
* ``q_1 = exp(-i theta_plus) |q_1|`` exactly (``q(theta)`` is even about the right turning
  point ``theta_plus``), ``|q_1| = (1/pi) int sin(omega tau_plus(q)) dq``;
* period, ``J/E``, ``|q_1|/sqrt(E)``, ``theta_minus``, the turning points etc. as adaptive
  piecewise Chebyshev interpolants in ``sqrt(E)`` (well bottom) and ``log(E_b - E)``
  (separatrix, or the approach to the limit of an open side), built once at construction
  (~0.02 s CPU, 420 orbits for the quartic; 0.07-0.16 s, 460 orbits, for Morse, sech^2 and
  algebraic tails);
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
Closer to the separatrix (or to the limit of a side open at infinity) the angle of a given point
is ill-conditioned (an error ``eps E_b`` in ``H0(q, p)`` moves theta by ~``eps E_b / (E_b - E)``:
4e-5 at ``E_b - E = 1e-12`` for Morse written as ``(1 - exp(-q))^2``).  The asymmetric quartic and the cubic
agree with DOP853 orbits and scipy quad to 1e-14 .. 1e-12 (limited by the references).

Wells open at infinity (docs/wells.md; closed forms of Morse ``D (1 - e^{-a q})^2`` and of
``tanh^2 q``): omega, J, ``q_1``, ``arg q_1`` within 1.2e-13 relative for every float
``E < E_b`` (the last one included; J of tanh^2 within 2.1e-13, the interpolation tolerance),
``phase_point`` within 1.2e-13 for ``E <= 0.99 E_b`` and 1.7e-13 as an angle up to
``E_b - E = 1e-12 E_b``; DOP853 orbits agree to their own accuracy (~1e-12).  Such wells need ``V'`` accurate to
relative precision in the tail (``2 tanh(q) / cosh(q)^2``, not ``2 tanh(q) (1 - tanh(q)^2)``: ValueError
naming dV).  ``V`` may lose relative accuracy at the bottom (``1 - cos q``, ``(1 - exp(-q))^2``):
this is detected and V is evaluated there as ``int_0^q V'`` (:mod:`safebasins.wells.bottom`).
"""
from __future__ import annotations

from functools import partial

from typing import Any

import numpy as np

from safebasins.core.checks import as_array, value_repr
from safebasins.wells.base import STEP_COST_TRANSCENDENTAL, Well
from safebasins.wells.bottom import cancellation_fix
from safebasins.wells.interpolation import BOTTOM, DEFAULT_TOL, EnergyInterpolant
from safebasins.wells.orbit_quadrature import EPS, OrbitQuadrature, solve_increasing
from safebasins.wells.well_shape import WellShape, _call, check_options
from safebasins.wells.compiled import user_code

__all__ = ["NumericWell", "check_options"]

# interpolated quantities (rows of the interpolant)
_T, _JE, _H, _THM, _TL, _QM, _QP = range(7)


def _minus(f: Any, c: Any, q: Any) -> Any:
    """``f(q) - c``."""
    return f(q) - c


class NumericWell(WellShape, Well):
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
        to ``search_bound`` has no barrier (``+-inf``); it is either closed (``V`` rises above the
        escape energy, within ``search_bound`` or beyond it) or open at infinity (``V`` converges
        to a finite limit along ``|q| = search_bound 2^k``, float precision), else ValueError.
    name : str
        Name used in datasets and configs.
    n_scan : int
        Points of the barrier scan on each side (>= 100).
    tol : float
        Target relative accuracy of the energy interpolants (trailing Chebyshev coefficients),
        in ``[1e-15, 1e-2]``.
    asymptotes : (left, right) or None
        Limits of ``V`` as ``q -> -inf`` / ``+inf`` when the caller knows them exactly (e.g.
        sympy's ``limit``): each a float, or None for "no finite limit" (``V -> inf``).  On a side
        without a barrier it is checked against ``V`` at large ``|q|`` (``1e-12`` relative) and,
        if open, against ``V(x0) + int_x0^inf V'`` (ValueError naming ``asymptotes`` on a
        mismatch) and replaces the float limit found along the geometric sequence; on a side
        with a barrier (escape over the barrier) it is not used.  ``None`` (default): detected.

    Attributes
    ----------
    barriers, barrier_energy (the lowest of the barriers' ``V(q_b)`` and of the limits of V at
    infinity), asymptotes (per side the finite limit of V on a side without a barrier, None
    where there is a barrier or ``V -> inf``), open_at_infinity (the escape energy is such a
    limit: thresholds ``xi_max`` must lie in ``(0, E_b)``), limits (bracket of all orbits of
    energy <= barrier_energy: barrier, the point where V exceeds it, or ``+-inf`` on a side open
    at infinity), bottom_integral (where V is evaluated as ``int_0^q V'``: the given V cancels
    near the bottom, e.g. ``1 - cos q``; None if it does not), omega0 (= sqrt(V''(0)), finite
    differences), interpolation_error (largest trailing-coefficient estimate of the energy
    interpolants, dominated by the panels within ~1e-12 E_b of the separatrix).

    Beyond :class:`~safebasins.wells.base.Well` (what a slow flow needs): ``period``,
    ``dJ_dE`` (= 1/omega), ``harmonic_amplitude`` (|q_1|, eq 20's G),
    ``harmonic_amplitude_derivative``, ``harmonic_phase`` (arg q_1, continuous in
    ``(-pi, 0)``), ``harmonic_phase_derivative``, ``check_energy``, ``check_point``.  Energies
    are in ``[0, E_b)``, every float below ``E_b`` (``turning_points``: ``[0, E_b]``, ``+-inf``
    on an open side at ``E_b``; derivatives: ``(0, E_b)``); arrays broadcast; bad input raises
    ValueError naming the argument.
    """

    name = "numeric"

    def __init__(self, V: Any, dV: Any, *, barriers: Any = None, search_bound: float = 10.0, name: str | None = None,
                 n_scan: int = 20001, tol: Any = DEFAULT_TOL, asymptotes: Any = None) -> None:
        if not callable(V):
            raise ValueError(f"V must be a callable V(q), got {V!r}")
        if not callable(dV):
            raise ValueError(f"dV must be a callable V'(q), got {dV!r}")
        tol, n_scan, declared = check_options(tol=tol, n_scan=n_scan, asymptotes=asymptotes)
        self.tol = tol
        if name is not None:
            self.name = str(name)
        self._V, self._dV = V, dV
        B = float(as_array("search_bound", search_bound))
        if not (np.isfinite(B) and B > 0):
            raise ValueError(f"search_bound must be finite and > 0, got {search_bound!r}")
        self.search_bound = B
        self._check_bottom()
        self.walls: dict[float, float] = {}              # side -> position of a wall (a pole of V' where V -> +inf)
        found = self._locate_barriers(B, n_scan)
        if barriers is not None:
            self._check_given_barriers(barriers, found)
        self._barriers = found
        vals = [float(_call(V, np.array([b]))[0]) for b in found if np.isfinite(b)]
        self._asymptotes = self._find_asymptotes(found, declared, B)
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
        dV_orbit = partial(_call, dV)
        slope = float(dV_orbit(np.zeros(1))[0])
        if slope != 0.0:
            # V'(0) is 0 up to the rounding of the constants as written (0.3 - 0.243 / 0.81 = -3e-17;
            # |V'(0)| <= BOTTOM_ATOL is checked): the orbits use V' - V'(0), whose minimum is exactly
            # at q = 0 (else int_0^q V' / q^2 ~ V'(0) / q, and the orbit data at E -> 0, are singular)
            dV_orbit = partial(_minus, dV_orbit, slope)
        self._V_bottom = cancellation_fix(partial(_call, V), dV_orbit, self._bottom_scales())
        V_acc = partial(_call, V) if self._V_bottom is None else self._V_bottom
        opened = ({"tails": self._tails, "core": max(self._bottom_scales()), "n_mean": 8}
                  if self.open_at_infinity else {})
        self._quad = OrbitQuadrature(V_acc, dV_orbit, self.limits, found, kappa, mean_rtol=tol, **opened)
        self._interp = EnergyInterpolant(self._orbit_table, self._E_b, tol=tol, noise=self._noise)
        self.interpolation_error = self._interp.error_estimate

    # ------------------------------------------------------------------ construction
    def _tol_spec(self) -> dict[str, Any]:
        """``{"tol": tol}`` when it is not the default (the ``tol`` key of a well spec), else ``{}``."""
        return {} if self.tol == DEFAULT_TOL else {"tol": self.tol}

    def _noise(self, kind: Any, a: Any, b: Any) -> Any:
        """Relative accuracy floor of the tabulated data on a panel (conditioning near E_b)."""
        if kind == BOTTOM:
            return 0.0
        return 64 * EPS * np.sqrt(self._E_b / np.exp(a))

    def _orbit_table(self, E: Any) -> Any:
        d = self._quad.orbit_data(E)
        return np.stack([d["T"], d["J"] / E, d["q1_abs"] / np.sqrt(E), d["theta_minus"],
                         d["t_left"] / d["T"], d["q_minus"], d["q_plus"]])

    # ------------------------------------------------------------------ checks
    def check_energy(self, name: str, E: Any, *, allow_separatrix: bool = False) -> Any:
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

    def _check_positive_energy(self, name: str, E: Any) -> Any:
        a = self.check_energy(name, E)
        if (a <= 0).any():
            raise ValueError(f"{name} must be > 0 for this derivative (|q_1| ~ sqrt(E) at the well bottom)")
        return a

    def check_point(self, q: Any, p: Any) -> Any:
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
    def V(self, q: Any) -> Any:
        """``V(q)``; near the bottom ``int_0^q V'`` where the given V loses relative accuracy
        (:mod:`safebasins.wells.bottom`, e.g. ``1 - cos q``)."""
        q = as_array("q", q)
        return _call(self._V, q) if self._V_bottom is None else self._V_bottom(q)

    def dV(self, q: Any) -> Any:
        q = as_array("q", q)
        return _call(self._dV, q)

    @property
    def barriers(self) -> Any:
        return self._barriers

    @property
    def barrier_energy(self) -> Any:
        return self._E_b

    @property
    def asymptotes(self) -> Any:
        return self._asymptotes

    @property
    def bottom_integral(self) -> Any:
        """``(q_left, q_right)`` where the given V loses relative accuracy at the bottom and
        :meth:`V` is ``int_0^q V'`` for ``-q_left < q < q_right`` (:mod:`safebasins.wells.bottom`),
        else None."""
        b = self._V_bottom
        return None if b is None else (b.q_left, b.q_right)

    def turning_points(self, E: Any) -> Any:
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
    def _eval(self, name: str, E: Any, k: Any) -> Any:
        E = self.check_energy(name, E)
        return self._interp.evaluate(E.ravel(), k)[0].reshape(E.shape), E

    def period(self, E: Any) -> Any:
        """Period ``T(E) = 2 pi / omega`` of the free orbit."""
        return self._eval("E", E, _T)[0]

    def omega(self, E: Any) -> Any:
        """Frequency ``omega(E) = dE/dJ = 2 pi / T`` (eq 16)."""
        return 2.0 * np.pi / self.period(E)

    def dJ_dE(self, E: Any) -> Any:
        """``dJ/dE = 1/omega = T / (2 pi)`` (eq 16)."""
        return self.period(E) / (2.0 * np.pi)

    def J(self, E: Any) -> Any:
        """Action ``J(E) = (1/2pi) oint p dq`` (eqs 8, 13, 19)."""
        je, E = self._eval("E", E, _JE)
        return je * E

    def harmonic_amplitude(self, E: Any) -> Any:
        """``|q_1(E)|``, half the amplitude of the first harmonic of ``q(theta)`` (eq 20's G)."""
        h, E = self._eval("E", E, _H)
        return h * np.sqrt(E)

    def harmonic_amplitude_derivative(self, E: Any) -> Any:
        """``d|q_1|/dE`` (derivative of the interpolant), ``0 < E < E_b`` (eq 20's dG/dxi)."""
        E = self._check_positive_energy("E", E)
        e = E.ravel()
        h, dh, bottom = self._interp.evaluate_var(e, _H)
        x = np.sqrt(e)
        # bottom panels in x = sqrt(E): |q_1| = x h(x), d/dE = (h + x h_x) / (2x)
        out = np.where(bottom, (h + x * dh) / (2.0 * x),
                       h / (2.0 * x) - x * dh / np.where(bottom, 1.0, self._E_b - e))
        return out.reshape(E.shape)

    def harmonic_phase(self, E: Any) -> Any:
        """``arg q_1(E)`` in ``(-pi, 0)``, continuous: ``-theta_plus`` with ``theta_plus`` the
        angle of the right turning point (``-pi/2`` for a symmetric well)."""
        thm, _ = self._eval("E", E, _THM)
        return -(thm + np.pi)

    def harmonic_phase_derivative(self, E: Any) -> Any:
        """``d arg q_1 / dE``, ``0 < E < E_b``."""
        E = self._check_positive_energy("E", E)
        _, d = self._interp.evaluate(E.ravel(), _THM, derivative=True)
        return -d.reshape(E.shape)

    def first_harmonic(self, E: Any) -> Any:
        """Complex ``q_1(E) = |q_1| exp(i arg q_1)`` (eq 12); ``-i G_exact`` for the quartic."""
        E = self.check_energy("E", E)
        e = E.ravel()
        h, thm = self._interp.evaluate_many(e, (_H, _THM))
        phase = -(thm + np.pi)
        return ((h * np.sqrt(e)) * (np.cos(phase) + 1j * np.sin(phase))).reshape(E.shape)

    # ------------------------------------------------------------------ angles
    def _orbits(self, E: Any) -> Any:
        """Per-item orbit data for 1-D energies ``0 < E < E_b``: interpolated period, angle of
        q_minus, time to the middle, and Newton-polished turning points with geometry."""
        T, thm, tl, qm0, qp0 = self._interp.evaluate_many(E, (_T, _THM, _TL, _QM, _QP))
        tl = tl * T
        guess = (qm0, qp0)
        qm, qp = self._quad.turning_points(E, guess)
        m, d, aL, aR = self._quad.geometry(E, qm, qp)
        return {"T": T, "omega": 2.0 * np.pi / T, "theta_minus": thm, "t_left": tl,
                "q_minus": qm, "q_plus": qp, "m": m, "d": d, "alpha_left": aL, "alpha_right": aR}

    def angle_energy(self, q: Any, p: Any) -> Any:
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
            close = half < 0.5
            if self.open_at_infinity:     # <V'> by a few nodes: only on the scale of the end
                close &= np.abs(qk - q_end) <= self._quad.end_length(q_end)
            if np.isfinite(self._quad.mean_length).any():   # V' singular near a side
                close &= np.abs(qk - q_end) <= self._quad.mean_cap(sigma)
            near = np.nonzero(close)[0]
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

    def phase_point(self, theta: Any, E: Any) -> Any:
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

            def fdf(v: Any, idx: Any) -> Any:
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
    #: a user's Python V, dV may call anything: the bound of a code calling libm functions
    step_cost = STEP_COST_TRANSCENDENTAL

    def _compiled_form(self) -> Any:
        return user_code(self._V, self._dV, self.barriers, self.name)

    def potential_text(self) -> str:
        return f"user function {getattr(self._V, '__qualname__', type(self._V).__name__)}"
