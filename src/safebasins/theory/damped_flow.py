"""Where does a slow trajectory of the damped slow flow go: over xi_max or onto an attractor?

For beta > 0 the flow contracts area (divergence -beta in (gamma, J), i.e. in the Cartesian frame
of :mod:`safebasins.theory.damped`, where the well bottom is a regular point), so it has no
periodic orbit and no cycle of separatrices: every trajectory that stays below xi_max converges to
a fixed point.  A trajectory is decided (docs/damping.md) when

* **escaped**: its action reaches ``J(xi_max)`` (checked between steps on the cubic Hermite
  interpolant of J(t), so that a tangency inside a step is not stepped over);
* **settled**, by one of two certificates that it can never reach xi_max:

  - it enters a *trapping ellipse* of an attracting fixed point: a level set ``V = c`` of the
    Lyapunov function ``V = d^T P d`` of the linearisation (``M^T P + P M = -I``), c the largest
    level (log bisection) on whose boundary the true flow satisfies ``V' <= -|d|^2 / 2`` at 64
    sampled points and that lies inside ``xi < xi_max`` -- fast for strong damping;
  - it closes a *trapping loop*: two consecutive crossings of a ray from an attracting fixed
    point (the pivot), in the same direction, the second nearer the pivot, with the flow crossing
    the segment between them in that direction (checked at 9 points).  The loop (trajectory arc +
    segment) is then a Jordan curve below xi_max whose inside the flow cannot leave -- fast for
    weak damping, where the ellipse is small but the trajectory winds round the pivot;

* **undecided**: neither within ``t_max`` (or ``max_steps``): never guessed, reported.

The batch integrator advances all trajectories at once (vectorised Dormand-Prince 5(4) with a
step per lane, on the tabulated flow :class:`~safebasins.theory.damped.SlowTables`), each lane
with its own (F, Omega) and its own fixed points.  Times are slow-flow times in tau.
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from safebasins.theory.damped import SlowTables
from safebasins.theory.responses import FixedPoints, fixed_points
from safebasins.theory.types import BoolArray, FloatArray

__all__ = ["STATUS", "SETTLED", "ESCAPED", "UNDECIDED", "Pivots", "pivots", "integrate_batch", "default_t_max"]

STATUS = ("settled", "escaped", "undecided")
SETTLED, ESCAPED, UNDECIDED = 0, 1, 2

_C = (1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0)
_A = ((1 / 5,), (3 / 40, 9 / 40), (44 / 45, -56 / 15, 32 / 9),
      (19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729),
      (9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656),
      (35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84))
_E = (71 / 57600, 0.0, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40)


class Pivots:
    """Attracting fixed points below xi_max per parameter pair (P, K arrays, ``valid`` marks real
    entries): position ``(x, y)`` (sheared Cartesian frame), the ray direction ``(ux, uy)`` (towards
    the well bottom), the Lyapunov matrix ``(p11, p12, p22)`` and the trapping-ellipse level ``c``
    (0: none); ``t_scale``: per pair, 2 pi over the slowest eigenvalue modulus of any fixed point
    below xi_max; ``fp``: the :class:`~safebasins.theory.responses.FixedPoints`."""

    fp: FixedPoints
    valid: BoolArray
    x: FloatArray
    y: FloatArray
    index: NDArray[np.intp]
    ux: FloatArray
    uy: FloatArray
    p11: FloatArray
    p12: FloatArray
    p22: FloatArray
    c: FloatArray
    t_scale: FloatArray


def _lyapunov(M: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """P with ``M^T P + P M = -I`` for stacked 2x2 M: ``(p11, p12, p22)``."""
    m11, m12, m21, m22 = M[:, 0, 0], M[:, 0, 1], M[:, 1, 0], M[:, 1, 1]
    z = np.zeros_like(m11)
    A = np.stack([np.stack([2 * m11, 2 * m21, z], -1), np.stack([m12, m11 + m22, m21], -1),
                  np.stack([z, 2 * m12, 2 * m22], -1)], -2)
    b = np.broadcast_to(np.array([-1.0, 0.0, -1.0]), m11.shape + (3,))
    p = np.linalg.solve(A, b[..., None])[..., 0]
    return p[:, 0], p[:, 1], p[:, 2]


def _ellipse_levels(tab: SlowTables, x: FloatArray, y: FloatArray, M: FloatArray, F: FloatArray, Om: FloatArray,
                    beta: float, r_max: float, n_ang: int = 64,
                    n_iter: int = 14) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Trapping-ellipse levels c (0 where none) and Lyapunov matrices for stable fixed points."""
    p11, p12, p22 = _lyapunov(M)
    l11 = np.sqrt(p11)
    l21 = p12 / l11
    l22 = np.sqrt(np.maximum(p22 - l21 * l21, 0.0))
    good = np.isfinite(l11) & np.isfinite(l22) & (l22 > 0) & (p11 > 0)
    l11, l21, l22 = (np.where(good, v, 1.0) for v in (l11, l21, l22))
    B = np.stack([np.stack([1 / l11, -l21 / (l11 * l22)], -1), np.stack([np.zeros_like(l11), 1 / l22], -1)], -2)
    smax = np.linalg.norm(B, ord=2, axis=(-2, -1))
    room = r_max - np.hypot(x, y)
    c_max = np.where(good & (room > 0), (0.999 * room / smax) ** 2, 0.0)
    t = np.linspace(0.0, 2 * np.pi, n_ang, endpoint=False)
    circ = np.stack([np.cos(t), np.sin(t)])

    def inward(c: FloatArray) -> BoolArray:
        d = np.sqrt(c)[:, None, None] * (B @ circ)              # (m, 2, n_ang)
        dx, dy = d[:, 0], d[:, 1]
        fx, fy = tab.rhs(x[:, None] + dx, y[:, None] + dy, F[:, None], Om[:, None], beta)
        dV = 2 * (dx * (p11[:, None] * fx + p12[:, None] * fy) + dy * (p12[:, None] * fx + p22[:, None] * fy))
        out: BoolArray = np.all(dV <= -0.5 * (dx * dx + dy * dy), axis=1)
        return out

    hi = np.log(np.maximum(c_max, 1e-300))
    lo = hi - 30.0
    ok_hi = inward(np.exp(hi)) & (c_max > 0)
    ok_lo = inward(np.exp(lo)) & (c_max > 0)
    for _ in range(n_iter):
        mid = 0.5 * (lo + hi)
        ok = inward(np.exp(mid))
        lo = np.where(ok, mid, lo)
        hi = np.where(ok, hi, mid)
    c = np.where(ok_hi, c_max, np.where(ok_lo, np.exp(lo), 0.0))
    return c, p11, p12, p22


