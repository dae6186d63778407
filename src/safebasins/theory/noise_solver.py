"""Backward Kolmogorov equation of the averaged noisy slow flow on a disc (docs/noise-theory.md).

The averaged generator in the canonical pair ``(gamma, J)`` (equal to the area of the regular
frame ``X + i Y = sqrt(2 J) e^{i gamma}``: ``dX dY = dgamma dJ``) is

    L u = b . grad u + (sigma^2/2) div(m grad u),
    b = (dC/dJ - beta d(J), -dC/dgamma - beta J),    m = diag(m_gg, m_JJ),

with the first integral ``C = H(J) - Omega J - F A(J) cos gamma`` of the slow flow; for an
asymmetric well gamma stands for the sheared phase ``phi = gamma + delta(J)`` (docs/damping.md:
``d = J ddelta/dJ``, 0 for a symmetric well), in which the averaged noise has no J-phase
covariance either (time reversal, docs/noise-theory.md).  Finite volumes
on cells uniform in ``(gamma, J)`` are a polar grid of equal-area cells in ``(X, Y)`` (rings of
equal area, the innermost ring wedges meeting at the well bottom, whose inner face has no length:
no boundary condition is needed there).  Fluxes:

* the Hamiltonian part through each face is the difference of C at the face's two corners (so the
  discrete velocity is exactly divergence-free), the damping's ``-beta J`` at the J-faces and
  ``-beta d`` at the gamma-faces (the same on every face of a ring: divergence-free); the face
  value is the mean of the two cells (``advection="central"``: no numerical diffusion, second order)
  or the downstream cell's (``"upwind"``: monotone, first order);
* the diffusion by two-point differences with ``m_JJ = J/omega`` at the J-faces (0 at J = 0) and
  ``m_gg`` at the cell centres.

The outer face ``J = J_max`` (the escape threshold xi_max) is absorbing: ``u = 1`` there for the
escape probability, ``u = 0`` for the mean first-passage time.  ``P(t)`` (``du/dt = L u``, ``u(0) =
0``) is marched with BDF2 (its first step: four implicit Euler substeps) with sparse LU factors
computed once; the mean first-passage time solves ``L T = -1``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from safebasins.theory.noise_averaging import AveragedDiffusion
from safebasins.theory.types import FloatArray

__all__ = ["ADVECTION", "DiscGrid", "generator", "interpolation", "row_range", "march_escape", "solve_first_passage"]

#: the face values of the advective fluxes
ADVECTION = ("central", "upwind")


@dataclass(frozen=True)
class DiscGrid:
    """Cells uniform in ``(gamma, J)`` on ``[0, 2 pi) x [0, J_max]``; cell ``k = i n_gamma + j``
    (ring i, sector j)."""

    n_gamma: int
    n_J: int
    J_max: float

    @property
    def d_gamma(self) -> float:
        return 2.0 * np.pi / self.n_gamma

    @property
    def d_J(self) -> float:
        return self.J_max / self.n_J

    @property
    def size(self) -> int:
        return self.n_gamma * self.n_J

    def centres(self) -> tuple[FloatArray, FloatArray]:
        """``(gamma, J)`` of the cell centres, 1-D."""
        g: FloatArray = (np.arange(self.n_gamma, dtype=np.float64) + 0.5) * self.d_gamma
        J: FloatArray = (np.arange(self.n_J, dtype=np.float64) + 0.5) * self.d_J
        return g, J


def generator(grid: DiscGrid, diff: AveragedDiffusion, F: float, Omega: float, beta: float, sigma: float,
              advection: str = "central") -> tuple[sp.csc_matrix, FloatArray]:
    """``(M, s)``: the discrete generator acting on the cell values and the weights of the boundary
    value, ``L u = M u + s u_boundary``; ``advection="none"``: the diffusion alone."""
    ng, nJ = grid.n_gamma, grid.n_J
    dg, dJ = grid.d_gamma, grid.d_J
    V = dg * dJ
    g_c, J_c = grid.centres()
    g_f = np.arange(ng + 1) * dg                    # sector edges
    J_f = np.arange(nJ + 1) * dJ                    # ring edges
    H_f, om_f, A_f, ar_f, _ = diff.at(J_f)
    C = H_f[:, None] - Omega * J_f[:, None] - F * A_f[:, None] * np.cos(g_f)[None, :]     # corners (nJ+1, ng+1)
    # outward fluxes (area per time) through the upper J-face of ring i and the upper gamma-face of sector j
    phi_J = -(C[:, 1:] - C[:, :-1]) - beta * J_f[:, None] * dg                            # (nJ+1, ng)
    phi_g = C[1:, 1:] - C[:-1, 1:]                                                          # (nJ, ng)
    if not diff.symmetric:
        # the sheared phase's damping drift -beta d(J) (d = J ddelta/dJ) through the gamma-faces
        phi_g = phi_g - (beta * dJ) * diff.d(J_c)[:, None]
    if advection == "none":
        phi_J, phi_g = np.zeros_like(phi_J), np.zeros_like(phi_g)
    _, _, _, _, at_c = diff.at(J_c)
    D_J = 0.5 * sigma ** 2 * (2.0 * J_f * ar_f) * dg / dJ                                   # (nJ+1,)
    D_g = 0.5 * sigma ** 2 * (at_c / (2.0 * J_c)) * dJ / dg                                 # (nJ,)
    idx = np.arange(grid.size).reshape(nJ, ng)
    rows: list[NDArray[np.intp]] = []
    cols: list[NDArray[np.intp]] = []
    vals: list[FloatArray] = []

    def couple(a: NDArray[np.intp], b: NDArray[np.intp], phi: FloatArray, D: FloatArray) -> None:
        """Face between cells a (flux phi out of a into b) and b: rates a->b and b->a."""
        if advection == "central":
            ra, rb = 0.5 * phi, -0.5 * phi
        else:
            ra, rb = np.maximum(phi, 0.0), np.maximum(-phi, 0.0)
        for x, y, r in ((a, b, (ra + D) / V), (b, a, (rb + D) / V)):
            rows.extend((x.ravel(), x.ravel()))
            cols.extend((y.ravel(), x.ravel()))
            vals.extend((r.ravel(), -r.ravel()))

    # ring faces between ring i and i+1
    if nJ > 1:
        couple(idx[:-1], idx[1:], phi_J[1:-1], np.broadcast_to(D_J[1:-1, None], (nJ - 1, ng)))
    # sector faces between sector j and j+1 (periodic)
    couple(idx, np.roll(idx, -1, axis=1), phi_g, np.broadcast_to(D_g[:, None], (nJ, ng)))
    # absorbing outer face: distance dJ/2 for the diffusion, the boundary value for the advection
    out = idx[-1]
    phi_b = phi_J[-1]
    adv = phi_b if advection == "central" else np.maximum(phi_b, 0.0)
    rate_b = (adv + 2.0 * D_J[-1]) / V
    rows.append(out)
    cols.append(out)
    vals.append(-rate_b)
    s = np.zeros(grid.size)
    s[out] = rate_b
    M = sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(grid.size, grid.size))
    return M, s


def interpolation(grid: DiscGrid, gamma: FloatArray, J: FloatArray) -> tuple[sp.csr_matrix, FloatArray]:
    """``(W, w_b)``: values at points ``(gamma, J)`` (``0 <= J <= J_max``) are ``W u + w_b u_boundary``:
    bilinear in (gamma, J) between cell centres (periodic in gamma); below the first ring's centre
    towards the ring's mean at the well bottom (the regular point), above the last towards the
    boundary value at J_max."""
    ng, nJ = grid.n_gamma, grid.n_J
    n = gamma.size
    x = np.mod(gamma, 2.0 * np.pi) / grid.d_gamma - 0.5
    j0 = np.floor(x).astype(np.intp)
    fg = x - j0
    j0, j1 = np.mod(j0, ng), np.mod(j0 + 1, ng)
    y = J / grid.d_J - 0.5
    i0 = np.floor(y).astype(np.intp)
    fJ = y - i0
    rows: list[NDArray[np.intp]] = []
    cols: list[NDArray[np.intp]] = []
    vals: list[FloatArray] = []
    w_b = np.zeros(n)
    pts = np.arange(n)

    def ring(i: NDArray[np.intp], w: FloatArray, sel: NDArray[np.bool_]) -> None:
        p, ii, ww = pts[sel], i[sel], w[sel]
        for jj, wg in ((j0[sel], 1.0 - fg[sel]), (j1[sel], fg[sel])):
            rows.append(p)
            cols.append(ii * ng + jj)
            vals.append(ww * wg)

    low = i0 < 0
    top = i0 >= nJ - 1
    mid = ~low & ~top
    ring(i0, 1.0 - fJ, mid)
    ring(i0 + 1, fJ, mid)
    # below the first centre: weight t = J / (dJ / 2) on ring 0, 1 - t on the value at the well bottom,
    # the rings' means extrapolated to J = 0 (1.5 mean_0 - 0.5 mean_1: exact for functions linear in J)
    t = np.clip(J / (0.5 * grid.d_J), 0.0, 1.0)
    ring(np.zeros(n, np.intp), t, low)
    p = pts[low]
    for i_r, c in ((0, 1.5), (1, -0.5)):
        if i_r < nJ:
            rows.append(np.repeat(p, ng))
            cols.append(np.tile(i_r * ng + np.arange(ng), p.size))
            vals.append(np.repeat(c * (1.0 - t[low]) / ng, ng))
    # above the last centre: towards the boundary value
    tb = np.clip((J - (grid.J_max - 0.5 * grid.d_J)) / (0.5 * grid.d_J), 0.0, 1.0)
    ring(np.full(n, nJ - 1, np.intp), 1.0 - tb, top)
    w_b[top] = tb[top]
    W = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, grid.size))
    return W, w_b


def row_range(W: sp.csr_matrix, w_b: FloatArray, u: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Row-wise min and max of the values a row of W touches (the boundary value 1 where w_b > 0)."""
    n = W.shape[0]
    lo = np.ones(n)
    hi = np.zeros(n)
    nz = np.diff(W.indptr) > 0
    if nz.any():
        v = u[W.indices]
        starts = W.indptr[:-1][nz]
        lo[nz] = np.minimum.reduceat(v, starts)
        hi[nz] = np.maximum.reduceat(v, starts)
    bnd = w_b > 0
    lo[bnd] = np.minimum(lo[bnd], 1.0)
    hi[bnd] = np.maximum(hi[bnd], 1.0)
    return lo, hi


