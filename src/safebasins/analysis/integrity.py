"""Dynamical integrity of safe basins: GIM, LIM and IF on a ``(q0, p0)`` grid.

A safe basin (SB) is given as a boolean mask over a uniform grid of initial
conditions ``(q0, p0)`` (``ij`` indexing: first grid axis ``q0``), analytic
(``~theory.slow_flow_escapes``) or numeric (``escape_cycle > t_eval`` of
``numerics.escape_chart``).  Three integrity measures (Soliman & Thompson; Lenci &
Rega) quantify how much of it is left:

GIM
    global integrity measure: the safe *area*.
LIM
    local integrity measure: radius of the largest disk centred at the well bottom
    ``(0, 0)`` that fits in the basin (0 if the bottom itself is not safe).
IF
    integrity factor: radius of the largest disk centred *anywhere* that fits in
    the basin (robust against thin fractal fingers, unlike GIM).

Normalisation
-------------
Each measure is divided by its value for the *unforced* safe set of the well
(``well.unforced_safe``; :func:`integrity_measures` needs ``well=`` for it unless the mask's
attributes name the well: a mask alone does not tell which well it is a basin of)

    S0(xi_max) = {H0(q0, p0) < xi_max,  q_minus(xi_max) < q0 < q_plus(xi_max)}   (eqs 4, 7)

(for the quartic ``q_plus = -q_minus = q_max(xi_max)``), computed on the *same grid with the
same estimator*, so resolution biases largely cancel and ``GIM = LIM = IF = 1`` at ``F = 0``.
Analytic unforced values (:func:`unforced_radii2`): the boundary of S0 is the orbit
``p = +-sqrt(2 (xi - V(q)))``, so the squared distance from ``(c, 0)`` to it is
``(q - c)^2 + 2 xi - 2 V(q)`` and

    r_local^2  = 2 xi - max_q (2 V(q) - q^2),
    r_global^2 = 2 xi - min_c max_q (2 V(q) - (q - c)^2)     (q, c in [q_minus, q_plus])

(S0 is symmetric in p with interval slices, so the largest disk has its centre on p = 0).  For
the quartic ``2 V(q) - q^2 = -q^4/2 <= 0``: both radii are ``sqrt(2 xi_max)`` (the half-width
``sqrt(2 xi - q^2 + q^4/2)`` of S0 decreases with ``|q|``); for an asymmetric well (the cubic)
the nearest boundary point can be a turning point and the largest disk sits off the bottom.
The unforced area is ``2 * pi * J(xi_max)`` (eq 19: the action is the enclosed area over
2 pi).  For a displacement criterion ``q_lower < q < q_upper`` (``|q| < q_max``: the pair
``(-q_max, q_max)``) use ``xi_max = safebasins.analysis.safe.displacement_energy(well, q_lower,
q_upper)`` (= min V(q_lower), V(q_upper); V(q_max) for the quartic): the unforced set of the
criterion is exactly ``S0`` of that energy.

Estimators and grid-resolution error
------------------------------------
Pixels are the grid nodes; a node is safe or not (the mask samples the basin at
node centres).  The grid is padded by one ring of *unsafe* nodes, i.e. whatever
lies beyond the grid counts as not safe (make the grid cover the well).

* area = (number of safe nodes) * dq * dp.  Error <= area of the band of
  half-width one pixel diagonal around the basin boundary (~ perimeter * diagonal).
* LIM radius = Euclidean distance from the well bottom to the nearest *unsafe*
  node centre: the exact distance transform of the sampled complement evaluated at
  the bottom (which need not be a node); a vectorised minimum, no pixel loop.
  It is 0 when the node nearest to the bottom is unsafe.
* IF radius = maximum of ``scipy.ndimage.distance_transform_edt(mask,
  sampling=(dq, dp))`` (distance of each safe node to the nearest unsafe node).

For a basin whose boundary is resolved by the grid (features wider than a pixel)
both radii satisfy ``|r_estimated - r_true| <= diag = sqrt(dq^2 + dp^2)``: the
nearest unsafe node lies within one diagonal outside the true boundary and the
disk centre is restricted to nodes (loss <= diag / 2).  Basin features narrower
than a pixel are invisible at that resolution.  ``tests/test_integrity.py`` checks
these bounds on a disk, an annulus and two disjoint disks.

Stacks
------
Every function works on masks of shape ``(..., n_q0, n_p0)`` (stacks over F,
t_eval, thresholds, phases...) and on ``xarray.DataArray`` with dims
``(..., "q0", "p0")``, returning DataArrays/Datasets over the leading dims.
"""
from __future__ import annotations

