"""Pseudo-arclength continuation of the period-1 orbits of the damped forced well (docs/continuation.md).

For ``q' = p, p' = -V'(q) - beta p + F sin(Omega t + Psi)`` the stroboscopic map of phase ``Psi``
is ``P(x; lambda) = phi_{0 -> T}(x)`` (``T = 2 pi / Omega``, ``lambda`` = Omega or F).  A T-periodic
response is a zero of::

    G(x, lambda) = P(x; lambda) - x                                                        (C1)

and its branches are curves in ``y = (q, p, lambda)``.  Lengths are measured in the scaled
coordinates ``z = (q, p, kappa lambda)`` (:class:`Family`).  A point is corrected by Newton's method
on the bordered system::

    [ D P - I    P_lambda / kappa ] dz = - [ G              ]                              (C2)
    [        n^T                  ]        [ n . (z - z_0)  ]

(``n`` the unit tangent and ``z_0`` the predictor ``z_prev + ds n``: pseudo-arclength; ``n = e_lambda``
and ``z_0`` at the wanted lambda: Newton on the period map at fixed lambda).  The tangent is the null
vector of the 2 x 3 block ``[D P - I, P_lambda / kappa]``, the cross product of its rows (C3).
``D P`` (the monodromy matrix) and ``G`` come from :func:`safebasins.analysis.floquet.shooting_step`
(central differences in one DOP853 system), ``P_lambda`` from central differences of
:func:`safebasins.analysis.floquet.forced_flow` in lambda (once per accepted point: a chord in the
lambda column).  The Floquet multipliers ``mu_1, mu_2`` are the eigenvalues of ``D P``; Liouville
(trace of the field's Jacobian = -beta) gives::

    mu_1 mu_2 = det D P = exp(-beta T) < 1,                                                (C4)

so a complex pair has ``|mu| = exp(-beta T / 2) < 1``: with damping a period-1 orbit loses
stability only through a real multiplier at +1 or -1.  The test functions along a branch are::

    f_+ = det(D P - I) = (1 - mu_1)(1 - mu_2),    f_- = det(D P + I) = (1 + mu_1)(1 + mu_2)  (C5)

a sign change of ``f_+`` is a fold (saddle-node) where the lambda component of the tangent changes
sign and a branch point (symmetry breaking) where it does not; one of ``f_-`` a period doubling.
Events are located by the Illinois variant of regula falsi on the step length ``s`` of the
corrector (C2) from the last point.
"""
from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import Literal

import numpy as np
import numpy.typing as npt

from safebasins.analysis.floquet import forced_flow, forced_flow_dense, shooting_step
from safebasins.wells.base import Well

__all__ = ["Family", "Point", "Event", "Curve", "correct", "follow", "curve", "at_parameter", "EVENT_KINDS", "RTOL"]

Array = npt.NDArray[np.float64]
Parameter = Literal["Omega", "F"]

#: DOP853 relative tolerance of the period map (Liouville (C4) holds to ~4e-10 with H_STATE); Newton's
#: first iterations use RTOL_COARSE until ``|G|`` < COARSE_UNTIL (the coarse map is good to ~1e-8)
RTOL = 1e-11
RTOL_COARSE = 1e-8
COARSE_UNTIL = 1e-6
#: central-difference step of D P (at 1e-7 the integration noise gives ~5e-9 in det D P, at 1e-6 ~3e-10)
H_STATE = 1e-6
#: relative central-difference step of P_lambda (only the Newton rate depends on it)
H_PARAM = 1e-6
#: Newton stops when ``|G|`` and the constraint are below RESIDUAL_TOL (the DOP853 map is good to ~1e-11),
#: or when its step is below STEP_TOL (scaled) with ``|G|`` below 1e-8 (the point after that step is good to
#: ~1e-15: the error of D P is ~1e-9 relative)
RESIDUAL_TOL = 1e-10
STEP_TOL = 1e-9
MAX_NEWTON = 10
#: the secant update of P_lambda needs a step in kappa lambda above this (the map's noise is ~1e-12)
SECANT_MIN = 1e-6
#: samples of the orbit over one period (amplitude, largest energy, first harmonic)
N_SAMPLES = 256
#: consecutive tangents turning by more than this (cosine) reject a step (a jump to another branch)
MIN_COS = math.cos(math.radians(30.0))
#: event location: bracket in s (scaled) and iterations
LOCATE_TOL = 1e-9
MAX_LOCATE = 40
#: kinds of event (flag values of the Dataset's ``event_kind``)
EVENT_KINDS = ("fold", "branch_point", "period_doubling", "left_well", "range_end", "step_failure", "max_points",
               "closed")


