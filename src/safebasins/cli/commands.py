"""The commands: `chart`, `fcr`, `basin`, `info` (group `main`, the console script)."""
from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from safebasins.cli.options import (DISPLACEMENT, ENERGY, FINITE, OPTION_OF, POSITIVE, THRESHOLD, Deferred, Fields,
                                    Number, NumberList, analytic_thresholds, checked, common_options, cost_guard,
                                    current_well,
                                    damping_option,
                                    forcing_options, fourier_of, from_library, from_schema, grid_options, grid_params,
                                    joined, lib_check, library_errors, numerics_options, out_option)
from safebasins.cli.interrupt import InterruptibleGroup
from safebasins.cli.output import chatter, describe, draw, finish, fmt, job, progress, write_outputs

if TYPE_CHECKING:
    import numpy as np
    import xarray as xr
    from numpy.typing import NDArray

    from safebasins.pipeline.registry import Job, Params
    from safebasins.wells.base import Well


def check_step(Omega: float | list[float], steps_per_cycle: int) -> None:
    """The engine's step check (numerics.engine.check_step) before anything is computed: a usage
    error naming --steps-per-cycle (the message says which value works, or a larger --Omega)."""
    from safebasins.numerics.engine import check_step as check

    with library_errors():
        check(Omega, steps_per_cycle, current_well(click.get_current_context()))


def well_of(params: Params) -> Well:
    """The run's well with its first harmonic (the pipeline's values.well)."""
    from safebasins.pipeline.values import well

    return well(params)


def grid_axes(grid: dict[str, Any]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    from safebasins.pipeline.values import grid_axes as axes

    return axes(grid)


def damping_text(damping: float) -> tuple[str, str]:
    """("damped ", ", beta = B") of a damped run's title; ("", "") undamped."""
    return ("damped ", f", beta = {fmt(damping)}") if damping > 0 else ("", "")


def well_label(spec: dict[str, Any]) -> str:
    """How titles name the well of a run."""
    return spec.get("expression", spec["name"]) if spec["name"] == "expression" else spec["name"]


@click.group(cls=InterruptibleGroup, context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100})
@click.version_option(package_name="safebasins")
def main() -> None:
    """Safe basins of q'' + V'(q) = F sin(Omega t + Psi): analytic (slow flow) and numeric.

    The well is the paper's quartic V = q^2/2 - q^4/4 unless --well names another one (a name,
    polynomial:..., expression:'...': the forms of the pipeline config's `well:`).

    Each command writes PREFIX.nc (CF + provenance attributes, the pipeline's dataset layout)
    and PREFIX.png (the pipeline's figure).  Long runs show a progress bar on stderr when it is
    a terminal.  `safebasins info FILE.nc` tells what a dataset holds and where it came from.
    """


@main.command()
@forcing_options
@click.option("--xi-max", "xi_max", type=NumberList("xi_max", THRESHOLD), multiple=True, required=True,
              callback=joined(unique=True),
              help="Energy thresholds in (0, E_b) (E_b: the well's barrier energy, 1/4 for the quartic; with "
                   "--damping > 0 also E_b itself): comma list or repeated (one basin each).")
@click.option("--q-max", "q_max", type=NumberList("q_max", DISPLACEMENT), multiple=True,
              callback=joined(unique=True), help="Displacement thresholds |q| > q_max up to the nearest barrier, "
                                                 "stored beside the energy ones.")
@grid_options
@numerics_options("safebasins.numerics:escape_chart", "integrated; the stored IoU is evaluated at it")
@click.option("--t-eval", "t_eval", type=Number("t_eval", POSITIVE), default=None,
              help="Evaluation time (EC, <= --cycles) of the basins drawn in the PNG [default: --cycles].")
@click.option("--n-points", "n_points", cls=Deferred, type=int, default=from_schema("basin_chart", "n_points"),
              callback=checked("n_points", lib_check("safebasins.core.checks:check_positive_int")),
              help="Vertices per analytic boundary curve.")
@click.option("--tiles", type=click.IntRange(min=1), default=None,
              help="Row tiles (blocks of q0) integrated one after another; the progress bar counts them "
                   "[default: min(NQ, 10)]. The chart does not depend on it.")
