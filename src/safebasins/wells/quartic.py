"""The paper's well: the truncated quartic ``V = q^2/2 - q^4/4`` in closed form (Sec. 2.1).

Barriers at ``q = +-1`` with energy ``1/4`` (the separatrix).  Everything here is the one home
of the quartic's formulas: V, V', H0 (eq 7), the turning point / displacement threshold
``q_max(xi)`` (eq 4) and the action-angle variables in Jacobi elliptic functions (eqs 13-20).

Conventions of the elliptic functions
-------------------------------------
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
  (``fourier="exact"``).

The underscored functions take validated arrays (no checks): the theory modules call them on
their own grids; the public, checked API is :mod:`safebasins.theory.action_angle` and the
:class:`QuarticWell` methods.
"""
from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt
from scipy import special

from safebasins.core.checks import as_array, check_finite, value_repr
from safebasins.wells.base import Well
from safebasins.wells.compiled import WellCode, quartic_code

__all__ = ["QuarticWell", "QUARTIC", "XI_SEPARATRIX", "FOURIER_VARIANTS", "check_fourier", "nome"]

#: energy of the hilltops q = +-1 of V(q) = q^2/2 - q^4/4
XI_SEPARATRIX = 0.25
#: first-harmonic variants: eq (20) as printed, or the exact sn coefficient
FOURIER_VARIANTS = ("paper", "exact")
_C_J = 2.0 * np.sqrt(2.0) / (3.0 * np.pi)


def check_fourier(fourier: str) -> str:
    """Validate the ``fourier`` keyword ("paper" = eq (20) as printed, "exact" = true harmonic)."""
    if fourier not in FOURIER_VARIANTS:
        raise ValueError(f"fourier must be one of {FOURIER_VARIANTS}, got {fourier!r}")
    return fourier


# ----------------------------------------------------------------------------- potential
def _V(q: Any) -> Any:
    return 0.5 * q * q - 0.25 * q ** 4


def _H0(q: Any, p: Any) -> Any:
    """Eq (7), untruncated: ``p^2/2 + q^2/2 - q^4/4`` (validated arrays)."""
    return 0.5 * p * p + 0.5 * q * q - 0.25 * q ** 4


def _q_max(xi: Any) -> Any:
    """Eq (4), ``sqrt(1 - sqrt(1 - 4 xi))``, evaluated as ``sqrt(4 xi / (1 + sqrt(1 - 4 xi)))``
    (no cancellation at small xi)."""
    return np.sqrt(4.0 * xi / (1.0 + np.sqrt(1.0 - 4.0 * xi)))


# ----------------------------------------------------------------------------- elliptic
def _ell(xi: Any) -> dict[str, Any]:
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


def _J(xi: Any, e: Any = None) -> Any:
    """Eqs (13)/(19): ``J = 2 sqrt(2) / (3 pi) sqrt(1 + mu) (E(k) - mu K(k))``."""
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


def _omega(xi: Any, e: Any = None) -> Any:
    """Eq (16): ``pi sqrt(1 + mu) / (2 sqrt(2) K)``."""
    e = _ell(xi) if e is None else e
    with np.errstate(divide="ignore"):
        return np.pi * np.sqrt(1.0 + e["mu"]) / (2.0 * np.sqrt(2.0) * e["K"])


def _G(xi: Any, fourier: str = "paper", e: Any = None) -> Any:
    """Eq (20) (``fourier="paper"``) or the exact first harmonic (divided by 1 - nome)."""
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


def _dK_dm(K: Any, E: Any, m: Any, m1: Any, RD3: Any) -> Any:
    # (E - (1-m) K) / (2 m (1-m)) with E = K - m RD3  ->  (K - RD3) / (2 (1-m))
    return (K - RD3) / (2.0 * m1)


def _dG_dxi(xi: Any, fourier: str = "paper", e: Any = None) -> Any:
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


