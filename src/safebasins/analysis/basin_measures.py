"""Fractal boundary measures of a labelled basin: basin entropy, the fractal test and the
uncertainty exponent on the grid (docs/basin-measures.md).

One family over labels on a ``(q0, p0)`` grid (:func:`safebasins.analysis.basin_labels.check_labels`;
an escape chart's via :func:`~safebasins.analysis.basin_labels.chart_labels`), each returning a
Dataset with the statistical uncertainty of its numbers:

- ``basin_entropy``: S_b and S_bb over boxes of ``box x box`` nodes (Daza et al. 2016) and the
  log 2 criterion (S_bb > log 2: fractal; needs three or more labels);
- ``fractal_test``: the test of Puy et al. (2021), S_bb of random balls against the value of a
  smooth boundary, with a p-value;
- ``grid_uncertainty_exponent``: f(eps) ~ eps^alpha of the labelled grid (eps in grid steps), the
  definition, fit and variables of :func:`safebasins.analysis.fractality.uncertainty_exponent`,
  which integrates fresh perturbed initial conditions instead;
- ``wada_test`` (:mod:`safebasins.analysis.wada`): the merging method of Daza et al. 2018.

Entropies use the natural logarithm.  Box sizes, ball radii and eps are counted in grid steps
(nodes); with grid axes (a DataArray) the widths in q0 and p0 units are coordinates as well.
"""
from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt
import xarray as xr
from scipy import integrate, stats

from safebasins.analysis.basin_labels import Axis, LabelsLike, check_labels
from safebasins.analysis.fractality import exponent_dataset
from safebasins.core import checks
from safebasins.core.provenance import api_provenance

Ints = npt.NDArray[np.int64]
Floats = npt.NDArray[np.float64]

__all__ = ["basin_entropy", "fractal_test", "grid_uncertainty_exponent", "smooth_boundary_entropy", "PUY_BIAS"]

DAZA2016 = ("A. Daza, A. Wagemakers, B. Georgeot, D. Guery-Odelin, M. A. F. Sanjuan, Basin entropy: a new tool "
            "to analyze uncertainty in dynamical systems, Sci. Rep. 6, 31416 (2016)")
PUY2021 = ("A. Puy, A. Daza, A. Wagemakers, M. A. F. Sanjuan, A test for fractal boundaries based on the basin "
           "entropy, Commun. Nonlinear Sci. Numer. Simul. 95, 105588 (2021)")
#: Puy et al.'s fit of the upward bias of S_bb of a smooth boundary sampled by balls of radius
#: eps grid steps: ``a * eps ** -b`` (as Attractors.jl's basins_fractal_test)
PUY_BIAS = (0.224, 1.006)
#: balls drawn per boundary ball wanted before fractal_test gives up
MAX_DRAWS_PER_BALL = 1000
_BATCH = 4096


@functools.cache
def smooth_boundary_entropy() -> float:
    """S_bb of a smooth boundary in the plane sampled by balls (Puy et al. 2021): a straight line
    at a uniform distance ``d`` in [0, 1) from the centre of a unit disc cuts off the fraction
    ``p(d) = (arccos d - d sqrt(1 - d^2)) / pi``, so S_bb = the mean over d of
    ``-p log p - (1 - p) log(1 - p)`` (0.4395 by quadrature; Puy et al. tabulate 0.4395093)."""
    def h(d: float) -> float:
        p = (np.arccos(d) - d * np.sqrt(1.0 - d * d)) / np.pi
        return 0.0 if p <= 0.0 or p >= 1.0 else float(-p * np.log(p) - (1 - p) * np.log1p(-p))
    return float(integrate.quad(h, 0.0, 1.0, epsabs=1e-13, epsrel=1e-12)[0])


def _positive_ints(name: str, value: int | Sequence[int], lowest: int = 1) -> Ints:
    a = np.atleast_1d(np.asarray(value))
    if a.ndim != 1 or a.size == 0 or a.dtype.kind not in "iu" or (a < lowest).any():
        raise ValueError(f"{name} must be an integer >= {lowest} or a 1-D sequence of them (grid steps), "
                         f"got {value!r}")
    if np.unique(a).size != a.size:
        raise ValueError(f"{name} must be distinct values, got {value!r}")
    return a.astype(np.int64)


