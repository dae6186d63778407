"""Escape under noise: escape probabilities of the Langevin equation from ensembles of paths.

    dq = p dt,    dp = (-beta p - V'(q) + F sin(Omega t + Psi)) dt + sigma dW

(additive white noise: Ito and Stratonovich agree; thermal noise at temperature T is
sigma^2 = 2 beta T).  :func:`escape_probability` integrates ``paths`` paths from every initial
condition with the compiled lanes of numerics.noise_kernels (the Strang splitting of the noise
around the engine's deterministic step: weak order 2; counter-based Philox streams keyed by
(seed, initial condition, path, step)), or their CUDA twin numerics.cuda_noise (the same escape
steps bitwise), and escapes by the criteria of
:func:`~safebasins.numerics.escape_chart` (energy H0 > xi_max or q beyond a barrier; a NaN state
counts as escaped), checked after every step.  At sigma = 0 every path is the engine's
trajectory, bitwise: the escape times are escape_chart's.  docs/noise.md: the model, the scheme
and its measured weak order, the boundary correction and the Kramers check.
"""
from __future__ import annotations

import importlib
import math
from types import ModuleType

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.core import cf, checks, noise_variates
from safebasins.core.statistics import WILSON_Z, wilson_interval
from safebasins.numerics import criteria, engine, noise_kernels, schemes
from safebasins.numerics.charts import ic_coords
from safebasins.numerics.problem import check_cycles, ensemble_problem
from safebasins.wells import resolve_well
from safebasins.wells.base import WellLike
from safebasins.wells.provenance import api_provenance

__all__ = ["escape_probability", "wilson_interval", "CORRECTIONS", "GOBET_SHIFT", "BOUNDARY_SHIFTS", "VARIATES",
           "WILSON_Z", "energy_shift"]

#: beta_1 = -zeta(1/2) / sqrt(2 pi): the boundary shift, in units of the local volatility times
#: sqrt(h), that removes the O(sqrt(h)) bias of a discretely monitored killed diffusion
#: (Broadie, Glasserman & Kou 1997; Gobet & Menozzi 2010)
GOBET_SHIFT = 0.5825971579390106
#: the variates' laws (noise_kernels): "gaussian" (Box-Muller; the default) or "five-point"
#: (0, +-sqrt 2, +-2 with probabilities 5/8, 1/8, 1/16: the Gaussian's moments through the fifth, weak
#: order 2 as well, one Philox block per 16 steps)
VARIATES = noise_variates.VARIATES
#: beta_1 per law: the mean overshoot, in units of sigma ``|p|`` sqrt(h), of the random walk whose
#: steps are a step's two kicks, (Z_1 + Z_2) / sqrt 2, over a level far away (Siegmund's corrected
#: diffusion approximation: the same shift of the boundary removes the O(sqrt h) bias).  Gaussian:
#: -zeta(1/2)/sqrt(2 pi); five-point: -(1/pi) int_0^inf t^-2 log(2 (1 - phi(t)) / t^2) dt with phi the
#: characteristic function of that step (Spitzer's identity; docs/noise.md;
#: tests/numerics/test_noise_variates.py recomputes both)
BOUNDARY_SHIFTS = {"gaussian": GOBET_SHIFT, "five-point": 0.6504667}
#: the discrete-monitoring corrections: "shift" (the energy threshold moved inwards by
#: GOBET_SHIFT sigma ``|p|`` sqrt(h), the local volatility of H0 being sigma ``|p|``) or "none"
CORRECTIONS = ("shift", "none")
#: the backends of the noisy ensemble, as the engine's: the CPU lanes (noise_kernels, the
#: reference), the CUDA kernel (cuda_noise: bitwise the same escape steps) or "auto" (the GPU when
#: one is visible)
NOISE_BACKENDS = engine.BACKENDS
#: paths in flight per task
LANES = 256
#: at most this many points on the survival curve's time axis
SURVIVAL_POINTS = 256

SCHEME_TEXT = ("Strang splitting p += a Z_1, deterministic step, p += a Z_2 with a = sigma sqrt(h/2), Z_i "
               "standard normal (the exact flow of the noise over h/2 around the deterministic scheme's step; "
               "weak order 2)")
