"""Compiling code written once in the wells' code language (wells.elementary) for each target.

* Bit casts, the primitives the code adds to wellcode's fma and mul: :func:`as_bits`,
  :func:`from_bits` (Python bodies for plain Python and numba's CUDA simulator; an LLVM bitcast
  on the CPU; libdevice's double_as_longlong / longlong_as_double on CUDA).
* :func:`compile_code`: every function of a set of modules, compiled by a target's decorator
  with its globals rebound to that target's primitives and to the other functions compiled
  alike (so one call graph of plain Python becomes one call graph per target, with no
  per-call-site overload resolution).
* :func:`cold_call_cpu`: a CPU call that a vectorised loop makes only for the lanes that need it.
  The call carries LLVM's vector-function-ABI attribute naming masked variants (2, 4 and 8
  lanes) which test the mask lane by lane and call the scalar function only where it is set:
  the loop vectoriser keeps the loop vectorised and a rare slow path (sin/cos of ``|x| > 2^30``)
  costs one well-predicted branch per vector.
* :func:`register_cpu_overload`: lets ``@njit`` code call a code function by its Python name.
"""
from __future__ import annotations

import struct
import types as pytypes
from collections.abc import Callable, Mapping, Sequence
from types import FunctionType, ModuleType, SimpleNamespace
from typing import Any, cast

import llvmlite.binding as llvm
from llvmlite import ir
from numba import types
from numba.extending import intrinsic, overload

from safebasins.core.numba_target import JIT_OPTIONS

__all__ = ["as_bits", "from_bits", "as_bits_cpu", "from_bits_cpu", "compile_code", "cold_call_cpu",
           "register_cpu_overload", "VECTOR_WIDTHS"]

#: lane counts of the masked vector variants of a cold call
VECTOR_WIDTHS = (2, 4, 8)


# ------------------------------------------------------------------------------- bit casts
def as_bits(x: float) -> int:
    """The IEEE 754 bits of a double as a signed 64-bit integer."""
    return cast(int, struct.unpack("<q", struct.pack("<d", x))[0])


def from_bits(i: int) -> float:
    """The double whose IEEE 754 bits are the signed 64-bit integer ``i``."""
    return cast(float, struct.unpack("<d", struct.pack("<q", i))[0])


@intrinsic
def as_bits_cpu(typingctx: Any, x: Any) -> Any:
    """:func:`as_bits` on the CPU: an LLVM bitcast (vectorises)."""
    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        return builder.bitcast(args[0], ir.IntType(64))
    return types.int64(types.float64), codegen


@intrinsic
def from_bits_cpu(typingctx: Any, i: Any) -> Any:
    """:func:`from_bits` on the CPU: an LLVM bitcast."""
    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        return builder.bitcast(args[0], ir.DoubleType())
    return types.float64(types.int64), codegen


# ------------------------------------------------------------------------------- one source, per target
def _code_functions(module: ModuleType) -> dict[str, FunctionType]:
    """{name: function} of the module-level functions defined in ``module``, except those it names
    in its ``NOT_CODE``."""
    skip = set(getattr(module, "NOT_CODE", ()))
    return {k: v for k, v in vars(module).items()
            if isinstance(v, pytypes.FunctionType) and v.__module__ == module.__name__ and k not in skip}


def compile_code(modules: Sequence[ModuleType], jit: Callable[[Callable[..., Any]], Any], primitives: dict[str, Any],
                 replace: Mapping[str, Callable[[SimpleNamespace], Any]] | None = None) -> SimpleNamespace:
    """SimpleNamespace of every code function of ``modules`` compiled by ``jit``; in each, the
    globals named in ``primitives`` are bound to the given objects and every global that is a code
    function (under any name) to its compiled version.  ``replace`` maps a name to a function of
    the compiled namespace returning what calls of that name compile to instead."""
    code = {m.__name__: _code_functions(m) for m in modules}
    envs = {m.__name__: dict(vars(m), **primitives) for m in modules}
    compiled, by_id = {}, {}
    for mname, funcs in code.items():
        for name, f in funcs.items():
            g = pytypes.FunctionType(f.__code__, envs[mname], name, f.__defaults__, f.__closure__)
            g.__qualname__, g.__doc__ = f.__qualname__, f.__doc__
            compiled[name] = by_id[id(f)] = jit(g)
    ns = SimpleNamespace(**compiled)
    swap = {name: make(ns) for name, make in (replace or {}).items()}
    for env in envs.values():     # resolved when a function is first compiled (lazily)
        for k, v in list(env.items()):
            if isinstance(v, pytypes.FunctionType) and id(v) in by_id:
                env[k] = by_id[id(v)]
        env.update(swap)
    return ns


# ------------------------------------------------------------------------------- masked cold calls (CPU)
_PURE = ("nounwind", "willreturn", "memory(none)" if llvm.llvm_version_info >= (16,) else "readnone")


