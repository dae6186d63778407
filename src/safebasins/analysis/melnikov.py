"""Melnikov threshold: first homoclinic / heteroclinic tangency of the hilltop saddle.

For ``q'' + beta q' + V'(q) = F sin(Omega t + Psi)`` with small ``(F, beta)`` the stable and
unstable manifolds of the forced saddle (the hyperbolic periodic orbit that continues the
hilltop of ``V``) are split by the Melnikov function, taken along the unforced separatrix
orbit ``(q0(t), p0(t))`` that leaves the saddle at ``t = -inf`` (docs/melnikov.md)::

    M(t0) = int p0(t) [F sin(Omega (t + t0) + Psi) - beta p0(t)] dt
          = -beta I1 + F |I2(Omega)| sin(Omega t0 + Psi + arg I2),
    I1 = int p0^2 dt = int p0 dq,        I2(Omega) = int p0 e^{i Omega t} dt = int e^{i Omega t(q)} dq.

``M(t0)`` is the energy gained along the perturbed orbit from the saddle back to a saddle; it
has simple zeros (transverse intersection, tangle, fractal basin boundary) iff ``F > F_M``::

    F_M(Omega) = beta I1 / |I2(Omega)|          (first order in F and beta).

The orbit is the separatrix of the saddle that sets the escape energy ``E_b`` (the lowest
barrier): **heteroclinic** from the left to the right saddle when both barriers have the energy
``E_b`` (the quartic, the pendulum: relative difference below :data:`HETEROCLINIC_RTOL`), else
**homoclinic**: it leaves the saddle ``q_b``, turns at the far turning point ``q_t`` (``V(q_t) =
E_b``) and returns (the cubic).  ``|I2|`` and ``F_M`` do not depend on the orientation or the
time origin of the orbit.

Quadrature (no time stepping): ``p0(q) = sqrt(2 (E_b - V(q)))`` and ``dt = dq / p0``.  Each half
of the orbit (from its middle ``t = 0`` to a saddle) is parametrised by ``v`` in ``[0, inf)``:

* heteroclinic half to the saddle ``q_e``: ``q_e - q = (q_e - q_o) / (1 + e^v)`` (``q_o`` the other
  saddle; ``v = 0`` at the midpoint);
* homoclinic half: ``q_e - q = (q_e - q_t) sech^2(v/2)`` (``v = 0`` at the turning point ``q_t``);

so that ``q_e - q ~ e^{-v}`` at the saddle (where ``t ~ v / lambda`` grows linearly, the log
singularity of ``t(q)`` removed) and ``q - q_t ~ v^2`` at the turning point (the square-root
singularity removed): ``dt/dv = |dq/dv| / p0`` is smooth and bounded.  Near an end ``q_e`` of
energy ``E_b`` (saddle or turning point) ``E_b - V(q) = (q_e - q) <V'>`` with ``<V'>`` the
Gauss-Legendre mean of ``V'`` over ``[q, q_e]`` (no cancellation); at the turning point the
factor ``tanh(v/2)`` common to ``dq/dv`` and ``p0`` is cancelled in closed form.  The time
``t(v)`` is the cumulative Clenshaw-Curtis integral of ``dt/dv`` on panels in ``v`` (spectral,
integrated outward from ``t = 0``), truncated at ``v = V_END`` (``e^{-V_END} ~ 4e-18``); then::

    I1 = sum over halves of  int p0 |dq/dv| dv,
    I2(Omega) = H_fwd(Omega) - H_bwd(-Omega),   H(Omega) = int_0^inf e^{i Omega s(v)} dq/dv dv,

(``s`` the time elapsed from the middle along the half, ``H_bwd`` the half run backward in
time; for the homoclinic orbit ``I2 = 2 i int_0^inf sin(Omega s) dq``), vectorised over Omega
(panels short enough for ``Omega dt <= PHASE_PER_PANEL`` per panel).  Accuracy: ~1e-14 relative
against the closed forms (tests/analysis/test_melnikov.py).  ``|I2|`` falls like ``e^{-d Omega}``
(``d`` the distance of the nearest complex singularity of ``p0(t)`` from the real axis) while the
quadrature sums terms of size ``|dq|``: once ``|I2|`` is within :data:`MIN_SIGNAL` rounding units of zero the
threshold (then astronomically large, far outside the first-order theory) is refused with a
ValueError naming ``Omega``.

Closed forms (derived in docs/melnikov.md; :data:`CLOSED_FORMS`):

* quartic ``V = q^2/2 - q^4/4`` (heteroclinic, ``q0 = tanh(t/sqrt 2)``): ``I1 = 2 sqrt(2)/3``,
  ``|I2| = sqrt(2) pi Omega / sinh(pi Omega / sqrt 2)``, ``F_M = 2 beta sinh(pi Omega/sqrt 2) / (3 pi Omega)``;
* cubic ``V = q^2/2 - q^3/3`` (homoclinic, ``q0 = 1 - (3/2) sech^2(t/2)``): ``I1 = 6/5``,
  ``|I2| = 6 pi Omega^2 / sinh(pi Omega)``, ``F_M = beta sinh(pi Omega) / (5 pi Omega^2)`` (Thompson);
* pendulum ``V = 1 - cos q`` (heteroclinic, ``q0 = 4 arctan(e^t) - pi``): ``I1 = 8``,
  ``|I2| = 2 pi sech(pi Omega / 2)``, ``F_M = (4 beta / pi) cosh(pi Omega / 2)``.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import numpy.typing as npt
import xarray as xr
from numpy.polynomial import legendre as _leg
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar
from scipy.interpolate import CubicSpline

from safebasins.core import checks
from safebasins.wells import resolve_well, well_attrs
from safebasins.wells.base import WellLike
from safebasins.wells.orbit_quadrature import clenshaw_curtis
from safebasins.wells.provenance import api_provenance

__all__ = ["melnikov_threshold", "melnikov_curve", "melnikov_function", "separatrix_integrals", "separatrix_orbit",
           "SeparatrixOrbit", "manifold_splitting", "CLOSED_FORMS"]

#: two barriers whose energies agree to this relative tolerance are one level: heteroclinic orbit
HETEROCLINIC_RTOL = 1e-9
#: truncation of each half orbit in v (the neglected tail of dq is ~ e^{-V_END} of the orbit's extent)
V_END = 40.0
#: Clenshaw-Curtis nodes per panel, the longest panel in v, the most phase Omega dt across one panel
N_NODES = 24
PANEL = 1.0
PHASE_PER_PANEL = 2.0
#: near an end (within END_ZONE of the half orbit's extent) E_b - V = (q_e - q) <V'>, N_MEAN Gauss nodes
END_ZONE = 0.05
N_MEAN = 8
#: closer to a saddle than END_FLOOR of the extent, <V'>/(q_e - q) is frozen (q_e - q not representable)
END_FLOOR = 1e-8
#: time window of the manifold flows (manifold_splitting)
_SEGMENT = 1.5
#: the smallest ``|I2|`` accepted, in units of the rounding level eps * (total variation of q0)
MIN_SIGNAL = 1e6

_EPS = np.finfo(float).eps
_CC = clenshaw_curtis(N_NODES)
_GX, _GW = _leg.leggauss(N_MEAN)
_MEAN_T, _MEAN_W = 0.5 * (_GX + 1.0), 0.5 * _GW

#: closed forms ``name -> (I1, |I2|(Omega), kind)`` of the named wells (docs/melnikov.md)
CLOSED_FORMS = {
    "quartic": (2.0 * np.sqrt(2.0) / 3.0,
                lambda W: np.sqrt(2.0) * np.pi * W / np.sinh(np.pi * W / np.sqrt(2.0)), "heteroclinic"),
    "cubic": (6.0 / 5.0, lambda W: 6.0 * np.pi * W ** 2 / np.sinh(np.pi * W), "homoclinic"),
    "pendulum": (8.0, lambda W: 2.0 * np.pi / np.cosh(0.5 * np.pi * W), "heteroclinic"),
}


@dataclasses.dataclass(frozen=True)
class SeparatrixOrbit:
    """The unforced separatrix orbit of the saddle that sets the escape energy.

    ``kind`` "heteroclinic" (``saddles = (q_left, q_right)``, the orbit runs left to right on the
    upper branch ``p > 0``) or "homoclinic" (``saddles = (q_b,)``, ``turning_point`` the far
    turning point ``q_t``, ``V(q_t) = E_b``); ``energy`` is ``E_b``."""
    kind: str
    saddles: tuple
    turning_point: float
    energy: float


def separatrix_orbit(well: WellLike = None) -> SeparatrixOrbit:
    """The separatrix orbit (module docstring) of ``well`` (any form :func:`resolve_well` reads).

    ValueError naming ``well`` when the escape energy is not set by a hilltop saddle (a well open
    at infinity whose limit of V is at or below its lowest barrier, e.g. sech2 and morse: no
    saddle, no separatrix)."""
    w = resolve_well(well)
    lo, hi = (float(b) for b in w.barriers)
    Vb = [float(np.asarray(w.V(np.array([b])))[0]) if np.isfinite(b) else np.inf for b in (lo, hi)]
    if not (np.isfinite(lo) or np.isfinite(hi)) or w.open_at_infinity:
        raise ValueError(f"well: the {w.name} well has no hilltop saddle that sets its escape energy "
                         f"(barriers at {(lo, hi)}, V -> {w.asymptotes} at infinity: escape to infinity "
                         f"over no saddle), so no separatrix and no Melnikov threshold")
    Eb = min(Vb)
    if np.isfinite(lo) and np.isfinite(hi) and abs(Vb[0] - Vb[1]) <= HETEROCLINIC_RTOL * abs(Eb):
        return SeparatrixOrbit("heteroclinic", (lo, hi), float("nan"), Eb)
    side = 0 if Vb[0] < Vb[1] else 1
    qb = (lo, hi)[side]
    qt = float(np.asarray(w.turning_points(Eb)[1 - side]))
    for _ in range(3):                         # polish V(q_t) = E_b (a simple root: V'(q_t) != 0)
        f = float(np.asarray(w.V(np.array([qt])))[0]) - Eb
        d = float(np.asarray(w.dV(np.array([qt])))[0])
        if f == 0.0 or d == 0.0 or not np.isfinite(f / d):
            break
        qt -= f / d
    if not (np.isfinite(qt) and qt * qb < 0):
        raise ValueError(f"well: the separatrix of the {w.name} well's saddle at q = {qb!r} has no turning point "
                         f"on the far side (got {qt!r})")
    return SeparatrixOrbit("homoclinic", (qb,), qt, Eb)


def _mean_dV(dV, q_end, gap):
    """Mean of V' over ``[q_end - gap, q_end]`` (Gauss-Legendre, nodes measured from ``q_end``)."""
    s = q_end - gap[..., None] * (1.0 - _MEAN_T)
    return np.asarray(dV(s.ravel()), dtype=float).reshape(s.shape) @ _MEAN_W


