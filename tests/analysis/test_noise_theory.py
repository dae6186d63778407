"""analysis.noise_theory: the averaged theory added to ensemble Datasets is theory.escape_probability
with probability_agreement (one level and stacked over noise) and stochastic_erosion_theory, value for
value; where it does not apply the Dataset says why; bad arguments are named."""
from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr

from safebasins import theory
from safebasins.analysis import stochastic_erosion
from safebasins.analysis.agreement import probability_agreement
from safebasins.analysis.noise_theory import (escape_probability_with_theory, stochastic_erosion_with_theory,
                                              theory_evaluations, theory_reason)
from safebasins.core.averaged_theory import theory_cycles
from safebasins.analysis.stochastic_integrity import stochastic_erosion_theory
from safebasins.numerics import escape_probability
from safebasins.theory.noise_averaging import table_evaluations
from safebasins.theory.noise_escape import solve_evaluations
from safebasins.wells import QUARTIC, resolve_well

Q0, P0 = np.linspace(-0.95, 0.95, 5), np.linspace(-0.75, 0.75, 4)
ARGS = (0.01, 0.9, math.pi)
SOLVER = dict(cells=(16, 20), steps_per_cycle=6)


def ensemble(noise: float, xi_max: float = 0.18, **kw) -> xr.Dataset:
    return escape_probability(Q0, P0, *ARGS, noise=noise, paths=6, xi_max=xi_max, t_eval=[1, 3], cycles=3,
                              steps_per_cycle=16, threads=1, **kw)


def test_one_level_is_the_theory_and_the_agreement() -> None:
    ens = ensemble(0.02)
    out = escape_probability_with_theory(ens, *ARGS, 0.18, **SOLVER)
    th = theory.escape_probability(Q0, P0, *ARGS, 0.18, noise=0.02, t_eval=[1, 3], **SOLVER)
    ref = probability_agreement(th, ens)
    np.testing.assert_array_equal(out["P_escape_theory"].values, th["P_escape"].values)
    for k in ("P_escape_mean_abs_difference", "P_escape_max_abs_difference"):
        np.testing.assert_array_equal(out[k].values, ref[k].values, err_msg=k)
    # the overall mean is the mean of the per-t_eval means (levels may be stacked), summed in
    # another order than probability_agreement's: its last bit follows numpy's SIMD loops
    assert out.attrs["P_escape_mean_abs_difference"] == pytest.approx(ref.attrs["P_escape_mean_abs_difference"],
                                                                      rel=1e-14)
    assert out.attrs["P_escape_max_abs_difference"] == ref.attrs["P_escape_max_abs_difference"]
    for k in ("P_escape_mean_abs_difference_uncertain", "P_escape_theory_within_wilson"):
        assert out[k].dims == () and float(out[k]) == ref.attrs[k] and out[k].attrs["units"] == "1"
    assert out.attrs["theory_cycles"] == 3 and list(out.attrs["theory_cells"]) == [16, 20]
    assert "P_escape_theory" not in ens                 # a copy: the ensemble is unchanged
    for v in ens.data_vars:
        xr.testing.assert_identical(out[v], ens[v])


def test_stacked_levels_are_the_single_levels() -> None:
    levels = [ensemble(s).expand_dims(noise=[s]) for s in (0.01, 0.02)]
    out = escape_probability_with_theory(xr.concat(levels, "noise", combine_attrs="drop_conflicts"), *ARGS, 0.18,
                                         **SOLVER)
    assert out["P_escape_theory"].dims == ("noise", "q0", "p0", "t_eval")
    means = []
    for i, s in enumerate((0.01, 0.02)):
        one = escape_probability_with_theory(ensemble(s), *ARGS, 0.18, **SOLVER)
        for k in ("P_escape_theory", "P_escape_mean_abs_difference", "P_escape_max_abs_difference",
                  "P_escape_mean_abs_difference_uncertain", "P_escape_theory_within_wilson"):
            np.testing.assert_array_equal(out[k].values[i], one[k].values, err_msg=f"{k} at {s}")
        means.append(one.attrs["P_escape_mean_abs_difference"])
    assert out.attrs["P_escape_mean_abs_difference"] == pytest.approx(np.mean(means), rel=1e-14)
    assert 0 < out.attrs["P_escape_mean_abs_difference"] < 0.2


@pytest.mark.parametrize("kw, ens_kw, reason", [
    (dict(theory=False), {}, "theory: false"),
    (dict(xi_max=0.25), dict(xi_max=0.25), "below the barrier energy"),
])
def test_no_theory_says_why(kw, ens_kw, reason) -> None:
    out = escape_probability_with_theory(ensemble(0.02, **ens_kw), *ARGS, **{"xi_max": 0.18, **kw}, **SOLVER)
    assert out.attrs["theory"] == "none" and reason in out.attrs["theory_reason"]
    assert "P_escape_theory" not in out


