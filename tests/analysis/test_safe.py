"""safe = escape_cycle > t_eval: masks, areas vectorised over t_eval, bad input."""
import numpy as np
import pytest
import xarray as xr

from safebasins.analysis.safe import is_safe, safe_area, safe_mask


def chart(q0=np.linspace(-1, 1, 5), p0=np.linspace(-0.5, 0.5, 3), cycles=100):  # noqa: B008  (read only)
    e = np.full((1, q0.size, p0.size), np.inf)
    e[0, 0, :] = 0.0
    e[0, -1, -1] = 40.0
    return xr.Dataset({"escape_cycle_energy": (("xi_max", "q0", "p0"), e),
                       "escape_cycle_displacement": (("q_max", "q0", "p0"), e.copy())},
                      coords={"xi_max": [0.2], "q_max": [0.9], "q0": q0, "p0": p0}, attrs={"cycles": cycles})


def test_is_safe_definition():
    assert is_safe(np.array([0.0, 40.0, np.inf]), 40).tolist() == [False, False, True]


def test_area_counts_match_direct_count_for_every_t_eval():
    c = chart()
    t = np.array([0, 39.5, 40, 100])
    a = safe_area(c, t)
    direct = [int((c["escape_cycle_energy"].values > x).sum()) for x in t]
    assert a["pixels_energy"].isel(xi_max=0).values.tolist() == direct
    # area = sum of the cells dq0 * dp0 of the safe nodes (edge nodes count a full spacing)
    w = np.outer([0.5, 0.5, 0.5, 0.5, 0.5], [0.5, 0.5, 0.5])
    safe = c["escape_cycle_energy"].values[0] > 100
    np.testing.assert_allclose(a["area_energy"].isel(xi_max=0, t_eval=-1), (w * safe).sum(), rtol=1e-12)
    assert (a["pixels_energy"].diff("t_eval") <= 0).all()  # the safe set only shrinks with t_eval


@pytest.mark.parametrize("call,words", [
    (lambda: safe_mask(chart(), 101), "horizon"),
    (lambda: safe_area(chart(), -1), ">= 0"),
    (lambda: safe_area(chart(q0=np.array([0.0])), 10), "q0 must have at least 2 grid points"),
])
def test_bad_input(call, words):
    with pytest.raises(ValueError, match=words):
        call()
