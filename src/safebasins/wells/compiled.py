"""The one compiled form of a well: its force and energy, written once, compiled for every target.

A well reaches the engines as a :class:`WellCode` (``Well.compiled``, built once per well object):

* ``force(w, q, f) = -V'(q) + f`` and ``energy2(w, q, p) = p^2 + 2 V(q)`` (eq 7, untruncated,
  compared with 2 xi_max: exact doubling) as plain, device-compatible Python functions.  ``w``
  is the tuple of the well's 14 run-time coefficients (``wpar[2:]``; the polynomial wells' Horner
  coefficients), ``wpar = [q_left, q_right, w_0 .. w_13]`` with the barriers (+-inf on a side
  without one).
* ``make(jit) -> (force, energy2)`` compiles them with a target's decorator: the CPU lanes use
  :func:`cpu_jit`, ``numba.njit`` inlined by LLVM with the primitives bound to their CPU
  intrinsics (numerics/kernels.py, through :func:`well_force` / :func:`well_energy2`),
  the CUDA kernels ``numba.cuda.jit(device=True)`` (numerics/cuda_kernels.py).  The SAME Python
  source serves both; only the two primitives below differ by target.
* ``key``: a 61-bit hash of the source text of the arithmetic and of this module (the primitives,
  the templates), the compile-time constant (numba literal) on which the CPU kernels are
  specialised and cached on disk.  Equal keys mean equal arithmetic, so a cached kernel is never
  reused for other code; the engine's own source enters through the scheme's key
  (numerics.scheme_code.engine_fingerprint, which hashes this module too), the kernels' other
  literal.
* ``abs_tracking``: a well symmetric about q = 0 may track max |q| (one maximum per lane: the
  quartic's closed-form path, eq (4)); every other code tracks max q and max -q.
* ``split`` (wells given by ``V`` and ``dV``: :func:`target_code`; None for the quartic and the
  polynomial codes, whose ``f`` enters an fma): ``split(jit) -> (gradient, gradient_potential)``,
  ``gradient(w, q) = V'(q)`` and ``gradient_potential(w, q) = (V'(q), V(q))``, with which
  ``force(w, q, f) == force_from(w, gradient(w, q), f)`` and ``energy2(w, q, p) ==
  energy2_from(w, V(q), p)`` bit for bit (:func:`force_from`, :func:`energy2_from`: the one
  final operation of each).  The lane loops carry V'(q) from a step's last kick to the next
  step's first (same q: first-same-as-last) and take V(q) of the energy test from the same call.

Primitives (one name each, an implementation per target):

* :func:`fma` -- correctly rounded a*b + c: llvm.fma on the CPU, fma.rn.f64 on the GPU
  (registered by numerics.cuda_kernels), the CPU's llvm.fma when called from Python (numba's CUDA
  simulator runs device functions as Python);
* :func:`mul` -- a rounded product that the GPU compiler may not contract with a following add
  (``__dmul_rn`` on the GPU, a plain product on the CPU, which never contracts).  Generated code
  (expression wells) writes every product with it, so CPU and GPU round the same operations.

Bitwise CPU = GPU holds for arithmetic wells (quartic, polynomials, rational expressions: IEEE
+, -, *, /, sqrt and fma are correctly rounded on both) and for the functions of
wells.elementary (sin, exp, tanh, ...: written once over fma and mul, compiled per target by
:func:`target_code`'s ``functions(jit)``); a libm function (glibc on the CPU, libdevice on the
GPU) may differ in the last bit.

Adding a compiled well family with run-time parameters is one :class:`WellCode` builder here
(see docs/adding-a-well.md); a well written as an expression needs none (wells.expression).
"""
from __future__ import annotations

import functools
import hashlib
import inspect
import operator
import re
import types as types_module
from dataclasses import dataclass, field
from pathlib import Path
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from numpy.typing import ArrayLike

import numpy as np
from numba import njit, types
from numba.core import errors
from numba.extending import intrinsic, overload

from safebasins.core import numba_target

if TYPE_CHECKING:
    from numba.core.decorators import _JITOptions   # numba's stubs: the options of njit

