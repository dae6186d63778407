"""``safebasins fatal-shock``: the dataset of the pipeline's minimal_fatal_shock kind (the same numbers
as the library call), the figure, the summary lines; bad options named before anything is written."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

from safebasins.analysis.fatal_shock import minimal_fatal_shock
from safebasins.cli import main

ARGS = ["fatal-shock", "--well", "cubic", "--F", "0.055", "--Omega", "0.85", "--xi-max", "0.16666", "--damping",
        "0.1", "--n-phases", "2", "--cycles", "10", "--n-directions", "16", "--n-radii", "12", "--n-lim", "21",
        "--steps-per-cycle", "32", "--threads", "1", "--quiet"]


def test_writes_the_library_dataset(tmp_path: Path) -> None:
    res = CliRunner().invoke(main, [*ARGS, "--weights", "1,4", "-o", str(tmp_path / "fs")], catch_exceptions=False)
    assert res.exit_code == 0, res.output
    ds = xr.open_dataset(tmp_path / "fs.nc")
    ref = minimal_fatal_shock(0.055, 0.85, 0.1, "cubic", phases=[0.0, math.pi], xi_max=0.16666, cycles=10,
                              weights=(1.0, 4.0), n_directions=16, n_radii=12, n_lim=21, steps_per_cycle=32,
                              threads=1)
    for k in ("mfs", "lim", "shock_dq", "shock_dp", "escape_cycle", "q_attractor", "response_amplitude"):
        np.testing.assert_array_equal(ds[k].values, ref[k].values, err_msg=k)
    assert list(ds["norm"].values) == ["energy", "weighted"] and ds.attrs["damping"] == 0.1
    assert (tmp_path / "fs.png").stat().st_size > 0
    mfs = ref["mfs"].values
    assert f"attractor 1 (amplitude {float(ref['response_amplitude'][1]):.4f}), energy norm: MFS " \
           f"{mfs[1, :, 0].min():.5f}" in res.output


@pytest.mark.parametrize("extra,option", [(["--damping", "0"], "--damping"), (["--n-lim", "20"], "--n-lim"),
                                          (["--weights", "1"], "--weights"), (["--weights", "1,0"], "--weights"),
                                          (["--xi-max", "0.2"], "--xi-max"), (["--n-directions", "4"],
                                                                              "--n-directions"),
                                          (["--radius-max", "0.01"], "--radius-max")])
def test_bad_options_named(tmp_path: Path, extra: list[str], option: str) -> None:
    args = list(ARGS)
    if extra[0] in args:
        args[args.index(extra[0]) + 1] = extra[1]
    else:
        args += extra
    res = CliRunner().invoke(main, [*args, "-o", str(tmp_path / "bad")])
    assert res.exit_code == 2 and option in res.output, res.output
    assert not (tmp_path / "bad.nc").exists() and "np.float64" not in res.output
