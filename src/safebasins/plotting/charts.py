"""Figures read from escape charts: nested safe basins with the theory boundaries (Figs 13-17),
the criteria comparison (Fig 19), DSB/ESB charts (Figs 20-21) and the safe area versus the
evaluation time (Fig 22).

Safe basin for a threshold and an evaluation time: :func:`safebasins.analysis.safe.is_safe`
(``escape_cycle > t_eval``), the one definition.
"""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.legend_handler import HandlerTuple
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from safebasins.analysis.safe import is_safe, safe_area
from safebasins.plotting.basins import analytic_safe, draw_boundaries, safe_fill, xy_grid
from safebasins.plotting.data import load_params, open_dataset, param, var
from safebasins.plotting.style import LABELS, SYMBOLS, fmt_value, grey_levels, param_text

LINE_STYLES = ["-", "--", "-.", ":", (0, (5, 1, 1, 1, 1, 1))]
THEORY_COLORS = ["tab:red", "tab:blue", "tab:green", "tab:orange", "tab:purple", "tab:brown", "tab:pink"]


def resolution(chart) -> str:
    return f"{chart.sizes['q0']}x{chart.sizes['p0']}"


# --------------------------------------------------------------------------------------------
# Figs 13-17: nested numeric safe basins, theory boundaries, IoU
# --------------------------------------------------------------------------------------------
def scan_masks(chart, scan, t_eval):
    """-> (values of the scanned parameter, safe masks over (q0, p0), one per value)."""
    ec = var(chart, "escape_cycle_energy")
    vals = np.atleast_1d(np.asarray(var(chart, scan), float))
    masks = []
    for i in range(vals.size):
        e = ec.isel({scan: i}) if scan in ec.dims else ec
        # squeeze the other singleton dims (xi_max in an F stack)
        extra = [d for d in e.dims if d not in ("q0", "p0")]
        for d in extra:
            if e.sizes[d] != 1:
                raise ValueError(f"escape chart has an extra non-singleton dimension {d!r}")
        masks.append(is_safe(e.isel({d: 0 for d in extra}), t_eval))
    return vals, masks


def draw_nested_safe(ax, masks, *, order=None, greys=None):
    """Paint safe masks so that lighter regions include darker ones: the largest basin is
    painted first (lightest), smaller ones on top (darker). Returns {index: grey}."""
    n = len(masks)
    if order is None:
        order = sorted(range(n), key=lambda i: -int(np.asarray(masks[i]).sum()))
    greys = greys or grey_levels(n)
    shade = {}
    for rank, i in enumerate(order):
        q, p, Z = xy_grid(masks[i])
        safe_fill(ax, q, p, Z.astype(bool), color=greys[rank], zorder=1 + rank * 0.01)
        shade[i] = greys[rank]
    return shade


def theory_slices(basins, scan, vals):
    """Slices of a boundary stack matching the numeric parameter values (ValueError if one is
    missing: the analytic and numeric datasets of a figure describe the same scan)."""
    bv = np.asarray(var(basins, scan), float)
    out = []
    for v in vals:
        j = np.flatnonzero(np.isclose(bv, v, rtol=1e-6, atol=1e-12))
        if not j.size:
            raise ValueError(f"no analytic basin for {scan} = {v} (analytic {scan}: {bv.tolist()})")
        out.append(basins.isel({scan: int(j[0])}))
    return out


