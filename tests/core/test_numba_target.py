"""The vector width of numba's CPU target (safebasins.core.numba_target): 512-bit vectors preferred
on a host with AVX-512 and nowhere else, never over the user's own choice, a kernel's cache entry
kept apart per setting.  Each check runs in a fresh interpreter: numba's CPU target takes its
features once per process.  Also: the loop interleave of kernel_compile, and the package's
compiled functions built without numba's C wrapper."""
from __future__ import annotations

import importlib
import json
import os
import pkgutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from numba.core.registry import CPUDispatcher

import safebasins.numerics
import safebasins.theory
import safebasins.wells
from safebasins.core import numba_target
from safebasins.core.numba_target import PREFER_256, wide_vector_features
from safebasins.numerics import noise_loops, well_loops
from safebasins.wells import compiled

WIDE = "-" + PREFER_256
#: the variables by which a user chooses numba's target (removed from the probes' environment)
USER_TARGET = ("NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES", "NUMBA_ENABLE_AVX")


def _host_avx512f() -> bool:
    """The kernel's word (not LLVM's, which the module asks) on whether this CPU runs AVX-512F."""
    cpuinfo = Path("/proc/cpuinfo")
    if not cpuinfo.exists():
        pytest.skip("needs /proc/cpuinfo to know the host's instruction set")
    flags = next((line for line in cpuinfo.read_text().splitlines() if line.startswith("flags")), "")
    return "avx512f" in flags.split()


def _probe(code: str, cwd: Path, **env: str) -> dict:
    """Run ``code`` in a fresh interpreter (the user's target variables unset unless given) and
    return the JSON object of its last output line."""
    environ = {k: v for k, v in os.environ.items() if k not in USER_TARGET} | env
    r = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                       cwd=cwd, env=environ, timeout=300)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


FEATURES = """
    import json
    from numba.core import config
    from numba.core.codegen import get_host_cpu_features
    {before}
    import safebasins.numerics
    from safebasins.core.numba_target import compiled_features
    print(json.dumps({{"host": get_host_cpu_features(), "compiled": compiled_features(),
                      "config": config.CPU_FEATURES}}))
"""

# a host without (or with) AVX-512 simulated on any machine: LLVM's host features as numba reads
# them, avx512* switched off (on); nothing is compiled, the target is only created
SIMULATED = """
    import json
    import numba.core.codegen as cg
    real = cg.get_host_cpu_features
    def simulated():
        flags = real().split(",")
        return ",".join(("{sign}" + f[1:]) if f[1:].startswith("avx512") else f for f in flags)
    cg.get_host_cpu_features = simulated
    from safebasins.core import numba_target
    print(json.dumps({{"set": numba_target.configure(), "host": simulated(),
                      "compiled": numba_target.compiled_features()}}))
"""


def test_wide_vector_features_appends_the_preference():
    host = "+64bit,+avx,+avx2,+avx512f,+avx512dq,-avx512fp16,+fma"
    assert wide_vector_features(host) == host + "," + WIDE
    # a preference already in the string is replaced, not doubled; every other entry kept in order
    assert wide_vector_features("+avx2,+prefer-256-bit,+avx512f,+fma") == "+avx2,+avx512f,+fma," + WIDE
    assert wide_vector_features("+avx512f," + WIDE) == "+avx512f," + WIDE


@pytest.mark.parametrize("host", ["+64bit,+avx,+avx2,-avx512f,+fma", "+64bit,+avx,+avx2,+fma", "",
                                  "+avx512fp16,-avx512f"])
def test_wide_vector_features_without_avx512f_is_none(host):
    assert wide_vector_features(host) is None


def test_applied_on_this_host_exactly_when_it_has_avx512f(tmp_path):
    got = _probe(FEATURES.format(before=""), tmp_path)
    assert PREFER_256 not in got["host"]            # LLVM's host detection names ISA features only
    if _host_avx512f():
        assert got["compiled"] == got["host"] + "," + WIDE
        assert got["config"] == got["compiled"]
    else:
        assert got["compiled"] == got["host"]
        assert got["config"] is None


@pytest.mark.parametrize("sign", ["-", "+"])
def test_simulated_hosts(tmp_path, sign):
    """Without AVX-512 the target keeps the host's features; with it, they prefer 512 bits."""
    got = _probe(SIMULATED.format(sign=sign), tmp_path)
    if sign == "-":
        assert got["set"] is None and got["compiled"] == got["host"]
    else:
        assert got["set"] == got["compiled"] == got["host"] + "," + WIDE


def test_the_users_choice_is_kept(tmp_path):
    host = _probe(FEATURES.format(before=""), tmp_path)["host"]
    # the host's own features named by the user: numba's default 256-bit preference stays
    got = _probe(FEATURES.format(before=""), tmp_path, NUMBA_CPU_FEATURES=host)
    assert got["compiled"] == host and got["config"] == host
    got = _probe(FEATURES.format(before=""), tmp_path, NUMBA_CPU_NAME="haswell")
    assert PREFER_256 not in got["compiled"] and got["config"] is None
    # numba's CPU target created by the user's own code before the package: left as it is
    got = _probe(FEATURES.format(before="import numba; numba.njit(lambda x: x)"), tmp_path)
    assert got["compiled"] == host and got["config"] is None


