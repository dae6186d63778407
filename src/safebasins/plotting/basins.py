"""Safe basins of the slow flow: the resonance-manifold portrait and the basin on the IC plane
(Figs 5-9), and the analytic basin on the IC plane of any basin dataset (:func:`draw_ic_basin`).

Reads ``basin_<experiment>.nc`` datasets (docs/contracts.md): boundary vertices ``gamma``,
``xi``, ``q0_vertex``, ``p0_vertex``, ``curve_index`` on dim ``vertex``, ``kind`` on dim
``curve``, the per-IC mask ``escapes(q0, p0)`` and, for Figs 5-9, ``C`` and ``escapes_rm`` on
``(gamma_rm, xi_rm)`` and the numeric check ``escape_cycle_numeric``, ``region``,
``region_size``, ``region_numeric_safe`` (:mod:`safebasins.analysis.confirm`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from scipy import ndimage

from safebasins.plotting import data
from safebasins.plotting.captions import add_note, count
from safebasins.plotting.curves import (IC_LINE, boundary_polylines, break_wraps, draw_well, hatch, plot_curve,
                                        safe_fill, separates_mask, xy_grid)
from safebasins.plotting.data import open_dataset, param, var
from safebasins.plotting.style import LABELS, SB_EDGE, SB_FACE, TRUNC_COLOR, fmt_value, param_text, pi_ticks
from safebasins.analysis.safe import is_safe

if TYPE_CHECKING:
    from collections.abc import Collection, Iterable, Sequence

    import numpy.typing as npt
    import xarray as xr
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from safebasins.plotting.data import DataSource

UNCONFIRMED_COLOR = "tab:orange"  # analytic-safe ICs the numerics do not keep (hatched)
UNCONFIRMED_EDGE = "#a04000"      # boundary of a part not confirmed (dotted; darker: visible on the hatch)
#: one rule for Figs 5-9: a connected part of the analytic basin is confirmed when at least this
#: fraction of its ICs stays the check's horizon in the numerics (the stored region_numeric_safe)
CONFIRMED_FROM = 0.5
BEYOND_COLOR = "0.93"  # xi above the barrier energy: no orbit of the well


# ------------------------------------------------------------------ the numeric check (Figs 5-9)
@dataclass
class Check:
    """What the stored numeric check says about the analytic basin (:func:`numeric_check`)."""
    cycles: float
    regions: list[tuple[int, float]]               # [(size, kept fraction), ...], part 1 = largest
    refuted: list[int]                             # part numbers (1-based) below CONFIRMED_FROM
    escaping: xr.DataArray                         # bool (q0, p0): analytic safe, numerics escape
    curves: set[int] = field(default_factory=set)  # boundary curves that border refuted parts only


def numeric_check(ds: xr.Dataset) -> Check | None:
    """The numeric check of a basin dataset, or None where it has none (no ``region``).

    A part whose kept fraction is below :data:`CONFIRMED_FROM` is *refuted*; its boundary
    curves (those bordering it and no confirmed part) are returned in ``curves``.  ``escaping``
    marks every analytic-safe IC that escapes within ``check_cycles`` (``escape_cycle_numeric``;
    without it, the pixels of the refuted parts)."""
    if "region" not in ds.variables:
        return None

    cycles = float(param(ds, "check_cycles"))
    region = var(ds, "region")
    size = np.asarray(var(ds, "region_size"), int)
    frac = np.asarray(var(ds, "region_numeric_safe"), float)
    refuted = [i + 1 for i in range(size.size) if frac[i] < CONFIRMED_FROM]
    dead = region.isin(refuted)
    if "escape_cycle_numeric" in ds.variables:
        escaping = (region > 0) & ~is_safe(var(ds, "escape_cycle_numeric").fillna(-np.inf), cycles)
    else:
        escaping = dead
    out = Check(cycles, list(zip(size.tolist(), frac.tolist())), refuted, escaping)
    if refuted:
        live = region.isin([i + 1 for i in range(size.size) if frac[i] >= CONFIRMED_FROM])
        for k, (xs, ys, _kind) in enumerate(boundary_polylines(ds, "q0_vertex", "p0_vertex")):
            if separates_mask(xs, ys, dead) and not separates_mask(xs, ys, live):
                out.curves.add(k)
    return out


def unconfirmed_parts(ds: xr.Dataset) -> tuple[set[int], xr.DataArray | None, list[tuple[int, float]]]:
    """``(refuted boundary curves, mask of the refuted parts or None, [(size, kept fraction), ...])``."""
    chk = numeric_check(ds)
    if chk is None:
        return set(), None, []
    return chk.curves, var(ds, "region").isin(chk.refuted), chk.regions


# ------------------------------------------------------------------ the resonance manifold (left panel)
def cut_width(ds: xr.Dataset) -> float:
    """How far the gamma window must reach beyond +-pi so that no safe part crossing the cut
    gamma = +-pi of the cylinder is drawn in two halves (0 when none does).  A part touching
    both edges of the -pi..pi window (a band around the cylinder) needs nothing."""
    safe = ~np.asarray(var(ds, "escapes_rm").transpose("gamma_rm", "xi_rm")).astype(bool)
    g = np.asarray(var(ds, "gamma_rm"), float)
    lab, n = ndimage.label(safe, structure=np.ones((3, 3), bool))
    width = 0.0
    for k in range(1, n + 1):
        rows = np.flatnonzero((lab == k).any(axis=1))
        left, right = rows[0] == 0, rows[-1] == g.size - 1
        if left != right:  # one half of a part cut by the seam: the other half needs this much room
            width = max(width, (g[rows[-1]] - g[0]) if left else (g[-1] - g[rows[0]]))
    return min(width, np.pi / 2)


def _periodic_window(g: npt.NDArray[np.float64], arrays: Sequence[npt.NDArray[Any]],
                     w: float) -> tuple[npt.NDArray[np.float64], list[npt.NDArray[Any]]]:
    """Periodic gamma columns (axis 1 of ``arrays``, gamma from -pi) over [-pi - w, pi + w]."""
    n = g.size - 1 if np.isclose(g[-1] - g[0], 2 * np.pi) else g.size  # drop a duplicated end point
    gg, aa = g[:n], [a[:, :n] for a in arrays]
    lo, hi = gg > np.pi - w, gg <= -np.pi + w  # hi holds gamma = -pi: it closes the window at +pi
    return (np.r_[gg[lo] - 2 * np.pi, gg, gg[hi] + 2 * np.pi],
            [np.concatenate([a[:, lo], a, a[:, hi]], axis=1) for a in aa])


def draw_rm_portrait(ax: Axes, ds: xr.Dataset, *, n_levels: int = 24, show_saddle: bool = True,
                     unconfirmed: Collection[int] = ()) -> float:
    """Left panel of Figs 5-9: level curves of C on (gamma, xi), truncation level dashed, safe
    basin grey with red boundary.  The gamma window is -pi..pi, widened just enough that a part
    cut by gamma = +-pi is drawn whole (:func:`cut_width`; the cut marked by dotted verticals).
    The xi axis reaches a little above xi_max, so the truncation line never lies on the frame;
    xi above the barrier energy (no orbit of the well) is shaded.  Boundary curves whose index
    is in ``unconfirmed`` are drawn dotted in UNCONFIRMED_EDGE.  Returns the widening."""
    Z = np.asarray(var(ds, "C").transpose("xi_rm", "gamma_rm"), float)
    g = np.asarray(var(ds, "gamma_rm"), float)
    xi = np.asarray(var(ds, "xi_rm"), float)
    xi_max = float(param(ds, "xi_max"))
    safe = ~np.asarray(var(ds, "escapes_rm").transpose("xi_rm", "gamma_rm")).astype(bool)
    w = cut_width(ds) if g.max() - g.min() > 1.9 * np.pi else 0.0
    if w > 0:
        w += 0.04 * np.pi  # a margin beyond the part
        g, (Z, safe) = _periodic_window(g, [Z, safe], w)
    safe_fill(ax, g, xi, safe)
    finite = Z[np.isfinite(Z)]
    if finite.size:
        levels = np.linspace(np.percentile(finite, 0.5), np.percentile(finite, 99.5), n_levels)
        ax.contour(g, xi, Z, levels=levels, colors="k", linewidths=0.5, alpha=0.55, zorder=3, linestyles="solid")
    shifts = (-2 * np.pi, 0.0, 2 * np.pi) if w > 0 else (0.0,)
    for k, (xs, ys, _kind) in enumerate(boundary_polylines(ds, "gamma", "xi")):
        xs, ys = break_wraps((xs + np.pi) % (2 * np.pi) - np.pi, ys)
        st: dict[str, Any] = (dict(color=UNCONFIRMED_EDGE, lw=1.6, ls=":") if k in unconfirmed
                              else dict(color=SB_EDGE, lw=1.8))
        for s in shifts:
            ax.plot(xs + s, ys, zorder=6, **st)
    ax.axhline(xi_max, color=TRUNC_COLOR, ls="--", lw=2.2, zorder=7)
    sg, sx = param(ds, "saddle_gamma"), param(ds, "saddle_xi")
    if show_saddle and np.isfinite(sg) and np.isfinite(sx):
        sg = (float(sg) + np.pi) % (2 * np.pi) - np.pi
        for s in shifts:
            if g.min() <= sg + s <= g.max():
                ax.plot(sg + s, sx, "o", mfc="w", mec="k", ms=5, zorder=8)
    if w > 0:
        for x in (-np.pi, np.pi):
            ax.axvline(x, color="0.3", lw=0.8, ls=":", zorder=7)
    top = max(xi.max(), xi_max) + 0.04 * (max(xi.max(), xi_max) - max(0.0, xi.min()))
    E_b = float(data.well(ds).barrier_energy)
    if top > E_b:
        ax.axhspan(E_b, top, color=BEYOND_COLOR, zorder=5, lw=0)
    ax.set_xlim(g.min(), g.max())
    ax.set_ylim(max(0.0, xi.min()), top)
    if g.max() - g.min() > 3:
        pi_ticks(ax, g.min(), g.max())
    ax.set_xlabel(LABELS["gamma"])
    ax.set_ylabel(LABELS["xi"])
    return w


# ------------------------------------------------------------------ the IC plane (right panel; plot_basin)
def draw_ic_basin(ax: Axes, ds: xr.Dataset, *, well: bool = True, unconfirmed: Collection[int] = (),
                  escaping: xr.DataArray | None = None) -> None:
    """The analytic safe basin of one basin dataset on (q0, p0): grey where ``escapes`` is False
    (when the dataset has the mask), boundary curves red, the well edge dashed.  Curves in
    ``unconfirmed`` are dotted (UNCONFIRMED_EDGE) and the ICs of ``escaping`` (analytic safe,
    numerics escape) hatched (UNCONFIRMED_COLOR)."""
    if "escapes" in ds.variables:
        q, p, Z = xy_grid(var(ds, "escapes"))
        safe_fill(ax, q, p, ~Z.astype(bool))
        if escaping is not None and np.asarray(escaping).any():
            _, _, U = xy_grid(escaping)
            safe_fill(ax, q, p, U.astype(bool), color=UNCONFIRMED_COLOR, zorder=1.5, alpha=0.45)
            hatch(ax, q, p, U.astype(bool), color=UNCONFIRMED_COLOR)
        ax.set_xlim(q.min(), q.max())
        ax.set_ylim(p.min(), p.max())
    for k, (xs, ys, _kind) in enumerate(boundary_polylines(ds, "q0_vertex", "p0_vertex")):
        if k in unconfirmed:
            plot_curve(ax, xs, ys, color=UNCONFIRMED_EDGE, lw=1.6, ls=":", zorder=6)
        else:
            plot_curve(ax, xs, ys, color=SB_EDGE, lw=1.8, zorder=6, **IC_LINE)
    if well:
        draw_well(ax, float(param(ds, "xi_max")), data.well(ds))
    ax.set_aspect("equal")
    ax.set_xlabel(LABELS["q0"])
    ax.set_ylabel(LABELS["p0"])


def _basin_legend_handles(xi_max: float | None = None, *, saddle: bool = False) -> list[Artist]:
    h: list[Artist] = [Patch(facecolor=SB_FACE, edgecolor=SB_EDGE, lw=1.5, label="safe basin (theory)")]
    if xi_max is not None:
        h.append(Line2D([], [], color=TRUNC_COLOR, ls="--", lw=2.2,
                        label=rf"truncation $\xi = \xi_{{max}}$ = {fmt_value(xi_max)}"))
    h.append(Line2D([], [], color="k", lw=0.6, alpha=0.6, label=r"level curves of $C(\gamma,\xi)$"))
    if saddle:
        h.append(Line2D([], [], marker="o", mfc="w", mec="k", ls="none", label="saddle"))
    return h


def basin_kinds(ds: xr.Dataset, skip: Collection[int] = (), only: Collection[int] | None = None) -> list[str]:
    """Kinds of the boundary curves (those in ``skip`` left out; with ``only``, just those)."""
    return sorted({str(k) for i, k in enumerate(np.asarray(var(ds, "kind")))
                   if str(k) and i not in skip and (only is None or i in only)})


#: the paper's names of the basin types (Sec. 2.3)
PAPER_TYPES = {"island": "maximum type (SBMT), island", "peninsula": "maximum type (SBMT), peninsula",
               "saddle": "saddle type (SBST)"}


def _types(kinds: Iterable[str]) -> str:
    return " + ".join(PAPER_TYPES.get(k, k) for k in kinds)


def figure_rm_basin(analytic: DataSource, *, title: str | None = None,
                    figsize: tuple[float, float] = (11.5, 4.6)) -> Figure:
    """Figs 5-9: (left) RM portrait with SB, (right) SB on the IC plane.  With a numeric check
    in the dataset, the analytic-safe ICs that escape in the numerics are hatched and the parts
    that fewer than CONFIRMED_FROM of their ICs survive are drawn dotted (one rule for Figs 5-9)."""
    ds = open_dataset(analytic)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=figsize, layout="constrained",
                                 gridspec_kw=dict(width_ratios=[1.25, 1]))
    data.attach(fig, ds)
    chk = numeric_check(ds)
    bad = chk.curves if chk else set()
    widened = draw_rm_portrait(a1, ds, unconfirmed=bad)
    draw_ic_basin(a2, ds, unconfirmed=bad, escaping=chk.escaping if chk else None)
    has_saddle = bool(np.isfinite(float(param(ds, "saddle_xi"))))
    below = dict(loc="upper center", bbox_to_anchor=(0.5, -0.13), fontsize=8, frameon=False)
    h1 = _basin_legend_handles(param(ds, "xi_max"), saddle=has_saddle)
    E_b = float(data.well(ds).barrier_energy)
    if a1.get_ylim()[1] > E_b:
        h1.append(Patch(facecolor=BEYOND_COLOR, label=rf"$\xi$ > {fmt_value(E_b)}: above the barrier energy"))
    if widened:
        h1.append(Line2D([], [], color="0.3", ls=":", lw=0.8, label=r"$\gamma = \pm\pi$: one line of the cylinder"))
    h2: list[Artist] = [Patch(facecolor=SB_FACE, edgecolor=SB_EDGE, lw=1.5, label="safe basin (theory)"),
          Line2D([], [], color="0.35", ls=(0, (4, 2)), lw=0.9, label=r"well edge $H_0 = \xi_{max}$")]
    if chk is not None:
        cyc = fmt_value(chk.cycles)
        if np.asarray(chk.escaping).any():
            h2.append(Patch(facecolor=UNCONFIRMED_COLOR, alpha=0.45, hatch="xxxx", edgecolor=UNCONFIRMED_COLOR,
                            label=f"theory safe, numerics escape within {cyc} EC"))
        if bad:
            lab = f"part not confirmed: < {100 * CONFIRMED_FROM:.0f}% of its ICs stay {cyc} EC"
            h1.append(Line2D([], [], color=UNCONFIRMED_EDGE, ls=":", lw=1.6, label=lab))
            h2.append(Line2D([], [], color=UNCONFIRMED_EDGE, ls=":", lw=1.6, label=lab))
    a1.legend(handles=h1, ncol=2, **below)
    a2.legend(handles=h2, ncol=1 if len(h2) > 2 else 2, **below)
    a1.set_title(r"resonance manifold $(\gamma, \xi)$")
    a2.set_title(r"initial conditions $(q_0, p_0)$")
    params = {k: param(ds, k) for k in ("F", "Omega", "Psi", "xi_max")}
    kinds, refuted = basin_kinds(ds, skip=bad), basin_kinds(ds, only=bad)
    kind_txt = ("; ".join(([_types(kinds)] if kinds else []) + ([f"not confirmed: {_types(refuted)}"] if refuted
                                                                else [])))
    fig.suptitle(title or (param_text(params) + (f"  [{kind_txt}]" if kind_txt else "")), fontsize=11)
    _rm_notes(fig, ds, kinds, refuted, chk, widened)
    return fig


def _parts_text(chk: Check) -> list[str]:
    """Each part of the basin with its size and kept fraction; beyond three, the rest summed."""
    def one(i: int, n: int, f: float) -> str:
        verdict = "confirmed" if f >= CONFIRMED_FROM else "not confirmed"
        return f"part {i + 1}: {n:,} ICs, {100 * f:.1f}% stay ({verdict})"

    if len(chk.regions) == 1:
        n, f = chk.regions[0]
        return [f"The basin is one part of {n:,} ICs, {100 * f:.1f}% stay "
                f"({'confirmed' if f >= CONFIRMED_FROM else 'not confirmed'})"]
    shown = [one(i, n, f) for i, (n, f) in enumerate(chk.regions[:3])]
    shown[0] = shown[0][0].upper() + shown[0][1:]
    rest = chk.regions[3:]
    if rest:
        n = sum(r[0] for r in rest)
        kept = sum(r[0] * r[1] for r in rest) / max(n, 1)
        ok = sum(r[1] >= CONFIRMED_FROM for r in rest)
        shown.append(f"{count(len(rest), 'further part')} ({count(n, 'IC')}): {100 * kept:.1f}% stay "
                     f"({ok} confirmed, {len(rest) - ok} not)")
    return shown


def _rm_notes(fig: Figure, ds: xr.Dataset, kinds: Sequence[str], refuted: Sequence[str], chk: Check | None,
              widened: float) -> None:
    """Caption notes of Figs 5-9, read from the basin dataset."""
    all_kinds = [str(k) for k in np.asarray(var(ds, "kind"))]
    sg, sx = float(param(ds, "saddle_gamma")), float(param(ds, "saddle_xi"))
    add_note(fig, "Boundary curves: " + ", ".join(f"{k} (level C = {c:.4g})" for k, c in
                                                 zip(all_kinds, np.asarray(var(ds, "C_level"), float)))
             + (f"; saddle of C at (γ, ξ) = ({sg:.3g}, {sx:.4g})." if np.isfinite(sx) else "; no saddle below ξ_max."))
    add_note(fig, "Paper's classification of what bounds the basin: " + (_types(kinds) if kinds else "none")
             + (f"; not confirmed by the numerics: {_types(refuted)}" if refuted else "") + ".")
    if chk is not None:
        cyc = fmt_value(chk.cycles)
        safe = int(sum(r[0] for r in chk.regions))
        esc = int(np.asarray(chk.escaping).sum())
        add_note(fig, f"Numeric check: every analytic-safe IC of the grid integrated {cyc} EC (energy criterion); one "
                      f"rule for Figs 5-9: a connected part of the basin is confirmed when at least "
                      f"{100 * CONFIRMED_FROM:.0f}% of its ICs stay, otherwise its boundary is drawn dotted dark "
                      "orange and "
                      f"it is left out of the classification; the ICs that escape are hatched orange. "
                      + "; ".join(_parts_text(chk)) + f". In all {esc:,} of {safe:,} analytic-safe ICs "
                      f"({100 * esc / max(safe, 1):.1f}%) escape within {cyc} EC.")
        if chk.curves:
            _refuted_note(fig, ds, chk)
    if widened:
        add_note(fig, f"A safe part crosses the cut γ = ±π of the cylinder: the γ window is widened to "
                      f"±{(np.pi + widened) / np.pi:.2f}π (dotted verticals at γ = ±π) so that it is drawn whole; "
                      "the strips beyond ±π repeat the other end of the cylinder.")


def _refuted_note(fig: Figure, ds: xr.Dataset, chk: Check) -> None:
    """Where the refuted boundary curves lie on the manifold; near the separatrix, why."""
    idx = np.asarray(var(ds, "curve_index"), float)
    x = np.asarray(var(ds, "xi"), float)
    lo = min(np.nanmin(x[idx == k]) for k in chk.curves)
    E_b = float(data.well(ds).barrier_energy)
    n = len(chk.curves)
    txt = (("The boundary curve of the part not confirmed reaches" if n == 1 else
            f"The {n} boundary curves of the parts not confirmed reach")
           + f" down to ξ = {lo:.4f} on the manifold (ξ_max = {fmt_value(param(ds, 'xi_max'))}).")
    if lo >= 0.97 * E_b:
        txt += (" " + ("It is a closed level curve" if n == 1 else "They are closed level curves")
                + " of C around fixed points of the slow flow (18) that the separatrix singularity creates "
                "(G(ξ) → 0 with G'(ξ) → -∞ as ξ → the barrier energy): an artefact of the singularity.")
    add_note(fig, txt)
