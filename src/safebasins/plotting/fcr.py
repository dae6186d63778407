"""Figures of the critical forcing F_cr(Omega): theory curves by mechanism (Figs 1-4) and
theory versus numerics (Figs 10-12).

Reads ``critical_forcing`` datasets stacked over ``curve`` (coordinates ``xi_max``, ``xi_ini``,
``gamma_ini``, ``Psi``, ``label``) and ``critical_forcing_numeric`` ones (docs/contracts.md).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.legend_handler import HandlerTuple
from matplotlib.lines import Line2D

from safebasins.plotting.captions import add_note, count, fmt_range
from safebasins.plotting.data import open_dataset, param, var
from safebasins.plotting.fcr_notes import comparison_notes, mechanism_array
from safebasins.plotting.style import LABELS, SYMBOLS, add_footnote, fmt_value, param_text, plain_text

if TYPE_CHECKING:
    from collections.abc import Iterable, Mapping, Sequence

    import numpy.typing as npt
    import xarray as xr
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from matplotlib.typing import ColorType, LegendLocType

    from safebasins.plotting.data import DataSource


# mechanism flags of theory.critical_forcing: "none MM_0 MM_pi SM SMM"
MECHANISMS: dict[int, dict[str, str]] = {
    1: dict(name="MM_0", label=r"MM ($\gamma^*=0$)", ls="-.", color="tab:purple"),
    2: dict(name="MM_pi", label=r"MM ($\gamma^*=\pi$)", ls="--", color="tab:green"),
    3: dict(name="SM", label="SM", ls="-", color="tab:blue"),
    4: dict(name="SMM", label="SMM", ls=":", color="tab:red"),
}
# branch variables of the critical_forcing dataset, in the mechanism order above
BRANCHES = {1: "F_MM_0", 2: "F_MM_pi", 3: "F_SM", 4: "F_SMM"}
#: the mechanisms in words (the paper, Sec. 3), keyed by the abbreviation of their legend labels
MECHANISM_WORDS = {
    "SM": "saddle mechanism (the level curve of C through the IC passes the saddle of C)",
    "MM": "maximum mechanism (the level curve touches ξ = ξ_max at γ* = 0 or π)",
    "SMM": "saddle maximum mechanism (the MM at γ* = 0 with the saddle above ξ_max)",
}


def mechanism_key(mechanisms: Iterable[int]) -> str:
    """What the abbreviations of the mechanisms drawn (MECHANISMS codes) stand for: the key written
    under every figure whose legend names them ("" for none)."""
    abbr = dict.fromkeys(MECHANISMS[m]["label"].split()[0] for m in sorted(mechanisms) if m in MECHANISMS)
    return "; ".join(f"{a}: {MECHANISM_WORDS[a]}" for a in abbr) + "." if abbr else ""
CURVE_COORDS = ("xi_max", "xi_ini", "gamma_ini", "Psi", "damping")


def curve_labels(ds: xr.Dataset, dim: str = "curve") -> tuple[list[str], dict[str, Any]]:
    """Legend labels from the coordinates that vary along ``dim``; constants -> title dict."""
    n = ds.sizes.get(dim, 1)
    varying: list[str] = []
    constant: dict[str, Any] = {}
    for c in CURVE_COORDS:
        if c in ds.coords and dim in ds[c].dims:
            vals = np.asarray(ds[c], float)
            if np.allclose(vals, vals[0], equal_nan=True):
                constant[c] = vals[0]
            else:
                varying.append(c)
        elif c in ds.attrs or (c in ds.coords and ds[c].size == 1):  # one curve: a scalar coordinate
            constant[c] = param(ds, c)
    if varying:
        labels = [param_text({c: ds[c].values[i] for c in varying}) for i in range(n)]
    elif "label" in ds.coords:
        labels = [_symbols(str(v)) for v in np.atleast_1d(np.asarray(ds["label"]))]
    else:
        labels = [f"curve {i}" for i in range(n)]
    return labels, constant


def _symbols(label: str) -> str:
    """"xi_ini = 0.05" (a stored curve label) -> "$\\xi_{ini}$ = 0.05"."""
    for name in ("xi_ini", "gamma_ini", "xi_max", "Psi", "damping"):
        label = label.replace(f"{name} =", f"{SYMBOLS[name]} =")
    return label


def ic_text(const: Mapping[str, Any]) -> str:
    """Title text for the constant curve parameters; the zero IC is named as such."""
    const = dict(const)
    if "xi_ini" in const and float(const["xi_ini"]) == 0.0:
        const.pop("xi_ini")
        const.pop("gamma_ini", None)
        txt = param_text(const)
        return (txt + ", zero IC") if txt else "zero IC"
    return param_text(const)


def _runs(values: npt.ArrayLike) -> list[tuple[Any, int, int]]:
    """Split an index range into runs of equal value: [(value, start, stop_exclusive), ...]."""
    values = np.asarray(values)
    if values.size == 0:
        return []
    change = np.flatnonzero(values[1:] != values[:-1]) + 1
    starts = np.r_[0, change]
    stops = np.r_[change, values.size]
    return [(values[s], s, e) for s, e in zip(starts, stops)]


def draw_fcr_curve(ax: Axes, Omega: npt.ArrayLike, F_cr: npt.ArrayLike, mechanism: npt.ArrayLike | None = None, *,
                   color: ColorType | None = None, by_mechanism_color: bool = False, lw: float = 1.8,
                   label: str | None = None, zorder: float = 3) -> set[int]:
    """One F_cr(Omega) curve split into runs of equal mechanism, styled per MECHANISMS.

    Consecutive runs share their junction point so the curve stays continuous."""
    Omega = np.asarray(Omega, float)
    F_cr = np.asarray(F_cr, float)
    mech = np.full(F_cr.shape, 3) if mechanism is None else mechanism_array(mechanism)
    mech = np.where(np.isfinite(F_cr), mech, 0)
    drawn: set[int] = set()
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


def mechanism_legend_handles(mechanisms: Iterable[int], *, by_mechanism_color: bool = False) -> list[Line2D]:
    return [Line2D([], [], color=MECHANISMS[m]["color"] if by_mechanism_color else "k",
                   ls=MECHANISMS[m]["ls"], lw=1.8, label=MECHANISMS[m]["label"])
            for m in sorted(mechanisms)]


#: thin lines of the branches where they do not set F_cr
THIN: dict[str, Any] = dict(lw=1.0, alpha=0.7)


def _mechanism_of(d: xr.Dataset) -> xr.DataArray | None:
    """The ``mechanism`` variable of one curve, or None where a dataset has none (drawn as one run)."""
    return var(d, "mechanism") if "mechanism" in d.variables else None


def draw_fcr(ax: Axes, ds: xr.Dataset, *, color_by: str = "curve", show_branches: bool = False,
             colors: Sequence[ColorType] | None = None, lw: float = 1.8, legend: bool = True,
             legend_loc: LegendLocType = "best") -> tuple[set[int], set[int]]:
    """All curves of a critical_forcing dataset stacked over ``curve`` (or a single curve).

    ``color_by="curve"``: one colour per curve, line style = mechanism (Figs 1, 2, 4);
    ``color_by="mechanism"``: colours *and* styles by mechanism (Fig 3).
    ``show_branches``: also draw every branch F_MM_0/F_MM_pi/F_SM/F_SMM thin where it exists.
    F_cr is the *largest* branch at each Omega (theory.critical_forcing: every branch is a lower
    bound F must exceed for the level curve through the IC to pass one obstacle), so a thin
    branch lies below the thick curve."""
    if "curve" not in ds.dims:
        ds = ds.expand_dims("curve")
    labels, _ = curve_labels(ds)
    n = ds.sizes["curve"]
    if colors is None:
        cmap = plt.get_cmap("viridis")
        colors = ["k"] if n == 1 else [cmap(v) for v in np.linspace(0.0, 0.9, n)]
    Omega = np.asarray(var(ds, "Omega"), float)
    # the damped theory has neither mechanisms nor branches: one line style, no mechanism legend
    show_branches = show_branches and all(v in ds.variables for v in BRANCHES.values())
    has_mechanism = "mechanism" in ds.variables
    mechs_seen: set[int] = set()
    curve_handles: list[Line2D] = []
    for i in range(n):
        d = ds.isel(curve=i)
        col = colors[i % len(colors)]
        if show_branches:
            for m, v in BRANCHES.items():
                st = MECHANISMS[m]
                ax.plot(Omega, np.asarray(var(d, v), float), ls=st["ls"], zorder=2,
                        color=st["color"] if color_by == "mechanism" else col, **THIN)
        drawn = draw_fcr_curve(ax, Omega, var(d, "F_cr"), _mechanism_of(d), color=col,
                               by_mechanism_color=(color_by == "mechanism"), lw=lw)
        mechs_seen |= drawn if has_mechanism else set()
        curve_handles.append(Line2D([], [], color=col, lw=lw, label=labels[i]))
    ax.set_xlabel(LABELS["Omega"])
    ax.set_ylabel(LABELS["F_cr"])
    ax.set_xlim(Omega.min(), Omega.max())
    ax.set_ylim(bottom=0)
    branches = ({m for m, v in BRANCHES.items() if np.isfinite(np.asarray(ds[v], float)).any()}
                if show_branches else set())
    if legend:
        by_color = color_by == "mechanism"
        if show_branches:
            # one entry per branch that exists: thick where it sets F_cr, thin where it lies below F_cr
            handles: list[Artist | tuple[Artist, ...]] = []
            labels = []
            for m in sorted(mechs_seen | branches):
                st = MECHANISMS[m]
                c = st["color"] if by_color else "k"
                thin = Line2D([], [], ls=st["ls"], color=c, **THIN)
                thick = Line2D([], [], ls=st["ls"], lw=lw, color=c)
                if m in mechs_seen:
                    handles.append((thick, thin) if m in branches else thick)
                    labels.append(st["label"])
                else:
                    handles.append(thin)
                    labels.append(st["label"] + r": below $F_{cr}$ everywhere")
            if color_by == "curve" and n > 1:
                handles = [*curve_handles, *handles]
                labels = [str(h.get_label()) for h in curve_handles] + labels
            ax.legend(handles, labels, handler_map={tuple: HandlerTuple(ndivide=None, pad=0.3)}, loc=legend_loc,
                      title="thick: sets $F_{cr}$ (the largest branch)\nthin: branch below $F_{cr}$",
                      title_fontsize=8)
        else:
            mech_handles = mechanism_legend_handles(mechs_seen, by_mechanism_color=by_color)
            if color_by == "curve" and n > 1:
                mech_handles = curve_handles + [Line2D([], [], ls="none", label="")] + mech_handles
            ax.legend(handles=mech_handles, loc=legend_loc)
    return mechs_seen, branches


def omega_margins(ax: Axes, Omega: npt.ArrayLike, frac: float = 0.025) -> None:
    """x limits of an F_cr axes with a margin, so that the markers at the ends are not clipped."""
    lo, hi = float(np.nanmin(Omega)), float(np.nanmax(Omega))
    pad = frac * (hi - lo) if hi > lo else 0.05
    ax.set_xlim(lo - pad, hi + pad)


def _fcr_ylim(ax: Axes, arrays: Iterable[npt.ArrayLike], top: float | None = None, pad: float = 1.08) -> None:
    if top is not None:
        ax.set_ylim(0, top)
        return
    vals = np.concatenate([np.asarray(a, float).ravel() for a in arrays])
    vals = vals[np.isfinite(vals)]
    if vals.size:
        ax.set_ylim(0, pad * vals.max())


def figure_fcr(analytic: DataSource, *, color_by: str = "curve", show_branches: bool = False,
               F_max: float | None = None, title: str | None = None,
               figsize: tuple[float, float] = (6.4, 4.6)) -> Figure:
    """Figs 1-4: theoretical F_cr(Omega) curves, mechanisms distinguished by line style."""
    ds = open_dataset(analytic)
    if "curve" not in ds.dims:
        ds = ds.expand_dims("curve")
    fig, ax = plt.subplots(figsize=figsize, layout="constrained")
    seen, branches = draw_fcr(ax, ds, color_by=color_by, show_branches=show_branches)
    _fcr_ylim(ax, [ds["F_cr"]], F_max)
    _fcr_notes(fig, ds, seen, branches, color_by)
    key = mechanism_key(seen | branches)
    if key:
        add_footnote(fig, "Mechanisms: " + key)
    _, const = curve_labels(ds)
    const.pop("Psi", None)  # F_cr on the RM does not depend on the forcing phase
    fourier = param(ds, "fourier")
    head = ic_text(const)
    if fourier and fourier != "paper":
        head += f"  (G: {fourier} first harmonic)"
    ax.set_title(title or f"Theoretical escape threshold, {head}")
    return fig


def _mechanism_text(m: int, color_by: str | None) -> str:
    st = MECHANISMS[m]
    style = {"-": "solid", "--": "dashed", "-.": "dash-dot", ":": "dotted"}[st["ls"]]
    name = st["label"].replace("$\\gamma^*=0$", "γ* = 0").replace("$\\gamma^*=\\pi$", "γ* = π")
    return f"{name} {style}" + (f" {st['color'].removeprefix('tab:')}" if color_by == "mechanism" else "")


def _fcr_notes(fig: Figure, ds: xr.Dataset, seen: set[int], branches: set[int], color_by: str) -> None:
    """Caption notes of Figs 1-4: the line styles drawn and each curve's minimum (read from the data)."""
    labels, _ = curve_labels(ds)
    if seen:
        add_note(fig, "Line styles drawn (mechanism setting F_cr): " + ", ".join(_mechanism_text(m, color_by) for m in
                                                                                sorted(seen)) + ". "
                      + mechanism_key(seen))
    if branches:
        _branch_notes(fig, ds, seen, branches, color_by)
    Om = np.asarray(ds["Omega"], float)
    parts: list[str] = []
    for i in range(ds.sizes["curve"]):
        d = ds.isel(curve=i)
        F = np.asarray(var(d, "F_cr"), float)
        if not np.isfinite(F).any():
            parts.append(f"{labels[i]}: no F_cr")
            continue
        k = int(np.nanargmin(F))
        m_d = _mechanism_of(d)
        mech = sorted({int(m) for m in mechanism_array(m_d) if m}) if m_d is not None else []
        parts.append(f"{plain_text(labels[i])}: minimum F_cr = {F[k]:.4g} at Ω = {Om[k]:.3g}"
                     + (", mechanisms " + ", ".join(_mechanism_text(m, None).rsplit(" ", 1)[0] for m in mech)
                        if mech else ""))
    add_note(fig, "; ".join(parts) + ".")


