"""Figures read from escape charts: nested safe basins with the theory boundaries (Figs 13-17),
the criteria comparison (Fig 19), DSB/ESB charts (Figs 20-21) and the safe area versus the
evaluation time (Fig 22).

Safe basin for a threshold and an evaluation time: :func:`safebasins.analysis.safe.is_safe`
(``escape_cycle > t_eval``), the one definition.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.legend_handler import HandlerTuple
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from scipy.spatial import cKDTree

from safebasins.analysis.safe import is_safe, safe_area
from safebasins.plotting.curves import (analytic_safe, boundary_polylines, plot_curve, safe_fill,
                                        separates_mask, xy_grid)
from safebasins.plotting.captions import add_note, count
from safebasins.plotting import data
from safebasins.plotting.data import load_params, open_dataset, param, source, var
from safebasins.plotting.style import LABELS, LAYOUT, SYMBOLS, fmt_value, grey_levels, param_text

if TYPE_CHECKING:
    import os
    from collections.abc import Sequence

    import numpy.typing as npt
    import xarray as xr
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from safebasins.plotting.data import DataSource

LINE_STYLES = ["-", "--", "-.", ":", (0, (5, 1, 1, 1, 1, 1))]
THEORY_COLORS = ["tab:red", "tab:blue", "tab:green", "tab:orange", "tab:purple", "tab:brown", "tab:pink"]


def resolution(chart: xr.Dataset) -> str:
    return f"{chart.sizes['q0']}x{chart.sizes['p0']}"


# --------------------------------------------------------------------------------------------
# Figs 13-17: nested numeric safe basins, theory boundaries, IoU
# --------------------------------------------------------------------------------------------
#: escape-time variable of a chart per criterion and the dimension of its thresholds
CRITERIA: dict[str, tuple[str, str]] = {"energy": ("escape_cycle_energy", "xi_max"),
                                         "displacement": ("escape_cycle_displacement", "q_max")}


def chart_scan(chart: xr.Dataset, criterion: str = "energy") -> str:
    """The scanned parameter of a chart: its attribute ``scan`` (pipeline charts), else ``F`` for
    a chart stacked over F, else the thresholds of the criterion (``xi_max`` / ``q_max``)."""
    if "scan" in chart.attrs:
        return str(param(chart, "scan"))
    name, thr = CRITERIA[criterion]
    dims = var(chart, name).dims
    if "control" in dims:
        raise ValueError(f"{source(chart)}: {name} has a 'control' dimension (escape_chart_batch): select one "
                         "control point first, e.g. chart.isel(control=0)")
    return "F" if "F" in dims else thr


def scan_masks(chart: xr.Dataset, scan: str, t_eval: float,
               criterion: str = "energy") -> tuple[npt.NDArray[np.float64], list[xr.DataArray]]:
    """-> (values of the scanned parameter, safe masks over (q0, p0), one per value)."""
    name, _ = CRITERIA[criterion]
    ec = var(chart, name)
    vals = np.atleast_1d(np.asarray(var(chart, scan), float))
    masks: list[xr.DataArray] = []
    for i in range(vals.size):
        e = ec.isel({scan: i}) if scan in ec.dims else ec
        # squeeze the other singleton dims (xi_max in an F stack)
        extra = [d for d in e.dims if d not in ("q0", "p0")]
        for d in extra:
            if e.sizes[d] != 1:
                raise ValueError(f"{source(chart)}: {name} has an extra non-singleton dimension {d!r}")
        masks.append(is_safe(e.isel({d: 0 for d in extra}), t_eval))
    return vals, masks


def draw_nested_safe(ax: Axes, masks: Sequence[xr.DataArray], *, order: Sequence[int] | None = None,
                     greys: Sequence[str] | None = None) -> dict[int, str]:
    """Paint safe masks so that lighter regions include darker ones: the largest basin is
    painted first (lightest), smaller ones on top (darker). Returns {index: grey}."""
    n = len(masks)
    if order is None:
        order = sorted(range(n), key=lambda i: -int(np.asarray(masks[i]).sum()))
    greys = greys or grey_levels(n)
    shade: dict[int, str] = {}
    for rank, i in enumerate(order):
        q, p, Z = xy_grid(masks[i])
        safe_fill(ax, q, p, Z.astype(bool), color=greys[rank], zorder=1 + rank * 0.01)
        shade[i] = greys[rank]
    return shade


def theory_slices(basins: xr.Dataset, scan: str, vals: npt.NDArray[np.float64], *,
                  strict: bool = True) -> list[xr.Dataset | None]:
    """Slices of a boundary stack matching the numeric parameter values.  ``strict``: a missing
    value is a ValueError (the analytic and numeric datasets of a figure describe the same
    scan); otherwise it is None.  A single basin (not stacked over ``scan``) matches the value
    of its attribute ``scan``."""
    out: list[xr.Dataset | None]
    if scan not in basins.dims:
        v0 = float(param(basins, scan))
        out = [basins if np.isclose(v0, v, rtol=1e-6, atol=1e-12) else None for v in vals]
        if strict and any(o is None for o in out):
            raise ValueError(f"no analytic basin for {scan} = {[float(v) for v, o in zip(vals, out) if o is None]} "
                             f"(the analytic basin has {scan} = {v0})")
        return out
    bv = np.asarray(var(basins, scan), float)
    out = []
    for v in vals:
        j = np.flatnonzero(np.isclose(bv, v, rtol=1e-6, atol=1e-12))
        if not j.size and strict:
            raise ValueError(f"no analytic basin for {scan} = {v} (analytic {scan}: {bv.tolist()})")
        out.append(basins.isel({scan: int(j[0])}) if j.size else None)
    return out


def _resample(xs: npt.NDArray[np.float64], ys: npt.NDArray[np.float64], n: int = 400) -> npt.NDArray[np.float64]:
    """Points of a polyline (NaN gaps dropped) resampled to about ``n`` points by arc length."""
    ok = np.isfinite(xs) & np.isfinite(ys)
    x, y = xs[ok], ys[ok]
    if x.size < 2:
        return np.c_[x, y]
    d = np.r_[0, np.cumsum(np.hypot(np.diff(x), np.diff(y)))]
    t = np.linspace(0, d[-1], n)
    return np.c_[np.interp(t, d, x), np.interp(t, d, y)]


def coincident_groups(curves: Sequence[tuple[int, npt.ArrayLike, npt.ArrayLike]],
                      tol: float) -> list[tuple[list[int], float]]:
    """Groups of polylines (``curves``: [(slice, xs, ys), ...]) of different slices that run
    along each other (every point of each within ``tol`` of the other): [([i, j, ...], largest
    distance), ...]."""
    pts = [_resample(np.asarray(x, float), np.asarray(y, float)) for _, x, y in curves]
    parent = list(range(len(curves)))
    dist: dict[int, float] = {}

    def root(i: int) -> int:
        while parent[i] != i:
            i = parent[i]
        return i

    for i in range(len(curves)):
        for j in range(i + 1, len(curves)):
            if curves[i][0] == curves[j][0] or len(pts[i]) < 2 or len(pts[j]) < 2:
                continue
            d = max(cKDTree(pts[j]).query(pts[i])[0].max(), cKDTree(pts[i]).query(pts[j])[0].max())
            if d < tol:
                ri, rj = root(i), root(j)
                parent[rj] = ri
                dist[ri] = max(dist.get(ri, 0.0), dist.pop(rj, 0.0), d)
    groups: dict[int, list[int]] = {}
    for i in range(len(curves)):
        groups.setdefault(root(i), []).append(i)
    return [(g, dist.get(r, 0.0)) for r, g in groups.items() if len(g) > 1]


#: boundaries of different parameter values closer than this many chart pixels everywhere are
#: drawn as one line of alternating colours (each colour stays visible)
COINCIDE_PIXELS = 2.5


def basin_damping(ds: xr.Dataset | None) -> float:
    """The damping beta of a dataset (attribute ``damping``; 0 without it: the undamped equation)."""
    return float(ds.attrs.get("damping", 0.0)) if ds is not None else 0.0


def draw_nested_chart(ax: Axes, chart: xr.Dataset, *, scan: str, t_eval: float, basins: xr.Dataset | None = None,
                      criterion: str = "energy", boundary_only: bool = True, strict: bool = True,
                      show_iou: bool = True) -> tuple[npt.NDArray[np.float64], list[tuple[list[float], float]]]:
    """Numeric safe basins of a chart nested by ``scan`` (lighter contains darker) with the
    analytic boundaries of ``basins`` (optional) as curves, legend on the right; a damped basin's
    boundaries are the outline of its safe mask (attribute ``boundary = "mask_outline"``,
    :func:`safebasins.analysis.ic_basins.mask_outline`), named so in the legend.  Boundaries of
    several values that stay within COINCIDE_PIXELS of each other are drawn in alternating
    colours.  Returns ``(values, shared)``: the scanned values and [(values, largest
    distance), ...] of the coinciding boundaries."""
    if basins is not None and basin_damping(basins) != basin_damping(chart):
        raise ValueError(f"{source(chart)}: the numeric chart has damping {basin_damping(chart)} but the analytic "
                         f"basin {basin_damping(basins)} (attribute damping; none = 0)")
    vals, masks = scan_masks(chart, scan, t_eval, criterion)
    shade = draw_nested_safe(ax, masks)
    theory: list[xr.Dataset | None] = (theory_slices(basins, scan, vals, strict=strict) if basins is not None
                                       else [None] * len(vals))
    iou = np.atleast_1d(np.asarray(chart["iou"], float)) if show_iou and "iou" in chart.variables else None
    q = np.asarray(var(chart, "q0"), float)
    p = np.asarray(var(chart, "p0"), float)
    style = {i: (THEORY_COLORS[i % len(THEORY_COLORS)], LINE_STYLES[i % len(LINE_STYLES)]) for i in range(len(vals))}
    curves: list[tuple[int, npt.NDArray[np.float64], npt.NDArray[np.float64]]] = []
    for i, th in enumerate(theory):
        if th is None:
            continue
        safe = analytic_safe(th) if boundary_only and "escapes" in th.variables else None
        for xs, ys, _kind in boundary_polylines(th, "q0_vertex", "p0_vertex"):
            if safe is None or separates_mask(xs, ys, safe):
                curves.append((i, xs, ys))
    px = max(q[1] - q[0], p[1] - p[0]) if q.size > 1 and p.size > 1 else 0.0
    groups = coincident_groups(curves, COINCIDE_PIXELS * px)
    grouped = {k for g, _ in groups for k in g}
    for k, (i, xs, ys) in enumerate(curves):
        if k not in grouped:
            col, ls = style[i]
            plot_curve(ax, xs, ys, color=col, ls=ls, lw=1.6, zorder=6)
    shared: list[tuple[list[float], float]] = []
    seg = 3.0  # dash length (in line widths): each member draws every n-th segment in its colour
    for g, d in groups:
        members = sorted(g, key=lambda k: vals[curves[k][0]])
        n = len(members)
        for r, k in enumerate(members):
            i, xs, ys = curves[k]
            plot_curve(ax, xs, ys, color=style[i][0], lw=1.9, ls=(r * seg * 1.9, (seg * 1.9, (n - 1) * seg * 1.9)),
                       zorder=6, dash_capstyle="butt")
        shared.append((sorted({float(vals[curves[k][0]]) for k in members}), d / px if px else 0.0))
    drawn = {i for i, _, _ in curves}
    outline = basins is not None and basin_damping(basins) > 0
    hs: list[Artist | tuple[Artist, ...]] = []
    ls_: list[str] = []
    for i in np.argsort(vals):  # legend in parameter order
        col, ls = style[i]
        lab = f"{SYMBOLS.get(scan, scan)} = {fmt_value(vals[i])}"
        if iou is not None:  # the stored IoU is that of the agreement's t_eval
            lab += f"   IoU = {iou[i]:.3f}"
        face = Patch(facecolor=shade[i], edgecolor="none")
        hs.append((face, Line2D([], [], color=col, ls=ls, lw=1.6)) if i in drawn else face)
        ls_.append(lab)
    hs.append(Patch(facecolor="white", edgecolor="0.5", lw=0.5))
    ls_.append("escape for all values")
    for vs, d in {(tuple(v), d) for v, d in shared}:
        idx = [int(np.flatnonzero(np.isclose(vals, v))[0]) for v in vs]
        hs.append(tuple(Line2D([], [], color=style[i][0], lw=1.9) for i in idx))
        ls_.append("alternating colours: one boundary\nshared by " + ", ".join(fmt_value(v) for v in vs)
                   + (f"\n(within {d:.1f} pixels)" if d >= 0.5 else ""))
    ax.set_xlim(q.min(), q.max())
    ax.set_ylim(p.min(), p.max())
    ax.set_aspect("equal")
    ax.set_xlabel(LABELS["q0"])
    ax.set_ylabel(LABELS["p0"])
    ax.legend(hs, ls_, handler_map={tuple: HandlerTuple(ndivide=None, pad=0)}, loc="upper left",
              bbox_to_anchor=(1.02, 1.0), borderaxespad=0,
              title="numeric SB (grey)" + ((" / damped slow flow\n(mask outline, lines)" if outline else
                                           " / theory (lines)") if curves else ""), title_fontsize=8)
    return vals, shared


def agreement_time(chart: xr.Dataset) -> float:
    """The evaluation time of a chart's stored agreement (``agreement_t_eval``), else its horizon."""
    return float(param(chart, "agreement_t_eval") if "agreement_t_eval" in chart.attrs else param(chart, "cycles"))


