"""Orbits of an area-preserving (period) map: rotation numbers, island chains, chaotic orbits.

Used for the stroboscopic map of eq (29) (Fig 18), but every function takes plain arrays of
iterates (or a map as a Python callable) and knows nothing about eq (1).

Rotation number about a centre
------------------------------
For an orbit ``x_n = (q_n, p_n)``, n = 0..N, around a centre ``c`` (the elliptic fixed point of
the main island), the angle ``theta_n = atan2(p_n - c_p, q_n - c_q)`` advances by
``d_n = wrap(theta_{n+1} - theta_n)`` (wrapped to (-pi, pi]) per iteration.  The rotation number
is the *weighted Birkhoff average* of ``d_n / 2 pi`` (counter-clockwise turns per iteration)
with the bump weight ``w(t) = exp(-1 / (t (1 - t)))`` (Das, Saiki, Sander & Yorke,
Nonlinearity 30 (2017) 4111).  On an invariant circle or an island torus the weighted average
converges faster than any power of N; on a chaotic orbit it does not converge.
``digits = -log10 |rho_1 - rho_2|`` of the averages over the first and second halves of the
orbit measures the convergence: regular orbits reach 7-16 digits in a few thousand
iterations, chaotic ones 1-4 (they fill an area instead of a curve).

Island chains
-------------
An orbit on an island chain of period k visits k islands in turn: each of its k sub-orbits
``x_{j + n k}`` stays in one island, and its rotation number is rational, ``rho = m / k`` (m
turns about the centre in k iterations; m = 0 for a chain that does not encircle the centre).
:func:`island_chains` takes the smallest k whose sub-orbits are narrow and have pairwise
disjoint bounding boxes, and requires ``k rho`` to be an integer; an orbit on a torus of the
main island fails the first test (its sub-orbits rotate by ``k rho mod 1`` per step and cover
the whole curve).

Periodic orbits
---------------
:func:`periodic_orbit` solves ``P^k(x) = x`` by Newton's method with a central-difference
Jacobian; its monodromy trace tells elliptic (``|tr| < 2``) from hyperbolic points, and
:func:`minimal_period` checks that no j < k already closes the orbit.  :func:`chain_orbits`
confirms every chain found from orbit statistics by an elliptic periodic orbit of the same
minimal period found this way (independent route), started at the island centroid.
"""
from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.core import checks
from safebasins.wells.provenance import api_provenance
from safebasins.numerics import stroboscopic_map, escape_chart
from safebasins.analysis.safe import Criterion
from safebasins.wells.base import WellLike

Array = npt.NDArray[np.float64]
#: one iteration of a map, ``step(q, p) -> (q', p')`` on arrays
Step = Callable[[Array, Array], tuple[Array, Array]]

__all__ = ["birkhoff_weights", "weighted_birkhoff", "rotation_numbers", "island_chains", "classify_orbits",
           "portrait_with_criteria",
           "periodic_orbit", "minimal_period", "strobe_step", "chain_orbits", "period_map_portrait",
           "ORBIT_CLASSES"]

#: orbit classes of :func:`classify_orbits` (flag values of the ``orbit_class`` variable)
ORBIT_CLASSES = {0: "escaped", 1: "main island", 2: "island chain", 3: "chaotic"}

MAX_DIGITS = 16.0


def birkhoff_weights(n: int) -> Array:
    """Normalised bump weights ``exp(-1 / (t (1 - t)))`` at t = (i + 1/2) / n, i = 0..n-1."""
    n = checks.check_positive_int("n", n)
    t = (np.arange(n) + 0.5) / n
    w = np.exp(-1.0 / (t * (1.0 - t)))
    return w / w.sum()


def weighted_birkhoff(values: npt.ArrayLike, axis: int = -1) -> Array | np.float64:
    """Weighted Birkhoff average of ``values`` along ``axis`` (bump weights, see module doc)."""
    v = np.moveaxis(np.asarray(values, float), axis, -1)
    if v.shape[-1] < 1:
        raise ValueError("values: need at least one element along the averaged axis")
    return (v * birkhoff_weights(v.shape[-1])).sum(axis=-1)