def pivots(tab: SlowTables, F: FloatArray, Om: FloatArray, beta: float, xi_max: float, n_grid: int = 1200) -> Pivots:
    """:class:`Pivots` for parameter pairs (F, Omega) (1-D arrays) below xi_max."""
    fp = fixed_points(F, Om, beta, tab.well, xi_max, n_grid=n_grid)
    below = fp.converged & (fp.xi < xi_max)
    att = fp.attracting & below
    P = F.size
    K = max(1, int(att.sum(axis=1).max()) if P else 1)
    pv = Pivots()
    pv.fp = fp
    order = np.argsort(~att, axis=1, kind="stable")[:, :K]
    take: Callable[[NDArray[Any]], NDArray[Any]] = lambda a: np.take_along_axis(a, order, axis=1)
    pv.valid = take(att)
    pv.x = np.where(pv.valid, take(fp.Xt), 0.0)
    pv.y = np.where(pv.valid, take(fp.Yt), 0.0)
    pv.index = np.where(pv.valid, order, -1)
    rad = np.hypot(pv.x, pv.y)
    far = rad > 1e-12
    pv.ux = np.where(far, -pv.x / np.where(far, rad, 1.0), 1.0)
    pv.uy = np.where(far, -pv.y / np.where(far, rad, 1.0), 0.0)
    for name in ("p11", "p12", "p22", "c"):
        setattr(pv, name, np.zeros((P, K)))
    r_max = np.sqrt(2.0 * float(tab.well.J(np.asarray(xi_max))))
    if beta > 0:
        r, k = np.nonzero(pv.valid)
        if r.size:
            M = np.take_along_axis(fp.M, order[..., None, None], axis=1)[r, k]
            c, p11, p12, p22 = _ellipse_levels(tab, pv.x[r, k], pv.y[r, k], M, F[r], Om[r], beta, r_max)
            pv.c[r, k], pv.p11[r, k], pv.p12[r, k], pv.p22[r, k] = c, p11, p12, p22
    lam = np.abs(fp.eig)
    lam = np.where(below[..., None] & (lam > 0), lam, -np.inf).max(axis=2)      # fastest rate per point
    lam = np.where(np.isfinite(lam), lam, np.inf).min(axis=1)                    # slowest point per pair
    w0 = float(tab.lookup(np.zeros(1))[0][0])                                    # omega at the bottom
    fallback = 2 * np.pi / np.maximum(np.abs(w0 - Om), 1e-3)
    pv.t_scale = np.where(np.isfinite(lam) & (lam > 0), 2 * np.pi / np.where(lam > 0, lam, 1.0), fallback)
    return pv