COLOURED_SCHEME_TEXT = ("Strang splitting eta = c1 eta + c2 Z_1, deterministic step with the force eta held "
                        "constant, eta = c1 eta + c2 Z_2 (the exact Ornstein-Uhlenbeck flow over h/2 around the "
                        "deterministic scheme's step; weak order 2)")
RNG_TEXTS = {
    "gaussian": ("Philox4x32-10 with counter (step, path, initial condition, 0) and key (seed mod 2^32, seed div "
                 "2^32); Box-Muller pair from its two 53-bit uniforms (wells.elementary log, sqrt, sincos)"),
    "five-point": ("Philox4x32-10 with counter (block, path, initial condition, 2) and key (seed mod 2^32, seed div "
                   "2^32), block = period * ceil(S/16) + sub-step div 16; the sub-step's byte of the block gives "
                   "Z_1, Z_2 from its low and high nibble t: +sqrt 2 (t < 2), -sqrt 2 (t < 4), +2 (t = 4), -2 "
                   "(t = 5), 0 otherwise; eta(0) Box-Muller of counter (0, path, initial condition, 1)"),
}


def energy_shift(sigma: float, h: float, correction: str, noise_time: float = 0.0, variates: str = "gaussian"
                 ) -> float:
    """The shift of 2 xi_max per ``|p|`` (noise_kernels): 2 beta_1 sigma sqrt(h) for "shift" and
    white noise, beta_1 the law's (BOUNDARY_SHIFTS); 0 for "none" and for coloured noise (p is then
    differentiable in time: no O(sqrt(h)) monitoring bias to correct)."""
    if correction != "shift" or noise_time != 0.0:
        return 0.0
    return 2.0 * BOUNDARY_SHIFTS[variates] * sigma * math.sqrt(h)


def _check_seed(seed: object) -> int:
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= int(seed) < 2 ** 63:
        raise ValueError(f"seed must be an integer in [0, 2^63), got {seed!r}")
    return int(seed)


def _check_choice(name: str, value: object, allowed: tuple[str, ...]) -> str:
    if not isinstance(value, str) or value not in allowed:
        raise ValueError(f"{name} must be one of {allowed}, got {value!r}")
    return value


def _survival_axis(cycles: int) -> np.ndarray:
    if cycles <= SURVIVAL_POINTS:
        return np.arange(cycles + 1, dtype=float)
    return np.linspace(0.0, float(cycles), SURVIVAL_POINTS + 1)


def _counts_within(tc: np.ndarray, times: np.ndarray) -> np.ndarray:
    """(n_ic, len(times)): how many paths of each initial condition escaped at or before each time."""
    srt = np.sort(tc, axis=1)
    return np.stack([np.searchsorted(row, times, side="right") for row in srt]) if srt.shape[0] else (
        np.zeros((0, times.size), np.int64))


