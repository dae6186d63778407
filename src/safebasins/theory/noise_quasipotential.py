"""Weak-noise limit of the averaged diffusion: the quasi-potential of the damped slow flow and its
Arrhenius law (docs/noise-theory.md, "The weak-noise limit").

In the regular frame ``x = (X, Y) = sqrt(2J) (cos phi, sin phi)`` (phi = gamma for a symmetric well,
the sheared ``gamma + delta(J)`` for an asymmetric one: docs/noise-theory.md) the averaged diffusion
(:mod:`safebasins.theory.noise_averaging`) is ``dx = b dt + sigma s dW`` with ``s s^T = A``,
``A = a_t I + c x x^T``, ``c = (a_r - a_t)/(2J)``; ``b`` is the damped slow flow
(:func:`safebasins.theory.damped.flow_tilde`; its O(sigma^2) noise-induced part changes only the
prefactor of the Arrhenius law).  The quasi-potential of an attractor x*,

    Phi(x) = inf over paths from x* to x of (1/2) int (x' - b)^T A^{-1} (x' - b) dt,

solves ``H(x, grad Phi) = 0`` with ``H = b.p + (1/2) p^T A p``; its characteristics
``x' = b + A p``, ``p' = -grad_x H`` carry ``Phi' = (1/2) p^T A p`` (each ray is a path, its Phi
that path's action: an upper bound of the infimum, reached by the minimising ray).  Rays start on
a small ellipse ``Phi = (1/2) dx^T Q dx`` around x* (``Q^{-1}`` solves the Lyapunov equation
``B S + S B^T + A(x*) = 0`` of the linearisation B) and are integrated with RK4 to the escape
circle ``J = J(xi_max)``; the parameter of the ellipse is refined around the best rays.

Exit set: escape is absorption at the circle.  From a saddle inside the disc the flow descends at
no cost along its unstable branches, so a saddle whose branch leaves the disc joins the circle
(cost Phi(saddle)), and one whose branches go to two attractors links them.  The mean first-passage
time from attractor k is ``T ~ C exp(barrier_k / sigma^2)``, barrier_k the exponent of the chain of
attractors with rates ``exp(-W / sigma^2)`` (one attractor: ``W(k -> circle)``).
"""
from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numba import literally
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline
from scipy.linalg import solve_continuous_lyapunov

from safebasins.core import checks
from safebasins.core.numba_target import package_jit
from safebasins.theory import damped
from safebasins.theory.damped import flow_tilde
from safebasins.theory.noise_averaging import AveragedDiffusion, averaged_diffusion
from safebasins.theory.responses import SADDLE, fixed_points
from safebasins.theory.types import FloatArray, WellArg
from safebasins.wells import resolve_well

__all__ = ["QuasiPotential", "quasi_potential", "attractor_barriers", "coefficient_table", "N_RAYS", "START",
           "STEP"]

#: rays of the first pass (per attractor), and of each refinement pass around a best ray
N_RAYS = 128
REFINE_RAYS = 24
REFINE_PASSES = 3
#: further passes (at most) while a saddle that sets a barrier is not yet reached by the rays
EXTRA_PASSES = 5
#: semi-major axis of the start ellipse over the escape radius sqrt(2 J_max)
START = 0.02
#: RK4 step times the largest rate of the linearised flow in the disc
STEP = 0.05
#: ray time limit in e-folding times of the slowest ray growth at the attractor, times ln(1/START)
SPAN = 8.0
#: a saddle counts as reached by the rays when the closest ray passes within this fraction of the
#: escape radius (Phi there is corrected to first order: error O(distance^2))
SADDLE_TOL = 2e-3
#: a ray stops where its Phi exceeds this many times the least exit Phi of its attractor's rays so far
PHI_CAP = 10.0
#: ... or its time this many times the earliest exit of those rays
TIME_CAP = 3
#: ... and one not reached is left out where Phi beside it exceeds the circle's by this fraction
SADDLE_MARGIN = 0.05
#: nodes of the coefficient table, uniform in J
TABLE_NODES = 4097
#: branch targets of a saddle: an attractor's index, or these
ESCAPE, UNDECIDED = -1, -2

_flow_tilde: Any = package_jit()(flow_tilde)     # the drift's one formula, compiled for the rays (scalars)
#: the numba literal of the cached ray kernels: a hash of the drift's module, so that a kernel
#: cached on disk (which holds the compiled drift) is never reused after an edit of it
_DRIFT_KEY = int(hashlib.blake2b(Path(damped.__file__).read_bytes(), digest_size=8).hexdigest()[:15], 16)


