"""Drawing pieces shared by the paper's 22 figures.

Every function here only *reads* datasets written by the pipeline (see docs/contracts.md):
nothing recomputes physics.  Two layers:

* axis-level pieces (``draw_*``) take a matplotlib ``Axes`` and an ``xarray`` object;
* figure-level builders (``figure_*``) take dataset paths (or datasets), lay out the panels the
  paper shows, put the paper's parameters (read from the dataset attributes) in the title and
  return the ``Figure``.  The notebooks call the builders and :func:`save_figure`.

Conventions (paper): dimensionless units, time in excitation cycles (EC); safe basin for a
threshold and an evaluation time ``t_eval`` = ``escape_cycle > t_eval``.
"""
from __future__ import annotations

import os
from contextlib import contextmanager

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import xarray as xr  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402
from matplotlib.legend_handler import HandlerTuple  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

# --------------------------------------------------------------------------------------------
# style and labels
# --------------------------------------------------------------------------------------------
DEFAULT_DPI = 180

LABELS = {
    "gamma": r"slow phase $\gamma$",
    "xi": r"averaged energy $\xi$",
    "q0": r"initial displacement $q_0$",
    "p0": r"initial momentum $p_0$",
    "q": r"displacement $q$",
    "p": r"momentum $p$",
    "Omega": r"forcing frequency $\Omega$",
    "F": r"forcing amplitude $F$",
    "F_cr": r"critical forcing $F_{cr}$",
    "t_eval": r"evaluation time $t_{eval}$ (EC)",
}

# symbols used in titles / legends for parameters
SYMBOLS = {
    "F": r"$F$",
    "Omega": r"$\Omega$",
    "Psi": r"$\Psi$",
    "xi_max": r"$\xi_{max}$",
    "q_max": r"$q_{max}$",
    "xi0": r"$\xi_{ini}$",
    "xi_ini": r"$\xi_{ini}$",
    "gamma0": r"$\gamma_{ini}$",
    "gamma_ini": r"$\gamma_{ini}$",
    "t_eval": r"$t_{eval}$",
}

# mechanism flags of theory.critical_forcing: "none MM_0 MM_pi SM SMM"
MECHANISMS = {
    1: dict(name="MM_0", label=r"MM ($\gamma^*=0$)", ls="-.", color="tab:purple"),
    2: dict(name="MM_pi", label=r"MM ($\gamma^*=\pi$)", ls="--", color="tab:green"),
    3: dict(name="SM", label="SM", ls="-", color="tab:blue"),
    4: dict(name="SMM", label="SMM", ls=":", color="tab:red"),
}
# branch variables of the critical_forcing dataset, in the mechanism order above
BRANCHES = {1: "F_MM_0", 2: "F_MM_pi", 3: "F_SM", 4: "F_SMM"}

SB_FACE = "0.72"        # safe basin grey (RM portraits, Figs 5-9)
SB_EDGE = "tab:red"     # safe basin boundary (Figs 5-9)
TRUNC_COLOR = "tab:blue"  # truncation level xi = xi_max (Figs 5-9, "blue dashed")

RC = {
    "figure.dpi": 100,
    "savefig.dpi": DEFAULT_DPI,
    "savefig.bbox": "tight",
    "font.size": 10,
    "axes.titlesize": 10,
    "axes.labelsize": 10,
    "legend.fontsize": 8,
    "legend.framealpha": 0.9,
    "xtick.direction": "in",
    "ytick.direction": "in",
    "xtick.top": True,
    "ytick.right": True,
    "axes.grid": False,
    "lines.linewidth": 1.6,
    "pdf.fonttype": 42,
}


def apply_style(**overrides):
    """Set the shared rcParams (call once at the top of a notebook)."""
    plt.rcParams.update({**RC, **overrides})


@contextmanager
def style(**overrides):
    with plt.rc_context({**RC, **overrides}):
        yield


def save_figure(fig, png=None, pdf=None, *, dpi=DEFAULT_DPI):
    """Write ``fig`` to PNG (``dpi``) and/or PDF, creating parent folders."""
    for path, kw in ((png, dict(dpi=dpi)), (pdf, {})):
        if path:
            d = os.path.dirname(os.fspath(path))
            if d:
                os.makedirs(d, exist_ok=True)
            fig.savefig(path, bbox_inches="tight", **kw)
    return fig


# --------------------------------------------------------------------------------------------
# small helpers
# --------------------------------------------------------------------------------------------
def open_dataset(src):
    """Path -> fully loaded Dataset (file closed again); a Dataset passes through."""
    if src is None or isinstance(src, (xr.Dataset, xr.DataArray)):
        return src
    with xr.open_dataset(src) as ds:
        return ds.load()


def fmt_value(v, name=None):
    """Compact number for titles; multiples of pi are written with pi."""
    try:
        v = float(v)
    except (TypeError, ValueError):
        return str(v)
    if not np.isfinite(v):
        return str(v)
    if name in ("Psi", "gamma0", "gamma_ini") and v != 0:
        r = v / np.pi
        for num, txt in ((1, r"\pi"), (0.5, r"\pi/2"), (-1, r"-\pi"), (-0.5, r"-\pi/2"), (2, r"2\pi")):
            if abs(r - num) < 1e-9:
                return f"${txt}$"
    if v != 0 and (abs(v) < 1e-3 or abs(v) >= 1e5):
        return f"{v:.3g}"
    return f"{v:.6g}" if abs(v) >= 1 else f"{round(v, 6):g}"


