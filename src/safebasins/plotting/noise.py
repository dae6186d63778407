"""Figure of escape probabilities under noise over a grid of initial conditions.

Input: the Dataset of :func:`safebasins.numerics.escape_probability` on a grid (or a path to a
netCDF file holding it).  The caption sentences are computed from it (:func:`add_note`).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import matplotlib.pyplot as plt
import numpy as np

from safebasins.plotting.captions import add_note
from safebasins.plotting.data import open_dataset, param, var
from safebasins.plotting.style import LABELS, param_text

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

    from safebasins.plotting.data import DataSource

__all__ = ["figure_escape_probability", "figure_escape_probability_levels"]


def figure_escape_probability(probability: DataSource, *, title: str | None = None) -> Figure:
    """One panel per evaluation time: P_escape over the (q0, p0) grid (0 white: no path escaped,
    1 black: every path escaped), with one colour bar."""
    ds = open_dataset(probability)
    P = var(ds, "P_escape")
    if P.dims[:2] != ("q0", "p0"):
        raise ValueError(f"probability: P_escape must be on a (q0, p0) grid, got dims {P.dims}")
    t_eval = var(ds, "t_eval").values
    n = t_eval.size
    fig, axes = plt.subplots(1, n, figsize=(max(4.2 * n, 5.6), 4.2), squeeze=False, layout="compressed")
    q0, p0 = var(ds, "q0").values, var(ds, "p0").values
    meshes = []
    for k, t in enumerate(t_eval):
        ax = axes[0, k]
        meshes.append(ax.pcolormesh(q0, p0, P.values[:, :, k].T, cmap="Greys", vmin=0.0, vmax=1.0, shading="nearest",
                                    rasterized=True))
        ax.set_xlim(q0[0], q0[-1])
        ax.set_ylim(p0[0], p0[-1])
        ax.set_title(f"({chr(ord('a') + k)}) within {t:g} cycles", fontsize=9)
        ax.set_xlabel(LABELS["q0"])
        ax.set_ylabel(LABELS["p0"])
    fig.colorbar(meshes[0], ax=axes[0, :].tolist(), label="escape probability $P_{escape}$", shrink=0.9)
    names = ("F", "Omega", "Psi", "xi_max", "damping", "noise", "noise_time")
    par = {k: param(ds, k) for k in names if k in ds.attrs}
    fig.suptitle(title or "Escape probability under noise: " + param_text(par), fontsize=10)
    _notes(fig, ds)
    return fig


def _notes(fig: Figure, ds: xr.Dataset) -> None:
    """Caption sentences computed from the data."""
    P = var(ds, "P_escape")
    paths = int(param(ds, "paths"))
    half = 0.5 * float((var(ds, "P_escape_high") - var(ds, "P_escape_low")).max())
    add_note(fig, f"{paths} paths from each of {ds.sizes['q0']} x {ds.sizes['p0']} initial conditions "
                  f"(seed {int(param(ds, 'seed'))}); 95% Wilson intervals at most +- {half:.2g} wide.")
    for t in var(ds, "t_eval").values:
        p = P.sel(t_eval=t).values
        add_note(fig, f"within {t:g} cycles: mean P_escape {float(np.mean(p)):.3f}; "
                      f"{100 * float(np.mean(p == 0)):.1f}% of the initial conditions with no escaped path, "
                      f"{100 * float(np.mean(p == 1)):.1f}% with every path escaped.")


def figure_escape_probability_levels(probability: DataSource, *, title: str | None = None) -> Figure:
    """One row per noise level sigma, one column per evaluation time: P_escape over the (q0, p0) grid
    (the Dataset of the ``escape_probability`` kind: ensembles stacked over ``noise``)."""
    ds = open_dataset(probability)
    P = var(ds, "P_escape")
    if P.dims != ("noise", "q0", "p0", "t_eval"):
        raise ValueError(f"probability: P_escape must be on (noise, q0, p0, t_eval), got dims {P.dims}")
    sig, t_eval = var(ds, "noise").values, var(ds, "t_eval").values
    q0, p0 = var(ds, "q0").values, var(ds, "p0").values
    fig, axes = plt.subplots(sig.size, t_eval.size, figsize=(3.6 * t_eval.size + 1.2, 3.0 * sig.size + 0.6),
                             squeeze=False, layout="compressed", sharex=True, sharey=True)
    meshes = []
    for i, s in enumerate(sig):
        for k, t in enumerate(t_eval):
            ax = axes[i, k]
            meshes.append(ax.pcolormesh(q0, p0, P.values[i, :, :, k].T, cmap="Greys", vmin=0.0, vmax=1.0,
                                        shading="nearest", rasterized=True))
            ax.set_title(f"({chr(ord('a') + i * t_eval.size + k)}) σ = {s:g}, within {t:g} cycles", fontsize=9)
            if i == sig.size - 1:
                ax.set_xlabel(LABELS["q0"])
            if k == 0:
                ax.set_ylabel(LABELS["p0"])
    fig.colorbar(meshes[0], ax=axes.ravel().tolist(), label="escape probability $P_{escape}$", shrink=0.8)
    names = ("F", "Omega", "Psi", "xi_max", "damping", "noise_time")
    par = {k: param(ds, k) for k in names if k in ds.attrs}
    fig.suptitle(title or "Escape probability under noise: " + param_text(par), fontsize=10)
    paths = int(param(ds, "paths"))
    add_note(fig, f"{paths} paths from each of {ds.sizes['q0']} x {ds.sizes['p0']} initial conditions per noise level "
                  f"(seed {int(param(ds, 'seed'))}).")
    t = t_eval[-1]
    for i, s in enumerate(sig):
        p = P.values[i, :, :, -1]
        add_note(fig, f"σ = {s:g}, within {t:g} cycles: mean P_escape {float(np.mean(p)):.3f}; "
                      f"{100 * float(np.mean(p <= 0.05)):.1f}% of the ICs at P_escape <= 0.05, "
                      f"{100 * float(np.mean(p == 1)):.1f}% with every path escaped.")
    return fig