def _angle_steps(q, p, center):
    """Clockwise angle increments (turns) about ``center`` of each orbit (rows)."""
    th = np.arctan2(p - center[1], q - center[0])
    d = np.diff(th, axis=-1)
    d = (d + np.pi) % (2 * np.pi) - np.pi
    return d / (2 * np.pi)


def _orbits(q: npt.ArrayLike, p: npt.ArrayLike) -> tuple[Array, Array]:
    q = np.atleast_2d(np.asarray(q, float))
    p = np.atleast_2d(np.asarray(p, float))
    if q.shape != p.shape:
        raise ValueError(f"q and p must have the same shape, got {q.shape} and {p.shape}")
    if q.shape[-1] < 5:
        raise ValueError(f"q, p: need at least 5 iterates per orbit, got {q.shape[-1]}")
    return q, p


def rotation_numbers(q: npt.ArrayLike, p: npt.ArrayLike, center: npt.ArrayLike) -> tuple[Array, Array]:
    """Rotation number about ``center`` and its convergence digits, per orbit.

    Parameters
    ----------
    q, p
        Iterates, shape (orbits, N + 1) (or (N + 1,) for one orbit); orbits containing NaN
        (escaped) give NaN.
    center
        (q_c, p_c), e.g. the elliptic fixed point of the main island.

    Returns
    -------
    rho, digits
        Clockwise turns per iteration (weighted Birkhoff average over the whole orbit) and
        ``-log10`` of the difference of the averages over the two halves (capped at 16).
    """
    q, p = _orbits(q, p)
    c = checks.check_finite("center", center).ravel()
    if c.size != 2:
        raise ValueError(f"center must be a point (q, p), got {center!r}")
    d = _angle_steps(q, p, c)
    ok = np.isfinite(d).all(axis=-1)
    rho = np.full(q.shape[0], np.nan)
    digits = np.full(q.shape[0], np.nan)
    if ok.any():
        dd = d[ok]
        h = dd.shape[-1] // 2
        rho[ok] = weighted_birkhoff(dd)
        diff = np.abs(weighted_birkhoff(dd[:, :h]) - weighted_birkhoff(dd[:, h:2 * h]))
        with np.errstate(divide="ignore"):
            digits[ok] = np.minimum(-np.log10(diff), MAX_DIGITS)
    return rho, digits


def island_chains(q: npt.ArrayLike, p: npt.ArrayLike, rho: npt.ArrayLike, digits: npt.ArrayLike, *,
                  max_period: int = 40, confine: float = 0.5, rational_tol: float = 1e-6, min_digits: float = 5.0
                  ) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
    """Period k and winding m of the island chain each regular orbit lies on (0, 0 if none).

    A regular orbit (``digits >= min_digits``) lies on a chain of period k (2 <= k <=
    ``max_period``, the smallest such k) when its k sub-orbits ``x_{j + n k}`` are confined to
    k separate islands (each sub-orbit narrower than ``confine`` times the whole orbit, the
    sub-orbit centroids further apart than the widest sub-orbit) and its rotation number is
    rational with that denominator, ``|k rho - m| < k rational_tol`` (m = the turns about the
    centre in k iterations; 0 for a chain that does not encircle the centre).
    """
    q, p = _orbits(q, p)
    rho = np.atleast_1d(np.asarray(rho, float))
    digits = np.atleast_1d(np.asarray(digits, float))
    max_period = checks.check_positive_int("max_period", max_period)
    period = np.zeros(q.shape[0], np.int64)
    winding = np.zeros(q.shape[0], np.int64)
    for i in range(q.shape[0]):
        if not (np.isfinite(rho[i]) and digits[i] >= min_digits):
            continue
        k = _island_period(q[i], p[i], max_period, confine)
        if k and abs(k * rho[i] - round(k * rho[i])) < k * rational_tol:
            period[i], winding[i] = k, int(round(k * rho[i]))
    return period, winding


