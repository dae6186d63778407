"""Critical-forcing curves F_cr(Omega), analytic and numeric, stacked over ``curve`` (Figs 1-4, 10-12).

A curve is a dict with ``label``, ``xi_max``, ``xi_ini``, ``gamma_ini``, optionally ``damping``
(beta > 0: the damped theory and numerics) and, for the numerics, ``Psi`` (safebasins.pipeline.values.curves makes them
from a config block); the pipeline's ``fcr_theory`` / ``fcr_compare`` kinds and ``safebasins fcr`` call these functions.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, cast

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.analysis.safe import Criterion
from safebasins.wells.base import WellLike
from safebasins.wells.provenance import api_provenance
from safebasins.core.stacking import stack
from safebasins.theory import critical_forcing, initial_condition
from safebasins.numerics import critical_forcing_numeric

__all__ = ["analytic_fcr_curves", "numeric_fcr_curves"]


@api_provenance
def analytic_fcr_curves(Omega: npt.ArrayLike, curves: Sequence[Mapping[str, Any]], *, well: WellLike = None,
                        label: str = "") -> xr.Dataset:
    """One :func:`safebasins.theory.critical_forcing` per curve (eqs 22-26), stacked over ``curve``
    with the coordinates xi_max, xi_ini, gamma_ini, label (and Psi when every curve has one)."""
    Omega = np.asarray(Omega, dtype=float)
    parts = []
    for c in curves:
        print(f"{label}: critical_forcing for {c['label']}")
        parts.append(critical_forcing(Omega, c["xi_max"], xi_ini=c["xi_ini"], gamma_ini=c["gamma_ini"], well=well,
                                      damping=c.get("damping", 0.0)))
    return stack(parts, "curve", coords=_curve_coords(curves, ("xi_max", "xi_ini", "gamma_ini", "label"),
                                                      ("Psi", "damping")))


def _curve_coords(curves, keys, optional):
    """Per-curve coordinates: ``keys`` and each of ``optional`` that every curve has (a curve
    without ``damping`` is undamped, and undamped stacks keep their old coordinates)."""
    have = [*keys, *(k for k in optional if all(k in c for c in curves))]
    return {k: [c[k] for c in curves] for k in have}


@api_provenance
def numeric_fcr_curves(Omega: npt.ArrayLike, curves: Sequence[Mapping[str, Any]], *, well: WellLike = None,
                       cycles: int, tol: float, F_bracket: Sequence[float] | None, criterion: Criterion, n_scan: int,
                       steps_per_cycle: int, threads: int | None = None, backend: str = "cpu",
                       label: str = "") -> xr.Dataset:
    """One :func:`safebasins.numerics.critical_forcing_numeric` per curve, from the IC
    ``theory.initial_condition(xi_ini, gamma_ini, Psi)``, stacked over ``curve`` with the
    coordinates xi_max, xi_ini, gamma_ini, Psi, label, q0, p0."""
    Omega = np.asarray(Omega, dtype=float)
    parts, q0s, p0s = [], [], []
    for c in curves:
        q0, p0 = (float(v) for v in initial_condition(c["xi_ini"], c["gamma_ini"], c["Psi"], well=well))
        q0s.append(q0)
        p0s.append(p0)
        print(f"{label}: {c['label']}: IC (q0, p0) = ({q0:.6f}, {p0:.6f})", flush=True)
        parts.append(critical_forcing_numeric(
            Omega, c["xi_max"], q0=q0, p0=p0, Psi=c["Psi"], cycles=cycles, tol=tol,
            F_bracket=None if F_bracket is None else cast(tuple[float, float], tuple(F_bracket)),
            criterion=criterion, n_scan=n_scan, steps_per_cycle=steps_per_cycle, threads=threads, backend=backend,
            well=well, damping=c.get("damping", 0.0)))
    coords = _curve_coords(curves, ("xi_max", "xi_ini", "gamma_ini", "Psi", "label"), ("damping",))
    coords.update(q0=q0s, p0=p0s)
    return stack(parts, "curve", coords=coords)
