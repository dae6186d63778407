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

from safebasins.plotting import data
from safebasins.plotting.data import open_dataset, param, var
from safebasins.plotting.style import LABELS, SB_EDGE, SB_FACE, TRUNC_COLOR, fmt_value, param_text, pi_ticks

UNCONFIRMED_COLOR = "tab:orange"  # parts of the analytic basin where no IC stays in the numerics


def draw_well(ax, xi_max, well, *, n=400, **kw):
    """Dashed outline of the unforced well ``H0(q, p) = xi_max`` on a (q, p) axes, between the
    turning points of the level (``-+q_max`` of eq (4) for the quartic)."""
    lo, hi = (float(np.ravel(t)[0]) for t in well.turning_points(xi_max))
    qq = np.linspace(lo, hi, n)
    pp = np.sqrt(np.clip(2 * (xi_max - well.V(qq)), 0, None))
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


def join_seams(xs, ys, tol=1e-9):
    """Drop NaN separators between coincident vertices (a curve split at the gamma = +-pi cut of
    the cylinder maps to one continuous curve on the IC plane), so that no cap is drawn there."""
    xs, ys = np.asarray(xs, float), np.asarray(ys, float)
    gap = np.flatnonzero(~np.isfinite(xs) | ~np.isfinite(ys))
    drop = [i for i in gap if 0 < i < xs.size - 1 and np.isfinite(xs[i - 1]) and np.isfinite(xs[i + 1])
            and np.hypot(xs[i + 1] - xs[i - 1], ys[i + 1] - ys[i - 1]) < tol]
    return np.delete(xs, drop), np.delete(ys, drop)


#: boundary lines on the IC plane: round caps and joins, so closed curves have no visible seam
IC_LINE = dict(solid_capstyle="round", solid_joinstyle="round")


def plot_curve(ax, xs, ys, **style):
    """A boundary polyline on the IC plane: seams at the gamma cut removed (:func:`join_seams`);
    a curve that closes on itself is drawn as one closed path (no start / end cap)."""
    from matplotlib.patches import Polygon

    xs, ys = join_seams(xs, ys)
    ok = np.isfinite(xs) & np.isfinite(ys)
    if ok.all() and xs.size > 3 and np.hypot(xs[-1] - xs[0], ys[-1] - ys[0]) < 1e-9:
        kw = {k: v for k, v in style.items() if k not in ("solid_capstyle", "solid_joinstyle", "dash_capstyle")}
        kw["edgecolor"] = kw.pop("color", SB_EDGE)
        kw["linewidth"] = kw.pop("lw", 1.8)
        kw["linestyle"] = kw.pop("ls", "-")
        patch = Polygon(np.c_[xs[:-1], ys[:-1]], closed=True, fill=False, joinstyle="round", **kw)
        ax.add_patch(patch)
        return [patch]
    return ax.plot(xs, ys, **style)


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


def draw_rm_portrait(ax, ds, *, n_levels=24, show_saddle=True, center=0.0, unconfirmed=()):
    """Left panel of Figs 5-9: level curves of C on (gamma, xi), truncation level dashed,
    safe basin grey with red boundary.  ``center``: gamma at the middle of the window (0: the
    window is -pi..pi, as in every figure; ``"auto"``: see :func:`rm_center`).  Boundary curves
    whose index is in ``unconfirmed`` (parts of the basin the numerics do not keep) are drawn
    dotted in UNCONFIRMED_COLOR."""
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
    for k, (xs, ys, _kind) in enumerate(boundary_polylines(ds, "gamma", "xi")):
        xs = (xs - lo) % (2 * np.pi) + lo
        xs, ys = break_wraps(xs, ys)
        if k in unconfirmed:
            ax.plot(xs, ys, color=UNCONFIRMED_COLOR, lw=1.6, ls=":", zorder=6)
        else:
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