def param_text(params, *, sep=", "):
    """``{"F": 0.0876, "Omega": 0.92}`` -> ``$F$ = 0.0876, $\\Omega$ = 0.92``."""
    parts = []
    for k, v in params.items():
        if v is None:
            continue
        parts.append(f"{SYMBOLS.get(k, k)} = {fmt_value(v, k)}")
    return sep.join(parts)


def _attr(ds, *names, default=None):
    for n in names:
        if ds is None:
            break
        if n in ds.attrs:
            v = ds.attrs[n]
            if isinstance(v, np.ndarray) and v.size == 1:
                v = v.item()
            return v
        if n in ds.coords and ds[n].size == 1:
            return ds[n].item()
    return default


def _var(ds, *names, required=True):
    """First of ``names`` present as data variable or coordinate."""
    for n in names:
        if n in ds.variables:
            return ds[n]
    if required:
        raise KeyError(f"none of {names} in dataset (variables: {sorted(map(str, ds.variables))})")
    return None


def _runs(values):
    """Split an index range into runs of equal value: [(value, start, stop_exclusive), ...]."""
    values = np.asarray(values)
    if values.size == 0:
        return []
    change = np.flatnonzero(values[1:] != values[:-1]) + 1
    starts = np.r_[0, change]
    stops = np.r_[change, values.size]
    return [(values[s], s, e) for s, e in zip(starts, stops)]


def _break_wraps(x, y, period=2 * np.pi):
    """Insert NaN where a periodic coordinate jumps by more than half a period."""
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    if x.size < 2:
        return x, y
    jumps = np.flatnonzero(np.abs(np.diff(x)) > period / 2) + 1
    if jumps.size:
        x = np.insert(x, jumps, np.nan)
        y = np.insert(y, jumps, np.nan)
    return x, y


def _pi_ticks(ax, lo, hi, axis="x"):
    """Ticks at multiples of pi/2 between lo and hi."""
    k = np.arange(np.ceil(lo / (np.pi / 2) - 1e-9), np.floor(hi / (np.pi / 2) + 1e-9) + 1)
    names = {0: "0", 1: r"$\pi/2$", -1: r"$-\pi/2$", 2: r"$\pi$", -2: r"$-\pi$", 3: r"$3\pi/2$",
             -3: r"$-3\pi/2$", 4: r"$2\pi$", -4: r"$-2\pi$"}
    ticks = k * np.pi / 2
    labels = [names.get(int(i), f"{int(i)}" + r"$\pi/2$") for i in k]
    if axis == "x":
        ax.set_xticks(ticks, labels)
    else:
        ax.set_yticks(ticks, labels)


def _grey_levels(n, light=0.86, dark=0.32):
    """n grey shades, lightest first."""
    if n <= 1:
        return [str(round((light + dark) / 2, 3))]
    return [str(round(v, 3)) for v in np.linspace(light, dark, n)]


def _xy_grid(da):
    """DataArray over (q0, p0) in any order -> (q0, p0, Z) with Z indexed [p0, q0] for pcolor."""
    da = da.transpose("p0", "q0")
    return np.asarray(da["q0"]), np.asarray(da["p0"]), np.asarray(da)


def well_energy(q, p):
    """H0 of eq (7) (untruncated): the unforced well, used only to draw ``H0 = xi_max``."""
    return 0.5 * p**2 + 0.5 * q**2 - 0.25 * q**4


def draw_well(ax, xi_max, *, q=None, p=None, n=400, **kw):
    """Dashed outline of the unforced well ``H0(q, p) = xi_max`` on a (q, p) axes."""
    if xi_max is None or not np.isfinite(xi_max):
        return None
    qm = np.sqrt(max(1 - np.sqrt(max(1 - 4 * float(xi_max), 0.0)), 0.0))  # eq (4)
    qq = np.linspace(-qm, qm, n)
    pp = np.sqrt(np.clip(2 * (xi_max - 0.5 * qq**2 + 0.25 * qq**4), 0, None))
    x = np.r_[qq, qq[::-1], qq[:1]]
    y = np.r_[pp, -pp[::-1], pp[:1]]
    style = dict(color="0.35", lw=0.9, ls=(0, (4, 2)), zorder=4)
    style.update(kw)
    (line,) = ax.plot(x, y, **style)
    return line


