"""Figures of the critical forcing F_cr(Omega): theory curves by mechanism (Figs 1-4) and
theory versus numerics (Figs 10-12).

Reads ``critical_forcing`` datasets stacked over ``curve`` (coordinates ``xi_max``, ``xi_ini``,
``gamma_ini``, ``Psi``, ``label``) and ``critical_forcing_numeric`` ones (docs/contracts.md).
"""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D

from safebasins.plotting.data import open_dataset, param, var
from safebasins.plotting.style import LABELS, fmt_value, param_text

# mechanism flags of theory.critical_forcing: "none MM_0 MM_pi SM SMM"
MECHANISMS = {
    1: dict(name="MM_0", label=r"MM ($\gamma^*=0$)", ls="-.", color="tab:purple"),
    2: dict(name="MM_pi", label=r"MM ($\gamma^*=\pi$)", ls="--", color="tab:green"),
    3: dict(name="SM", label="SM", ls="-", color="tab:blue"),
    4: dict(name="SMM", label="SMM", ls=":", color="tab:red"),
}
# branch variables of the critical_forcing dataset, in the mechanism order above
BRANCHES = {1: "F_MM_0", 2: "F_MM_pi", 3: "F_SM", 4: "F_SMM"}
CURVE_COORDS = ("xi_max", "xi_ini", "gamma_ini", "Psi")


def curve_labels(ds, dim="curve"):
    """Legend labels from the coordinates that vary along ``dim``; constants -> title dict."""
    n = ds.sizes.get(dim, 1)
    varying, constant = [], {}
    for c in CURVE_COORDS:
        if c in ds.coords and dim in ds[c].dims:
            vals = np.asarray(ds[c], float)
            if np.allclose(vals, vals[0], equal_nan=True):
                constant[c] = vals[0]
            else:
                varying.append(c)
        elif c in ds.attrs:
            constant[c] = param(ds, c)
    if varying:
        labels = [param_text({c: ds[c].values[i] for c in varying}) for i in range(n)]
    elif "label" in ds.coords:
        labels = [str(v) for v in np.asarray(ds["label"])]
    else:
        labels = [f"curve {i}" for i in range(n)]
    return labels, constant


def ic_text(const):
    """Title text for the constant curve parameters; the zero IC is named as such."""
    const = dict(const)
    if "xi_ini" in const and float(const["xi_ini"]) == 0.0:
        const.pop("xi_ini")
        const.pop("gamma_ini", None)
        txt = param_text(const)
        return (txt + ", zero IC") if txt else "zero IC"
    return param_text(const)


def _runs(values):
    """Split an index range into runs of equal value: [(value, start, stop_exclusive), ...]."""
    values = np.asarray(values)
    if values.size == 0:
        return []
    change = np.flatnonzero(values[1:] != values[:-1]) + 1
    starts = np.r_[0, change]
    stops = np.r_[change, values.size]
    return [(values[s], s, e) for s, e in zip(starts, stops)]


def _mechanism_array(da):
    m = np.asarray(da, dtype=float)
    m = np.where(np.isfinite(m), m, 0).astype(int)
    return m


def draw_fcr_curve(ax, Omega, F_cr, mechanism=None, *, color=None, by_mechanism_color=False,
                   lw=1.8, label=None, zorder=3):
    """One F_cr(Omega) curve split into runs of equal mechanism, styled per MECHANISMS.

    Consecutive runs share their junction point so the curve stays continuous."""
    Omega = np.asarray(Omega, float)
    F_cr = np.asarray(F_cr, float)
    mech = np.full(F_cr.shape, 3) if mechanism is None else _mechanism_array(mechanism)
    mech = np.where(np.isfinite(F_cr), mech, 0)
    drawn = set()
    first = True
    for m, s, e in _runs(mech):
        if m == 0:
            continue
        st = MECHANISMS.get(int(m), MECHANISMS[3])
        stop = min(e + 1, F_cr.size) if e < F_cr.size and mech[min(e, F_cr.size - 1)] != 0 else e
        c = st["color"] if by_mechanism_color else color
        ax.plot(Omega[s:stop], F_cr[s:stop], ls=st["ls"], color=c, lw=lw, zorder=zorder,
                label=label if first else None, solid_capstyle="butt")
        first = False
        drawn.add(int(m))
    return drawn


def mechanism_legend_handles(mechanisms, *, by_mechanism_color=False):
    return [Line2D([], [], color=MECHANISMS[m]["color"] if by_mechanism_color else "k",
                   ls=MECHANISMS[m]["ls"], lw=1.8, label=MECHANISMS[m]["label"])
            for m in sorted(mechanisms)]


