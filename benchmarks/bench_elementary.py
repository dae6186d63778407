"""The elementary functions of the wells (safebasins.wells.elementary): the dense accuracy sweep
and their speed against the platform's libm, in one process (docs/elementary.md).

    python benchmarks/bench_elementary.py                    # accuracy (1e5 samples per function) and speed
    python benchmarks/bench_elementary.py --samples 1000000 --only sin,cos
    python benchmarks/bench_elementary.py --no-accuracy      # speed only
    python benchmarks/bench_elementary.py --no-accuracy --before HEAD~1   # speed before / after

Accuracy: the largest error in ulps against mpmath (~100 bits beyond double) over the samples of
tests/wells/elementary_reference.py (the whole domain of each function, every binade down to the
subnormals and up to overflow) and its hard points, for the CPU compilation; the bound the tests
assert is elementary.ULP_BOUNDS.  Speed: ns per call in an njit loop over 4096 arguments (uniform
in [-10, 10], log in (0, 20], pow with y in [-3, 3]), the best of --repeat interleaved runs,
elementary (vectorised lanes) against numba's math.* (libm: glibc), both on the same arrays.
With --before REV: also wells/elementary.py of git revision REV (its sibling modules today's),
compiled for the CPU beside today's in this process and timed in the same interleaved rounds;
the column after/before is today's time over REV's, and the bits of both on the speed arrays
are compared (a change meant to keep the bits must print "bits equal").  With --floor: also the
cost floor of floor_elementary.py (the cheapest polynomial forms, not faithful) where it has
the function, timed in the same rounds.
"""
from __future__ import annotations

import argparse
import importlib.util
import math
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numba import njit

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from safebasins.wells import elementary  # noqa: E402
from safebasins.wells.compiled import fma_cpu, mul_cpu  # noqa: E402
from safebasins.wells.elementary_targets import as_bits_cpu, cold_call_cpu, compile_code, from_bits_cpu  # noqa: E402
from tests.wells import elementary_reference as ref  # noqa: E402
from floor_elementary import FLOOR, floor_namespace  # noqa: E402  (beside this script)


def machine() -> str:
    info: dict[str, str] = {}
    for line in open("/proc/cpuinfo"):
        k, _, v = line.partition(":")
        if k.strip() in ("model name", "flags") and k.strip() not in info:
            info[k.strip()] = v.strip()
    flags = set(info.get("flags", "").split())
    simd = ", ".join(f for f in ("avx2", "fma", "avx512f") if f in flags)
    la = os.getloadavg()
    return (f"{info.get('model name', '?')}, {os.cpu_count()} CPUs, SIMD: {simd}, NUMBA_CPU_NAME="
            f"{os.environ.get('NUMBA_CPU_NAME', 'host')}; load average {la[0]:.2f}")


def accuracy(names: list[str], n: int) -> None:
    print(f"{'function':9s} {'bound':>6s} {'max ulp':>8s}  worst argument   (samples {n} + hard points)")
    for name in names:
        t = time.perf_counter()
        worst: tuple[float, float, float | None] = (0.0, math.nan, None)
        for x, y in (ref.samples(name, n), ref.hard_points(name)):
            w = ref.max_ulp(name, x, y, ref.cpu_values(name, x, y))
            worst = max(worst, w, key=lambda r: r[0])
        arg = f"{worst[1]!r}" + ("" if worst[2] is None else f", {worst[2]!r}")
        took = time.perf_counter() - t
        print(f"{name:9s} {elementary.ULP_BOUNDS[name]:6.2f} {worst[0]:8.4f}  ({arg})  [{took:.0f} s]", flush=True)


def _loops(f: Callable[..., float], two: bool) -> Any:
    if two:
        @njit
        def run2(x: np.ndarray, y: np.ndarray, out: np.ndarray) -> None:
            for i in range(x.size):
                out[i] = f(x[i], y[i])
        return run2

    @njit
    def run1(x: np.ndarray, y: np.ndarray, out: np.ndarray) -> None:
        for i in range(x.size):
            out[i] = f(x[i])
    return run1


def _libm(name: str) -> Any:
    if name == "pow":
        return njit(lambda x, y: x ** y)
    g = getattr(math, name, None)
    return None if g is None else njit(lambda x: g(x))


