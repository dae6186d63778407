"""Figures for the beyond-the-paper products (they only read datasets, never recompute).

* :func:`figure_erosion`    -> ``extra_erosion.png``: GIM / LIM / IF versus F, analytic
  lines (paper solid, exact dashed) vs numeric markers shaded by t_eval (light = early).
* :func:`figure_true_basin` -> ``extra_true_basin.png``: per-phase basins (faint) and the
  phase-invariant basin, analytic vs numeric, with the LIM/IF disks and integrity numbers.
* :func:`figure_fourier`    -> ``extra_fourier.png``: relative F_cr error versus Omega and
  the IoU per chart, paper vs exact first harmonic.

Inputs are the Datasets of :mod:`safebasins.erosion`, :mod:`safebasins.phase_invariant`
and :mod:`safebasins.fourier_compare` (or paths to netCDF files holding them).
"""
from __future__ import annotations

import os

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr
from matplotlib.colors import to_rgb
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, Patch

from safebasins.plotting import LABELS, draw_well, open_dataset, save_figure, style

__all__ = ["figure_erosion", "figure_true_basin", "figure_fourier", "shade", "describe_extras"]

MEASURE_LABELS = {"GIM": "GIM (safe area)", "LIM": "LIM (disk at the well bottom)", "IF": "IF (largest disk)"}
FOURIER_STYLE = {"paper": dict(ls="-", marker="o", label="paper G (eq 20)"),
                 "exact": dict(ls="--", marker="s", label="exact first harmonic")}
FOURIER_COLOR = {"paper": "tab:blue", "exact": "tab:orange"}


def shade(color, frac):
    """Mix ``color`` with white: frac = 1 -> the colour, frac = 0 -> white."""
    c = np.asarray(to_rgb(color))
    return tuple(1 - frac * (1 - c))


def _values(ds, dim):
    return list(ds[dim].values) if dim in ds.dims else [None]


def _sel(da, **kw):
    kw = {k: v for k, v in kw.items() if v is not None and k in da.dims}
    return da.sel(**kw) if kw else da


def figure_erosion(analytic=None, numeric=None, *, measures=("GIM", "LIM", "IF"), xi_max=None,
                   t_eval=None, title=None, png=None, pdf=None):
    """GIM / LIM / IF versus F: analytic lines vs numeric markers, several t_eval shades.

    analytic : Dataset over ([fourier,] F, xi_max) (``erosion_profile_analytic``) or None.
    numeric  : Dataset over (F, xi_max, t_eval) (``erosion_profile_numeric`` /
               ``profile_from_charts``) or None.
    xi_max, t_eval : subsets to draw (default: all).
    """
    analytic, numeric = open_dataset(analytic), open_dataset(numeric)
    if analytic is None and numeric is None:
        raise ValueError("give at least one of analytic, numeric")
    ref = analytic if analytic is not None else numeric
    xis = list(np.atleast_1d(xi_max)) if xi_max is not None else _values(ref, "xi_max")
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    with style():
        fig, axes = plt.subplots(1, len(measures), figsize=(4.0 * len(measures), 3.4), sharey=True,
                                 squeeze=False)
        handles = []
        for a, m in enumerate(measures):
            ax = axes[0, a]
            for i, x in enumerate(xis):
                col = colors[i % len(colors)]
                if analytic is not None:
                    for f in _values(analytic, "fourier"):
                        y = _sel(analytic[m], xi_max=x, fourier=f)
                        st = FOURIER_STYLE.get(f or analytic.attrs.get("fourier", "paper"), FOURIER_STYLE["paper"])
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
                key = f or analytic.attrs.get("fourier", "paper")
                handles.append(Line2D([], [], color="0.2", ls=FOURIER_STYLE[key]["ls"],
                                      label=f"analytic, {FOURIER_STYLE[key]['label']}"))
        if numeric is not None:
            ts = list(np.atleast_1d(t_eval)) if t_eval is not None else _values(numeric, "t_eval")
            for k, t in enumerate(ts):
                frac = 0.35 + 0.65 * (k + 1) / len(ts)
                lab = "numeric" + (f", $t_{{eval}}$ = {float(t):g} EC" if t is not None else "")
                handles.append(Line2D([], [], ls="none", marker="o", mfc=shade("0.2", frac), mec="0.2", mew=0.6,
                                      label=lab))
        axes[0, -1].legend(handles=handles, loc="upper right", fontsize=7)
        par = {k: ref.attrs.get(k) for k in ("Omega", "Psi") if ref.attrs.get(k) is not None}
        fig.suptitle(title or "Erosion profiles: " + ", ".join(
            rf"$\{k}$ = {float(v):.3g}" for k, v in par.items()), fontsize=10)
        fig.tight_layout()
    save_figure(fig, png, pdf)
    return fig


