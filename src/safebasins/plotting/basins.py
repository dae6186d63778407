"""Safe basins of the slow flow: the resonance-manifold portrait and the basin on the IC plane
(Figs 5-9), and the drawing pieces every basin figure shares (boundary curves, safe-mask fill,
the unforced well outline).

Reads ``basin_<experiment>.nc`` datasets (docs/contracts.md): boundary vertices ``gamma``,
``xi``, ``q0_vertex``, ``p0_vertex``, ``curve_index`` on dim ``vertex``, ``kind`` on dim
``curve``, the per-IC mask ``escapes(q0, p0)`` and, for Figs 5-9, ``C`` and ``escapes_rm`` on
``(gamma_rm, xi_rm)``.
"""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import ListedColormap
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from safebasins.plotting.data import open_dataset, param, var
from safebasins.plotting.style import LABELS, SB_EDGE, SB_FACE, TRUNC_COLOR, fmt_value, param_text, pi_ticks
from safebasins.wells.quartic import QUARTIC


def draw_well(ax, xi_max, *, n=400, **kw):
    """Dashed outline of the unforced well ``H0(q, p) = xi_max`` on a (q, p) axes."""
    qm = float(QUARTIC.q_max(xi_max))
    qq = np.linspace(-qm, qm, n)
    pp = np.sqrt(np.clip(2 * (xi_max - QUARTIC.V(qq)), 0, None))
    x = np.r_[qq, qq[::-1], qq[:1]]
    y = np.r_[pp, -pp[::-1], pp[:1]]
    style = dict(color="0.35", lw=0.9, ls=(0, (4, 2)), zorder=4)
    style.update(kw)
    (line,) = ax.plot(x, y, **style)
    return line


def boundary_polylines(ds, xname, yname):
    """Polylines (x, y, kind) of a safe_basin_boundaries dataset (one slice of a stack);
    ``xname``/``yname``: ``"gamma"``/``"xi"`` on the manifold, ``"q0_vertex"``/``"p0_vertex"``
    on the IC plane."""
    x = np.asarray(var(ds, xname), float)
    y = np.asarray(var(ds, yname), float)
    idx = np.asarray(var(ds, "curve_index"), float)
    idx = np.where(np.isfinite(idx), idx, -1).astype(int)
    kinds = [str(k) for k in np.asarray(var(ds, "kind"))]
    out = []
    for ci in np.unique(idx[idx >= 0]):
        sel = idx == ci
        # keep NaN separators that sit between vertices of this curve
        xs, ys = x[sel], y[sel]
        if not np.isfinite(xs).any():
            continue
        out.append((xs, ys, kinds[ci]))
    return out


def analytic_safe(ds):
    """Analytic safe mask ``~escapes`` over (q0, p0) of one basin slice."""
    return ~var(ds, "escapes").astype(bool)


def rm_center(ds):
    """Window centre for gamma: pi when the safe region sits at the seam gamma = +-pi and not
    at gamma = 0 (island around the MM tangency at gamma* = pi, Fig 5), else 0."""
    safe = ~np.asarray(var(ds, "escapes_rm").transpose("xi_rm", "gamma_rm")).astype(bool)
    g = np.asarray(var(ds, "gamma_rm"), float)
    mid = np.abs(g) < 0.15 * np.pi
    edge = np.abs(g) > 0.85 * np.pi
    return np.pi if safe[..., edge].any() and not safe[..., mid].any() else 0.0


def draw_rm_portrait(ax, ds, *, n_levels=24, show_saddle=True, center="auto"):
    """Left panel of Figs 5-9: level curves of C on (gamma, xi), truncation level dashed,
    safe basin grey with red boundary.  ``center``: gamma at the middle of the window
    (``"auto"``: see :func:`rm_center`)."""
    Z = np.asarray(var(ds, "C").transpose("xi_rm", "gamma_rm"), float)
    g = np.asarray(var(ds, "gamma_rm"), float)
    xi = np.asarray(var(ds, "xi_rm"), float)
    xi_max = param(ds, "xi_max")
    safe = ~np.asarray(var(ds, "escapes_rm").transpose("xi_rm", "gamma_rm")).astype(bool)
    if center == "auto":
        center = rm_center(ds)
    if g.max() - g.min() > 1.9 * np.pi:
        g, (Z, safe) = _recenter(g, [Z, safe], float(center))
    safe_fill(ax, g, xi, safe)
    finite = Z[np.isfinite(Z)]
    if finite.size:
        levels = np.linspace(np.percentile(finite, 0.5), np.percentile(finite, 99.5), n_levels)
        ax.contour(g, xi, Z, levels=levels, colors="k", linewidths=0.5, alpha=0.55, zorder=3,
                   linestyles="solid")
    lo = g.min()
    for xs, ys, _kind in boundary_polylines(ds, "gamma", "xi"):
        xs = (xs - lo) % (2 * np.pi) + lo
        xs, ys = break_wraps(xs, ys)
        ax.plot(xs, ys, color=SB_EDGE, lw=1.8, zorder=6)
    ax.axhline(float(xi_max), color=TRUNC_COLOR, ls="--", lw=2.2, zorder=7)
    sg, sx = param(ds, "saddle_gamma"), param(ds, "saddle_xi")
    if show_saddle and np.isfinite(sg) and np.isfinite(sx):
        sg = (float(sg) - lo) % (2 * np.pi) + lo
        ax.plot(sg, sx, "o", mfc="w", mec="k", ms=5, zorder=8)
    ax.set_xlim(g.min(), g.max())
    ax.set_ylim(max(0.0, xi.min()), xi.max())
    if g.max() - g.min() > 3:
        pi_ticks(ax, g.min(), g.max())
    ax.set_xlabel(LABELS["gamma"])
    ax.set_ylabel(LABELS["xi"])


