"""Action-angle variables of the free quartic oscillator (paper Sec. 2.1, eqs 4, 7, 13-20).

The checked public API of the theory; the formulas themselves live once in
:mod:`safebasins.wells.quartic` (Jacobi elliptic closed forms; see its docstring for the
conventions: SciPy's parameter ``m = k^2``, ``ellipkm1`` near the separatrix, the paper's G
versus the exact first harmonic).  Default everywhere is ``fourier="paper"``.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from safebasins.core.checks import check_finite
from safebasins.theory.types import FloatArray, WellArg
from safebasins.wells import resolve_well
from safebasins.wells.quartic import QUARTIC, check_fourier
from safebasins.wells.quartic import nome as quartic_nome

__all__ = ["H0", "q_max_from_xi", "J", "omega", "G", "dJ_dxi", "dG_dxi", "nome",
           "angle_energy", "phase_point", "initial_condition", "check_fourier"]


def H0(q: ArrayLike, p: ArrayLike) -> FloatArray:
    """Basic Hamiltonian, eq (7) untruncated: ``p^2/2 + q^2/2 - q^4/4``."""
    out: FloatArray = QUARTIC.H0(check_finite("q", q), check_finite("p", p))
    return out


def q_max_from_xi(xi_max: ArrayLike) -> FloatArray:
    """Displacement threshold for an energy threshold, eq (4): ``sqrt(1 - sqrt(1 - 4 xi_max))``."""
    out: FloatArray = QUARTIC.q_max(QUARTIC.check_threshold("xi_max", xi_max))
    return out


def J(xi: ArrayLike) -> FloatArray:
    """Averaged action as a function of energy, eqs (13)/(19).

    ``J = 2 sqrt(2) / (3 pi) sqrt(1 + mu) (E(k) - mu K(k))``, ``mu = sqrt(1 - 4 xi)``.
    Defined on ``0 <= xi <= 1/4`` (``J(1/4) = 2 sqrt(2) / (3 pi)``).
    """
    out: FloatArray = QUARTIC.J(QUARTIC.check_energy("xi", xi, allow_separatrix=True))
    return out


def omega(xi: ArrayLike) -> FloatArray:
    """Frequency of free oscillation ``dE/dI``, eq (16): ``pi sqrt(1 + mu) / (2 sqrt(2) K)``.

    ``omega(0) = 1``, ``omega(1/4) = 0``.  Equals ``1 / J'(xi)``.
    """
    out: FloatArray = QUARTIC.omega(QUARTIC.check_energy("xi", xi, allow_separatrix=True))
    return out


def dJ_dxi(xi: ArrayLike) -> FloatArray:
    """``dJ/dxi = 1 / omega(xi)`` (eq 16); infinite on the separatrix."""
    x = QUARTIC.check_energy("xi", xi, allow_separatrix=True)
    with np.errstate(divide="ignore"):
        out: FloatArray = 1.0 / QUARTIC.omega(x)
        return out


def G(xi: ArrayLike, fourier: str = "paper") -> FloatArray:
    """First-harmonic coefficient of ``q(theta)`` entering C, eq (20).

    ``fourier="paper"``: eq (20) exactly as printed,
    ``G = pi sqrt(1 + mu) / K(k) * exp(-pi K(k') / (2 K(k)))``.
    ``fourier="exact"``: the true half-amplitude of the first sine harmonic of ``q(theta)``
    (DLMF 22.11.1), i.e. eq (20) divided by ``1 - nome``, ``nome = exp(-pi K'/K)``; the paper's
    form is the leading term of that series: it is 6.8% below the exact value at xi = 0.24 and
    19.3% below at xi = 0.2499 (the exact value is 7.3% / 23.9% larger than the paper's).
    ``G(0) = 0``; ``G(1/4) = 0`` (limit).
    """
    check_fourier(fourier)
    x = QUARTIC.check_energy("xi", xi, allow_separatrix=True)
    out: FloatArray = resolve_well(None, fourier).harmonic_amplitude(x)
    return out


def dG_dxi(xi: ArrayLike, fourier: str = "paper") -> FloatArray:
    """Analytic derivative ``dG/dxi`` of eq (20) (or its exact form); xi in (0, 1/4)."""
    check_fourier(fourier)
    x = QUARTIC.check_energy("xi", xi)
    if (x <= 0).any():
        raise ValueError("xi must be > 0 for dG_dxi (G ~ sqrt(xi/2) at the well bottom)")
    out: FloatArray = resolve_well(None, fourier).harmonic_amplitude_derivative(x)
    return out


def nome(xi: ArrayLike) -> FloatArray:
    """Jacobi nome ``exp(-pi K'/K)`` of the free orbit with energy xi (0 at xi = 0, 1 at 1/4)."""
    out: FloatArray = quartic_nome(QUARTIC.check_energy("xi", xi, allow_separatrix=True))
    return out


def angle_energy(q: ArrayLike, p: ArrayLike, well: WellArg = None) -> tuple[FloatArray, FloatArray]:
    """Angle and energy ``(theta, xi)`` of a phase point, eqs (7) and (14).

    ``xi = H0(q, p)``; ``theta = pi F(phi|m) / (2 K)`` with the Jacobi amplitude ``phi`` taken
    from both ``q`` (``sn = q/A``) and ``p`` (``cn = p/(B dn)``) so that all four quadrants are
    covered: eq (14) alone (``phi = arcsin(q/A)``) gives only the half orbit with ``p >= 0``.
    ``theta`` is in ``[0, 2 pi)``; ``theta = 0`` at the well bottom (angle immaterial).
    Points must lie inside the well: ``|q| < 1`` and ``H0 < 1/4``.
    ``well``: another well (safebasins.wells) with the same angle convention (theta = 0 at
    q = 0 with p > 0); the default is the quartic.
    """
    return resolve_well(well).angle_energy(q, p)


def phase_point(theta: ArrayLike, xi: ArrayLike, well: WellArg = None) -> tuple[FloatArray, FloatArray]:
    """Phase point ``(q, p)`` of angle theta on the free orbit of energy xi, eqs (15), (17).

    ``q = sqrt(1 - mu) sn(2 K theta / pi | m)``,
    ``p = sqrt((1 - mu^2)/2) cn(.) dn(.)``.  Inverse of :func:`angle_energy`; ``well``: another
    well's orbit (numeric action-angle for wells without closed forms).
    """
    th = check_finite("theta", theta)
    if well is not None:
        return resolve_well(well).phase_point(th, xi)
    return QUARTIC.phase_point(th, QUARTIC.check_energy("xi", xi))


def initial_condition(xi_ini: ArrayLike, gamma_ini: ArrayLike, Psi: ArrayLike,
                      well: WellArg = None) -> tuple[FloatArray, FloatArray]:
    """IC ``(q0, p0)`` with averaged energy xi_ini and slow phase gamma_ini at tau = 0.

    ``gamma = theta - Psi - Omega tau`` so ``theta0 = gamma_ini + Psi``:
    returns ``phase_point(gamma_ini + Psi, xi_ini)`` (of ``well``; default the quartic).
    """
    xi = resolve_well(well).check_energy("xi_ini", xi_ini)
    g = check_finite("gamma_ini", gamma_ini)
    ps = check_finite("Psi", Psi)
    return phase_point(g + ps, xi, well)
