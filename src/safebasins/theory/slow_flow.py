"""Slow flow on the 1:1 resonance manifold and its escape criterion (paper eqs 11, 18, 21).

First integral (eq 18), ``gamma = theta - Psi - Omega tau``:

    C(gamma, xi) = xi - Omega J(xi) - F G(xi) cos(gamma).

Averaging ``-F q sin(Omega tau + Psi)`` with ``q = 2 G sin(theta) + ...`` gives
``-F G cos(gamma)``, so eq (18) follows from eq (12) with ``q_1 = -i G``; the slow flow
(eq 11) is Hamiltonian in the canonical pair ``(gamma, J)``:
``J' = -dC/dgamma = -F G sin(gamma)``, ``gamma' = dC/dJ = omega - Omega - F omega G'(xi) cos(gamma)``.
This is the sign convention of the true system ``q' = p, p' = -q + q^3 + F sin(Omega tau + Psi)``
(eq 1); the printed eq (5) has its signs swapped (it should read ``q' = dH/dp, p' = -dH/dq``).

Escape criterion (used everywhere in this package)
--------------------------------------------------
Write ``h(xi) = xi - Omega J(xi)``, ``a(xi) = h - F G`` (C on the ray gamma = 0) and
``b(xi) = h + F G`` (C on gamma = pi).  For F > 0, C is strictly increasing in gamma on
(0, pi) and even in gamma, so on each circle xi = const the level ``c`` is attained (in the
upper half) at exactly one gamma iff ``a(xi) <= c <= b(xi)``.  The component of the level set
``C = c0`` through ``(gamma_ini, xi_ini)`` is therefore, in the upper half, a graph ``gamma(xi)``
over the maximal xi-interval around xi_ini on which ``a < c0 < b``; its ends lie on the rays
gamma = 0 or pi, where it joins its mirror image, unless the interval reaches xi_max.
Hence the IC escapes (the level curve (21) reaches the circle xi = xi_max) iff

    max_{xi in [xi_ini, xi_max]} a(xi)  <=  c0  <=  min_{xi in [xi_ini, xi_max]} b(xi).

Interior maxima of ``a`` are the saddles on gamma = 0 (``a'(xi) = 0``, i.e.
``1 - Omega/omega - F G' = 0``, eq 25); interior minima of ``b`` are saddles on gamma = pi;
the ends ``xi = xi_max`` are the tangencies of eqs (22)-(24).  ``a`` and ``b`` are tabulated
on a fine xi grid with their critical points (located by Brent's method) inserted as nodes,
so that ``a`` is monotone between nodes and the suffix max/min are exact.
"""
from __future__ import annotations

import numpy as np
from scipy import optimize

from safebasins.core.checks import check_finite, check_nonnegative, check_positive, check_scalar
from safebasins.wells import resolve_well
from safebasins.wells.quartic import XI_SEPARATRIX, _G, _J, _dG_dxi, _ell, _omega, check_fourier

__all__ = ["first_integral", "escapes_on_manifold", "slow_flow_escapes", "slow_flow_profile",
           "slow_flow_rhs", "xi_from_J", "saddles"]


def _scalar(name, value, check):
    a = check(name, value)
    if a.ndim != 0:
        raise ValueError(f"{name} must be a scalar here, got shape {a.shape}")
    return float(a)


def first_integral(gamma, xi, F, Omega, fourier=None, well=None):
    """First integral of the slow flow, eq (18): ``C = xi - Omega J(xi) - F G(xi) cos(gamma)``;
    for any well ``C = xi - Omega J(xi) - F A(xi) cos(gamma + delta(xi))`` with
    ``q_1 = -i A e^{i delta}`` (wells.base).

    Broadcasts all array arguments.  ``0 <= xi <= barrier energy`` (1/4 for the quartic, where
    G(1/4) = 0), ``F >= 0``, ``Omega > 0``.  ``well``: the quartic by default; ``fourier``
    ("paper" | "exact") selects the quartic's G.
    """
    w = resolve_well(well, fourier)
    gamma = check_finite("gamma", gamma)
    xi = w.check_energy("xi", xi, allow_separatrix=True)
    F = check_nonnegative("F", F)
    Omega = check_positive("Omega", Omega)
    return xi - Omega * w.J(xi) - F * w.harmonic_amplitude(xi) * np.cos(gamma + w.harmonic_shift(xi))


