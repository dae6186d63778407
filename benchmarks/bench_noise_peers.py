"""The noisy ensemble against the Python SDE solvers a researcher would use, at equal weak
accuracy, in one process (docs/noise.md, Speed).

The peers are not dependencies of safebasins: run it from a separate environment,

    python3 -m venv /tmp/peers
    /tmp/peers/bin/pip install diffrax jax sdeint numba numpy scipy xarray netCDF4 matplotlib pyyaml \\
        jsonschema nbformat rocrate click tqdm sympy
    PYTHONPATH=src /tmp/peers/bin/python benchmarks/bench_noise_peers.py           # ~1.5 min on 2 cores

It stops with an error naming the package when numba, jax, diffrax or sdeint is missing (a table
with a peer silently absent would read as a win). torchsde is not run: on PyPI it needs torch,
whose Linux wheel pulls the CUDA stack (nvidia-* wheels, several GB) even for CPU work; the
CPU-only wheel lives on download.pytorch.org, outside PyPI.

The problem: the paper's quartic V = q^2/2 - q^4/4 at Fig 14's forcing (F 0.01, Omega 0.9,
Psi pi, read from config/config.yaml), undamped, white noise sigma 0.03 on the momentum, from the
bottom of the well (q, p) = (0, 0); escape when H0 > xi_max = 0.25 or |q| > 1, checked after
every step (the criteria of escape_chart); the quantity is P_escape within 50 forcing cycles
(~0.55).

safebasins runs under each law of its variates (numerics.noise.VARIATES: "gaussian", Box-Muller
normals, the default; "five-point", 0, +-sqrt 2, +-2 from four random bits, the Gaussian's moments
through the fifth): one set of rows per law, the same step search, accuracy criterion and boundary
shift rule (each law's shift is the library's, BOUNDARY_SHIFTS); the table names each row's law
(the peers draw normals) and gives every time against each law's row.

Monitoring: a step-wise check of the threshold misses crossings between steps, an O(sqrt(h))
bias of every scheme. safebasins corrects it (the boundary shift, docs/noise.md); the peers, as
a researcher gets them, do not (a diffrax Event, sdeint's trajectory, a hand-written loop). The
table compares each method as shipped; extra rows put both sides under the same rule
(safebasins uncorrected, per law; the numba Euler-Maruyama with the Gaussian shift), and a BENCH
line per law gives the smaller of the two same-rule ratios against the numba Euler-Maruyama,
symplectic (the fastest peer in the runs of docs/noise.md).

Accuracy criterion: |P_escape - P_ref| <= TOL = 0.02 with N = 8000 paths per method and step
(standard error of the difference ~0.006: TOL is ~3.3 of them). P_ref: safebasins, 128 steps
per cycle, 100,000 paths, boundary shift (its statistical error printed; checked against 64
steps). For each method the steps per cycle double from its first value until the criterion
holds; the coarsest such step is the method's step, and the wall time of those N paths is its
time (best of the search run and one re-run, interleaved; safebasins' short runs best of four).
safebasins starts at 8, the coarsest power of two its step limit accepts for the quartic. A
method that has not reached TOL at the cap (512 steps per cycle) is reported with its time at
the cap: its ratio is then a lower bound (">=").

Methods (one thread each, the same process; jax is held to one thread with XLA_FLAGS):

* safebasins: numerics.escape_probability (SRKN6b Strang splitting, Philox), each law of the
  variates, threads = 1; also threads = all cores at the same step (the ratio columns marked with
  the core count: peer on one thread / ours on all);
* numba: hand-written @njit Euler-Maruyama (serial: one thread), numba's np.random normals, one
  loop per path: symplectic (p then q, the stronger variant for a Hamiltonian drift) and plain (q
  and p from the old state, the textbook scheme, which is what sdeint's itoEuler and diffrax's
  Euler integrate);
* diffrax: Euler and ShARK (additive-noise Runge-Kutta, space-time Levy area), jax.jit of
  jax.vmap over the paths, UnsafeBrownianPath, an Event ends each path at escape; compile time
  excluded, printed. Both are slow on the CPU (~0.7-1.4e6 path-steps/s under vmap), so they run
  fewer paths and their time is scaled to N: Euler 500 paths at the plain Euler-Maruyama's step
  (the same map); ShARK 1500 paths a step (standard error ~0.013), searched from the uncorrected
  Gaussian splitting's step (below it the monitoring bias alone exceeds TOL for any scheme);
* sdeint: itoEuler, pure Python: 4 paths are timed and the time scaled to N (its step is the
  plain Euler-Maruyama's: the same map, checked on one path to 1e-12 with the same increments).
  itoSRI2 is not run (its accuracy would need a search over thousands of pure-Python paths).

The whole run takes ~1.5 min on 2 cores under load (the reference ~10 s, diffrax ~30 s).
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import time

os.environ.setdefault("XLA_FLAGS", "--xla_cpu_multi_thread_eigen=false intra_op_parallelism_threads=1")

_MISSING = []
try:
    import numba
    from numba import njit
except ImportError:
    _MISSING.append("numba")
try:
    import jax
    import jax.numpy as jnp
except ImportError:
    _MISSING.append("jax")
try:
    import diffrax
except ImportError:
    _MISSING.append("diffrax")
try:
    import sdeint
except ImportError:
    _MISSING.append("sdeint")
if _MISSING:
    sys.exit(f"bench_noise_peers.py: missing {', '.join(_MISSING)}: pip install {' '.join(_MISSING)} into a separate "
             f"venv (module docstring); the peers are not safebasins dependencies")

import numpy as np  # noqa: E402
import yaml  # noqa: E402

from _report import machine, report  # noqa: E402

from safebasins.numerics import escape_probability  # noqa: E402
from safebasins.numerics.noise import GOBET_SHIFT, VARIATES  # noqa: E402

jax.config.update("jax_enable_x64", True)

with open(os.path.join(os.path.dirname(__file__), "..", "config", "config.yaml")) as _fh:
    _FIG14 = yaml.safe_load(_fh)["figures"]["fig14"]
F, OMEGA = float(_FIG14["F"]), float(_FIG14["Omega"])
PSI = math.pi if str(_FIG14["Psi"]) == "pi" else float(_FIG14["Psi"])
SIGMA, XI, CYCLES, Q0, P0 = 0.03, 0.25, 50, 0.0, 0.0
TOL, N, N_REF, S_REF = 0.02, 8000, 100_000, 128
# the slow peers run fewer paths, their time scaled to N (diffrax: one vmapped call)
B_EULER, B_SHARK, K_SDEINT = 500, 1500, 4


def step(S):
    return 2 * math.pi / (OMEGA * S)


# ---------------------------------------------------------------- safebasins
def ours(S, paths, threads=1, seed=1, correction="shift", variates="gaussian"):
    ds = escape_probability(Q0, P0, F, OMEGA, PSI, noise=SIGMA, paths=paths, xi_max=XI, t_eval=[CYCLES],
                            steps_per_cycle=S, threads=threads, seed=seed, correction=correction, grid=False,
                            variates=variates)
    return float(ds.P_escape.values.ravel()[0])


def ours_row(law, correction):
    """The table's name of safebasins' row under the variates' law ``law`` and ``correction``."""
    return f"safebasins {law}, " + ("shift" if correction == "shift" else "uncorrected")