@dataclasses.dataclass(frozen=True)
class Family:
    """The equation and the swept parameter: ``parameter`` ("Omega" or "F") varies, the other is fixed;
    ``kappa`` scales lambda in the arclength (C2); ``xi_max`` the energy that ends a branch."""
    well: Well
    F: float
    Omega: float
    beta: float
    Psi: float
    parameter: Parameter
    kappa: float
    xi_max: float

    def forcing(self, lam: float) -> tuple[float, float]:
        """``(F, Omega)`` at the parameter value ``lam``."""
        return (lam, self.Omega) if self.parameter == "F" else (self.F, lam)

    @property
    def scale(self) -> Array:
        """``z = scale * y``: the scaled coordinates of the arclength."""
        return np.array([1.0, 1.0, self.kappa])


@dataclasses.dataclass(frozen=True)
class Point:
    """A converged period-1 orbit: ``y = (q, p, lambda)`` (fixed point at the section), the monodromy
    matrix ``D`` = D P, ``p_lam`` Newton's last estimate of ``P_lambda`` (for the tangent), its
    multipliers ``mu`` (larger modulus first), ``residual`` the largest ``|G|`` at Newton's last
    evaluation, the largest ``|q|`` and ``H0`` over the period, the first harmonic ``q ~ harmonic
    sin(Omega t + Psi - lag)``; ``s``: arclength from the curve's first point (set by :func:`follow`)."""
    y: Array
    D: Array
    p_lam: Array
    mu: npt.NDArray[np.complex128]
    residual: float
    amplitude: float
    energy_max: float
    harmonic: float
    lag: float
    s: float = 0.0

    @property
    def stable(self) -> bool:
        """Both multipliers inside the unit circle (an attractor)."""
        return bool(np.max(np.abs(self.mu)) < 1.0)

    @property
    def f_plus(self) -> float:
        """``det(D P - I)`` (C5)."""
        return float(np.linalg.det(self.D - np.eye(2)))

    @property
    def f_minus(self) -> float:
        """``det(D P + I)`` (C5)."""
        return float(np.linalg.det(self.D + np.eye(2)))


@dataclasses.dataclass(frozen=True)
class Event:
    """Where a branch bifurcates or ends: ``kind`` one of :data:`EVENT_KINDS`; ``point`` the located orbit
    (``located`` False: the location failed and ``point`` is the nearest point of the branch found)."""
    kind: str
    point: Point
    located: bool = True


@dataclasses.dataclass
class Curve:
    """One continued branch: its points in arclength order, its bifurcations, and the events that end
    it at its first and its last point (``ends``)."""
    points: list[Point]
    events: list[Event]
    ends: tuple[Event, Event]


def _evaluate(fam: Family, y: Array, rtol: float) -> tuple[Array, Array]:
    """``G`` (2,) and ``D P`` (2, 2) at ``y`` (ValueError when the flow cannot be integrated)."""
    F, Om = fam.forcing(float(y[2]))
    if not Om > 0:
        raise ValueError(f"Omega: the continuation reached Omega = {Om!r}")
    D, r = shooting_step(fam.well, F, Om, fam.beta, fam.Psi, y[:2, None], np.zeros(1), 2.0 * np.pi / Om, rtol,
                         H_STATE)
    return r[:, 0], D[:, :, 0]


def _p_lambda(fam: Family, y: Array, r: Array, rtol: float) -> Array:
    """``dP / dlambda`` at ``y`` (``r`` = G there): for F a central difference in one system; for Omega
    (a period of its own) a forward difference against ``P(y) = y + r``.  Their noise, ~RTOL / H_PARAM,
    only slows Newton's chord in lambda and tilts the predictor."""
    lam = float(y[2])
    h = H_PARAM * max(1.0, abs(lam))
    F, Om = fam.forcing(lam)
    x = y[:2, None]
    if fam.parameter == "F":
        Y = forced_flow(fam.well, np.array([F + h, F - h]), Om, fam.beta, np.full(2, fam.Psi), np.repeat(x, 2, 1),
                        2.0 * np.pi / Om, rtol)
        return (Y[:, 0] - Y[:, 1]) / (2.0 * h)
    up = forced_flow(fam.well, F, Om + h, fam.beta, np.full(1, fam.Psi), x, 2.0 * np.pi / (Om + h), rtol)[:, 0]
    return (up - (y[:2] + r)) / h


