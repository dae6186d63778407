"""IoU, pixel agreement and criteria counts: values on hand-made masks, bad input rejected."""
import numpy as np
import pytest
import xarray as xr

from safebasins.analysis.agreement import criteria_counts, iou, mask_agreement, pixel_agreement


def test_mask_agreement_values():
    a = xr.DataArray(np.array([[1, 1], [0, 0]], bool), dims=("q0", "p0"))
    n = xr.DataArray(np.array([[1, 0], [0, 0]], bool), dims=("q0", "p0"))
    i, pix = mask_agreement(a, n)
    assert float(i) == 0.5 and float(pix) == 0.75
    i, pix = mask_agreement(a & False, n & False)
    assert float(i) == 1.0 and float(pix) == 1.0  # both empty: perfect agreement


def test_numpy_masks_broadcast_over_a_stack():
    a = np.zeros((4, 4), bool)
    a[:2] = True
    stack = np.stack([a, ~a])
    np.testing.assert_array_equal(iou(stack, a), [1.0, 0.0])
    np.testing.assert_array_equal(pixel_agreement(stack, a), [1.0, 0.0])


def test_criteria_counts_per_repetition():
    e = np.array([np.inf, 5.0, np.inf, np.inf, 0.0, 50.0])
    d = np.array([np.inf, np.inf, np.inf, np.inf, 0.0, np.inf])
    chart = xr.Dataset({"escape_cycle_energy": (("xi_max", "sample"), e[None]),
                        "escape_cycle_displacement": (("q_max", "sample"), d[None])})
    A_E, A_q = criteria_counts(chart, 10, 2)
    assert A_E.tolist() == [2, 2] and A_q.tolist() == [3, 2]
    with pytest.raises(ValueError, match="groups"):
        criteria_counts(chart, 10, 4)


@pytest.mark.parametrize("call,words", [
    (lambda: iou(np.ones((3, 3)), np.ones((3, 3), bool)), "boolean"),
    (lambda: pixel_agreement(np.zeros((0, 0), bool), np.zeros((0, 0), bool)), "empty"),
    (lambda: iou(np.ones((3, 3), bool), np.ones((2, 2), bool)), "broadcastable"),
])
def test_bad_masks(call, words):
    with pytest.raises(ValueError, match=words):
        call()
