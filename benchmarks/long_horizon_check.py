"""Long-horizon check of the Fig 21/22 chart (F = 0.0876, Omega = 0.95, Psi = pi, xi_max = 0.25).

The paper (Fig 22) says the safe-basin area shrinks for ~2000 forcing cycles (EC) and then
stays; the engine (SRKN6b, 32 steps/cycle) has no energy escape after a few dozen cycles.
This script checks who is right and why:

1. the 300x300 chart over [-1, 1] x [-0.75, 0.75] for 11,000 cycles (read from
   results/data/numeric/chart_fig21.nc if present, else computed): area vs t_eval;
2. ~24 engine-safe ICs on the edge of the energy-safe basin and ~8 of the latest energy
   escapers, integrated with scipy DOP853 (rtol 1e-10, atol 1e-12, terminal events H0 = xi_max
   and |q| = 1) for --dop-cycles cycles: agreement with the engine;
3. the same chart with the engine's classic RK4 at 32 steps/cycle (drains energy) and, for
   the DOP853 ICs, scipy RK45 at loose tolerance (a non-symplectic scheme whose energy error
   has the other sign at this tolerance?): does integrator energy drift make the area change
   over ~2000 EC?

    python benchmarks/long_horizon_check.py [--workers 2] [--dop-cycles 2000]
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import time

import numpy as np

from _reference import H0, ivp_escape  # noqa: E402  (benchmarks/ is on sys.path)

PAR = dict(F=0.0876, Omega=0.95, Psi=np.pi, xi_max=0.25)
T_EVALS = (1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000, 11000)
CHART_NC = os.path.join(os.path.dirname(__file__), "..", "results", "data", "numeric", "chart_fig21.nc")


def heun_escape(q0, p0, F, Om, Psi, xi_max, S, cycles):
    """Energy-criterion escape cycle (inf: none) with Heun's RK2 at S steps/cycle, checked
    after every step: a non-symplectic scheme that GAINS energy (harmonic limit: |amplification|^2
    = 1 + h^4/4 per step), compiled with numba (prange over ICs)."""
    from numba import njit, prange

    @njit(parallel=True, cache=False)
    def run(q0, p0, F, Om, Psi, xi2, S, cycles):
        h = 2 * np.pi / (Om * S)
        out = np.full(q0.size, np.inf)
        for i in prange(q0.size):
            q = q0[i]
            p = p0[i]
            for n in range(cycles * S):
                t = n * h
                f0 = F * np.sin(Om * t + Psi)
                f1 = F * np.sin(Om * (t + h) + Psi)
                a0 = q * q * q - q + f0
                qe = q + h * p
                pe = p + h * a0
                a1 = qe * qe * qe - qe + f1
                q = q + 0.5 * h * (p + pe)
                p = p + 0.5 * h * (a0 + a1)
                if p * p + q * q - 0.5 * q ** 4 > xi2 or abs(q) > 1:
                    out[i] = (n + 1) / S
                    break
        return out
    return run(np.ascontiguousarray(q0, dtype=float), np.ascontiguousarray(p0, dtype=float), F, Om, Psi,
               2 * xi_max, S, cycles)


def run_pool(fn, args, workers):
    if workers > 1:
        from multiprocessing import Pool
        with Pool(workers) as pool:
            return pool.map(fn, args, chunksize=1)
    return [fn(a) for a in args]


def area_table(charts, t_evals):
    """Safe pixels (energy criterion) vs t_eval for several charts (escape_cycle arrays)."""
    names = list(charts)
    print(f"{'t_eval':>7s} " + " ".join(f"{n:>22s}" for n in names))
    for t in t_evals:
        print(f"{t:7g} " + " ".join(f"{int((charts[n] > t).sum()):22d}" for n in names))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--dop-cycles", type=int, default=2000)
    ap.add_argument("--n-edge", type=int, default=24)
    ap.add_argument("--n-late", type=int, default=8)
    ap.add_argument("--recompute", action="store_true", help="compute the SRKN6b chart even if the .nc exists")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)

    import xarray as xr

    from safebasins.numerics import escape_chart
    F, Om, Psi, xi = PAR["F"], PAR["Omega"], PAR["Psi"], PAR["xi_max"]
    qa = np.linspace(-1, 1, 300)
    pa = np.linspace(-0.75, 0.75, 300)
    print(f"load average {os.getloadavg()[0]:.2f}")

    # ---- 1. the SRKN6b chart
    if os.path.exists(CHART_NC) and not args.recompute:
        ch = xr.open_dataset(CHART_NC).load()
        print(f"SRKN6b chart read from {os.path.normpath(CHART_NC)} ({ch.attrs.get('integrator')}, "
              f"{ch.attrs.get('steps_per_cycle')} steps/cycle, {ch.attrs.get('cycles')} cycles)")
        assert np.allclose(ch["q0"], qa) and np.allclose(ch["p0"], pa)
    else:
        t = time.perf_counter()
        ch = escape_chart(qa, pa, F, Om, Psi, xi_max=xi, q_max=1.0, cycles=11000, grid=True)
        print(f"SRKN6b chart computed in {time.perf_counter() - t:.1f} s")
    eS = ch["escape_cycle_energy"].sel(xi_max=xi).values          # (q0, p0)
    dS = ch["escape_cycle_displacement"].values[0]
    fin = np.isfinite(eS) & (eS > 0)
    print(f"energy criterion: {np.isinf(eS).sum()} safe ICs at 11,000 EC; latest energy escape at "
          f"{eS[fin].max():.2f} EC; escapes after 20 / 30 / 50 EC: {(fin & (eS > 20)).sum()} / "
          f"{(fin & (eS > 30)).sum()} / {(fin & (eS > 50)).sum()}")
    fd = np.isfinite(dS) & (dS > 0)
    print(f"displacement criterion (q_max = 1): {np.isinf(dS).sum()} safe; latest escape {dS[fd].max():.2f} EC")

    # ---- 3a. RK4 (engine) at 32 and 256 steps/cycle on the same chart
    charts = {"SRKN6b S=32": eS}
    dcharts = {"SRKN6b S=32": dS}
    for S in (32, 256):
        t = time.perf_counter()
        r = escape_chart(qa, pa, F, Om, Psi, xi_max=xi, q_max=1.0, cycles=11000, steps_per_cycle=S, grid=True,
                         integrator="rk4")
        er = r["escape_cycle_energy"].values[0]
        charts[f"RK4 S={S}"] = er
        dcharts[f"RK4 S={S}"] = r["escape_cycle_displacement"].values[0]
        f = np.isfinite(er) & (er > 0)
        print(f"RK4 engine, {S} steps/cycle, 11,000 EC: {time.perf_counter() - t:.1f} s; {np.isinf(er).sum()} safe; "
              f"latest escape {er[f].max():.2f} EC; differs from SRKN6b (safe at 11,000) on "
              f"{int((np.isinf(er) != np.isinf(eS)).sum())} ICs ({int((np.isinf(er) & ~np.isinf(eS)).sum())} "
              f"safe only with RK4)")
    print("\nsafe pixels (energy criterion, 300x300) vs t_eval:")
    area_table(charts, T_EVALS)
    print("\nsafe pixels (displacement criterion q_max = 1, 300x300) vs t_eval:")
    area_table(dcharts, T_EVALS)

    # ---- 2. DOP853 on edge ICs and late escapers
    rng = np.random.default_rng(args.seed)
    safe = np.isinf(eS)
    esc = ~safe
    nb = np.zeros_like(safe)
    nb[1:, :] |= esc[:-1, :]
    nb[:-1, :] |= esc[1:, :]
    nb[:, 1:] |= esc[:, :-1]
    nb[:, :-1] |= esc[:, 1:]
    edge = np.argwhere(safe & nb)
    pick = edge[rng.choice(len(edge), min(args.n_edge, len(edge)), replace=False)]
    late_idx = np.argwhere(fin)
    order = np.argsort(eS[fin])[::-1][:args.n_late]
    late = late_idx[order]
    ics = [(qa[i], pa[j], "edge", eS[i, j]) for i, j in pick] + [(qa[i], pa[j], "late", eS[i, j]) for i, j in late]
    print(f"\n{len(edge)} edge ICs (engine-safe, 4-neighbour of an escaping IC); DOP853 (rtol 1e-10, atol 1e-12) "
          f"on {len(pick)} of them and the {len(late)} latest escapers, {args.dop_cycles} cycles, "
          f"{args.workers} workers ...", flush=True)
    t = time.perf_counter()
    res = run_pool(ivp_escape, [(q, p, F, Om, Psi, xi, args.dop_cycles, "DOP853", 1e-10, 1e-12)
                                for q, p, _, _ in ics], args.workers)
    print(f"  done in {time.perf_counter() - t:.0f} s")
    # loose RK45 (non-symplectic, adaptive) on the same ICs
    t = time.perf_counter()
    res45 = {tol: run_pool(ivp_escape, [(q, p, F, Om, Psi, xi, args.dop_cycles, "RK45", tol, tol * 1e-3)
                                       for q, p, _, _ in ics], args.workers) for tol in (1e-3, 1e-5)}
    print(f"  RK45 (rtol 1e-3 and 1e-5) done in {time.perf_counter() - t:.0f} s")
    # the late escapers graze the threshold (max H0 - xi_max ~ 1e-6 .. 3e-5): DOP853's event
    # detection (sign change between its steps) can miss that; re-run them with max_step T/512
    t = time.perf_counter()
    res_ms = run_pool(ivp_escape, [(q, p, F, Om, Psi, xi, int(min(args.dop_cycles, e + 5)), "DOP853", 1e-10, 1e-12,
                                    1 / 512) for q, p, k, e in ics if k == "late"], args.workers)
    print(f"  DOP853 with max_step T/512 on the late escapers: {time.perf_counter() - t:.0f} s")
    ms = iter(res_ms)
    rk4_32 = charts["RK4 S=32"]
    print(f"\n{'kind':5s} {'q0':>8s} {'p0':>8s} {'engine':>9s} {'DOP853':>9s} {'RK4 S=32':>9s} {'RK45 1e-3':>10s} "
          f"{'RK45 1e-5':>10s} {'DOP853 max_step T/512':>21s}")
    agree = {"edge": 0, "late": 0}
    for (q, p, kind, e), (d, _, _), (r3, _, _), (r5, _, _) in zip(ics, res, res45[1e-3], res45[1e-5]):
        i, j = int(np.argmin(abs(qa - q))), int(np.argmin(abs(pa - p)))
        e_cmp = e if e <= args.dop_cycles else np.inf
        agree[kind] += (np.isinf(e_cmp) == np.isinf(d)) and (np.isinf(d) or abs(d - e) < 1.0)
        dm = next(ms)[0] if kind == "late" else np.nan
        if kind == "late":
            late_ms = agree.setdefault("late_ms", 0)
            agree["late_ms"] = late_ms + (np.isfinite(dm) and abs(dm - e) < 1.0)
        print(f"{kind:5s} {q:8.4f} {p:8.4f} {e:9.2f} {d:9.2f} {rk4_32[i, j]:9.2f} {r3:10.2f} {r5:10.2f} "
              f"{dm:21.2f}")
    n_edge_esc = sum(np.isfinite(d) for (d, _, _), (_, _, k, _) in zip(res, ics) if k == "edge")
    print(f"\nedge ICs: {n_edge_esc}/{len(pick)} escape under DOP853 within {args.dop_cycles} EC; "
          f"engine agrees on {agree['edge']}/{len(pick)}")
    print(f"late escapers: engine and DOP853 agree (escape, |dt| < 1 EC) on {agree['late']}/{len(late)} with "
          f"DOP853's default steps, on {agree.get('late_ms', 0)}/{len(late)} with max_step T/512")
    # energy-GAINING scheme on the engine-safe ICs
    iq, jp = np.nonzero(safe)
    print(f"\nHeun RK2 (gains energy) on the {iq.size} SRKN6b-safe ICs, {args.dop_cycles} cycles, energy criterion:")
    heun = {}
    for S in (128, 256, 512):
        t = time.perf_counter()
        heun[S] = heun_escape(qa[iq], pa[jp], F, Om, Psi, xi, S, args.dop_cycles)
        print(f"  S = {S:3d} steps/cycle ({time.perf_counter() - t:.0f} s): still safe at t_eval = "
              + ", ".join(f"{te}: {int((heun[S] > te).sum())}" for te in T_EVALS if te <= args.dop_cycles))
    for tol in (1e-3, 1e-5):
        ne = sum(np.isfinite(r) for (r, _, _), (_, _, k, _) in zip(res45[tol], ics) if k == "edge")
        print(f"RK45 rtol {tol:g}: {ne}/{len(pick)} edge ICs escape within {args.dop_cycles} EC; escape times "
              f"{sorted(round(float(r), 1) for (r, _, _), (_, _, k, _) in zip(res45[tol], ics) if k == 'edge' and np.isfinite(r))}")

    # ---- displacement criterion: long transients (escape over the barrier after 500-2000 EC)
    dl = np.argwhere(np.isfinite(dS) & (dS > 500) & (dS <= args.dop_cycles))
    if len(dl):
        dl = dl[rng.choice(len(dl), min(args.n_late, len(dl)), replace=False)]
        print(f"\ndisplacement criterion (|q| > 1): {int((np.isfinite(dS) & (dS > 500)).sum())} ICs escape after "
              f"500 EC in the engine; DOP853 (event |q| = 1 only) on {len(dl)} with engine escape in "
              f"(500, {args.dop_cycles}] EC:")
        t = time.perf_counter()
        rd = run_pool(ivp_escape, [(qa[i], pa[j], F, Om, Psi, None, args.dop_cycles, "DOP853", 1e-10, 1e-12)
                                   for i, j in dl], args.workers)
        for (i, j), (d, _, _) in zip(dl, rd):
            print(f"  q0 {qa[i]:8.4f} p0 {pa[j]:8.4f} H0 {H0(qa[i], pa[j]):.4f}: engine {dS[i, j]:8.2f}  "
                  f"DOP853 {d:8.2f}  RK4 S=32 {dcharts['RK4 S=32'][i, j]:8.2f}")
        print(f"  ({time.perf_counter() - t:.0f} s; chaotic transients: only the statistics, not the times, "
              f"can agree between integrators)")

    # ---- energy drift sign of the loose schemes on the free oscillator
    print("\nfree oscillator (F = 0, Omega = 1), IC at rest at H0 = 0.2, 2000 cycles: relative H0 change")
    q0 = math.sqrt(1 - math.sqrt(1 - 0.8))
    for method, tol in (("RK45", 1e-3), ("RK45", 1e-5), ("DOP853", 1e-10)):
        _, nfev, y = ivp_escape((q0, 0.0, 0.0, 1.0, 0.0, 0.25, 2000, method, tol, tol * 1e-3 if method == "RK45" else 1e-12))
        print(f"  {method} rtol {tol:g}: {(H0(*y) - 0.2) / 0.2:+.2e} ({nfev / 2000:.0f} rhs evaluations/cycle)")
    from safebasins.numerics import kernels, schemes
    from safebasins.numerics.scheme_code import scheme_code
    for S in (128, 256, 512):
        h = 2 * np.pi / S
        qq, pp = q0, 0.0
        for n in range(2000 * S):
            a0 = qq ** 3 - qq
            qe, pe = qq + h * pp, pp + h * a0
            qq, pp = qq + 0.5 * h * (pp + pe), pp + 0.5 * h * (a0 + qe ** 3 - qe)
        print(f"  Heun RK2 {S} steps/cycle: {(H0(qq, pp) - 0.2) / 0.2:+.2e}")
    for S in (32, 256):
        q, p = kernels.final_states(np.array([q0]), np.zeros(1), np.zeros(1, np.int64), schemes.lane_coefficients(1.0, S, "rk4"),
                              np.array([0.0]), schemes.sine_table(S, 0.0, "rk4"), 2000, scheme=scheme_code("rk4"))
        print(f"  engine RK4 {S} steps/cycle: {(H0(q[0], p[0]) - 0.2) / 0.2:+.2e}")


if __name__ == "__main__":
    sys.exit(main())
