"""Plotting any dataset of the API or the command line (not only the pipeline's layout).

Each function draws one figure from the Datasets that :mod:`safebasins.numerics`,
:mod:`safebasins.theory` and :mod:`safebasins.analysis.integrity_map` return, or that
``safebasins chart|fcr|basin`` write to PREFIX.nc, with the same drawing pieces as the paper's
figures (:mod:`~safebasins.plotting.charts`, :mod:`~safebasins.plotting.basins`,
:mod:`~safebasins.plotting.fcr`, :mod:`~safebasins.plotting.integrity_maps`).  They return the
Figure and write nothing; ``ax=`` draws into an existing axes.  A dataset without a variable the
figure needs is a ValueError naming it (:class:`safebasins.plotting.data.MissingData`).  Save
with :func:`safebasins.plotting.style.save_figure` to keep the datasets' provenance in the PNG.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.legend_handler import HandlerTuple

from safebasins.plotting import data
from safebasins.plotting.charts import CRITERIA, agreement_time, chart_scan, draw_nested_chart, draw_nested_safe
from safebasins.plotting.curves import IC_LINE, boundary_polylines, draw_well, plot_curve
from safebasins.plotting.data import DataSource, MissingData, open_dataset, param, source, var
from safebasins.plotting.integrity_maps import plot_integrity_map
from safebasins.plotting.style import (LABELS, SB_EDGE, SB_FACE, SYMBOLS, add_footnote, fmt_value, new_axes,
                                       param_text)
from safebasins.plotting.basins import draw_ic_basin
from safebasins.plotting.fcr import (CURVE_COLORS, CURVE_MARKERS, bracket_handle, curve_labels, draw_fcr,
                                     draw_fcr_numeric, ic_text, mechanism_key, mechanism_legend_handles, omega_margins)

if TYPE_CHECKING:
    from collections.abc import Iterable

    import numpy.typing as npt
    import xarray as xr
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from matplotlib.patches import Polygon
    from matplotlib.typing import ColorType

__all__ = ["plot_escape_chart", "plot_basin", "plot_fcr", "plot_integrity_map"]

FORCING = ("F", "Omega", "Psi")


def _attrs_text(ds: xr.Dataset, names: Iterable[str]) -> str:
    """``F = 0.01, Omega = 0.9, ...`` of the attributes a dataset has (parameters it does not
    carry are left out, never guessed)."""
    return param_text({k: ds.attrs[k] for k in names if k in ds.attrs})


def plot_escape_chart(chart: DataSource, *, t_eval: float | None = None, xi_max: npt.ArrayLike | None = None,
                      basin: DataSource | None = None, ax: Axes | None = None) -> Figure:
    """Draw the numeric safe basins of an escape chart, optionally with analytic boundaries.

    Parameters
    ----------
    chart : xarray.Dataset or path
        From :func:`safebasins.numerics.escape_chart` on a grid (dims ``q0``, ``p0``), the
        ``safebasins chart`` command (PREFIX.nc) or the pipeline (``chart_<experiment>.nc``,
        also stacked over ``F``).  Uses ``escape_cycle_energy`` (one basin per ``xi_max``), or
        ``escape_cycle_displacement`` (one per ``q_max``) when the chart has no energy criterion,
        and the attribute ``cycles``.
    t_eval : float, optional
        Evaluation time in forcing cycles: safe = ``escape_cycle > t_eval``
        (:func:`safebasins.analysis.safe.is_safe`).  Default: the chart's stored agreement time,
        else its horizon ``cycles``.
    xi_max : float or sequence, optional
        Draw only these energy thresholds (each must be in the chart).
    basin : xarray.Dataset or path, optional
        Analytic boundaries to overlay: :func:`safebasins.theory.safe_basin_boundaries` (one
        basin: drawn with the threshold equal to its ``xi_max``, or its ``F`` for a chart stacked
        over F) or a pipeline basin stack (``basin_<experiment>.nc``).  A damped basin
        (attribute ``damping``) must match the chart's damping; its lines are the outline of its
        safe mask.
    ax : matplotlib.axes.Axes, optional
        Draw into this axes (legend to its right); default: a new figure.

    Returns
    -------
    matplotlib.figure.Figure
        Basins nested in grey (lighter contains darker; white = escape for every threshold),
        analytic boundaries as coloured lines.

    Raises
    ------
    ValueError
        A variable or attribute the figure needs is missing (named), a requested ``xi_max`` is
        not in the chart, or ``t_eval`` lies beyond the horizon.

    Examples
    --------
    >>> import numpy as np
    >>> import safebasins.numerics as nu, safebasins.theory as th
    >>> from safebasins.plotting import plot_escape_chart
    >>> q0, p0 = np.linspace(-0.9, 0.9, 60), np.linspace(-0.7, 0.7, 60)
    >>> chart = nu.escape_chart(q0, p0, F=0.01, Omega=0.9, Psi=np.pi, xi_max=(0.14, 0.18), cycles=200)
    >>> basin = th.safe_basin_boundaries(0.01, 0.9, np.pi, 0.18)
    >>> fig = plot_escape_chart(chart, basin=basin)
    >>> fig.savefig("chart.png")  # doctest: +SKIP
    """
    chart = open_dataset(chart)
    basin = open_dataset(basin)
    criterion = "energy" if "escape_cycle_energy" in chart.variables else "displacement"
    name, thr = CRITERIA[criterion]
    if name not in chart.variables:
        raise MissingData(f"{source(chart)}: no variable 'escape_cycle_energy' or 'escape_cycle_displacement' "
                          f"(it has {sorted(map(str, chart.data_vars))})")
    horizon = float(param(chart, "cycles"))
    t = agreement_time(chart) if t_eval is None else float(t_eval)
    if t > horizon:
        raise ValueError(f"t_eval = {t} lies beyond the chart's horizon cycles = {horizon}")
    if xi_max is not None:
        if criterion != "energy":
            raise ValueError(f"{source(chart)}: xi_max selects energy thresholds, the chart has none "
                             "(no 'escape_cycle_energy')")
        have = np.atleast_1d(np.asarray(var(chart, "xi_max"), float))
        want = np.atleast_1d(np.asarray(xi_max, float))
        idx = [np.flatnonzero(np.isclose(have, x, rtol=1e-9, atol=1e-12)) for x in want]
        missing = [float(x) for x, i in zip(want, idx) if not i.size]
        if missing:
            raise ValueError(f"xi_max = {missing} not in the chart (it has {have.tolist()})")
        chart = chart.isel(xi_max=[int(i[0]) for i in idx])
    scan = chart_scan(chart, criterion)
    fig, ax = new_axes(ax, figsize=(8.8, 5.4))
    data.attach(fig, chart, basin)
    draw_nested_chart(ax, chart, scan=scan, t_eval=t, basins=basin, criterion=criterion, strict=False,
                      show_iou=t_eval is None)
    head = f"Numeric safe basins ({criterion} criterion, $t_{{eval}}$ = {fmt_value(t)} EC)"
    fixed = _attrs_text(chart, [k for k in (*FORCING, "damping") if k != scan])
    ax.set_title(head + (f"\n{fixed}" if fixed else ""), fontsize=10)
    return fig


def _stack_dim(basin: xr.Dataset) -> str | None:
    """The dimension a basin dataset is stacked over (``xi_max``, ``F``), or None."""
    extra = [str(d) for d in var(basin, "q0_vertex").dims if d != "vertex"]
    if len(extra) > 1:
        raise ValueError(f"{source(basin)}: q0_vertex has dimensions {extra} besides 'vertex': select one basin")
    return extra[0] if extra else None


def _draw_basin_slice(ax: Axes, b: xr.Dataset, *, color: ColorType = SB_EDGE,
                      ls: str = "-") -> list[Line2D | Polygon]:
    lines: list[Line2D | Polygon] = []
    for xs, ys, _kind in boundary_polylines(b, "q0_vertex", "p0_vertex"):
        lines += plot_curve(ax, xs, ys, color=color, ls=ls, lw=1.8, zorder=6, **IC_LINE)
    return lines


def plot_basin(basin: DataSource, *, ax: Axes | None = None) -> Figure:
    """Draw the analytic (slow-flow) safe basin on the plane of initial conditions.

    Parameters
    ----------
    basin : xarray.Dataset or path
        From :func:`safebasins.theory.safe_basin_boundaries` (boundary vertices ``q0_vertex``,
        ``p0_vertex``, ``curve_index``, ``kind``), the ``safebasins basin`` command (PREFIX.nc) or
        the pipeline (``basin_<experiment>.nc``, also stacked over ``xi_max`` or ``F``: one colour
        per value).  Where it holds the per-IC mask ``escapes(q0, p0)`` (e.g. from
        :func:`safebasins.theory.slow_flow_escapes`, see the example) the basin is filled grey;
        the attributes ``xi_max`` and ``well`` add the well edge ``H0 = xi_max``.  A damped basin
        (:func:`safebasins.analysis.ic_basins.analytic_basin` with ``damping > 0``, attribute
        ``damping``) is drawn the same way; its boundary curves are the outline of its safe mask,
        named so in the legend, and beta is in the title.
    ax : matplotlib.axes.Axes, optional
        Draw into this axes; default: a new figure.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        A boundary variable is missing (the message names it).

    Examples
    --------
    >>> import numpy as np, xarray as xr
    >>> import safebasins.theory as th
    >>> from safebasins.plotting import plot_basin
    >>> basin = th.safe_basin_boundaries(0.01, 0.9, np.pi, 0.18)
    >>> fig = plot_basin(basin)                      # boundaries and the well edge
    >>> q0, p0 = np.linspace(-0.9, 0.9, 80), np.linspace(-0.7, 0.7, 80)
    >>> esc = th.slow_flow_escapes(q0[:, None], p0[None, :], 0.01, 0.9, np.pi, 0.18)
    >>> basin["escapes"] = xr.DataArray(esc, dims=("q0", "p0"), coords={"q0": q0, "p0": p0})
    >>> fig = plot_basin(basin)                      # filled
    """
    basin = open_dataset(basin)
    for v in ("q0_vertex", "p0_vertex", "curve_index", "kind"):
        var(basin, v)
    dim = _stack_dim(basin)
    fig, ax = new_axes(ax, figsize=(6.2, 5.2))
    data.attach(fig, basin)
    has_well = "well" in basin.attrs
    damped = float(basin.attrs.get("damping", 0.0)) > 0
    flow = "damped slow flow" if damped else "slow flow"
    handles: list[Artist]
    if dim is None:
        draw_ic_basin(ax, basin, well=has_well and "xi_max" in basin.attrs)
        handles = [Line2D([], [], color=SB_EDGE, lw=1.8, label="safe-basin boundary (" + (
            "damped slow flow, mask outline" if damped else "slow flow") + ")")]
    else:
        vals = np.asarray(var(basin, dim), float)
        slices = [basin.isel({dim: i}) for i in range(vals.size)]
        colors = plt.get_cmap("tab10")
        if "escapes" in basin.variables:  # lighter contains darker, as in Figs 13-17
            draw_nested_safe(ax, [~var(b, "escapes").astype(bool) for b in slices])
        for i, b in enumerate(slices):
            _draw_basin_slice(ax, b, color=colors(i % 10))
        handles = []
        for i in np.argsort(vals):
            handles.append(Line2D([], [], color=colors(int(i) % 10), lw=1.8,
                                  label=f"{SYMBOLS.get(dim, dim)} = {fmt_value(vals[i])}"))
        if has_well:
            xm = float(vals.max()) if dim == "xi_max" else float(param(basin, "xi_max"))
            draw_well(ax, xm, data.well(basin))
        ax.set_aspect("equal")
        ax.set_xlabel(LABELS["q0"])
        ax.set_ylabel(LABELS["p0"])
    if has_well and ("xi_max" in basin.attrs or dim == "xi_max"):
        handles.append(Line2D([], [], color="0.35", ls=(0, (4, 2)), lw=0.9, label=r"well edge $H_0 = \xi_{max}$"))
    if "escapes" in basin.variables:
        handles.insert(0, Patch(facecolor=SB_FACE, label=f"safe ({flow})"))
    if damped and dim is not None:
        handles.append(Line2D([], [], color="0.3", lw=1.8, label="lines: damped slow flow (mask outline)"))
    ax.legend(handles=handles, loc="best", fontsize=8)
    shown = _attrs_text(basin, [k for k in (*FORCING, "xi_max", "damping") if k != dim])
    ax.set_title(("Analytic damped safe basin" if damped else "Analytic safe basin") + (f": {shown}" if shown else ""),
                 fontsize=10)
    return fig


def _curves(ds: xr.Dataset | None) -> list[xr.Dataset]:
    if ds is None:
        return []
    return [ds.isel(curve=i) for i in range(ds.sizes["curve"])] if "curve" in ds.dims else [ds]


def plot_fcr(analytic: DataSource | None = None, numeric: DataSource | None = None, *,
             ax: Axes | None = None) -> Figure:
    """Draw the critical forcing F_cr(Omega): theory as lines, numerics as markers.

    Parameters
    ----------
    analytic : xarray.Dataset or path, optional
        From :func:`safebasins.theory.critical_forcing` (``F_cr`` over ``Omega``; its
        ``mechanism`` sets the line style: MM dashed/dash-dot, SM solid, SMM dotted), a stack over
        ``curve`` (pipeline ``fcr_figNN.nc``, ``safebasins fcr`` PREFIX.nc).
    numeric : xarray.Dataset or path, optional
        From :func:`safebasins.numerics.critical_forcing_numeric` (``F_cr`` over ``Omega``;
        with ``F_escape_low``, ``F_escape_all`` and ``non_monotone`` the non-monotone escape
        brackets are drawn as black bars), or a stack over ``curve`` matching ``analytic``.
    ax : matplotlib.axes.Axes, optional
        Draw into this axes; default: a new figure.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        Neither dataset given, or one lacks ``F_cr`` or ``Omega`` (the message names it).

    Examples
    --------
    >>> import numpy as np
    >>> import safebasins.numerics as nu, safebasins.theory as th
    >>> from safebasins.plotting import plot_fcr
    >>> ana = th.critical_forcing(np.linspace(0.6, 1.2, 200), xi_max=0.15)
    >>> num = nu.critical_forcing_numeric([0.7, 0.9, 1.1], 0.15, cycles=100, n_scan=8)
    >>> fig = plot_fcr(ana, num)
    """
    analytic, numeric = open_dataset(analytic), open_dataset(numeric)
    ref = analytic if analytic is not None else numeric
    if ref is None:
        raise ValueError("give at least one of analytic (theory.critical_forcing) and numeric "
                         "(numerics.critical_forcing_numeric)")
    for ds in (analytic, numeric):
        if ds is not None:
            for name in ("F_cr", "Omega"):
                var(ds, name)
    own = ax is None
    fig, ax = new_axes(ax, figsize=(6.6, 4.8))
    data.attach(fig, analytic, numeric)
    labels, const = curve_labels(ref.expand_dims("curve") if "curve" not in ref.dims else ref)
    several = "curve" in ref.dims and ref.sizes["curve"] > 1
    colors = CURVE_COLORS if several else ["k"]
    handles: list[Artist | tuple[Artist, ...]] = []
    texts: list[str] = []
    mechs: set[int] = set()
    if analytic is not None:
        mechs, _ = draw_fcr(ax, analytic, color_by="curve" if several else "mechanism", colors=colors, legend=False)
        hs = mechanism_legend_handles(mechs, by_mechanism_color=not several)
        handles += hs
        texts += [str(h.get_label()) for h in hs]
    n_bracket = 0
    nums = _curves(numeric)
    for i, b in enumerate(nums):
        bracket = all(v in b.variables for v in ("F_escape_low", "F_escape_all", "non_monotone"))
        n_bracket += draw_fcr_numeric(ax, b, color=colors[i % len(colors)] if several else "tab:orange",
                                      marker=CURVE_MARKERS[i % len(CURVE_MARKERS)] if several else "o",
                                      bracket=bracket)
    if several:
        handles = [Line2D([], [], color=colors[i % len(colors)], lw=1.8,
                          marker=CURVE_MARKERS[i % len(CURVE_MARKERS)] if nums else None) for i in
                   range(len(labels))] + handles
        texts = list(labels) + texts
    if nums and numeric is not None:
        cyc = f" ({fmt_value(numeric.attrs['cycles'])} EC)" if "cycles" in numeric.attrs else ""
        handles.append(Line2D([], [], ls="none", marker="o", mfc="k" if several else "tab:orange", mec="k", ms=5))
        texts.append("numeric bisection" + cyc)
    if n_bracket:
        handles.append(bracket_handle())
        texts.append(r"non-monotone in $F$: $F_{escape,low}$ .. $F_{escape,all}$")
    ax.legend(handles, texts, handler_map={tuple: HandlerTuple(ndivide=None, pad=0.2)}, loc="best", fontsize=8)
    Om = np.concatenate([np.asarray(var(d, "Omega"), float).ravel() for d in (analytic, numeric) if d is not None])
    omega_margins(ax, Om)
    vals = np.concatenate([np.asarray(var(d, "F_cr"), float).ravel() for d in (analytic, numeric) if d is not None])
    vals = vals[np.isfinite(vals)]
    ax.set_ylim(0, 1.08 * vals.max() if vals.size else 1.0)
    ax.set_xlabel(LABELS["Omega"])
    ax.set_ylabel(LABELS["F_cr"])
    head = ic_text(const)
    ax.set_title("Critical forcing" + (f", {head}" if head else ""), fontsize=10)
    if own and mechs:   # the legend's abbreviations in words, under a figure of its own
        add_footnote(fig, "Mechanisms: " + mechanism_key(mechs))
    return fig
