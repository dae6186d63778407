"""``safebasins basin-measures``: the dataset of the pipeline's basin_measures kind (the same numbers
as the library call), the figure, the summary lines; bad options named before anything runs."""
from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

from safebasins.analysis.boundary_measures import boundary_measures
from safebasins.cli import main

ARGS = ["basin-measures", "--well", "cubic", "--F", "0.055,0.07", "--Omega", "0.85", "--xi-max", "0.16666",
        "--damping", "0.1", "--n", "41", "--n-iter", "60", "--radius", "3", "--box", "4", "--quiet"]


def test_writes_the_library_dataset(tmp_path):
    res = CliRunner().invoke(main, [*ARGS, "-o", str(tmp_path / "bm")], catch_exceptions=False)
    assert res.exit_code == 0, res.output
    ds = xr.open_dataset(tmp_path / "bm.nc")
    q0, p0 = np.linspace(-0.8, 1.2, 41), np.linspace(-0.8, 0.8, 41)
    assert ds["q0"].values[0] < ds["q0"].values[-1]
    ref = boundary_measures([0.055, 0.07], 0.85, 0.0, 0.16666, ds["q0"].values, ds["p0"].values, damping=0.1,
                            well="cubic", n_iter=60, radius=3, box=4)
    for k in ("S_bb", "p_value", "alpha", "W"):
        np.testing.assert_array_equal(ds[k].values, ref[k].values)
    assert (tmp_path / "bm.png").stat().st_size > 0 and ds.attrs["damping"] == 0.1
    assert "F = 0.055 (0.87 F_M): escape boundary" in res.output and q0.size == p0.size


@pytest.mark.parametrize("extra,option", [(["--damping", "0"], "--damping"), (["--radius", "30"], "--radius"),
                                          (["--box", "50"], "--box"), (["--F", "0.1,0.2,0.3,0.4"], "--F"),
                                          (["--xi-max", "0.2"], "--xi-max"), (["--n", "20"], "--n")])
def test_bad_options_named(tmp_path, extra, option):
    args = list(ARGS)
    for k in range(0, len(extra), 2):
        i = args.index(extra[k]) if extra[k] in args else None
        if i is None:
            args += extra[k:k + 2]
        elif extra[k] == "--F":
            args += extra[k:k + 2]
        else:
            args[i + 1] = extra[k + 1]
    res = CliRunner().invoke(main, [*args, "-o", str(tmp_path / "bad")])
    assert res.exit_code == 2 and option in res.output, res.output
    assert not (tmp_path / "bad.nc").exists()
