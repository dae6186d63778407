"""The wells the explorer offers and, per well, its slider ranges, defaults and plot windows.

A well is any form :func:`safebasins.wells.spec_of` reads: a named well of ``NAMED_WELLS`` (read
at run time, so a well added there appears in the explorer), ``{"expression": "<V(q)>"}`` or
``{"polynomial": [c0, c1, ...]}``.  Ranges scale with the well: energies with its barrier energy
E_b, frequencies with its small-oscillation frequency omega(0), forces with its static escape
force (:func:`static_escape_force`), the plane of initial conditions is ``Well.ic_window``.  For
the quartic the defaults are the paper's Fig 14 (F = 0.01, Omega = 0.9, Psi = pi, xi_max = 0.18).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from safebasins import wells

__all__ = ["Slider", "WellRanges", "well_names", "well_description", "well_ranges", "static_escape_force",
           "EXPRESSION"]

#: highest threshold offered, as a fraction of the barrier energy (the slow flow is singular at E_b)
TOP = 0.98
#: largest damping of the slider, in units of omega(0) (beta = 0.05 for the quartic: Q = 20, still
#: small against omega, where the isolated-resonance theory applies, docs/damping.md)
DAMPING_MAX = 0.05
#: the forcing amplitude slider: up to F_FRACTION_MAX of the static escape force, by default
#: F_FRACTION_DEFAULT of it (the quartic: 0.385 / 40 = 0.0096, about Fig 14's F = 0.01)
F_FRACTION_MAX = 0.5
F_FRACTION_DEFAULT = 1 / 40
#: the spec name of a well written as a formula in q (the explorer's text input)
EXPRESSION = "expression"


def well_names() -> list[str]:
    """Names of the named wells offered: every named well of :mod:`safebasins.wells`."""
    return list(wells.NAMED_WELLS)


def well_description(name: str) -> str:
    """The one-line description of a named well (``safebasins.wells.NAMED_WELLS``)."""
    if name not in wells.NAMED_WELLS:
        raise ValueError(f"well: unknown well {name!r}; the explorer offers {', '.join(well_names())} "
                         "and any expression V(q)")
    return wells.NAMED_WELLS[name][1]


def static_escape_force(well: wells.Well) -> float:
    """The constant force that tilts the well until its bottom disappears (the well's own,
    :attr:`safebasins.wells.base.Well.static_escape_force`: the quartic 2 / (3 sqrt 3) = 0.385, the
    pendulum 1)."""
    return float(well.static_escape_force)


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
    name, spec, well
        The well's spec name (a named well, ``"expression"`` or ``"polynomial"``), its resolved spec
        (:func:`safebasins.wells.spec_of`) and its :class:`~safebasins.wells.base.Well` object.
    barrier_energy, omega0, force
        Escape energy E_b, small-oscillation frequency omega(0) and static escape force.
    Omega, F, Psi, xi_max, damping
        The sliders (damping: beta of q'' + beta q' + V'(q) = ..., from 0, the undamped equation).
    q_window, p_window
        The plane of initial conditions shown (``Well.ic_window``).
    xi_top
        Top of the resonance-manifold panel.
    """

    name: str
    spec: dict
    well: wells.Well
    barrier_energy: float
    omega0: float
    force: float
    Omega: Slider
    F: Slider
    Psi: Slider
    xi_max: Slider
    damping: Slider
    q_window: tuple[float, float]
    p_window: tuple[float, float]
    xi_top: float

    @property
    def label(self) -> str:
        """The well in words: its name, or ``V = <formula>`` of an unnamed well."""
        return self.name if self.name in wells.NAMED_WELLS else f"V = {self.well.potential_text()}"

    def description(self) -> str:
        """One line about the well: what it is and its scales."""
        what = (well_description(self.name) if self.name in wells.NAMED_WELLS
                else f"your well V = {self.well.potential_text()}")
        return (f"{what}; E_b = {self.barrier_energy:.4g}, omega(0) = {self.omega0:.4g}, "
                f"static escape force {self.force:.3g}")


def well_ranges(well: object = "quartic") -> WellRanges:
    """Sliders and windows of a well given as a name, ``{"expression": ...}`` or
    ``{"polynomial": [...]}``; ValueError naming ``well`` (or the spec's key) if it is not one."""
    spec = wells.spec_of(well)
    w = wells.from_spec(spec)
    Eb = float(w.barrier_energy)
    omega0 = float(w.omega(0.0))
    force = static_escape_force(w)
    top = TOP * Eb
    (q_lo, q_hi), (p_lo, p_hi) = w.ic_window()
    quartic = spec["name"] == "quartic"
    return WellRanges(
        name=spec["name"], spec=spec, well=w, barrier_energy=Eb, omega0=omega0, force=force,
        Omega=Slider(0.4 * omega0, 1.4 * omega0, 0.005 * omega0, 0.9 * omega0),
        F=Slider(0.0, F_FRACTION_MAX * force, force / 2000, 0.01 if quartic else F_FRACTION_DEFAULT * force),
        Psi=Slider(-np.pi, np.pi, np.pi / 180, np.pi),
        xi_max=Slider(0.02 * Eb, top, Eb / 1000, 0.18 if quartic else 0.72 * Eb),
        damping=Slider(0.0, DAMPING_MAX * omega0, 0.0005 * omega0, 0.0),
        q_window=(q_lo, q_hi), p_window=(p_lo, p_hi), xi_top=w.manifold_top)