def coefficient_table(diff: AveragedDiffusion, n: int = TABLE_NODES) -> FloatArray:
    """Columns ``omega, omega', a, a', a'', a_t, a_t', c, c', d_r, d_r'`` (primes: d/dJ; ``a =
    A/sqrt(2J)``, ``c = (a_r - a_t)/(2J)``, ``d_r = d/sqrt(2J)`` the sheared phase's damping
    drift, 0 for a symmetric well) of an :class:`AveragedDiffusion` on ``n`` nodes uniform in
    ``[0, J_max]``, from one cubic spline of its tables (so the rays' derivatives are consistent)."""
    J = diff.J_nodes
    c = np.empty_like(J)
    c[1:] = (diff.a_r[1:] - diff.a_t[1:]) / (2.0 * J[1:])
    c[0] = c[1] + (c[1] - c[2]) * J[1] / (J[2] - J[1])       # smooth at J = 0: extrapolated
    d_r = np.zeros_like(J) if diff.d_r is None else diff.d_r
    sp = CubicSpline(J, np.stack([diff.omega, diff.a, diff.a_t, c, d_r], axis=1))
    Jn = np.linspace(0.0, diff.J_max, n)
    v, d1, d2 = sp(Jn), sp(Jn, 1), sp(Jn, 2)
    return np.ascontiguousarray(np.stack([v[:, 0], d1[:, 0], v[:, 1], d1[:, 1], d2[:, 1], v[:, 2], d1[:, 2],
                                          v[:, 3], d1[:, 3], v[:, 4], d1[:, 4]], axis=1))


@package_jit()
def _flow(tab, J_max, X, Y, F, Om, beta):  # type: ignore[no-untyped-def]
    """Drift (bX, bY), its Jacobian (dbX/dX, dbX/dY, dbY/dX, dbY/dY) and the diffusion's
    (a_t, c, a_t', c') at one point.  With ``g = omega - beta d - Omega``, ``e = a'``:
    ``bX = -(beta/2) X - g Y + F e X Y``, ``bY = g X - (beta/2) Y - F (a + e X^2)`` (d = 0 for a
    symmetric well; ``d ~ sqrt(2J)`` at the bottom, where ``g'`` ~ 1/sqrt(J) multiplies terms O(J))."""
    J = min(0.5 * (X * X + Y * Y), J_max)
    u = J / J_max * (tab.shape[0] - 1)
    i = min(int(u), tab.shape[0] - 2)
    f = u - i
    r = tab[i] + f * (tab[i + 1] - tab[i])
    om, om1, a, e, e1 = r[0], r[1], r[2], r[3], r[4]
    rr = math.sqrt(2.0 * J)
    d = r[9] * rr
    if rr > 0.0:
        om1 = om1 - beta * (r[10] * rr + r[9] / rr)         # dg/dJ
    bX, bY = _flow_tilde(X, Y, F, Om, beta, om, a, e, d)
    g = om - beta * d - Om
    jxx = -0.5 * beta - om1 * X * Y + F * (e1 * X * X * Y + e * Y)
    jxy = -g - om1 * Y * Y + F * (e1 * X * Y * Y + e * X)
    jyx = g + om1 * X * X - F * (3.0 * e * X + e1 * X * X * X)
    jyy = om1 * X * Y - 0.5 * beta - F * (e * Y + e1 * X * X * Y)
    return bX, bY, jxx, jxy, jyx, jyy, r[5], r[7], r[6], r[8]


@package_jit()
def _ray_rhs(tab, J_max, X, Y, pX, pY, F, Om, beta):  # type: ignore[no-untyped-def]
    """Characteristics of ``H = b.p + (1/2) p^T A p``, ``A = a_t I + c x x^T``."""
    bX, bY, jxx, jxy, jyx, jyy, at, c, at1, c1 = _flow(tab, J_max, X, Y, F, Om, beta)
    xp = X * pX + Y * pY
    ApX = at * pX + c * xp * X
    ApY = at * pY + c * xp * Y
    gk = at1 * (pX * pX + pY * pY) + c1 * xp * xp          # grad_x p^T A p = gk x + 2 c (x.p) p
    return (bX + ApX, bY + ApY, -(jxx * pX + jyx * pY) - 0.5 * gk * X - c * xp * pX,
            -(jxy * pX + jyy * pY) - 0.5 * gk * Y - c * xp * pY, 0.5 * (pX * ApX + pY * ApY))


