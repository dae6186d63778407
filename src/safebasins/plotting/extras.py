"""Figures for the beyond-the-paper products (they only read datasets, never recompute).

* :func:`figure_erosion`    -> ``extra_erosion.png``: GIM / LIM / IF versus F, analytic
  lines (paper solid, exact dashed) vs numeric markers shaded by t_eval (light = early).
* :func:`figure_true_basin` -> ``extra_true_basin.png``: per-phase basins (faint) and the
  phase-invariant basin, analytic vs numeric, with the LIM/IF disks and integrity numbers.
* :func:`figure_fourier`    -> ``extra_fourier.png``: relative F_cr error versus Omega and
  the IoU per chart, paper vs exact first harmonic.

Inputs are the Datasets of :mod:`safebasins.analysis.erosion`,
:mod:`safebasins.analysis.phase_invariant` and :mod:`safebasins.analysis.fourier_compare` (or
paths to netCDF files holding them).  Like every figure builder they return the Figure; the
notebook applies the style and saves it.
"""
from __future__ import annotations

import re
from typing import TYPE_CHECKING, Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import to_rgb
from matplotlib.legend_handler import HandlerTuple
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, Patch
from matplotlib.cm import ScalarMappable
from matplotlib.colors import Normalize

from safebasins.plotting.curves import draw_well, plot_curve, separates_mask
from safebasins.plotting.captions import add_note, count, fmt_range
from safebasins.plotting import data
from safebasins.plotting.data import open_dataset, param, var
from safebasins.plotting.fcr import curve_labels, ic_text
from safebasins.plotting.style import LABELS, fmt_value, param_text
from safebasins.plotting.style import pi_ticks

if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence

    import numpy.typing as npt
    import xarray as xr
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes
    from matplotlib.colorbar import Colorbar
    from matplotlib.figure import Figure
    from matplotlib.typing import ColorType

    from safebasins.plotting.data import DataSource

    #: a group of paired bars: its title and (tick label, paper value, exact value) per bar
    BarGroup = tuple[str, list[tuple[str, float, float]]]

__all__ = ["figure_erosion", "figure_true_basin", "figure_fourier", "shade"]

MEASURE_LABELS = {"GIM": "GIM (safe area)", "LIM": "LIM (disk at the well bottom)", "IF": "IF (largest disk)"}
FOURIER_STYLE: dict[str, dict[str, Any]] = {"paper": dict(ls="-", marker="o", label="paper G (eq 20)"),
                 "exact": dict(ls="--", marker="s", label="exact first harmonic")}
FOURIER_COLOR = {"paper": "tab:blue", "exact": "tab:orange"}
LIM_COLOR, IF_COLOR, XI_TRUE_COLOR = "crimson", "#7b3fa0", "black"


def shade(color: ColorType, frac: float) -> tuple[float, ...]:
    """Mix ``color`` with white: frac = 1 -> the colour, frac = 0 -> white."""
    c = np.asarray(to_rgb(color))
    return tuple(1 - frac * (1 - c))


def _values(ds: xr.Dataset, dim: str) -> list[Any]:
    return list(ds[dim].values) if dim in ds.dims else [None]


def _sel(da: xr.DataArray, **kw: Any) -> xr.DataArray:
    kw = {k: v for k, v in kw.items() if v is not None and k in da.dims}
    return da.sel(**kw) if kw else da


