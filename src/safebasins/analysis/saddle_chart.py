"""The hilltop saddle's manifolds over escape charts of the damped well, at several F, with the F
of their first tangency: the data of the pipeline's ``hilltop_saddle`` kind.

For each F: the escape chart of the section ``t = 0`` (phase Psi; energy criterion at ``xi_max``,
``cycles`` forcing cycles, :func:`safebasins.numerics.escape_chart`), the saddle's stable and
unstable manifolds on the same plane (:func:`safebasins.analysis.saddle.saddle_manifolds`) and its
orbit's Floquet data (:func:`safebasins.analysis.saddle.hilltop_orbit`); once: the Melnikov
threshold and, optionally, the numeric tangency (:func:`safebasins.analysis.saddle.manifold_tangency`).
Below the tangency the inner stable manifold bounds the safe basin; past it the unstable
manifold crosses it and the boundary is tangled.
"""
from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.analysis.melnikov import melnikov_threshold
from safebasins.analysis.saddle import hilltop_orbit, manifold_tangency, saddle_manifolds
from safebasins.core import checks
from safebasins.core.cf import annotate
from safebasins.core.stacking import stack
from safebasins.numerics import escape_chart
from safebasins.wells import resolve_well, well_attrs
from safebasins.wells.base import WellLike
from safebasins.wells.provenance import api_provenance

__all__ = ["saddle_chart"]

_threshold: Callable[..., Any] = melnikov_threshold
_chart: Callable[..., Any] = escape_chart
_ONE = {"units": "1"}


@api_provenance
def saddle_chart(F_values: float | Sequence[float], Omega: float, Psi: float, xi_max: float, q0: npt.ArrayLike,
                 p0: npt.ArrayLike, *, damping: float, well: WellLike = None, cycles: int = 500,
                 steps_per_cycle: int | None = None, threads: int | None = None,
                 manifolds: dict[str, Any] | None = None, tangency: dict[str, Any] | None = None) -> xr.Dataset:
    """Escape charts, the saddle's manifolds and its Floquet data at each F (module docstring).

    ``manifolds``: keyword arguments of :func:`~safebasins.analysis.saddle.saddle_manifolds`
    (``iterations``, ``ds_max``, ``angle_max``, ``max_points``, ``rtol``); ``tangency``: those of
    :func:`~safebasins.analysis.saddle.manifold_tangency` (None: not computed, ``F_tangency`` NaN).

    Returns a Dataset over ``F``: ``escape_cycle`` (F, q0, p0), ``safe_fraction``, the manifolds
    (F, curve / vertex: ``kind``, ``side``, ``multiplier``, ``resolved``, ``q0_vertex``,
    ``p0_vertex``, ``curve_index``, ``iterate``, padded with NaN / -1), ``q_fixed``, ``p_fixed``,
    ``multiplier_unstable``, ``multiplier_stable`` (F, saddle); scalars ``F_melnikov``,
    ``F_tangency``, ``F_splitting``."""
    F = checks.check_1d("F_values", F_values, checks.check_nonnegative)
    Om = checks.check_scalar("Omega", Omega, checks.check_positive)
    beta = checks.check_positive_damping(damping, "the escape charts' safe basins need attractors inside the well")
    cycles = checks.check_positive_int("cycles", cycles)
    w = resolve_well(well)
    FM = float(_threshold(Om, beta, w))
    kw: dict[str, Any] = {} if steps_per_cycle is None else {"steps_per_cycle": steps_per_cycle}
    parts = []
    for f in F:
        chart = _chart(q0, p0, float(f), Om, Psi, xi_max=[xi_max], well=w, cycles=cycles, threads=threads,
                       grid=True, damping=beta, **kw)
        esc = chart["escape_cycle_energy"].isel(xi_max=0, drop=True).rename("escape_cycle")
        man = saddle_manifolds(float(f), Om, beta, w, Psi, **(manifolds or {}))
        orb = hilltop_orbit(float(f), Om, beta, w, Psi, n_time=8)
        part = man.drop_vars(["q_fixed", "p_fixed"])
        part["escape_cycle"] = esc.drop_vars([c for c in esc.coords if c not in ("q0", "p0")])
        part["safe_fraction"] = ((), float(np.isinf(esc.values).mean()),
                                 {**_ONE, "long_name": f"fraction of the chart safe over {cycles} cycles"})
        for name in ("q_fixed", "p_fixed", "multiplier_unstable", "multiplier_stable"):
            part[name] = orb[name].drop_vars(["q_barrier"])
        manifold_rtol = float(man.attrs["rtol"])
        part.attrs = {}
        parts.append(part)
    ds = stack(parts, "F", F)
    if tangency is None:
        F_T = F_S = np.nan
    else:
        tan = manifold_tangency(Om, beta, w, Psi, **tangency)
        F_T, F_S = float(tan["F_tangency"]), float(tan["F_splitting"])
    ds["F_melnikov"] = ((), FM, {**_ONE, "long_name": "Melnikov threshold (first order in F and beta)"})
    ds["F_tangency"] = ((), F_T, {**_ONE, "long_name": "F of the first tangency of the saddle's manifolds (numeric)"})
    ds["F_splitting"] = ((), F_S, {**_ONE, "long_name": "root of the largest section energy gap "
                                                         "(melnikov.manifold_splitting)"})
    ds.attrs = {"title": "hilltop saddle's manifolds over escape charts", **well_attrs(w), "Omega": Om, "Psi": Psi,
                "damping": beta, "xi_max": float(xi_max), "cycles": cycles,
                # the manifolds' vertices are integrated orbits, known to this tolerance (amplified
                # along the unstable direction): safebasins.io.reproduction compares them as such
                "manifold_rtol": manifold_rtol,
                "method": "escape charts: safebasins.numerics.escape_chart; manifolds, orbit and tangency: "
                          "safebasins.analysis.saddle"}
    return annotate(ds)
