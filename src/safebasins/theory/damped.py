"""The damped slow flow of the 1:1 resonance, any well (docs/damping.md, "Slow flow with damping").

The equation ``q'' + beta q' + V'(q) = F sin(Omega tau + Psi)`` in action-angle variables of the
unforced well, averaged over the fast angle (first order in F and beta):

    J' = -dC/dgamma - beta J,        gamma' = dC/dJ,

with ``C(gamma, J) = H0(J) - Omega J - F A(J) cos(gamma + delta(J))`` (eq 12 / eq 18 for any
well, ``q_1 = -i A e^{i delta}``).  The damping term is exact for every well: on an unforced
orbit ``<p^2>/omega = (1/2 pi) oint p dq = J``; the damping's contribution to the angle averages
to zero (time reversal ``p -> -p`` maps ``theta -> c - theta``).  In the energy ``xi``
(``dJ/dxi = 1/omega``):

    xi' = -omega (dC/dgamma + beta J),     gamma' = omega dC/dxi.

C is no longer conserved: ``C' = -beta J gamma'``.

Cartesian frame (regular at the well bottom).  With the sheared phase ``phi = gamma + delta(J)``
and ``Xt = r cos phi``, ``Yt = r sin phi``, ``r = sqrt(2 J)``:

    Xt' = -(beta/2) Xt - (w~ - Omega) Yt + F e Xt Yt
    Yt' =  (w~ - Omega) Xt - (beta/2) Yt - F (a + e Xt^2)

with ``a = A/r``, ``b = r dA/dJ``, ``e = (b - a)/r^2``, ``w~ = omega - beta d``, ``d = J ddelta/dJ``
(``d = 0`` for a symmetric well, where phi = gamma).  a, e, omega, d are smooth functions of J
(a -> 1/(2 sqrt(omega(0))), e finite at J = 0), so the flow is a polynomial in (Xt, Yt) with
coefficients tabulated once per well (:class:`SlowTables`).  The divergence in (gamma, J), i.e.
in (Xt, Yt), is ``-beta`` everywhere: for beta > 0 there is no periodic orbit (Bendixson), so every
slow trajectory either reaches xi_max or converges to a fixed point.

Fixed points (``damped_fixed_points``; :mod:`safebasins.theory.responses` builds on them):

    F A sin(phi) = -beta J,      w~ - Omega - F omega dA/dxi cos(phi) = 0.
"""
from __future__ import annotations

import weakref

import numpy as np
from numpy.typing import ArrayLike

from safebasins.core.checks import check_nonnegative, check_positive, check_scalar
from safebasins.theory.profile import unshear
from safebasins.theory.types import FloatArray
from safebasins.wells.base import Well
from safebasins.wells.quartic import QuarticWell

__all__ = ["coefficients", "xi_of_J", "SlowTables", "slow_tables", "flow_tilde",
           "to_tilde", "from_tilde", "rhs_exact", "rhs_gamma_frame"]

#: coefficients at energies below ``XI_FLOOR * barrier_energy`` are taken there (the cancellation
#: in e = (b - a)/r^2 is harmless: e multiplies Xt Yt ~ J)
XI_FLOOR = 1e-8
#: the top of the tables: ``(1 - TOP_GAP) * barrier_energy`` (below the separatrix singularity)
TOP_GAP = 1e-9


def shift_derivative(well: Well, xi: FloatArray) -> FloatArray:
    """``d delta / d xi`` (the phase of the first harmonic, wells.base.harmonic_shift), ``xi > 0``;
    0 for the quartic; the well's own derivative where it has one, else central differences."""
    if isinstance(well, QuarticWell):
        return np.zeros(np.shape(xi))
    der = getattr(well, "harmonic_phase_derivative", None)
    if der is not None:
        out: FloatArray = der(xi)
        return out
    h = 1e-6 * np.maximum(xi, 1e-6 * well.barrier_energy)
    lo = np.maximum(xi - h, 0.5 * xi)
    hi = np.minimum(xi + h, well.barrier_energy * (1 - TOP_GAP))
    diff: FloatArray = (well.harmonic_shift(hi) - well.harmonic_shift(lo)) / (hi - lo)
    return diff


def coefficients(well: Well, xi: ArrayLike) -> dict[str, FloatArray]:
    """The slow flow's functions of the energy (validated ``0 <= xi < barrier_energy``).

    Returns a dict with ``J``, ``omega``, ``A`` (= ``|q_1|``), ``A_xi`` (dA/dxi), ``delta``,
    ``delta_xi`` and the Cartesian-frame coefficients ``a = A/r``, ``e = (r dA/dJ - A/r)/r^2``,
    ``d = J ddelta/dJ`` (module docstring); below ``XI_FLOOR * barrier_energy`` the derivatives
    and a, e, d are those at that floor.
    """
    x = np.asarray(xi, float)
    xf = np.maximum(x, XI_FLOOR * well.barrier_energy)
    J = well.J(x)
    Jf = well.J(xf)
    om = well.omega(xf)
    A = well.harmonic_amplitude(x)
    Af = well.harmonic_amplitude(xf)
    A_xi = well.harmonic_amplitude_derivative(xf)
    delta_xi = shift_derivative(well, xf)
    r = np.sqrt(2.0 * Jf)
    a = Af / r
    b = r * om * A_xi
    return {"J": J, "omega": well.omega(x), "A": A, "A_xi": A_xi, "delta": well.harmonic_shift(x),
            "delta_xi": delta_xi, "a": a, "e": (b - a) / (r * r), "d": Jf * om * delta_xi}


