"""The vector width numba compiles the package's kernels for: 512 bits on a CPU with AVX-512.

LLVM tunes the Intel AVX-512 cores (Skylake-X, Cascade Lake, Ice Lake, Sapphire Rapids) with
``prefer-256-bit``, so its loop vectoriser fills 256-bit registers (4 doubles) where the CPU has
512-bit ones (8).  The engine's lane loops (every well's force, the elementary functions) are
elementwise arithmetic: wider vectors change no bit of a result and, on a Cascade Lake, make a
step about 1.6x faster for the quartic and the transcendental wells alike
(benchmarks/bench_wells.py).

:func:`configure` therefore gives numba the host's feature string with ``-prefer-256-bit``
appended, on a CPU with ``avx512f`` only, and leaves numba alone where the user chose its target
(``NUMBA_CPU_NAME``, ``NUMBA_CPU_FEATURES`` or numba's config file; ``NUMBA_ENABLE_AVX=0``
removes ``avx512f`` from the host's features) or where numba's CPU target already exists in the
process (code compiled before the package was imported: its features stay, one set per process).
The feature string is part of numba's cache key (the codegen's ``magic_tuple``), so a kernel
cached by a 256-bit process is never loaded by a 512-bit one, nor the reverse.

The loop vectoriser's interleave count is the other setting (:func:`kernel_compile`).  A step of
a well whose force calls elementary functions (sin, exp: 100-150 instructions each) is a long
dependency chain; the period loops advance 4 lanes' chains per iteration, but written one after
the other they do not fit the CPU's out-of-order window together, and the step runs at the
chain's latency.  Interleaved by :data:`INTERLEAVE`, the vector body issues each instruction for
two vectors side by side: on an AMD Zen 3 (AVX2) a step becomes 1.15x (quartic) to 1.6x (Morse)
faster (benchmarks/bench_wells.py ``--interleave-before 0``; docs/elementary.md).  Lanes stay
independent and every operation is the same IEEE operation, so no bit of a result changes.
LLVM reads the count from a process-wide option: :func:`kernel_compile` sets it under numba's
compiler lock for the package's kernels only and puts back LLVM's default (0: the cost model's
choice) after.  A kernel loaded from numba's cache was compiled so; the option's value is in the
engine's fingerprint (this file is one of numerics.scheme_code.ENGINE_FILES).

Every function the package compiles for the CPU goes through :func:`package_jit` (or takes
:data:`JIT_OPTIONS`): numba's C-callable wrapper is not built, but for the three functions the
lane machinery calls through a function pointer (:func:`pointer_jit`).
"""
from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any, Final, Unpack, cast

import llvmlite.binding as llvm
from numba import njit
from numba.core import config
from numba.core.codegen import get_host_cpu_features
from numba.core.compiler_lock import global_compiler_lock
from numba.core.registry import cpu_target

if TYPE_CHECKING:
    from numba.core.decorators import _JITOptions, _JITWrapper   # numba's stubs: njit's options, its decorator

__all__ = ["PREFER_256", "INTERLEAVE", "VECTOR_LANES", "JIT_OPTIONS", "POINTER_OPTIONS", "package_jit", "pointer_jit",
           "wide_vector_features",
           "compiled_features", "configure", "kernel_compile"]

#: LLVM's tuning feature that caps the loop vectoriser at 256 bits on AVX-512 cores
PREFER_256 = "prefer-256-bit"
#: the loop vectoriser's interleave count for the package's kernels (LLVM's
#: ``-force-vector-interleave``; 0 leaves it to LLVM's cost model)
INTERLEAVE = 2
#: doubles per vector-loop iteration at most: 8 (512 bits) times INTERLEAVE; a lane loop whose
#: trip count is a multiple of it has no scalar remainder on any host
VECTOR_LANES = 8 * INTERLEAVE
#: numba's options for every function the package compiles for the CPU: no C-callable wrapper.
#: numba builds one per function and signature for the function's use as a first-class value,
#: which the package never makes; building and optimising them was about a sixth of the compile of
#: a first chart (benchmarks/profile_compile.py)
#: (numba's stubs do not list the option)
JIT_OPTIONS: Final = cast("_JITOptions", {"no_cfunc_wrapper": True})


