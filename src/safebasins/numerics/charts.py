"""Escape charts: escape time of every initial condition for many thresholds in one pass."""
from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.core import checks
from safebasins.core import cf
from safebasins.wells.provenance import api_provenance
from safebasins.numerics import criteria, engine, schemes
from safebasins.numerics.problem import check_cycles, displacement_pairs, ensemble_problem
from safebasins.wells import Well, resolve_well
from safebasins.wells.base import WellLike


def ic_coords(is_grid: bool, qa: np.ndarray, pa: np.ndarray, Q: np.ndarray, P: np.ndarray
              ) -> tuple[tuple[int, ...], tuple[str, ...], dict[str, Any]]:
    """(shape, dims, coords) of a result over the initial conditions of
    :func:`safebasins.core.checks.initial_conditions`: a grid (q0, p0) of the axes qa, pa, or paired
    samples (sample) at Q, P."""
    if is_grid:
        return (qa.size, pa.size), ("q0", "p0"), {"q0": ("q0", qa, cf.attrs("q0")), "p0": ("p0", pa, cf.attrs("p0"))}
    return (Q.size,), ("sample",), {"sample": ("sample", np.arange(Q.size), cf.attrs("sample")),
                                    "q0": ("sample", Q, cf.attrs("q0")), "p0": ("sample", P, cf.attrs("p0"))}