def before_cpu(rev: str) -> tuple[Any, str]:
    """wells/elementary.py of git revision ``rev`` compiled for the CPU as today's elementary.cpu()
    compiles today's (the sibling modules and the primitives today's): (a namespace of
    dispatchers, the module's source)."""
    src = subprocess.run(["git", "show", f"{rev}:src/safebasins/wells/elementary.py"], cwd=ROOT, check=True,
                         capture_output=True, text=True).stdout
    path = Path(tempfile.mkdtemp(prefix="safebasins_elementary_before")) / "elementary_before.py"
    path.write_text(src)
    spec = importlib.util.spec_from_file_location("elementary_before", path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules["elementary_before"] = mod
    spec.loader.exec_module(mod)
    prims = {"fma": fma_cpu, "mul": mul_cpu, "as_bits": as_bits_cpu, "from_bits": from_bits_cpu}
    # its rare paths as today's: masked cold calls (symbols of their own)
    modules = (mod, *elementary._MODULES[1:])
    cold = {k: (lambda ns, k=k: cold_call_cpu(getattr(ns, k), f"before{k}"))
            for k in elementary.COLD_PATHS if any(k in vars(m) for m in modules)}
    return compile_code(modules, njit(error_model="numpy", forceinline=True), prims, cold), src


def speed(names: list[str], repeat: int, before: str | None = None, floor: bool = False) -> None:
    rng = np.random.default_rng(0)
    x = rng.uniform(-10.0, 10.0, 4096)
    pos = rng.uniform(1e-3, 20.0, 4096)
    y = rng.uniform(-3.0, 3.0, 4096)
    out = np.empty_like(x)
    cpu = elementary.cpu()
    old = before_cpu(before)[0] if before else None
    extra = f" {'before ns':>9s} {'after/before':>12s}  bits" if old else ""
    flo = floor_namespace() if floor else None
    extra += f" {'floor ns':>9s} {'elementary/floor':>16s}" if flo else ""
    print(f"\n{'function':9s} {'elementary ns':>14s} {'libm ns':>9s} {'ratio':>6s}{extra}")
    for name in names:
        if name in ("powi", "sincos"):
            continue
        arg = pos if name in ("log", "sqrt", "pow") else x
        two = name == "pow"
        jobs = {"elementary": _loops(getattr(cpu, name), two)}
        lib = _libm(name)
        if lib is not None:
            jobs["libm"] = _loops(lib, two)
        if old is not None:
            jobs["before"] = _loops(getattr(old, name), two)
        if flo is not None and name in FLOOR:
            jobs["floor"] = _loops(getattr(flo, name), two)
        best = dict.fromkeys(jobs, math.inf)
        outs = {}
        for k, fn in jobs.items():
            fn(arg, y, out)
            outs[k] = out.copy()
        for _ in range(repeat):
            for k, fn in jobs.items():
                t = time.perf_counter()
                for _ in range(50):
                    fn(arg, y, out)
                best[k] = min(best[k], (time.perf_counter() - t) / (50 * arg.size) * 1e9)
        lm = best.get("libm", math.nan)
        line = f"{name:9s} {best['elementary']:14.2f} {lm:9.2f} {best['elementary'] / lm:6.2f}"
        if old is not None:
            same = np.array_equal(outs["elementary"].view(np.int64), outs["before"].view(np.int64))
            line += (f" {best['before']:9.2f} {best['elementary'] / best['before']:12.2f}  "
                     f"{'bits equal' if same else 'BITS DIFFER'}")
        if flo is not None:
            fl = best.get("floor", math.nan)
            line += f" {fl:9.2f} {best['elementary'] / fl:16.2f}"
        print(line, flush=True)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--samples", type=int, default=100_000)
    ap.add_argument("--only", default=",".join(ref.CHECKED))
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--no-accuracy", action="store_true")
    ap.add_argument("--no-speed", action="store_true")
    ap.add_argument("--before", default=None, help="git revision: also time its wells/elementary.py (after/before)")
    ap.add_argument("--floor", action="store_true", help="also time the cost floor of floor_elementary.py")
    a = ap.parse_args(argv)
    names = a.only.split(",")
    print("machine:", machine())
    if not a.no_accuracy:
        accuracy(names, a.samples)
    if not a.no_speed:
        speed(names, a.repeat, a.before, a.floor)
    print("machine after:", machine())
    return 0


if __name__ == "__main__":
    sys.exit(main())
