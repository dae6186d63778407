"""Figure of the damped erosion study: integrity versus F with the Melnikov tangency, the
boundary's uncertainty exponent alpha(F) and the long-time basins before and after the tangency.

Inputs are the Datasets of :func:`safebasins.analysis.tangency.tangency_profile` and
:func:`safebasins.analysis.tangency.fractality_profile` (or paths to netCDF files holding them).
"""
from __future__ import annotations

import textwrap
from typing import TYPE_CHECKING, Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import ListedColormap

from safebasins.analysis.fractality import MIN_UNCERTAIN
from safebasins.plotting.captions import add_note
from safebasins.plotting.data import open_dataset, param
from safebasins.plotting.style import LABELS, param_text

if TYPE_CHECKING:
    import numpy.typing as npt
    import xarray as xr
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from safebasins.plotting.data import DataSource

__all__ = ["figure_tangency"]

MEASURE_STYLE: dict[str, dict[str, Any]] = {"GIM": dict(color="tab:blue", marker="o"),
                                            "LIM": dict(color="crimson", marker="s"),
                                            "IF": dict(color="#7b3fa0", marker="^")}
MELNIKOV_STYLE: dict[str, Any] = dict(color="black", ls="--", lw=1.0)
SAFE_CMAP = ListedColormap(["white", "#4a7fb5"])


def _melnikov_line(ax: Axes, F_M: float, label: bool = True) -> None:
    ax.axvline(F_M, **MELNIKOV_STYLE, label=rf"Melnikov $F_M$ = {F_M:.4f}" if label else None)


def figure_tangency(profile: DataSource, fractality: DataSource | None = None, *, xi_max: float | None = None,
                    title: str | None = None) -> Figure:
    """(a) GIM / LIM / IF versus F at each t_eval (light = early, dark = the long-time basin) with
    the Melnikov threshold; (b) the uncertainty exponent alpha(F) +- its standard error, alpha = 1
    (smooth boundary) dotted; (c, d) the safe basins at the kept F (``safe``), before and after
    the tangency."""
    profile, fractality = open_dataset(profile), open_dataset(fractality)
    F_M = float(profile["F_melnikov"])
    xi = float(profile["xi_max"].values[0] if xi_max is None else xi_max)
    kept = profile["F_basin"].values if "safe" in profile else np.zeros(0)
    ncol = 2 + kept.size
    fig, axes = plt.subplots(1, ncol, figsize=(3.6 * ncol, 3.8), squeeze=False)
    ax = axes[0, 0]
    ts = profile["t_eval"].values
    for m, st in MEASURE_STYLE.items():
        for k, t in enumerate(ts):
            y = profile[m].sel(xi_max=xi, t_eval=t)
            last = k == ts.size - 1
            ax.plot(y["F"], y.values, color=st["color"], marker=st["marker"], ms=3.5 if last else 2.5,
                    lw=1.2 if last else 0.6, alpha=1.0 if last else 0.35,
                    label=f"{m}, $t_{{eval}}$ = {t:g} EC" if last or k == 0 else None)
    _melnikov_line(ax, F_M)
    ax.set_xlabel(LABELS["F"])
    ax.set_ylabel("normalised integrity")
    ax.set_ylim(-0.03, 1.05)
    ax.set_title("(a) integrity of the long-time basin")
    ax.legend(fontsize=6.5, frameon=False, loc="lower left")
    ax = axes[0, 1]
    if fractality is not None:
        Ff, a, e = fractality["F"].values, fractality["alpha"].values, fractality["alpha_err"].values
        ax.errorbar(Ff, a, yerr=e, fmt="o", ms=4, color="tab:green", capsize=2,
                    label=rf"$\alpha$ (n = {int(param(fractality, 'n'))} base points)")
        ax.axhline(1.0, color="0.5", lw=0.8, ls=":", label=r"$\alpha$ = 1: smooth boundary")
        _melnikov_line(ax, F_M, label=False)
        ax.set_ylim(0.0, 1.4)
        pad = 0.05 * max(float(np.ptp(np.r_[Ff, F_M])), 1e-3)
        ax.set_xlim(min(Ff.min(), F_M) - pad, max(Ff.max(), F_M) + pad)
        ax.legend(fontsize=6.5, frameon=False, loc="lower left")
        why = unfitted_text(fractality)
        if why:
            ax.text(0.5, 0.62, textwrap.fill(why, 48), transform=ax.transAxes, ha="center", va="center", fontsize=6.5,
                    bbox=dict(facecolor="white", edgecolor="0.7", boxstyle="round,pad=0.4"))
    else:
        ax.text(0.5, 0.5, "no fractality dataset", ha="center", va="center", transform=ax.transAxes)
    ax.set_xlabel(LABELS["F"])
    ax.set_ylabel(r"uncertainty exponent $\alpha$ = 2 - dim")
    ax.set_title("(b) fractality of the basin boundary")
    for j, F in enumerate(kept):
        ax = axes[0, 2 + j]
        s = profile["safe"].sel(F_basin=F, xi_max=xi)
        q0, p0 = s["q0"].values, s["p0"].values
        ax.pcolormesh(q0, p0, s.values.T, cmap=SAFE_CMAP, vmin=0, vmax=1, shading="nearest", rasterized=True)
        side = "below" if F < F_M else "above"
        frac = float(s.values.mean())
        ax.set_title(f"({chr(ord('c') + j)}) F = {F:g} ({side} $F_M$): safe {100 * frac:.1f}%", fontsize=9)
        ax.set_xlabel(LABELS["q0"])
        ax.set_ylabel(LABELS["p0"])
    par = {k: param(profile, k) for k in ("Omega", "Psi", "damping")}
    fig.suptitle(title or "Basin erosion across the homoclinic tangency: " + param_text(par), fontsize=10)
    fig.tight_layout()
    _notes(fig, profile, fractality, F_M, xi)
    return fig