@damping_option()
@common_options
@out_option("chart")
def chart(F: float, Omega: float, Psi: float, xi_max: list[float], q_max: list[float],
          grid: dict[str, list[float]] | None, n: list[int], cycles: int, steps_per_cycle: int, threads: int | None,
          backend: str, t_eval: float | None, n_points: int, tiles: int | None, damping: float, fourier: str | None,
          well: dict[str, Any], no_plot: bool, quiet: bool, verbose: bool, allow_expensive: bool, out: str) -> None:
    """Numeric escape chart on an IC grid with the analytic safe basins and their IoU.

    One integration serves every threshold.  PREFIX.nc is the chart in the layout of the
    pipeline's Figs 13-15 (`escape_cycle_energy(xi_max, q0, p0)`, `iou(xi_max)`,
    `pixel_agreement(xi_max)`, numeric safe = escape cycle > cycles); PREFIX.png shows the
    numeric safe basins (grey, nested) with the slow-flow boundaries (lines).  With --damping
    beta > 0 the numerics integrate the damped equation and the analytic basins are the damped slow
    flow's (docs/damping.md), their boundary the outline of the safe mask.

    Example: safebasins chart --F 0.01 --Omega 0.9 --Psi pi --xi-max 0.14,0.18 --n 100 --cycles 1000
    """
    from safebasins.pipeline.values import damping_param

    analytic_thresholds(click.get_current_context(), [(x, damping) for x in xi_max])
    t_eval = float(cycles) if t_eval is None else t_eval
    if t_eval > cycles:
        raise click.BadParameter(f"evaluation time {t_eval} beyond the horizon --cycles {cycles}",
                                 param_hint="'--t-eval'")
    tiles = min(n[0], 10) if tiles is None else tiles
    if tiles > n[0]:
        raise click.BadParameter(f"{tiles} tiles but only {n[0]} q0 rows", param_hint="'--tiles'")
    name = Path(out).name
    fourier = fourier_of(click.get_current_context(), fourier)
    params: Params = dict(command="chart", kind="basin_chart", experiment=name, fourier=fourier, well=well,
                          scan="xi_max", F=F, xi_max=xi_max, q_max=q_max, Omega=Omega, Psi=Psi,
                          grid=grid_params(grid, n), cycles=cycles, t_eval=[t_eval], n_points=n_points,
                          steps_per_cycle=steps_per_cycle, tasks=[{"F": F, "xi_max": xi_max, "q_max": q_max}],
                          **damping_param(damping))
    damped, beta = damping_text(damping)
    params["title"] = (f"Escape chart and {damped}slow-flow safe basins, {well_label(well)} well, F = {fmt(F)}, "
                       f"Omega = {fmt(Omega)}, Psi = {fmt(Psi, angle=True)}{beta} (safebasins chart {name})")
    check_step(Omega, steps_per_cycle)
    cost_guard("basin_chart", params, allow_expensive)
    with library_errors(), chatter(verbose):
        ds, basins = chart_dataset(params, tiles, job(threads, backend), quiet)
        finish(ds, title=params["title"], params=params)
        fig = None
        if not no_plot:
            from safebasins.plotting.charts import figure_nested_basins

            fig = draw(figure_nested_basins, basins, ds, t_eval=None if t_eval == cycles else t_eval)
    write_outputs([(f"{out}.nc", ds)], fig, f"{out}.png")
    for x, a, px in zip(ds["xi_max"].values, ds["iou"].values, ds["pixel_agreement"].values):
        click.echo(f"xi_max = {fmt(x)}: IoU = {a:.4f}, pixel agreement = {px:.4f} (t_eval = {cycles} EC)")