@package_jit()
def _rk4_step(tab, J_max, F, Om, beta, X, Y, pX, pY, P, dt):  # type: ignore[no-untyped-def]
    """One RK4 step of the rays' equations."""
    h = 0.5 * dt
    a1, b1, c1, d1, e1 = _ray_rhs(tab, J_max, X, Y, pX, pY, F, Om, beta)
    a2, b2, c2, d2, e2 = _ray_rhs(tab, J_max, X + h * a1, Y + h * b1, pX + h * c1, pY + h * d1, F, Om, beta)
    a3, b3, c3, d3, e3 = _ray_rhs(tab, J_max, X + h * a2, Y + h * b2, pX + h * c2, pY + h * d2, F, Om, beta)
    a4, b4, c4, d4, e4 = _ray_rhs(tab, J_max, X + dt * a3, Y + dt * b3, pX + dt * c3, pY + dt * d3, F, Om, beta)
    w = dt / 6.0
    return (X + w * (a1 + 2.0 * a2 + 2.0 * a3 + a4), Y + w * (b1 + 2.0 * b2 + 2.0 * b3 + b4),
            pX + w * (c1 + 2.0 * c2 + 2.0 * c3 + c4), pY + w * (d1 + 2.0 * d2 + 2.0 * d3 + d4),
            P + w * (e1 + 2.0 * e2 + 2.0 * e3 + e4))


@package_jit(cache=True)
def _shoot(key, tab, J_max, F, Om, beta, s0, owner, points, dt, steps, stop_radius, exits, near_d,  # type: ignore[no-untyped-def]
           near_phi):
    """RK4 rays from the rows ``(X, Y, pX, pY, Phi)`` of s0 until ``J >= J_max`` (``exits[n]``: Phi,
    X, Y there, a partial step found by Newton's method on J; inf, nan, nan if not within
    ``steps``) and the closest step to each point (``near_d``, and ``near_phi``: Phi there plus
    ``p.(point - x)``).  A ray stops early (rays winding without end) where its Phi exceeds PHI_CAP
    times the least exit Phi of an earlier ray of the same owner or its time TIME_CAP times their
    earliest exit, or within ``stop_radius`` of a point (``key``: :data:`_DRIFT_KEY`)."""
    literally(key)
    best = np.full(owner.max() + 1, np.inf)
    first = np.full(owner.max() + 1, steps)
    for n in range(s0.shape[0]):
        cap = PHI_CAP * best[owner[n]]
        limit = min(steps, TIME_CAP * first[owner[n]])
        X, Y, pX, pY, P = s0[n, 0], s0[n, 1], s0[n, 2], s0[n, 3], s0[n, 4]
        exits[n, 0], exits[n, 1], exits[n, 2] = np.inf, np.nan, np.nan
        for j in range(points.shape[0]):
            near_d[j, n], near_phi[j, n] = np.inf, np.inf
        for k in range(limit):
            Xn, Yn, pXn, pYn, Pn = _rk4_step(tab, J_max, F, Om, beta, X, Y, pX, pY, P, dt)
            Jo, Jn = 0.5 * (X * X + Y * Y), 0.5 * (Xn * Xn + Yn * Yn)
            if Jn >= J_max:
                tau = dt * (J_max - Jo) / (Jn - Jo)
                for _ in range(4):          # Newton on J(tau) = J_max, dJ/dtau = x . x'
                    Xc, Yc, pXc, pYc, Pc = _rk4_step(tab, J_max, F, Om, beta, X, Y, pX, pY, P, tau)
                    dX, dY, _, _, _ = _ray_rhs(tab, J_max, Xc, Yc, pXc, pYc, F, Om, beta)
                    tau = min(max(tau - (0.5 * (Xc * Xc + Yc * Yc) - J_max) / (Xc * dX + Yc * dY), 0.0), dt)
                Xc, Yc, pXc, pYc, Pc = _rk4_step(tab, J_max, F, Om, beta, X, Y, pX, pY, P, tau)
                exits[n, 0], exits[n, 1], exits[n, 2] = Pc, Xc, Yc
                best[owner[n]] = min(best[owner[n]], Pc)
                first[owner[n]] = min(first[owner[n]], k + 1)
                break
            if Pn > cap:
                break
            X, Y, pX, pY, P = Xn, Yn, pXn, pYn, Pn
            caught = False
            for j in range(points.shape[0]):
                dx, dy = points[j, 0] - X, points[j, 1] - Y
                d = math.sqrt(dx * dx + dy * dy)
                if d < near_d[j, n]:
                    near_d[j, n] = d
                    near_phi[j, n] = P + pX * dx + pY * dy
                caught = caught or d < stop_radius
            if caught:
                break