# before the package's first kernel: numba's CPU target takes its vector width when it is created
numba_target.configure()

__all__ = ["WellCode", "fma", "mul", "fma_cpu", "mul_cpu", "N_WPAR", "quartic_code", "polynomial_code", "callable_code",
           "target_code", "force_from", "energy2_from",
           "well_force", "well_energy2", "abs_tracking", "code_of", "literal_code", "cpu_jit", "cpu_leaf_jit",
           "LLVM_INLINE",
           "cpu_functions", "cpu_split",
           "POLY_DEGREES"]

#: a target's decorator (njit-like, cuda.jit(device=True)): a plain function -> its compiled form
Jit = Callable[[Callable[..., Any]], Any]
#: the well's run-time coefficients as the compiled functions see them (a tuple of 14 floats)
Coefs = tuple[float, ...]
#: wpar = [q_left, q_right, w_0 .. w_13]
N_WPAR = 16
#: degree classes of the polynomial codes (a well of degree n runs in the smallest class >= n)
POLY_DEGREES = (4, 8)


# ------------------------------------------------------------------------------- primitives
@intrinsic
def fma_cpu(typingctx: Any, a: Any, b: Any, c: Any) -> Any:
    """Correctly rounded a*b + c (llvm.fma.f64): same bits in vector and scalar code."""
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        return builder.fma(*args)

    return sig, codegen


@numba_target.package_jit(cache=True)
def _fma_python(a: float, b: float, c: float) -> float:
    return fma_cpu(a, b, c)  # type: ignore[call-arg]  # numba types an intrinsic with its typing context


def fma(a: float, b: float, c: float) -> float:
    """Correctly rounded ``a*b + c`` on every target (see the module docstring)."""
    return _fma_python(a, b, c)


def mul(a: float, b: float) -> float:
    """``a * b``, never contracted with a following add (see the module docstring)."""
    return a * b


#: the options of the engine's compiled helpers (:func:`cpu_jit`, the overloads' implementations):
#: each compiled on its own and inlined by LLVM (alwaysinline) into its callers
LLVM_INLINE: _JITOptions = {**numba_target.JIT_OPTIONS, "forceinline": True, "error_model": "numpy"}


@overload(fma, jit_options=LLVM_INLINE)
def _ol_fma(a: Any, b: Any, c: Any) -> Callable[..., float]:
    # an overload's implementation takes its parameters with the same annotations (numba compares them)
    def impl(a: Any, b: Any, c: Any) -> float:
        return fma_cpu(a, b, c)  # type: ignore[call-arg]  # as in _fma_python
    return impl


@overload(mul, jit_options=LLVM_INLINE)
def _ol_mul(a: Any, b: Any) -> Callable[..., float]:
    def impl(a: Any, b: Any) -> float:
        return a * b  # type: ignore[no-any-return]  # floats (numba types the call)
    return impl


# ------------------------------------------------------------------------------- the compiled form
#: hash of this module's source: part of every well's key (an edit of the primitives or the
#: templates never reuses a kernel cached before it)
MODULE_HASH = hashlib.blake2b(Path(__file__).read_bytes(), digest_size=16).hexdigest()

_CODES: dict[int, WellCode] = {}


@dataclass(frozen=True, eq=False)
class WellCode:
    """A well as the compiled engines see it (module docstring)."""

    name: str
    make: Callable[[Jit], tuple[Any, Any]] = field(repr=False)
    wpar: np.ndarray = field(repr=False)
    abs_tracking: bool
    source: str = field(repr=False)
    split: Callable[[Jit], tuple[Any, Any]] | None = field(default=None, repr=False)
    key: int = field(init=False)

    def __post_init__(self) -> None:
        w = np.ascontiguousarray(self.wpar, dtype=float)
        if w.shape != (N_WPAR,):
            raise ValueError(f"wpar must have {N_WPAR} entries [q_left, q_right, w_0 .. w_13], got shape {w.shape}")
        object.__setattr__(self, "wpar", w)
        text = f"{MODULE_HASH}\0{self.source}\0abs={bool(self.abs_tracking)}"
        key = int.from_bytes(hashlib.blake2b(text.encode(), digest_size=8).digest(), "little") >> 3
        object.__setattr__(self, "key", key)
        _CODES.setdefault(key, self)

    @property
    def barriers(self) -> tuple[float, float]:
        return float(self.wpar[0]), float(self.wpar[1])

    def signed(self) -> WellCode:
        """The same arithmetic with max q / max -q tracking (asymmetric displacement bounds)."""
        if not self.abs_tracking:
            return self
        return _signed_variant(self)


