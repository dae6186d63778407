"""The ``escape-probability`` command: escape probabilities under noise over a grid of initial
conditions (:func:`safebasins.numerics.escape_probability`, docs/noise.md)."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import click

from safebasins.cli.commands import check_step, damping_text, grid_axes, well_label
from safebasins.cli.options import (NONNEG, THRESHOLD, Deferred, Fields, Number, NumberList, checked,
                                    common_options, cost_guard, current_well, damping_option, forcing_options,
                                    from_library, grid_options, grid_params, joined, lib_check, library_errors,
                                    no_fourier, out_option, steps_option, threads_option)
from safebasins.cli.output import chatter, draw, finish, write_outputs
from safebasins.core.averaged_theory import CELLS, MIN_CELLS, STEPS_PER_CYCLE, check_cells
from safebasins.core.noise_variates import VARIATES
from safebasins.pipeline.cost import NOISE_STEP_COSTS
from safebasins.pipeline.values import fmt

__all__ = ["escape_probability", "theory_options", "noise_options", "theory_settings", "THEORY_REDUCE"]

#: the library function whose defaults the options take
LIBRARY = "safebasins.numerics:escape_probability"
#: at most this many --t-eval values (one panel each)
MAX_T_EVAL = 4
#: what the cost guard suggests where the averaged theory's solve is over the analytic budget
THEORY_REDUCE = "--theory-cells, --theory-steps-per-cycle or the largest --t-eval (or pass --no-theory)"


def theory_options(f: Any) -> Any:
    """--theory/--no-theory, --theory-cells, --theory-steps-per-cycle (the theory's defaults,
    safebasins.core.averaged_theory)."""
    f = click.option("--theory-steps-per-cycle", "theory_steps_per_cycle", type=int, default=STEPS_PER_CYCLE,
                     show_default=True,
                     callback=checked("steps_per_cycle", lib_check("safebasins.core.checks:check_positive_int")),
                     help="The averaged theory's time steps per forcing cycle.")(f)
    f = click.option("--theory-cells", "theory_cells", type=Fields("size"), default="x".join(str(n) for n in CELLS),
                     show_default=True, callback=checked(None, lambda v: check_cells(tuple(int(n) for n in v))),
                     help=f"The averaged theory's polar grid: N or N_GAMMAxN_J cells (>= {MIN_CELLS}).")(f)
    return click.option("--theory/--no-theory", "theory", default=True, show_default=True,
                        help="Also solve the averaged theory (docs/noise-theory.md) and store it with its agreement "
                             "where it applies (white or Ornstein-Uhlenbeck noise, every --noise > 0, a symmetric "
                             "well, --xi-max below the barrier); elsewhere the dataset's attribute theory_reason "
                             "says why not.")(f)


def noise_options(f: Any) -> Any:
    """--noise-time, --paths, --seed, --variates (the library's defaults)."""
    f = click.option("--variates", "variates", cls=Deferred, type=click.Choice(VARIATES),
                     default=from_library(LIBRARY, "variates"),
                     help="Law of the kicks' random numbers: gaussian, or five-point (0, +-sqrt 2, +-2 at 5/8, 1/8, "
                          "1/16: the same moments through the fifth, the same weak order, about three times "
                          "faster; docs/noise.md).")(f)
    f = click.option("--seed", "seed", cls=Deferred, type=click.IntRange(0, 2 ** 63 - 1),
                     default=from_library(LIBRARY, "seed"),
                     help="Key of the counter-based random streams (the same numbers for any --threads).")(f)
    f = click.option("--paths", "paths", type=int, default=100, show_default=True,
                     callback=checked("paths", lib_check("safebasins.core.checks:check_positive_int")),
                     help="Paths per initial condition (the 95% Wilson interval of P_escape is about "
                          "+-1/sqrt(paths)).")(f)
    return click.option("--noise-time", "noise_time", cls=Deferred, type=Number("noise_time", NONNEG),
                        default=from_library(LIBRARY, "noise_time"),
                        help="Correlation time tau >= 0 of coloured noise (an Ornstein-Uhlenbeck force of the same "
                             "low-frequency intensity sigma^2; 0: white noise). The step must resolve it.")(f)


def theory_settings(theory: bool, theory_cells: tuple[int, int], theory_steps_per_cycle: int) -> dict[str, Any]:
    """The keywords of safebasins.analysis.noise_theory's functions from the theory options."""
    return dict(theory=theory, cells=tuple(theory_cells), steps_per_cycle=theory_steps_per_cycle)


@click.command("escape-probability")
@forcing_options
@click.option("--xi-max", "xi_max", type=Number("xi_max", THRESHOLD), required=True,
              help="Escape threshold (energy) in (0, E_b], E_b the well's barrier energy; also escape past a barrier.")
@click.option("--noise", "noise", type=Number("noise", NONNEG), required=True,
              help="Noise amplitude sigma >= 0 of dp = ... + sigma dW (thermal noise at temperature T: "
                   "sigma^2 = 2 beta T; 0: every path is the deterministic trajectory).")
@noise_options
@click.option("--t-eval", "t_eval", type=NumberList("t_eval", NONNEG), multiple=True, required=True,
              callback=joined(unique=True),
              help=f"Evaluation times in forcing cycles (>= 0): comma list or repeated, at most {MAX_T_EVAL} "
                   "(one panel each); all from one pass.")
@click.option("--cycles", type=click.IntRange(min=1), default=None,
              help="Horizon in forcing cycles (>= every --t-eval; the first-passage mean is restricted to it) "
                   "[default: the largest --t-eval rounded up].")
@grid_options
@theory_options
@steps_option(LIBRARY, " (>= 4)")
@threads_option
@damping_option()
@common_options
@out_option("escape_probability")
def escape_probability(F: float, Omega: float, Psi: float, xi_max: float, noise: float, noise_time: float, paths: int,
                       seed: int, variates: str, t_eval: list[float], cycles: int | None,
                       grid: dict[str, list[float]] | None, n: list[int], theory: bool,
                       theory_cells: tuple[int, int], theory_steps_per_cycle: int,
                       steps_per_cycle: int, threads: int | None, damping: float, fourier: str | None,
                       well: dict[str, Any], no_plot: bool,
                       quiet: bool, verbose: bool, allow_expensive: bool, out: str) -> None:
    """Escape probabilities under noise over a grid of initial conditions.

    From each initial condition --paths paths of dq = p dt, dp = (-beta p - V'(q) + F sin(Omega t
    + Psi)) dt + sigma dW (or an Ornstein-Uhlenbeck force with --noise-time) are integrated (weak
    order 2, counter-based random numbers) and escape by the criteria of the escape charts.
    PREFIX.nc is the library's dataset: P_escape(q0, p0, t_eval) with its 95% Wilson interval,
    the survival curve and the restricted mean first-passage time (docs/noise.md), and where the
    averaged theory applies (white or Ornstein-Uhlenbeck noise, any well, --xi-max below the barrier;
    at --noise 0 the noise-free slow flow) its map P_escape_theory with the agreement |P_escape_theory - P_escape|
    (docs/noise-theory.md; --no-theory: none, and the attribute theory_reason says why);
    PREFIX.png maps P_escape at each --t-eval with the theory's contours.

    Example: safebasins escape-probability --F 0.05 --Omega 0.9 --xi-max 0.2 --damping 0.05 --noise 0.06
    --t-eval 3,5 --n 41 --paths 200
    """
    no_fourier(fourier)
    if len(t_eval) > MAX_T_EVAL:
        raise click.BadParameter(f"at most {MAX_T_EVAL} values, got {len(t_eval)}", param_hint="'--t-eval'")
    if cycles is not None and max(t_eval) > cycles:
        raise click.BadParameter(f"evaluation time {fmt(max(t_eval))} beyond the horizon --cycles {cycles}",
                                 param_hint="'--t-eval'")
    ctx = click.get_current_context()
    name = Path(out).name
    params: dict[str, Any] = dict(command="escape-probability", experiment=name, well=well, F=F, Omega=Omega, Psi=Psi,
                                  xi_max=xi_max, damping=damping, noise=noise, noise_time=noise_time, paths=paths,
                                  seed=seed, variates=variates, t_eval=t_eval, cycles=cycles, grid=grid_params(grid, n),
                                  steps_per_cycle=steps_per_cycle, theory=theory, theory_cells=list(theory_cells),
                                  theory_steps_per_cycle=theory_steps_per_cycle)
    damped, beta = damping_text(damping)
    params["title"] = (f"Escape probability under noise sigma = {fmt(noise)}"
                       + (f", tau = {fmt(noise_time)}" if noise_time > 0 else "")
                       + f", {damped}{well_label(well)} well, F = {fmt(F)}, Omega = {fmt(Omega)}, "
                       f"Psi = {fmt(Psi, angle=True)}{beta} (safebasins escape-probability {name})")
    check_step(Omega, steps_per_cycle)
    nq, np_ = params["grid"]["n"]
    horizon = cycles if cycles is not None else max(1, math.ceil(max(t_eval)))
    # the ensemble, its theory and its figure load numba, scipy and matplotlib: imported when the
    # command runs, so that `safebasins --help` and the other commands start without them
    from safebasins.analysis.noise_theory import escape_probability_with_theory, theory_evaluations

    # each noisy step: the well's force and the random numbers (pipeline.cost.NOISE_STEP_COSTS);
    # the averaged theory: its tables and one solve (the pipeline's count)
    step_cost = current_well(ctx).step_cost + NOISE_STEP_COSTS[variates]
    settings = theory_settings(theory, theory_cells, theory_steps_per_cycle)
    cost_guard(None, params, allow_expensive, steps=nq * np_ * paths * horizon * steps_per_cycle * step_cost,
               reduce="--n, --paths or --cycles", reduce_analytic=THEORY_REDUCE,
               evaluations=theory_evaluations(noise=noise, t_eval=t_eval, n_ics=nq * np_, solves=1,
                                              well=current_well(ctx), noise_time=noise_time, **settings))
    from safebasins.numerics import escape_probability as ensemble
    from safebasins.plotting.noise import figure_escape_probability_levels

    q0, p0 = grid_axes(params["grid"])
    with library_errors(), chatter(verbose):
        ds = ensemble(q0, p0, F, Omega, Psi, noise=noise, paths=paths, xi_max=xi_max, t_eval=t_eval,
                      damping=damping, well=current_well(ctx), seed=seed, cycles=cycles, noise_time=noise_time,
                      steps_per_cycle=steps_per_cycle, grid=True, threads=threads, variates=variates)
        params["cycles"] = int(ds.attrs["cycles"])
        ds = escape_probability_with_theory(ds, F, Omega, Psi, xi_max, damping=damping, well=current_well(ctx),
                                            noise_time=noise_time, **settings)
        ds = finish(ds, title=params["title"], params=params)
        # the pipeline's figure of stacked noise levels, one row: the theory's contours and notes
        fig = None if no_plot else draw(figure_escape_probability_levels, ds.expand_dims(noise=[noise]))
    write_outputs([(f"{out}.nc", ds)], fig, f"{out}.png")
    for t in t_eval:
        p = ds["P_escape"].sel(t_eval=t)
        half = float((ds["P_escape_high"] - ds["P_escape_low"]).sel(t_eval=t).max()) / 2
        click.echo(f"within {fmt(t)} cycles: mean P_escape {float(p.mean()):.4f} over {p.size} ICs, "
                   f"{float((p == 0).mean()):.1%} with no path escaped (95% intervals at most +-{half:.2g})")
    if "P_escape_theory" in ds:
        click.echo(f"averaged theory vs ensemble: mean |P_escape_theory - P_escape| "
                   f"{ds.attrs['P_escape_mean_abs_difference']:.4f}, max {ds.attrs['P_escape_max_abs_difference']:.4f} "
                   f"over the ICs and t_eval; inside the 95% Wilson interval at "
                   f"{float(ds['P_escape_theory_within_wilson']):.0%} of them")
    else:
        click.echo(f"no averaged theory: {ds.attrs['theory_reason']}")
