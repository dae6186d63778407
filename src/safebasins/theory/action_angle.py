"""Action-angle variables of the free quartic oscillator (paper Sec. 2.1, eqs 4, 7, 13-20).

Conventions
-----------
* Energy ``xi`` is measured from the well bottom, ``0 <= xi < 1/4`` (separatrix at 1/4).
* ``mu = sqrt(1 - 4 xi)``, modulus ``k^2 = m = (1 - mu) / (1 + mu)``; SciPy takes the
  *parameter* ``m = k^2`` (paper footnote 1).  We evaluate ``m = 4 xi / (1 + mu)^2`` and the
  complementary parameter ``1 - m = 2 mu / (1 + mu)`` separately, and use
  ``scipy.special.ellipkm1`` for both ``K = K(m)`` and ``K' = K(1 - m)`` so that neither
  loses digits at ``xi -> 0`` nor at ``xi -> 1/4``.
* Free motion: ``q = A sn(u|m)``, ``p = B cn(u|m) dn(u|m)`` with ``u = 2 K theta / pi``,
  ``A = sqrt(1 - mu)``, ``B = sqrt((1 - mu^2) / 2)`` (eqs 15, 17); ``theta`` advances at
  ``omega = dE/dI`` (eq 16) along ``q' = p, p' = -q + q^3``.
* ``G``: the paper's eq (20) is the leading term of the Fourier series of ``sn``
  (DLMF 22.11.1).  The exact half-amplitude of the first sine harmonic of ``q(theta)`` is
  ``G_paper / (1 - nome)``, ``nome = exp(-pi K'/K)``, so ``q(theta) = 2 G sin(theta) + ...``
  (``fourier="exact"``).  Default everywhere is ``fourier="paper"``.
"""
from __future__ import annotations

import numpy as np
from scipy import special

from .._validate import XI_SEPARATRIX, _arr, check_energy, check_threshold

__all__ = ["H0", "q_max_from_xi", "J", "omega", "G", "dJ_dxi", "dG_dxi", "nome",
           "angle_energy", "phase_point", "initial_condition", "check_fourier"]

_FOURIER = ("paper", "exact")
_C_J = 2.0 * np.sqrt(2.0) / (3.0 * np.pi)


def check_fourier(fourier):
    """Validate the ``fourier`` keyword ("paper" = eq (20) as printed, "exact" = true harmonic)."""
    if fourier not in _FOURIER:
        raise ValueError(f"fourier must be one of {_FOURIER}, got {fourier!r}")
    return fourier


def H0(q, p):
    """Basic Hamiltonian, eq (7) untruncated: ``p^2/2 + q^2/2 - q^4/4``."""
    q = _arr("q", q)
    p = _arr("p", p)
    q2 = q * q
    return 0.5 * p * p + 0.5 * q2 - 0.25 * q2 * q2


def q_max_from_xi(xi_max):
    """Displacement threshold for an energy threshold, eq (4): ``sqrt(1 - sqrt(1 - 4 xi_max))``.

    Evaluated as ``sqrt(4 xi / (1 + sqrt(1 - 4 xi)))`` (no cancellation at small xi).
    """
    xi = check_threshold("xi_max", xi_max)
    return np.sqrt(4.0 * xi / (1.0 + np.sqrt(1.0 - 4.0 * xi)))


# ----------------------------------------------------------------------------- internals
def _ell(xi):
    """Elliptic quantities for validated energies ``0 <= xi <= 1/4`` (no checks).

    Returns dict with mu, m, m1 (= 1 - m), K, Kp (= K(1-m)), E.  At xi = 1/4 K = inf.
    """
    xi = np.asarray(xi, dtype=float)
    mu = np.sqrt(np.maximum(1.0 - 4.0 * xi, 0.0))
    m = 4.0 * xi / (1.0 + mu) ** 2
    m1 = 2.0 * mu / (1.0 + mu)
    with np.errstate(divide="ignore", invalid="ignore"):
        K = special.ellipkm1(m1)      # K(m), accurate as m -> 1
        Kp = special.ellipkm1(m)      # K(1 - m), accurate as m -> 0
    E = special.ellipe(m)
    # (K - E)/m = R_D(0, 1-m, 1)/3 (Carlson), used to avoid cancellation in J and dK/dm at small m
    RD3 = special.elliprd(0.0, m1, 1.0) / 3.0
    return {"mu": mu, "m": m, "m1": m1, "K": K, "Kp": Kp, "E": E, "RD3": RD3}