@functools.cache
def _signed_variant(code: WellCode) -> WellCode:
    return WellCode(code.name, code.make, code.wpar, False, code.source, code.split)


def code_of(key: int) -> WellCode:
    """The registered code of a kernel key."""
    try:
        return _CODES[key]
    except KeyError:
        raise ValueError(f"no compiled well with key {key!r} (build it from a well: Well.compiled)") from None


def _wpar(barriers: Sequence[float], coefficients: ArrayLike = ()) -> np.ndarray:
    w = np.zeros(N_WPAR)
    w[0], w[1] = float(barriers[0]), float(barriers[1])
    c = np.asarray(coefficients, dtype=float)
    w[2:2 + c.size] = c
    return w


def _plain(force: Callable[..., float], energy2: Callable[..., float]) -> tuple[Callable[[Jit], tuple[Any, Any]], str]:
    """(``make``, source) of a code whose two functions need nothing but the primitives."""
    def make(jit: Jit) -> tuple[Any, Any]:
        return jit(force), jit(energy2)
    return make, inspect.getsource(force) + inspect.getsource(energy2)


# ------------------------------------------------------------------------------- the quartic, eq (2)
def quartic_force(w: Coefs, q: float, f: float) -> float:
    """q^3 - q + f for V = q^2/2 - q^4/4 (eq 1)."""
    return fma(q * q, q, f - q)


def quartic_energy2(w: Coefs, q: float, p: float) -> float:
    """2 H0 = p^2 + q^2 - q^4/2 (eq 7, untruncated)."""
    q2 = q * q
    return fma(q2, fma(-0.5, q2, 1.0), p * p)


_QUARTIC_MAKE = _plain(quartic_force, quartic_energy2)


@functools.cache
def quartic_code() -> WellCode:
    """The paper's quartic in closed form, barriers +-1, |q| tracking."""
    return WellCode("quartic", _QUARTIC_MAKE[0], _wpar((-1.0, 1.0)), True, _QUARTIC_MAKE[1])


# ------------------------------------------------------------------------------- polynomial wells
# -V'(q) + f = f + q (g_1 + q (g_2 + ...)), g_k = -(k+1) c_{k+1}:  w[0 .. 6] = g_1 .. g_7
# 2 V(q) + p^2 = q^2 (e_2 + q (e_3 + ...)) + p^2, e_k = 2 c_k:   w[7 .. 13] = e_2 .. e_8
# Horner with explicit fma over the class's full length: a missing top coefficient is a zero,
# and fma(0, q, g) = g for finite q leaves the value bitwise unchanged.
def poly4_force(w: Coefs, q: float, f: float) -> float:
    return fma(fma(fma(w[2], q, w[1]), q, w[0]), q, f)


def poly4_energy2(w: Coefs, q: float, p: float) -> float:
    h = fma(fma(w[9], q, w[8]), q, w[7])
    return fma(h, q * q, p * p)


def poly8_force(w: Coefs, q: float, f: float) -> float:
    a = fma(w[6], q, w[5])
    a = fma(a, q, w[4])
    a = fma(a, q, w[3])
    a = fma(a, q, w[2])
    a = fma(a, q, w[1])
    a = fma(a, q, w[0])
    return fma(a, q, f)


def poly8_energy2(w: Coefs, q: float, p: float) -> float:
    h = fma(w[13], q, w[12])
    h = fma(h, q, w[11])
    h = fma(h, q, w[10])
    h = fma(h, q, w[9])
    h = fma(h, q, w[8])
    h = fma(h, q, w[7])
    return fma(h, q * q, p * p)


