"""``safebasins hilltop-saddle``: the dataset of the pipeline's hilltop_saddle kind (the library's
numbers), the figure, the summary lines; bad options named before anything runs."""
from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

from safebasins.analysis import hilltop_orbit
from safebasins.cli import main

ARGS = ["hilltop-saddle", "--well", "cubic", "--F", "0.055", "--Omega", "0.85", "--xi-max", "0.16666",
        "--damping", "0.1", "--n", "21", "--cycles", "20", "--ds-max", "0.1", "--quiet"]


def test_writes_the_library_dataset(tmp_path):
    res = CliRunner().invoke(main, [*ARGS, "-o", str(tmp_path / "hs")], catch_exceptions=False)
    assert res.exit_code == 0, res.output
    ds = xr.open_dataset(tmp_path / "hs.nc")
    ref = hilltop_orbit(0.055, 0.85, 0.1, "cubic")
    np.testing.assert_allclose(ds["q_fixed"].values[0], ref["q_fixed"].values, atol=1e-9)
    assert ds["escape_cycle"].shape == (1, 21, 21) and np.isnan(ds["F_tangency"])
    assert (tmp_path / "hs.png").stat().st_size > 0 and ds.attrs["damping"] == 0.1
    assert "F = 0.055 (0.87 F_M): saddle fixed point" in res.output


@pytest.mark.parametrize("extra,option", [(["--damping", "0"], "--damping"), (["--F", "0.01,0.02,0.03,0.04"], "--F"),
                                          (["--xi-max", "0.2"], "--xi-max"), (["--ds-max", "-1"], "--ds-max")])
def test_bad_options_named(tmp_path, extra, option):
    args = list(ARGS)
    i = args.index(extra[0])
    args[i + 1] = extra[1]
    res = CliRunner().invoke(main, [*args, "-o", str(tmp_path / "bad")])
    assert res.exit_code == 2 and option in res.output, res.output
    assert not (tmp_path / "bad.nc").exists()
