"""The Wada property of three or more basins: the merging method (Daza, Wagemakers & Sanjuan,
Sci. Rep. 8, 9954 (2018); Attractors.jl's ``test_wada_merge``).

Basins have the Wada property when every boundary point of one is a boundary point of all.  Merge
every basin but one, for each basin in turn: the boundary of basin k against the union of the
others is ``B_k``.  If the basins are Wada, every ``B_k`` is the one common boundary; if not,
some ``B_k`` has parts far from another (three sectors: each ``B_k`` is two of the three rays).
On a grid the boundaries agree only to within the resolution, so the test measures how far
each ``B_j`` lies from each ``B_k`` in grid steps.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt
import xarray as xr
from scipy import ndimage

from safebasins.analysis.basin_labels import LabelsLike, check_labels
from safebasins.core import checks
from safebasins.core.provenance import api_provenance

__all__ = ["wada_test", "merged_boundaries"]

DAZA2018 = ("A. Daza, A. Wagemakers, M. A. F. Sanjuan, Ascertaining when a basin is Wada: the merging method, "
            "Sci. Rep. 8, 9954 (2018)")


def merged_boundaries(lab: npt.NDArray[np.int64], values: npt.NDArray[np.int64]) -> npt.NDArray[np.bool_]:
    """``B_k`` of each label value (bool, label first): the nodes of basin k with a grid neighbour
    (along q0 or p0) outside it, and the nodes outside with a neighbour inside."""
    out = np.zeros((len(values),) + lab.shape, bool)
    for k, v in enumerate(values):
        m = lab == v
        dq = m[1:, :] != m[:-1, :]
        dp = m[:, 1:] != m[:, :-1]
        b = out[k]
        b[1:, :] |= dq
        b[:-1, :] |= dq
        b[:, 1:] |= dp
        b[:, :-1] |= dp
    return out


@api_provenance
def wada_test(labels: LabelsLike, *, r: int | Sequence[int] = (1, 2, 3, 4, 6, 8, 12, 16), r_wada: int = 3,
              tol: float = 0.01) -> xr.Dataset:
    """Do three or more basins share one boundary?  The merging method of Daza, Wagemakers &
    Sanjuan, Sci. Rep. 8, 9954 (2018).

    ``far[j, k, r]`` is the fraction of the nodes of ``B_k`` (module docstring) farther than r grid
    steps (Euclidean) from ``B_j``; ``W(r)`` the largest over the pairs; ``hausdorff[j, k]`` the
    Hausdorff distance of ``B_j`` and ``B_k`` in grid steps.  The basins are Wada at the grid's
    resolution when ``W(r_wada) <= tol``: every merged boundary lies within ``r_wada`` steps of
    every other but for a fraction ``tol`` of its nodes (unresolved filaments).  Attractors.jl's
    ``test_wada_merge`` returns the analogue of W(r) for one r (as a fraction of all nodes rather
    than of the boundary's).

    Parameters
    ----------
    labels : labelled basin with at least three labels
        (:func:`safebasins.analysis.basin_labels.check_labels`).
    r : distances in grid steps at which ``far`` and ``W`` are reported (distinct integers >= 1).
    r_wada : the distance of the decision (one of ``r``).
    tol : the fraction of a merged boundary allowed beyond ``r_wada`` steps, in [0, 1).

    Returns
    -------
    xr.Dataset: ``far`` (label_from, label_to, r), ``W`` (r), ``hausdorff`` (label_from,
    label_to), ``n_boundary`` (label: nodes of B_k), scalar ``wada``; attributes ``r_wada``,
    ``tol``, ``max_hausdorff`` (grid steps).
    """
    lab, q0, p0 = check_labels(labels)
    rr = np.atleast_1d(np.asarray(r))
    if rr.ndim != 1 or rr.size == 0 or rr.dtype.kind not in "iu" or (rr < 1).any() or np.unique(rr).size != rr.size:
        raise ValueError(f"r must be distinct integers >= 1 (grid steps), got {r!r}")
    if isinstance(r_wada, bool) or not isinstance(r_wada, (int, np.integer)) or r_wada not in rr:
        raise ValueError(f"r_wada must be one of r = {rr.tolist()}, got {r_wada!r}")
    tol = checks.check_scalar("tol", tol, checks.check_nonnegative)
    if tol >= 1:
        raise ValueError(f"tol must lie in [0, 1), got {tol!r}")
    values = np.unique(lab)
    if values.size < 3:
        raise ValueError(f"labels must hold at least three basins for a Wada test, got {values.size} "
                         f"({values.tolist()}); an escape chart's safe/escaped labels are two")
    B = merged_boundaries(lab, values)
    L = values.size
    far = np.zeros((L, L, rr.size))
    haus = np.zeros((L, L))
    dist = [ndimage.distance_transform_edt(~B[k]) for k in range(L)]
    for j in range(L):
        for k in range(L):
            d = dist[j][B[k]]                   # steps from each node of B_k to B_j
            far[j, k] = (d[:, None] > rr[None, :]).mean(axis=0)
            haus[j, k] = d.max()
    haus = np.maximum(haus, haus.T)
    W = far.max(axis=(0, 1))
    wada = bool(W[int(np.flatnonzero(rr == r_wada)[0])] <= tol)
    lv = ("label_from", "label_to")
    ds = xr.Dataset(
        {"far": (lv + ("r",), far, {"units": "1", "long_name": "fraction of B_to farther than r grid steps from "
                                                              "B_from (B: boundary of a basin against the rest)"}),
         "W": ("r", W, {"units": "1", "long_name": "largest fraction of a merged boundary farther than r from "
                                                   "another"}),
         "hausdorff": (lv, haus, {"units": "1", "long_name": "Hausdorff distance of the merged boundaries in "
                                                             "grid steps"}),
         "n_boundary": ("label", B.sum(axis=(1, 2)).astype(np.int64),
                        {"units": "1", "long_name": "nodes of the basin's merged boundary"}),
         "wada": ((), wada, {"long_name": f"Wada: W(r_wada = {int(r_wada)}) <= tol = {tol:g}"})},
        coords={"label": ("label", values, {"long_name": "basin label"}),
                "label_from": ("label_from", values, {"long_name": "basin label of the reference boundary"}),
                "label_to": ("label_to", values, {"long_name": "basin label of the measured boundary"}),
                "r": ("r", rr.astype(np.int64), {"units": "1", "long_name": "distance in grid steps"})},
    )
    ds.attrs.update(n_labels=int(L), label_values=values.tolist(), r_wada=int(r_wada), tol=tol,
                    max_hausdorff=float(haus.max()),
                    method="merging method: boundary of each basin against the union of the others; Euclidean "
                           "distance transform of each boundary", reference=DAZA2018)
    if q0 is not None and p0 is not None:
        ds.attrs.update(grid_step_q0=float(q0[1] - q0[0]), grid_step_p0=float(p0[1] - p0[0]))
    return ds
