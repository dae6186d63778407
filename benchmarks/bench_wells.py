"""Speed of the compiled engine per well, in ONE process (see docs/numerics.md).

    python benchmarks/bench_wells.py                 # SRKN6b and RK4, 1 thread, best of 7
    python benchmarks/bench_wells.py --threads 2 --integrators srkn6b

Before / after: the engine's kernels module as it was before the well flag (git revision
--before, default f85d441, the last commit with the quartic hard-wired) is checked out into a
temporary directory (`git show REV:src/safebasins/numerics/kernels.py`, self-contained: numpy
and numba only) and imported beside today's safebasins.numerics.kernels; both run the same
jobs on the same arrays in this process, interleaved (job A, job B, job A, ... and the best
time of each), and their escape steps are compared (must be equal: the quartic path is
bitwise unchanged).

Jobs (kernel only: kernels.ensemble with the arrays engine.run_cpu would pass):
  dense  ICs inside the well, F = 0: nothing escapes, every lane steps for --dense-cycles
         cycles (the per-step rate);
  chart  the 100x100 chart of bench_escape.py (quartic: F = 0.0876, Omega = 0.95, Psi = pi,
         xi_max = 0.25, 300 cycles; cubic: F = 0.06, Omega = 0.85, xi_max = 1/6), steps
         counted to the escape step or the horizon.
Wells, each in its one compiled form (Well.compiled, wells.compiled): the quartic's closed
form (before and after; its signed variant: the same arithmetic with signed maxima, for
asymmetric displacement bounds), the polynomial codes (the cubic V = q^2/2 - q^3/3 and the
quartic written as coefficients [0, 0, 0.5, 0, -0.25] in the degree-4 class; the cubic in the
degree-8 class, i.e. a degree 5-8 well) and the generic V, dV code of an expression well (the
cubic as an expression; the pendulum 1 - cos q, sech^2 tanh(q)^2, Morse (1 - exp(-q))^2, whose
forces call wells.elementary in the vectorised lanes, and the electrostatic q^2/2 - a/(1 - q) + a
+ a q, a = 0.05).  Ratios to the quartic: from the best times, and the median of the ratios paired
within each interleaved round (robust to a loaded machine).

Generated code before / after (``--wells-only --sources-before REV``): only the dense jobs of the
quartic and the non-polynomial wells, each expression well also compiled from the V, dV source
that wells/expression.py of git revision REV generates for it (imported from a temporary file
beside today's package), both in this process, interleaved; ratios to the quartic paired per
round.  Elementary functions before / after (``--wells-only --elementary-before REV``): each
expression well also compiled with today's source around wells/elementary.py of revision REV
(bench_elementary.before_cpu), likewise.  Interleave count before / after (``--wells-only
--interleave-before N``): every well's kernels (the quartic's too) also compiled with LLVM's loop
interleave count N (0: the cost model's choice) instead of core.numba_target.INTERLEAVE, under a
key of their own, in this process; escape steps compared (must be equal).  The cost floor
(``--wells-only --floor``): each expression well also compiled around floor_elementary.py (the
cheapest polynomial sin, cos, exp, expm1 and tanh, not faithful) instead of wells.elementary,
likewise: a ratio no faithful version could go below.

Measured (docs/numerics.md, "Wells"), AMD EPYC (AVX-512), 1 thread, SRKN6b, with one compiled form per well:
quartic after / before 1.020 dense, 0.957 chart (escape steps equal); time per step vs the quartic:
signed 1.12, cubic (degree 4) 1.29, quartic coefficients 1.29, degree-8 class 3.07, cubic as an
expression 1.19, pendulum (sin, cos: scalar lanes) 68.  With wells.elementary: docs/elementary.md.
"""
from __future__ import annotations

import argparse
import importlib
import importlib.util
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

from safebasins import wells
from safebasins.core import numba_target
from safebasins.numerics import engine, kernels, schemes
from safebasins.numerics.scheme_code import scheme_code
from safebasins.wells import compiled, elementary

