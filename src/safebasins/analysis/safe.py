"""Safe basins read from escape charts: the one definition ``safe = escape_cycle > t_eval``.

An escape chart (:func:`safebasins.numerics.escape_chart`) stores the first escape time of
every initial condition for every threshold (``+inf`` = no escape within the horizon); the
safe basin for a threshold and an evaluation time ``t_eval <= cycles`` is the set of ICs that
have not escaped by then.  Every reader of charts (agreement, integrity, erosion, phase-invariant
basins, criteria counts, figures) goes through :func:`is_safe`.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal, overload

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.core import checks
from safebasins.core import cf
from safebasins.wells import from_attrs, QuarticWell
from safebasins.wells.base import Well

__all__ = ["is_safe", "check_t_eval", "check_chart", "safe_mask", "safe_area", "safe_stack", "escape_variable",
           "chart_well", "displacement_energy", "q_max_energy"]

#: a threshold criterion of escape charts
Criterion = Literal["energy", "displacement"]
#: those two or the asymmetric displacement bounds ``q_bounds`` (charts made with ``q_bounds``)
AnyCriterion = Literal["energy", "displacement", "bounds"]
#: escape-time variable and threshold dimension of each criterion
CRITERIA = {"energy": ("escape_cycle_energy", "xi_max"),
            "displacement": ("escape_cycle_displacement", "q_max")}
#: the asymmetric displacement criterion q_lower < q < q_upper (charts made with ``q_bounds``)
BOUNDS = ("escape_cycle_bounds", "q_bounds")


@overload
def is_safe(escape_cycle: xr.DataArray, t_eval: npt.ArrayLike | xr.DataArray) -> xr.DataArray: ...


@overload
def is_safe(escape_cycle: npt.NDArray[Any], t_eval: npt.ArrayLike) -> npt.NDArray[np.bool_]: ...


def is_safe(escape_cycle: xr.DataArray | npt.NDArray[Any], t_eval: npt.ArrayLike | xr.DataArray
            ) -> xr.DataArray | npt.NDArray[np.bool_]:
    """``escape_cycle > t_eval``: not escaped by ``t_eval`` (numpy arrays or DataArrays)."""
    return escape_cycle > t_eval


def escape_variable(chart: xr.Dataset, criterion: AnyCriterion) -> tuple[xr.DataArray, str]:
    """(escape-time DataArray, threshold dimension) of ``criterion`` ("energy" | "displacement" |
    "bounds": the asymmetric displacement bounds ``q_bounds`` of the chart)."""
    known = {**CRITERIA, "bounds": BOUNDS}
    if criterion not in known:
        raise ValueError(f"criterion must be one of {sorted(known)}, got {criterion!r}")
    var, thr = known[criterion]
    check_chart(chart, variables=())
    if var not in chart:
        raise ValueError(f"criterion {criterion!r}: the chart has no {var!r} (make it with the thresholds "
                         f"{thr!r} of numerics.escape_chart)")
    return chart[var], thr


_CHART_VARIABLES = tuple(v for v, _ in CRITERIA.values())


def check_chart(chart: Any, name: str = "chart", variables: Sequence[str] = _CHART_VARIABLES) -> xr.Dataset:
    """``chart`` is an escape chart Dataset (numerics.escape_chart) with ``variables``; ValueError
    naming ``name`` otherwise."""
    if not isinstance(chart, xr.Dataset):
        raise ValueError(f"{name} must be an escape chart (an xarray Dataset from numerics.escape_chart), "
                         f"got {type(chart).__name__}")
    missing = [v for v in variables if v not in chart]
    if missing:
        raise ValueError(f"{name} is not an escape chart: it has no {', '.join(map(repr, missing))} (variables: "
                         f"{sorted(map(str, chart.data_vars)) or 'none'}); make it with numerics.escape_chart")
    return chart


def chart_well(chart: xr.Dataset) -> Well:
    """The well an escape chart was integrated in (its ``well`` attributes, written by
    ``numerics.escape_chart``); ValueError when the chart does not name one."""
    if "well" not in chart.attrs:
        raise ValueError("the chart names no well (attribute 'well', written by numerics.escape_chart): "
                         "cannot tell its unforced safe set")
    return from_attrs(chart.attrs)


def displacement_energy(well: Well, q_lower: npt.ArrayLike, q_upper: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """Energy of the unforced safe set of a displacement criterion ``q_lower < q < q_upper``.

    An unforced orbit of energy E stays inside the bounds iff its turning points do,
    ``q_lower < q_minus(E)`` and ``q_plus(E) < q_upper``; V increases away from the bottom up to
    each barrier, so this is ``E < min(V(q_lower), V(q_upper))``: the set is S0 of that energy.
    The symmetric ``|q| < q_max`` is ``(-q_max, q_max)``; for the quartic it is V(q_max), the
    inverse of eq (4).  Bounds must satisfy ``q_left <= q_lower < 0 < q_upper <= q_right`` (the
    barriers of the well).
    """
    lo = checks.check_finite("q_lower", q_lower)
    hi = checks.check_finite("q_upper", q_upper)
    if not ((lo < 0).all() and (hi > 0).all()):
        raise ValueError(f"displacement bounds must satisfy q_lower < 0 < q_upper (the well bottom inside), "
                         f"got q_lower={lo.tolist()}, q_upper={hi.tolist()}")
    ql, qr = well.barriers
    if (lo < ql).any() or (hi > qr).any():
        raise ValueError(f"displacement bounds must lie inside the barriers ({ql!r}, {qr!r}) of the {well.name} "
                         f"well, got q_lower={lo.tolist()}, q_upper={hi.tolist()}")
    return np.minimum(well.V(lo), well.V(hi))


def q_max_energy(well: Well, q_max: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """Energy of the unforced safe set of the symmetric criterion ``|q| < q_max``:
    :func:`displacement_energy` of ``(-q_max, q_max)``; for the quartic its closed form
    ``V(q_max)`` (eq (4) inverted, ``QuarticWell.xi_from_q_max``: both sides are equal, and
    evaluating V(-q_max) separately could differ from V(q_max) in the last bit)."""
    if isinstance(well, QuarticWell):
        return well.xi_from_q_max(well.check_displacement("q_max", q_max))
    qm = checks.as_array("q_max", q_max)
    return displacement_energy(well, -qm, qm)


def check_t_eval(t_eval: npt.ArrayLike, cycles: float | None) -> npt.NDArray[np.float64]:
    """Validated evaluation times (scalar or 1-D, forcing cycles), each <= the horizon ``cycles``."""
    t = checks.check_nonempty("t_eval", checks.check_nonnegative("t_eval", t_eval))
    if t.ndim > 1:
        raise ValueError(f"t_eval must be a scalar or 1-D, got shape {t.shape}")
    if cycles is not None and (t > float(cycles) * (1 + 1e-12)).any():
        raise ValueError(f"t_eval must be <= the chart's horizon cycles = {cycles} (the chart knows nothing "
                         f"beyond it), got max {float(t.max())!r}")
    return t


def _t_eval_array(t, name="t_eval"):
    return xr.DataArray(t, dims=(name,) if t.ndim else (), name=name, attrs=cf.attrs("t_eval"))


def safe_mask(chart: xr.Dataset, t_eval: npt.ArrayLike) -> xr.Dataset:
    """Safe basins of an escape chart at evaluation time(s) ``t_eval`` (cycles, <= chart cycles).

    Returns a Dataset with bool ``safe_energy`` (xi_max, ...) and ``safe_displacement``
    (q_max, ...).  A 1-D t_eval adds a leading dim ``t_eval``; a scalar gives a scalar coordinate.
    """
    t = check_t_eval(t_eval, check_chart(chart).attrs.get("cycles"))
    tda = _t_eval_array(t)
    out = xr.Dataset({f"safe_{c}": is_safe(chart[CRITERIA[c][0]], tda) for c in CRITERIA})
    out = out.assign_coords(t_eval=tda)
    if "t_eval" in out.dims:
        out = out.transpose("t_eval", ...)
    for c in CRITERIA:
        out[f"safe_{c}"].attrs = {"long_name": f"safe (no {c} escape up to t_eval)"}
    out.attrs.update({k: chart.attrs[k] for k in ("F", "Omega", "Psi", "cycles",
                                                  "steps_per_cycle") if k in chart.attrs})
    return out


def _cell_widths(name, x):
    x = np.asarray(x, dtype=float)
    if x.size < 2:
        raise ValueError(f"{name} must have at least 2 grid points to define a cell area, got {x.size}")
    w = np.empty_like(x)
    w[1:-1] = 0.5 * (x[2:] - x[:-2])
    w[0] = x[1] - x[0]
    w[-1] = x[-1] - x[-2]
    return np.abs(w)


def safe_area(chart: xr.Dataset, t_eval: npt.ArrayLike) -> xr.Dataset:
    """Safe-basin size versus evaluation time, vectorised over t_eval.

    Returns a Dataset with ``pixels_energy`` (t_eval?, xi_max) and ``pixels_displacement``
    (t_eval?, q_max): number of safe ICs; ``area_*``: phase-space area (sum of the cells
    dq0 * dp0 of the safe grid points), NaN for paired ICs; ``fraction_*``: pixels / ICs.
    A grid axis with a single point has no cell size: ValueError.
    """
    m = safe_mask(chart, t_eval)
    is_grid = "q0" in chart.dims and "p0" in chart.dims
    dims = ("q0", "p0") if is_grid else ("sample",)
    n = int(np.prod([chart.sizes[d] for d in dims]))
    out = xr.Dataset(coords={"t_eval": m["t_eval"]})
    if is_grid:
        w = xr.DataArray(np.outer(_cell_widths("q0", chart["q0"].values), _cell_widths("p0", chart["p0"].values)),
                         dims=dims)
    for kind in CRITERIA:
        s = m[f"safe_{kind}"]
        pix = s.sum(dims)
        out[f"pixels_{kind}"] = pix.astype(np.int64)
        out[f"pixels_{kind}"].attrs = {"units": "1", "long_name": f"number of safe ICs ({kind} criterion)"}
        out[f"fraction_{kind}"] = pix / n
        out[f"fraction_{kind}"].attrs = {"units": "1", "long_name": f"safe fraction of the ICs ({kind} criterion)"}
        area = (s * w).sum(dims) if is_grid else pix * np.nan
        out[f"area_{kind}"] = area
        out[f"area_{kind}"].attrs = {"units": "1", "long_name": f"safe area in the (q0, p0) plane ({kind} criterion)"}
    if "t_eval" in out.dims:
        out = out.transpose("t_eval", ...)
    out.attrs.update(m.attrs)
    return out


def safe_stack(chart: xr.Dataset, t_eval: npt.ArrayLike | None = None, criterion: AnyCriterion = "energy"
               ) -> tuple[xr.DataArray, xr.DataArray]:
    """Safe masks with a leading dimension ``t_eval`` (default: the chart horizon).

    Returns ``(safe (t_eval, ..., q0, p0), xi_norm)`` where ``xi_norm`` is the energy that
    normalises integrity measures: the ``xi_max`` coordinate, or the energy of the unforced set
    of the displacement thresholds in the chart's well (:func:`q_max_energy`,
    :func:`displacement_energy`: V(q_max) for the quartic; the set ``{max |q(t)| < q_max}`` is
    S0(V(q_max))).
    """
    esc, thr = escape_variable(chart, criterion)
    if not {"q0", "p0"} <= set(esc.dims):
        raise ValueError(f"chart must be an escape chart on a (q0, p0) grid (integrity needs a grid), got dims "
                         f"{esc.dims}")
    cycles: Any = chart.attrs.get("cycles")
    t = np.atleast_1d(check_t_eval(float(cycles) if t_eval is None else t_eval, cycles)).astype(float)
    tda = xr.DataArray(t, dims="t_eval", coords={"t_eval": t},
                       attrs=cf.attrs("t_eval"))
    safe = is_safe(esc, tda).transpose("t_eval", ..., "q0", "p0")
    if thr == "xi_max":
        xi_norm = safe["xi_max"]
    elif thr == "q_max":
        qm = safe["q_max"].values
        xi_norm = xr.DataArray(q_max_energy(chart_well(chart), qm), dims=safe["q_max"].dims,
                               coords={"q_max": safe["q_max"]})
    else:
        e = displacement_energy(chart_well(chart), chart["q_lower"].values, chart["q_upper"].values)
        xi_norm = xr.DataArray(e, dims=("q_bounds",), coords={"q_bounds": safe["q_bounds"]})
    return safe, xi_norm