@package_jit(cache=True)
def _flow_points(key, tab, J_max, xs, F, Om, beta):  # type: ignore[no-untyped-def]
    """:func:`_flow` at the rows of xs: (n, 10) (``key``: :data:`_DRIFT_KEY`)."""
    literally(key)
    out = np.empty((xs.shape[0], 10))
    for n in range(xs.shape[0]):
        out[n] = _flow(tab, J_max, xs[n, 0], xs[n, 1], F, Om, beta)
    return out


@dataclass(frozen=True)
class _Problem:
    tab: FloatArray
    J_max: float
    F: float
    Omega: float
    beta: float

    def flow(self, xs: FloatArray) -> FloatArray:
        xs = np.ascontiguousarray(xs, dtype=np.float64)
        out: FloatArray = _flow_points(_DRIFT_KEY, self.tab, self.J_max, xs, self.F, self.Omega, self.beta)
        return out

    def jacobian(self, x: FloatArray) -> FloatArray:
        r = self.flow(x[None, :])[0]
        return np.array([[r[2], r[3]], [r[4], r[5]]])

    def diffusion(self, x: FloatArray) -> FloatArray:
        """``A = a_t I + c x x^T`` at one point."""
        r = self.flow(x[None, :])[0]
        out: FloatArray = r[6] * np.eye(2) + r[7] * np.outer(x, x)
        return out

    def shoot(self, s0: FloatArray, owner: NDArray[np.intp], points: FloatArray, dt: float, steps: int,
              stop_radius: float = 0.0) -> tuple[FloatArray, FloatArray, FloatArray]:
        n, m = s0.shape[0], points.shape[0]
        exits, near_d, near_phi = np.empty((n, 3)), np.empty((m, n)), np.empty((m, n))
        _shoot(_DRIFT_KEY, self.tab, self.J_max, self.F, self.Omega, self.beta, np.ascontiguousarray(s0),
               np.ascontiguousarray(owner, dtype=np.intp), np.ascontiguousarray(points, dtype=np.float64).reshape(m, 2),
               dt, steps, stop_radius, exits, near_d, near_phi)
        return exits, near_d, near_phi


@dataclass(frozen=True)
class QuasiPotential:
    """The weak-noise limit of the averaged diffusion at one forcing (regular frame
    ``(X, Y) = sqrt(2J) (cos gamma, sin gamma)``; K attractors, S saddles inside the escape circle).

    ``attractors`` (K, 2), ``hessian`` (K, 2, 2): Q of ``Phi ~ (1/2) dx^T Q dx`` at each;
    ``saddles`` (S, 2) and ``saddle_targets`` (S, 2): where each saddle's two unstable branches go
    (an attractor's index, ESCAPE = -1: the circle); ``to_circle`` (K,): the least Phi of each
    attractor on the circle along its rays, at ``exit_point`` (K, 2); ``to_saddle`` (K, S): Phi of
    each attractor at each saddle (inf: not reached by its rays within ``SADDLE_TOL``; allowed only
    for a saddle that cannot set the barrier, else RuntimeError);
    ``barrier`` (K,): Delta Phi, the exponent of the mean first-passage time from each attractor,
    ``T ~ C exp(barrier / sigma^2)`` as sigma -> 0 (:func:`attractor_barriers`); ``exit_set`` (K,):
    what sets it for a single attractor ("circle" or "saddle <j>"), "chain" for two."""

    F: float
    Omega: float
    damping: float
    xi_max: float
    J_max: float
    attractors: FloatArray
    hessian: FloatArray
    saddles: FloatArray
    saddle_targets: NDArray[np.intp]
    to_circle: FloatArray
    exit_point: FloatArray
    to_saddle: FloatArray
    barrier: FloatArray
    exit_set: tuple[str, ...]


