"""Periodic orbits of the forced equation by DOP853 shooting, and their Floquet multipliers.

    q' = p,   p' = -V'(q) - beta p + F sin(Omega t + Psi)

The stroboscopic (period) map ``P(x) = phi_{0 -> T}(x)`` (``T = 2 pi / Omega``, the section
``t = 0`` of forcing phase ``Psi``) is integrated here with scipy's DOP853, every trajectory of
one call in one system: one step sequence for all of them, so finite differences of the flow
are smooth in the initial condition and a central-difference Jacobian keeps ~9 digits.  Not the
compiled engine: its escape criteria stop every trajectory beyond a barrier (the hilltop
saddle's orbit straddles the barrier), it has no backward map, and a fixed point of its
fixed-step map is one of the scheme's, ``O(h^4)`` off the true one; at ``rtol`` 1e-11 to 1e-12
a fixed point found here is one of the true map to ~1e-11.

* :func:`forced_flow`: the flow of many initial conditions, forward or backward in time;
* :func:`periodic_orbit`: the T-periodic orbit by multiple shooting (``m`` nodes ``x_j`` at
  ``t_j = j T / m``, Newton on ``phi_{t_j -> t_{j+1}}(x_j) = x_{j+1}`` cyclically, central-difference
  blocks).  ``m = 1`` is Newton on the stroboscopic map; a saddle with ``lambda T`` large needs
  ``lambda T / m <= 1`` (single shooting would amplify every error by ``e^{lambda T}``).  Its
  monodromy matrix (the product of the blocks) gives the Floquet multipliers;
* :func:`linear_response`: the periodic response of ``xi'' + beta xi' + k xi = F sin(Omega t + Psi)``,
  the first guess near an equilibrium ``q_e`` of V (``k = V''(q_e)``);
* :func:`saddle_orbit`: the forced hilltop saddle's hyperbolic orbit near a barrier and its
  Floquet directions (:mod:`safebasins.analysis.saddle`).
"""
from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.integrate import solve_ivp

from safebasins.wells.base import Well

__all__ = ["forced_flow", "periodic_orbit", "PeriodicOrbit", "linear_response", "stiffness", "saddle_orbit",
           "shooting_step"]

Array = npt.NDArray[np.float64]
Box = tuple[tuple[float, float], tuple[float, float]]

#: relative step of the central difference of V' that gives V'' (stiffness)
_CURVATURE_STEP = 1e-4
#: the layer outside a box over which the field is switched off (forced_flow), of the box's width
_BOX_LAYER = 0.1


def _field(well: Well, F: float | Array, Omega: float, damping: float, phase: Array,
           n: int) -> Callable[[float, Array], Array]:
    def fun(tau: float, y: Array) -> Array:
        q, p = y[:n], y[n:]
        return np.concatenate([p, -np.asarray(well.dV(q), dtype=float) - damping * p
                               + F * np.sin(Omega * tau + phase)])
    return fun


def _boxed(free: Callable[[float, Array], Array], box: Box, n: int) -> Callable[[float, Array], Array]:
    """``free`` scaled by ``exp(-d^4)`` outside ``box`` (forced_flow)."""
    (q_lo, q_hi), (p_lo, p_hi) = box
    dq, dp = _BOX_LAYER * (q_hi - q_lo), _BOX_LAYER * (p_hi - p_lo)
    centre = np.full(n, 0.5 * (q_lo + q_hi))

    def fun(tau: float, y: Array) -> Array:
        q, p = y[:n], y[n:]
        d = np.maximum(np.maximum(q_lo - q, q - q_hi) / dq, np.maximum(p_lo - p, p - p_hi) / dp)
        c = np.exp(-np.maximum(d, 0.0) ** 4)
        far = c == 0.0
        if far.any():                       # frozen: V' is not evaluated out there
            y = np.where(np.concatenate([far, far]), np.concatenate([centre, np.zeros(n)]), y)
        return np.concatenate([c, c]) * free(tau, y)
    return fun


def forced_flow(well: Well, F: float | Array, Omega: float, damping: float, phase: Array, y0: Array,
                tau_end: float, rtol: float, box: Box | None = None) -> Array:
    """DOP853 of ``q' = p, p' = -V'(q) - damping p + F sin(Omega tau + phase_k)`` for the columns of
    ``y0`` (2, N) over local times ``tau`` in ``[0, tau_end]`` (``tau_end < 0``: backward); ``phase``
    (N,) is each trajectory's forcing phase at ``tau = 0``, ``F`` a scalar or one value per column.
    ``box`` ((q_lo, q_hi), (p_lo, p_hi)): outside it the field is scaled by ``exp(-d^4)`` (``d`` the
    distance beyond the box in units of ``0.1`` of its width; smooth, so the common step is not cut
    down), so that a trajectory leaving a well open to infinity slows to a halt instead of blowing
    up; its end state then lies outside the box (and means nothing else).  Returns the states at
    ``tau_end`` (2, N).  ValueError naming ``F`` when the integration fails."""
    sol = _solve(well, F, Omega, damping, phase, y0, tau_end, rtol, box, dense=False)
    return np.asarray(sol.y[:, -1], dtype=float).reshape(2, y0.shape[1])