def chart_dataset(params: Params, tiles: int, job: Job, quiet: bool) -> tuple[xr.Dataset, xr.Dataset]:
    """(chart with agreement, analytic basins): the chart integrated in row tiles (one progress
    step each; the chart does not depend on the tiling), gathered, and compared with the slow-flow
    basins by the library functions the pipeline's basin_chart kind calls."""
    from safebasins.analysis.agreement import chart_agreement
    from safebasins.analysis.ic_basins import analytic_basin_stack
    from safebasins.io.gather import gather_chart, gather_tiles
    from safebasins.numerics import escape_chart
    from safebasins.pipeline.values import damping, grid_axes, tile_slice, well

    q0, p0 = grid_axes(params["grid"])
    w = well(params)
    beta = damping(params)
    parts = []
    with progress(tiles, "escape chart", "tile", quiet) as bar:
        for k in range(tiles):
            parts.append(escape_chart(q0[tile_slice(q0.size, tiles, k)], p0, params["F"], params["Omega"],
                                      params["Psi"], xi_max=tuple(params["xi_max"]), q_max=tuple(params["q_max"]),
                                      cycles=params["cycles"], steps_per_cycle=params["steps_per_cycle"],
                                      threads=job.threads, grid=True, backend=job.backend, well=w, damping=beta))
            bar.update(1)
    chart = gather_chart([gather_tiles(parts)], cycles=params["cycles"], scan="xi_max", t_eval=params["t_eval"])
    basins = analytic_basin_stack("xi_max", params["xi_max"], params["F"], params["Omega"], params["Psi"], None, q0,
                                  p0, well=w, n_points=params["n_points"], label=params["experiment"], damping=beta)
    basins.attrs.update(F=params["F"], Omega=params["Omega"], Psi=params["Psi"], fourier=params["fourier"])
    return chart_agreement(chart, basins, params["cycles"], "xi_max"), basins


def n_scan_check(n: int) -> int:
    if n < 0 or n == 1:
        raise ValueError(f"n_scan must be 0 (no scan) or an integer >= 2, got {n}")
    return n


@main.command()
@click.option("--Omega-range", "Omega_range", type=Fields("range"), default=None,
              help="Analytic Omega values start,stop,num (endpoints included) [default: 0.5 w0,1.2 w0,351 with w0 "
                   "the well's small-amplitude frequency: 0.5,1.2,351 for the quartic].")
@click.option("--xi-max", "xi_max", type=NumberList("xi_max", THRESHOLD), multiple=True, required=True,
              callback=joined(unique=False),
              help="Truncation levels in (0, E_b) (a damped curve also E_b itself): one curve each (comma list or "
                   "repeated).")
@click.option("--xi-ini", "xi_ini", type=NumberList("xi_ini", ENERGY), multiple=True,
              callback=joined(unique=False), help="Initial energies (< xi_max) [default: 0, the zero IC].")
@click.option("--gamma-ini", "gamma_ini", type=NumberList("gamma_ini", FINITE, angle=True), multiple=True,
              callback=joined(unique=False), help="Initial slow phases gamma_ini = theta0 - Psi [default: 0].")
@click.option("--numeric/--no-numeric", default=False, show_default=True,
              help="Also the numeric F_cr (bisection + F scan) for the IC (xi_ini, gamma_ini, Psi).")
@click.option("--numeric-Omega", "numeric_Omega", type=Fields("range"), default=None,
              help="Numeric Omega values start,stop,num [default: --Omega-range].")
@click.option("--Psi", "Psi", type=Number("Psi", FINITE, angle=True), default="0", show_default=True,
              help="Forcing phase of the numeric runs (maps (xi_ini, gamma_ini) to (q0, p0)).")
@numerics_options("safebasins.numerics:critical_forcing_numeric", "of the numeric escape test")
@click.option("--tol", type=Number("tol", POSITIVE),
              cls=Deferred, default=from_library("safebasins.numerics:critical_forcing_numeric", "tol"),
              help="Bisection tolerance on F.")
@click.option("--n-scan", "n_scan", type=int, callback=checked(None, n_scan_check),
              cls=Deferred, default=from_library("safebasins.numerics:critical_forcing_numeric", "n_scan"),
              help="F values of the non-monotonicity scan (0: none).")
@click.option("--F-bracket", "F_bracket", type=Fields("bracket"), default=None,
              help="Bisection bracket lo,hi of F; its top is doubled (up to 3 times) where it does not escape "
                   "[default: 0 to the well's static escape force, rounded up: 0,0.39 for the quartic].")
@click.option("--criterion", type=click.Choice(["energy", "displacement"]), default="energy", show_default=True,
              help="Numeric escape: H0 > xi_max, or |q| > q_max(xi_max).")
