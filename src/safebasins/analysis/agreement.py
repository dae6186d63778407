"""Agreement of safe sets: intersection over union, pixel agreement, criteria counts; of escape-probability maps.

One definition each, used by the pipeline (the IoU stored in the Figs 13-17 charts, the
Fig 19 counts), the first-harmonic comparison and the tests.
"""
from __future__ import annotations

from collections.abc import Hashable, Sequence
from typing import Any, Literal, overload

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.core import cf
from safebasins.analysis.safe import CRITERIA, check_chart, check_t_eval, is_safe

__all__ = ["iou", "pixel_agreement", "mask_agreement", "criteria_counts", "criteria_table", "chart_agreement",
           "probability_agreement"]


def _boolean(name, a):
    dtype = a.dtype if isinstance(a, xr.DataArray) else np.asarray(a).dtype
    if dtype.kind != "b":
        raise ValueError(f"{name} must be a boolean mask (True = safe), got dtype {dtype}")


def _pair(a, b, dims, names=("a", "b")):
    _boolean(names[0], a)
    _boolean(names[1], b)
    if isinstance(a, xr.DataArray) or isinstance(b, xr.DataArray):
        for name, m in zip(names, (a, b)):
            if not isinstance(m, xr.DataArray):
                raise ValueError(f"{name} must be a DataArray like the other mask (or give two numpy arrays)")
            missing = [d for d in dims if d not in m.dims]
            if missing:
                raise ValueError(f"{name} has no dimension {missing[0]!r} to reduce over (dims: {m.dims}); name the "
                                 f"grid dims with dims= (default ('q0', 'p0'))")
        try:
            a, b = xr.align(a, b, join="exact")
        except ValueError as exc:
            raise ValueError(f"{names[0]} and {names[1]} must share their coordinates ({exc})") from None
        n = int(np.prod([a.sizes[d] for d in dims]))
    else:
        for name, m in zip(names, (a, b)):
            nd = np.ndim(m)
            if any(not isinstance(d, (int, np.integer)) or not -nd <= d < nd for d in dims):
                raise ValueError(f"{name} with shape {np.shape(m)} has no axes {tuple(dims)} to reduce over (numpy "
                                 "masks: the (q0, p0) grid is the last two axes)")
        try:
            a, b = np.broadcast_arrays(np.asarray(a), np.asarray(b))
        except ValueError as exc:
            raise ValueError(f"masks must have broadcastable shapes, got {np.shape(a)} and {np.shape(b)}") from exc
        n = int(np.prod([a.shape[d] for d in dims])) if a.ndim else 0
    if n == 0:
        raise ValueError("masks must not be empty: agreement over no points is undefined")
    return a, b


@overload
def iou(a: xr.DataArray, b: xr.DataArray, dims: Sequence[Hashable] = ("q0", "p0"), *,
        names: tuple[str, str] = ("a", "b")) -> xr.DataArray: ...


@overload
def iou(a: npt.ArrayLike, b: npt.ArrayLike, dims: Sequence[Hashable] = ("q0", "p0"), *,
        names: tuple[str, str] = ("a", "b")) -> npt.NDArray[np.float64]: ...


def iou(a: Any, b: Any, dims: Sequence[Hashable] = ("q0", "p0"), *,
        names: tuple[str, str] = ("a", "b")) -> xr.DataArray | npt.NDArray[np.float64]:
    """Intersection over union ``|A and B| / |A or B|`` of two boolean masks (1 when both are
    empty: perfect agreement).  DataArrays reduce over the named ``dims``; numpy arrays over the
    axes ``dims`` (default: the last two)."""
    if not isinstance(a, xr.DataArray) and not isinstance(b, xr.DataArray) and dims == ("q0", "p0"):
        dims = (-2, -1)
    a, b = _pair(a, b, dims, names)
    if isinstance(a, xr.DataArray):
        inter = (a & b).sum(dims)
        union = (a | b).sum(dims)
        return xr.where(union > 0, inter / union.where(union > 0, 1), 1.0).astype(float)
    inter = (a & b).sum(axis=dims)
    union = (a | b).sum(axis=dims)
    return np.where(union > 0, inter / np.maximum(union, 1), 1.0)


