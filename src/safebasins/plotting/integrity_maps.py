"""Integrity maps over the control plane (Omega, F): slow flow, numerics, their difference and
the erosion fronts (datasets of the ``integrity_map`` kind, docs/contracts.md)."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D

from safebasins.plotting.data import open_dataset, param, var
from safebasins.plotting.style import LABELS, fmt_value, param_text

MEASURES = ("GIM", "LIM")


def _front(ax, ds, name, **kw):
    Om = np.asarray(var(ds, "Omega"), float)
    F = np.asarray(var(ds, name), float)
    return ax.plot(Om, F, **kw)


def figure_integrity_map(analytic, numeric, *, t_eval=None, title=None):
    """Rows: analytic, numeric (at ``t_eval``, default the last), numeric - analytic; columns: GIM,
    LIM.  The erosion fronts (F at which the measure falls to the stored level) are drawn on every
    panel: slow flow solid white/black, numerics dashed, all-phase slow flow dotted."""
    an = open_dataset(analytic)
    nu = open_dataset(numeric)
    t = float(var(nu, "t_eval")[-1] if t_eval is None else t_eval)
    nu_t = nu.sel(t_eval=t)
    Om = np.asarray(var(an, "Omega"), float)
    F = np.asarray(var(an, "F"), float)
    fig, axes = plt.subplots(3, len(MEASURES), figsize=(5.2 * len(MEASURES), 11.0), layout="constrained",
                             sharex=True, sharey=True)
    level = param(nu, "level")
    for j, m in enumerate(MEASURES):
        rows = [(var(an, m), f"{m}, slow flow", "viridis", (0, 1)),
                (var(nu_t, m), f"{m}, numeric ($t_{{eval}}$ = {fmt_value(t)} EC)", "viridis", (0, 1)),
                (var(nu_t, f"{m}_diff"), f"{m}: numeric $-$ slow flow", "RdBu", (-1, 1))]
        for i, (da, label, cmap, (lo, hi)) in enumerate(rows):
            ax = axes[i, j]
            mesh = ax.pcolormesh(Om, F, np.asarray(da.transpose("F", "Omega"), float), cmap=cmap, vmin=lo, vmax=hi,
                                 shading="nearest", rasterized=True)
            fig.colorbar(mesh, ax=ax, shrink=0.85)
            edge = "k" if i == 2 else "w"
            _front(ax, an, f"F_{m}", color=edge, lw=1.6)
            _front(ax, nu_t, f"F_{m}", color=edge, lw=1.6, ls="--")
            _front(ax, an, f"F_{m}_true" if m == "LIM" else "F_GIM_true", color=edge, lw=1.2, ls=":")
            ax.set_title(label, fontsize=9.5)
            ax.set_xlim(Om.min(), Om.max())
            ax.set_ylim(F.min(), F.max())
        axes[-1, j].set_xlabel(LABELS["Omega"])
    for i in range(3):
        axes[i, 0].set_ylabel(LABELS["F"])
    fig.legend(handles=[Line2D([], [], color="0.3", lw=1.6, label=f"slow flow: measure = {level:g}"),
                        Line2D([], [], color="0.3", lw=1.6, ls="--", label=f"numeric: measure = {level:g}"),
                        Line2D([], [], color="0.3", lw=1.2, ls=":", label="slow flow, safe for every phase")],
               loc="outside lower center", ncol=3, fontsize=8.5, frameon=False)
    shown = {"xi_max": param(an, "xi_max"), "Psi": param(an, "Psi")}
    fig.suptitle(title or ("Integrity over the control plane: " + param_text(shown) +
                           f"\n{nu.sizes['Omega']} x {nu.sizes['F']} control points, {param(nu, 'cycles')} EC; "
                           "lines: erosion fronts"), fontsize=10.5)
    return fig
