"""The stroboscopic (period) map of non-escaping trajectories with the predicted safe-basin
boundary (Fig 18, eq 29).

Reads ``strobe_<experiment>.nc`` (``q``, ``p`` over (sample, iteration), the orbit
classification of :func:`safebasins.analysis.period_map.period_map_portrait`: ``orbit_class``,
``rotation_number``, ``birkhoff_digits``, ``period``, ``chain_index``; the chains' elliptic
periodic orbits ``chain_q``, ``chain_p``) and the experiment's analytic basin
(docs/contracts.md).  Orbits are coloured by class: main-island tori in blue shades by rotation
number, one colour per island chain (labelled ``1:k``, the k-periodic solution), chaotic orbits
(the stochastic layer) black.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D

from safebasins.plotting.curves import analytic_safe, draw_boundaries, draw_well
from safebasins.plotting.captions import add_note, count, fmt_range
from safebasins.plotting import data
from safebasins.plotting.data import open_dataset, param, var
from safebasins.plotting.style import LABELS, fmt_value, param_text

if TYPE_CHECKING:
    import numpy.typing as npt
    from matplotlib.artist import Artist
    from matplotlib.figure import Figure

    from safebasins.plotting.data import DataSource

CHAIN_COLORS = ["tab:red", "tab:orange", "tab:purple", "tab:green", "tab:brown", "tab:pink", "tab:olive"]
CHAOS_COLOR = "k"
MAIN_CMAP = "Blues"


def _fraction(rho: float, k: int) -> str:
    """Rotation number of a chain as text: winding m / period k."""
    m = int(round(rho * k))
    return "0" if m == 0 else f"{m}/{k}"


def chain_tag(rho: float, k: int) -> str:
    """Label of an island chain: ``m:k`` (the paper's 1:6) from its rotation number m/k about the
    centre; a chain that does not turn about the centre (m = 0) is named by its period."""
    m = int(round(rho * k)) if np.isfinite(rho) else 0
    return f"{m}:{k}" if m else f"period {k}, ρ=0"


def figure_period_map(analytic: DataSource, numeric: DataSource, *, title: str | None = None,
                      figsize: tuple[float, float] = (8.2, 7.4), s: float = 0.6,
                      max_points: int | None = None) -> Figure:
    strobe = open_dataset(numeric)
    basin = open_dataset(analytic)
    fig, ax = plt.subplots(figsize=figsize, layout="constrained")
    data.attach(fig, basin, strobe)
    q = np.asarray(var(strobe, "q").transpose("sample", "iteration"), float)
    p = np.asarray(var(strobe, "p").transpose("sample", "iteration"), float)
    cls = np.asarray(var(strobe, "orbit_class"), int)
    rho = np.asarray(var(strobe, "rotation_number"), float)
    digits = np.asarray(var(strobe, "birkhoff_digits"), float)
    chain = np.asarray(var(strobe, "chain_index"), int)
    origin = np.asarray(var(strobe, "origin")).astype(str)
    e_esc = np.asarray(var(strobe, "escape_cycle_energy"), float)
    d_esc = np.asarray(var(strobe, "escape_cycle_displacement"), float)
    k_chain = np.asarray(var(strobe, "chain_period"), int)
    n_chain_orbits = np.asarray(var(strobe, "chain_n_orbits"), int)
    cq = np.asarray(var(strobe, "chain_q"), float)
    cp = np.asarray(var(strobe, "chain_p"), float)
    center = (float(param(strobe, "center_q")), float(param(strobe, "center_p")))
    n_iter = int(param(strobe, "n_iter"))
    min_digits = float(param(strobe, "min_digits"))
    criterion = str(param(strobe, "criterion"))
    xi_max, q_max = float(param(strobe, "xi_max")), float(param(strobe, "q_max"))
    n = q.shape[0]
    sl = slice(None, max_points)

    main = cls == 1
    cmap = plt.get_cmap(MAIN_CMAP)
    r_main = rho[main]
    lo, hi = (np.nanmin(r_main), np.nanmax(r_main)) if main.any() else (0.0, 1.0)
    for i in np.flatnonzero(main):
        frac = 0.35 + 0.6 * ((rho[i] - lo) / (hi - lo) if hi > lo else 0.5)
        ax.scatter(q[i, sl], p[i, sl], s=s, color=cmap(frac), marker=".", linewidths=0, rasterized=True, zorder=2)
    unconfirmed = (cls == 2) & (chain < 0)
    for i in np.flatnonzero((cls == 3) | unconfirmed):
        ax.scatter(q[i, sl], p[i, sl], s=s, color=CHAOS_COLOR if cls[i] == 3 else "0.45", marker=".",
                   linewidths=0, rasterized=True, zorder=3)
    handles: list[Artist] = []
    if main.any():
        handles.append(Line2D([], [], marker="o", ls="none", color=cmap(0.75), ms=4,
                              label=f"main island: {count(main.sum(), 'torus', 'tori')}, "
                                    rf"$\rho$ = {fmt_range(r_main)}"))
    labels: list[tuple[int, str, str, npt.NDArray[np.float64]]] = []
    for c in range(k_chain.size):
        col = CHAIN_COLORS[c % len(CHAIN_COLORS)]
        members = np.flatnonzero(chain == c)
        for i in members:
            ax.scatter(q[i, sl], p[i, sl], s=s, color=col, marker=".", linewidths=0, rasterized=True, zorder=4)
        k = int(k_chain[c])
        pts = np.c_[cq[c, :k], cp[c, :k]]
        ax.plot(pts[:, 0], pts[:, 1], "+", color=col, ms=7, mew=1.4, zorder=7)
        rho_c = float(np.nanmedian(rho[members])) if members.size else np.nan
        tag = chain_tag(rho_c, k)
        labels.append((c, f"{tag} ({chr(65 + c)})", col, pts))
        turn = _fraction(rho_c, k)
        handles.append(Line2D([], [], marker="+", ls="none", color=col, ms=7, mew=1.4,
                              label=f"chain {chr(65 + c)}, {tag}: period-{k} elliptic orbit (+), "
                                    f"{count(n_chain_orbits[c], 'orbit')}, " + rf"$\rho$ = {turn}"
                                    + (" (does not encircle the centre)" if turn == "0" else "")))
    if (cls == 3).any():
        handles.append(Line2D([], [], marker="o", ls="none", color=CHAOS_COLOR, ms=3,
                              label=f"stochastic layer: {count((cls == 3).sum(), 'chaotic orbit')} "
                                    rf"($\rho$ converges to < {fmt_value(min_digits)} digits)"))
    if unconfirmed.any():
        handles.append(Line2D([], [], marker="o", ls="none", color="0.45", ms=3,
                              label=f"{count(unconfirmed.sum(), 'chain orbit')} without a Newton-confirmed centre"))
    ax.plot(*center, "x", color="k", ms=7, mew=1.5, zorder=8)
    handles.append(Line2D([], [], marker="x", ls="none", color="k", ms=7, mew=1.5,
                          label=r"centre: elliptic fixed point, $\rho_0$ = "
                                rf"{float(param(strobe, 'center_rotation')):.4f}"))
    line = origin == "line"
    if line.any():
        ax.plot(np.asarray(var(strobe, "q0"))[line], np.asarray(var(strobe, "p0"))[line], "o", mfc="none",
                mec="tab:green", ms=2.6, mew=0.7, zorder=9)
        handles.append(Line2D([], [], marker="o", ls="none", mfc="none", mec="tab:green", ms=4,
                              label=f"{count(line.sum(), 'IC')} on a line (the rest seeded random)"))
    blines = draw_boundaries(ax, basin, color="k", ls="--", lw=1.6, safe=analytic_safe(basin))
    draw_well(ax, xi_max, data.well(basin), color="0.5", lw=0.8, ls=":")
    handles += [Line2D([], [], color="k", ls="--", lw=1.6, label="theory: SB boundary"),
                Line2D([], [], color="0.5", ls=":", lw=0.8, label=r"well edge $H_0 = \xi_{max}$")]
    # frame the portrait and the predicted boundary (not the whole, mostly empty, well)
    bxy = [np.asarray(b.get_xy() if hasattr(b, "get_xy") else np.c_[b.get_xdata(), b.get_ydata()], float)
           for b in blines]
    xs = np.concatenate([q[np.isfinite(q)]] + [b[:, 0] for b in bxy])
    ys = np.concatenate([p[np.isfinite(p)]] + [b[:, 1] for b in bxy])
    xs, ys = xs[np.isfinite(xs)], ys[np.isfinite(ys)]
    if xs.size and ys.size:
        pad = 0.05 * max(np.ptp(xs), np.ptp(ys), 0.1)
        ax.set_xlim(xs.min() - pad, xs.max() + pad)
        ax.set_ylim(ys.min() - (1.4 + 0.9 * len(labels) if labels else 1.0) * pad, ys.max() + pad)
        # chain labels below the portrait (one row each), joined to the lowest-but-one island of the chain
        for c, tag, col, pts in labels:
            order = np.argsort(pts[:, 1] + 1e-3 * pts[:, 0])
            j = int(order[min(1 + c, len(order) - 1)])
            ax.annotate(tag, pts[j], xytext=(pts[j, 0], ys.min() - (1.2 + 0.9 * c) * pad), textcoords="data",
                        ha="center", va="center", fontsize=9, color=col, fontweight="bold", zorder=8,
                        arrowprops=dict(arrowstyle="-", color=col, lw=0.9, shrinkA=2, shrinkB=4))
    ax.set_aspect("equal")
    ax.set_xlabel(LABELS["q"] + r" at $t = nT$")
    ax.set_ylabel(LABELS["p"] + r" at $t = nT$")
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.08), ncol=2, fontsize=7.5, frameon=False)
    shown = {k: param(strobe, k) for k in ("F", "Omega", "Psi", "xi_max")}
    crit = (rf"escape: $|q| > q_{{max}}(\xi_{{max}})$ = {q_max:.3f}" if criterion == "displacement"
            else r"escape: $H_0 > \xi_{max}$")
    ax.set_title(title or (rf"Period map $(q,p)(t) \mapsto (q,p)(t+2\pi/\Omega)$: {n} non-escaping orbits, "
                           f"{n_iter} iterations\n" + param_text(shown) + f"; {crit}"))

    # what the data show (report caption)
    n_cand = int(param(strobe, "n_candidates"))
    add_note(fig, f"{n} non-escaping orbits of {n_iter:,} iterations ({criterion} criterion"
                  + (f", |q| > q_max(ξ_max) = {q_max:.3f}" if criterion == "displacement" else "")
                  + f"): the first {int(line.sum())} come from the line of {int(param(strobe, 'n_line'))} ICs, "
                  f"the rest from seeded random ICs (seed {param(strobe, 'seed')}); "
                  f"{int(param(strobe, 'n_non_escaping'))} of the {n_cand:,} candidates never escape.")
    add_note(fig, f"Centre: elliptic fixed point of the period map (Newton) at (q, p) = ({center[0]:.4f}, "
                  f"{center[1]:.4f}), linear rotation number {float(param(strobe, 'center_rotation')):.4f}.")
    if main.any():
        add_note(fig, f"Main island: {count(main.sum(), 'orbit')} on invariant tori around the centre, rotation "
                      f"numbers {fmt_range(r_main)} (rotation numbers converge to "
                      f"{fmt_range(digits[main], '{:.0f}')} digits).")
    if k_chain.size:
        per = ", ".join(f"chain {chr(65 + c)} (labelled "
                        f"{chain_tag(float(np.nanmedian(rho[chain == c])), int(k_chain[c]))}"
                        f"): period {int(k_chain[c])}, {count(n_chain_orbits[c], 'orbit')}, "
                        f"rotation {_fraction(float(np.nanmedian(rho[chain == c])), int(k_chain[c]))} about the "
                        "centre, "
                        f"monodromy trace {float(var(strobe, 'chain_trace')[c]):.3f}"
                        for c in range(k_chain.size))
        add_note(fig, f"{count(k_chain.size, 'island chain')} (each confirmed by an elliptic periodic orbit of the "
                      f"same minimal period found by Newton on the k-th iterate): {per}. Periods found: "
                      f"{sorted(set(int(k) for k in k_chain))}; the paper names the 1:6 chain.")
    else:
        add_note(fig, "No island chain among the drawn orbits.")
    if (cls == 3).any():
        add_note(fig, f"Stochastic layer: {count((cls == 3).sum(), 'orbit')} survive {n_iter:,} iterations but fill "
                      f"an area (rotation number converged to {fmt_range(digits[cls == 3], '{:.1f}')} digits, below "
                      f"{fmt_value(min_digits)}).")
    if criterion == "displacement":
        surv = np.isinf(e_esc)
        by = ", ".join(f"{int((surv & (cls == c_)).sum())} of {int((cls == c_).sum())} {name}"
                       for c_, name in ((1, "main-island"), (2, "chain"), (3, "chaotic")) if (cls == c_).any())
        lost = [name for c_, name in ((1, "the main island"), (2, "the island chains"), (3, "the stochastic layer"))
                if (cls == c_).any() and not (surv & (cls == c_)).any()]
        kept = [name for c_, name in ((1, "the main island"), (2, "the island chains"), (3, "the stochastic layer"))
                if (surv & (cls == c_)).any()]
        add_note(fig, f"Paper: ξ_max = {fmt_value(xi_max)}, escape criterion not stated for this figure; its "
                      f"portrait (island chains and a stochastic layer) is that of the displacement criterion "
                      f"|q| > q_max(ξ_max) (eq 4) drawn here. Under the energy criterion H0 > ξ_max only "
                      f"{int(surv.sum())} of these {n} orbits survive {n_iter:,} cycles ({by})"
                      + (f": {' and '.join(lost)} cross H0 = ξ_max" if lost else "")
                      + (f", an energy-criterion portrait would show {' and '.join(kept)} "
                         "only." if kept and lost else "."))
    else:
        surv = np.isinf(d_esc)
        add_note(fig, f"{int(surv.sum())} of these {n} orbits also survive the displacement criterion "
                      f"|q| > q_max = {q_max:.3f}.")
    return fig