def figure_nested_basins(analytic: DataSource | None, numeric: DataSource, *, title: str | None = None,
                         t_eval: float | None = None, figsize: tuple[float, float] = (9.6, 5.6),
                         boundary_only: bool = True) -> Figure:
    """Figs 13-17: numeric safe basins shaded by the scanned parameter (attribute ``scan``, else
    :func:`chart_scan`: lighter regions include darker ones, white = escape for every value),
    theory boundaries as curves, the stored IoU in the legend.  ``t_eval`` defaults to the
    agreement's evaluation time (else the horizon); ``boundary_only``: draw only the theory
    curves that border the analytic safe mask; ``analytic`` may be None (numerics only).
    Boundaries of several parameter values that coincide (e.g. a saddle-type curve below every
    threshold) are drawn as one line of alternating colours, each colour still visible.  Damped
    data (attribute ``damping``): beta in the title and a note, the analytic boundary
    is the outline of the damped slow flow's safe mask (the numeric and analytic damping must be
    equal)."""
    chart = open_dataset(numeric)
    basins = open_dataset(analytic)
    scan = chart_scan(chart)
    t_ev = agreement_time(chart) if t_eval is None else float(t_eval)
    fig, ax = plt.subplots(figsize=figsize, layout=LAYOUT)
    data.attach(fig, basins, chart)
    # a stack over the scan must match it value for value; a single basin draws with its own value
    strict = basins is not None and scan in basins.dims
    vals, shared = draw_nested_chart(ax, chart, scan=scan, t_eval=t_ev, basins=basins, boundary_only=boundary_only,
                                     strict=strict, show_iou=t_eval is None)
    fixed = {k: param(chart, k) for k in ("F", "Omega", "Psi", "xi_max", "damping") if k != scan and
             (k in chart.attrs or (k in chart.coords and chart[k].size == 1))}
    beta = basin_damping(chart)
    ax.set_title(title or (("Damped safe basins" if beta > 0 else "Safe basins") + f" vs {SYMBOLS.get(scan, scan)}: "
                           + param_text(fixed) + f"\n(numeric: {resolution(chart)} ICs, {fmt_value(t_ev)} EC; "
                           "lighter regions contain darker ones)"))
    name = {"xi_max": "ξ_max", "F": "F"}.get(scan, scan)
    if beta > 0:
        add_note(fig, f"Damped equation q'' + β q' + V'(q) = F sin(Ω t + Ψ), β = {fmt_value(beta)}: the numerics "
                      "integrate it; the analytic basin is the damped slow flow's (an IC is safe when its slow "
                      "trajectory settles on an attractor below ξ_max, docs/damping.md), its boundary drawn as the "
                      "outline of the analytic safe mask (level curves of C bound no damped basin).")
    add_note(fig, f"Numeric basins: {resolution(chart)} ICs, energy criterion, safe = no escape within "
                  f"{fmt_value(t_ev)} EC" + (f" (agreement evaluated at {fmt_value(agreement_time(chart))} EC)."
                                             if "iou" in chart.variables else "."))
    if all(v in chart.variables for v in ("iou", "pixel_agreement", "safe_numeric", "safe_analytic")):
        iou, pix, n_num, n_ana = (np.atleast_1d(np.asarray(chart[v], float))
                                  for v in ("iou", "pixel_agreement", "safe_numeric", "safe_analytic"))
        add_note(fig, "Analytic vs numeric, per " + name + ": " + "; ".join(
            f"{fmt_value(vals[i])}: IoU {iou[i]:.3f}, pixel agreement {pix[i]:.3f}, safe ICs {int(n_ana[i]):,} "
            f"analytic / {int(n_num[i]):,} numeric" for i in np.argsort(vals)) + ".")
    for vs, d in shared:
        add_note(fig, f"The analytic boundaries of {name} = {', '.join(fmt_value(v) for v in vs)} "
                      + ("coincide along one curve" if d < 0.5 else
                         f"run within {d:.1f} chart pixels of each other ({COINCIDE_PIXELS:g} pixels or less "
                         "counts as one line)") + " (drawn in alternating colours).")
    return fig


