"""CF metadata: the one table of units and long names of every shared variable name.

Names follow docs/contracts.md and the paper (dimensionless units; times in forcing cycles).
:func:`annotate` fills ``units`` / ``long_name`` of coordinates and data variables that do not
carry their own.
"""
from __future__ import annotations

import xarray as xr

REFERENCE = ("G. Karmi, P. Kravetc, O. Gendelman, Analytic exploration of safe basins in a "
             "benchmark problem of forced escape")
INSTITUTION = "safebasins reproduction"

# name -> (units, long_name). Dimensionless units are "1" (CF); times are counted in forcing cycles
# (dimensionless, named so in the long_name).
VARIABLES = {
    "q0": ("1", "initial displacement q(0)"),
    "p0": ("1", "initial momentum p(0) = dq/dt(0)"),
    "q": ("1", "displacement at the stroboscopic instants"),
    "p": ("1", "momentum at the stroboscopic instants"),
    "sample": ("1", "initial-condition index"),
    "iteration": ("1", "stroboscopic-map iteration (forcing cycles)"),
    "Omega": ("1", "forcing frequency Omega"),
    "F": ("1", "forcing amplitude F"),
    "Psi": ("rad", "forcing phase Psi"),
    "xi_max": ("1", "energy truncation level xi_max (escape threshold on H0)"),
    "q_max": ("1", "displacement escape threshold q_max"),
    "q_bounds": ("1", "displacement bound pair index (escape: q < q_lower or q > q_upper)"),
    "q_lower": ("1", "lower displacement bound: escape when q < q_lower"),
    "q_upper": ("1", "upper displacement bound: escape when q > q_upper"),
    "t_eval": ("1", "evaluation time (forcing cycles)"),
    "gamma": ("rad", "slow phase gamma = theta - Psi - Omega tau"),
    "xi": ("1", "averaged energy xi"),
    "gamma_rm": ("rad", "slow phase gamma on the resonance-manifold grid"),
    "xi_rm": ("1", "averaged energy xi on the resonance-manifold grid"),
    "repeat": ("1", "random repetition index"),
    "seed": ("1", "random seed of the repetition"),
    "xi_ini": ("1", "initial averaged energy xi_ini"),
    "gamma_ini": ("rad", "initial slow phase gamma_ini"),
    "curve": ("1", "curve index"),
    "label": ("", "curve label"),
    "vertex": ("1", "boundary vertex index"),
    "curve_index": ("1", "index of the boundary curve a vertex belongs to (-1 = padding)"),
    "kind": ("", "boundary kind (island | peninsula | saddle)"),
    "C_level": ("1", "level of the first integral C on the boundary curve"),
    "C": ("1", "first integral C(gamma, xi) of the slow flow, eq (18)"),
    "escapes": ("1", "analytic (slow-flow) escape: True = the IC escapes"),
    "escapes_rm": ("1", "analytic escape of the resonance-manifold point: True = escapes"),
    "escape_cycle_energy": ("1", "escape time in forcing cycles, energy criterion H0 > xi_max (inf: no escape)"),
    "escape_cycle_displacement": ("1", "escape time in forcing cycles, displacement criterion |q| > q_max (inf: no "
                                       "escape)"),
    "escape_cycle_bounds": ("1", "escape time in forcing cycles, displacement criterion q < q_lower or q > q_upper "
                                 "(inf: no escape)"),
    "escape_cycle": ("1", "escape time in forcing cycles (inf: no escape)"),
    "escaped": ("1", "trajectory escaped within the horizon"),
    "P_escape": ("1", "probability of escape at or before t_eval under noise (fraction of paths)"),
    "P_escape_low": ("1", "lower end of the 95% Wilson interval of P_escape"),
    "P_escape_high": ("1", "upper end of the 95% Wilson interval of P_escape"),
    "noise": ("1", "noise amplitude sigma of dp = ... + sigma dW"),
    "epsilon": ("1", "escape-probability level of the stochastic safe basin P_escape <= epsilon"),
    "t_survival": ("1", "time of the survival curve (forcing cycles)"),
    "survival": ("1", "fraction of paths not escaped by t_survival"),
    "first_passage_mean": ("1", "restricted mean first-passage time E[min(tau, cycles)] (forcing cycles)"),
    "first_passage_sem": ("1", "standard error of first_passage_mean (forcing cycles)"),
    "censored_fraction": ("1", "fraction of paths not escaped within the horizon (censored first passages)"),
    "mean_first_passage": ("1", "mean first-passage time E[tau] to xi_max (forcing cycles)"),
    "P_escape_theory": ("1", "probability of escape at or before t_eval from the averaged (stochastic slow-flow) "
                             "theory"),
    "P_escape_mean_abs_difference": ("1", "mean over the initial conditions of |P_escape theory - P_escape numerics|"),
    "P_escape_max_abs_difference": ("1", "maximum over the initial conditions of |P_escape theory - P_escape "
                                         "numerics|"),
    "P_escape_mean_abs_difference_uncertain": ("1", "mean over the initial conditions and t_eval of |P_escape "
                                                    "theory - P_escape numerics|, without the ICs whose P_escape "
                                                    "is 1 in both at every t_eval"),
    "P_escape_theory_within_wilson": ("1", "fraction of (initial condition, t_eval) where the theory's P_escape "
                                           "lies in the numerics' 95% Wilson interval"),
    "F_cr": ("1", "critical forcing amplitude"),
    "F_MM_0": ("1", "critical forcing, maximum mechanism through gamma* = 0"),
    "F_MM_pi": ("1", "critical forcing, maximum mechanism through gamma* = pi"),
    "F_SM": ("1", "critical forcing, saddle mechanism"),
    "F_SMM": ("1", "critical forcing, saddle maximum mechanism"),
    "F_escape_low": ("1", "lowest escaping F on the scan"),
    "F_escape_all": ("1", "F above which every scanned F escapes"),
    "non_monotone": ("1", "escape is not monotone in F on the scan"),
    "mechanism": ("1", "escape mechanism of the overall F_cr"),
    "xi_saddle": ("1", "averaged energy of the saddle point"),
    "gamma_saddle": ("rad", "slow phase of the saddle point"),
    "saddle_gamma": ("rad", "slow phase of the saddle point"),
    "saddle_xi": ("1", "averaged energy of the saddle point"),
    "iou": ("1", "intersection over union of the analytic and numeric safe basins"),
    "pixel_agreement": ("1", "fraction of grid points where the analytic and numeric safe/escape labels agree"),
    "safe_analytic": ("1", "number of grid points in the analytic safe basin"),
    "safe_numeric": ("1", "number of grid points in the numeric safe basin"),
    "A_E": ("1", "number of ICs in the energy-criterion safe basin (ESB)"),
    "A_q": ("1", "number of ICs in the displacement-criterion safe basin (DSB)"),
    "rel_diff": ("1", "(A_q - A_E) / A_E"),
}


def annotate(ds: xr.Dataset) -> xr.Dataset:
    """Fill missing `units` / `long_name` of coordinates and data variables (in place, returned)."""
    for name in list(ds.variables):
        entry = VARIABLES.get(str(name))
        if entry is None:
            continue
        units, long_name = entry
        attrs = ds[name].attrs
        if units and "units" not in attrs and ds[name].dtype.kind in "fiub":
            attrs["units"] = units
        attrs.setdefault("long_name", long_name)
    return ds


def attrs(name: str) -> dict:
    """``{"units": ..., "long_name": ...}`` of a shared variable name (KeyError if not in the table)."""
    units, long_name = VARIABLES[name]
    return {"units": units, "long_name": long_name} if units else {"long_name": long_name}
