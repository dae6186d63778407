"""The stroboscopic (period) map of non-escaping trajectories with the predicted safe-basin
boundary (Fig 18, eq 29).

Reads ``strobe_<experiment>.nc`` (``q``, ``p`` over (sample, iteration), ``escaped``) and the
experiment's analytic basin (docs/contracts.md).
"""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D

from safebasins.plotting.basins import analytic_safe, draw_boundaries, draw_well
from safebasins.plotting.data import open_dataset, param, var
from safebasins.plotting.style import LABELS, param_text


def figure_period_map(analytic, numeric, *, title=None, figsize=(7.6, 6.4), s=0.8, max_points=None):
    strobe = open_dataset(numeric)
    basin = open_dataset(analytic)
    fig, ax = plt.subplots(figsize=figsize, layout="constrained")
    keep = ~np.asarray(var(strobe, "escaped")).astype(bool)
    q = np.asarray(var(strobe, "q").transpose("sample", "iteration"), float)[keep]
    p = np.asarray(var(strobe, "p").transpose("sample", "iteration"), float)[keep]
    n = q.shape[0]
    cmap = plt.get_cmap("tab20")
    for i in range(n):
        qi, pi_ = q[i], p[i]
        if max_points:
            qi, pi_ = qi[:max_points], pi_[:max_points]
        ax.scatter(qi, pi_, s=s, color=cmap(i % 20), marker=".", linewidths=0, rasterized=True)
    xi_max = param(strobe, "xi_max")
    blines = draw_boundaries(ax, basin, color="k", ls="--", lw=1.6, safe=analytic_safe(basin))
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
               label=f"{n} non-escaping trajectories ({strobe.sizes['iteration']} iterations)"),
        Line2D([], [], color="k", ls="--", lw=1.6, label="theory: SB boundary"),
        Line2D([], [], color="0.5", ls=":", lw=0.8, label=r"well edge $H_0 = \xi_{max}$")],
        loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=3, fontsize=8, frameon=False)
    shown = {k: param(strobe, k) for k in ("F", "Omega", "Psi", "xi_max")}
    ax.set_title(title or (r"Period map $(q,p)(t) \mapsto (q,p)(t+2\pi/\Omega)$" + "\n" +
                           param_text(shown) + f", seed {param(strobe, 'seed')}"))
    return fig
