"""Stochastic averaging of the noisy slow flow on the 1:1 resonance (docs/noise-theory.md).

With ``dp = (...) dtau + sigma dW`` the action-angle pair ``(theta, J)`` of the unforced well is
canonical, so ``dJ/dp = dq/dtheta`` and ``dtheta/dp = -dq/dJ`` (at fixed q, resp. theta), and the
noise's generator ``(sigma^2/2) d^2/dp^2`` is ``(sigma^2/2) div(v v^T grad)`` in ``(theta, J)`` with
the divergence-free field ``v = (-q_J, q_theta)``.  Averaged over the fast angle it becomes
``(sigma^2/2) div(m grad)`` in ``(gamma, J)`` with the orbit averages

    m_JJ = <q_theta^2> = <p^2>/omega^2 = J/omega,
    m_gg = <q_J^2>,          m_gJ = -<q_J q_theta>     (0 for a symmetric well),

i.e. the action diffusion ``sigma^2 J/omega``, the noise-induced action drift
``(sigma^2/2) d(J/omega)/dJ``, the phase diffusion ``sigma^2 m_gg`` and the J-gamma covariance
``sigma^2 m_gJ``.  In the regular frame ``X + i Y = sqrt(2J) e^{i gamma}`` the same operator is
``(sigma^2/2) div(A grad)`` with ``A = a_r e_r e_r^T + a_t e_g e_g^T`` (symmetric well),
``a_r = 1/(2 omega)``, ``a_t = 2 J m_gg``; both tend to ``1/(2 omega(0))`` at the well bottom
(isotropic: the linear oscillator's ``sigma^2/(2 omega)``).

``q_J = omega dq/dE`` at fixed theta is taken by central differences of the well's
``phase_point`` (any well with action-angle variables), and the averages by the trapezoidal rule
over theta (spectrally accurate for the periodic integrand).  Under an Ornstein-Uhlenbeck force of
correlation time tau (``noise_time``) each harmonic k of ``q_theta`` and ``q_J`` is weighted by the
force's spectrum at ``k omega`` (:func:`coloured_averages`, by FFT over the same angles).

None of these tables depends on sigma, F, Omega or the damping (the noise enters the solvers as
the factor sigma^2 of the diffusion): :func:`averaged_diffusion` computes them once per well and
``(xi_max, n, n_theta, noise_time)`` and keeps them (read-only) for the well's lifetime, so a sweep over noise
levels or forcings shares one set, bit for bit the first call's.
"""
from __future__ import annotations

import weakref
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from safebasins.theory.damped import shift_derivative
from safebasins.theory.types import FloatArray
from safebasins.wells.base import Well
from safebasins.wells.quartic import QuarticWell

__all__ = ["orbit_averages", "coloured_averages", "spectral_weights", "AveragedDiffusion", "averaged_diffusion",
           "table_evaluations", "N_THETA", "N_NODES"]

#: angles of the trapezoidal rule of the orbit averages
N_THETA = 256
#: action nodes of the tables
N_NODES = 600
#: tables kept per well (the most recently used (xi_max, n, n_theta))
_KEPT = 16
#: slow-flow evaluations (safebasins.pipeline.cost's unit, 1e6 per second) per phase point of the
#: tables: the quartic's closed forms (0.33 s for the default tables, 3 x 600 x 256 points, on one
#: core of the shared 2.5 GHz Xeon test machine), any other well's orbit quadrature (the pendulum's:
#: 5.9-10 s, 13-22 us a point)
CLOSED_FORM_POINT_EVALUATIONS = 1
QUADRATURE_POINT_EVALUATIONS = 25
#: the largest phase of the first harmonic (rad) of a well taken as symmetric
SHIFT_TOL = 1e-9
#: relative step of the central difference in the energy (q_J = omega dq/dE at fixed theta)
_REL_STEP = 1e-6