def _name(m: int) -> str:
    return _mechanism_text(m, None).rsplit(" ", 1)[0]


def _branch_notes(fig: Figure, ds: xr.Dataset, seen: set[int], branches: set[int], color_by: str) -> None:
    """Which branch is operative (sets F_cr) and where the others lie below it, from the data."""
    add_note(fig, "F_cr is the largest branch at each Ω, not the smallest: each branch is a lower bound that F must "
                  "exceed for the level curve of C through the IC to pass one obstacle (the tangency with ξ = ξ_max at "
                  "γ* = 0 or π, or a saddle of C below ξ_max), so the IC escapes only above all of them "
                  "(safebasins.theory.critical_forcing). The operative branch is the largest; a lower one does not "
                  "cause escape, because at its F the level curve through the IC is still held by the operative "
                  "obstacle (it closes below that saddle, or crosses the ray γ = 0 or π of that tangency below ξ_max).")
    never = sorted(branches - seen)
    if never:
        add_note(fig, "Drawn thin only (a branch that exists but lies below F_cr wherever it exists): "
                      + ", ".join(_mechanism_text(m, color_by) + " for Ω = " + _extent(ds, BRANCHES[m]) for m in never)
                      + ".")
    Om = np.asarray(ds["Omega"], float)
    for i in range(ds.sizes["curve"]):
        d = ds.isel(curve=i)
        F = np.asarray(var(d, "F_cr"), float)
        mech = mechanism_array(var(d, "mechanism"))
        parts: list[str] = []
        for m in sorted(branches):
            b = np.asarray(var(d, BRANCHES[m]), float)
            below = np.isfinite(b) & np.isfinite(F) & (mech != m)
            for op, s_, e in _runs(np.where(below, mech, 0)):
                if op:
                    gap = np.nanmax((F - b)[s_:e])
                    xs = f" (saddle at ξ = {fmt_range(np.asarray(var(d, 'xi_saddle'), float)[s_:e], '{:.3g}')})" \
                        if op == 3 and "xi_saddle" in d.variables else ""
                    parts.append(f"{_name(m)} below F_cr for Ω = {Om[s_]:.3g}-{Om[e - 1]:.3g} (up to "
                                 f"{gap:.3g} below), where {_name(int(op))} sets F_cr{xs}")
        if parts:
            add_note(fig, "Branches below F_cr" + (f" ({plain_text(curve_labels(ds)[0][i])})" if ds.sizes["curve"] > 1
                                                   else "") + ": " + "; ".join(parts) + ".")