def attractor_barriers(to_circle: FloatArray, to_saddle: FloatArray, saddle_targets: NDArray[np.intp]
                       ) -> tuple[FloatArray, tuple[str, ...]]:
    """Arrhenius exponents of the mean first-passage times from each attractor, from the costs
    ``W(k -> circle)`` (the least of ``to_circle[k]`` and ``to_saddle[k, j]`` over saddles j with a
    branch to k and one leaving the disc) and ``W(k -> m)`` (``to_saddle[k, j]`` over saddles with
    branches to k and m).  One attractor: ``W(0 -> circle)``.  Two (A, R): the chain with rates
    ``a, c, r, d = exp(-(W_AR, W_AC, W_RA, W_RC) / sigma^2)`` has ``T_A = (r + d + a)/(a d + c r +
    c d)``, so ``barrier_A = min(W_AR + W_RC, W_AC + W_RA, W_AC + W_RC) - min(W_RA, W_RC, W_AR)``.
    More than two attractors: ValueError."""
    K = to_circle.size
    if K > 2:
        raise ValueError(f"F, Omega: {K} attractors inside the escape circle; the Arrhenius exponent is written for "
                         "one or two")
    W = np.full((K, K + 1), np.inf)            # column K: the circle
    W[:, K] = to_circle
    sets = ["circle"] * K
    for j, (t0, t1) in enumerate(saddle_targets):
        for k, other in ((t0, t1), (t1, t0)):
            if k < 0 or other == UNDECIDED:
                continue
            col = K if other == ESCAPE else int(other)
            if col != k and to_saddle[k, j] < W[k, col]:
                W[k, col] = to_saddle[k, j]
                if col == K:
                    sets[k] = f"saddle {j}"
    if K == 1:
        return W[:, 1].copy(), tuple(sets)
    out = np.empty(2)
    for A, R in ((0, 1), (1, 0)):
        w_ar, w_ac, w_ra, w_rc = W[A, R], W[A, 2], W[R, A], W[R, 2]
        if not np.isfinite(w_ar):
            out[A] = w_ac
        else:
            out[A] = min(w_ar + w_rc, w_ac + w_ra, w_ac + w_rc) - min(w_ra, w_rc, w_ar)
    return out, ("chain", "chain")


def quasi_potential(F: float, Omega: float, xi_max: float, *, damping: float, well: WellArg = None,
                    n_rays: int = N_RAYS, step: float = STEP, noise_time: float = 0.0) -> QuasiPotential:
    """Quasi-potential barriers of the averaged noisy slow flow (weak-noise limit).

    ``F, Omega, xi_max``: as :func:`~safebasins.theory.escape_probability`; ``damping``: beta > 0
    (the damped slow flow's attractors: the resonant and the non-resonant response, or the well
    bottom at F = 0); ``well``: any well (default the quartic; an asymmetric one in its sheared phase,
    like the fixed points); ``n_rays``: rays of the
    first pass per attractor (>= 16); ``step``: the RK4 step times the flow's largest rate
    (<= 0.5); ``noise_time``: tau of an Ornstein-Uhlenbeck force (0: white noise; the same tables as
    the backward equation's, :func:`~safebasins.theory.noise_averaging.averaged_diffusion`).
    Returns a :class:`QuasiPotential`: for each attractor inside the escape circle its barrier
    Delta Phi, with ``T ~ C exp(Delta Phi / sigma^2)`` (C absorbs the time unit) and
    ``P_escape(t) ~ 1 - exp(-t / T)`` once t exceeds the relaxation to the attractor.  At F = 0
    the barrier is ``2 beta xi_max`` (docs/noise-theory.md)."""
    w = resolve_well(well)
    f = checks.check_scalar("F", F, checks.check_nonnegative)
    Om = checks.check_scalar("Omega", Omega, checks.check_positive)
    xm = checks.check_scalar("xi_max", xi_max, w.check_analytic_threshold)
    beta = checks.check_positive_damping(damping, "the quasi-potential needs attractors of the damped slow flow")
    nr = checks.check_positive_int("n_rays", n_rays)
    if nr < 16:
        raise ValueError(f"n_rays must be >= 16, got {n_rays!r}")
    h = checks.check_scalar("step", step, checks.check_positive)
    if h > 0.5:
        raise ValueError(f"step must be <= 0.5 (RK4 step times the flow's largest rate), got {step!r}")
    tau = checks.check_scalar("noise_time", noise_time, checks.check_nonnegative)
    diff = averaged_diffusion(w, xm, noise_time=tau)
    fp = fixed_points(np.array([f]), np.array([Om]), beta, w, xm)
    stable = fp.attracting[0] & (fp.xi[0] < xm)
    saddle = (fp.kind[0] == SADDLE) & (fp.xi[0] < xm)
    if not stable.any():
        raise ValueError(f"F, Omega: the damped slow flow has no attractor below xi_max = {xm!r} (every slow "
                         "trajectory escapes; there is no weak-noise limit to take)")
    pb = _Problem(coefficient_table(diff), diff.J_max, f, Om, beta)
    atts = _newton(pb, np.stack([fp.Xt[0][stable], fp.Yt[0][stable]], axis=1))
    sads = _newton(pb, np.stack([fp.Xt[0][saddle], fp.Yt[0][saddle]], axis=1).reshape(-1, 2))
    return _solve(pb, atts, sads, xm, nr, h)


