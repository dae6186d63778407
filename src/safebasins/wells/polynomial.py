"""Polynomial wells ``V(q) = sum_k c_k q^k`` (the paper's eq (2) is ``c = (0, 0, 1/2, 0, -1/4)``).

:class:`PolynomialWell` is a :class:`~safebasins.wells.numeric.NumericWell` whose potential is
a polynomial: V and V' by Horner's rule, the barriers from the real roots of ``V'``.

Which sides have a barrier.  ``c_0 = c_1 = 0`` and ``c_2 > 0`` make ``q = 0`` a non-degenerate
minimum, so ``V' > 0`` just right of 0 and ``V' < 0`` just left of it.  On each side the barrier
is the real root of ``V'`` nearest to 0 at which ``V'`` changes sign (a root of even
multiplicity is an inflection point of V, not a maximum).  If ``V'`` has no such root on a side
it keeps its sign there, so ``V`` increases monotonically and, being a non-constant polynomial,
tends to ``+inf``: no escape that way (barrier ``+-inf``).  A side on which ``V -> -inf``
without a maximum is therefore impossible: ``V`` would have to turn down, and ``V'`` to change
sign, somewhere.  The remaining special cases are rejected with ValueError by
:class:`NumericWell`: no barrier on either side (e.g. an even polynomial with positive leading
coefficient, or the harmonic well) and a degenerate barrier (a root of ``V'`` of odd
multiplicity >= 3, ``V''(q_b) = 0``).

``cubic()`` is the Helmholtz-Thompson escape equation ``q'' + q - q^2 = F sin(Omega t + Psi)``:
``V = q^2/2 - q^3/3``, one barrier at ``q = 1`` with energy 1/6, none on the left.
"""
from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt
from numpy.polynomial import polynomial as P

from safebasins.core.checks import as_array
from safebasins.wells.base import STEP_COST_POLY4, STEP_COST_POLY8
from safebasins.wells.numeric import NumericWell, check_options
from safebasins.wells.compiled import POLY_DEGREES, polynomial_code

__all__ = ["PolynomialWell", "polynomial", "cubic", "quartic_polynomial"]


def _check_coefficients(coefficients: Any) -> Any:
    try:
        c = np.array(coefficients, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"coefficients must be a sequence of numbers c_0..c_n, got {coefficients!r}") from exc
    if c.ndim != 1 or c.size < 3:
        raise ValueError(f"coefficients must be a 1-D sequence c_0, c_1, c_2, ... (at least 3), got shape {c.shape}")
    if not np.isfinite(c).all():
        raise ValueError("coefficients must be finite (no NaN / inf)")
    if c[0] != 0.0:
        raise ValueError(f"coefficients: c_0 = {float(c[0])!r}, must be 0 (V(0) = 0: energies from the well bottom)")
    if c[1] != 0.0:
        raise ValueError(f"coefficients: c_1 = {float(c[1])!r}, must be 0 (V'(0) = 0: the minimum at q = 0)")
    if not c[2] > 0.0:
        raise ValueError(f"coefficients: c_2 = {float(c[2])!r}, must be > 0 (V''(0) = 2 c_2 > 0: q = 0 a minimum)")
    return np.trim_zeros(c, "b")


