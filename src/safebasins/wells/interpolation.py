"""Piecewise Chebyshev interpolation of orbit data in the energy ``E`` on ``[0, E_b)``.

Action-angle data of a well are analytic in ``x = sqrt(E)`` at the well bottom (the orbit's
amplitude is ~ ``x``; ``J`` and ``omega`` are even in it) and behave like
``a + b log(E_b - E) + O((E_b - E) log)`` at the separatrix (eq 16: ``omega -> 0``
logarithmically).  The energy range is therefore split at ``E_split`` into

* *bottom panels* in ``x = sqrt(E)`` on ``[0, sqrt(E_split)]``, and
* *separatrix panels* in ``u = log(E_b - E)`` on ``[log(s_min), log(E_b - E_split)]``, a
  geometric partition of ``E_b - E`` down to below the float spacing of ``E_b`` (every float
  ``E < E_b`` is covered); in ``u`` the logarithmic terms are polynomial and ``s log s`` is
  entire, so few nodes per panel suffice.

Each panel holds ``n`` Chebyshev coefficients (first-kind nodes: neither ``E = 0`` nor
``E = E_b`` is ever sampled).  Panels are split until the trailing coefficients of every
quantity are below ``tol`` relative to the panel's values (plus a noise floor supplied by the
caller, e.g. the conditioning near the separatrix).  Evaluation is one compiled (numba) loop:
binary search of the panel, Clenshaw's recurrence; derivatives with respect to ``E`` use the
differentiated series and the chain rule of the panel variable.
"""
from __future__ import annotations

from typing import Any

import numpy as np
from numpy.polynomial import chebyshev as _cheb

from safebasins.core.numba_target import package_jit

__all__ = ["EnergyInterpolant", "DEFAULT_TOL", "TOL_RANGE"]

BOTTOM, SEPARATRIX = 0, 1
#: default relative accuracy of the interpolants (a numeric well's ``tol``, the ``tol`` key of a well spec)
DEFAULT_TOL = 1e-13
#: the accepted range of that tol
TOL_RANGE = (1e-15, 1e-2)


