"""Figure of escape probabilities under noise over a grid of initial conditions.

Input: the Dataset of :func:`safebasins.numerics.escape_probability` on a grid (or a path to a
netCDF file holding it), stacked over noise levels with the averaged theory's map and agreement by
the ``escape_probability`` kind.  The caption sentences are computed from it (:func:`add_note`).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Literal

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D

from safebasins.plotting.captions import add_note
from safebasins.plotting.data import open_dataset, param, var
from safebasins.plotting.style import LABELS, param_text

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.axes import Axes
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


#: the averaged theory's P_escape levels drawn over the ensembles' maps, with their line styles
THEORY_LEVELS: dict[float, Literal["--", "-"]] = {0.05: "--", 0.5: "-"}
THEORY_COLOUR = "tab:red"


def _theory_contours(ax: Axes, q0: np.ndarray, p0: np.ndarray, P: np.ndarray) -> None:
    """The theory's P_escape contours on one panel (a level outside the map's range is not drawn)."""
    levels = [v for v in THEORY_LEVELS if P.min() < v < P.max()]
    if levels:
        ax.contour(q0, p0, P.T, levels=levels, colors=THEORY_COLOUR, linewidths=1.1,
                   linestyles=[THEORY_LEVELS[v] for v in levels])


def figure_escape_probability_levels(probability: DataSource, *, title: str | None = None) -> Figure:
    """One row per noise level sigma, one column per evaluation time: P_escape over the (q0, p0) grid
    (the Dataset of the ``escape_probability`` kind: ensembles stacked over ``noise``); where the
    Dataset holds the averaged theory (``P_escape_theory``), its P_escape = 0.05 and 0.5 contours
    over each map and its agreement with the ensembles in the caption notes."""
    ds = open_dataset(probability)
    P = var(ds, "P_escape")
    if P.dims != ("noise", "q0", "p0", "t_eval"):
        raise ValueError(f"probability: P_escape must be on (noise, q0, p0, t_eval), got dims {P.dims}")
    theory = var(ds, "P_escape_theory").transpose(*P.dims).values if "P_escape_theory" in ds else None
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
            if theory is not None:
                _theory_contours(ax, q0, p0, theory[i, :, :, k])
            ax.set_title(f"({chr(ord('a') + i * t_eval.size + k)}) σ = {s:g}, within {t:g} cycles", fontsize=9)
            if i == sig.size - 1:
                ax.set_xlabel(LABELS["q0"])
            if k == 0:
                ax.set_ylabel(LABELS["p0"])
    fig.colorbar(meshes[0], ax=axes.ravel().tolist(), label="escape probability $P_{escape}$", shrink=0.8)
    if theory is not None:
        handles = [Line2D([], [], color=THEORY_COLOUR, linestyle=ls, label=f"averaged theory: $P_{{escape}}$ = {v:g}")
                   for v, ls in THEORY_LEVELS.items()]
        fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), fontsize=8, frameon=False)
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
    _theory_notes(fig, ds)
    return fig


def _theory_notes(fig: Figure, ds: xr.Dataset) -> None:
    """Caption sentences on the averaged theory: its agreement per noise level, or why it is absent."""
    if "P_escape_theory" not in ds:
        if "theory_reason" in ds.attrs:
            add_note(fig, f"No averaged theory: {param(ds, 'theory_reason')}.")
        return
    n_gamma, n_J = (int(n) for n in param(ds, "theory_cells"))
    add_note(fig, "Red contours: the averaged theory's P_escape (docs/noise-theory.md: the backward Kolmogorov "
                  f"equation of the stochastic slow flow on {n_gamma} x {n_J} cells) at 0.05 (dashed) and 0.5 "
                  "(solid); |ΔP| = |P_theory - P_ensemble| over the initial conditions.")
    times = " / ".join(f"{t:g}" for t in var(ds, "t_eval").values)
    mean, high = var(ds, "P_escape_mean_abs_difference"), var(ds, "P_escape_max_abs_difference")
    uncertain, wilson = var(ds, "P_escape_mean_abs_difference_uncertain"), var(ds, "P_escape_theory_within_wilson")
    for s in var(ds, "noise").values:
        m = " / ".join(f"{x:.3f}" for x in mean.sel(noise=s).values)
        x = " / ".join(f"{x:.2f}" for x in high.sel(noise=s).values)
        add_note(fig, f"σ = {s:g}, theory vs ensembles within {times} cycles: mean |ΔP| {m}, max {x}; mean "
                      f"{float(uncertain.sel(noise=s)):.3f} over the ICs not escaping at once; the theory inside "
                      f"the 95% Wilson interval at {100 * float(wilson.sel(noise=s)):.0f}% of (IC, t).")
