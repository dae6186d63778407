"""Semi-Lagrangian march of the averaged backward equation (docs/noise-theory.md).

``u_t = b . grad u + (sigma^2/2) div(m grad u)`` split (Strang) into half steps of the diffusion
(implicit Euler, the finite volumes of :func:`~safebasins.theory.noise_solver.generator` without
advection) around an exact advection step: ``u(x) <- u(Phi_dt(x))`` with ``Phi_dt`` the slow flow's
(RK4 substeps in the regular frame ``X + iY = sqrt(2J) e^{i gamma}``, where it is smooth at the well
bottom; a departure path that reaches J_max has escaped: value 1).  The departure points are fixed
(the flow is autonomous), so the advection is one sparse matrix: bicubic Lagrange interpolation in
``(gamma, J)`` clipped to the range of the four surrounding cells (quasi-monotone, Bermejo and
Staniforth 1992; bilinear next to J = 0 and J_max).  Unlike an Eulerian scheme it has no cell
Peclet limit: the solution stays in [0, 1] at any noise, and its numerical diffusion
(interpolation error once per step) is far below first-order upwinding's.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from safebasins.theory.damped import flow_tilde
from safebasins.theory.noise_averaging import AveragedDiffusion
from safebasins.theory.noise_solver import DiscGrid, generator, interpolation, row_range
from safebasins.theory.types import FloatArray

__all__ = ["departure_points", "advection_matrix", "march_escape_sl", "escape_times"]


def _flow(X: FloatArray, Y: FloatArray, diff: AveragedDiffusion, a_J: FloatArray, F: float, Omega: float,
          beta: float) -> tuple[FloatArray, FloatArray]:
    """The slow flow in the regular (sheared) frame (:func:`~safebasins.theory.damped.flow_tilde`)
    with the tables' coefficients at ``J = (X^2 + Y^2)/2`` (``e = da/dJ``; d = 0 for a symmetric well)."""
    J = np.minimum(0.5 * (X * X + Y * Y), diff.J_max)
    om = np.interp(J, diff.J_nodes, diff.omega)
    a = np.interp(J, diff.J_nodes, diff.a)
    e = np.interp(J, diff.J_nodes, a_J)
    return flow_tilde(X, Y, F, Omega, beta, om, a, e, diff.d(J))


def _rk4(X: FloatArray, Y: FloatArray, h: float, diff: AveragedDiffusion, a_J: FloatArray, F: float, Omega: float,
         beta: float) -> tuple[FloatArray, FloatArray]:
    """One RK4 step of :func:`_flow`."""
    k1 = _flow(X, Y, diff, a_J, F, Omega, beta)
    k2 = _flow(X + 0.5 * h * k1[0], Y + 0.5 * h * k1[1], diff, a_J, F, Omega, beta)
    k3 = _flow(X + 0.5 * h * k2[0], Y + 0.5 * h * k2[1], diff, a_J, F, Omega, beta)
    k4 = _flow(X + h * k3[0], Y + h * k3[1], diff, a_J, F, Omega, beta)
    return X + h / 6.0 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]), Y + h / 6.0 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])


def departure_points(grid: DiscGrid, diff: AveragedDiffusion, F: float, Omega: float, beta: float, dt: float,
                     substeps: int) -> tuple[FloatArray, FloatArray, np.ndarray]:
    """``(gamma, J, escaped)`` of ``Phi_dt`` from every cell centre (RK4, ``substeps`` steps);
    ``escaped``: the path reached J_max (checked at every substep)."""
    g_c, J_c = grid.centres()
    G, Jm = np.meshgrid(g_c, J_c)                   # (n_J, n_gamma): cell k = i n_gamma + j
    r = np.sqrt(2.0 * Jm.ravel())
    X, Y = r * np.cos(G.ravel()), r * np.sin(G.ravel())
    a_J = np.gradient(diff.a, diff.J_nodes)
    h = dt / substeps
    escaped = np.zeros(X.size, bool)
    for _ in range(substeps):
        X, Y = _rk4(X, Y, h, diff, a_J, F, Omega, beta)
        escaped |= 0.5 * (X * X + Y * Y) >= diff.J_max
    J = np.minimum(0.5 * (X * X + Y * Y), diff.J_max)
    return np.mod(np.arctan2(Y, X), 2.0 * np.pi), J, escaped