def _newton(pb: _Problem, x: FloatArray) -> FloatArray:
    """Equilibria of the tabulated drift, polished from those of the well's exact slow flow."""
    for _ in range(8):
        r = pb.flow(x)
        det = r[:, 2] * r[:, 5] - r[:, 3] * r[:, 4]
        x = x - np.stack([(r[:, 5] * r[:, 0] - r[:, 3] * r[:, 1]) / det,
                          (r[:, 2] * r[:, 1] - r[:, 4] * r[:, 0]) / det], axis=1)
    return x


def _rate(pb: _Problem, R: float) -> float:
    """The largest eigenvalue modulus of the drift's Jacobian on a polar sample of the disc."""
    r, g = np.meshgrid(R * np.linspace(0.0, 1.0, 17), np.linspace(0.0, 2.0 * np.pi, 33))
    jac = pb.flow(np.stack([(r * np.cos(g)).ravel(), (r * np.sin(g)).ravel()], axis=1))[:, 2:6]
    return float(np.abs(np.linalg.eigvals(jac.reshape(-1, 2, 2))).max())


def _branches(pb: _Problem, saddles: FloatArray, attractors: FloatArray, dt: float, steps: int, R: float
              ) -> NDArray[np.intp]:
    """Where the two unstable branches of each saddle go (attractor index, ESCAPE or UNDECIDED):
    rays with p = 0 are trajectories of the drift."""
    S = saddles.shape[0]
    if S == 0:
        return np.zeros((0, 2), np.intp)
    starts = []
    for x in saddles:
        lam, vec = np.linalg.eig(pb.jacobian(x))
        v = np.real(vec[:, int(np.argmax(lam.real))])
        starts += [x + 1e-4 * R * v, x - 1e-4 * R * v]
    s0 = np.zeros((2 * S, 5))
    s0[:, :2] = starts
    exits, near_d, _ = pb.shoot(s0, np.arange(2 * S), attractors, dt, steps, START * R)   # own caps
    flag = np.full(2 * S, UNDECIDED, np.intp)
    k = np.argmin(near_d, axis=0)
    caught = near_d[k, np.arange(2 * S)] < START * R
    flag[caught] = k[caught]
    flag[np.isfinite(exits[:, 0])] = ESCAPE
    return flag.reshape(S, 2)


def _unreached(targets: NDArray[np.intp], sad_d: FloatArray, sad_phi: FloatArray, best_c: FloatArray, R: float,
               K: int) -> list[tuple[int, int]]:
    """(attractor, saddle) pairs whose saddle the rays have not reached although it may set the
    attractor's barrier: an unreached saddle may be left out only where the rays' Phi beside it is
    well above the circle's (one attractor, the saddle's other branch escaping)."""
    out = []
    for j in range(targets.shape[0]):
        for k in targets[j][targets[j] >= 0]:
            irrelevant = K == 1 and ESCAPE in targets[j] and sad_phi[k, j] > (1.0 + SADDLE_MARGIN) * best_c[k]
            if sad_d[k, j] > SADDLE_TOL * R and not irrelevant:
                out.append((int(k), j))
    return out