def _extent(ds: xr.Dataset, name: str) -> str:
    """Omega range where variable ``name`` is finite (any curve)."""
    v = np.asarray(ds[name], float).reshape(-1, ds.sizes["Omega"])
    Om = np.asarray(ds["Omega"], float)[np.isfinite(v).any(axis=0)]
    return f"{Om.min():.3g}-{Om.max():.3g}" if Om.size else "none"


BRACKET_COLOR = "k"
CURVE_COLORS = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:cyan"]
CURVE_MARKERS = ["o", "s", "^", "D", "v", "P", "X", "<"]


def draw_fcr_numeric(ax: Axes, num: xr.Dataset, *, color: ColorType = "k", marker: str = "o", label: str | None = None,
                     bracket: bool = True, ms: float = 5.0) -> int:
    """Numeric bisection F_cr (markers) and, where escape is non-monotone in F, the bracket
    F_escape_low .. F_escape_all: a black bar with caps and a black ring around the marker (the
    bracket is often only a few 1e-3 tall)."""
    Om = np.asarray(num["Omega"], float)
    F = np.asarray(num["F_cr"], float)
    ax.plot(Om, F, marker, ms=ms, mfc=color, mec="k", mew=0.5, color=color, ls="none", zorder=5,
            label=label)
    if not bracket:
        return 0
    lo = np.asarray(var(num, "F_escape_low"), float)
    hi = np.asarray(var(num, "F_escape_all"), float)
    sel = np.asarray(var(num, "non_monotone")).astype(bool) & np.isfinite(lo) & np.isfinite(hi)
    if sel.any():
        ax.vlines(Om[sel], lo[sel], hi[sel], color=BRACKET_COLOR, lw=1.8, zorder=6)
        ax.plot(Om[sel], lo[sel], "_", color=BRACKET_COLOR, ms=8, mew=1.6, zorder=6)
        ax.plot(Om[sel], hi[sel], "_", color=BRACKET_COLOR, ms=8, mew=1.6, zorder=6)
        ax.plot(Om[sel], F[sel], "o", ms=ms + 5, mfc="none", mec=BRACKET_COLOR, mew=1.0, zorder=6)
    return int(sel.sum())


