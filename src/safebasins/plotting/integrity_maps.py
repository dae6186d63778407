"""Integrity maps over the control plane (Omega, F): slow flow, numerics, their difference and
the erosion fronts (datasets of the ``integrity_map`` kind and of
:mod:`safebasins.analysis.integrity_map`, docs/contracts.md)."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D

from safebasins.plotting import data
from safebasins.plotting.captions import add_note, count
from safebasins.plotting.data import DataSource, open_dataset, param, var
from safebasins.plotting.style import LABELS, fmt_value, new_axes, param_text, plain_text

if TYPE_CHECKING:
    from collections.abc import Mapping

    import numpy.typing as npt
    import xarray as xr
    from matplotlib.axes import Axes
    from matplotlib.collections import QuadMesh
    from matplotlib.figure import Figure
    from matplotlib.typing import ColorType

MEASURES = ("GIM", "LIM")
#: erosion-front line styles: slow flow, numerics, the slow flow's all-phase basin
FRONT_STYLE: dict[str, dict[str, Any]] = {"analytic": dict(lw=1.6, ls="-"), "numeric": dict(lw=1.8, ls=":"),
                                          "all_phase": dict(lw=1.3, ls="--")}
FRONT_TEXT = {"analytic": "slow flow solid", "numeric": "numerics dotted", "all_phase": "all-phase slow flow dashed"}


def symmetric_limit(*arrays: npt.ArrayLike) -> float:
    """Colour limit of a difference map: the largest ``|value|`` of the data, rounded up to two
    significant digits (never the full +-1 range, on which small differences look blank)."""
    v = np.concatenate([np.abs(np.asarray(a, float)).ravel() for a in arrays])
    v = v[np.isfinite(v)]
    top = float(v.max()) if v.size else 0.0
    if top <= 0:
        return 1e-3
    e = 10 ** (np.floor(np.log10(top)) - 1)
    return float(np.ceil(top / e) * e)


def draw_measure_map(ax: Axes, da: xr.DataArray, *, label: str, diverging: bool = False, limit: float | None = None,
                     cbar: bool = True) -> QuadMesh:
    """One measure over (Omega, F) as a pcolormesh with a labelled colourbar: viridis on 0..1,
    or, ``diverging``, RdBu on a symmetric scale from the data (``limit`` to share one)."""
    Om = np.asarray(da["Omega"], float)  # the dims of a measure over the control plane
    F = np.asarray(da["F"], float)
    Z = np.asarray(da.transpose("F", "Omega"), float)
    kw: dict[str, Any]
    if diverging:
        lim = limit if limit is not None else symmetric_limit(Z)
        kw = dict(cmap="RdBu", vmin=-lim, vmax=lim)
    else:
        kw = dict(cmap="viridis", vmin=0.0, vmax=1.0)
    mesh = ax.pcolormesh(Om, F, Z, shading="nearest", rasterized=True, **kw)
    if cbar:
        ax.figure.colorbar(mesh, ax=ax, shrink=0.85, label=label)
    ax.set_xlim(Om.min(), Om.max())
    ax.set_ylim(F.min(), F.max())
    ax.set_xlabel(LABELS["Omega"])
    ax.set_ylabel(LABELS["F"])
    return mesh


def draw_front(ax: Axes, ds: xr.Dataset, name: str, *, color: ColorType = "w", style: str = "analytic") -> list[Line2D]:
    """An erosion front ``name`` (F over Omega) of a dataset."""
    return ax.plot(np.asarray(var(ds, "Omega"), float), np.asarray(var(ds, name), float), color=color,
                   **FRONT_STYLE[style])


def _all_phase(m: str) -> str:
    return f"F_{m}_true"


def figure_integrity_map(analytic: DataSource, numeric: DataSource, *, t_eval: float | None = None,
                         title: str | None = None) -> Figure:
    """Rows: analytic, numeric (at ``t_eval``, default the last), numeric - analytic; columns: GIM,
    LIM.  Erosion fronts (F at which the measure falls to the stored level): slow flow solid and
    numerics dotted on every panel, the slow flow's all-phase basin dashed on the top row."""
    an = open_dataset(analytic)
    nu = open_dataset(numeric)
    t = float(var(nu, "t_eval")[-1] if t_eval is None else t_eval)
    nu_t = nu.sel(t_eval=t)
    fig, axes = plt.subplots(3, len(MEASURES), figsize=(5.2 * len(MEASURES), 11.0), layout="constrained",
                             sharex=True, sharey=True)
    data.attach(fig, an, nu)
    level = param(nu, "level")
    for j, m in enumerate(MEASURES):
        diff = var(nu_t, f"{m}_diff")
        rows = [(var(an, m), f"{m}, slow flow", f"{m} (normalised)"),
                (var(nu_t, m), f"{m}, numeric ($t_{{eval}}$ = {fmt_value(t)} EC)", f"{m} (normalised)"),
                (diff, f"{m}: numeric $-$ slow flow", f"{m}: numeric $-$ slow flow")]
        for i, (da, head, cb) in enumerate(rows):
            ax = axes[i, j]
            draw_measure_map(ax, da, label=cb, diverging=i == 2)
            edge = "k" if i == 2 else "w"
            draw_front(ax, an, f"F_{m}", color=edge, style="analytic")
            draw_front(ax, nu_t, f"F_{m}", color=edge, style="numeric")
            if i == 0:
                draw_front(ax, an, _all_phase(m), color=edge, style="all_phase")
            ax.set_title(head, fontsize=9.5)
            ax.label_outer()
    fig.legend(handles=[Line2D([], [], color="0.3", **FRONT_STYLE["analytic"], label=f"slow flow: measure = {level:g}"),
                        Line2D([], [], color="0.3", **FRONT_STYLE["numeric"], label=f"numeric: measure = {level:g}"),
                        Line2D([], [], color="0.3", **FRONT_STYLE["all_phase"],
                               label=f"slow flow, safe for every phase (top row): measure = {level:g}")],
               loc="outside lower center", ncol=3, fontsize=8.5, frameon=False)
    shown = {"xi_max": param(an, "xi_max"), "Psi": param(an, "Psi")}
    fig.suptitle(title or ("Integrity over the control plane: " + param_text(shown) +
                           f"\n{nu.sizes['Omega']} x {nu.sizes['F']} control points, {param(nu, 'cycles')} EC; "
                           "lines: erosion fronts"), fontsize=10.5)
    _map_notes(fig, an, nu, nu_t, t, level, shown)
    return fig


