"""Melnikov threshold checks: the numbers of docs/melnikov.md.

1. quadrature vs closed forms: ``I1`` and ``|I2(Omega)|`` of the quartic, cubic and pendulum
   separatrices on 400 Omega in [0.02, 4] (and the large-Omega rounding limit);
2. quadrature vs a direct DOP853 integration of the separatrix orbit of a well without closed
   form (the asymmetric quartic V = q^2/2 + (0.2/3) q^3 - q^4/4: homoclinic to its left saddle),
   started at the turning point and stopped 1e-5 from the saddle, linear tail added;
3. the physical check: the manifolds of the forced saddle of the escape equation
   q'' + beta q' + q - q^2 = F sin(Omega t) (beta = 0.1, Omega = 0.85) on the normal section of
   the homoclinic orbit at F = 0.9 F_M, F_M and 1.1 F_M (``manifold_splitting``), the numeric
   tangency F* (max over t0 of the energy gap = 0, Brent) and F*/F_M as beta -> 0; one
   heteroclinic case (the quartic) too.

    python benchmarks/melnikov_check.py [--quick]
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from numpy.polynomial import polynomial as P
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from safebasins.analysis.melnikov import (CLOSED_FORMS, manifold_splitting, melnikov_threshold, separatrix_integrals,
                                          separatrix_orbit)
from safebasins.wells import resolve_well

ASYMMETRIC = [0.0, 0.0, 0.5, 0.2 / 3, -0.25]


def closed_forms():
    print("1. quadrature vs closed forms (400 Omega in [0.02, 4])")
    W = np.linspace(0.02, 4.0, 400)
    for name, (I1c, I2c, kind) in CLOSED_FORMS.items():
        resolve_well(name)
        t = time.perf_counter()
        I1, I2, orbit = separatrix_integrals(W, name)
        dt = time.perf_counter() - t
        err = np.max(np.abs(np.abs(I2) / I2c(W) - 1))
        big = {}
        for Om in (6.0, 8.0, 10.0, 12.0):
            try:
                big[Om] = abs(abs(separatrix_integrals(Om, name)[1]) / I2c(Om) - 1)
            except ValueError:
                big[Om] = "refused"
        print(f"   {name:9s} {orbit.kind:12s} I1 rel err {abs(I1 / I1c - 1):.1e}  max |I2| rel err {err:.1e}  "
              f"({dt * 1e3:.0f} ms for 400 Omega)  large Omega: "
              + ", ".join(f"{k:g}: {v if isinstance(v, str) else f'{v:.0e}'}" for k, v in big.items()))


def dop853(delta=1e-5):
    print(f"2. quadrature vs DOP853 (asymmetric quartic {ASYMMETRIC}, stop {delta:g} from the saddle)")
    w = resolve_well({"polynomial": ASYMMETRIC})
    orbit = separatrix_orbit(w)
    (qb,), qt = orbit.saddles, orbit.turning_point
    lam = np.sqrt(-P.polyval(qb, P.polyder(ASYMMETRIC, 2)))
    W = np.array([0.3, 0.9, 2.0])
    I1q, I2q, _ = separatrix_integrals(W, w)
    dV = P.polyder(ASYMMETRIC)

    def f(t, y):
        return [y[1], -P.polyval(y[0], dV), y[1] ** 2, *(y[1] * np.sin(W * t))]
    event = lambda t, y: abs(y[0] - qb) - delta
    event.terminal = True
    sol = solve_ivp(f, (0.0, 200.0), [qt, 0.0, 0.0, 0.0, 0.0, 0.0], method="DOP853", rtol=1e-13, atol=1e-15,
                    events=event)
    te, (q, p, J1, *S) = sol.t[-1], sol.y[:, -1]
    x = q - qb                        # the tail: q - q_b = x e^{-lambda (t - t_e)}
    I1 = 2.0 * (J1 + 0.5 * lam * x * x)
    I2 = 2.0 * (np.array(S) + np.imag(-lam * x * np.exp(1j * W * te) / (lam - 1j * W)))
    print(f"   {orbit.kind} to q_b = {qb:.6f}, turning point {qt:.6f}; I1 = {I1q:.15f}, rel diff {I1 / I1q - 1:.1e}")
    for Om, a, b in zip(W, I2, np.imag(I2q)):
        print(f"   Omega = {Om}: Im I2 = {b:.15f} (quadrature), rel diff DOP853 {a / b - 1:.1e}")


def manifolds(well, Omega, beta, n_phase, factors=(0.9, 1.0, 1.1), tangency=True):
    FM = melnikov_threshold(Omega, beta, well)
    print(f"   {well}: beta = {beta}, Omega = {Omega}: F_M = {FM:.6f}")
    for fac in factors:
        t = time.perf_counter()
        ds = manifold_splitting(fac * FM, Omega, beta, well, n_phase=n_phase)
        print(f"     F = {fac:.2f} F_M: energy gap H0(W^u) - H0(W^s) over t0 in [{ds.attrs['min_energy_gap']:+.5f}, "
              f"{ds.attrs['max_energy_gap']:+.5f}] (first order M(t0): [{float(ds.melnikov.min()):+.5f}, "
              f"{float(ds.melnikov.max()):+.5f}]); intersect: {bool(ds.attrs['manifolds_intersect'])} "
              f"({time.perf_counter() - t:.2f} s)")
    if tangency:
        g = lambda F: manifold_splitting(F, Omega, beta, well, n_phase=n_phase).attrs["max_energy_gap"]
        Fs = brentq(g, 0.8 * FM, 1.2 * FM, xtol=1e-7 * FM)
        print(f"     numeric tangency F* = {Fs:.7f}, F*/F_M - 1 = {Fs / FM - 1:+.1e}")
        return Fs / FM


def physical(quick):
    n = 32 if quick else 96
    print(f"3. manifolds of the forced saddle on the normal section ({n} start times per period)")
    manifolds("cubic", 0.85, 0.1, n)
    if not quick:
        print("   convergence in the numerics (cubic, beta = 0.1, Omega = 0.85, F = 1.1 F_M): max energy gap")
        FM = melnikov_threshold(0.85, 0.1, "cubic")
        for n_phase, offset, rtol in ((48, 1e-6, 1e-11), (96, 1e-6, 1e-11), (96, 1e-7, 1e-12), (192, 1e-6, 1e-11)):
            ds = manifold_splitting(1.1 * FM, 0.85, 0.1, "cubic", n_phase=n_phase, offset=offset, rtol=rtol)
            print(f"     n_phase {n_phase:3d}, offset {offset:g}, rtol {rtol:g}: {ds.attrs['max_energy_gap']:+.9f}")
        print("   F*/F_M as beta -> 0 (first order in (F, beta)):")
        for beta in (0.1, 0.05, 0.02, 0.01):
            manifolds("cubic", 0.85, beta, n, factors=())
        print("   heteroclinic (quartic, Psi = 0):")
        manifolds("quartic", 0.9, 0.05, n)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="coarse manifold check only")
    args = ap.parse_args()
    closed_forms()
    dop853()
    physical(args.quick)


if __name__ == "__main__":
    main()
