"""What the public plotting functions accept, as their annotations say: a path for every dataset
(plot_integrity_map too), axes inside a subfigure (the Figure returned is the whole figure, which
save_figure can write), and a Dataset in a provenance list is never taken for a parameter file."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr
from matplotlib.figure import Figure

import safebasins.theory as th
from safebasins.analysis.integrity_map import integrity_map_analytic
from safebasins.io.datasets import write_netcdf
from safebasins.plotting import plot_basin, plot_integrity_map, save_figure
from safebasins.plotting.data import describe, provenance


def test_plot_integrity_map_reads_a_path(tmp_path):
    q = np.linspace(-0.5, 0.5, 9)
    ana = integrity_map_analytic([0.9, 1.0], [0.0, 0.02], np.pi, 0.18, q, q, n_gamma=16, n_xi=8)
    path = tmp_path / "integrity_map_analytic.nc"
    write_netcdf(ana, path)
    from_path, from_data = plot_integrity_map(path, measure="LIM"), plot_integrity_map(ana, measure="LIM")
    drawn = [np.asarray(f.axes[0].collections[0].get_array()) for f in (from_path, from_data)]
    np.testing.assert_array_equal(drawn[0], drawn[1])
    assert from_path.axes[0].get_title() == from_data.axes[0].get_title()
    plt.close("all")


def test_axes_in_a_subfigure_return_the_figure(tmp_path):
    basin = th.safe_basin_boundaries(0.01, 0.9, np.pi, 0.18, n_points=100)
    fig = plt.figure(figsize=(8, 4))
    left, _right = fig.subfigures(1, 2)
    out = plot_basin(basin, ax=left.subplots())
    assert out is fig and isinstance(out, Figure)
    save_figure(out, tmp_path / "basin.png", dpi=40)
    assert (tmp_path / "basin.png").stat().st_size > 1000
    plt.close(fig)


def test_a_dataset_is_not_taken_for_a_parameter_file(tmp_path, capsys):
    ds = xr.Dataset({"iou": ("xi_max", [0.9])}, coords={"xi_max": [0.2]},
                    attrs={"title": "a chart", "params_file": "results/params/chart.yaml"})
    assert str(ds).endswith(".yaml")               # what a check on the text alone would read as a path
    assert provenance(ds) == {"Source": "<dataset>", "Title": "a chart"}
    assert "variables: iou" in describe(chart=ds)
    params = tmp_path / "chart.yaml"
    params.write_text("F: 0.01\n")
    assert provenance(ds, str(params)) == {"Source": "<dataset>", "Title": "a chart"}  # the file itself: skipped
    assert "F: 0.01" in describe(params=str(params))
    capsys.readouterr()