from typing import overload

import numpy as np
import numpy.typing as npt
import xarray as xr
from scipy import ndimage

from safebasins.core import checks
from safebasins.wells import from_attrs, resolve_well, well_attrs
from safebasins.wells.base import WellLike

Array = npt.NDArray[np.float64]

__all__ = [
    "unforced_safe_mask",
    "unforced_radii2",
    "integrity_measures",
    "grid_spacing",
    "MEASURE_ATTRS",
]

MEASURE_ATTRS = {
    "GIM": {"units": "1", "long_name": "global integrity measure (safe area / unforced safe area)"},
    "LIM": {"units": "1", "long_name": "local integrity measure (radius of largest safe disk centred at the "
            "well bottom / unforced value)"},
    "IF": {"units": "1", "long_name": "integrity factor (radius of largest safe disk anywhere / unforced value)"},
    "area": {"units": "1", "long_name": "safe area in the (q0, p0) plane"},
    "r_local": {"units": "1", "long_name": "radius of the largest safe disk centred at the well bottom"},
    "r_global": {"units": "1", "long_name": "radius of the largest safe disk anywhere in the basin"},
    "if_q0": {"units": "1", "long_name": "q0 of the centre of the largest safe disk (NaN if the basin is empty)"},
    "if_p0": {"units": "1", "long_name": "p0 of the centre of the largest safe disk (NaN if the basin is empty)"},
    "area_unforced": {"units": "1", "long_name": "area of the unforced safe set H0 < xi_max on the same grid"},
    "r_local_unforced": {"units": "1", "long_name": "LIM radius of the unforced safe set on the same grid"},
    "r_global_unforced": {"units": "1", "long_name": "IF radius of the unforced safe set on the same grid"},
}

_RAW = ("area", "r_local", "r_global", "if_q0", "if_p0")


# --------------------------------------------------------------------------- basics
def grid_spacing(q0: npt.ArrayLike, p0: npt.ArrayLike) -> tuple[Array, Array, float, float]:
    """Validate 1-D, increasing, uniform grid axes; return ``(q0, p0, dq, dp)``."""
    out = []
    for name, ax in (("q0", q0), ("p0", p0)):
        a = checks.check_finite(name, ax)
        if a.ndim != 1 or a.size < 2:
            raise ValueError(f"{name} must be a 1-D grid axis with at least 2 points, got shape {a.shape}")
        d = np.diff(a)
        if (d <= 0).any():
            raise ValueError(f"{name} must be strictly increasing")
        if not np.allclose(d, d.mean(), rtol=1e-6, atol=0):
            raise ValueError(f"{name} must be uniformly spaced (distance transform needs one sampling step)")
        out.append((a, float(d.mean())))
    (q, dq), (p, dp) = out
    return q, p, dq, dp