def _seed(seed: int) -> int:
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
    return int(seed)


def _significance(value: float) -> float:
    s = float(checks.check_scalar("significance", value, checks.check_positive))
    if s >= 1:
        raise ValueError(f"significance must lie in (0, 1), got {s!r}")
    return s


def _entropy(counts: Ints) -> Floats:
    """Gibbs entropy ``-sum p log p`` of each row of label counts (0 log 0 = 0)."""
    n = counts.sum(axis=1, keepdims=True)
    p = counts / n
    with np.errstate(divide="ignore", invalid="ignore"):
        terms = np.where(counts > 0, -p * np.log(np.where(counts > 0, p, 1.0)), 0.0)
    out: Floats = terms.sum(axis=1)
    return out


def _width_coords(name: str, steps: Ints, q0: Axis, p0: Axis, what: str) -> dict[str, Any]:
    """Coordinates ``<name>_q0``, ``<name>_p0``: ``steps`` grid steps in q0 and p0 units."""
    if q0 is None or p0 is None:
        return {}
    dq, dp = float(q0[1] - q0[0]), float(p0[1] - p0[0])
    return {f"{name}_q0": (name, steps * dq, {"units": "1", "long_name": f"{what} in q0 units"}),
            f"{name}_p0": (name, steps * dp, {"units": "1", "long_name": f"{what} in p0 units"})}


def _common_attrs(values: Ints) -> dict[str, Any]:
    return {"n_labels": int(values.size), "label_values": values.tolist()}