def _map_notes(fig: Figure, an: xr.Dataset, nu: xr.Dataset, nu_t: xr.Dataset, t: float, level: float,
               shown: Mapping[str, Any]) -> None:
    """Caption notes: grid, the differences and the fronts, read from the datasets."""
    Om, F = np.asarray(var(an, "Omega"), float), np.asarray(var(an, "F"), float)
    ts = np.asarray(var(nu, "t_eval"), float)
    add_note(fig, f"{plain_text(param_text(shown))}; {nu.sizes['Omega']} x {nu.sizes['F']} control points, "
                  f"Ω = {Om.min():.3g}-{Om.max():.3g}, F = {F.min():.3g}-{F.max():.3g}; "
                  + (f"ICs: {param(nu, 'integrity_grid')}; " if "integrity_grid" in nu.attrs else "")
                  + f"numerics over {param(nu, 'cycles')} EC, shown at t_eval = {fmt_value(t)} EC (stored: "
                  + ", ".join(fmt_value(x) for x in ts) + " EC). Fronts: F at which the measure falls to "
                  f"{fmt_value(level)}; " + ", ".join(FRONT_TEXT.values()) + " (the last on the top row only).")
    for m in MEASURES:
        d = np.asarray(var(nu_t, f"{m}_diff"), float)
        lim = symmetric_limit(d)
        over = int((d < -0.01).sum())
        fa, fn = np.asarray(var(an, f"F_{m}"), float), np.asarray(var(nu_t, f"F_{m}"), float)
        gap = np.abs(fn - fa)
        k = int(np.nanargmax(gap)) if np.isfinite(gap).any() else None
        txt = (f"{m}: numeric - slow flow from {np.nanmin(d):.3f} to {np.nanmax(d):.3f} (mean {np.nanmean(d):.3f}; "
               f"colour scale ±{lim:g}); the slow flow is higher by more than 0.01 at "
               f"{count(over, 'control point')} of {d.size}")
        if k is not None:
            txt += (f"; erosion fronts: median |F_numeric - F_slow flow| = {np.nanmedian(gap):.3g}, largest "
                    f"{gap[k]:.3g} at Ω = {Om[k]:.3g}")
        fp = np.asarray(var(an, _all_phase(m)), float)
        below = fa - fp
        if np.isfinite(below).any():
            txt += f"; the all-phase front lies {np.nanmin(below):.3g}-{np.nanmax(below):.3g} below the slow-flow one"
        add_note(fig, txt + ".")