@api_provenance
def escape_probability(q0: npt.ArrayLike, p0: npt.ArrayLike, F: float, Omega: float, Psi: float, *, noise: float,
                       paths: int, xi_max: float, t_eval: npt.ArrayLike, damping: float = 0.0, well: WellLike = None,
                       seed: int = 0, cycles: int | None = None, noise_time: float = 0.0,
                       steps_per_cycle: int = engine.DEFAULT_STEPS_PER_CYCLE, grid: bool | None = None,
                       correction: str = "shift", integrator: str = engine.DEFAULT_INTEGRATOR,
                       threads: int | None = None, backend: str = "cpu",
                       variates: str = noise_variates.DEFAULT_VARIATES,
                       ic_offset: int = 0, path_offset: int = 0) -> xr.Dataset:
    """Probability of escape within each ``t_eval`` under noise, from ``paths`` paths per initial condition.

    Parameters
    ----------
    q0, p0, grid : initial conditions as :func:`~safebasins.numerics.escape_chart` (a grid of
        1-D axes -> dims (q0, p0); paired -> dim sample).
    F, Omega, Psi, damping, well, integrator, steps_per_cycle : the equation and the deterministic
        scheme, as escape_chart (its damped variant for damping > 0).
    noise : sigma >= 0, the amplitude of the white noise dp = ... + sigma dW (thermal noise at
        temperature T: sigma^2 = 2 damping T).  0: every path is escape_chart's trajectory.
    noise_time : tau >= 0, the correlation time of coloured noise (default 0: white): the force
        eta in dp = (... + eta) dt is the Ornstein-Uhlenbeck process d eta = -(eta / tau) dt +
        (sigma / tau) dW, started from its stationary law N(0, sigma^2 / (2 tau)), with
        autocorrelation sigma^2 / (2 tau) exp(-``|t|`` / tau) and the white noise's integrated
        intensity (the integral of the autocorrelation is sigma^2; tau -> 0 is white noise).  The
        step must resolve it: a step h = 2 pi / (Omega steps_per_cycle) > tau is refused.
    paths : paths per initial condition (positive integer).
    xi_max : the energy threshold (a scalar in (0, barrier energy]): escape when H0 > xi_max or q
        beyond a barrier, checked after every step; or a 1-D sequence of thresholds, all from one
        pass (each path runs until it is beyond the largest): the Dataset's variables gain the
        dimension ``xi_max`` after the initial conditions'.
    t_eval : evaluation times in forcing cycles (>= 0, up to ``cycles``).
    seed : integer in [0, 2^63): the key of the Philox streams; path m of initial condition i
        draws the same numbers for any threads, lanes or order (numerics.noise_kernels).
    cycles : the horizon in forcing cycles (None: the largest t_eval rounded up); the first-passage
        mean is restricted to it.
    correction : "shift" (default: the energy threshold moved inwards by beta_1 sigma ``|p|``
        sqrt(h), beta_1 = BOUNDARY_SHIFTS[variates], removing the O(sqrt(h)) bias of checking the
        threshold only at the steps) or "none".
    variates : the law of the kicks' random numbers: "gaussian" (default: Box-Muller pairs) or
        "five-point" (0, +-sqrt 2, +-2 with probabilities 5/8, 1/8, 1/16 each: the same moments
        through the fifth, so the same weak order 2, at about three times the speed: one Philox
        block serves 16 steps).  The two laws draw different paths: their P_escape agree within the
        weak error and the sampling error, not bitwise.
    ic_offset, path_offset : integers >= 0 (default 0): the index of the first initial condition and
        of the first path in the random counters, so that a chunk of a larger ensemble draws that
        ensemble's streams: the paths m0 .. m0 + paths - 1 of the initial conditions i0, i0 + 1, ...
        (the initial conditions in the order of the sample, or of the grid flattened with q0
        outermost).  Chunks run with their offsets give, together, the escape steps of one run.
    threads : numba threads of the CPU backend (None: the current setting); the result does not
        depend on it.
    backend : "cpu" (default: the compiled CPU lanes, the reference), "cuda" (numerics.cuda_noise
        on a CUDA GPU, or numba's CUDA simulator: the same escape steps bitwise, so the same
        Dataset) or "auto" (the GPU when numba-cuda sees one, else the CPU).

    Returns
    -------
    xr.Dataset with P_escape (ic dims, t_eval): the fraction of paths escaped at or before t_eval,
    its 95% Wilson interval P_escape_low, P_escape_high; survival (ic dims, t_survival), the
    fraction not escaped by t_survival (every forcing cycle up to 256 cycles, else 257 points);
    first_passage_mean (ic dims): the restricted mean first-passage time E[min(tau, cycles)]
    in forcing cycles with its standard error first_passage_sem (NaN for paths = 1: not
    estimable) and censored_fraction, the fraction of paths not escaped within cycles (where it
    is 0 the restricted mean is the mean first-passage time; otherwise a lower bound of it).
    Attributes: the equation, noise (and noise_time), paths, seed, the scheme, the random
    numbers, the correction, the escape criteria and the well.
    """
    is_grid, qa, pa, Q, P = checks.initial_conditions(q0, p0, grid)
    F = checks.check_scalar("F", F, checks.check_nonnegative)
    Omega = checks.check_scalar("Omega", Omega, checks.check_positive)
    Psi = checks.check_scalar("Psi", Psi, checks.check_finite)
    damping = checks.check_damping(damping)
    sigma = checks.check_scalar("noise", noise, checks.check_nonnegative)
    tau = checks.check_scalar("noise_time", noise_time, checks.check_nonnegative)
    paths = checks.check_positive_int("paths", paths)
    w = resolve_well(well)
    several = np.ndim(xi_max) > 0
    xi = engine.thresholds("xi_max", xi_max, w.check_threshold)
    if xi.size == 0 or not np.isfinite(xi).all():
        raise ValueError(f"xi_max must be one or more finite energies, got {xi_max!r}")
    te = checks.check_1d("t_eval", t_eval, checks.check_nonnegative)
    cycles = check_cycles("cycles", max(1, math.ceil(float(te.max()))) if cycles is None else cycles)
    if te.max() > cycles:
        raise ValueError(f"t_eval must be <= cycles = {cycles}, got max {float(te.max())!r}")
    seed = _check_seed(seed)
    correction = _check_choice("correction", correction, CORRECTIONS)
    variates = _check_choice("variates", variates, VARIATES)
    gpu = _cuda_backend(_check_choice("backend", backend, NOISE_BACKENDS))
    schemes.check_integrator(integrator)
    spc = engine.check_step(Omega, engine.check_steps_per_cycle(steps_per_cycle), w, integrator)
    threads = engine.check_threads(threads)
    h = 2.0 * math.pi / (Omega * spc)
    if 0.0 < tau < h:
        # the splitting holds eta constant over a step: on the damped oscillator the variance's
        # relative error is ~0.1 (h / tau)^2 (docs/noise.md), unbounded as tau -> 0 at fixed h
        raise ValueError(f"noise_time = {tau:.4g} is shorter than the step h = {h:.4g} ({spc} steps per forcing "
                         f"cycle at Omega = {Omega:.4g}): the coloured noise is not resolved; use steps_per_cycle >= "
                         f"{math.ceil(2.0 * math.pi / (Omega * tau))} or noise_time = 0 (white noise)")
    if cycles * spc > noise_kernels.MAX_STEPS:
        raise ValueError(f"cycles: {cycles} cycles of {spc} steps exceed {noise_kernels.MAX_STEPS} steps per path")
    # the path and the IC index are 32-bit words of the random counter: beyond, streams would repeat
    if paths > 2 ** 32:
        raise ValueError(f"paths must be <= 2^32 (a word of the random counter), got {paths}")
    if Q.size > 2 ** 32:
        raise ValueError(f"q0 and p0: at most 2^32 initial conditions (a word of the random counter), got {Q.size}")
    noise_kernels.check_offsets((ic_offset, path_offset), Q.size, paths)

    problem = ensemble_problem(Q, P, np.zeros(Q.size, np.int64), [Omega], [F], Psi, xi_max=xi, cycles=cycles,
                               steps_per_cycle=spc, integrator=integrator, well=w, damping=damping)
    h = float(problem.step_sizes()[0])              # (the same h, as the engine forms it)
    # one argument list, either backend (cuda_noise.escape_steps takes noise_kernels.escape_steps's)
    args = (problem.code, problem.scheme, Q, P, paths, problem.coefficients(), problem.sine_table(), F,
            problem.thrE2 if several else float(problem.thrE2[0]), cycles,
            noise_kernels.step_noise(sigma, h, tau, noise_kernels.LAWS[variates]), seed)
    shift = energy_shift(sigma, h, correction, tau, variates)
    offsets = dict(ic_offset=ic_offset, path_offset=path_offset)
    if gpu is not None:
        steps = gpu.escape_steps(*args, shift=shift, ic_offset=ic_offset, path_offset=path_offset)
    else:
        with engine.thread_count(threads) as nthreads:
            n_tasks = max(1, min(math.ceil(Q.size * paths / LANES), nthreads))
            steps = noise_kernels.escape_steps(*args, shift=shift, n_tasks=n_tasks, lanes=LANES,
                                               ic_offset=ic_offset, path_offset=path_offset)
    ts = _survival_axis(cycles)
    if several:                 # the sorted thresholds' columns, in the caller's order
        caller = np.empty_like(steps)
        caller[..., problem.order_E] = steps
        stats = [_path_statistics(engine.steps_to_cycles(caller[..., k], spc), te, ts, cycles)
                 for k in range(xi.size)]
        # (n_ic, xi_max, ...): the threshold axis after the initial conditions'
        columns = {name: np.stack([st[name] for st in stats], axis=1) for name in stats[0]}
    else:
        columns = _path_statistics(engine.steps_to_cycles(steps, spc), te, ts, cycles)

    shape, dims, coords = ic_coords(is_grid, qa, pa, Q, P)
    if several:
        coords["xi_max"] = ("xi_max", xi, cf.attrs("xi_max"))
    coords["t_eval"] = ("t_eval", te, cf.attrs("t_eval"))
    coords["t_survival"] = ("t_survival", ts, cf.attrs("t_survival"))
    thr_dims: tuple[str, ...] = ("xi_max",) if several else ()

    def field(name: str, last: tuple[str, ...] = ()) -> tuple[tuple[str, ...], np.ndarray, dict[str, str]]:
        a = columns[name]
        return dims + thr_dims + last, a.reshape(shape + a.shape[1:]), cf.attrs(name)

    data = {name: field(name, last) for name, last in _FIELDS.items()}
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update(
        F=F, Omega=Omega, Psi=Psi, **({} if several else {"xi_max": float(xi[0])}), noise=sigma, paths=paths,
        seed=seed, cycles=cycles, steps_per_cycle=spc,
        noise_model=_model_text(tau), integrator=engine.integrator_text(integrator, damping),
        noise_scheme=SCHEME_TEXT if tau == 0 else COLOURED_SCHEME_TEXT, variates=variates,
        random_numbers=RNG_TEXTS[variates], boundary_correction=_correction_text(correction, tau, variates),
        first_passage=("restricted mean E[min(tau, cycles)] in forcing cycles; censored_fraction of the paths had "
                       "not escaped within cycles (the mean first-passage time where it is 0, a lower bound "
                       "otherwise)"),
        grid=int(is_grid), escape_criteria=criteria.criteria_text(w), **w.numerics_attrs(),
        **engine.damping_attrs(damping), **({"noise_time": tau} if tau > 0 else {}),
        **{k: int(v) for k, v in offsets.items() if v})
    return ds