_POLY_MAKE = {4: _plain(poly4_force, poly4_energy2), 8: _plain(poly8_force, poly8_energy2)}


def polynomial_code(coefficients: ArrayLike, barriers: Sequence[float], name: str = "polynomial",
                    degree_class: int | None = None) -> WellCode:
    """Code of ``V = sum_k c_k q^k`` (c_0 = c_1 = 0, degree <= 8) with its barriers: one compiled
    kernel per degree class (the coefficients are run-time numbers); ``degree_class`` (4 or 8)
    forces a class at least the degree's (None: the smallest)."""
    c = np.trim_zeros(np.asarray(coefficients, dtype=float), "b")
    n = c.size - 1
    if c.ndim != 1 or n < 2 or c[0] != 0.0 or c[1] != 0.0:
        raise ValueError(f"coefficients must be c_0 = 0, c_1 = 0, c_2, ... (degree >= 2), got {coefficients!r}")
    if degree_class is not None and degree_class not in POLY_DEGREES:
        raise ValueError(f"degree_class must be one of {POLY_DEGREES}, got {degree_class!r}")
    cls = next((d for d in POLY_DEGREES if n <= d and (degree_class is None or d >= degree_class)), None)
    if cls is None:
        raise ValueError(f"coefficients: degree {n} exceeds the largest compiled polynomial class {max(POLY_DEGREES)} "
                         "(write the well as an expression: {'expression': ...})")
    w = np.zeros(14)
    for k in range(1, n):
        w[k - 1] = -(k + 1) * c[k + 1]
    for k in range(2, n + 1):
        w[7 + k - 2] = 2.0 * c[k]
    make, source = _POLY_MAKE[cls]
    return WellCode(f"{name} (degree class {cls})", make, _wpar(barriers, w), False, source)


# ------------------------------------------------------------------------------- any V, dV
def force_from(w: Coefs, dv: float, f: float) -> float:
    """-V'(q) + f from dv = V'(q) (a split code's force: one IEEE subtraction)."""
    return f - dv


def energy2_from(w: Coefs, v: float, p: float) -> float:
    """2 H0 = p^2 + 2 V(q) from v = V(q) (a split code's energy)."""
    return fma(p, p, 2.0 * v)


#: ``functions(jit) -> (V, dV)`` or ``(V, dV, dV_V)`` of :func:`target_code`
Functions = Callable[[Jit], tuple[Callable[..., Any], ...]]


def _template(V: Callable[[float], float], dV: Callable[[float], float], dV_V: Callable[[float], tuple[float, float]],
              force_of: Callable[[Coefs, float, float], float], energy2_of: Callable[[Coefs, float, float], float]
              ) -> tuple[Callable[..., Any], ...]:
    """(force, energy2, gradient, gradient_potential) of a well given by scalar functions V, dV and
    dV_V(q) = (V'(q), V(q)) (compiled for the target), force_of / energy2_of: :func:`force_from`,
    :func:`energy2_from` compiled for it: the same lines for every such well."""
    def force(w: Coefs, q: float, f: float) -> float:
        return force_of(w, dV(q), f)

    def energy2(w: Coefs, q: float, p: float) -> float:
        return energy2_of(w, V(q), p)

    def gradient(w: Coefs, q: float) -> float:
        return dV(q)

    def gradient_potential(w: Coefs, q: float) -> tuple[float, float]:
        return dV_V(q)

    return force, energy2, gradient, gradient_potential


def _pair(V: Callable[[float], float], dV: Callable[[float], float]) -> Callable[[float], tuple[float, float]]:
    """dV_V(q) = (dV(q), V(q)) from the two functions (a well without a joint form)."""
    def dV_V(q: float) -> tuple[float, float]:
        return dV(q), V(q)
    return dV_V


_TEMPLATE_SOURCE = "".join(inspect.getsource(f) for f in (force_from, energy2_from, _template, _pair))


