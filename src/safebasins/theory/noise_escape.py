"""Escape under noise from the averaged theory: escape probabilities and mean first-passage times.

The slow flow of the 1:1 resonance with white noise ``sigma dW`` on the momentum, averaged over the
fast angle (:mod:`safebasins.theory.noise_averaging`), is a diffusion in ``(gamma, J)``; its
backward Kolmogorov equation, absorbing at ``J(xi_max)``, is solved on a polar grid of the regular
frame (:mod:`safebasins.theory.noise_solver`).  Each initial condition ``(q0, p0)`` at tau = 0 is
mapped to ``(theta0, xi_ini)`` of the unforced well (eqs 7, 14), ``gamma = theta0 - Psi``, as in
:func:`~safebasins.theory.slow_flow_escapes`; ICs at or beyond ``xi_max`` or outside the well
escape at t = 0.  docs/noise-theory.md: the derivation, the checks and the agreement with the SDE
ensembles of :func:`safebasins.numerics.escape_probability`.
"""
from __future__ import annotations

import math

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from safebasins.core import cf, checks
from safebasins.core.averaged_theory import CELLS, STEPS_PER_CYCLE, check_cells, theory_cycles
from safebasins.theory.noise_averaging import AveragedDiffusion, averaged_diffusion
from safebasins.theory.noise_semilagrangian import escape_times, march_escape_sl
from safebasins.theory.noise_solver import ADVECTION, DiscGrid, generator, interpolation, march_escape, \
    solve_first_passage
from safebasins.theory.types import FloatArray, WellArg
from safebasins.wells import resolve_well
from safebasins.wells.base import Well
from safebasins.wells.provenance import api_provenance

__all__ = ["escape_probability", "mean_first_passage", "solve_evaluations", "SCHEMES"]

#: the advection of the time march: semi-Lagrangian (noise_semilagrangian) or the finite volumes'
SCHEMES = ("semi-lagrangian",) + ADVECTION
#: how far outside [0, 1] an Eulerian march may go before its oscillations are an error
RANGE_TOL = 0.02
#: slow-flow evaluations (safebasins.pipeline.cost's unit, 1e6 per second) of one semi-Lagrangian
#: solve past its coefficient tables, measured on one core of the shared 2.5 GHz Xeon test machine
#: (quartic and pendulum, 128 x 160 cells, 21^2 and 201^2 ICs, 1 and 20 cycles): per cell and time
#: step (0.7-0.8 us), per cell of the set-up (departure points, advection matrix, LU factors: 15 us),
#: per IC (its action-angle point and the interpolation: up to 5 us) and per IC and time step (0.2 us)
CELL_STEP_EVALUATIONS = 1
CELL_SETUP_EVALUATIONS = 20
IC_EVALUATIONS = 5
IC_STEP_EVALUATIONS = 0.2

MODEL_TEXT = ("averaged diffusion of the slow flow (gamma, J) under dp = ... + sigma dW: drift dC/dJ, -dC/dgamma - "
              "beta J plus the noise-induced (sigma^2/2) d(J/omega)/dJ; diffusion sigma^2 J/omega (action), sigma^2 "
              "<q_J^2> (phase), no J-phase covariance (for an asymmetric well in the sheared phase gamma + delta(J), "
              "where it vanishes); docs/noise-theory.md")
COLOURED_MODEL_TEXT = ("averaged diffusion of the slow flow (gamma, J) under an Ornstein-Uhlenbeck force of "
                       "correlation time tau (noise_time) and intensity sigma^2: drift dC/dJ, -dC/dgamma - beta J "
                       "plus the noise-induced (sigma^2/2) dm_JJ/dJ; diffusion sigma^2 m_JJ (action), sigma^2 m_gg "
                       "(phase), the orbit's harmonics k weighted by 1/(1 + k^2 omega^2 tau^2) (m_gg with the shear "
                       "of the orbits over a correlation time); J-gamma covariance and phase drift of order tau left "
                       "out; for tau short against the slow time; docs/noise-theory.md")

NOISE_FREE_TEXT = ("the averaged theory at sigma = 0: the deterministic slow flow (gamma, J) (drift dC/dJ, -dC/dgamma "
                   "- beta J), P_escape 0 or 1 from each initial condition's first passage of xi_max; "
                   "docs/noise-theory.md")