# --------------------------------------------------------------------------------------------
# Figs 1-4 (and theory lines of 10-12): F_cr(Omega) with mechanisms distinguished
# --------------------------------------------------------------------------------------------
CURVE_COORDS = ("xi_max", "xi0", "gamma0", "Psi")


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
            constant[c] = _attr(ds, c)
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
    if "xi0" in const and float(const["xi0"]) == 0.0:
        const.pop("xi0")
        const.pop("gamma0", None)
        txt = param_text(const)
        return (txt + ", zero IC") if txt else "zero IC"
    return param_text(const)


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
                if v in d:
                    st = MECHANISMS[m]
                    ax.plot(Omega, np.asarray(d[v], float), ls=st["ls"], lw=0.9, alpha=0.45,
                            color=st["color"] if color_by == "mechanism" else col, zorder=2)
        mech = d["mechanism"] if "mechanism" in d else None
        mechs_seen |= draw_fcr_curve(ax, Omega, d["F_cr"], mech, color=col,
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
    fourier = _attr(ds, "fourier")
    head = ic_text(const)
    if fourier and fourier != "paper":
        head += f"  (G: {fourier} first harmonic)"
    ax.set_title(title or f"Theoretical escape threshold, {head}")
    return fig


# --------------------------------------------------------------------------------------------
# Figs 10-12: theory lines + numeric dots (+ non-monotone bracket)
# --------------------------------------------------------------------------------------------
def draw_fcr_numeric(ax, num, *, color="k", label=None, bracket=True, ms=4.5):
    """Numeric bisection F_cr (dots) and, where escape is non-monotone in F, the bracket
    F_escape_low .. F_escape_all as a vertical bar."""
    Om = np.asarray(num["Omega"], float)
    F = np.asarray(num["F_cr"], float)
    ax.plot(Om, F, "o", ms=ms, mfc=color, mec="k", mew=0.5, color=color, ls="none", zorder=5,
            label=label)
    if not bracket or "F_escape_low" not in num or "F_escape_all" not in num:
        return 0
    lo = np.asarray(num["F_escape_low"], float)
    hi = np.asarray(num["F_escape_all"], float)
    if "non_monotone" in num:
        sel = np.asarray(num["non_monotone"]).astype(bool)
    else:
        sel = np.isfinite(lo) & np.isfinite(hi) & (hi - lo > 0)
    sel &= np.isfinite(lo) & np.isfinite(hi)
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
    cycles = _attr(num, "cycles")
    tol = _attr(num, "tol")
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


# --------------------------------------------------------------------------------------------
# Figs 5-9: resonance-manifold portrait + safe basin on (q0, p0)
# --------------------------------------------------------------------------------------------
def vertex_var(ds, base, dim="vertex"):
    """Boundary-vertex variable ``base`` (gamma, xi, q0, p0, curve_index) on the ``vertex``
    dimension.  In files that also hold a (q0, p0) grid the vertex coordinates cannot be named
    ``q0``/``p0``; accept ``<base>_<dim>``, ``<dim>_<base>``, ``boundary_<base>`` etc."""
    if base in ds.variables and dim in ds[base].dims:
        return ds[base]
    for n in (f"{base}_{dim}", f"{dim}_{base}", f"boundary_{base}", f"{base}_boundary", f"{base}v",
              f"b_{base}"):
        if n in ds.variables and dim in ds[n].dims:
            return ds[n]
    cands = [n for n in ds.variables if dim in ds[n].dims and str(n).replace("_", "").startswith(base.replace("_", ""))]
    cands += [n for n in ds.variables if dim in ds[n].dims and base in str(n).split("_")]
    return ds[cands[0]] if cands else None


def _boundary_polylines(ds, xname, yname):
    """Polylines (x, y, kind) of a safe_basin_boundaries dataset (one slice of a stack)."""
    xv, yv = vertex_var(ds, xname), vertex_var(ds, yname)
    if xv is None or yv is None:
        return []
    x = np.asarray(xv, float)
    y = np.asarray(yv, float)
    iv = vertex_var(ds, "curve_index")
    idx = np.asarray(iv, float) if iv is not None else np.zeros_like(x)
    idx = np.where(np.isfinite(idx), idx, -1).astype(int)
    kinds = [str(k) for k in np.asarray(ds["kind"])] if "kind" in ds else []
    out = []
    for ci in np.unique(idx[idx >= 0]):
        sel = idx == ci
        # keep NaN separators that sit between vertices of this curve
        xs, ys = x[sel], y[sel]
        if not np.isfinite(xs).any():
            continue
        kind = kinds[ci] if ci < len(kinds) else ""
        out.append((xs, ys, kind))
    return out


def separates_mask(xs, ys, safe, *, halo=2, min_fraction=0.5):
    """True if the polyline (xs, ys) runs along the edge of the boolean DataArray ``safe``
    (dims q0, p0): at least ``min_fraction`` of its vertices have both safe and escaping
    pixels within ``halo`` pixels.  Level curves of C through a saddle can lie entirely
    inside the predicted basin (e.g. a saddle-type region contained in a peninsula): they are
    not boundaries of the safe basin and are not drawn on the IC plane."""
    q = np.asarray(safe["q0"], float)
    p = np.asarray(safe["p0"], float)
    S = np.asarray(safe.transpose("q0", "p0")).astype(bool)
    ok = np.isfinite(xs) & np.isfinite(ys)
    if not ok.any():
        return False
    i = np.clip(np.searchsorted(q, xs[ok]), 0, q.size - 1)
    j = np.clip(np.searchsorted(p, ys[ok]), 0, p.size - 1)
    edge = np.zeros(i.size, bool)
    for k, (a, b) in enumerate(zip(i, j)):
        win = S[max(a - halo, 0):a + halo + 1, max(b - halo, 0):b + halo + 1]
        edge[k] = win.any() and not win.all()
    return edge.mean() >= min_fraction


def draw_boundaries(ax, ds, xname, yname, *, periodic=False, safe=None, **kw):
    """Boundary polylines of a safe_basin_boundaries dataset.  With ``safe`` (the analytic
    safe mask on (q0, p0)), curves that do not border it are skipped (:func:`separates_mask`)."""
    style = dict(color=SB_EDGE, lw=1.8, zorder=6)
    style.update(kw)
    lines = []
    for xs, ys, _kind in _boundary_polylines(ds, xname, yname):
        if safe is not None and not separates_mask(xs, ys, safe):
            continue
        if periodic:
            xs, ys = _break_wraps(xs, ys)
        lines += ax.plot(xs, ys, **style)
    return lines


def analytic_safe(ds):
    """Analytic safe mask ``~escapes`` over (q0, p0) of one basin slice, or None."""
    esc = _var(ds, "escapes", required=False) if ds is not None else None
    if esc is None or "q0" not in esc.dims or "p0" not in esc.dims or esc.ndim != 2:
        return None
    return ~esc.astype(bool)


def _safe_fill(ax, x, y, safe, *, color=SB_FACE, zorder=1, alpha=1.0):
    """Fill where ``safe`` (2-D, indexed [y, x]) is True with a flat colour."""
    z = np.ma.masked_where(~safe, np.ones(safe.shape))
    return ax.pcolormesh(x, y, z, cmap=ListedColormap([color]), vmin=0, vmax=1, shading="nearest",
                         zorder=zorder, alpha=alpha, rasterized=True, linewidth=0)


def _recenter(g, arrays, center):
    """Shift periodic gamma columns to the window [center - pi, center + pi)."""
    lo = center - np.pi
    gg = (g - lo) % (2 * np.pi) + lo
    keep = np.r_[True, np.abs(np.diff(g)) > 0]
    if np.isclose(g[-1] - g[0], 2 * np.pi):  # duplicated end point: drop it, re-add on the right
        keep[-1] = False
    order = np.argsort(gg[keep], kind="stable")
    gg = gg[keep][order]
    out = [a[:, keep][:, order] for a in arrays]
    # close the window: repeat the first column at +2 pi
    gg = np.r_[gg, gg[0] + 2 * np.pi]
    out = [np.concatenate([a, a[:, :1]], axis=1) for a in out]
    return gg, out


def rm_center(ds):
    """Window centre for gamma: pi when the safe region sits at the seam gamma = +-pi and not
    at gamma = 0 (island around the MM tangency at gamma* = pi, Fig 5), else 0."""
    esc = _var(ds, "escapes_rm", required=False)
    if esc is None:
        return 0.0
    gdim = [d for d in esc.dims if "gamma" in d][0]
    safe = ~np.asarray(esc.transpose(..., gdim)).astype(bool)
    g = np.asarray(ds[gdim], float)
    mid = np.abs(g) < 0.15 * np.pi
    edge = np.abs(g) > 0.85 * np.pi
    return np.pi if safe[..., edge].any() and not safe[..., mid].any() else 0.0


def draw_rm_portrait(ax, ds, *, n_levels=24, show_saddle=True, center="auto"):
    """Left panel of Figs 5-9: level curves of C on (gamma, xi), truncation level dashed,
    safe basin grey with red boundary.  ``center``: gamma at the middle of the window
    (``"auto"``: see :func:`rm_center`)."""
    C = _var(ds, "C", "C_rm")
    gdim = [d for d in C.dims if "gamma" in d][0]
    xdim = [d for d in C.dims if "xi" in d][0]
    C = C.transpose(xdim, gdim)
    g = np.asarray(ds[gdim], float)
    xi = np.asarray(ds[xdim], float)
    Z = np.asarray(C, float)
    xi_max = _attr(ds, "xi_max")
    esc = _var(ds, "escapes_rm", required=False)
    safe = None if esc is None else ~np.asarray(esc.transpose(xdim, gdim)).astype(bool)
    if center == "auto":
        center = rm_center(ds)
    if g.max() - g.min() > 1.9 * np.pi:
        arrays = [Z] + ([safe] if safe is not None else [])
        g, arrays = _recenter(g, arrays, float(center))
        Z = arrays[0]
        safe = arrays[1] if safe is not None else None
    if safe is not None:
        _safe_fill(ax, g, xi, safe)
    finite = Z[np.isfinite(Z)]
    if finite.size:
        levels = np.linspace(np.percentile(finite, 0.5), np.percentile(finite, 99.5), n_levels)
        ax.contour(g, xi, Z, levels=levels, colors="k", linewidths=0.5, alpha=0.55, zorder=3,
                   linestyles="solid")
    lo = g.min()
    for xs, ys, _kind in _boundary_polylines(ds, "gamma", "xi"):
        xs = (xs - lo) % (2 * np.pi) + lo
        xs, ys = _break_wraps(xs, ys)
        ax.plot(xs, ys, color=SB_EDGE, lw=1.8, zorder=6)
    if xi_max is not None:
        ax.axhline(float(xi_max), color=TRUNC_COLOR, ls="--", lw=2.2, zorder=7)
    sg, sx = _attr(ds, "saddle_gamma"), _attr(ds, "saddle_xi")
    if show_saddle and sg is not None and sx is not None and np.isfinite(sg) and np.isfinite(sx):
        sg = (float(sg) - lo) % (2 * np.pi) + lo
        ax.plot(sg, sx, "o", mfc="w", mec="k", ms=5, zorder=8)
    ax.set_xlim(g.min(), g.max())
    ax.set_ylim(max(0.0, xi.min()), xi.max())
    if g.max() - g.min() > 3:
        _pi_ticks(ax, g.min(), g.max())
    ax.set_xlabel(LABELS["gamma"])
    ax.set_ylabel(LABELS["xi"])


def draw_ic_basin(ax, ds, *, well=True):
    """Right panel of Figs 5-9: analytic safe basin on (q0, p0), boundary red."""
    xi_max = _attr(ds, "xi_max")
    esc = _var(ds, "escapes", required=False)
    if esc is not None and "q0" in esc.dims:
        q, p, Z = _xy_grid(esc)
        _safe_fill(ax, q, p, ~Z.astype(bool))
        ax.set_xlim(q.min(), q.max())
        ax.set_ylim(p.min(), p.max())
    draw_boundaries(ax, ds, "q0", "p0")
    if well and xi_max is not None:
        draw_well(ax, float(xi_max))
    ax.set_aspect("equal")
    ax.set_xlabel(LABELS["q0"])
    ax.set_ylabel(LABELS["p0"])


def _basin_legend_handles(xi_max=None, *, saddle=False):
    h = [Patch(facecolor=SB_FACE, edgecolor=SB_EDGE, lw=1.5, label="safe basin (theory)")]
    if xi_max is not None:
        h.append(Line2D([], [], color=TRUNC_COLOR, ls="--", lw=2.2,
                        label=rf"truncation $\xi = \xi_{{max}}$ = {fmt_value(xi_max)}"))
    h.append(Line2D([], [], color="k", lw=0.6, alpha=0.6, label=r"level curves of $C(\gamma,\xi)$"))
    if saddle:
        h.append(Line2D([], [], marker="o", mfc="w", mec="k", ls="none", label="saddle"))
    return h


def basin_kinds(ds):
    if "kind" not in ds:
        return []
    return sorted({str(k) for k in np.asarray(ds["kind"]) if str(k)})


def figure_rm_basin(analytic, *, title=None, figsize=(11.5, 4.6)):
    """Figs 5-9: (left) RM portrait with SB, (right) SB on the IC plane."""
    ds = open_dataset(analytic)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=figsize, layout="constrained",
                                 gridspec_kw=dict(width_ratios=[1.25, 1]))
    draw_rm_portrait(a1, ds)
    draw_ic_basin(a2, ds)
    sx = _attr(ds, "saddle_xi")
    has_saddle = sx is not None and np.isfinite(float(sx))
    below = dict(loc="upper center", bbox_to_anchor=(0.5, -0.13), fontsize=8, frameon=False)
    a1.legend(handles=_basin_legend_handles(_attr(ds, "xi_max"), saddle=has_saddle),
              ncol=2, **below)
    a2.legend(handles=[Patch(facecolor=SB_FACE, edgecolor=SB_EDGE, lw=1.5, label="safe basin (theory)"),
                       Line2D([], [], color="0.35", ls=(0, (4, 2)), lw=0.9,
                              label=r"well edge $H_0 = \xi_{max}$")],
              ncol=2, **below)
    a1.set_title(r"resonance manifold $(\gamma, \xi)$")
    a2.set_title(r"initial conditions $(q_0, p_0)$")
    params = {k: _attr(ds, k) for k in ("F", "Omega", "Psi", "xi_max")}
    kinds = basin_kinds(ds)
    kind_txt = f"  [{' + '.join(kinds)}]" if kinds else ""
    fig.suptitle(title or (param_text(params) + kind_txt), fontsize=11)
    return fig


