"""The ``hilltop-saddle`` command: the hilltop saddle's stable and unstable manifolds over escape
charts of a damped well at a few F, with the F of their first tangency (the pipeline's
``hilltop_saddle`` kind)."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from safebasins.cli.commands import well_label
from safebasins.cli.options import (FINITE, NONNEG, POSITIVE, THRESHOLD, Deferred, Fields, Number, NumberList,
                                    common_options, cost_guard, from_schema, grid_params, joined, library_errors,
                                    no_fourier, out_option, steps_option, threads_option)
from safebasins.cli.output import chatter, draw, finish, job, write_outputs
from safebasins.pipeline.values import fmt

__all__ = ["hilltop_saddle"]


@click.command("hilltop-saddle")
@click.option("--F", "F", type=NumberList("F", NONNEG), multiple=True, required=True, callback=joined(unique=True),
              help="Forcing amplitudes (>= 0): comma list or repeated, at most 3 (one panel each).")
@click.option("--Omega", "Omega", type=Number("Omega", POSITIVE), required=True, help="Forcing frequency (> 0).")
@click.option("--Psi", "Psi", type=Number("Psi", FINITE, angle=True), default="0", show_default=True,
              help="Forcing phase (rad) of the section t = 0: a number, pi, pi/2, -3pi/4, ...")
@click.option("--xi-max", "xi_max", type=Number("xi_max", THRESHOLD), required=True,
              help="Escape threshold (energy) of the charts in (0, E_b], E_b the well's barrier energy.")
@click.option("--damping", "damping", type=Number("damping", POSITIVE), required=True,
              help="Linear damping beta > 0 of q'' + beta q' + V'(q) = F sin(Omega t + Psi).")
@click.option("--n", "n", type=Fields("size"), default="101", show_default=True,
              help="Points per axis of the escape charts: N, or NQxNP (q0 x p0).")
@click.option("--grid", "grid", type=Fields("grid"), default=None,
              help="IC window q0min,q0max,p0min,p0max [default: the well's Well.ic_window()].")
@click.option("--cycles", cls=Deferred, type=click.IntRange(min=1), default=from_schema("hilltop_saddle", "cycles"),
              help="Horizon of the escape charts (forcing cycles).")
@click.option("--ds-max", "ds_max", cls=Deferred, type=Number("ds_max", POSITIVE),
              default=from_schema("hilltop_saddle", "manifolds", "ds_max"),
              help="Longest segment of the drawn manifolds.")
@click.option("--tangency/--no-tangency", default=False, show_default=True,
              help="Also find the F of the manifolds' first tangency (Brent; a few minutes).")
@steps_option("safebasins.numerics:escape_chart", " of the charts (>= 4)")
@threads_option
@common_options
@out_option("hilltop_saddle")
def hilltop_saddle(F: list[float], Omega: float, Psi: float, xi_max: float, damping: float, n: list[int],
                   grid: dict[str, list[float]] | None, cycles: int, ds_max: float, tangency: bool,
                   steps_per_cycle: int, threads: int | None, fourier: str | None, well: dict[str, Any],
                   no_plot: bool, quiet: bool, verbose: bool, allow_expensive: bool, out: str) -> None:
    """The hilltop saddle's orbit and manifolds over escape charts of a damped well.

    The saddle's T-periodic orbit by multiple shooting (Newton on the stroboscopic map, DOP853),
    its stable and unstable manifolds grown on the stroboscopic map of the section t = 0, drawn
    over the escape chart of that section at each F; with --tangency the F of the manifolds'
    first tangency beside the Melnikov threshold.  PREFIX.nc has the layout of the pipeline's
    hilltop_saddle datasets; PREFIX.png is its figure.

    Example: safebasins hilltop-saddle --well cubic --F 0.055,0.07 --Omega 0.85 --xi-max 0.1666 --damping 0.1
    """
    no_fourier(fourier)
    if len(F) > 3:
        raise click.BadParameter(f"at most 3 values, got {len(F)}", param_hint="'--F'")
    name = Path(out).name
    params: dict[str, Any] = dict(command="hilltop-saddle", kind="hilltop_saddle", experiment=name, well=well,
                                  F=list(F), Omega=Omega, Psi=Psi, xi_max=xi_max, damping=damping,
                                  grid=grid_params(grid, n), cycles=cycles, steps_per_cycle=steps_per_cycle,
                                  manifolds={"iterations": None, "ds_max": ds_max, "rtol": 1e-10},
                                  tangency={"enabled": tangency, "xtol": 1e-6, "ds_max": 0.02, "rtol": 1e-9})
    params["title"] = (f"Hilltop saddle, {well_label(well)} well, F = {', '.join(fmt(f) for f in F)}, "
                       f"Omega = {fmt(Omega)}, Psi = {fmt(Psi, angle=True)}, beta = {fmt(damping)} "
                       f"(safebasins hilltop-saddle {name})")
    cost_guard("hilltop_saddle", params, allow_expensive)
    # the computation and its figure load the engine and matplotlib: imported when the command runs,
    # so that `safebasins --help` and the other commands start without them
    from safebasins.pipeline.kinds.saddle import build_saddle
    from safebasins.plotting.saddle import figure_hilltop_saddle

    with library_errors(), chatter(verbose):
        ds = build_saddle(params, {}, job(threads, "cpu"))
        ds = finish(ds, title=params["title"], params=params)
        fig = None if no_plot else draw(figure_hilltop_saddle, ds)
    write_outputs([(f"{out}.nc", ds)], fig, f"{out}.png")
    F_M, F_T = float(ds["F_melnikov"]), float(ds["F_tangency"])
    if tangency:
        click.echo(f"first tangency F = {F_T:.6g} = {F_T / F_M:.4f} F_M (Melnikov F_M = {F_M:.6g})")
    for k, f in enumerate(F):
        mu = float(ds["multiplier_unstable"][k, 0])
        click.echo(f"F = {fmt(f)} ({f / F_M:.2f} F_M): saddle fixed point ({float(ds['q_fixed'][k, 0]):.5f}, "
                   f"{float(ds['p_fixed'][k, 0]):.5f}), unstable multiplier {mu:.5g}; "
                   f"{100 * float(ds['safe_fraction'][k]):.1f}% of the chart safe")