def _draw_basin_panel(ax, ds, sel, label):
    safe = _sel(ds["safe"], **sel)
    true = _sel(ds["true_safe"], **sel)
    q, p = ds["q0"].values, ds["p0"].values
    ext = [q[0], q[-1], p[0], p[-1]]
    n = safe.sizes["Psi"]
    sv = safe.transpose("Psi", "q0", "p0").values
    union = sv.any(axis=0)
    ax.contourf(q, p, union.T.astype(float), levels=[0.5, 1.5], colors=["0.9"], zorder=0)
    cmap = plt.get_cmap("twilight")
    psis = np.asarray(safe["Psi"].values, float)
    for k in range(n):  # each per-phase basin: a faint outline coloured by its phase
        if sv[k].any() and not sv[k].all():
            ax.contour(q, p, sv[k].T.astype(float), levels=[0.5], linewidths=0.5, alpha=0.5,
                       colors=[cmap((psis[k] % (2 * np.pi)) / (2 * np.pi))], zorder=2)
    tv = true.transpose("q0", "p0").values
    ax.contourf(q, p, tv.T.astype(float), levels=[0.5, 1.5], colors=["tab:green"], alpha=0.75)
    ax.contour(q, p, tv.T.astype(float), levels=[0.5], colors=["darkgreen"], linewidths=0.9)
    xi = sel.get("xi_max", ds.attrs.get("xi_max"))
    if xi is not None:
        draw_well(ax, float(xi))
    g = {k: float(_sel(ds[f"{k}_true"], **sel)) for k in ("GIM", "LIM", "IF")}
    rl = float(_sel(ds["r_local_true"], **sel))
    rg = float(_sel(ds["r_global_true"], **sel))
    if rl > 0:
        ax.add_patch(Circle((0, 0), rl, fill=False, ec="tab:red", lw=1.0, ls="--", zorder=6))
    if rg > 0:
        c = (float(_sel(ds["if_q0_true"], **sel)), float(_sel(ds["if_p0_true"], **sel)))
        ax.add_patch(Circle(c, rg, fill=False, ec="tab:purple", lw=1.0, zorder=6))
    ax.set_title(f"{label}, {n} phases\ntrue basin: GIM = {g['GIM']:.3f}, LIM = {g['LIM']:.3f}, "
                 f"IF = {g['IF']:.3f}", fontsize=8.5)
    ax.set_xlabel(LABELS["q0"])
    ax.set_aspect("equal", adjustable="box")


def figure_true_basin(analytic=None, numeric=None, *, xi_max=None, t_eval=None, fourier="paper", title=None,
                      png=None, pdf=None):
    """Per-phase safe basins (faint outlines coloured by Psi, light grey union) and the
    phase-invariant basin (green) with its LIM (red dashed) and IF (purple) disks; analytic
    and/or numeric panels."""
    analytic, numeric = open_dataset(analytic), open_dataset(numeric)
    panels = [(d, lab) for d, lab in ((analytic, "analytic"), (numeric, "numeric")) if d is not None]
    if not panels:
        raise ValueError("give at least one of analytic, numeric")
    with style():
        fig, axes = plt.subplots(1, len(panels), figsize=(4.3 * len(panels), 3.9), squeeze=False)
        for ax, (ds, lab) in zip(axes[0], panels):
            x = xi_max if xi_max is not None else (float(ds["xi_max"][0]) if "xi_max" in ds.dims else None)
            sel = {"xi_max": x, "fourier": fourier}
            if "t_eval" in ds.dims:
                sel["t_eval"] = t_eval if t_eval is not None else float(ds["t_eval"][-1])
                lab = f"{lab}, $t_{{eval}}$ = {sel['t_eval']:g} EC"
            elif "fourier" in ds.dims or "fourier" in ds.attrs:
                lab = f"{lab} ({fourier} G)"
            _draw_basin_panel(ax, ds, sel, lab)
            if "xi_true" in ds:
                xt = float(_sel(ds["xi_true"], **sel))
                if xt > 0:
                    draw_well(ax, xt, color="darkgreen", ls=":", lw=0.9)
        axes[0, 0].set_ylabel(LABELS["p0"])
        ref = panels[0][0]
        handles = [Patch(color="0.9", label="safe for some phase"),
                   Line2D([], [], color=plt.get_cmap("twilight")(0.3), lw=0.8,
                          label=r"per-phase basins (colour: $\Psi$)"),
                   Patch(color="tab:green", alpha=0.75, label="safe for all phases"),
                   Line2D([], [], color="tab:red", ls="--", label="LIM disk"),
                   Line2D([], [], color="tab:purple", label="IF disk")]
        if "xi_true" in ref:
            handles.append(Line2D([], [], color="darkgreen", ls=":", label=r"$H_0 = \xi_{true}$ (all $\Psi$)"))
        fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=7, frameon=False,
                   bbox_to_anchor=(0.5, -0.02))
        F, Om = ref.attrs.get("F"), ref.attrs.get("Omega")
        head = "Phase-invariant safe basin"
        if F is not None and Om is not None:
            head += rf": $F$ = {float(F):g}, $\Omega$ = {float(Om):g}"
        if xi_max is not None or "xi_max" in ref.dims:
            head += rf", $\xi_{{max}}$ = {float(xi_max if xi_max is not None else ref['xi_max'][0]):g}"
        fig.suptitle(title or head, fontsize=10)
        fig.tight_layout(rect=(0, 0.06, 1, 1))
    save_figure(fig, png, pdf)
    return fig