# --------------------------------------------------------------------------------------------
# Figs 13-17: nested numeric safe basins, theory boundaries, IoU
# --------------------------------------------------------------------------------------------
def escape_cycles(chart, criterion="energy"):
    """The escape_cycle variable of a chart for 'energy' or 'displacement'."""
    if criterion == "energy":
        return _var(chart, "escape_cycle_energy", "escape_cycle")
    return _var(chart, "escape_cycle_displacement")


def safe_from_cycles(ec, t_eval):
    """Safe basin for t_eval: escape_cycle > t_eval (+inf = never escaped)."""
    a = np.asarray(ec, float)
    return np.isposinf(a) | (a > float(t_eval))


def _stack_param(chart, param, criterion="energy"):
    """-> (values, list of safe-mask DataArrays over (q0, p0)), following the parameter."""
    ec = escape_cycles(chart, criterion)
    t_eval = _attr(chart, "t_eval", "agreement_t_eval", "cycles")
    if t_eval is None:
        t_eval = np.inf
    vals = np.atleast_1d(np.asarray(chart[param], float)) if param in chart.coords else np.array([np.nan])
    masks = []
    for i, v in enumerate(vals):
        e = ec.isel({param: i}) if param in ec.dims else ec
        # squeeze any other singleton dims (e.g. xi_max in an F stack)
        extra = [d for d in e.dims if d not in ("q0", "p0")]
        for d in extra:
            if e.sizes[d] != 1:
                raise ValueError(f"escape chart has an extra non-singleton dimension {d!r}")
        e = e.isel({d: 0 for d in extra})
        masks.append(xr.DataArray(safe_from_cycles(e, t_eval), dims=e.dims, coords={
            "q0": e["q0"], "p0": e["p0"]}))
    return vals, masks, t_eval


