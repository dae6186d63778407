"""The fractal boundary measures of a damped well's basins over a list of F (docs/basin-measures.md).

For each forcing amplitude the stroboscopic map of an IC grid labels every initial condition by
its fate (:func:`safebasins.analysis.basin_labels.map_labels`: escaped, or the attractor it
settles on: the resonant and the non-resonant response where both exist).  Two labellings are
measured: ``escape`` (escaped or safe: the boundary the Melnikov tangency tangles) and
``attractors`` (escape and each attractor's basin: the boundaries between coexisting responses
as well).  Each gives basin entropy, the fractal test and the grid uncertainty exponent with
their uncertainties; the attractors' labels give the Wada test (three or more basins); beside
them the Melnikov threshold of the hilltop saddle.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt
import xarray as xr

from safebasins.analysis.basin_labels import map_labels
from safebasins.analysis.basin_measures import (basin_entropy, fractal_test, grid_uncertainty_exponent,
                                                smooth_boundary_entropy)
from safebasins.analysis.common import as_1d
from safebasins.analysis.tangency import melnikov_variable
from safebasins.analysis.wada import wada_test
from safebasins.core import checks
from safebasins.core.cf import annotate
from safebasins.numerics import DEFAULT_STEPS_PER_CYCLE, stroboscopic_map
from safebasins.wells.provenance import api_provenance

__all__ = ["boundary_measures", "WADA_FLAGS", "LABELLINGS"]

#: flag values of ``wada``: not applicable (fewer than three basins), not Wada, Wada
WADA_FLAGS = {-1: "fewer_than_three_basins", 0: "not_wada", 1: "wada"}
#: the Wada test's decision distance (grid steps) and tolerance
R_WADA, WADA_TOL = 3, 0.01

#: the two labellings measured (dimension ``labelling``)
LABELLINGS = ("escape", "attractors")

_VARS = {
    "S_b": "basin entropy S_b (mean Gibbs entropy of box x box tiles)",
    "S_b_err": "standard error of S_b",
    "S_bb": "boundary basin entropy S_bb (tiles with more than one label)",
    "S_bb_err": "standard error of S_bb",
    "log2_z": "(S_bb - log 2) / S_bb_err",
    "ball_S_bb": "S_bb of random balls on the boundary (fractal test)",
    "ball_S_bb_err": "standard error of ball_S_bb",
    "p_value": "fractal test: probability of so large a departure for a smooth boundary",
    "multi_fraction": "fractal test: fraction of the boundary balls holding three or more labels",
    "alpha": "uncertainty exponent alpha of the labelled grid (f(eps) ~ eps^alpha)",
    "alpha_err": "standard error of alpha (weighted fit)",
}


def _measures(lab: npt.NDArray[np.int64], box: int, radius: float, n_balls: int, eps: Sequence[int],
              seed: int) -> dict[str, Any]:
    """Basin entropy (all ``box**2`` tilings), fractal test and grid uncertainty exponent of one labelling."""
    be = basin_entropy(lab, box=box, offsets=box * box, seed=seed)
    ft = fractal_test(lab, radius=radius, n_balls=n_balls, seed=seed)
    ue = grid_uncertainty_exponent(lab, eps=eps, seed=seed)
    return {"S_b": be["S_b"].item(), "S_b_err": be["S_b_err"].item(), "S_bb": be["S_bb"].item(),
            "S_bb_err": be["S_bb_err"].item(), "log2_z": be["log2_z"].item(),
            "fractal_log2": bool(be["fractal_log2"].item()), "ball_S_bb": ft["S_bb"].item(),
            "ball_S_bb_err": ft["S_bb_err"].item(), "p_value": ft["p_value"].item(),
            "fractal": bool(ft["fractal"].item()), "multi_fraction": ft["multi_fraction"].item(),
            "alpha": ue.attrs["alpha"], "alpha_err": ue.attrs["alpha_err"]}


@api_provenance
def boundary_measures(F_values: float | Sequence[float], Omega: float, Psi: float, xi_max: float,
                      q0: npt.ArrayLike, p0: npt.ArrayLike, *, damping: float, well: Any = None, n_iter: int = 150,
                      box: int = 5, radius: float = 4.0, n_balls: int = 1000, eps: Sequence[int] = (2, 4, 8, 16),
                      seed: int = 0, tol: float = 1e-4, steps_per_cycle: int = DEFAULT_STEPS_PER_CYCLE,
                      threads: int | None = None) -> xr.Dataset:
    """Basin entropy, fractal test, Wada test and uncertainty exponent of the basins of escape and
    of each attractor, for each F.

    Parameters
    ----------
    F_values, Omega, Psi : the forcing F sin(Omega t + Psi), one map per F.
    xi_max : escape threshold (energy criterion, as :func:`safebasins.numerics.stroboscopic_map`).
    q0, p0 : the grid axes (uniform).
    damping : beta > 0 (attractors need damping).
    well, steps_per_cycle, threads : as the numerics.
    n_iter, tol : map iterations and the settling tolerance of
        :func:`~safebasins.analysis.basin_labels.map_labels`.
    box, seed : :func:`~safebasins.analysis.basin_measures.basin_entropy` (all ``box**2`` tilings).
    radius, n_balls : :func:`~safebasins.analysis.basin_measures.fractal_test` (grid steps).
    eps : :func:`~safebasins.analysis.basin_measures.grid_uncertainty_exponent` (grid steps).

    Returns
    -------
    xr.Dataset: ``basin`` (F, q0, p0; 0 escaped, k the k-th attractor by the q of its lowest
    point); over (F, labelling) ``S_b``, ``S_bb`` and their ``_err``, ``log2_z``,
    ``fractal_log2``, ``ball_S_bb``, ``ball_S_bb_err``, ``p_value``, ``fractal``,
    ``multi_fraction`` (fractal test: boundary balls where three basins meet), ``alpha``,
    ``alpha_err``; over F ``W`` (NaN with fewer than three basins), ``wada`` (int8 flags
    :data:`WADA_FLAGS`), ``n_attractors``, ``safe_fraction``, ``n_unsettled``; scalars
    ``F_melnikov`` and ``S_bb_smooth``.
    """
    F = as_1d("F_values", F_values, checks.check_nonnegative)
    beta = float(checks.check_scalar("damping", damping, checks.check_positive))
    qa = checks.check_finite("q0", q0)
    pa = checks.check_finite("p0", p0)
    Q, P = np.meshgrid(qa, pa, indexing="ij")
    rows: list[list[dict[str, Any]]] = []
    per_F: list[dict[str, Any]] = []
    labels = []
    for f in F:
        strobe = stroboscopic_map(Q, P, float(f), Omega, Psi, n_iter=n_iter, xi_max=xi_max, well=well,
                                  damping=beta, steps_per_cycle=steps_per_cycle, threads=threads)
        lab = map_labels(strobe, tol=tol)
        rows.append([_measures((lab.values > 0).astype(np.int64), box, radius, n_balls, eps, seed),
                     _measures(lab.values, box, radius, n_balls, eps, seed)])
        W, flag = np.nan, -1
        if np.unique(lab.values).size >= 3:
            wt = wada_test(lab, r_wada=R_WADA, tol=WADA_TOL)
            W, flag = float(wt["W"].sel(r=R_WADA)), int(bool(wt["wada"]))
        per_F.append({"W": W, "wada": flag, "safe_fraction": float((lab.values > 0).mean()),
                      "n_attractors": len(lab.attrs["attractor_q"]), "n_unsettled": lab.attrs["n_unsettled"]})
        labels.append(lab.values.astype(np.int8))
    ds = xr.Dataset(coords={"F": ("F", F), "labelling": ("labelling", list(LABELLINGS),
                                                         {"long_name": "escape: escaped / safe; attractors: escaped / "
                                                                       "each attractor's basin"}),
                            "q0": ("q0", qa), "p0": ("p0", pa)})
    ds["basin"] = (("F", "q0", "p0"), np.stack(labels),
                   {"long_name": "basin label: escaped (0) or the attractor settled on (1, 2, ...)",
                    "flag_meanings": "escaped attractor_1 attractor_2 ..."})
    dims = ("F", "labelling")
    for k, text in _VARS.items():
        ds[k] = (dims, np.array([[r[k] for r in row] for row in rows], float), {"units": "1", "long_name": text})
    ds["fractal_log2"] = (dims, np.array([[r["fractal_log2"] for r in row] for row in rows]),
                          {"long_name": "S_bb > log 2 (fractal)"})
    ds["fractal"] = (dims, np.array([[r["fractal"] for r in row] for row in rows]),
                     {"long_name": "fractal test: fractal boundary"})
    ds["W"] = ("F", np.array([r["W"] for r in per_F]), {"units": "1", "long_name": (
        "Wada test: largest fraction of a merged boundary farther than r_wada grid steps from another")})
    ds["safe_fraction"] = ("F", np.array([r["safe_fraction"] for r in per_F]),
                           {"units": "1", "long_name": "fraction of the grid not escaped within n_iter cycles"})
    ds["wada"] = ("F", np.array([r["wada"] for r in per_F], np.int8),
                  {"long_name": f"Wada test: W(r = {R_WADA}) <= {WADA_TOL:g}", "flag_values": list(WADA_FLAGS),
                   "flag_meanings": " ".join(WADA_FLAGS.values())})
    for k, text in (("n_attractors", "attractors inside the well"),
                    ("n_unsettled", "ICs not settled after n_iter cycles (given the nearest attractor)")):
        ds[k] = ("F", np.array([r[k] for r in per_F], np.int64), {"units": "1", "long_name": text})
    ds["F_melnikov"] = melnikov_variable(Omega, beta, well)
    ds["S_bb_smooth"] = xr.DataArray(smooth_boundary_entropy(),
                                     attrs={"units": "1", "long_name": "ball S_bb of a smooth boundary"})
    ds.attrs.update(Omega=float(Omega), Psi=float(Psi), xi_max=float(xi_max), damping=beta, n_iter=int(n_iter),
                    box=int(box), radius=float(radius), n_balls=int(n_balls), eps=[int(e) for e in eps],
                    seed=int(seed), tol=float(tol), steps_per_cycle=int(steps_per_cycle), r_wada=R_WADA,
                    wada_tol=WADA_TOL, significance=0.01,
                    method="labels from the stroboscopic map (escape, attractors); basin_entropy, fractal_test, "
                           "wada_test, grid_uncertainty_exponent of safebasins.analysis")
    out: xr.Dataset = annotate(ds)
    return out