def march_escape(M: sp.csc_matrix, s: FloatArray, W: sp.csr_matrix, w_b: FloatArray, t_end: float,
                 steps: int) -> tuple[FloatArray, FloatArray, tuple[float, float]]:
    """``(t, P, (u_min, u_max))``: the escape probability ``P(t)`` at the points of ``(W, w_b)``
    (shape (steps + 1, points)) on ``steps`` uniform steps to ``t_end``, from ``u(0) = 0`` with
    boundary value 1, and the range of the cell values over the march (outside [0, 1]: the
    central scheme's oscillations, unresolved cell Peclet numbers)."""
    n = M.shape[0]
    dt = t_end / steps
    eye = sp.identity(n, format="csc")
    sub = 4
    lu_ie = spla.splu((eye - (dt / sub) * M).tocsc())
    lu_bdf = spla.splu((3.0 * eye - 2.0 * dt * M).tocsc())
    u_prev = np.zeros(n)
    u = u_prev
    for _ in range(sub):
        u = lu_ie.solve(u + (dt / sub) * s)
    out = np.empty((steps + 1, W.shape[0]))
    out[0] = w_b
    out[1] = W @ u + w_b
    lo, hi = float(u.min()), float(u.max())
    for k in range(2, steps + 1):
        u, u_prev = lu_bdf.solve(4.0 * u - u_prev + 2.0 * dt * s), u
        out[k] = W @ u + w_b
        lo, hi = min(lo, float(u.min())), max(hi, float(u.max()))
    return np.linspace(0.0, t_end, steps + 1), out, (lo, hi)


def solve_first_passage(M: sp.csc_matrix, W: sp.csr_matrix) -> tuple[FloatArray, float]:
    """Mean first-passage time at the points of ``W`` (``M T = -1``, T = 0 on the boundary) and the
    smallest cell value (negative: oscillations of the central fluxes)."""
    T = spla.splu(M.tocsc()).solve(-np.ones(M.shape[0]))
    out: FloatArray = W @ T
    return out, float(T.min())