def _thresholds(w: Well, xi_max: npt.ArrayLike, q_max: npt.ArrayLike, q_bounds: npt.ArrayLike
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Checked thresholds of a chart in the well w: (xi, q_max, q_bounds (n, 2))."""
    xi = engine.thresholds("xi_max", xi_max, w.check_threshold)
    qm = engine.thresholds("q_max", q_max, w.check_displacement)
    qb = w.check_bounds("q_bounds", q_bounds)
    if xi.size == 0 and qm.size == 0 and qb.shape[0] == 0:
        raise ValueError("xi_max, q_max and q_bounds: at least one threshold is required")
    displacement_pairs(qm, qb)          # nested (ValueError naming q_max / q_bounds)
    return xi, qm, qb


@api_provenance
def escape_chart(q0: npt.ArrayLike, p0: npt.ArrayLike, F: float, Omega: float, Psi: float, *,
                 xi_max: npt.ArrayLike = (0.25,), q_max: npt.ArrayLike = (), q_bounds: npt.ArrayLike = (),
                 well: WellLike = None, cycles: int = 3000, steps_per_cycle: int = engine.DEFAULT_STEPS_PER_CYCLE,
                 threads: int | None = None, grid: bool | None = None, integrator: str = engine.DEFAULT_INTEGRATOR,
                 backend: str = "cpu", damping: float = 0.0) -> xr.Dataset:
    """Escape time (forcing cycles) of every initial condition, for every threshold.

    Parameters
    ----------
    q0, p0 : initial conditions.  grid=True: 1-D AXES -> dims ('q0', 'p0'), ij indexing (first
        axis q0).  grid=False: paired ICs of equal shape (e.g. random ICs) -> flat dim 'sample'
        with coords q0(sample), p0(sample) (C order).  grid=None (default) decides: two 1-D,
        strictly monotonic arrays are axes (a grid), anything else is paired.  Random ICs are
        therefore paired automatically; pass grid=False for paired ICs that happen to be sorted
        (e.g. points on a line) and grid=True/False explicitly in library code.
    F, Omega, Psi : forcing amplitude (>= 0), frequency (> 0), phase of
        q'' + beta q' + V'(q) = F sin(Omega t + Psi).
    damping : beta >= 0 (default 0: the paper's undamped equation, results bitwise as before
        damping existed); > 0 integrates with the scheme's damped variant (SRKN6b: conformal
        symplectic, order 4; steps.DAMPED_INTEGRATORS) and records ``damping`` in the attributes.
    well : the potential (None: the paper's quartic V = q^2/2 - q^4/4, eq 1); a polynomial well
        (an object with `coefficients`, e.g. safebasins.wells.polynomial.cubic()) runs in the
        same compiled engine (numerics.criteria).  Dataset attrs `well`, `well_potential`,
        `well_barriers`, `escape_criteria` name it.
    xi_max : energy thresholds in (0, barrier energy]: H0 = p^2/2 + V(q) > xi_max means escape
        (eq 7).  q beyond a barrier (quartic: ``|q| > 1``; in general q > q_right or q < q_left; a
        side without barrier never escapes that way) also counts as energy escape.
    q_max : symmetric displacement thresholds, ``|q| > q_max`` means escape (q_max(xi_max): eq 4),
        q_max up to the nearest barrier.
    q_bounds : asymmetric displacement bounds, pairs (lo, hi) (shape (n, 2); one pair may be
        given as (lo, hi)): q < lo or q > hi means escape; lo < 0 < hi, inside the barriers.
        The energy-level bounds of a well are its turning points,
        q_bounds = numerics.displacement_bounds(xi, well) = (q_minus(xi), q_plus(xi)).  All
        displacement thresholds (q_max as (-q_max, q_max) and q_bounds) must be nested.
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
    xr.Dataset with escape_cycle_energy (xi_max, ...), escape_cycle_displacement (q_max, ...) and,
    when q_bounds are given, escape_cycle_bounds (q_bounds, ...) with coords q_lower(q_bounds),
    q_upper(q_bounds) (q_bounds = pair index):
    step of first crossing / steps_per_cycle (exact to one step), 0 if the IC is already beyond,
    +inf if no crossing within `cycles`.  Safe basin for (threshold, t_eval): escape_cycle > t_eval.
    One integration serves every threshold and every t_eval <= cycles; a trajectory stops once
    it has crossed every requested threshold.
    """
    is_grid, qa, pa, Q, P = checks.initial_conditions(q0, p0, grid)
    F = checks.check_scalar("F", F, checks.check_nonnegative)
    Omega = checks.check_scalar("Omega", Omega, checks.check_positive)
    Psi = checks.check_scalar("Psi", Psi, checks.check_finite)
    damping = checks.check_damping(damping)
    w = resolve_well(well)
    xi, qm, qb = _thresholds(w, xi_max, q_max, q_bounds)
    cycles = check_cycles("cycles", cycles)
    schemes.check_integrator(integrator)
    spc = engine.check_step(Omega, engine.check_steps_per_cycle(steps_per_cycle), w, integrator)
    threads = engine.check_threads(threads)

    problem = ensemble_problem(Q, P, np.zeros(Q.size, np.int64), [Omega], [F], Psi, xi_max=xi, q_max=qm,
                               q_bounds=qb, cycles=cycles, steps_per_cycle=spc, integrator=integrator, well=w,
                               damping=damping)
    sE, sQ = engine.integrate(problem, backend, threads=threads)
    tE = engine.steps_to_cycles(sE, spc).T   # (nE, N)
    tQ = engine.steps_to_cycles(sQ, spc).T   # (nQ + nB, N)
    shape, dims, coords = ic_coords(is_grid, qa, pa, Q, P)
    coords["xi_max"] = ("xi_max", xi, cf.attrs("xi_max"))
    coords["q_max"] = ("q_max", qm, cf.attrs("q_max"))
    data = {
        "escape_cycle_energy": (("xi_max",) + dims, tE.reshape((xi.size,) + shape), cf.attrs("escape_cycle_energy")),
        "escape_cycle_displacement": (("q_max",) + dims, tQ[:qm.size].reshape((qm.size,) + shape),
                                      cf.attrs("escape_cycle_displacement")),
    }
    if qb.shape[0]:
        coords.update(_bounds_coords(qb))
        data["escape_cycle_bounds"] = (("q_bounds",) + dims, tQ[qm.size:].reshape((qb.shape[0],) + shape),
                                       cf.attrs("escape_cycle_bounds"))
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update(
        F=F, Omega=Omega, Psi=Psi, cycles=cycles, steps_per_cycle=spc,
        integrator=engine.integrator_text(integrator, damping),
        grid=int(is_grid), escape_criteria=criteria.criteria_text(w),
        safe_basin="escape_cycle > t_eval (t_eval <= cycles)", **w.numerics_attrs(), **engine.damping_attrs(damping),
    )
    return ds


def _bounds_coords(qb: np.ndarray) -> dict[str, Any]:
    return {"q_bounds": ("q_bounds", np.arange(qb.shape[0]), cf.attrs("q_bounds")),
            "q_lower": ("q_bounds", qb[:, 0], cf.attrs("q_lower")),
            "q_upper": ("q_bounds", qb[:, 1], cf.attrs("q_upper"))}


@api_provenance
def escape_chart_batch(q0: npt.ArrayLike, p0: npt.ArrayLike, F: npt.ArrayLike, Omega: npt.ArrayLike, Psi: float, *,
                       xi_max: npt.ArrayLike = (0.25,), q_max: npt.ArrayLike = (), q_bounds: npt.ArrayLike = (),
                       well: WellLike = None, cycles: int = 3000,
                       steps_per_cycle: int = engine.DEFAULT_STEPS_PER_CYCLE, threads: int | None = None,
                       integrator: str = engine.DEFAULT_INTEGRATOR, backend: str = "cpu",
                       damping: float = 0.0) -> xr.Dataset:
    """Escape charts of one IC grid for several control points ``(F[k], Omega[k])`` in ONE ensemble.

    Every trajectory carries its control point (the lanes refill across charts, so a control
    point whose ICs escape early frees its lanes for the others); each chart is bitwise the
    :func:`escape_chart` of its control point.  ``q0``, ``p0``: 1-D grid axes; ``F``, ``Omega``:
    1-D of equal length K; ``well``, ``xi_max``, ``q_max``, ``q_bounds`` as :func:`escape_chart`.
    Returns a Dataset with ``escape_cycle_energy (control, xi_max, q0, p0)``,
    ``escape_cycle_displacement (control, q_max, q0, p0)`` (and ``escape_cycle_bounds (control,
    q_bounds, q0, p0)`` when q_bounds are given) and coordinates ``F(control)``, ``Omega(control)``.
    """
    is_grid, qa, pa, Q, P = checks.initial_conditions(q0, p0, True)
    F = checks.check_1d("F", F, checks.check_nonnegative)
    Omega = checks.check_1d("Omega", Omega, checks.check_positive)
    if F.size != Omega.size or F.size == 0:
        raise ValueError(f"F and Omega must be 1-D of the same non-zero length, got {F.size} and {Omega.size}")
    Psi = checks.check_scalar("Psi", Psi, checks.check_finite)
    damping = checks.check_damping(damping)
    w = resolve_well(well)
    xi, qm, qb = _thresholds(w, xi_max, q_max, q_bounds)
    cycles = check_cycles("cycles", cycles)
    schemes.check_integrator(integrator)
    spc = engine.check_step(Omega, engine.check_steps_per_cycle(steps_per_cycle), w, integrator)
    threads = engine.check_threads(threads)
    K, n = F.size, Q.size
    problem = ensemble_problem(np.tile(Q, K), np.tile(P, K), np.repeat(np.arange(K), n), Omega, F, Psi,
                               xi_max=xi, q_max=qm, q_bounds=qb, cycles=cycles, steps_per_cycle=spc,
                               integrator=integrator, well=w, damping=damping)
    sE, sQ = engine.integrate(problem, backend, threads=threads)
    shape = (K, qa.size, pa.size)
    nQ, nB = qm.size, qb.shape[0]
    tE = np.moveaxis(engine.steps_to_cycles(sE, spc).reshape(shape + (xi.size,)), -1, 1)
    tQ = np.moveaxis(engine.steps_to_cycles(sQ, spc).reshape(shape + (nQ + nB,)), -1, 1)
    data = {"escape_cycle_energy": (("control", "xi_max", "q0", "p0"), tE, cf.attrs("escape_cycle_energy")),
            "escape_cycle_displacement": (("control", "q_max", "q0", "p0"), tQ[:, :nQ],
                                          cf.attrs("escape_cycle_displacement"))}
    coords = {"control": ("control", np.arange(K), {"long_name": "control-point index"}),
              "F": ("control", F, cf.attrs("F")), "Omega": ("control", Omega, cf.attrs("Omega")),
              "q0": ("q0", qa, cf.attrs("q0")), "p0": ("p0", pa, cf.attrs("p0")),
              "xi_max": ("xi_max", xi, cf.attrs("xi_max")), "q_max": ("q_max", qm, cf.attrs("q_max"))}
    if nB:
        coords.update(_bounds_coords(qb))
        data["escape_cycle_bounds"] = (("control", "q_bounds", "q0", "p0"), tQ[:, nQ:], cf.attrs("escape_cycle_bounds"))
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update(Psi=Psi, cycles=cycles, steps_per_cycle=spc, integrator=engine.integrator_text(integrator, damping),
                    escape_criteria=criteria.criteria_text(w), safe_basin="escape_cycle > t_eval (t_eval <= cycles)",
                    **w.numerics_attrs(), **engine.damping_attrs(damping))
    return ds
