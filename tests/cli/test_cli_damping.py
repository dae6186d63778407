"""``--damping`` on `safebasins chart` and `safebasins basin`: the damped numerics and
the damped slow flow's basins, beta recorded in the dataset; bad values and options that do not
apply with damping are usage errors naming --damping."""
from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr

from tests.cli.test_cli import CHART, run

BASIN = ["basin", "--F", "0.01", "--Omega", "0.9", "--Psi", "pi", "--xi-max", "0.18", "--n", "16x12"]


def test_chart_with_damping_integrates_and_classifies_damped(tmp_path):
    res = run([*CHART, "--damping", "0.01", "-o", "c"], tmp_path)
    assert res.returncode == 0, res.stderr
    with xr.open_dataset(tmp_path / "c.nc") as ds:
        assert ds.attrs["damping"] == 0.01 and json.loads(ds.attrs["parameters"])["damping"] == 0.01
        assert "beta = 0.01" in ds.attrs["title"]
        from safebasins.numerics import escape_chart

        ref = escape_chart(ds["q0"].values, ds["p0"].values, 0.01, 0.9, np.pi, xi_max=(0.14, 0.18), cycles=20,
                           damping=0.01)
        assert np.array_equal(ds["escape_cycle_energy"].values, ref["escape_cycle_energy"].values)
    assert (tmp_path / "c.png").stat().st_size > 0
    # beta = 0 is the undamped command: no damping recorded
    res = run([*CHART, "--damping", "0", "--no-plot", "-o", "u"], tmp_path)
    assert res.returncode == 0, res.stderr
    with xr.open_dataset(tmp_path / "u.nc") as ds:
        assert "damping" not in ds.attrs and "damping" not in json.loads(ds.attrs["parameters"])


def test_basin_with_damping_draws_the_ic_plane_only(tmp_path):
    res = run([*BASIN, "--damping", "0.01", "-o", "b"], tmp_path)
    assert res.returncode == 0, res.stderr
    assert "mask_outline" in res.stdout
    with xr.open_dataset(tmp_path / "b.nc") as ds:
        assert ds.attrs["damping"] == 0.01 and "C" not in ds and "escapes_rm" not in ds
        from safebasins.theory import slow_flow_escapes

        q, p = ds["q0"].values, ds["p0"].values
        want = slow_flow_escapes(q[:, None], p[None, :], 0.01, 0.9, np.pi, 0.18, damping=0.01)
        assert np.array_equal(ds["escapes"].transpose("q0", "p0").values, want)
    assert (tmp_path / "b.png").stat().st_size > 0


@pytest.mark.parametrize("args, text", [
    ([*CHART, "--damping", "-0.1"], ">= 0"),
    ([*CHART, "--damping", "nan"], "NaN"),
    ([*BASIN, "--damping", "inf"], "finite"),
    ([*BASIN, "--damping", "0.01", "--n-gamma", "24"], "--n-gamma"),
    ([*BASIN, "--damping", "0.01", "--xi-top", "0.2"], "--xi-top"),
])
def test_bad_damping_is_a_usage_error_naming_it(tmp_path, args, text):
    res = run([*args, "-o", "x"], tmp_path)
    assert res.returncode == 2 and "'--damping'" in res.stderr and text in res.stderr, res.stderr
    assert not list(tmp_path.iterdir())
