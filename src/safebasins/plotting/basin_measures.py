"""Figure of the fractal boundary measures of a damped well's basins: the labelled basins at each F
and, over F, the fractal test's ball entropy and the uncertainty exponent of the two labellings,
with the Melnikov threshold.

Input: the Dataset of :func:`safebasins.analysis.boundary_measures.boundary_measures` (or a path
to a netCDF file holding it).  The caption sentences are computed from it (:func:`add_note`).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import ListedColormap

from safebasins.analysis.basin_measures import PUY_BIAS
from safebasins.analysis.boundary_measures import WADA_FLAGS
from safebasins.plotting.captions import add_note
from safebasins.plotting.data import open_dataset, param, var
from safebasins.plotting.style import LABELS, param_text

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

    from safebasins.plotting.data import DataSource

__all__ = ["figure_basin_measures"]

#: escaped white, then one colour per attractor
BASIN_COLOURS = ["white", "#4a7fb5", "#e08a3c", "#5aa469", "#b65fa0", "#8c8c8c"]
LABELLING_STYLE: dict[str, dict[str, Any]] = {"escape": dict(color="black", marker="o"),
                                               "attractors": dict(color="tab:red", marker="s")}
MELNIKOV_STYLE: dict[str, Any] = dict(color="0.3", ls="--", lw=1.0)


def _decision(ds: xr.Dataset, k: int) -> str:
    flag = int(var(ds, "wada").values[k])
    return {1: "Wada", 0: "not Wada", -1: "no Wada test"}[flag]


def figure_basin_measures(measures: DataSource, *, title: str | None = None) -> Figure:
    """Top: the basins at each F (white: escaped; colours: the attractors); bottom: (left) the
    fractal test's S_bb +- its standard error for the escape and the attractor labellings against
    the smooth-boundary band and log 2, (right) the uncertainty exponent alpha +- its error, alpha
    = 1 dotted; the Melnikov threshold dashed in both."""
    ds = open_dataset(measures)
    F = var(ds, "F").values
    F_M = float(var(ds, "F_melnikov"))
    n = F.size
    ncol = max(n, 2)
    fig = plt.figure(figsize=(3.4 * ncol, 6.8))
    grid = fig.add_gridspec(2, ncol * 2)
    basin = var(ds, "basin")
    q0, p0 = basin["q0"].values, basin["p0"].values
    n_col = int(basin.max()) + 1
    cmap = ListedColormap(BASIN_COLOURS[:max(n_col, 2)])
    for k, f in enumerate(F):
        ax = fig.add_subplot(grid[0, 2 * k:2 * k + 2])
        ax.pcolormesh(q0, p0, basin.isel(F=k).values.T, cmap=cmap, vmin=-0.5, vmax=max(n_col, 2) - 0.5,
                      shading="nearest", rasterized=True)
        side = "below" if f < F_M else "above"
        n_att = int(var(ds, "n_attractors").values[k])
        ax.set_title(f"({chr(ord('a') + k)}) F = {f:g} ({side} $F_M$): {n_att} attractor{'s' if n_att != 1 else ''}, "
                     f"{_decision(ds, k)}", fontsize=8.5)
        ax.set_xlabel(LABELS["q0"])
        ax.set_ylabel(LABELS["p0"])
    S_s = float(var(ds, "S_bb_smooth"))
    radius = float(param(ds, "radius"))
    bias = PUY_BIAS[0] * radius ** -PUY_BIAS[1]
    axS = fig.add_subplot(grid[1, :ncol])
    axA = fig.add_subplot(grid[1, ncol:])
    shift = 0.012 * max(float(np.ptp(np.r_[F, F_M])), 1e-3)   # side by side where the labellings agree
    for j, (lab, st) in enumerate(LABELLING_STYLE.items()):
        x = F + (j - 0.5) * shift
        axS.errorbar(x, var(ds, "ball_S_bb").sel(labelling=lab), yerr=var(ds, "ball_S_bb_err").sel(labelling=lab),
                     fmt=st["marker"], color=st["color"], ms=4, capsize=2, label=f"{lab} labels")
        axA.errorbar(x, var(ds, "alpha").sel(labelling=lab), yerr=var(ds, "alpha_err").sel(labelling=lab),
                     fmt=st["marker"], color=st["color"], ms=4, capsize=2, label=f"{lab} labels")
    axS.axhspan(S_s, S_s + bias, color="0.85", label="smooth boundary (with pixel bias)")
    axS.axhline(np.log(2.0), color="0.4", lw=0.8, ls=":", label="log 2")
    axA.axhline(1.0, color="0.4", lw=0.8, ls=":", label=r"$\alpha$ = 1: smooth")
    for ax in (axS, axA):
        ax.axvline(F_M, **MELNIKOV_STYLE, label=rf"Melnikov $F_M$ = {F_M:.4f}")
        pad = 0.1 * max(float(np.ptp(np.r_[F, F_M])), 1e-3)
        ax.set_xlim(min(F.min(), F_M) - pad, max(F.max(), F_M) + pad)
        ax.set_xlabel(LABELS["F"])
        ax.legend(fontsize=6.5, frameon=False, loc="center right" if ax is axS else "lower left")
    axS.set_ylabel(r"ball $S_{bb}$ (fractal test)")
    axS.set_title(f"({chr(ord('a') + n)}) boundary basin entropy, balls of radius {radius:g} steps", fontsize=9)
    axA.set_ylabel(r"uncertainty exponent $\alpha$ = 2 - dim")
    axA.set_ylim(0.0, 1.3)
    axA.set_title(f"({chr(ord('a') + n + 1)}) uncertainty exponent of the grid", fontsize=9)
    par = {k: param(ds, k) for k in ("Omega", "Psi", "damping", "xi_max")}
    fig.suptitle(title or "Fractal boundary measures of the basins: " + param_text(par), fontsize=10)
    fig.tight_layout()
    _notes(fig, ds, F_M)
    return fig


def _notes(fig: Figure, ds: xr.Dataset, F_M: float) -> None:
    """Caption sentences computed from the data."""
    F = var(ds, "F").values
    nq, np_ = ds.sizes["q0"], ds.sizes["p0"]
    add_note(fig, f"{nq} x {np_} initial conditions, {int(param(ds, 'n_iter'))} map iterations; Melnikov threshold "
                  f"F_M = {F_M:.5f}; significance {param(ds, 'significance'):g}.")
    for k, f in enumerate(F):
        parts = []
        for lab in ("escape", "attractors"):
            def v(name: str, lab: str = lab) -> float:
                return float(var(ds, name).sel(labelling=lab).values[k])
            verdict = "fractal" if bool(var(ds, "fractal").sel(labelling=lab).values[k]) else "smooth"
            parts.append(f"{lab} labels: S_bb {v('S_bb'):.3f} +- {v('S_bb_err'):.3f} (box {int(param(ds, 'box'))}), "
                         f"ball S_bb {v('ball_S_bb'):.3f} +- {v('ball_S_bb_err'):.3f}, p = {v('p_value'):.2g} "
                         f"({verdict}; {100 * v('multi_fraction'):.0f}% of the balls meet three basins), "
                         f"alpha {v('alpha'):.3f} +- {v('alpha_err'):.3f}")
        W = float(var(ds, "W").values[k])
        wada = WADA_FLAGS[int(var(ds, "wada").values[k])].replace("_", " ")
        wtext = f"Wada test W(3) = {W:.3f}: {wada}" if np.isfinite(W) else f"Wada test: {wada}"
        add_note(fig, f"F = {f:g} ({f / F_M:.2f} F_M), safe {100 * float(var(ds, 'safe_fraction').values[k]):.1f}%, "
                      f"{int(var(ds, 'n_attractors').values[k])} attractor(s): " + "; ".join(parts) + f"; {wtext}.")
