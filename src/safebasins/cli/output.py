"""Output plumbing of the command line: provenance, progress bars, figures, files, `info`."""
from __future__ import annotations

import contextlib
import json
import os
import shlex
import sys
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, TypeVar

import click

from safebasins.pipeline.values import fmt  # noqa: F401  (the one number/angle formatter: commands import it from here)

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

    from safebasins.pipeline.registry import Job, Params

T = TypeVar("T")

#: global attributes shown under "provenance" (never among the physical parameters)
PROVENANCE = ("safebasins_version", "git_commit", "date_created", "config_hash", "source", "history",
              "Conventions")


def command_line() -> str:
    """The CF ``history``: the command as typed."""
    return shlex.join(["safebasins", *sys.argv[1:]])


def chatter(verbose: bool) -> contextlib.redirect_stdout[Any]:
    """The pipeline build functions print log lines: to stderr with --verbose, else dropped (stdout
    is the command's own report)."""
    import io

    return contextlib.redirect_stdout(sys.stderr if verbose else io.StringIO())


def progress(total: float, desc: str, unit: str, quiet: bool) -> Any:
    """tqdm bar with ETA on stderr; off with --quiet, and off when stderr is not a terminal (typed Any:
    tqdm has no type information in the environment)."""
    from tqdm import tqdm  # type: ignore[import-untyped,unused-ignore]  # (no stubs: types-tqdm not installed)

    try:  # a terminal that reports no size (a bare pty) would get no bar at all
        size = os.get_terminal_size(sys.stderr.fileno())
        shape: dict[str, int] = {"ncols": size.columns or 80, "nrows": size.lines or 24}
    except (OSError, ValueError):
        shape = {}
    return tqdm(total=total, desc=desc, unit=unit, file=sys.stderr, disable=True if quiet else None, **shape)


def job(threads: int | None, backend: str) -> Job:
    """How the pipeline build functions compute (threads, backend): never what they compute."""
    from safebasins.pipeline.registry import Job

    return Job(threads=threads, backend=backend)


def finish(ds: xr.Dataset, *, title: str, params: Params) -> xr.Dataset:
    """CF + provenance attributes (params = the command's resolved arguments; history = command line)."""
    from safebasins.io.datasets import finalize

    return finalize(ds, title=title, params=params, history=command_line())


def draw(builder: Callable[..., T], *args: Any, **kw: Any) -> T:
    """Build a figure with a pipeline figure builder under the shared style (Agg: no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    from safebasins.plotting.style import style

    with style():
        return builder(*args, **kw)


def write_outputs(datasets: Sequence[tuple[str, xr.Dataset]], fig: Figure | None, png: str) -> None:
    """Write the datasets, then the PNG, each atomically.  Called once everything is computed and
    drawn, so a bad argument or a failed computation leaves no file behind."""
    from safebasins.io.datasets import write_netcdf
    from safebasins.io.files import atomic_path

    for path, ds in datasets:
        write_netcdf(ds, path)
        click.echo(f"wrote {path}")
    if fig is not None:
        import matplotlib.pyplot as plt

        from safebasins.plotting.style import save_figure

        with atomic_path(png) as tmp:       # provenance of the datasets in the PNG (and the well named)
            save_figure(fig, tmp, datasets=[ds for _, ds in datasets])
        plt.close(fig)
        click.echo(f"wrote {png}")


def describe(path: str | os.PathLike[str], show_params: bool = True, width: int = 100) -> list[str]:
    """Lines: title, dims, coordinates with ranges, variables with units, parameters, provenance, agreement."""
    import numpy as np
    import xarray as xr

    from safebasins.plotting.data import HEADLINE, SUMMARY_ATTRS

    try:
        ds = xr.load_dataset(path, engine="netcdf4")
    except (OSError, ValueError, RuntimeError) as exc:
        raise click.BadParameter(f"{path} is not a readable netCDF file ({str(exc).splitlines()[0]})",
                                 param_hint="'FILE'") from None
    a = ds.attrs

    def span(v: xr.DataArray) -> str:
        x = np.asarray(v.values)
        if x.size == 0:
            return "empty"
        if x.dtype.kind == "b":
            return f"{int(x.sum())} of {x.size} true"
        if x.dtype.kind in "fiu":
            fin = x[np.isfinite(x)] if x.dtype.kind == "f" else x
            if fin.size == 0:
                return "all NaN"
            rng = f"[{fin.min():.6g}, {fin.max():.6g}]" if fin.size > 1 else f"{fin.min():.6g}"
            return rng + (f", {x.size - fin.size} non-finite" if fin.size < x.size else "")
        vals = [str(s) for s in x.ravel()[:4]]
        return ", ".join(vals) + (" ..." if x.size > 4 else "")

    def number(c: Any) -> str:
        return f"{c:.6g}" if np.asarray(c).dtype.kind in "fiu" else str(c)

    def label(v: xr.DataArray) -> str:
        u, ln = v.attrs.get("units"), v.attrs.get("long_name")
        return "  ".join(s for s in (f"[{u}]" if u else "", ln or "") if s)

    lines = [f"{path}", f"  title: {a.get('title', '(none)')}"]
    if "experiment" in a:
        lines.append(f"  experiment: {a['experiment']}")
    if "well" in a:
        detail = a.get("well_expression", a.get("well_potential", a.get("well_coefficients", "")))
        lines.append(f"  well: {a['well']}" + (f" (V = {detail})" if len(str(detail)) else ""))
    lines.append("dimensions: " + (", ".join(f"{k}={v}" for k, v in ds.sizes.items()) or "none"))
    lines.append("coordinates:")
    for k, v in ds.coords.items():
        lines.append(f"  {k} ({', '.join(map(str, v.dims))}): {span(v)}  {label(v)}".rstrip())
    lines.append("data variables:")
    for k, v in ds.data_vars.items():
        lines.append(f"  {k} ({', '.join(map(str, v.dims))}) {v.dtype}: {span(v)}  {label(v)}".rstrip())
    shown = [k for k in SUMMARY_ATTRS if k in a and k not in PROVENANCE and k != "title"]
    if shown:
        lines.append("parameters: " + ", ".join(f"{k}={a[k]}" for k in shown))
    lines.append("provenance:")
    for k in ("safebasins_version", "git_commit", "date_created", "config_hash", "history"):
        lines.append(f"  {k}: {a.get(k, '(missing)')}")
    if show_params and "parameters" in a:
        lines.append("  parameters:")
        try:
            params = json.loads(a["parameters"])
        except ValueError:
            params = None
        if isinstance(params, dict):  # one line per key, long values cut
            for k, v in params.items():
                txt = json.dumps(v)
                lines.append(f"    {k}: {txt if len(txt) <= width else txt[:width - 5] + ' ...'}")
        else:
            lines.append(f"    {a['parameters']}")
    heads = [v for v in HEADLINE if v in ds]
    if heads:
        t = a.get("agreement_t_eval")
        lines.append("headline numbers" + (f" (agreement at t_eval = {t} EC)" if t is not None else "") + ":")
        for v in heads:
            da = ds[v]
            if da.ndim == 1:
                c = da[da.dims[0]].values
                vals = ", ".join(f"{da.dims[0]} = {number(ci)}: {x:.4f}" for ci, x in zip(c, da.values))
            else:
                vals = np.array2string(np.asarray(da.values), precision=4).replace("\n", " ")
            lines.append(f"  {v}: {vals}")
    return lines