def classify_orbits(q: npt.ArrayLike, p: npt.ArrayLike, center: npt.ArrayLike, *, min_digits: float = 5.0,
                    max_period: int = 40, confine: float = 0.5, rational_tol: float = 1e-6
                    ) -> dict[str, npt.NDArray[Any]]:
    """Rotation number, convergence digits, chain period / winding and class of every orbit.

    Classes (:data:`ORBIT_CLASSES`): 0 escaped (NaN iterates), 1 main island (regular, winds
    around ``center``), 2 island chain (:func:`island_chains`), 3 chaotic (``digits <
    min_digits``: the rotation number does not converge, the orbit fills an area).

    Returns a dict of arrays over the orbits: ``rotation_number``, ``birkhoff_digits``,
    ``chain_period``, ``chain_winding``, ``orbit_class``.
    """
    q, p = _orbits(q, p)
    rho, digits = rotation_numbers(q, p, center)
    period, winding = island_chains(q, p, rho, digits, max_period=max_period, confine=confine,
                                    rational_tol=rational_tol, min_digits=min_digits)
    cls = np.where(~np.isfinite(rho), 0, np.where(digits < min_digits, 3, np.where(period > 0, 2, 1)))
    return dict(rotation_number=rho, birkhoff_digits=digits, chain_period=period, chain_winding=winding,
                orbit_class=cls.astype(np.int8))


def _iterate(step, x, k):
    q, p = np.asarray(x[..., 0], float), np.asarray(x[..., 1], float)
    for _ in range(k):
        q, p = step(q, p)
        q, p = np.asarray(q, float), np.asarray(p, float)
    return np.stack([q, p], axis=-1)


def periodic_orbit(step: Step, x0: npt.ArrayLike, period: int, *, h: float = 1e-7, tol: float = 1e-11,
                   max_iter: int = 40) -> tuple[Array, float, float] | None:
    """Newton's method for ``P^period(x) = x``.

    Parameters
    ----------
    step
        The map, ``step(q, p) -> (q', p')`` on arrays (vectorised: the five points of the
        central-difference Jacobian go through one call per iteration).
    x0
        Starting point (q, p).

    Returns
    -------
    tuple or None
        ``(x, trace, residual)`` (``trace`` of the monodromy matrix D P^period at x: elliptic
        if ``|trace| < 2``) or None if Newton does not converge (or the orbit leaves the map's
        domain: NaN iterates).
    """
    period = checks.check_positive_int("period", period)
    x = checks.check_finite("x0", x0).ravel().astype(float)
    if x.size != 2:
        raise ValueError(f"x0 must be a point (q, p), got {x0!r}")
    for _ in range(max_iter):
        pts = np.array([x, x + [h, 0], x - [h, 0], x + [0, h], x - [0, h]])
        y = _iterate(step, pts, period)
        if not np.isfinite(y).all():
            return None
        M = np.column_stack([(y[1] - y[2]) / (2 * h), (y[3] - y[4]) / (2 * h)])
        f = y[0] - x
        try:
            dx = np.linalg.solve(M - np.eye(2), -f)
        except np.linalg.LinAlgError:
            return None
        x = x + dx
        if np.abs(dx).max() < tol:
            y = _iterate(step, x[None, :], period)[0]
            return x, float(np.trace(M)), float(np.abs(y - x).max())
    return None


def minimal_period(step: Step, x: npt.ArrayLike, max_period: int, *, tol: float = 1e-8) -> int:
    """Smallest j <= max_period with ``|P^j(x) - x| < tol`` (0 if none)."""
    max_period = checks.check_positive_int("max_period", max_period)
    y = np.asarray(x, float).reshape(1, 2)
    x = y.copy()
    for j in range(1, max_period + 1):
        y = _iterate(step, y, 1)
        if not np.isfinite(y).all():
            return 0
        if np.abs(y - x).max() < tol:
            return j
    return 0


