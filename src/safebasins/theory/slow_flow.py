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
so that ``a`` is monotone between nodes and the suffix max/min are exact
(:mod:`safebasins.theory.profile`; the ICs of a grid are classified by
:mod:`safebasins.theory.slow_flow_grid`).

This module is the entry point of both slow flows: :func:`slow_flow_escapes` with damping > 0
hands over to the damped slow flow (:mod:`safebasins.theory.damped_escape`), which builds on
the profile's module, never on this one.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from safebasins.core.checks import check_finite, check_nonnegative, check_positive, check_scalar
from safebasins.theory.damped_escape import damped_escapes
from safebasins.theory.profile import SlowFlowProfile, level_escapes, xi_grid
from safebasins.theory.slow_flow_grid import GridSlowFlow
from safebasins.theory.types import BoolArray, FloatArray, WellArg
from safebasins.wells import resolve_well
from safebasins.wells.quartic import QUARTIC, XI_SEPARATRIX, check_fourier

__all__ = ["first_integral", "escapes_on_manifold", "slow_flow_escapes", "slow_flow_profile",
           "slow_flow_rhs", "xi_from_J", "saddles"]


def first_integral(gamma: ArrayLike, xi: ArrayLike, F: ArrayLike, Omega: ArrayLike, fourier: str | None = None,
                   well: WellArg = None) -> FloatArray:
    """First integral of the slow flow, eq (18): ``C = xi - Omega J(xi) - F G(xi) cos(gamma)``;
    for any well ``C = xi - Omega J(xi) - F A(xi) cos(gamma + delta(xi))`` with
    ``q_1 = -i A e^{i delta}`` (wells.base).

    Broadcasts all array arguments.  ``0 <= xi <= barrier energy`` (1/4 for the quartic, where
    G(1/4) = 0), ``F >= 0``, ``Omega > 0``.  ``well``: the quartic by default; ``fourier``
    ("paper" | "exact") selects the quartic's G.
    """
    w = resolve_well(well, fourier)
    g = check_finite("gamma", gamma)
    x = w.check_energy("xi", xi, allow_separatrix=True)
    f = check_nonnegative("F", F)
    om = check_positive("Omega", Omega)
    out: FloatArray = x - om * w.J(x) - f * w.harmonic_amplitude(x) * np.cos(g + w.harmonic_shift(x))
    return out


# ----------------------------------------------------------------------------- profile
def slow_flow_profile(F: float, Omega: float, xi_max: float, fourier: str | None = None, n: int = 1500,
                      well: WellArg = None) -> SlowFlowProfile:
    """Build the :class:`SlowFlowProfile` (a, b, suffix extrema, critical points) for one
    parameter set; see the module docstring."""
    w = resolve_well(well, fourier)
    f = check_scalar("F", F, check_nonnegative)
    om = check_scalar("Omega", Omega, check_positive)
    xm = check_scalar("xi_max", xi_max, w.check_threshold)
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 16:
        raise ValueError(f"n must be an integer >= 16 (nodes of the xi grid of the profile), got {n!r}")
    return SlowFlowProfile(f, om, xm, w, n)


def saddles(F: float, Omega: float, xi_max: float | None = None, fourier: str | None = None,
            well: WellArg = None) -> list[tuple[float, float]]:
    """Saddles of the slow flow below xi_max (eq 25), as a list of ``(gamma, xi)``.

    gamma = 0 saddles are interior maxima of ``a(xi)``, gamma = pi saddles interior minima of
    ``b(xi)``; each root of ``a'`` / ``b'`` is bracketed on a fine grid and polished by Brent's
    method (the paper uses Newton-Raphson, Sec. 3.2).  ``xi_max``: the barrier energy by
    default.  For a well with a phase delta(xi), the returned gamma is 0 or pi of the sheared
    rays (the saddle's slow phase is gamma - delta(xi)).
    """
    w = resolve_well(well, fourier)
    xm = w.barrier_energy if xi_max is None else xi_max
    prof = slow_flow_profile(F, Omega, xm, n=1500, well=w)
    out = [(0.0, float(x)) for x in prof.a_max if x < xm]
    out += [(np.pi, float(x)) for x in prof.b_min if x < xm]
    return sorted(out, key=lambda t: t[1])


def _escapes_rm(gamma: FloatArray, xi: FloatArray, prof: SlowFlowProfile) -> BoolArray:
    """Escape classification for validated points (gamma, xi) given a profile."""
    gamma, xi = np.broadcast_arrays(gamma, xi)
    out = np.ones(gamma.shape, dtype=bool)
    inside = xi < prof.xi_max
    g, x = gamma[inside], xi[inside]
    w = prof.well
    out[inside] = level_escapes(prof, x, w.J(x), w.harmonic_amplitude(x), np.cos(g + w.harmonic_shift(x)))
    return out


def escapes_on_manifold(gamma: ArrayLike, xi: ArrayLike, F: float, Omega: float, xi_max: float,
                        fourier: str | None = None, well: WellArg = None) -> BoolArray:
    """Does the slow-flow level curve (21) through ``(gamma, xi)`` reach ``xi = xi_max``?

    Boolean array (True = escapes), broadcast over gamma and xi; points with
    ``xi >= xi_max`` escape.  F, Omega, xi_max are scalars.  Criterion: see module docstring
    (``max a <= C(gamma, xi) <= min b`` over ``[xi, xi_max]``).
    """
    w = resolve_well(well, fourier)
    g = check_finite("gamma", gamma)
    x = w.check_energy("xi", xi, allow_separatrix=True)
    prof = slow_flow_profile(F, Omega, check_scalar("xi_max", xi_max, w.check_analytic_threshold), well=w)
    return _escapes_rm(g, x, prof)