def orbit_averages(well: Well, xi: ArrayLike, n_theta: int = N_THETA, noise_time: float = 0.0,
                   sheared: bool = False) -> dict[str, FloatArray]:
    """Orbit averages of the noise terms at energies ``0 < xi < barrier_energy`` (validated by the
    well): ``J``, ``omega``, ``m_JJ = <(dJ/dp)^2> = <p^2>/omega^2``, ``m_gg = <(dtheta/dp)^2> =
    <q_J^2>``, ``m_gJ = <(dtheta/dp)(dJ/dp)> = -<q_J q_theta>``, and ``drift_J = <d^2J/dp^2>/2 =
    (1 - J domega/dE)/(2 omega)`` (the noise-induced action drift per unit sigma^2), each an array
    of the shape of xi.  ``noise_time`` tau > 0 (an Ornstein-Uhlenbeck force): the averages
    weighted by the force's spectrum at the orbit's harmonics (:func:`coloured_averages`).

    ``sheared``: the phase terms for the sheared angle ``phi = theta + delta(J)`` (``delta`` the
    phase of the first harmonic, ``well.harmonic_shift``) instead of theta: ``q_J`` taken at fixed
    phi, so ``m_gg = <(dphi/dp)^2>`` and ``m_gJ = <(dphi/dp)(dJ/dp)>``; the regular frame of an
    asymmetric well, where ``m_gJ`` vanishes (time reversal, docs/noise-theory.md)."""
    x = np.asarray(well.check_energy("xi", xi), float)
    if (x <= 0).any():
        raise ValueError("xi must be > 0 for the orbit averages (the angle is undefined at the well bottom)")
    th = 2.0 * np.pi * np.arange(n_theta) / n_theta
    xs = x.reshape(-1)
    h = _REL_STEP * np.minimum(xs, well.barrier_energy - xs)
    q, p = well.phase_point(th[:, None], xs[None, :])
    if sheared:
        # theta = phi - delta(J): at fixed phi the angle moves with the energy by -d delta
        d0 = np.asarray(well.harmonic_shift(xs), float)
        d_hi = np.asarray(well.harmonic_shift(xs + h), float) - d0
        d_lo = np.asarray(well.harmonic_shift(xs - h), float) - d0
        q_hi, _ = well.phase_point(th[:, None] - d_hi[None, :], (xs + h)[None, :])
        q_lo, _ = well.phase_point(th[:, None] - d_lo[None, :], (xs - h)[None, :])
    else:
        q_hi, _ = well.phase_point(th[:, None], (xs + h)[None, :])
        q_lo, _ = well.phase_point(th[:, None], (xs - h)[None, :])
    om = np.asarray(well.omega(xs), float)
    q_J = om * (q_hi - q_lo) / (2.0 * h)
    q_th = p / om
    # d omega/dE by the same central difference (omega(E) is smooth inside the well)
    om_E = (np.asarray(well.omega(xs + h)) - np.asarray(well.omega(xs - h))) / (2.0 * h)
    J = np.asarray(well.J(xs), float)
    if noise_time > 0:
        out = {"J": J, "omega": om, **coloured_averages(q_th, q_J, om, om * om_E, noise_time)}
        return {k: v.reshape(x.shape) for k, v in out.items()}
    p2 = (p * p).mean(axis=0)
    out = {"J": J, "omega": om, "m_JJ": p2 / om ** 2, "m_gg": (q_J * q_J).mean(axis=0),
           "m_gJ": -(q_J * q_th).mean(axis=0), "drift_J": 0.5 * (1.0 / om - p2 * om_E / om ** 2)}
    return {k: v.reshape(x.shape) for k, v in out.items()}


def spectral_weights(k: ArrayLike, omega: ArrayLike, noise_time: float) -> FloatArray:
    """``w_k = 1 / (1 + k^2 omega^2 tau^2)``: the Ornstein-Uhlenbeck force's spectrum at the
    harmonic ``k omega`` over its zero-frequency value sigma^2 (1 for white noise, tau = 0)."""
    kw = np.asarray(k, float) * np.asarray(omega, float) * noise_time
    out: FloatArray = 1.0 / (1.0 + kw * kw)
    return out


def coloured_averages(q_th: FloatArray, q_J: FloatArray, omega: FloatArray, omega_J: FloatArray,
                      noise_time: float) -> dict[str, FloatArray]:
    """The noise coefficients per unit sigma^2 under an Ornstein-Uhlenbeck force of correlation
    time ``noise_time`` (docs/noise-theory.md), from ``q_theta``, ``q_J`` on uniform angles (axis 0)
    and ``omega``, ``omega_J = domega/dJ`` per orbit.  With ``c_k``, ``d_k`` the Fourier coefficients
    of ``q_theta``, ``q_J`` and ``w_k`` the spectral weights: ``m_JJ = sum |c_k|^2 w_k``, ``m_gg =
    sum |d_k|^2 w_k - omega_J tau Re sum conj(c_k) d_k / (1 - i k omega tau)^2`` (the second term:
    an action kick shears the phase by omega_J times the lag within a correlation time) and
    ``drift_J = (1/2) dm_JJ/dJ`` (``d c_k/dJ = i k d_k``; ``w_k`` depends on J through omega).
    ``m_gJ`` (the J-phase covariance rate) and ``kappa`` (the antisymmetric part of the averaged
    matrix, whose J-derivative is a phase drift) are what the solver leaves out (diagnostics, O(tau);
    0 at tau = 0 for a symmetric well)."""
    n = q_th.shape[0]
    c = np.fft.fft(q_th, axis=0) / n
    d = np.fft.fft(q_J, axis=0) / n
    k = np.fft.fftfreq(n, 1.0 / n)[:, None]
    w = spectral_weights(k, omega[None, :], noise_time)
    c2 = (c * c.conj()).real
    dc2 = 2.0 * (c.conj() * 1j * k * d).real
    dw = -2.0 * k * k * omega * omega_J * noise_time ** 2 * w * w
    one = 1.0 / (1.0 - 1j * k * omega * noise_time)             # int_0^inf R(s) e^{i k omega s} ds / sigma^2, x2
    m_gJ = (-(c.conj() * d + d.conj() * c) * 0.5 * one + 0.5 * omega_J * noise_time * c2 * one * one).real.sum(axis=0)
    kappa = (0.25 * (c.conj() * d - d.conj() * c) * one + 0.25 * omega_J * noise_time * c2 * one * one).real.sum(0)
    shear = -omega_J * noise_time * (c.conj() * d * one * one).real.sum(axis=0)
    return {"m_JJ": (c2 * w).sum(axis=0), "m_gg": ((d * d.conj()).real * w).sum(axis=0) + shear, "m_gJ": m_gJ,
            "drift_J": 0.5 * (dc2 * w + c2 * dw).sum(axis=0), "kappa": kappa}