def draw_ic_basin(ax, ds, *, well=True):
    """Right panel of Figs 5-9: analytic safe basin on (q0, p0), boundary red."""
    q, p, Z = xy_grid(var(ds, "escapes"))
    safe_fill(ax, q, p, ~Z.astype(bool))
    ax.set_xlim(q.min(), q.max())
    ax.set_ylim(p.min(), p.max())
    draw_boundaries(ax, ds)
    if well:
        draw_well(ax, float(param(ds, "xi_max")))
    ax.set_aspect("equal")
    ax.set_xlabel(LABELS["q0"])
    ax.set_ylabel(LABELS["p0"])


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


def draw_boundaries(ax, ds, *, safe=None, **kw):
    """Boundary polylines of a basin dataset on the IC plane.  With ``safe`` (the analytic safe
    mask on (q0, p0)), curves that do not border it are skipped (:func:`separates_mask`)."""
    style = dict(color=SB_EDGE, lw=1.8, zorder=6)
    style.update(kw)
    lines = []
    for xs, ys, _kind in boundary_polylines(ds, "q0_vertex", "p0_vertex"):
        if safe is not None and not separates_mask(xs, ys, safe):
            continue
        lines += ax.plot(xs, ys, **style)
    return lines


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


def break_wraps(x, y, period=2 * np.pi):
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


def xy_grid(da):
    """DataArray over (q0, p0) in any order -> (q0, p0, Z) with Z indexed [p0, q0] for pcolor."""
    da = da.transpose("p0", "q0")
    return np.asarray(da["q0"]), np.asarray(da["p0"]), np.asarray(da)


def safe_fill(ax, x, y, safe, *, color=SB_FACE, zorder=1, alpha=1.0):
    """Fill where ``safe`` (2-D, indexed [y, x]) is True with a flat colour."""
    z = np.ma.masked_where(~safe, np.ones(safe.shape))
    return ax.pcolormesh(x, y, z, cmap=ListedColormap([color]), vmin=0, vmax=1, shading="nearest",
                         zorder=zorder, alpha=alpha, rasterized=True, linewidth=0)


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
    return sorted({str(k) for k in np.asarray(ds["kind"]) if str(k)})


def figure_rm_basin(analytic, *, title=None, figsize=(11.5, 4.6)):
    """Figs 5-9: (left) RM portrait with SB, (right) SB on the IC plane."""
    ds = open_dataset(analytic)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=figsize, layout="constrained",
                                 gridspec_kw=dict(width_ratios=[1.25, 1]))
    draw_rm_portrait(a1, ds)
    draw_ic_basin(a2, ds)
    has_saddle = bool(np.isfinite(float(param(ds, "saddle_xi"))))
    below = dict(loc="upper center", bbox_to_anchor=(0.5, -0.13), fontsize=8, frameon=False)
    a1.legend(handles=_basin_legend_handles(param(ds, "xi_max"), saddle=has_saddle),
              ncol=2, **below)
    a2.legend(handles=[Patch(facecolor=SB_FACE, edgecolor=SB_EDGE, lw=1.5, label="safe basin (theory)"),
                       Line2D([], [], color="0.35", ls=(0, (4, 2)), lw=0.9,
                              label=r"well edge $H_0 = \xi_{max}$")],
              ncol=2, **below)
    a1.set_title(r"resonance manifold $(\gamma, \xi)$")
    a2.set_title(r"initial conditions $(q_0, p_0)$")
    params = {k: param(ds, k) for k in ("F", "Omega", "Psi", "xi_max")}
    kinds = basin_kinds(ds)
    kind_txt = f"  [{' + '.join(kinds)}]" if kinds else ""
    fig.suptitle(title or (param_text(params) + kind_txt), fontsize=11)
    return fig