def target_code(functions: Functions, barriers: Sequence[float], name: str, source: str) -> WellCode:
    """Code of a well from ``functions(jit) -> (V, dV)`` or ``(V, dV, dV_V)``: scalar,
    numba-compilable plain Python functions for the target whose decorator is ``jit`` (each target
    compiles them; what they call may differ by target, e.g. wells.elementary compiled for it);
    ``dV_V(q) = (dV(q), V(q))`` with the same bits, sharing their work (absent: the two calls).
    ``source`` must identify their arithmetic exactly (the expression well's generated text and
    the elementary functions' hash; for user functions the LLVM IR of their CPU compilation): it
    is the cache key of the compiled kernels."""
    @functools.cache
    def compiled_for(jit: Jit) -> tuple[Any, Any, Any, Any]:
        fs = functions(jit)
        leaf = cpu_leaf_jit if jit is cpu_jit else jit
        V, dV = leaf(fs[0]), leaf(fs[1])
        dV_V = leaf(fs[2]) if len(fs) > 2 else jit(_pair(V, dV))
        force, energy2, gradient, gradient_potential = _template(V, dV, dV_V, jit(force_from), jit(energy2_from))
        return jit(force), jit(energy2), jit(gradient), jit(gradient_potential)

    def make(jit: Jit) -> tuple[Any, Any]:
        return compiled_for(jit)[:2]

    def split(jit: Jit) -> tuple[Any, Any]:
        return compiled_for(jit)[2:]

    return WellCode(name, make, _wpar(barriers), False, f"{_TEMPLATE_SOURCE}\0{source}", split)


def callable_code(V: Callable[[float], float], dV: Callable[[float], float], barriers: Sequence[float], name: str,
                  source: str) -> WellCode:
    """Code of a well from scalar, numba-compilable Python functions ``V(q)``, ``dV(q)``, the same
    on every target (:func:`target_code`)."""
    return target_code(lambda jit: (V, dV), barriers, name, source)


# ------------------------------------------------------------------------------- CPU dispatch
def literal_code(well: Any) -> WellCode:
    """The registered code of a numba literal kernel key (typing time of the CPU kernels)."""
    if not isinstance(well, types.IntegerLiteral):
        raise errors.TypingError(f"well must be a compile-time constant kernel key (a numba literal), got {well}")
    return code_of(well.literal_value)


@intrinsic
def mul_cpu(typingctx: Any, a: Any, b: Any) -> Any:
    """``a * b`` exactly as numba compiles it (the CPU's mul)."""
    sig = typingctx.resolve_function_type(operator.mul, (a, b), {})

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        return context.get_function(operator.mul, signature)(builder, args)

    return sig, codegen


_CPU_PRIMITIVES = {"fma": (fma, fma_cpu), "mul": (mul, mul_cpu)}


def cpu_jit(fn: Callable[..., Any]) -> Any:
    """A function of the wells' one source (a force, an energy, a scheme's step, a well's ``V`` or
    ``dV``) for the CPU lanes: ``njit`` with its globals ``fma`` and ``mul`` (when they are this
    module's) bound to the CPU primitives, compiled on its own once per signature and inlined by
    LLVM into its callers (:data:`LLVM_INLINE`).  Inlined by numba instead (``inline="always"``),
    every call site would be typed and lowered anew (the step once per chain of the lane loop, the
    force once per stage of the step): most of a kernel's first compile.  numpy's error model: a
    division never raises (x/0 is inf, as on the GPU); a raising one would give the lane loop an
    exit and keep it scalar."""
    return njit(**LLVM_INLINE)(_cpu_globals(fn))


def cpu_leaf_jit(fn: Callable[..., Any]) -> Any:
    """A well's ``V`` or ``dV`` for the CPU lanes: :func:`cpu_jit`."""
    return cpu_jit(fn)


def _cpu_globals(fn: Callable[..., Any]) -> Callable[..., Any]:
    """``fn`` with its globals ``fma`` and ``mul`` (when they are this module's) bound to the CPU
    primitives."""
    g = fn.__globals__
    cpu = {k: c for k, (generic, c) in _CPU_PRIMITIVES.items() if g.get(k) is generic}
    if cpu:
        fn = types_module.FunctionType(fn.__code__, {**g, **cpu}, fn.__name__, fn.__defaults__, fn.__closure__)
    return fn