def figure_nested_basins(analytic, numeric, *, title=None, t_eval=None, figsize=(9.6, 5.6), boundary_only=True):
    """Figs 13-17: numeric safe basins shaded by the scanned parameter (attribute ``scan``:
    lighter regions include darker ones, white = escape for every value), theory boundaries as
    curves, the stored IoU in the legend.  ``t_eval`` defaults to the agreement's evaluation
    time; ``boundary_only``: draw only the theory curves that border the analytic safe mask."""
    chart = open_dataset(numeric)
    basins = open_dataset(analytic)
    scan = param(chart, "scan")
    t_ev = float(param(chart, "agreement_t_eval") if t_eval is None else t_eval)
    vals, masks = scan_masks(chart, scan, t_ev)
    fig, ax = plt.subplots(figsize=figsize, layout="constrained")
    shade = draw_nested_safe(ax, masks)
    theory = theory_slices(basins, scan, vals)
    iou = np.atleast_1d(np.asarray(var(chart, "iou"), float))
    handles = []
    for i in np.argsort(vals):  # legend in parameter order
        col = THEORY_COLORS[i % len(THEORY_COLORS)]
        ls = LINE_STYLES[i % len(LINE_STYLES)]
        draw_boundaries(ax, theory[i], color=col, ls=ls, lw=1.6,
                        safe=analytic_safe(theory[i]) if boundary_only else None)
        lab = f"{SYMBOLS[scan]} = {fmt_value(vals[i])}"
        if t_eval is None:  # the stored IoU is that of the agreement's t_eval
            lab += f"   IoU = {iou[i]:.3f}"
        handles.append(((Patch(facecolor=shade[i], edgecolor="none"), Line2D([], [], color=col, ls=ls, lw=1.6)), lab))
    q = np.asarray(chart["q0"], float)
    p = np.asarray(chart["p0"], float)
    ax.set_xlim(q.min(), q.max())
    ax.set_ylim(p.min(), p.max())
    ax.set_aspect("equal")
    ax.set_xlabel(LABELS["q0"])
    ax.set_ylabel(LABELS["p0"])
    hs = [h for h, _ in handles] + [Patch(facecolor="white", edgecolor="0.5", lw=0.5)]
    ls_ = [lab for _, lab in handles] + ["escape for all values"]
    ax.legend(hs, ls_, handler_map={tuple: HandlerTuple(ndivide=None, pad=0)}, loc="upper left",
              bbox_to_anchor=(1.02, 1.0), borderaxespad=0,
              title="numeric SB (grey) / theory (lines)", title_fontsize=8)
    fixed = {k: param(chart, k) for k in ("F", "Omega", "Psi", "xi_max") if k != scan}
    ax.set_title(title or (f"Safe basins vs {SYMBOLS[scan]}: " + param_text(fixed) +
                           f"\n(numeric: {resolution(chart)} ICs, {fmt_value(t_ev)} EC; "
                           "lighter regions contain darker ones)"))
    return fig


# --------------------------------------------------------------------------------------------
# Fig 19: relative difference of the two escape criteria
# --------------------------------------------------------------------------------------------
def figure_criteria(numeric, *, title=None, figsize=(6.4, 4.4)):
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
    return fig


# --------------------------------------------------------------------------------------------
# Figs 20-22: DSB / ESB charts and area vs t_eval
# --------------------------------------------------------------------------------------------
def chart_thresholds(chart):
    """The (first) energy and displacement thresholds of a chart."""
    return float(np.asarray(var(chart, "xi_max")).ravel()[0]), float(np.asarray(var(chart, "q_max")).ravel()[0])


def draw_dsb_esb(ax, chart, t_eval):
    """DSB (displacement criterion) grey, ESB (energy criterion) black on top."""
    esb = var(chart, "escape_cycle_energy").isel(xi_max=0)
    dsb = var(chart, "escape_cycle_displacement").isel(q_max=0)
    q, p, Zd = xy_grid(dsb)
    _, _, Ze = xy_grid(esb)
    safe_fill(ax, q, p, is_safe(Zd, t_eval), color="0.62", zorder=1)
    safe_fill(ax, q, p, is_safe(Ze, t_eval), color="k", zorder=2)
    ax.set_xlim(q.min(), q.max())
    ax.set_ylim(p.min(), p.max())
    ax.set_aspect("equal")
    ax.set_xlabel(LABELS["q0"])
    ax.set_ylabel(LABELS["p0"])
    ax.set_title(rf"$t_{{eval}}$ = {t_eval:,.0f} EC")


