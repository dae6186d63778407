"""The averaged theory beside the noisy ensembles: its escape-probability map with the agreement,
and its stochastic erosion profile, added to the ensembles' Datasets where the theory applies.

The averaged theory (:func:`safebasins.theory.escape_probability`, docs/noise-theory.md) is derived
for white or Ornstein-Uhlenbeck noise of intensity sigma^2 (correlation time short against the
slow time; at sigma = 0 it is the deterministic slow flow) in any well below the barrier.  Elsewhere
(xi_max at the barrier, or ``theory=False``) the Dataset
gets no theory variables but the attributes ``theory = "none"`` and ``theory_reason`` saying why:
an absent theory is stated, never a silent gap.  Where it applies the Dataset gains

* :func:`escape_probability_with_theory` (an ensemble map of
  :func:`safebasins.numerics.escape_probability`, one level or stacked over ``noise``):
  ``P_escape_theory``, ``P_escape_mean_abs_difference`` and ``P_escape_max_abs_difference`` over
  ``t_eval`` (:func:`safebasins.analysis.agreement.probability_agreement`), the per-level summaries
  ``P_escape_mean_abs_difference_uncertain`` and ``P_escape_theory_within_wilson`` as variables, and
  the attributes of the theory's settings with the agreement over everything;
* :func:`stochastic_erosion_with_theory` (a profile of
  :func:`safebasins.analysis.stochastic_erosion`): ``GIM_theory``, ``LIM_theory``, ``IF_theory``
  (:func:`safebasins.analysis.stochastic_integrity.stochastic_erosion_theory`).
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.analysis.agreement import probability_agreement
from safebasins.analysis.stochastic_integrity import stochastic_erosion_theory
from safebasins.core import cf, checks
from safebasins.core.averaged_theory import CELLS, STEPS_PER_CYCLE, check_cells, theory_cycles
from safebasins.theory import escape_probability as theory_escape_probability
from safebasins.theory.noise_averaging import table_evaluations
from safebasins.theory.noise_escape import solve_evaluations
from safebasins.wells import resolve_well
from safebasins.wells.base import WellLike

__all__ = ["escape_probability_with_theory", "stochastic_erosion_with_theory", "theory_reason", "theory_evaluations",
           "THEORY_MEASURES"]

#: the integrity measures the theory's erosion profile adds (as <measure>_theory)
THEORY_MEASURES = ("GIM", "LIM", "IF")
#: the theory's refusals (a ValueError naming one of these arguments): the well, xi_max at the barrier
_REFUSALS = ("well:", "xi_max ")
#: the per-level summaries of probability_agreement stored as variables (stacked over noise)
_LEVEL_SUMMARIES = ("P_escape_mean_abs_difference_uncertain", "P_escape_theory_within_wilson")
_AGREEMENT = ("P_escape_theory", "P_escape_mean_abs_difference", "P_escape_max_abs_difference")


def theory_reason(*, theory: bool, noise: float | Sequence[float] | npt.ArrayLike, noise_time: float) -> str | None:
    """Why the theory is not solved (None: it is, unless the well or xi_max is refused by the solve);
    ``noise_time`` (white or coloured noise) is checked, both are solved."""
    checks.check_nonnegative("noise_time", noise_time)
    if not theory:
        return "not computed (theory: false)"
    return None


def theory_evaluations(*, noise: float | Sequence[float] | npt.ArrayLike, t_eval: npt.ArrayLike, n_ics: int,
                       solves: int, well: WellLike = None, noise_time: float = 0.0, theory: bool = True,
                       cells: tuple[int, int] = CELLS, steps_per_cycle: int = STEPS_PER_CYCLE) -> int:
    """Upper-bound slow-flow evaluations (safebasins.pipeline.cost's unit) of the averaged theory
    that :func:`escape_probability_with_theory` (``solves``: the noise levels) or
    :func:`stochastic_erosion_with_theory` (``solves``: F values x noise levels) add on ``n_ics``
    initial conditions: the well's coefficient tables once and each solve's march
    (:func:`safebasins.theory.noise_escape.solve_evaluations`); 0 where :func:`theory_reason` says
    it is not solved (an upper bound where the solve refuses the well or xi_max).  The pipeline's
    and the command line's cost guards count the theory with it."""
    if theory_reason(theory=theory, noise=noise, noise_time=noise_time) is not None:
        return 0
    return table_evaluations(resolve_well(well)) + solves * solve_evaluations(n_ics, t_eval, cells, steps_per_cycle)


def _refused(exc: ValueError) -> str:
    """The reason of the theory's refusal (its well or xi_max); any other error is raised."""
    if not str(exc).startswith(_REFUSALS):
        raise exc
    return f"not applicable: {exc}"


def _settings_attrs(solve: xr.Dataset, cells: tuple[int, int], steps_per_cycle: int,
                    t_eval: npt.ArrayLike) -> dict[str, Any]:
    """The attributes naming the theory's model and settings (``solve``: one solve's Dataset)."""
    return dict(theory=solve.attrs["theory"], theory_model=solve.attrs["noise_model"],
                theory_solver=solve.attrs["solver"], theory_cells=list(cells),
                theory_steps_per_cycle=steps_per_cycle, theory_cycles=theory_cycles(t_eval))


def _settings(cells: Any, steps_per_cycle: Any, theory: Any) -> tuple[tuple[int, int], int]:
    if not isinstance(theory, (bool, np.bool_)):
        raise ValueError(f"theory must be True or False, got {checks.value_repr(theory)}")
    c = tuple(checks.check_positive_int("cells", n) for n in np.atleast_1d(np.asarray(cells)).tolist())
    return check_cells(c), checks.check_positive_int("steps_per_cycle", steps_per_cycle)


def _levels(ensemble: Any) -> tuple[np.ndarray, bool]:
    """The ensemble's noise levels and whether they are a dimension ``noise``."""
    if not isinstance(ensemble, xr.Dataset) or "P_escape" not in ensemble:
        raise ValueError("ensemble must be the Dataset of numerics.escape_probability (P_escape over q0, p0, t_eval)")
    dims = set(ensemble["P_escape"].dims) - {"noise"}
    if dims != {"q0", "p0", "t_eval"}:
        raise ValueError(f"ensemble: P_escape must be on a (q0, p0) grid over t_eval, got dims "
                         f"{ensemble['P_escape'].dims}")
    if "noise" in ensemble["P_escape"].dims:
        return np.asarray(ensemble["noise"].values, float), True
    if "noise" not in ensemble.attrs:
        raise ValueError("ensemble: no noise level (neither a dimension noise nor an attribute noise)")
    return np.atleast_1d(float(ensemble.attrs["noise"])), False


def escape_probability_with_theory(ensemble: xr.Dataset, F: float, Omega: float, Psi: float, xi_max: float, *,
                                   damping: float = 0.0, well: WellLike = None, noise_time: float = 0.0,
                                   theory: bool = True, cells: tuple[int, int] = CELLS,
                                   steps_per_cycle: int = STEPS_PER_CYCLE) -> xr.Dataset:
    """The ensemble map with the averaged theory's map and their agreement, where the theory applies.

    ``ensemble``: the Dataset of :func:`safebasins.numerics.escape_probability` on a (q0, p0) grid at
    one noise level (its attribute ``noise``), or several such stacked over a dimension ``noise``;
    ``F, Omega, Psi, xi_max, damping, well, noise_time``: the ensemble's arguments; ``theory``:
    False stores only the reason; ``cells``, ``steps_per_cycle``: the theory's solver
    (:func:`safebasins.theory.escape_probability`), one solve per noise level on the ensemble's ICs
    and t_eval.

    Returns a copy of ``ensemble`` with ``P_escape_theory``, ``P_escape_mean_abs_difference``,
    ``P_escape_max_abs_difference`` (over the ICs, per t_eval),
    ``P_escape_mean_abs_difference_uncertain`` and ``P_escape_theory_within_wilson`` (per level) and
    the attributes ``theory``, ``theory_model``, ``theory_solver``, ``theory_cells``,
    ``theory_steps_per_cycle``, ``theory_cycles``, ``P_escape_mean_abs_difference`` and
    ``P_escape_max_abs_difference`` (over levels, ICs and t_eval); where the theory does not apply,
    the copy with ``theory = "none"`` and ``theory_reason``.
    """
    levels, stacked = _levels(ensemble)
    cells_, spc = _settings(cells, steps_per_cycle, theory)
    noise_time = float(checks.check_nonnegative("noise_time", noise_time))
    out = ensemble.copy()
    reason = theory_reason(theory=bool(theory), noise=levels, noise_time=noise_time)
    q0, p0, t_eval = (np.asarray(ensemble[c].values, float) for c in ("q0", "p0", "t_eval"))
    w = resolve_well(well)
    parts: list[xr.Dataset] = []
    solve: xr.Dataset | None = None
    for i, s in enumerate(levels if reason is None else []):
        try:
            solve = theory_escape_probability(q0, p0, F, Omega, Psi, xi_max, noise=float(s), t_eval=t_eval,
                                              damping=damping, well=w, cells=cells_, steps_per_cycle=spc,
                                              noise_time=noise_time)
        except ValueError as exc:
            if i > 0:
                raise
            reason = _refused(exc)
            break
        numeric = ensemble.isel(noise=i) if stacked else ensemble
        agreed = probability_agreement(solve, numeric)
        part = xr.Dataset({k: agreed[k].reset_coords(drop=True) for k in _AGREEMENT})
        for k in _LEVEL_SUMMARIES:
            part[k] = xr.DataArray(agreed.attrs[k], attrs=cf.attrs(k))
        parts.append(part.expand_dims(noise=[float(s)]) if stacked else part)
    if reason is not None or solve is None:
        out.attrs.update(theory="none", theory_reason=str(reason))
        return out
    added = xr.concat(parts, dim="noise", data_vars="all") if stacked else parts[0]
    for k in (*_AGREEMENT, *_LEVEL_SUMMARIES):
        da = added[k].reset_coords(drop=True)
        if stacked:
            da = da.assign_coords(noise=ensemble["noise"])
        out[k] = da
    out.attrs.update(**_settings_attrs(solve, cells_, spc, t_eval),
                     P_escape_mean_abs_difference=float(out["P_escape_mean_abs_difference"].mean()),
                     P_escape_max_abs_difference=float(out["P_escape_max_abs_difference"].max()))
    return out


def stochastic_erosion_with_theory(profile: xr.Dataset, q0: npt.ArrayLike, p0: npt.ArrayLike,
                                   F: float | Sequence[float] | npt.ArrayLike, Omega: float, Psi: float, *,
                                   noise: float | Sequence[float] | npt.ArrayLike, epsilon: npt.ArrayLike,
                                   xi_max: float, t_eval: npt.ArrayLike, damping: float = 0.0, well: WellLike = None,
                                   bottom: tuple[float, float] = (0.0, 0.0), noise_time: float = 0.0,
                                   theory: bool = True, cells: tuple[int, int] = CELLS,
                                   steps_per_cycle: int = STEPS_PER_CYCLE) -> xr.Dataset:
    """The ensembles' erosion profile with the averaged theory's, where the theory applies.

    ``profile``: the Dataset of :func:`safebasins.analysis.stochastic_erosion` called with the
    arguments given here; ``theory``, ``cells``, ``steps_per_cycle``: as
    :func:`escape_probability_with_theory`.  Returns a copy of ``profile`` with ``GIM_theory``,
    ``LIM_theory``, ``IF_theory`` (:func:`safebasins.analysis.stochastic_integrity.stochastic_erosion_theory`,
    on the profile's dims: a different sweep is an error) and the theory's settings as attributes;
    where the theory does not apply, the copy with ``theory = "none"`` and ``theory_reason``.
    """
    if not isinstance(profile, xr.Dataset) or not all(m in profile for m in THEORY_MEASURES):
        raise ValueError("profile must be the Dataset of analysis.stochastic_erosion (GIM, LIM, IF)")
    cells_, spc = _settings(cells, steps_per_cycle, theory)
    noise_time = float(checks.check_nonnegative("noise_time", noise_time))
    out = profile.copy()
    reason, solved = theory_reason(theory=bool(theory), noise=noise, noise_time=noise_time), None
    if reason is None:
        try:
            solved = stochastic_erosion_theory(q0, p0, F, Omega, Psi, noise=noise, epsilon=epsilon, xi_max=xi_max,
                                               t_eval=t_eval, damping=damping, well=well, bottom=bottom,
                                               cells=cells_, steps_per_cycle=spc, noise_time=noise_time)
        except ValueError as exc:
            reason = _refused(exc)
    if solved is None:
        out.attrs.update(theory="none", theory_reason=str(reason))
        return out
    for m in THEORY_MEASURES:
        da = solved[m].reset_coords(drop=True).transpose(*out[m].dims)
        xr.align(out[m], da, join="exact")      # the same sweep: a mismatch is an error, never NaN
        out[m + "_theory"] = da.assign_attrs(long_name=f"{da.attrs['long_name']}, from the averaged theory")
    out.attrs.update(_settings_attrs(solved, cells_, spc, t_eval))
    return out