def default_t_max(pv: Pivots, beta: float) -> FloatArray:
    """The generous slow-time horizon per pair: 200 slow periods (t_scale) and at least 60/beta,
    capped at 1e6."""
    return np.minimum(np.maximum(200.0 * pv.t_scale, 60.0 / beta), 1e6)


def _hermite_max(J0: FloatArray, J1: FloatArray, m0: FloatArray, m1: FloatArray) -> FloatArray:
    """Maximum over the step of the cubic Hermite interpolant of J (values J0, J1, slopes*h m0, m1)."""
    a = 6 * J0 + 3 * m0 - 6 * J1 + 3 * m1
    b = -6 * J0 - 4 * m0 + 6 * J1 - 2 * m1
    c = m0
    best = np.maximum(J0, J1)
    disc = b * b - 4 * a * c
    sq = np.sqrt(np.maximum(disc, 0.0))
    # a root of a (nearly) degenerate quadratic is inf, NaN or huge: it lies outside (0, 1) and is
    # dropped before the cubic is evaluated there (no overflow)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        roots = ((-b + sq) / (2 * a), (-b - sq) / (2 * a), -c / b)
    for tau in roots:
        ok = (disc >= 0) & (tau > 0) & (tau < 1)
        tau = np.where(ok, tau, 0.0)
        p = ((2 * tau ** 3 - 3 * tau ** 2 + 1) * J0 + (tau ** 3 - 2 * tau ** 2 + tau) * m0
             + (-2 * tau ** 3 + 3 * tau ** 2) * J1 + (tau ** 3 - tau ** 2) * m1)
        best = np.where(ok & np.isfinite(p), np.maximum(best, p), best)
    return best


def _hermite_crossing(x0: FloatArray, y0: FloatArray, x1: FloatArray, y1: FloatArray, mx0: FloatArray,
                      my0: FloatArray, mx1: FloatArray, my1: FloatArray, px: FloatArray, py: FloatArray,
                      ux: FloatArray, uy: FloatArray, n_iter: int = 40) -> tuple[FloatArray, FloatArray]:
    """Where the cubic Hermite interpolant of a step (ends (x0, y0), (x1, y1), slopes*h m) crosses the
    line through (px, py) along (ux, uy) (its cross product changes sign over the step): bisection on
    the interpolant (error O(h^5) instead of the chord's O(h^2), which could fake or hide the
    decrease of a slowly contracting spiral)."""
    def point(s: FloatArray) -> tuple[FloatArray, FloatArray]:
        h00, h10 = 2 * s ** 3 - 3 * s ** 2 + 1, s ** 3 - 2 * s ** 2 + s
        h01, h11 = -2 * s ** 3 + 3 * s ** 2, s ** 3 - s ** 2
        return h00 * x0 + h10 * mx0 + h01 * x1 + h11 * mx1, h00 * y0 + h10 * my0 + h01 * y1 + h11 * my1

    def cross(s: FloatArray) -> FloatArray:
        x, y = point(s)
        return ux * (y - py) - uy * (x - px)

    lo, hi = np.zeros_like(x0), np.ones_like(x0)
    pos_lo = cross(lo) > 0
    for _ in range(n_iter):
        mid = 0.5 * (lo + hi)
        same = (cross(mid) > 0) == pos_lo
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
    return point(0.5 * (lo + hi))