# --------------------------------------------------------------------------- basin entropy
def _tiling(inv: Ints, n_labels: int, b: int, oq: int, op: int) -> tuple[Floats, npt.NDArray[np.bool_]]:
    """Entropy of each box of the tiling by ``b x b`` boxes from node (oq, op) (incomplete boxes at
    the far edges are left out) and whether it holds more than one label."""
    mq, mp = (inv.shape[0] - oq) // b, (inv.shape[1] - op) // b
    if mq == 0 or mp == 0:
        return np.zeros(0), np.zeros(0, bool)
    sub = inv[oq:oq + mq * b, op:op + mp * b]
    box = (np.arange(mq * b) // b)[:, None] * mp + (np.arange(mp * b) // b)[None, :]
    counts = np.bincount((box * n_labels + sub).ravel(), minlength=mq * mp * n_labels).reshape(mq * mp, n_labels)
    return _entropy(counts), (counts > 0).sum(axis=1) > 1


def _mean_err(x: Floats) -> tuple[float, float]:
    """Mean and its standard error (NaN, NaN for no values; error NaN for one)."""
    if x.size == 0:
        return np.nan, np.nan
    return float(x.mean()), float(x.std(ddof=1) / np.sqrt(x.size)) if x.size > 1 else np.nan


@api_provenance
def basin_entropy(labels: LabelsLike, *, box: int | Sequence[int] = 5, offsets: int = 1, seed: int = 0,
                  significance: float = 0.01) -> xr.Dataset:
    """Basin entropy S_b and boundary basin entropy S_bb (Daza et al., Sci. Rep. 6, 31416 (2016)).

    The grid is tiled by boxes of ``box x box`` nodes; box i holding the labels j with fractions
    p_ij has the Gibbs entropy ``S_i = -sum_j p_ij log p_ij``.  S_b is the mean of S_i over all
    boxes, S_bb the mean over the boundary boxes (more than one label).  ``S_bb > log 2`` implies a
    fractal boundary (Daza et al.); with two labels S_i <= log 2 always, so the criterion cannot
    fire and :func:`fractal_test` decides instead.  As in Attractors.jl's ``basin_entropy``, boxes
    are tiled from the first node and incomplete boxes at the far edges are left out.

    Parameters
    ----------
    labels : labelled basin (:func:`safebasins.analysis.basin_labels.check_labels`).
    box : box side(s) in grid steps, integers >= 2 (a sequence gives a ``box`` dimension).
    offsets : number of tilings, shifted by random offsets in ``[0, box)`` (seeded: ``seed``; the
        first is unshifted; with ``offsets >= box**2`` all shifts): the spread over tilings enters
        the uncertainty.
    significance : level of the log 2 criterion: fractal when ``S_bb - log 2`` exceeds the one-sided
        normal quantile of ``significance`` times ``S_bb_err``.

    Returns
    -------
    xr.Dataset over ``box``: ``S_b``, ``S_bb``, their standard errors ``S_b_err``, ``S_bb_err``
    (the standard error of the mean over the boxes of a tiling, combined with the spread over
    tilings; NaN with fewer than two boxes), ``n_boxes``, ``n_boundary_boxes`` (over all tilings),
    ``log2_z`` = (S_bb - log 2) / S_bb_err and ``fractal_log2``.  S_bb is NaN where no box holds
    two labels (``n_boundary_boxes`` = 0).  Attributes: ``n_labels``, ``label_values``,
    ``max_entropy`` (log of the number of labels), ``log2_criterion``.
    """
    lab, q0, p0 = check_labels(labels)
    boxes = _positive_ints("box", box, lowest=2)
    if boxes.max() > min(lab.shape):
        raise ValueError(f"box must be at most the grid's shorter side ({min(lab.shape)} nodes), got {boxes.max()}")
    offsets = checks.check_positive_int("offsets", offsets)
    rng = np.random.default_rng(_seed(seed))
    z_crit = float(stats.norm.isf(_significance(significance)))
    values, inv = np.unique(lab, return_inverse=True)
    inv = inv.reshape(lab.shape)
    rows = []
    for b in boxes:
        b = int(b)
        if offsets >= b * b:
            shifts = [(i, j) for i in range(b) for j in range(b)]
        else:
            drawn = rng.integers(0, b, (offsets - 1, 2))
            shifts = [(0, 0)] + [(int(x), int(y)) for x, y in drawn]
        rows_b = []
        for oq, op in shifts:
            S, bnd = _tiling(inv, values.size, b, oq, op)
            rows_b.append((*_mean_err(S), *_mean_err(S[bnd]), S.size, int(bnd.sum())))
        per = np.array(rows_b, dtype=float)
        row = []
        for col in (0, 2):
            ok = np.isfinite(per[:, col])
            if not ok.any():
                row += [np.nan, np.nan]
                continue
            m, se = per[ok, col], per[ok, col + 1]
            spread = m.var() if m.size > 1 else 0.0
            row += [float(m.mean()), float(np.sqrt(np.mean(se ** 2) + spread))]
        rows.append(row + [int(per[:, 4].sum()), int(per[:, 5].sum())])
    r = np.array(rows, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        z = (r[:, 2] - np.log(2.0)) / r[:, 3]
    dims = "box"
    ds = xr.Dataset(
        {"S_b": (dims, r[:, 0], {"units": "1", "long_name": "basin entropy S_b (mean box entropy)"}),
         "S_b_err": (dims, r[:, 1], {"units": "1", "long_name": "standard error of S_b"}),
         "S_bb": (dims, r[:, 2], {"units": "1", "long_name": "boundary basin entropy S_bb (mean over boxes "
                                                             "with more than one label)"}),
         "S_bb_err": (dims, r[:, 3], {"units": "1", "long_name": "standard error of S_bb"}),
         "n_boxes": (dims, r[:, 4].astype(np.int64), {"units": "1", "long_name": "boxes measured (all tilings)"}),
         "n_boundary_boxes": (dims, r[:, 5].astype(np.int64),
                              {"units": "1", "long_name": "boxes with more than one label (all tilings)"}),
         "log2_z": (dims, z, {"units": "1", "long_name": "(S_bb - log 2) / S_bb_err"}),
         "fractal_log2": (dims, np.nan_to_num(z, nan=-np.inf) > z_crit,
                          {"long_name": f"S_bb > log 2 at significance {significance:g} (fractal boundary)"})},
        coords={"box": (dims, boxes, {"units": "1", "long_name": "box side in grid steps"}),
                **_width_coords("box", boxes, q0, p0, "box side")},
    )
    ds.attrs.update(
        _common_attrs(values), max_entropy=float(np.log(values.size)), offsets=offsets, seed=int(seed),
        significance=float(significance),
        log2_criterion=("S_bb > log 2 implies a fractal boundary; with two labels S_bb <= log 2 always and the "
                        "criterion cannot decide (use fractal_test)"),
        method="mean Gibbs entropy (natural log) of box x box tiles; boundary boxes hold more than one label",
        reference=DAZA2016)
    return ds


# --------------------------------------------------------------------------- fractal test
def _ball_offsets(radius: float) -> tuple[Ints, Ints]:
    k = int(np.ceil(radius)) + 1
    d = np.arange(-k, k + 1)
    DI, DJ = np.meshgrid(d, d, indexing="ij")
    return DI.ravel(), DJ.ravel()


def _ball_entropies(inv: Ints, n_labels: int, radius: float, rng: np.random.Generator,
                    n: int) -> tuple[Floats, Ints]:
    """Entropies of ``n`` balls of ``radius`` grid steps at uniform random centres (kept inside
    the grid), and the number of labels each holds."""
    nq, np_ = inv.shape
    cq = rng.uniform(radius, nq - 1 - radius, n)
    cp = rng.uniform(radius, np_ - 1 - radius, n)
    DI, DJ = _ball_offsets(radius)
    I = np.floor(cq).astype(np.int64)[:, None] + DI[None, :]
    J = np.floor(cp).astype(np.int64)[:, None] + DJ[None, :]
    inside = (I - cq[:, None]) ** 2 + (J - cp[:, None]) ** 2 <= radius * radius
    lab = inv[np.clip(I, 0, nq - 1), np.clip(J, 0, np_ - 1)]
    ball = np.broadcast_to(np.arange(n)[:, None], lab.shape)
    counts = np.bincount((ball * n_labels + lab)[inside], minlength=n * n_labels).reshape(n, n_labels)
    n_held: Ints = (counts > 0).sum(axis=1)
    return _entropy(counts), n_held


@api_provenance
def fractal_test(labels: LabelsLike, *, radius: float = 20, n_balls: int = 1000, seed: int = 0,
                 significance: float = 0.01) -> xr.Dataset:
    """Is the basin boundary fractal?  The test of Puy, Daza, Wagemakers & Sanjuan, Commun.
    Nonlinear Sci. Numer. Simul. 95, 105588 (2021), as Attractors.jl's ``basins_fractal_test``,
    with a p-value.

    Balls of ``radius`` grid steps are dropped at uniform random centres inside the grid until
    ``n_balls`` of them hold more than one label; their mean entropy estimates S_bb with the
    standard error ``S_bb_err``.  A smooth boundary seen through a ball is locally straight, which
    gives ``S_bb_smooth`` (:func:`smooth_boundary_entropy`, 0.4395) plus an upward pixelation bias
    of at most ``bias = 0.224 radius^-1.006`` (Puy et al.'s fit, :data:`PUY_BIAS`).  A fractal
    boundary puts a different mixture of labels in the balls, higher or lower.  The distance of
    S_bb from the band ``[S_bb_smooth, S_bb_smooth + bias]`` in standard errors is ``z``;
    ``p_value = 2 sf(z)`` (normal, two-sided, 1 inside the band); ``fractal`` when ``p_value <
    significance``.  The decision is for structure at the scale of the ball: Puy et al. advise a
    grid at least 50 radii wide (``grid_over_radius``).  The smooth value is that of two basins:
    where three or more basins meet within a ball (``multi_fraction`` of the boundary balls) S_bb
    rises above it without a fractal boundary, and a smooth boundary curved or folded at the
    ball's scale departs from it as well.

    Parameters
    ----------
    labels : labelled basin (:func:`safebasins.analysis.basin_labels.check_labels`).
    radius : ball radius in grid steps (> 0; the grid must be wider than a diameter).
    n_balls : boundary balls to average (>= 100).
    seed : seed of the ball centres.
    significance : level of the test, in (0, 1).

    Returns
    -------
    xr.Dataset of scalars: ``S_bb``, ``S_bb_err``, ``S_bb_smooth``, ``bias``, ``z``, ``p_value``,
    ``fractal``, ``multi_fraction`` (boundary balls holding three or more labels), ``n_draws``
    (balls drawn to find ``n_balls`` on the boundary).  ValueError when
    fewer than ``n_balls`` boundary balls turn up in ``MAX_DRAWS_PER_BALL * n_balls`` draws.
    """
    lab, q0, p0 = check_labels(labels)
    radius = float(checks.check_scalar("radius", radius, checks.check_positive))
    n_balls = checks.check_positive_int("n_balls", n_balls)
    if n_balls < 100:
        raise ValueError(f"n_balls must be >= 100 (the test averages over boundary balls), got {n_balls}")
    if min(lab.shape) - 1 <= 2 * radius:
        raise ValueError(f"radius {radius:g} is too large for the grid {lab.shape}: a ball must fit inside it")
    rng = np.random.default_rng(_seed(seed))
    sig = _significance(significance)
    values, inv = np.unique(lab, return_inverse=True)
    if values.size < 2:
        raise ValueError(f"labels hold a single label ({values[0]}): there is no boundary to test")
    inv = inv.reshape(lab.shape)
    found: list[Floats] = []
    held: list[Ints] = []
    draws = 0
    while sum(h.size for h in found) < n_balls:
        if draws >= MAX_DRAWS_PER_BALL * n_balls:
            got = sum(h.size for h in found)
            raise ValueError(f"n_balls: only {got} of {draws} random balls of radius {radius:g} hold two labels, "
                             f"fewer than n_balls = {n_balls}: the boundary is too small a part of the grid "
                             "(crop the grid to the boundary or lower n_balls)")
        h, k = _ball_entropies(inv, values.size, radius, rng, _BATCH)
        found.append(h[k > 1])
        held.append(k[k > 1])
        draws += _BATCH
    h = np.concatenate(found)[:n_balls]
    multi = float((np.concatenate(held)[:n_balls] > 2).mean())
    S, err = float(h.mean()), float(h.std(ddof=1) / np.sqrt(n_balls))
    S_s = smooth_boundary_entropy()
    bias = PUY_BIAS[0] * radius ** -PUY_BIAS[1]
    gap = S_s - S if S < S_s else max(S - S_s - bias, 0.0)
    with np.errstate(divide="ignore"):
        z = gap / err if gap > 0 else 0.0
    p = float(min(1.0, 2.0 * stats.norm.sf(z)))
    ds = xr.Dataset(
        {"S_bb": ((), S, {"units": "1", "long_name": "boundary basin entropy of random balls"}),
         "S_bb_err": ((), err, {"units": "1", "long_name": "standard error of S_bb"}),
         "S_bb_smooth": ((), S_s, {"units": "1", "long_name": "S_bb of a smooth boundary (straight line in a ball)"}),
         "bias": ((), bias, {"units": "1", "long_name": "upward pixelation bias of a smooth boundary's S_bb"}),
         "z": ((), z, {"units": "1", "long_name": "distance of S_bb from the smooth band in standard errors"}),
         "p_value": ((), p, {"units": "1", "long_name": "probability of so large a z for a smooth boundary"}),
         "fractal": ((), p < sig, {"long_name": f"fractal boundary at significance {sig:g}"}),
         "multi_fraction": ((), multi, {"units": "1", "long_name": "fraction of the boundary balls holding three "
                                                                   "or more labels"}),
         "n_draws": ((), draws, {"units": "1", "long_name": "random balls drawn"})})
    ds.attrs.update(_common_attrs(values), radius=radius, n_balls=n_balls, seed=int(seed), significance=sig,
                    grid_over_radius=float(min(lab.shape) / radius),
                    decision="fractal" if p < sig else "smooth",
                    method="mean entropy of random balls holding two or more labels against the smooth-boundary "
                           "band [S_bb_smooth, S_bb_smooth + bias]", reference=PUY2021)
    if q0 is not None and p0 is not None:
        ds.attrs.update(radius_q0=radius * float(q0[1] - q0[0]), radius_p0=radius * float(p0[1] - p0[0]))
    return ds


# --------------------------------------------------------------------------- uncertainty exponent
@api_provenance
def grid_uncertainty_exponent(labels: LabelsLike, *, eps: int | Sequence[int] = (2, 4, 8, 16, 32), n: int = 100_000,
                              seed: int = 0, axes: str | Sequence[str] = ("q0", "p0")) -> xr.Dataset:
    """Uncertainty exponent alpha of the boundary of a labelled grid: f(eps) ~ eps^alpha, the
    boundary's box-counting dimension ``2 - alpha`` (Grebogi, McDonald, Ott & Yorke, Phys. Lett.
    A 99, 415 (1983); McDonald et al., Physica D 17, 125 (1985)).

    The definition of :func:`safebasins.analysis.fractality.uncertainty_exponent` on the grid: a
    node x is eps-uncertain when x, x + eps e and x - eps e (e one grid step along q0 or p0, at
    random) do not all have the same label.  ``n`` base nodes are drawn uniformly (with
    replacement, seeded) among those at least ``max(eps)`` steps from the grid's edges along e, so
    ``fraction_err`` (binomial) is the sampling error of the grid's f(eps); the fit is the same
    weighted fit of log f against log eps (:func:`safebasins.analysis.fractality.exponent_dataset`).
    Structure finer than a grid step is invisible here, which biases alpha up (towards a smooth
    boundary) at eps of one or two steps: on the Cantor basins of
    :func:`safebasins.analysis.reference_basins.cantor_basins` eps = 1..16 gives 0.42-0.50 for
    the exact 0.369, eps = 4..256 within 0.015 of it (docs/basin-measures.md).  To go below the
    grid step, integrate fresh points with ``uncertainty_exponent``.

    Parameters
    ----------
    labels : labelled basin (:func:`safebasins.analysis.basin_labels.check_labels`).
    eps : perturbations in grid steps (distinct integers >= 1).
    n : base nodes.
    seed : seed of the base nodes and directions.
    axes : the directions of e: ``("q0", "p0")`` (either, at random) or one of them (a basin that
        varies along one axis only, on a grid too narrow along the other).

    Returns
    -------
    xr.Dataset over ``eps`` (grid steps; ``eps_q0``, ``eps_p0`` in q0 and p0 units for a DataArray):
    ``n_uncertain``, ``fraction``, ``fraction_err``, ``used``; attributes ``alpha``,
    ``alpha_err``, ``boundary_dimension`` (NaN when fewer than two eps have enough uncertain
    nodes, as ``uncertainty_exponent``).
    """
    lab, q0, p0 = check_labels(labels)
    e = _positive_ints("eps", eps)
    n = checks.check_positive_int("n", n)
    names = (axes,) if isinstance(axes, str) else tuple(axes)
    if not names or len(set(names)) != len(names) or not set(names) <= {"q0", "p0"}:
        raise ValueError(f"axes must be 'q0', 'p0' or both, got {axes!r}")
    m = int(e.max())
    for a in names:
        size = lab.shape[0 if a == "q0" else 1]
        if size <= 2 * m:
            raise ValueError(f"eps: the largest perturbation ({m} steps) along {a} needs more than {2 * m} nodes "
                             f"along it, the grid has {size} (lower eps or perturb along the other axis: axes)")
    rng = np.random.default_rng(_seed(seed))
    along_q = np.isin(rng.integers(0, len(names), n), [names.index("q0")] if "q0" in names else [])
    i = np.where(along_q, rng.integers(m, lab.shape[0] - m, n) if "q0" in names else 0,
                 rng.integers(0, lab.shape[0], n))
    j = np.where(along_q, rng.integers(0, lab.shape[1], n),
                 rng.integers(m, lab.shape[1] - m, n) if "p0" in names else 0)
    di, dj = along_q.astype(np.int64), (~along_q).astype(np.int64)
    base = lab[i, j]
    k = np.array([((lab[i + s * di, j + s * dj] != base) | (lab[i - s * di, j - s * dj] != base)).sum() for s in e])
    ds = exponent_dataset(e, k, n, {"units": "1", "long_name": "perturbation in grid steps (along q0 or p0)"})
    ds = ds.assign_coords(_width_coords("eps", e, q0, p0, "perturbation"))
    ds.attrs.update(_common_attrs(np.unique(lab)), n=n, seed=int(seed), axes=list(names),
                    method="f(eps) ~ eps^alpha, node x and x +- eps e (e a grid step along the axes, at random) "
                           "with different labels; weighted fit of log f")
    return ds
