"""Figure of the attractors of a damped well followed across F or Omega: the response curves (stable
solid, unstable dashed, the folds, period doublings and exits from the well marked) above, each
attractor's basin integrity (GIM) and the safe basin's against the swept parameter, with the Dover
cliffs, below.

Input: the Dataset of :func:`safebasins.analysis.continuation.continue_attractors` (or a path to a
netCDF file holding it).  The caption sentences are computed from it (:func:`add_note`).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D

from safebasins.plotting.captions import add_note, count
from safebasins.plotting.data import open_dataset, param, var
from safebasins.plotting.fatal_shock import ATTRACTOR_COLOURS
from safebasins.plotting.style import LABELS, SYMBOLS, param_text

if TYPE_CHECKING:
    import numpy.typing as npt
    import xarray as xr
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from safebasins.plotting.data import DataSource

__all__ = ["figure_continuation"]

#: the unstable (saddle) branches
UNSTABLE_COLOUR = "0.45"
#: marker of each bifurcation or end drawn on the branches (the other ends are not marked)
EVENT_MARKERS: dict[str, dict[str, Any]] = {
    "fold": dict(marker="o", mfc="white", mec="k", label="fold"),
    "branch_point": dict(marker="s", mfc="white", mec="k", label="branch point"),
    "period_doubling": dict(marker="D", mfc="tab:orange", mec="k", label="period doubling"),
    "left_well": dict(marker="X", mfc="k", mec="k", label=r"orbit reaches $\xi_{max}$ (leaves the well)"),
}
#: the events in the notes
NOTE_WORDS = {"fold": "folds", "branch_point": "branch points", "period_doubling": "period doublings",
              "left_well": "exits from the well (the orbit's largest H0 reaching ξ_max)"}
#: ends of a branch the notes report (the branch stopped before the sweep's end or the well's edge)
EARLY_ENDS = ("step_failure", "max_points")
#: the plain-text symbol of the swept parameter in the notes
PLAIN = {"F": "F", "Omega": "Ω"}


def _colour(a: int) -> str:
    return ATTRACTOR_COLOURS[a % len(ATTRACTOR_COLOURS)]


def _kinds(ds: xr.Dataset) -> list[str]:
    """The event kinds by flag value."""
    return str(var(ds, "event_kind").attrs["flag_meanings"]).split()


def _classes(ds: xr.Dataset) -> list[str]:
    return [c.replace("_", "-") for c in str(var(ds, "attractor_class").attrs["flag_meanings"]).split()]


def figure_continuation(continuation: DataSource, *, title: str | None = None) -> Figure:
    """(a) The largest ``|q|`` of the period-1 orbits against the swept parameter: stable stretches in
    their attractor's colour (solid), unstable ones grey dashed, events marked; (b) each attractor's
    GIM and the safe basin's against the swept parameter, each basin's Dover cliff shaded in its
    colour (the safe basin's hatched)."""
    ds = open_dataset(continuation)
    name = str(param(ds, "parameter"))
    fig, (axB, axG) = plt.subplots(2, 1, figsize=(8.0, 8.4), sharex=True, gridspec_kw={"height_ratios": [1.15, 1.0]})
    _branches(axB, ds)
    _integrity(axG, ds)
    sweep = var(ds, name).values
    pad = 0.01 * float(sweep[-1] - sweep[0])
    axG.set_xlim(float(sweep[0]) - pad, float(sweep[-1]) + pad)
    axG.set_xlabel(LABELS[name])
    fixed = "F" if name == "Omega" else "Omega"
    par = {k: param(ds, k) for k in (fixed, "damping", "Psi", "xi_max")}
    fig.suptitle(title or f"Attractors followed across {SYMBOLS[name]}: " + param_text(par), fontsize=10)
    fig.tight_layout()
    _notes(fig, ds)
    return fig


def _branches(ax: Axes, ds: xr.Dataset) -> None:
    """Panel (a): the continued curves and their events."""
    curve, lam = var(ds, "curve").values, var(ds, "parameter").values
    amp, stable = var(ds, "amplitude").values, var(ds, "stable").values.astype(bool)
    att = var(ds, "point_attractor").values
    for c in np.unique(curve):
        idx = np.flatnonzero(curve == c)
        # runs of equal stability and attractor, each sharing its first point with the run before
        cuts = np.flatnonzero((stable[idx][1:] != stable[idx][:-1]) | (att[idx][1:] != att[idx][:-1])) + 1
        for lo, hi in zip(np.r_[0, cuts], np.r_[cuts, idx.size]):
            run = idx[max(lo - 1, 0):hi]
            if stable[idx[lo]]:
                ax.plot(lam[run], amp[run], color=_colour(int(att[idx[lo]])), lw=1.6)
            else:
                ax.plot(lam[run], amp[run], color=UNSTABLE_COLOUR, lw=1.1, ls="--")
    kinds = _kinds(ds)
    ek = var(ds, "event_kind").values
    handles = [Line2D([], [], color="0.2", lw=1.6, label="stable (an attractor, its colour in (b))"),
               Line2D([], [], color=UNSTABLE_COLOUR, lw=1.1, ls="--", label="unstable (saddle)")]
    for kind, style in EVENT_MARKERS.items():
        sel = ek == kinds.index(kind)
        if sel.any():
            mk = {k: v for k, v in style.items() if k != "label"}
            ax.plot(var(ds, "event_parameter").values[sel], var(ds, "event_amplitude").values[sel], ls="", ms=7,
                    mew=1.0, zorder=5, **mk)
            handles.append(Line2D([], [], ls="", ms=7, mew=1.0, label=style["label"], **mk))
    ax.set_ylabel(r"response amplitude: largest $|q|$ over the period")
    ax.set_title("(a) period-1 orbits inside the well", fontsize=9)
    ax.legend(handles=handles, fontsize=7, frameon=False, loc="lower right")


def _integrity(ax: Axes, ds: xr.Dataset) -> None:
    """Panel (b): GIM of each attractor's basin and of the safe basin, the cliffs shaded."""
    name = str(param(ds, "parameter"))
    sweep = var(ds, name).values
    gim, cls = var(ds, "GIM").values, _classes(ds)
    lo, hi, drop = (var(ds, k).values for k in ("cliff_low", "cliff_high", "cliff_drop"))
    for a in range(ds.sizes["attractor"]):
        c = _colour(a)
        ax.plot(sweep, gim[:, a], "o-", color=c, ms=4, lw=2.4,
                label=f"attractor {a} ({cls[int(var(ds, 'attractor_class').values[a])]})")
        if np.isfinite(lo[a]):
            ax.axvspan(lo[a], hi[a], color=c, alpha=0.15, lw=0)
            ax.text(0.5 * (lo[a] + hi[a]), 1.10 - 0.05 * a, f"−{drop[a]:.3f}", color=c, fontsize=7, ha="center",
                    va="top", zorder=6, bbox=dict(fc="white", ec="none", pad=0.5))
    # on top, thin: where one attractor holds the whole safe basin the two curves coincide
    ax.plot(sweep, var(ds, "GIM_safe").values, "s--", color="k", ms=2.0, lw=0.9, zorder=4,
            label="safe basin (no escape)")
    s_lo, s_hi = float(var(ds, "safe_cliff_low")), float(var(ds, "safe_cliff_high"))
    if np.isfinite(s_lo):
        ax.axvspan(s_lo, s_hi, facecolor="none", edgecolor="k", hatch="///", lw=0.0, alpha=0.5,
                   label="safe basin's Dover cliff")
    ax.plot([], [], color="0.5", alpha=0.3, lw=6, label="an attractor's cliff (its colour; on top: the GIM lost)")
    ax.set_ylim(-0.03, 1.13)
    ax.set_ylabel("GIM (basin area / unforced safe area)")
    ax.set_title("(b) basin integrity and the Dover cliff (the most of a basin escaping over one step)", fontsize=9)
    ax.legend(fontsize=7, frameon=False, loc="center right")


def _values(x: npt.NDArray[np.float64]) -> str:
    """Distinct values to 6 significant digits, in increasing order."""
    return ", ".join(dict.fromkeys(f"{v:.6g}" for v in np.sort(x)))


def _notes(fig: Figure, ds: xr.Dataset) -> None:
    """Caption sentences computed from the data."""
    name = str(param(ds, "parameter"))
    sym = PLAIN[name]
    sweep = var(ds, name).values
    n_att, n_grid = ds.sizes["attractor"], int(param(ds, "n_grid"))
    add_note(fig, f"{sym} swept from {sweep[0]:.4g} to {sweep[-1]:.4g} ({sweep.size} values); basins labelled on "
                  f"{n_grid} x {n_grid} ICs over the well, escape when H0 > ξ_max = {float(param(ds, 'xi_max')):.4g}; "
                  f"{count(np.unique(var(ds, 'curve').values).size, 'continued curve')} of "
                  f"{count(ds.sizes['point'], 'point')}, {count(n_att, 'attractor')} (stable stretches of "
                  "the curves).")
    kinds, ek = _kinds(ds), var(ds, "event_kind").values
    ep, located = var(ds, "event_parameter").values, var(ds, "event_located").values.astype(bool)
    found = []
    for kind, word in NOTE_WORDS.items():
        sel = ek == kinds.index(kind)
        found.append(f"{word} at {sym} = {_values(ep[sel])}" if sel.any() else f"no {word}")
    early = [k for k in EARLY_ENDS if (ek == kinds.index(k)).any()]
    missed = int((~located).sum())
    add_note(fig, "Events: " + "; ".join(found) + "."
             + (f" {missed} event(s) not located (drawn at the nearest point)." if missed else "")
             + (f" A branch stopped early ({', '.join(early)})." if early else ""))
    cls = _classes(ds)
    gim, exists = var(ds, "GIM").values, var(ds, "exists").values.astype(bool)
    ends, end_kind = var(ds, "attractor_end_parameter").values, var(ds, "attractor_end_kind").values
    lo, hi, drop = (var(ds, k).values for k in ("cliff_low", "cliff_high", "cliff_drop"))
    for a in range(n_att):
        on = np.flatnonzero(exists[:, a])
        span = (f"GIM {gim[on[0], a]:.3f} at {sym} = {sweep[on[0]]:.4g} to {gim[on[-1], a]:.3f} at "
                f"{sweep[on[-1]]:.4g}" if on.size else "at none of the swept values")
        cliff = (f"its Dover cliff: GIM {drop[a]:.3f} lost to escape between {sym} = {lo[a]:.4g} and {hi[a]:.4g}"
                 if np.isfinite(drop[a]) else "none of its basin escapes on the grid")
        add_note(fig, f"Attractor {a} ({cls[int(var(ds, 'attractor_class').values[a])]}): stable for {sym} from "
                      f"{ends[a, 0]:.6g} ({kinds[end_kind[a, 0]].replace('_', ' ')}) to {ends[a, 1]:.6g} "
                      f"({kinds[end_kind[a, 1]].replace('_', ' ')}); {span}; {cliff}.")
    g_safe = var(ds, "GIM_safe").values
    s_lo, s_hi, s_drop = (float(var(ds, k)) for k in ("safe_cliff_low", "safe_cliff_high", "safe_cliff_drop"))
    safe = f"Safe basin: GIM {g_safe[0]:.3f} at {sym} = {sweep[0]:.4g}, {g_safe[-1]:.3f} at {sweep[-1]:.4g}; "
    if np.isfinite(s_drop):
        k = int(np.flatnonzero(sweep == s_hi)[0])
        safe += (f"its Dover cliff: GIM {s_drop:.3f} lost to escape between {sym} = {s_lo:.4g} and {s_hi:.4g} "
                 f"(GIM {g_safe[k - 1]:.3f} to {g_safe[k]:.3f}).")
    else:
        safe += "none of it escapes between neighbouring values."
    unf = var(ds, "n_unfollowed").values
    if unf.any():
        safe += (f" At {int((unf > 0).sum())} of {sweep.size} values the grid settles on attractors no branch "
                 "follows (period > 1, or a fixed point Newton did not converge on): their basins count as safe, "
                 "not as a followed attractor's.")
    uns = var(ds, "n_unsettled").values
    if uns.any():
        k = int(np.argmax(uns))
        safe += (f" ICs not settled within the map iterations (each given the nearest attractor) at "
                 f"{int((uns > 0).sum())} of {sweep.size} values, the most {int(uns[k])} of {n_grid ** 2} at "
                 f"{sym} = {sweep[k]:.4g}.")
    add_note(fig, safe)