# ---------------------------------------------------------------- numba Euler-Maruyama
@njit(cache=False)
def _em(n_paths, h, n_steps, sigma, F, Omega, Psi, xi, shift, symplectic, seed):
    """Escaped within n_steps, per path (0/1); shift: the boundary shift's factor (0: none)."""
    out = np.zeros(n_paths, np.int64)
    sh = sigma * math.sqrt(h)
    for j in range(n_paths):  # one thread, as every row (a prange would take all cores)
        np.random.seed(seed + j)  # noqa: NPY002  (one stream a path)
        q, p = 0.0, 0.0
        for n in range(n_steps):
            f = q * q * q - q + F * math.sin(Omega * n * h + Psi)
            z = np.random.standard_normal()  # noqa: NPY002
            if symplectic:
                p += h * f + sh * z
                q += h * p
            else:
                q, p = q + h * p, p + h * f + sh * z
            H = 0.5 * p * p + 0.5 * q * q - 0.25 * q ** 4
            if not (H <= xi - shift * abs(p)) or abs(q) > 1.0:
                out[j] = 1
                break
    return out


def numba_em(S, paths, symplectic, shifted=False, seed=11):
    h = step(S)
    shift = GOBET_SHIFT * SIGMA * math.sqrt(h) if shifted else 0.0
    return float(_em(paths, h, CYCLES * S, SIGMA, F, OMEGA, PSI, XI, shift, symplectic, seed).mean())


# ---------------------------------------------------------------- diffrax
def _drift(t, y, args):
    q, p = y[0], y[1]
    return jnp.stack([p, q * q * q - q + F * jnp.sin(OMEGA * t + PSI)])


def _diffusion(t, y, args):
    return jnp.array([[0.0], [SIGMA]])