def figure_fourier(fcr=None, iou=None, *, title=None, png=None, pdf=None):
    """Paper vs exact first harmonic: relative F_cr error vs Omega (left) and IoU per chart (right).

    fcr : Dataset(s) of ``fcr_fourier_comparison`` (optionally with a ``curve`` dim), or a list.
    iou : Dataset(s) of ``iou_fourier_comparison``, or a list (one per chart file); each
          (chart, threshold, t_eval) combination becomes one x position.
    """
    fcrs = [open_dataset(d) for d in (fcr if isinstance(fcr, (list, tuple)) else [fcr]) if d is not None]
    ious = [open_dataset(d) for d in (iou if isinstance(iou, (list, tuple)) else [iou]) if d is not None]
    if not fcrs and not ious:
        raise ValueError("give at least one of fcr, iou")
    n = int(bool(fcrs)) + int(bool(ious))
    with style():
        fig, axes = plt.subplots(1, n, figsize=(5.4 * n, 4.2), squeeze=False)
        k = 0
        if fcrs:
            ax = axes[0, k]
            k += 1
            markers = "o^vsD<>p"
            j = 0
            curve_handles = []
            for ds in fcrs:
                curves = list(range(ds.sizes["curve"])) if "curve" in ds.dims else [None]
                for c in curves:
                    d = ds.isel(curve=c) if c is not None else ds
                    mk = markers[j % len(markers)]
                    for f in d["fourier"].values:
                        y = d["rel_error"].sel(fourier=f)
                        ax.plot(d["Omega"], 100 * y.values, color=FOURIER_COLOR[str(f)],
                                ls=FOURIER_STYLE[str(f)]["ls"], marker=mk, ms=3.5, lw=1.0)
                    par = []
                    for key, sym in (("xi_max", r"$\xi_{max}$"), ("xi0", r"$\xi_{ini}$"), ("gamma0", r"$\gamma_{ini}$")):
                        v = d[key] if key in d.coords else d.attrs.get(key)
                        if v is not None and (key == "xi_max" or float(v) != 0):
                            par.append(f"{sym}={float(v):g}")
                    curve_handles.append(Line2D([], [], color="0.3", ls="none", marker=mk, ms=4, label=", ".join(par)))
                    j += 1
            ax.axhline(0, color="0.5", lw=0.6)
            ax.set_xlabel(LABELS["Omega"])
            ax.set_ylabel(r"relative $F_{cr}$ error, theory vs numeric (%)")
            txt = []
            for f in ("paper", "exact"):
                vals = np.concatenate([np.ravel(ds["rel_error"].sel(fourier=f).values) for ds in fcrs])
                vals = vals[np.isfinite(vals)]
                if vals.size:
                    txt.append(f"{f}: RMS {100 * np.sqrt(np.mean(vals ** 2)):.2f}%")
            ax.text(0.02, 0.98, "\n".join(txt), transform=ax.transAxes, va="top", fontsize=7.5,
                    bbox=dict(fc="white", ec="0.7", alpha=0.85, lw=0.5))
            lh = [Line2D([], [], color=FOURIER_COLOR[f], ls=FOURIER_STYLE[f]["ls"],
                         label=FOURIER_STYLE[f]["label"]) for f in ("paper", "exact")] + curve_handles
            if len(curve_handles) > 4:  # many curves (Figs 10-12 together): legend below the axes
                ax.legend(handles=lh, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=2, fontsize=6.5)
            else:
                ax.legend(handles=lh, loc="best", fontsize=7)
            ax.set_title(r"critical forcing $F_{cr}(\Omega)$")
        if ious:
            ax = axes[0, k]
            labels, vals = [], {"paper": [], "exact": []}
            abbr = {"F": "F", "xi_max": r"$\xi$", "t_eval": "t", "Omega": r"$\Omega$", "Psi": r"$\Psi$",
                    "q_max": "q"}
            for ds in ious:
                it = ds["iou"]
                others = [dd for dd in it.dims if dd != "fourier"]
                shown = [dd for dd in others if it.sizes[dd] > 1]
                st = it.stack(_pos=others) if others else it.expand_dims(_pos=[0])
                head = " ".join(f"{abbr[kk]}={float(ds.attrs[kk]):.3g}" for kk in ("Omega", "Psi", "F")
                                if kk in ds.attrs and kk not in others)
                for i in range(st.sizes["_pos"]):
                    cell = st.isel(_pos=i)
                    lab = " ".join(f"{abbr.get(dd, dd)}={float(cell[dd]):.3g}" for dd in shown)
                    labels.append((head + " " + lab).strip())
                    for f in ("paper", "exact"):
                        vals[f].append(float(cell.sel(fourier=f)) if f in cell["fourier"].values else np.nan)
            x = np.arange(len(labels))
            w = 0.38
            for s, f in ((-1, "paper"), (1, "exact")):
                ax.bar(x + s * w / 2, vals[f], width=w, color=FOURIER_COLOR[f], label=FOURIER_STYLE[f]["label"])
            lo = np.nanmin([np.nanmin(vals["paper"] or [1]), np.nanmin(vals["exact"] or [1])])
            ax.set_ylim(max(0.0, lo - 0.05), 1.0)
            ax.set_xticks(x)
            ax.set_xticklabels(labels, rotation=55, ha="right", fontsize=6.5)
            ax.set_ylabel("IoU, analytic vs numeric")
            ax.legend(loc="lower left", fontsize=7, framealpha=1.0)
            ax.set_title("safe basins")
        fig.suptitle(title or "First harmonic: paper's truncated G vs exact", fontsize=10)
        fig.tight_layout()
    save_figure(fig, png, pdf)
    return fig