#: the Dataset's variables and their dimensions after the initial conditions' (and xi_max)
_FIELDS: dict[str, tuple[str, ...]] = {
    "P_escape": ("t_eval",), "P_escape_low": ("t_eval",), "P_escape_high": ("t_eval",), "survival": ("t_survival",),
    "first_passage_mean": (), "first_passage_sem": (), "censored_fraction": ()}


def _path_statistics(tc: np.ndarray, te: np.ndarray, ts: np.ndarray, cycles: int) -> dict[str, np.ndarray]:
    """The _FIELDS of one threshold from the escape cycles tc (n_ic, paths; inf: not within cycles)."""
    paths = tc.shape[1]
    k_eval = _counts_within(tc, te)
    low, high = wilson_interval(k_eval, paths)
    restricted = np.minimum(tc, float(cycles))
    # one path has no spread to estimate the standard error from: NaN, as documented
    sem = restricted.std(axis=1, ddof=1) / math.sqrt(paths) if paths > 1 else np.full(tc.shape[0], np.nan)
    return {"P_escape": k_eval / paths, "P_escape_low": low, "P_escape_high": high,
            "survival": 1.0 - _counts_within(tc, ts) / paths, "first_passage_mean": restricted.mean(axis=1),
            "first_passage_sem": sem, "censored_fraction": np.isinf(tc).mean(axis=1)}