def _escaped(t, y, args, **kwargs):
    q, p = y[0], y[1]
    return (0.5 * p * p + 0.5 * q * q - 0.25 * q ** 4 > XI) | (jnp.abs(q) > 1.0) | ~jnp.isfinite(q)


def diffrax_runner(solver_name, S_max):
    """A jitted function (h, keys) -> escaped flags of every path, for steps up to S_max a cycle."""
    solver = {"Euler": diffrax.Euler, "ShARK": diffrax.ShARK}[solver_name]()
    levy = diffrax.SpaceTimeLevyArea if solver_name == "ShARK" else diffrax.BrownianIncrement
    t1 = CYCLES * 2 * math.pi / OMEGA

    def one(h, key):
        bm = diffrax.UnsafeBrownianPath(shape=(1,), key=key, levy_area=levy)
        terms = diffrax.MultiTerm(diffrax.ODETerm(_drift), diffrax.ControlTerm(_diffusion, bm))
        sol = diffrax.diffeqsolve(terms, solver, 0.0, t1, h, jnp.array([Q0, P0]),
                                  saveat=diffrax.SaveAt(t1=True), event=diffrax.Event(_escaped),
                                  max_steps=CYCLES * S_max + 16, throw=False, adjoint=diffrax.ForwardMode())
        return sol.event_mask

    return jax.jit(jax.vmap(one, in_axes=(None, 0)))


def diffrax_em(run, S, paths, seed=21):
    keys = jax.random.split(jax.random.PRNGKey(seed), paths)
    return float(np.asarray(jax.block_until_ready(run(step(S), keys))).mean())


# ---------------------------------------------------------------- sdeint
def sdeint_paths(S, paths, seed=31):
    """Escape flags of sdeint.itoEuler paths (the whole horizon is integrated, then checked)."""
    h = step(S)
    tspan = np.arange(CYCLES * S + 1) * h

    def f(y, t):
        return np.array([y[1], y[0] ** 3 - y[0] + F * math.sin(OMEGA * t + PSI)])

    def G(y, t):
        return np.array([[0.0], [SIGMA]])

    rng = np.random.default_rng(seed)
    out = []
    with np.errstate(all="ignore"):
        for _ in range(paths):
            y = sdeint.itoEuler(f, G, np.array([Q0, P0]), tspan, generator=rng)
            q, p = y[1:, 0], y[1:, 1]
            bad = ~(0.5 * p * p + 0.5 * q * q - 0.25 * q ** 4 <= XI) | (np.abs(q) > 1.0)
            out.append(bool(bad.any()))
    return np.array(out)


def sdeint_is_plain_em():
    """Max difference of sdeint.itoEuler and the plain Euler-Maruyama map on one path, same increments."""
    S = 64
    h, n = step(S), 5 * S
    tspan = np.arange(n + 1) * h
    dW = np.random.default_rng(5).normal(0.0, math.sqrt(h), (n, 1))
    y = sdeint.itoEuler(lambda y, t: np.array([y[1], y[0] ** 3 - y[0] + F * math.sin(OMEGA * t + PSI)]),
                        lambda y, t: np.array([[0.0], [SIGMA]]), np.array([Q0, P0]), tspan, dW=dW)
    q, p, err = Q0, P0, 0.0
    for k in range(n):
        q, p = q + h * p, p + h * (q ** 3 - q + F * math.sin(OMEGA * k * h + PSI)) + SIGMA * dW[k, 0]
        err = max(err, abs(q - y[k + 1, 0]), abs(p - y[k + 1, 1]))
    return err