# --------------------------------------------------------------------------------------------
# Fig 19: relative difference of the two escape criteria
# --------------------------------------------------------------------------------------------
def figure_criteria(numeric: DataSource, *, title: str | None = None,
                    figsize: tuple[float, float] = (6.4, 4.4)) -> Figure:
    ds = open_dataset(numeric)
    rd = var(ds, "rel_diff").transpose("F", "repeat")
    F = np.asarray(var(ds, "F"), float)
    stats = [("min", rd.min("repeat"), "tab:blue"), ("mean", rd.mean("repeat"), "tab:orange"),
             ("max", rd.max("repeat"), "tab:green")]
    fig, ax = plt.subplots(figsize=figsize, layout="constrained")
    for name, v, c in stats:
        ax.plot(F, np.asarray(v, float), "o", color=c, ms=5, label=f"{name} of {rd.sizes['repeat']}")
    ax.axhline(0, color="0.6", lw=0.6)
    ax.set_xlabel(LABELS["F"])
    ax.set_ylabel(r"$(A_q - A_E)/A_E$")
    ax.legend(loc="upper left")
    params = {k: param(ds, k) for k in ("Omega", "Psi", "xi_max", "q_max")}
    extra = f"{int(param(ds, 'n_ic'))} random ICs in $[-1,1]^2$, {fmt_value(param(ds, 'cycles'))} EC"
    ax.set_title(title or ("Displacement vs energy criterion: " + param_text(params) + "\n" + extra))
    mean = np.asarray(rd.mean("repeat"), float)
    big = mean > 0.01
    add_note(fig, f"{int(param(ds, 'n_ic')):,} random ICs per repetition, {rd.sizes['repeat']} repetitions, "
                  f"{fmt_value(param(ds, 'cycles'))} EC, F = {fmt_value(F.min())} ... {fmt_value(F.max())}.")
    add_note(fig, f"Mean (A_q - A_E)/A_E: {100 * mean[0]:.2f}% at F = {fmt_value(F[0])}, "
                  f"{100 * mean[-1]:.1f}% at F = {fmt_value(F[-1])}, largest {100 * np.nanmax(mean):.1f}% at "
                  f"F = {fmt_value(F[np.nanargmax(mean)])}; "
                  + (f"first above 1% at F = {fmt_value(F[np.argmax(big)])}." if big.any() else "below 1% at every F."))
    return fig


