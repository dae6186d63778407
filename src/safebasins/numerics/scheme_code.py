"""The compiled form of a scheme: its step generated once from the constant, compiled for every target.

:func:`scheme_code` turns a scheme of schemes.py (and whether the equation is damped) into a
:class:`SchemeCode`: the Python source of

* ``step(w, q, p, c, f) -> (q, p)``: one step with the coefficient tuple ``c``
  (schemes.lane_coefficients of one parameter set) and the forcing values ``f`` (F sin(Omega t + Psi)
  at the scheme's distinct force sub-times), calling ``force(w, q, f_k) = -V'(q) + f_k`` of a well's
  compiled form (wells/compiled.py) and the primitives ``fma`` / ``mul`` (every product that meets an
  add is an explicit fma; the damped ``p *= e`` is a mul: never contracted on the GPU);
* ``split_step(w, q, p, c, f, d) -> (q, p, d, v)``: the same step for a well with a split force
  (wells.compiled.WellCode.split), the same bits with fewer evaluations: ``d = V'(q)`` at the start
  is given (a splitting's first kick, RK's first stage), ``V'`` and ``V`` at the end come from one
  ``gradient_potential`` call (a splitting's last kick is there) and are returned for the next
  step's first force and the energy test;
* the tuple helpers of its arity: ``row(tab, s)`` (a forcing-table row), ``scaled(F, t)`` (F times
  it: the products the shared path precomputes), ``coefs(c)`` (a coefficient row as a tuple),
  ``column(CL, l)`` (a lane's coefficient column), ``from_h(h)`` (undamped: the coefficients formed
  from the step h, the same IEEE products as lane_coefficients), ``flat_row(tab, o)`` and
  ``flat_coefs(coef, o)`` (CUDA: flat arrays at an unsigned offset).

``make(jit, force)`` (``make_split(jit, gradient, gradient_potential, force_from)``) compiles the
step for a target (the CPU lanes: wells.compiled.cpu_jit; CUDA: ``cuda.jit(device=True)``),
``helpers(jit)`` the tuple helpers.  ``key`` hashes the generated
source and the engine's (:func:`engine_fingerprint`): the numba literal on which the CPU kernels
are specialised and cached, as a well's key (wells.compiled.WellCode.key) is the other.

numba's disk cache checks only the source file of the cached function itself, not the modules
inlined into it; every cached kernel of the engine is specialised on a scheme key, so an edit of
any file the kernels inline changes that key and compiles the kernel anew.
"""
from __future__ import annotations

import functools
import hashlib
from dataclasses import dataclass, field
from pathlib import Path
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np

from safebasins.core import numba_target
from safebasins.numerics.schemes import RungeKutta, Scheme, Splitting, scheme_of
from safebasins.wells import compiled

__all__ = ["SchemeCode", "scheme_code", "code_of_scheme", "engine_fingerprint", "fingerprint", "ENGINE_FILES"]

#: the source files inlined into the engine's cached CPU kernels, and the one that sets the vector
#: width they are compiled for (tests/numerics/test_cache_keys.py checks the list against the
#: modules the kernels import)
ENGINE_FILES = (compiled.__file__, numba_target.__file__, *(str(Path(__file__).with_name(name)) for name in
                ("schemes.py", "scheme_code.py", "steps.py", "periods.py", "well_loops.py", "kernels.py")))


def fingerprint(paths: Iterable[str | Path]) -> str:
    """Hash of the bytes of the files ``paths``, in order."""
    h = hashlib.blake2b(digest_size=16)
    for path in paths:
        h.update(Path(path).read_bytes())
    return h.hexdigest()


@functools.cache
def engine_fingerprint() -> str:
    """Hash of the engine's source (:data:`ENGINE_FILES`: the wells' compiled form, the schemes,
    this module, steps, periods, well_loops, kernels): part of every scheme key, so an edit of the engine
    never reuses a kernel cached before it."""
    return fingerprint(ENGINE_FILES)


def _force(q: str, f: str, split: str) -> str:
    """The force at ``q`` with forcing value ``f``: ``force(w, q, f)``; with ``split`` the split
    form, ``first`` from the carried ``d = V'(q)``, ``last`` from the ``d`` just computed with V(q),
    ``mid`` calling the gradient."""
    if not split:
        return f"force(w, {q}, {f})"
    return f"force_from(w, {'gradient(w, ' + q + ')' if split == 'mid' else 'd'}, {f})"