def _island_period(q, p, max_period, confine):
    """Smallest k in 2..max_period such that the k sub-orbits ``x_{j + n k}`` lie in k separate
    islands: each sub-orbit is narrower than ``confine`` times the whole orbit and the bounding
    boxes of the k sub-orbits are pairwise disjoint (0 if no such k)."""
    full = np.hypot(np.ptp(q), np.ptp(p))
    if not np.isfinite(full) or full == 0:
        return 0
    for k in range(2, max_period + 1):
        if q.size < 4 * k:
            break
        qs = [q[j::k] for j in range(k)]
        ps = [p[j::k] for j in range(k)]
        if max(np.hypot(np.ptp(a), np.ptp(b)) for a, b in zip(qs, ps)) >= confine * full:
            continue
        lo_q, hi_q = np.array([a.min() for a in qs]), np.array([a.max() for a in qs])
        lo_p, hi_p = np.array([b.min() for b in ps]), np.array([b.max() for b in ps])
        overlap = ((lo_q[:, None] < hi_q[None, :]) & (lo_q[None, :] < hi_q[:, None])
                   & (lo_p[:, None] < hi_p[None, :]) & (lo_p[None, :] < hi_p[:, None]))
        overlap[np.diag_indices(k)] = False
        if not overlap.any():
            return k
    return 0


def strobe_step(F: float, Omega: float, Psi: float, *, xi_max: float | None = None, q_max: float | None = None,
                steps_per_cycle: int | None = None, integrator: str | None = None, well: WellLike = None) -> Step:
    """The period map of eq (29) as ``step(q, p) -> (q', p')`` (NaN once a threshold is crossed),
    for :func:`periodic_orbit` and :func:`minimal_period`; ``well``: the well of eq (1) (None: the
    paper's quartic; see ``numerics.stroboscopic_map``)."""
    kw: dict[str, Any] = {k: v for k, v in (("steps_per_cycle", steps_per_cycle), ("integrator", integrator))
                          if v is not None}

    def step(q, p):
        q, p = np.atleast_1d(np.asarray(q, float)), np.atleast_1d(np.asarray(p, float))
        qn, pn = np.full(q.shape, np.nan), np.full(p.shape, np.nan)
        ok = np.isfinite(q) & np.isfinite(p)
        if ok.any():
            d = stroboscopic_map(q[ok], p[ok], F, Omega, Psi, n_iter=1, xi_max=xi_max, q_max=q_max, well=well,
                                 **kw)
            qn[ok], pn[ok] = d["q"].values[:, 1], d["p"].values[:, 1]
        return qn, pn

    return step


def _orbit_points(step, x, k):
    pts = [np.asarray(x, float)]
    for _ in range(k - 1):
        q, p = step(pts[-1][:1], pts[-1][1:])
        pts.append(np.array([q[0], p[0]]))
    return np.array(pts)