def bracket_handle() -> tuple[Line2D, Line2D]:
    """Legend entry of the non-monotone bracket, drawn as in the axes."""
    return (Line2D([], [], color=BRACKET_COLOR, marker="_", ms=8, mew=1.6, lw=1.8),
            Line2D([], [], ls="none", marker="o", ms=10, mfc="none", mec=BRACKET_COLOR, mew=1.0))


def _match_numeric_curve(ana: xr.Dataset, num: xr.Dataset, i: int) -> xr.Dataset | None:
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


def figure_fcr_comparison(analytic: DataSource, numeric: DataSource, *, layout: str = "overlay",
                          F_max: float | None = None, title: str | None = None, bracket: bool = True,
                          figsize: tuple[float, float] | None = None) -> Figure:
    """Figs 10-12: theoretical F_cr(Omega) (lines) vs numeric bisection (markers).

    ``layout="panels"``: one panel per curve (Fig 10: one per truncation level);
    ``layout="overlay"``: all curves on one axes (Figs 11, 12), one qualitative colour and one
    marker per curve.  Non-monotone escape brackets are black bars with a ring (legend alike)."""
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
        fig, grid = plt.subplots(1, n, figsize=figsize, layout="constrained", squeeze=False)
        axes: list[Axes] = list(grid[0])
        colors, markers = ["tab:blue"] * n, ["o"] * n
    else:
        figsize = figsize or (6.8, 5.0)
        fig, ax = plt.subplots(figsize=figsize, layout="constrained")
        axes = [ax] * n
        colors = [CURVE_COLORS[i % len(CURVE_COLORS)] for i in range(n)]
        markers = [CURVE_MARKERS[i % len(CURVE_MARKERS)] for i in range(n)]
    n_bracket = 0
    ax_brackets: dict[int, int] = {}
    pairs: list[tuple[str, xr.Dataset, xr.Dataset | None]] = []
    for i in range(n):
        ax = axes[i]
        a = ana.isel(curve=i)
        col, mk = colors[i], markers[i]
        Om = np.asarray(a["Omega"], float)
        ax.plot(Om, np.asarray(a["F_cr"], float), "-", color=col, lw=1.8, zorder=3,
                label=(None if layout == "overlay" else "theory"))
        b = _match_numeric_curve(ana, num, i)
        if b is not None:
            nb = draw_fcr_numeric(ax, b, color=col, marker=mk, bracket=bracket,
                                  label=("numeric" if layout == "panels" else None))
            n_bracket += nb
            ax_brackets[id(ax)] = ax_brackets.get(id(ax), 0) + nb
        pairs.append((labels[i], a, b))
        arrays = [a["F_cr"]] + ([b["F_cr"]] if b is not None else [])
        if layout == "panels" or i == n - 1:
            ax.set_xlabel(LABELS["Omega"])
            ax.set_ylabel(LABELS["F_cr"])
            omega_margins(ax, Om)
        if layout == "panels":
            _fcr_ylim(ax, arrays, F_max)
            ax.set_title(labels[i])
    undamped = _draw_undamped(axes, ana, layout)
    if layout == "overlay":
        _fcr_ylim(axes[0], [ana["F_cr"], num["F_cr"]], F_max)
    bracket_label = r"non-monotone in $F$: $F_{escape,low}$ .. $F_{escape,all}$"
    for ax in dict.fromkeys(axes):
        hs: list[Artist | tuple[Artist, ...]]
        if layout == "overlay":
            hs = [(Line2D([], [], color=colors[i], lw=1.8),
                   Line2D([], [], ls="none", marker=markers[i], ms=5, mfc=colors[i], mec="k", mew=0.5))
                  for i in range(n)]
            ls_ = list(labels)
            ls_.append(f"line: theory; marker: numeric bisection ({fmt_value(cycles)} EC)" if cycles
                       else "line: theory; marker: numeric")
            hs.append(Line2D([], [], ls="none"))
        else:
            h, l_ = ax.get_legend_handles_labels()
            hs, ls_ = [x for x, lab in zip(h, l_) if lab], [lab for lab in l_ if lab]
        if undamped:
            hs.append(Line2D([], [], **UNDAMPED_STYLE))
            ls_.append(r"undamped theory ($\beta$ = 0)")
        if ax_brackets.get(id(ax)) and bracket:
            hs.append(bracket_handle())
            ls_.append(bracket_label)
        ax.legend(hs, ls_, handler_map={tuple: HandlerTuple(ndivide=None, pad=0.2)}, loc="best")
    head = ic_text(const)
    sub: list[str] = []
    if cycles:
        sub.append(f"{fmt_value(cycles)} EC")
    if tol:
        sub.append(f"tol {fmt_value(tol)}")
    fig.suptitle(title or ("Escape threshold: theory (lines) vs numerics (markers)" +
                           (f", {head}" if head else "") + (f"  [{', '.join(sub)}]" if sub else "")),
                 fontsize=10)
    comparison_notes(fig, pairs, cycles, tol)
    if undamped:
        _damping_notes(fig, ana, labels)
    return fig