ROOT = Path(__file__).resolve().parents[1]
QUARTIC_COEFS = [0.0, 0.0, 0.5, 0.0, -0.25]
CUBIC_COEFS = [0.0, 0.0, 0.5, -1.0 / 3.0]
CHART_QUARTIC = dict(F=0.0876, Omega=0.95, Psi=np.pi, xi_max=0.25, box=((-1, 1), (-1, 1)))
CHART_CUBIC = dict(F=0.06, Omega=0.85, Psi=np.pi, xi_max=1.0 / 6.0, box=((-0.8, 1.0), (-0.7, 0.7)))


def machine():
    info = {}
    try:
        for line in open("/proc/cpuinfo"):
            k, _, v = line.partition(":")
            k = k.strip()
            if k in ("model name", "flags") and k not in info:
                info[k] = v.strip()
    except OSError:   # pragma: no cover
        pass
    flags = set(info.get("flags", "").split())
    simd = ", ".join(f for f in ("avx2", "fma", "avx512f", "avx512dq", "avx512vl") if f in flags) or "?"
    la = os.getloadavg()
    return (f"{info.get('model name', '?')}, {os.cpu_count()} CPUs, SIMD: {simd}; "
            f"load average {la[0]:.2f} {la[1]:.2f} {la[2]:.2f}")


def load_before(rev, path=None):
    """The kernels module of git revision `rev` (or the file `path`, e.g. where there is no git
    history), imported from a temporary directory (its numba cache lives there too, so a second
    run does not recompile)."""
    if path:
        src, rev = Path(path).read_text(), Path(path).stem
    else:
        src = subprocess.run(["git", "show", f"{rev}:src/safebasins/numerics/kernels.py"], cwd=ROOT, check=True,
                             capture_output=True, text=True).stdout
    if any(line.startswith(("from safebasins", "import safebasins")) for line in src.splitlines()):
        raise SystemExit(f"kernels.py of {rev} imports safebasins: not the self-contained module this "
                         "benchmark expects (pick the revision before the well flag)")
    d = Path(tempfile.gettempdir()) / "safebasins_kernels_before"
    d.mkdir(exist_ok=True)
    name = "kernels_" + "".join(ch if ch.isalnum() else "_" for ch in rev)
    path = d / f"{name}.py"
    if not path.exists() or path.read_text() != src:
        path.write_text(src)
    sys.path.insert(0, str(d))     # an importable module: numba's cache reloads it by name
    try:
        return importlib.import_module(name)
    finally:
        sys.path.remove(str(d))


def disc_ics(n, H0, limit, seed=0):
    """n ICs with H0 < limit (rejection from the box around the well bottom)."""
    rng = np.random.default_rng(seed)
    out = np.empty((0, 2))
    while out.shape[0] < n:
        z = rng.uniform(-1, 1, (4 * n, 2))
        out = np.concatenate([out, z[H0(z[:, 0], z[:, 1]) < limit]])
    return np.ascontiguousarray(out[:n, 0]), np.ascontiguousarray(out[:n, 1])


def grid_ics(box, n=100):
    q = np.linspace(*box[0], n)
    p = np.linspace(*box[1], n)
    Q, P = np.meshgrid(q, p, indexing="ij")
    return Q.ravel(), P.ravel()


def H_quartic(q, p):
    return 0.5 * p * p + 0.5 * q * q - 0.25 * q ** 4


def H_cubic(q, p):
    return 0.5 * p * p + 0.5 * q * q - q ** 3 / 3.0