def escape_times(diff: AveragedDiffusion, F: float, Omega: float, beta: float, phase: FloatArray, J: FloatArray,
                 t_end: float, steps: int, substeps: int = 8) -> FloatArray:
    """First times at which the noise-free slow flow from the points ``(phase, J)`` (the tables'
    phase) reaches J_max, on ``steps`` x ``substeps`` RK4 steps to ``t_end`` (the march's
    characteristics; the time of the first substep at or past J_max); inf where it does not."""
    r = np.sqrt(2.0 * J)
    X, Y = r * np.cos(phase), r * np.sin(phase)
    a_J = np.gradient(diff.a, diff.J_nodes)
    n = steps * substeps
    h = t_end / n
    out = np.full(X.size, np.inf)
    live = J < diff.J_max
    out[~live] = 0.0
    for k in range(1, n + 1):
        if not live.any():
            break
        X[live], Y[live] = _rk4(X[live], Y[live], h, diff, a_J, F, Omega, beta)
        hit = live & (0.5 * (X * X + Y * Y) >= diff.J_max)
        out[hit] = k * h
        live &= ~hit
    return out


def _cubic_weights(f: FloatArray) -> FloatArray:
    """Lagrange weights of the nodes -1, 0, 1, 2 at offset f in [0, 1) (shape (4, n))."""
    return np.stack([-f * (f - 1) * (f - 2) / 6, (f + 1) * (f - 1) * (f - 2) / 2,
                     -(f + 1) * f * (f - 2) / 2, (f + 1) * f * (f - 1) / 6])


def advection_matrix(grid: DiscGrid, gamma: FloatArray, J: FloatArray, escaped: np.ndarray
                     ) -> tuple[sp.csr_matrix, FloatArray, sp.csr_matrix, FloatArray]:
    """``(W3, w3_b, W1, w1_b)``: bicubic (W3) and bilinear (W1, the clipping stencil) interpolation
    at the departure points; escaped points take the boundary value (weight 1 in ``w_b``)."""
    ng, nJ = grid.n_gamma, grid.n_J
    W1, w1_b = interpolation(grid, gamma, J)
    x = gamma / grid.d_gamma - 0.5
    j0 = np.floor(x).astype(np.intp)
    y = J / grid.d_J - 0.5
    i0 = np.floor(y).astype(np.intp)
    cubic = (i0 >= 1) & (i0 <= nJ - 3) & ~escaped
    pts = np.nonzero(cubic)[0]
    wg = _cubic_weights(x[pts] - j0[pts])
    wJ = _cubic_weights(y[pts] - i0[pts])
    rows, cols, vals = [], [], []
    for a in range(4):
        jj = np.mod(j0[pts] + a - 1, ng)
        for b in range(4):
            rows.append(pts)
            cols.append((i0[pts] + b - 1) * ng + jj)
            vals.append(wJ[b] * wg[a])
    W3c = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(J.size, grid.size))
    lin = ~cubic & ~escaped
    keep = sp.diags(lin.astype(float))
    W3 = (W3c + keep @ W1).tocsr()
    w3_b = np.where(escaped, 1.0, np.where(lin, w1_b, 0.0))
    W1 = (keep @ W1 + sp.diags((cubic).astype(float)) @ W1).tocsr()
    w1_b = np.where(escaped, 1.0, w1_b)
    return W3, w3_b, W1, w1_b


def march_escape_sl(grid: DiscGrid, diff: AveragedDiffusion, F: float, Omega: float, beta: float, sigma: float,
                    W: sp.csr_matrix, w_b: FloatArray, t_end: float, steps: int, substeps: int = 8
                    ) -> tuple[FloatArray, FloatArray]:
    """``(t, P)``: the escape probability at the points of ``(W, w_b)`` on ``steps`` uniform steps to
    ``t_end`` (shape (steps + 1, points)), by the Strang-split semi-Lagrangian march."""
    dt = t_end / steps
    M_d, s_d = generator(grid, diff, F, Omega, beta, sigma, advection="none")
    lu = spla.splu((sp.identity(grid.size, format="csc") - 0.5 * dt * M_d).tocsc())
    gd, Jd, esc = departure_points(grid, diff, F, Omega, beta, dt, substeps)
    W3, w3_b, W1, w1_b = advection_matrix(grid, gd, Jd, esc)
    u = np.zeros(grid.size)
    out = np.empty((steps + 1, W.shape[0]))
    out[0] = w_b
    for k in range(1, steps + 1):
        u = lu.solve(u + 0.5 * dt * s_d)
        lo, hi = row_range(W1, w1_b, u)
        u = np.clip(W3 @ u + w3_b, lo, hi)
        u = lu.solve(u + 0.5 * dt * s_d)
        out[k] = np.clip(W @ u + w_b, *row_range(W, w_b, u))
    return np.linspace(0.0, t_end, steps + 1), out
