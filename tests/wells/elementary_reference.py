"""Sample sets and the mpmath reference for the elementary functions (wells.elementary): shared by
tests/wells/test_elementary.py (modest counts) and benchmarks/bench_elementary.py (the dense sweep
whose maxima docs/elementary.md states)."""
from __future__ import annotations

import math
from collections.abc import Callable

import mpmath as mp
import numpy as np
from numba import njit

from safebasins.wells import elementary

#: mpmath's function of each elementary function of one argument (sincos: its two parts)
MPMATH: dict[str, Callable[[mp.mpf], mp.mpf]] = {
    "sin": mp.sin, "cos": mp.cos, "tan": mp.tan, "exp": mp.exp, "expm1": mp.expm1, "log": mp.log,
    "log1p": mp.log1p, "tanh": mp.tanh, "cosh": mp.cosh, "sinh": mp.sinh, "sqrt": mp.sqrt}
#: the functions compared with mpmath (sincos is sin and cos, checked bitwise against them)
CHECKED = (*MPMATH, "pow", "powi")
_TRIG = ("sin", "cos", "tan")
TINY = 5e-324
HUGE = 1.7976931348623157e308


def _log_uniform(rng: np.random.Generator, n: int, lo: float, hi: float, signed: bool = True) -> np.ndarray:
    m = np.exp(rng.uniform(math.log(lo), math.log(hi), n))
    return m * (rng.choice([-1.0, 1.0], n) if signed else 1.0)


def samples(name: str, n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray | None]:
    """(x, y): ``n`` arguments over the function's whole domain (uniform where the function is
    used, log-uniform over every binade up to the overflow limit and down to the subnormals);
    y the second argument of pow (float) and powi (integer), None otherwise."""
    rng = np.random.default_rng(seed + sum(map(ord, name)))
    k = n // 4
    if name in _TRIG:
        parts = [rng.uniform(-7.0, 7.0, k), _log_uniform(rng, k, 1e-300, 1e6), _log_uniform(rng, k, 1e6, HUGE),
                 rng.uniform(-1e5, 1e5, n - 3 * k)]
    elif name == "exp":
        parts = [rng.uniform(-745.2, 709.8, k), rng.uniform(-1.0, 1.0, k), _log_uniform(rng, k, 1e-300, 1.0),
                 rng.uniform(-745.2, -708.0, n - 3 * k)]
    elif name == "expm1":
        parts = [rng.uniform(-40.0, 709.8, k), rng.uniform(-1.0, 1.0, k), _log_uniform(rng, k, 1e-300, 1.0),
                 rng.uniform(-0.5, 0.5, n - 3 * k)]
    elif name in ("log", "sqrt"):
        parts = [rng.uniform(0.5, 2.0, k), _log_uniform(rng, k, TINY, HUGE, False),
                 1.0 + _log_uniform(rng, k, 1e-16, 1e-3), _log_uniform(rng, n - 3 * k, TINY, 2.2e-308, False)]
    elif name == "log1p":
        parts = [rng.uniform(-0.999, 2.0, k), _log_uniform(rng, k, 1e-300, HUGE, False),
                 -_log_uniform(rng, k, 1e-300, 1.0, False), _log_uniform(rng, n - 3 * k, 1e-300, 1.0)]
    elif name == "tanh":
        parts = [rng.uniform(-20.0, 20.0, 2 * k), _log_uniform(rng, n - 2 * k, 1e-300, 1.0)]
    elif name in ("cosh", "sinh"):
        parts = [rng.uniform(-710.4, 710.4, k), rng.uniform(-2.0, 2.0, k), _log_uniform(rng, k, 1e-300, 1.0),
                 rng.uniform(-0.3, 0.3, n - 3 * k)]
    elif name == "pow":
        x = np.concatenate([_log_uniform(rng, n - k, 1e-300, 1e300, False), rng.uniform(0.5, 2.0, k)])
        t = rng.uniform(-740.0, 705.0, n)              # y log x = t: results over the whole range
        y = t / np.log(x)
        y[::7] = np.round(y[::7])                      # integer exponents (negative x below)
        x[::7] = np.where(np.arange(x[::7].size) % 2 == 0, -x[::7], x[::7])
        return x, y
    elif name == "powi":
        x = np.concatenate([rng.uniform(-2.0, 2.0, n - k), _log_uniform(rng, k, 1e-5, 1e5)])
        m = rng.integers(-40, 41, n)
        big = np.abs(x) > 2.0
        m[big] = np.clip(m[big], -60, 60)
        return x, m.astype(float)
    else:
        raise ValueError(f"no samples for {name!r}")
    return np.concatenate(parts), None