def draw_nested_safe(ax, masks, *, order=None, greys=None):
    """Paint safe masks so that lighter regions include darker ones: the largest basin is
    painted first (lightest), smaller ones on top (darker). Returns {index: grey}."""
    n = len(masks)
    if order is None:
        order = sorted(range(n), key=lambda i: -int(np.asarray(masks[i]).sum()))
    greys = greys or _grey_levels(n)
    shade = {}
    for rank, i in enumerate(order):
        q, p, Z = _xy_grid(masks[i])
        _safe_fill(ax, q, p, Z.astype(bool), color=greys[rank], zorder=1 + rank * 0.01)
        shade[i] = greys[rank]
    return shade


LINE_STYLES = ["-", "--", "-.", ":", (0, (5, 1, 1, 1, 1, 1))]


def _theory_stack(basins, param, vals):
    """Slices of a boundary stack matching the numeric parameter values."""
    if basins is None:
        return [None] * len(vals)
    if param not in basins.dims:
        return [basins] * len(vals)
    bv = np.asarray(basins[param], float)
    out = []
    for v in vals:
        j = np.flatnonzero(np.isclose(bv, v, rtol=1e-6, atol=1e-12))
        out.append(basins.isel({param: int(j[0])}) if j.size else None)
    return out


def _agreement(chart, name, param, i):
    if name not in chart:
        return None
    a = chart[name]
    if param in a.dims:
        a = a.isel({param: i})
    a = np.asarray(a, float).ravel()
    return float(a[0]) if a.size else None