@dataclass(frozen=True)
class AveragedDiffusion:
    """The averaged diffusion of one well on ``0 <= J <= J_max``: tables over the action
    ``J_nodes`` of the energy ``H``, ``omega``, the first-harmonic amplitude over the radius
    ``a = A / sqrt(2 J)`` (C = H - Omega J - F A cos phi; a is smooth at J = 0, A is not) and the
    regular frame's radial and tangential coefficients ``a_r = 1/(2 omega)``, ``a_t = 2 J m_gg``
    (smooth at J = 0); linear interpolation in J.  The phase is the sheared ``phi = gamma +
    delta(J)`` (docs/damping.md; phi = gamma for a symmetric well, ``d_r`` None); an asymmetric
    well's ``d_r = d / sqrt(2 J)``, ``d = J ddelta/dJ``, turns the damping into the phase drift
    ``-beta d`` (smooth at J = 0, where ``d ~ sqrt(2 J)``)."""

    J_nodes: FloatArray
    H: FloatArray
    omega: FloatArray
    a: FloatArray
    a_r: FloatArray
    a_t: FloatArray
    d_r: FloatArray | None = None

    @property
    def symmetric(self) -> bool:
        """Whether the well is symmetric (phi = gamma: no shear of the phase)."""
        return self.d_r is None

    def d(self, J: ArrayLike) -> FloatArray:
        """``d = J ddelta/dJ`` at actions ``0 <= J <= J_max`` (0 for a symmetric well)."""
        Ja = np.asarray(J, float)
        if self.d_r is None:
            return np.zeros_like(Ja)
        out: FloatArray = np.interp(Ja, self.J_nodes, self.d_r) * np.sqrt(2.0 * Ja)
        return out

    @property
    def J_max(self) -> float:
        return float(self.J_nodes[-1])

    def at(self, J: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
        """``(H, omega, A, a_r, a_t)`` at actions ``0 <= J <= J_max``."""
        Ja = np.asarray(J, float)
        H, om, a, a_r, a_t = (np.interp(Ja, self.J_nodes, v) for v in (self.H, self.omega, self.a, self.a_r, self.a_t))
        return H, om, a * np.sqrt(2.0 * Ja), a_r, a_t

    def m_JJ(self, J: ArrayLike) -> FloatArray:
        """``J/omega``: the action's diffusion per unit sigma^2 (``2 J a_r``)."""
        Ja = np.asarray(J, float)
        out: FloatArray = 2.0 * Ja * np.interp(Ja, self.J_nodes, self.a_r)
        return out

    def m_gg(self, J: ArrayLike) -> FloatArray:
        """``<q_J^2>``: the phase's diffusion per unit sigma^2 (``a_t / (2 J)``, J > 0)."""
        Ja = np.asarray(J, float)
        out: FloatArray = np.interp(Ja, self.J_nodes, self.a_t) / (2.0 * Ja)
        return out


def table_evaluations(well: Well, n: int = N_NODES, n_theta: int = N_THETA) -> int:
    """Upper-bound slow-flow evaluations of :func:`averaged_diffusion`'s tables of ``well``: the
    three phase points (at the energy and its two neighbours of the central difference) per action
    node and angle."""
    per = CLOSED_FORM_POINT_EVALUATIONS if isinstance(well, QuarticWell) else QUADRATURE_POINT_EVALUATIONS
    return 3 * n * n_theta * per


#: well -> its tables by (xi_max, n, n_theta, noise_time); a well's entry goes with the well
_TABLES: weakref.WeakKeyDictionary[Well, OrderedDict[tuple[float, int, int, float], AveragedDiffusion]] = \
    weakref.WeakKeyDictionary()


def averaged_diffusion(well: Well, xi_max: float, n: int = N_NODES, n_theta: int = N_THETA,
                       noise_time: float = 0.0) -> AveragedDiffusion:
    """:class:`AveragedDiffusion` of ``well`` up to the energy ``xi_max`` (< its barrier
    energy), on ``n`` nodes uniform in J (node 0: the well bottom, where ``a_t = a_r = 1/(2
    omega(0))``).  A well whose first harmonic has a phase (an asymmetric well) gets its tables
    in the sheared phase, where the J-phase covariance vanishes as in a symmetric well.  ``noise_time``: tau of an
    Ornstein-Uhlenbeck force (0: white noise), whose spectral weights enter ``a_r`` and ``a_t``.
    Computed once per well and ``(xi_max, n, n_theta, noise_time)`` and then returned again (the
    same read-only tables; an unhashable well's are computed at every call)."""
    key = (float(xi_max), int(n), int(n_theta), float(noise_time))
    if type(well).__hash__ is None:
        return _tables(well, *key)
    kept = _TABLES.setdefault(well, OrderedDict())
    if key in kept:
        kept.move_to_end(key)
        return kept[key]
    out = _tables(well, *key)
    kept[key] = out
    if len(kept) > _KEPT:
        kept.popitem(last=False)
    return out


def _tables(well: Well, xi_max: float, n: int, n_theta: int, noise_time: float) -> AveragedDiffusion:
    """The tables of :func:`averaged_diffusion`, computed (read-only arrays)."""
    xi_nodes = _xi_nodes(well, xi_max, n)
    # a numeric well's phase is rounding (1e-16) where it is symmetric; an asymmetric well's is O(sqrt(xi))
    sheared = bool(np.any(np.abs(np.asarray(well.harmonic_shift(xi_nodes[1:]))) > SHIFT_TOL))
    av = orbit_averages(well, xi_nodes[1:], n_theta, noise_time, sheared=sheared)
    J = np.concatenate([[0.0], av["J"]])
    om = np.asarray(well.omega(xi_nodes), float)
    a_t = np.concatenate([[np.nan], 2.0 * av["J"] * av["m_gg"]])
    a_t[0] = 0.5 / om[0]
    a_r = 0.5 / om
    if noise_time > 0:
        # the spectrum at the orbit's harmonics; at the bottom the linear oscillator's one harmonic
        a_r = np.concatenate([[0.5 / om[0]], 0.5 * av["m_JJ"] / av["J"]])
        a_r[0] *= spectral_weights(1, om[0], noise_time)
        a_t[0] = a_r[0]
    a = np.empty_like(J)
    a[1:] = np.asarray(well.harmonic_amplitude(xi_nodes[1:]), float) / np.sqrt(2.0 * J[1:])
    a[0] = a[1] + (a[1] - a[2]) * J[1] / (J[2] - J[1])      # extrapolated in J (a is smooth there)
    tables = {"J_nodes": J, "H": xi_nodes, "omega": om, "a": a, "a_r": a_r, "a_t": a_t}
    if sheared:
        d_r = np.empty_like(J)
        d_r[1:] = J[1:] * om[1:] * shift_derivative(well, xi_nodes[1:]) / np.sqrt(2.0 * J[1:])
        d_r[0] = d_r[1] + (d_r[1] - d_r[2]) * J[1] / (J[2] - J[1])
        tables["d_r"] = d_r
    for v in tables.values():
        v.flags.writeable = False       # shared by every later call: no caller may change them
    return AveragedDiffusion(**tables)


def _xi_nodes(well: Well, xi_max: float, n: int) -> FloatArray:
    """Energies of ``n`` actions uniform on ``[0, J(xi_max)]`` (Newton on dJ/dxi = 1/omega from a
    dense table)."""
    grid = xi_max * np.linspace(0.0, 1.0, 4001) ** 2
    Jg = np.asarray(well.J(grid), float)
    Jn = np.linspace(0.0, Jg[-1], n)
    x = np.interp(Jn, Jg, grid)
    for _ in range(3):
        inner = (x > 0) & (x < xi_max)
        xs = np.where(inner, x, 0.5 * xi_max)
        x = np.where(inner, x - (np.asarray(well.J(xs)) - Jn) * np.asarray(well.omega(xs)), x)
        x = np.clip(x, 0.0, xi_max)
    x[0], x[-1] = 0.0, xi_max
    return x
