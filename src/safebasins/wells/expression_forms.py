"""Equivalent forms of an expression well's V or V' that share work (wells.expression chooses).

A form is ``lets`` (local variables, in order) and a ``body`` using them; every form equals the
original expression for real q.  The rewrite here: the functions of the exponential family
(exp, sinh, cosh, tanh, sech) whose arguments are rational multiples ``c a`` of one argument ``a``
are rational functions of one exponential ``D = exp(+-g a)`` (``g`` the largest common step of the
``c``); the factors ``D - 1``, which cancel where ``a`` is small, become ``M = expm1(+-g a)``.  D
and M of one argument cost about one call: wells.elementary's ``exp_expm1`` returns both from one
reduction and polynomial.

For a function even or odd in q (``a = q``) the variable is the decaying ``D = exp(-g |q|)`` in
(0, 1] and the sign is restored by ``sign(q)``: no overflow however large ``|q|`` (``exp(+g q)``
would overflow in a power of D at a few hundred), no cancellation in the decaying tail (a sum
``D + c`` with ``D`` in (0, 1] and ``c > 0``).  Each rewrite is offered in three spellings
(D only, D and M, M only); the accuracy test of wells.expression keeps only the forms as accurate
as the best.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any

__all__ = ["Form", "exponential_forms", "FAMILY"]

#: the sympy functions of the exponential family (rewritten into exp)
FAMILY = ("exp", "sinh", "cosh", "tanh", "sech")


@dataclass(frozen=True)
class Form:
    """``lets``: ((symbol or tuple of symbols, sympy expression), ...) evaluated in order (a
    tuple: ``exp_expm1``'s pair); ``body``: the value."""

    lets: tuple[tuple[Any, Any], ...]
    body: Any


def _sympy() -> Any:
    import sympy  # noqa: PLC0415  (lazy: as wells.expression)

    return sympy


def _family_atoms(f: Any) -> list[Any]:
    sp = _sympy()
    kinds = tuple(getattr(sp, k) for k in FAMILY)
    return [a for a in f.atoms(sp.Function) if isinstance(a, kinds)]


def exponential_forms(f: Any, q: Any) -> list[Form]:
    """The forms of ``f`` through one exponential (module docstring); [] when ``f`` calls no
    function of the family, their arguments are not rational multiples of one argument, or ``f``
    is not a rational function of them."""
    sp = _sympy()
    atoms = _family_atoms(f)
    if not atoms:
        return []
    parts = [a.args[0].as_coeff_Mul() for a in atoms]
    base = parts[0][1]
    if any(r != base or not c.is_Rational for c, r in parts) or not base.has(q):
        return []
    g = functools.reduce(sp.gcd, [abs(c) for c, _ in parts])
    T = sp.Dummy("T", positive=True)             # T = exp(g a)

    def to_T(e: Any) -> Any:
        c, r = e.args[0].as_coeff_Mul()
        return T ** (c / g) if r == base and c.is_Rational and (c / g).is_Integer else e

    R = f.xreplace({a: a.rewrite(sp.exp) for a in atoms}).replace(lambda e: isinstance(e, sp.exp), to_T)
    if any(isinstance(a, sp.exp) and a.has(q) and a.args[0].as_coeff_Mul()[1] == base for a in R.atoms(sp.Function)):
        return []
    if not R.is_rational_function(T):             # e.g. log(1 + exp(q)): not a rational function of D
        return []
    R = sp.cancel(sp.together(R))
    k = _power_step(R, T)                        # R a function of T^k: D = exp(+-k g a)
    if k > 1:
        R, g = sp.cancel(R.xreplace({T: T ** sp.Rational(1, k)})), g * k
    D, M, a = sp.Symbol("ex"), sp.Symbol("em"), sp.Symbol("a")
    # (lets before D, the argument of D and M, a factor +-1 or sign(q), f / that factor in D)
    variants: list[tuple[tuple[tuple[Any, Any], ...], Any, Any, Any]] = []
    if base == q:
        mirrored = R.xreplace({T: 1 / T}).subs(q, -q)
        even, odd = sp.cancel(mirrored - R) == 0, sp.cancel(mirrored + R) == 0
        if even or odd:
            s = sp.Symbol("s")
            variants.append((((s, sp.Abs(q)),), -g * s, sp.sign(q) if odd else 1, R.xreplace({T: 1 / D}).subs(q, s)))
    for sgn in (-1, 1):
        variants.append(((), sgn * g * base, 1, R.xreplace({T: D ** sgn})))
    out: list[Form] = []
    expm1, exp_expm1 = sp.Function("expm1"), sp.Function("exp_expm1")
    for lets, arg, sign, RD in variants:
        RD = sp.factor(sp.cancel(RD), D)
        repaired = RD.xreplace({D - 1: M, 1 - D: -M})
        only_m = sp.factor(sp.cancel(RD.xreplace({D: M + 1})), M)
        for body in (RD, repaired, only_m):
            both = body.has(D) and body.has(M)
            used = (((D, M), exp_expm1(a)),) if both else tuple(
                (k, v) for k, v in ((D, sp.exp(a)), (M, expm1(a))) if body.has(k))
            out.append(Form(lets + ((a, arg),) + used, sign * body))
    return out


def _power_step(R: Any, T: Any) -> int:
    """The largest k such that the rational function R of T is a function of T^k."""
    sp = _sympy()
    try:
        monoms = [m[0] for part in sp.fraction(R) for m in sp.Poly(part, T).monoms()]
    except sp.PolynomialError:
        return 1
    return int(functools.reduce(math.gcd, monoms, 0)) or 1
