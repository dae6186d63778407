"""Bad input to the API ("nothing silently wrong"): a ValueError that names the argument
and says why, never a KeyError / IndexError / numpy message, a NaN or a silently wrong number."""
from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from safebasins import wells
from safebasins.core import checks
from safebasins.analysis import agreement, erosion, integrity, integrity_map, safe
from safebasins.numerics import escape_chart

Q = np.linspace(-0.5, 0.5, 5)


@pytest.fixture(scope="module")
def grid_chart():
    return escape_chart(Q, Q, 0.01, 0.9, 0.0, xi_max=(0.2,), q_max=(0.9,), cycles=5)


# ------------------------------------------------------------------ wells
@pytest.mark.parametrize("call, words", [
    (lambda: wells.from_spec({}), "not a well"),
    (lambda: wells.from_spec({"name": "polynomial"}), "lacks 'coefficients'"),
    (lambda: wells.spec_of(5), "5 is not a well"),
    (lambda: wells.from_attrs({}), "names no well"),
    (lambda: wells.from_attrs(5), "attrs must be"),
    (lambda: wells.from_attrs({"well": "polynomial"}), "lacks the attribute 'well_coefficients'"),
    (lambda: wells.from_attrs({"well": "expression"}), "lacks the attribute 'well_expression'"),
    (lambda: wells.from_attrs({"well": ["cubic"]}), "must be a well's name"),
])
def test_well_specs_and_attributes(call, words):
    with pytest.raises(ValueError, match=words):
        call()


def test_from_attrs_reads_a_netcdf_round_trip(tmp_path):
    w = wells.from_attrs({"well": "polynomial", "well_coefficients": np.array([0, 0, 0.5, -0.25])})
    assert list(w.coefficients) == [0, 0, 0.5, -0.25]


def test_quartic_q_max_and_its_inverse_refuse_out_of_range():
    with pytest.raises(ValueError, match=r"xi_max must lie in \(0, 1/4\], got 0.3"):
        wells.QUARTIC.q_max(0.3)                    # was NaN
    with pytest.raises(ValueError, match=r"q_max must lie in \(0, 1\], got 1.5"):
        wells.QUARTIC.xi_from_q_max(1.5)            # was -0.14
    # valid input: the closed forms, DataArrays kept
    x = np.linspace(0.01, 0.25, 7)
    assert np.array_equal(wells.QUARTIC.q_max(x), np.sqrt(4 * x / (1 + np.sqrt(1 - 4 * x))))
    qm = np.linspace(0.1, 1.0, 7)
    assert np.array_equal(wells.QUARTIC.xi_from_q_max(qm), 0.5 * qm * qm - 0.25 * qm ** 4)
    assert isinstance(wells.QUARTIC.q_max(xr.DataArray(x)), xr.DataArray)


# ------------------------------------------------------------------ checks
def test_complex_input_is_refused_naming_the_argument():
    with pytest.raises(ValueError, match=r"^q0 must be real, got the complex value"):
        escape_chart(Q + 0.1j, Q, 0.01, 0.9, 0.0, cycles=2)
    with pytest.raises(ValueError, match="F must be real"):
        checks.check_nonnegative("F", np.array([0.01 + 0j]))
    # real input as before: lists, ints, float32, strings of numbers
    assert checks.as_array("x", [1, 2]).dtype == float
    assert checks.as_array("x", np.float32(0.1)) == np.float64(np.float32(0.1))
    assert checks.as_array("x", "1.5") == 1.5


def test_empty_sequences_are_refused():
    with pytest.raises(ValueError, match="F_values must not be empty"):
        erosion.analytic_safe_masks([], 0.9, 0.0, 0.18, Q, Q)
    with pytest.raises(ValueError, match="F must not be empty"):
        integrity_map.integrity_map_analytic(0.9, [], 0.0, 0.18, Q, Q)


@pytest.mark.parametrize("call, words", [
    (lambda: erosion.analytic_safe_masks([0.01], [0.9, 1.0], 0.0, 0.18, Q, Q), "Omega must be a scalar"),
    (lambda: erosion.analytic_safe_masks([0.01], 0.9, [0.0, 1.0], 0.18, Q, Q), "Psi must be a scalar"),
    (lambda: erosion.erosion_profile_numeric([0.01], [0.9, 1.0], 0.0, 0.18, Q, Q, cycles=2), "Omega must be a scalar"),
    (lambda: integrity_map.integrity_map_numeric([0.9], [0.01], [0, 1], 0.18, Q, Q, cycles=2), "Psi must be a scalar"),
    (lambda: integrity_map.integrity_map_numeric([0.9], [0.01], 0, [0.1, 0.2], Q, Q, cycles=2),
     "xi_max must be a scalar"),
])
def test_a_list_where_a_scalar_is_expected(call, words):
    with pytest.raises(ValueError, match=words):
        call()