def unforced_safe_mask(q0: npt.ArrayLike, p0: npt.ArrayLike, xi_max: npt.ArrayLike, well: WellLike = None
                       ) -> npt.NDArray[np.bool_]:
    """Unforced safe set S0 = {H0 < xi_max, q_minus < q0 < q_plus} (eqs 4, 7) on the grid: the
    well's ``unforced_safe`` (None: the paper's quartic, ``|q0| < q_max(xi_max)``).

    ``xi_max`` may be an array: the result has shape ``xi_max.shape + (n_q0, n_p0)``.
    """
    q, p, _, _ = grid_spacing(q0, p0)
    w = resolve_well(well)
    xi = w.check_threshold("xi_max", xi_max)
    Q, P = np.meshgrid(q, p, indexing="ij")
    return w.unforced_safe(Q, P, xi[..., None, None])


def unforced_radii2(xi: float, well: WellLike = None, *, n: int = 1001) -> tuple[float, float]:
    """Squared LIM and IF radii ``(r_local^2, r_global^2)`` of the unforced set S0(xi) of
    ``well`` (None: the quartic) from the orbit curve, not from a grid (module docstring).

    ``q`` runs over ``n`` equally spaced points of ``[q_minus(xi), q_plus(xi)]`` plus the bottom
    ``q = 0``; the centre ``c`` over the same points, then over ``n`` points within one spacing
    of the best one: ``r_local^2`` is accurate to ``O(h^2)``, ``r_global^2`` to
    ``O(h / n)`` (``h`` the spacing).  Both are exactly ``2 xi`` for the quartic (then
    ``2 V(q) - q^2 <= 0`` in floating point too, with equality at the bottom).  ``xi`` is a
    scalar in ``[0, barrier_energy]``.
    """
    w = resolve_well(well)
    xi = float(checks.check_scalar("xi", xi, checks.check_nonnegative))
    if xi > w.barrier_energy:
        raise ValueError(f"xi must be <= {w.barrier_energy!r} (the barrier energy of the {w.name} well), got {xi!r}")
    n = checks.check_positive_int("n", n)
    lo, hi = (float(np.asarray(t)) for t in w.turning_points(xi))
    q = np.union1d(np.linspace(lo, hi, n), [0.0])
    V2 = 2.0 * np.asarray(w.V(q), float)
    r_local2 = 2.0 * xi - float(np.max(V2 - q * q))

    # worst(c) = max_q (2 V(q) - (q - c)^2); k = argmin over c = q, then the min over c_fine
    best, k = _min_worst(V2, q, q, np.inf, -1)
    c_fine = np.union1d(np.linspace(q[max(k - 1, 0)], q[min(k + 1, q.size - 1)], n), [q[k]])
    r_global2 = 2.0 * xi - float(min(best, _min_worst(V2, q, c_fine, best, -1)[0]))
    return r_local2, r_global2


def _worst_rows(V2, q, c):
    """``worst(c) = max_q (V2 - (q - c)^2)`` per centre and the q index of each maximum."""
    M = V2[None, :] - (q[None, :] - c[:, None]) ** 2
    return np.max(M, axis=1), np.argmax(M, axis=1)


def _min_worst(V2, q, c, best, kbest, stride=32, chunk=128):
    """Smallest ``(worst(c_i), i)`` (lexicographic: the first index of the minimum, as
    ``np.argmin``) that beats ``(best, kbest)``, as ``(value, index)``; ``(best, kbest)`` if none.

    Exact (the values are those of the full ``(c, q)`` matrix, the same expression element by
    element; max and min select, they do not round): every ``stride``-th centre is evaluated in
    full; any other centre whose value at the maxima of its two evaluated neighbours (a lower
    bound of its max) already loses is skipped; the rest are evaluated in full."""
    nc = c.size
    if not np.isfinite(V2).all():          # NaN ordering: the plain matrix
        vals = _worst_rows(V2, q, c)[0]
        i = int(np.argmin(vals))
        return _lexmin(best, kbest, vals[i], i)
    sub = np.unique(np.concatenate([np.arange(0, nc, stride), [nc - 1]]))
    vals, arg = _worst_rows(V2, q, c[sub])
    i = int(np.argmin(vals))
    best, kbest = _lexmin(best, kbest, vals[i], int(sub[i]))
    rest = np.setdiff1d(np.arange(nc), sub)
    if rest.size == 0:
        return best, kbest
    pos = np.searchsorted(sub, rest)
    cr = c[rest]
    jl, jr = arg[pos - 1], arg[np.minimum(pos, sub.size - 1)]
    lb = np.maximum(V2[jl] - (q[jl] - cr) ** 2, V2[jr] - (q[jr] - cr) ** 2)
    todo = rest[~((lb > best) | ((lb == best) & (rest > kbest)))]
    for s in range(0, todo.size, chunk):
        idx = todo[s:s + chunk]
        v = _worst_rows(V2, q, c[idx])[0]
        i = int(np.argmin(v))
        best, kbest = _lexmin(best, kbest, v[i], int(idx[i]))
    return best, kbest