def figure_nested_basins(analytic, numeric, *, param="xi_max", title=None, t_eval=None,
                         figsize=(9.6, 5.6), theory_colors=None, boundary_only=True):
    """Figs 13-17: numeric safe basins shaded by ``param`` (lighter regions include darker
    ones, white = escape for every value), theory boundaries as curves, IoU in the legend.
    ``boundary_only``: draw only the theory curves that border the analytic safe mask."""
    chart = open_dataset(numeric)
    basins = open_dataset(analytic)
    if t_eval is not None:
        chart = chart.assign_attrs(t_eval=t_eval)
    vals, masks, t_ev = _stack_param(chart, param)
    fig, ax = plt.subplots(figsize=figsize, layout="constrained")
    shade = draw_nested_safe(ax, masks)
    theory = _theory_stack(basins, param, vals)
    colors = theory_colors or ["tab:red", "tab:blue", "tab:green", "tab:orange", "tab:purple",
                               "tab:brown", "tab:pink"]
    handles = []
    # legend in parameter order
    for i in np.argsort(vals):
        col = colors[i % len(colors)]
        ls = LINE_STYLES[i % len(LINE_STYLES)]
        if theory[i] is not None:
            draw_boundaries(ax, theory[i], "q0", "p0", color=col, ls=ls, lw=1.6,
                            safe=analytic_safe(theory[i]) if boundary_only else None)
        iou = _agreement(chart, "iou", param, i)
        lab = f"{SYMBOLS[param]} = {fmt_value(vals[i])}"
        if iou is not None and np.isfinite(iou):
            lab += f"   IoU = {iou:.3f}"
        patch = Patch(facecolor=shade[i], edgecolor="none")
        line = Line2D([], [], color=col, ls=ls, lw=1.6)
        handles.append(((patch, line), lab))
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
    fixed = {k: _attr(chart, k) for k in ("F", "Omega", "Psi", "xi_max") if k != param}
    if param == "F":
        fixed["xi_max"] = (float(np.asarray(chart["xi_max"]).ravel()[0]) if "xi_max" in chart.coords
                           else _attr(basins, "xi_max"))
    fixed = {k: v for k, v in fixed.items() if v is not None}
    res = f"{chart.sizes.get('q0', '?')}x{chart.sizes.get('p0', '?')} ICs"
    te = f"{fmt_value(t_ev)} EC" if np.isfinite(t_ev) else ""
    ax.set_title(title or (f"Safe basins vs {SYMBOLS[param]}: " + param_text(fixed) +
                           f"\n(numeric: {res}, {te}; lighter regions contain darker ones)"))
    return fig


# --------------------------------------------------------------------------------------------
# Fig 18: period map + predicted boundary
# --------------------------------------------------------------------------------------------
def figure_period_map(analytic, numeric, *, title=None, figsize=(7.6, 6.4), s=0.8,
                      max_points=None):
    strobe = open_dataset(numeric)
    basin = open_dataset(analytic)
    fig, ax = plt.subplots(figsize=figsize, layout="constrained")
    q = np.asarray(strobe["q"], float)
    p = np.asarray(strobe["p"], float)
    if q.ndim == 1:
        q, p = q[None], p[None]
    if "sample" in strobe["q"].dims and strobe["q"].dims[0] != "sample":
        q, p = q.T, p.T
    if "escaped" in strobe:
        keep = ~np.asarray(strobe["escaped"]).astype(bool)
        q, p = q[keep], p[keep]
    n = q.shape[0]
    cmap = plt.get_cmap("tab20")
    for i in range(n):
        qi, pi_ = q[i], p[i]
        if max_points:
            qi, pi_ = qi[:max_points], pi_[:max_points]
        ax.scatter(qi, pi_, s=s, color=cmap(i % 20), marker=".", linewidths=0, rasterized=True)
    xi_max = _attr(basin, "xi_max", default=_attr(strobe, "xi_max"))
    blines = draw_boundaries(ax, basin, "q0", "p0", color="k", ls="--", lw=1.6,
                             safe=analytic_safe(basin))
    if xi_max is not None:
        draw_well(ax, float(xi_max), color="0.5", lw=0.8, ls=":")
    # frame the portrait and the predicted boundary (not the whole, mostly empty, well)
    xs = [q[np.isfinite(q)]] + [np.asarray(b.get_xdata(), float) for b in blines]
    ys = [p[np.isfinite(p)]] + [np.asarray(b.get_ydata(), float) for b in blines]
    xs, ys = np.concatenate(xs), np.concatenate(ys)
    xs, ys = xs[np.isfinite(xs)], ys[np.isfinite(ys)]
    if xs.size and ys.size:
        pad = 0.08 * max(np.ptp(xs), np.ptp(ys), 0.1)
        ax.set_xlim(xs.min() - pad, xs.max() + pad)
        ax.set_ylim(ys.min() - pad, ys.max() + pad)
    ax.set_aspect("equal")
    ax.set_xlabel(LABELS["q"] + r" at $t = nT$")
    ax.set_ylabel(LABELS["p"] + r" at $t = nT$")
    ax.legend(handles=[
        Line2D([], [], marker="o", ls="none", color="tab:blue", ms=3,
               label=f"{n} non-escaping trajectories ({strobe.sizes.get('iteration', '?')} iterations)"),
        Line2D([], [], color="k", ls="--", lw=1.6, label="theory: SB boundary"),
        Line2D([], [], color="0.5", ls=":", lw=0.8, label=r"well edge $H_0 = \xi_{max}$")],
        loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=3, fontsize=8, frameon=False)
    params = {k: _attr(strobe, k, default=_attr(basin, k)) for k in ("F", "Omega", "Psi", "xi_max")}
    seed = _attr(strobe, "seed")
    ax.set_title(title or (r"Period map $(q,p)(t) \mapsto (q,p)(t+2\pi/\Omega)$" + "\n" +
                           param_text(params) + (f", seed {seed}" if seed is not None else "")))
    return fig


