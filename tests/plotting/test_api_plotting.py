"""The public plotting functions (safebasins.plotting.plot_*) on datasets made directly by the API
(small grids, few cycles), their errors on a dataset missing a variable, and the provenance the
saved PNG carries."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest
import xarray as xr

import safebasins.numerics as nu
import safebasins.theory as th
from safebasins.plotting import plot_basin, plot_escape_chart, plot_fcr, plot_integrity_map, save_figure

Q0, P0 = np.linspace(-0.9, 0.9, 30), np.linspace(-0.7, 0.7, 30)
ARGS = dict(F=0.01, Omega=0.9, Psi=np.pi)


@pytest.fixture(scope="module")
def chart():
    return nu.escape_chart(Q0, P0, **ARGS, xi_max=(0.14, 0.18), q_max=(0.8,), cycles=50)


@pytest.fixture(scope="module")
def basin():
    return th.safe_basin_boundaries(0.01, 0.9, np.pi, 0.18, n_points=200)


def _png_ok(fig, tmp_path, name):
    path = tmp_path / f"{name}.png"
    save_figure(fig, path, dpi=50)
    plt.close(fig)
    assert path.stat().st_size > 5000
    return path


def test_plot_escape_chart(chart, basin, tmp_path):
    fig = plot_escape_chart(chart, basin=basin)
    ax = fig.axes[0]
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any("0.14" in t for t in texts) and any("0.18" in t for t in texts)
    assert "theory" in ax.get_legend().get_title().get_text()  # the basin's boundaries are drawn
    assert "50 EC" in ax.get_title()
    _png_ok(fig, tmp_path, "chart")
    # one threshold, an earlier t_eval, into an existing axes
    f0, a0 = plt.subplots()
    assert plot_escape_chart(chart, xi_max=0.14, t_eval=20, ax=a0) is f0
    assert len(a0.get_legend().get_texts()) == 2 and "20 EC" in a0.get_title()
    plt.close(f0)
    # displacement criterion when the chart has no energy one
    fig = plot_escape_chart(chart.drop_vars("escape_cycle_energy"))
    assert "displacement" in fig.axes[0].get_title()
    plt.close(fig)
    with pytest.raises(ValueError, match="not in the chart"):
        plot_escape_chart(chart, xi_max=0.2)
    with pytest.raises(ValueError, match="beyond the chart's horizon"):
        plot_escape_chart(chart, t_eval=60)


def test_plot_basin(basin, tmp_path):
    fig = plot_basin(basin)  # boundaries only: the API's safe_basin_boundaries has no mask
    ax = fig.axes[0]
    assert ax.lines or ax.patches
    assert "0.18" in ax.get_title()
    plt.close(fig)
    esc = th.slow_flow_escapes(Q0[:, None], P0[None, :], 0.01, 0.9, np.pi, 0.18)
    filled = basin.assign(escapes=xr.DataArray(esc, dims=("q0", "p0"), coords={"q0": Q0, "p0": P0}))
    fig = plot_basin(filled)
    assert fig.axes[0].collections  # the grey fill
    _png_ok(fig, tmp_path, "basin")


def test_plot_basin_and_chart_with_a_basin_stack(chart, basin, tmp_path):
    """A stack over xi_max (the pipeline's layout, Figs 13-15) draws one colour per value."""
    from safebasins.core.stacking import stack

    parts = []
    for x in (0.14, 0.18):
        b = th.safe_basin_boundaries(0.01, 0.9, np.pi, x, n_points=200)
        esc = th.slow_flow_escapes(Q0[:, None], P0[None, :], 0.01, 0.9, np.pi, x)
        parts.append(b.assign(escapes=xr.DataArray(esc, dims=("q0", "p0"), coords={"q0": Q0, "p0": P0})))
    stacked = stack(parts, "xi_max", [0.14, 0.18])
    fig = plot_basin(stacked)
    texts = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert sum(t.startswith(r"$\xi_{max}$ = ") for t in texts) == 2
    _png_ok(fig, tmp_path, "basin_stack")
    fig = plot_escape_chart(chart, basin=stacked)
    ax = fig.axes[0]  # a theory colour per threshold (closed curves are patches)
    colors = {ln.get_color() for ln in ax.lines} | {matplotlib.colors.to_hex(p.get_edgecolor()) for p in ax.patches}
    assert {"#d62728", "#1f77b4"} <= {matplotlib.colors.to_hex(c) for c in colors}
    plt.close(fig)


def test_plot_fcr(tmp_path):
    ana = th.critical_forcing(np.linspace(0.6, 1.2, 120), xi_max=0.15)
    num = nu.critical_forcing_numeric([0.7, 1.1], 0.15, cycles=50, n_scan=6)
    fig = plot_fcr(ana, num)
    ax = fig.axes[0]
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "SM" in texts and any("numeric" in t for t in texts)
    lo, hi = ax.get_xlim()
    assert lo < 0.6 and hi > 1.2  # the end markers are not clipped
    _png_ok(fig, tmp_path, "fcr")
    for only in (dict(analytic=ana), dict(numeric=num)):
        plt.close(plot_fcr(**only))
    with pytest.raises(ValueError, match="at least one"):
        plot_fcr()


def test_plot_integrity_map(tmp_path):
    from safebasins.analysis.integrity_map import erosion_front, integrity_map_analytic, integrity_map_numeric

    q, p = np.linspace(-0.7, 0.7, 15), np.linspace(-0.6, 0.6, 15)
    ana = integrity_map_analytic([0.8, 1.0], [0.0, 0.02, 0.04], np.pi, 0.18, q, p, n_gamma=32, n_xi=16)
    fig = plot_integrity_map(ana.merge(erosion_front(ana)), measure="LIM")
    assert fig.axes[1].get_ylabel().startswith("LIM")  # the colour bar is labelled
    assert fig.axes[0].get_legend() is not None  # the erosion front
    _png_ok(fig, tmp_path, "imap")
    num = integrity_map_numeric([0.8, 1.0], [0.0, 0.02], np.pi, 0.18, q, p, cycles=20, t_eval=[10, 20])
    fig = plot_integrity_map(num)
    assert "20 EC" in fig.axes[0].get_title()  # the last t_eval
    plt.close(fig)
    diff = ana[["GIM"]].assign(GIM_diff=ana["GIM"] - 1.0)
    fig = plot_integrity_map(diff, measure="GIM_diff")
    lo, hi = fig.axes[0].collections[0].get_clim()
    assert lo == -hi and hi < 1.5  # symmetric, from the data
    plt.close(fig)


def test_missing_variable_is_a_value_error_naming_it(chart, basin):
    from safebasins.analysis.integrity_map import integrity_map_analytic

    with pytest.raises(ValueError, match="'escape_cycle_energy' or 'escape_cycle_displacement'"):
        plot_escape_chart(chart.drop_vars(["escape_cycle_energy", "escape_cycle_displacement"]))
    with pytest.raises(ValueError, match="'cycles'"):
        plot_escape_chart(chart.drop_attrs(deep=False))
    with pytest.raises(ValueError, match="'q0_vertex'"):
        plot_basin(basin.drop_vars("q0_vertex"))
    with pytest.raises(ValueError, match="'F_cr'"):
        plot_fcr(th.critical_forcing([0.8, 0.9], xi_max=0.15).drop_vars("F_cr"))
    q = np.linspace(-0.5, 0.5, 9)
    ana = integrity_map_analytic([0.9], [0.0, 0.02], np.pi, 0.18, q, q, n_gamma=16, n_xi=8)
    with pytest.raises(ValueError, match="'IF_true'"):
        plot_integrity_map(ana.drop_vars("IF_true"), measure="IF_true")
    plt.close("all")


def test_nested_basins_builder_reads_an_api_chart(chart, basin):
    """The pipeline builder (Figs 13-17) takes the API's chart: no ``scan`` attribute, no IoU."""
    from safebasins.plotting.charts import figure_nested_basins

    fig = figure_nested_basins(basin, chart)
    texts = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any("0.18" in t for t in texts) and not any("IoU" in t for t in texts)
    plt.close(fig)
    plt.close(figure_nested_basins(None, chart))


def test_png_carries_the_provenance_of_its_datasets(chart, tmp_path):
    from PIL import Image

    from safebasins.io.datasets import finalize

    ds = finalize(chart.copy(), title="test chart", params={"F": 0.01})
    fig = plot_escape_chart(ds)
    path = _png_ok(fig, tmp_path, "provenance")
    text = Image.open(path).text
    assert text["safebasins_version"] == ds.attrs["safebasins_version"]
    assert text["git_commit"] == ds.attrs["git_commit"] and text["config_hash"] == ds.attrs["config_hash"]
    assert '"F": 0.01' in text["parameters"] and text["well"] == "quartic" and text["Title"] == "test chart"
    # the pipeline notebooks pass the dataset files
    nc = tmp_path / "chart.nc"
    ds.to_netcdf(nc)
    fig, _ = plt.subplots()
    save_figure(fig, tmp_path / "nb.png", tmp_path / "nb.pdf", dpi=30, datasets=[str(nc), "results/params/x.yaml"])
    plt.close(fig)
    text = Image.open(tmp_path / "nb.png").text
    assert text["Source"] == str(nc) and text["config_hash"] == ds.attrs["config_hash"]
    assert (tmp_path / "nb.pdf").stat().st_size > 0