class Job:
    """One kernels.ensemble call with fixed arrays; run() returns the escape steps."""

    def __init__(self, name, mod, Q, P, F, Omega, Psi, xi_max, cycles, S, integrator, threads, code=None):
        self.name, self.mod, self.cycles, self.S = name, mod, cycles, S
        self.Q, self.P = Q, P
        N = Q.size
        self.args = (Q, P, np.zeros(N, np.int64), schemes.lane_coefficients([Omega], S, integrator),
                     schemes.step_sizes([Omega], S), np.array([F]), schemes.sine_table(S, Psi, integrator),
                     np.array([2.0 * xi_max]), np.zeros(0), cycles, False,
                     max(1, min(-(-N // engine.LANES), threads)), engine.LANES)
        self.kw = {} if code is None else dict(well=code, thrQlo=np.zeros(0))
        if mod is kernels:          # today's engine takes the scheme's compiled form
            self.kw["scheme"] = scheme_code(integrator)
        self.out = None

    def run(self):
        N = self.Q.size
        outE = np.full((N, 1), -1, np.int64)
        outQ = np.full((N, 0), -1, np.int64)
        self.mod.ensemble(*self.args, outE, outQ, np.empty((0, 0, 2)), False, **self.kw)
        self.out = outE
        return outE

    def steps(self):
        e = self.out[:, 0]
        return float(np.where(e < 0, self.cycles * self.S, e).sum())


def bench(jobs, repeat, rounds=None):
    """(best wall time, its CPU time) per job over ``repeat`` interleaved rounds; ``rounds``, when
    given, collects every round's wall time per job (paired ratios: median over rounds)."""
    for j in jobs:                      # compile / cache load outside the timings
        j.run()
    best = {j.name: np.inf for j in jobs}
    cpu = {}
    for _ in range(repeat):
        for j in jobs:                  # interleaved: load changes hit every job alike
            t, c = time.perf_counter(), time.process_time()
            j.run()
            w = time.perf_counter() - t
            if rounds is not None:
                rounds.setdefault(j.name, []).append(w)
            if w < best[j.name]:
                best[j.name], cpu[j.name] = w, time.process_time() - c
    return best, cpu


#: the non-polynomial wells of the per-step comparison (name -> well spec): their forces call
#: wells.elementary (vectorised lanes); the electrostatic (MEMS) well is arithmetic with a pole
TRANSCENDENTAL = {"pendulum": "pendulum", "sech2": "sech2", "morse": "morse",
                  "electrostatic": {"expression": "q**2/2 - 0.05/(1 - q) + 0.05 + 0.05*q"}}


def well_ics(well, n, seed):
    """n ICs with H0 below half the barrier energy, between the well's barriers."""
    lo, hi = well.barriers
    Eb = well.barrier_energy

    def H(q, p):
        with np.errstate(all="ignore"):
            return np.where((q > lo) & (q < hi), 0.5 * p * p + well.V(q), np.inf)
    return disc_ics(n, H, 0.5 * Eb, seed=seed)


def load_expression_before(rev):
    """wells/expression.py of git revision ``rev`` as a module (its generate_source prints the
    V, dV source that revision compiled)."""
    src = subprocess.run(["git", "show", f"{rev}:src/safebasins/wells/expression.py"], cwd=ROOT, check=True,
                         capture_output=True, text=True).stdout
    d = Path(tempfile.mkdtemp(prefix="safebasins_expression_before"))
    path = d / "expression_before.py"
    path.write_text(src)
    spec = importlib.util.spec_from_file_location("expression_before", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def code_before(well, before):
    """The compiled form of expression well ``well`` from the source ``before`` generates."""
    X = sys.modules["safebasins.wells.expression"]
    V, q = X.parse(well.expression)
    source = before.generate_source(V, q)[0]

    def functions(jit):
        return X._functions(source, X._compiled_namespace(elementary.for_target(jit)))
    return compiled.target_code(functions, well.barriers, f"{well.name} (before)",
                                f"{elementary.MODULE_HASH}\0{source}"), source


def code_around(well, functions_cpu, label, text):
    """The compiled form of expression well ``well`` (today's source and joint form) around the
    CPU namespace ``functions_cpu`` of elementary functions instead of wells.elementary's (``text``:
    their source, in the key)."""
    X = sys.modules["safebasins.wells.expression"]
    source, joint = well.source, X.joint_source(well.source)

    def functions(jit):
        assert jit is compiled.cpu_jit, f"{label}: compiled for the CPU only"
        return X._joint_functions(source, joint, X._compiled_namespace(functions_cpu))
    return compiled.target_code(functions, well.barriers, f"{well.name} ({label})",
                                f"{label} {text}\0{elementary.MODULE_HASH}\0{source}\0{joint}")


def code_elementary_before(well, rev):
    """:func:`code_around` wells/elementary.py of git revision ``rev`` (bench_elementary.before_cpu)."""
    import bench_elementary  # noqa: PLC0415  (beside this script; imports the test references)

    old, text = bench_elementary.before_cpu(rev)
    return code_around(well, old, f"elementary {rev}", text)


def code_floor(well):
    """:func:`code_around` the cost floor of floor_elementary.py (the cheapest polynomial forms,
    not faithful)."""
    import floor_elementary  # noqa: PLC0415  (beside this script)

    text = Path(floor_elementary.__file__).read_text()
    return code_around(well, floor_elementary.floor_namespace(), "floor", text)


class InterleaveJob(Job):
    """A Job whose kernels are compiled (on the first run) with the loop interleave count
    ``interleave`` instead of core.numba_target.INTERLEAVE, under keys of their own."""

    def __init__(self, *a, interleave, code, **kw):
        code = compiled.WellCode(code.name, code.make, code.wpar, code.abs_tracking,
                                 f"{code.source}\0interleave {interleave}")
        super().__init__(*a, code=code, **kw)
        self.interleave = interleave

    def run(self):
        if self.out is not None:
            return super().run()
        with numba_target.kernel_compile(self.interleave):     # the outer block sets the count
            return super().run()


def wells_only(args):
    """Dense jobs of the quartic and the non-polynomial wells, today's generated code and (with
    --sources-before) the code of that revision's wells/expression.py, interleaved."""
    S = args.steps_per_cycle
    qd, pd = disc_ics(args.dense_n, H_quartic, 0.2)
    before = load_expression_before(args.sources_before) if args.sources_before else None
    for integ in args.integrators:
        dense = dict(F=0.0, Omega=1.0, Psi=0.0, xi_max=0.25, cycles=args.dense_cycles, S=S, integrator=integ,
                     threads=args.threads)
        jobs = [Job("quartic dense, after", kernels, qd, pd, **dense, code=wells.QUARTIC.compiled)]
        if args.interleave_before is not None:
            jobs.append(InterleaveJob("quartic dense, before", kernels, qd, pd, **dense,
                                      code=wells.QUARTIC.compiled, interleave=args.interleave_before))
        for i, (k, spec) in enumerate(TRANSCENDENTAL.items()):
            if k not in args.wells:
                continue
            w = wells.resolve_well(spec)
            ics = well_ics(w, args.dense_n, seed=2 + i)
            kw = dict(dense, xi_max=w.barrier_energy)
            jobs.append(Job(f"{k} dense, after", kernels, *ics, **kw, code=w.compiled))
            if before is not None:
                code, source = code_before(w, before)
                print(f"{k}: today's source\n{w.source}\n{k}: source of {args.sources_before}\n{source}")
                jobs.append(Job(f"{k} dense, before", kernels, *ics, **kw, code=code))
            elif args.elementary_before:
                code = code_elementary_before(w, args.elementary_before)
                jobs.append(Job(f"{k} dense, before", kernels, *ics, **kw, code=code))
            elif args.floor:
                jobs.append(Job(f"{k} dense, floor", kernels, *ics, **kw, code=code_floor(w)))
            elif args.interleave_before is not None:
                jobs.append(InterleaveJob(f"{k} dense, before", kernels, *ics, **kw, code=w.compiled,
                                          interleave=args.interleave_before))
        t = time.perf_counter()
        rounds = {}
        best, _ = bench(jobs, args.repeat, rounds)
        print(f"\n=== {integ} (compile or cache load + runs: {time.perf_counter() - t:.0f} s) ===")
        ref = jobs[0]
        ns = np.array(rounds[ref.name]) / ref.steps() * 1e9
        print(f"{ref.name}: {best[ref.name] / ref.steps() * 1e9:.2f} ns per trajectory step (best), "
              f"{np.median(ns):.2f} (median of {ns.size} rounds)")
        for j in jobs[1:]:
            paired = np.array(rounds[j.name]) / j.steps() / (np.array(rounds[ref.name]) / ref.steps())
            ratio = best[j.name] / j.steps() / (best[ref.name] / ref.steps())
            print(f"{j.name}: time per step / quartic's = {ratio:.2f} (best times), "
                  f"{np.median(paired):.2f} (median of {paired.size} paired rounds, "
                  f"{paired.min():.2f}-{paired.max():.2f})")
        by = {j.name: j for j in jobs}
        for k in ["quartic", *args.wells]:
            if f"{k} dense, before" in by:
                a, b = np.array(rounds[f"{k} dense, after"]), np.array(rounds[f"{k} dense, before"])
                same = np.array_equal(by[f"{k} dense, after"].out, by[f"{k} dense, before"].out)
                print(f"{k}: after / before = {np.median(a / b):.2f} (median of paired rounds), "
                      f"{a.min() / b.min():.2f} (best times); escape steps equal: {same}")
    print("\nmachine after:", machine())


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--before", default="f85d441", help="git revision of the kernels before the well flag")
    ap.add_argument("--before-file", default=None, help="the old kernels.py as a file (instead of --before)")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--integrators", nargs="+", default=["srkn6b", "rk4"])
    ap.add_argument("--dense-n", type=int, default=4096)
    ap.add_argument("--dense-cycles", type=int, default=600)
    ap.add_argument("--chart-cycles", type=int, default=300)
    ap.add_argument("--steps-per-cycle", type=int, default=32)
    ap.add_argument("--wells-only", action="store_true",
                    help="only the dense jobs of the quartic and the non-polynomial wells")
    ap.add_argument("--sources-before", default=None,
                    help="with --wells-only: also each expression well's code as this git revision generated it")
    ap.add_argument("--elementary-before", default=None,
                    help="with --wells-only: also each expression well around this git revision's "
                         "wells/elementary.py (CPU)")
    ap.add_argument("--interleave-before", type=int, default=None,
                    help="with --wells-only: also every well compiled with this loop interleave count "
                         "(0: LLVM's cost model)")
    ap.add_argument("--floor", action="store_true",
                    help="with --wells-only: each well also with the cost floor of floor_elementary.py")
    ap.add_argument("--wells", nargs="+", default=list(TRANSCENDENTAL), choices=list(TRANSCENDENTAL),
                    help="with --wells-only: which wells")
    args = ap.parse_args(argv)
    if args.wells_only:
        numba.set_num_threads(args.threads)
        print("machine:", machine())
        return wells_only(args)

    numba.set_num_threads(args.threads)
    print("machine:", machine())
    print(f"numba {numba.__version__}, threads {args.threads}, steps_per_cycle {args.steps_per_cycle}, "
          f"best of {args.repeat} interleaved runs, kernel only (kernels.ensemble)")
    t = time.perf_counter()
    before = load_before(args.before, args.before_file)
    print(f"before: kernels.py of {args.before_file or args.before} (loaded in {time.perf_counter() - t:.1f} s)")
    S = args.steps_per_cycle
    qd, pd = disc_ics(args.dense_n, H_quartic, 0.2)
    cd_q, cd_p = disc_ics(args.dense_n, H_cubic, 0.14, seed=1)
    qc, pc = grid_ics(CHART_QUARTIC["box"])
    cq, cp = grid_ics(CHART_CUBIC["box"])
    cq_ = {k: CHART_QUARTIC[k] for k in ("F", "Omega", "Psi", "xi_max")}
    cc_ = {k: CHART_CUBIC[k] for k in ("F", "Omega", "Psi", "xi_max")}
    quartic = wells.QUARTIC.compiled
    quartic_poly = wells.polynomial(QUARTIC_COEFS).compiled
    cubic = wells.cubic().compiled
    cubic8 = compiled.polynomial_code(CUBIC_COEFS, (-np.inf, 1.0), "cubic", degree_class=8)
    cubic_expr = wells.expression("q**2/2 - q**3/3").compiled
    others = {k: wells.resolve_well(v) for k, v in TRANSCENDENTAL.items()}
    other_ics = {k: well_ics(w, args.dense_n, seed=2 + i) for i, (k, w) in enumerate(others.items())}
    for integ in args.integrators:
        dense = dict(F=0.0, Omega=1.0, Psi=0.0, xi_max=0.25, cycles=args.dense_cycles, S=S, integrator=integ,
                     threads=args.threads)
        dense_c = dict(dense, xi_max=1.0 / 6.0)
        chart = dict(cycles=args.chart_cycles, S=S, integrator=integ, threads=args.threads)
        jobs = [
            Job("quartic dense, before", before, qd, pd, **dense),
            Job("quartic dense, after", kernels, qd, pd, **dense, code=quartic),
            Job("quartic dense, signed", kernels, qd, pd, **dense, code=quartic.signed()),
            Job("quartic dense, coefficients", kernels, qd, pd, **dense, code=quartic_poly),
            Job("cubic dense, degree-4 class", kernels, cd_q, cd_p, **dense_c, code=cubic),
            Job("cubic dense, degree-8 class", kernels, cd_q, cd_p, **dense_c, code=cubic8),
            Job("cubic dense, expression", kernels, cd_q, cd_p, **dense_c, code=cubic_expr),
            *(Job(f"{k} dense, expression", kernels, *other_ics[k], **dict(dense, xi_max=w.barrier_energy),
                  code=w.compiled) for k, w in others.items()),
            Job("quartic chart, before", before, qc, pc, **cq_, **chart),
            Job("quartic chart, after", kernels, qc, pc, **cq_, **chart, code=quartic),
            Job("cubic chart, degree-4 class", kernels, cq, cp, **cc_, **chart, code=cubic),
        ]
        t = time.perf_counter()
        rounds = {}
        best, cpu = bench(jobs, args.repeat, rounds)
        print(f"\n=== {integ} (compile or cache load + runs: {time.perf_counter() - t:.0f} s) ===")
        by = {j.name: j for j in jobs}
        for a, b in (("quartic dense, before", "quartic dense, after"),
                     ("quartic chart, before", "quartic chart, after")):
            same = np.array_equal(by[a].out, by[b].out)
            print(f"escape steps {a.split(',')[0]}: before == after: {same}")
            if not same:
                raise SystemExit("the quartic path changed its results")
        ref = by["quartic dense, after"]
        ref_rate = ref.steps() / best[ref.name]
        print(f"{'job':36s} {'traj-steps':>11s} {'wall [s]':>9s} {'steps/s':>10s} {'CPU s':>7s} "
              f"{'vs quartic dense':>16s}")
        for j in jobs:
            n = j.steps()
            r = n / best[j.name]
            print(f"{j.name:36s} {n:11.4g} {best[j.name]:9.4f} {r:10.4g} {cpu[j.name]:7.3f} {r / ref_rate:16.3f}")
        for kind in ("dense", "chart"):
            b, a = by[f"quartic {kind}, before"], by[f"quartic {kind}, after"]
            print(f"quartic {kind}: after / before = {best[b.name] / best[a.name]:.3f} (steps/s ratio; 1 = same speed)")
        for name in ("cubic dense, degree-4 class", "quartic dense, coefficients", "cubic dense, degree-8 class",
                     "quartic dense, signed", "cubic dense, expression", *(f"{k} dense, expression" for k in others)):
            j = by[name]
            paired = np.array(rounds[name]) / j.steps() / (np.array(rounds[ref.name]) / ref.steps())
            print(f"{name}: time per step / quartic's = {ref_rate / (j.steps() / best[name]):.3f} (best times), "
                  f"{np.median(paired):.3f} (median of {paired.size} paired rounds, "
                  f"{paired.min():.3f}-{paired.max():.3f})")
    print("\nmachine after:", machine())


if __name__ == "__main__":
    sys.exit(main())