# ---------------------------------------------------------------- the search
def search(name, fn, S0, S_cap, ref):
    """(S, P, time, reached) at the coarsest doubling of S0 with |P - ref| <= TOL, else at S_cap."""
    S = S0
    while True:
        t = time.perf_counter()
        P = fn(S)
        dt = time.perf_counter() - t
        ok = abs(P - ref) <= TOL
        print(f"  {name:34s} {S:5d} steps/cycle: P = {P:.4f} (bias {P - ref:+.4f}), {dt:7.2f} s"
              f"{'  <- reaches TOL' if ok else ''}", flush=True)
        if ok or S >= S_cap:
            return S, P, dt, ok
        S *= 2


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.parse_args()
    ncores = os.cpu_count() or 1
    print(f"machine: {machine()}; numba {numba.__version__}, jax {jax.__version__}, diffrax {diffrax.__version__}, "
          f"sdeint {getattr(sdeint, '__version__', '?')}")
    print(f"problem: quartic, F {F}, Omega {OMEGA}, Psi {PSI:.6f} (config fig14), undamped, sigma {SIGMA}, "
          f"IC ({Q0}, {P0}), xi_max {XI}, P_escape within {CYCLES} cycles; TOL {TOL}, N {N} paths")
    print("torchsde: not run (PyPI's torch wheel pulls the CUDA stack, several GB; CPU wheel not on PyPI)")

    t = time.perf_counter()
    for law in VARIATES:
        ours(16, 64, variates=law)
        ours(16, 64, threads=ncores, variates=law)
    _em(64, 0.1, 10, SIGMA, F, OMEGA, PSI, XI, 0.0, True, 0)
    _em(64, 0.1, 10, SIGMA, F, OMEGA, PSI, XI, 0.0, False, 0)
    print(f"compile (safebasins, numba EM; excluded): {time.perf_counter() - t:.1f} s", flush=True)
    S_CAP = 512
    runners = {}
    for name, batch in (("diffrax Euler", B_EULER), ("diffrax ShARK", B_SHARK)):
        runners[name] = diffrax_runner(name.split()[1], S_CAP)
        t = time.perf_counter()
        diffrax_em(runners[name], 8, batch)
        print(f"compile ({name}, {batch} paths a call; excluded): {time.perf_counter() - t:.1f} s", flush=True)
    err = sdeint_is_plain_em()
    print(f"sdeint.itoEuler vs the plain Euler-Maruyama map, one path, same increments: max |diff| {err:.1e}")
    assert err < 1e-12, "sdeint.itoEuler is not the plain Euler-Maruyama map"

    t = time.perf_counter()
    ref = ours(S_REF, N_REF, threads=ncores, seed=99)
    se = math.sqrt(ref * (1 - ref) / N_REF)
    ref64 = ours(S_REF // 2, N_REF, threads=ncores, seed=98)
    print(f"reference: P_ref = {ref:.4f} +- {se:.4f} (safebasins, {S_REF} steps/cycle, {N_REF} paths, shift; "
          f"{S_REF // 2} steps/cycle: {ref64:.4f}; {time.perf_counter() - t:.1f} s)", flush=True)

    # safebasins starts at 8: the coarsest power of two its step limit accepts for the quartic
    law_of = {ours_row(law, c): law for law in VARIATES for c in ("shift", "none")}
    methods = {ours_row(law, c): (lambda S, c=c, law=law: ours(S, N, correction=c, variates=law), 8, S_CAP)
               for law in VARIATES for c in ("shift", "none")}
    methods |= {
        "numba EM, symplectic": (lambda S: numba_em(S, N, True), 16, S_CAP),
        "numba EM, symplectic+shift": (lambda S: numba_em(S, N, True, True), 16, S_CAP),
        "numba EM, plain": (lambda S: numba_em(S, N, False), S_CAP // 2, S_CAP),
    }
    found = {}
    print(f"search (each line: {N} paths at that step, one thread):")
    for name, (fn, S0, cap) in methods.items():
        found[name] = search(name, fn, S0, cap, ref)
    # one more timing round, interleaved, at each method's step
    times = {}
    for name, (fn, _, _) in methods.items():
        S = found[name][0]
        t = time.perf_counter()
        fn(S)
        times[name] = min(found[name][2], time.perf_counter() - t)
    for name in law_of:                                               # short runs: best of three more
        for _ in range(3):
            t = time.perf_counter()
            methods[name][0](found[name][0])
            times[name] = min(times[name], time.perf_counter() - t)
    S_ours = {law: found[ours_row(law, "shift")][0] for law in VARIATES}
    t_ours = {law: times[ours_row(law, "shift")] for law in VARIATES}
    t_ours_all = dict.fromkeys(VARIATES, math.inf)
    for _ in range(3):
        for law in VARIATES:
            t = time.perf_counter()
            ours(S_ours[law], N, threads=ncores, variates=law)
            t_ours_all[law] = min(t_ours_all[law], time.perf_counter() - t)
    # the slow peers: fewer paths, time scaled to N
    S_plain, _, _, plain_ok = found["numba EM, plain"]
    print(f"diffrax Euler and sdeint.itoEuler are the plain Euler-Maruyama map: its step ({S_plain}), "
          f"{B_EULER} and {K_SDEINT} paths timed, scaled to {N}:")
    t = time.perf_counter()
    P = diffrax_em(runners["diffrax Euler"], S_plain, B_EULER)
    dt = time.perf_counter() - t
    print(f"  {'diffrax Euler':34s} {S_plain:5d} steps/cycle: P = {P:.4f} ({B_EULER} paths), {dt:7.2f} s", flush=True)
    found["diffrax Euler"] = (S_plain, P, dt * N / B_EULER, plain_ok)
    t = time.perf_counter()
    sdeint_paths(S_plain, K_SDEINT)
    found["sdeint itoEuler"] = (S_plain, float("nan"), (time.perf_counter() - t) * N / K_SDEINT, plain_ok)
    # ShARK checks at the steps only (an O(sqrt(h)) bias for every scheme): from the uncorrected splitting's step
    S_none = found[ours_row("gaussian", "none")][0]
    print(f"diffrax ShARK: {B_SHARK} paths a step (standard error ~{0.5 / math.sqrt(B_SHARK):.3f}), from the "
          f"uncorrected splitting's step {S_none} (the monitoring bias is the same for every scheme), scaled to {N}:")
    S, P, dt, ok = search("diffrax ShARK", lambda S: diffrax_em(runners["diffrax ShARK"], S, B_SHARK), S_none,
                          S_CAP, ref)
    found["diffrax ShARK"] = (S, P, dt * N / B_SHARK, ok)
    for name in ("diffrax Euler", "sdeint itoEuler", "diffrax ShARK"):
        times[name] = found[name][2]

    print(f"\n{'method':34s} {'variates':10s} {'steps/cycle':>11s} {'P':>7s} {'bias':>8s} {'time N paths':>13s}"
          + "".join(f" {f'/{law} {n}t':>15s}" for law in VARIATES for n in (1, ncores)))
    for name, (S, P, _, ok) in found.items():
        geq = "" if ok else ">="
        Ps, bias = (f"{P:7.4f}", f"{P - ref:+.4f}") if P == P else ("-", "-")
        print(f"{name:34s} {law_of.get(name, 'normal'):10s} {S:>9d}{'' if ok else '*':2s} {Ps:>7s} {bias:>8s} "
              f"{times[name]:11.2f} s" + "".join(f" {geq + format(times[name] / t, '.1f'):>15s}" for law in VARIATES
                                               for t in (t_ours[law], t_ours_all[law])))
    print("; ".join(f"safebasins {law} on {ncores} threads at {S_ours[law]} steps/cycle: {t_ours_all[law]:.2f} s"
                    for law in VARIATES)
          + f"; /<law> columns: time / safebasins' shifted row of that law on 1 or {ncores} threads; * = TOL not "
          f"reached at the cap (time at the cap: the ratio is a lower bound); diffrax Euler, ShARK, sdeint: "
          f"{B_EULER}, {B_SHARK}, {K_SDEINT} paths timed, scaled to {N}; 'normal': the peer's Gaussian increments")
    for law in VARIATES:
        # the same threshold rule for both: checked at the steps (no correction), or both shifted
        same_raw = times["numba EM, symplectic"] / times[ours_row(law, "none")]
        same_shift = times["numba EM, symplectic+shift"] / t_ours[law]
        print(f"same threshold rule, safebasins {law}: numba EM symplectic / safebasins, both uncorrected: "
              f"{same_raw:.1f}; both shifted: {same_shift:.1f}")
        report(f"noise_peers_numba_EM_symplectic_same_rule_{law.replace('-', '_')}",
               round(min(same_raw, same_shift), 1),
               f"time of numba EM, symplectic / time of the noisy ensemble with {law} variates, both with the same "
               f"threshold rule (the smaller of: both uncorrected, both shifted) at |P_escape bias| <= {TOL}",
               f"quartic Fig 14 forcing, sigma {SIGMA}, {CYCLES} cycles, {N} paths, one thread each")
    for law in VARIATES:
        for name in ("numba EM, symplectic", "numba EM, plain", "diffrax Euler", "diffrax ShARK", "sdeint itoEuler"):
            r = times[name] / t_ours[law]
            report("noise_peers_" + name.split()[0].lower() + "_" + "_".join(name.split()[1:]).replace(",", "")
                   + "_vs_" + law.replace("-", "_"),
                   round(r, 1), f"time of {name} / time of the noisy ensemble with {law} variates (one thread each) at "
                   f"equal weak accuracy (|P_escape bias| <= {TOL})"
                   f"{'' if found[name][3] else ', lower bound: TOL not reached at the cap'}",
                   f"quartic Fig 14 forcing, sigma {SIGMA}, {CYCLES} cycles, {N} paths; steps/cycle {found[name][0]} "
                   f"vs {S_ours[law]}")


if __name__ == "__main__":
    main()