def _solve(pb: _Problem, atts: FloatArray, sads: FloatArray, xm: float, n_rays: int, step: float) -> QuasiPotential:
    K, S = atts.shape[0], sads.shape[0]
    R = math.sqrt(2.0 * pb.J_max)
    dt = step / _rate(pb, R)
    Qs, frames, growth = [], [], []
    for x in atts:
        B, A0 = pb.jacobian(x), pb.diffusion(x)
        Q = np.linalg.inv(solve_continuous_lyapunov(B, -A0))
        Q = 0.5 * (Q + Q.T)
        lam, V = np.linalg.eigh(Q)
        frames.append(V / np.sqrt(lam) * (START * R * math.sqrt(lam[0])))    # semi-major axis START * R
        Qs.append(Q)
        growth.append(float(np.linalg.eigvals(B + A0 @ Q).real.min()))
    steps = int(math.ceil(SPAN * math.log(1.0 / START) / min(growth) / dt))

    def starts(k: int, s: FloatArray) -> FloatArray:
        dx = frames[k] @ np.stack([np.cos(s), np.sin(s)])
        p = Qs[k] @ dx
        return np.vstack([atts[k][:, None] + dx, p, 0.5 * np.einsum("in,in->n", dx, p)[None, :]]).T

    best_c, best_x, best_s = np.full(K, np.inf), np.full((K, 2), np.nan), np.zeros(K)
    sad_phi, sad_d, sad_s = np.full((K, S), np.inf), np.full((K, S), np.inf), np.zeros((K, S))
    params = [np.linspace(0.0, 2.0 * np.pi, n_rays, endpoint=False) for _ in range(K)]
    width = np.full(K, 2.0 * np.pi / n_rays)
    sad_width = np.full((K, S), 2.0 * np.pi / n_rays)
    ref = np.linspace(-1.0, 1.0, REFINE_RAYS)
    targets = _branches(pb, sads, atts, dt, 4 * steps, R)
    for j in range(S):
        if UNDECIDED in targets[j]:
            raise RuntimeError(f"a branch of saddle {j} neither escapes nor reaches an attractor within the time limit")
    passes = 0
    while passes <= REFINE_PASSES or (passes <= REFINE_PASSES + EXTRA_PASSES
                                      and _unreached(targets, sad_d, sad_phi, best_c, R, K)):
        passes += 1
        owner = np.concatenate([np.full(p.size, k) for k, p in enumerate(params)])
        s_all = np.concatenate(params)
        exits, near_d, near_phi = pb.shoot(np.concatenate([starts(k, p) for k, p in enumerate(params)]), owner,
                                           sads, dt, steps)
        exits[~np.isfinite(exits[:, 0]), 0] = np.inf          # a ray that went wrong is no exit
        near_phi[~np.isfinite(near_phi)] = np.inf
        near_d[~np.isfinite(near_phi)] = np.inf
        params = []
        for k in range(K):
            mine = owner == k
            ex = exits[mine]
            i = int(np.argmin(ex[:, 0]))
            if ex[i, 0] < best_c[k]:
                best_c[k], best_x[k], best_s[k] = ex[i, 0], ex[i, 1:], s_all[mine][i]
            nxt = [best_s[k] + width[k] * ref]
            for j in range(S):
                d, ph = near_d[j, mine], near_phi[j, mine]
                i = int(np.argmin(d))
                if d[i] < sad_d[k, j]:
                    sad_d[k, j], sad_phi[k, j], sad_s[k, j] = d[i], ph[i], s_all[mine][i]
                nxt.append(sad_s[k, j] + sad_width[k, j] * ref)
            sad_width[k] *= 2.0 / (REFINE_RAYS - 1)
            width[k] *= 2.0 / (REFINE_RAYS - 1)
            params.append(np.concatenate(nxt))
    reached = sad_d <= SADDLE_TOL * R
    missed = _unreached(targets, sad_d, sad_phi, best_c, R, K)
    if missed:
        k, j = missed[0]
        raise RuntimeError(f"the rays of attractor {k} pass saddle {j} no closer than "
                           f"{sad_d[k, j] / R:.2g} of the escape radius; raise n_rays")
    to_saddle = np.where(reached, sad_phi, np.inf)
    barrier, sets = attractor_barriers(best_c, to_saddle, targets)
    if not np.isfinite(barrier).all():
        lost = np.nonzero(~np.isfinite(barrier))[0].tolist()
        raise RuntimeError(f"no ray of the attractors {lost} reached the escape circle within the time limit")
    return QuasiPotential(F=pb.F, Omega=pb.Omega, damping=pb.beta, xi_max=xm, J_max=pb.J_max, attractors=atts,
                          hessian=np.array(Qs), saddles=sads, saddle_targets=targets, to_circle=best_c,
                          exit_point=best_x, to_saddle=to_saddle, barrier=barrier, exit_set=sets)
