"""Figure of the stochastic erosion profile: GIM, LIM and IF of the stochastic safe basin against
the noise amplitude sigma (one curve per F) and against F (one curve per sigma).

Input: the Dataset of :func:`safebasins.analysis.stochastic_erosion` over (F, noise, epsilon,
t_eval) (the ``stochastic_erosion`` kind), or a path to a netCDF file holding it.  The caption
sentences are computed from it (:func:`add_note`).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import matplotlib.pyplot as plt
import numpy as np

from safebasins.plotting.captions import add_note
from safebasins.plotting.data import open_dataset, param, var
from safebasins.plotting.style import param_text

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

    from safebasins.plotting.data import DataSource

__all__ = ["figure_stochastic_erosion"]

MEASURES = ("GIM", "LIM", "IF")


def _profile(ds: xr.Dataset) -> xr.Dataset:
    """The profile with dimensions (F, noise, epsilon) at its last t_eval (absent ones added)."""
    for d in ("F", "noise", "epsilon"):
        if d not in ds["GIM"].dims:
            ds = ds.expand_dims(d) if d in ds.coords else ds.expand_dims({d: [float(param(ds, d))]})
    return ds.isel(t_eval=-1) if "t_eval" in ds["GIM"].dims else ds


def figure_stochastic_erosion(erosion: DataSource, *, title: str | None = None) -> Figure:
    """Top row: GIM, LIM, IF against sigma, one colour per F; bottom row: the same against F, one
    colour per sigma; solid the basin {P_escape <= epsilon} at the smallest epsilon, dashed the
    conservative one, dotted the basin at the largest epsilon, crosses the averaged theory's basin at the
    smallest epsilon (where the Dataset holds ``GIM_theory``, ...); all at the last evaluation time."""
    ds = open_dataset(erosion)
    for v in MEASURES:
        var(ds, v)
    t = float(var(ds, "t_eval").values.ravel()[-1])
    pr = _profile(ds)
    Fs, sig, eps = pr["F"].values, pr["noise"].values, pr["epsilon"].values
    cons = all(v + "_conservative" in pr for v in MEASURES)
    fig, axes = plt.subplots(2, 3, figsize=(12.0, 7.0), squeeze=False, layout="compressed")
    for row, (x, xname, lines, lname) in enumerate(((sig, "noise", Fs, "F"), (Fs, "F", sig, "noise"))):
        colours = plt.get_cmap("viridis")(np.linspace(0.0, 0.85, lines.size))
        for j, m in enumerate(MEASURES):
            ax = axes[row, j]
            for c, val in zip(colours, lines):
                cut = pr.sel({lname: val})
                label = f"{'σ' if lname == 'noise' else 'F'} = {val:g}"
                ax.plot(x, cut[m].sel(epsilon=eps[0]).transpose(xname).values, "-o", color=c, ms=3, label=label)
                if cons:
                    ax.plot(x, cut[m + "_conservative"].sel(epsilon=eps[0]).transpose(xname).values, "--",
                            color=c, lw=1)
                if eps.size > 1:
                    ax.plot(x, cut[m].sel(epsilon=eps[-1]).transpose(xname).values, ":", color=c, lw=1)
                if m + "_theory" in pr:
                    ax.plot(x, cut[m + "_theory"].sel(epsilon=eps[0]).transpose(xname).values, "x", color=c,
                            ms=6, mew=1.2)
            ax.set_xlabel("noise amplitude σ" if xname == "noise" else "forcing amplitude F")
            ax.set_ylabel(m)
            ax.set_ylim(-0.03, 1.08)
            ax.set_title(f"({chr(ord('a') + 3 * row + j)}) {m} against {'σ' if xname == 'noise' else 'F'}",
                         fontsize=9)
            ax.grid(alpha=0.3)
        axes[row, 0].legend(fontsize=7, loc="lower left")
    par = {k: param(ds, k) for k in ("Omega", "Psi", "xi_max", "damping") if k in ds.attrs}
    fig.suptitle(title or "Stochastic erosion profile: " + param_text(par), fontsize=10)
    _notes(fig, ds, pr, t, cons)
    return fig


def _notes(fig: Figure, ds: xr.Dataset, pr: xr.Dataset, t: float, cons: bool) -> None:
    """Caption sentences computed from the data."""
    eps = pr["epsilon"].values
    styles = f"solid: P_escape <= {eps[0]:g}" + (", dashed: its conservative basin" if cons else "")
    if eps.size > 1:
        styles += f", dotted: P_escape <= {eps[-1]:g}"
    theory = all(v + "_theory" in pr for v in MEASURES)
    if theory:
        styles += (f", crosses: the averaged theory's P_escape <= {eps[0]:g} (docs/noise-theory.md, "
                   f"{' x '.join(str(int(n)) for n in param(ds, 'theory_cells'))} cells)")
    add_note(fig, f"{int(param(ds, 'paths'))} paths per initial condition (seed {int(param(ds, 'seed'))}), "
                  f"within {t:g} cycles; {styles}.")
    g = pr["GIM"].sel(epsilon=eps[0])
    for F in pr["F"].values:
        row = g.sel(F=F).values
        add_note(fig, f"F = {F:g}: GIM (ε = {eps[0]:g}) " + ", ".join(
            f"{v:.3f}" for v in row) + " at σ = " + ", ".join(f"{s:g}" for s in pr["noise"].values) + ".")
    if cons:
        gap = float((g - pr["GIM_conservative"].sel(epsilon=eps[0])).max())
        add_note(fig, f"The conservative basin's GIM lies at most {gap:.3f} below the plain one's.")
    if theory:
        d = abs(pr["GIM_theory"].sel(epsilon=eps[0]) - g)
        add_note(fig, f"The averaged theory's GIM (ε = {eps[0]:g}) differs from the ensembles' by "
                      f"{float(d.mean()):.3f} on average, at most {float(d.max()):.3f}.")
    elif "theory_reason" in ds.attrs:
        add_note(fig, f"No averaged theory: {param(ds, 'theory_reason')}.")
