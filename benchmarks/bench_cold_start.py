"""Cold start of the CPU engine: the first ``numerics.escape_chart`` call of a fresh
process, with an empty numba cache and with the project's cache (``make`` warms it at install).

    .venv/bin/python benchmarks/bench_cold_start.py            # 1 run of each
    .venv/bin/python benchmarks/bench_cold_start.py --runs 3   # medians of 3

Each case is a fresh subprocess (``NUMBA_CACHE_DIR`` set to an empty temporary folder for the
cold cases, unset for the installed cache, which then lives in the package's ``__pycache__``):

* ``chart, empty cache``: import of safebasins.numerics, then the first call (compiles every
  kernel the call needs);
* ``chart, same cache again``: a second fresh process on the cache the first one wrote (loads);
* ``chart, installed cache``: the first call with the project's own cache as ``make`` leaves it;
* ``plain numba kernel, empty cache``: the compile and first call of a small ``@njit`` loop (a
  leapfrog of the quartic) -- the unit the chart's compile time is quoted in, so that the ratio
  carries over between machines.

Prints the times (wall clock, and the CPU time of the first call: on a loaded machine the wall
clock counts other processes' turns), the ratio chart / plain kernel and a ``BENCH`` line.
benchmarks/profile_compile.py breaks a first compile down by numba's compile events.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from _report import machine, report  # noqa: E402

CHART = r"""
import json, time
t0 = time.perf_counter()
import numpy as np
import safebasins.numerics as nu
t1 = time.perf_counter()
c1 = time.process_time()
q = np.linspace(-0.5, 0.5, 4)
nu.escape_chart(q, q, F=0.01, Omega=0.9, Psi=np.pi, xi_max=(0.18,), cycles=5)
t2 = time.perf_counter()
c2 = time.process_time()
nu.escape_chart(q, q, F=0.01, Omega=0.9, Psi=np.pi, xi_max=(0.18,), cycles=5)
t3 = time.perf_counter()
print(json.dumps({"import": t1 - t0, "first": t2 - t1, "second": t3 - t2, "cpu": c2 - c1}))
"""

# a new expression well (a Coulomb term whose constant no cache has seen) on a cache that holds
# everything else: what a user waits for at the first chart of a well of their own
EXPRESSION = r"""
import json, sys, time
t0 = time.perf_counter()
import numpy as np
import safebasins.numerics as nu
from safebasins import wells
from numba.core import event as ev
t1 = time.perf_counter()
a = float(sys.argv[1])
w = wells.expression(f"q**2/2 - {a!r}/(1 - q) + {a!r} + {a!r}*q")
w.compiled
class Total(ev.Listener):
    def __init__(self):
        self.depth, self.start, self.total = 0, 0.0, 0.0
    def on_start(self, event):
        if self.depth == 0:
            self.start = time.perf_counter()
        self.depth += 1
    def on_end(self, event):
        self.depth -= 1
        if self.depth == 0:
            self.total += time.perf_counter() - self.start
llvm = Total()
q = np.linspace(-0.2, 0.2, 4)
t2 = time.perf_counter()
c2 = time.process_time()
with ev.install_listener("numba:llvm_lock", llvm):
    nu.escape_chart(q, q, F=0.01, Omega=0.9, Psi=np.pi, xi_max=(0.05,), cycles=5, well=w)
t3 = time.perf_counter()
print(json.dumps({"import": t1 - t0, "well": t2 - t1, "first": t3 - t2, "second": 0.0, "llvm": llvm.total,
                  "cpu": time.process_time() - c2}))
"""

PLAIN = r"""
import json, time
t0 = time.perf_counter()
import numpy as np
from numba import njit
t1 = time.perf_counter()
c1 = time.process_time()

@njit(cache=True)
def leapfrog(q, p, h, n):
    for i in range(q.size):
        a, b = q[i], p[i]
        for _ in range(n):
            b += 0.5 * h * (a * a * a - a)
            a += h * b
            b += 0.5 * h * (a * a * a - a)
        q[i], p[i] = a, b
    return q