# ------------------------------------------------------------------ safe sets, agreement, erosion
def test_safe_mask_of_something_that_is_not_a_chart(grid_chart):
    with pytest.raises(ValueError, match="chart is not an escape chart: it has no 'escape_cycle_energy'"):
        safe.safe_mask(xr.Dataset(), 10)
    with pytest.raises(ValueError, match="chart must be an escape chart"):
        safe.safe_mask(grid_chart["escape_cycle_energy"], 1)
    with pytest.raises(ValueError, match="t_eval must not be empty"):
        safe.safe_mask(grid_chart, [])
    with pytest.raises(ValueError, match="t_eval must not contain NaN"):
        safe.safe_mask(grid_chart, np.nan)
    with pytest.raises(ValueError, match="t_eval must not be empty"):
        safe.safe_area(grid_chart, np.array([]))


def test_mask_agreement_names_the_missing_dim():
    a = xr.DataArray(np.ones((3, 3), bool), dims=("x", "y"))
    with pytest.raises(ValueError, match="analytic_safe has no dimension 'q0'"):
        agreement.mask_agreement(a, a)
    b = xr.DataArray(np.ones((3, 3), bool), dims=("q0", "p0"))
    with pytest.raises(ValueError, match="numeric_safe must be a DataArray"):
        agreement.mask_agreement(b, np.ones((3, 3), bool))


def test_iou_of_one_dimensional_masks():
    with pytest.raises(ValueError, match=r"a with shape \(4,\) has no axes \(-2, -1\)"):
        agreement.iou(np.ones(4, bool), np.ones(4, bool))
    with pytest.raises(ValueError, match="b with shape"):
        agreement.pixel_agreement(np.ones((2, 2), bool), np.ones(2, bool), dims=(0, 1))
    assert agreement.iou(np.ones(4, bool), np.zeros(4, bool), dims=(0,)) == 0.0


def test_criteria_counts_needs_paired_ics(grid_chart):
    with pytest.raises(ValueError, match="paired ICs \\(dim 'sample'"):
        agreement.criteria_counts(grid_chart, 5, 1)
    paired = escape_chart(Q, Q, 0.01, 0.9, 0.0, xi_max=(0.2,), q_max=(0.9,), cycles=5, grid=False)
    with pytest.raises(ValueError, match="t_eval must not contain NaN"):
        agreement.criteria_counts(paired, np.nan, 1)
    with pytest.raises(ValueError, match="groups must divide"):
        agreement.criteria_counts(paired, 5, 2.5)
    A_E, A_q = agreement.criteria_counts(paired, 5, 5)
    assert A_E.shape == A_q.shape == (5,)


def test_level_crossing_checks_dim_and_level():
    prof = xr.DataArray(np.linspace(1, 0, 5), dims="F", coords={"F": np.linspace(0, 1, 5)}, name="GIM")
    with pytest.raises(ValueError, match="dim 'Omega' is not a dimension of the profile"):
        erosion.level_crossing(prof, 0.5, dim="Omega")
    with pytest.raises(ValueError, match="level must not contain NaN"):
        erosion.level_crossing(prof, np.nan)
    with pytest.raises(ValueError, match="level must be a scalar"):
        erosion.level_crossing(prof, [0.5, 0.6])
    with pytest.raises(ValueError, match="none of GIM, LIM, IF"):
        erosion.level_crossing(xr.Dataset({"x": prof}))
    assert float(erosion.level_crossing(prof, 0.5)) == pytest.approx(0.5)


# ------------------------------------------------------------------ integrity normalised by the right well
def test_integrity_needs_the_well_of_the_mask():
    """A cubic chart's basin normalised by the quartic's unforced set was silently wrong (LIM
    0.575 instead of 0.652): the well is required, or read from the mask's attributes."""
    cubic = wells.cubic()
    q, p = np.linspace(-0.5, 0.9, 41), np.linspace(-0.55, 0.55, 41)
    chart = escape_chart(q, p, 0.005, 0.9, np.pi, xi_max=(0.12,), cycles=50, well=cubic)
    mask = chart["escape_cycle_energy"].isel(xi_max=0) > 50
    with pytest.raises(ValueError, match="^well is required to normalise GIM, LIM and IF"):
        integrity.integrity_measures(mask.values, q, p, 0.12)
    with pytest.raises(ValueError, match="^well is required"):
        integrity.integrity_measures(mask, xi_max=0.12)
    right = integrity.integrity_measures(mask, xi_max=0.12, well=safe.chart_well(chart))
    wrong = integrity.integrity_measures(mask, xi_max=0.12, well="quartic")
    assert float(right["LIM"]) != float(wrong["LIM"])
    # a mask whose attributes name its well needs no well=, and a different well= is refused
    named = mask.assign_attrs(wells.spec_attrs("cubic"))
    assert float(integrity.integrity_measures(named, xi_max=0.12)["LIM"]) == float(right["LIM"])
    with pytest.raises(ValueError, match="^well: the mask names the cubic well"):
        integrity.integrity_measures(named, xi_max=0.12, well="quartic")
    # raw measures (no normalisation) need no well
    assert "GIM" not in integrity.integrity_measures(mask.values, q, p)