@damping_option(multiple=True)
@common_options
@out_option("fcr")
def fcr(Omega_range: dict[str, Any] | None, xi_max: list[float], xi_ini: list[float], gamma_ini: list[float],
        numeric: bool, numeric_Omega: dict[str, Any] | None, Psi: float, cycles: int, steps_per_cycle: int,
        threads: int | None, backend: str, tol: float, n_scan: int, F_bracket: list[float] | None, criterion: str,
        damping: list[float], fourier: str | None, well: dict[str, Any], no_plot: bool, quiet: bool, verbose: bool,
        allow_expensive: bool, out: str) -> None:
    """Critical forcing F_cr(Omega): analytic curves, optionally with the numeric bisection.

    Curves come from --xi-max / --xi-ini / --gamma-ini / --damping (equal lengths or length 1).  Writes
    PREFIX.nc (analytic, layout of the pipeline's fcr datasets: `F_cr(curve, Omega)`,
    `mechanism`, branches) and with --numeric also PREFIX_numeric.nc (`F_cr`, brackets,
    `non_monotone`); PREFIX.png shows the curves (and the numeric dots).

    Example: safebasins fcr --xi-max 0.15 --numeric --numeric-Omega 0.6,1.1,11 --cycles 1000
    """
    from safebasins.pipeline import values

    damping = damping or [0.0]
    if len(damping) > 1 and not all(b > 0 for b in damping):
        raise click.BadParameter(f"a list makes one damped curve per value: every value must be > 0, got {damping}",
                                 param_hint="'--damping'")
    block: dict[str, Any] = {"xi_max": xi_max, "xi_ini": xi_ini or [0.0], "gamma_ini": gamma_ini or [0.0], "Psi": Psi,
             "damping": damping if len(damping) > 1 else damping[0]}
    lens = {k: len(v) for k, v in values.curve_lists(block).items()}
    ncurve = max(lens.values())
    for k, m in lens.items():
        if m not in (1, ncurve):
            raise click.BadParameter(f"{m} values but another curve list has {ncurve}: give equal lengths or one",
                                     param_hint=f"'{OPTION_OF[k]}'")
    curves = values.curves(block, numeric)
    analytic_thresholds(click.get_current_context(), [(c["xi_max"], c.get("damping", 0.0)) for c in curves])
    for c in curves:
        if not c["xi_ini"] < c["xi_max"]:
            raise click.BadParameter(f"initial energy {c['xi_ini']} must be below the truncation level xi_max = "
                                     f"{c['xi_max']}", param_hint="'--xi-ini'")
    name = Path(out).name
    ctx = click.get_current_context()
    fourier = fourier_of(ctx, fourier)
    if Omega_range is None:
        w0 = float(current_well(ctx).omega(0.0))
        Omega_range = {"start": round(0.5 * w0, 12), "stop": round(1.2 * w0, 12), "num": 351}
    params: Params = dict(command="fcr", kind="fcr_compare" if numeric else "fcr_theory", experiment=name,
                          fourier=fourier, well=well, **values.damping_param(block["damping"]),
                          Omega=values.range_values(Omega_range), curves=curves)
    if numeric:
        if F_bracket is None:
            from safebasins.numerics.bisection import default_bracket

            F_bracket = list(default_bracket(current_well(ctx)))
        params["numeric"] = {"Omega": values.range_values(numeric_Omega or Omega_range), "cycles": cycles,
                             "tol": tol, "F_bracket": F_bracket, "n_scan": n_scan, "criterion": criterion,
                             "steps_per_cycle": steps_per_cycle}
    params["title"] = f"Critical forcing F_cr(Omega), {well_label(well)} well (safebasins fcr {name})"
    if numeric:
        check_step(params["numeric"]["Omega"], steps_per_cycle)
    cost_guard("fcr_compare" if numeric else "fcr_theory", params, allow_expensive)
    from safebasins.analysis.fcr_curves import analytic_fcr_curves

    with library_errors(), chatter(verbose):
        ana = analytic_fcr_curves(params["Omega"], curves, well=well_of(params), label=name)
        ana.attrs["fourier"] = fourier
        ana = finish(ana, title=params["title"], params=params)
        outputs = [(f"{out}.nc", ana)]
        num = None
        if numeric:
            num = finish(fcr_numeric(params, job(threads, backend), quiet), title=params["title"], params=params)
            outputs.append((f"{out}_numeric.nc", num))
        fig = None
        if not no_plot:
            from safebasins.plotting import fcr as plots

            fig = (draw(plots.figure_fcr_comparison, ana, num) if numeric
                   else draw(plots.figure_fcr, ana, show_branches=len(curves) == 1))
    write_outputs(outputs, fig, f"{out}.png")
    for i, c in enumerate(curves):
        f = ana["F_cr"].isel(curve=i)
        line = (f"analytic min F_cr = {fmt(float(f.min()))} at Omega = {fmt(float(f.idxmin('Omega')))}"
                if bool(f.notnull().any()) else "no analytic F_cr in the Omega range")
        if num is not None:
            g = num.isel(curve=i)
            line += (f"; numeric F_cr at {int(g['F_cr'].notnull().sum())} of {g.sizes['Omega']} Omega, "
                     f"{int(g['non_monotone'].sum())} non-monotone")
        click.echo(f"{c['label']}: {line}")