def integrate_batch(tab: SlowTables, X0: FloatArray, Y0: FloatArray, F: FloatArray, Om: FloatArray, beta: float,
                    xi_max: float, pv: Pivots, pair: NDArray[np.intp], t_max: FloatArray, tol: float = 1e-8,
                    max_steps: int = 200000) -> tuple[NDArray[np.int8], FloatArray, NDArray[np.int64], int]:
    """Decide trajectories of the damped slow flow (beta > 0) from (X0, Y0) (sheared frame).

    ``F``, ``Om``: per pair; ``pair``: each lane's pair index into F, Om and the :class:`Pivots`
    ``pv``; ``t_max``: per pair.  Returns ``(status, t_end, attractor, steps)``: status codes
    :data:`STATUS`, the time of the decision (t_max for undecided), the index of the settling
    fixed point in ``pv.fp`` (-1 when escaped or undecided) and the number of accepted steps.
    """
    n = X0.size
    status = np.full(n, UNDECIDED, np.int8)
    t_end = np.zeros(n)
    attractor = np.full(n, -1, np.int64)
    J_max = float(tab.well.J(np.asarray(xi_max)))
    r_max = np.sqrt(2.0 * J_max)
    atol = tol * r_max
    lane = np.arange(n)
    X, Y = X0.astype(float).copy(), Y0.astype(float).copy()
    start_out = 0.5 * (X * X + Y * Y) >= J_max
    status[start_out] = ESCAPED
    keep = ~start_out
    lane, X, Y = lane[keep], X[keep], Y[keep]
    pr = pair[lane]
    Fl, Ol, Tl = F[pr], Om[pr], t_max[pr]
    px, py, ux, uy = pv.x[pr], pv.y[pr], pv.ux[pr], pv.uy[pr]
    p11, p12, p22, cl, valid, idx = pv.p11[pr], pv.p12[pr], pv.p22[pr], pv.c[pr], pv.valid[pr], pv.index[pr]
    K = px.shape[1]
    t = np.zeros(lane.size)
    last_rho = np.full((lane.size, K), np.nan)
    last_dir = np.zeros((lane.size, K), np.int8)
    k1 = tab.rhs(X, Y, Fl, Ol, beta)
    speed = np.hypot(*k1)
    h = np.minimum(0.05 * r_max / np.maximum(speed, 1e-300), Tl)
    steps = 0
    for _ in range(max_steps):
        if lane.size == 0:
            break
        # ---- step cap: move at most a quarter of the distance to the nearest pivot per step
        dist = np.where(valid, np.hypot(X[:, None] - px, Y[:, None] - py), np.inf).min(axis=1)
        cap = 0.25 * np.minimum(np.maximum(dist, 1e-3 * r_max), r_max) / np.maximum(np.hypot(*k1), 1e-300)
        h = np.minimum(np.minimum(h, cap), np.maximum(Tl - t, 1e-12))
        ks = [k1]
        for a_row, _c in zip(_A[:5], _C):
            xs = X + h * sum(a * k[0] for a, k in zip(a_row, ks))
            ys = Y + h * sum(a * k[1] for a, k in zip(a_row, ks))
            ks.append(tab.rhs(xs, ys, Fl, Ol, beta))
        Xn = X + h * sum(a * k[0] for a, k in zip(_A[5], ks))
        Yn = Y + h * sum(a * k[1] for a, k in zip(_A[5], ks))
        k7 = tab.rhs(Xn, Yn, Fl, Ol, beta)
        ks.append(k7)
        ex = h * sum(e * k[0] for e, k in zip(_E, ks))
        ey = h * sum(e * k[1] for e, k in zip(_E, ks))
        sx = atol + tol * np.maximum(np.abs(X), np.abs(Xn))
        sy = atol + tol * np.maximum(np.abs(Y), np.abs(Yn))
        err = np.sqrt(0.5 * ((ex / sx) ** 2 + (ey / sy) ** 2))
        acc = err <= 1.0
        fac = np.clip(0.9 * np.maximum(err, 1e-10) ** -0.2, 0.2, 5.0)
        h_next = h * np.where(acc, fac, np.minimum(fac, 1.0))
        # ---- accepted lanes: decisions
        J0, J1 = 0.5 * (X * X + Y * Y), 0.5 * (Xn * Xn + Yn * Yn)
        m0 = h * (X * k1[0] + Y * k1[1])
        m1 = h * (Xn * k7[0] + Yn * k7[1])
        esc = acc & ((J1 >= J_max) | (_hermite_max(J0, J1, m0, m1) >= J_max))
        dx, dy = Xn[:, None] - px, Yn[:, None] - py
        V = p11 * dx * dx + 2 * p12 * dx * dy + p22 * dy * dy
        in_ell = valid & (cl > 0) & (V <= cl)
        settled = acc & ~esc & in_ell.any(axis=1)
        att = np.where(settled, idx[np.arange(lane.size), np.argmax(in_ell, axis=1)], -1)
        # ray crossings of the pivots' rays
        cr0 = ux * (Y[:, None] - py) - uy * (X[:, None] - px)
        cr1 = ux * dy - uy * dx
        cross = acc[:, None] & ~esc[:, None] & valid & ((cr0 > 0) != (cr1 > 0))
        if cross.any():
            r, k = np.nonzero(cross)
            cx, cy = _hermite_crossing(X[r], Y[r], Xn[r], Yn[r], h[r] * k1[0][r], h[r] * k1[1][r],
                                       h[r] * k7[0][r], h[r] * k7[1][r], px[r, k], py[r, k], ux[r, k], uy[r, k])
            cx, cy = cx - px[r, k], cy - py[r, k]
            rho = ux[r, k] * cx + uy[r, k] * cy
            on_ray = rho > 0
            r, k, rho = r[on_ray], k[on_ray], rho[on_ray]
            d = np.where(cr1[r, k] > cr0[r, k], 1, -1).astype(np.int8)
            cand = (last_dir[r, k] == d) & (rho < last_rho[r, k])
            if cand.any():
                rc, kc, dc = r[cand], k[cand], d[cand]
                s = np.linspace(0.0, 1.0, 9)
                rr = rho[cand][:, None] + s * (last_rho[rc, kc] - rho[cand])[:, None]
                qx = px[rc, kc][:, None] + rr * ux[rc, kc][:, None]
                qy = py[rc, kc][:, None] + rr * uy[rc, kc][:, None]
                fx, fy = tab.rhs(qx, qy, Fl[rc][:, None], Ol[rc][:, None], beta)
                trans = np.all((ux[rc, kc][:, None] * fy - uy[rc, kc][:, None] * fx) * dc[:, None] > 0, axis=1)
                trap = rc[trans]
                first = ~settled[trap]
                settled[trap[first]] = True
                att[trap[first]] = idx[trap[first], kc[trans][first]]
            last_rho[r, k] = rho
            last_dir[r, k] = d
        # ---- advance
        X = np.where(acc, Xn, X)
        Y = np.where(acc, Yn, Y)
        t = np.where(acc, t + h, t)
        k1 = (np.where(acc, k7[0], k1[0]), np.where(acc, k7[1], k1[1]))
        h = h_next
        steps += 1
        over = ~esc & ~settled & (t >= Tl * (1 - 1e-12))
        done = esc | settled | over
        if done.any():
            ln = lane[done]
            status[ln] = np.where(esc[done], ESCAPED, np.where(settled[done], SETTLED, UNDECIDED))
            t_end[ln] = t[done]
            attractor[ln] = np.where(settled[done], att[done], -1)
            live = ~done
            lane, X, Y, t, h = lane[live], X[live], Y[live], t[live], h[live]
            k1 = (k1[0][live], k1[1][live])
            Fl, Ol, Tl = Fl[live], Ol[live], Tl[live]
            px, py, ux, uy = px[live], py[live], ux[live], uy[live]
            p11, p12, p22, cl, valid, idx = p11[live], p12[live], p22[live], cl[live], valid[live], idx[live]
            last_rho, last_dir = last_rho[live], last_dir[live]
    t_end[lane] = t                          # left over after max_steps: undecided
    return status, t_end, attractor, steps
