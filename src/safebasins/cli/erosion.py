"""The ``stochastic-erosion`` command: GIM, LIM and IF of the stochastic safe basin {P_escape <=
epsilon} against the noise amplitude and/or F (:func:`safebasins.analysis.stochastic_erosion`,
docs/stochastic-integrity.md), with the averaged theory's profile where it applies."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import click

from safebasins.cli.commands import check_step, damping_text, grid_axes, well_label
from safebasins.cli.noise import THEORY_REDUCE, noise_options, theory_options, theory_settings
from safebasins.cli.options import (FINITE, NONNEG, POSITIVE, THRESHOLD, Deferred, Number, NumberList, common_options,
                                    cost_guard, current_well, damping_option, from_library, grid_options, grid_params,
                                    joined, library_errors, no_fourier, out_option, steps_option, threads_option)
from safebasins.cli.output import chatter, draw, finish, write_outputs
from safebasins.core.statistics import certifiable_epsilon, paths_needed
from safebasins.pipeline.cost import NOISE_STEP_COSTS
from safebasins.pipeline.values import fmt

__all__ = ["stochastic_erosion"]

#: the library function whose defaults the options take
LIBRARY = "safebasins.analysis:stochastic_erosion"
#: the profile's swept options and their library arguments
SWEEPS = {"F": "--F", "noise": "--noise", "epsilon": "--epsilon"}


def _probabilities(ctx: click.Context, param: click.Parameter, value: Any) -> list[float]:
    """--epsilon: escape-probability levels in (0, 1)."""
    eps = joined(unique=True)(ctx, param, value)
    bad = [e for e in eps if not 0 < e < 1]
    if bad:
        raise click.BadParameter(f"epsilon must lie in (0, 1) (a probability of escape), got {fmt(bad[0])}", ctx,
                                 param)
    return eps


def _increasing(values: dict[str, list[float]]) -> None:
    """The profile's axes are coordinates: each list strictly increasing (the library's order)."""
    for name, v in values.items():
        if any(b <= a for a, b in zip(v, v[1:])):
            raise click.BadParameter(f"{name} must be strictly increasing (one point of the profile each), got "
                                     + ",".join(fmt(x) for x in v), param_hint=f"'{SWEEPS[name]}'")


def _one_or_list(v: list[float]) -> float | list[float]:
    # one value: no dimension (the library's scalar), several: a dimension of the profile
    return v[0] if len(v) == 1 else v


@click.command("stochastic-erosion")
@click.option("--F", "F", type=NumberList("F", NONNEG), multiple=True, required=True, callback=joined(unique=True),
              help="Forcing amplitude(s) >= 0: comma list or repeated, strictly increasing (several: a profile "
                   "against F).")
@click.option("--Omega", "Omega", type=Number("Omega", POSITIVE), required=True, help="Forcing frequency (> 0).")
@click.option("--Psi", "Psi", type=Number("Psi", FINITE, angle=True), default="0", show_default=True,
              help="Forcing phase (rad): a number, pi, pi/2, -3pi/4, ...")
@click.option("--xi-max", "xi_max", type=Number("xi_max", THRESHOLD), required=True,
              help="Escape threshold (energy) in (0, E_b], E_b the well's barrier energy; also escape past a barrier.")
@click.option("--noise", "noise", type=NumberList("noise", NONNEG), multiple=True, required=True,
              callback=joined(unique=True),
              help="Noise amplitude(s) sigma >= 0 of dp = ... + sigma dW: comma list or repeated, strictly "
                   "increasing (several: a profile against sigma; 0: the deterministic basin).")
@click.option("--epsilon", "epsilon", type=NumberList("epsilon", FINITE), multiple=True, required=True,
              callback=_probabilities,
              help="Escape-probability level(s) in (0, 1) of the safe basin {P_escape <= epsilon}: comma list or "
                   "repeated, strictly increasing.")
@noise_options
@click.option("--t-eval", "t_eval", type=NumberList("t_eval", NONNEG), multiple=True, required=True,
              callback=joined(unique=True),
              help="Evaluation times in forcing cycles (>= 0): comma list or repeated, strictly increasing; the "
                   "figure shows the last.")
@click.option("--cycles", type=click.IntRange(min=1), default=None,
              help="Horizon in forcing cycles (>= every --t-eval) [default: the largest --t-eval rounded up].")
@click.option("--conservative/--no-conservative", "conservative", cls=Deferred,
              default=from_library(LIBRARY, "conservative"),
              help="Also the conservative basin: the upper end of the 95% Wilson interval <= epsilon (each of its "
                   "ICs safe with 95% confidence; needs --paths large enough for the smallest --epsilon).")
@grid_options
@theory_options
@steps_option("safebasins.numerics:escape_probability", " (>= 4)")
@threads_option
@damping_option()
@common_options
@out_option("stochastic_erosion")
def stochastic_erosion(F: list[float], Omega: float, Psi: float, xi_max: float, noise: list[float],
                       epsilon: list[float], noise_time: float, paths: int, seed: int, variates: str,
                       t_eval: list[float],
                       cycles: int | None, conservative: bool, grid: dict[str, list[float]] | None, n: list[int],
                       theory: bool, theory_cells: tuple[int, int], theory_steps_per_cycle: int,
                       steps_per_cycle: int, threads: int | None, damping: float, fourier: str | None,
                       well: dict[str, Any], no_plot: bool, quiet: bool, verbose: bool, allow_expensive: bool,
                       out: str) -> None:
    """Stochastic erosion profile: integrity of the stochastic safe basin against noise and F.

    For each (F, sigma) an ensemble of --paths paths per initial condition gives P_escape
    (safebasins escape-probability; all with the same --seed: common random numbers), and the
    stochastic safe basin {P_escape <= epsilon} at each --t-eval is measured by GIM, LIM and IF
    (Soliman and Thompson's stochastic integrity; with --conservative also the basin of the upper
    end of the 95% Wilson interval). Where the averaged theory applies (white or Ornstein-Uhlenbeck
    noise, any well, --xi-max below the barrier; at --noise 0 the noise-free slow flow) its profile
    GIM_theory, LIM_theory, IF_theory is added (docs/noise-theory.md; --no-theory: none, the
    attribute theory_reason says why). PREFIX.nc is the library's dataset over (F, noise, epsilon,
    t_eval) (a single value: no dimension); PREFIX.png draws the profile against sigma and
    against F at the last --t-eval.

    Example: safebasins stochastic-erosion --F 0.02,0.05 --Omega 0.9 --xi-max 0.2 --damping 0.05
    --noise 0.02,0.04,0.06 --epsilon 0.1 --t-eval 5 --n 41 --paths 200
    """
    no_fourier(fourier)
    _increasing({"F": F, "noise": noise, "epsilon": epsilon})
    if any(b <= a for a, b in zip(t_eval, t_eval[1:])):
        raise click.BadParameter("evaluation times must be strictly increasing", param_hint="'--t-eval'")
    if cycles is not None and max(t_eval) > cycles:
        raise click.BadParameter(f"evaluation time {fmt(max(t_eval))} beyond the horizon --cycles {cycles}",
                                 param_hint="'--t-eval'")
    noisy = sum(1 for s in noise if s > 0)
    if conservative and noisy and min(epsilon) < certifiable_epsilon(paths):
        raise click.BadParameter(
            f"{paths} paths certify no epsilon below {certifiable_epsilon(paths):.4g} (the upper end of the 95% "
            f"Wilson interval with no escaped path), --epsilon {fmt(min(epsilon))} asks for --paths >= "
            f"{paths_needed(min(epsilon))}; or pass --no-conservative", param_hint="'--paths'")
    ctx = click.get_current_context()
    name = Path(out).name
    params: dict[str, Any] = dict(command="stochastic-erosion", experiment=name, well=well, F=F, Omega=Omega, Psi=Psi,
                                  xi_max=xi_max, damping=damping, noise=noise, epsilon=epsilon, noise_time=noise_time,
                                  paths=paths, seed=seed, variates=variates, t_eval=t_eval, cycles=cycles,
                                  conservative=conservative,
                                  grid=grid_params(grid, n), steps_per_cycle=steps_per_cycle, theory=theory,
                                  theory_cells=list(theory_cells), theory_steps_per_cycle=theory_steps_per_cycle)
    damped, beta = damping_text(damping)
    params["title"] = (f"Stochastic erosion profile at noise sigma = {', '.join(fmt(s) for s in noise)}"
                       + (f", tau = {fmt(noise_time)}" if noise_time > 0 else "")
                       + f", {damped}{well_label(well)} well, F = {', '.join(fmt(f) for f in F)}, "
                       f"Omega = {fmt(Omega)}, Psi = {fmt(Psi, angle=True)}{beta} "
                       f"(safebasins stochastic-erosion {name})")
    check_step(Omega, steps_per_cycle)
    nq, np_ = params["grid"]["n"]
    horizon = cycles if cycles is not None else max(1, math.ceil(max(t_eval)))
    # the ensembles, the theory and the figure load numba, scipy and matplotlib: imported when the command runs
    from safebasins.analysis import stochastic_erosion as profile
    from safebasins.analysis.noise_theory import stochastic_erosion_with_theory, theory_evaluations
    from safebasins.plotting.stochastic_erosion import figure_stochastic_erosion

    # one ensemble per (F, sigma): paths per IC at sigma > 0 (each step with its random numbers,
    # pipeline.cost.NOISE_STEP_COSTS), one deterministic path at sigma = 0; the averaged theory:
    # its tables and one solve per (F, sigma) (the pipeline's count)
    step_cost = current_well(ctx).step_cost
    per_ic = noisy * paths * (step_cost + NOISE_STEP_COSTS[variates]) + (len(noise) - noisy) * step_cost
    settings = theory_settings(theory, theory_cells, theory_steps_per_cycle)
    cost_guard(None, params, allow_expensive, steps=len(F) * nq * np_ * horizon * steps_per_cycle * per_ic,
               reduce="--n, --paths, --cycles or the --F / --noise lists", reduce_analytic=THEORY_REDUCE,
               evaluations=theory_evaluations(noise=noise, t_eval=t_eval, n_ics=nq * np_, solves=len(F) * len(noise),
                                              well=current_well(ctx), noise_time=noise_time, **settings))

    q0, p0 = grid_axes(params["grid"])
    sweep: dict[str, Any] = dict(noise=_one_or_list(noise), epsilon=_one_or_list(epsilon), xi_max=xi_max, t_eval=t_eval,
                 damping=damping, well=current_well(ctx))
    with library_errors(), chatter(verbose):
        ds = profile(q0, p0, _one_or_list(F), Omega, Psi, paths=paths, seed=seed, cycles=cycles,
                     conservative=conservative, noise_time=noise_time, steps_per_cycle=steps_per_cycle,
                     threads=threads, variates=variates, **sweep)
        ds = stochastic_erosion_with_theory(ds, q0, p0, _one_or_list(F), Omega, Psi, noise_time=noise_time,
                                            **sweep, **settings)
        ds = finish(ds, title=params["title"], params=params)
        fig = None if no_plot else draw(figure_stochastic_erosion, ds)
    write_outputs([(f"{out}.nc", ds)], fig, f"{out}.png")
    gim = ds["GIM"].isel(t_eval=-1)
    if "epsilon" in gim.dims:
        gim = gim.isel(epsilon=0)
    click.echo(f"GIM of {{P_escape <= {fmt(min(epsilon))}}} within {fmt(t_eval[-1])} cycles: "
               f"{float(gim.min()):.3f} to {float(gim.max()):.3f} over {gim.size} (F, sigma)")
    if "GIM_theory" in ds:
        d = abs(ds["GIM_theory"] - ds["GIM"])
        click.echo(f"averaged theory: |GIM_theory - GIM| mean {float(d.mean()):.3f}, max {float(d.max()):.3f}")
    else:
        click.echo(f"no averaged theory: {ds.attrs['theory_reason']}")