# --------------------------------------------------------------------------------------------
# Figs 20-22: DSB / ESB charts and area vs t_eval
# --------------------------------------------------------------------------------------------
def has_dsb(chart: xr.Dataset) -> bool:
    """Whether a chart has a displacement threshold (a DSB; the energy criterion alone for a well
    other than the quartic, whose escape is over its own barriers)."""
    return "escape_cycle_displacement" in chart.variables and chart.sizes.get("q_max", 0) > 0


def chart_thresholds(chart: xr.Dataset) -> tuple[float, float | None]:
    """The (first) energy and displacement thresholds of a chart (displacement None without one)."""
    qm = float(np.asarray(var(chart, "q_max")).ravel()[0]) if has_dsb(chart) else None
    return float(np.asarray(var(chart, "xi_max")).ravel()[0]), qm


def draw_dsb_esb(ax: Axes, chart: xr.Dataset, t_eval: float) -> None:
    """DSB (displacement criterion) grey, ESB (energy criterion) black on top (the ESB alone for a
    chart without displacement threshold)."""
    esb = var(chart, "escape_cycle_energy").isel(xi_max=0)
    q, p, Ze = xy_grid(esb)
    if has_dsb(chart):
        _, _, Zd = xy_grid(var(chart, "escape_cycle_displacement").isel(q_max=0))
        safe_fill(ax, q, p, is_safe(Zd, t_eval), color="0.62", zorder=1)
    safe_fill(ax, q, p, is_safe(Ze, t_eval), color="k", zorder=2)
    ax.set_xlim(q.min(), q.max())
    ax.set_ylim(p.min(), p.max())
    ax.set_aspect("equal")
    ax.set_xlabel(LABELS["q0"])
    ax.set_ylabel(LABELS["p0"])
    ax.set_title(rf"$t_{{eval}}$ = {t_eval:,.0f} EC")