def chain_orbits(step: Step, q: npt.ArrayLike, p: npt.ArrayLike, period: npt.ArrayLike, *, max_period: int = 40,
                 same_tol: float = 1e-6) -> tuple[npt.NDArray[np.int64], list[dict[str, Any]]]:
    """The periodic orbits at the centres of the island chains (independent check of the
    periods found from orbit statistics by :func:`island_chains`).

    For every orbit with ``period[i] = k > 0`` not yet explained, Newton's method on ``P^k``
    (:func:`periodic_orbit`) starts at the centroid of the sub-orbit ``x_{i, n k}``; a converged,
    elliptic point whose minimal period (:func:`minimal_period`) is k defines a chain, and
    orbits whose islands (sub-orbit bounding boxes) each hold a point of a found chain, or whose
    Newton point lies on it, join it (the centroids of the k islands are tried in turn until
    one converges).

    Returns ``(chain_of_orbit, chains)``: per-orbit chain index (-1: none / not confirmed) and a
    list of dicts ``period``, ``points`` (k x 2, the elliptic periodic orbit in map order),
    ``trace`` (monodromy trace), ``minimal_period`` (Newton route), ``residual``.
    """
    q, p = _orbits(q, p)
    period = np.atleast_1d(np.asarray(period, np.int64))
    chains: list[dict[str, Any]] = []
    member = np.full(q.shape[0], -1, np.int64)
    def contains(i, ch):
        """Every island (sub-orbit bounding box) of orbit i holds a point of chain ch."""
        k = ch["period"]
        for j in range(k):
            a, b = q[i, j::k], p[i, j::k]
            inside = ((ch["points"][:, 0] >= np.nanmin(a)) & (ch["points"][:, 0] <= np.nanmax(a))
                      & (ch["points"][:, 1] >= np.nanmin(b)) & (ch["points"][:, 1] <= np.nanmax(b)))
            if not inside.any():
                return False
        return True

    for i in np.flatnonzero(period > 0):
        k = int(period[i])
        known = next((c for c, ch in enumerate(chains) if ch["period"] == k and contains(i, ch)), None)
        if known is not None:
            member[i] = known
            continue
        for j in range(k):  # the centroid of an arc-shaped island can lie outside it: try each island
            x0 = np.array([np.nanmean(q[i, j::k]), np.nanmean(p[i, j::k])])
            sol = periodic_orbit(step, x0, k)
            if sol is None:
                continue
            x, tr, res = sol
            hit = next((c for c, ch in enumerate(chains)
                        if ch["period"] == k and np.abs(ch["points"] - x).max(axis=1).min() < same_tol), None)
            if hit is None:
                if not abs(tr) < 2 or minimal_period(step, x, max_period) != k:
                    continue
                chains.append(dict(period=k, points=_orbit_points(step, x, k), trace=tr, minimal_period=k,
                                   residual=res))
                hit = len(chains) - 1
            member[i] = hit
            break
    for i in np.flatnonzero((period > 0) & (member < 0)):  # islands around a chain found later
        member[i] = next((c for c, ch in enumerate(chains) if ch["period"] == period[i] and contains(i, ch)), -1)
    return member, chains