def _t_evals(params, t_evals):
    """Evaluation times: explicit, else the experiment's parameter file ``t_eval``."""
    vals = load_params(params)["t_eval"] if t_evals is None else t_evals
    return [float(t) for t in np.atleast_1d(vals)]


def figure_dsb_esb(numeric, params, *, t_evals=None, title=None, figsize=None):
    """Figs 20-21: DSB grey / ESB black at the first (left) and last (right) t_eval."""
    chart = open_dataset(numeric)
    t_evals = _t_evals(params, t_evals)
    if figsize is None:  # panels follow the window's aspect ratio (equal axes)
        aspect = np.ptp(np.asarray(chart["p0"], float)) / max(np.ptp(np.asarray(chart["q0"], float)), 1e-12)
        w = 5.6
        figsize = (w * len(t_evals) + 0.6, min(w * aspect, 7.5) + 1.5)
    fig, axes = plt.subplots(1, len(t_evals), figsize=figsize, layout="constrained", squeeze=False)
    for ax, t in zip(axes[0], t_evals):
        draw_dsb_esb(ax, chart, t)
    xi, qm = chart_thresholds(chart)
    fig.legend(handles=[
        Patch(facecolor="0.62", label=f"DSB: displacement criterion, $q_{{max}}$ = {fmt_value(qm)}"),
        Patch(facecolor="k", label=rf"ESB: energy criterion, $\xi_{{max}}$ = {fmt_value(xi)}")],
        loc="outside lower center", ncol=2, fontsize=9, frameon=False)
    shown = {k: param(chart, k) for k in ("F", "Omega", "Psi")}
    shown["xi_max"] = xi
    fig.suptitle(title or ("Safe basins by the displacement (DSB, grey) and energy (ESB, black) "
                           "criterion\n" + param_text(shown) + f", resolution {resolution(chart)}"), fontsize=10.5)
    return fig


def figure_area_vs_time(numeric, params, *, t_evals=None, title=None, figsize=(6.6, 4.4)):
    """Fig 22: ln(SB area in pixels) vs t_eval, DSB dashed, ESB solid (one point per t_eval)."""
    chart = open_dataset(numeric)
    t_evals = np.asarray(_t_evals(params, t_evals), float)
    area = safe_area(chart, t_evals)
    fig, ax = plt.subplots(figsize=figsize, layout="constrained")
    xi, qm = chart_thresholds(chart)
    for pix, ls, lab in ((area["pixels_displacement"].isel(q_max=0), "--", f"DSB ($q_{{max}}$ = {fmt_value(qm)})"),
                         (area["pixels_energy"].isel(xi_max=0), "-", rf"ESB ($\xi_{{max}}$ = {fmt_value(xi)})")):
        n = np.asarray(pix, float)
        with np.errstate(divide="ignore"):
            la = np.where(n > 0, np.log(n), np.nan)
        ax.plot(t_evals, la, ls=ls, color="k", lw=1.4, marker="o" if t_evals.size <= 40 else None, ms=3, label=lab)
    ax.set_xlabel(LABELS["t_eval"])
    ax.set_ylabel(r"$\ln$(SB area / pixels)")
    ax.set_xlim(0, t_evals.max())
    ax.legend(loc="upper right")
    shown = {k: param(chart, k) for k in ("F", "Omega", "Psi")}
    shown["xi_max"] = xi
    ax.set_title(title or ("Safe-basin area vs evaluation time\n" + param_text(shown) +
                           f", resolution {resolution(chart)}"))
    return fig


__all__ = ["figure_nested_basins", "figure_criteria", "figure_dsb_esb", "figure_area_vs_time",
           "draw_nested_safe", "draw_dsb_esb", "scan_masks", "theory_slices", "chart_thresholds"]