def _lexmin(best, kbest, v, i):
    if v < best or (v == best and i < kbest):
        return v, i
    return best, kbest


# --------------------------------------------------------------------------- core
def _padded_axes(q, p, dq, dp):
    qp = np.concatenate([[q[0] - dq], q, [q[-1] + dq]])
    pp = np.concatenate([[p[0] - dp], p, [p[-1] + dp]])
    return qp, pp


def _raw_measures(stack, q, p, dq, dp, bottom):
    """stack: bool (N, nq, np). Returns dict of float arrays (N,)."""
    n = stack.shape[0]
    qp, pp = _padded_axes(q, p, dq, dp)
    Qp, Pp = np.meshgrid(qp, pp, indexing="ij")
    dist_bottom = np.hypot(Qp - bottom[0], Pp - bottom[1])
    # node nearest to the bottom (in padded indices)
    ib = int(np.argmin(np.abs(qp - bottom[0])))
    jb = int(np.argmin(np.abs(pp - bottom[1])))

    area = stack.sum(axis=(-2, -1)).astype(float) * dq * dp
    r_local = np.empty(n)
    r_global = np.empty(n)
    cq = np.full(n, np.nan)
    cp = np.full(n, np.nan)
    padded = np.zeros((stack.shape[1] + 2, stack.shape[2] + 2), dtype=bool)
    for k in range(n):  # one C-level distance transform per mask, not a pixel loop
        padded[1:-1, 1:-1] = stack[k]
        if padded[ib, jb]:
            r_local[k] = float(np.min(dist_bottom[~padded]))
        else:
            r_local[k] = 0.0
        if padded.any():
            edt = ndimage.distance_transform_edt(padded, sampling=(dq, dp))
            idx = int(np.argmax(edt))
            i, j = np.unravel_index(idx, edt.shape)
            r_global[k] = float(edt[i, j])
            cq[k], cp[k] = qp[i], pp[j]
        else:
            r_global[k] = 0.0
    return {"area": area, "r_local": r_local, "r_global": r_global, "if_q0": cq, "if_p0": cp}


def _ratio(a, b):
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(b > 0, a / np.where(b > 0, b, 1.0), np.nan)


