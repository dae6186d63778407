"""Where the first compile of an engine kernel goes, from numba's compile events.

    .venv/bin/python benchmarks/profile_compile.py quartic      # first chart, empty numba cache
    .venv/bin/python benchmarks/profile_compile.py expression   # a new expression well's first
                                                                # chart, the rest of the cache warm
    .venv/bin/python benchmarks/profile_compile.py noise        # first escape_probability, empty cache

Each case runs in a fresh subprocess; the first thing it compiles is the plain ``@njit`` leapfrog
of bench_cold_start.py (the unit the compile times are quoted in: the machine's speed and load
cancel in the ratio).  Then it records every ``numba:run_pass`` and ``numba:llvm_lock`` event of the
chart's first call and prints the exclusive time per compiler pass (LLVM's time, inside the lock,
apart), per compiled function, the number of functions typed, type inference runs and
``numba:compile`` events (one per dispatcher and signature).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))

CASE = r"""
import collections, json, sys, time
import numpy as np
from numba import njit
from numba.core import event as ev


class Profile(ev.Listener):
    # exclusive time per pass / per function; LLVM (the lock) apart, nested compiles subtracted
    def __init__(self):
        self.stack = []          # [kind, label, start, child time]
        self.passes = collections.Counter()
        self.funcs = collections.Counter()
        self.runs = collections.Counter()
        self.llvm = 0.0
        self.compiles = collections.Counter()
        self.pairs = collections.Counter()
        self.llvm_funcs = collections.Counter()

    def on_start(self, event):
        label = None
        if event.kind == "numba:run_pass":
            label = (event.data["name"].split(" [")[0], event.data["qualname"])
        elif event.kind == "numba:compile":
            d = event.data["dispatcher"]
            self.compiles[getattr(d, "__qualname__", None) or d.py_func.__qualname__] += 1
            return
        self.stack.append([event.kind, label, time.process_time(), 0.0])

    def on_end(self, event):
        if event.kind == "numba:compile":
            return
        kind, label, start, child = self.stack.pop()
        dt = time.process_time() - start
        if self.stack:
            self.stack[-1][3] += dt
        own = dt - child
        if kind == "numba:llvm_lock":
            self.llvm += own
            outer = next((e[1][1] for e in reversed(self.stack) if e[1] is not None), "(none)")
            self.llvm_funcs[outer] += own
            return
        name, qual = label
        self.passes[name] += own
        self.funcs[qual] += own
        self.pairs[f"{qual} | {name}"] += own
        if name == "nopython_type_inference":
            self.runs[qual] += 1


@njit
def leapfrog(q, p, h, n):
    for i in range(q.size):
        a, b = q[i], p[i]
        for _ in range(n):
            b += 0.5 * h * (a * a * a - a)
            a += h * b
            b += 0.5 * h * (a * a * a - a)
        q[i], p[i] = a, b
    return q


t0 = time.process_time()
leapfrog(np.zeros(4), np.ones(4) * 0.1, 0.01, 10)
plain = time.process_time() - t0

import safebasins.numerics as nu
from safebasins import wells
case = sys.argv[1]
if case in ("quartic", "noise"):
    q = np.linspace(-0.5, 0.5, 4)
    kw = dict(xi_max=(0.18,))
else:
    a = float(sys.argv[2])
    w = wells.expression(f"q**2/2 - {a!r}/(1 - q) + {a!r} + {a!r}*q")
    w.compiled
    q = np.linspace(-0.2, 0.2, 4)
    kw = dict(xi_max=(0.05,), well=w)
prof = Profile()
t0 = time.process_time()
with ev.install_listener("numba:run_pass", prof), ev.install_listener("numba:llvm_lock", prof), \
        ev.install_listener("numba:compile", prof):
    if case == "noise":
        nu.escape_probability(q, q, 0.01, 0.9, np.pi, noise=0.01, paths=2, xi_max=0.18, t_eval=[20.0])
    else:
        nu.escape_chart(q, q, F=0.01, Omega=0.9, Psi=np.pi, cycles=5, **kw)
first = time.process_time() - t0
print(json.dumps({"plain": plain, "first": first, "llvm": prof.llvm, "passes": dict(prof.passes),
                  "funcs": dict(prof.funcs), "runs": dict(prof.runs), "compiles": dict(prof.compiles),
                  "pairs": dict(prof.pairs), "llvm_funcs": dict(prof.llvm_funcs)}))
"""


def run(case, cache_dir, *argv):
    env = dict(os.environ)
    env["NUMBA_CACHE_DIR"] = cache_dir
    src = os.path.join(os.path.dirname(HERE), "src")
    env["PYTHONPATH"] = src + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    with tempfile.TemporaryDirectory() as d:
        script = os.path.join(d, "case.py")
        with open(script, "w") as fh:
            fh.write(CASE)
        out = subprocess.run([sys.executable, script, case, *argv], env=env, capture_output=True, text=True)
    if out.returncode:
        raise SystemExit(f"case failed:\n{out.stderr}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def show(r, top):
    plain, first = r["plain"], r["first"]
    front = sum(r["passes"].values())
    print(f"plain @njit {plain:.2f} s; first chart {first:.2f} s = {first / plain:.1f}x plain; "
          f"LLVM {r['llvm']:.2f} s ({r['llvm'] / first:.0%}), numba passes {front:.2f} s ({front / first:.0%})")
    print(f"functions typed: {len(r['runs'])}, type inference runs: {sum(r['runs'].values())}, "
          f"numba:compile events: {sum(r['compiles'].values())} over {len(r['compiles'])} dispatchers")
    print("\nexclusive time per pass [s]:")
    for k, v in sorted(r["passes"].items(), key=lambda kv: -kv[1])[:top]:
        print(f"  {v:7.2f}  {k}")
    print("\nexclusive time per function (numba passes, without LLVM) [s] (type inference runs):")
    for k, v in sorted(r["funcs"].items(), key=lambda kv: -kv[1])[:top]:
        print(f"  {v:7.2f}  {k} ({r['runs'].get(k, 0)})")
    print("\nLLVM time per function compiled [s]:")
    for k, v in sorted(r["llvm_funcs"].items(), key=lambda kv: -kv[1])[:top]:
        print(f"  {v:7.2f}  {k}")
    print("\nnumba:compile events per dispatcher:")
    for k, v in sorted(r["compiles"].items(), key=lambda kv: -kv[1]):
        print(f"  {v:3d}  {k}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case", choices=("quartic", "expression", "noise"))
    ap.add_argument("--top", type=int, default=15, help="rows of the per-pass and per-function tables")
    ap.add_argument("--json", help="also write the raw numbers to this file")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as d:
        if args.case == "expression":
            run("expression", d, "0.05")      # the well-independent parts cached
            r = run("expression", d, "0.0731")
        else:
            r = run(args.case, d)
    show(r, args.top)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(r, fh, indent=1)


if __name__ == "__main__":
    main()