#: the options of a function the lane machinery calls through a function pointer
#: (numerics.well_loops, numerics.noise_loops): it keeps the C-callable wrapper, through which such
#: a call goes, and has no CPython wrapper (Python never calls one of its literal specialisations:
#: about 0.3 s less of a new well's first chart)
POINTER_OPTIONS: Final = cast("_JITOptions", {"no_cfunc_wrapper": False, "no_cpython_wrapper": True})


def package_jit(*, cache: bool = False, **options: Unpack[_JITOptions]) -> _JITWrapper:
    """``numba.njit(cache=cache, **options)`` with :data:`JIT_OPTIONS`: the decorator of the
    package's compiled functions."""
    decorator: _JITWrapper = cast(Any, njit)(cache=cache, **{**options, **JIT_OPTIONS})
    return decorator


def pointer_jit(*, cache: bool = False, **options: Unpack[_JITOptions]) -> _JITWrapper:
    """``numba.njit(cache=cache, **options)`` with :data:`POINTER_OPTIONS`: the decorator of a
    function called through a function pointer."""
    decorator: _JITWrapper = cast(Any, njit)(cache=cache, **{**options, **POINTER_OPTIONS})
    return decorator


def wide_vector_features(host_features: str) -> str | None:
    """``host_features`` (LLVM's ``+name,-name,...``) with 512-bit vectors preferred: any
    ``prefer-256-bit`` entry replaced by ``-prefer-256-bit`` at the end; None where the string
    does not enable ``avx512f`` (nothing to widen)."""
    flags = [f for f in host_features.split(",") if f]
    if "+avx512f" not in flags:
        return None
    return ",".join([*(f for f in flags if f[1:] != PREFER_256), "-" + PREFER_256])


def compiled_features() -> str:
    """The feature string numba's CPU target compiles with in this process (the one its cache
    key holds); creates the target when it does not exist yet."""
    features: str = cpu_target.target_context.codegen().magic_tuple()[2]
    return features


def configure() -> str | None:
    """Make numba's CPU target prefer 512-bit vectors on this host (see the module docstring),
    before the package compiles or loads a kernel.  Returns the feature string set, None where
    numba was left as it was."""
    # numba.config sets CPU_NAME and CPU_FEATURES from the environment: not declared to mypy
    if config.CPU_NAME is not None or config.CPU_FEATURES is not None:  # type: ignore[attr-defined]
        return None                                                      # the user's choice
    wide = wide_vector_features(get_host_cpu_features())
    if wide is None:
        return None
    config.CPU_FEATURES = wide  # type: ignore[attr-defined]
    # the target reads the features once, when it is created: created here, a later reload of
    # numba's config (any change of a NUMBA_ variable) cannot undo them
    if compiled_features() != wide:         # the target existed already, with its own features
        config.CPU_FEATURES = None  # type: ignore[attr-defined]
        return None
    return wide


@contextmanager
def kernel_compile(interleave: int = INTERLEAVE) -> Iterator[None]:
    """Compile the package's kernels inside this block: LLVM's loop vectoriser interleaves by
    ``interleave`` (module docstring), under numba's compiler lock so that no other thread's
    compile sees the option; LLVM's default is put back on leaving.  Blocks nest: the outermost
    sets the count (a benchmark compiles the kernels with another count around the engine's
    own blocks)."""
    global _depth
    with global_compiler_lock:
        outer = _depth == 0
        if outer:
            llvm.set_option("", f"-force-vector-interleave={interleave}")
        _depth += 1
        try:
            yield
        finally:
            _depth -= 1
            if outer:
                llvm.set_option("", "-force-vector-interleave=0")


_depth = 0      # kernel_compile blocks open (in the thread that holds the compiler lock)
