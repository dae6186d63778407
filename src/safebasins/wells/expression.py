"""Wells written as an expression in ``q``: ``{expression: "1 - cos(q)"}``.

The text is parsed by sympy; ``V'`` is its symbolic derivative.  Each is printed in its most
accurate equivalent form, the cheapest of the equally accurate ones (sympy's spellings, the
rewrites of wells.expression_forms), common subexpressions once (:func:`generate_source`).  One
generated Python source of ``V(q)`` and ``dV(q)`` serves every consumer:

* the theory (action-angle variables by quadrature, :class:`~safebasins.wells.numeric.NumericWell`)
  runs it vectorised on numpy arrays;
* the compiled engines run it through the well's compiled form (wells.compiled.target_code),
  with ``dV_V(q) = (V'(q), V(q))`` sharing their calls (wells.expression_joint),
  compiled by numba for the CPU and by numba-cuda for the GPU; every product is written with
  ``mul`` (never contracted into an fma by the GPU compiler) and the functions are those of
  wells.elementary compiled for the target (the same bits on both; ``atan`` and ``asinh``: the
  target's libm).

The generated source is what a user would write by hand (``1.0 - cos(q)``, ``sin(q)``), the
functions named without a module; numpy's run it for the theory, wells.elementary's in the
engines.
A side where ``V`` tends to a finite limit (sympy's ``limit``) is declared open at infinity with
that limit as its escape energy (sech^2, Morse).

Allowed: the variable ``q``, numbers, ``+ - * / **``, ``pi``, ``E`` and the functions of
:data:`FUNCTIONS`.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from types import SimpleNamespace
from typing import Any

import numpy as np

from safebasins.wells.base import STEP_COST_ARITHMETIC, STEP_COST_ELEMENTARY, STEP_COST_TRANSCENDENTAL
from safebasins.wells.numeric import NumericWell
from safebasins.wells import elementary
from safebasins.wells.compiled import Jit, WellCode, mul, target_code
from safebasins.wells.expression_forms import Form, exponential_forms
from safebasins.wells.expression_joint import joint_source

__all__ = ["ExpressionWell", "expression", "FUNCTIONS"]

#: functions an expression may use -> their numpy version (the theory's arrays); in the compiled
#: engines those of wells.elementary (the same bits on the CPU and the GPU), atan and asinh the
#: target's libm
FUNCTIONS = {"sin": np.sin, "cos": np.cos, "tan": np.tan, "exp": np.exp, "log": np.log, "sqrt": np.sqrt,
             "sinh": np.sinh, "cosh": np.cosh, "tanh": np.tanh, "atan": np.arctan, "asinh": np.arcsinh}
#: the functions of the generated source that are not wells.elementary's
_LIBM = {"atan": math.atan, "asinh": math.asinh}
#: the namespace of the generated source when it runs on numpy arrays (the theory)
#: the functions only the rewritten forms call (wells.expression_forms), with their numpy version
_REWRITE_FUNCTIONS = {"expm1": np.expm1, "exp_expm1": lambda a: (np.exp(a), np.expm1(a))}
_NAMESPACE_NUMPY = {"mul": np.multiply, "pow": np.power, "copysign": np.copysign, **_REWRITE_FUNCTIONS, **FUNCTIONS}


def _sympy() -> Any:
    import sympy  # noqa: PLC0415  (lazy: sympy takes ~0.5 s to import, needed only to build an expression well)

    return sympy


def parse(text: str) -> tuple[Any, Any]:
    """``(V, q)`` as sympy objects from the text of an expression in q; ValueError naming
    ``expression`` for anything else."""
    sp = _sympy()
    if not isinstance(text, str) or not text.strip():
        raise ValueError(f"expression must be a non-empty string in q, e.g. '1 - cos(q)', got {text!r}")
    if "__" in text or any(c in text for c in ";\n"):
        raise ValueError(f"expression: {text!r} is not a formula in q")
    q = sp.Symbol("q", real=True)
    names = {"q": q, "pi": sp.pi, "E": sp.E, "sech": sp.sech}
    names.update({k: getattr(sp, k) for k in FUNCTIONS})
    from sympy.parsing.sympy_parser import parse_expr, standard_transformations  # noqa: PLC0415  (lazy: as _sympy)

    try:
        V = parse_expr(text, local_dict=names, global_dict={"Integer": sp.Integer, "Float": sp.Float,
                                                            "Rational": sp.Rational, "Symbol": sp.Symbol},
                       transformations=standard_transformations)
    except Exception as exc:  # noqa: BLE001  (sympy raises SyntaxError, TokenError, TypeError, NameError ...)
        raise ValueError(f"expression: cannot read {text!r} as a formula in q ({type(exc).__name__}: {exc})") from None
    if not isinstance(V, sp.Expr):
        raise ValueError(f"expression: {text!r} is not a formula in q")
    extra = sorted(str(s) for s in V.free_symbols if s != q)
    if extra:
        raise ValueError(f"expression: unknown name(s) {', '.join(extra)} in {text!r} (the only variable is q; "
                         f"functions: {', '.join(sorted(FUNCTIONS))}, sech; constants pi, E)")
    if q not in V.free_symbols:
        raise ValueError(f"expression: {text!r} does not depend on q")
    return V, q


class _Printer:
    """Python source of a sympy expression: calls of the functions by their names, products with
    ``mul`` (left to right), quotients as ``/``, integer powers as repeated products."""

    def __init__(self, q: Any) -> None:
        self.q = q
        self.sp = _sympy()

    def __call__(self, e: Any) -> str:
        sp = self.sp
        if e.is_Symbol:
            return str(e.name)                  # q, or a local variable of the generated code
        if e is sp.pi:
            return repr(math.pi)
        if e is sp.E:
            return repr(math.e)
        if e.is_Number:
            if not e.is_real:
                raise ValueError(f"expression: complex constant {e}")
            return repr(float(e))
        if e.is_Add:
            return self._add(e)
        if e.is_Mul:
            return self._mul(e)
        if e.is_Pow:
            return self._pow(e.base, e.exp)
        if isinstance(e, sp.sech):
            return f"1.0 / cosh({self(e.args[0])})"
        if isinstance(e, sp.Abs):
            return f"abs({self(e.args[0])})"
        if isinstance(e, sp.sign):
            return f"copysign(1.0, {self(e.args[0])})"
        if type(e).__name__ in _REWRITE_FUNCTIONS:  # the rewritten forms' (wells.expression_forms)
            return f"{type(e).__name__}({self(e.args[0])})"
        name = type(e).__name__
        if isinstance(e, sp.Function) and name in FUNCTIONS and len(e.args) == 1:
            return f"{name}({self(e.args[0])})"
        raise ValueError(f"expression: {e} is not supported (functions: {', '.join(sorted(FUNCTIONS))}, sech)")

    def _wrap(self, e: Any) -> str:
        s = self(e)
        return f"({s})" if e.is_Add or (e.is_Number and float(e) < 0) else s

    def _add(self, e: Any) -> str:
        terms = list(e.args)
        out = self._wrap(terms[0]) if terms[0].is_Add else self(terms[0])
        for t in terms[1:]:
            if t.could_extract_minus_sign():
                out = f"{out} - {self._term(-t)}"
            else:
                out = f"{out} + {self._term(t)}"
        return out

    def _term(self, t: Any) -> str:
        s = self(t)
        return f"({s})" if t.is_Add or s.startswith("-") else s

    def _product(self, factors: list[Any]) -> str:
        out = self._factor(factors[0])
        for f in factors[1:]:
            out = f"mul({out}, {self._factor(f)})"
        return out

    def _factor(self, f: Any) -> str:
        s = self(f)
        return f"({s})" if f.is_Add or s.startswith("-") or " / " in s else s

    def _mul(self, e: Any) -> str:
        sp = self.sp
        if e.could_extract_minus_sign():
            return f"-{self._factor(-e)}"
        num, den = [], []
        for f in e.args:
            if f.is_Pow and f.exp.is_number and f.exp.is_negative:
                den.append(sp.Pow(f.base, -f.exp, evaluate=False) if f.exp != -1 else f.base)
            elif f.is_Rational and not f.is_Integer:
                if f.p != 1:
                    num.append(sp.Integer(f.p))
                den.append(sp.Integer(f.q))
            else:
                num.append(f)
        top = self._product(num) if num else "1.0"
        if not den:
            return top
        return f"{top} / {self._factor(den[0]) if len(den) == 1 else '(' + self._product(den) + ')'}"

    def _pow(self, b: Any, x: Any) -> str:
        sp = self.sp
        if x.is_Integer or (x.is_Float and float(x).is_integer()):
            n = int(x)
            if n == 0:
                return "1.0"
            if n < 0:
                return f"1.0 / {self._factor(sp.Pow(b, -n, evaluate=False)) if n != -1 else self._factor(b)}"
            return self._product([b] * n)
        if x == sp.Rational(1, 2):
            return f"sqrt({self(b)})"
        if x == sp.Rational(-1, 2):
            return f"1.0 / sqrt({self(b)})"
        return f"pow({self(b)}, {self(x)})"


#: where the candidate forms of V and V' are compared with a 40-digit evaluation: ``|q|`` from
#: 1e-4 to 30 (the bottom and the decaying tail) and far out, to 1e3 (no form may overflow into a
#: NaN or an infinity where the value is a double)
_PROBE = np.concatenate([-np.geomspace(1e-4, 30.0, 40)[::-1], [-1e3, -300.0, -100.0, 100.0, 300.0, 1e3],
                         np.geomspace(1e-4, 30.0, 40)])
#: forms whose largest relative error is within this of the most accurate form's are as accurate
#: (four ulps of 1): the cheapest of them is printed
ACCURACY_SLACK = 4 * 2.0 ** -52
_TINY, _HUGE = np.finfo(float).tiny, np.finfo(float).max


def _exact(f: Any, q: Any) -> list[Any]:
    """``f`` at the probe points to 30 digits (mpmath at ``40 + 3 |q|`` digits, the cancellation
    of an exponential tail included, confirmed at twice that); None where it is not a finite real
    number, exactly zero or not confirmed."""
    import mpmath  # type: ignore[import-untyped]  # noqa: PLC0415  (lazy: sympy's dependency, as sympy)

    sp = _sympy()
    fn = sp.lambdify(q, f, modules="mpmath")

    def at(x: float, dps: int) -> Any:
        with mpmath.workdps(dps):
            try:
                e = fn(mpmath.mpf(x))
            except (ZeroDivisionError, ValueError, OverflowError):
                return None
            return e if isinstance(e, mpmath.mpf) and mpmath.isfinite(e) and e != 0 else None

    out: list[Any] = []
    for x in _PROBE:
        dps = 40 + 3 * int(abs(x))
        e, e2 = at(float(x), dps), at(float(x), 2 * dps)
        with mpmath.workdps(2 * dps):
            out.append(e2 if e is not None and e2 is not None and abs(e - e2) <= abs(e2) * 1e-30 else None)
    return out


def _relative_error(form: Form, exact: list[Any], pr: _Printer) -> float:
    """Largest relative error of the double-precision evaluation of ``form`` (its generated source,
    on numpy) against ``exact`` on the probe points: a value that underflows counts its error
    relative to the smallest normal double, one that overflows only a NaN; a NaN or an infinity
    where the value is a double is an infinite error."""
    import mpmath  # noqa: PLC0415  (as _exact)

    f = _functions(_code("V", form, pr) + "\n\ndef dV(q):\n    return 0.0\n", _NAMESPACE_NUMPY)[0]
    with np.errstate(all="ignore"):
        got = np.asarray(f(_PROBE.copy()), dtype=float) * np.ones_like(_PROBE)
    worst = 0.0
    with mpmath.workdps(40):
        for g, e in zip(got, exact):
            if e is None:
                continue
            if abs(e) > _HUGE:
                err = math.inf if np.isnan(g) else 0.0
            elif not np.isfinite(g):
                err = math.inf
            else:
                err = float(abs(mpmath.mpf(float(g)) - e) / max(abs(e), _TINY))
            worst = max(worst, err)
    return worst


def _cost(form: Form) -> tuple[int, int, int]:
    """(function calls, counting exp and expm1 of one argument once; calls; operations) of a form."""
    sp = _sympy()
    exprs = [v for _, v in form.lets] + [form.body]
    calls = {(type(c).__name__, c.args) for e in exprs for c in e.atoms(sp.Function)
             if not isinstance(c, (sp.Abs, sp.sign))}
    groups = {("exp", a) if n in ("exp", *_REWRITE_FUNCTIONS) else (n, a) for n, a in calls}
    return len(groups), len(calls), int(sum(sp.count_ops(e) for e in exprs))


def _choose(forms: list[Form], n_given: int, f: Any, q: Any, pr: _Printer) -> Form:
    """The form printed: of the first ``n_given`` (sympy's own spellings) the most accurate
    (ties: the first), unless a form as accurate (:data:`ACCURACY_SLACK`) is cheaper
    (:func:`_cost`) or that one is not as accurate as the best of all."""
    if len(forms) == 1:
        return forms[0]
    exact = _exact(f, q)
    errors = [_relative_error(g, exact, pr) for g in forms]
    default = int(np.argmin(errors[:n_given]))
    best = min(errors)
    if not math.isfinite(best):
        return forms[default]
    ok = [i for i, e in enumerate(errors) if e <= best + ACCURACY_SLACK]
    cheapest = min(ok, key=lambda i: (_cost(forms[i]), i))
    if default in ok and _cost(forms[default]) <= _cost(forms[cheapest]):
        return forms[default]
    return forms[cheapest]


def _forms(f: Any, q: Any, spellings: bool) -> tuple[list[Form], int]:
    """(candidate forms of ``f``, how many are sympy's spellings of it): ``f`` itself and, when
    ``spellings``, its simplified and cancelled forms; then the rewrites of
    wells.expression_forms."""
    sp = _sympy()
    given: list[Any] = []
    for g in (f, sp.simplify(f), sp.cancel(f)) if spellings else (f,):
        if all(g != h for h in given):
            given.append(g)
    forms = [Form((), g) for g in given]
    seen = {(g.lets, g.body) for g in forms}
    for g in exponential_forms(f, q):
        if (g.lets, g.body) not in seen:
            seen.add((g.lets, g.body))
            forms.append(g)
    return forms, len(given)


def _code(name: str, form: Form, pr: _Printer) -> str:
    """Source of ``def name(q)`` computing ``form``: its local variables, the common
    subexpressions of its body once each (sympy's cse), the base of an integer power once."""
    sp = _sympy()
    reps, (body,) = sp.cse([form.body], symbols=sp.numbered_symbols("t"))
    lines: list[str] = []
    bases: dict[Any, Any] = {}
    for k, v in (*form.lets, *reps):
        names = ", ".join(map(str, k)) if isinstance(k, tuple) else str(k)
        lines.append(f"    {names} = {pr(_name_power_bases(v, bases, lines, pr))}")
    lines.append(f"    return {pr(_name_power_bases(body, bases, lines, pr))}")
    return f"def {name}(q):\n" + "\n".join(lines) + "\n"


def _name_power_bases(e: Any, bases: dict[Any, Any], lines: list[str], pr: _Printer) -> Any:
    """``e`` with the base of every integer power ``b^n`` (``|n| >= 2``, ``b`` not a name or a
    number; printed as repeated products) replaced by a local variable, defined in ``lines``
    before its first use."""
    sp = _sympy()
    if e.is_Atom:
        return e
    args = [_name_power_bases(a, bases, lines, pr) for a in e.args]
    e = e.func(*args) if any(a is not b for a, b in zip(args, e.args)) else e
    if e.is_Pow and e.exp.is_Integer and abs(e.exp) >= 2 and not (e.base.is_Symbol or e.base.is_Number):
        if e.base not in bases:
            bases[e.base] = sp.Symbol(f"b{len(bases)}")
            lines.append(f"    {bases[e.base]} = {pr(e.base)}")
        return sp.Pow(bases[e.base], e.exp, evaluate=False)
    return e


def generate_source(V: Any, q: Any) -> tuple[str, Any]:
    """(source text of ``V(q)`` and ``dV(q)``, the sympy derivative as printed).

    Each of V and V' is printed in whichever equivalent form keeps the best relative accuracy in
    double precision at the probe points (``|q|`` in [1e-4, 30] and far out, against a 40-digit
    evaluation), the cheapest among those as accurate (:func:`_choose`): sympy's spellings of V'
    (as differentiated, simplified, cancelled: the derivative of tanh(q)^2 as differentiated,
    2 tanh(q) (1 - tanh(q)^2), has no relative accuracy where the well's tail decays) and the
    rewrites through one exponential (wells.expression_forms: sech^2's V' = 2 tanh(q)/cosh(q)^2 as
    -8 sign(q) D M/(D + 1)^3 with D = exp(-2|q|), M = expm1(-2|q|)).  Common subexpressions are
    computed once."""
    sp = _sympy()
    dV = sp.diff(V, q)
    pr = _Printer(q)
    fV = _choose(*_forms(V, q, spellings=False), V, q, pr)
    fdV = _choose(*_forms(dV, q, spellings=True), dV, q, pr)
    printed = fdV.body
    for k, v in reversed(fdV.lets):
        if isinstance(k, tuple):                     # (D, M) = exp_expm1(a)
            k, v = dict(zip(k, (sp.exp(v.args[0]), sp.Function("expm1")(v.args[0])))), None
        printed = printed.xreplace(k if v is None else {k: v})
    return f"{_code('V', fV, pr)}\n\n{_code('dV', fdV, pr)}", printed


def _step_cost(V: Any, dV: Any) -> float:
    """Step cost of the generated code (safebasins.wells.base): arithmetic (sums, products,
    quotients, powers: vectorised lanes), calling wells.elementary (sin, exp, tanh, ...: vectorised
    lanes, each call some tens of operations) or a libm function (atan, asinh: scalar lanes)."""
    sp = _sympy()
    called = {type(f).__name__ for f in V.atoms(sp.Function) | dV.atoms(sp.Function)}
    if called & set(_LIBM):
        return STEP_COST_TRANSCENDENTAL
    return STEP_COST_ELEMENTARY if called or not _integer_powers(V, dV) else STEP_COST_ARITHMETIC


def _integer_powers(V: Any, dV: Any) -> bool:
    """True when every power of V and V' has an integer or +-1/2 exponent (products, sqrt)."""
    sp = _sympy()
    return all(p.exp.is_Integer or abs(p.exp) == sp.Rational(1, 2) for p in V.atoms(sp.Pow) | dV.atoms(sp.Pow))


def _functions(source: str, namespace: dict[str, Any]) -> tuple[Callable[..., Any], Callable[..., Any]]:
    ns = dict(namespace)
    exec(compile(source, "<safebasins expression well>", "exec"), ns)   # our own generated text
    return ns["V"], ns["dV"]


def _joint_functions(source: str, joint: str, namespace: dict[str, Any]) -> tuple[Callable[..., Any], ...]:
    """(V, dV, dV_V) of the generated source and its joint form (wells.expression_joint)."""
    ns = dict(namespace)
    exec(compile(f"{source}\n\n{joint}", "<safebasins expression well>", "exec"), ns)   # our own generated text
    return ns["V"], ns["dV"], ns["dV_V"]


def _limit(V: Any, q: Any, side: int) -> float | None:
    """Finite limit of V as q -> side * inf, or None (unbounded or oscillating)."""
    sp = _sympy()
    try:
        lim = sp.limit(V, q, side * sp.oo)
    except (NotImplementedError, ValueError):
        return None
    if isinstance(lim, sp.AccumBounds) or not (lim.is_number and lim.is_finite and lim.is_real):
        return None                        # unbounded, or oscillating (AccumBounds: 1 - cos q)
    return float(lim)


class ExpressionWell(NumericWell):
    """A well ``V(q)`` given as text, e.g. ``ExpressionWell("1 - cos(q)")`` (the pendulum).

    ``expression`` is kept as given; ``formula`` is sympy's reading of it, ``derivative`` its
    V'(q), ``source`` the generated Python source of V and dV (what the engines compile).
    Remaining keywords go to :class:`NumericWell` (``tol``, ``search_bound``, ...).
    """

    name = "expression"

    def __init__(self, expression: str, *, name: str | None = None, **kwargs: Any) -> None:
        V, q = parse(expression)
        self.expression = expression
        self.formula = str(V)
        self.source, dV = generate_source(V, q)
        self.derivative = str(dV)
        self.step_cost = _step_cost(V, dV)
        Vn, dVn = _functions(self.source, _NAMESPACE_NUMPY)
        kwargs.setdefault("asymptotes", (_limit(V, q, -1), _limit(V, q, 1)))
        super().__init__(Vn, dVn, name=name, **kwargs)

    def _compiled_form(self) -> WellCode:
        source = self.source
        joint = joint_source(source)

        def functions(jit: Jit) -> tuple[Callable[..., Any], ...]:
            return _joint_functions(source, joint, _compiled_namespace(elementary.for_target(jit)))

        return target_code(functions, self.barriers, self.name, f"{elementary.MODULE_HASH}\0{source}\0{joint}")

    def potential_text(self) -> str:
        return self.formula

    def spec(self) -> dict[str, Any]:
        if self.name != ExpressionWell.name:            # a named well (wells.NAMED_WELLS)
            return {"name": self.name}
        return {"name": "expression", "expression": self.expression, **self._tol_spec()}


def _compiled_namespace(functions: SimpleNamespace) -> dict[str, Any]:
    """The generated source's names in a compiled engine: ``functions`` (wells.elementary compiled
    for the target), the libm functions elementary has not, the wells' ``mul``."""
    own = {k: getattr(functions, k) for k in (*FUNCTIONS, "pow", "sincos", *_REWRITE_FUNCTIONS) if k not in _LIBM}
    return {"mul": mul, "copysign": functions._copysign, **_LIBM, **own}


def expression(text: str, **kwargs: Any) -> ExpressionWell:
    """The well ``V(q) = text`` (see :class:`ExpressionWell`)."""
    return ExpressionWell(text, **kwargs)