def fcr_numeric(params: Params, job: Job, quiet: bool) -> xr.Dataset:
    """Numeric F_cr in chunks of Omega (each point bisects independently, so the result equals one
    call; the library offers no per-level hook), with a progress bar per chunk."""
    import numpy as np
    import xarray as xr

    from safebasins.analysis.fcr_curves import numeric_fcr_curves

    n = params["numeric"]
    Om = n["Omega"]
    size = max(4, math.ceil(len(Om) / 20))
    parts = []
    with progress(len(Om), "numeric F_cr", "Omega", quiet) as bar:
        for i in range(0, len(Om), size):
            parts.append(numeric_fcr_curves(Om[i:i + size], params["curves"], well=well_of(params), cycles=n["cycles"],
                                            tol=n["tol"], F_bracket=n["F_bracket"], criterion=n["criterion"],
                                            n_scan=n["n_scan"], steps_per_cycle=n["steps_per_cycle"],
                                            threads=job.threads, backend=job.backend, label=params["experiment"]))
            bar.update(len(Om[i:i + size]))
    out = xr.concat(parts, dim="Omega", data_vars="minimal", coords="minimal", compat="override",
                    combine_attrs="override")
    # bisection_levels (an attribute, or a coordinate over curve where curves differ) counts the
    # levels of one call: the chunked run reports the maximum over its chunks, as one call would
    ncurve = out.sizes["curve"]
    levels = np.max([p["bisection_levels"].values if "bisection_levels" in p.coords
                     else np.full(ncurve, p.attrs["bisection_levels"]) for p in parts], axis=0).astype(np.int64)
    out = out.drop_vars("bisection_levels", errors="ignore")
    out.attrs.pop("bisection_levels", None)
    if np.all(levels == levels[0]):
        out.attrs["bisection_levels"] = int(levels[0])
    else:
        out = out.assign_coords(bisection_levels=("curve", levels))
    return out


@main.command()
@forcing_options
@click.option("--xi-max", "xi_max", type=Number("xi_max", THRESHOLD), required=True,
              help="Energy truncation level in (0, E_b) (with --damping > 0 also E_b itself).")
@grid_options
@click.option("--n-points", "n_points", cls=Deferred, type=int, default=from_schema("basin_rm", "n_points"),
              callback=checked("n_points", lib_check("safebasins.core.checks:check_positive_int")),
              help="Vertices per boundary curve.")
@click.option("--n-gamma", "n_gamma", type=click.IntRange(min=2),
              cls=Deferred, default=from_schema("basin_rm", "manifold", "n_gamma"),
              help="gamma points of the resonance-manifold panel.")
@click.option("--n-xi", "n_xi", type=click.IntRange(min=2),
              cls=Deferred, default=from_schema("basin_rm", "manifold", "n_xi"),
              help="xi points of the resonance-manifold panel.")
@click.option("--xi-top", "xi_top", type=Number("xi_top", ENERGY), default=None,
              help="Top of the resonance-manifold panel (< E_b) [default: the well's, Well.manifold_top = "
                   "0.9996 E_b: 0.2499 for the quartic].")
