"""Quadrature over one free orbit of a general well (paper Sec. 2.1, eqs 8, 12-17 generalised).

The orbit of energy ``E`` runs between its turning points ``q_minus < 0 < q_plus``
(``V(q_pm) = E``).  With ``m = (q_plus + q_minus)/2``, ``d = (q_plus - q_minus)/2`` and
``q = m + d sin(phi)`` the upper branch (``p > 0``) is ``phi`` in ``[-pi/2, pi/2]`` and

    ``p = R(phi) cos(phi)``,   ``dt/dphi = d / R(phi)``,   ``R = sqrt(2 (E - V(q))) / |cos phi|``,

where ``R > 0`` is smooth: the square-root end singularities of ``dt = dq / p`` are removed.
Each half ``phi <= 0`` / ``phi >= 0`` is measured from its own end, ``psi = pi/2 -+ phi`` in
``[0, pi/2]`` (``psi = 0`` at the turning point), so that

    ``q = q_end - sigma 2 d sin^2(psi/2)``   (``sigma = -1`` left end, ``+1`` right end),

and near the end ``E - V(q) = (q_end - q) <V'>`` with ``<V'>`` the mean of ``V'`` over
``[q, q_end]`` (Gauss-Legendre), which gives ``R = sqrt(sigma d <V'>) / cos(psi/2)`` without
cancellation.  Close to the separatrix the orbit lingers near a barrier and ``dt/dpsi`` has a
peak of width ``alpha ~ (E_b - E)^(1/4)`` at ``psi = 0`` (complex zeros of ``<V'>`` at
``psi = +-i alpha``); the map ``psi = alpha sinh(v)`` turns it into an integrand of unit width
in ``v``, integrated on panels of length <= ``panel_length`` (Clenshaw-Curtis with its
integration matrix for cumulative times, Gauss-Legendre for the time to one point): spectral
convergence, work ~ ``log(1/alpha)``.

Quantities of one orbit (``tau_side(psi)`` = time from the side's turning point):

* period ``T = 2 (tau_left(pi/2) + tau_right(pi/2))``, ``omega = 2 pi / T`` (eq 16);
* action ``J = (1/pi) int p dq = (d/pi) int R cos^2(phi) dphi`` (eqs 8, 13);
* angle ``theta = omega t``, ``theta = 0`` at ``q = 0, p > 0`` (eq 14): the left turning point
  has ``theta_minus = -omega tau_minus(0) in (-pi, 0)``, the right one ``theta_plus =
  theta_minus + pi``;
* first harmonic (eq 12): ``q(theta)`` is even about ``theta_plus`` (time reversal), so
  ``q_1 = exp(-i theta_plus) |q_1|`` with, after an integration by parts,
  ``|q_1| = (1/pi) int_{q_minus}^{q_plus} sin(omega tau_plus(q)) dq``.
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.polynomial import chebyshev as _cheb
from numpy.polynomial import legendre as _leg

from safebasins.wells.interpolation import DEFAULT_TOL

__all__ = ["clenshaw_curtis", "solve_increasing", "OrbitQuadrature"]

EPS = np.finfo(float).eps
#: Gauss-Legendre rules tried for the mean of V' over a segment (:meth:`OrbitQuadrature.mean_dV`)
MEAN_NODES = (4, 6, 8, 12, 16)
#: rounding noise of one evaluation of V', relative to its largest value in the well: an absolute
#: floor of the accuracy of that mean (:meth:`OrbitQuadrature._calibrate_mean`)
NOISE = 16 * EPS


def clenshaw_curtis(n: Any) -> Any:
    """Clenshaw-Curtis rule on [-1, 1]: ascending nodes ``x``, weights ``w`` and the matrix
    ``S`` of the indefinite integral, ``int_{-1}^{x_i} f ~ sum_j S[i, j] f(x_j)``."""
    x = -np.cos(np.pi * np.arange(n) / (n - 1))
    x[(n - 1) // 2] = 0.0 if n % 2 else x[(n - 1) // 2]
    vinv = np.linalg.inv(_cheb.chebvander(x, n - 1))
    anti = np.empty((n, n))
    for k in range(n):
        c = np.zeros(n)
        c[k] = 1.0
        anti[:, k] = _cheb.chebval(x, _cheb.chebint(c, lbnd=-1.0))
    S = anti @ vinv
    return x, S[-1].copy(), S


def solve_increasing(fdf: Any, lo: Any, hi: Any, x0: Any, *, xtol: Any = 4 * EPS, atol: float = 0.0,
                     maxiter: int = 200) -> Any:
    """Vectorised safeguarded Newton (rtsafe) for increasing ``F`` with ``F(lo) <= 0 <= F(hi)``.

    ``fdf(x, idx)`` returns ``F(x), F'(x)`` for the items ``idx``.  Newton steps that leave the
    bracket, or that do not halve the step before last, are replaced by bisection, so the
    iteration always converges (to the bracketed root, or to the noise band of ``F``).
    Converged when a step (or the Newton correction) is below ``xtol |x| + atol`` or
    ``F == 0``.
    """
    lo = np.array(lo, dtype=float, copy=True)
    hi = np.array(hi, dtype=float, copy=True)
    x = np.clip(np.array(x0, dtype=float, copy=True), lo, hi)
    n = x.size
    dx_old = hi - lo
    dx = dx_old.copy()
    active = np.arange(n)
    tiny = max(float(atol), 1e-300)
    for _ in range(maxiter):
        if active.size == 0:
            return x
        xa = x[active]
        F, dF = fdf(xa, active)
        F = np.asarray(F, dtype=float)
        dF = np.asarray(dF, dtype=float)
        done = F == 0.0
        neg = F < 0.0
        lo[active] = np.where(neg, xa, lo[active])
        hi[active] = np.where(F > 0.0, xa, hi[active])
        la, ha = lo[active], hi[active]
        with np.errstate(divide="ignore", invalid="ignore"):
            step = F / dF
            xn = xa - step
        # a finite Newton correction below the tolerance: converged at xa (checked before the
        # bracket test, as xa - step may round to the bracket end xa itself)
        done = done | ((dF > 0.0) & (np.abs(step) <= (xtol * np.abs(xa) + tiny)))
        bad = (~np.isfinite(xn)) | (xn <= la) | (xn >= ha) | (dF <= 0.0) | \
              (np.abs(2.0 * step) > np.abs(dx_old[active]))
        xb = 0.5 * (la + ha)
        xn = np.where(bad, xb, xn)
        dx_old[active] = dx[active]
        dx[active] = xn - xa
        x[active] = np.where(done, xa, xn)
        conv = done | (np.abs(xn - xa) <= (xtol * np.abs(xn) + tiny)) | (ha - la <= (xtol * np.abs(xn) + tiny))
        active = active[~conv]
    raise RuntimeError(f"turning-point / angle solver did not converge for {active.size} items")


def _reference_mean(dV: Any, a: Any, b: Any, rtol: Any, floor: Any, panels: int = 16, n: int = 20) -> Any:
    """Mean of ``V'`` over ``[a, b]`` (arrays) by composite Gauss-Legendre (``panels`` x ``n`` nodes),
    and where it agrees with half as many panels to ``rtol`` (relative) plus ``floor`` (absolute):
    converged."""
    x, w = _leg.leggauss(n)

    def composite(m: Any) -> Any:
        edges = np.linspace(0.0, 1.0, m + 1)
        total = 0.0
        for lo, hi in zip(edges[:-1], edges[1:]):
            for xt, wt in zip(x, w):
                total = total + 0.5 * (hi - lo) * wt * dV(a + (b - a) * (lo + 0.5 * (hi - lo) * (xt + 1.0)))
        return total

    fine, coarse = composite(panels), composite(panels // 2)
    return fine, np.abs(fine - coarse) <= rtol * np.abs(fine) + floor


class OrbitQuadrature:
    """Orbit integrals of ``q'' = -V'(q)`` in the coordinates of the module docstring.

    ``V``, ``dV`` are the (vectorised) potential and its derivative; ``limits`` the brackets
    ``(q_lo, q_hi)`` of the turning points (barriers or points where ``V`` exceeds the escape
    energy); ``barriers`` the barrier positions (``+-inf`` where none); ``kappa =
    (-V''(q_left), -V''(q_right))`` the barrier curvatures (``nan`` where a side has no
    barrier), which set the width ``alpha`` of the near-separatrix peak.

    Rules: ``n_nodes`` Clenshaw-Curtis nodes per panel for half-orbit profiles (cumulative
    time), ``n_point`` Gauss-Legendre nodes per panel for the time to one point, panels of
    length <= ``panel_length`` in ``v``; ``alpha`` is capped at ``alpha_max`` (far from the
    separatrix the map is nearly linear).  ``E - V(q)`` is evaluated directly where
    ``(q_end - q)/d > gap_switch``, else as ``(q_end - q) <V'>`` with ``n_mean`` Gauss nodes
    (for a well open at infinity also only within ``gap_switch`` times :meth:`end_length`);
    turning points within ``barrier_zone |q_b|`` of a barrier use the barrier form.  The
    defaults give ~1e-15 relative accuracy (tested against closed forms).

    Sides open at infinity (``tails``: per side a :class:`~safebasins.wells.open_sides.Tail` or
    None; ``limits`` are ``+-inf`` there).  Beyond the tail's ``x0``, ``E - V(q) = G(|q|) - (A - E)``
    and ``V(q) - E = (A - E) - G(|q|)`` with ``G = A - V`` from the quadrature of ``V'`` (no
    cancellation near ``A``); turning points are bracketed by the tail's knots.  Near ``A`` the
    orbit lingers at its far turning point ``q_t`` as it does at a barrier: the peak of
    ``dt/dpsi`` has the width ``alpha = 2 sqrt(l / d)`` with ``l = (A - E) / |V'(q_t)|`` the decay
    length of ``A - V`` (the barrier formula with ``l = V'(q_t) / |V''(q_b)|``).  Between ``q_t``
    and the well ``A - V`` changes by ``log(G / (A - E))`` e-folds (up to ~37), and along an
    algebraic tail the well proper (extent ``core``) is a sliver of the half orbit: the panels are
    graded (:meth:`breaks`).
    """

    def __init__(self, V: Any, dV: Any, limits: Any, barriers: Any, kappa: Any, *, tails: Any = (None, None),
                 core: Any = None, n_nodes: int = 20, n_point: int = 12,
                 panel_length: float = 1.5, alpha_max: float = 3.0, gap_switch: float = 0.02, n_mean: int = 4,
                 barrier_zone: float = 0.1, span: float = 4.0, mean_rtol: Any = DEFAULT_TOL) -> None:
        self.V, self.dV = V, dV
        self.tails = tuple(tails)
        self.open = any(t is not None for t in self.tails)
        self.core, self.span = core, float(span)
        self.limits = (float(limits[0]), float(limits[1]))
        self.barriers = tuple(float(b) for b in barriers)
        self.barrier_V = tuple(float(V(np.array([b]))[0]) if np.isfinite(b) else np.inf
                               for b in self.barriers)
        self.kappa = tuple(float(k) for k in kappa)
        self.barrier_zone = float(barrier_zone)
        self.panel_length = float(panel_length)
        self.alpha_max = float(alpha_max)
        self.gap_switch = float(gap_switch)
        self.x, self.w, self.S = clenshaw_curtis(n_nodes)      # profiles (cumulative integrals)
        self.gx, self.gw = _leg.leggauss(n_point)                # definite integrals to a point
        n_mean, self.mean_length = self._calibrate_mean(int(n_mean), float(mean_rtol))
        gx, gw = _leg.leggauss(n_mean)
        self.mean_t = 0.5 * (gx + 1.0)
        self.mean_w = 0.5 * gw
        self.n_mean = n_mean

    def _mean_segments(self) -> Any:
        """Per side, the segments ``(q_end, length)`` over which :meth:`mean_dV` is taken: at the
        barrier (``barrier_zone |q_b|``, turning points) and at turning points near the limit and
        inside the well (``gap_switch`` times the orbit's width, the integrand's ``near`` form);
        none on a side open at infinity (its tail has its own lengths)."""
        finite = all(np.isfinite(self.limits))
        width = abs(self.limits[0]) + abs(self.limits[1]) if finite else self.core
        near = self.gap_switch * width
        out: list[Any] = []
        for k, lim in enumerate(self.limits):
            if self.tails[k] is not None or not np.isfinite(lim):
                out.append([])
                continue
            segs = [(f * lim, near * t) for f in (1.0, 0.75, 0.5) for t in (1.0, 0.5, 0.25)]
            qb = self.barriers[k]
            if np.isfinite(qb):
                segs += [(qb, self.barrier_zone * abs(qb) * t) for t in (1.0, 0.5, 0.25)]
            out.append(segs)
        return out

    def _calibrate_mean(self, n_first: Any, rtol: Any) -> Any:
        """``(n, (length_left, length_right))``: the Gauss rule of :meth:`mean_dV` and, per side, the
        longest segment it may span.  ``<V'>`` must reach ``rtol`` (relative, plus the rounding
        floor :data:`NOISE` of V') against a composite reference on the segments of
        :meth:`_mean_segments`.  The first of ``n_first`` and the larger
        :data:`MEAN_NODES` that does so everywhere is used with unrestricted lengths (``inf``: a smooth
        V', e.g. every polynomial, the pendulum); if none does -- a singularity of V' just beyond a
        barrier or a closing point, such as the pole of an electrostatic (MEMS) wall -- the largest rule is
        used and each failing side's segments are halved until they pass: there the barrier form of the
        turning points and the integrand's end form are used only that close to the end, and ``E - V``
        is taken directly beyond (accurate there: V' is not small)."""
        sides = self._mean_segments()
        ends = [lim for lim, t in zip(self.limits, self.tails) if t is None and np.isfinite(lim)]
        if not ends:
            return n_first, (np.inf, np.inf)
        # the rounding noise of V' itself (~eps of its terms, at least of its largest value in the
        # well) is not a quadrature error: it sets an absolute floor
        scan = np.linspace(min(min(ends), 0.0), max(max(ends), 0.0), 401)
        floor = NOISE * float(np.max(np.abs(self.dV(scan))))

        def passes(n: Any, segs: Any, cap: Any = np.inf) -> Any:
            if not segs:
                return True
            q_end = np.array([s[0] for s in segs])
            sigma = np.sign(q_end)
            q = q_end - sigma * np.minimum([s[1] for s in segs], cap)
            ref, ok = _reference_mean(self.dV, q, q_end, rtol, floor)
            x, w = _leg.leggauss(n)
            got = sum(0.5 * wt * self.dV(q + (q_end - q) * 0.5 * (xt + 1.0)) for xt, wt in zip(x, w))
            return bool(ok.all() and (np.abs(got - ref) <= rtol * np.abs(ref) + floor).all())

        for n in (n_first,) + tuple(m for m in MEAN_NODES if m > n_first):
            if all(passes(n, segs) for segs in sides):
                return n, (np.inf, np.inf)
        n = max(n_first, MEAN_NODES[-1])
        lengths = []
        for segs in sides:
            if passes(n, segs):
                lengths.append(np.inf)
                continue
            start = cap = max(s[1] for s in segs)
            while not passes(n, segs, cap):
                cap *= 0.5
                if cap < 1e-6 * start:
                    raise ValueError(f"dV: V' is not smooth near the {'left' if segs[0][0] < 0 else 'right'} end of "
                                     f"the well (q = {segs[0][0]!r}): its mean over segments of length "
                                     f"{cap!r} still differs between quadrature rules (a singularity of V' there?)")
            lengths.append(cap)
        return n, tuple(lengths)

    def mean_cap(self, sigma: Any) -> Any:
        """Longest segment of :meth:`mean_dV` at a turning point of the side ``sigma`` (-1 left, +1
        right; arrays broadcast): ``inf`` unless V' has a singularity near that side."""
        return np.where(np.asarray(sigma) < 0, self.mean_length[0], self.mean_length[1])

    # ------------------------------------------------------------------ turning points
    def turning_points(self, E: Any, guess: Any = None) -> Any:
        """``(q_minus, q_plus)`` with ``V = E`` for ``0 <= E <= E_b`` (validated, 1-D)."""
        E_all = np.asarray(E, dtype=float)
        pos = np.nonzero(E_all > 0)[0]              # E = 0: both turning points at the bottom
        E = E_all[pos]
        out = []
        for k, side in enumerate((-1.0, 1.0)):
            lim, qb, Vb = self.limits[k], self.barriers[k], self.barrier_V[k]
            if self.tails[k] is not None:
                q = np.zeros(E_all.shape)
                q[pos] = side * self._tail_turning_point(self.tails[k], E, None if guess is None else
                                                         side * np.asarray(guess[k])[pos])
                out.append(q)
                continue
            x0 = np.full(E.shape, 0.5 * lim) if guess is None else np.asarray(guess[k])[pos]

            # F(s) = V(side s) - E is increasing in s = side q on [0, |lim|]; near a barrier
            # V(q) - E = (V_b - E) - (q_b - q) <V'>_[q, q_b]: only V' and the exact difference
            # V_b - E enter, so q is found to ~eps (the energy to ~eps sqrt(V_b - E)).
            def fdf(s: Any, idx: Any, side: Any = side, qb: Any = qb, Vb: Any = Vb, k: Any = k) -> Any:
                q = side * s
                F = self.V(q) - E[idx]
                if np.isfinite(qb):
                    zone = np.abs(qb - q) <= min(self.barrier_zone * abs(qb), self.mean_length[k])
                    if zone.any():
                        qz = q[zone]
                        mean = self.mean_dV(qz, qb)
                        F[zone] = (Vb - E[idx][zone]) - (qb - qz) * mean
                return F, side * self.dV(q)
            s = solve_increasing(fdf, np.zeros(E.shape), np.full(E.shape, abs(lim)), side * x0)
            q = np.zeros(E_all.shape)
            q[pos] = np.where(E >= Vb, qb, side * s)   # on the separatrix: the barrier itself
            out.append(q)
        return out[0], out[1]

    def _tail_turning_point(self, tail: Any, E: Any, guess: Any) -> Any:
        """Distance ``x`` of the turning point on an open side: ``V(side x) = E`` (``inf`` at
        ``E >= A``); in the tail as ``(A - E) - G(x) = 0`` (both terms exact or accurate)."""
        side = tail.side
        s_E = tail.A - E                      # exact for E >= A/2 (Sterbenz), i.e. wherever the tail is used
        x = np.full(E.shape, np.inf)
        i = np.nonzero(s_E > 0)[0]
        Ei, si = E[i], s_E[i]
        lo, hi = tail.bracket(si)
        x0 = 0.5 * (lo + hi) if guess is None else np.clip(guess[i], lo, hi)

        def fdf(s: Any, idx: Any) -> Any:
            F = self.V(side * s) - Ei[idx]
            far = s >= tail.x0
            if far.any():
                F[far] = si[idx][far] - tail.G(s[far])
            return F, side * self.dV(side * s)
        x[i] = solve_increasing(fdf, lo, hi, x0)
        return x

    def _tail_gap(self, E: Any, q: Any, gap: Any) -> Any:
        """``E - V(q)`` (``gap``, computed directly) replaced beyond each open side's ``x0`` by
        ``G(|q|) - (A - E)``."""
        for tail in self.tails:
            if tail is not None:
                far = tail.side * q >= tail.x0
                if far.any():
                    gap[far] = tail.G(tail.side * q[far]) - (tail.A - E[far])
        return gap

    def _tail_length(self, q: Any) -> Any:
        """Decay length ``l = (A - V) / |V'|`` at the points ``q`` (``inf`` outside the tails)."""
        ell = np.full(np.shape(q), np.inf)
        for tail in self.tails:
            if tail is not None:
                x = tail.side * q
                far = x >= tail.x0
                ell[far] = tail.length_at(x[far])
        return ell

    def end_length(self, q_end: Any) -> Any:
        """Length scale of V' at a turning point of a well open at infinity: the decay length
        ``l`` of the tail beyond ``x0``, else the extent ``core`` of the well proper (with a far
        turning point on an open side the half width ``d`` is far larger than either)."""
        ell = self._tail_length(np.asarray(q_end, dtype=float))
        return np.where(np.isfinite(ell), ell, self.core)

    def breaks(self, v_end: Any, d: Any, alpha: Any, q_end: Any, sigma: Any, max_panels: int = 4000) -> Any:
        """Panel breaks ``(N, M + 1)`` on ``[0, v_end]`` for a well open at infinity, marching from
        the turning point: a panel spans at most ``panel_length`` in ``v`` and, in ``q``, at most
        ``span`` decay lengths ``l = (A - V) / |V'|`` of a tail (``sqrt(A - V)`` changes by
        ``span / 2`` e-folds) and half the distance to the well bottom, at least half ``core``:
        uniform in ``q`` along an exponential tail, geometric along an algebraic one (where the
        well proper shrinks to a sliver at ``psi = pi/2``), a few panels across the well proper.
        Items that end earlier are padded with ``v_end`` (empty panels)."""
        v_end = np.asarray(v_end, dtype=float)
        q_end, d, alpha, sigma = (np.broadcast_to(np.asarray(a, dtype=float), v_end.shape)
                                  for a in (q_end, d, alpha, sigma))
        v = np.zeros(v_end.shape)
        rows = [v]
        for _ in range(max_panels):
            going = v < v_end
            if not going.any():
                return np.stack(rows, axis=-1)
            q = q_end - sigma * 2.0 * d * np.sin(0.5 * alpha * np.sinh(v)) ** 2
            step = np.minimum(self.span * self._tail_length(q), 0.5 * np.maximum(np.abs(q), self.core))
            gap = np.minimum(np.abs(q_end - q) + step, d)          # distance from the turning point
            v_next = np.arcsinh(2.0 * np.arcsin(np.sqrt(0.5 * gap / d)) / alpha)
            v = np.where(going, np.minimum(np.minimum(v_next, v + self.panel_length), v_end), v)
            rows.append(v)
        raise RuntimeError(f"panel breaks of the open well did not reach the end in {max_panels} panels")

    @staticmethod
    def _nodes_between(b: Any, x: Any) -> Any:
        """Nodes ``(N, M, n)`` (reference nodes ``x`` on [-1, 1]) on the panels between the breaks
        ``b`` ``(N, M + 1)``, and the panel half-lengths ``(N, M, 1)``."""
        half = 0.5 * (b[:, 1:, None] - b[:, :-1, None])
        return b[:, :-1, None] + half * (x[None, None, :] + 1.0), half

    def mean_dV(self, q: Any, q_end: Any) -> Any:
        """Mean of ``V'`` over the segment ``[q, q_end]`` (Gauss-Legendre, ``n_mean`` nodes)."""
        mean = np.zeros(np.broadcast_shapes(np.shape(q), np.shape(q_end)))
        for t, wt in zip(self.mean_t, self.mean_w):
            mean = mean + wt * self.dV(q + (q_end - q) * t)
        return mean

    def geometry(self, E: Any, q_minus: Any, q_plus: Any) -> Any:
        """Centre ``m``, half-width ``d`` and peak widths ``alpha`` of each side."""
        m = 0.5 * (q_plus + q_minus)
        d = 0.5 * (q_plus - q_minus)
        alphas = []
        for sigma, q_end, kappa, tail in ((-1.0, q_minus, self.kappa[0], self.tails[0]),
                                          (1.0, q_plus, self.kappa[1], self.tails[1])):
            if tail is not None:
                # the barrier formula with the decay length l = (A - E) / |V'(q_t)| of the tail
                a = np.full(np.shape(E), self.alpha_max)
                far = sigma * q_end >= tail.x0
                if far.any():
                    ell = tail.length(sigma * q_end[far], tail.A - E[far])
                    a[far] = np.clip(2.0 * np.sqrt(ell / d[far]), 1e-12, self.alpha_max)
            elif np.isfinite(kappa) and kappa > 0:
                slope = np.maximum(sigma * self.dV(q_end), 0.0)
                with np.errstate(divide="ignore", invalid="ignore"):
                    a = 2.0 * np.sqrt(slope / (kappa * d))
                a = np.where(np.isfinite(a), a, self.alpha_max)
                a = np.clip(a, 1e-12, self.alpha_max)
            else:
                a = np.full(np.shape(E), self.alpha_max)
            alphas.append(a)
        return m, d, alphas[0], alphas[1]

    # ------------------------------------------------------------------ integrand
    def integrand(self, E: Any, q_end: Any, d: Any, alpha: Any, sigma: Any, v: Any) -> Any:
        """At nodes ``v`` (items along axis 0, per-item arrays of shape (N, 1)): ``psi``, ``q``,
        ``R`` and ``dpsi/dv``."""
        psi = alpha * np.sinh(v)
        dpsi = alpha * np.cosh(v)
        half = 0.5 * psi
        s2 = np.sin(half) ** 2
        q = q_end - sigma * (2.0 * d) * s2
        shape = np.broadcast_shapes(psi.shape, np.shape(E), np.shape(d))
        q = np.broadcast_to(q, shape)
        psi_b = np.broadcast_to(psi, shape)
        near = 2.0 * s2 <= self.gap_switch
        if self.open:      # <V'> by n_mean nodes only over a short stretch on the scale of the end
            near = near & (2.0 * d * s2 <= self.gap_switch * self.end_length(q_end))
        if np.isfinite(self.mean_length).any():   # V' singular near a side: <V'> only that close
            near = near & (2.0 * d * s2 <= self.mean_cap(sigma))
        near = np.broadcast_to(near, shape)
        R = np.empty(shape)
        Eb = np.broadcast_to(E, shape)
        # away from the end: E - V(q) directly (no cancellation there)
        far = ~near
        if far.any():
            gap = Eb[far] - self.V(q[far])
            if self.open:
                gap = self._tail_gap(Eb[far], q[far], gap)
            R[far] = np.sqrt(2.0 * gap) / np.sin(psi_b[far])
        if near.any():
            qn = q[near]
            qe = np.broadcast_to(q_end, shape)[near]
            dn = np.broadcast_to(d, shape)[near]
            sg = np.broadcast_to(sigma, shape)[near]
            mean = self.mean_dV(qn, qe)
            R[near] = np.sqrt(np.maximum(sg * dn * mean, 0.0)) / np.cos(0.5 * psi_b[near])
        return psi, q, R, dpsi

    # ------------------------------------------------------------------ composite rules
    @staticmethod
    def _nodes(v_end: Any, m: Any, x: Any) -> Any:
        """Composite nodes (reference nodes ``x`` on [-1, 1]) on ``[0, v_end]`` (per item) with
        ``m`` equal panels: shape (N, m, n) and the panel half-lengths (N, 1, 1)."""
        h = (v_end / m)[:, None, None]
        a = h * np.arange(m)[None, :, None]
        v = a + h * 0.5 * (x[None, None, :] + 1.0)
        return v, 0.5 * h

    def side_profile(self, E: Any, q_end: Any, d: Any, alpha: Any, sigma: Any, m: Any | None = None) -> Any:
        """Half orbit from one turning point to ``q = m`` (``psi`` in [0, pi/2]), all nodes.

        Returns dict with per-node ``psi``, ``q``, ``R``, ``dpsi`` (N, K), the cumulative time
        ``tau`` from the turning point (N, K) and the CC weights in v (N, K).
        """
        v_end = np.arcsinh(0.5 * np.pi / alpha)
        if self.open:
            v, half = self._nodes_between(self.breaks(v_end, d, alpha, q_end, sigma), self.x)
        else:
            if m is None:
                m = max(int(np.ceil(np.max(v_end) / self.panel_length)), 1)
            v, half = self._nodes(v_end, m, self.x)
        N = v.shape[0]
        col: Callable[[Any], Any] = lambda a: np.asarray(a, dtype=float).reshape(N, 1, 1)
        psi, q, R, dpsi = self.integrand(col(E), col(q_end), col(d), col(alpha), sigma, v)
        f = col(d) / R * dpsi
        cum = half * (f @ self.S.T)
        tot = cum[..., -1]
        off = np.concatenate([np.zeros((N, 1)), np.cumsum(tot, axis=1)[:, :-1]], axis=1)
        tau = cum + off[..., None]
        wts = np.broadcast_to(half * self.w, v.shape)
        flat: Callable[[Any], Any] = lambda a: np.broadcast_to(a, v.shape).reshape(N, -1)
        return {"psi": flat(psi), "q": flat(q), "R": flat(R), "dpsi": flat(dpsi),
                "tau": flat(tau), "w": flat(wts), "total": tau[:, -1, -1]}

    def side_time(self, E: Any, q_end: Any, d: Any, alpha: Any, sigma: Any, psi: Any) -> Any:
        """Time from the turning point ``q_end`` to the point at ``psi`` (1-D arrays), by
        composite Gauss-Legendre in ``v = asinh(psi/alpha)``, items grouped by their number of
        panels."""
        E, q_end, d, alpha, psi = (np.asarray(a, dtype=float) for a in (E, q_end, d, alpha, psi))
        sigma = np.broadcast_to(np.asarray(sigma, dtype=float), E.shape)
        v_end = np.arcsinh(psi / alpha)
        if self.open:
            v, half = self._nodes_between(self.breaks(v_end, d, alpha, q_end, sigma), self.gx)
            col: Callable[[Any], Any] = lambda a: a.reshape(-1, 1, 1)
            _, _, R, dpsi = self.integrand(col(E), col(q_end), col(d), col(alpha), col(sigma), v)
            return np.sum(half[:, :, 0] * ((col(d) / R * dpsi) @ self.gw), axis=1)
        m = np.maximum(np.ceil(v_end / self.panel_length), 1).astype(int)
        out = np.zeros(E.shape)
        for mm in np.unique(m):
            idx = np.nonzero(m == mm)[0]
            v, half = self._nodes(v_end[idx], int(mm), self.gx)
            col = lambda a: a[idx].reshape(-1, 1, 1)
            _, _, R, dpsi = self.integrand(col(E), col(q_end), col(d), col(alpha), col(sigma), v)
            f = col(d) / R * dpsi
            out[idx] = np.sum(half[:, :, 0] * (f @ self.gw), axis=1)
        return out

    def rate(self, E: Any, q_end: Any, d: Any, alpha: Any, sigma: Any, v: Any) -> Any:
        """``dtau/dv`` and ``(psi, q, R)`` at single nodes ``v`` (1-D arrays)."""
        psi, q, R, dpsi = self.integrand(E, q_end, d, alpha, sigma, v)
        return d / R * dpsi, psi, q, R

    # ------------------------------------------------------------------ one orbit
    def orbit_data(self, E: Any, guess: Any = None) -> Any:
        """Period, action, first harmonic and angle data of the orbits of energies ``E``
        (1-D, ``0 < E < E_b``): dict of 1-D arrays ``q_minus, q_plus, T, J, q1_abs,
        theta_minus, t_left`` (``t_left``: time from ``q_minus`` to ``m``)."""
        E = np.asarray(E, dtype=float)
        qm, qp = self.turning_points(E, guess)
        m, d, aL, aR = self.geometry(E, qm, qp)
        left = self.side_profile(E, qm, d, aL, -1.0)
        right = self.side_profile(E, qp, d, aR, 1.0)
        T = 2.0 * (left["total"] + right["total"])
        omega = 2.0 * np.pi / T
        J = 0.0
        q1 = 0.0
        for side in (left, right):
            s = np.sin(side["psi"])
            J = J + np.sum(side["w"] * side["R"] * s * s * side["dpsi"], axis=1)
            q1 = q1 + np.sum(side["w"] * np.sin(omega[:, None] * side["tau"]) * s * side["dpsi"], axis=1)
        J = d / np.pi * J
        q1 = d / np.pi * q1
        # time from q_minus to q = 0 (upper branch)
        on_left = m >= 0.0
        ratio = np.where(on_left, -qm, qp) / (2.0 * d)
        psi0 = 2.0 * np.arcsin(np.sqrt(np.clip(ratio, 0.0, 1.0)))
        tl = self.side_time(E, np.where(on_left, qm, qp), d, np.where(on_left, aL, aR),
                            np.where(on_left, -1.0, 1.0), psi0)
        t0 = np.where(on_left, tl, 0.5 * T - tl)
        out = {"q_minus": qm, "q_plus": qp, "T": T, "J": J, "q1_abs": q1,
               "theta_minus": -omega * t0, "t_left": left["total"]}
        for k, a in out.items():
            if not np.isfinite(a).all():
                raise RuntimeError(f"orbit quadrature produced non-finite {k} (E in [{E.min()}, {E.max()}])")
        return out