def _measures_numpy(safe, q0, p0, xi_max, bottom, well=None):
    safe = np.asarray(safe)
    if safe.dtype != bool:
        raise ValueError(f"safe must be a boolean mask, got dtype {safe.dtype}")
    q, p, dq, dp = grid_spacing(q0, p0)
    if safe.ndim < 2 or safe.shape[-2:] != (q.size, p.size):
        raise ValueError(f"safe must have shape (..., {q.size}, {p.size}) matching (q0, p0), got {safe.shape}")
    lead = safe.shape[:-2]
    stack = safe.reshape((-1,) + safe.shape[-2:])
    raw = _raw_measures(stack, q, p, dq, dp, bottom)
    out = {k: v.reshape(lead) for k, v in raw.items()}

    if xi_max is not None:
        if well is None:
            raise ValueError("well is required to normalise GIM, LIM and IF: the unforced safe set S0(xi_max) "
                             "depends on the well, and the mask does not name one (a DataArray may carry its "
                             "well in the attributes 'well', ...). Pass well='quartic' for the paper's well, or "
                             "well=safebasins.analysis.safe.chart_well(chart) for an escape chart's")
        xi = resolve_well(well).check_threshold("xi_max", xi_max)
        try:
            xi_b = np.broadcast_to(xi, lead)
        except ValueError as exc:
            raise ValueError(f"xi_max with shape {xi.shape} does not broadcast to the leading mask shape "
                             f"{lead}") from exc
        uniq, inv = np.unique(xi_b, return_inverse=True)
        ref = _raw_measures(unforced_safe_mask(q, p, uniq, well), q, p, dq, dp, bottom)
        inv = inv.reshape(lead)
        out["area_unforced"] = ref["area"][inv]
        out["r_local_unforced"] = ref["r_local"][inv]
        out["r_global_unforced"] = ref["r_global"][inv]
        out["GIM"] = _ratio(out["area"], out["area_unforced"])
        out["LIM"] = _ratio(out["r_local"], out["r_local_unforced"])
        out["IF"] = _ratio(out["r_global"], out["r_global_unforced"])
    return out


@overload
def integrity_measures(safe: xr.DataArray, q0: npt.ArrayLike | None = None, p0: npt.ArrayLike | None = None,
                       xi_max: npt.ArrayLike | xr.DataArray | None = None, *,
                       bottom: tuple[float, float] = (0.0, 0.0), well: WellLike = None) -> xr.Dataset: ...


@overload
def integrity_measures(safe: npt.ArrayLike, q0: npt.ArrayLike | None = None, p0: npt.ArrayLike | None = None,
                       xi_max: npt.ArrayLike | None = None, *,
                       bottom: tuple[float, float] = (0.0, 0.0), well: WellLike = None) -> dict[str, Array]: ...


def integrity_measures(safe: xr.DataArray | npt.ArrayLike, q0: npt.ArrayLike | None = None,
                       p0: npt.ArrayLike | None = None, xi_max: npt.ArrayLike | xr.DataArray | None = None, *,
                       bottom: tuple[float, float] = (0.0, 0.0), well: WellLike = None
                       ) -> xr.Dataset | dict[str, Array]:
    """GIM, LIM and IF of safe-basin masks (see the module docstring for definitions and errors).

    Parameters
    ----------
    safe : bool array ``(..., n_q0, n_p0)`` or ``xr.DataArray`` with dims ``(..., "q0", "p0")``
        True = safe initial condition.  Leading dimensions are a stack (F, t_eval,
        xi_max, Psi, ...); each mask is measured separately.
    q0, p0 : 1-D uniform grid axes.  Taken from the DataArray coordinates when omitted.
    xi_max : energy threshold(s) for the normalisation, broadcastable to the leading
        shape (numpy) or a scalar / DataArray over leading dims (xarray).  For a
        DataArray it defaults to its ``xi_max`` coordinate (a dimension or a scalar
        coordinate).  ``None`` with numpy input: only the raw measures are returned.
    bottom : the well bottom (centre of the LIM disk), default ``(0, 0)``.
    well : the potential well of the normalising unforced set (any form of safebasins.wells:
        ``"quartic"`` for the paper's well).  Required whenever the measures are normalised
        (``xi_max`` given or a coordinate) unless ``safe`` is a DataArray whose attributes name
        its well (``well``, ``well_coefficients``, ...: :func:`safebasins.wells.spec_attrs`); a
        mask carries no trace of its well, and the quartic's S0 would silently misnormalise the
        basin of another well (for a chart: ``safebasins.analysis.safe.chart_well(chart)``).

    Returns
    -------
    numpy input: dict of arrays over the leading shape; DataArray input: ``xr.Dataset``
    over the leading dims.  Keys/variables: ``GIM``, ``LIM``, ``IF`` (normalised),
    ``area``, ``r_local``, ``r_global`` (raw), ``if_q0``, ``if_p0`` (centre of the IF
    disk), ``area_unforced``, ``r_local_unforced``, ``r_global_unforced``
    (normalisers on the same grid).  Radii are accurate to one pixel diagonal.
    """
    if isinstance(safe, xr.DataArray):
        return _measures_xarray(safe, q0, p0, xi_max, bottom, well)
    if q0 is None or p0 is None:
        raise ValueError("q0 and p0 are required for a numpy mask")
    return _measures_numpy(safe, q0, p0, xi_max, bottom, well)