def forced_flow_dense(well: Well, F: float, Omega: float, damping: float, phase: Array, y0: Array,
                      tau_end: float, rtol: float) -> Callable[[Array], Array]:
    """:func:`forced_flow`'s dense output: ``tau`` (k,) -> states (2, N, k)."""
    sol = _solve(well, F, Omega, damping, phase, y0, tau_end, rtol, None, dense=True)
    n = y0.shape[1]
    return lambda tau: np.asarray(sol.sol(tau), dtype=float).reshape(2, n, -1)


def _solve(well: Well, F: float | Array, Omega: float, damping: float, phase: Array, y0: Array,
           tau_end: float, rtol: float, box: Box | None, dense: bool) -> Any:
    n = y0.shape[1]
    fun = _field(well, F, Omega, damping, phase, n)
    if box is not None:
        fun = _boxed(fun, box, n)
    sol = solve_ivp(fun, (0.0, tau_end), y0.ravel(), method="DOP853", rtol=rtol, atol=rtol * 1e-2,
                    dense_output=dense)
    if sol.status != 0:
        raise ValueError(f"F: the forced flow could not be integrated ({sol.message})")
    return sol


def stiffness(well: Well, q: float) -> float:
    """``V''(q)`` by a central difference of ``V'`` (step ``1e-4 max(1, |q|)``)."""
    dq = _CURVATURE_STEP * max(1.0, abs(q))
    dV_pm = np.asarray(well.dV(np.array([q + dq, q - dq])), dtype=float)
    return float(dV_pm[0] - dV_pm[1]) / (2 * dq)


def linear_response(F: float, Omega: float, damping: float, Psi: float, k: float, t: npt.ArrayLike,
                    q_e: float = 0.0) -> Array:
    """States (2, len(t)) of the T-periodic response ``q = q_e + xi`` of
    ``xi'' + damping xi' + k xi = F sin(Omega t + Psi)``: ``xi = Im(a e^{i (Omega t + Psi)})``,
    ``a = F / (k - Omega^2 + i damping Omega)`` (``k < 0``: a saddle, ``k > 0``: a well bottom)."""
    a = F / (-Omega ** 2 + k + 1j * damping * Omega)
    z = a * np.exp(1j * (Omega * np.asarray(t, dtype=float) + Psi))
    return np.stack([q_e + z.imag, Omega * z.real], axis=0)


@dataclasses.dataclass(frozen=True)
class PeriodicOrbit:
    """A T-periodic orbit of the forced equation found by :func:`periodic_orbit`.

    ``nodes`` (2, m): the states at ``times`` ``t_j = j T / m`` (``nodes[:, 0]`` is the fixed point
    of the stroboscopic map of phase ``Psi``); ``monodromy`` (2, 2): ``D P`` at it;
    ``multipliers`` (2,) complex and ``vectors`` (2, 2) (columns) its eigen-pairs, larger
    modulus first; ``residual``: the largest ``|phi(x_j) - x_{j+1}|`` at the last Newton step
    (before its correction); ``converged``: Newton met its tolerance."""
    nodes: Array
    times: Array
    period: float
    monodromy: Array
    multipliers: npt.NDArray[np.complex128]
    vectors: npt.NDArray[np.complex128]
    residual: float
    iterations: int
    converged: bool

    @property
    def point(self) -> Array:
        """The fixed point of the stroboscopic map (the node at ``t = 0``)."""
        return self.nodes[:, 0]

    @property
    def stable(self) -> bool:
        """Every Floquet multiplier inside the unit circle (an attractor)."""
        return bool(np.max(np.abs(self.multipliers)) < 1.0)

    def saddle_directions(self) -> tuple[tuple[float, Array], tuple[float, Array]] | None:
        """``((mu_u, e_u), (mu_s, e_s))``: the real multipliers ``|mu_u| > 1 > |mu_s|`` of a
        hyperbolic saddle and their unit eigenvectors at ``t = 0``; None if it is not one."""
        mu, vec = self.multipliers, self.vectors
        if np.any(np.abs(np.imag(mu)) > 0) or not (np.max(np.abs(mu)) > 1 > np.min(np.abs(mu))):
            return None
        mu_r, vec_r = np.real(mu), np.real(vec)
        iu, is_ = int(np.argmax(np.abs(mu_r))), int(np.argmin(np.abs(mu_r)))
        return (float(mu_r[iu]), vec_r[:, iu]), (float(mu_r[is_]), vec_r[:, is_])


