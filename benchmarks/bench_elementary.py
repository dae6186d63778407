"""The elementary functions of the wells (safebasins.wells.elementary): the dense accuracy sweep
and their speed against the platform's libm, in one process (docs/elementary.md).

    python benchmarks/bench_elementary.py                    # accuracy (1e5 samples per function) and speed
    python benchmarks/bench_elementary.py --samples 1000000 --only sin,cos
    python benchmarks/bench_elementary.py --no-accuracy      # speed only

Accuracy: the largest error in ulps against mpmath (~100 bits beyond double) over the samples of
tests/wells/elementary_reference.py (the whole domain of each function, every binade down to the
subnormals and up to overflow) and its hard points, for the CPU compilation; the bound the tests
assert is elementary.ULP_BOUNDS.  Speed: ns per call in an njit loop over 4096 arguments (uniform
in [-10, 10], log in (0, 20], pow with y in [-3, 3]), the best of --repeat interleaved runs,
elementary (vectorised lanes) against numba's math.* (libm: glibc), both on the same arrays.
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numba import njit

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from safebasins.wells import elementary  # noqa: E402
from tests.wells import elementary_reference as ref  # noqa: E402


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


def speed(names: list[str], repeat: int) -> None:
    rng = np.random.default_rng(0)
    x = rng.uniform(-10.0, 10.0, 4096)
    pos = rng.uniform(1e-3, 20.0, 4096)
    y = rng.uniform(-3.0, 3.0, 4096)
    out = np.empty_like(x)
    print(f"\n{'function':9s} {'elementary ns':>14s} {'libm ns':>9s} {'ratio':>6s}")
    cpu = elementary.cpu()
    for name in names:
        if name in ("powi", "sincos"):
            continue
        arg = pos if name in ("log", "sqrt", "pow") else x
        two = name == "pow"
        jobs = {"elementary": _loops(getattr(cpu, name), two)}
        lib = _libm(name)
        if lib is not None:
            jobs["libm"] = _loops(lib, two)
        best = dict.fromkeys(jobs, math.inf)
        for fn in jobs.values():
            fn(arg, y, out)
        for _ in range(repeat):
            for k, fn in jobs.items():
                t = time.perf_counter()
                for _ in range(50):
                    fn(arg, y, out)
                best[k] = min(best[k], (time.perf_counter() - t) / (50 * arg.size) * 1e9)
        lm = best.get("libm", math.nan)
        print(f"{name:9s} {best['elementary']:14.2f} {lm:9.2f} {best['elementary'] / lm:6.2f}", flush=True)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--samples", type=int, default=100_000)
    ap.add_argument("--only", default=",".join(ref.CHECKED))
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--no-accuracy", action="store_true")
    ap.add_argument("--no-speed", action="store_true")
    a = ap.parse_args(argv)
    names = a.only.split(",")
    print("machine:", machine())
    if not a.no_accuracy:
        accuracy(names, a.samples)
    if not a.no_speed:
        speed(names, a.repeat)
    print("machine after:", machine())
    return 0


if __name__ == "__main__":
    sys.exit(main())