def _splitting_step(s: Splitting, damped: bool, split: bool = False) -> list[str]:
    nd, nk = len(s.drift_values), len(s.kick_values)
    lines = []
    last = len(s.kick) - 1
    for k, b in enumerate(s.kick):
        ck = nd + s.kick_values.index(b)
        if split and k == last:
            lines.append("d, v = gradient_potential(w, q)")
        kind = ("first" if k == 0 else "last" if k == last else "mid") if split else ""
        lines.append(f"p = fma(c[{ck}], {_force('q', f'f[{s.times.index(s.kick_times[k])}]', kind)}, p)")
        if k < len(s.drift):
            j = s.drift_values.index(s.drift[k])
            lines.append(f"q = fma(c[{j}], p, q)")
            if damped:
                lines.append(f"p = mul(p, c[{nd + nk + j}])")
    return lines


def _sum(names: list[str]) -> str:
    text = names[0]
    for n in names[1:]:
        text = f"({text} + {n})" if len(names) > 2 else f"{text} + {n}"
    return text


def _rk_step(s: RungeKutta, damped: bool, split: bool = False) -> list[str]:
    lines = []
    P, Q = ["p"], ["q"]
    if damped:
        lines.append(f"nb = -c[{len(s.stage_values) + 1}]")
    for i in range(len(s.weights)):
        if i:
            qi, pi = "q", "p"
            for j, a in enumerate(s.a[i]):
                if a != 0.0:
                    ca = s.stage_values.index(a)
                    qi = f"fma(c[{ca}], {P[j]}, {qi})"
                    pi = f"fma(c[{ca}], k{j + 1}, {pi})"
            lines += [f"q{i + 1} = {qi}", f"p{i + 1} = {pi}"]
            Q.append(f"q{i + 1}")
            P.append(f"p{i + 1}")
        force = _force(Q[i], f"f[{s.times.index(s.c[i])}]", ("first" if i == 0 else "mid") if split else "")
        lines.append(f"k{i + 1} = fma(nb, {P[i]}, {force})" if damped else f"k{i + 1} = {force}")
    cw = len(s.stage_values)
    for var, terms in (("q", P), ("p", [f"k{i + 1}" for i in range(len(s.weights))])):
        ones = [t for t, w in zip(terms, s.weights) if w == 1]
        twos = [t for t, w in zip(terms, s.weights) if w == 2]
        parts = []
        if ones:
            parts.append(_sum(ones))
        if twos:
            lines.append(f"s{var} = {_sum(twos)}")
            parts.append(f"(s{var} + s{var})")
        total = " + ".join(f"({x})" if " + " in x and not x.startswith("(") else x for x in parts)
        lines.append(f"{var}_new = fma(c[{cw}], {total}, {var})")
    lines += ["q = q_new", "p = p_new"]
    if split:
        lines.append("d, v = gradient_potential(w, q)")
    return lines


def _tuple(items: list[str]) -> str:
    return "(" + ", ".join(items) + ("," if len(items) == 1 else "") + ")"


def _source(s: Scheme, damped: bool) -> str:
    body = _splitting_step(s, damped) if isinstance(s, Splitting) else _rk_step(s, damped)
    split = _splitting_step(s, damped, True) if isinstance(s, Splitting) else _rk_step(s, damped, True)
    n, W = s.n_coef(damped), len(s.times)
    from_h = (_splitting_from_h(s) if isinstance(s, Splitting) else
              _tuple([f"h * C{j}" for j in range(len(s.stage_values) + 1)]))
    return "\n".join([
        "def step(w, q, p, c, f):",
        *("    " + line for line in body),
        "    return q, p",
        "",
        "def split_step(w, q, p, c, f, d):",
        *("    " + line for line in split),
        "    return q, p, d, v",
        "",
        "def row(tab, s):",
        f"    return {_tuple([f'tab[s, {j}]' for j in range(W)])}",
        "",
        "def scaled(F, t):",
        f"    return {_tuple([f'F * t[{j}]' for j in range(W)])}",
        "",
        "def coefs(c):",
        f"    return {_tuple([f'c[{j}]' for j in range(n)])}",
        "",
        "def column(CL, l):",
        f"    return {_tuple([f'CL[{j}, l]' for j in range(n)])}",
        "",
        "def from_h(h):",
        f"    return {from_h}",
        "",
        "def flat_row(tab, o):",
        f"    return {_tuple(['tab[o]'] + [f'tab[o + U{j}]' for j in range(1, W)])}",
        "",
        "def flat_coefs(coef, o):",
        f"    return {_tuple(['coef[o]'] + [f'coef[o + U{j}]' for j in range(1, n)])}",
        "",
    ])


