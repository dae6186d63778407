"""Escape charts: escape time of every initial condition for many thresholds in one pass."""
from __future__ import annotations

import numpy as np
import xarray as xr

from safebasins import checks
from safebasins.io import cf
from safebasins.wells.quartic import QUARTIC
from safebasins.numerics import engine
from safebasins.numerics import kernels

def _monotone(a):
    d = np.diff(a)
    return bool(np.all(d > 0) or np.all(d < 0))


def _ic_arrays(q0, p0, grid):
    qa = checks.check_finite("q0", q0)
    pa = checks.check_finite("p0", p0)
    if grid is None:
        grid = qa.ndim == 1 and pa.ndim == 1 and _monotone(qa) and _monotone(pa)
    if grid:
        if qa.ndim != 1 or pa.ndim != 1:
            raise ValueError(f"q0 and p0 must be 1-D axes for grid=True, got shapes {qa.shape}, {pa.shape}")
        if qa.size == 0 or pa.size == 0:
            raise ValueError("q0 and p0 axes must not be empty")
        Q, P = np.meshgrid(qa, pa, indexing="ij")
        return True, qa, pa, Q.ravel(), P.ravel()
    if qa.shape != pa.shape:
        raise ValueError(f"q0 and p0 must have the same shape for paired initial conditions (grid=False), "
                         f"got {qa.shape} and {pa.shape}")
    return False, qa, pa, qa.ravel(), pa.ravel()


def escape_chart(q0, p0, F, Omega, Psi, *, xi_max=(0.25,), q_max=(), cycles=3000,
                 steps_per_cycle=engine.DEFAULT_STEPS_PER_CYCLE, threads=None, grid=None,
                 integrator=engine.DEFAULT_INTEGRATOR, backend="cpu"):
    """Escape time (forcing cycles) of every initial condition, for every threshold.

    Parameters
    ----------
    q0, p0 : initial conditions.  grid=True: 1-D AXES -> dims ('q0', 'p0'), ij indexing (first
        axis q0).  grid=False: paired ICs of equal shape (e.g. random ICs) -> flat dim 'sample'
        with coords q0(sample), p0(sample) (C order).  grid=None (default) decides: two 1-D,
        strictly monotonic arrays are axes (a grid), anything else is paired.  Random ICs are
        therefore paired automatically; pass grid=False for paired ICs that happen to be sorted
        (e.g. points on a line) and grid=True/False explicitly in library code.
    F, Omega, Psi : forcing amplitude (>= 0), frequency (> 0), phase of eq (1).
    xi_max : energy thresholds, H0 = p^2/2 + q^2/2 - q^4/4 > xi_max means escape (eq 7).
        |q| > 1 (beyond the barrier, out of the well) also counts as energy escape.
    q_max : displacement thresholds, |q| > q_max means escape (q_max(xi_max): eq 4).
    cycles : horizon in forcing cycles (integer).
    steps_per_cycle : fixed steps per forcing period.
    integrator : "srkn6b" (default: Blanes-Moan SRKN6b, order 4, symplectic) or "rk4" (classic
        RK4, same engine; not symplectic, it drains energy: needs ~256 steps/cycle for a 1e-5
        relative energy error over 11,000 cycles).  Dataset attr `integrator` names it.
    threads : numba threads (None: current setting); results are bitwise independent of it.
    backend : "cpu" (default, the reference), "cuda" (numba-cuda kernels, bitwise equal escape
        steps) or "auto" (the GPU when one is visible).

    Returns
    -------
    xr.Dataset with escape_cycle_energy (xi_max, ...), escape_cycle_displacement (q_max, ...):
    step of first crossing / steps_per_cycle (exact to one step), 0 if the IC is already beyond,
    +inf if no crossing within `cycles`.  Safe basin for (threshold, t_eval): escape_cycle > t_eval.
    One integration serves every threshold and every t_eval <= cycles; a trajectory stops once
    it has crossed every requested threshold.
    """
    is_grid, qa, pa, Q, P = _ic_arrays(q0, p0, grid)
    F = checks.check_scalar("F", F, checks.check_nonnegative)
    Omega = checks.check_scalar("Omega", Omega, checks.check_positive)
    Psi = checks.check_scalar("Psi", Psi, checks.check_finite)
    xi = engine.thresholds("xi_max", xi_max, QUARTIC.check_threshold)
    qm = engine.thresholds("q_max", q_max, QUARTIC.check_displacement)
    if xi.size == 0 and qm.size == 0:
        raise ValueError("xi_max and q_max: at least one threshold is required")
    cycles = engine.check_cycles("cycles", cycles)
    spc = engine.check_steps_per_cycle(steps_per_cycle)
    threads = engine.check_threads(threads)
    kernels.check_integrator(integrator)

    sE, sQ = engine.integrate(Q, P, np.zeros(Q.size, np.int64), [Omega], [F], Psi, xi_max=xi, q_max=qm,
                              cycles=cycles, steps_per_cycle=spc, threads=threads, integrator=integrator,
                              backend=backend)
    tE = engine.steps_to_cycles(sE, spc).T   # (nE, N)
    tQ = engine.steps_to_cycles(sQ, spc).T
    if is_grid:
        shape, dims = (qa.size, pa.size), ("q0", "p0")
        coords = {"q0": ("q0", qa, cf.attrs("q0")), "p0": ("p0", pa, cf.attrs("p0"))}
    else:
        shape, dims = (Q.size,), ("sample",)
        coords = {"sample": ("sample", np.arange(Q.size), cf.attrs("sample")), "q0": ("sample", Q, cf.attrs("q0")),
                  "p0": ("sample", P, cf.attrs("p0"))}
    coords["xi_max"] = ("xi_max", xi, cf.attrs("xi_max"))
    coords["q_max"] = ("q_max", qm, cf.attrs("q_max"))
    ds = xr.Dataset(
        {
            "escape_cycle_energy": (("xi_max",) + dims, tE.reshape((xi.size,) + shape),
                                    cf.attrs("escape_cycle_energy")),
            "escape_cycle_displacement": (("q_max",) + dims, tQ.reshape((qm.size,) + shape),
                                          cf.attrs("escape_cycle_displacement")),
        },
        coords=coords,
    )
    ds.attrs.update(
        F=F, Omega=Omega, Psi=Psi, cycles=cycles, steps_per_cycle=spc, integrator=kernels.INTEGRATORS[integrator],
        grid=int(is_grid),
        escape_criteria=("energy: H0 = p^2/2 + q^2/2 - q^4/4 > xi_max or |q| > 1; displacement: |q| > q_max; "
                         "checked after every step; escape_cycle = step / steps_per_cycle"),
        safe_basin="escape_cycle > t_eval (t_eval <= cycles)",
    )
    return ds