#: headline variables printed by :func:`describe_extras` (those present in a dataset)
HEADLINE = ("F_GIM", "F_LIM", "F_IF", "xi_true", "GIM_true", "LIM_true", "IF_true", "GIM_continuous",
            "GIM_closed", "LIM_closed", "rms_rel_error", "mean_abs_rel_error", "mean_iou")


def describe_extras(**datasets):
    """Text summary of extra datasets (paths, lists of paths or Datasets): title, the parameters
    that define them and their headline numbers (level crossings, true-basin integrity, errors)."""
    lines = []
    for name, src in datasets.items():
        for s in (src if isinstance(src, (list, tuple)) else [src]):
            if s is None:
                continue
            ds = open_dataset(s)
            where = os.fspath(s) if isinstance(s, (str, os.PathLike)) else "<dataset>"
            lines.append(f"[{name}] {where}: {ds.attrs.get('title', '')}")
            par = {k: ds.attrs[k] for k in ("F", "Omega", "Psi", "cycles", "steps_per_cycle", "level",
                                            "source_experiment") if k in ds.attrs}
            if par:
                lines.append("  " + ", ".join(f"{k} = {v}" for k, v in par.items()))
            for v in HEADLINE:
                if v in ds:
                    da = ds[v]
                    dims = ", ".join(f"{d}={np.array2string(np.asarray(da[d].values), precision=4)}"
                                     for d in da.dims)
                    vals = np.array2string(np.asarray(da.values), precision=4, suppress_small=True)
                    lines.append(f"  {v}" + (f" over ({dims})" if dims else "") + f":\n    " +
                                 vals.replace("\n", "\n    "))
    return "\n".join(lines)