def draw_ic_basin(ax, ds, *, well=True, unconfirmed=(), unconfirmed_mask=None):
    """Right panel of Figs 5-9: analytic safe basin on (q0, p0), boundary red; curves in
    ``unconfirmed`` dotted and the pixels of ``unconfirmed_mask`` hatched (UNCONFIRMED_COLOR)."""
    q, p, Z = xy_grid(var(ds, "escapes"))
    safe_fill(ax, q, p, ~Z.astype(bool))
    if unconfirmed_mask is not None and unconfirmed_mask.any():
        _, _, U = xy_grid(unconfirmed_mask)
        ax.contourf(q, p, U.astype(float), levels=[0.5, 1.5], colors="none", hatches=["xxxx"], zorder=2)
        safe_fill(ax, q, p, U.astype(bool), color=UNCONFIRMED_COLOR, zorder=1.5, alpha=0.45)
    ax.set_xlim(q.min(), q.max())
    ax.set_ylim(p.min(), p.max())
    for k, (xs, ys, _kind) in enumerate(boundary_polylines(ds, "q0_vertex", "p0_vertex")):
        if k in unconfirmed:
            plot_curve(ax, xs, ys, color=UNCONFIRMED_COLOR, lw=1.6, ls=":", zorder=6)
        else:
            plot_curve(ax, xs, ys, color=SB_EDGE, lw=1.8, zorder=6, **IC_LINE)
    if well:
        draw_well(ax, float(param(ds, "xi_max")), data.well(ds))
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
    style = dict(color=SB_EDGE, lw=1.8, zorder=6, **IC_LINE)
    style.update(kw)
    lines = []
    for xs, ys, _kind in boundary_polylines(ds, "q0_vertex", "p0_vertex"):
        if safe is not None and not separates_mask(xs, ys, safe):
            continue
        lines += plot_curve(ax, xs, ys, **style)
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


def basin_kinds(ds, skip=()):
    """Kinds of the boundary curves (those whose index is in ``skip`` left out)."""
    return sorted({str(k) for i, k in enumerate(np.asarray(ds["kind"])) if str(k) and i not in skip})


#: the paper's names of the basin types (Sec. 2.3)
PAPER_TYPES = {"island": "maximum type (SBMT), island", "peninsula": "maximum type (SBMT), peninsula",
               "saddle": "saddle type (SBST)"}


def unconfirmed_parts(ds):
    """Parts of the analytic basin that the stored numeric check does not keep at all.

    Returns ``(curve indices, mask over (q0, p0) or None, regions)``: the boundary curves that
    border such a part, its pixels, and the table [(size, kept fraction), ...] of every part;
    empty when the dataset has no numeric check (``region``)."""
    if "region" not in ds.variables:
        return set(), None, []
    region = var(ds, "region")
    size = np.asarray(var(ds, "region_size"), int)
    frac = np.asarray(var(ds, "region_numeric_safe"), float)
    dead = [i + 1 for i in range(size.size) if frac[i] == 0.0]
    mask = region.isin(dead)
    curves = set()
    if dead:
        main = region.isin([i + 1 for i in range(size.size) if frac[i] > 0])
        for k, (xs, ys, _kind) in enumerate(boundary_polylines(ds, "q0_vertex", "p0_vertex")):
            if separates_mask(xs, ys, mask) and not separates_mask(xs, ys, main):
                curves.add(k)
    return curves, mask, list(zip(size.tolist(), frac.tolist()))


