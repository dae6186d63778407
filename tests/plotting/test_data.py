"""safebasins.plotting.data as docs/contracts.md describes it: MissingData names the dataset and the
exact name and is both a KeyError and a ValueError; a plot_* function raises it for a dataset
without a variable it needs; contracts.md documents it and the public plotting modules (api,
curves), and every name it gives there exists."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import safebasins.plotting as plotting
from safebasins.io.datasets import write_netcdf
from safebasins.plotting import api, curves
from safebasins.plotting.data import MissingData, open_dataset, param, var

CONTRACTS = Path(__file__).resolve().parents[2] / "docs" / "contracts.md"


@pytest.fixture
def stored(tmp_path):
    path = tmp_path / "chart_x.nc"
    write_netcdf(xr.Dataset({"iou": ("xi_max", [0.9])}, coords={"xi_max": [0.2]}, attrs={"F": 0.01}), path)
    return path


def test_missing_variable_names_file_and_name(stored):
    ds = open_dataset(stored)
    with pytest.raises(MissingData) as info:
        var(ds, "escape_cycle_energy")
    msg = str(info.value)
    assert msg.startswith(f"{stored}: no variable 'escape_cycle_energy'") and "'iou'" in msg and not msg.startswith('"')
    assert isinstance(info.value, KeyError) and isinstance(info.value, ValueError)
    with pytest.raises(MissingData, match=f"{re.escape(str(stored))}: no attribute or single-valued coordinate "
                                          "'Omega'"):
        param(ds, "Omega")
    assert param(ds, "F") == 0.01 and param(ds, "xi_max") == 0.2


def test_plot_function_raises_missing_data_for_an_unfit_dataset():
    bad = xr.Dataset({"something": (("q0", "p0"), np.zeros((3, 3)))}, coords={"q0": [0, 1, 2], "p0": [0, 1, 2]})
    with pytest.raises(ValueError, match="no variable"):     # documented as ValueError (MissingData)
        api.plot_escape_chart(bad)


def test_contracts_document_missing_data_and_the_public_plotting_modules():
    text = CONTRACTS.read_text()
    section = text.split("## safebasins.plotting", 1)[1].split("\n## ", 1)[0]
    for name in ("MissingData", "KeyError", "ValueError", "api.plot_escape_chart", "api.plot_basin", "api.plot_fcr",
                 "plot_integrity_map", "curves", "draw_well", "save_figure"):
        assert name in section, name
    for name in re.findall(r"`api\.(\w+)", section):
        assert hasattr(api, name) and name in plotting.__all__, name
    assert callable(curves.draw_well)