def _t_evals(params: str | os.PathLike[str], t_evals: npt.ArrayLike | None) -> list[float]:
    """Evaluation times: explicit, else the experiment's parameter file ``t_eval``."""
    vals = load_params(params)["t_eval"] if t_evals is None else t_evals
    return [float(t) for t in np.atleast_1d(vals)]


def ec(t: float) -> str:
    """A time in forcing cycles for captions: "11,000 EC", "145 EC", "9,697 EC"."""
    t = float(t)
    return f"{t:,.0f} EC" if abs(t) >= 10 or t == round(t) else f"{t:.3g} EC"


def _area_curves(chart: xr.Dataset, t: npt.ArrayLike) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Safe pixels of the energy (ESB) and displacement (DSB; NaN without one) criteria at
    evaluation times t."""
    area = safe_area(chart, np.asarray(t, float))
    nE = np.asarray(area["pixels_energy"].isel(xi_max=0), float)
    return nE, (np.asarray(area["pixels_displacement"].isel(q_max=0), float) if has_dsb(chart)
                else np.full(nE.shape, np.nan))


def _last_escape(chart: xr.Dataset, name: str, dim: str) -> float:
    """Latest finite escape time of a criterion on the chart (NaN if nothing escapes)."""
    e = np.asarray(var(chart, name).isel({dim: 0}), float)
    e = e[np.isfinite(e)]
    return float(e.max()) if e.size else np.nan


def settle_time(t: npt.ArrayLike, n: npt.ArrayLike, frac: float = 0.01) -> float:
    """First t from which the area n(t) stays within ``frac`` of its final value."""
    t, n = np.asarray(t, float), np.asarray(n, float)
    off = np.flatnonzero(np.abs(n - n[-1]) > frac * max(n[-1], 1.0))
    return float(t[0]) if not off.size else float(t[min(off[-1] + 1, t.size - 1)])


def _esb_notes(fig: Figure, chart: xr.Dataset, t_evals: Sequence[float]) -> None:
    """Caption notes of a chart with the energy criterion only."""
    nE, _ = _area_curves(chart, t_evals)
    esc = np.asarray(var(chart, "escape_cycle_energy").isel(xi_max=0), float)
    changed = int(((esc > t_evals[0]) != (esc > t_evals[-1])).sum())
    add_note(fig, f"Safe pixels of {esc.size:,}: " + "; ".join(f"t_eval = {ec(t)}: ESB {int(e):,}"
                                                              for t, e in zip(t_evals, nE)) + ".")
    add_note(fig, f"No displacement threshold (q_max) in the chart: the ESB alone; between t_eval = {ec(t_evals[0])} "
                  f"and {ec(t_evals[-1])} {count(changed, 'ESB pixel')} change, the last energy escape is at "
                  f"{ec(_last_escape(chart, 'escape_cycle_energy', 'xi_max'))}.")


def figure_dsb_esb(numeric: DataSource, params: str | os.PathLike[str], *, t_evals: npt.ArrayLike | None = None,
                   title: str | None = None, figsize: tuple[float, float] | None = None) -> Figure:
    """Figs 20-21: DSB grey / ESB black at the first (left) and last (right) t_eval."""
    chart = open_dataset(numeric)
    t_evals = _t_evals(params, t_evals)
    if figsize is None:  # panels follow the window's aspect ratio (equal axes)
        aspect = np.ptp(np.asarray(chart["p0"], float)) / max(np.ptp(np.asarray(chart["q0"], float)), 1e-12)
        w = 5.6
        figsize = (w * len(t_evals) + 0.6, min(w * aspect, 7.5) + 1.5)
    fig, axes = plt.subplots(1, len(t_evals), figsize=figsize, layout=LAYOUT, squeeze=False)
    data.attach(fig, chart)
    for ax, t in zip(axes[0], t_evals):
        draw_dsb_esb(ax, chart, t)
    xi, qm = chart_thresholds(chart)
    fig.legend(handles=([Patch(facecolor="0.62", label=f"DSB: displacement criterion, $q_{{max}}$ = {fmt_value(qm)}")]
                        if qm is not None else [])
               + [Patch(facecolor="k", label=rf"ESB: energy criterion, $\xi_{{max}}$ = {fmt_value(xi)}")],
               loc="outside lower center", ncol=2, fontsize=9, frameon=False)
    shown = {k: param(chart, k) for k in ("F", "Omega", "Psi")}
    shown["xi_max"] = xi
    head = ("Safe basins by the displacement (DSB, grey) and energy (ESB, black) criterion" if qm is not None
            else "Safe basins by the energy criterion (ESB, black; no displacement threshold)")
    fig.suptitle(title or (head + "\n" + param_text(shown) + f", resolution {resolution(chart)}"), fontsize=10.5)
    if qm is None:
        _esb_notes(fig, chart, t_evals)
        return fig
    # what the data show
    nE, nD = _area_curves(chart, t_evals)
    esc = np.asarray(var(chart, "escape_cycle_energy").isel(xi_max=0), float)
    dsc = np.asarray(var(chart, "escape_cycle_displacement").isel(q_max=0), float)
    t0, t1 = t_evals[0], t_evals[-1]
    changed_E = int(((esc > t0) != (esc > t1)).sum())
    changed_D = int(((dsc > t0) != (dsc > t1)).sum())
    outside = int(max(((esc > t) & ~(dsc > t)).sum() for t in t_evals))
    n = esc.size
    add_note(fig, "Safe pixels of " + f"{n:,}: " + "; ".join(
        f"t_eval = {ec(t)}: ESB {int(e):,}, DSB {int(d):,}" for t, e, d in zip(t_evals, nE, nD)) + ".")
    irregular_E = changed_E > 0.01 * max(nE[0], 1)  # more than 1% of the ESB changes: a transient shows
    add_note(fig, "Paper: at the short t_eval both boundaries are irregular (transients), at the long one smoother. "
                  + ("Reproduced" if irregular_E else "Not reproduced") + f" for the ESB: between t_eval = {ec(t0)} "
                  f"and {ec(t1)} {count(changed_E, 'ESB pixel')} change ({100 * changed_E / max(nE[0], 1):.2g}% of "
                  "the ESB" + (", the same set of pixels at both)" if changed_E == 0 else ")")
                  + f", the last energy escape in the chart is at "
                  f"{ec(_last_escape(chart, 'escape_cycle_energy', 'xi_max'))}. The DSB changes by "
                  f"{count(changed_D, 'pixel')} ({100 * changed_D / max(nD[0], 1):.2g}%), the last displacement escape "
                  f"at {ec(_last_escape(chart, 'escape_cycle_displacement', 'q_max'))}.")
    add_note(fig, f"ESB pixels outside the DSB: {outside} (the DSB contains the ESB"
                  + (")." if outside == 0 else " except for these)."))
    return fig


#: the paper's Fig 22 text: "rapid shrinking for about 2000 EC, followed by almost no change"
PAPER_SHRINK_EC = 2000.0


def figure_area_vs_time(numeric: DataSource, params: str | os.PathLike[str], *, t_evals: npt.ArrayLike | None = None,
                        title: str | None = None, figsize: tuple[float, float] = (11.5, 4.6),
                        n_log: int = 300) -> Figure:
    """Fig 22: ln(SB area in pixels) vs t_eval, DSB dashed, ESB solid.  Left, as in the paper: a
    linear time axis with a point per configured t_eval; right: a logarithmic time axis from one
    cycle (so that the early transient shows), the configured t_eval plus ``n_log`` log-spaced
    times.  Everything is read from the same chart."""
    chart = open_dataset(numeric)
    t_cfg = np.asarray(_t_evals(params, t_evals), float)
    horizon = float(param(chart, "cycles"))
    t = np.unique(np.r_[np.geomspace(1.0, horizon, n_log), t_cfg])
    nE, nD = _area_curves(chart, t)
    cE, cD = _area_curves(chart, t_cfg)
    fig, (a_lin, a_log) = plt.subplots(1, 2, figsize=figsize, layout="constrained")
    data.attach(fig, chart)
    xi, qm = chart_thresholds(chart)
    with np.errstate(divide="ignore"):
        lE, lD, pE, pD = (np.where(n > 0, np.log(n), np.nan) for n in (nE, nD, cE, cD))
    ms = 3.0 if t_cfg.size <= 100 else 1.6
    if qm is not None:
        a_lin.plot(t_cfg, pD, ls="--", color="k", lw=0.8, marker="o", ms=ms, mfc="w", mew=0.6,
                   label=f"DSB ($q_{{max}}$ = {fmt_value(qm)})")
    a_lin.plot(t_cfg, pE, ls="-", color="k", lw=0.8, marker="o", ms=ms, mew=0.6,
               label=rf"ESB ($\xi_{{max}}$ = {fmt_value(xi)})")
    a_lin.set_xlim(0, horizon * 1.01)
    a_lin.set_xlabel(LABELS["t_eval"])
    a_lin.set_title(f"as in the paper: one point per $t_{{eval}}$ ({t_cfg.size} values)", fontsize=9)
    if qm is not None:
        a_log.plot(t, lD, ls="--", color="k", lw=1.4)
    a_log.plot(t, lE, ls="-", color="k", lw=1.4)
    tE = _last_escape(chart, "escape_cycle_energy", "xi_max")
    tD = settle_time(t, nD) if qm is not None else np.nan
    for ax in (a_lin, a_log):
        for x, txt, yf in ((tE, "last ESB escape", 0.62), (tD, "DSB within 1%\nof its final area", 0.78)):
            if np.isfinite(x):
                ax.axvline(x, color="0.55", lw=0.8, ls=":")
                ax.text(x, yf, f" {txt}:\n {x:,.0f} EC", transform=ax.get_xaxis_transform(), fontsize=7.5,
                        color="0.3", va="top", ha="left")
        ax.set_ylabel(r"$\ln$(SB area / pixels)")
    a_log.set_xscale("log")
    a_log.set_xlabel(LABELS["t_eval"] + ", logarithmic")
    a_log.set_xlim(1.0, horizon)
    a_log.set_title(f"logarithmic time from 1 EC ({n_log} more times)", fontsize=9)
    a_lin.legend(loc="upper right")
    shown = {k: param(chart, k) for k in ("F", "Omega", "Psi")}
    shown["xi_max"] = xi
    fig.suptitle(title or ("Safe-basin area vs evaluation time: " + param_text(shown) +
                           f", resolution {resolution(chart)}"), fontsize=10.5)
    iD = np.interp(t_cfg, t, nD)
    t_short = float(np.atleast_1d(param(chart, "t_eval"))[0])
    add_note(fig, f"Read from the chart of {resolution(chart)} ICs over {ec(horizon)}, at the "
                  f"{t_cfg.size} configured t_eval ({ec(t_cfg.min())} ... {ec(t_cfg.max())}; left, one point each) and "
                  f"{n_log} log-spaced ones from {ec(1)} (right).")
    if qm is None:
        add_note(fig, f"No displacement threshold (q_max) in the chart: the ESB alone; it keeps {int(nE[-1]):,} pixels "
                      f"at {ec(horizon)}, its last escape at {ec(tE)}.")
        return fig
    reproduced = tE >= PAPER_SHRINK_EC / 2
    add_note(fig, f"Paper: the area shrinks rapidly for about {ec(PAPER_SHRINK_EC)} and then hardly changes. "
                  + ("Reproduced" if reproduced else "Not reproduced") + f" for the ESB: it loses its last pixel at "
                  f"{ec(tE)} and keeps {int(nE[-1]):,} pixels from there to {ec(horizon)} (identical at every later "
                  f"t_eval). The DSB falls from {int(iD[0]):,} pixels at {ec(t_cfg[0])} to {int(nD[-1]):,} at "
                  f"{ec(horizon)} and stays within 1% of its final value from {ec(tD)} on (within 5% from "
                  f"{ec(settle_time(t, nD, 0.05))}, within 0.1% from {ec(settle_time(t, nD, 0.001))}); the "
                  f"displacement escapes after {ec(t_cfg[0])} are {count(iD[0] - nD[-1], 'pixel')}, "
                  f"{100 * (iD[0] - np.interp(t_short, t, nD)) / max(iD[0] - nD[-1], 1):.0f}% of them by "
                  f"{ec(t_short)} (the short t_eval of the chart's own figure).")
    return fig


__all__ = ["figure_nested_basins", "figure_criteria", "figure_dsb_esb", "figure_area_vs_time",
           "draw_nested_safe", "draw_nested_chart", "draw_dsb_esb", "scan_masks", "theory_slices", "chart_scan",
           "chart_thresholds", "coincident_groups", "settle_time", "basin_damping"]