def figure_rm_basin(analytic, *, title=None, figsize=(11.5, 4.6)):
    """Figs 5-9: (left) RM portrait with SB, (right) SB on the IC plane.  With a numeric check
    in the dataset, the parts of the basin where no IC stays are hatched / dotted."""
    ds = open_dataset(analytic)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=figsize, layout="constrained",
                                 gridspec_kw=dict(width_ratios=[1.25, 1]))
    bad, bad_mask, regions = unconfirmed_parts(ds)
    draw_rm_portrait(a1, ds, unconfirmed=bad)
    draw_ic_basin(a2, ds, unconfirmed=bad, unconfirmed_mask=bad_mask)
    has_saddle = bool(np.isfinite(float(param(ds, "saddle_xi"))))
    below = dict(loc="upper center", bbox_to_anchor=(0.5, -0.13), fontsize=8, frameon=False)
    h1 = _basin_legend_handles(param(ds, "xi_max"), saddle=has_saddle)
    h2 = [Patch(facecolor=SB_FACE, edgecolor=SB_EDGE, lw=1.5, label="safe basin (theory)"),
          Line2D([], [], color="0.35", ls=(0, (4, 2)), lw=0.9, label=r"well edge $H_0 = \xi_{max}$")]
    if bad:
        cyc = fmt_value(param(ds, "check_cycles"))
        h1.append(Line2D([], [], color=UNCONFIRMED_COLOR, ls=":", lw=1.6,
                         label=f"slow-flow islands: no IC stays {cyc} EC (numerics)"))
        h2.append(Patch(facecolor=UNCONFIRMED_COLOR, alpha=0.45, hatch="xxxx", edgecolor=UNCONFIRMED_COLOR,
                        label=f"no IC stays {cyc} EC (numerics)"))
    a1.legend(handles=h1, ncol=2, **below)
    a2.legend(handles=h2, ncol=2, **below)
    a1.set_title(r"resonance manifold $(\gamma, \xi)$")
    a2.set_title(r"initial conditions $(q_0, p_0)$")
    params = {k: param(ds, k) for k in ("F", "Omega", "Psi", "xi_max")}
    kinds = basin_kinds(ds, skip=bad)
    kind_txt = f"  [{' + '.join(PAPER_TYPES.get(k, k) for k in kinds)}]" if kinds else ""
    fig.suptitle(title or (param_text(params) + kind_txt), fontsize=11)
    _rm_notes(fig, ds, kinds, bad, regions)
    return fig


def _rm_notes(fig, ds, kinds, bad, regions):
    """Caption notes of Figs 5-9, read from the basin dataset."""
    from safebasins.plotting.captions import add_note, count

    all_kinds = [str(k) for k in np.asarray(ds["kind"])]
    sg, sx = float(param(ds, "saddle_gamma")), float(param(ds, "saddle_xi"))
    add_note(fig, "Boundary curves: " + ", ".join(f"{k} (level C = {c:.4g})" for k, c in
                                                 zip(all_kinds, np.asarray(var(ds, "C_level"), float)))
             + (f"; saddle of C at (γ, ξ) = ({sg:.3g}, {sx:.4g})." if np.isfinite(sx) else "; no saddle below ξ_max."))
    add_note(fig, "Paper's classification of what bounds the basin: "
             + (", ".join(PAPER_TYPES.get(k, k) for k in kinds) if kinds else "none") + ".")
    if regions:
        cyc = fmt_value(param(ds, "check_cycles"))
        live = [(n, f) for n, f in regions if f > 0]
        dead = [n for n, f in regions if f == 0]
        txt = "; ".join(f"{'the basin' if len(live) == 1 else f'part {i + 1}'}: {n:,} ICs, {100 * f:.1f}% stay"
                        for i, (n, f) in enumerate(live))
        if dead:
            txt += (("; " if txt else "") + f"{count(len(dead), 'further part')} ({count(sum(dead), 'IC')}): "
                    "none stays")
        add_note(fig, f"Numeric check (every analytic-safe IC of the grid integrated {cyc} EC, energy criterion): "
                      f"{txt}.")
    g = np.asarray(var(ds, "gamma_rm"), float)
    safe_rm = ~np.asarray(var(ds, "escapes_rm").transpose("gamma_rm", "xi_rm")).astype(bool)
    if safe_rm[0].any() and safe_rm[-1].any() and not safe_rm[np.abs(g) < np.pi / 2].any():
        add_note(fig, "The safe region lies across the cut γ = ±π of the cylinder: it is drawn at both edges of the "
                      "γ window (the same window, -π..π, in every figure).")
    if bad:
        x = [np.asarray(var(ds, "xi"), float)[np.asarray(var(ds, "curve_index"), float) == k] for k in sorted(bad)]
        lo = min(np.nanmin(v) for v in x)
        add_note(fig, f"The {count(len(bad), 'thin island')} at ξ ≥ {lo:.4f}, just below ξ_max = "
                      f"{fmt_value(param(ds, 'xi_max'))}, are closed level curves of C around fixed points of the slow "
                      "flow (18) that the separatrix singularity creates (G(ξ) → 0 with G'(ξ) → -∞ as ξ → 1/4); no IC "
                      "in them stays in the numerics, so they are drawn dotted / hatched as an artefact of the "
                      "ξ → 1/4 singularity and left out of the basin's classification.")
