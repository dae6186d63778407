"""Labelled basins from the numerics: an escape chart's escaped/safe labels, and the escape and
attractor basins of a damped stroboscopic map (Thompson's escape equation below the Melnikov
tangency, beta = 0.1, Omega = 0.85, F = 0.055: a resonant and a non-resonant attractor)."""
from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from scipy.integrate import solve_ivp

from safebasins.analysis.basin_labels import ESCAPED, SAFE, chart_labels, check_labels, map_labels
from safebasins.numerics import escape_chart, stroboscopic_map

OM, F, BETA = 0.85, 0.055, 0.1


def test_chart_labels_follow_is_safe():
    q0, p0 = np.linspace(-0.8, 1.2, 12), np.linspace(-0.8, 0.8, 10)
    ch = escape_chart(q0, p0, F, OM, 0.0, xi_max=(1 / 6,), cycles=30, well="cubic", damping=BETA)
    lab = chart_labels(ch, 20)
    t = ch["escape_cycle_energy"].isel(xi_max=0).values
    np.testing.assert_array_equal(lab.values, np.where(t > 20, SAFE, ESCAPED))
    assert lab.dims == ("q0", "p0") and lab.attrs["flag_meanings"] == "escaped safe" and lab.attrs["t_eval"] == 20
    assert lab.attrs["damping"] == BETA and lab.attrs["well"] == "cubic"
    assert 0 < (lab.values == SAFE).mean() < 1
    with pytest.raises(ValueError, match="threshold 0.2"):
        chart_labels(ch, threshold=0.2)
    with pytest.raises(ValueError, match="t_eval"):
        chart_labels(ch, 31)


def test_map_labels_find_the_two_attractors():
    """Each attractor found is a fixed point of the period map (DOP853 over one period, 1e-4),
    each basin holds ICs, and escaped ICs are the map's escaped ones."""
    q0, p0 = np.linspace(-0.8, 1.2, 30), np.linspace(-0.8, 0.8, 24)
    Q, P = np.meshgrid(q0, p0, indexing="ij")
    m = stroboscopic_map(Q, P, F, OM, 0.0, n_iter=100, xi_max=1 / 6, well="cubic", damping=BETA)
    lab = map_labels(m)
    assert lab.attrs["flag_meanings"] == "escaped attractor_1 attractor_2" and lab.attrs["attractor_period"] == [1, 1]
    np.testing.assert_array_equal(lab.values.ravel() == 0, m["escaped"].values)
    assert all((lab.values == k).sum() > 20 for k in range(3))
    T = 2 * np.pi / OM

    def rhs(t, y):
        return [y[1], -BETA * y[1] - y[0] + y[0] ** 2 + F * np.sin(OM * t)]
    for q, p in zip(lab.attrs["attractor_q"], lab.attrs["attractor_p"]):
        end = solve_ivp(rhs, (0, T), [q, p], method="DOP853", rtol=1e-11, atol=1e-12).y[:, -1]
        assert np.hypot(end[0] - q, end[1] - p) < 1e-4
    # the resonant attractor has the larger amplitude: its orbit's smallest q is lower
    assert lab.attrs["attractor_q"][0] < lab.attrs["attractor_q"][1] - 0.1


def test_check_labels():
    lab, q0, p0 = check_labels(np.array([[1.0, 2.0], [2.0, 1.0]]))
    assert lab.dtype == np.int64 and q0 is None
    da = xr.DataArray(np.zeros((3, 2), bool), dims=("p0", "q0"), coords={"q0": [0.0, 1.0], "p0": [0.0, 1.0, 2.0]})
    lab, q0, p0 = check_labels(da)
    assert lab.shape == (2, 3) and q0.tolist() == [0.0, 1.0]
    with pytest.raises(ValueError, match="labels must hold integer labels"):
        check_labels(np.array([["a", "b"], ["c", "d"]]))
    with pytest.raises(ValueError, match="at least 2 nodes"):
        check_labels(np.zeros((1, 5), int))