def _summary(fam: Family, y: Array) -> tuple[float, float, float, float]:
    """Largest ``|q|``, largest ``H0``, first-harmonic amplitude and lag of the orbit through ``y``."""
    F, Om = fam.forcing(float(y[2]))
    T = 2.0 * np.pi / Om
    tau = T * np.arange(N_SAMPLES) / N_SAMPLES
    qp = forced_flow_dense(fam.well, F, Om, fam.beta, np.full(1, fam.Psi), y[:2, None], T, RTOL)(tau)[:, 0]
    H = np.asarray(fam.well.H0(qp[0], qp[1]), dtype=float)
    # q ~ Im(a e^{i (Omega t + Psi)}), a = 2 i c_1 = |a| e^{-i lag}
    a = 2j * np.mean(qp[0] * np.exp(-1j * (Om * tau + fam.Psi)))
    return float(np.max(np.abs(qp[0]))), float(np.max(H)), float(abs(a)), float(np.mod(-np.angle(a), 2.0 * np.pi))


def correct(fam: Family, y0: Array, n: Array, p_lam: Array | None = None, start: Array | None = None
            ) -> Point | None:
    """Newton on (C2) with the hyperplane ``n . (z - z_0) = 0`` through ``y0`` (``n`` a unit vector in the
    scaled coordinates), from ``start`` (default ``y0``); ``p_lam``: the lambda column (default: computed
    at the first iterate).  None when Newton fails, stops contracting, leaves the domain or the flow
    cannot be integrated."""
    S = fam.scale
    y = np.array(y0 if start is None else start, dtype=float)
    A = np.zeros((3, 3))
    A[2] = n
    last: tuple[Array, Array, Array, float] | None = None   # (G, D P, dy, rtol) before the last step
    rtol = RTOL_COARSE
    res_prev = np.inf
    for _ in range(MAX_NEWTON):
        try:
            r, D = _evaluate(fam, y, rtol)
            if p_lam is None:
                p_lam = _p_lambda(fam, y, r, rtol)
        except ValueError:
            return None
        if last is not None and last[3] == rtol and abs(last[2][2]) * fam.kappa > SECANT_MIN:
            # secant update of the lambda column: G(y) - G(y_old) = (mean D P - I) dx + P_lambda dlambda
            r0, D0, dy, _ = last
            p_lam = (r - r0 - (0.5 * (D + D0) - np.eye(2)) @ dy[:2]) / dy[2]
        fine = rtol == RTOL
        c = float(n @ (S * (y - y0)))
        res = float(np.max(np.abs(r)))
        if res > 2.0 * res_prev and res > RESIDUAL_TOL:
            return None                     # not contracting: past a fold or off the branch; a shorter step
        res_prev = res
        if fine and res <= RESIDUAL_TOL and abs(c) <= RESIDUAL_TOL:
            return _point(fam, y, D, p_lam, res)
        A[:2, :2] = D - np.eye(2)
        A[:2, 2] = p_lam / fam.kappa
        try:
            dz = np.linalg.solve(A, -np.concatenate([r, [c]]))
        except np.linalg.LinAlgError:
            return None
        last = (r, D, dz / S, rtol)
        y = y + dz / S
        if not np.isfinite(y).all():
            return None
        if fine and float(np.max(np.abs(dz))) <= STEP_TOL and res <= 1e-8:
            # G at the new y is the linearisation's remainder, O(|dz|^2 + 1e-9 |dz|)
            return _point(fam, y, D, p_lam, res)
        if res < COARSE_UNTIL and not fine:
            rtol, res_prev = RTOL, np.inf   # the fine map's G differs from the coarse one's by ~1e-8
    return None


def _point(fam: Family, y: Array, D: Array, p_lam: Array, res: float) -> Point | None:
    try:
        amp, e_max, harm, lag = _summary(fam, y)
    except ValueError:
        return None
    mu = np.linalg.eigvals(D).astype(complex)
    mu = mu[np.argsort(-np.abs(mu), kind="stable")]
    return Point(y=y, D=D, p_lam=p_lam, mu=mu, residual=res, amplitude=amp, energy_max=e_max, harmonic=harm, lag=lag)