def shooting_step(well: Well, F: float, Omega: float, damping: float, Psi: float, X: Array, t: Array, T: float,
                  rtol: float, h: float) -> tuple[Array, Array]:
    """The blocks ``D phi`` (2, 2, m) and the mismatches ``phi(x_j) - x_{j+1}`` (2, m) at the nodes X."""
    m = X.shape[1]
    E = np.eye(2)
    Y0 = np.concatenate([X, X + h * E[0][:, None], X - h * E[0][:, None], X + h * E[1][:, None],
                         X - h * E[1][:, None]], axis=1)
    Y = forced_flow(well, F, Omega, damping, np.tile(Omega * t + Psi, 5), Y0, T / m, rtol).reshape(2, 5, m)
    D = np.stack([(Y[:, 1] - Y[:, 2]) / (2 * h), (Y[:, 3] - Y[:, 4]) / (2 * h)], axis=1)
    return D, Y[:, 0] - np.roll(X, -1, axis=1)


def periodic_orbit(well: Well, F: float, Omega: float, damping: float, Psi: float, X: npt.ArrayLike, *,
                   rtol: float = 1e-11, h: float = 1e-7, tol: float | None = None,
                   max_iter: int = 40) -> PeriodicOrbit:
    """Multiple shooting for the T-periodic orbit from the guess ``X`` (2, m) at ``t_j = j T / m``
    (module docstring); ``tol``: Newton stops once its correction is below it (default
    ``1e-12 max(1, max |X|)``).  Returns a :class:`PeriodicOrbit` (``converged`` False and NaN
    nodes when Newton fails or leaves the domain)."""
    Xa: Array = np.array(X, dtype=float, copy=True).reshape(2, -1)
    m = Xa.shape[1]
    T = 2.0 * np.pi / Omega
    t = T * np.arange(m) / m
    if tol is None:
        tol = 1e-12 * max(1.0, float(np.max(np.abs(Xa))))
    E = np.eye(2)
    D = np.full((2, 2, m), np.nan)
    res, n_iter, ok = np.nan, 0, False
    for _ in range(max_iter):
        n_iter += 1
        try:
            D, r = shooting_step(well, F, Omega, damping, Psi, Xa, t, T, rtol, h)
        except ValueError:
            break
        res = float(np.max(np.abs(r)))
        J = np.zeros((2 * m, 2 * m))
        for j in range(m):
            J[2 * j:2 * j + 2, 2 * j:2 * j + 2] = D[:, :, j]
            k = (j + 1) % m
            J[2 * j:2 * j + 2, 2 * k:2 * k + 2] -= E
        try:
            dx = np.linalg.solve(J, -r.T.ravel()).reshape(m, 2).T
        except np.linalg.LinAlgError:
            break
        Xa = Xa + dx
        if not np.isfinite(Xa).all():
            break
        if np.max(np.abs(dx)) <= tol:
            ok = True
            break
    if not ok:
        Xa = Xa + np.nan
    P = E
    for j in range(m):
        P = D[:, :, j] @ P
    if np.isfinite(P).all():
        mu, vec = np.linalg.eig(P)
        order = np.argsort(-np.abs(mu), kind="stable")
        mu, vec = mu[order].astype(complex), vec[:, order].astype(complex)
    else:
        mu, vec = np.full(2, np.nan + 0j), np.full((2, 2), np.nan + 0j)
    return PeriodicOrbit(nodes=Xa, times=t, period=T, monodromy=P, multipliers=mu, vectors=vec, residual=res,
                         iterations=n_iter, converged=ok)


def saddle_orbit(well: Well, F: float, Omega: float, damping: float, Psi: float, q_b: float, rtol: float,
                 h: float = 1e-7) -> PeriodicOrbit:
    """The forced saddle's hyperbolic T-periodic orbit near ``(q_b, 0)`` (a local maximum of V):
    multiple shooting with ``m = ceil(sqrt(-V''(q_b)) T)`` nodes (``lambda T / m <= 1``), started
    from :func:`linear_response` about ``q_b``.  ValueError naming ``well`` when ``q_b`` is not a
    hyperbolic saddle, naming ``F`` when Newton does not converge (F too large for a continuation
    of the hilltop) or the orbit is not a saddle (:meth:`PeriodicOrbit.saddle_directions`)."""
    T = 2.0 * np.pi / Omega
    kappa = -stiffness(well, q_b)
    if not kappa > 0:
        raise ValueError(f"well: the barrier at q = {q_b!r} is not a hyperbolic saddle (V'' = {-kappa!r})")
    m = int(np.ceil(np.sqrt(kappa) * T))
    X = linear_response(F, Omega, damping, Psi, -kappa, T * np.arange(m) / m, q_e=q_b)
    orbit = periodic_orbit(well, F, Omega, damping, Psi, X, rtol=rtol, h=h, tol=1e-12 * max(1.0, abs(q_b)))
    if not orbit.converged:
        raise ValueError(f"F = {F!r}: no hyperbolic periodic orbit of the forced saddle near q = {q_b!r} (Newton did "
                         "not converge: F too large for a continuation of the hilltop)")
    if orbit.saddle_directions() is None:
        raise ValueError(f"F = {F!r}: the periodic orbit near q = {q_b!r} is not a saddle (multipliers "
                         f"{orbit.multipliers})")
    return orbit
