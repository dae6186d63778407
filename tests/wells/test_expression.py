"""wells.expression's generated V and V': accurate against closed forms written by hand in mpmath
(not sympy's), finite far out, common subexpressions computed once, the exponential family
through one exponential where that is as accurate, and the same bits compiled for the CPU lanes
as run as Python source over wells.elementary (the code the CUDA simulator runs).

Measured (this file's sweep, numpy's exp and expm1: 4000 points with |q| in [1e-8, 40]): largest
relative error of V and V' 3.7e-16, 6.2e-16 (sech^2), 3.0e-16, 3.1e-16 (Morse), 5.0e-16,
7.0e-16 (1 - sech q), 3.6e-16, 1.1e-16 (sinh^2(q/2)); the bound is 8 ulps of 1 (for exp(-q^2)
plus the rounding of q^2 times q^2).
"""
from __future__ import annotations

import re
import sys
from collections.abc import Callable
from typing import Any

import mpmath as mp
import numpy as np
import pytest
import sympy as sp
from numba import njit

from safebasins import wells
from safebasins.wells import elementary
from safebasins.wells.expression_forms import exponential_forms
import safebasins.wells.expression  # noqa: F401  (the module; the package binds the name to the function)

X = sys.modules["safebasins.wells.expression"]
#: relative error allowed (8 ulps of 1)
BOUND = 8 * 2.0 ** -52
#: text -> (V, V') in closed form, evaluated by mpmath
CLOSED: dict[str, tuple[Callable[[Any], Any], Callable[[Any], Any]]] = {
    "tanh(q)**2": (lambda q: mp.tanh(q) ** 2, lambda q: 2 * mp.tanh(q) * mp.sech(q) ** 2),
    "(1 - exp(-q))**2": (lambda q: mp.expm1(-q) ** 2, lambda q: -2 * mp.exp(-q) * mp.expm1(-q)),
    "1 - 1/cosh(q)": (lambda q: 1 - mp.sech(q), lambda q: mp.tanh(q) * mp.sech(q)),
    "1 - exp(-q**2)": (lambda q: -mp.expm1(-q * q), lambda q: 2 * q * mp.exp(-q * q)),
    "cosh(q/2)**2 - 1": (lambda q: mp.sinh(q / 2) ** 2, lambda q: mp.sinh(q) / 2),
}
Q = np.concatenate([-np.geomspace(1e-8, 40.0, 2000)[::-1], np.geomspace(1e-8, 40.0, 2000)])
FAR = np.array([-1e4, -1e3, -710.0, -300.0, 300.0, 710.0, 1e3, 1e4])


def _generated(text: str, namespace: dict[str, Any]) -> tuple[Callable[..., Any], Callable[..., Any]]:
    V, q = X.parse(text)
    return X._functions(X.generate_source(V, q)[0], namespace)


#: the relative error that rounding an argument itself brings (exp(-q^2): q^2 rounded, times q^2)
CONDITION = {"1 - exp(-q**2)": lambda q: 2.0 ** -53 * q * q}


def _worst(got: np.ndarray, exact: Callable[[Any], Any], q: np.ndarray, text: str) -> float:
    """Largest relative error over BOUND plus the argument's rounding (CONDITION): <= 1 passes."""
    cond = CONDITION.get(text, lambda q: 0.0)
    worst = 0.0
    with mp.workdps(60):
        for g, x in zip(got, q):
            e = exact(mp.mpf(float(x)))
            if e != 0 and abs(e) > 1e-300:
                worst = max(worst, float(abs((mp.mpf(float(g)) - e) / e)) / (BOUND + cond(float(x))))
    return worst


@pytest.mark.parametrize("text", list(CLOSED))
def test_generated_forms_accurate_and_finite(text):
    V, dV = _generated(text, X._NAMESPACE_NUMPY)
    rV, rdV = CLOSED[text]
    with np.errstate(all="ignore"):
        v, d = V(Q.copy()), dV(Q.copy())
        far_v, far_d = V(FAR.copy()), dV(FAR.copy())
    assert _worst(v, rV, Q, text) <= 1.0, text
    assert _worst(d, rdV, Q, text) <= 1.0, text
    # far out no NaN: a value that is a double is a double (overflow only where V itself overflows)
    with mp.workdps(60):
        for x, a, b in zip(FAR, far_v, far_d):
            for got, ref in ((a, rV), (b, rdV)):
                e = ref(mp.mpf(float(x)))
                assert not np.isnan(got), (text, x)
                if abs(e) < 1e300:
                    assert np.isfinite(got), (text, x, got, e)
                    assert abs(got - float(e)) <= (BOUND + CONDITION.get(text, lambda q: 0.0)(x)) * abs(float(e)) \
                        + 1e-300, (text, x, got, e)