# --------------------------------------------------------------------------------------------
# Fig 19: relative difference of the two escape criteria
# --------------------------------------------------------------------------------------------
def figure_criteria(numeric, *, title=None, figsize=(6.4, 4.4)):
    ds = open_dataset(numeric)
    rd = _var(ds, "rel_diff")
    if "repeat" not in rd.dims:
        raise ValueError("rel_diff needs a 'repeat' dimension")
    F = np.asarray(ds["F"], float)
    rd = rd.transpose("F", "repeat")
    stats = [("min", rd.min("repeat"), "tab:blue"), ("mean", rd.mean("repeat"), "tab:orange"),
             ("max", rd.max("repeat"), "tab:green")]
    fig, ax = plt.subplots(figsize=figsize, layout="constrained")
    for name, v, c in stats:
        ax.plot(F, np.asarray(v, float), "o", color=c, ms=5, label=f"{name} of {rd.sizes['repeat']}")
    ax.axhline(0, color="0.6", lw=0.6)
    ax.set_xlabel(LABELS["F"])
    ax.set_ylabel(r"$(A_q - A_E)/A_E$")
    ax.legend(loc="upper left")
    params = {k: _attr(ds, k) for k in ("Omega", "Psi", "xi_max", "q_max")}
    if "xi_max" in ds.coords and params["xi_max"] is None:
        params["xi_max"] = float(np.asarray(ds["xi_max"]).ravel()[0])
    n_ic = _attr(ds, "n_samples", "n", "n_ic")
    cyc = _attr(ds, "cycles")
    extra = []
    if n_ic is not None:
        extra.append(f"{int(n_ic)} random ICs in $[-1,1]^2$")
    if cyc is not None:
        extra.append(f"{fmt_value(cyc)} EC")
    ax.set_title(title or ("Displacement vs energy criterion: " + param_text(params) +
                           (("\n" + ", ".join(extra)) if extra else "")))
    return fig


# --------------------------------------------------------------------------------------------
# Figs 20-22: DSB / ESB charts and area vs t_eval
# --------------------------------------------------------------------------------------------
def _first(da, dim):
    return da.isel({dim: 0}) if dim in da.dims else da


def chart_thresholds(chart):
    xi = float(np.asarray(chart["xi_max"]).ravel()[0]) if "xi_max" in chart.coords else _attr(chart, "xi_max")
    qm = float(np.asarray(chart["q_max"]).ravel()[0]) if "q_max" in chart.coords else _attr(chart, "q_max")
    return xi, qm


def draw_dsb_esb(ax, chart, t_eval):
    """DSB (displacement criterion) grey, ESB (energy criterion) black on top."""
    esb = _first(escape_cycles(chart, "energy"), "xi_max")
    dsb = _first(escape_cycles(chart, "displacement"), "q_max")
    q, p, Zd = _xy_grid(dsb)
    _, _, Ze = _xy_grid(esb)
    _safe_fill(ax, q, p, safe_from_cycles(Zd, t_eval), color="0.62", zorder=1)
    _safe_fill(ax, q, p, safe_from_cycles(Ze, t_eval), color="k", zorder=2)
    ax.set_xlim(q.min(), q.max())
    ax.set_ylim(p.min(), p.max())
    ax.set_aspect("equal")
    ax.set_xlabel(LABELS["q0"])
    ax.set_ylabel(LABELS["p0"])
    ax.set_title(rf"$t_{{eval}}$ = {t_eval:,.0f} EC")


def load_params(src):
    """Resolved parameter file (results/params/figNN.yaml) -> dict; dict/None pass through."""
    if src is None or isinstance(src, dict):
        return src or {}
    import yaml

    with open(src) as fh:
        return yaml.safe_load(fh) or {}


