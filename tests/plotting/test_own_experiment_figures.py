"""Figures of a user's own experiment are readable: the heading (the experiment's title, the well
and its potential) overlaps nothing drawn, an expression well is named by its formula, the
legend's mechanism abbreviations are spelled out on the figure, an empty fractality panel says why
(on the panel and in the caption), and a chart's labels and legend stay inside the figure."""
import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest
import xarray as xr

from safebasins import theory
from safebasins.analysis.ic_basins import analytic_basin
from safebasins.analysis.tangency import fractality_profile, tangency_profile
from safebasins.numerics import escape_chart
from safebasins.plotting import plot_escape_chart, plot_fcr, save_figure
from safebasins.plotting.captions import notes
from safebasins.plotting.data import well_text
from safebasins.plotting.fcr import MECHANISM_WORDS, figure_fcr
from safebasins.plotting.tangency import figure_tangency

PEND_Q, PEND_P = np.linspace(-2.9, 2.9, 24), np.linspace(-2.05, 2.05, 18)


@pytest.fixture(scope="module")
def pendulum_chart():
    chart = escape_chart(PEND_Q, PEND_P, 0.05, 0.8, 0.0, xi_max=(1.0, 1.5), cycles=30, steps_per_cycle=16,
                         well="pendulum")
    basin = analytic_basin(0.05, 0.8, 0.0, 1.5, PEND_Q, PEND_P, well="pendulum", n_points=200)
    return chart, basin


def _extents(fig, skip=None):
    """(name, window extent) of everything drawn on the figure but ``skip``: each axes with its
    titles, labels, drawn tick labels and legend (its tight bbox), the figure's texts, suptitle and
    legends."""
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    out = [(f"axes {ax.get_title()!r}", ax.get_tightbbox(r)) for ax in fig.axes]
    texts = [t for t in (*fig.texts, fig._suptitle) if t is not None and t is not skip and t.get_text()]
    out += [(t.get_text(), t.get_window_extent(r)) for t in texts]
    out += [("figure legend", lg.get_window_extent(r)) for lg in fig.legends]
    return out


def _check_heading(fig, heading):
    hb = heading.get_window_extent(fig.canvas.get_renderer())
    others = _extents(fig, skip=heading)
    hits = [name for name, bb in others if bb.overlaps(hb)]
    assert not hits, f"the heading overlaps {hits}"
    assert hb.y0 >= max(bb.y1 for _, bb in others) - 1          # above everything drawn


def test_heading_names_title_and_well_above_everything(pendulum_chart, tmp_path):
    chart, basin = pendulum_chart
    fig = plot_escape_chart(chart, basin=basin)
    fig.suptitle("a figure title of its own")             # a suptitle too: the heading goes above it
    save_figure(fig, tmp_path / "chart.png", datasets=[chart], heading="My pendulum run")
    heading = [t for t in fig.texts if "My pendulum run" in t.get_text()]
    assert len(heading) == 1
    assert "well: pendulum" in heading[0].get_text() and "V = 1 - cos q" in heading[0].get_text()
    _check_heading(fig, heading[0])


def test_fcr_heading_and_mechanism_key(tmp_path):
    ds = theory.critical_forcing(np.linspace(0.5, 1.1, 25), 1.5, well="pendulum")
    fig = figure_fcr(ds, show_branches=True)
    save_figure(fig, tmp_path / "fcr.png", datasets=[ds])
    heading = [t for t in fig.texts if t.get_text().startswith("well: pendulum")]
    assert len(heading) == 1
    _check_heading(fig, heading[0])
    key = " ".join(t.get_text() for t in fig.texts if "Mechanisms:" in t.get_text())
    for abbr in ("SM", "MM"):
        assert f"{abbr}: {MECHANISM_WORDS[abbr].split(' (')[0]}" in key.replace("\n", " "), key
    # the API figure too
    fig2 = plot_fcr(ds)
    assert any("saddle mechanism" in t.get_text().replace("\n", " ") for t in fig2.texts)


def test_expression_well_is_named_by_its_formula():
    attrs = {"well": "expression", "well_expression": "q**2/2 - q**3/4 + q**4/40"}
    assert well_text(attrs) == "well: V(q) = q**2/2 - q**3/4 + q**4/40"
    assert well_text({"well": "quartic"}) is None and well_text({}) is None
    assert well_text({"well": "polynomial", "well_coefficients": [0.0, 0.0, 0.5, -1 / 3]}).startswith(
        "well: polynomial, V(q) = 0.5 q^2")


@pytest.mark.parametrize("well, q, p", [("pendulum", PEND_Q, PEND_P),
                                        ("quartic", np.linspace(-1, 1, 20), np.linspace(-0.75, 0.75, 16))])
def test_chart_labels_and_legend_inside_the_figure(well, q, p):
    """A plain ``fig.savefig`` (no tight bbox) keeps every axis label and the legend: the figure's
    tight bbox lies inside the canvas."""
    chart = escape_chart(q, p, 0.05 if well == "pendulum" else 0.01, 0.8, 0.0, xi_max=(1.0,) if well == "pendulum"
                         else (0.18,), cycles=10, steps_per_cycle=16, well=well)
    fig = plot_escape_chart(chart)
    fig.canvas.draw()
    bb = fig.get_tightbbox(fig.canvas.get_renderer())
    w, h = fig.get_size_inches()
    assert bb.x0 >= 0 and bb.y0 >= 0 and bb.x1 <= w and bb.y1 <= h, (bb.bounds, (w, h))


@pytest.fixture(scope="module")
def tangency_data():
    q, p = np.linspace(-0.8, 1.2, 9), np.linspace(-0.8, 0.8, 9)
    F = [0.05, 0.07]
    charts = [escape_chart(q, p, f, 0.85, 0.0, xi_max=(1 / 6,), cycles=20, steps_per_cycle=16, well="cubic",
                           damping=0.1).assign_attrs(F=f) for f in F]
    prof = tangency_profile(charts, keep_F=[0.05])
    frac = fractality_profile(F, 0.85, 0.0, 1 / 6, ((-0.8, 1.2), (-0.8, 0.8)), damping=0.1, n=100, cycles=20,
                              steps_per_cycle=16, well="cubic")
    return prof, frac


def test_empty_fractality_panel_says_why(tangency_data):
    prof, frac = tangency_data
    assert not np.isfinite(frac["alpha"].values).any()        # 100 base points: too few uncertain ones
    fig = figure_tangency(prof, frac)
    panel = fig.axes[1]
    said = " ".join(t.get_text() for t in panel.texts).replace("\n", " ")
    assert "not fitted" in said and "too few uncertain" in said and "100 base points" in said, said
    caption = " ".join(notes(fig))
    assert "nan" not in caption.lower(), caption
    assert "not fitted" in caption and "too few uncertain" in caption


def test_fitted_fractality_has_no_excuse(tangency_data):
    prof, frac = tangency_data
    fitted = frac.copy()
    fitted["alpha"] = xr.full_like(frac["alpha"], 0.8)
    fitted["alpha_err"] = xr.full_like(frac["alpha_err"], 0.05)
    fig = figure_tangency(prof, fitted)
    assert not any("not fitted" in t.get_text() for t in fig.axes[1].texts)
    assert not any("not fitted" in n for n in notes(fig))