class PolynomialWell(NumericWell):
    """``V(q) = sum_k c_k q^k`` with ``c_0 = c_1 = 0``, ``c_2 > 0``.

    ``coefficients`` (float ndarray, trailing zeros removed) is kept for compiled integrators;
    ``dV_coefficients`` are those of ``V'``.  Remaining keywords go to :class:`NumericWell`
    (``tol``, checked first); ``search_bound`` defaults to a bound on every real root of ``V'``
    and of ``V - E_b`` (Cauchy), so that the no-barrier side closes within it; where Cauchy's
    bound exceeds 1e3 times 4 x the largest of those roots (high degree, small leading
    coefficient: 1.7e30 for the degree-8 Taylor pendulum), the latter.
    """

    name = "polynomial"

    def __init__(self, coefficients: Any, *, name: str | None = None, **kwargs: Any) -> None:
        check_options(**{k: kwargs[k] for k in ("tol", "n_scan", "asymptotes") if k in kwargs})
        c = _check_coefficients(coefficients)
        self.coefficients = c
        self.dV_coefficients = P.polyder(c)
        self._d2 = P.polyder(self.dV_coefficients)
        if "barriers" in kwargs:
            raise ValueError("barriers: a PolynomialWell finds its barriers from the roots of V'")
        if "search_bound" not in kwargs:
            kwargs["search_bound"] = self._default_search_bound()
        dc = self.dV_coefficients
        super().__init__(lambda q: P.polyval(q, c), lambda q: P.polyval(q, dc), name=name, **kwargs)

    def _default_search_bound(self) -> Any:
        cauchy = self._cauchy_bound()
        roots = self._root_bound()
        return cauchy if not (roots > 0 and cauchy > 1e3 * roots) else roots

    def _root_bound(self) -> Any:
        """4 x the largest real root of ``V'`` and of ``V - E_b`` (0 without a barrier)."""
        barriers = self._locate_barriers(None, None)
        Vb = [float(P.polyval(b, self.coefficients)) for b in barriers if np.isfinite(b)]
        if not Vb:
            return 0.0
        shifted = self.coefficients.copy()
        shifted[0] -= min(Vb)
        r = P.polyroots(shifted)
        real = r[np.abs(r.imag) <= 1e-7 * max(1.0, float(np.max(np.abs(r))))].real
        return 4.0 * float(np.max(np.abs(np.concatenate([real, self._real_roots]))))

    def _cauchy_bound(self) -> Any:
        """Search bound (x4 margin) from Cauchy's root bound ``1 + max |a_k / a_n|``: it contains
        every real root of ``V'`` (the barriers) and of ``V - E`` for every E up to a bound of
        ``|V|`` on the roots' range, so the no-barrier side rises above the escape energy within it."""
        c = self.coefficients
        dc = self.dV_coefficients
        b1 = 1.0 + np.max(np.abs(dc[:-1] / dc[-1]))
        Eb = float(np.sum(np.abs(c) * b1 ** np.arange(c.size)))    # >= |V| on |q| <= b1
        cc = c.copy()
        cc[0] = -Eb
        b2 = 1.0 + np.max(np.abs(cc[:-1] / cc[-1]))
        return float(4.0 * max(b1, b2))

    def _locate_barriers(self, B: Any, n: Any) -> Any:
        """Nearest sign-changing real roots of V' on each side of 0 (Newton-polished)."""
        dc = self.dV_coefficients
        if dc.size <= 2:           # V' = 2 c_2 q: harmonic, no barrier
            return (-np.inf, np.inf)
        r = P.polyroots(P.polydiv(dc, [0.0, 1.0])[0])   # V' = q * (2 c_2 + 3 c_3 q + ...)
        scale = max(1.0, float(np.max(np.abs(r))))
        real = np.sort(r[np.abs(r.imag) <= 1e-7 * scale].real)
        real = np.array([self._polish(x) for x in real])
        out = []
        for side in (-1.0, 1.0):
            cand = np.sort(side * real[side * real > 0])        # distances from 0, ascending
            barrier = side * np.inf
            for i, s in enumerate(cand):
                nxt = cand[i + 1] if i + 1 < cand.size else 2.0 * s + 1.0
                probe = side * 0.5 * (s + nxt)
                if side * P.polyval(probe, dc) < 0:          # V' changed sign: a maximum
                    barrier = side * s
                    break
            out.append(float(barrier))
        self._real_roots = real
        return tuple(out)

    def _check_monotone(self, side: Any, lim: Any) -> None:
        """No root of V' strictly between 0 and the limit (a root of even multiplicity there is
        an equilibrium with V' = 0 whose orbit is not periodic)."""
        inner = [r for r in self._real_roots if 0 < side * r < abs(lim) * (1 - 1e-12)]
        if inner:
            raise ValueError(f"coefficients: V' vanishes at q = {float(inner[0])!r} inside the well without changing "
                             "sign "
                             "(an inflection point with V' = 0): the orbit through it is not periodic")

    def _polish(self, x: Any) -> Any:
        dc, d2 = self.dV_coefficients, self._d2
        for _ in range(8):
            f, g = P.polyval(x, dc), P.polyval(x, d2)
            if g == 0 or not np.isfinite(f / g):
                break
            step = f / g
            x = x - step
            if abs(step) <= 4 * np.finfo(float).eps * max(abs(x), 1e-300):
                break
        return float(x)

    def _curvature(self, qb: Any) -> Any:
        return float(-P.polyval(qb, self._d2))

    def V(self, q: npt.ArrayLike) -> Any:
        return P.polyval(as_array("q", q), self.coefficients)

    def dV(self, q: npt.ArrayLike) -> Any:
        return P.polyval(as_array("q", q), self.dV_coefficients)


    # ------------------------------------------------------------------ the numerics
    @property
    def step_cost(self) -> float:  # type: ignore[override]  # (Well's class attribute, computed here)
        """Step cost of its degree class (``STEP_COST_POLY4`` / ``STEP_COST_POLY8`` of
        safebasins.wells.base)."""
        return STEP_COST_POLY4 if self.coefficients.size - 1 <= POLY_DEGREES[0] else STEP_COST_POLY8

    def _compiled_form(self) -> Any:
        return polynomial_code(self.coefficients, self.barriers, self.name)

    def potential_text(self) -> str:
        terms = [f"{'-' if c < 0 else '+'} {abs(c)!r} q^{k}" for k, c in enumerate(self.coefficients.tolist())
                 if c != 0.0]
        return " ".join(terms).removeprefix("+ ")

    def numerics_attrs(self) -> Any:
        return {**super().numerics_attrs(), "well_coefficients": np.array(self.coefficients, dtype=float)}

    def spec(self) -> Any:
        if self.name != "polynomial":          # a named polynomial well (cubic)
            return super().spec()
        return {"name": "polynomial", "coefficients": [float(c) for c in self.coefficients], **self._tol_spec()}


def polynomial(coefficients: Any, **kwargs: Any) -> Any:
    """The well ``V = sum_k c_k q^k`` (see :class:`PolynomialWell`)."""
    return PolynomialWell(coefficients, **kwargs)


def cubic(**kwargs: Any) -> Any:
    """Helmholtz-Thompson escape well ``V = q^2/2 - q^3/3`` (``q'' + q - q^2 = F sin(...)``):
    barrier at ``q = 1`` with energy 1/6, none on the left (``V -> inf`` as ``q -> -inf``)."""
    kwargs.setdefault("name", "cubic")
    return PolynomialWell([0.0, 0.0, 0.5, -1.0 / 3.0], **kwargs)


def quartic_polynomial(**kwargs: Any) -> Any:
    """The paper's well, eq (2), ``V = q^2/2 - q^4/4`` by quadrature (closed form:
    :mod:`safebasins.wells.quartic`)."""
    kwargs.setdefault("name", "quartic-numeric")
    return PolynomialWell([0.0, 0.0, 0.5, 0.0, -0.25], **kwargs)