@overload
def pixel_agreement(a: xr.DataArray, b: xr.DataArray, dims: Sequence[Hashable] = ("q0", "p0"), *,
                    names: tuple[str, str] = ("a", "b")) -> xr.DataArray: ...


@overload
def pixel_agreement(a: npt.ArrayLike, b: npt.ArrayLike, dims: Sequence[Hashable] = ("q0", "p0"), *,
                    names: tuple[str, str] = ("a", "b")) -> npt.NDArray[np.float64]: ...


def pixel_agreement(a: Any, b: Any, dims: Sequence[Hashable] = ("q0", "p0"), *,
                    names: tuple[str, str] = ("a", "b")) -> xr.DataArray | npt.NDArray[np.float64]:
    """Fraction of grid points on which two boolean masks agree."""
    if not isinstance(a, xr.DataArray) and not isinstance(b, xr.DataArray) and dims == ("q0", "p0"):
        dims = (-2, -1)
    a, b = _pair(a, b, dims, names)
    if isinstance(a, xr.DataArray):
        return (a == b).mean(dims).astype(float)
    return (a == b).mean(axis=dims)


def mask_agreement(analytic_safe: xr.DataArray, numeric_safe: xr.DataArray, dims: Sequence[Hashable] = ("q0", "p0")
                   ) -> tuple[xr.DataArray, xr.DataArray]:
    """``(iou, pixel_agreement)`` of two boolean safe masks (DataArrays), reduced over ``dims``."""
    names = ("analytic_safe", "numeric_safe")
    return (iou(analytic_safe, numeric_safe, dims, names=names),
            pixel_agreement(analytic_safe, numeric_safe, dims, names=names))