@api_provenance
def period_map_portrait(q0: npt.ArrayLike, p0: npt.ArrayLike, F: float, Omega: float, Psi: float, *, n_keep: int,
                        n_iter: int = 3000, xi_max: float | None = None, q_max: float | None = None,
                        steps_per_cycle: int | None = None, threads: int | None = None, min_digits: float = 5.0,
                        max_period: int = 40, confine: float = 0.5, rational_tol: float = 1e-6,
                        well: WellLike = None) -> xr.Dataset:
    """Stroboscopic map of the first ``n_keep`` non-escaping candidates, classified.

    The centre of the main island is the elliptic fixed point of the map found by Newton's
    method (:func:`periodic_orbit`, period 1) from the median centroid of the kept orbits (then
    from each orbit's centroid, smallest orbit first).
    Every kept orbit gets its rotation number about it, its convergence digits, its chain
    period / winding and its class (:func:`classify_orbits`); chains are confirmed by the
    Newton route (:func:`chain_orbits`).

    Parameters
    ----------
    q0, p0
        Candidate ICs in priority order (e.g. a line of ICs first, then seeded random ones).
    xi_max, q_max
        Escape thresholds of the map (energy H0 > xi_max or q beyond a barrier;
        displacement ``|q| > q_max``); at least one.
    well
        The well of eq (1) (None: the paper's quartic; a polynomial well, see
        ``numerics.stroboscopic_map``).

    Returns
    -------
    xr.Dataset
        Over (``sample``, ``iteration``): ``q``, ``p``, ``q0``, ``p0``,
        ``candidate`` (index into the candidates), ``escape_cycle``, ``rotation_number``,
        ``birkhoff_digits``, ``period``, ``winding``, ``orbit_class``, ``chain_index``; over
        ``chain`` (and ``island``): ``chain_period``, ``chain_winding``, ``chain_trace``,
        ``chain_minimal_period``, ``chain_n_orbits``, ``chain_q``, ``chain_p`` (the elliptic
        periodic orbit, NaN-padded); attributes ``center_q``, ``center_p``, ``center_trace``,
        ``center_rotation`` (rotation number of the linearised map at the centre), the counts
        ``n_candidates``, ``n_non_escaping``, ``n_main``, ``n_chain``, ``n_chaotic`` and the
        classification settings.
    """


    n_keep = checks.check_positive_int("n_keep", n_keep)
    kw: dict[str, Any] = {} if steps_per_cycle is None else {"steps_per_cycle": steps_per_cycle}
    ds = stroboscopic_map(q0, p0, F, Omega, Psi, n_iter=n_iter, xi_max=xi_max, q_max=q_max, threads=threads,
                          well=well, **kw)
    safe = np.flatnonzero(~np.asarray(ds["escaped"].values, dtype=bool))
    if safe.size < n_keep:
        raise ValueError(f"only {safe.size} of {ds.sizes['sample']} candidates never escape in {n_iter} "
                         f"iterations, {n_keep} requested: draw more candidates")
    keep = safe[:n_keep]
    out = ds.isel(sample=keep)
    out = out.assign_coords(candidate=("sample", keep), sample=np.arange(keep.size))
    q = np.asarray(out["q"].values, float)
    p = np.asarray(out["p"].values, float)
    step = strobe_step(F, Omega, Psi, xi_max=xi_max, q_max=q_max, well=well, **kw)
    # Newton from the median orbit centroid, then from the centroids of the orbits, smallest first
    cq, cp = q.mean(axis=1), p.mean(axis=1)
    size = np.hypot(np.ptp(q, axis=1), np.ptp(p, axis=1))
    starts = [np.array([np.median(cq), np.median(cp)])] + [np.array([cq[i], cp[i]]) for i in np.argsort(size)]
    for guess in starts:
        sol = periodic_orbit(step, guess, 1)
        if sol is not None and abs(sol[1]) < 2:
            break
    else:
        raise ValueError("no elliptic fixed point of the period map found from the centroids of the kept orbits")
    center, tr, _ = sol
    cls = classify_orbits(q, p, center, min_digits=min_digits, max_period=max_period, confine=confine,
                          rational_tol=rational_tol)
    member, chains = chain_orbits(step, q, p, cls["chain_period"], max_period=max_period)
    flags = sorted(ORBIT_CLASSES)
    out["rotation_number"] = ("sample", cls["rotation_number"], {
        "units": "1", "long_name": "rotation number about the central fixed point (counter-clockwise turns per "
                                   "iteration, weighted Birkhoff average)"})
    out["birkhoff_digits"] = ("sample", cls["birkhoff_digits"], {
        "units": "1", "long_name": "-log10 |difference of the rotation numbers of the two halves of the orbit|"})
    out["period"] = ("sample", cls["chain_period"], {
        "units": "1", "long_name": "period k of the island chain the orbit lies on (0: none)"})
    out["winding"] = ("sample", cls["chain_winding"], {
        "units": "1", "long_name": "turns about the central fixed point in one chain period"})
    out["orbit_class"] = ("sample", cls["orbit_class"], {
        "long_name": "orbit class", "flag_values": np.array(flags, np.int8),
        "flag_meanings": " ".join(ORBIT_CLASSES[f].replace(" ", "_") for f in flags)})
    out["chain_index"] = ("sample", member, {"units": "1", "long_name": "index of the orbit's chain (-1: none)"})
    nk = max([c["period"] for c in chains], default=1)
    cq = np.full((len(chains), nk), np.nan)
    cp = np.full((len(chains), nk), np.nan)
    for c, ch in enumerate(chains):
        cq[c, :ch["period"]] = ch["points"][:, 0]
        cp[c, :ch["period"]] = ch["points"][:, 1]
    winding = [int(np.bincount(cls["chain_winding"][member == c] - cls["chain_winding"].min()).argmax()
                   + cls["chain_winding"].min()) for c in range(len(chains))]
    out["chain_period"] = ("chain", np.array([c["period"] for c in chains], np.int64),
                           {"units": "1", "long_name": "period of the island chain (iterations of the map)"})
    out["chain_winding"] = ("chain", np.array(winding, np.int64),
                            {"units": "1", "long_name": "turns about the central fixed point in one period"})
    out["chain_trace"] = ("chain", np.array([c["trace"] for c in chains], float),
                          {"units": "1", "long_name": "trace of the monodromy matrix of the periodic orbit"})
    out["chain_minimal_period"] = ("chain", np.array([c["minimal_period"] for c in chains], np.int64),
                                   {"units": "1", "long_name": "minimal period of the Newton periodic orbit"})
    out["chain_n_orbits"] = ("chain", np.array([(member == c).sum() for c in range(len(chains))], np.int64),
                             {"units": "1", "long_name": "number of drawn orbits on the chain"})
    out["chain_q"] = (("chain", "island"), cq, {"units": "1", "long_name": "q of the chain's elliptic periodic orbit"})
    out["chain_p"] = (("chain", "island"), cp, {"units": "1", "long_name": "p of the chain's elliptic periodic orbit"})
    c_ = cls["orbit_class"]
    out.attrs.update(
        center_q=float(center[0]), center_p=float(center[1]), center_trace=float(tr),
        center_rotation=float(np.arccos(np.clip(tr / 2, -1, 1)) / (2 * np.pi)),
        n_candidates=int(ds.sizes["sample"]), n_non_escaping=int(safe.size),
        n_main=int((c_ == 1).sum()), n_chain=int((c_ == 2).sum()), n_chaotic=int((c_ == 3).sum()),
        min_digits=float(min_digits), max_period=int(max_period), confine=float(confine),
        rational_tol=float(rational_tol),
        classification=("rotation number about the central fixed point by weighted Birkhoff averages; "
                        "chaotic: birkhoff_digits < min_digits; chain of period k: k sub-orbits in k "
                        "disjoint islands and k * rotation_number integral, confirmed by an elliptic "
                        "periodic orbit of minimal period k (Newton on the k-th iterate)"))
    return out