def hard_points(name: str) -> tuple[np.ndarray, np.ndarray | None]:
    """Arguments where an implementation is most likely to fail: the ends of the domain and of the
    fast reduction, the closest doubles to multiples of pi/2, the subnormal and overflow edges."""
    big = [2.0 ** 30, np.nextafter(2.0 ** 30, 3e9), 6381956970095103.0 * 2.0 ** 797, 5.319372648326541e255,
           1e22, 1e300, HUGE, 2.0 ** 1023, 1.0e6, 3.14159265358979311599796346854, 1.5707963267948966,
           4.71238898038469, 355.0, 103993.0, 7.0e6 * math.pi, TINY, 2.2250738585072014e-308, 1e-300, 1.4e-8]
    if name in _TRIG:
        x = np.array(big + [-v for v in big])
    elif name == "exp":
        x = np.array([709.782712893384, 709.78, -708.3964185322641, -708.4, -744.44, -745.1332191019411, -745.13,
                      -745.1332191019412, 1e-300, -1e-300, TINY, 0.34657359027997264, -0.34657359027997264, 1.0])
    elif name == "expm1":
        x = np.array([709.782712893384, -37.0, -38.0, 1e-300, -TINY, 5.551115123125783e-17, 1e-10, 0.3465735902799726,
                      -0.3465735902799726, 41.5, 42.0])
    elif name in ("log", "sqrt"):
        x = np.array([TINY, 1e-310, 2.2250738585072014e-308, HUGE, 1.0 + 2.0 ** -52, 1.0 - 2.0 ** -53,
                      0.7071067811865476, 1.4142135623730951, 2.0, 0.5])
    elif name == "log1p":
        x = np.array([-1.0 + 2.0 ** -53, -0.2928932188134524, 0.41421356237309503, TINY, -TINY, 1e-17, HUGE,
                      2.0 ** 53, 1e-300])
    elif name == "tanh":
        x = np.array([TINY, 7.450580596923828e-09, 0.5493061443340548, 19.06154746539849, 20.0, 22.0, -22.0, 1e-300])
    elif name in ("cosh", "sinh"):
        x = np.array([710.4758600739439, -710.4758600739439, 710.47586007394, 0.25, -0.25, 3.725290298461914e-09,
                      TINY, 1e-300, 22.0, 1e-8])
    elif name == "pow":
        pairs = [(2.0, 1023.0), (2.0, -1074.0), (2.0, -1022.5), (0.5, 1074.0), (10.0, 308.25), (10.0, -323.5),
                 (HUGE, 1.0), (HUGE, 0.5), (TINY, 0.5), (TINY, -0.5), (1.0 + 2.0 ** -52, 2.0 ** 60),
                 (1.0 - 2.0 ** -53, -2.0 ** 62), (-2.0, 1023.0), (-3.0, -5.0), (9.0, 0.5), (0.1, 3.0)]
        return np.array([a for a, _ in pairs]), np.array([b for _, b in pairs])
    elif name == "powi":
        pairs = [(2.0, 1023.0), (2.0, -1022.0), (2.0, -1074.0), (-2.0, 1023.0), (10.0, 22.0), (10.0, -22.0),
                 (1.0000001, 1000000.0), (HUGE, 1.0), (HUGE, 2.0), (TINY, 1.0), (TINY, -1.0), (0.1, 300.0)]
        return np.array([a for a, _ in pairs]), np.array([b for _, b in pairs])
    else:
        raise ValueError(f"no hard points for {name!r}")
    return x, None


def reference(name: str, x: float, y: float | None = None) -> mp.mpf:
    """f(x) (pow: x^y) to ~100 bits beyond double precision."""
    e = abs(math.frexp(x)[1]) + (abs(math.frexp(y)[1]) if y is not None else 0)
    with mp.workprec(140 + (e if name in _TRIG or name in ("pow", "powi") else 0)):
        if name in ("pow", "powi"):
            return mp.power(mp.mpf(x), mp.mpf(y))
        return MPMATH[name](mp.mpf(x))


def ulp_error(got: float, ref: mp.mpf) -> float:
    """|got - ref| in units of the last place of ref (2^-1074 in the subnormal range); inf when got
    is not finite but ref rounds to a finite double (or the other way round)."""
    r = float(ref)                                   # ref rounded to the nearest double
    if math.isinf(r):
        return 0.0 if got == r else math.inf
    if not math.isfinite(got):
        return math.inf
    if ref == 0:
        return 0.0 if got == 0.0 else math.inf
    e = int(mp.frexp(ref)[1])                        # |ref| in [2^(e-1), 2^e)
    return float(abs(mp.mpf(got) - ref) / mp.ldexp(1, max(e - 53, -1074)))


@njit(cache=False)
def _map1(f: Callable[[float], float], x: np.ndarray, out: np.ndarray) -> None:
    for i in range(x.size):
        out[i] = f(x[i])


@njit(cache=False)
def _map2(f: Callable[[float, float], float], x: np.ndarray, y: np.ndarray, out: np.ndarray) -> None:
    for i in range(x.size):
        out[i] = f(x[i], y[i])


@njit(cache=False)
def _map_powi(f: Callable[[float, np.int64], float], x: np.ndarray, n: np.ndarray, out: np.ndarray) -> None:
    for i in range(x.size):
        out[i] = f(x[i], np.int64(n[i]))


def cpu_values(name: str, x: np.ndarray, y: np.ndarray | None = None) -> np.ndarray:
    """The CPU compilation's values (an njit loop over wells.elementary.cpu())."""
    f = getattr(elementary.cpu(), name)
    out = np.empty(x.size)
    if name == "powi":
        assert y is not None, "powi takes an exponent"
        _map_powi(f, x, y, out)
    elif y is not None:
        _map2(f, x, y, out)
    else:
        _map1(f, x, out)
    return out


def max_ulp(name: str, x: np.ndarray, y: np.ndarray | None, got: np.ndarray) -> tuple[float, float, float | None]:
    """(largest ulp error of ``got`` against mpmath, its x, its y)."""
    worst, at, at_y = 0.0, math.nan, None
    for i in range(x.size):
        yi = None if y is None else float(y[i])
        err = ulp_error(float(got[i]), reference(name, float(x[i]), yi))
        if err > worst:
            worst, at, at_y = err, float(x[i]), yi
    return worst, at, at_y