def _setup(q0: ArrayLike, p0: ArrayLike, F: float, Omega: float, Psi: float, xi_max: float, noise: float,
           damping: float, well: WellArg, grid: bool | None, cells: tuple[int, int], advection: str,
           schemes: tuple[str, ...], noise_time: float
           ) -> tuple[Well, dict[str, float], tuple[bool, FloatArray, FloatArray, FloatArray, FloatArray], DiscGrid,
                      AveragedDiffusion]:
    """Checked arguments (ValueError naming the argument before anything runs)."""
    w = resolve_well(well)
    par = {"F": checks.check_scalar("F", F, checks.check_nonnegative),
           "Omega": checks.check_scalar("Omega", Omega, checks.check_positive),
           "Psi": checks.check_scalar("Psi", Psi, checks.check_finite),
           "xi_max": checks.check_scalar("xi_max", xi_max, w.check_analytic_threshold),
           "noise": checks.check_scalar("noise", noise, checks.check_nonnegative),
           "damping": checks.check_damping(damping),
           "noise_time": checks.check_scalar("noise_time", noise_time, checks.check_nonnegative)}
    if advection not in schemes:
        raise ValueError(f"advection must be one of {schemes}, got {advection!r}")
    n_gamma, n_J = check_cells(cells)
    ics = checks.initial_conditions(q0, p0, grid)
    diff = averaged_diffusion(w, par["xi_max"], noise_time=par["noise_time"])
    return w, par, ics, DiscGrid(n_gamma, n_J, diff.J_max), diff


def solve_evaluations(n_ics: int, t_eval: ArrayLike, cells: tuple[int, int] = CELLS,
                      steps_per_cycle: int = STEPS_PER_CYCLE) -> int:
    """Upper-bound slow-flow evaluations of one :func:`escape_probability` solve on ``n_ics``
    initial conditions (its march to the horizon of ``t_eval`` and its set-up; the coefficient
    tables, shared by the solves of a well, are
    :func:`~safebasins.theory.noise_averaging.table_evaluations`)."""
    steps = theory_cycles(t_eval) * steps_per_cycle
    n_cells = cells[0] * cells[1]
    return math.ceil(n_cells * (steps * CELL_STEP_EVALUATIONS + CELL_SETUP_EVALUATIONS)
                     + n_ics * (IC_EVALUATIONS + steps * IC_STEP_EVALUATIONS))


def _slow_points(w: Well, Q: FloatArray, P: FloatArray, Psi: float, xi_max: float, diff: AveragedDiffusion
                 ) -> tuple[np.ndarray, FloatArray, FloatArray]:
    """``(inside, phase, J)`` of the ICs inside the well and below xi_max; the phase of the
    tables: gamma, or for an asymmetric well the sheared ``gamma + delta(xi)``."""
    H = np.asarray(w.H0(Q, P), float)
    inside = np.asarray(w.in_well(Q), bool) & (H < xi_max)
    theta, xi = w.angle_energy(Q[inside], P[inside])
    phase = np.asarray(theta, float) - Psi
    if not diff.symmetric:
        phase = phase + np.asarray(w.harmonic_shift(xi), float)
    return inside, phase, np.asarray(w.J(xi), float)


def _coords(is_grid: bool, qa: FloatArray, pa: FloatArray, Q: FloatArray, P: FloatArray
            ) -> tuple[tuple[int, ...], tuple[str, ...], dict[str, object]]:
    if is_grid:
        return (qa.size, pa.size), ("q0", "p0"), {"q0": ("q0", qa, cf.attrs("q0")), "p0": ("p0", pa, cf.attrs("p0"))}
    return (Q.size,), ("sample",), {"sample": ("sample", np.arange(Q.size), cf.attrs("sample")),
                                    "q0": ("sample", Q, cf.attrs("q0")), "p0": ("sample", P, cf.attrs("p0"))}


def _attrs(par: dict[str, float], w: Well, grid: DiscGrid, advection: str) -> dict[str, object]:
    model = COLOURED_MODEL_TEXT if par["noise_time"] > 0 else MODEL_TEXT
    solver = (f"finite volumes on {grid.n_gamma} x {grid.n_J} cells uniform in (gamma, J) (equal-area polar "
              f"grid of X + iY = sqrt(2J) e^(i gamma)), {advection} advection, absorbing at J(xi_max)")
    if par["noise"] == 0:
        model, solver = NOISE_FREE_TEXT, ("RK4 along each initial condition's slow trajectory (the semi-Lagrangian "
                                          "march's characteristics), escape at its first passage of J(xi_max)")
    return {**par, "noise_model": model, "theory": "averaged (stochastic slow flow)", "solver": solver,
            "escape_criteria": f"averaged energy xi reaches xi_max = {par['xi_max']!r}", **w.numerics_attrs()}


