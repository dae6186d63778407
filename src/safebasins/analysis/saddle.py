"""The hilltop saddle of the forced well: its periodic orbit, its manifolds and their first tangency.

For ``q'' + beta q' + V'(q) = F sin(Omega t + Psi)`` the hilltop ``(q_b, 0)`` of a barrier persists,
for small F, as a hyperbolic T-periodic orbit (``T = 2 pi / Omega``): a saddle fixed point ``x_s``
of the stroboscopic map ``P`` of phase ``Psi`` (the section ``t = 0`` of an escape chart).  Its
stable manifold bounds the safe basin below the first tangency of the stable and unstable
manifolds; past it the boundary is fractal (docs/melnikov.md).

* :func:`hilltop_orbit`: the orbit by multiple shooting with DOP853
  (:func:`safebasins.analysis.floquet.saddle_orbit`), its Floquet multipliers, and the
  first-order closed form beside it: the linear saddle's response ``q = q_b + Im(a e^{i (Omega t +
  Psi)})``, ``a = F / (-omega_b^2 - Omega^2 + i beta Omega)`` (``omega_b^2 = -V''(q_b)``; undamped:
  ``q_b - F sin(Omega t + Psi) / (omega_b^2 + Omega^2)``), multipliers ``exp(lambda_+- T)``,
  ``lambda_+- = -beta/2 +- sqrt(beta^2/4 + omega_b^2)``, and the mean shift of second order
  ``<q> - q_b = V'''(q_b) |a|^2 / (4 omega_b^2)`` (averaging ``V'''(q_b) xi^2 / 2`` over a period).
* :func:`saddle_manifolds`: the branches of ``W^u`` and ``W^s`` grown on ``P`` from a fundamental
  segment of the eigenvector, ``x_s + s0 |mu|^u e`` for ``u`` in ``[0, 1]``, iterated forward
  (``W^u``) or backward (``W^s``: DOP853 backward in time); intervals in ``u`` are halved until
  every image segment is shorter than ``ds_max`` and turns by less than ``angle_max``.  A point
  that leaves the box around the well, or enters the disc of radius :data:`RETURN_RADIUS` about
  a hilltop ``(q_b, 0)`` (its own or the other barrier's: the first return along a stable
  manifold; beyond it neighbours split over both sides of the saddle and no refinement ends), is
  dropped (NaN).
* :func:`manifold_tangency`: the F of the first tangency of the inner branches of ``W^u`` and
  ``W^s`` (homoclinic: one saddle; heteroclinic: the left saddle's ``W^u``, the right saddle's
  ``W^s``), the root in F of the largest signed distance of ``W^u`` from ``W^s`` (positive:
  outside, on the far side from the well bottom), by Brent's method; beside it the Melnikov
  threshold and the root of the section energy gap of
  :func:`safebasins.analysis.melnikov.manifold_splitting`.
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt
import xarray as xr
from scipy.optimize import brentq
from scipy.spatial import cKDTree

from safebasins.analysis.floquet import (Box, PeriodicOrbit, forced_flow, forced_flow_dense, linear_response,
                                         saddle_orbit, stiffness)
from safebasins.analysis.melnikov import manifold_splitting, melnikov_threshold, separatrix_orbit
from safebasins.core import checks
from safebasins.core.cf import annotate
from safebasins.wells import resolve_well, well_attrs
from safebasins.wells.base import Well, WellLike
from safebasins.wells.provenance import api_provenance

__all__ = ["hilltop_orbit", "saddle_manifolds", "manifold_tangency", "BARRIERS", "RETURN_RADIUS", "default_iterations",
           "signed_gap"]

Array = npt.NDArray[np.float64]

#: which barriers' saddles: "escape" (those of the separatrix that sets the escape energy: one for
#: a homoclinic loop, both for a heteroclinic orbit), "left", "right", "both"
BARRIERS = ("escape", "left", "right", "both")
#: a manifold point is dropped when an iterate brings it from outside to within this distance (of
#: the well's IC-window width) of a hilltop: its first return
RETURN_RADIUS = 0.05
#: the largest distance (of the well's IC-window width) at which W^u points are compared with W^s
_NEAR = 0.05
#: points added around the closest approach per refinement round (manifold_tangency)
_LOCAL = 24
_ONE = {"units": "1"}
#: melnikov's threshold and splitting (not annotated there)
_threshold: Callable[..., Any] = melnikov_threshold
_splitting: Callable[..., Any] = manifold_splitting


def _check_forcing(F: Any, Omega: Any, damping: Any, Psi: Any) -> tuple[float, float, float, float]:
    return (checks.check_scalar("F", F, checks.check_nonnegative),
            checks.check_scalar("Omega", Omega, checks.check_positive),
            checks.check_damping(damping), checks.check_scalar("Psi", Psi, checks.check_finite))


def _saddles(w: Well, barrier: str) -> list[float]:
    """The barrier positions of ``barrier`` (:data:`BARRIERS`)."""
    if barrier not in BARRIERS:
        raise ValueError(f"barrier must be one of {BARRIERS}, got {barrier!r}")
    if barrier == "escape":
        return [float(b) for b in separatrix_orbit(w).saddles]
    lo, hi = (float(b) for b in w.barriers)
    pick = {"left": [lo], "right": [hi], "both": [lo, hi]}[barrier]
    out = [b for b in pick if np.isfinite(b)]
    if not out:
        raise ValueError(f"barrier: the {w.name} well has no {barrier} barrier (barriers at {(lo, hi)})")
    return out


def _directions(orbit: PeriodicOrbit) -> tuple[tuple[float, Array], tuple[float, Array]]:
    dirs = orbit.saddle_directions()
    if dirs is None:                    # saddle_orbit returns saddles only
        raise ValueError(f"the periodic orbit is not a saddle (multipliers {orbit.multipliers})")
    return dirs


def _orbit_row(w: Well, F: float, Om: float, beta: float, Psi: float, qb: float, t: Array,
               rtol: float) -> dict[str, Any]:
    """hilltop_orbit's data of the saddle at qb: the orbit on the times t and its closed forms."""
    orb = saddle_orbit(w, F, Om, beta, Psi, qb, rtol)
    (mu_u, e_u), (mu_s, e_s) = _directions(orb)
    T, m = orb.period, orb.nodes.shape[1]
    dense = forced_flow_dense(w, F, Om, beta, Om * orb.times + Psi, orb.nodes, T / m, rtol)
    seg = np.minimum((t // (T / m)).astype(int), m - 1)        # each instant on its node's segment
    states = np.empty((2, t.size))
    for j in range(m):
        sel = seg == j
        if sel.any():
            states[:, sel] = dense(t[sel] - orb.times[j])[:, j, :]
    ends = dense(np.array([T / m]))[:, :, 0]
    k = stiffness(w, qb)                                           # V''(q_b) < 0
    d3 = (stiffness(w, qb + 1e-4) - stiffness(w, qb - 1e-4)) / 2e-4  # V'''(q_b)
    a = F / (-Om ** 2 + k + 1j * beta * Om)
    lam = -0.5 * beta + np.array([1.0, -1.0]) * np.sqrt(0.25 * beta ** 2 - k)
    return dict(states=states, lin=linear_response(F, Om, beta, Psi, k, t, q_e=qb), fixed=orb.point,
                mu=(mu_u, mu_s), vec=(e_u, e_s), mu_lin=np.exp(lam * T),
                shift=float(np.mean(states[0])) - qb, shift2=d3 * abs(a) ** 2 / (-4.0 * k), residual=orb.residual,
                nodes=m, closure=float(np.max(np.abs(ends - np.roll(orb.nodes, -1, axis=1)))))


@api_provenance
def hilltop_orbit(F: float, Omega: float, damping: float = 0.0, well: WellLike = None, Psi: float = 0.0, *,
                  barrier: str = "escape", n_time: int = 129, rtol: float = 1e-12) -> xr.Dataset:
    """The forced hilltop saddle's T-periodic orbit at each chosen barrier, with its Floquet data.

    Multiple shooting (Newton on the stroboscopic map with ``lambda T / m <= 1`` nodes) with
    DOP853 at ``rtol`` (module docstring); ``barrier`` one of :data:`BARRIERS`.  Returns a Dataset
    over ``saddle`` (coordinate ``q_barrier``) and ``time`` (``n_time`` instants in one period
    ``[0, T)``): ``q``, ``p`` (the orbit), ``q_linear``, ``p_linear`` (the linear saddle's response,
    first order in F); over ``saddle``: ``q_fixed``, ``p_fixed`` (the saddle fixed point of the
    map of phase ``Psi``), ``multiplier_unstable``, ``multiplier_stable`` (real, ``> 1`` and
    ``< 1`` in modulus), ``multiplier_linear_unstable``, ``multiplier_linear_stable``
    (``exp(lambda_+- T)``), ``eigvec_unstable``, ``eigvec_stable`` (over ``component`` = q, p; unit,
    at ``t = 0``), ``mean_shift`` and ``mean_shift_second_order`` (``<q> - q_b`` and
    ``V''' |a|^2 / (4 omega_b^2)``), ``newton_residual``, ``closure`` (the dense orbit's mismatch at
    the nodes).  ValueError naming ``F`` when no hyperbolic orbit continues the hilltop."""
    F, Om, beta, Psi = _check_forcing(F, Omega, damping, Psi)
    n_time = checks.check_positive_int("n_time", n_time)
    rtol = checks.check_scalar("rtol", rtol, checks.check_positive)
    w = resolve_well(well)
    qbs = _saddles(w, barrier)
    T = 2.0 * np.pi / Om
    t = T * np.arange(n_time) / n_time
    rows = [_orbit_row(w, F, Om, beta, Psi, qb, t, rtol) for qb in qbs]

    def col(key: str, i: int | None = None) -> Array:
        return np.array([r[key] if i is None else r[key][i] for r in rows])

    def var(dims: tuple[str, ...], data: Array, long_name: str) -> tuple[tuple[str, ...], Array, dict[str, str]]:
        return dims, data, {**_ONE, "long_name": long_name}

    S, ST, SC = ("saddle",), ("saddle", "time"), ("saddle", "component")
    ds = xr.Dataset(
        {
            "q": var(ST, col("states", 0), "q on the saddle's periodic orbit"),
            "p": var(ST, col("states", 1), "p on the saddle's periodic orbit"),
            "q_linear": var(ST, col("lin", 0), "q of the linear saddle's periodic response (first order in F)"),
            "p_linear": var(ST, col("lin", 1), "p of the linear saddle's periodic response (first order in F)"),
            "q_fixed": var(S, col("fixed", 0), "q of the saddle fixed point of the stroboscopic map"),
            "p_fixed": var(S, col("fixed", 1), "p of the saddle fixed point of the stroboscopic map"),
            "multiplier_unstable": var(S, col("mu", 0), "unstable Floquet multiplier"),
            "multiplier_stable": var(S, col("mu", 1), "stable Floquet multiplier"),
            "multiplier_linear_unstable": var(S, col("mu_lin", 0), "exp(lambda_+ T) of the linear saddle"),
            "multiplier_linear_stable": var(S, col("mu_lin", 1), "exp(lambda_- T) of the linear saddle"),
            "eigvec_unstable": var(SC, col("vec", 0), "unstable eigenvector of the map at the fixed point (q, p)"),
            "eigvec_stable": var(SC, col("vec", 1), "stable eigenvector of the map at the fixed point (q, p)"),
            "mean_shift": var(S, col("shift"), "period mean of q minus the barrier q_b"),
            "mean_shift_second_order": var(S, col("shift2"),
                                           "V'''(q_b) |a|^2 / (4 omega_b^2): the mean shift, second order in F"),
            "newton_residual": var(S, col("residual"), "largest shooting mismatch at the last Newton step"),
            "closure": var(S, col("closure"), "largest mismatch of the dense orbit at the shooting nodes"),
        },
        coords={"saddle": ("saddle", np.arange(len(qbs)), {**_ONE, "long_name": "saddle index"}),
                "q_barrier": ("saddle", np.array(qbs, float), {**_ONE, "long_name": "barrier (hilltop of V) q_b"}),
                "time": ("time", t, {**_ONE, "long_name": "time from the section t = 0 (one forcing period)"}),
                "component": ("component", np.array(["q", "p"]), {"long_name": "state component"})},
        attrs={"title": "periodic orbit of the forced hilltop saddle", **well_attrs(w), "F": F, "Omega": Om,
               "Psi": Psi, "damping": beta, "period": T, "barrier": barrier, "rtol": rtol,
               "shooting_nodes": col("nodes").astype(np.int64),
               "method": "multiple shooting (lambda T / m <= 1 nodes), Newton with central-difference blocks, "
                         "DOP853 (safebasins.analysis.floquet)"})
    return annotate(ds)


# ---------------------------------------------------------------------------------------------
# manifolds
# ---------------------------------------------------------------------------------------------
def _box(w: Well) -> Box:
    """((q_lo, q_hi), (p_lo, p_hi)): the well's window (Well.ic_window) widened by half its width in
    q and twice in p; points of a manifold leave it over a barrier or far outside the well."""
    (lo, hi), (pl, ph) = w.ic_window()
    width = hi - lo
    return (lo - 0.5 * width, hi + 0.5 * width), (2.0 * pl, 2.0 * ph)


class _Branch:
    """One branch of a saddle's manifold: the parameters ``u`` in [0, 1] of its fundamental segment
    and the states of their iterates (iterations + 1, 2, n); NaN once a point has left the box or
    returned to the saddle (module docstring)."""

    def __init__(self, w: Well, forcing: tuple[float, float, float, float], x_s: Array, mu: float, e: Array,
                 forward: bool, iterations: int, s0: float, rtol: float) -> None:
        self.w, self.forcing = w, forcing
        self.x_s, self.e, self.forward, self.K, self.s0, self.rtol = x_s, e, forward, iterations, s0, rtol
        self.box = _box(w)
        (lo, hi), _ = w.ic_window()
        self.r_return = RETURN_RADIUS * (hi - lo)
        self.hilltops = np.array([b for b in w.barriers if np.isfinite(b)], dtype=float)
        self.log_mu = float(np.log(abs(mu)) if forward else -np.log(abs(mu)))   # > 0: the segment grows
        self.u: Array = np.zeros(0)
        self.S: Array = np.zeros((iterations + 1, 2, 0))

    def add(self, u_new: npt.ArrayLike) -> None:
        """Iterate the points of the fundamental segment at the parameters u_new (new ones only)."""
        un = np.setdiff1d(np.asarray(u_new, float), self.u)
        if un.size == 0:
            return
        F, Om, beta, Psi = self.forcing
        T = 2.0 * np.pi / Om
        S = np.full((self.K + 1, 2, un.size), np.nan)
        S[0] = self.x_s[:, None] + (self.s0 * np.exp(self.log_mu * un))[None, :] * self.e[:, None]
        (ql, qh), (pl, ph) = self.box
        alive = np.ones(un.size, bool)
        for k in range(self.K):
            idx = np.flatnonzero(alive)
            if idx.size == 0:
                break
            Y = forced_flow(self.w, F, Om, beta, np.full(idx.size, Psi), S[k][:, idx], T if self.forward else -T,
                            self.rtol, box=self.box)
            r_old = np.hypot(S[k][0, idx][:, None] - self.hilltops, S[k][1, idx][:, None])
            r = np.hypot(Y[0][:, None] - self.hilltops, Y[1][:, None])
            back = ((r < self.r_return) & (r_old >= self.r_return)).any(axis=1)
            keep = (Y[0] >= ql) & (Y[0] <= qh) & (Y[1] >= pl) & (Y[1] <= ph) & ~back
            S[k + 1][:, idx[keep]] = Y[:, keep]
            alive[idx[~keep]] = False
        u = np.concatenate([self.u, un])
        order = np.argsort(u)
        self.u, self.S = u[order], np.concatenate([self.S, S], axis=2)[:, :, order]

    def refine(self, ds_max: float, angle_max: float, max_points: int) -> bool:
        """Halve the u intervals whose image segments are longer than ds_max or turn by more than
        angle_max at an end, until none is (True) or there are max_points (False)."""
        while self.u.size < max_points:
            d = np.diff(self.S, axis=2)                                  # (K + 1, 2, n - 1)
            L = np.hypot(d[:, 0], d[:, 1])
            split = L > ds_max
            cross = d[:, 0, :-1] * d[:, 1, 1:] - d[:, 1, :-1] * d[:, 0, 1:]
            dot = d[:, 0, :-1] * d[:, 0, 1:] + d[:, 1, :-1] * d[:, 1, 1:]
            with np.errstate(invalid="ignore"):
                bent = np.abs(np.arctan2(cross, dot)) > angle_max
            split[:, :-1] |= bent
            split[:, 1:] |= bent
            split &= np.isfinite(L) & (L > 1e-4 * ds_max)              # a kink is not refined forever
            gaps = np.flatnonzero(split.any(axis=0) & (np.diff(self.u) > 1e-12))
            if gaps.size == 0:
                return True
            gaps = gaps[:max(1, max_points - self.u.size)]
            self.add(0.5 * (self.u[gaps] + self.u[gaps + 1]))
        return False

    def polyline(self) -> tuple[Array, npt.NDArray[np.int64], npt.NDArray[np.int64]]:
        """The vertices (n_v, 2) in order (piece k = the k-th iterate of the segment, u ascending),
        with the piece and the index into u of each."""
        K1, n = self.S.shape[0], self.u.size
        pts = np.transpose(self.S, (0, 2, 1)).reshape(-1, 2)
        return pts, np.repeat(np.arange(K1, dtype=np.int64), n), np.tile(np.arange(n, dtype=np.int64), K1)


def default_iterations(mu: float, s0: float) -> int:
    """Iterates that carry the fundamental segment from ``s0`` to the well's scale ``1``, plus one."""
    return int(np.ceil(np.log(1.0 / s0) / abs(np.log(abs(mu))))) + 1


def _grow(w: Well, forcing: tuple[float, float, float, float], q_b: float, side: float, forward: bool, *,
          iterations: int | None, s0: float, ds_max: float, angle_max: float, max_points: int, rtol: float,
          n0: int = 33) -> tuple[_Branch, float]:
    """The branch (:class:`_Branch`) of the saddle at q_b: W^u (forward) or W^s, on the well side
    (side +1) or the outer side (-1), refined; with its multiplier."""
    F, Om, beta, Psi = forcing
    orb = saddle_orbit(w, F, Om, beta, Psi, q_b, rtol)
    (mu_u, e_u), (mu_s, e_s) = _directions(orb)
    mu, e = (mu_u, e_u) if forward else (mu_s, e_s)
    if mu < 0:
        raise ValueError(f"F = {F!r}: the saddle at q = {q_b!r} reverses orientation (multiplier {mu!r}): its "
                         "manifolds need the second iterate of the map, not grown here")
    inward = np.sign(-q_b) if q_b != 0 else 1.0
    e = e * (side * inward * np.sign(e[0]) if e[0] != 0 else 1.0)
    K = iterations if iterations is not None else default_iterations(mu, s0)
    b = _Branch(w, forcing, orb.point, mu, e, forward, K, s0, rtol)
    b.add(np.linspace(0.0, 1.0, n0))
    b.refine(ds_max, angle_max, max_points)
    return b, mu


@api_provenance
def saddle_manifolds(F: float, Omega: float, damping: float = 0.0, well: WellLike = None, Psi: float = 0.0, *,
                     barrier: str = "escape", iterations: int | None = None, s0: float = 1e-7, ds_max: float = 0.02,
                     angle_max: float = 0.1, max_points: int = 20000, rtol: float = 1e-10) -> xr.Dataset:
    """Stable and unstable manifolds of the hilltop saddle(s) on the stroboscopic map of phase Psi.

    For each saddle of ``barrier`` (:data:`BARRIERS`) four branches: ``W^u`` and ``W^s``, each on the
    well side ("inner") and the outer side ("outer") of the saddle, grown from ``s0`` along the
    eigenvector for ``iterations`` iterates of the map (default :func:`default_iterations`) and
    refined to ``ds_max`` / ``angle_max`` with at most ``max_points`` points per branch (module
    docstring).  Points that leave the box around the well (its IC window widened) or return to
    the saddle are dropped.

    Returns a Dataset in the boundary-curve layout (docs/contracts.md): dim ``curve`` with
    ``kind`` ("unstable" | "stable"), ``side`` ("inner" | "outer"), ``q_barrier``, ``multiplier``,
    ``resolved`` (the refinement met ``ds_max`` / ``angle_max`` within ``max_points``); dim
    ``vertex`` with ``q0_vertex``, ``p0_vertex`` (the section ``t = 0``: the plane of the escape
    chart of phase Psi), ``curve_index`` and ``iterate`` (the map iterate the vertex belongs to;
    NaN rows split a curve where points were dropped); over ``saddle``: ``q_fixed``, ``p_fixed``."""
    F, Om, beta, Psi = _check_forcing(F, Omega, damping, Psi)
    w = resolve_well(well)
    if iterations is not None:
        iterations = checks.check_positive_int("iterations", iterations)
    s0 = checks.check_scalar("s0", s0, checks.check_positive)
    ds_max = checks.check_scalar("ds_max", ds_max, checks.check_positive)
    angle_max = checks.check_scalar("angle_max", angle_max, checks.check_positive)
    max_points = checks.check_positive_int("max_points", max_points)
    rtol = checks.check_scalar("rtol", rtol, checks.check_positive)
    qbs = _saddles(w, barrier)
    curves: list[tuple[str, str, float, float, bool, Array, npt.NDArray[np.int64]]] = []
    fixed = []
    for qb in qbs:
        for kind, forward in (("unstable", True), ("stable", False)):
            for side_name, side in (("inner", 1.0), ("outer", -1.0)):
                b, mu = _grow(w, (F, Om, beta, Psi), qb, side, forward, iterations=iterations, s0=s0,
                              ds_max=ds_max, angle_max=angle_max, max_points=max_points, rtol=rtol)
                pts, piece, _ = b.polyline()
                curves.append((kind, side_name, qb, mu, b.u.size < max_points, pts, piece))
        fixed.append(b.x_s)
    C = ("curve",)
    ds = xr.Dataset(
        {
            "kind": (C, np.array([c[0] for c in curves]), {"long_name": "manifold of the saddle (unstable | stable)"}),
            "side": (C, np.array([c[1] for c in curves]),
                     {"long_name": "branch: the well side (inner) or the outer side"}),
            "q_barrier": (C, np.array([c[2] for c in curves]), {**_ONE, "long_name": "barrier q_b of the saddle"}),
            "multiplier": (C, np.array([c[3] for c in curves]),
                           {**_ONE, "long_name": "Floquet multiplier along the manifold"}),
            "resolved": (C, np.array([c[4] for c in curves]),
                         {"long_name": "refined to ds_max and angle_max within max_points"}),
            "q0_vertex": ("vertex", np.concatenate([c[5][:, 0] for c in curves]),
                          {**_ONE, "long_name": "q of the manifold on the section t = 0 (initial displacement)"}),
            "p0_vertex": ("vertex", np.concatenate([c[5][:, 1] for c in curves]),
                          {**_ONE, "long_name": "p of the manifold on the section t = 0 (initial momentum)"}),
            "curve_index": ("vertex", np.concatenate([np.full(c[5].shape[0], i, np.int64)
                                                      for i, c in enumerate(curves)]),
                            {"long_name": "index of the curve a vertex belongs to"}),
            "iterate": ("vertex", np.concatenate([c[6] for c in curves]),
                        {**_ONE, "long_name": "map iterate of the fundamental segment"}),
            "q_fixed": ("saddle", np.array([x[0] for x in fixed]),
                        {**_ONE, "long_name": "q of the saddle fixed point of the stroboscopic map"}),
            "p_fixed": ("saddle", np.array([x[1] for x in fixed]),
                        {**_ONE, "long_name": "p of the saddle fixed point of the stroboscopic map"}),
        },
        attrs={"title": "stable and unstable manifolds of the forced hilltop saddle", **well_attrs(w), "F": F,
               "Omega": Om, "Psi": Psi, "damping": beta, "barrier": barrier, "s0": s0, "ds_max": ds_max,
               "angle_max": angle_max, "max_points": max_points, "rtol": rtol,
               "method": "fundamental segment x_s + s0 |mu|^u e (u in [0, 1]) iterated on the stroboscopic map "
                         "(DOP853; backward in time for W^s), u intervals halved to ds_max / angle_max"})
    return annotate(ds)


# ---------------------------------------------------------------------------------------------
# first tangency
# ---------------------------------------------------------------------------------------------
def signed_gap(Pu: Array, Ps: Array, inside: Array, near: float) -> tuple[float, int, int]:
    """Largest signed distance of the vertices ``Pu`` (n, 2) from the polyline ``Ps`` (m, 2; NaN rows
    split it), over the vertices within ``near`` of it whose foot lies inside a segment; positive on
    the side away from ``inside`` (a point on the well side).  Returns (gap, index into Pu, segment
    index of Ps); ``(-near, -1, -1)`` when no vertex is that near."""
    A, B = Ps[:-1], Ps[1:]
    d = B - A
    L2 = np.einsum("ij,ij->i", d, d)
    seg_ok = np.isfinite(L2) & (L2 > 0)
    seg_ids = np.flatnonzero(seg_ok)
    ok_u = np.flatnonzero(np.isfinite(Pu).all(axis=1))
    if seg_ids.size == 0 or ok_u.size == 0:
        return -near, -1, -1
    tree = cKDTree(0.5 * (A + B)[seg_ok])
    k_in = seg_ids[tree.query(inside)[1]]          # the well's side: the segment nearest to `inside`
    orient = np.sign(d[k_in, 0] * (inside[1] - A[k_in, 1]) - d[k_in, 1] * (inside[0] - A[k_in, 0]))
    cand = tree.query_ball_point(Pu[ok_u], near + 0.5 * np.sqrt(L2[seg_ok].max()))
    ii = np.concatenate([np.full(len(c), r, np.int64) for r, c in zip(ok_u, cand)])
    if ii.size == 0:
        return -near, -1, -1
    jj = seg_ids[np.concatenate([np.asarray(c, np.int64) for c in cand])]
    x = Pu[ii] - A[jj]
    t = np.einsum("ij,ij->i", x, d[jj]) / L2[jj]
    cross = d[jj, 0] * x[:, 1] - d[jj, 1] * x[:, 0]
    dist = np.where((t >= 0) & (t <= 1), np.abs(cross) / np.sqrt(L2[jj]), np.inf)
    order = np.lexsort((dist, ii))                 # each vertex: its nearest segment with an inner foot
    sel = order[np.r_[True, ii[order][1:] != ii[order][:-1]]]
    sel = sel[dist[sel] < near]
    if sel.size == 0:
        return -near, -1, -1
    signed = -orient * np.sign(cross[sel]) * dist[sel]
    k = int(np.argmax(signed))
    return float(signed[k]), int(ii[sel[k]]), int(jj[sel[k]])


def _tangency_gap(w: Well, forcing: tuple[float, float, float, float], pair: tuple[float, float],
                  opts: dict[str, Any], rounds: int = 3) -> float:
    """Largest signed distance of the inner W^u of saddle pair[0] from the inner W^s of pair[1]
    (positive: they intersect), with ``rounds`` local refinements around the closest approach."""
    bu, _ = _grow(w, forcing, pair[0], 1.0, True, **opts)
    bs, _ = _grow(w, forcing, pair[1], 1.0, False, **opts)
    (lo, hi), _ = w.ic_window()
    near = _NEAR * (hi - lo)
    inside = np.zeros(2)                           # the well bottom
    gap = -near
    for r in range(rounds + 1):
        Pu, _, iu = bu.polyline()
        Ps, _, is_ = bs.polyline()
        gap, i, j = signed_gap(Pu, Ps, inside, near)
        if r == rounds or i < 0:
            break
        for b, k_idx in ((bu, int(iu[i])), (bs, int(is_[j]))):
            b.add(np.linspace(b.u[max(k_idx - 1, 0)], b.u[min(k_idx + 2, b.u.size - 1)], _LOCAL + 2)[1:-1])
    return gap


@api_provenance
def manifold_tangency(Omega: float, damping: float, well: WellLike = None, Psi: float = 0.0, *,
                      F_bracket: tuple[float, float] | None = None, xtol: float = 1e-7, s0: float = 1e-7,
                      ds_max: float = 0.01, angle_max: float = 0.05, max_points: int = 5000, rtol: float = 1e-10,
                      splitting: bool = True, n_phase: int = 48) -> xr.Dataset:
    """F of the first tangency of the hilltop saddle's stable and unstable manifolds (module docstring).

    The signed gap of the inner ``W^u`` from the inner ``W^s`` (grown with ``s0``, ``ds_max``,
    ``angle_max``, ``max_points``, ``rtol``, then refined three times around their closest approach)
    is negative while ``W^u`` lies inside ``W^s`` and changes sign at the tangency; its root in F by
    Brent's method to ``xtol``, in ``F_bracket`` (default ``(0.5, 1.25) F_M``: far past the tangency
    the tangle makes every evaluation slow).  With ``splitting``
    also the root of the largest section energy gap of
    :func:`~safebasins.analysis.melnikov.manifold_splitting` (``n_phase`` start times), an
    independent numeric route.

    Returns a Dataset of scalars ``F_tangency``, ``F_melnikov``, ``F_splitting`` (NaN without
    ``splitting`` or when the energy gap does not change sign in the bracket),
    ``tangency_ratio`` = F_tangency / F_M, ``splitting_ratio`` = F_splitting / F_M;
    over ``evaluation``: ``F_evaluated``, ``gap`` (every F Brent tried and its signed gap).
    ValueError naming ``F_bracket`` when the gap does not change sign in it, naming ``damping`` for 0
    (the undamped manifolds intersect for every F > 0: the threshold is 0)."""
    Om = checks.check_scalar("Omega", Omega, checks.check_positive)
    beta = checks.check_damping(damping)
    Psi = checks.check_scalar("Psi", Psi, checks.check_finite)
    if beta == 0:
        raise ValueError("damping: without damping the manifolds intersect for every F > 0 (the tangency is at F = 0)")
    w = resolve_well(well)
    orbit = separatrix_orbit(w)
    pair = (float(orbit.saddles[0]), float(orbit.saddles[-1]))
    FM = float(_threshold(Om, beta, w))
    if F_bracket is None:
        lo, hi = 0.5 * FM, 1.25 * FM
    else:
        fb = checks.check_nonnegative("F_bracket", F_bracket).ravel()
        if fb.size != 2 or not fb[0] < fb[1]:
            raise ValueError(f"F_bracket must be (F_lo, F_hi) with F_lo < F_hi, got {F_bracket!r}")
        lo, hi = float(fb[0]), float(fb[1])
    opts: dict[str, Any] = dict(
        iterations=None, s0=checks.check_scalar("s0", s0, checks.check_positive),
        ds_max=checks.check_scalar("ds_max", ds_max, checks.check_positive),
        angle_max=checks.check_scalar("angle_max", angle_max, checks.check_positive),
        max_points=checks.check_positive_int("max_points", max_points),
        rtol=checks.check_scalar("rtol", rtol, checks.check_positive))
    xtol = checks.check_scalar("xtol", xtol, checks.check_positive)
    n_phase = checks.check_positive_int("n_phase", n_phase)
    seen: list[tuple[float, float]] = []

    def gap(F: float) -> float:
        g = _tangency_gap(w, (F, Om, beta, Psi), pair, opts)
        seen.append((F, g))
        return g

    g_lo, g_hi = gap(lo), gap(hi)
    if not (g_lo < 0 < g_hi):
        raise ValueError(f"F_bracket: the manifolds' gap does not change sign in [{lo!r}, {hi!r}] (gaps {g_lo:.3g}, "
                         f"{g_hi:.3g}); give a bracket around the first tangency")
    F_star = float(brentq(gap, lo, hi, xtol=xtol))
    F_split = np.nan
    if splitting:
        def split(F: float) -> float:
            return float(_splitting(F, Om, beta, w, Psi, n_phase=n_phase).attrs["max_energy_gap"])
        s_lo, s_hi = split(lo), split(hi)
        if s_lo < 0 < s_hi:                             # else its root is not in the bracket: NaN
            F_split = float(brentq(split, lo, hi, xtol=xtol))
    seen.sort()
    E = ("evaluation",)
    ds = xr.Dataset(
        {
            "F_tangency": ((), F_star, {**_ONE, "long_name": "F of the first tangency of the saddle's manifolds "
                                                             "(grown on the stroboscopic map)"}),
            "F_melnikov": ((), FM, {**_ONE, "long_name": "Melnikov threshold (first order in F and beta)"}),
            "F_splitting": ((), F_split, {**_ONE, "long_name": "root of the largest section energy gap "
                                                                "(melnikov.manifold_splitting)"}),
            "tangency_ratio": ((), F_star / FM, {**_ONE, "long_name": "F_tangency / F_melnikov"}),
            "splitting_ratio": ((), F_split / FM, {**_ONE, "long_name": "F_splitting / F_melnikov"}),
            "F_evaluated": (E, np.array([s[0] for s in seen]), {**_ONE, "long_name": "F where the gap was computed"}),
            "gap": (E, np.array([s[1] for s in seen]),
                    {**_ONE, "long_name": "largest signed distance of W^u from W^s (positive: they intersect)"}),
        },
        attrs={"title": "first tangency of the hilltop saddle's manifolds", **well_attrs(w), "Omega": Om, "Psi": Psi,
               "damping": beta, "orbit": orbit.kind, "saddles": np.array(orbit.saddles, float), "xtol": xtol,
               "s0": opts["s0"], "ds_max": opts["ds_max"], "angle_max": opts["angle_max"], "rtol": opts["rtol"],
               "method": "Brent in F on the largest signed distance of the inner W^u from the inner W^s "
                         "(safebasins.analysis.saddle)"})
    return annotate(ds)