@functools.cache
def cpu_functions(key: int) -> tuple[Any, Any]:
    """(force, energy2) of a code compiled for the CPU lanes (inlined into the kernels)."""
    return code_of(key).make(cpu_jit)


@functools.cache
def cpu_split(key: int) -> tuple[Any, Any] | None:
    """(gradient, gradient_potential) of a split code compiled for the CPU lanes (WellCode.split);
    None for a code without one."""
    split = code_of(key).split
    return None if split is None else split(cpu_jit)


def well_force(well: int, w: Coefs, q: float, f: float) -> float:
    """-V'(q) + f of the code with kernel key ``well`` (a compile-time constant), f = F sin(...)."""
    raise NotImplementedError("well_force is compiled code (numba)")


def well_energy2(well: int, w: Coefs, q: float, p: float) -> float:
    """2 H0 = p^2 + 2 V(q) of the code with kernel key ``well`` (a compile-time constant)."""
    raise NotImplementedError("well_energy2 is compiled code (numba)")


def abs_tracking(well: int) -> bool:
    """True when the code of kernel key ``well`` tracks max |q| (a compile-time constant)."""
    raise NotImplementedError("abs_tracking is compiled code (numba)")


# the code of a key is chosen at typing time: a kernel holds only its own well's arithmetic
@overload(well_force, jit_options=LLVM_INLINE)
def _ol_well_force(well: Any, w: Any, q: Any, f: Any) -> Callable[..., float]:
    FORCE = cpu_functions(literal_code(well).key)[0]

    def impl(well: Any, w: Any, q: Any, f: Any) -> float:
        return FORCE(w, q, f)  # type: ignore[no-any-return]  # a compiled force (numba dispatcher)
    return impl


@overload(well_energy2, jit_options=LLVM_INLINE)
def _ol_well_energy2(well: Any, w: Any, q: Any, p: Any) -> Callable[..., float]:
    ENERGY2 = cpu_functions(literal_code(well).key)[1]

    def impl(well: Any, w: Any, q: Any, p: Any) -> float:
        return ENERGY2(w, q, p)  # type: ignore[no-any-return]  # a compiled energy (numba dispatcher)
    return impl


@overload(abs_tracking, jit_options=LLVM_INLINE)
def _ol_abs_tracking(well: Any) -> Callable[..., bool]:
    def yes(well: Any) -> bool:
        return True

    def no(well: Any) -> bool:
        return False
    return yes if literal_code(well).abs_tracking else no


def _ir_identity(arg: str, fn: Callable[..., Any]) -> tuple[Callable[..., Any], str]:
    """(plain Python function, text identifying its float64 -> float64 compilation): the LLVM IR of
    its CPU compilation with the mangled symbol names removed (they carry process-local counters)."""
    py = getattr(fn, "py_func", fn)
    if not callable(py):
        raise ValueError(f"{arg} must be a callable, got {fn!r}")
    try:
        d = njit(py)
        d.compile((types.float64,))
        ir = d.inspect_llvm((types.float64,))
        # CompileResult is a namedtuple over a field list mypy cannot read
        returns = d.overloads[(types.float64,)].signature.return_type  # type: ignore[attr-defined]
    except errors.NumbaError as exc:
        head = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ValueError(f"{arg}: the compiled engines need {arg}(q) as a scalar function numba can compile "
                         f"(numpy/math calls on a float; numba said: {head}); or write the well as an expression "
                         "{'expression': ...}") from None
    if returns not in (types.float64, types.int64):
        raise ValueError(f"{arg}(q) must return a float for a float q, numba infers {returns}")
    return py, re.sub(r"_ZN\w+", "_Z", ir)


def user_code(V: Callable[..., Any], dV: Callable[..., Any], barriers: Sequence[float], name: str) -> WellCode:
    """Code of a well from the user's callables (a NumericWell): V, dV compiled by numba for a
    scalar q (plain Python functions or numba dispatchers); ValueError naming V / dV otherwise."""
    pv, iv = _ir_identity("V", V)
    pd, id_ = _ir_identity("dV", dV)
    return callable_code(pv, pd, barriers, name, f"V:\n{iv}\ndV:\n{id_}")