def _mask_well(safe, well):
    """``well``, or the well the mask's attributes name (``wells.spec_attrs``); ValueError naming
    ``well`` when both are given and differ."""
    if "well" not in safe.attrs:
        return well
    if well is None:
        return from_attrs(safe.attrs)
    given = well_attrs(resolve_well(well))["well"]
    if given != safe.attrs["well"]:
        raise ValueError(f"well: the mask names the {safe.attrs['well']} well (attribute 'well'), not the {given} "
                         "well given")
    return well


def _measures_xarray(safe, q0, p0, xi_max, bottom, well):
    for d in ("q0", "p0"):
        if d not in safe.dims:
            raise ValueError(f"safe must have dims (..., 'q0', 'p0'), got {safe.dims}")
    well = _mask_well(safe, well)
    safe = safe.transpose(..., "q0", "p0")
    q = safe["q0"].values if q0 is None else q0
    p = safe["p0"].values if p0 is None else p0
    lead_dims = safe.dims[:-2]
    template = safe.isel(q0=0, p0=0, drop=True)
    if xi_max is None and "xi_max" in safe.coords:
        xi_max = safe["xi_max"]
        if xi_max.ndim == 0:
            xi_max = float(xi_max)
    if isinstance(xi_max, xr.DataArray):
        extra = set(xi_max.dims) - set(lead_dims)
        if extra:
            raise ValueError(f"xi_max has dims {sorted(map(str, extra))} that the mask does not have")
        xi_np = xi_max.broadcast_like(template).transpose(*lead_dims).values
    elif xi_max is None:
        raise ValueError("xi_max is required: pass it or give the mask an xi_max coordinate")
    else:
        xi_np = xi_max
    res = _measures_numpy(safe.values.astype(bool, copy=False), q, p, xi_np, bottom, well)
    coords = {k: v for k, v in template.coords.items()}
    ds = xr.Dataset(
        {k: xr.DataArray(v, dims=lead_dims, attrs=dict(MEASURE_ATTRS[k])) for k, v in res.items()},
        coords=coords,
    )
    if np.ndim(xi_np) == 0 and "xi_max" not in ds.coords:
        ds = ds.assign_coords(xi_max=float(xi_np))
    order = ["GIM", "LIM", "IF", "area", "r_local", "r_global", "if_q0", "if_p0",
             "area_unforced", "r_local_unforced", "r_global_unforced"]
    ds = ds[[k for k in order if k in ds]]
    ds.attrs.update(_grid_attrs(q, p, bottom))
    return ds


def _grid_attrs(q, p, bottom):
    q, p, dq, dp = grid_spacing(q, p)
    return {
        "integrity_grid": f"{q.size}x{p.size} nodes, q0 in [{q[0]:g}, {q[-1]:g}], p0 in [{p[0]:g}, {p[-1]:g}]",
        "pixel_diagonal": float(np.hypot(dq, dp)),
        "integrity_method": "area = node count * dq * dp; LIM = distance from the well bottom to the nearest "
                            "unsafe node; IF = max scipy.ndimage.distance_transform_edt(sampling=(dq, dp)); "
                            "grid padded by unsafe nodes; normalised by the unforced set H0 < xi_max, "
                            "q_minus < q0 < q_plus (the well's unforced_safe) on the same grid",
        "well_bottom": list(map(float, bottom)),
    }