def nome(xi: Any) -> Any:
    """The elliptic nome ``q = exp(-pi K'(m) / K(m))`` of the quartic's orbit of energy ``xi``
    (1 at the separatrix, where K diverges): its powers set the Fourier coefficients of the orbit."""
    e = _ell(xi)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(np.isfinite(e["K"]), np.exp(-np.pi * e["Kp"] / e["K"]), 1.0)


def _amplitudes(mu: Any) -> tuple[Any, Any]:
    return np.sqrt(1.0 - mu), np.sqrt(0.5 * (1.0 - mu * mu))


def _angle_energy(q: Any, p: Any) -> tuple[Any, Any]:
    """Eq (14) extended to the whole orbit (validated points inside the well)."""
    xi = _H0(q, p)
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


def _phase_point(theta: Any, xi: Any) -> tuple[Any, Any]:
    """Eqs (15), (17) (validated)."""
    e = _ell(xi)
    A, B = _amplitudes(e["mu"])
    u = 2.0 * e["K"] * np.mod(theta, 2.0 * np.pi) / np.pi
    sn, cn, dn, _ = special.ellipj(u, e["m"])
    return A * sn, B * cn * dn


# ----------------------------------------------------------------------------- the well
class QuarticWell(Well):
    """``V(q) = q^2/2 - q^4/4``: barriers at ``q = +-1``, escape energy ``1/4``.

    ``fourier`` selects the first harmonic: ``"paper"`` (eq 20 as printed, the default of the
    paper reproduction) or ``"exact"`` (divided by ``1 - nome``).
    """

    name = "quartic"

    def __init__(self, fourier: str = "paper") -> None:
        self.fourier = check_fourier(fourier)

    # -- checks
    def check_energy(self, name: str, xi: npt.ArrayLike, *, allow_separatrix: bool = False) -> np.ndarray:
        """Energy in [0, 1/4) (or [0, 1/4] with allow_separatrix)."""
        a = as_array(name, xi)
        if (a < 0).any():
            raise ValueError(f"{name} must be >= 0 (energy measured from the well bottom), got min {float(a.min())!r}")
        if allow_separatrix:
            if (a > XI_SEPARATRIX).any():
                raise ValueError(f"{name} must be <= 1/4 (separatrix energy), got max {float(a.max())!r}")
        elif (a >= XI_SEPARATRIX).any():
            raise ValueError(
                f"{name} must be < 1/4: the action-angle map is singular on the separatrix, got max {float(a.max())!r}")
        return a

    def check_threshold(self, name: str, xi_max: npt.ArrayLike) -> np.ndarray:
        """Energy truncation level in (0, 1/4]."""
        a = as_array(name, xi_max)
        if ((a <= 0) | (a > XI_SEPARATRIX)).any():
            raise ValueError(f"{name} must lie in (0, 1/4], got {value_repr(a)}")
        return a

    @property
    def barrier_energy_text(self) -> str:
        return "1/4"

    def check_displacement(self, name: str, q_max: npt.ArrayLike) -> np.ndarray:
        """Displacement threshold in (0, 1] (the barrier at ``|q| = 1``)."""
        a = as_array(name, q_max)
        if ((a <= 0) | (a > 1)).any():
            raise ValueError(f"{name} must lie in (0, 1], got {value_repr(a)}")
        return a

    # -- the numerics
    def _compiled_form(self) -> WellCode:
        return quartic_code()

    def potential_text(self) -> str:
        return "q^2/2 - q^4/4"

    @property
    def omega_max(self) -> float:
        """``sqrt(max |V''|)`` on ``|q| <= 1``: ``V'' = 1 - 3 q^2`` is -2 at the barriers."""
        return float(np.sqrt(2.0))

    def barrier_text(self) -> str:
        return "|q| > 1"

    # -- potential (plain arithmetic: numpy arrays, DataArrays and scalars alike, no checks)
    def V(self, q: Any) -> Any:
        return _V(q)

    def dV(self, q: Any) -> Any:
        return q - q * q * q

    @property
    def barriers(self) -> tuple[float, float]:
        return (-1.0, 1.0)

    @property
    def barrier_energy(self) -> float:
        return XI_SEPARATRIX

    def H0(self, q: npt.ArrayLike, p: npt.ArrayLike) -> Any:
        """Eq (7), untruncated: ``p^2/2 + q^2/2 - q^4/4``."""
        return _H0(q, p)

    def q_max(self, xi_max: npt.ArrayLike) -> Any:
        """Displacement threshold of an energy threshold, eq (4) (``xi_max`` in (0, 1/4]: else
        ValueError naming it)."""
        self.check_threshold("xi_max", xi_max)
        return _q_max(xi_max)

    def xi_from_q_max(self, q_max: npt.ArrayLike) -> Any:
        """Energy ``V(q_max)`` equivalent to a displacement threshold ``q_max`` in (0, 1] (else
        ValueError naming it)."""
        self.check_displacement("q_max", q_max)
        return _V(q_max)

    def turning_points(self, E: npt.ArrayLike) -> tuple[Any, Any]:
        qm = _q_max(self.check_energy("E", E, allow_separatrix=True))
        return -qm, qm

    def unforced_safe(self, q: Any, p: Any, xi_max: Any) -> Any:
        """The unforced safe set of a threshold, ``S0 = {H0 < xi_max, |q| < q_max(xi_max)}``."""
        return (_H0(q, p) < xi_max) & (abs(q) < _q_max(xi_max))

    # -- action-angle
    def J(self, E: npt.ArrayLike) -> Any:
        return _J(self.check_energy("E", E, allow_separatrix=True))

    def omega(self, E: npt.ArrayLike) -> Any:
        return _omega(self.check_energy("E", E, allow_separatrix=True))

    def angle_energy(self, q: npt.ArrayLike, p: npt.ArrayLike) -> tuple[Any, Any]:
        q, p = np.broadcast_arrays(check_finite("q", q), check_finite("p", p))
        if (np.abs(q) >= 1.0).any():
            raise ValueError("q must satisfy |q| < 1 (inside the potential well)")
        if (_H0(q, p) >= XI_SEPARATRIX).any():
            raise ValueError("p: phase point has H0(q, p) >= 1/4 (outside the well)")
        return _angle_energy(q, p)

    def phase_point(self, theta: npt.ArrayLike, E: npt.ArrayLike) -> tuple[Any, Any]:
        theta = check_finite("theta", theta)
        xi = self.check_energy("E", E)
        theta, xi = np.broadcast_arrays(theta, xi)
        return _phase_point(theta, xi)

    def first_harmonic(self, E: npt.ArrayLike) -> Any:
        """``q_1 = -i G`` (``q(theta) = 2 G sin(theta) + ...``), G of this well's ``fourier``."""
        return -1j * _G(self.check_energy("E", E, allow_separatrix=True), self.fourier)

    def harmonic_amplitude(self, E: npt.ArrayLike) -> Any:
        """G of eq (20) (this well's ``fourier``): ``|q_1|``."""
        return _G(self.check_energy("E", E, allow_separatrix=True), self.fourier)

    def harmonic_amplitude_derivative(self, E: npt.ArrayLike) -> Any:
        xi = self.check_energy("E", E)
        if (xi <= 0).any():
            raise ValueError("E must be > 0 for dG/dxi (G ~ sqrt(xi/2) at the well bottom)")
        return _dG_dxi(xi, self.fourier)

    def harmonic_phase(self, E: npt.ArrayLike) -> Any:
        return np.full(np.shape(self.check_energy("E", E, allow_separatrix=True)), -0.5 * np.pi)

    def harmonic_shift(self, E: npt.ArrayLike) -> Any:
        """Exactly 0: the quartic is symmetric, ``q(theta)`` is odd."""
        return np.zeros(np.shape(self.check_energy("E", E, allow_separatrix=True)))


#: the paper's well with the paper's first harmonic
QUARTIC = QuarticWell("paper")