def criteria_counts(chart: xr.Dataset, t_eval: float, groups: int
                    ) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
    """Safe counts of the energy and displacement criteria on random ICs (paper Appendix, Fig 19).

    ``chart``: an escape chart over ``sample`` with one ``xi_max`` and one ``q_max`` threshold;
    its samples are split into ``groups`` consecutive equal groups (the repetitions).  Returns
    ``(A_E, A_q)``: int64 arrays of length ``groups``, the number of ICs that have not escaped by
    ``t_eval`` under the energy (ESB) and the displacement (DSB) criterion.
    """
    check_chart(chart)
    for var, thr in CRITERIA.values():
        if "sample" not in chart[var].dims:
            raise ValueError(f"chart must be an escape chart of paired ICs (dim 'sample', numerics.escape_chart "
                             f"with grid=False), got {var} with dims {chart[var].dims}")
        if chart.sizes.get(thr, 0) < 1:
            raise ValueError(f"chart has no {thr} threshold: criteria counts need one xi_max and one q_max")
    if check_t_eval(t_eval, chart.attrs.get("cycles")).ndim:
        raise ValueError(f"t_eval must be one evaluation time here, got {t_eval!r}")
    n = chart.sizes["sample"]
    if isinstance(groups, bool) or not isinstance(groups, (int, np.integer)) or groups < 1 or n % groups:
        raise ValueError(f"groups must divide the {n} samples into equal repetitions, got {groups}")
    out = []
    for crit in ("energy", "displacement"):
        var, thr = CRITERIA[crit]
        s = np.asarray(is_safe(chart[var].isel({thr: 0}).values, t_eval))
        out.append(s.reshape(groups, n // groups).sum(axis=1).astype(np.int64))
    return out[0], out[1]


def criteria_table(charts: Sequence[xr.Dataset], F: Sequence[float] | npt.NDArray[np.float64], *, n_ic: int,
                   repeats: int, seeds: Sequence[int] | npt.NDArray[np.integer[Any]], cycles: float) -> xr.Dataset:
    """Energy versus displacement criterion (paper Appendix, Fig 19): ``A_E``, ``A_q`` (safe counts
    at ``cycles``) and ``rel_diff = (A_q - A_E) / A_E`` over ``(F, repeat)``, from one escape chart
    per F over ``n_ic * repeats`` random samples (``repeats`` consecutive groups of ``n_ic``,
    seeded by ``seeds``)."""
    A_E = np.zeros((len(charts), repeats), dtype=np.int64)
    A_q = np.zeros((len(charts), repeats), dtype=np.int64)
    for i, ds in enumerate(charts):
        if ds.sizes["sample"] != n_ic * repeats:
            raise ValueError(f"chart {i}: {ds.sizes['sample']} samples, expected n_ic * repeats = {n_ic * repeats}")
        A_E[i], A_q[i] = criteria_counts(ds, cycles, repeats)
        print(f"F={F[i]}: A_E={A_E[i].tolist()} A_q={A_q[i].tolist()}", flush=True)
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(A_E > 0, (A_q - A_E) / np.maximum(A_E, 1), np.nan)
    return xr.Dataset(
        {"A_E": (("F", "repeat"), A_E), "A_q": (("F", "repeat"), A_q), "rel_diff": (("F", "repeat"), rel)},
        coords={"F": ("F", np.asarray(F, dtype=float)), "repeat": ("repeat", np.arange(repeats)),
                "seed": ("repeat", np.asarray(seeds, dtype=np.int64))},
    )


def chart_agreement(chart: xr.Dataset, basin: xr.Dataset, t_eval: float, scan: Literal["xi_max", "F"]) -> xr.Dataset:
    """The escape chart with its agreement with the analytic basin, per value of ``scan``.

    numeric safe = ``escape_cycle_energy > t_eval``; analytic safe = not ``escapes``
    (slow_flow_escapes); ``chart`` and ``basin`` on the same (q0, p0) grid and ``scan`` values
    ("xi_max": one chart serves every threshold; "F": stacked charts with one threshold).
    Adds ``iou``, ``pixel_agreement``, ``safe_analytic``, ``safe_numeric`` (over ``scan``) and
    the attributes ``agreement_t_eval``, ``agreement_definition``, ``iou_mean``, ``iou_min``,
    ``pixel_agreement_mean``, ``pixel_agreement_min``."""
    numeric_safe = is_safe(chart["escape_cycle_energy"], t_eval)
    if scan == "F":
        numeric_safe = numeric_safe.isel(xi_max=0, drop=True)
    analytic_safe = ~basin["escapes"].astype(bool).reset_coords(drop=True)  # no saddle_* coords in the chart
    numeric_safe = numeric_safe.reset_coords(drop=True)
    for ax in ("q0", "p0"):
        a, n = np.asarray(analytic_safe[ax].values), np.asarray(numeric_safe[ax].values)
        if a.shape != n.shape or not np.allclose(a, n, rtol=0, atol=1e-12):
            raise ValueError(f"analytic and numeric grids differ along {ax}")
    a, n = np.asarray(analytic_safe[scan].values, float), np.asarray(numeric_safe[scan].values, float)
    if a.shape != n.shape or not np.allclose(a, n, rtol=1e-12, atol=0):
        raise ValueError(f"analytic and numeric {scan} values differ: {a} vs {n}")
    analytic_safe = analytic_safe.assign_coords({c: numeric_safe[c] for c in ("q0", "p0", scan)})
    analytic_safe = analytic_safe.transpose(*numeric_safe.dims)
    i, pixel = mask_agreement(analytic_safe, numeric_safe)
    out = chart.copy()
    # fresh attributes (the CF table fills them): arithmetic would pass on those of its operands
    out["iou"] = i.drop_attrs(deep=False)
    out["pixel_agreement"] = pixel.drop_attrs(deep=False)
    out["safe_analytic"] = analytic_safe.sum(("q0", "p0")).astype(np.int64).drop_attrs(deep=False)
    out["safe_numeric"] = numeric_safe.sum(("q0", "p0")).astype(np.int64).drop_attrs(deep=False)
    out.attrs.update(
        agreement_t_eval=t_eval,
        agreement_definition=("numeric safe = escape_cycle_energy > t_eval (= cycles); analytic safe = not "
                              "escapes (slow_flow_escapes); iou = |A and N| / |A or N|; pixel_agreement = "
                              "mean(A == N) over the (q0, p0) grid"),
        iou_mean=float(i.mean()), iou_min=float(i.min()),
        pixel_agreement_mean=float(pixel.mean()), pixel_agreement_min=float(pixel.min()),
    )
    for v, a_, px in zip(np.atleast_1d(i[scan].values), np.atleast_1d(i.values), np.atleast_1d(pixel.values)):
        print(f"{scan} = {v}: IoU = {a_:.4f}, pixel agreement = {px:.4f}")
    return out


def probability_agreement(theory: xr.Dataset, numeric: xr.Dataset) -> xr.Dataset:
    """Agreement of two escape-probability maps on the same initial conditions and ``t_eval``:
    ``theory`` (theory.escape_probability) and ``numeric`` (numerics.escape_probability, with its
    Wilson interval).

    Returns ``numeric`` with ``P_escape_theory`` and, over ``t_eval``, ``P_escape_mean_abs_difference``
    and ``P_escape_max_abs_difference`` (mean and maximum of ``|P_theory - P_numeric|`` over the ICs),
    and the attributes ``P_escape_mean_abs_difference`` / ``P_escape_max_abs_difference`` (over ICs
    and t_eval), the same mean over the ICs not certain to escape (``P_escape = 1`` in both at every
    t_eval; the ICs at or beyond the threshold, which agree trivially) as
    ``P_escape_mean_abs_difference_uncertain``, the fraction of (IC, t_eval) where the theory lies in
    the numerics' 95% Wilson interval (``P_escape_theory_within_wilson``) and ``agreement_definition``."""
    for name, ds in (("theory", theory), ("numeric", numeric)):
        if not isinstance(ds, xr.Dataset) or "P_escape" not in ds or "t_eval" not in ds["P_escape"].dims:
            raise ValueError(f"{name} must be an escape-probability Dataset with P_escape over t_eval")
    pt, pn = theory["P_escape"], numeric["P_escape"]
    if set(pt.dims) != set(pn.dims):
        raise ValueError(f"theory and numeric P_escape have different dims: {pt.dims} vs {pn.dims}")
    for c in pn.dims:
        for coord in [c] + [k for k in ("q0", "p0") if k in numeric.coords and c in numeric[k].dims and k != c]:
            a, b = np.asarray(theory[coord].values, float), np.asarray(numeric[coord].values, float)
            if a.shape != b.shape or not np.allclose(a, b, rtol=1e-12, atol=1e-12):
                raise ValueError(f"theory and numeric differ along {coord}")
    pt = pt.reset_coords(drop=True).assign_coords({c: numeric[c] for c in pn.dims}).transpose(*pn.dims)
    ic = [d for d in pn.dims if d != "t_eval"]
    diff = abs(pt - pn.reset_coords(drop=True))
    certain = ((pt == 1) & (pn == 1)).all("t_eval")
    out = numeric.copy()
    for name, da in (("P_escape_theory", pt), ("P_escape_mean_abs_difference", diff.mean(ic)),
                     ("P_escape_max_abs_difference", diff.max(ic))):
        out[name] = da.drop_attrs(deep=False).assign_attrs(cf.attrs(name))
    uncertain = diff.where(~certain)
    attrs = {"P_escape_mean_abs_difference": float(diff.mean()), "P_escape_max_abs_difference": float(diff.max()),
             "P_escape_mean_abs_difference_uncertain": float(uncertain.mean()) if bool((~certain).any()) else 0.0,
             "agreement_definition": ("|P_escape_theory - P_escape| over the initial conditions (mean, max) per "
                                      "t_eval; the attributes over ICs and t_eval, _uncertain without the ICs whose "
                                      "P_escape is 1 in both at every t_eval")}
    if "P_escape_low" in numeric and "P_escape_high" in numeric:
        inside = (pt >= numeric["P_escape_low"].reset_coords(drop=True)) & (
            pt <= numeric["P_escape_high"].reset_coords(drop=True))
        attrs["P_escape_theory_within_wilson"] = float(inside.mean())
    out.attrs.update(attrs)
    return out
