"""wells.expression_joint: dV_V(q) of an expression well is (dV(q), V(q)) bit for bit, compiled for
the CPU lanes and run as Python over wells.elementary (what the CUDA simulator runs), and it
shares the calls the two have in common (sin and cos through one sincos, exp and expm1 of one
argument through one exp_expm1)."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from safebasins import wells
from safebasins.wells import compiled, elementary
from safebasins.wells.expression import _compiled_namespace, _joint_functions
from safebasins.wells.expression_joint import joint_source

SPECS = {"pendulum": "pendulum", "sech2": "sech2", "morse": "morse",
         "mems": {"expression": "q**2/2 - 1/20/(1 - q) + 1/20 + q/20"},
         "1 - sech": {"expression": "1 - 1/cosh(q)"}, "gauss": {"expression": "1 - exp(-q**2)"},
         "mixed": {"expression": "1 - cos(q) + q**2*exp(-q**2)/5 - q**4/8"}}

Q = np.concatenate([np.linspace(-4.0, 4.0, 401), [0.0, -0.0, 1e-300, -5e-324, 0.7, 2.0 ** 31 + 0.5, 1e22, -1e300,
                                                  np.inf, -np.inf, np.nan]])


def _bits(x: float) -> int:
    return int(np.float64(x).view(np.int64))


def _same(a: float, b: float) -> bool:
    return (np.isnan(a) and np.isnan(b)) or _bits(a) == _bits(b)


@pytest.mark.parametrize("name", list(SPECS))
def test_joint_is_dV_and_V_bitwise(name: str) -> None:
    w = wells.resolve_well(SPECS[name])
    code = w.compiled
    split = compiled.cpu_split(code.key)
    assert split is not None
    gradient, gradient_potential = split
    force, energy2 = compiled.cpu_functions(code.key)
    coefs = (0.0,) * 14
    py = _joint_functions(w.source, joint_source(w.source), _compiled_namespace(SimpleNamespace(**vars(elementary))))
    for q in Q.tolist():
        d, v = gradient_potential(coefs, q)
        assert _same(d, gradient(coefs, q)), (name, q)
        assert _same(compiled.fma(0.5, 0.5, 2.0 * v), energy2(coefs, q, 0.5)), (name, q)
        assert _same(0.25 - d, force(coefs, q, 0.25)), (name, q)
        try:                           # as Python, a division by zero raises (mems at its pole)
            dp, vp = py[2](q)
        except ZeroDivisionError:
            with pytest.raises(ZeroDivisionError):
                py[1](q)
            continue
        assert _same(dp, py[1](q)) and _same(vp, py[0](q)), (name, q)
        assert _same(dp, d) and _same(vp, v), (name, q)


def test_joint_shares_the_calls() -> None:
    """One sincos for the pendulum, one exp_expm1 for Morse and the Gaussian well; sech2's V
    (tanh) and V' (exp_expm1 of -2|q|) share nothing but the names."""
    src = {k: joint_source(wells.resolve_well(v).source) for k, v in SPECS.items()}
    assert src["pendulum"].count("sincos(") == 1 and "sin(" not in src["pendulum"].replace("sincos(", "")
    for k in ("morse", "gauss", "1 - sech"):
        assert src[k].count("exp_expm1(") == 1 and "expm1(" not in src[k].replace("exp_expm1(", ""), src[k]
    assert src["sech2"].count("exp_expm1(") == 1 and src["sech2"].count("tanh(") == 1
    assert src["mixed"].count("sincos(") == 1 and src["mixed"].count("exp") == 1, src["mixed"]
