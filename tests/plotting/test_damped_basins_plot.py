"""Damped safe basins drawn: figure_nested_basins / plot_escape_chart / plot_basin name
beta, label the analytic lines as the damped slow flow's mask outline and refuse a basin whose
damping differs from the chart's."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

from safebasins.analysis.agreement import chart_agreement
from safebasins.analysis.ic_basins import analytic_basin_stack
from safebasins.numerics import escape_chart
from safebasins.plotting import plot_basin, plot_escape_chart
from safebasins.plotting.captions import notes
from safebasins.plotting.charts import figure_nested_basins

Q, P = np.linspace(-0.9, 0.9, 30), np.linspace(-0.7, 0.7, 24)
ARGS = ("xi_max", [0.14, 0.18], 0.01, 0.9, np.pi, None, Q, P)


@pytest.fixture(scope="module")
def damped():
    b = analytic_basin_stack(*ARGS, damping=0.01)
    ch = escape_chart(Q, P, 0.01, 0.9, np.pi, xi_max=(0.14, 0.18), cycles=100, damping=0.01)
    ch.attrs["scan"] = "xi_max"
    return chart_agreement(ch, b, 100, "xi_max"), b


def test_nested_figure_names_beta_and_the_mask_outline(damped):
    chart, basin = damped
    fig = figure_nested_basins(basin, chart)
    ax = fig.axes[0]
    assert r"$\beta$ = 0.01" in ax.get_title() and ax.get_title().startswith("Damped safe basins")
    assert "mask outline" in ax.get_legend().get_title().get_text()
    assert len(ax.lines) + len(ax.patches) > 0
    text = " ".join(notes(fig))
    assert "β = 0.01" in text and "outline of the analytic safe mask" in text
    assert f"IoU {float(chart['iou'][0]):.3f}" in text          # caption numbers from the data
    plt.close(fig)


def test_a_basin_of_other_damping_is_refused(damped):
    chart, _ = damped
    with pytest.raises(ValueError, match="damping"):
        figure_nested_basins(analytic_basin_stack(*ARGS, n_points=100), chart)
    with pytest.raises(ValueError, match="damping"):
        plot_escape_chart(chart, basin=analytic_basin_stack(*ARGS, n_points=100))


def test_api_plots_draw_damped_basins(damped):
    chart, basin = damped
    fig = plot_escape_chart(chart, basin=basin)
    assert r"$\beta$ = 0.01" in fig.axes[0].get_title()
    plt.close(fig)
    fig = plot_basin(basin.isel(xi_max=1).assign_attrs(xi_max=0.18))
    ax = fig.axes[0]
    assert "damped" in ax.get_title() and r"$\beta$ = 0.01" in ax.get_title()
    assert any("mask outline" in t.get_text() for t in ax.get_legend().get_texts())
    plt.close(fig)
    fig = plot_basin(basin)
    assert any("mask outline" in t.get_text() for t in fig.axes[0].get_legend().get_texts())
    plt.close(fig)