def escape_chart_batch(q0, p0, F, Omega, Psi, *, xi_max=(0.25,), q_max=(), cycles=3000,
                       steps_per_cycle=engine.DEFAULT_STEPS_PER_CYCLE, threads=None,
                       integrator=engine.DEFAULT_INTEGRATOR, backend="cpu"):
    """Escape charts of one IC grid for several control points ``(F[k], Omega[k])`` in ONE ensemble.

    Every trajectory carries its control point (the lanes refill across charts, so a control
    point whose ICs escape early frees its lanes for the others); each chart is bitwise the
    :func:`escape_chart` of its control point.  ``q0``, ``p0``: 1-D grid axes; ``F``, ``Omega``:
    1-D of equal length K.  Returns a Dataset with ``escape_cycle_energy (control, xi_max, q0,
    p0)``, ``escape_cycle_displacement (control, q_max, q0, p0)`` and coordinates ``F(control)``,
    ``Omega(control)``.
    """
    is_grid, qa, pa, Q, P = _ic_arrays(q0, p0, True)
    F = checks.check_1d("F", F, checks.check_nonnegative)
    Omega = checks.check_1d("Omega", Omega, checks.check_positive)
    if F.size != Omega.size or F.size == 0:
        raise ValueError(f"F and Omega must be 1-D of the same non-zero length, got {F.size} and {Omega.size}")
    Psi = checks.check_scalar("Psi", Psi, checks.check_finite)
    xi = engine.thresholds("xi_max", xi_max, QUARTIC.check_threshold)
    qm = engine.thresholds("q_max", q_max, QUARTIC.check_displacement)
    if xi.size == 0 and qm.size == 0:
        raise ValueError("xi_max and q_max: at least one threshold is required")
    cycles = engine.check_cycles("cycles", cycles)
    spc = engine.check_steps_per_cycle(steps_per_cycle)
    threads = engine.check_threads(threads)
    kernels.check_integrator(integrator)
    K, n = F.size, Q.size
    sE, sQ = engine.integrate(np.tile(Q, K), np.tile(P, K), np.repeat(np.arange(K), n), Omega, F, Psi,
                              xi_max=xi, q_max=qm, cycles=cycles, steps_per_cycle=spc, threads=threads,
                              integrator=integrator, backend=backend)
    shape = (K, qa.size, pa.size)
    tE = np.moveaxis(engine.steps_to_cycles(sE, spc).reshape(shape + (xi.size,)), -1, 1)
    tQ = np.moveaxis(engine.steps_to_cycles(sQ, spc).reshape(shape + (qm.size,)), -1, 1)
    ds = xr.Dataset(
        {"escape_cycle_energy": (("control", "xi_max", "q0", "p0"), tE, cf.attrs("escape_cycle_energy")),
         "escape_cycle_displacement": (("control", "q_max", "q0", "p0"), tQ, cf.attrs("escape_cycle_displacement"))},
        coords={"control": ("control", np.arange(K), {"long_name": "control-point index"}),
                "F": ("control", F, cf.attrs("F")), "Omega": ("control", Omega, cf.attrs("Omega")),
                "q0": ("q0", qa, cf.attrs("q0")), "p0": ("p0", pa, cf.attrs("p0")),
                "xi_max": ("xi_max", xi, cf.attrs("xi_max")), "q_max": ("q_max", qm, cf.attrs("q_max"))})
    ds.attrs.update(Psi=Psi, cycles=cycles, steps_per_cycle=spc, integrator=kernels.INTEGRATORS[integrator],
                    safe_basin="escape_cycle > t_eval (t_eval <= cycles)")
    return ds
