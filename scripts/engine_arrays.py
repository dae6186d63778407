#!/usr/bin/env python
"""The public numerics API on a fixed matrix of cases, as arrays: proof that an engine change keeps
every escape step, on one machine.

    python scripts/engine_arrays.py save OUT.npz        # with the code of one commit
    python scripts/engine_arrays.py compare A.npz B.npz # bit for bit (NaN == NaN); exit 1 on a difference

Cases: five wells (the quartic in closed form, the cubic, an asymmetric quartic, the pendulum,
a rational expression) x the schemes srkn6b and rk4 x undamped / damped, each through
escape_chart on a grid (shared-parameter loop), escape_chart_batch (per-lane loop), energy,
displacement and asymmetric bound thresholds, critical_forcing_numeric (bisection and scan) and
stroboscopic_map (stored iterates).  Only public functions are called, so two commits with
different internals can be compared.
"""
from __future__ import annotations

import argparse
import sys

import numpy as np

import safebasins.numerics as nu

WELLS = {"quartic": None, "cubic": "cubic", "asym": {"polynomial": [0.0, 0.0, 0.5, -0.1, -0.25]},
         "pendulum": "pendulum", "rational": {"expression": "q**2/2 - q**4/4 + q**6/(60*(1 + q**2))"}}
XI = {"quartic": (0.12, 0.2), "cubic": (0.1, 0.15), "asym": (0.05, 0.1), "pendulum": (1.0, 1.5), "rational": (0.1, 0.2)}


def compute() -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    for name, well in WELLS.items():
        xi = XI[name]
        F = 0.08 if name == "pendulum" else 0.03
        for integrator in ("srkn6b", "rk4"):
            for beta in (0.0, 0.02):
                tag = f"{name}/{integrator}/beta{beta}"
                q = np.linspace(-0.6, 0.6, 13)
                p = np.linspace(-0.5, 0.5, 11)
                kw = dict(well=well, cycles=40, integrator=integrator, damping=beta, threads=2)
                ds = nu.escape_chart(q, p, F, 0.85, 0.4, xi_max=xi, grid=True, **kw)
                out[f"{tag}/chart_E"] = ds.escape_cycle_energy.values
                qb = nu.displacement_bounds(xi[0], well)
                ds = nu.escape_chart(q, p, F, 0.85, 0.4, xi_max=(), q_bounds=qb, grid=True, **kw)
                out[f"{tag}/chart_B"] = ds.escape_cycle_bounds.values
                if well is None:
                    ds = nu.escape_chart(q, p, F, 0.85, 0.4, xi_max=(), q_max=(0.5, 0.7), grid=True, **kw)
                    out[f"{tag}/chart_Q"] = ds.escape_cycle_displacement.values
                rng = np.random.default_rng(7)
                qs, ps = rng.uniform(-0.5, 0.5, 60), rng.uniform(-0.4, 0.4, 60)
                ds = nu.escape_chart_batch(qs, ps, np.array([0.5 * F, F, 2 * F]), np.array([0.9, 0.8, 1.0]), 1.0, xi_max=xi, **kw)
                out[f"{tag}/batch_E"] = ds.escape_cycle_energy.values
                fc = nu.critical_forcing_numeric(np.array([0.8, 0.95]), xi[1], cycles=60, tol=1e-3, n_scan=21,
                                                 well=well, integrator=integrator, damping=beta,
                                                 F_bracket=(0.0, 0.4 if name == "pendulum" else 0.2))
                for v in ("F_cr", "F_escape_low", "F_escape_all"):
                    out[f"{tag}/fcr_{v}"] = fc[v].values
                sm = nu.stroboscopic_map(qs[:8], ps[:8], F, 0.9, 0.2, n_iter=30, xi_max=xi[1], well=well,
                                         integrator=integrator, damping=beta)
                for v in sm.data_vars:
                    out[f"{tag}/strobe_{v}"] = sm[v].values
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("save")
    s.add_argument("out")
    c = sub.add_parser("compare")
    c.add_argument("a")
    c.add_argument("b")
    args = ap.parse_args(argv)
    if args.cmd == "save":
        arrays = compute()
        np.savez_compressed(args.out, **arrays)
        print(f"{len(arrays)} arrays -> {args.out}")
        return 0
    a, b = np.load(args.a), np.load(args.b)
    keys = sorted(set(a.files) | set(b.files))
    bad = [k for k in keys if k not in a.files or k not in b.files
           or a[k].shape != b[k].shape or not np.array_equal(a[k], b[k], equal_nan=True)]
    for k in bad:
        print(f"DIFFERS {k}")
    print(f"{len(keys)} arrays compared, {len(bad)} differ")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