def _half_integrand(well, E_end, q_end, q_start, kind, v):
    """At nodes ``v``: ``dq/dv`` (signed, along the half from its middle to the saddle ``q_end``),
    ``p0 = |dq/dt|`` and ``ds/dv`` (``s`` the time from the middle).  ``q_start`` is the other
    saddle (heteroclinic) or the turning point (homoclinic)."""
    D = q_end - q_start
    if kind == "heteroclinic":
        a = 1.0 / (1.0 + np.exp(v))            # (q_end - q) / D
        dqdv = D * a * (1.0 - a)
        gap_end = D * a                        # q_end - q, exact
        gap_start = D - gap_end                # q - q_start
    else:
        c = np.tanh(0.5 * v)
        s2 = 1.0 / np.cosh(0.5 * v) ** 2
        dqdv = D * c * s2
        gap_end = D * s2
        gap_start = D * c * c
    q = np.where(np.abs(gap_end) <= np.abs(gap_start), q_end - gap_end, q_start + gap_start)
    zone = END_ZONE * abs(D)
    ew = E_end - np.asarray(well.V(q.ravel()), dtype=float).reshape(q.shape)     # E_b - V(q), away from the ends
    near_end = np.abs(gap_end) <= zone
    if near_end.any():
        # E_b - V = g^2 r with r = <V'>_[q_e - g, q_e] / g -> -V''(q_e)/2; at g < END_FLOOR |D| (where
        # q_e - g is no longer representable to a few digits) r is frozen at g = END_FLOOR |D|, an
        # error O(END_FLOOR) where the orbit carries a weight O(END_FLOOR)
        g = gap_end[near_end]
        g_eff = np.where(np.abs(g) < END_FLOOR * abs(D), np.copysign(END_FLOOR * abs(D), D), g)
        ew[near_end] = g * g * (_mean_dV(well.dV, q_end, g_eff) / g_eff)
    p0 = np.sqrt(2.0 * np.maximum(ew, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        dsdv = np.abs(dqdv) / p0
    if kind == "homoclinic":
        near_turn = np.abs(gap_start) <= zone
        if near_turn.any():
            # E_b - V = -(q - q_t) <V'>_[q_t, q] = -D tanh^2 <V'>: cancel tanh(v/2) in dq/dv / p0
            mean = -_mean_dV(well.dV, q_start, -gap_start[near_turn])
            root = np.sqrt(2.0 * np.abs(D * mean))
            dsdv[near_turn] = np.abs(D) * s2[near_turn] / root
            p0[near_turn] = np.abs(c[near_turn]) * root
    return dqdv, p0, dsdv


def _half(well, E_end, q_end, q_start, kind, Omega_max):
    """Nodes of one half orbit: time ``s`` from the middle, quadrature weights times ``dq/dv`` and
    the half's contribution to I1."""
    x, w, S = _CC

    def nodes(length):
        m = int(np.ceil(V_END / length))
        h = V_END / m
        v = h * (np.arange(m)[:, None] + 0.5 * (x[None, :] + 1.0))
        dqdv, p0, dsdv = _half_integrand(well, E_end, q_end, q_start, kind, v)
        return v, h, dqdv, p0, dsdv

    v, h, dqdv, p0, dsdv = nodes(PANEL)
    rate = float(np.max(dsdv))
    if not (np.isfinite(dsdv).all() and np.isfinite(p0).all() and rate > 0):
        raise ValueError(f"well: the separatrix quadrature of the {well.name} well failed (non-finite dt/dq between "
                         f"q = {q_start!r} and the saddle at {q_end!r}: is V(q) < E_b on the whole orbit?)")
    if Omega_max * rate * PANEL > PHASE_PER_PANEL:
        v, h, dqdv, p0, dsdv = nodes(PHASE_PER_PANEL / (Omega_max * rate))
    cum = 0.5 * h * (dsdv @ S.T)                 # within each panel, from its left end
    off = np.concatenate([[0.0], np.cumsum(cum[:, -1])[:-1]])
    s = cum + off[:, None]
    wq = 0.5 * h * w[None, :] * dqdv
    I1 = float(np.sum(0.5 * h * w[None, :] * p0 * np.abs(dqdv)))
    return s.ravel(), wq.ravel(), I1


def _fourier(s, wq, Omega, sign=1.0, chunk=1 << 21):
    """``sum wq exp(i sign Omega s)`` for each Omega (1-D), in chunks."""
    out = np.empty(Omega.shape, dtype=complex)
    step = max(1, chunk // max(s.size, 1))
    for i in range(0, Omega.size, step):
        out[i:i + step] = np.exp(1j * sign * Omega[i:i + step, None] * s[None, :]) @ wq
    return out


def _integrals(orbit, well, Omega):
    """``I1``, complex ``I2(Omega)`` (1-D Omega) of the orbit and the rounding level of each I2
    (``eps`` times the sum of the moduli of its terms)."""
    Om = float(np.max(Omega)) if Omega.size else 1.0
    if orbit.kind == "heteroclinic":
        lo, hi = orbit.saddles
        V_lo, V_hi = (float(np.asarray(well.V(np.array([b])))[0]) for b in (lo, hi))
        s_f, w_f, I1_f = _half(well, V_hi, hi, lo, "heteroclinic", Om)      # forward: to the right saddle
        s_b, w_b, I1_b = _half(well, V_lo, lo, hi, "heteroclinic", Om)      # backward: to the left saddle
        I2 = _fourier(s_f, w_f, Omega) - _fourier(s_b, w_b, Omega, -1.0)
        I1 = I1_f + I1_b
        floor = np.full(Omega.shape, _EPS * (np.sum(np.abs(w_f)) + np.sum(np.abs(w_b))))
    else:
        (qb,), qt = orbit.saddles, orbit.turning_point
        Vb = float(np.asarray(well.V(np.array([qb])))[0])
        s, wq, I1h = _half(well, Vb, qb, qt, "homoclinic", Om)
        I2 = np.zeros(Omega.shape, dtype=complex)
        floor = np.zeros(Omega.shape)
        step = max(1, (1 << 21) // s.size)
        for i in range(0, Omega.size, step):
            sin = np.sin(Omega[i:i + step, None] * s[None, :])
            I2[i:i + step] = 2j * (sin @ wq)
            floor[i:i + step] = 2.0 * _EPS * (np.abs(sin) @ np.abs(wq))
        I1 = 2.0 * I1h
    return I1, I2, floor


def _check_omega(Omega):
    Om = checks.as_array("Omega", Omega)
    if not np.isfinite(Om).all():
        raise ValueError("Omega must be finite")
    if (Om <= 0).any():
        raise ValueError(f"Omega must be > 0 (a forcing frequency), got min {float(Om.min())!r}")
    return Om


def separatrix_integrals(Omega: npt.ArrayLike, well: WellLike = None
                         ) -> tuple[float, npt.NDArray[np.complex128], SeparatrixOrbit]:
    """``(I1, I2, orbit)`` along the separatrix orbit (:func:`separatrix_orbit`) of ``well``, by
    the quadrature of the module docstring: ``I1 = int p0^2 dt`` (float) and the complex
    ``I2(Omega) = int p0(t) e^{i Omega t} dt`` (array shaped like ``Omega``) with the time origin
    ``t = 0`` at the middle of the orbit (the turning point of a homoclinic orbit, where ``I2`` is
    imaginary; the midpoint ``q = (q_left + q_right)/2`` of a heteroclinic one).  ValueError
    naming ``Omega`` (<= 0, NaN, inf, or so large that ``|I2|`` is lost in rounding) or ``well``
    (no hilltop saddle)."""
    Om = _check_omega(Omega)
    w = resolve_well(well)
    orbit = separatrix_orbit(w)
    flat = Om.ravel()
    I1, I2, floor = _integrals(orbit, w, flat)
    A = np.abs(I2)
    bad = A < MIN_SIGNAL * floor
    if bad.any():
        ok = flat[~bad]
        hint = f"; Omega <= {float(ok.max())!r} works" if ok.size else ""
        i = int(np.argmin(np.where(bad, flat, np.inf)))
        raise ValueError(f"Omega = {float(flat[i])!r} is too large for the {w.name} well: |int p0 e^(i Omega t) "
                         f"dt| = {float(A[i]):.3g} decays exponentially in Omega and is within "
                         f"{MIN_SIGNAL:g} rounding units ({float(floor[i]):.2g}) of zero, so F_M (beta I1 / |I2| > "
                         f"{I1 / (MIN_SIGNAL * float(floor[i])):.3g} beta, far outside the first-order theory) cannot "
                         f"be computed{hint}")
    return I1, I2.reshape(Om.shape), orbit


def melnikov_threshold(Omega: npt.ArrayLike, damping: float, well: WellLike = None) -> float | npt.NDArray[np.float64]:
    """Melnikov forcing threshold ``F_M(Omega) = damping * I1 / |I2(Omega)|`` of
    ``q'' + damping q' + V'(q) = F sin(Omega t + Psi)`` (module docstring): below ``F_M`` the
    stable and unstable manifolds of the forced hilltop saddle do not intersect (to first order in
    F and damping), at ``F_M`` they touch (homoclinic / heteroclinic tangency), above it they
    intersect transversally: a homoclinic tangle, fractal basin boundaries, erosion of the safe
    basin.  Independent of the phase Psi (it shifts the zeros of M(t0) only).

    ``Omega`` > 0 (scalar or array; a scalar gives a float, an array an array of its shape),
    ``damping`` >= 0 (``damping = 0`` gives ``F_M = 0``: without damping the manifolds of the
    saddle intersect transversally for every F > 0 (``M(t0) = F |I2| sin(...)`` has simple zeros),
    the threshold is F = 0 itself), ``well`` any form :func:`safebasins.wells.resolve_well` reads
    (None: the paper's quartic).  ValueError naming ``Omega``, ``damping`` or ``well`` (no hilltop
    saddle: sech2, morse)."""
    damping = checks.check_damping(damping)
    I1, I2, _ = separatrix_integrals(Omega, well)
    F = damping * I1 / np.abs(I2)
    return float(F) if np.ndim(F) == 0 else F


def melnikov_function(t0: npt.ArrayLike, F: float, Omega: float, damping: float, well: WellLike = None,
                      Psi: float = 0.0) -> float | npt.NDArray[np.float64]:
    """First-order Melnikov function ``M(t0) = -damping I1 + F Im(e^{i (Omega t0 + Psi)} I2(Omega))``
    (array shaped like ``t0``): the energy ``H0`` of the unstable manifold minus that of the stable
    manifold where they cross the normal of the separatrix orbit at its middle (the turning point
    of a homoclinic orbit, the midpoint of a heteroclinic one) at the time ``t0``, for the forcing
    ``F sin(Omega t + Psi)``.  ``M < 0`` for every ``t0`` iff ``F < F_M`` (no intersection).
    ``Omega`` a scalar here."""
    t0 = checks.check_finite("t0", t0)
    F = checks.check_scalar("F", F, checks.check_nonnegative)
    Psi = checks.check_scalar("Psi", Psi, checks.check_finite)
    Om = checks.check_scalar("Omega", Omega, lambda n, v: _check_omega(v))
    damping = checks.check_damping(damping)
    I1, I2, _ = separatrix_integrals(Om, well)
    M = -damping * I1 + F * np.imag(np.exp(1j * (Om * t0 + Psi)) * complex(I2))
    return float(M) if np.ndim(M) == 0 else M


@api_provenance
def melnikov_curve(Omega: npt.ArrayLike, damping: float, well: WellLike = None) -> xr.Dataset:
    """:func:`melnikov_threshold` over the 1-D ``Omega`` as a Dataset: ``F_M(Omega)``, the separatrix
    integrals ``I1`` and ``I2_abs(Omega)``, attributes naming the well (:func:`well_attrs`), the
    damping, the orbit kind ("heteroclinic" / "homoclinic"), its saddles and energy."""
    Om = checks.check_1d("Omega", Omega, checks.as_array)
    damping = checks.check_damping(damping)
    I1, I2, orbit = separatrix_integrals(Om, well)
    A = np.abs(I2)
    w = resolve_well(well)
    ds = xr.Dataset(coords={"Omega": ("Omega", Om, {"units": "1", "long_name": "forcing frequency Omega"})})
    ds["F_M"] = ("Omega", damping * I1 / A, {
        "units": "1",
        "long_name": "Melnikov threshold F_M = beta I1 / |I2| (first tangency of the saddle's manifolds)"})
    ds["I2_abs"] = ("Omega", A, {"units": "1",
                                 "long_name": "|I2| = |int p0(t) exp(i Omega t) dt| along the separatrix"})
    ds["I1"] = ((), I1, {"units": "1", "long_name": "I1 = int p0(t)^2 dt along the separatrix"})
    ds.attrs.update({
        "title": "Melnikov threshold of the hilltop saddle", **well_attrs(w),
        "damping": float(damping), "orbit": orbit.kind,
        "saddles": np.array(orbit.saddles, dtype=float), "separatrix_energy": float(orbit.energy),
        "method": "safebasins.analysis.melnikov: separatrix quadrature in q (no time stepping)",
        "forcing": "F sin(Omega t + Psi)"})
    if orbit.kind == "homoclinic":
        ds.attrs["turning_point"] = float(orbit.turning_point)
    return ds


# ---------------------------------------------------------------------------------------------
# numeric check: the forced saddle's manifolds on the normal section of the separatrix
# ---------------------------------------------------------------------------------------------
def _flow(well, F, Omega, damping, phase, y0, tau_end, rtol, dense=False):
    """DOP853 of ``q' = p, p' = -V'(q) - damping p + F sin(Omega tau + phase_k)`` for the columns of
    ``y0`` (2, N) over local times ``tau`` in ``[0, tau_end]`` (``tau_end < 0``: backward)."""
    n = y0.shape[1]

    def fun(tau, y):
        q, p = y[:n], y[n:]
        return np.concatenate([p, -np.asarray(well.dV(q), dtype=float) - damping * p
                               + F * np.sin(Omega * tau + phase)])
    sol = solve_ivp(fun, (0.0, tau_end), y0.ravel(), method="DOP853", rtol=rtol, atol=rtol * 1e-2,
                    dense_output=dense)
    if sol.status != 0:
        raise ValueError(f"F: the forced flow could not be integrated ({sol.message})")
    return sol if dense else sol.y[:, -1].reshape(2, n)


def _saddle_orbit(well, F, Omega, damping, Psi, q_b, rtol, h=1e-7):
    """The forced saddle's hyperbolic T-periodic orbit near ``(q_b, 0)`` and its Floquet directions:
    ``x*(0)``, ``(mu_u, e_u)``, ``(mu_s, e_s)`` at ``t = 0``.

    Multiple shooting (the orbit is unstable both ways: single shooting over a period amplifies
    errors by ``e^{lambda T}``): ``m`` nodes ``x_j`` at ``t_j = j T / m`` with ``lambda T / m <= 1``,
    Newton on ``phi_{t_j -> t_{j+1}}(x_j) = x_{j+1}`` (cyclic) with finite-difference blocks,
    started from the linear response ``xi = Im(F e^{i (Omega t + Psi)} / (-Omega^2 + i damping Omega -
    kappa))`` of ``xi'' + damping xi' - kappa xi = F sin(Omega t + Psi)`` (``kappa = -V''(q_b)``)."""
    T = 2.0 * np.pi / Omega
    scale = max(1.0, abs(q_b))
    dq = 1e-4 * scale
    dV_pm = np.asarray(well.dV(np.array([q_b + dq, q_b - dq])), dtype=float)
    kappa = -float(dV_pm[0] - dV_pm[1]) / (2 * dq)
    if not kappa > 0:
        raise ValueError(f"well: the barrier at q = {q_b!r} is not a hyperbolic saddle (V'' = {-kappa!r})")
    m = int(np.ceil(np.sqrt(kappa) * T))
    t = T * np.arange(m) / m
    A = F / (-Omega ** 2 - kappa + 1j * damping * Omega)          # xi = Im(A e^{i (Omega t + Psi)})
    z = A * np.exp(1j * (Omega * t + Psi))
    X = np.stack([q_b + z.imag, Omega * z.real], axis=0)          # (2, m)
    E = np.eye(2)
    for _ in range(40):
        Y0 = np.concatenate([X, X + h * E[0][:, None], X - h * E[0][:, None], X + h * E[1][:, None],
                             X - h * E[1][:, None]], axis=1)
        Y = _flow(well, F, Omega, damping, np.tile(Omega * t + Psi, 5), Y0, T / m, rtol)
        Y = Y.reshape(2, 5, m)
        D = np.stack([(Y[:, 1] - Y[:, 2]) / (2 * h), (Y[:, 3] - Y[:, 4]) / (2 * h)], axis=1)   # (2, 2, m)
        r = Y[:, 0] - np.roll(X, -1, axis=1)                       # phi(x_j) - x_{j+1}
        J = np.zeros((2 * m, 2 * m))
        for j in range(m):
            J[2 * j:2 * j + 2, 2 * j:2 * j + 2] = D[:, :, j]
            k = (j + 1) % m
            J[2 * j:2 * j + 2, 2 * k:2 * k + 2] -= E
        dx = np.linalg.solve(J, -r.T.ravel()).reshape(m, 2).T
        X = X + dx
        if not np.isfinite(X).all():
            break
        if np.max(np.abs(dx)) <= 1e-12 * scale:
            break
    else:
        X = X + np.nan
    if not np.isfinite(X).all():
        raise ValueError(f"F = {F!r}: no hyperbolic periodic orbit of the forced saddle near q = {q_b!r} (Newton did "
                         "not converge: F too large for a continuation of the hilltop)")
    P = E
    for j in range(m):
        P = D[:, :, j] @ P
    mu, vec = np.linalg.eig(P)
    if np.any(np.abs(np.imag(mu)) > 0) or not (np.max(np.abs(mu)) > 1 > np.min(np.abs(mu))):
        raise ValueError(f"F = {F!r}: the periodic orbit near q = {q_b!r} is not a saddle (multipliers {mu})")
    mu, vec = np.real(mu), np.real(vec)
    iu, is_ = int(np.argmax(np.abs(mu))), int(np.argmin(np.abs(mu)))
    return X[:, 0], (mu[iu], vec[:, iu]), (mu[is_], vec[:, is_])


def _manifold_section(well, F, Omega, damping, Psi, q_b, direction, unstable, section, sigma, offset, rtol):
    """Start times ``sigma`` (1-D, in [0, T)), a point ``offset`` along the unstable (stable)
    direction of the forced saddle's periodic orbit at each, on the side ``sign(e_q) = direction``;
    flow forward (backward) to the first crossing of the section.  Returns crossing times ``t_c``
    and the states there (2, N)."""
    T = 2.0 * np.pi / Omega
    x, (mu_u, e_u), (mu_s, e_s) = _saddle_orbit(well, F, Omega, damping, Psi, q_b, rtol)
    e = e_u if unstable else e_s
    h = 1e-5
    Y0 = np.stack([x, x + h * e, x - h * e], axis=1)
    sol = _flow(well, F, Omega, damping, np.full(3, Psi), Y0, T, rtol, dense=True)
    Ys = sol.sol(sigma).reshape(2, 3, -1)                      # (component, trajectory, sigma)
    xs = Ys[:, 0, :]
    es = (Ys[:, 1, :] - Ys[:, 2, :]) / (2 * h)
    es = es / np.hypot(es[0], es[1])
    es = es * np.where(np.sign(es[0]) == direction, 1.0, -1.0)
    y0 = xs + offset * es
    phase = Omega * sigma + Psi
    lam = abs(np.log(abs(mu_u if unstable else mu_s)) / T)
    n = sigma.size
    # in windows of SEGMENT time units, the trajectories that have not crossed yet only (a crossed
    # one may leave the well and blow up soon after: the stable manifold, flowed backward, comes
    # from beyond the barrier)
    t_c = np.full(n, np.nan)
    states = np.empty((2, n))
    active = np.arange(n)
    tau0, y, step = 0.0, y0, _SEGMENT if unstable else -_SEGMENT
    tau_max = 4.0 * ((np.log(1.0 / offset) + 10.0) / lam + T)
    while active.size:
        if abs(tau0) > tau_max:
            raise ValueError(f"F = {F!r}: a {'un' if unstable else ''}stable manifold of the saddle at q = {q_b!r} "
                             "never crosses the separatrix's normal section (F far above the threshold?)")
        sol = _flow(well, F, Omega, damping, phase[active] + Omega * tau0, y, step, rtol, dense=True)
        m = active.size
        taus = np.linspace(0.0, step, 101)
        Y = sol.sol(taus).reshape(2, m, -1)
        g, ok = section(Y[0], Y[1])
        cross = ok[:, 1:] & ok[:, :-1] & (np.sign(g[:, 1:]) != np.sign(g[:, :-1]))
        hit = cross.any(axis=1)
        first = np.argmax(cross, axis=1)
        for j in np.nonzero(hit)[0]:
            a, b = taus[first[j]], taus[first[j] + 1]
            fj = lambda tau, j=j: section(*sol.sol(tau).reshape(2, m)[:, j:j + 1, None])[0][0, 0]
            tc = brentq(fj, min(a, b), max(a, b), xtol=1e-14, rtol=4 * _EPS)
            t_c[active[j]] = sigma[active[j]] + tau0 + tc
            states[:, active[j]] = sol.sol(tc).reshape(2, m)[:, j]
        y = sol.y[:, -1].reshape(2, m)[:, ~hit]
        active = active[~hit]
        tau0 += step
    return t_c, states


@api_provenance
def manifold_splitting(F: float, Omega: float, damping: float, well: WellLike = None, Psi: float = 0.0,
                       n_phase: int = 48, offset: float = 1e-6, rtol: float = 1e-11) -> xr.Dataset:
    """Numeric splitting of the forced saddle's manifolds: the energy gap ``H0(W^u) - H0(W^s)``
    where the unstable and stable manifolds first cross the normal section of the separatrix orbit
    at its middle (homoclinic: ``p = 0`` at the turning point; heteroclinic: ``q = (q_left +
    q_right)/2``), as a function of the section time ``t0`` in one forcing period, next to its
    first-order prediction :func:`melnikov_function`.  The manifolds do not intersect there while
    the gap keeps one sign (``< 0``, ``F < F_M`` to first order) and intersect once it changes sign.

    Method: the hyperbolic T-periodic orbit of the forced saddle (Newton on the period map, DOP853)
    and its Floquet directions; for ``n_phase`` start times ``sigma`` in one period a point
    ``offset`` along the unstable (stable) direction is flowed forward (backward) to its first
    crossing of the section (DOP853 at ``rtol``, crossing by Brent on the dense output); the
    crossing energies, as functions of the crossing time mod T, are periodic cubic splines,
    evaluated on ``4 n_phase`` section times ``t0``; their extrema are refined by Brent on the
    splines.  Returns a Dataset with ``energy_gap`` and ``melnikov`` over ``t0`` and attributes
    ``min_energy_gap``, ``max_energy_gap``, ``manifolds_intersect`` (the gap takes both signs),
    ``F_M``, the parameters and the well.  ValueError naming ``F`` when the forced saddle has no
    hyperbolic periodic orbit (F far too large) or a manifold never reaches the section."""
    F = checks.check_scalar("F", F, checks.check_nonnegative)
    Om = checks.check_scalar("Omega", Omega, lambda n, v: _check_omega(v))
    damping = checks.check_damping(damping)
    Psi = checks.check_scalar("Psi", Psi, checks.check_finite)
    n_phase = checks.check_positive_int("n_phase", n_phase)
    if n_phase < 8:
        raise ValueError(f"n_phase must be >= 8 (start times per forcing period), got {n_phase}")
    offset = checks.check_scalar("offset", offset, checks.check_positive)
    rtol = checks.check_scalar("rtol", rtol, checks.check_positive)
    w = resolve_well(well)
    orbit = separatrix_orbit(w)
    T = 2.0 * np.pi / Om
    sigma = T * np.arange(n_phase) / n_phase
    if orbit.kind == "homoclinic":
        (qb,), qt = orbit.saddles, orbit.turning_point
        direction = float(np.sign(qt - qb))
        section = lambda q, p: (p, (q - qb) / (qt - qb) > 0.5)
        ends = [(qb, direction, True), (qb, direction, False)]
    else:
        lo, hi = orbit.saddles
        mid = 0.5 * (lo + hi)
        section = lambda q, p: (q - mid, np.abs(q - mid) < 0.5 * (hi - lo))
        ends = [(lo, 1.0, True), (hi, -1.0, False)]
    energies = []
    for q_b, direction, unstable in ends:
        t_c, (q, p) = _manifold_section(w, F, Om, damping, Psi, q_b, direction, unstable, section, sigma, offset, rtol)
        theta = np.mod(t_c, T)
        order = np.argsort(theta)
        theta, E = theta[order], np.asarray(w.H0(q, p), dtype=float)[order]
        spline = CubicSpline(np.append(theta, theta[0] + T), np.append(E, E[0]), bc_type="periodic")
        energies.append(spline)
    t0 = T * np.arange(4 * n_phase) / (4 * n_phase)
    gap_of = lambda t: energies[0](t) - energies[1](t)          # (periodic extrapolation)
    gap = gap_of(t0)
    extrema = []
    for sign in (1.0, -1.0):                                    # min, max: Brent on the splines
        k = int(np.argmin(sign * gap))
        res = minimize_scalar(lambda t: sign * gap_of(t), bounds=(t0[k] - T / (4 * n_phase), t0[k] + T / (4 * n_phase)),
                              method="bounded", options={"xatol": 1e-10 * T})
        extrema.append(sign * min(float(res.fun), sign * float(gap[k])))
    M = melnikov_function(t0, F, Om, damping, w, Psi)
    ds = xr.Dataset(coords={"t0": ("t0", t0, {"units": "1", "long_name": "section time t0 (one forcing period)"})})
    ds["energy_gap"] = ("t0", gap, {"units": "1", "long_name": "H0(unstable manifold) - H0(stable manifold) on the "
                                                          "separatrix's normal section (numeric)"})
    ds["melnikov"] = ("t0", M, {"units": "1", "long_name": "first-order Melnikov function M(t0)"})
    ds.attrs.update({"title": "splitting of the forced saddle's manifolds", **well_attrs(w), "F": F, "Omega": Om,
                     "damping": damping, "Psi": Psi, "orbit": orbit.kind,
                     "F_M": melnikov_threshold(Om, damping, w) if damping > 0 else 0.0,
                     "min_energy_gap": extrema[0], "max_energy_gap": extrema[1],
                     "manifolds_intersect": int(extrema[0] < 0 < extrema[1]), "n_phase": n_phase,
                     "offset": offset, "rtol": rtol,
                     "method": "DOP853 from the Floquet directions of the forced saddle's periodic orbit; first "
                               "crossing of the normal section; periodic cubic splines in the crossing time"})
    return ds