def tangent(fam: Family, pt: Point, previous: Array | None, direction: float = 1.0) -> Array:
    """The unit tangent (C3) at ``pt`` in scaled coordinates, oriented along ``previous`` (or so that
    lambda grows with ``direction`` > 0)."""
    rows = np.concatenate([pt.D - np.eye(2), (pt.p_lam / fam.kappa)[:, None]], axis=1)
    t: Array = np.cross(rows[0], rows[1])
    t = t / np.linalg.norm(t)
    ref = previous if previous is not None else np.array([0.0, 0.0, direction])
    return -t if float(t @ ref) < 0 else t


def _locate(fam: Family, prev: Point, new: Point, t: Array, ds: float, f: Callable[[Point], float]
            ) -> tuple[Point, bool]:
    """The zero of ``f`` between ``prev`` and ``new`` on the corrector from ``prev`` (the hyperplane at step
    ``s`` in (0, ds) along ``t``, Newton from the chord), by Illinois regula falsi; and whether it converged
    (if not: the bracket's end with the smaller ``|f|``)."""
    S = fam.scale
    f0, f1 = f(prev), f(new)
    a, fa, b, fb = 0.0, f0, ds, f1
    side = 0
    best: Point | None = None
    for _ in range(MAX_LOCATE):
        s = (a * fb - b * fa) / (fb - fa)
        pt = correct(fam, prev.y + s * t / S, t, prev.p_lam, start=prev.y + (s / ds) * (new.y - prev.y))
        if pt is None:
            break
        moved = best is None or abs(prev.s + s - best.s) > LOCATE_TOL
        best = dataclasses.replace(pt, s=prev.s + s)
        fs = f(pt)
        if fs == 0.0 or not moved:
            return best, True
        if (fs > 0) == (fb > 0):
            b, fb = s, fs
            if side == -1:
                fa *= 0.5
            side = -1
        else:
            a, fa = s, fs
            if side == 1:
                fb *= 0.5
            side = 1
        if b - a <= LOCATE_TOL:
            return best, True
    return (prev if abs(f0) < abs(f1) else new), False


def _at_parameter(fam: Family, a: Point, b: Point, lam: float) -> Point | None:
    """The orbit at ``lambda = lam`` between the points ``a`` and ``b`` (Newton at fixed lambda from the chord)."""
    w = (lam - a.y[2]) / (b.y[2] - a.y[2])
    y0 = a.y + w * (b.y - a.y)
    y0[2] = lam
    pt = correct(fam, y0, np.array([0.0, 0.0, 1.0]))
    return None if pt is None else dataclasses.replace(pt, s=a.s + w * (b.s - a.s))


def at_parameter(fam: Family, points: list[Point], lam: float) -> list[Point]:
    """Every orbit of a curve at ``lambda = lam`` (one per crossing of its chords)."""
    out = []
    for a, b in zip(points[:-1], points[1:]):
        if a.y[2] == lam:
            out.append(a)
        elif (a.y[2] - lam) * (b.y[2] - lam) < 0:
            pt = _at_parameter(fam, a, b, lam)
            if pt is not None:
                out.append(pt)
    if points and points[-1].y[2] == lam:
        out.append(points[-1])
    return out


def _sign_change(u: float, v: float) -> bool:
    return (u > 0) != (v > 0)


def _step_events(fam: Family, prev: Point, new: Point, t: Array, t_new: Array, ds: float,
                 bounds: tuple[float, float]) -> list[Event]:
    """The events between ``prev`` and ``new``, located, in arclength order (a terminal one last)."""
    found: list[Event] = []
    if _sign_change(prev.f_plus, new.f_plus):
        kind = "fold" if _sign_change(t[2], t_new[2]) else "branch_point"
        found.append(Event(kind, *_locate(fam, prev, new, t, ds, lambda p: p.f_plus)))
    if _sign_change(prev.f_minus, new.f_minus):
        found.append(Event("period_doubling", *_locate(fam, prev, new, t, ds, lambda p: p.f_minus)))
    found.sort(key=lambda e: e.point.s)
    if new.energy_max >= fam.xi_max:
        pt, ok = _locate(fam, prev, new, t, ds, lambda p: p.energy_max - fam.xi_max)
        inside = pt.energy_max <= fam.xi_max * (1 + 1e-6)
        end = Event("left_well", pt if inside else prev, ok and inside)
        return [e for e in found if e.point.s < end.point.s] + [end]
    lam = float(new.y[2])
    if not bounds[0] <= lam <= bounds[1]:
        edge = bounds[0] if lam < bounds[0] else bounds[1]
        at = _at_parameter(fam, prev, new, edge)
        end = Event("range_end", at) if at is not None else Event("range_end", prev, False)
        return [e for e in found if e.point.s < end.point.s] + [end]
    return found


