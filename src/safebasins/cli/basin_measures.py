"""The ``basin-measures`` command: basin entropy, fractal and Wada tests and the uncertainty
exponent of a damped well's basins over a list of F (the pipeline's ``basin_measures`` kind)."""
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

__all__ = ["basin_measures"]


@click.command("basin-measures")
@click.option("--F", "F", type=NumberList("F", NONNEG), multiple=True, required=True, callback=joined(unique=True),
              help="Forcing amplitudes (>= 0): comma list or repeated, at most 4 (one basin map each).")
@click.option("--Omega", "Omega", type=Number("Omega", POSITIVE), required=True, help="Forcing frequency (> 0).")
@click.option("--Psi", "Psi", type=Number("Psi", FINITE, angle=True), default="0", show_default=True,
              help="Forcing phase (rad): a number, pi, pi/2, -3pi/4, ...")
@click.option("--xi-max", "xi_max", type=Number("xi_max", THRESHOLD), required=True,
              help="Escape threshold (energy) in (0, E_b], E_b the well's barrier energy.")
@click.option("--damping", "damping", type=Number("damping", POSITIVE), required=True,
              help="Linear damping beta > 0 of q'' + beta q' + V'(q) = F sin(Omega t + Psi) (attractors need it).")
@click.option("--n", "n", type=Fields("size"), default="201", show_default=True,
              help="Points per axis: N, or NQxNP (q0 x p0).")
@click.option("--grid", "grid", type=Fields("grid"), default=None,
              help="IC window q0min,q0max,p0min,p0max [default: the well's Well.ic_window()].")
@click.option("--n-iter", "n_iter", cls=Deferred, type=click.IntRange(min=10),
              default=from_schema("basin_measures", "n_iter"),
              help="Map iterations (forcing cycles) for the transients to die out.")
@click.option("--radius", cls=Deferred, type=Number("radius", POSITIVE),
              default=from_schema("basin_measures", "measures", "radius"),
              help="Ball radius of the fractal test (grid steps; Puy et al. advise a grid 50 radii wide).")
@click.option("--box", cls=Deferred, type=click.IntRange(min=2),
              default=from_schema("basin_measures", "measures", "box"),
              help="Box side of the basin entropy (grid steps).")
@steps_option("safebasins.numerics:stroboscopic_map", " (>= 4)")
@threads_option
@common_options
@out_option("basin_measures")
def basin_measures(F: list[float], Omega: float, Psi: float, xi_max: float, damping: float, n: list[int],
                   grid: dict[str, list[float]] | None, n_iter: int, radius: float, box: int, steps_per_cycle: int,
                   threads: int | None, fourier: str | None, well: dict[str, Any], no_plot: bool, quiet: bool,
                   verbose: bool, allow_expensive: bool, out: str) -> None:
    """Fractal boundary measures of a damped well's basins (escape and each attractor).

    Each initial condition of the grid is labelled by the stroboscopic map (escaped, or the
    attractor it settles on) and both labellings (escape: escaped / safe; attractors) are
    measured at each F: basin entropy S_b, S_bb with the log 2 criterion, the ball test for a
    fractal boundary, the Wada test of three basins and the uncertainty exponent, each with its
    standard error, beside the Melnikov threshold (docs/basin-measures.md).  PREFIX.nc has the
    layout of the pipeline's basin_measures datasets; PREFIX.png is its figure.

    Example: safebasins basin-measures --well cubic --F 0.055,0.07 --Omega 0.85 --xi-max 0.1666 --damping 0.1
    """
    no_fourier(fourier)
    if len(F) > 4:
        raise click.BadParameter(f"at most 4 values, got {len(F)}", param_hint="'--F'")
    name = Path(out).name
    params: dict[str, Any] = dict(command="basin-measures", kind="basin_measures", experiment=name, well=well,
                                  F=list(F), Omega=Omega, Psi=Psi, xi_max=xi_max, damping=damping,
                                  grid=grid_params(grid, n), n_iter=n_iter, tol=1e-4, steps_per_cycle=steps_per_cycle,
                                  seed=0, measures={"box": box, "radius": radius, "n_balls": 1000,
                                                    "eps": [2, 4, 8, 16]})
    side = min(params["grid"]["n"])
    for opt, bad, text in (("--box", box > side, f"{box} is larger than the grid ({side} nodes a side)"),
                           ("--radius", side - 1 <= 2 * radius, f"a ball of radius {fmt(radius)} does not fit the "
                                                                f"grid ({side} nodes a side)"),
                           ("--n", side <= 32, f"the uncertainty exponent's eps up to 16 steps need more than 32 "
                                               f"nodes a side, got {side}")):
        if bad:
            raise click.BadParameter(text, param_hint=f"'{opt}'")
    params["title"] = (f"Fractal boundary measures, {well_label(well)} well, F = {', '.join(fmt(f) for f in F)}, "
                       f"Omega = {fmt(Omega)}, Psi = {fmt(Psi, angle=True)}, beta = {fmt(damping)} "
                       f"(safebasins basin-measures {name})")
    cost_guard("basin_measures", params, allow_expensive)
    from safebasins.pipeline.kinds.basin_measures import build_measures

    with library_errors(), chatter(verbose):
        ds = build_measures(params, {}, job(threads, "cpu"))
        ds = finish(ds, title=params["title"], params=params)
        fig = None
        if not no_plot:
            from safebasins.plotting.basin_measures import figure_basin_measures

            fig = draw(figure_basin_measures, ds)
    write_outputs([(f"{out}.nc", ds)], fig, f"{out}.png")
    for f in F:
        m = ds.sel(F=f, labelling="escape")
        click.echo(f"F = {fmt(f)} ({f / float(ds['F_melnikov']):.2f} F_M): escape boundary "
                   f"{'fractal' if bool(m['fractal']) else 'smooth'} (ball test p = {float(m['p_value']):.2g}), "
                   f"alpha = {float(m['alpha']):.3f} +- {float(m['alpha_err']):.3f}; "
                   f"{int(ds['n_attractors'].sel(F=f))} attractor(s)")
