"""Fixed points of the damped slow flow and the steady (frequency) responses (docs/damping.md).

A fixed point of ``J' = -F A sin(phi) - beta J``, ``phi' = w~ - Omega - F dA/dJ cos(phi)``
(:mod:`safebasins.theory.damped`; ``phi = gamma + delta``, ``w~ = omega - beta J ddelta/dJ``) has

    sin(phi) = -s,   s = beta J / (F A),        Omega = w~ - sigma F omega dA/dxi sqrt(1 - s^2),

with ``sigma = sign(cos phi) = +-1``: at fixed F and beta the fixed points form the response curve
``Omega_sigma(xi)`` (two branches where ``s < 1``, joined where ``s = 1``, i.e. at the top of the
resonance peak).  Its backbone is ``Omega = omega(xi)``.  In (phi, J) the Jacobian has trace
``-beta`` and determinant ``det = F A cos(phi) dOmega/dJ`` along the curve, so a fixed point is a
saddle where ``sigma dOmega_sigma/dxi < 0`` and attracting (a node or a focus) elsewhere (a
centre for beta = 0); the folds (saddle-node points of a frequency sweep) are the extrema of
``Omega_sigma(xi)``.  Fixed points are seeded from sign changes of ``Omega_sigma(xi) - Omega`` on a
grid and polished by Newton's method in (xi, phi) with the well's exact functions.
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike, NDArray

from safebasins.core import checks
from safebasins.core.checks import check_1d, check_nonnegative, check_positive, check_positive_int, check_scalar
from safebasins.theory.damped import TOP_GAP, coefficients, slow_tables
from safebasins.theory.profile import unshear
from safebasins.theory.types import BoolArray, FloatArray, WellArg
from safebasins.wells.base import Well
from safebasins.wells import resolve_well
from safebasins.wells.provenance import api_provenance

__all__ = ["steady_responses", "fixed_points", "FixedPoints", "KINDS"]

#: kinds of fixed points (flag values 0..4 of ``kind``)
KINDS = ("none", "stable_node", "stable_focus", "saddle", "center")
NODE, FOCUS, SADDLE, CENTER = 1, 2, 3, 4


def _grid(xi_hi: float, n: int) -> FloatArray:
    """xi nodes on (0, xi_hi]: geometric below 1e-3 xi_hi (small-amplitude responses far from
    resonance), Chebyshev-Lobatto above."""
    t = np.linspace(0.0, 1.0, n)
    lo = 1e-3 * xi_hi
    cheb = lo + (xi_hi - lo) * 0.5 * (1.0 - np.cos(np.pi * t))
    return np.concatenate([xi_hi * np.geomspace(1e-11, 1e-3, 48, endpoint=False), cheb])


def _branches(c: dict[str, FloatArray], F: FloatArray, Omega: FloatArray,
              beta: float) -> tuple[dict[int, FloatArray], dict[int, FloatArray], BoolArray]:
    """Omega_sigma(xi) - Omega and phi_sigma(xi) on a grid (rows: pairs (F, Omega)); NaN where s >= 1."""
    Fc = F[:, None]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):   # s = inf or huge: outside
        s = beta * c["J"][None, :] / (Fc * c["A"][None, :])
    inside = s < 1.0
    s_in = np.where(inside, s, 0.0)                  # 1 - s^2 only where s < 1 (no overflow outside)
    root = np.where(inside, np.sqrt(1.0 - s_in * s_in), np.nan)
    wt = (c["omega"] - beta * c["d"])[None, :]
    k = Fc * (c["omega"] * c["A_xi"])[None, :]
    g = {1: wt - k * root - Omega[:, None], -1: wt + k * root - Omega[:, None]}
    phi = {1: np.arctan2(-s, root), -1: np.arctan2(-s, -root)}
    return g, phi, inside


def _residuals(well: Well, xi: FloatArray, phi: FloatArray, F: FloatArray, Omega: FloatArray, beta: float,
               xi_hi: float) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray,
                                      dict[str, FloatArray]]:
    """Newton residuals and Jacobian in (xi, phi), central differences in xi for the derivatives
    of omega - beta d and omega dA/dxi."""
    c = coefficients(well, xi)
    h = 1e-6 * np.minimum(xi, xi_hi - xi)
    cp = coefficients(well, xi + h)
    cm = coefficients(well, xi - h)
    sn, cs = np.sin(phi), np.cos(phi)
    K = c["omega"] * c["A_xi"]
    f1 = F * c["A"] * sn + beta * c["J"]
    f2 = c["omega"] - beta * c["d"] - Omega - F * K * cs
    dW = ((cp["omega"] - beta * cp["d"]) - (cm["omega"] - beta * cm["d"])) / (2 * h)
    dK = (cp["omega"] * cp["A_xi"] - cm["omega"] * cm["A_xi"]) / (2 * h)
    a11 = F * c["A_xi"] * sn + beta / c["omega"]
    a12 = F * c["A"] * cs
    a21 = dW - F * dK * cs
    a22 = F * K * sn
    return f1, f2, a11, a12, a21, a22, c


class FixedPoints:
    """Fixed points of the damped slow flow for P parameter pairs (F, Omega), padded to K per pair.

    Arrays (P, K): ``xi``, ``phi`` (sheared phase), ``gamma``, ``J``, ``Xt``, ``Yt`` (sheared
    Cartesian frame), ``det`` (Jacobian determinant in (phi, J); trace = -beta), ``kind`` (KINDS
    codes, 0 = padding), ``converged``; ``eig`` (P, K, 2) complex eigenvalues; ``M`` (P, K, 2, 2)
    the Jacobian in (Xt, Yt).
    """

    phi: FloatArray
    gamma: FloatArray
    J: FloatArray
    Xt: FloatArray
    Yt: FloatArray
    det: FloatArray

    def __init__(self, P: int, K: int) -> None:
        self.xi: FloatArray = np.full((P, K), np.nan)
        for name in ("phi", "gamma", "J", "Xt", "Yt", "det"):
            setattr(self, name, np.full((P, K), np.nan))
        self.kind: NDArray[np.int8] = np.zeros((P, K), np.int8)
        self.converged: BoolArray = np.zeros((P, K), bool)
        self.eig: NDArray[np.complex128] = np.full((P, K, 2), np.nan + 0j)
        self.M: FloatArray = np.full((P, K, 2, 2), np.nan)

    @property
    def attracting(self) -> BoolArray:
        """Stable nodes and foci (centres for beta = 0: the pivots of the trapping test)."""
        out: BoolArray = (self.kind == NODE) | (self.kind == FOCUS) | (self.kind == CENTER)
        return out


def fixed_points(F: ArrayLike, Omega: ArrayLike, beta: float, well: Well, xi_hi: float, n_grid: int = 1200,
                 n_newton: int = 30) -> FixedPoints:
    """All fixed points with ``0 < xi < xi_hi`` of the damped slow flow for pairs (F, Omega)
    (1-D arrays of equal length, F >= 0, Omega > 0; beta >= 0): a :class:`FixedPoints`.

    F = 0: the one fixed point is the well bottom (a stable focus for beta > 0, a centre at 0).
    """
    Fa = np.asarray(F, float)
    Om = np.asarray(Omega, float)
    P = Fa.size
    grid = _grid(xi_hi, n_grid)
    c = coefficients(well, grid)
    pos = Fa > 0
    seeds_p: list[NDArray[np.intp]] = []
    seeds_x: list[FloatArray] = []
    seeds_f: list[FloatArray] = []
    if pos.any():
        rows = np.nonzero(pos)[0]
        g, phi, inside = _branches(c, Fa[rows], Om[rows], beta)
        for sg in (1, -1):
            gg = g[sg]
            link = inside[:, :-1] & inside[:, 1:] & ((gg[:, :-1] > 0) != (gg[:, 1:] > 0))
            r, i = np.nonzero(link)
            w = gg[r, i] / (gg[r, i] - gg[r, i + 1])
            seeds_p.append(rows[r])
            seeds_x.append(grid[i] + w * (grid[i + 1] - grid[i]))
            seeds_f.append(phi[sg][r, i] + w * (phi[sg][r, i + 1] - phi[sg][r, i]))
        # junctions of the two branches where s crosses 1 between grid nodes
        edge = np.zeros_like(inside)
        edge[:, :-1] |= inside[:, :-1] & ~inside[:, 1:]
        edge[:, 1:] |= inside[:, 1:] & ~inside[:, :-1]
        link = edge & ((g[1] > 0) != (g[-1] > 0))
        r, i = np.nonzero(link)
        seeds_p.append(rows[r])
        seeds_x.append(grid[i])
        seeds_f.append(np.full(r.size, -0.5 * np.pi))
    sp = np.concatenate(seeds_p) if seeds_p else np.empty(0, int)
    sx = np.concatenate(seeds_x) if seeds_x else np.empty(0)
    sf = np.concatenate(seeds_f) if seeds_f else np.empty(0)

    ok = np.zeros(sp.size, bool)
    if sp.size:
        Fs, Os = Fa[sp], Om[sp]
        x, f = sx.copy(), sf.copy()
        for _ in range(n_newton):
            f1, f2, a11, a12, a21, a22, _ = _residuals(well, x, f, Fs, Os, beta, xi_hi)
            det = a11 * a22 - a12 * a21
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):   # a singular step is dropped
                dx = (a22 * f1 - a12 * f2) / det
                df = (a11 * f2 - a21 * f1) / det
            bad = ~np.isfinite(dx) | ~np.isfinite(df)
            dx, df = np.where(bad, 0.0, dx), np.where(bad, 0.0, df)
            dx = np.clip(dx, -0.5 * (xi_hi - x), 0.5 * x)     # x - dx stays in (x / 2, (x + xi_hi) / 2)
            df = np.clip(df, -0.5, 0.5)
            x, f = x - dx, f - df
            done = (np.abs(dx) <= 1e-14 * x + 1e-300) & (np.abs(df) <= 1e-13)
            if done.all():
                break
        f1, f2, a11, a12, a21, a22, cc = _residuals(well, x, f, Fs, Os, beta, xi_hi)
        scale1 = Fs * cc["A"] + beta * cc["J"]
        ok = (np.abs(f1) <= 1e-9 * scale1) & (np.abs(f2) <= 1e-9) & (x > 0) & (x < xi_hi)
        sp, x, f = sp[ok], x[ok], f[ok]
        a11, a12, a21, a22 = a11[ok], a12[ok], a21[ok], a22[ok]
        cc = {k: v[ok] for k, v in cc.items()}
        f = np.mod(f + np.pi, 2.0 * np.pi) - np.pi
        # one entry per fixed point: drop duplicates found from neighbouring seeds
        order = np.lexsort((f, x, sp))
        sp, x, f = sp[order], x[order], f[order]
        a11, a12, a21, a22 = a11[order], a12[order], a21[order], a22[order]
        cc = {k: v[order] for k, v in cc.items()}
        dup = np.zeros(sp.size, bool)
        dup[1:] = (sp[1:] == sp[:-1]) & (np.abs(x[1:] - x[:-1]) <= 1e-9 * x[1:]) & \
            (np.abs(f[1:] - f[:-1]) <= 1e-7)
        keep = ~dup
        sp, x, f = sp[keep], x[keep], f[keep]
        a11, a12, a21, a22 = a11[keep], a12[keep], a21[keep], a22[keep]
        cc = {k: v[keep] for k, v in cc.items()}
    counts = np.bincount(sp, minlength=P) if sp.size else np.zeros(P, int)
    K = max(1, int(counts.max()) if P else 1)
    out = FixedPoints(P, K)
    if sp.size:
        slot = np.arange(sp.size) - np.searchsorted(sp, sp)
        om = cc["omega"]
        # Jacobian in (phi, J): rows (phi', J'), trace -beta
        Mq = np.stack([np.stack([a22, om * a21], -1), np.stack([-a12, -om * a11], -1)], -2)
        r = np.sqrt(2.0 * cc["J"])
        T = np.stack([np.stack([-r * np.sin(f), np.cos(f) / r], -1),
                      np.stack([r * np.cos(f), np.sin(f) / r], -1)], -2)
        out.M[sp, slot] = T @ Mq @ np.linalg.inv(T)
        out.xi[sp, slot] = x
        out.phi[sp, slot] = f
        out.J[sp, slot] = cc["J"]
        out.Xt[sp, slot] = r * np.cos(f)
        out.Yt[sp, slot] = r * np.sin(f)
        out.gamma[sp, slot] = unshear(f, cc["delta"])
        out.det[sp, slot] = a22 * (-om * a11) - om * a21 * (-a12)
        out.converged[sp, slot] = True
    zero = np.nonzero(~pos)[0]
    if zero.size:                                   # F = 0: the well bottom
        w0 = float(slow_tables(well).lookup(np.zeros(1))[0][0])
        dw = w0 - Om[zero]
        out.xi[zero, 0] = out.J[zero, 0] = out.Xt[zero, 0] = out.Yt[zero, 0] = 0.0
        out.phi[zero, 0] = out.gamma[zero, 0] = 0.0
        out.det[zero, 0] = 0.25 * beta * beta + dw * dw
        out.M[zero, 0] = np.stack([np.stack([-0.5 * beta + 0 * dw, -dw], -1),
                                   np.stack([dw, -0.5 * beta + 0 * dw], -1)], -2)
        out.converged[zero, 0] = True
    have = out.converged
    tr = -beta
    disc = (tr * tr - 4.0 * np.where(have, out.det, 0.0)).astype(complex)
    out.eig[..., 0] = np.where(have, 0.5 * (tr + np.sqrt(disc)), np.nan)
    out.eig[..., 1] = np.where(have, 0.5 * (tr - np.sqrt(disc)), np.nan)
    kind = np.where(out.det < 0, SADDLE, np.where(beta == 0, CENTER, np.where(disc.real >= 0, NODE, FOCUS)))
    out.kind = np.where(have, kind, 0).astype(np.int8)
    return out


def _refine_junctions(well: Well, grid: FloatArray, F: float, beta: float) -> FloatArray:
    """The grid with nodes clustered (geometrically, down to 1e-9 of the last cell) on the inside of
    each junction ``s(xi) = 1`` of the two branches, where xi is a poor parameter of the curve and
    the fold nearest the peak hides; the junction itself (both branches at Omega = w~) is a node."""
    def s_of(x: FloatArray) -> FloatArray:
        c = coefficients(well, x)
        return beta * c["J"] / (F * c["A"])

    s = s_of(grid)
    flip = np.nonzero((s[:-1] < 1.0) != (s[1:] < 1.0))[0]
    extra: list[Any] = []
    for i in flip:
        lo, hi = grid[i], grid[i + 1]
        inside_lo = s[i] < 1.0
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            if (s_of(np.array(mid)) < 1.0) == inside_lo:
                lo = mid
            else:
                hi = mid
        x_in, x_s = (lo, grid[i]) if inside_lo else (hi, grid[i + 1])
        extra.append(x_in + (x_s - x_in) * np.geomspace(1.0, 1e-9, 60))
        extra.append([x_in])
    return np.unique(np.concatenate([grid] + extra)) if extra else grid


def _folds(well: Well, c: dict[str, FloatArray], grid: FloatArray, F: float,
           beta: float) -> list[tuple[float, float, float, int]]:
    """Extrema of Omega_sigma(xi) on each branch (grid sign changes of dOmega/dxi, refined by
    bisection on a central difference of the exact Omega_sigma)."""
    g, _, inside = _branches(c, np.array([F]), np.zeros(1), beta)
    out = []
    for sg in (1, -1):
        Om = g[sg][0]
        d = np.diff(Om)
        ok = inside[0, 1:-1] & inside[0, :-2] & inside[0, 2:]
        idx = np.nonzero(ok & ((d[:-1] > 0) != (d[1:] > 0)))[0] + 1

        def slope(x: float) -> float:
            h = 1e-7 * x
            cp, cm = coefficients(well, x + h), coefficients(well, x - h)
            gp, _, _ = _branches({k: np.atleast_1d(v) for k, v in cp.items()}, np.array([F]), np.zeros(1), beta)
            gm, _, _ = _branches({k: np.atleast_1d(v) for k, v in cm.items()}, np.array([F]), np.zeros(1), beta)
            return float((gp[sg] - gm[sg])[0, 0])

        for i in idx:
            lo, hi = grid[i - 1], grid[i + 1]
            slo = slope(lo)
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                if (slope(mid) > 0) == (slo > 0):
                    lo = mid
                else:
                    hi = mid
            x = 0.5 * (lo + hi)
            cx = {k: np.atleast_1d(v) for k, v in coefficients(well, np.array(x)).items()}
            gx, phx, _ = _branches(cx, np.array([F]), np.zeros(1), beta)
            out.append((float(gx[sg][0, 0]), x, float(phx[sg][0, 0] - cx["delta"][0]), sg))
    return sorted(out)


@api_provenance
def steady_responses(Omega: ArrayLike, F: float, damping: float, well: WellArg = None, xi_max: float | None = None,
                     fourier: str | None = None, n_grid: int = 4000) -> xr.Dataset:
    """Steady responses of ``q'' + beta q' + V'(q) = F sin(Omega tau + Psi)`` in the damped slow flow.

    The fixed points of the damped slow flow (docs/damping.md; module docstring) at each forcing
    frequency, with their stability, plus the whole response curve xi(Omega) at this F, its
    backbone Omega = omega(xi) and its folds (saddle-node points) -- the classic bent resonance
    peak of a softening well.

    Parameters
    ----------
    Omega : array_like, > 0
        Forcing frequencies.
    F : float, >= 0
        Forcing amplitude.
    damping : float, >= 0
        beta (0: the undamped flow's centres and saddles).
    well, fourier : the potential (default the paper's quartic; ``fourier`` its G).
    xi_max : float, optional
        Report fixed points with ``xi < xi_max`` (default: the whole well).
    n_grid : int
        Grid nodes in xi that seed the roots (polished by Newton).

    Returns
    -------
    xarray.Dataset
        dims ``Omega``, ``response`` (the fixed points at each Omega, ordered by xi, NaN-padded),
        ``eig`` (2), ``curve_point``, ``fold``:

        * ``xi``, ``gamma``, ``J`` (Omega, response): the fixed point (averaged energy, slow phase
          gamma = theta - Psi - Omega tau, action); ``kind`` (int8; flag_meanings
          "none stable_node stable_focus saddle center"), ``stable`` (bool: a node or focus);
          ``eig_real``, ``eig_imag`` (Omega, response, eig): the Jacobian's eigenvalues (trace
          -beta); ``n_responses`` (Omega).
        * ``Omega_curve``, ``xi_curve``, ``gamma_curve``, ``branch`` (+1: cos(gamma + delta) > 0,
          -1: < 0), ``stable_curve`` (curve_point): the response curve (branch +1 by increasing xi,
          then branch -1 back; NaN rows split it where it leaves the domain s < 1);
          ``Omega_backbone`` (curve_point): omega(xi_curve).
        * ``Omega_fold``, ``xi_fold``, ``gamma_fold``, ``branch_fold`` (fold): the folds.

        attrs: F, damping, xi_max, well, fourier.
    """
    w = resolve_well(well, fourier)
    beta = checks.check_damping(damping)
    Om = check_1d("Omega", Omega, check_positive)
    F = check_scalar("F", F, check_nonnegative)
    n_grid = check_positive_int("n_grid", n_grid)
    if n_grid < 64:
        raise ValueError(f"n_grid must be >= 64, got {n_grid}")
    top = float(w.barrier_energy) * (1.0 - TOP_GAP)
    xm = top if xi_max is None else min(check_scalar("xi_max", xi_max, w.check_threshold), top)
    fp = fixed_points(np.full(Om.size, F), Om, beta, w, xm, n_grid=n_grid)
    order = np.argsort(np.where(fp.converged, fp.xi, np.inf), axis=1, kind="stable")
    take: Callable[[NDArray[Any]], NDArray[Any]] = (
        lambda a: np.take_along_axis(a, order[..., None] if a.ndim == 3 else order, axis=1))
    kind = take(fp.kind)
    eig = take(fp.eig)

    grid = _grid(xm, n_grid)
    if F > 0 and beta > 0:
        grid = _refine_junctions(w, grid, F, beta)
    c = coefficients(w, grid)
    if F > 0:
        g, phi, inside = _branches(c, np.array([F]), np.zeros(1), beta)
        parts = []
        for sg in (1, -1):
            Oc = np.where(inside[0], g[sg][0], np.nan)
            dO = np.gradient(Oc, grid)
            gam = phi[sg][0] - c["delta"]
            seq = slice(None) if sg == 1 else slice(None, None, -1)
            parts.append((Oc[seq], grid[seq], gam[seq], np.full(grid.size, sg, np.int8), (sg * dO > 0)[seq]))
        Oc, xc, gc, bc, sc = (np.concatenate([p[k] for p in parts]) for k in range(5))
        xc = np.where(np.isfinite(Oc), xc, np.nan)
        gc = unshear(np.where(np.isfinite(Oc), gc, np.nan), 0.0)
        folds = _folds(w, c, grid, F, beta)
    else:
        Oc = xc = gc = np.empty(0)
        bc, sc = np.empty(0, np.int8), np.empty(0, bool)
        folds = []
    with np.errstate(invalid="ignore"):
        backbone = np.where(np.isfinite(xc), w.omega(np.nan_to_num(np.minimum(xc, top))), np.nan)
    fo = np.array(folds, float).reshape(-1, 4)
    fo[:, 2] = unshear(fo[:, 2], 0.0)

    one = {"units": "1"}
    ds = xr.Dataset(
        {
            "xi": (("Omega", "response"), take(fp.xi), {**one, "long_name": "averaged energy of the steady response"}),
            "gamma": (("Omega", "response"), take(fp.gamma),
                      {"units": "rad", "long_name": "slow phase gamma = theta - Psi - Omega tau of the steady "
                                                    "response"}),
            "J": (("Omega", "response"), take(fp.J), {**one, "long_name": "averaged action of the steady response"}),
            "kind": (("Omega", "response"), kind, {"long_name": "fixed point of the damped slow flow",
                                                   "flag_values": np.arange(len(KINDS), dtype=np.int8),
                                                   "flag_meanings": " ".join(KINDS)}),
            "stable": (("Omega", "response"), (kind == NODE) | (kind == FOCUS),
                       {"long_name": "attracting steady response (stable node or focus)"}),
            "eig_real": (("Omega", "response", "eig"), eig.real,
                         {**one, "long_name": "Jacobian eigenvalue, real part"}),
            "eig_imag": (("Omega", "response", "eig"), eig.imag,
                         {**one, "long_name": "Jacobian eigenvalue, imaginary part"}),
            "n_responses": ("Omega", (kind > 0).sum(axis=1).astype(np.int64),
                            {"long_name": "number of fixed points"}),
            "Omega_curve": ("curve_point", Oc, {**one, "long_name": "forcing frequency along the response curve"}),
            "xi_curve": ("curve_point", xc, {**one, "long_name": "averaged energy along the response curve"}),
            "gamma_curve": ("curve_point", gc, {"units": "rad", "long_name": "slow phase along the response curve"}),
            "branch": ("curve_point", bc, {"long_name": "branch: +1 where cos(gamma + delta) > 0, -1 where < 0"}),
            "stable_curve": ("curve_point", sc, {"long_name": "attracting part of the response curve"}),
            "Omega_backbone": ("curve_point", backbone,
                               {**one, "long_name": "backbone: free frequency omega(xi_curve)"}),
            "Omega_fold": ("fold", fo[:, 0], {**one, "long_name": "forcing frequency of a fold (saddle-node)"}),
            "xi_fold": ("fold", fo[:, 1], {**one, "long_name": "averaged energy of a fold"}),
            "gamma_fold": ("fold", fo[:, 2], {"units": "rad", "long_name": "slow phase of a fold"}),
            "branch_fold": ("fold", fo[:, 3].astype(np.int8), {"long_name": "branch of a fold"}),
        },
        coords={"Omega": ("Omega", Om, {**one, "long_name": "forcing frequency"})},
        attrs={"F": F, "damping": beta, "xi_max": xm, "well": w.name, "fourier": w.fourier,
               "description": "steady responses (fixed points) of the damped slow flow, docs/damping.md"},
    )
    return ds