@api_provenance
def escape_probability(q0: ArrayLike, p0: ArrayLike, F: float, Omega: float, Psi: float, xi_max: float, *,
                       noise: float, t_eval: ArrayLike, damping: float = 0.0, well: WellArg = None,
                       grid: bool | None = None, cells: tuple[int, int] = CELLS,
                       steps_per_cycle: int = STEPS_PER_CYCLE, advection: str = "semi-lagrangian",
                       noise_time: float = 0.0) -> xr.Dataset:
    """Probability of escape within each ``t_eval`` (forcing cycles) from the averaged theory.

    ``q0, p0, grid``: initial conditions at tau = 0 as :func:`safebasins.numerics.escape_probability`
    reads them (1-D axes -> dims (q0, p0), paired -> sample); ``F, Omega, Psi, xi_max``: as
    :func:`~safebasins.theory.slow_flow_escapes`; ``noise``: sigma >= 0 of ``dp = ... + sigma dW``
    (0: the noise-free slow flow, P_escape 0 or 1 from each IC's slow trajectory);
    ``noise_time``: tau >= 0, an Ornstein-Uhlenbeck force of correlation time tau and intensity
    sigma^2 instead (its spectrum at the orbit's harmonics weights the diffusion; valid for tau short
    against the slow time, docs/noise-theory.md); ``damping``: beta >= 0; ``well``: any well
    (default the quartic; an asymmetric well is solved in its sheared phase).  ``cells``: the polar
    grid ``(n_gamma, n_J)``; ``steps_per_cycle``:
    time steps per forcing cycle;
    ``advection``: "semi-lagrangian" (default: exact characteristics of the slow flow, quasi-monotone
    bicubic interpolation, Strang-split implicit diffusion; values in [0, 1] at any noise), or the
    finite volumes' BDF2 march with "central" (second order; oscillates where the cell Peclet
    number is large, and then raises an error naming ``cells``) or "upwind" (monotone, numerically
    diffusive) fluxes.

    Returns a Dataset with ``P_escape`` (ic dims, t_eval) and ``first_passage_mean`` (ic dims), the
    restricted mean ``E[min(tau, cycles)]`` in forcing cycles, ``cycles = ceil(max t_eval)`` (the
    numerics' names and horizon); attributes: the parameters, the model and the solver.
    """
    w, par, (is_grid, qa, pa, Q, P), dgrid, diff = _setup(q0, p0, F, Omega, Psi, xi_max, noise, damping, well,
                                                          grid, cells, advection, SCHEMES, noise_time)
    te = checks.check_1d("t_eval", t_eval, checks.check_nonnegative)
    spc = checks.check_positive_int("steps_per_cycle", steps_per_cycle)
    cycles = theory_cycles(te)
    inside, gamma, J = _slow_points(w, Q, P, par["Psi"], par["xi_max"], diff)
    period = 2.0 * np.pi / par["Omega"]
    if par["noise"] == 0:
        # the noise-free limit: each IC's slow trajectory, P = 1 from its first passage on
        T = escape_times(diff, par["F"], par["Omega"], par["damping"], gamma, J, cycles * period, cycles * spc)
        return _dataset(par, w, dgrid, advection, is_grid, qa, pa, Q, P, te, inside,
                        (T[:, None] <= te[None, :] * period).astype(float), np.minimum(T / period, cycles),
                        cycles, spc)
    W, w_b = interpolation(dgrid, gamma, J)
    if advection == "semi-lagrangian":
        t, Pt = march_escape_sl(dgrid, diff, par["F"], par["Omega"], par["damping"], par["noise"], W, w_b,
                                cycles * period, cycles * spc)
    else:
        M, s = generator(dgrid, diff, par["F"], par["Omega"], par["damping"], par["noise"], advection)
        t, Pt, (lo, hi) = march_escape(M, s, W, w_b, cycles * period, cycles * spc)
        if lo < -RANGE_TOL or hi > 1 + RANGE_TOL:
            raise ValueError(f"cells: the {advection} finite volumes oscillate on {dgrid.n_gamma} x {dgrid.n_J} cells "
                             f"at noise = {par['noise']!r} (values from {lo:.3g} to {hi:.3g}): the cell Peclet number "
                             "is too large; use advection='semi-lagrangian' (the default) or finer cells")
    t = t / period
    P_in = np.stack([np.interp(te, t, col) for col in Pt.T]) if Pt.shape[1] else np.zeros((0, te.size))
    surv = 1.0 - Pt
    fp_in = np.sum(0.5 * (surv[1:] + surv[:-1]) * np.diff(t)[:, None], axis=0)
    return _dataset(par, w, dgrid, advection, is_grid, qa, pa, Q, P, te, inside, P_in, fp_in, cycles, spc)