def test_named_wells_call_one_exponential():
    sech2, morse = wells.resolve_well("sech2"), wells.resolve_well("morse")
    dV = sech2.source.split("def dV")[1]
    assert "tanh(" not in dV and "cosh(" not in dV
    def calls(src: str) -> list[int]:
        return [len(re.findall(rf"\b{c}\(", src)) for c in ("exp", "expm1", "exp_expm1")]

    assert calls(dV) == [0, 0, 1]                                    # e^a and e^a - 1 from one reduction
    Vm, dVm = morse.source.split("def dV")
    assert calls(Vm) == [0, 1, 0] and calls(dVm) == [0, 0, 1]


def test_common_subexpressions_printed_once():
    V, q = X.parse("sin(q)**2 + sin(q) + cos(q)**3")
    src, _ = X.generate_source(V, q)
    v, d = src.split("def dV")
    assert v.count("sin(q)") == 1 and v.count("cos(q)") == 1
    assert d.count("sin(q)") == 1 and d.count("cos(q)") == 1
    f, df = X._functions(src, X._NAMESPACE_NUMPY)
    x = np.linspace(-3, 3, 61)
    np.testing.assert_allclose(f(x), np.sin(x) ** 2 + np.sin(x) + np.cos(x) ** 3, rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(df(x), 2 * np.sin(x) * np.cos(x) + np.cos(x) - 3 * np.cos(x) ** 2 * np.sin(x),
                               rtol=1e-14, atol=1e-15)


def test_a_cheaper_form_is_taken_only_when_as_accurate():
    V, q = X.parse("tanh(q)**2")
    dV = sp.diff(V, q)
    pr = X._Printer(q)
    forms, n = X._forms(dV, q, spellings=True)
    # expm1 alone, -8 M (M + 1)/(M + 2)^3, is the cheapest form: it cancels in the tail (M -> -1)
    only_m = [f for f in forms if any(str(k) == "em" for k, _ in f.lets) and not any(str(k) == "ex" for k, _ in f.lets)]
    exact = X._exact(dV, q)
    assert only_m and all(X._relative_error(f, exact, pr) > 1e-6 for f in only_m)
    errors = [X._relative_error(f, exact, pr) for f in forms]
    default = forms[int(np.argmin(errors[:n]))]                      # 2 tanh(q)/cosh(q)^2
    assert "cosh" in str(default.body) and errors[:n].count(min(errors[:n])) == 1
    chosen = X._choose(forms, n, dV, q, pr)
    assert X._relative_error(chosen, exact, pr) <= min(errors) + X.ACCURACY_SLACK
    assert X._cost(chosen) < X._cost(default)                          # one exponential, not tanh and cosh
    # alone with the accurate spelling, the inaccurate cheap form is not taken
    assert X._choose([default, only_m[0]], 1, dV, q, pr) is default


@pytest.mark.parametrize("text", ["tanh(q)**2", "(1 - exp(-q))**2", "1 - 1/cosh(q)"])
def test_compiled_equals_python_source_bitwise(text):
    """The CPU lanes' compilation and the Python source over wells.elementary (what the CUDA
    simulator runs) give the same bits."""
    V, q = X.parse(text)
    src = X.generate_source(V, q)[0]
    cpu = X._functions(src, X._compiled_namespace(elementary.cpu()))
    py = X._functions(src, X._compiled_namespace(elementary))
    x = np.concatenate([np.linspace(-6, 6, 97), [-0.0, 0.0, 1e-300, -1e-9, 700.0, -700.0, 1e3, -1e3]])
    for c, p in zip(cpu, py):
        f = njit(error_model="numpy")(c)
        a = np.array([f(float(v)) for v in x])
        b = np.array([p(float(v)) for v in x])
        assert not np.isnan(a).any(), text
        assert np.array_equal(a.view(np.int64), b.view(np.int64)), text


@pytest.mark.parametrize("text,V,dV", [
    ("log(1 + exp(q))", lambda q: np.logaddexp(0.0, q), lambda q: 0.5 * (1 + np.tanh(q / 2))),
    ("sqrt(1 + exp(-q))", lambda q: np.sqrt(1 + np.exp(-q)), lambda q: -np.exp(-q) / (2 * np.sqrt(1 + np.exp(-q)))),
    ("sin(exp(q))", lambda q: np.sin(np.exp(q)), lambda q: np.exp(q) * np.cos(np.exp(q))),
])
def test_not_rational_in_the_exponential_left_to_sympy(text, V, dV):
    """The family inside a function other than a rational one: no rewrite, the spellings of sympy."""
    V_, q = X.parse(text)
    assert exponential_forms(V_, q) == []
    f, df = _generated(text, X._NAMESPACE_NUMPY)
    x = np.linspace(-3, 3, 41)
    np.testing.assert_allclose(f(x), V(x), rtol=1e-14)
    np.testing.assert_allclose(df(x), dV(x), rtol=1e-13)