class EnergyInterpolant:
    """Adaptive piecewise Chebyshev interpolant of ``Q`` functions of ``E`` on ``[0, E_b)``.

    ``func(E)`` (1-D array, ``0 < E < E_b``) returns an array ``(Q, len(E))``.
    ``noise(kind, a, b)`` returns the relative accuracy to which ``func`` is known on a panel
    (``kind`` BOTTOM/SEPARATRIX, ``[a, b]`` in that panel's variable).
    """

    def __init__(self, func: Any, E_b: Any, *, E_split: Any = None, n: int = 20, tol: Any = DEFAULT_TOL,
                 noise: Any = None, bottom_panels: int = 2, separatrix_step: float = 2.5, max_rounds: int = 12) -> None:
        self.E_b = float(E_b)
        self.E_split = 0.5 * self.E_b if E_split is None else float(E_split)
        self.n = int(n)
        self.tol = float(tol)
        s_top = self.E_b - self.E_split
        s_min = self.E_b - np.nextafter(self.E_b, 0.0)      # smallest E_b - E of a float E
        self.u_min = float(np.log(s_min))
        xs = np.sqrt(self.E_split)
        bottom = [(BOTTOM, a, b) for a, b in zip(np.linspace(0.0, xs, bottom_panels + 1)[:-1],
                                                 np.linspace(0.0, xs, bottom_panels + 1)[1:])]
        u_top = float(np.log(s_top))
        k = max(int(np.ceil((u_top - self.u_min) / separatrix_step)), 1)
        ub = np.linspace(self.u_min, u_top, k + 1)
        sep = [(SEPARATRIX, a, b) for a, b in zip(ub[:-1], ub[1:])]
        j = np.arange(self.n)
        self._t = np.cos(np.pi * (j + 0.5) / self.n)          # first-kind nodes, descending
        todo = bottom + sep
        done = []
        self.n_evaluations = 0
        for _ in range(max_rounds):
            if not todo:
                break
            E_nodes = np.concatenate([self._energies(p) for p in todo])
            vals = np.asarray(func(E_nodes), dtype=float)
            self.n_evaluations += E_nodes.size
            vals = vals.reshape(vals.shape[0], len(todo), self.n)
            coefs = self._coefficients(todo, E_nodes.reshape(len(todo), self.n), vals)
            nxt = []
            for i, p in enumerate(todo):
                scale = np.max(np.abs(vals[:, i, :]), axis=1)
                tail = np.max(np.abs(coefs[:, i, -3:]), axis=1)
                floor = self.tol + (noise(*p) if noise is not None else 0.0)
                err = np.max(tail / np.where(scale > 0, scale, 1.0))
                if err <= floor:
                    done.append((p, coefs[:, i, :], err))
                else:
                    kind, a, b = p
                    c = 0.5 * (a + b)
                    nxt += [(kind, a, c), (kind, c, b)]
            todo = nxt
        if todo:
            where = ", ".join(f"E in [{min(e):.6g}, {max(e):.6g}]" for e in (self._energies(p) for p in todo[:3]))
            raise ValueError(f"tol: the energy interpolation did not reach tol = {self.tol!r} after {max_rounds} "
                             "rounds "
                             f"({len(todo)} panels, {where}, ...): the orbit data are not smooth in E there, or V, dV "
                             "are not accurate to tol; give a larger tol (a well spec's key, e.g. {expression: '...', "
                             "tol: 1e-11}) or a smoother, more accurate V")
        self.n_quantities = done[0][1].shape[0]
        self.error_estimate = max(e for _, _, e in done)
        self._build(done)

    # ------------------------------------------------------------------ construction
    def _energies(self, panel: Any) -> Any:
        kind, a, b = panel
        var = 0.5 * (a + b) + 0.5 * (b - a) * self._t
        return var * var if kind == BOTTOM else self.E_b - np.exp(var)

    def _coefficients(self, panels: Any, E_nodes: Any, vals: Any) -> Any:
        """Chebyshev coefficients (Q, P, n) interpolating the values at the energies actually
        sampled: a node energy is rounded to a float, which near E_b moves ``u = log(E_b - E)``
        visibly (only multiples of the float spacing of E_b exist there), so the series is
        fitted at the true positions (least squares on the distinct ones, lower degree where
        fewer than n distinct energies exist in the panel)."""
        Q, P, n = vals.shape
        coefs = np.zeros((Q, P, n))
        for i, (kind, a, b) in enumerate(panels):
            E = E_nodes[i]
            var = np.sqrt(E) if kind == BOTTOM else np.log(self.E_b - E)
            t = (2.0 * var - (a + b)) / (b - a)
            t_u, first = np.unique(t, return_index=True)
            deg = t_u.size - 1
            A = _cheb.chebvander(t_u, deg)
            sol = np.linalg.lstsq(A, vals[:, i, first].T, rcond=None)[0]
            coefs[:, i, :deg + 1] = sol.T
        return coefs

    def _build(self, done: Any) -> None:
        self.breaks, self.coef, self.dcoef = {}, {}, {}
        for kind in (BOTTOM, SEPARATRIX):
            items = sorted([(p[1], p[2], c) for p, c, _ in done if p[0] == kind])
            a = np.array([it[0] for it in items])
            b = np.array([it[1] for it in items])
            if not np.allclose(a[1:], b[:-1], rtol=0, atol=1e-14 * max(1.0, np.abs(b).max())):
                raise RuntimeError("energy interpolation panels do not tile the range")
            C = np.stack([it[2] for it in items], axis=-1)          # (Q, n, P)
            D = np.zeros_like(C)
            D[:, :-1, :] = _cheb.chebder(C, axis=1)
            self.breaks[kind] = np.append(a, b[-1])
            self.coef[kind] = np.ascontiguousarray(C)
            self.dcoef[kind] = np.ascontiguousarray(D)

    @property
    def n_panels(self) -> Any:
        return sum(len(b) - 1 for b in self.breaks.values())

    # ------------------------------------------------------------------ evaluation
    def _run(self, E: Any, quantities: Any, derivative: Any) -> Any:
        E = np.ascontiguousarray(E, dtype=float).ravel()
        q = np.asarray(quantities, dtype=np.int64)
        out = np.empty((q.size, E.size))
        var = np.empty(E.size)
        scale = np.empty(E.size)
        bottom = np.empty(E.size, dtype=np.bool_)
        C = self.dcoef if derivative else self.coef
        _eval_kernel(E, self.E_split, self.E_b, self.breaks[BOTTOM], C[BOTTOM], self.breaks[SEPARATRIX],
                     C[SEPARATRIX], q, out, var, scale, bottom)
        return out, var, scale, bottom

    def evaluate_many(self, E: Any, quantities: Any) -> Any:
        """Values of several quantities (one panel search): array (len(quantities), len(E)).
        ``E`` is a validated 1-D array in ``[0, E_b)``."""
        return self._run(E, quantities, False)[0]

    def evaluate(self, E: Any, quantity: Any, derivative: bool = False) -> Any:
        """``(value, dvalue/dE)`` of one quantity (the derivative None unless requested)."""
        val = self._run(E, (quantity,), False)[0][0]
        if not derivative:
            return val, None
        dv, var, scale, bottom = self._run(E, (quantity,), True)
        dv = dv[0] * scale
        with np.errstate(divide="ignore", invalid="ignore"):
            # dx/dE = 1/(2x) on bottom panels, du/dE = -1/(E_b - E) on separatrix panels
            der = np.where(bottom, dv / (2.0 * var), -dv / (self.E_b - E))
        return val, der

    def evaluate_var(self, E: Any, quantity: Any) -> Any:
        """Values, derivatives with respect to the panel variable (``x = sqrt(E)`` or
        ``u = log(E_b - E)``) and the mask of bottom panels, for callers that combine factors
        analytically."""
        val = self._run(E, (quantity,), False)[0][0]
        dv, var, scale, bottom = self._run(E, (quantity,), True)
        return val, dv[0] * scale, bottom