def draw_fcr(ax, ds, *, color_by="curve", show_branches=False, colors=None, lw=1.8,
             legend=True, legend_loc="best"):
    """All curves of a critical_forcing dataset stacked over ``curve`` (or a single curve).

    ``color_by="curve"``: one colour per curve, line style = mechanism (Figs 1, 2, 4);
    ``color_by="mechanism"``: colours *and* styles by mechanism (Fig 3).
    ``show_branches``: also draw every branch F_MM_0/F_MM_pi/F_SM/F_SMM thin and faint where it
    exists, so the branch the overall minimum switches from stays visible."""
    if "curve" not in ds.dims:
        ds = ds.expand_dims("curve")
    labels, _ = curve_labels(ds)
    n = ds.sizes["curve"]
    if colors is None:
        cmap = plt.get_cmap("viridis")
        colors = ["k"] if n == 1 else [cmap(v) for v in np.linspace(0.0, 0.9, n)]
    Omega = np.asarray(ds["Omega"], float)
    mechs_seen = set()
    curve_handles = []
    for i in range(n):
        d = ds.isel(curve=i)
        col = colors[i % len(colors)]
        if show_branches:
            for m, v in BRANCHES.items():
                st = MECHANISMS[m]
                ax.plot(Omega, np.asarray(var(d, v), float), ls=st["ls"], lw=0.9, alpha=0.45,
                        color=st["color"] if color_by == "mechanism" else col, zorder=2)
        mechs_seen |= draw_fcr_curve(ax, Omega, var(d, "F_cr"), var(d, "mechanism"), color=col,
                                     by_mechanism_color=(color_by == "mechanism"), lw=lw)
        curve_handles.append(Line2D([], [], color=col, lw=lw, label=labels[i]))
    ax.set_xlabel(LABELS["Omega"])
    ax.set_ylabel(LABELS["F_cr"])
    ax.set_xlim(Omega.min(), Omega.max())
    ax.set_ylim(bottom=0)
    if legend:
        handles = mechanism_legend_handles(mechs_seen, by_mechanism_color=(color_by == "mechanism"))
        if show_branches:
            handles.append(Line2D([], [], color="0.5", lw=0.9, alpha=0.6,
                                  label="thin: branch where it is not the minimum"))
        if color_by == "curve" and n > 1:
            handles = curve_handles + [Line2D([], [], ls="none", label="")] + handles
        ax.legend(handles=handles, loc=legend_loc)
    return mechs_seen


def _fcr_ylim(ax, arrays, top=None, pad=1.08):
    if top is not None:
        ax.set_ylim(0, top)
        return
    vals = np.concatenate([np.asarray(a, float).ravel() for a in arrays])
    vals = vals[np.isfinite(vals)]
    if vals.size:
        ax.set_ylim(0, pad * vals.max())


def figure_fcr(analytic, *, color_by="curve", show_branches=False, F_max=None, title=None,
               figsize=(6.4, 4.6)):
    """Figs 1-4: theoretical F_cr(Omega) curves, mechanisms distinguished by line style."""
    ds = open_dataset(analytic)
    if "curve" not in ds.dims:
        ds = ds.expand_dims("curve")
    fig, ax = plt.subplots(figsize=figsize, layout="constrained")
    draw_fcr(ax, ds, color_by=color_by, show_branches=show_branches)
    _fcr_ylim(ax, [ds["F_cr"]], F_max)
    _, const = curve_labels(ds)
    const.pop("Psi", None)  # F_cr on the RM does not depend on the forcing phase
    fourier = param(ds, "fourier")
    head = ic_text(const)
    if fourier and fourier != "paper":
        head += f"  (G: {fourier} first harmonic)"
    ax.set_title(title or f"Theoretical escape threshold, {head}")
    return fig


def draw_fcr_numeric(ax, num, *, color="k", label=None, bracket=True, ms=4.5):
    """Numeric bisection F_cr (dots) and, where escape is non-monotone in F, the bracket
    F_escape_low .. F_escape_all as a vertical bar."""
    Om = np.asarray(num["Omega"], float)
    F = np.asarray(num["F_cr"], float)
    ax.plot(Om, F, "o", ms=ms, mfc=color, mec="k", mew=0.5, color=color, ls="none", zorder=5,
            label=label)
    if not bracket:
        return 0
    lo = np.asarray(var(num, "F_escape_low"), float)
    hi = np.asarray(var(num, "F_escape_all"), float)
    sel = np.asarray(var(num, "non_monotone")).astype(bool) & np.isfinite(lo) & np.isfinite(hi)
    if sel.any():
        ax.vlines(Om[sel], lo[sel], hi[sel], color=color, lw=1.0, alpha=0.8, zorder=4)
        ax.plot(Om[sel], lo[sel], "_", color=color, ms=6, zorder=4)
        ax.plot(Om[sel], hi[sel], "_", color=color, ms=6, zorder=4)
    return int(sel.sum())