def _dataset(par: dict[str, float], w: Well, dgrid: DiscGrid, advection: str, is_grid: bool, qa: FloatArray,
             pa: FloatArray, Q: FloatArray, P: FloatArray, te: FloatArray, inside: np.ndarray, P_in: FloatArray,
             fp_in: FloatArray, cycles: int, spc: int) -> xr.Dataset:
    """:func:`escape_probability`'s Dataset from the values at the ICs inside (the others escape at 0)."""
    P_all = np.ones((Q.size, te.size))
    P_all[inside] = P_in
    fp = np.zeros(Q.size)
    fp[inside] = fp_in
    shape, dims, coords = _coords(is_grid, qa, pa, Q, P)
    coords["t_eval"] = ("t_eval", te, cf.attrs("t_eval"))
    ds = xr.Dataset({"P_escape": (dims + ("t_eval",), P_all.reshape(shape + (te.size,)), cf.attrs("P_escape")),
                     "first_passage_mean": (dims, fp.reshape(shape), cf.attrs("first_passage_mean"))},
                    coords=coords)
    ds.attrs.update(_attrs(par, w, dgrid, advection), cycles=cycles, steps_per_cycle=spc, grid=int(is_grid))
    return ds


@api_provenance
def mean_first_passage(q0: ArrayLike, p0: ArrayLike, F: float, Omega: float, Psi: float, xi_max: float, *,
                       noise: float, damping: float = 0.0, well: WellArg = None, grid: bool | None = None,
                       cells: tuple[int, int] = CELLS, advection: str = "central", noise_time: float = 0.0
                       ) -> xr.Dataset:
    """Mean first-passage time to ``xi_max`` (forcing cycles) of the averaged theory, from the
    stationary backward equation ``L T = -1`` on the finite volumes (``advection`` "central" or
    "upwind"; a central solution with negative times, unresolved cell Peclet numbers, raises an
    error naming ``cells``); other arguments as :func:`escape_probability`.  Returns a Dataset with
    ``mean_first_passage`` (ic dims; 0 for ICs at or beyond xi_max)."""
    if checks.check_scalar("noise", noise, checks.check_nonnegative) == 0:
        raise ValueError("noise must be > 0 for the mean first-passage time (at noise 0 a slow trajectory that "
                         "settles never escapes); escape_probability gives the noise-free first passages")
    w, par, (is_grid, qa, pa, Q, P), dgrid, diff = _setup(q0, p0, F, Omega, Psi, xi_max, noise, damping, well,
                                                          grid, cells, advection, ADVECTION, noise_time)
    inside, gamma, J = _slow_points(w, Q, P, par["Psi"], par["xi_max"], diff)
    M, _ = generator(dgrid, diff, par["F"], par["Omega"], par["damping"], par["noise"], advection)
    W, _ = interpolation(dgrid, gamma, J)
    T_in, T_min = solve_first_passage(M, W)
    if T_min < 0:
        raise ValueError(f"cells: the {advection} finite volumes oscillate on {dgrid.n_gamma} x {dgrid.n_J} cells at "
                         f"noise = {par['noise']!r} (negative first-passage times): the cell Peclet number is too "
                         "large; use finer cells or advection='upwind' (monotone, numerically diffusive)")
    T = np.zeros(Q.size)
    T[inside] = T_in * par["Omega"] / (2.0 * np.pi)
    shape, dims, coords = _coords(is_grid, qa, pa, Q, P)
    ds = xr.Dataset({"mean_first_passage": (dims, T.reshape(shape), cf.attrs("mean_first_passage"))}, coords=coords)
    ds.attrs.update(_attrs(par, w, dgrid, advection), grid=int(is_grid))
    return ds
