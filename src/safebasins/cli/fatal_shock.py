"""The ``fatal-shock`` command: the minimal fatal shock of each period-1 attractor of a damped well at
shock phases over one forcing period, with the LIM beside it (the pipeline's ``minimal_fatal_shock``
kind)."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from safebasins.cli.commands import well_label
from safebasins.cli.options import (FINITE, NONNEG, POSITIVE, THRESHOLD, Deferred, Number, NumberList,
                                    common_options, cost_guard, from_schema, library_errors, no_fourier, out_option,
                                    steps_option, threads_option)
from safebasins.cli.output import chatter, draw, finish, job, write_outputs
from safebasins.pipeline.values import fmt

__all__ = ["fatal_shock"]

KIND = "minimal_fatal_shock"


@click.command("fatal-shock")
@click.option("--F", "F", type=Number("F", NONNEG), required=True, help="Forcing amplitude (>= 0).")
@click.option("--Omega", "Omega", type=Number("Omega", POSITIVE), required=True, help="Forcing frequency (> 0).")
@click.option("--Psi", "Psi", type=Number("Psi", FINITE, angle=True), default="0", show_default=True,
              help="Forcing phase (rad) of the section t = 0, the first shock phase: a number, pi, pi/2, ...")
@click.option("--xi-max", "xi_max", type=Number("xi_max", THRESHOLD), required=True,
              help="Escape threshold (energy) in (0, E_b], E_b the well's barrier energy.")
@click.option("--damping", "damping", type=Number("damping", POSITIVE), required=True,
              help="Linear damping beta > 0 of q'' + beta q' + V'(q) = F sin(Omega t + Psi) (attractors need it).")
@click.option("--n-phases", "n_phases", cls=Deferred, type=click.IntRange(min=1),
              default=from_schema(KIND, "n_phases"),
              help="Shock phases Omega t + Psi = Psi + 2 pi k / N over one forcing period.")
@click.option("--cycles", cls=Deferred, type=click.IntRange(min=1), default=from_schema(KIND, "cycles"),
              help="Horizon after the shock (forcing cycles).")
@click.option("--weights", type=NumberList("weights", POSITIVE), default=None,
              help="w_q,w_p of a weighted norm sqrt(w_q dq^2 + w_p dp^2) beside the energy norm.")
@click.option("--radius-max", "radius_max", type=Number("radius_max", POSITIVE), default=None,
              help="Largest energy-norm shock searched [default: 1.5 sqrt(2 xi_max)].")
@click.option("--n-directions", "n_directions", cls=Deferred, type=click.IntRange(min=8),
              default=from_schema(KIND, "search", "n_directions"), help="Directions of the polar grid of shocks.")
@click.option("--n-radii", "n_radii", cls=Deferred, type=click.IntRange(min=2),
              default=from_schema(KIND, "search", "n_radii"), help="Radii of the polar grid of shocks.")
@click.option("--n-lim", "n_lim", cls=Deferred, type=click.IntRange(min=3),
              default=from_schema(KIND, "search", "n_lim"),
              help="Nodes per side of the LIM grid centred on the attractor (odd).")
@steps_option("safebasins.analysis.fatal_shock:minimal_fatal_shock", " (>= 4; the energy is checked after each step)")
@threads_option
@common_options
@out_option("fatal_shock")
def fatal_shock(F: float, Omega: float, Psi: float, xi_max: float, damping: float, n_phases: int, cycles: int,
                weights: list[float] | None, radius_max: float | None, n_directions: int, n_radii: int, n_lim: int,
                steps_per_cycle: int, threads: int | None, fourier: str | None, well: dict[str, Any],
                no_plot: bool, quiet: bool, verbose: bool, allow_expensive: bool, out: str) -> None:
    """The minimal fatal shock of a damped well's attractors.

    Each stable period-1 attractor inside the well (found from a grid of seeds, polished by Newton
    on the stroboscopic map) is kicked at each shock phase; the smallest kick that leads to escape
    (H0 > xi_max or beyond a barrier within --cycles) is found on a polar grid and refined by
    k-section and Brent, in the energy norm and with --weights in a weighted norm, beside the LIM
    centred on the attractor (docs/fatal-shock.md).  PREFIX.nc has the layout of the pipeline's
    minimal_fatal_shock datasets; PREFIX.png is its figure.

    Example: safebasins fatal-shock --well cubic --F 0.055 --Omega 0.85 --xi-max 0.1666 --damping 0.1
    """
    from safebasins.pipeline.kinds.fatal_shock import shock_phases

    no_fourier(fourier)
    if weights is not None and len(weights) != 2:
        raise click.BadParameter(f"give two weights w_q,w_p, got {len(weights)}", param_hint="'--weights'")
    if n_lim % 2 == 0:
        raise click.BadParameter(f"must be odd (the attractor a node of the LIM grid), got {n_lim}",
                                 param_hint="'--n-lim'")
    name = Path(out).name
    search = {k: from_schema(KIND, "search", k)() for k in ("n_refine", "n_seeds", "tol")}
    search.update(n_directions=n_directions, n_radii=n_radii, n_lim=n_lim)
    params: dict[str, Any] = dict(command="fatal-shock", kind=KIND, experiment=name, well=well, F=F, Omega=Omega,
                                  Psi=Psi, xi_max=xi_max, damping=damping, phases=shock_phases(Psi, n_phases),
                                  cycles=cycles, weights=weights, radius_max=radius_max,
                                  steps_per_cycle=steps_per_cycle, search=search)
    params["title"] = (f"Minimal fatal shock, {well_label(well)} well, F = {fmt(F)}, Omega = {fmt(Omega)}, "
                       f"beta = {fmt(damping)}, xi_max = {fmt(xi_max)} (safebasins fatal-shock {name})")
    cost_guard(KIND, params, allow_expensive, reduce="--n-phases, --cycles, --n-lim or the search")
    # the computation and its figure load the engine and matplotlib: imported when the command runs
    from safebasins.pipeline.kinds.fatal_shock import build_fatal_shock
    from safebasins.plotting.fatal_shock import figure_fatal_shock

    with library_errors(), chatter(verbose):
        ds = build_fatal_shock(params, {}, job(threads, "cpu"))
        ds = finish(ds, title=params["title"], params=params)
        fig = None if no_plot else draw(figure_fatal_shock, ds)
    write_outputs([(f"{out}.nc", ds)], fig, f"{out}.png")
    for a in range(ds.sizes["attractor"]):
        for n, norm in enumerate(ds["norm"].values):
            mfs = ds["mfs"].values[a, :, n]
            k = int(mfs.argmin())
            click.echo(f"attractor {a} (amplitude {float(ds['response_amplitude'][a]):.4f}), {norm} norm: MFS "
                       f"{mfs.min():.5f} (phase {fmt(float(ds['phase'][k]), angle=True)}) to {mfs.max():.5f} over "
                       f"{mfs.size} phase(s); LIM - MFS <= {float((ds['lim'].values[a, :, n] - mfs).max()):.2g}")