def plot_integrity_map(ds: DataSource, *, measure: str = "GIM", ax: Axes | None = None) -> Figure:
    """Draw one integrity measure over the control plane (Omega, F).

    Parameters
    ----------
    ds : xarray.Dataset or path
        From :func:`safebasins.analysis.integrity_map.integrity_map_analytic` or
        :func:`~safebasins.analysis.integrity_map.integrity_map_numeric` (or the pipeline's
        ``integrity_map_analytic.nc`` / ``_numeric.nc``): the variable ``measure`` over
        (``Omega``, ``F``), optionally ``t_eval`` (the last one is drawn).
    measure : str
        ``"GIM"``, ``"LIM"``, ``"IF"``, the all-phase ``"GIM_true"``, ... or a difference
        ``"GIM_diff"`` (drawn on a symmetric diverging scale from the data).  Where the dataset
        holds the erosion front ``F_<measure>`` (:func:`~safebasins.analysis.integrity_map.erosion_front`
        merged in, or the pipeline's datasets) it is drawn as a white line.
    ax : matplotlib.axes.Axes, optional
        Draw into this axes (a colourbar is added beside it); default: a new figure.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        The dataset lacks ``measure``, ``Omega`` or ``F`` (the message names it).

    Examples
    --------
    >>> import numpy as np
    >>> from safebasins.analysis.integrity_map import integrity_map_analytic
    >>> from safebasins.plotting import plot_integrity_map
    >>> q0, p0 = np.linspace(-0.7, 0.7, 21), np.linspace(-0.6, 0.6, 21)
    >>> ds = integrity_map_analytic([0.8, 0.9, 1.0], [0.0, 0.02, 0.04], np.pi, 0.18, q0, p0)
    >>> fig = plot_integrity_map(ds, measure="LIM")
    """
    ds = open_dataset(ds)
    da = var(ds, measure)
    for d in ("Omega", "F"):
        var(ds, d)
    t = None
    if "t_eval" in da.dims:
        t = float(da["t_eval"][-1])
        da = da.isel(t_eval=-1)
    extra = [d for d in da.dims if d not in ("Omega", "F")]
    if extra:
        raise ValueError(f"{data.source(ds)}: {measure} has dimensions {extra} besides (Omega, F): select one value")
    fig, ax = new_axes(ax, figsize=(6.0, 4.6))
    data.attach(fig, ds)
    draw_measure_map(ax, da, label=measure + ("" if measure.endswith("_diff") else " (normalised)"),
                     diverging=measure.endswith("_diff"))
    front = f"F_{measure}"
    if front in ds.variables:
        at = ds.isel(t_eval=-1) if "t_eval" in ds[front].dims else ds
        (line,) = draw_front(ax, at, front, color="w", style="analytic")
        line.set_label(f"erosion front ({measure} = {fmt_value(ds.attrs['level'])})" if "level" in ds.attrs
                       else "erosion front")
        ax.legend(loc="upper center", fontsize=8)
    shown = {k: ds.attrs[k] for k in ("xi_max", "Psi") if k in ds.attrs}
    ax.set_title(f"{measure}" + (f", {param_text(shown)}" if shown else "")
                 + (f", $t_{{eval}}$ = {fmt_value(t)} EC" if t is not None else ""), fontsize=10)
    return fig