def _J(xi, e=None):
    e = _ell(xi) if e is None else e
    # E - mu K = (1 - mu) K - m (K - E)/m ; both terms O(xi) at the well bottom (no cancellation)
    mu = e["mu"]
    with np.errstate(invalid="ignore"):
        small = mu > 0.5
        one_m_mu = 4.0 * np.asarray(xi, float) / (1.0 + mu)
        lo = one_m_mu * e["K"] - e["m"] * e["RD3"]
        hi = e["E"] - np.where(mu > 0, mu * e["K"], 0.0)
        d = np.where(small, lo, hi)
    return _C_J * np.sqrt(1.0 + mu) * d


def _omega(xi, e=None):
    e = _ell(xi) if e is None else e
    with np.errstate(divide="ignore"):
        return np.pi * np.sqrt(1.0 + e["mu"]) / (2.0 * np.sqrt(2.0) * e["K"])


def _G(xi, fourier="paper", e=None):
    e = _ell(xi) if e is None else e
    K, Kp = e["K"], e["Kp"]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(np.isfinite(K), Kp / K, 0.0)
        g = np.pi * np.sqrt(1.0 + e["mu"]) / K * np.exp(-0.5 * np.pi * ratio)
        if fourier == "exact":
            g = g / (1.0 - np.exp(-np.pi * ratio))
    g = np.where(np.asarray(xi) <= 0.0, 0.0, g)
    g = np.where(np.isfinite(K), g, 0.0)   # separatrix limit G(1/4) = 0
    return g


def _dK_dm(K, E, m, m1, RD3):
    # (E - (1-m) K) / (2 m (1-m)) with E = K - m RD3  ->  (K - RD3) / (2 (1-m))
    return (K - RD3) / (2.0 * m1)


def _dG_dxi(xi, fourier="paper", e=None):
    """dG/dxi for 0 < xi < 1/4 (validated)."""
    e = _ell(xi) if e is None else e
    mu, m, m1, K, Kp, E, RD3 = e["mu"], e["m"], e["m1"], e["K"], e["Kp"], e["E"], e["RD3"]
    with np.errstate(divide="ignore", invalid="ignore"):
        g = _G(xi, fourier, e)
        dm_dxi = 4.0 / (mu * (1.0 + mu) ** 2)
        dmu_dxi = -2.0 / mu
        # d ln G / d xi ;  d(K'/K)/dm = -pi / (4 m m1 K^2)  (Legendre relation)
        dlog = 0.5 * dmu_dxi / (1.0 + mu)
        dlog = dlog + dm_dxi * (-_dK_dm(K, E, m, m1, RD3) / K + np.pi ** 2 / (8.0 * m * m1 * K ** 2))
        if fourier == "exact":
            q = np.exp(-np.pi * Kp / K)
            dlog = dlog + dm_dxi * q / (1.0 - q) * np.pi ** 2 / (4.0 * m * m1 * K ** 2)
        return g * dlog


# ----------------------------------------------------------------------------- public
def J(xi):
    """Averaged action as a function of energy, eqs (13)/(19).

    ``J = 2 sqrt(2) / (3 pi) sqrt(1 + mu) (E(k) - mu K(k))``, ``mu = sqrt(1 - 4 xi)``.
    Defined on ``0 <= xi <= 1/4`` (``J(1/4) = 2 sqrt(2) / (3 pi)``).
    """
    xi = check_energy("xi", xi, allow_separatrix=True)
    return _J(xi)


def omega(xi):
    """Frequency of free oscillation ``dE/dI``, eq (16): ``pi sqrt(1 + mu) / (2 sqrt(2) K)``.

    ``omega(0) = 1``, ``omega(1/4) = 0``.  Equals ``1 / J'(xi)``.
    """
    xi = check_energy("xi", xi, allow_separatrix=True)
    return _omega(xi)


def dJ_dxi(xi):
    """``dJ/dxi = 1 / omega(xi)`` (eq 16); infinite on the separatrix."""
    xi = check_energy("xi", xi, allow_separatrix=True)
    with np.errstate(divide="ignore"):
        return 1.0 / _omega(xi)


def G(xi, fourier="paper"):
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
    xi = check_energy("xi", xi, allow_separatrix=True)
    return _G(xi, fourier)


def dG_dxi(xi, fourier="paper"):
    """Analytic derivative ``dG/dxi`` of eq (20) (or its exact form); xi in (0, 1/4)."""
    check_fourier(fourier)
    xi = check_energy("xi", xi)
    if (xi <= 0).any():
        raise ValueError("xi must be > 0 for dG_dxi (G ~ sqrt(xi/2) at the well bottom)")
    return _dG_dxi(xi, fourier)


