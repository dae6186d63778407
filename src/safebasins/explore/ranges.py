"""The wells the explorer offers and, per well, its slider ranges, defaults and plot windows.

The wells are the named wells of :mod:`safebasins.wells` (``NAMED_WELLS``), read at run time, so
a well added there appears in the explorer.  Ranges scale with the well: energies with its
barrier energy E_b, frequencies with its small-oscillation frequency omega(0).  For the quartic
the defaults are the paper's Fig 14 (F = 0.01, Omega = 0.9, Psi = pi, xi_max = 0.18).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from safebasins import wells

__all__ = ["Slider", "WellRanges", "well_names", "well_description", "well_ranges"]

#: highest threshold offered, as a fraction of the barrier energy (the slow flow is singular at E_b)
TOP = 0.98
#: largest damping of the slider, in units of omega(0) (beta = 0.05 for the quartic: Q = 20, still
#: small against omega, where the isolated-resonance theory applies, docs/damping.md)
DAMPING_MAX = 0.05


def well_names() -> list[str]:
    """Names of the wells offered: every named well of :mod:`safebasins.wells`."""
    return list(wells.NAMED_WELLS)


def well_description(name: str) -> str:
    """The one-line description of a named well (``safebasins.wells.NAMED_WELLS``)."""
    if name not in wells.NAMED_WELLS:
        raise ValueError(f"well: unknown well {name!r}; the explorer offers {', '.join(well_names())}")
    return wells.NAMED_WELLS[name][1]


@dataclass(frozen=True)
class Slider:
    """Range, step and default value of one slider."""

    start: float
    end: float
    step: float
    value: float


@dataclass(frozen=True)
class WellRanges:
    """One well with its sliders and windows.

    Attributes
    ----------
    name, well
        The well's name and its :class:`~safebasins.wells.base.Well` object.
    barrier_energy, omega0
        Escape energy E_b and small-oscillation frequency omega(0).
    Omega, F, Psi, xi_max, damping
        The sliders (damping: beta of q'' + beta q' + V'(q) = ..., from 0, the undamped equation).
    q_window, p_window
        The plane of initial conditions shown: the orbit of the highest threshold with a margin.
    xi_top
        Top of the resonance-manifold panel.
    """

    name: str
    well: wells.Well
    barrier_energy: float
    omega0: float
    Omega: Slider
    F: Slider
    Psi: Slider
    xi_max: Slider
    damping: Slider
    q_window: tuple[float, float]
    p_window: tuple[float, float]
    xi_top: float


def well_ranges(name: str) -> WellRanges:
    """Sliders and windows of the named well ``name`` (ValueError naming ``well`` if unknown)."""
    well_description(name)
    w = wells.resolve_well(name)
    Eb = float(w.barrier_energy)
    omega0 = float(w.omega(0.0))
    top = TOP * Eb
    q_lo, q_hi = (float(v) for v in w.turning_points(top))
    pad = 0.06 * (q_hi - q_lo)
    p_hi = 1.06 * np.sqrt(2.0 * top)
    quartic = name == "quartic"
    return WellRanges(
        name=name, well=w, barrier_energy=Eb, omega0=omega0,
        Omega=Slider(0.4 * omega0, 1.4 * omega0, 0.005 * omega0, 0.9 * omega0),
        F=Slider(0.0, 0.4 * Eb, Eb / 1000, 0.01 if quartic else 0.04 * Eb),
        Psi=Slider(-np.pi, np.pi, np.pi / 180, np.pi),
        xi_max=Slider(0.02 * Eb, top, Eb / 1000, 0.18 if quartic else 0.72 * Eb),
        damping=Slider(0.0, DAMPING_MAX * omega0, 0.0005 * omega0, 0.0),
        q_window=(q_lo - pad, q_hi + pad), p_window=(-p_hi, p_hi), xi_top=top)