def _splitting_from_h(s: Splitting) -> str:
    nd = len(s.drift_values)
    return _tuple([f"h * C{j}" for j in range(nd + len(s.kick_values))])


def _constants(s: Scheme) -> dict[str, Any]:
    """The products' constants of from_h (the same floats lane_coefficients multiplies by) and the
    unsigned offsets of the flat loads."""
    vals = (s.drift_values + s.kick_values) if isinstance(s, Splitting) else (s.stage_values + (s.weight_scale,))
    consts: dict[str, Any] = {f"C{j}": float(v) for j, v in enumerate(vals)}
    consts.update({f"U{j}": np.uint64(j) for j in range(1, 64)})
    return consts


@dataclass(frozen=True, eq=False)
class SchemeCode:
    """A scheme (and damping or not) as the compiled engines see it (module docstring)."""

    scheme: Scheme
    damped: bool
    source: str = field(repr=False)
    key: int = field(init=False)

    def __post_init__(self) -> None:
        text = f"{engine_fingerprint()}\0scheme\0{self.source}"
        key = int.from_bytes(hashlib.blake2b(text.encode(), digest_size=8).digest(), "little") >> 3
        object.__setattr__(self, "key", key)
        _CODES.setdefault(key, self)

    @property
    def name(self) -> str:
        return self.scheme.name

    @property
    def n_coef(self) -> int:
        return self.scheme.n_coef(self.damped)

    @property
    def width(self) -> int:
        """Forcing values per step (the forcing table's width)."""
        return len(self.scheme.times)

    def _namespace(self, well: dict[str, Any], primitives: dict[str, Any]) -> dict[str, Any]:
        ns: dict[str, Any] = {**well, **primitives, **_constants(self.scheme)}
        exec(compile(self.source, f"<scheme {self.name}{' damped' if self.damped else ''}>", "exec"), ns)
        return ns

    def make(self, jit: Callable[..., Any], force: Callable[..., Any]) -> Any:
        """The step compiled with ``jit`` around ``force`` (already compiled for the target)."""
        return jit(self._namespace({"force": force}, {"fma": compiled.fma, "mul": compiled.mul})["step"])

    def make_split(self, jit: Callable[..., Any], gradient: Callable[..., Any], gradient_potential: Callable[..., Any],
                   force_from: Callable[..., Any]) -> Any:
        """``split_step(w, q, p, c, f, d) -> (q, p, d, v)`` compiled with ``jit`` around a split
        well's functions (wells.compiled.WellCode.split, compiled for the target): the step with
        ``d = V'(q)`` at its start given, and ``d = V'(q)``, ``v = V(q)`` at its end returned (the
        next step's ``d``, the energy's V).  The same bits as ``step``: its forces are
        ``force_from(w, V'(q), f)``, the split code's force."""
        well = {"gradient": gradient, "gradient_potential": gradient_potential, "force_from": force_from}
        return jit(self._namespace(well, {"fma": compiled.fma, "mul": compiled.mul})["split_step"])

    def helpers(self, jit: Callable[..., Any]) -> dict[str, Any]:
        """The tuple helpers (row, scaled, coefs, column, from_h, flat_row, flat_coefs) compiled with jit."""
        ns = self._namespace({}, {})
        return {k: jit(ns[k]) for k in ("row", "scaled", "coefs", "column", "from_h", "flat_row", "flat_coefs")}


_CODES: dict[int, SchemeCode] = {}


@functools.cache
def scheme_code(integrator: str, damped: bool = False) -> SchemeCode:
    """The compiled form of the scheme ``integrator`` (a name of schemes.SCHEMES), damped or not."""
    s = scheme_of(integrator)
    return SchemeCode(s, bool(damped), _source(s, bool(damped)))


def code_of_scheme(key: int) -> SchemeCode:
    """The registered scheme code of a kernel key."""
    try:
        return _CODES[key]
    except KeyError:
        raise ValueError(f"no compiled scheme with key {key!r} (build it with scheme_code)") from None
