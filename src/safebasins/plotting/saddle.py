"""Figure of the hilltop saddle's stable and unstable manifolds over escape charts of a damped well.

Input: the Dataset of :func:`safebasins.analysis.saddle_chart.saddle_chart` (or a path to a netCDF
file holding it).  The caption sentences are computed from it (:func:`add_note`).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import ListedColormap
from matplotlib.lines import Line2D
from matplotlib.patches import Rectangle

from safebasins.plotting.captions import add_note
from safebasins.plotting.data import open_dataset, param, var
from safebasins.plotting.style import LABELS, param_text

if TYPE_CHECKING:
    import numpy.typing as npt
    import xarray as xr
    from matplotlib.figure import Figure

    from safebasins.plotting.data import DataSource

__all__ = ["figure_hilltop_saddle"]

#: (kind, side) -> line style
BRANCH_STYLE: dict[tuple[str, str], dict[str, Any]] = {
    ("stable", "inner"): dict(color="tab:blue", lw=1.3), ("stable", "outer"): dict(color="tab:blue", lw=0.8, ls="--"),
    ("unstable", "inner"): dict(color="tab:red", lw=1.0), ("unstable", "outer"): dict(color="tab:red", lw=0.8, ls="--")}
CHART_COLOURS = ListedColormap(["white", "0.8"])          # escaped, safe


def _branches(ds: xr.Dataset, k: int) -> list[tuple[tuple[str, str], npt.NDArray[np.float64], npt.NDArray[np.float64]]]:
    """(kind, side), q, p of each manifold branch at the k-th F (NaN rows split a branch)."""
    q, p = var(ds, "q0_vertex").values[k], var(ds, "p0_vertex").values[k]
    idx = var(ds, "curve_index").values[k]
    kinds, sides = var(ds, "kind").values[k], var(ds, "side").values[k]
    return [((str(kinds[c]), str(sides[c])), q[idx == c], p[idx == c]) for c in range(kinds.size) if str(kinds[c])]


def figure_hilltop_saddle(saddle: DataSource, *, title: str | None = None) -> Figure:
    """One panel per F: the escape chart (grey: safe over the horizon, white: escaped), the stable
    (blue) and unstable (red) manifolds of the hilltop saddle, inner branches solid and outer
    dashed, and the saddle fixed point of the stroboscopic map (black dot)."""
    ds = open_dataset(saddle)
    F = var(ds, "F").values
    F_M = float(var(ds, "F_melnikov"))
    n = F.size
    fig, axes = plt.subplots(1, n, figsize=(max(4.6 * n, 7.0), 4.4), squeeze=False)
    q0, p0 = var(ds, "q0").values, var(ds, "p0").values
    for k, f in enumerate(F):
        ax = axes[0, k]
        safe = np.isinf(var(ds, "escape_cycle").values[k])
        ax.pcolormesh(q0, p0, safe.T.astype(float), cmap=CHART_COLOURS, vmin=0, vmax=1, shading="nearest",
                      rasterized=True)
        for key, q, p in _branches(ds, k):
            ax.plot(q, p, **BRANCH_STYLE[key])
        ax.plot(var(ds, "q_fixed").values[k], var(ds, "p_fixed").values[k], "ko", ms=3.5)
        ax.set_xlim(q0[0], q0[-1])
        ax.set_ylim(p0[0], p0[-1])
        ax.set_title(f"({chr(ord('a') + k)}) F = {f:g} = {f / F_M:.2f} $F_M$", fontsize=9)
        ax.set_xlabel(LABELS["q0"])
        ax.set_ylabel(LABELS["p0"])
    handles = [Line2D([], [], **BRANCH_STYLE[("stable", "inner")], label=r"$W^s$ (inner; dashed: outer)"),
               Line2D([], [], **BRANCH_STYLE[("unstable", "inner")], label=r"$W^u$ (inner; dashed: outer)"),
               Line2D([], [], color="k", marker="o", ls="", ms=3.5, label="saddle fixed point"),
               Rectangle((0, 0), 1, 1, color="0.8", label=f"safe over {int(param(ds, 'cycles'))} cycles")]
    axes[0, -1].legend(handles=handles, fontsize=7, loc="lower left", framealpha=0.9)
    par = {k: param(ds, k) for k in ("Omega", "Psi", "damping")}
    fig.suptitle(title or "Hilltop saddle's manifolds over the escape chart: " + param_text(par), fontsize=10)
    fig.tight_layout()
    _notes(fig, ds, F_M)
    return fig


def _notes(fig: Figure, ds: xr.Dataset, F_M: float) -> None:
    """Caption sentences computed from the data."""
    F_T, F_S = float(var(ds, "F_tangency")), float(var(ds, "F_splitting"))
    nq, np_ = ds.sizes["q0"], ds.sizes["p0"]
    text = f"Melnikov threshold F_M = {F_M:.5f}"
    if np.isfinite(F_T):
        text += (f"; the manifolds grown on the stroboscopic map first touch at F = {F_T:.7f} (F / F_M - 1 = "
                 f"{F_T / F_M - 1:.2g})"
                 + (f", the root of the section energy gap is {F_S:.7f} ({F_S / F_M - 1:.2g})" if np.isfinite(F_S)
                    else ""))
    else:
        text += " (the numeric tangency was not computed)"
    add_note(fig, text + f"; escape charts of {nq} x {np_} initial conditions, energy criterion xi_max = "
                         f"{param(ds, 'xi_max'):.4g}, {int(param(ds, 'cycles'))} cycles.")
    for k, f in enumerate(var(ds, "F").values):
        where = "" if not np.isfinite(F_T) else (", below the tangency" if f < F_T else ", past the tangency")
        mu_u = float(var(ds, "multiplier_unstable").values[k].max())
        q_s, p_s = float(var(ds, "q_fixed").values[k, 0]), float(var(ds, "p_fixed").values[k, 0])
        safe = 100 * float(var(ds, "safe_fraction").values[k])
        add_note(fig, f"F = {f:g} ({f / F_M:.2f} F_M{where}): saddle fixed point ({q_s:.4f}, {p_s:.4f}), unstable "
                      f"multiplier {mu_u:.4g}; {safe:.1f}% of the chart safe.")