# ----------------------------------------------------------------------------- profile
def _h_prime(xi, Omega, well):
    with np.errstate(divide="ignore"):
        return 1.0 - Omega / well.omega(xi)


def _ab_prime(xi, F, Omega, well):
    hp = _h_prime(xi, Omega, well)
    gp = well.harmonic_amplitude_derivative(xi)
    return hp - F * gp, hp + F * gp


def unshear(g, shift):
    """The slow phase gamma (in (-pi, pi]) of a point at gamma' = g on the sheared rays
    gamma' = gamma + delta(xi) (``shift`` = delta; 0 for a symmetric well: g itself)."""
    return np.pi - np.mod(np.pi - (g - shift), 2.0 * np.pi)


#: a shift delta smaller than this in magnitude (rad) is noise of a well's tables (a symmetric
#: well's delta is 0, its tables give a few 1e-16 of either sign, which would put a point of the
#: ray gamma' = pi at +pi or -pi)
SHIFT_RESOLUTION = 1e-12


def resolved_shift(well, xi):
    """``well.harmonic_shift(xi)`` with values below :data:`SHIFT_RESOLUTION` set to exactly 0."""
    d = np.asarray(well.harmonic_shift(xi), dtype=float)
    return np.where(np.abs(d) < SHIFT_RESOLUTION, 0.0, d)


def _xi_grid(lo, hi, n):
    """Grid on [lo, hi] clustered at both ends (Chebyshev-Lobatto spacing)."""
    t = np.linspace(0.0, 1.0, n)
    x = lo + (hi - lo) * 0.5 * (1.0 - np.cos(np.pi * t))
    x[0], x[-1] = lo, hi
    return x