def _t_evals(chart, params, t_evals, default):
    """Evaluation times: explicit > parameter file ``t_eval`` > chart attribute > default."""
    if t_evals is not None:
        return [float(t) for t in np.atleast_1d(t_evals)]
    p = load_params(params)
    if p.get("t_eval") is not None:
        return [float(t) for t in np.atleast_1d(p["t_eval"])]
    a = _attr(chart, "t_eval")
    if a is not None:
        return [float(t) for t in np.atleast_1d(a)]
    return list(default)


def figure_dsb_esb(numeric, params=None, *, t_evals=None, title=None, figsize=None):
    """Figs 20-21: DSB grey / ESB black at the first (left) and last (right) t_eval."""
    chart = open_dataset(numeric)
    cycles = float(_attr(chart, "cycles", default=11000))
    t_evals = _t_evals(chart, params, t_evals, (min(500.0, cycles), cycles))
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
    params = {k: _attr(chart, k) for k in ("F", "Omega", "Psi")}
    params["xi_max"] = xi
    res = f"{chart.sizes.get('q0', '?')}x{chart.sizes.get('p0', '?')}"
    fig.suptitle(title or ("Safe basins by the displacement (DSB, grey) and energy (ESB, black) "
                           "criterion\n" + param_text(params) + f", resolution {res}"), fontsize=10.5)
    return fig


def safe_area_curve(ec, t_evals):
    """Number of safe pixels (escape_cycle > t) for every t in ``t_evals`` (vectorised)."""
    a = np.sort(np.asarray(ec, float).ravel())
    t = np.asarray(t_evals, float)
    return a.size - np.searchsorted(a, t, side="right")


def figure_area_vs_time(numeric, params=None, *, t_evals=None, title=None, figsize=(6.6, 4.4)):
    """Fig 22: ln(SB area in pixels) vs t_eval, DSB dashed, ESB solid (one point per t_eval)."""
    chart = open_dataset(numeric)
    cycles = float(_attr(chart, "cycles", default=11000))
    t_evals = np.asarray(_t_evals(chart, params, t_evals, np.linspace(cycles / 100, cycles, 100)), float)
    esb = _first(escape_cycles(chart, "energy"), "xi_max")
    dsb = _first(escape_cycles(chart, "displacement"), "q_max")
    fig, ax = plt.subplots(figsize=figsize, layout="constrained")
    xi, qm = chart_thresholds(chart)
    for ec, ls, lab in ((dsb, "--", f"DSB ($q_{{max}}$ = {fmt_value(qm)})"),
                        (esb, "-", rf"ESB ($\xi_{{max}}$ = {fmt_value(xi)})")):
        area = safe_area_curve(ec, t_evals).astype(float)
        with np.errstate(divide="ignore"):
            la = np.where(area > 0, np.log(area), np.nan)
        ax.plot(t_evals, la, ls=ls, color="k", lw=1.4, marker="o" if t_evals.size <= 40 else None,
                ms=3, label=lab)
    ax.set_xlabel(LABELS["t_eval"])
    ax.set_ylabel(r"$\ln$(SB area / pixels)")
    ax.set_xlim(0, t_evals.max())
    ax.legend(loc="upper right")
    params = {k: _attr(chart, k) for k in ("F", "Omega", "Psi")}
    params["xi_max"] = xi
    res = f"{chart.sizes.get('q0', '?')}x{chart.sizes.get('p0', '?')}"
    ax.set_title(title or ("Safe-basin area vs evaluation time\n" + param_text(params) +
                           f", resolution {res}"))
    return fig


# --------------------------------------------------------------------------------------------
# notebook summary
# --------------------------------------------------------------------------------------------
_SUMMARY_ATTRS = ("title", "F", "Omega", "Psi", "xi_max", "q_max", "xi0", "gamma0", "cycles",
                  "steps_per_cycle", "integrator", "tol", "criterion", "fourier", "seed",
                  "saddle_gamma", "saddle_xi", "git_commit", "config_hash", "safebasins_version")


def describe(**datasets):
    """Text summary of the datasets a figure reads: parameters, provenance, agreement."""
    lines = []
    for name, src in datasets.items():
        if src is None:
            continue
        where = src if isinstance(src, (str, os.PathLike)) else "<dataset>"
        if isinstance(src, dict) or str(src).endswith((".yaml", ".yml")):
            p = load_params(src)
            lines.append(f"[{name}] {where}")
            for k, v in p.items():
                if k != "tasks":
                    txt = repr(v)
                    lines.append(f"  {k}: {txt if len(txt) < 120 else txt[:117] + '...'}")
            continue
        ds = open_dataset(src)
        lines.append(f"[{name}] {where}")
        dims = ", ".join(f"{k}={v}" for k, v in ds.sizes.items())
        lines.append(f"  dims: {dims}")
        lines.append(f"  variables: {', '.join(map(str, ds.data_vars))}")
        for k in _SUMMARY_ATTRS:
            if k in ds.attrs:
                lines.append(f"  {k}: {ds.attrs[k]}")
        for v in ("iou", "pixel_agreement"):
            if v in ds:
                da = ds[v]
                if da.ndim == 1:
                    d = da.dims[0]
                    pairs = ", ".join(f"{fmt_value(c)}: {float(x):.3f}"
                                      for c, x in zip(np.asarray(da[d]), np.asarray(da, float)))
                    lines.append(f"  {v} by {d}: {pairs}")
                else:
                    lines.append(f"  {v}: {np.asarray(da, float).round(3).tolist()}")
    text = "\n".join(lines)
    print(text)
    return text