def portrait_with_criteria(q0: npt.ArrayLike, p0: npt.ArrayLike, origin: Sequence[str], F: float, Omega: float,
                           Psi: float, *, criterion: Criterion, xi_max: float, q_max: float, n_keep: int, n_iter: int,
                           steps_per_cycle: int, threads: int | None = None, min_digits: float = 5.0,
                           max_period: int = 40) -> xr.Dataset:
    """Fig 18: :func:`period_map_portrait` of the candidates (q0, p0) under one escape
    ``criterion`` ("energy": H0 > xi_max, "displacement": ``|q| > q_max``), with each kept orbit's
    ``origin`` label and its escape cycle under BOTH criteria (``escape_cycle_energy``,
    ``escape_cycle_displacement``: one escape chart of the kept ICs, paired samples)."""
    thresholds: dict[str, Any] = dict(xi_max=xi_max) if criterion == "energy" else dict(q_max=q_max)
    out = period_map_portrait(q0, p0, F, Omega, Psi, n_keep=n_keep, n_iter=n_iter, steps_per_cycle=steps_per_cycle,
                              threads=threads, min_digits=min_digits, max_period=max_period, **thresholds)
    cand = np.asarray(out["candidate"].values)
    out["origin"] = ("sample", np.array([origin[i] for i in cand]),
                     {"long_name": "where the IC comes from (line | random)"})
    other = escape_chart(np.asarray(out["q0"].values, float), np.asarray(out["p0"].values, float), F, Omega, Psi,
                         xi_max=(xi_max,), q_max=(q_max,), cycles=n_iter, steps_per_cycle=steps_per_cycle,
                         threads=threads, grid=False)
    out["escape_cycle_energy"] = ("sample", np.asarray(other["escape_cycle_energy"].isel(xi_max=0).values, float),
                                  {"units": "1", "long_name": "escape time in forcing cycles, energy criterion "
                                                              "H0 > xi_max (inf: no escape)"})
    out["escape_cycle_displacement"] = ("sample", np.asarray(other["escape_cycle_displacement"].isel(q_max=0).values,
                                                             float),
                                        {"units": "1", "long_name": "escape time in forcing cycles, displacement "
                                                                    "criterion |q| > q_max (inf: no escape)"})
    return out