def _damping_notes(fig: Figure, ana: xr.Dataset, labels: Sequence[str]) -> None:
    """The damped theory's minimum F_cr against the undamped one's, per curve, from the data."""
    parts: list[str] = []
    for i in range(ana.sizes["curve"]):
        a = ana.isel(curve=i)
        Om = np.asarray(a["Omega"], float)
        F, F0 = np.asarray(a["F_cr"], float), np.asarray(a["F_cr_undamped"], float)
        if not (np.isfinite(F).any() and np.isfinite(F0).any()):
            continue
        k, k0 = np.nanargmin(F), np.nanargmin(F0)
        parts.append(f"{plain_text(labels[i])}: {F[k]:.4g} at Ω = {Om[k]:.3g} (undamped {F0[k0]:.4g} at "
                     f"Ω = {Om[k0]:.3g}, x{F[k] / F0[k0]:.2f})")
    if parts:
        add_note(fig, "Damping raises the threshold most at the resonance: minimum theoretical F_cr " + "; ".join(parts)
                      + ".")
    if "undecided" in ana.variables:
        n_und = int(np.asarray(ana["undecided"]).astype(bool).sum())
        add_note(fig, f"Damped theory: {count(n_und, 'Ω point')} left undecided (a slow trajectory neither "
                      "escaped nor was certified settled within its time limit; F_cr is NaN there, never guessed)."
                 if n_und else "Damped theory: every slow trajectory was decided (escaped or certified settled).")


#: the undamped theory beside damped curves (theory.critical_forcing's F_cr_undamped)
UNDAMPED_STYLE: dict[str, Any] = dict(color="0.45", lw=1.0, ls="--")


def _draw_undamped(axes: Sequence[Axes], ana: xr.Dataset, layout: str) -> bool:
    """The undamped theory of damped curves, once per distinct curve without its damping (one line
    where every curve has the same xi_max and IC); False when the curves are undamped."""
    if "F_cr_undamped" not in ana.variables:
        return False
    seen: set[tuple[float, ...]] = set()
    for i in range(ana.sizes["curve"]):
        a = ana.isel(curve=i)
        key = (id(axes[i]), *(float(a[c]) for c in ("xi_max", "xi_ini", "gamma_ini") if c in a.coords))
        if key in seen:
            continue
        seen.add(key)
        axes[i].plot(np.asarray(a["Omega"], float), np.asarray(a["F_cr_undamped"], float), zorder=2,
                     **UNDAMPED_STYLE)
    return True
