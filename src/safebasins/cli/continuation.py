"""The ``continue-attractors`` command: the period-1 attractors of a damped well followed across a sweep
of F or Omega, with their basins' integrity and the Dover cliff (the pipeline's ``continue_attractors``
kind)."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import click

from safebasins.cli.commands import well_label
from safebasins.cli.options import (FINITE, NONNEG, POSITIVE, THRESHOLD, Deferred, Number, NumberList,
                                    common_options, cost_guard, from_schema, library_errors, no_fourier, out_option,
                                    steps_option, threads_option)
from safebasins.cli.output import chatter, draw, finish, job, write_outputs
from safebasins.pipeline.values import fmt

__all__ = ["continue_attractors"]

KIND = "continue_attractors"
SWEEP_HELP = (": a value, or the sweep: comma-separated increasing values, e.g. $(seq -s, {}); exactly one of --F "
              "and --Omega is a sweep.")


@click.command("continue-attractors")
@click.option("--F", "F", type=NumberList("F", NONNEG), required=True,
              help="Forcing amplitude (>= 0)" + SWEEP_HELP.format("0.04 0.002 0.1"))
@click.option("--Omega", "Omega", type=NumberList("Omega", POSITIVE), required=True,
              help="Forcing frequency (> 0)" + SWEEP_HELP.format("0.7 0.01 1.0"))
@click.option("--Psi", "Psi", type=Number("Psi", FINITE, angle=True), default="0", show_default=True,
              help="Forcing phase (rad) of the stroboscopic section t = 0: a number, pi, pi/2, ...")
@click.option("--xi-max", "xi_max", type=Number("xi_max", THRESHOLD), default=None,
              help="Escape energy in (0, E_b]; a branch ends where its orbit reaches it [default: E_b, the well's "
                   "barrier energy].")
@click.option("--damping", "damping", type=Number("damping", POSITIVE), required=True,
              help="Linear damping beta > 0 of q'' + beta q' + V'(q) = F sin(Omega t + Psi) (attractors need it).")
@click.option("--n-grid", "n_grid", cls=Deferred, type=click.IntRange(min=9), default=from_schema(KIND, "n_grid"),
              help="Nodes per side of the IC grid over the well's IC window (the basin labels).")
@click.option("--n-iter", "n_iter", type=click.IntRange(min=1), default=None,
              help="Map iterations of the basin labels [default: max(50, 2 * 15 / (beta T)), transients decayed "
                   "to exp(-15)].")
@click.option("--step-max", "step_max", type=Number("step_max", POSITIVE), default=None,
              help="Largest arclength step in (q, p, kappa lambda) [default: the IC window's q-width / 20].")
@click.option("--max-points", "max_points", cls=Deferred, type=click.IntRange(min=3),
              default=from_schema(KIND, "max_points"), help="Points per direction of a branch at most.")
@steps_option("safebasins.analysis.continuation:continue_attractors", " of the basin labels (>= 4)")
@threads_option
@common_options
@out_option("continuation")
def continue_attractors(F: list[float], Omega: list[float], Psi: float, xi_max: float | None, damping: float,
                        n_grid: int, n_iter: int | None, step_max: float | None, max_points: int,
                        steps_per_cycle: int, threads: int | None, fourier: str | None, well: dict[str, Any],
                        no_plot: bool, quiet: bool, verbose: bool, allow_expensive: bool, out: str) -> None:
    """The attractors of a damped well followed across F or Omega, with their basins.

    The basins are labelled on a grid of initial conditions at every swept value (the compiled
    stroboscopic map); every period-1 attractor found there is followed by pseudo-arclength
    continuation of the DOP853 period map through its folds onto the saddle branch, with the
    Floquet multipliers, the folds, period doublings and the exit from the well located; each
    attractor's basin is measured (GIM, LIM) at every swept value, and its Dover cliff, where the
    most of it escapes, found (docs/continuation.md).  PREFIX.nc has the layout of the pipeline's
    continue_attractors datasets; PREFIX.png is its figure.

    Example: safebasins continue-attractors --well cubic --F $(seq -s, 0.04 0.002 0.1) --Omega 0.85 --damping 0.1
    """
    no_fourier(fourier)
    swept = [k for k, v in (("F", F), ("Omega", Omega)) if len(v) > 1]
    if len(swept) != 1:
        raise click.BadParameter(
            "exactly one of --F and --Omega is a sweep (comma-separated values), the other one value; got "
            + ("both" if swept else "neither"), param_hint="'--Omega'" if swept else "'--F'")
    sweep = swept[0]
    name = Path(out).name
    params: dict[str, Any] = dict(command="continue-attractors", kind=KIND, experiment=name, well=well,
                                  damping=damping, sweep=sweep, F=F if sweep == "F" else F[0],
                                  Omega=Omega if sweep == "Omega" else Omega[0], Psi=Psi, xi_max=xi_max,
                                  n_grid=n_grid, n_iter=n_iter, step_max=step_max, max_points=max_points,
                                  steps_per_cycle=steps_per_cycle)
    fixed = "Omega" if sweep == "F" else "F"
    params["title"] = (f"Attractors across {sweep}, {well_label(well)} well, {fixed} = {fmt(params[fixed])}, "
                       f"beta = {fmt(damping)} (safebasins continue-attractors {name})")
    cost_guard(KIND, params, allow_expensive, reduce="the swept values, --n-grid, --n-iter or --max-points")
    # the computation and its figure load the engine and matplotlib: imported when the command runs
    from safebasins.pipeline.kinds.continuation import build_continuation
    from safebasins.plotting.continuation import figure_continuation

    with library_errors(), chatter(verbose):
        ds = build_continuation(params, {}, job(threads, "cpu"))
        ds = finish(ds, title=params["title"], params=params)
        fig = None if no_plot else draw(figure_continuation, ds)
    write_outputs([(f"{out}.nc", ds)], fig, f"{out}.png")
    _summary(ds, sweep)


def _summary(ds: Any, sweep: str) -> None:
    """One line per event kind found, per attractor and for the safe basin."""
    kinds = str(ds["event_kind"].attrs["flag_meanings"]).split()
    for kind in ("fold", "branch_point", "period_doubling", "left_well"):
        at = ds["event_parameter"].values[ds["event_kind"].values == kinds.index(kind)]
        if at.size:
            click.echo(f"{kind.replace('_', ' ')} at {sweep} = {', '.join(f'{v:.6g}' for v in sorted(at))}")
    classes = str(ds["attractor_class"].attrs["flag_meanings"]).split()
    for a in range(ds.sizes["attractor"]):
        lo, hi = ds["attractor_end_parameter"].values[a]
        drop = float(ds["cliff_drop"][a])
        cliff = (f"cliff {sweep} = {float(ds['cliff_low'][a]):.6g} to {float(ds['cliff_high'][a]):.6g} "
                 f"(GIM {drop:.3f} lost to escape)" if not math.isnan(drop) else "no loss to escape")
        click.echo(f"attractor {a} ({classes[int(ds['attractor_class'][a])]}): {sweep} {lo:.6g} to {hi:.6g}; {cliff}")
    drop = float(ds["safe_cliff_drop"])
    click.echo("safe basin: " + (f"cliff {sweep} = {float(ds['safe_cliff_low']):.6g} to "
                                 f"{float(ds['safe_cliff_high']):.6g} (GIM {drop:.3f} lost to escape)"
                                 if not math.isnan(drop) else "no loss to escape"))
