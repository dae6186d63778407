"""Shared by the benchmarks: the machine in words and one machine-readable result line.

Every benchmark that feeds the README table prints ``BENCH {json}`` lines with ``name``,
``ratio`` (the figure to quote; what it is a ratio of in ``what``), ``detail`` and ``machine``;
``scripts/update_benchmarks.py`` collects them (``make benchmarks``)."""
from __future__ import annotations

import json
import os
import platform


def cpu_info():
    """(model name, SIMD level, logical cores, nominal GHz or None) from /proc/cpuinfo."""
    model, simd, ghz = platform.processor() or "?", "?", None
    try:
        with open("/proc/cpuinfo") as fh:
            info = fh.read()
        model = next(ln.split(":", 1)[1].strip() for ln in info.splitlines() if ln.startswith("model name"))
        simd = "AVX-512" if "avx512f" in info else "AVX2" if "avx2" in info else "no AVX2"
        mhz = [float(ln.split(":", 1)[1]) for ln in info.splitlines() if ln.startswith("cpu MHz")]
        ghz = max(mhz) / 1000.0 if mhz else None
    except (OSError, StopIteration, ValueError):
        pass
    return model, simd, os.cpu_count(), ghz


def cpu_family():
    """(CPU family number, vendor id) from /proc/cpuinfo; (0, "?") where unreadable."""
    try:
        with open("/proc/cpuinfo") as fh:
            lines = fh.read().splitlines()
        family = int(next(ln.split(":", 1)[1] for ln in lines if ln.startswith("cpu family")))
        vendor = next(ln.split(":", 1)[1].strip() for ln in lines if ln.startswith("vendor_id"))
        return family, vendor
    except (OSError, StopIteration, ValueError):
        return 0, "?"


def machine():
    model, simd, n, _ = cpu_info()
    return f"{model} ({simd}), {n} logical cores"


def report(name, ratio, what, detail=""):
    """Print one ``BENCH {json}`` line."""
    print("BENCH " + json.dumps({"name": name, "ratio": ratio, "what": what, "detail": detail,
                                 "machine": machine()}), flush=True)