def nome(xi):
    """Jacobi nome ``exp(-pi K'/K)`` of the free orbit with energy xi (0 at xi = 0, 1 at 1/4)."""
    xi = check_energy("xi", xi, allow_separatrix=True)
    e = _ell(xi)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(np.isfinite(e["K"]), np.exp(-np.pi * e["Kp"] / e["K"]), 1.0)


def _amplitudes(mu):
    return np.sqrt(1.0 - mu), np.sqrt(0.5 * (1.0 - mu * mu))


def _angle_energy(q, p):
    xi = 0.5 * p * p + 0.5 * q * q - 0.25 * q ** 4
    xi = np.clip(xi, 0.0, None)
    e = _ell(xi)
    A, B = _amplitudes(e["mu"])
    m, K = e["m"], e["K"]
    # amplitude phi: sn = sin(phi) = q/A, cn = cos(phi) = p/(B dn), dn = sqrt(1 - m sn^2);
    # atan2 of both (scaled by A*B*dn > 0) is robust in all quadrants and at turning points.
    with np.errstate(divide="ignore", invalid="ignore"):
        sn2 = np.where(A > 0, np.minimum((q / np.where(A > 0, A, 1.0)) ** 2, 1.0), 0.0)
    dn = np.sqrt(1.0 - m * sn2)
    phi = np.arctan2(q * B * dn, p * A)            # in (-pi, pi]
    # reduce to |phi| <= pi/2 for eq (14):  F(phi) = 2K - F(pi - phi),  F(-phi) = -F(phi)
    big = np.abs(phi) > 0.5 * np.pi
    phr = np.where(big, np.sign(phi) * np.pi - phi, phi)
    Fi = special.ellipkinc(phr, m)
    Fi = np.where(big, np.sign(phi) * 2.0 * K - Fi, Fi)
    theta = np.mod(0.5 * np.pi * Fi / K, 2.0 * np.pi)   # eq (14)
    theta = np.where(xi > 0, theta, 0.0)
    theta = np.where(theta >= 2.0 * np.pi, 0.0, theta)
    return theta, xi


def angle_energy(q, p):
    """Angle and energy ``(theta, xi)`` of a phase point, eqs (7) and (14).

    ``xi = H0(q, p)``; ``theta = pi F(phi|m) / (2 K)`` with the Jacobi amplitude ``phi`` taken
    from both ``q`` (``sn = q/A``) and ``p`` (``cn = p/(B dn)``) so that all four quadrants are
    covered: eq (14) alone (``phi = arcsin(q/A)``) gives only the half orbit with ``p >= 0``.
    ``theta`` is in ``[0, 2 pi)``; ``theta = 0`` at the well bottom (angle immaterial).
    Points must lie inside the well: ``|q| < 1`` and ``H0 < 1/4``.
    """
    q = _arr("q", q)
    p = _arr("p", p)
    q, p = np.broadcast_arrays(q, p)
    if (np.abs(q) >= 1.0).any():
        raise ValueError("q must satisfy |q| < 1 (inside the potential well)")
    xi = 0.5 * p * p + 0.5 * q * q - 0.25 * q ** 4
    if (xi >= XI_SEPARATRIX).any():
        raise ValueError("p: phase point has H0(q, p) >= 1/4 (outside the well)")
    return _angle_energy(q, p)


def _phase_point(theta, xi):
    e = _ell(xi)
    A, B = _amplitudes(e["mu"])
    u = 2.0 * e["K"] * np.mod(theta, 2.0 * np.pi) / np.pi
    sn, cn, dn, _ = special.ellipj(u, e["m"])
    return A * sn, B * cn * dn


def phase_point(theta, xi):
    """Phase point ``(q, p)`` of angle theta on the free orbit of energy xi, eqs (15), (17).

    ``q = sqrt(1 - mu) sn(2 K theta / pi | m)``,
    ``p = sqrt((1 - mu^2)/2) cn(.) dn(.)``.  Inverse of :func:`angle_energy`.
    """
    theta = _arr("theta", theta)
    xi = check_energy("xi", xi)
    theta, xi = np.broadcast_arrays(theta, xi)
    return _phase_point(theta, xi)


def initial_condition(xi_ini, gamma_ini, Psi):
    """IC ``(q0, p0)`` with averaged energy xi_ini and slow phase gamma_ini at tau = 0.

    ``gamma = theta - Psi - Omega tau`` so ``theta0 = gamma_ini + Psi``:
    returns ``phase_point(gamma_ini + Psi, xi_ini)``.
    """
    xi = check_energy("xi_ini", xi_ini)
    g = _arr("gamma_ini", gamma_ini)
    ps = _arr("Psi", Psi)
    return phase_point(g + ps, xi)