def _critical_points(xi, F, Omega, well, which):
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

    def f(x):
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
    phase delta(xi), a and b are C on the sheared rays gamma + delta(xi) = 0, pi.
    """

    def __init__(self, F, Omega, xi_max, well, n=1500, lo=0.0):
        self.F, self.Omega, self.xi_max, self.well = F, Omega, xi_max, well
        base = _xi_grid(lo, xi_max, n)
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
        self.A = np.maximum.accumulate(self.a[::-1])[::-1]
        self.B = np.minimum.accumulate(self.b[::-1])[::-1]

    def suffix(self, xi_ini):
        """(max a, min b) over [xi_ini, xi_max] for xi_ini < xi_max, excluding a(xi_ini), b(xi_ini)."""
        j = np.searchsorted(self.xi, xi_ini, side="right")
        j = np.minimum(j, self.xi.size - 1)
        return self.A[j], self.B[j]


def slow_flow_profile(F, Omega, xi_max, fourier=None, n=1500, well=None):
    """Build the :class:`SlowFlowProfile` (a, b, suffix extrema, critical points) for one
    parameter set; see the module docstring."""
    w = resolve_well(well, fourier)
    F = _scalar("F", F, check_nonnegative)
    Omega = _scalar("Omega", Omega, check_positive)
    xi_max = _scalar("xi_max", xi_max, w.check_threshold)
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 16:
        raise ValueError(f"n must be an integer >= 16 (nodes of the xi grid of the profile), got {n!r}")
    return SlowFlowProfile(F, Omega, xi_max, w, n)


def saddles(F, Omega, xi_max=None, fourier=None, well=None):
    """Saddles of the slow flow below xi_max (eq 25), as a list of ``(gamma, xi)``.

    gamma = 0 saddles are interior maxima of ``a(xi)``, gamma = pi saddles interior minima of
    ``b(xi)``; each root of ``a'`` / ``b'`` is bracketed on a fine grid and polished by Brent's
    method (the paper uses Newton-Raphson, Sec. 3.2).  ``xi_max``: the barrier energy by
    default.  For a well with a phase delta(xi), the returned gamma is 0 or pi of the sheared
    rays (the saddle's slow phase is gamma - delta(xi)).
    """
    w = resolve_well(well, fourier)
    xi_max = w.barrier_energy if xi_max is None else xi_max
    prof = slow_flow_profile(F, Omega, xi_max, n=1500, well=w)
    out = [(0.0, float(x)) for x in prof.a_max if x < xi_max]
    out += [(np.pi, float(x)) for x in prof.b_min if x < xi_max]
    return sorted(out, key=lambda t: t[1])


def _escapes_rm(gamma, xi, prof):
    """Escape classification for validated points (gamma, xi) given a profile."""
    F, Omega, xi_max = prof.F, prof.Omega, prof.xi_max
    gamma, xi = np.broadcast_arrays(gamma, xi)
    out = np.ones(gamma.shape, dtype=bool)
    inside = xi < xi_max
    if F == 0.0:
        out[inside] = False
        return out
    g, x = gamma[inside], xi[inside]
    w = prof.well
    c0 = x - Omega * w.J(x) - F * w.harmonic_amplitude(x) * np.cos(g + w.harmonic_shift(x))
    A, B = prof.suffix(x)
    out[inside] = (A <= c0) & (c0 <= B)
    return out


def escapes_on_manifold(gamma, xi, F, Omega, xi_max, fourier=None, well=None):
    """Does the slow-flow level curve (21) through ``(gamma, xi)`` reach ``xi = xi_max``?

    Boolean array (True = escapes), broadcast over gamma and xi; points with
    ``xi >= xi_max`` escape.  F, Omega, xi_max are scalars.  Criterion: see module docstring
    (``max a <= C(gamma, xi) <= min b`` over ``[xi, xi_max]``).
    """
    w = resolve_well(well, fourier)
    gamma = check_finite("gamma", gamma)
    xi = w.check_energy("xi", xi, allow_separatrix=True)
    prof = slow_flow_profile(F, Omega, _scalar("xi_max", xi_max, w.check_analytic_threshold), well=w)
    return _escapes_rm(gamma, xi, prof)


def slow_flow_escapes(q0, p0, F, Omega, Psi, xi_max, fourier=None, well=None, damping=0.0):
    """Analytic escape prediction for initial conditions ``(q0, p0)`` at tau = 0.

    Each IC is mapped to ``(theta0, xi_ini)`` (eqs 7, 14), ``gamma_ini = theta0 - Psi``, and
    classified by whether the level curve of C (eq 18) through ``(gamma_ini, xi_ini)`` reaches
    ``xi_max`` (eq 21).  ICs with ``H0 >= xi_max`` or beyond a barrier escape.  Broadcasts q0
    and p0; F, Omega, Psi, xi_max are scalars.  Returns a bool array (True = escapes).

    ``damping`` (beta >= 0, default 0: the above): for beta > 0 the level curves of C are no longer
    trajectories; an IC is safe iff its trajectory of the damped slow flow settles on an attractor
    without reaching xi_max (:func:`safebasins.theory.damped_escape.slow_flow_outcomes`,
    docs/damping.md).  Undecided trajectories count as escaping, with an ``UndecidedWarning``.
    """
    w = resolve_well(well, fourier)
    if check_scalar("damping", damping, check_nonnegative) > 0:
        from safebasins.theory.damped_escape import damped_escapes
        return damped_escapes(q0, p0, F, Omega, Psi, xi_max, damping, well=w)
    xi_max = _scalar("xi_max", xi_max, w.check_analytic_threshold)
    q0 = check_finite("q0", q0)
    p0 = check_finite("p0", p0)
    _scalar("Psi", Psi, check_finite)
    prof = slow_flow_profile(F, Omega, xi_max, well=w)
    q0, p0 = np.broadcast_arrays(q0, p0)
    H = w.H0(q0, p0)
    inside = w.in_well(q0) & (H < prof.xi_max)
    out = np.ones(q0.shape, dtype=bool)
    theta, xi = w.angle_energy(q0[inside], p0[inside])
    out[inside] = _escapes_rm(theta - float(Psi), xi, prof)
    return out


# ----------------------------------------------------------------------------- Cartesian flow
_TABLE = []


def _J_table():
    if not _TABLE:
        tab_x = _xi_grid(0.0, XI_SEPARATRIX, 4001)
        _TABLE.append((tab_x, _J(tab_x)))
    return _TABLE[0]


def xi_from_J(Jv):
    """Invert eq (19): energy xi with ``J(xi) = Jv`` (0 <= Jv <= 4/(3 pi)), Newton on dJ/dxi = 1/omega."""
    Jv = check_nonnegative("Jv", Jv)
    Jmax = float(_J(np.asarray(XI_SEPARATRIX)))
    if (Jv > Jmax).any():
        raise ValueError(f"Jv must be <= J(1/4) = {Jmax}")
    # initial guess from a monotone table, then Newton steps
    tab_x, tab_J = _J_table()
    x = np.interp(Jv, tab_J, tab_x)
    for _ in range(3):
        inner = (x > 0) & (x < XI_SEPARATRIX)
        xs = np.where(inner, x, 0.1)
        e = _ell(xs)
        x = np.where(inner, x - (_J(xs, e) - Jv) * _omega(xs, e), x)
        x = np.clip(x, 0.0, XI_SEPARATRIX)
    return x


def slow_flow_rhs(X, Y, F, Omega, fourier="paper"):
    """Slow flow (11) in Cartesian slow variables ``X = sqrt(2J) cos(gamma)``, ``Y = sqrt(2J) sin(gamma)``.

    With ``J' = -F G sin(gamma)`` and ``gamma' = omega - Omega - F omega G'(xi) cos(gamma)``:
    ``X' = J' cos(gamma)/r - Y gamma'``, ``Y' = J' sin(gamma)/r + X gamma'`` (``r^2 = 2J``).
    Regular at the well bottom (there ``X' = 0``, ``Y' = -F/2`` for ``G ~ r/2``).  Returns
    ``(dX, dY)``; C (eq 18) is conserved.  ``F >= 0``, ``Omega > 0`` (finite scalars or arrays),
    ``fourier`` "paper" | "exact", ``X^2 + Y^2 <= 2 J(1/4)``; a ValueError names the argument
    otherwise.  With damping see :func:`safebasins.theory.damped.rhs_gamma_frame`.
    """
    check_nonnegative("F", F)
    check_positive("Omega", Omega)
    check_fourier(fourier)
    check_finite("X", X)
    check_finite("Y", Y)
    X = np.asarray(X, float)
    Y = np.asarray(Y, float)
    r2 = X * X + Y * Y
    if (0.5 * r2 > float(_J(np.asarray(XI_SEPARATRIX)))).any():
        raise ValueError("X, Y must lie inside the separatrix: X^2 + Y^2 <= 2 J(1/4) = "
                         f"{2 * float(_J(np.asarray(XI_SEPARATRIX)))!r}")
    r = np.sqrt(r2)
    xi = xi_from_J(0.5 * r2)
    small = r < 1e-12
    rs = np.where(small, 1.0, r)
    xs = np.where(small, 1e-30, xi)
    c, s = np.where(small, 1.0, X / rs), np.where(small, 0.0, Y / rs)
    e = _ell(xs)
    w = _omega(xs, e)
    Jdot = -F * _G(xs, fourier, e) * s
    gdot = w - Omega - F * w * _dG_dxi(xs, fourier, e) * c
    dX = Jdot * c / rs - Y * gdot
    dY = Jdot * s / rs + X * gdot
    dX = np.where(small, 0.0, dX)
    dY = np.where(small, -0.5 * F, dY)
    return dX, dY