leapfrog(np.zeros(4), np.ones(4) * 0.1, 0.01, 10)
t2 = time.perf_counter()
print(json.dumps({"import": t1 - t0, "first": t2 - t1, "second": 0.0, "cpu": time.process_time() - c1}))
"""


def run(code, cache_dir, *argv):
    env = dict(os.environ)
    env.pop("NUMBA_CACHE_DIR", None)
    if cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = cache_dir
    src = os.path.join(os.path.dirname(HERE), "src")
    env["PYTHONPATH"] = src + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    with tempfile.TemporaryDirectory() as d:      # a file: numba caches only functions of files
        script = os.path.join(d, "case.py")
        with open(script, "w") as fh:
            fh.write(code)
        out = subprocess.run([sys.executable, script, *argv], env=env, capture_output=True, text=True)
    if out.returncode:
        raise SystemExit(f"case failed:\n{out.stderr}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=1, help="repetitions of each case (medians)")
    ap.add_argument("--quick", action="store_true", help="(accepted for make benchmarks; same as --runs 1)")
    args = ap.parse_args()
    print(machine())
    rows = {k: [] for k in ("chart, empty cache", "chart, same cache again", "chart, installed cache",
                            "new expression well, warm cache", "plain numba kernel, empty cache")}
    rng = np.random.default_rng()
    for _ in range(max(1, args.runs)):
        with tempfile.TemporaryDirectory() as d:
            rows["chart, empty cache"].append(run(CHART, d))
            rows["chart, same cache again"].append(run(CHART, d))
            run(EXPRESSION, d, "0.05")          # the engine's well-independent parts cached
            rows["new expression well, warm cache"].append(run(EXPRESSION, d, repr(rng.uniform(0.01, 0.1))))
        rows["chart, installed cache"].append(run(CHART, None))
        with tempfile.TemporaryDirectory() as d:
            rows["plain numba kernel, empty cache"].append(run(PLAIN, d))
    med = {k: {f: float(np.median([r[f] for r in v])) for f in ("import", "first", "second", "cpu")}
           for k, v in rows.items()}
    print(f"{'case':34s} {'import [s]':>10s} {'first call [s]':>15s} {'(CPU [s])':>10s} {'second [s]':>10s}")
    for k, v in med.items():
        print(f"{k:34s} {v['import']:10.2f} {v['first']:15.2f} {v['cpu']:10.2f} {v['second']:10.3f}")
    plain = med["plain numba kernel, empty cache"]["first"]
    cold = med["chart, empty cache"]["first"]
    inst = med["chart, installed cache"]["first"]
    print(f"first chart call / plain kernel compile: empty cache {cold / plain:.1f}, "
          f"installed cache {inst / plain:.2f}")
    c_plain, c_cold = med["plain numba kernel, empty cache"]["cpu"], med["chart, empty cache"]["cpu"]
    c_new = med["new expression well, warm cache"]["cpu"]
    print(f"in CPU time (less sensitive to the machine's load): plain kernel {c_plain:.2f} s, "
          f"empty cache chart {c_cold / c_plain:.1f}x, new expression well {c_new:.2f} s ({c_new / c_plain:.1f}x)")
    ex = rows["new expression well, warm cache"]
    llvm = float(np.median([r["llvm"] for r in ex]))
    well = float(np.median([r["well"] for r in ex]))
    first = med["new expression well, warm cache"]["first"]
    print(f"new expression well: well built (sympy, orbits) {well:.2f} s; first chart {first:.2f} s, "
          f"of which LLVM (numba:llvm_lock) {llvm:.2f} s, numba's front end (typing, lowering) the rest")
    report("escape_chart cold start", round(cold / plain, 1),
           "first call with an empty numba cache / compile of a plain @njit loop",
           f"empty cache {cold:.1f} s, installed cache {inst:.2f} s, plain kernel {plain:.2f} s "
           f"(installed / plain {inst / plain:.2f})")


if __name__ == "__main__":
    main()