ASM = """
    import json
    import numpy as np
    from numba import njit
    from safebasins.wells import elementary
    sin = elementary.cpu().sin

    @njit(error_model="numpy")
    def lanes(x, out):
        for i in range(x.size):
            out[i] = sin(x[i])

    x = np.linspace(-3.0, 3.0, 64)
    out = np.empty_like(x)
    lanes(x, out)
    asm = lanes.inspect_asm(lanes.signatures[0])
    print(json.dumps({"zmm": asm.count("%zmm"), "ymm": asm.count("%ymm"), "sum": float(out.sum())}))
"""


def test_a_lane_loop_uses_512_bit_registers(tmp_path):
    if not _host_avx512f():
        pytest.skip("the host has no AVX-512")
    host = _probe(FEATURES.format(before=""), tmp_path)["host"]
    wide = _probe(ASM, tmp_path, NUMBA_DISABLE_CACHE="1")
    narrow = _probe(ASM, tmp_path, NUMBA_DISABLE_CACHE="1", NUMBA_CPU_FEATURES=host)
    assert wide["zmm"] > 2 * wide["ymm"], wide
    assert narrow["ymm"] > 2 * narrow["zmm"], narrow
    assert wide["sum"] == narrow["sum"]


CACHED = """
    import json, sys
    import safebasins.wells
    sys.path.insert(0, {path!r})
    from cached_kernel import lanes
    print(json.dumps({{"result": lanes(2.0), "hits": sum(lanes.stats.cache_hits.values()),
                      "misses": sum(lanes.stats.cache_misses.values())}}))
"""


def test_the_cache_keeps_the_two_widths_apart(tmp_path):
    """A kernel cached by a 256-bit process is compiled anew by a 512-bit one (and the reverse);
    each then loads its own entry."""
    if not _host_avx512f():
        pytest.skip("one width only on a host without AVX-512")
    src = tmp_path / "src"
    src.mkdir()
    (src / "cached_kernel.py").write_text(textwrap.dedent("""
        import numpy as np
        from numba import njit

        @njit(cache=True)
        def lanes(a):
            x = np.arange(64.0)
            return float(np.sum(x * a + 1.0))
    """))
    host = _probe(FEATURES.format(before=""), tmp_path)["host"]
    code = CACHED.format(path=str(src))
    env = {"NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    narrow = {"NUMBA_CPU_FEATURES": host, **env}
    runs = [_probe(code, tmp_path, **narrow), _probe(code, tmp_path, **env),
            _probe(code, tmp_path, **narrow), _probe(code, tmp_path, **env)]
    assert [(r["hits"], r["misses"]) for r in runs] == [(0, 1), (0, 1), (1, 0), (1, 0)], runs
    assert len({r["result"] for r in runs}) == 1


def test_kernel_compile_interleaves_and_puts_the_default_back(tmp_path):
    """Inside kernel_compile a vectorised loop is interleaved INTERLEAVE times (each of the body's
    two multiplications is INTERLEAVE vector multiplications); inside nested blocks the outermost
    block's count holds; a loop compiled after them gets the cost model's choice again, as one
    compiled before."""
    counts = _probe("""
        import json, re
        from numba import njit, types
        from safebasins.core import numba_target

        def loop():
            @njit
            def f(a, b):
                for i in range(a.size):
                    b[i] = a[i] * 3.0 + a[i] * a[i]
            return f

        arr = types.Array(types.float64, 1, "C")
        out = []
        for inside in (False, True, "nested", False):
            f = loop()
            if inside == "nested":
                with numba_target.kernel_compile(3), numba_target.kernel_compile():
                    f.compile((arr, arr))
            elif inside:
                with numba_target.kernel_compile():
                    f.compile((arr, arr))
            else:
                f.compile((arr, arr))
            out.append(len(re.findall(r"fmul <\\d+ x double>", f.inspect_llvm((arr, arr)))))
        print(json.dumps(out + [numba_target.INTERLEAVE]))
        """, tmp_path)
    before, inside, nested, after, interleave = counts
    assert interleave >= 2 and interleave != 3
    assert inside == 2 * interleave, counts
    assert nested == 2 * 3, counts
    assert after == before, counts


def test_the_package_compiles_no_c_wrappers_but_for_its_pointers():
    """Every CPU function the engine, the wells and the theory compile is a package_jit (or takes
    JIT_OPTIONS): numba builds no C-callable wrapper for it; those the lane machinery (deterministic
    or noisy) calls through a function pointer are pointer_jit, and keep theirs."""
    found = {}
    for layer in (safebasins.numerics, safebasins.wells, safebasins.theory):
        for info in pkgutil.walk_packages(layer.__path__, layer.__name__ + "."):
            module = importlib.import_module(info.name)
            for name, value in vars(module).items():
                if isinstance(value, CPUDispatcher) and value.py_func.__module__ == module.__name__:
                    found[f"{module.__name__}.{name}"] = value.targetoptions.get("no_cfunc_wrapper")
    assert len(found) > 20, found
    pointers = {f"safebasins.numerics.well_loops.{name}"
                for name in ("_shared_period", "_lanes_period", "_replay", "_check_state")}
    pointers |= {f"safebasins.numerics.noise_loops.{name}" for name in ("_lane_steps", "_lane_enter")}
    assert {name for name, flag in found.items() if flag is not True} == pointers, found
    assert all(found[name] is False for name in pointers)
    for layer in (well_loops, noise_loops):
        for name, value in vars(layer).items():
            if f"{layer.__name__}.{name}" in pointers:    # called through C only: no CPython wrapper
                assert value.targetoptions.get("no_cpython_wrapper") is True, name
    assert numba_target.JIT_OPTIONS.items() <= compiled.LLVM_INLINE.items()