@damping_option()
@common_options
@out_option("basin")
def basin(F: float, Omega: float, Psi: float, xi_max: float, grid: dict[str, list[float]] | None, n: list[int],
          n_points: int, n_gamma: int, n_xi: int, xi_top: float | None, damping: float, fourier: str | None,
          well: dict[str, Any], no_plot: bool, quiet: bool, verbose: bool, allow_expensive: bool, out: str) -> None:
    """Analytic safe basin of the slow flow, on the resonance manifold and on the IC plane.

    PREFIX.nc has the layout of the pipeline's Figs 5-9: boundary curves (`gamma`, `xi`,
    `q0_vertex`, `p0_vertex`, `kind`), `escapes(q0, p0)`, `C` and `escapes_rm` on
    (gamma_rm, xi_rm); PREFIX.png is the two-panel figure.  With --damping beta > 0 the first
    integral C is not conserved: only the IC plane applies (the damped slow flow's `escapes(q0, p0)`
    and the outline of its safe mask as the boundary curves, docs/damping.md); the
    resonance-manifold options are refused there.

    Example: safebasins basin --F 0.0876 --Omega 0.92 --xi-max 0.24
    """
    from safebasins.pipeline.values import damping_param

    ctx = click.get_current_context()
    analytic_thresholds(ctx, [(xi_max, damping)])
    if damping > 0:
        given = [OPTION_OF.get(k, f"--{k.replace('_', '-')}") for k in ("n_gamma", "n_xi", "xi_top")
                 if ctx.get_parameter_source(k) is not click.core.ParameterSource.DEFAULT]
        if given:
            raise click.BadParameter(f"{', '.join(given)} set the resonance-manifold panel, which does not apply "
                                     f"with --damping {fmt(damping)} > 0 (C is not conserved; only the IC plane "
                                     "is drawn)", param_hint="'--damping'")
    if xi_top is None:
        xi_top = current_well(ctx).manifold_top
    if not xi_top > 0:
        raise click.BadParameter(f"must be > 0, got {xi_top}", param_hint="'--xi-top'")
    name = Path(out).name
    fourier = fourier_of(ctx, fourier)
    params: Params = dict(command="basin", kind="basin_rm", experiment=name, fourier=fourier, well=well, F=F,
                          Omega=Omega, Psi=Psi, xi_max=xi_max, grid=grid_params(grid, n), n_points=n_points,
                          manifold={"n_gamma": n_gamma, "n_xi": n_xi, "xi_top": xi_top}, **damping_param(damping))
    damped, beta = damping_text(damping)
    params["title"] = (f"Analytic {damped}safe basin, {well_label(well)} well, F = {fmt(F)}, Omega = {fmt(Omega)}, "
                       f"Psi = {fmt(Psi, angle=True)}, xi_max = {fmt(xi_max)}{beta} (safebasins basin {name})")
    if damping > 0:  # no resonance-manifold panel: C is not conserved
        params["manifold"] = {"n_gamma": 0, "n_xi": 0, "xi_top": xi_top}
    cost_guard("basin_rm", params, allow_expensive, numeric=False)
    from safebasins.analysis.ic_basins import add_resonance_manifold, analytic_basin

    with library_errors(), chatter(verbose):
        w = well_of(params)
        q0, p0 = grid_axes(params["grid"])
        ds = analytic_basin(F, Omega, Psi, xi_max, q0, p0, well=w, n_points=n_points, label=name, damping=damping)
        if damping == 0:  # the resonance-manifold panel: level curves of the conserved C
            ds = add_resonance_manifold(ds, F, Omega, xi_max, n_gamma=n_gamma, n_xi=n_xi, xi_top=xi_top, well=w)
        ds.attrs.update(F=F, Omega=Omega, Psi=Psi, xi_max=xi_max, fourier=fourier)
        ds = finish(ds, title=params["title"], params=params)
        fig = None
        if not no_plot:
            from safebasins.plotting.api import plot_basin
            from safebasins.plotting.basins import figure_rm_basin

            fig = draw(plot_basin, ds) if damping > 0 else draw(figure_rm_basin, ds)
    write_outputs([(f"{out}.nc", ds)], fig, f"{out}.png")
    safe = ~ds["escapes"].astype(bool)
    kinds = sorted({str(k) for k in ds["kind"].values if str(k)})
    click.echo(f"analytic safe: {int(safe.sum())} of {safe.size} ICs ({float(safe.mean()):.1%}); "
               f"boundary curves: {', '.join(kinds) or 'none'}")


@main.command()
@click.argument("file", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--params/--no-params", "show_params", default=True, show_default=True,
              help="Print the parameters JSON (briefly).")
def info(file: Path, show_params: bool) -> None:
    """What a safebasins netCDF dataset holds and where it came from."""
    for line in describe(file, show_params=show_params):
        click.echo(line)