def _cold_functions(context: Any, module: ir.Module, sym: str, fndesc: Any, sig: Any) -> ir.Function:
    """The scalar function ``sym(double, ...) -> double`` (out of line, calling the compiled code) and
    its masked vector variants ``sym_v<N>(<N x double>, ..., <N x i1>)``; returns the scalar one."""
    d = ir.DoubleType()
    k = len(sig.args)
    scalar = ir.Function(module, ir.FunctionType(d, [d] * k), sym)
    # the copies numba links into one kernel merge by name: internal ones would be renamed
    # (sym.58), and the call's vector-variant attribute would no longer name its callee
    scalar.linkage = "linkonce_odr"
    for a in ("noinline",) + _PURE:
        set.add(scalar.attributes, a)     # llvmlite's add() knows no 'willreturn' / 'memory(none)'
    b = ir.IRBuilder(scalar.append_basic_block())
    _, res = context.call_internal_no_propagate(b, fndesc, sig, list(scalar.args))
    b.ret(res)
    used = []
    for n in VECTOR_WIDTHS:
        vt = ir.VectorType(d, n)
        vf = ir.Function(module, ir.FunctionType(vt, [vt] * k + [ir.VectorType(ir.IntType(1), n)]), f"{sym}_v{n}")
        vf.linkage = "linkonce_odr"
        for a in ("noinline",) + _PURE:
            set.add(vf.attributes, a)
        b = ir.IRBuilder(vf.append_basic_block())
        acc = vf.args[0]       # the result vector: masked-off lanes keep the first argument
        for i in range(n):
            lane = ir.Constant(ir.IntType(32), i)
            before = b.block
            then, after = b.append_basic_block(), b.append_basic_block()
            b.cbranch(b.extract_element(vf.args[k], lane), then, after)
            b.position_at_end(then)
            new = b.insert_element(acc, b.call(scalar, [b.extract_element(a, lane) for a in vf.args[:k]]), lane)
            b.branch(after)
            b.position_at_end(after)
            phi = b.phi(vt)
            phi.add_incoming(acc, before)
            phi.add_incoming(new, then)
            acc = phi
        b.ret(acc)
        used.append(vf)
    _keep_alive(module, used)
    return scalar


def _keep_alive(module: ir.Module, functions: list[ir.Function]) -> None:
    """Append ``functions`` to the module's llvm.compiler.used (the variants are unreferenced until the
    loop vectoriser calls them); llvmlite cannot resize a global, so the array is replaced."""
    ptr = ir.PointerType(ir.IntType(8))
    old = module.globals.pop("llvm.compiler.used", None)
    items = (list(old.initializer.constant) if old is not None else []) + [f.bitcast(ptr) for f in functions]
    keep = ir.GlobalVariable(module, ir.ArrayType(ptr, len(items)), f"{functions[0].name}.used")
    module.globals.pop(keep.name)
    keep._name = "llvm.compiler.used"        # an intrinsic global's fixed name, once per module
    keep.linkage = "appending"
    keep.section = "llvm.metadata"
    keep.initializer = ir.Constant(keep.type.pointee, items)
    module.globals[keep.name] = keep


def cold_call_cpu(dispatcher: Any, name: str) -> Any:
    """An intrinsic calling the compiled ``dispatcher(x, ...)`` (one or two floats -> float, pure) out
    of line, with masked vector variants: in a vectorised loop only the lanes that reach the call
    make it."""
    nargs = dispatcher.py_func.__code__.co_argcount
    sig = types.float64(*(types.float64,) * nargs)
    sym = f"safebasins_cold_{name}"
    variants = ",".join(f"_ZGV_LLVM_M{n}{'v' * nargs}_{sym}({sym}_v{n})" for n in VECTOR_WIDTHS)

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        cres = context.compile_subroutine(builder, dispatcher.py_func, sig)
        fn = builder.module.globals.get(sym)
        if fn is None:
            fn = _cold_functions(context, builder.module, sym, cres.fndesc, sig)
        call = builder.call(fn, [context.cast(builder, a, t, types.float64) for a, t in zip(args, signature.args)])
        set.add(call.attributes, "nounwind")
        set.add(call.attributes, f'"vector-function-abi-variant"="{variants}"')
        return call

    if nargs == 1:
        @intrinsic
        def cold(typingctx: Any, x: Any) -> Any:
            return sig, codegen
    elif nargs == 2:
        @intrinsic
        def cold(typingctx: Any, x: Any, y: Any) -> Any:
            return sig, codegen
    else:
        raise ValueError(f"cold_call_cpu: {name} takes {nargs} arguments; one or two are supported")
    return cold


# ------------------------------------------------------------------------------- @njit callers
def register_cpu_overload(generic: Callable[..., Any], compiled: Callable[[], Any]) -> None:
    """Let ``@njit`` code call the code function ``generic`` (one to three arguments): it compiles to
    a call of ``compiled()`` (a CPU dispatcher, built at the first such call)."""
    names = generic.__code__.co_varnames[:generic.__code__.co_argcount]
    src = (f"def _ol({', '.join(names)}):\n"
           f"    impl = compiled()\n"
           f"    return lambda {', '.join(names)}: impl({', '.join(names)})\n")
    ns = {"compiled": compiled}
    exec(compile(src, f"<overload of {generic.__name__}>", "exec"), ns)   # our own text: the signature
    overload(generic, jit_options={**JIT_OPTIONS, "forceinline": True, "error_model": "numpy"})(ns["_ol"])