def figure_erosion(analytic: DataSource | None = None, numeric: DataSource | None = None, *,
                   measures: Sequence[str] = ("GIM", "LIM", "IF"), xi_max: npt.ArrayLike | None = None,
                   t_eval: npt.ArrayLike | None = None, title: str | None = None) -> Figure:
    """GIM / LIM / IF versus F: analytic lines vs numeric markers, several t_eval shades.

    Parameters
    ----------
    analytic
        Dataset over ([fourier,] F, xi_max) (``erosion_profile_analytic``) or None.
    numeric
        Dataset over (F, xi_max, t_eval) (``erosion_profile_numeric`` /
        ``profile_from_charts``) or None.
    xi_max, t_eval
        Subsets to draw (default: all).
    """
    analytic, numeric = open_dataset(analytic), open_dataset(numeric)
    ref = analytic if analytic is not None else numeric
    if ref is None:
        raise ValueError("give at least one of analytic, numeric")
    xis = list(np.atleast_1d(xi_max)) if xi_max is not None else _values(ref, "xi_max")
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    fig, axes = plt.subplots(1, len(measures), figsize=(4.0 * len(measures), 3.9), sharey=True,
                             squeeze=False)
    handles: list[Artist | tuple[Artist, ...]] = []
    for a, m in enumerate(measures):
        ax = axes[0, a]
        for i, x in enumerate(xis):
            col = colors[i % len(colors)]
            if analytic is not None:
                for f in _values(analytic, "fourier"):
                    y = _sel(analytic[m], xi_max=x, fourier=f)
                    st = FOURIER_STYLE[f or param(analytic, "fourier")]
                    ax.plot(y["F"], y.values, color=col, ls=st["ls"], lw=1.5, zorder=3)
            if numeric is not None:
                ts = list(np.atleast_1d(t_eval)) if t_eval is not None else _values(numeric, "t_eval")
                for k, t in enumerate(ts):
                    frac = 0.35 + 0.65 * (k + 1) / len(ts)
                    y = _sel(numeric[m], xi_max=x, t_eval=t)
                    ms = 6.5 - 3.0 * k / max(len(ts) - 1, 1)  # early t_eval: big and light, late: small and dark
                    ax.plot(y["F"], y.values, ls="none", marker="o", ms=ms, mfc=shade(col, frac),
                            mec=shade(col, min(1.0, frac + 0.2)), mew=0.6, zorder=4)
        ax.set_xlabel(LABELS["F"])
        ax.set_title(MEASURE_LABELS.get(m, m))
        ax.set_ylim(-0.03, 1.05)
        ax.axhline(0.5, color="0.7", lw=0.6, ls=":", zorder=1)
    axes[0, 0].set_ylabel("normalised integrity")
    for i, x in enumerate(xis):
        if x is not None:
            handles.append(Patch(color=colors[i % len(colors)], label=rf"$\xi_{{max}}$ = {float(x):g}"))
    if analytic is not None:
        for f in _values(analytic, "fourier"):
            key = f or param(analytic, "fourier")
            handles.append(Line2D([], [], color="0.2", ls=FOURIER_STYLE[key]["ls"],
                                  label=f"analytic, {FOURIER_STYLE[key]['label']}"))
    labels = [str(h.get_label()) for h in handles if not isinstance(h, tuple)]  # no tuple yet: one label each
    if numeric is not None:
        ts = list(np.atleast_1d(t_eval)) if t_eval is not None else _values(numeric, "t_eval")
        for k, t in enumerate(ts):
            frac = 0.35 + 0.65 * (k + 1) / len(ts)
            ms = 6.5 - 3.0 * k / max(len(ts) - 1, 1)
            lab = "numeric" + (f", $t_{{eval}}$ = {float(t):g} EC" if t is not None else "")
            # the markers as drawn: one per xi_max colour, at this t_eval's shade and size
            handles.append(tuple(Line2D([], [], ls="none", marker="o", ms=ms, mfc=shade(colors[i % len(colors)], frac),
                                        mec=shade(colors[i % len(colors)], min(1.0, frac + 0.2)), mew=0.6)
                                 for i in range(len(xis))))
            labels.append(lab)
    ncol = len(handles) if len(handles) <= 4 else (len(handles) + 1) // 2
    # matplotlib's stubs let Axes.legend take tuple handles (drawn by HandlerTuple), not Figure.legend, which does
    fig.legend(handles, labels, handler_map={tuple: HandlerTuple(ndivide=None, pad=0.1)},  # type: ignore[call-overload]
               loc="lower center", ncol=ncol, fontsize=7.5, frameon=False, bbox_to_anchor=(0.5, 0.0),
               columnspacing=1.5)
    par = {k: param(ref, k) for k in ("Omega", "Psi")}
    if "damping" in ref.attrs:          # a damped profile (both sides integrate the damped equation)
        par["damping"] = param(ref, "damping")
    fig.suptitle(title or ("Damped erosion profiles: " if "damping" in par else "Erosion profiles: ")
                 + param_text(par), fontsize=10)
    fig.tight_layout(rect=(0, 0.04 + 0.045 * -(-len(handles) // ncol), 1, 1))
    _erosion_notes(fig, ref, analytic, numeric, measures)
    return fig


def _erosion_notes(fig: Figure, ref: xr.Dataset, analytic: xr.Dataset | None, numeric: xr.Dataset | None,
                   measures: Sequence[str]) -> None:
    """Caption notes: grids and the first F at which each measure falls to the stored level (``ref``: the
    analytic dataset, else the numeric one)."""
    def crossings(ds: xr.Dataset, **sel: Any) -> str:
        return ", ".join(f"F_{m} = {float(_sel(var(ds, f'F_{m}'), **sel)):.4g}" for m in measures)

    if "damping" in ref.attrs:
        und = int(np.asarray(analytic["n_undecided"]).sum()) if analytic is not None and "n_undecided" in analytic \
            else 0
        add_note(fig, f"Damped equation q'' + β q' + V'(q) = F sin(Ω t + Ψ), β = {fmt_value(param(ref, 'damping'))}: "
                      "the numerics integrate it, the analytic profile follows each IC's damped slow trajectory until "
                      "it escapes or settles below ξ_max (docs/damping.md)"
                      + (f"; {count(und, 'slow trajectory', 'slow trajectories')} undecided, counted as escaping."
                         if und else "."))
    if analytic is not None and "grid_n" in analytic.attrs:  # written by the pipeline's erosion kind
        n = np.atleast_1d(param(analytic, "grid_n"))
        add_note(fig, f"Analytic profiles from the slow flow on {' x '.join(str(int(v)) for v in n)} ICs of the "
                      "window; numeric ones from one escape chart per F.")
    if analytic is not None and "F_GIM" in analytic.variables:
        for x in _values(analytic, "xi_max"):
            for f in _values(analytic, "fourier"):
                add_note(fig, f"First F at which each measure falls to {fmt_value(param(analytic, 'level'))}, ξ_max = "
                              f"{fmt_value(x)}, analytic ({f or param(analytic, 'fourier')} G): "
                              f"{crossings(analytic, xi_max=x, fourier=f)}.")
    if numeric is not None and "F_GIM" in numeric.variables:
        for x in _values(numeric, "xi_max"):
            add_note(fig, f"Numeric, ξ_max = {fmt_value(x)}: " + "; ".join(
                f"t_eval = {fmt_value(t)} EC: {crossings(numeric, xi_max=x, t_eval=t)}"
                for t in _values(numeric, "t_eval")) + ".")


def _draw_basin_panel(ax: Axes, ds: xr.Dataset, sel: Mapping[str, Any], label: str) -> None:
    safe = _sel(ds["safe"], **sel)
    true = _sel(ds["true_safe"], **sel)
    q, p = ds["q0"].values, ds["p0"].values
    n = safe.sizes["Psi"]
    sv = safe.transpose("Psi", "q0", "p0").values
    union = sv.any(axis=0)
    ax.contourf(q, p, union.T.astype(float), levels=[0.5, 1.5], colors=["0.9"], zorder=0)
    cmap = plt.get_cmap("twilight")
    psis = np.asarray(safe["Psi"].values, float)
    curves = "boundary_q0" in ds.variables
    for k in range(n):  # each per-phase basin: a faint outline coloured by its phase
        col = cmap((psis[k] % (2 * np.pi)) / (2 * np.pi))
        if curves:  # analytic: the slow flow's own boundary curves of this phase
            b = ds.isel(Psi=k)
            bq = np.asarray(_sel(var(b, "boundary_q0"), **sel), float)
            bp = np.asarray(_sel(var(b, "boundary_p0"), **sel), float)
            bc = np.asarray(_sel(var(b, "boundary_curve"), **sel), int)
            mask = _sel(safe.isel(Psi=k), **sel).transpose("q0", "p0")
            for c in np.unique(bc[bc >= 0]):
                xs, ys = bq[bc == c], bp[bc == c]
                if separates_mask(xs, ys, mask):
                    plot_curve(ax, xs, ys, color=col, lw=0.7, alpha=0.7, zorder=2)
        elif sv[k].any() and not sv[k].all():  # numeric: outline of the chart's safe pixels
            ax.contour(q, p, sv[k].T.astype(float), levels=[0.5], linewidths=0.5, alpha=0.5,
                       colors=[col], zorder=2)
    tv = true.transpose("q0", "p0").values
    ax.contourf(q, p, tv.T.astype(float), levels=[0.5, 1.5], colors=["tab:green"], alpha=0.55)
    draw_well(ax, float(sel["xi_max"]), data.well(ds))
    g = {k: float(_sel(ds[f"{k}_true"], **sel)) for k in ("GIM", "LIM", "IF")}
    rl = float(_sel(ds["r_local_true"], **sel))
    rg = float(_sel(ds["r_global_true"], **sel))
    # IF below (wide, solid), LIM on top (thin, dashed): both stay visible when they coincide
    if rg > 0:
        c = (float(_sel(ds["if_q0_true"], **sel)), float(_sel(ds["if_p0_true"], **sel)))
        ax.add_patch(Circle(c, rg, fill=False, ec=IF_COLOR, lw=2.2, zorder=6))
        ax.plot(*c, marker="+", color=IF_COLOR, ms=6, mew=1.2, zorder=7)
    if rl > 0:
        ax.add_patch(Circle((0, 0), rl, fill=False, ec=LIM_COLOR, lw=1.1, ls=(0, (3, 2)), zorder=7))
    ax.set_title(f"{label}, {n} phases\ntrue basin: GIM = {g['GIM']:.3f}, LIM = {g['LIM']:.3f}, "
                 f"IF = {g['IF']:.3f}", fontsize=8.5)
    ax.set_xlabel(LABELS["q0"])
    ax.set_aspect("equal", adjustable="box")


def _phase_colorbar(fig: Figure, cax: Axes) -> Colorbar:
    """Colour scale of the per-phase outlines: the forcing phase Psi over one period."""
    cb = fig.colorbar(ScalarMappable(norm=Normalize(0, 2 * np.pi), cmap="twilight"), cax=cax)
    cb.set_label(r"forcing phase $\Psi$ of the per-phase outlines")
    pi_ticks(cb.ax, 0, 2 * np.pi, axis="y")
    return cb


def figure_true_basin(analytic: DataSource | None = None, numeric: DataSource | None = None, *,
                      xi_max: float | None = None, t_eval: float | None = None, fourier: str = "paper",
                      title: str | None = None) -> Figure:
    """Per-phase safe basins (faint outlines coloured by Psi, light grey union) and the
    phase-invariant basin (green) with its LIM (red dashed) and IF (purple) disks; analytic
    and/or numeric panels."""
    analytic, numeric = open_dataset(analytic), open_dataset(numeric)
    panels = [(d, lab) for d, lab in ((analytic, "analytic"), (numeric, "numeric")) if d is not None]
    if not panels:
        raise ValueError("give at least one of analytic, numeric")
    fig, axes = plt.subplots(1, len(panels), figsize=(4.3 * len(panels) + 0.8, 4.5), squeeze=False)
    data.attach(fig, analytic, numeric)
    for ax, (ds, lab) in zip(axes[0], panels):
        x = xi_max if xi_max is not None else (float(ds["xi_max"][0]) if "xi_max" in ds.dims else None)
        sel: dict[str, Any] = {"xi_max": x, "fourier": fourier}
        if "t_eval" in ds.dims:
            sel["t_eval"] = t_eval if t_eval is not None else float(ds["t_eval"][-1])
            lab = f"{lab}, $t_{{eval}}$ = {sel['t_eval']:g} EC"
        elif "fourier" in ds.dims or "fourier" in ds.attrs:
            lab = f"{lab} ({fourier} G)"
        _draw_basin_panel(ax, ds, sel, lab)
        if analytic is not None:  # the analytic all-phase basin on every panel (the numeric one is compared to it)
            xt = float(_sel(var(analytic, "xi_true"), xi_max=x, fourier=fourier))
            if xt > 0:
                draw_well(ax, xt, data.well(analytic), color=XI_TRUE_COLOR, ls=":", lw=1.4, zorder=9)
    axes[0, 0].set_ylabel(LABELS["p0"])
    ref = panels[0][0]
    handles: list[Artist] = [Patch(color="0.9", label="safe for some phase"),
               Line2D([], [], color=plt.get_cmap("twilight")(0.3), lw=0.8,
                      label=r"per-phase basins (colour: $\Psi$)"),
               Patch(color="tab:green", alpha=0.55, label="safe for all sampled phases"),
               Line2D([], [], color=IF_COLOR, lw=2.2, marker="+", ms=6, label="IF disk (+ centre)"),
               Line2D([], [], color=LIM_COLOR, lw=1.1, ls=(0, (3, 2)), label="LIM disk")]
    if analytic is not None:
        handles.append(Line2D([], [], color=XI_TRUE_COLOR, ls=":", lw=1.4,
                              label=r"analytic $H_0 = \xi_{true}$ (all $\Psi$)"))
    fig.legend(handles=handles, loc="lower center", ncol=3, fontsize=7.5, frameon=False,
               bbox_to_anchor=(0.5, 0.0), columnspacing=1.5)
    par: dict[str, Any] = {"F": param(ref, "F"), "Omega": param(ref, "Omega")}
    if xi_max is not None or "xi_max" in ref.dims:
        par["xi_max"] = float(xi_max if xi_max is not None else ref["xi_max"][0])
    head = "Phase-invariant safe basin" + (": " + param_text(par) if any(v is not None for v in par.values()) else "")
    fig.suptitle(title or head, fontsize=10)
    fig.subplots_adjust(left=0.08, right=0.88, top=0.84, bottom=0.2, wspace=0.22)
    _phase_colorbar(fig, fig.add_axes((0.905, 0.3, 0.014, 0.5)))
    for ds, lab in panels:
        x = xi_max if xi_max is not None else (float(ds["xi_max"][0]) if "xi_max" in ds.dims else None)
        sel = {"xi_max": x, "fourier": fourier}
        if "t_eval" in ds.dims:
            sel["t_eval"] = t_eval if t_eval is not None else float(ds["t_eval"][-1])
        m = {k: float(_sel(var(ds, f"{k}_true"), **sel)) for k in ("GIM", "LIM", "IF")}
        per = np.asarray(_sel(var(ds, "GIM"), **sel), float) if "GIM" in ds.variables else np.array([np.nan])
        txt = (f"{lab}" + (f" (t_eval = {fmt_value(sel['t_eval'])} EC)" if "t_eval" in sel else f" ({fourier} G)")
               + f", {ds.sizes['Psi']} phases: true basin GIM = {m['GIM']:.3f}, LIM = {m['LIM']:.3f}, IF = "
                 f"{m['IF']:.3f}"
               + (f"; single-phase GIM {fmt_range(per, '{:.3f}')}" if np.isfinite(per).any() else "")
               + (f"; contained in every per-phase basin: {bool(_sel(var(ds, 'contained'), **sel))}"
                  if "contained" in ds.variables else ""))
        add_note(fig, txt + ".")
    if analytic is not None:
        x = xi_max if xi_max is not None else float(analytic["xi_max"][0])
        xt = float(_sel(var(analytic, "xi_true"), xi_max=x, fourier=fourier))
        add_note(fig, f"All phases (continuous Ψ), analytic: the basin is the energy disk H0 < ξ_true = {xt:.4g}, GIM "
                      "= "
                      f"{float(_sel(var(analytic, 'GIM_closed'), xi_max=x, fourier=fourier)):.3f}, LIM = IF = "
                      f"{float(_sel(var(analytic, 'LIM_closed'), xi_max=x, fourier=fourier)):.3f} (closed forms); "
                      "the analytic per-phase outlines are the slow flow's boundary curves, the numeric ones outline "
                      "chart pixels.")
    return fig


def _source_name(ds: xr.Dataset, k: int) -> str:
    """"Fig 10" from the dataset's ``source_experiment`` attribute (else "set k+1")."""
    src = str(param(ds, "source_experiment"))
    m = re.fullmatch(r"fig(\d+)", src)
    return f"Fig {int(m.group(1))}" if m else (src or f"set {k + 1}")


def _compact(txt: str) -> str:
    return txt.replace(" = ", "=")


def _curve_labels(ds: xr.Dataset) -> tuple[list[str], str]:
    """Short label per curve of an F_cr comparison (the parameters that vary between its curves,
    e.g. "ξini=0.05") and the title text of the constant ones."""
    if "curve" in ds.dims:
        labels, const = curve_labels(ds)
    else:
        labels, const = [], {k: ds[k].values if k in ds.coords else ds.attrs[k]
                             for k in ("xi_max", "xi_ini", "gamma_ini", "Psi") if k in ds.coords or k in ds.attrs}
        labels = [param_text({"xi_max": const.pop("xi_max")})] if "xi_max" in const else ["theory"]
    return [_compact(t) for t in labels], _compact(ic_text(const))


def _curves(ds: xr.Dataset) -> list[xr.Dataset]:
    return [ds.isel(curve=c) for c in range(ds.sizes["curve"])] if "curve" in ds.dims else [ds]


def _rms(x: npt.ArrayLike) -> float:
    v = np.ravel(np.asarray(x, float))
    v = v[np.isfinite(v)]
    return float(np.sqrt(np.mean(v ** 2))) if v.size else np.nan


def _grouped_bars(ax: Axes, groups: Sequence[BarGroup], ylabel: str, *, ymax: float,
                  fmt: str = "{:.2f}") -> dict[str, list[float]]:
    """Paired bars (paper, exact) grouped by source figure: ``groups`` = [(title, [(tick, paper,
    exact), ...]), ...]. Group titles sit inside the axes above ``ymax``, dotted separators
    between groups. Returns the (paper, exact) values."""
    w = 0.4
    x0: float = 0
    ticks: list[float] = []
    labels: list[str] = []
    allv: dict[str, list[float]] = {"paper": [], "exact": []}
    for g, (head, bars) in enumerate(groups):
        x = x0 + np.arange(len(bars))
        for s, f, v in ((-1, "paper", [b[1] for b in bars]), (1, "exact", [b[2] for b in bars])):
            allv[f] += v
            ax.bar(x + s * w / 2, v, width=w, color=FOURIER_COLOR[f],
                   label=FOURIER_STYLE[f]["label"] if g == 0 else None)
        ticks += list(x)
        labels += [b[0] for b in bars]
        ax.text(x.mean(), 0.985, head, transform=ax.get_xaxis_transform(), ha="center", va="top", fontsize=7.5)
        if g:
            ax.axvline(x0 - 0.75, color="0.6", lw=0.7, ls=":")
        x0 += len(bars) + 0.5
    ax.set_xlim(-0.6, x0 - 0.9)
    ax.set_ylim(0, ymax)
    ax.set_xticks(ticks)
    ax.set_xticklabels(labels, rotation=60, ha="right", rotation_mode="anchor", fontsize=7)
    ax.tick_params(axis="x", which="both", top=False, length=2)
    ax.set_ylabel(ylabel)
    return allv


def figure_fourier(fcr: DataSource | list[DataSource] | tuple[DataSource, ...] | None = None,
                   iou: DataSource | list[DataSource] | tuple[DataSource, ...] | None = None, *,
                   title: str | None = None) -> Figure:
    """Paper vs exact first harmonic against the numerics.

    Top row: relative F_cr error versus Omega, one panel per F_cr dataset (source figure), paper G
    solid, exact dashed, one colour per curve. Bottom row: RMS relative F_cr error per curve and
    IoU of the analytic and numeric safe basins per chart, paired bars grouped by source figure.
    The overall RMS error and mean IoU are in the title.

    Parameters
    ----------
    fcr
        Dataset(s) of ``fcr_fourier_comparison`` (optionally with a ``curve`` dim), or a list.
    iou
        Dataset(s) of ``iou_fourier_comparison``, or a list (one per chart file); each
        combination of its non-singleton dims becomes one pair of bars.
    """
    fcrs = [open_dataset(d) for d in (fcr if isinstance(fcr, (list, tuple)) else [fcr]) if d is not None]
    ious = [open_dataset(d) for d in (iou if isinstance(iou, (list, tuple)) else [iou]) if d is not None]
    if not fcrs and not ious:
        raise ValueError("give at least one of fcr, iou")
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    summary: list[str] = []
    nf = len(fcrs)
    fig = plt.figure(figsize=(max(11.0, 3.7 * nf), 3.3 * (bool(fcrs) + bool(ious or fcrs)) + 0.9))
    rows = int(bool(fcrs)) + 1
    gs = fig.add_gridspec(rows, 1, height_ratios=[1.0] * rows, hspace=0.45)
    if fcrs:
        top = gs[0].subgridspec(1, nf, wspace=0.08)
        ax0: Axes | None = None
        for k, ds in enumerate(fcrs):
            ax = fig.add_subplot(top[0, k], sharey=ax0)
            ax0 = ax0 or ax
            labs, const = _curve_labels(ds)
            for c, (d, lab) in enumerate(zip(_curves(ds), labs)):
                col = colors[c % len(colors)]
                for f in ("paper", "exact"):
                    if f in d["fourier"].values:
                        ax.plot(d["Omega"], 100 * d["rel_error"].sel(fourier=f).values, color=col,
                                ls=FOURIER_STYLE[f]["ls"], lw=1.1, marker="o", ms=2.2,
                                label=lab if f == "paper" else None)
            ax.axhline(0, color="0.5", lw=0.6, zorder=0)
            ax.set_xlabel(LABELS["Omega"])
            ax.set_title(_source_name(ds, k) + (f": {const}" if const else ""), fontsize=8.5)
            if k == 0:
                ax.set_ylabel(r"rel. $F_{cr}$ error vs numeric (%)")
            else:
                ax.tick_params(labelleft=False)
            ax.legend(loc="upper center", bbox_to_anchor=(0.56, 1.0), fontsize=6.5, ncol=2 if len(labs) > 3 else 1,
                      handlelength=1.4, columnspacing=0.8, labelspacing=0.25, framealpha=0.9)
        style_h = [Line2D([], [], color="0.25", ls=FOURIER_STYLE[f]["ls"], label=FOURIER_STYLE[f]["label"])
                   for f in ("paper", "exact")]
        fig.legend(handles=style_h, loc="center", bbox_to_anchor=(0.5, 0.925), ncol=2, fontsize=8,
                   frameon=False, handlelength=2.5)
        rms = {f: _rms(np.concatenate([np.ravel(ds["rel_error"].sel(fourier=f).values) for ds in fcrs]))
               for f in ("paper", "exact")}
        summary.append(rf"RMS rel. $F_{{cr}}$ error: paper {100 * rms['paper']:.1f}%, "
                       rf"exact {100 * rms['exact']:.1f}%")
    bottom = gs[rows - 1].subgridspec(1, 2, width_ratios=[max(sum(len(_curves(d)) for d in fcrs), 1) + 2,
                                                          max(sum(_n_iou(d) for d in ious), 1) + 2] if fcrs and ious
                                      else [1, 0.0001], wspace=0.12)
    bi = 0
    if fcrs:
        ax = fig.add_subplot(bottom[0, bi])
        bi += 1
        groups: list[BarGroup] = []
        for k, ds in enumerate(fcrs):
            bars: list[tuple[str, float, float]] = []
            for d, lab in zip(_curves(ds), _curve_labels(ds)[0]):
                r = {f: _rms(d["rel_error"].sel(fourier=f).values) if f in d["fourier"].values else np.nan
                     for f in ("paper", "exact")}
                bars.append((lab, 100 * r["paper"], 100 * r["exact"]))
            groups.append((_source_name(ds, k), bars))
        finite = [v for g in groups for b in g[1] for v in b[1:] if np.isfinite(v)]
        _grouped_bars(ax, groups, r"RMS rel. $F_{cr}$ error (%)", ymax=1.18 * max(finite or [1.0]))
        ax.legend(loc="upper left", bbox_to_anchor=(0.0, 0.9), fontsize=7, framealpha=0.9)
        ax.set_title(r"critical forcing: RMS error per curve over $\Omega$", fontsize=9)
    if ious:
        ax = fig.add_subplot(bottom[0, bi])
        groups = []
        for k, ds in enumerate(ious):
            it = ds["iou"]
            others = [dd for dd in it.dims if dd != "fourier"]
            shown = [str(dd) for dd in others if it.sizes[dd] > 1]
            st = it.stack(_pos=others) if others else it.expand_dims(_pos=[0])
            fixed = {kk: ds.attrs[kk] for kk in ("Omega", "Psi", "F") if kk in ds.attrs and kk not in shown}
            fixed.update({dd: float(it[dd][0]) for dd in others if dd not in shown and dd in ("xi_max", "F")})
            bars = []
            for i in range(st.sizes["_pos"]):
                cell = st.isel(_pos=i)
                lab = _compact(param_text({dd: float(cell[dd]) for dd in shown}))
                v = {f: float(cell.sel(fourier=f)) if f in cell["fourier"].values else np.nan
                     for f in ("paper", "exact")}
                bars.append((lab or _source_name(ds, k), v["paper"], v["exact"]))
            head = _source_name(ds, k) + "\n" + _compact(param_text(fixed, sep="\n"))
            groups.append((head, bars))
        allv = _grouped_bars(ax, groups, "IoU, analytic vs numeric", ymax=1.45)
        ax.set_yticks(np.arange(0, 1.01, 0.2))
        ax.axhline(1.0, color="0.6", lw=0.6, ls="-", zorder=0)
        ax.set_title("safe basins: IoU per chart", fontsize=9)
        if not fcrs:
            ax.legend(loc="lower left", fontsize=7, framealpha=0.9)
        summary.append("mean IoU: paper {:.3f}, exact {:.3f}".format(float(np.nanmean(allv["paper"])),
                                                                    float(np.nanmean(allv["exact"]))))
    for line in summary:
        add_note(fig, line.replace(r"$F_{cr}$", "F_cr") + " (over the figures' numeric points / charts).")
    head = title or "First harmonic: paper's truncated G (eq 20) vs exact, against the numerics"
    fig.suptitle(head + ("\n" + "; ".join(summary) if summary and not title else ""), fontsize=10, y=0.995)
    fig.subplots_adjust(left=0.06, right=0.99, top=0.87 if fcrs else 0.8, bottom=0.12 if fcrs else 0.3)
    return fig


def _n_iou(ds: xr.Dataset) -> int:
    it = ds["iou"]
    return int(np.prod([it.sizes[d] for d in it.dims if d != "fourier"]))