def slow_flow_escapes(q0: ArrayLike, p0: ArrayLike, F: float, Omega: float, Psi: float, xi_max: float,
                      fourier: str | None = None, well: WellArg = None, damping: float = 0.0) -> BoolArray:
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
        return damped_escapes(q0, p0, F, Omega, Psi, xi_max, damping, well=w)
    xm = check_scalar("xi_max", xi_max, w.check_analytic_threshold)
    q = check_finite("q0", q0)
    p = check_finite("p0", p0)
    psi = check_scalar("Psi", Psi, check_finite)
    prof = slow_flow_profile(F, Omega, xm, well=w)
    grid = GridSlowFlow(q, p, psi, prof.xi_max, w, reuse=False)
    return grid.escapes(grid.profile(prof.F, prof.Omega))


# ----------------------------------------------------------------------------- Cartesian flow
_TABLE: list[tuple[FloatArray, FloatArray]] = []


def _J_table() -> tuple[FloatArray, FloatArray]:
    if not _TABLE:
        tab_x = xi_grid(0.0, XI_SEPARATRIX, 4001)
        _TABLE.append((tab_x, QUARTIC.J(tab_x)))
    return _TABLE[0]


def xi_from_J(Jv: ArrayLike) -> FloatArray:
    """Invert eq (19): energy xi with ``J(xi) = Jv`` (0 <= Jv <= 4/(3 pi)), Newton on dJ/dxi = 1/omega."""
    Jc = check_nonnegative("Jv", Jv)
    Jmax = float(QUARTIC.J(XI_SEPARATRIX))
    if (Jc > Jmax).any():
        raise ValueError(f"Jv must be <= J(1/4) = {Jmax}")
    # initial guess from a monotone table, then Newton steps
    tab_x, tab_J = _J_table()
    x: FloatArray = np.interp(Jc, tab_J, tab_x)
    for _ in range(3):
        inner = (x > 0) & (x < XI_SEPARATRIX)
        xs = np.where(inner, x, 0.1)
        x = np.where(inner, x - (QUARTIC.J(xs) - Jc) * QUARTIC.omega(xs), x)
        x = np.clip(x, 0.0, XI_SEPARATRIX)
    return x


def slow_flow_rhs(X: ArrayLike, Y: ArrayLike, F: ArrayLike, Omega: ArrayLike,
                  fourier: str = "paper") -> tuple[FloatArray, FloatArray]:
    """Slow flow (11) in Cartesian slow variables ``X = sqrt(2J) cos(gamma)``, ``Y = sqrt(2J) sin(gamma)``.

    With ``J' = -F G sin(gamma)`` and ``gamma' = omega - Omega - F omega G'(xi) cos(gamma)``:
    ``X' = J' cos(gamma)/r - Y gamma'``, ``Y' = J' sin(gamma)/r + X gamma'`` (``r^2 = 2J``).
    Regular at the well bottom (there ``X' = 0``, ``Y' = -F/2`` for ``G ~ r/2``).  Returns
    ``(dX, dY)``; C (eq 18) is conserved.  ``F >= 0``, ``Omega > 0`` (finite scalars or arrays),
    ``fourier`` "paper" | "exact", ``X^2 + Y^2 <= 2 J(1/4)``; a ValueError names the argument
    otherwise.  With damping see :func:`safebasins.theory.damped.rhs_gamma_frame`.
    """
    Fv = np.asarray(check_nonnegative("F", F), float)
    Om = np.asarray(check_positive("Omega", Omega), float)
    check_fourier(fourier)
    check_finite("X", X)
    check_finite("Y", Y)
    Xa = np.asarray(X, float)
    Ya = np.asarray(Y, float)
    r2 = Xa * Xa + Ya * Ya
    if (0.5 * r2 > float(QUARTIC.J(XI_SEPARATRIX))).any():
        raise ValueError("X, Y must lie inside the separatrix: X^2 + Y^2 <= 2 J(1/4) = "
                         f"{2 * float(QUARTIC.J(XI_SEPARATRIX))!r}")
    r = np.sqrt(r2)
    xi = xi_from_J(0.5 * r2)
    small = r < 1e-12
    rs = np.where(small, 1.0, r)
    xs = np.where(small, 1e-30, xi)
    c, s = np.where(small, 1.0, Xa / rs), np.where(small, 0.0, Ya / rs)
    well = resolve_well(None, fourier)
    w = well.omega(xs)
    dG = np.full(xs.shape, np.nan)            # no derivative on the separatrix (xi = 1/4)
    below = xs < XI_SEPARATRIX
    dG[below] = well.harmonic_amplitude_derivative(xs[below])
    Jdot = -Fv * well.harmonic_amplitude(xs) * s
    gdot = w - Om - Fv * w * dG * c
    dX: FloatArray = np.where(small, 0.0, Jdot * c / rs - Ya * gdot)
    dY: FloatArray = np.where(small, -0.5 * Fv, Jdot * s / rs + Xa * gdot)
    return dX, dY
