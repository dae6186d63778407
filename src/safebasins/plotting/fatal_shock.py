"""Figure of the minimal fatal shock of a damped well's attractors: the attractors and their fatal
shocks in the phase plane beside the escape level, and the MFS over the shock phase with the LIM
centred on the attractor.

Input: the Dataset of :func:`safebasins.analysis.fatal_shock.minimal_fatal_shock` (or a path to a
netCDF file holding it).  The caption sentences are computed from it (:func:`add_note`).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D

from safebasins.plotting.captions import add_note
from safebasins.plotting.data import open_dataset, param, var, well
from safebasins.plotting.style import LABELS, param_text, pi_ticks

if TYPE_CHECKING:
    import numpy.typing as npt
    import xarray as xr
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from safebasins.plotting.data import DataSource

__all__ = ["figure_fatal_shock"]

#: one colour per attractor (ordered by the amplitude of the response)
ATTRACTOR_COLOURS = ["tab:blue", "tab:red", "tab:green", "tab:purple", "tab:brown"]
#: line style of each norm in the MFS panel
NORM_STYLE: dict[str, dict[str, Any]] = {"energy": dict(ls="-", marker="o"), "weighted": dict(ls="--", marker="^")}


def _colour(a: int) -> str:
    return ATTRACTOR_COLOURS[a % len(ATTRACTOR_COLOURS)]


#: the escape level H0 = xi_max in the phase plane
LEVEL_COLOUR = "0.25"


def _phase_text(phi: float) -> str:
    """A shock phase in [0, 2 pi), in units of pi (plain text for captions)."""
    r = float(np.mod(phi, 2.0 * np.pi)) / np.pi
    return "0" if r == 0 else "π" if r == 1 else f"{r:.3g}π"


def figure_fatal_shock(shock: DataSource, *, title: str | None = None) -> Figure:
    """(a) The phase plane: the escape level H0 = xi_max (dashed), each attractor's state at the shock
    phases (dots, joined in phase order) and its minimal fatal shock in the energy norm (arrows to the
    escaping state, a cross); (b) the MFS over the shock phase per attractor (solid: energy norm;
    dashed: the weighted norm, if any) with the LIM centred on the attractor (open markers)."""
    ds = open_dataset(shock)
    phi = var(ds, "phase").values
    order = np.argsort(np.mod(phi, 2.0 * np.pi), kind="stable")
    x = np.mod(phi, 2.0 * np.pi)[order]
    norms = [str(n) for n in var(ds, "norm").values]
    n_att = ds.sizes["attractor"]
    amp = var(ds, "response_amplitude").values
    fig, (axP, axM) = plt.subplots(1, 2, figsize=(11.0, 4.6), gridspec_kw={"width_ratios": [1.0, 1.15]})
    _phase_plane(axP, ds)
    for a in range(n_att):
        for n, name in enumerate(norms):
            st = NORM_STYLE.get(name, NORM_STYLE["weighted"])
            label = f"attractor {a} (amplitude {amp[a]:.3g})" + (f", {name} norm" if len(norms) > 1 else "")
            axM.plot(x, var(ds, "mfs").values[a, order, n], color=_colour(a), ms=4, lw=1.2, label=label, **st)
            axM.plot(x, var(ds, "lim").values[a, order, n], color=_colour(a), marker=st["marker"], ls="",
                     mfc="none", ms=7, mew=0.8)
    axM.plot([], [], color="0.3", marker="o", ls="", mfc="none", ms=7, mew=0.8,
             label="LIM centred on the attractor (grid)")
    axM.set_xlim(-0.1, 2.0 * np.pi + 0.1)
    pi_ticks(axM, 0.0, 2.0 * np.pi)
    top = float(np.nanmax(np.r_[var(ds, "mfs").values.ravel(), var(ds, "lim").values.ravel()]))
    axM.set_ylim(0.0, 1.6 * top)    # room for the legend above the curves
    axM.set_xlabel(r"shock phase $\varphi = \Omega t + \Psi$")
    axM.set_ylabel("minimal fatal shock (norm of the kick)")
    axM.set_title(f"(b) minimal fatal shock over the phase, {int(param(ds, 'cycles'))}-cycle horizon", fontsize=9)
    axM.legend(fontsize=7, frameon=False, loc="upper right")
    par = {k: param(ds, k) for k in ("F", "Omega", "damping", "xi_max")}
    fig.suptitle(title or "Minimal fatal shock of the attractors: " + param_text(par), fontsize=10)
    fig.tight_layout()
    _notes(fig, ds)
    return fig


def _phase_plane(ax: Axes, ds: xr.Dataset) -> None:
    """Panel (a): escape level, attractor states and their energy-norm fatal shocks."""
    w = well(ds)
    xi = float(param(ds, "xi_max"))
    qa, pa = var(ds, "q_attractor").values, var(ds, "p_attractor").values
    n = [str(k) for k in var(ds, "norm").values].index("energy")
    dq, dp = var(ds, "shock_dq").values[:, :, n], var(ds, "shock_dp").values[:, :, n]
    (q_lo, q_hi), (p_lo, p_hi) = w.ic_window()
    q_all = np.r_[q_lo, q_hi, (qa + dq).ravel()]
    p_all = np.r_[p_lo, p_hi, (pa + dp).ravel()]
    pad_q, pad_p = 0.05 * float(np.ptp(q_all)), 0.05 * float(np.ptp(p_all))
    # room for the legend below the escape level
    Q, P = np.meshgrid(np.linspace(q_all.min() - pad_q, q_all.max() + pad_q, 400),
                       np.linspace(p_all.min() - 7.0 * pad_p, p_all.max() + pad_p, 300))
    ax.contour(Q, P, 0.5 * P * P + w.V(Q), levels=[xi], colors=LEVEL_COLOUR, linestyles="--", linewidths=1.0)
    for a in range(qa.shape[0]):
        c = _colour(a)
        ax.plot(np.r_[qa[a], qa[a, :1]], np.r_[pa[a], pa[a, :1]], color=c, lw=0.6, alpha=0.6)
        ax.plot(qa[a], pa[a], "o", color=c, ms=3)
        ax.plot(qa[a, 0], pa[a, 0], "o", color=c, ms=6, mfc="none")
        for k in range(qa.shape[1]):
            ax.annotate("", xy=(qa[a, k] + dq[a, k], pa[a, k] + dp[a, k]), xytext=(qa[a, k], pa[a, k]),
                        arrowprops=dict(arrowstyle="->", color=c, lw=0.8, shrinkA=0, shrinkB=0))
        ax.plot(qa[a] + dq[a], pa[a] + dp[a], "x", color=c, ms=4, mew=0.9)
    handles = [Line2D([], [], color=LEVEL_COLOUR, ls="--", lw=1.0, label=rf"escape level $H_0$ = {xi:.4g}"),
               Line2D([], [], color="0.3", marker="o", ls="-", lw=0.6, ms=3,
                      label="attractor at the shock phases (ring: the first)"),
               Line2D([], [], color="0.3", marker="x", ls="", ms=4, label="state after its minimal fatal shock")]
    ax.legend(handles=handles, fontsize=7, frameon=False, loc="lower center")
    ax.set_xlabel(LABELS["q"])
    ax.set_ylabel(LABELS["p"])
    ax.set_title("(a) attractors and their fatal shocks (energy norm)", fontsize=9)


def _span(values: npt.NDArray[np.float64], phi: npt.NDArray[np.float64]) -> str:
    """``"a (at phi_a) to b (at phi_b)"`` of the values over the phases."""
    i, j = int(np.nanargmin(values)), int(np.nanargmax(values))
    if values[i] == values[j]:
        return f"{values[i]:.4f} at every phase"
    return f"{values[i]:.4f} (at φ = {_phase_text(phi[i])}) to {values[j]:.4f} (at φ = {_phase_text(phi[j])})"


def _notes(fig: Figure, ds: xr.Dataset) -> None:
    """Caption sentences computed from the data."""
    phi = var(ds, "phase").values
    norms = [str(n) for n in var(ds, "norm").values]
    amp, mu = var(ds, "response_amplitude").values, var(ds, "multiplier_modulus").values
    atts = "; ".join(f"attractor {a}: response amplitude {amp[a]:.4f}, Floquet multipliers of modulus "
                     f"{mu[a]:.4f}" for a in range(amp.size))
    add_note(fig, f"{amp.size} stable period-1 attractor{'s' if amp.size != 1 else ''} inside the well ({atts}); "
                  f"shocks at {phi.size} phase{'s' if phi.size != 1 else ''} φ = Ωt + Ψ from {_phase_text(phi[0])}; "
                  f"escape when H0 > ξ_max = {float(param(ds, 'xi_max')):.4g} or beyond a barrier within "
                  f"{int(param(ds, 'cycles'))} cycles ({int(param(ds, 'steps_per_cycle'))} steps per cycle).")
    wq, wp = var(ds, "weight_q").values, var(ds, "weight_p").values
    add_note(fig, "Norms: " + "; ".join(f"{name} sqrt({wq[n]:.4g} dq² + {wp[n]:.4g} dp²)"
                                        for n, name in enumerate(norms))
             + f". Search: {int(param(ds, 'n_directions'))} directions x {int(param(ds, 'n_radii'))} radii, "
               f"k-section and Brent over the direction to a relative bracket {float(param(ds, 'tol')):.0e}; "
               f"LIM on a grid of node diagonal {', '.join(f'{s:.4g}' for s in var(ds, 'lim_spacing').values)}.")
    for a in range(amp.size):
        for n, name in enumerate(norms):
            mfs = var(ds, "mfs").values[a, :, n]
            lim = var(ds, "lim").values[a, :, n]
            grid = var(ds, "mfs_grid").values[a, :, n]
            cyc = var(ds, "escape_cycle").values[a, :, n]
            gap = lim - mfs
            spacing = float(var(ds, "lim_spacing").values[n])
            bound = int(np.sum((gap >= 0) & (gap <= spacing)))
            at_once = int(np.sum(cyc == 0))
            flight = cyc[np.isfinite(cyc) & (cyc > 0)]
            if at_once == 0:
                fate = f"the shock's trajectory escapes in flight, within {flight.max():.3g} cycles"
            else:
                fate = (f"the shock's trajectory escapes at once (H0 > ξ_max) at {at_once} of {phi.size} phases"
                        + (f", in flight within {flight.max():.3g} cycles at the others" if flight.size else ""))
            add_note(fig, f"Attractor {a}, {name} norm: MFS {_span(mfs, phi)}; LIM - MFS {gap.min():.2g} to "
                          f"{gap.max():.2g} (0 <= LIM - MFS <= node diagonal at {bound} of {phi.size} phases); "
                          f"polar grid estimate up to {100 * float(np.max(grid / mfs - 1)):.2g}% above the MFS; "
                          + fate + ".")