def _match_numeric_curve(ana, num, i):
    """Numeric curve matching analytic curve i (by coordinates, else by position)."""
    if "curve" not in num.dims:
        return num
    if num.sizes["curve"] == ana.sizes["curve"]:
        return num.isel(curve=i)
    a = ana.isel(curve=i)
    for j in range(num.sizes["curve"]):
        b = num.isel(curve=j)
        if all(c not in a.coords or c not in b.coords or np.isclose(float(a[c]), float(b[c]))
               for c in CURVE_COORDS):
            return b
    return None


def figure_fcr_comparison(analytic, numeric, *, layout="overlay", F_max=None, title=None,
                          bracket=True, figsize=None):
    """Figs 10-12: theoretical F_cr(Omega) (solid) vs numeric bisection (dots).

    ``layout="panels"``: one panel per curve (Fig 10: one per truncation level);
    ``layout="overlay"``: all curves on one axes (Figs 11, 12)."""
    ana = open_dataset(analytic)
    num = open_dataset(numeric)
    if "curve" not in ana.dims:
        ana = ana.expand_dims("curve")
    if "curve" not in num.dims:
        num = num.expand_dims("curve")
    n = ana.sizes["curve"]
    labels, const = curve_labels(ana)
    cycles = param(num, "cycles")
    tol = param(num, "tol")
    if layout == "panels":
        figsize = figsize or (4.2 * n, 4.0)
        fig, axes = plt.subplots(1, n, figsize=figsize, layout="constrained", squeeze=False)
        axes = list(axes[0])
        colors = ["tab:blue"] * n
    else:
        figsize = figsize or (6.6, 4.8)
        fig, ax = plt.subplots(figsize=figsize, layout="constrained")
        axes = [ax] * n
        cmap = plt.get_cmap("viridis")
        colors = ["tab:blue"] if n == 1 else [cmap(v) for v in np.linspace(0.0, 0.88, n)]
    n_bracket = 0
    for i in range(n):
        ax = axes[i]
        a = ana.isel(curve=i)
        col = colors[i]
        Om = np.asarray(a["Omega"], float)
        ax.plot(Om, np.asarray(a["F_cr"], float), "-", color=col, lw=1.8, zorder=3,
                label=(f"theory, {labels[i]}" if layout == "overlay" else "theory"))
        b = _match_numeric_curve(ana, num, i)
        if b is not None:
            n_bracket += draw_fcr_numeric(ax, b, color=col, bracket=bracket,
                                          label=("numeric" if layout == "panels" or i == n - 1 else None))
        arrays = [a["F_cr"]] + ([b["F_cr"]] if b is not None else [])
        if layout == "panels" or i == n - 1:
            ax.set_xlabel(LABELS["Omega"])
            ax.set_ylabel(LABELS["F_cr"])
            ax.set_xlim(Om.min(), Om.max())
        if layout == "panels":
            _fcr_ylim(ax, arrays, F_max)
            ax.set_title(labels[i])
    if layout == "overlay":
        _fcr_ylim(axes[0], [ana["F_cr"], num["F_cr"]], F_max)
    extra = []
    if n_bracket and bracket:
        extra.append(Line2D([], [], color="0.3", marker="_", ms=6, lw=1.0,
                            label=r"non-monotone: $F_{escape,low}$ .. $F_{escape,all}$"))
    for ax in dict.fromkeys(axes):
        h, l_ = ax.get_legend_handles_labels()
        h = [x for x, lab in zip(h, l_) if lab]
        if layout == "overlay":
            # dots legend entry in neutral colour
            h = [x for x in h if x.get_label() != "numeric"] + [
                Line2D([], [], marker="o", ls="none", mfc="0.6", mec="k", mew=0.5,
                       label=f"numeric (bisection, {fmt_value(cycles)} EC)" if cycles else "numeric")]
        ax.legend(handles=h + extra, loc="best")
    head = ic_text(const)
    sub = []
    if cycles:
        sub.append(f"{fmt_value(cycles)} EC")
    if tol:
        sub.append(f"tol {fmt_value(tol)}")
    fig.suptitle(title or (f"Escape threshold: theory (lines) vs numerics (dots)" +
                           (f", {head}" if head else "") + (f"  [{', '.join(sub)}]" if sub else "")),
                 fontsize=10)
    return fig