def test_coloured_noise_is_the_theory_with_its_correlation_time() -> None:
    # the ensemble's noise_time reaches the solve: the coloured theory's map, not the white one's
    kw = dict(noise=0.02, t_eval=[1, 3], **SOLVER)
    out = escape_probability_with_theory(ensemble(0.02, noise_time=1.0), *ARGS, 0.18, noise_time=1.0, **SOLVER)
    th = theory.escape_probability(Q0, P0, *ARGS, 0.18, noise_time=1.0, **kw)
    white = theory.escape_probability(Q0, P0, *ARGS, 0.18, **kw)
    np.testing.assert_array_equal(out["P_escape_theory"].values, th["P_escape"].values)
    assert "theory_reason" not in out.attrs and "Ornstein-Uhlenbeck" in out.attrs["theory_model"]
    assert np.abs(th["P_escape"].values - white["P_escape"].values).max() > 1e-3
    # the erosion profile's theory too
    ekw = dict(noise=[0.02], epsilon=[0.5], xi_max=0.18, t_eval=[1, 3], noise_time=1.0)
    prof = stochastic_erosion(Q0, P0, [0.01], 0.9, math.pi, paths=12, steps_per_cycle=16, **ekw)
    got = stochastic_erosion_with_theory(prof, Q0, P0, [0.01], 0.9, math.pi, **ekw, **SOLVER)
    ref = stochastic_erosion_theory(Q0, P0, [0.01], 0.9, math.pi, **ekw, **SOLVER)
    np.testing.assert_array_equal(got["GIM_theory"].values, ref["GIM"].transpose(*got["GIM"].dims).values)


def test_reason_and_horizon() -> None:
    assert theory_reason(theory=True, noise=[0.01, 0.02], noise_time=0.0) is None
    assert theory_reason(theory=True, noise=[0.0, 0.02], noise_time=0.0) is None     # noise 0: the slow flow
    assert "theory: false" in theory_reason(theory=False, noise=[0.02], noise_time=0.0)
    assert theory_cycles([1, 2.5]) == 3 and theory_cycles([0]) == 1


@pytest.mark.parametrize("kw, word", [
    (dict(cells=(4, 20)), "cells"),
    (dict(cells=(16,)), "cells"),
    (dict(steps_per_cycle=0), "steps_per_cycle"),
    (dict(theory="yes"), "theory"),
    (dict(noise_time=-1.0), "noise_time"),
])
def test_bad_arguments_named(kw, word) -> None:
    with pytest.raises(ValueError, match=word):
        escape_probability_with_theory(ensemble(0.02), *ARGS, 0.18, **{**SOLVER, **kw})
    with pytest.raises(ValueError, match="ensemble"):
        escape_probability_with_theory(xr.Dataset(), *ARGS, 0.18)


def test_erosion_is_the_theory_profile() -> None:
    kw = dict(noise=[0.01, 0.02], epsilon=[0.3, 0.5], xi_max=0.18, t_eval=[1, 3])
    prof = stochastic_erosion(Q0, P0, [0.0, 0.01], 0.9, math.pi, paths=12, steps_per_cycle=16, **kw)
    out = stochastic_erosion_with_theory(prof, Q0, P0, [0.0, 0.01], 0.9, math.pi, **kw, **SOLVER)
    ref = stochastic_erosion_theory(Q0, P0, [0.0, 0.01], 0.9, math.pi, **kw, **SOLVER)
    for m in ("GIM", "LIM", "IF"):
        np.testing.assert_array_equal(out[m + "_theory"].values, ref[m].transpose(*out[m].dims).values, err_msg=m)
    assert out.attrs["theory_solver"] == ref.attrs["solver"]
    # another sweep than the profile's is an error, never a NaN-filled alignment
    with pytest.raises(ValueError):
        stochastic_erosion_with_theory(prof, Q0, P0, [0.0, 0.02], 0.9, math.pi, **kw, **SOLVER)
    none = stochastic_erosion_with_theory(prof, Q0, P0, [0.0, 0.01], 0.9, math.pi, **kw, theory=False)
    assert none.attrs["theory"] == "none" and not [v for v in none.data_vars if str(v).endswith("_theory")]


# --------------------------------------------------------------------------- the cost guards' count
def test_theory_evaluations_count_the_tables_once_and_each_solve() -> None:
    kw = dict(noise=[0.01, 0.02], t_eval=[1, 3], n_ics=20, **SOLVER)
    one = solve_evaluations(20, [1, 3], (16, 20), 6)
    assert theory_evaluations(solves=2, **kw) == table_evaluations(QUARTIC) + 2 * one
    # each further solve adds its march, the tables are counted once
    counts = [theory_evaluations(solves=k, **kw) for k in (1, 2, 3)]
    assert counts[2] - counts[1] == counts[1] - counts[0] == one > 0
    # the march grows with the cells and the time steps (the set-up with the cells alone)
    assert solve_evaluations(20, [1, 3], (32, 40), 6) > 3 * one
    assert one < solve_evaluations(20, [1, 3], (16, 20), 12) < 2 * one
    assert solve_evaluations(20, [1, 2.5], (16, 20), 6) == one           # the horizon: the largest t_eval, up
    assert solve_evaluations(2000, [1, 3], (16, 20), 6) > one            # the ICs count too
    # a well without closed-form action-angle variables: its tables cost more (orbit quadrature)
    assert table_evaluations(resolve_well("pendulum")) > 10 * table_evaluations(QUARTIC)
    assert theory_evaluations(solves=2, well="pendulum", **kw) - theory_evaluations(solves=2, **kw) == (
        table_evaluations(resolve_well("pendulum")) - table_evaluations(QUARTIC))


def test_theory_evaluations_zero_where_not_solved() -> None:
    kw = dict(noise=[0.01, 0.02], t_eval=[1, 3], n_ics=20, solves=2, **SOLVER)
    assert theory_evaluations(**{**kw, "theory": False}) == 0 < theory_evaluations(**kw)
    # a noise level 0 is solved (the noise-free slow flow), counted as a solve: an upper bound
    assert theory_evaluations(**{**kw, "noise": [0.0, 0.01]}) == theory_evaluations(**kw)
    # coloured noise: the same tables and solves as white noise
    assert theory_evaluations(**kw, noise_time=0.5) == theory_evaluations(**kw)
