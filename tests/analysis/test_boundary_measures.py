"""The measures of a damped well's basins over F (Thompson's escape equation, beta = 0.1,
Omega = 0.85 on a coarse grid): each number is the library measure of the map's labels, and the
figure draws them with caption notes read from the data."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest

from safebasins.analysis import basin_entropy, fractal_test
from safebasins.analysis.basin_labels import map_labels
from safebasins.analysis.basin_measures import grid_uncertainty_exponent
from safebasins.analysis.boundary_measures import boundary_measures
from safebasins.analysis.melnikov import melnikov_threshold
from safebasins.analysis.wada import wada_test
from safebasins.numerics import stroboscopic_map
from safebasins.plotting.basin_measures import figure_basin_measures
from safebasins.plotting.captions import notes
from tests.plotting.test_plotting import render

Q, P = np.linspace(-0.8, 1.2, 40), np.linspace(-0.8, 0.8, 36)
KW = dict(damping=0.1, well="cubic", n_iter=60, radius=3, n_balls=100, eps=(1, 2, 4), box=4)


@pytest.fixture(scope="module")
def measures():
    return boundary_measures([0.055, 0.07], 0.85, 0.0, 1 / 6, Q, P, **KW)


def test_each_number_is_the_measure_of_the_map_labels(measures):
    QQ, PP = np.meshgrid(Q, P, indexing="ij")
    lab = map_labels(stroboscopic_map(QQ, PP, 0.055, 0.85, 0.0, n_iter=60, xi_max=1 / 6, well="cubic", damping=0.1))
    np.testing.assert_array_equal(measures["basin"].isel(F=0).values, lab.values)
    for name, labels in (("escape", (lab.values > 0).astype(int)), ("attractors", lab.values)):
        m = measures.sel(F=0.055, labelling=name)
        be = basin_entropy(labels, box=4, offsets=16)
        ft = fractal_test(labels, radius=3, n_balls=100)
        ue = grid_uncertainty_exponent(labels, eps=(1, 2, 4))
        assert m["S_bb"].item() == be["S_bb"].item() and m["S_bb_err"].item() == be["S_bb_err"].item()
        assert m["p_value"].item() == ft["p_value"].item() and m["ball_S_bb"].item() == ft["S_bb"].item()
        assert m["alpha"].item() == ue.attrs["alpha"]
    assert measures["W"].sel(F=0.055).item() == wada_test(lab)["W"].sel(r=3).item()
    assert measures["n_attractors"].values.tolist() == [2, 1]               # the resonant branch is lost past F_M
    assert np.isnan(measures["W"].sel(F=0.07).item()) and measures["wada"].sel(F=0.07).item() == -1
    assert measures["F_melnikov"].item() == pytest.approx(melnikov_threshold(0.85, 0.1, well="cubic"))
    assert measures.attrs["well"] == "cubic" and "parameters" in measures.attrs
    assert measures["safe_fraction"].sel(F=0.055).item() == pytest.approx((lab.values > 0).mean())


def test_figure_notes_from_the_data(measures, tmp_path):
    fig = figure_basin_measures(measures)
    text = " ".join(notes(fig))
    m = measures.sel(F=0.055, labelling="escape")
    assert f"alpha {m['alpha'].item():.3f}" in text and f"F_M = {measures['F_melnikov'].item():.5f}" in text
    assert "fewer than three basins" in text and f"W(3) = {measures['W'].values[0]:.3f}" in text
    assert len(fig.axes) == 4
    render(fig, tmp_path, "basin_measures")


def test_bad_input():
    with pytest.raises(ValueError, match="damping"):
        boundary_measures([0.05], 0.85, 0.0, 1 / 6, Q, P, **{**KW, "damping": 0.0})
    with pytest.raises(ValueError, match="F_values"):
        boundary_measures([-0.05], 0.85, 0.0, 1 / 6, Q, P, **KW)