@package_jit(cache=True)
def _eval_kernel(E: Any, E_split: float, E_b: float, br0: Any, C0: Any, br1: Any, C1: Any, quantities: Any, out: Any,
                 var_out: Any, scale_out: Any, bottom_out: Any) -> None:
    """Piecewise Chebyshev series (Clenshaw) at energies E: for each point the panel variable
    (``sqrt(E)`` below ``E_split``, ``log(E_b - E)`` above), its panel (binary search in the
    breaks), the local ``t`` in [-1, 1] and the series ``C[q, :, panel]`` for every q."""
    n = C0.shape[1]
    for i in range(E.size):
        e = E[i]
        if e <= E_split:
            v = np.sqrt(e)
            br = br0
            C = C0
            bottom_out[i] = True
        else:
            v = np.log(E_b - e)
            br = br1
            C = C1
            bottom_out[i] = False
        P = br.size - 1
        p = np.searchsorted(br, v, side="right") - 1
        if p < 0:
            p = 0
        elif p > P - 1:
            p = P - 1
        a = br[p]
        b = br[p + 1]
        t = (2.0 * v - (a + b)) / (b - a)
        var_out[i] = v
        scale_out[i] = 2.0 / (b - a)
        t2 = 2.0 * t
        for j in range(quantities.size):
            qj = quantities[j]
            b1 = 0.0
            b2 = 0.0
            for k in range(n - 1, 0, -1):
                tmp = C[qj, k, p] + t2 * b1 - b2
                b2 = b1
                b1 = tmp
            out[j, i] = C[qj, 0, p] + t * b1 - b2