def _predict(S: Array, pts: list[Point], t: Array, ds: float) -> Array:
    """The predictor ``z + ds t + ds^2 c / 2``, the curvature ``c`` from the previous point (scaled
    coordinates: ``z_prev = z - h t + h^2 c / 2``); the tangent alone at a curve's first step."""
    z = S * pts[-1].y
    pred = z + ds * t
    if len(pts) > 1:
        h = pts[-1].s - pts[-2].s
        if h > 0:
            c = 2.0 * (S * pts[-2].y - z + h * t) / (h * h)
            pred = pred + 0.5 * ds * ds * (c - (c @ t) * t)
    return pred / S


def follow(fam: Family, start: Point, direction: float, bounds: tuple[float, float], ds_max: float,
           max_points: int) -> tuple[list[Point], list[Event]]:
    """Pseudo-arclength continuation from ``start`` with lambda first growing (``direction`` > 0) or
    falling, until the branch leaves ``bounds`` in lambda, leaves the well (``H0`` reaches xi_max
    on the orbit), closes on itself, or the step falls below ``1e-6 ds_max``.  Returns the points
    (``start`` first) and the events; the last event says why the branch ends there."""
    S = fam.scale
    t = tangent(fam, start, None, direction)
    lam = float(start.y[2])
    if (lam <= bounds[0] and t[2] < 0) or (lam >= bounds[1] and t[2] > 0):
        return [start], [Event("range_end", start)]
    pts, events = [start], []
    ds = 0.25 * ds_max
    while True:
        if len(pts) >= max_points:
            events.append(Event("max_points", pts[-1]))
            break
        prev = pts[-1]
        new = correct(fam, _predict(S, pts, t, ds), t, prev.p_lam)
        t_new = tangent(fam, new, t) if new is not None else t
        if new is None or float(t_new @ t) < MIN_COS:
            ds *= 0.5
            if ds < 1e-6 * ds_max:
                events.append(Event("step_failure", prev))
                break
            continue
        new = dataclasses.replace(new, s=prev.s + ds)
        found = _step_events(fam, prev, new, t, t_new, ds, bounds)
        events.extend(found)
        end = bool(found) and found[-1].kind in ("left_well", "range_end")
        pts.extend(e.point for e in (found[:-1] if end else found) if prev.s < e.point.s < new.s)
        if end:
            if found[-1].point is not prev:
                pts.append(found[-1].point)
            break
        pts.append(new)
        if len(pts) > 3 and float(np.max(np.abs(S * (new.y - start.y)))) < 0.5 * ds:
            events.append(Event("closed", new))
            break
        t = t_new
        ds = min(ds_max, 1.5 * ds)
    return pts, events


def curve(fam: Family, seed: Point, bounds: tuple[float, float], ds_max: float, max_points: int) -> Curve:
    """The whole branch through ``seed``: :func:`follow` towards smaller and larger lambda, joined in
    arclength order (``s`` < 0 on the first part)."""
    back, ev_back = follow(fam, seed, -1.0, bounds, ds_max, max_points)
    fwd, ev_fwd = follow(fam, seed, 1.0, bounds, ds_max, max_points)
    flipped = {id(p): dataclasses.replace(p, s=-p.s) for p in back}
    flip = [Event(e.kind, flipped.get(id(e.point), dataclasses.replace(e.point, s=-e.point.s)), e.located)
            for e in ev_back]
    pts = [flipped[id(p)] for p in back[:0:-1]] + fwd
    return Curve(points=pts, events=flip[-2::-1] + ev_fwd[:-1], ends=(flip[-1], ev_fwd[-1]))