def _cuda_backend(backend: str) -> ModuleType | None:
    """numerics.cuda_noise when ``backend`` resolves to "cuda" (engine.resolve_backend), None for the
    CPU: ImportError naming the extra without numba-cuda, RuntimeError without a GPU or the
    simulator, before anything runs."""
    if engine.resolve_backend(backend) != "cuda":
        return None
    engine.cuda_engine().require_cuda()
    return importlib.import_module("safebasins.numerics.cuda_noise")


def _model_text(tau: float) -> str:
    if tau == 0:
        return "dp = (-beta p - V'(q) + F sin(Omega t + Psi)) dt + sigma dW (white, additive; sigma = noise)"
    return ("dp = (-beta p - V'(q) + F sin(Omega t + Psi) + eta) dt, d eta = -(eta / tau) dt + (sigma / tau) dW "
            "(coloured: Ornstein-Uhlenbeck force, tau = noise_time, sigma = noise, eta(0) stationary)")


def _correction_text(correction: str, tau: float, variates: str) -> str:
    if tau > 0:
        return "none needed: p is differentiable in time under coloured noise"
    if correction == "shift":
        source = "Gobet-Menozzi" if variates == "gaussian" else "Siegmund's mean overshoot of the five-point walk"
        return f"energy threshold shifted inwards by {BOUNDARY_SHIFTS[variates]} sigma |p| sqrt(h) ({source})"
    return "none: checked after every step only"