def unfitted_text(fractality: xr.Dataset) -> str | None:
    """Why alpha is NaN at some F, read from the data (None when it is fitted at every F): the fit
    needs at least two eps with MIN_UNCERTAIN uncertain base points each."""
    a = np.atleast_1d(fractality["alpha"].values)
    bad = ~np.isfinite(a)
    if not bad.any():
        return None
    F = np.atleast_1d(fractality["F"].values)
    used = np.asarray(fractality["used"].values, bool).reshape(F.size, -1)
    k = np.asarray(fractality["n_uncertain"].values).reshape(F.size, -1)
    n, n_eps = int(param(fractality, "n")), used.shape[1]
    where = "any F" if bad.all() else "F = " + ", ".join(f"{f:g}" for f in F[bad])
    return (f"alpha not fitted at {where}: too few uncertain initial conditions (the fit needs at least 2 of the "
            f"{n_eps} eps with {MIN_UNCERTAIN} or more uncertain of the {n:,} base points; here at most "
            f"{int(used[bad].sum(axis=1).max())} eps and {int(k[bad].max()):,} uncertain points). More base points "
            "(fractality n) or a box closer to the basin boundary would resolve it.")


def _first_below(F: npt.NDArray[np.float64], y: npt.NDArray[np.float64], level: float) -> float:
    below = np.flatnonzero(y < level)
    return float(F[below[0]]) if below.size else np.nan


def _notes(fig: Figure, profile: xr.Dataset, fractality: xr.Dataset | None, F_M: float, xi: float) -> None:
    """Caption sentences computed from the data (add_note)."""
    t = float(profile["t_eval"].values[-1])
    cross = {m: float(profile[f"F_{m}"].sel(xi_max=xi, t_eval=t)) for m in ("GIM", "LIM", "IF")}
    lvl = param(profile, "level")
    add_note(fig, f"Melnikov threshold F_M = {F_M:.5f}; at t_eval = {t:g} EC the integrity measures fall below "
                  f"{lvl:g} at F = " + ", ".join(f"{v:.4g} ({m}, {v / F_M:.3f} F_M)" for m, v in cross.items()) + ".")
    if fractality is not None:
        F, a, e = fractality["F"].values, fractality["alpha"].values, fractality["alpha_err"].values
        add_note(fig, "Uncertainty exponent: " + "; ".join(
            f"F = {f:g} ({f / F_M:.2f} F_M): " + (f"{x:.2f} +- {s:.2f}" if np.isfinite(x) else "not fitted")
            for f, x, s in zip(F, a, e)) + ".")
        add_note(fig, unfitted_text(fractality))
    if "safe" in profile:
        for F in profile["F_basin"].values:
            frac = float(profile["safe"].sel(F_basin=F, xi_max=xi).mean())
            add_note(fig, f"Basin at F = {F:g}: {100 * frac:.1f}% of the grid safe at t_eval = {t:g} EC.")