def flow_tilde(Xt: FloatArray, Yt: FloatArray, F: float | FloatArray, Omega: float | FloatArray, beta: float,
               omega: FloatArray, a: FloatArray, e: FloatArray, d: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The damped slow flow in the sheared Cartesian frame (module docstring), given the
    coefficients at ``J = (Xt^2 + Yt^2)/2``; returns ``(Xt', Yt')``."""
    om = omega - beta * d - Omega
    dX: FloatArray = -0.5 * beta * Xt - om * Yt + F * e * Xt * Yt
    dY: FloatArray = om * Xt - 0.5 * beta * Yt - F * (a + e * Xt * Xt)
    return dX, dY


# ----------------------------------------------------------------------------- tables
class SlowTables:
    """The coefficients ``omega, a, e, d`` (and xi) of one well tabulated on a uniform grid in
    ``s = -log(1 - J/J_c)`` (J_c just above the table's top action): uniform in J near the well
    bottom, geometrically refined towards the separatrix, where omega ~ 1/log and dA/dxi diverge
    (smooth in s).  Evaluation is an O(1) index plus linear interpolation (no search).

    Accuracy (linear interpolation, ``n = 2**15`` nodes): the tabulated flow differs from
    :func:`rhs_exact` by less than 1e-5 of its magnitude up to xi = 0.2499 of the quartic and
    xi = 0.1666 of the cubic (measured 2e-6 and 3e-6; tests/theory/test_damped.py).
    """

    def __init__(self, well: Well, n: int = 2 ** 15) -> None:
        self.well = well
        E_b = float(well.barrier_energy)
        self.xi_top = E_b * (1.0 - TOP_GAP)
        J_top = float(well.J(np.asarray(self.xi_top)))
        self.J_c = J_top * (1.0 + 1e-7)
        self.s_top = -np.log1p(-J_top / self.J_c)
        s = np.linspace(0.0, self.s_top, n)
        self.ds = s[1] - s[0]
        Jn = -self.J_c * np.expm1(-s)
        Jn[-1] = J_top
        xi = self._invert(Jn)
        xi[0], xi[-1] = 0.0, self.xi_top
        c = coefficients(well, xi)
        with np.errstate(divide="ignore", invalid="ignore"):
            c["d_r"] = c["d"] / np.sqrt(2.0 * Jn)      # d ~ r near the bottom of an asymmetric well
        for k in ("a", "e", "d_r"):        # node 0 (J = 0): extrapolated in J from nodes 1, 2
            v = c[k]
            v[0] = v[1] + (v[1] - v[2]) * Jn[1] / (Jn[2] - Jn[1])
        self.n = n
        self.J = Jn
        self.xi = xi
        vals = np.stack([c["omega"], c["a"], c["e"], c["d_r"], xi], axis=1)
        slopes = np.zeros_like(vals)
        slopes[:-1] = np.diff(vals, axis=0)
        self._tab = np.ascontiguousarray(np.concatenate([vals, slopes], axis=1))
        self.symmetric = bool(np.all(c["delta"] == 0.0))

    def _invert(self, Jv: FloatArray) -> FloatArray:
        """xi with J(xi) = Jv (0 <= Jv <= J_top): Chebyshev table, then Newton on dJ/dxi = 1/omega."""
        w = self.well
        t = np.linspace(0.0, 1.0, 4001)
        xg = self.xi_top * 0.5 * (1.0 - np.cos(np.pi * t))
        Jg = w.J(xg)
        x: FloatArray = np.interp(Jv, Jg, xg)
        for _ in range(4):
            x = np.clip(x, 0.0, self.xi_top)
            x = x - (w.J(x) - Jv) * w.omega(x)
        return np.clip(x, 0.0, self.xi_top)

    def lookup(self, J: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
        """``(omega, a, e, d, xi)`` at actions J (arrays of the shape of J), linear in s (d as d/r,
        which is smooth at the bottom of an asymmetric well, where d ~ r); J above the table's top
        gets the top values."""
        Jc = np.minimum(J, self.J[-1])
        s = -np.log1p(-Jc / self.J_c)
        u = s * (1.0 / self.ds)
        i = np.minimum(u.astype(np.intp), self.n - 2)
        f = (u - i)[..., None]
        row = self._tab[i]
        v = row[..., :5] + f * row[..., 5:]
        return v[..., 0], v[..., 1], v[..., 2], v[..., 3] * np.sqrt(2.0 * Jc), v[..., 4]

    def rhs(self, Xt: FloatArray, Yt: FloatArray, F: float | FloatArray, Omega: float | FloatArray,
            beta: float) -> tuple[FloatArray, FloatArray]:
        """The tabulated flow (Xt', Yt') at points (Xt, Yt) (F, Omega broadcast with them)."""
        om, a, e, d, _ = self.lookup(0.5 * (Xt * Xt + Yt * Yt))
        return flow_tilde(Xt, Yt, F, Omega, beta, om, a, e, d)


_QUARTIC_TABLES: dict[str, SlowTables] = {}
_TABLES: weakref.WeakKeyDictionary[Well, SlowTables] = weakref.WeakKeyDictionary()


def slow_tables(well: Well) -> SlowTables:
    """The :class:`SlowTables` of a well, built once and kept (per fourier variant for the quartic)."""
    if isinstance(well, QuarticWell):
        tab = _QUARTIC_TABLES.get(well.fourier)
        if tab is None:
            tab = _QUARTIC_TABLES[well.fourier] = SlowTables(well)
        return tab
    tab = _TABLES.get(well)
    if tab is None:
        tab = _TABLES[well] = SlowTables(well)
    return tab


def forcing_and_level(well: Well, F: float, Omega: float, xi_max: float) -> tuple[float, float, float, SlowTables]:
    """``(F, Omega, xi_max, tables)`` of a damped slow-flow call, checked (ValueError naming the
    argument); xi_max is clipped to the top of the well's :class:`SlowTables` (just below the
    separatrix, where the tables end)."""
    f = check_scalar("F", F, check_nonnegative)
    Om = check_scalar("Omega", Omega, check_positive)
    xm = check_scalar("xi_max", xi_max, well.check_threshold)
    tab = slow_tables(well)
    return f, Om, min(xm, tab.xi_top), tab


def xi_of_J(well: Well, Jv: ArrayLike) -> FloatArray:
    """Energy xi with ``J(xi) = Jv`` for any well (tables, then two Newton steps on the exact J)."""
    tab = slow_tables(well)
    Ja = np.asarray(Jv, float)
    x = tab.lookup(Ja)[4]
    for _ in range(2):
        x = np.clip(x, 0.0, tab.xi_top)
        x = x - (well.J(x) - Ja) * well.omega(x)
    out: FloatArray = np.clip(x, 0.0, tab.xi_top)
    return out


# ----------------------------------------------------------------------------- frames
def to_tilde(well: Well, gamma: float | FloatArray, xi: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """``(Xt, Yt) = sqrt(2 J(xi)) (cos phi, sin phi)``, ``phi = gamma + delta(xi)``."""
    r = np.sqrt(2.0 * well.J(xi))
    phi = gamma + well.harmonic_shift(xi)
    return r * np.cos(phi), r * np.sin(phi)


def from_tilde(well: Well, Xt: FloatArray, Yt: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``(gamma, xi)`` of points of the sheared Cartesian frame, gamma in (-pi, pi]."""
    xi = xi_of_J(well, 0.5 * (Xt * Xt + Yt * Yt))
    return unshear(np.arctan2(Yt, Xt), well.harmonic_shift(xi)), xi


def rhs_exact(well: Well, Xt: FloatArray, Yt: FloatArray, F: float | FloatArray, Omega: float | FloatArray,
              beta: float) -> tuple[FloatArray, FloatArray]:
    """The damped slow flow (Xt', Yt') with the well's exact functions (no tables): xi from J by
    Newton, then :func:`coefficients`."""
    xi = xi_of_J(well, 0.5 * (Xt * Xt + Yt * Yt))
    c = coefficients(well, xi)
    return flow_tilde(Xt, Yt, F, Omega, beta, c["omega"], c["a"], c["e"], c["d"])


def rhs_gamma_frame(well: Well, X: ArrayLike, Y: ArrayLike, F: float | FloatArray, Omega: float | FloatArray,
                    beta: float) -> tuple[FloatArray, FloatArray]:
    """The damped slow flow in ``X = sqrt(2J) cos(gamma)``, ``Y = sqrt(2J) sin(gamma)`` for any well.

    With ``Z = X + iY = e^{-i delta} Zt``: ``Z' = e^{-i delta} (Zt' - i (ddelta/dJ) J' Zt)``,
    ``J' = Re(conj(Zt) Zt')``; at the well bottom ``Z' = -F a(0) e^{-i delta(0)} i``.
    """
    Xa, Ya = np.broadcast_arrays(np.asarray(X, float), np.asarray(Y, float))
    xi = xi_of_J(well, 0.5 * (Xa * Xa + Ya * Ya))
    c = coefficients(well, xi)
    rot = np.exp(1j * c["delta"])
    Zt = rot * (Xa + 1j * Ya)
    dX, dY = flow_tilde(Zt.real, Zt.imag, F, Omega, beta, c["omega"], c["a"], c["e"], c["d"])
    dZt = dX + 1j * dY
    Jdot = (np.conj(Zt) * dZt).real
    dZ = (dZt - 1j * c["delta_xi"] * c["omega"] * Jdot * Zt) / rot
    return dZ.real, dZ.imag
